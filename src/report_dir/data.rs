//! The report's numbers the figures draw, read back from the report JSON (SPEC §7) by key:
//! `sweep` rows, `placement` (occupation, timeline), `pareto` rows. Only the fields drawn are
//! read; the others are ignored, so the report may grow without touching this module.

use serde::Deserialize;
use serde_json::Value;

/// min / mean / max words over the PEs of one type (a `sweep` row's `pe_words_add`…).
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct Words {
    /// Smallest, words.
    pub min: f64,
    /// Mean, words.
    pub mean: f64,
    /// Largest, words.
    pub max: f64,
}

/// The drawn fields of one `sweep` row.
#[derive(Clone, Debug, Deserialize)]
pub struct SweepRow {
    /// N (ADD PEs = MULTI PEs).
    pub n: u32,
    /// `classical`, `mobility` or `classical+fbi`.
    pub priority: String,
    /// `naive` or `preferential`.
    pub select: String,
    /// Cycles of the placement.
    pub cycles: f64,
    /// Cycles in µs at the target's clock.
    pub us: f64,
    /// First lower-bound curve of seed §3.3, cycles.
    pub resource_bound: f64,
    /// Second curve: the critical path, cycles.
    pub critical_path: f64,
    /// Number Y (seed §3.2).
    pub y: f64,
    /// Parallelisation rate (seed §3.4).
    pub parallelisation_rate: f64,
    /// PE memory words over the ADD PEs.
    pub pe_words_add: Words,
    /// PE memory words over the MULTI PEs.
    pub pe_words_mul: Words,
    /// Buffer words over the ADD PEs.
    pub buffer_words_add: Words,
    /// Buffer words over the MULTI PEs.
    pub buffer_words_mul: Words,
}

impl SweepRow {
    /// The configuration's label: `classical`, `mobility`, `classical/naive`, `classical+fbi`.
    pub fn config(&self) -> String {
        if self.select == "preferential" {
            self.priority.clone()
        } else {
            format!("{}/{}", self.priority, self.select)
        }
    }
}

/// Occupation per cycle of each PE type (`placement.occupation`).
#[derive(Clone, Debug, Deserialize)]
pub struct Occupation {
    /// ADD PEs, one rate per cycle.
    pub add: Vec<f64>,
    /// MULTI PEs.
    pub mul: Vec<f64>,
}

/// One issue of `placement.timeline`.
#[derive(Clone, Debug, Deserialize)]
pub struct Issue {
    /// `add` or `mul`.
    pub pe_type: String,
    /// PE index within its type.
    pub pe: u32,
    /// Issue cycle.
    pub cycle: u32,
    /// Latency, cycles.
    pub latency: u32,
    /// Op kind.
    pub op: String,
    /// Value defined.
    pub value: String,
}

/// `placement.timeline`.
#[derive(Clone, Debug, Deserialize)]
pub struct Timeline {
    /// First cycle.
    pub start: u32,
    /// One past the last cycle.
    pub end: u32,
    /// The issues.
    pub issues: Vec<Issue>,
}

/// The drawn fields of `placement`.
#[derive(Clone, Debug, Deserialize)]
pub struct Placement {
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// Cycles.
    pub cycles: u32,
    /// Clock, MHz.
    pub clock_mhz: f64,
    /// Occupation per cycle.
    pub occupation: Occupation,
    /// Timeline window.
    pub timeline: Timeline,
}

/// min/mean/p95/max bits of one precision of a `pareto` row.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct Bits {
    /// Mean bits of error.
    pub mean_bits: f64,
}

/// The drawn fields of one `pareto` row.
#[derive(Clone, Debug, Deserialize)]
pub struct ParetoRow {
    /// The pipeline.
    pub pipeline: String,
    /// The time objective, cycles.
    pub time_cycles: f64,
    /// binary32 errors.
    pub f32: Bits,
    /// binary64 errors.
    pub f64: Bits,
    /// On the front.
    pub pareto_optimal: bool,
    /// Within the error budget.
    pub sound: bool,
}

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
    pub placement: Option<Placement>,
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
