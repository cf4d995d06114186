//! `accuracy<samples=1000;seed=1;mode=sampled|hard;params=FILE.json;worst=DIR;…>`: measures
//! how far each output is from its exact value when the function is computed in binary32 (the
//! FPGA) and in binary64, in the IR's own operation order (SPEC §6).
//!
//! Phase: any → unchanged (an analysis; timing and placement are kept). For each function:
//! 1. draw `samples` input points (ranges and hard points in [`inputs`]; `params` fixes known
//!    inputs), deterministically from `seed` (point `i` depends only on `seed` and `i`);
//! 2. at each point evaluate the function in binary32 and binary64 (the interpreter's
//!    semantics, through `robovec_ir::numerics::Tape`) and compute the certified reference
//!    (double-double with a running error bound, 256/1024-bit astro-float where the bound does
//!    not certify; `robovec_ir::numerics::reference`) **of the function as it entered the
//!    pipeline** (`PassContext::original`: the parsed equations or the input `.rvir`; outputs
//!    and inputs matched by name, so a rewrite that changes the mathematics shows as error);
//! 3. bits of error per output and point (Herbie: log2(1 + floats between the computed and the
//!    correctly rounded exact value); `robovec_ir::numerics::bits`);
//! 4. `mode=hard` then hill-climbs from the worst points ([`hard`]);
//! 5. summarise per output and over all (output, point) pairs: mean, 95th percentile, max,
//!    and list the `worst-count` worst points (largest binary32 error) with every input.
//!
//! Results go to `PassContext::accuracy`; the driver writes them into the report (SPEC §7
//! `accuracy`) and on stderr, and `worst=DIR` makes it write `DIR/worst-K.json` (the `-eval`
//! input format) for each listed point. Points are measured in parallel (rayon) and streamed
//! ([`stream`]: memory independent of `samples`); cost is O(samples × ops) plus the rare
//! 256-bit re-evaluations, bounded by the work budget `max-work`.

pub mod acc;
pub mod check;
pub mod hard;
pub mod inputs;
pub mod measure;
pub mod report;
pub mod stats;
pub mod stream;

use std::collections::BTreeMap;

use robovec_ir::{Function, Module};

use crate::params::ParamKind;
use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};
pub use acc::ReferenceCounts;
pub use measure::{BitsSummary, PointErrors, Subject};
pub use report::{AccuracyReport, OutputAccuracy, ReferenceInfo, WorstPoint};

/// Sampled (physical ranges) or hard (near-singular poses, extreme scales, search) inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Uniform / log-uniform draws over physical ranges.
    Sampled,
    /// Hard points plus hill climbing on the binary32 error.
    Hard,
}

impl Mode {
    /// `sampled` or `hard`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Sampled => "sampled",
            Mode::Hard => "hard",
        }
    }
}

/// Options of one measurement.
#[derive(Clone, Debug)]
pub struct Options {
    /// Points measured (and summarised), samples.
    pub samples: u32,
    /// Seed of the deterministic draws.
    pub seed: u64,
    /// Sampled or hard.
    pub mode: Mode,
    /// Path of a JSON file of known input values (read when the pass runs).
    pub params: Option<String>,
    /// Known input values (from `params`); not sampled.
    pub known: BTreeMap<String, f64>,
    /// Folder for `worst-K.json` files (written by the driver).
    pub worst_dir: Option<String>,
    /// Worst points listed, points.
    pub worst_count: u32,
    /// Hill-climbing rounds (`mode=hard`).
    pub climb_rounds: u32,
    /// Points hill-climbing starts from (the worst ones; `mode=hard`).
    pub climb_points: u32,
    /// Work budget, op evaluations (samples × ops of the measured and reference tapes, plus
    /// hill-climbing neighbours × ops); see [`stream`].
    pub max_work: u64,
    /// Stop (and say so) when this instant passes; checked once per chunk of samples.
    pub deadline: Option<std::time::Instant>,
    /// Samples measured so far, advanced once per chunk (hidden unless the driver shows
    /// progress; see [`crate::progress`]).
    pub progress: crate::progress::Task,
}

/// Default work budget, op evaluations (about 10 minutes on two cores).
pub const DEFAULT_MAX_WORK: u64 = 20_000_000_000;

