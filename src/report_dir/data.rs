//! The report's numbers the figures draw, read back from the report JSON (SPEC §7) by key:
//! `sweep` rows, `placement` (occupation, timeline), `pareto` rows. Each is read as the type
//! the pass that writes it declares ([`SweepRow`], [`PlacementReport`], [`ParetoRow`]: serde
//! both ways), so the figures read exactly what the report holds.

use robovec_passes::place::report::PlacementReport;
use robovec_passes::sweep::SweepRow;
use robovec_passes::whole_run::pareto::ParetoRow;
use serde_json::Value;

/// What the figures draw, read from one report.
#[derive(Clone, Debug, Default)]
pub struct ReportData {
    /// Model name: the input file's stem.
    pub model: String,
    /// The reported function.
    pub function: String,
    /// The pipeline.
    pub pipeline: String,
    /// `sweep` rows (empty without a sweep).
    pub sweep: Vec<SweepRow>,
    /// `placement`, when the final IR is placed.
    pub placement: Option<PlacementReport>,
    /// `pareto` rows (empty without `-pareto`).
    pub pareto: Vec<ParetoRow>,
}

impl ReportData {
    /// Reads the drawn fields of `report`.
    ///
    /// # Errors
    /// A message naming the key whose shape is not the report's (an internal inconsistency:
    /// the report is made by the same program).
    pub fn read(report: &Value) -> Result<ReportData, String> {
        let text = |k: &str| report.get(k).and_then(Value::as_str).unwrap_or_default().to_string();
        let input = text("input");
        let model = std::path::Path::new(&input)
            .file_stem()
            .map_or_else(|| input.clone(), |s| s.to_string_lossy().into_owned());
        fn key<T: serde::de::DeserializeOwned>(report: &Value, k: &str) -> Result<Option<T>, String> {
            report
                .get(k)
                .map(|v| serde_json::from_value(v.clone()).map_err(|e| format!("report key `{k}`: {e}")))
                .transpose()
        }
        Ok(ReportData {
            model,
            function: text("function"),
            pipeline: text("pipeline"),
            sweep: key(report, "sweep")?.unwrap_or_default(),
            placement: key(report, "placement")?,
            pareto: key(report, "pareto")?.unwrap_or_default(),
        })
    }
}
