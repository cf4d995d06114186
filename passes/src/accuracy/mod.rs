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

pub mod check;
pub mod hard;
pub mod inputs;
pub mod measure;
pub mod report;
pub mod stats;
pub mod stream;

use std::collections::BTreeMap;

use robovec_ir::{Function, Module};

use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};
pub use measure::{BitsSummary, PointErrors, Subject};
pub use report::{AccuracyReport, OutputAccuracy, ReferenceCounts, ReferenceInfo, WorstPoint};

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
}

/// Default work budget, op evaluations (about 10 minutes on two cores).
pub const DEFAULT_MAX_WORK: u64 = 20_000_000_000;

impl Default for Options {
    fn default() -> Options {
        Options {
            samples: 1000,
            seed: 1,
            mode: Mode::Sampled,
            params: None,
            known: BTreeMap::new(),
            worst_dir: None,
            worst_count: 5,
            climb_rounds: 4,
            climb_points: 8,
            max_work: DEFAULT_MAX_WORK,
            deadline: None,
        }
    }
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "accuracy",
    doc: "bits of error (Herbie) of every output in f32 and f64 against a certified extended-precision reference",
    params: &[
        ParamInfo { name: "samples", default: "1000", doc: "input points measured, 1..=10000000" },
        ParamInfo { name: "seed", default: "1", doc: "seed of the deterministic draws (u64)" },
        ParamInfo {
            name: "mode",
            default: "sampled",
            doc: "`sampled` (physical ranges) or `hard` (singular poses, extreme scales, hill climbing)",
        },
        ParamInfo {
            name: "params",
            default: "none",
            doc: "JSON file of known input values ({\"m[2]\": 1.5}); the rest is drawn",
        },
        ParamInfo {
            name: "worst",
            default: "none",
            doc: "folder for worst-K.json, the worst points in -eval's input format",
        },
        ParamInfo { name: "worst-count", default: "5", doc: "worst points listed (and written), 0..=1000" },
        ParamInfo { name: "climb", default: "4", doc: "hill-climbing rounds in hard mode, 0..=100" },
        ParamInfo { name: "climb-points", default: "8", doc: "worst points hill climbing starts from, 1..=1000" },
        ParamInfo {
            name: "max-work",
            default: "20000000000",
            doc: "work budget in op evaluations (samples x ops, plus hill climbing); stops early and says so",
        },
    ],
    build: |p: &Params| Ok(Box::new(Accuracy { opts: options_from(p)? })),
};

fn options_from(p: &Params) -> Result<Options, PassError> {
    let bad = |m: String| PassError::BadParameter { pass: "accuracy".into(), message: m };
    let d = Options::default();
    let seed = match p.get("seed") {
        None => d.seed,
        Some(s) => s
            .parse::<u64>()
            .map_err(|_| bad(format!("parameter `seed` must be an integer in 0..=2^64-1, found `{s}`")))?,
    };
    let mode = match p.get("mode") {
        None | Some("sampled") => Mode::Sampled,
        Some("hard") => Mode::Hard,
        Some(m) => return Err(bad(format!("parameter `mode` must be `sampled` or `hard`, found `{m}`"))),
    };
    let path = |k: &str| p.get(k).filter(|s| !s.is_empty()).map(str::to_string);
    Ok(Options {
        samples: p.u32_in("samples", d.samples, 1, 10_000_000)?,
        seed,
        mode,
        params: path("params"),
        known: BTreeMap::new(),
        worst_dir: path("worst"),
        worst_count: p.u32_in("worst-count", d.worst_count, 0, 1000)?,
        climb_rounds: p.u32_in("climb", d.climb_rounds, 0, 100)?,
        climb_points: p.u32_in("climb-points", d.climb_points, 1, 1000)?,
        max_work: match p.get("max-work") {
            None => d.max_work,
            Some(s) => s.parse::<u64>().ok().filter(|&w| w >= 1).ok_or_else(|| {
                bad(format!("parameter `max-work` must be an integer in 1..=2^64-1 (op evaluations), found `{s}`"))
            })?,
        },
        deadline: None,
    })
}

/// The `accuracy` pass.
pub struct Accuracy {
    /// Options (the `params` file is read when the pass runs).
    pub opts: Options,
}

impl Pass for Accuracy {
    fn name(&self) -> &'static str {
        "accuracy"
    }

    fn preserves_timing(&self) -> bool {
        true
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let mut o = self.opts.clone();
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
            cx.accuracy.push(measure_against(f, original, &o).map_err(fail)?);
        }
        Ok(())
    }

    fn needs_original(&self) -> bool {
        true
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