impl Default for Options {
    /// The defaults declared in [`INFO`].
    fn default() -> Options {
        options_from(&Params::defaults(&INFO)).expect("declared defaults are valid")
    }
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "accuracy",
    doc: "bits of error (Herbie) of every output in f32 and f64 against a certified extended-precision reference",
    params: &[
        ParamInfo {
            name: "samples",
            kind: ParamKind::U32 { default: 1000, min: 1, max: 10_000_000 },
            doc: "input points measured",
        },
        ParamInfo {
            name: "seed",
            kind: ParamKind::U64 { default: 1, min: 0, max: u64::MAX },
            doc: "seed of the deterministic draws",
        },
        ParamInfo {
            name: "mode",
            kind: ParamKind::Choice { choices: &["sampled", "hard"], default: "sampled" },
            doc: "`sampled` (physical ranges) or `hard` (singular poses, extreme scales, hill climbing)",
        },
        ParamInfo {
            name: "params",
            kind: ParamKind::Path,
            doc: "JSON file of known input values ({\"m[2]\": 1.5}); the rest is drawn",
        },
        ParamInfo {
            name: "worst",
            kind: ParamKind::OutputFolder,
            doc: "folder for worst-K.json, the worst points in -eval's input format",
        },
        ParamInfo {
            name: "worst-count",
            kind: ParamKind::U32 { default: 5, min: 0, max: 1000 },
            doc: "worst points listed (and written)",
        },
        ParamInfo {
            name: "climb",
            kind: ParamKind::U32 { default: 4, min: 0, max: 100 },
            doc: "hill-climbing rounds in hard mode",
        },
        ParamInfo {
            name: "climb-points",
            kind: ParamKind::U32 { default: 8, min: 1, max: 1000 },
            doc: "worst points hill climbing starts from",
        },
        ParamInfo {
            name: "max-work",
            kind: ParamKind::U64 { default: DEFAULT_MAX_WORK, min: 1, max: u64::MAX },
            doc: "work budget in op evaluations (samples x ops, plus hill climbing); stops early and says so",
        },
    ],
    build: |p: &Params| Ok(Box::new(Accuracy { opts: options_from(p)? })),
    props: crate::Props {
        at_time_limit: crate::AtTimeLimit::Skip,
        preserves_timing: true,
        needs_original: true,
        bit_exact: true,
        ..crate::Props::DEFAULT
    },
};

fn options_from(p: &Params) -> Result<Options, PassError> {
    Ok(Options {
        samples: p.u32("samples")?,
        seed: p.u64("seed")?,
        mode: if p.choice("mode")? == "hard" { Mode::Hard } else { Mode::Sampled },
        params: p.path("params")?,
        known: BTreeMap::new(),
        worst_dir: p.path("worst")?,
        worst_count: p.u32("worst-count")?,
        climb_rounds: p.u32("climb")?,
        climb_points: p.u32("climb-points")?,
        max_work: p.u64("max-work")?,
        deadline: None,
        progress: crate::progress::Task::default(),
    })
}

/// The `accuracy` pass.
#[derive(Debug)]
pub struct Accuracy {
    /// Options (the `params` file is read when the pass runs).
    pub opts: Options,
}

impl Pass for Accuracy {
    fn name(&self) -> &'static str {
        "accuracy"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let mut o = self.opts.clone();
        // `-time-limit`: accuracy checks it once per chunk of samples.
        o.deadline = cx.deadline.map(|d| d.end());
        if let Some(path) = &o.params {
            o.known =
                inputs::read_params(path).map_err(|message| PassError::Failed { pass: "accuracy".into(), message })?;
            for name in o.known.keys() {
                let has = |m: &Module| m.functions.iter().any(|f| f.inputs.iter().any(|&v| f.name_of(v) == name));
                let used = has(m) || cx.original.as_ref().is_some_and(has);
                if !used {
                    return Err(PassError::Failed {
                        pass: "accuracy".into(),
                        message: format!("params file `{path}`: `{name}` is not an input of any function"),
                    });
                }
            }
        }
        let fail = |message: String| PassError::Failed { pass: "accuracy".into(), message };
        let mut reports = Vec::new();
        for f in &m.functions {
            let original = match &cx.original {
                None => None,
                Some(om) => Some(om.function(&f.name).ok_or_else(|| {
                    fail(format!(
                        "function @{} is not in the module as it entered the pipeline (the error reference)",
                        f.name
                    ))
                })?),
            };
            // An early stop (work budget or `-time-limit`) is in the report's
            // `accuracy.stopped_early` and printed with the accuracy summary.
            o.progress = cx.progress.task(&format!("accuracy @{}: samples", f.name), u64::from(o.samples));
            reports.push(measure_against(f, original, &o).map_err(fail)?);
            o.progress.finish();
        }
        cx.emit(report::AccuracyRun { reports });
        Ok(())
    }
}

/// What `against` says when the reference is the pipeline's input.
pub const AGAINST_INPUT: &str = "input of the pipeline: the function of the same name as parsed or read";
/// What `against` says when no original was available.
pub const AGAINST_SELF: &str = "the measured IR itself";

/// Measures `f` (any phase, verified) under `o` (with `o.known` already read) against its own
/// exact value.
pub fn measure_function(f: &Function, o: &Options) -> AccuracyReport {
    measure_against(f, None, o).expect("a function is its own reference")
}

/// Measures `f` under `o` against the exact value of `original` (the same function as it
/// entered the pipeline; `None`: `f` itself).
///
/// # Errors
/// A message when an output of `f` is not an output of `original`.
pub fn measure_against(f: &Function, original: Option<&Function>, o: &Options) -> Result<AccuracyReport, String> {
    let sub = Subject::new(f, original)?;
    let run = stream::run(&sub, o);
    let against = if original.is_some() { AGAINST_INPUT } else { AGAINST_SELF };
    Ok(report::build(&f.name, &sub, o, run, against))
}
