//! `-pareto="PIPELINE_A;PIPELINE_B;…"`: speed against error. Runs each pipeline on the same
//! input, measures the final IR's speed (ops, critical path, placed cycles when the pipeline
//! places) and its accuracy (the `accuracy` measurement with the same samples and seed for
//! every pipeline, **against the exact value of the loaded module**, not of the pipeline's own
//! result), checks it against the error budget (`accuracy::check`, same points), and marks the
//! Pareto-optimal rows.
//!
//! **Dominance** (two objectives, both minimised): *time* = placed cycles when the pipeline
//! placed, else the critical path `asap_cycle` (SPEC §4), and *error* = mean binary32 bits of
//! error (Herbie's score, over every output and sample) with its 95% confidence interval
//! `mean ± h`, `h = 1.96·s/√n` over the per-sample means. Row B is *better* on error than A
//! when the intervals do not overlap (`B.mean + B.h < A.mean − A.h`), *worse* when
//! `B.mean − B.h > A.mean + A.h`, and *tied* otherwise (the difference is within the sampling
//! noise). B dominates A when B's time is ≤ A's, B is not worse on error, and B is strictly
//! faster or better on error (Herbie's `pareto.rkt` frontier, with noise-aware ties). A row
//! whose result breaks the error budget of the original (`sound: false`: a rewrite that
//! changed the mathematics) is never Pareto-optimal and dominates nothing.
//!
//! Pipelines are separated by `;` outside `<…>` (parameters also use `;`); any registered pass
//! works. A pipeline that does not parse or names an unknown pass is bad usage (exit 2); a
//! pipeline that fails on the input is bad input (exit 1).

use robovec_ir::{Function, Module};
use serde::{Deserialize, Serialize};

use super::Failure;
use crate::accuracy::check::check_function_until;
use crate::accuracy::{measure_against, BitsSummary, Options as AccuracyOptions};
use crate::summary::stats;
use crate::{Instrumentation, PassContext, PassManager, Session};

/// One pipeline's figures: a row of the report's `pareto` (written, and read back for
/// `-report-dir`'s figures) and of the `-pareto` table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParetoRow {
    /// The pipeline as given (normalised).
    pub pipeline: String,
    /// Ops of the final IR (SPEC §1).
    pub ops: u64,
    /// Critical path in unit steps.
    pub asap: u32,
    /// Critical path in cycles (`asap_cycle`, with the pipeline's latencies).
    pub asap_cycle: u32,
    /// N (ADD PEs = MULTI PEs) of the placement, when the pipeline placed.
    pub n: Option<u32>,
    /// Cycles of the placement (SPEC §4), when the pipeline placed.
    pub placed_cycles: Option<u32>,
    /// The time objective: `placed_cycles`, else `asap_cycle`, cycles.
    pub time_cycles: u32,
    /// Samples of the accuracy measurement.
    pub samples: u64,
    /// binary32 bits of error (mean / 95th percentile / max), against the loaded module.
    pub f32: BitsSummary,
    /// Half-width of the 95% confidence interval of `f32.mean_bits`, bits.
    pub f32_mean_ci95_bits: f64,
    /// binary64 bits of error.
    pub f64: BitsSummary,
    /// True when every output stays within the error budget of the loaded module at the
    /// measured points (`-check`'s property); false for a rewrite that changed the values
    /// beyond its rounding.
    pub sound: bool,
    /// The first output outside its budget, when not sound.
    pub violation: Option<String>,
    /// User callbacks evaluated with the interpreter's stand-in.
    pub callback_standins: Vec<String>,
    /// Passes of this pipeline, and its accuracy measurement, that stopped early under
    /// `-time-limit` or a work budget, one line each (absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stopped_early: Vec<String>,
    /// True when no other row dominates this one (never for a row that is not sound).
    pub pareto_optimal: bool,
    /// With an input domain (`-ranges`, a URDF's limits): the certified bound of the row's
    /// function in binary32 and binary64 (`error-bound`'s, [`crate::error_bound`]), the largest
    /// over the outputs relative to each output's largest magnitude over the domain; `None`
    /// without a domain, or when the pipeline changed the exact function or its values cannot
    /// be bounded (absent from the report then).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub certified: Option<Certified>,
}

