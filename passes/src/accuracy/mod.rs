//! `accuracy<samples=1000;seed=1;mode=sampled|hard;params=FILE.json;ranges=FILE.json;worst=DIR;…>`:
//! measures how far each output is from its exact value when the function is computed in
//! binary32 (the FPGA) and in binary64, in the IR's own operation order (SPEC §6).
//!
//! Phase: any → unchanged (an analysis; timing and placement are kept). For each function:
//! 1. draw `samples` input points (ranges and hard points in [`inputs`]; `params` fixes known
//!    inputs), deterministically from `seed` (point `i` depends only on `seed` and `i`). When
//!    the run has an input domain ([`PassContext::domain`]: `-ranges=FILE`, or a URDF's
//!    defaults when a pass needs them) or the pass has `ranges=FILE` (the same JSON, applied
//!    over the run's domain: [`crate::range::domain_with_file`]), every input the domain
//!    covers is drawn inside its range, exactly — sampled, hard and hill-climbed points alike
//!    ([`inputs`], "In a domain"); the others from the physical table. Without a domain the
//!    draws are those of the physical table, unchanged. The report says which
//!    (`drawn_in`: `domain`, `physical table` or `domain and physical table`);
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
//!    and list the `worst-count` worst points (largest binary32 error) with every input; per
//!    output also the largest **absolute** error in binary32 and binary64 (`max_abs_f32`,
//!    `max_abs_f64`, in the output's units): the maximum over the points of an upper bound of
//!    |computed − exact|, from the reference's certified enclosure of the exact value
//!    (`robovec_ir::numerics::Enclosure`), `+∞` for a non-finite computed value. What an error
//!    bound over the domain must not be below: [`max_abs_errors`] gives them to tests.
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

use robovec_ir::domain::Domain;
use robovec_ir::{Function, Module};

