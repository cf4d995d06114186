//! `error-bound<format=f64|f32|mixed;ranges=FILE>`: the worst-case rounding error of every
//! output over the input domain (issue 48 item 3), proved, not sampled.
//!
//! Phase: atomised → atomised; an analysis (the IR is unchanged, bit-exact). For each function
//! it encloses every value over the domain ([`crate::range::enclose_with`], intervals and affine
//! forms as `range<method=affine>`), then bounds every value's error in one sweep
//! ([`bound::bound`]: the table and the roundings of each format are in its module doc). The
//! bound is against **the exact real-number function of the pipeline's input** (the function
//! `accuracy` measures against): the passes before it must keep the exact real value of every
//! output ([`crate::Props::exact_in_reals`]: reassociation, distribution, common
//! subexpressions, fused multiply-adds, reordering, analyses). A pass that changes it (a
//! constant folded in binary64 by `specialize` or `eqsat`, or a user rule of `eqsat`) before
//! `error-bound` is an error naming it: the bound would then be against the rewritten function.
//! To bound a specialised function, give the parameters as point ranges instead
//! (`{"m[2]": [1.5, 1.5]}`) and leave them to the bound.
//!
//! `format`: `f64` every value binary64 (the C back end's `double`, `-eval`), `f32` every
//! value binary32 (inputs and constants rounded to it: the C back end's `float`, `accuracy`'s
//! binary32 evaluation — whose inputs are binary32 already, so it measures no input rounding:
//! the bound counts it), `mixed` each value in its IR format ([`robovec_ir::format`]; a
//! function without formats is binary64). A fixed-point value whose computed range may
//! overflow its format is an error naming it (the range proof of the format).
//!
//! Report, per function, `error_bound: {format, outputs: {NAME: {abs, rel}}, max_abs,
//! max_rel}`: `abs` the bound on |computed − exact| over the domain, `rel` = `abs` / the
//! smallest |value| of the output's enclosure when that enclosure excludes 0 (else `null`),
//! the maxima over the outputs; an output with no finite bound (a callback, a divisor the
//! error may carry through 0) has `abs: null` and is named in `unbounded`. With `witness=N`
//! each output also gets `witness`: the largest error of the rounding model's worst execution
//! at `N` points of the domain ([`witness`]), a lower bound of every bound sound under the
//! model (so `abs / witness` is the bound's pessimism; printed as its median). Cost: O(ops ·
//! terms) for the enclosures, O(ops) for the bound, O(N · outputs · ops) in double-double for
//! the witnesses.

pub mod bound;
pub mod witness;

use robovec_ir::{Function, Interval, Module, Operand};
use serde::Serialize;

use crate::params::ParamKind;
use crate::range::{domain_with_file, enclose_in_pass, Method};
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};
pub use bound::{bound, BoundError, Formats, Rounding, TrigImpl};

crate::params::word_enum! {
    /// Which format the function is computed in.
    pub enum FormatWord {
        /// Every value binary64.
        F64 = "f64",
        /// Every value binary32.
        F32 = "f32",
        /// Each value in its IR format.
        Mixed = "mixed",
    }
}

