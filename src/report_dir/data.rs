//! The report's numbers the figures draw, as the run made them: the `sweep` rows, the
//! `placement` (occupation, timeline) and the `pareto` rows of the reported function, taken from
//! the run's artifacts and final figures as their own types ([`SweepRow`] of each
//! [`SweepTable`], [`ParetoRow`] of the [`ParetoRun`], the final IR's [`PlacementReport`]),
//! the same values the report JSON holds under the same keys (SPEC §7; the report writes them
//! from these types, `tests/report_dir.rs` checks the figures' CSVs against the JSON). Nothing
//! is parsed back.

use robovec_passes::place::report::PlacementReport;
use robovec_passes::summary::Figures;
use robovec_passes::sweep::{SweepRow, SweepTable};
use robovec_passes::whole_run::pareto::{ParetoRow, ParetoRun};
use robovec_passes::PassContext;

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
    /// What the figures of the report of `own.function` draw after a run of `pipeline` on
    /// `input` with context `cx`: every `sweep` row of the function in the order measured
    /// (the report's `sweep`, appended run after run), the last `-pareto` study of it (the
    /// report's `pareto`) and the final IR's placement figures.
    pub fn of(input: &str, pipeline: &str, own: &Figures, cx: &PassContext) -> ReportData {
        let model = std::path::Path::new(input)
            .file_stem()
            .map_or_else(|| input.to_string(), |s| s.to_string_lossy().into_owned());
        let function = own.function.clone();
        let sweep = cx
            .artifacts_of::<SweepTable>()
            .flat_map(|t| t.rows.iter().filter(|r| r.function == function))
            .cloned()
            .collect();
        let pareto = cx
            .artifacts_of::<ParetoRun>()
            .filter(|p| p.function == function)
            .last()
            .map(|p| p.rows.clone())
            .unwrap_or_default();
        ReportData { model, function, pipeline: pipeline.to_string(), sweep, placement: own.placement.clone(), pareto }
    }
}