use crate::params::ParamKind;
use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};
pub use acc::ReferenceCounts;
pub use measure::{BitsSummary, PointErrors, Subject};
pub use report::{AccuracyReport, OutputAccuracy, OutputErrors, ReferenceInfo, WorstPoint};

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
    /// Path of a ranges file (`-ranges`' JSON) applied over the run's domain when the pass
    /// runs, giving [`Options::domain`].
    pub ranges: Option<String>,
    /// The input domain: every input it covers is drawn inside its range
    /// ([`inputs`], "In a domain"); `None`: the physical table for every input. The pass sets
    /// it from [`PassContext::domain`] and `ranges`.
    pub domain: Option<Domain>,
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
    doc: "bits of error (Herbie) and largest absolute error of every output in f32 and f64 against a certified \
          extended-precision reference, over inputs drawn in the run's domain (-ranges) or physical ranges",
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
            doc:
                "`sampled` (uniform over the domain, or physical ranges) or `hard` (singular poses, the domain's ends \
                  or extreme scales, hill climbing)",
        },
        ParamInfo {
            name: "params",
            kind: ParamKind::Path,
            doc: "JSON file of known input values ({\"m[2]\": 1.5}); the rest is drawn",
        },
        ParamInfo {
            name: "ranges",
            kind: ParamKind::Path,
            doc: "JSON file of input ranges ({\"q[*]\": [-1, 1], \"m[2]\": [1.5, 1.5]}) over the run's domain \
                  (-ranges): the inputs it covers are drawn inside their ranges",
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
        ranges: p.path("ranges")?,
        domain: None,
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
        // The domain: the run's, with `ranges=FILE` over it (its errors are this pass's).
        if cx.domain.is_some() || o.ranges.is_some() {
            let d =
                crate::range::domain_with_file(cx.domain.as_ref(), o.ranges.as_deref(), m).map_err(|e| match e {
                    PassError::Failed { message, .. } => PassError::Failed { pass: "accuracy".into(), message },
                    e => e,
                })?;
            o.domain = Some(d);
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

/// The largest absolute error of every output of `f` over `samples` points drawn in `domain`
/// (sampled, or `hard`: hard points and hill climbing, [`hard`]), with `seed` — what an error
/// bound claimed over `domain` must not be below (issue 48: `error-bound`'s soundness test).
///
/// The points are those of `accuracy<samples=N;seed=S;mode=…>` run with the domain `domain`:
/// every input inside its range exactly (module doc of [`inputs`], "In a domain"), so a bound
/// over the domain covers them. Returns one `(output, max_abs_f32, max_abs_f64)` per output of
/// `f`, in output order, in the output's units: the largest over the points of an upper bound
/// of |computed − exact| in binary32 and binary64 (the report's `max_abs_f32`/`max_abs_f64`;
/// `+∞` where a computed value was not finite or the reference unbounded). The exact value is
/// that of `original` (the function as it entered the pipeline; `None`: `f` itself). The work
/// budget is the pass's default ([`DEFAULT_MAX_WORK`]): a function of `ops` steps measures at
/// most `max(32, 2·10¹⁰ / ops)` samples.
///
/// # Errors
/// `samples` is 0 or above `u32::MAX`; an input of `f` or `original` has no range in
/// `domain` (all of them named); an output of `f` is not an output of `original`.
pub fn max_abs_errors(
    f: &Function,
    original: Option<&Function>,
    domain: &Domain,
    samples: u64,
    seed: u64,
    hard: bool,
) -> Result<Vec<(String, f64, f64)>, String> {
    let samples = u32::try_from(samples)
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| format!("max_abs_errors: {samples} samples: expected 1 to {}", u32::MAX))?;
    let sub = Subject::new(f, original)?;
    let missing: Vec<&str> = sub.names.iter().map(String::as_str).filter(|n| domain.get(n).is_none()).collect();
    if !missing.is_empty() {
        return Err(format!("@{}: no range in the domain for input(s) {}", f.name, missing.join(", ")));
    }
    let o = Options {
        samples,
        seed,
        mode: if hard { Mode::Hard } else { Mode::Sampled },
        domain: Some(domain.clone()),
        ..Options::default()
    };
    let run = stream::run(&sub, &o);
    Ok(sub
        .tape
        .outputs
        .iter()
        .enumerate()
        .map(|(k, (name, _))| (name.clone(), run.acc.max_abs_f32[k], run.acc.max_abs_f64[k]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::domain::Range as DomainRange;
    use robovec_ir::Interval;

    fn domain(ranges: &[(&str, f64, f64)]) -> Domain {
        let mut d = Domain::default();
        for &(n, lo, hi) in ranges {
            d.ranges.insert(n.into(), DomainRange { interval: Interval::new(lo, hi), source: "test".into() });
        }
        d
    }

    fn parse(src: &str) -> Function {
        let m = robovec_ir::text::parse(src).unwrap();
        robovec_ir::verifier::verify(&m).unwrap();
        m.functions.into_iter().next().unwrap()
    }

    /// `x` as an exact integer multiple of 2⁻⁸⁰ (panics when it is not one).
    fn units(x: f64) -> i128 {
        let bits = x.to_bits();
        let (sign, exp, frac) = (bits >> 63, ((bits >> 52) & 0x7ff) as i32, (bits & ((1 << 52) - 1)) as i128);
        let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | 1 << 52, exp - 1075) };
        assert!(e + 80 >= 0 && e + 80 < 70, "{x:e} is not a multiple of 2^-80 within i128");
        let v = m << (e + 80);
        if sign == 1 {
            -v
        } else {
            v
        }
    }

    #[test]
    fn the_absolute_error_of_one_rounding_is_computed_exactly() {
        // y = x·0.1 + 0.3 over x ∈ [1, 1]: x = 1 exactly, the product is exact in both formats,
        // so the error is the one rounding of the sum (and, in binary32, the constants' own).
        // Exact value: 0.1 + 0.3 with the binary64 constants (0x1.999999999999ap-4 and
        // 0x1.3333333333333p-2): 0x1.99999999999998p-2, a tie between two binary64 numbers;
        // binary64 rounds it to the even 0x1.999999999999ap-2, 2⁻⁵⁵ above. binary32 reads the
        // constants as 0x1.99999ap-4 and 0x1.333334p-2, sums them exactly to 0x1.99999a8p-2 and
        // rounds down to 0x1.99999ap-2: 0x0.00000066666668p-2 = 429496730·2⁻⁵⁶ above.
        let f = parse(
            "func @f {\n  phase atomised\n  input %x\n  %a = mul %x, 0.1\n  %y = add %a, 0.3\n  output y = %y\n}\n",
        );
        let dom = domain(&[("x", 1.0, 1.0)]);
        // Independently, in integers (units of 2⁻⁸⁰): |fl(0.1 + 0.3) − (0.1 + 0.3)|.
        let exact = units(0.1) + units(0.3);
        let e64 = (units(0.1f64 + 0.3f64) - exact).abs() as f64 / 2f64.powi(80);
        let e32 = (units((0.1f32 + 0.3f32) as f64) - exact).abs() as f64 / 2f64.powi(80);
        assert_eq!(e64, 2f64.powi(-55));
        assert_eq!(e32, 429496730.0 * 2f64.powi(-56));
        for hard in [false, true] {
            let got = max_abs_errors(&f, None, &dom, 50, 1, hard).unwrap();
            assert_eq!(got, vec![("y".to_string(), e32, e64)], "hard = {hard}");
        }
        // The report has the same figures, and says where the inputs were drawn.
        let o = Options { samples: 10, domain: Some(dom.clone()), ..Options::default() };
        let r = measure_function(&f, &o);
        assert_eq!(r.drawn_in, report::DRAWN_IN_DOMAIN);
        let (name, y) = &r.outputs.0[0];
        assert_eq!((name.as_str(), y.max_abs_f32, y.max_abs_f64), ("y", e32, e64));
        assert!(r.worst.iter().all(|w| w.inputs["x"] == 1.0));
        assert_eq!(measure_function(&f, &Options { samples: 10, ..Options::default() }).drawn_in, "physical table");
        // Errors: an input without a range, no samples.
        let e = max_abs_errors(&f, None, &Domain::default(), 10, 1, false).unwrap_err();
        assert!(e.contains("no range in the domain for input(s) x"), "{e}");
        assert!(max_abs_errors(&f, None, &dom, 0, 1, false).is_err());
    }

    #[test]
    fn every_point_stays_in_the_domain_through_hill_climbing() {
        // Angles, rates and parameters with ends that are not binary32 numbers; hard mode
        // keeps every point (worst-count above the samples), so the report's worst points are
        // every sample after the climbs replaced their starts.
        let f = parse(
            "func @f {\n  phase parsed\n  input %q[1]\n  input %q[2]\n  input %qd[1]\n  input %m[1]\n  input %l[1][2]\n  \
             %s = sin %q[1]\n  %c = cos %q[2]\n  %y = %m[1]*(%s*%c*%qd[1] - %l[1][2]*%c*%c) + 0.7*%s\n  %z = %s*%s + %c*%c - 1.0\n  \
             output y = %y\n  output z = %z\n}\n",
        );
        let ranges =
            [("q[1]", -0.3, 1.7), ("q[2]", 1.5, 1.6), ("qd[1]", -0.1, 0.3), ("m[1]", 0.7, 0.7), ("l[1][2]", 0.1, 0.9)];
        let dom = domain(&ranges);
        let o = Options {
            samples: 200,
            mode: Mode::Hard,
            domain: Some(dom.clone()),
            worst_count: 1000,
            climb_points: 200,
            climb_rounds: 6,
            ..Options::default()
        };
        let r = measure_function(&f, &o);
        assert_eq!(r.evaluations, 200 + 200 * 6 * 8, "every climb ran");
        assert_eq!(r.worst.len(), 200);
        for w in &r.worst {
            for &(n, lo, hi) in &ranges {
                let x = w.inputs[n];
                assert!(lo <= x && x <= hi, "{n} = {x:e} outside [{lo}, {hi}]");
            }
        }
        // The climbs moved points: without them the points differ.
        let flat = measure_function(&f, &Options { climb_rounds: 0, ..o.clone() });
        let points = |r: &AccuracyReport| r.worst.iter().map(|w| w.inputs.clone()).collect::<Vec<_>>();
        assert_ne!(points(&flat), points(&r));
        // The absolute errors bound the errors at every point, recomputed here from the
        // interpreter and a 1024-bit reference.
        let t = robovec_ir::numerics::Tape::new(&f);
        let all: Vec<usize> = (0..t.outputs.len()).collect();
        for w in &r.worst {
            let x: Vec<f64> = t.inputs.iter().map(|n| w.inputs[n]).collect();
            let exact = robovec_ir::numerics::reference::eval_big(&t, &x, 1024, &all);
            let c32 = robovec_ir::interp::eval::<f32>(&f, |n| w.inputs[n]);
            let c64 = robovec_ir::interp::eval::<f64>(&f, |n| w.inputs[n]);
            for (k, (name, out)) in r.outputs.0.iter().enumerate() {
                // exact.f64 is the exact value rounded: within half an ulp of it.
                let slack = exact[k].f64.abs() * f64::EPSILON;
                let (d32, d64) = ((c32[k].1 as f64 - exact[k].f64).abs(), (c64[k].1 - exact[k].f64).abs());
                assert!(d32 <= out.max_abs_f32 + slack, "{name}: f32 error {d32:e} above {:e}", out.max_abs_f32);
                assert!(d64 <= out.max_abs_f64 + slack, "{name}: f64 error {d64:e} above {:e}", out.max_abs_f64);
            }
        }
        // Not vacuous: binary32 errs by more than binary64, and neither is 0 on y.
        let y = &r.outputs.0[0].1;
        assert!(y.max_abs_f32 > y.max_abs_f64 && y.max_abs_f64 > 0.0, "{y:?}");
        assert!(y.max_abs_f32 < 1e-5, "{y:?}");
    }
}