impl FormatWord {
    /// The sweep's mode.
    pub fn formats(self) -> Formats {
        match self {
            FormatWord::F64 => Formats::F64,
            FormatWord::F32 => Formats::F32,
            FormatWord::Mixed => Formats::Mixed,
        }
    }
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "error-bound",
    doc: "certified worst-case rounding error of every output over the input domain, against the exact function of \
          the pipeline's input",
    params: &[
        ParamInfo {
            name: "format",
            kind: ParamKind::Choice { choices: FormatWord::WORDS, default: "mixed" },
            doc: "f64: every value binary64; f32: every value binary32 (inputs and constants rounded); mixed: each \
                  value in its IR format (binary64 by default)",
        },
        crate::range::RANGES,
        crate::range::METHOD,
        crate::range::TERMS,
        TRIG,
        ParamInfo {
            name: "witness",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "points of the domain (the two corners, then draws) at which the rounding model's worst execution is \
                  run (witness.rs; 0: none): each output's `witness`, a lower bound of every bound sound under the \
                  model, so abs / witness is how pessimistic the bound is",
        },
    ],
    build: |p: &Params| {
        Ok(Box::new(ErrorBoundPass {
            format: p.word("format")?,
            ranges: p.path("ranges")?,
            method: p.word("method")?,
            terms: p.u32("terms")? as usize,
            witness: p.u32("witness")?,
            trig: p.word("trig")?,
        }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        exact_in_reals: true,
        formats: true,
        needs_domain: true,
        ..crate::Props::DEFAULT
    },
};

/// The `error-bound` pass.
#[derive(Debug)]
pub struct ErrorBoundPass {
    /// The formats the function is computed in.
    pub format: FormatWord,
    /// A ranges file applied over the run's domain.
    pub ranges: Option<String>,
    /// How the values are enclosed.
    pub method: Method,
    /// Most noise symbols of an affine form.
    pub terms: usize,
    /// Points the model's worst execution is run at ([`witness`]; 0: none).
    pub witness: u32,
    /// The `sin`/`cos` the code will call.
    pub trig: TrigImpl,
}

/// `trig=libm|inline` (also `precision`'s): the `sin`/`cos` the computed function calls.
pub const TRIG: ParamInfo = ParamInfo {
    name: "trig",
    kind: ParamKind::Choice { choices: TrigImpl::WORDS, default: "libm" },
    doc:
        "libm: the C library's sin/cos (and -eval's), allowed 4 ulps; inline: robovec's own, as codegen<c;trig=inline> \
          writes it, whose binary32 sin/cos within |x| <= 2048 is allowed 1 ulp (every such argument checked: \
          scripts/trig_ulps.sh); the certificate then holds for that code only",
};

impl Pass for ErrorBoundPass {
    fn name(&self) -> &'static str {
        "error-bound"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let failed = |message: String| PassError::Failed { pass: "error-bound".into(), message };
        if let Some(pass) = &cx.reals_changed_by {
            return Err(failed(format!(
                "`{pass}` ran before it and changes the exact real-number function (a constant folded in binary64, \
                 or a rule that is not an identity), so no bound against the pipeline's input can be proved; run \
                 error-bound before it, or give folded parameters as point ranges (-ranges) instead of specializing \
                 (docs/accuracy.md, \"Certified error bounds\")"
            )));
        }
        let dom = domain_with_file(cx.domain.as_ref(), self.ranges.as_deref(), m)?;
        let affine = (self.method == Method::Affine).then_some(self.terms);
        let (word, formats) = (self.format, self.format.formats());
        let functions = try_each_function(
            m,
            cx,
            "error-bound",
            AtTimeLimit::Skip,
            Before::Ticked,
            |f, k| Some(format!("before @{} ({k} functions bounded)", f.name)),
            |f, _, ticker| {
                let located = |message: String, span: Option<robovec_ir::Span>| {
                    PassError::Failed { pass: "error-bound".into(), message }
                        .at(span.unwrap_or(robovec_ir::Span::DUMMY))
                };
                let x = match enclose_in_pass("error-bound", f, &dom, affine, ticker)? {
                    Ok(x) => x,
                    Err(stop) => return Ok(stop),
                };
                let adjoints = bound::OutputAdjoints::new(f, &x);
                let e =
                    match bound::bound_with_adjoints(f, &x, formats, 0, adjoints.as_ref(), self.trig, || ticker.tick())
                    {
                        Ok(e) => e,
                        Err(err @ BoundError::Stopped(_)) => {
                            return Ok(Step::Stopped { what: err.message(&f.name), kept: None });
                        }
                        Err(err) => return Err(located(err.message(&f.name), err.span())),
                    };
                let mut summary = summarise(f, &x, &e, word, self.trig);
                if self.witness > 0 {
                    let found = witnesses(f, &dom, formats, self.witness, || ticker.tick());
                    let Some(found) = found else {
                        let what = format!("in @{}'s witnesses (its bounds kept, without witnesses)", f.name);
                        return Ok(Step::Stopped { what, kept: Some(summary) });
                    };
                    for ((_, b), w) in summary.outputs.iter_mut().zip(found) {
                        b.witness = w;
                    }
                }
                Ok(Step::Done(summary))
            },
        )?;
        cx.emit(ErrorBoundRun { functions });
        Ok(())
    }
}

/// One output's bound.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OutputBound {
    /// Bound on |computed − exact| over the domain (`None`: no finite bound).
    pub abs: Option<f64>,
    /// `abs` / min |exact| over the domain, when the output's enclosure excludes 0.
    pub rel: Option<f64>,
    /// With `witness=N`: the largest error of the rounding model's worst execution at the `N`
    /// points ([`witness`]), in the output's units; no bound sound under the model is below
    /// it. Absent without `witness`, or when no point gave one (a constant output, an
    /// uncertified reference).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub witness: Option<f64>,
}