/// A row's certified bounds (see [`ParetoRow::certified`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Certified {
    /// Largest binary32 bound over the outputs, relative to each output's range (`null`: some
    /// output has no finite bound).
    pub f32_max_rel: Option<f64>,
    /// Largest binary64 bound, likewise.
    pub f64_max_rel: Option<f64>,
}

/// The certified bounds of `f` over `domain` (see [`ParetoRow::certified`]): `None` when its
/// values cannot all be enclosed.
pub fn certify(f: &Function, domain: &robovec_ir::domain::Domain) -> Option<Certified> {
    use crate::error_bound::bound::{bound, Formats};
    let x = crate::range::enclose_with(f, domain, Some(crate::range::affine::DEFAULT_TERMS), || false).ok()?;
    let worst = |formats: Formats| -> Option<f64> {
        let e = bound(f, &x, formats, || false).ok()?;
        let mut worst = 0.0f64;
        for o in &f.outputs {
            let robovec_ir::Operand::Value(v) = o.value else { continue };
            let m = x[v.index()].mag();
            if m > 0.0 {
                let r = e[v.index()] / m;
                if !r.is_finite() {
                    return None;
                }
                worst = worst.max(r);
            }
        }
        Some(worst)
    };
    Some(Certified { f32_max_rel: worst(Formats::F32), f64_max_rel: worst(Formats::F64) })
}

/// Splits `-pareto`'s text into pipelines at `;` outside `<…>`.
///
/// # Errors
/// A message for an empty list or an empty pipeline.
pub fn split_pipelines(text: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, c) in text.char_indices() {
        match c {
            '<' => depth += 1,
            '>' => depth -= 1,
            ';' if depth == 0 => {
                out.push(text[start..i].trim().to_string());
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(text[start..].trim().to_string());
    if out.iter().any(String::is_empty) {
        return Err(format!("error: -pareto: empty pipeline in `{text}` (pipelines are separated by `;`)\n"));
    }
    Ok(out)
}

/// -1 when error `b` is better (lower) than `a` beyond the noise, 1 when worse, 0 when tied:
/// `(mean, ci95 half-width)` intervals that overlap are tied (see the module doc).
pub fn compare_error(b: (f64, f64), a: (f64, f64)) -> i32 {
    if b.0 + b.1 < a.0 - a.1 {
        -1
    } else if b.0 - b.1 > a.0 + a.1 {
        1
    } else {
        0
    }
}

/// Marks the rows no other row dominates (see the module doc).
pub fn mark_front(rows: &mut [ParetoRow]) {
    let key: Vec<(u32, (f64, f64), bool)> =
        rows.iter().map(|r| (r.time_cycles, (r.f32.mean_bits, r.f32_mean_ci95_bits), r.sound)).collect();
    for (i, r) in rows.iter_mut().enumerate() {
        let (t, e, _) = key[i];
        let dominated = key.iter().any(|&(t2, e2, sound2)| {
            let c = compare_error(e2, e);
            sound2 && t2 <= t && c <= 0 && (t2 < t || c < 0)
        });
        r.pareto_optimal = r.sound && !dominated;
    }
}

/// Splits `-pareto`'s text and builds each pipeline's pass manager (every name and parameter
/// checked); the driver's preflight calls it before any work, [`measure`] again to run them.
///
/// # Errors
/// [`Failure::Usage`] for an empty list, an empty pipeline, an unknown pass or a bad parameter.
pub fn managers(registry: crate::Registry, text: &str) -> Result<Vec<(String, PassManager)>, Failure> {
    split_pipelines(text)
        .map_err(Failure::Usage)?
        .into_iter()
        // They run on the driver's loaded module, which `load` verified.
        .map(|p| {
            match PassManager::with_registry(
                registry,
                &p,
                Instrumentation { input_verified: true, ..Instrumentation::default() },
            ) {
                Ok(pm) => Ok((p, pm)),
                Err(e) => Err(Failure::Usage(format!("error: -pareto pipeline `{p}`: {e}\n"))),
            }
        })
        .collect()
}

/// The rows of one `-pareto` study of one function: the table on stderr and the report's
/// `pareto`.
#[derive(Clone, Debug)]
pub struct ParetoRun {
    /// The function measured.
    pub function: String,
    /// One row per pipeline, in the order given.
    pub rows: Vec<ParetoRow>,
}

impl crate::Artifact for ParetoRun {
    fn pass(&self) -> &'static str {
        "-pareto"
    }

    fn log_text(&self, _detail: bool) -> String {
        to_table(&self.function, &self.rows)
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        (function == self.function).then(|| crate::ReportEntry::new("pareto", &self.rows, crate::Merge::Last))
    }
}

/// Runs every pipeline of `text` (built from `registry`) on a copy of `module` and measures
/// function `function`.
/// `module` must be verified (the driver's `load` does it): the pipelines do not check it again.
/// `progress` shows the pipelines done (one task, `-pareto: pipelines`).
///
/// # Errors
/// [`Failure::Usage`] for a bad pipeline, [`Failure::Input`] when a pipeline fails.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    registry: crate::Registry,
    module: &Module,
    function: &str,
    text: &str,
    samples: u32,
    seed: u64,
    deadline: Option<crate::Deadline>,
    target: &robovec_machine::target::Target,
    progress: &crate::progress::Progress,
    domain: Option<&robovec_ir::domain::Domain>,
) -> Result<ParetoRun, Failure> {
    // A bad text fails in `run_reporting` with its own message; the total is then moot.
    let pipelines = split_pipelines(text).map_or(0, |v| v.len());
    let task = progress.task("-pareto: pipelines", pipelines as u64);
    let rows = run_reporting(registry, module, function, text, samples, seed, deadline, target, &task, domain)?;
    task.finish();
    Ok(ParetoRun { function: function.to_string(), rows })
}

