//! `range<ranges=FILE;samples=64>`: a certified enclosure of every value of each function over
//! the input domain (issue 48 item 2), by outward-rounded interval arithmetic
//! ([`robovec_ir::interval`], [`enclose()`]) intersected, with `method=affine` (the default),
//! with affine forms ([`affine`]) and with affine forms on the harmonics of the joint angles
//! ([`harmonic`], which keep `sin² + cos² = 1` through rotations).
//!
//! Phase: atomised → atomised; an analysis: the IR is unchanged (bit-exact, timing kept). The
//! domain is the run's ([`PassContext::domain`]: the input's defaults and `-ranges=FILE`),
//! with the keys of `ranges=FILE` given here applied over it (the same JSON format,
//! [`robovec_ir::domain`]). Every input of a function must have a range: those without one
//! are named in the error (exit 1), with the hint `-ranges=FILE`. A division whose divisor's
//! enclosure holds 0, or a square root of an enclosure holding negatives, is an error naming
//! the value, its source line and the range. User callbacks are enclosed by every real.
//!
//! **What is certified.** Each value's enclosure contains its exact real value and the value
//! the interpreter computes in binary64, for every input point of the domain (the module doc
//! of [`robovec_ir::interval`]; `sin`/`cos` assume a libm within [`robovec_ir::interval::LIBM_ULPS`]
//! ulps). As a check and a measure of tightness the pass also evaluates each function at
//! `samples` points of the domain (the corners `lo…` and `hi…`, then uniform draws of
//! [`robovec_ir::rng::SplitMix64`], seed 1): a sampled value outside its enclosure is an error
//! (a bug, never seen), and per output the ratio of the enclosure's width to the width of
//! the sampled values is reported (how pessimistic the enclosure is).
//!
//! Printed after the run, one line per function (`range @f: 24 outputs enclosed over 31
//! inputs; …`), and in the report as `range` (per output `[lo, hi]`, the summary) and `domain`
//! (per input `[lo, hi]` and where it came from). The enclosures of every value stay
//! available to later analyses through [`enclose_with()`]. Cost: O(ops) for the enclosure, plus
//! O(ops · samples) for the samples.

pub mod affine;
pub mod enclose;
pub mod harmonic;

use std::collections::HashMap;

use robovec_ir::domain::{self, Domain, Range};
use robovec_ir::{Function, Interval, Module, Operand};
use serde::Serialize;

use crate::params::ParamKind;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};
pub use enclose::{enclose, enclose_with, EncloseError};

crate::params::word_enum! {
    /// How `range` encloses the values.
    pub enum Method {
        /// Outward-rounded interval arithmetic alone.
        Interval = "interval",
        /// Intervals intersected with affine forms of at most `terms` noise symbols and with
        /// harmonic forms ([`harmonic`]).
        Affine = "affine",
    }
}

/// `ranges=FILE`: input ranges over the run's domain (also `error-bound`'s and `precision`'s).
pub const RANGES: ParamInfo = ParamInfo {
    name: "ranges",
    kind: ParamKind::Path,
    doc: "JSON file of input ranges ({\"q[*]\": [-3.1416, 3.1416], \"m[2]\": [1, 1]}) over the run's domain (-ranges)",
};

/// `method=interval|affine` (also `error-bound`'s).
pub const METHOD: ParamInfo = ParamInfo {
    name: "method",
    kind: ParamKind::Choice { choices: Method::WORDS, default: "affine" },
    doc: "interval: outward-rounded interval arithmetic; affine: intervals intersected with affine forms \
          (correlation-aware, O(ops · terms)) and with affine forms on the harmonics of the joint angles \
          (rotations exact, O(ops · atoms²), atoms = 2^20 / ops within [48, 1024])",
};