/// The `k`-th point of a box of `ranges` (one interval per input): the corner of every input
/// at its lower end for `k = 0`, at its upper end for `k = 1`, then each input at an end (⅓,
/// either end) or uniform inside, drawn from `rng`; every coordinate inside its interval.
pub fn domain_point(ranges: &[Interval], k: u64, rng: &mut robovec_ir::rng::SplitMix64) -> Vec<f64> {
    ranges
        .iter()
        .map(|i| {
            let t = match k {
                0 => 0.0,
                1 => 1.0,
                _ if rng.chance(333) => rng.below(2) as f64,
                _ => rng.unit(),
            };
            (i.lo + t * (i.hi - i.lo)).clamp(i.lo, i.hi)
        })
        .collect()
}

/// Per output of `f` (in output order), the largest [`witness::Witness`] error over `n` points
/// of `dom` in `formats`: the points of [`domain_point`] (seeded: the same points every
/// run). A point where a fixed-point value overflows is skipped. `None` when `tick`
/// stopped it (called once per point and [`witness::Witness::errors_at_until`]'s per output).
pub fn witnesses(
    f: &Function,
    dom: &robovec_ir::domain::Domain,
    formats: Formats,
    n: u32,
    mut tick: impl FnMut() -> bool,
) -> Option<Vec<Option<f64>>> {
    let mut w = witness::Witness::new(f, formats);
    let ranges: Vec<Interval> =
        w.inputs().iter().map(|name| dom.get(name).map_or(Interval::point(0.0), |r| r.interval)).collect();
    let mut rng = robovec_ir::rng::SplitMix64::new(0x5eed);
    let mut worst: Vec<Option<f64>> = vec![None; f.outputs.len()];
    for k in 0..n {
        if tick() {
            return None;
        }
        let xs = domain_point(&ranges, u64::from(k), &mut rng);
        let errors = match w.errors_at_until(&xs, &mut tick) {
            Ok(Some(errors)) => errors,
            Ok(None) => return None,
            Err(_) => continue,
        };
        for (m, e) in worst.iter_mut().zip(errors) {
            if let Some(e) = e {
                *m = Some(m.map_or(e, |m| m.max(e)));
            }
        }
    }
    Some(worst)
}

/// One function's bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct FunctionBound {
    /// Function name.
    pub function: String,
    /// The formats it was bounded in.
    pub format: FormatWord,
    /// The `sin`/`cos` it was bounded for.
    pub trig: TrigImpl,
    /// Per output, in output order: name and bound.
    pub outputs: Vec<(String, OutputBound)>,
    /// The largest finite `abs` and its output.
    pub max_abs: Option<(String, f64)>,
    /// The largest `rel` and its output.
    pub max_rel: Option<(String, f64)>,
    /// Outputs without a finite bound.
    pub unbounded: Vec<String>,
}