/// The rows of [`measure`]. Under `-time-limit` (`deadline`), each pipeline and measurement stops
/// early as in a normal run (a valid result, fewer samples) and its row says so in
/// `stopped_early`; each pipeline gets an equal share of the time left when it starts (half
/// of it to measure, half for the check of the same points), so every pipeline is measured
/// before the limit.
///
/// `task` is set to the pipelines done after each one.
///
/// # Errors
/// As [`measure`].
#[allow(clippy::too_many_arguments)]
fn run_reporting(
    registry: crate::Registry,
    module: &Module,
    function: &str,
    text: &str,
    samples: u32,
    seed: u64,
    deadline: Option<crate::Deadline>,
    target: &robovec_machine::target::Target,
    task: &crate::progress::Task,
    domain: Option<&robovec_ir::domain::Domain>,
) -> Result<Vec<ParetoRow>, Failure> {
    let original =
        module.function(function).ok_or_else(|| Failure::Usage(format!("error: no function `{function}`\n")))?;
    let (pipelines, managers): (Vec<String>, Vec<PassManager>) = managers(registry, text)?.into_iter().unzip();
    let mut rows = Vec::new();
    let n = pipelines.len();
    for (k, (p, pm)) in pipelines.iter().zip(managers).enumerate() {
        // Each pipeline gets an equal share of the time left, half of it to measure (the
        // soundness check of the same points takes about as long), so that every pipeline is
        // measured (with fewer samples) before the limit.
        let now = std::time::Instant::now();
        let share = deadline.map(|d| now + d.time_left() / (2 * (n - k)) as u32);
        let later_share = deadline.map(|d| now + d.time_left() / (n - k) as u32);
        let opts =
            AccuracyOptions { samples, seed, deadline: share, domain: domain.cloned(), ..AccuracyOptions::default() };
        let bit_exact = pm.is_bit_exact();
        let cx = PassContext { original: Some(module.clone()), deadline, ..PassContext::with_target(target.clone()) };
        let mut session = Session::new(pm, module.clone(), cx);
        session.run_quiet().map_err(|e| Failure::Input(format!("error: -pareto pipeline `{p}`: {e}\n")))?;
        let (cx, pm) = (&session.cx, session.pipeline());
        let f: &Function = session
            .module
            .function(function)
            .ok_or_else(|| Failure::Input(format!("error: -pareto pipeline `{p}` removed function @{function}\n")))?;
        let s = stats(f, &cx.latencies);
        let placed = f.placement.as_ref().map(|pl| (pl.arch.n_add, crate::place::cycles(f, pl)));
        let fail = |e: String| Failure::Input(format!("error: -pareto pipeline `{p}`: {e}\n"));
        let acc = measure_against(f, Some(original), &opts).map_err(fail)?;
        // The same points as the measurement (fewer when it stopped early under `-time-limit`).
        let measured = u32::try_from(acc.samples).unwrap_or(samples).min(samples);
        let check = check_function_until(f, original, bit_exact, measured, seed, later_share).map_err(fail)?;
        rows.push(ParetoRow {
            pipeline: pm.pipeline_text(),
            ops: s.ops.total,
            asap: s.asap,
            asap_cycle: s.asap_cycle,
            n: placed.map(|x| x.0),
            placed_cycles: placed.map(|x| x.1),
            time_cycles: placed.map_or(s.asap_cycle, |x| x.1),
            samples: acc.samples,
            f32: acc.f32,
            f32_mean_ci95_bits: acc.f32_mean_ci95_bits,
            f64: acc.f64,
            sound: check.violation.is_none(),
            violation: check.violation.map(|v| v.to_string()),
            callback_standins: acc.callback_standins,
            stopped_early: cx
                .stopped()
                .into_iter()
                .chain(acc.stopped_early.map(|w| format!("accuracy stopped early: {w}")))
                .chain((check.samples < u64::from(measured)).then(|| {
                    format!("soundness check stopped early: {} of {measured} points: time limit", check.samples)
                }))
                .collect(),
            pareto_optimal: false,
            certified: domain.filter(|_| cx.reals_changed_by.is_none()).and_then(|d| certify(f, d)),
        });
        task.set(rows.len() as u64);
    }
    mark_front(&mut rows);
    Ok(rows)
}