/// `terms=K` (also `error-bound`'s).
pub const TERMS: ParamInfo = ParamInfo {
    name: "terms",
    kind: ParamKind::U32 { default: affine::DEFAULT_TERMS as u32, min: 2, max: 1024 },
    doc: "most noise symbols of one affine form (method=affine); the smallest beyond are folded into the value's \
          own symbol",
};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "range",
    doc: "certified enclosure of every value over the input domain (outward-rounded interval arithmetic)",
    params: &[
        RANGES,
        METHOD,
        TERMS,
        ParamInfo {
            name: "samples",
            kind: ParamKind::U32 { default: 64, min: 0, max: 1_000_000 },
            doc: "points of the domain each function is evaluated at, to check the enclosures and measure their \
                  tightness",
        },
    ],
    build: |p: &Params| {
        Ok(Box::new(RangePass {
            ranges: p.path("ranges")?,
            samples: p.u32("samples")?,
            method: p.word("method")?,
            terms: p.u32("terms")? as usize,
        }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        needs_domain: true,
        ..crate::Props::DEFAULT
    },
};

/// The `range` pass.
#[derive(Debug)]
pub struct RangePass {
    /// A ranges file applied over the run's domain.
    pub ranges: Option<String>,
    /// Sample points per function.
    pub samples: u32,
    /// Interval arithmetic alone, or with affine forms.
    pub method: Method,
    /// Most noise symbols of an affine form.
    pub terms: usize,
}

/// The domain of `m`'s inputs: `base` (the run's) with the keys of the ranges file `path`
/// (when given) applied over it.
///
/// # Errors
/// The file cannot be read, or [`domain::parse_ranges`] / [`domain::resolve`] refuse it:
/// the message names the file, line and column.
pub fn domain_with_file(base: Option<&Domain>, path: Option<&str>, m: &Module) -> Result<Domain, PassError> {
    let base = base.cloned().unwrap_or_default();
    let Some(path) = path else { return Ok(base) };
    let failed = |message: String| PassError::Failed { pass: "range".into(), message };
    let text = std::fs::read_to_string(path).map_err(|e| failed(format!("cannot read ranges file `{path}`: {e}")))?;
    let located = |e: robovec_ir::SourceError| {
        let (line, col) = robovec_ir::span::line_col(&text, e.span.start as usize);
        let notes: String = e.notes.iter().map(|n| format!("\n  = {n}")).collect();
        failed(format!("{path}:{line}:{col}: {}{notes}", e.message))
    };
    let keys = domain::parse_ranges(&text).map_err(located)?;
    let inputs = m.functions.iter().flat_map(|f| f.inputs.iter().map(|&v| f.name_of(v)));
    let mut names: Vec<&str> = inputs.collect();
    names.sort_unstable();
    names.dedup();
    domain::resolve(&base.ranges, Some((path, &keys)), names).map_err(located)
}

impl Pass for RangePass {
    fn name(&self) -> &'static str {
        "range"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let dom = domain_with_file(cx.domain.as_ref(), self.ranges.as_deref(), m)?;
        let samples = self.samples;
        let (method, affine) = match self.method {
            Method::Interval => (self.method, None),
            Method::Affine => (self.method, Some(self.terms)),
        };
        let functions = try_each_function(
            m,
            cx,
            "range",
            AtTimeLimit::Skip,
            Before::Ticked,
            |f, k| Some(format!("before @{} ({k} functions enclosed)", f.name)),
            |f, _, ticker| {
                let x = match enclose_in_pass("range", f, &dom, affine, ticker)? {
                    Ok(x) => x,
                    Err(stop) => return Ok(stop),
                };
                measure(f, &x, samples, method).map(Step::Done)
            },
        )?;
        let domains = m
            .functions
            .iter()
            .take(functions.len())
            .map(|f| FunctionDomain {
                function: f.name.clone(),
                inputs: dom.of_function(f).into_iter().map(|(n, r)| (n, r.clone())).collect(),
            })
            .collect();
        cx.emit(DomainUsed { functions: domains });
        cx.emit(RangeRun { functions });
        Ok(())
    }
}

/// The enclosures of `f` (as [`enclose_with`]) in the per-function loop of pass `pass`
/// ([`try_each_function`]), its ticker read once per value: `Ok(Ok(x))`, or `Ok(Err(step))` —
/// the loop's [`Step::Stopped`] — when the limit stopped the sweep (`range`, `error-bound` and
/// `precision` share it).
///
/// # Errors
/// The enclosure's refusal ([`EncloseError`]: inputs without a range, a divisor that may be 0,
/// a square root of a range holding negatives) as [`PassError::Failed`] of `pass`, located at the
/// value's definition.
pub fn enclose_in_pass<T>(
    pass: &str,
    f: &Function,
    dom: &Domain,
    affine: Option<usize>,
    ticker: &crate::Ticker,
) -> Result<Result<Vec<Interval>, Step<T>>, PassError> {
    match enclose_with(f, dom, affine, || ticker.tick()) {
        Ok(x) => Ok(Ok(x)),
        Err(e @ EncloseError::Stopped(_)) => Ok(Err(Step::Stopped { what: e.message(&f.name), kept: None })),
        Err(e) => {
            let span = e.span().unwrap_or(robovec_ir::Span::DUMMY);
            Err(PassError::Failed { pass: pass.into(), message: e.message(&f.name) }.at(span))
        }
    }
}