/// The bounds of `f`'s outputs from the enclosures `x` and value bounds `e`.
fn summarise(f: &Function, x: &[Interval], e: &[f64], format: FormatWord, trig: TrigImpl) -> FunctionBound {
    let outputs: Vec<(String, OutputBound)> = f
        .outputs
        .iter()
        .map(|o| {
            let (range, err) = match o.value {
                Operand::Value(v) => (x[v.index()], e[v.index()]),
                // A constant output is computed exactly (binary32 rounds it).
                Operand::Const(c) => {
                    (Interval::point(c), if format == FormatWord::F32 { (c - c as f32 as f64).abs() } else { 0.0 })
                }
            };
            let abs = err.is_finite().then_some(err);
            let mig = range.mig();
            let rel = abs.filter(|_| mig > 0.0).map(|a| (a / mig).next_up());
            (o.name.clone(), OutputBound { abs, rel, witness: None })
        })
        .collect();
    let largest = |pick: fn(&OutputBound) -> Option<f64>| {
        outputs.iter().filter_map(|(n, b)| Some((n.clone(), pick(b)?))).max_by(|a, b| a.1.total_cmp(&b.1))
    };
    FunctionBound {
        function: f.name.clone(),
        format,
        trig,
        max_abs: largest(|b| b.abs),
        max_rel: largest(|b| b.rel),
        unbounded: outputs.iter().filter(|(_, b)| b.abs.is_none()).map(|(n, _)| n.clone()).collect(),
        outputs,
    }
}

/// What one `error-bound` run proved, per function: printed after the run, and the report's
/// `error_bound`.
#[derive(Clone, Debug)]
pub struct ErrorBoundRun {
    /// Per function.
    pub functions: Vec<FunctionBound>,
}

impl std::fmt::Display for FunctionBound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.outputs.len() - self.unbounded.len();
        write!(
            f,
            "error-bound @{} ({}{}): {n} of {} outputs bounded",
            self.function,
            self.format.as_str(),
            if self.trig == TrigImpl::Inline { ", trig=inline" } else { "" },
            self.outputs.len()
        )?;
        if let Some((o, a)) = &self.max_abs {
            write!(f, "; max abs {a:.3e} ({o})")?;
        }
        if let Some((o, r)) = &self.max_rel {
            write!(f, "; max rel {r:.3e} ({o})")?;
        }
        let mut pessimism: Vec<f64> =
            self.outputs.iter().filter_map(|(_, b)| Some(b.abs? / b.witness.filter(|w| *w > 0.0)?)).collect();
        if !pessimism.is_empty() {
            pessimism.sort_by(f64::total_cmp);
            write!(
                f,
                "; bound / witness median {:.1}, max {:.1}",
                pessimism[pessimism.len() / 2],
                pessimism[pessimism.len() - 1]
            )?;
        }
        if let Some(first) = self.unbounded.first() {
            write!(f, "; unbounded: {first}")?;
            if self.unbounded.len() > 1 {
                write!(f, " and {} more", self.unbounded.len() - 1)?;
            }
        }
        Ok(())
    }
}

/// The report's `error_bound` object.
#[derive(Serialize)]
struct ErrorBoundReport<'a> {
    format: &'static str,
    /// Present with `trig=inline` only (the report is unchanged by default).
    #[serde(skip_serializing_if = "Option::is_none")]
    trig: Option<&'static str>,
    outputs: serde_json::Map<String, serde_json::Value>,
    max_abs: Option<f64>,
    max_rel: Option<f64>,
    unbounded: &'a [String],
}

impl crate::Artifact for ErrorBoundRun {
    fn pass(&self) -> &'static str {
        "error-bound"
    }

    fn log_text(&self, _detail: bool) -> String {
        self.functions.iter().map(|r| format!("{r}\n")).collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let r = self.functions.iter().find(|r| r.function == function)?;
        let outputs =
            r.outputs.iter().map(|(n, b)| (n.clone(), serde_json::to_value(b).expect("serialises"))).collect();
        let value = ErrorBoundReport {
            format: r.format.as_str(),
            trig: (r.trig == TrigImpl::Inline).then_some(r.trig.as_str()),
            outputs,
            max_abs: r.max_abs.as_ref().map(|m| m.1),
            max_rel: r.max_rel.as_ref().map(|m| m.1),
            unbounded: &r.unbounded,
        };
        Some(crate::ReportEntry::new("error_bound", &value, crate::Merge::Last))
    }
}