/// The table printed on stderr (`*` marks Pareto-optimal rows).
pub fn to_table(function: &str, rows: &[ParetoRow]) -> String {
    let b = |s: &BitsSummary| format!("{:.2}/{:.2}/{:.2}", s.mean_bits, s.p95_bits, s.max_bits);
    let w = rows.iter().map(|r| r.pipeline.len()).max().unwrap_or(8).max(8);
    let mut s = format!(
        "@{function}: speed against error ({} samples, errors against the input of the pipelines; * = \
         Pareto-optimal in time (placed cycles, else critical path) and mean f32 bits, ties within the 95% \
         confidence interval; ! = outside the error budget of the input, never optimal)\n",
        rows.first().map_or(0, |r| r.samples)
    );
    s += &format!(
        "  {:<w$} {:>8} {:>11} {:>4} {:>8} {:>20} {:>8} {:>20}\n",
        "pipeline", "ops", "crit.path", "N", "placed", "f32 mean/p95/max", "±95%", "f64 mean/p95/max"
    );
    for r in rows {
        let opt = |x: Option<u32>| x.map_or(String::new(), |v| v.to_string());
        s += &format!(
            "{} {:<w$} {:>8} {:>11} {:>4} {:>8} {:>20} {:>8} {:>20}\n",
            if r.pareto_optimal {
                "*"
            } else if r.sound {
                " "
            } else {
                "!"
            },
            r.pipeline,
            r.ops,
            r.asap_cycle,
            opt(r.n),
            opt(r.placed_cycles),
            b(&r.f32),
            format!("{:.3}", r.f32_mean_ci95_bits),
            b(&r.f64)
        );
    }
    if rows.iter().any(|r| r.certified.is_some()) {
        s += "  certified over the domain (error-bound, largest bound / output range; - = not certifiable):\n";
        let c = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2e}"));
        for r in rows {
            let (a, b) = r.certified.map_or((None, None), |x| (x.f32_max_rel, x.f64_max_rel));
            s += &format!("  {:<w$} f32 {:>9}  f64 {:>9}\n", r.pipeline, c(a), c(b));
        }
    }
    for r in rows {
        if let Some(v) = &r.violation {
            s += &format!("! {}: {v}\n", r.pipeline);
        }
        for w in &r.stopped_early {
            s += &format!("note: -pareto pipeline {}: {w}\n", r.pipeline);
        }
        for c in &r.callback_standins {
            s += &format!(
                "warning: @{function} calls user callback `{c}`; evaluated with the stand-in (pipeline {})\n",
                r.pipeline
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(time: u32, err: f64) -> ParetoRow {
        row_ci(time, err, 0.0, true)
    }

    fn row_ci(time: u32, err: f64, ci: f64, sound: bool) -> ParetoRow {
        let bits = BitsSummary { mean_bits: err, p95_bits: err, max_bits: err };
        ParetoRow {
            pipeline: format!("{time}/{err}"),
            ops: 0,
            asap: 0,
            asap_cycle: time,
            n: None,
            placed_cycles: None,
            time_cycles: time,
            samples: 1,
            f32: bits,
            f32_mean_ci95_bits: ci,
            f64: bits,
            sound,
            violation: None,
            callback_standins: Vec::new(),
            stopped_early: Vec::new(),
            pareto_optimal: false,
            certified: None,
        }
    }

    #[test]
    fn front_by_hand() {
        let mut rows = vec![row(100, 2.0), row(80, 3.0), row(80, 2.5), row(120, 1.0), row(130, 1.0), row(100, 2.0)];
        mark_front(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto_optimal).collect();
        // (80, 2.5) dominates (80, 3.0); (120, 1.0) dominates (130, 1.0); equal rows do not
        // dominate each other.
        assert_eq!(front, [true, false, true, true, false, true]);
    }

    #[test]
    fn front_ties_errors_within_the_noise_and_drops_unsound_rows() {
        // (100, 2.00 ± 0.05) and (100, 2.08 ± 0.05) overlap: tied, both optimal. (100, 2.30 ± 0.05)
        // is worse beyond the noise: dominated. (90, 2.2 ± 0.5) is faster and tied on error with
        // the first two: it dominates them. An unsound row (50, 40 bits) is never optimal and
        // dominates nothing, even though it is the fastest.
        let mut rows = vec![row_ci(100, 2.0, 0.05, true), row_ci(100, 2.08, 0.05, true), row_ci(100, 2.3, 0.05, true)];
        mark_front(&mut rows);
        assert_eq!(rows.iter().map(|r| r.pareto_optimal).collect::<Vec<_>>(), [true, true, false]);
        rows.push(row_ci(90, 2.2, 0.5, true));
        rows.push(row_ci(50, 40.0, 0.5, false));
        rows.push(row_ci(80, 9.0, 0.5, true));
        mark_front(&mut rows);
        assert_eq!(rows.iter().map(|r| r.pareto_optimal).collect::<Vec<_>>(), [false, false, false, true, false, true]);
        assert_eq!(compare_error((1.0, 0.1), (1.15, 0.1)), 0);
        assert_eq!(compare_error((1.0, 0.1), (1.25, 0.1)), -1);
        assert_eq!(compare_error((1.25, 0.1), (1.0, 0.1)), 1);
    }

    #[test]
    fn pipelines_split_outside_brackets() {
        assert_eq!(
            split_pipelines("atomise; atomise,place<pe=4;improve=0>;atomise,dce").unwrap(),
            ["atomise", "atomise,place<pe=4;improve=0>", "atomise,dce"]
        );
        assert!(split_pipelines("atomise;;dce").is_err());
        assert!(split_pipelines("").is_err());
    }
}