/// One output's enclosure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputRange {
    /// The output's name.
    pub output: String,
    /// Its enclosure over the domain.
    pub enclosure: Interval,
    /// The smallest and largest value it took at the sample points (`None` without samples).
    pub sampled: Option<Interval>,
    /// Enclosure width / sampled width (`None` when either is 0 or not finite, or no samples).
    pub ratio: Option<f64>,
}

/// One function's enclosures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FunctionRange {
    /// Function name.
    pub function: String,
    /// How the enclosures were computed.
    pub method: Method,
    /// Per output, in output order.
    pub outputs: Vec<OutputRange>,
    /// Values (inputs and body) whose enclosure is unbounded (a callback's, an overflow).
    pub unbounded_values: usize,
    /// Sample points evaluated.
    pub samples: u32,
    /// Median of the outputs' [`OutputRange::ratio`]s (`None` when no output has one).
    pub median_ratio: Option<f64>,
    /// Largest of them.
    pub worst_ratio: Option<f64>,
    /// The output with the largest ratio.
    pub worst_output: Option<String>,
    /// The widest enclosure's output and its width.
    pub widest: Option<(String, f64)>,
}

/// Evaluates `f` at `samples` points of the domain (its inputs' enclosures in `x`), checks every value against its enclosure in
/// `x` and summarises the outputs.
fn measure(f: &Function, x: &[Interval], samples: u32, method: Method) -> Result<FunctionRange, PassError> {
    // Inputs in input order: the draws do not depend on a hash order.
    let ranges: Vec<(&str, Interval)> = f.inputs.iter().map(|&v| (f.name_of(v), x[v.index()])).collect();
    let mut rng = robovec_ir::rng::SplitMix64::new(1);
    let mut sampled: Vec<Option<Interval>> = vec![None; f.outputs.len()];
    for k in 0..samples {
        let point: HashMap<&str, f64> = ranges
            .iter()
            .map(|&(n, r)| {
                let t = match k {
                    0 => 0.0,
                    1 => 1.0,
                    _ => rng.unit(),
                };
                (n, (r.lo + t * (r.hi - r.lo)).clamp(r.lo, r.hi))
            })
            .collect();
        let vals = robovec_ir::interp::eval_values::<f64>(f, |n| point.get(n).copied().unwrap_or(0.0));
        for (i, (&y, e)) in vals.iter().zip(x).enumerate() {
            if !(y.is_nan() || e.contains(y)) {
                let v = robovec_ir::Value::with_number(i as u32);
                return Err(PassError::Failed {
                    pass: "range".into(),
                    message: format!(
                        "@{}: internal error: %{} = {y:e} at sample {k} lies outside its enclosure {e} (please report)",
                        f.name,
                        f.name_of(v)
                    ),
                });
            }
        }
        for (o, s) in f.outputs.iter().zip(sampled.iter_mut()) {
            let y = match o.value {
                Operand::Value(v) => vals[v.index()],
                Operand::Const(c) => c,
            };
            if !y.is_nan() {
                *s = Some(s.map_or(Interval::point(y), |s| s.hull(Interval::point(y))));
            }
        }
    }
    let outputs: Vec<OutputRange> = f
        .outputs
        .iter()
        .zip(sampled)
        .map(|(o, sampled)| {
            let enclosure = match o.value {
                Operand::Value(v) => x[v.index()],
                Operand::Const(c) => Interval::point(c),
            };
            let ratio = sampled.and_then(|s| {
                let (we, ws) = (enclosure.width(), s.width());
                (we.is_finite() && ws.is_finite() && ws > 0.0).then_some(we / ws)
            });
            OutputRange { output: o.name.clone(), enclosure, sampled, ratio }
        })
        .collect();
    let mut ratios: Vec<(f64, &str)> = outputs.iter().filter_map(|o| Some((o.ratio?, o.output.as_str()))).collect();
    ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
    let widest = outputs.iter().map(|o| (o.output.clone(), o.enclosure.width())).max_by(|a, b| a.1.total_cmp(&b.1));
    Ok(FunctionRange {
        function: f.name.clone(),
        method,
        unbounded_values: x.iter().filter(|i| !i.is_bounded()).count(),
        samples,
        median_ratio: ratios.get(ratios.len() / 2).map(|r| r.0),
        worst_ratio: ratios.last().map(|r| r.0),
        worst_output: ratios.last().map(|r| r.1.to_string()),
        widest,
        outputs,
    })
}

/// The domain one `range` run used, per function: printed in the report as `domain`.
#[derive(Clone, Debug)]
pub struct DomainUsed {
    /// Per function.
    pub functions: Vec<FunctionDomain>,
}

/// One function's inputs and their ranges.
#[derive(Clone, Debug)]
pub struct FunctionDomain {
    /// Function name.
    pub function: String,
    /// Input name → its range, in input order.
    pub inputs: Vec<(String, Range)>,
}

/// The report's `domain` object: input → `{"range": [lo, hi], "from": SOURCE}`.
#[derive(Serialize)]
struct DomainEntry<'a> {
    range: Interval,
    from: &'a str,
}

impl crate::Artifact for DomainUsed {
    fn pass(&self) -> &'static str {
        "range"
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let d = self.functions.iter().find(|d| d.function == function)?;
        let mut obj = serde_json::Map::new();
        for (n, r) in &d.inputs {
            let e = DomainEntry { range: r.interval, from: &r.source };
            obj.insert(n.clone(), serde_json::to_value(e).expect("serialises"));
        }
        Some(crate::ReportEntry { key: "domain", value: serde_json::Value::Object(obj), merge: crate::Merge::Last })
    }
}

/// What one `range` run found, per function: printed after the run, and the report's `range`.
#[derive(Clone, Debug)]
pub struct RangeRun {
    /// Per function.
    pub functions: Vec<FunctionRange>,
}

impl std::fmt::Display for FunctionRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "range @{}: {} outputs enclosed ({})", self.function, self.outputs.len(), self.method.as_str())?;
        if let Some((o, w)) = &self.widest {
            write!(f, "; widest {o} (width {w:.3e})")?;
        }
        match (self.median_ratio, self.worst_ratio, &self.worst_output) {
            (Some(m), Some(w), Some(o)) => write!(
                f,
                "; enclosure / sampled width over {} samples: median {m:.3}, worst {w:.3e} ({o})",
                self.samples
            )?,
            _ => write!(f, "; {} samples", self.samples)?,
        }
        if self.unbounded_values > 0 {
            write!(f, "; {} values unbounded", self.unbounded_values)?;
        }
        Ok(())
    }
}

/// The report's `range` object.
#[derive(Serialize)]
struct RangeReport<'a> {
    method: Method,
    outputs: serde_json::Map<String, serde_json::Value>,
    samples: u32,
    median_ratio: Option<f64>,
    worst_ratio: Option<f64>,
    worst_output: &'a Option<String>,
    widest: &'a Option<(String, f64)>,
    unbounded_values: usize,
}

impl crate::Artifact for RangeRun {
    fn pass(&self) -> &'static str {
        "range"
    }

    fn log_text(&self, _detail: bool) -> String {
        self.functions.iter().map(|r| format!("{r}\n")).collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let r = self.functions.iter().find(|r| r.function == function)?;
        let outputs = r
            .outputs
            .iter()
            .map(|o| (o.output.clone(), serde_json::to_value(o.enclosure).expect("serialises")))
            .collect();
        let value = RangeReport {
            method: r.method,
            outputs,
            samples: r.samples,
            median_ratio: r.median_ratio,
            worst_ratio: r.worst_ratio,
            worst_output: &r.worst_output,
            widest: &r.widest,
            unbounded_values: r.unbounded_values,
        };
        Some(crate::ReportEntry::new("range", &value, crate::Merge::Last))
    }
}
