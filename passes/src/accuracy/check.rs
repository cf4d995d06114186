//! `-check`: the numeric property of the fuzzing and property tests (`robovec-testkit`'s
//! `numeric_check`) on any pipeline and any function (trig, division, square root and callbacks
//! included), at the command line.
//!
//! At `samples` sampled points (the `accuracy` sampled draws, stream 0: point `i` of seed `s`
//! is `accuracy<seed=s>`'s point `i`), every output of the function after the pipeline, computed
//! in binary32 and in binary64 in the IR's order, must lie within its **error budget** of the
//! exact value of the function **as it entered the pipeline** (outputs and inputs matched by
//! name):
//!
//! `|fl(after) − exact(before)| ≤ max(γ_K·M, B) + E`
//!
//! - `γ_K·M`: the a-priori budget of `+ − ×` functions (`robovec_ir::numerics::budget`, the
//!   fuzzing property; only when the rewritten function has no trig, division or call);
//! - `B`: a running error bound of that very evaluation (Wilkinson, Higham §3.3;
//!   `robovec_ir::numerics::reference::float_bound`), rigorous for any function: it covers
//!   the rounding of inputs and constants to the format, every operation, `sin`/`cos` within
//!   two ulps and underflow;
//! - `E`: the double-double reference's own bound.
//!
//! A sound rewrite (the same real function) always passes: its exact value is the original's,
//! and each bound covers its own rounding. An output where a bound is infinite (a divisor
//! interval through zero, an overflow) or the reference is not finite is not decided at that
//! point (counted in `undecided`). Pipelines made only of passes declared bit-exact ([`crate::Props::bit_exact`], asked of a pipeline with [`crate::PassManager::is_bit_exact`]) must also reproduce the original bit for bit (the sign of an exact zero aside).

use std::collections::BTreeMap;
use std::fmt;

use rayon::prelude::*;
use robovec_ir::numerics::budget::{allowed, terms, U32, U64};
use robovec_ir::numerics::reference::{dd_bounded, float_bound};
use robovec_ir::numerics::DD;
use robovec_ir::Function;

use super::inputs::{point, range_of, rng_for, Range};
use super::measure::Subject;

/// Inputs a violation's message lists (all are in [`Violation::inputs`]).
const SHOWN: usize = 12;

/// Default number of points of `-check`.
pub const DEFAULT_SAMPLES: u32 = 200;

/// The first output found outside its budget.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Violation {
    /// Function.
    pub function: String,
    /// Output name.
    pub output: String,
    /// `f32` or `f64`.
    pub format: &'static str,
    /// Sample index of the point.
    pub sample: u64,
    /// Every input at the point (the `-eval` format).
    pub inputs: BTreeMap<String, f64>,
    /// The value the rewritten function computes.
    pub computed: f64,
    /// The exact value of the original function (double-double, rounded to binary64).
    pub exact: f64,
    /// |computed − exact|.
    pub error: f64,
    /// What the budget allows (bit-exact pipelines: the original's own result, `error` 0).
    pub budget: f64,
    /// True when the pipeline is bit-exact and the value changed.
    pub bit_exact: bool,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.bit_exact {
            write!(
                f,
                "@{}: output {} changed in {} (the pipeline is bit-exact): computed {:e}, original {:e}",
                self.function, self.output, self.format, self.computed, self.budget
            )?;
        } else {
            write!(
                f,
                "@{}: output {} in {} is {:e} from the exact value of the original ({:e}), above the error budget \
                 {:e}: computed {:e}",
                self.function, self.output, self.format, self.error, self.exact, self.budget, self.computed
            )?;
        }
        let inputs: Vec<String> = self.inputs.iter().take(SHOWN).map(|(k, v)| format!("{k} = {v:e}")).collect();
        let more = self.inputs.len().saturating_sub(SHOWN);
        let more = if more > 0 { format!(", … {more} more inputs") } else { String::new() };
        write!(f, " at sample {} ({}{more})", self.sample, inputs.join(", "))
    }
}

/// What a check found.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CheckSummary {
    /// Function.
    pub function: String,
    /// Points checked.
    pub samples: u64,
    /// Outputs checked at each point.
    pub outputs: u64,
    /// (output, point, format) triples no bound could decide.
    pub undecided: u64,
    /// The first violation (lowest sample, then output order, then f32 before f64).
    pub violation: Option<Violation>,
}

fn same_bits(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0) || (a.is_nan() && b.is_nan())
}

/// Checks `after` (the function after a pipeline) against `before` (as it entered) at
/// `samples` points of seed `seed`; `bit_exact` also demands identical results.
///
/// # Errors
/// A message when an output of `after` is not an output of `before`.
pub fn check_function(
    after: &Function,
    before: &Function,
    bit_exact: bool,
    samples: u32,
    seed: u64,
) -> Result<CheckSummary, String> {
    check_function_until(after, before, bit_exact, samples, seed, None)
}

/// Points checked between two reads of the clock by [`check_function_until`].
pub const CHECK_CHUNK: u64 = 256;

/// [`check_function`] that checks no further chunk of [`CHECK_CHUNK`] points once `deadline`
/// is reached (`-time-limit`; the first chunk always runs): the summary's `samples` are the
/// points checked, the first ones of the full check.
///
/// # Errors
/// As [`check_function`].
pub fn check_function_until(
    after: &Function,
    before: &Function,
    bit_exact: bool,
    samples: u32,
    seed: u64,
    deadline: Option<std::time::Instant>,
) -> Result<CheckSummary, String> {
    let sub = Subject::new(after, Some(before))?;
    let ranges: Vec<Range> = sub.names.iter().map(|n| range_of(n)).collect();
    let (t1, t0) = (&sub.tape, &sub.reference);
    let at = |t: &robovec_ir::numerics::Tape| -> Vec<usize> {
        t.inputs.iter().map(|n| sub.names.iter().position(|m| m == n).expect("union")).collect()
    };
    let (at1, at0) = (at(t1), at(t0));
    let known = BTreeMap::new();
    let per_point = |i: u64| -> (u64, Option<Violation>) {
        let x = point(&sub.names, &ranges, &known, &mut rng_for(seed, 0, i), false);
        let x1: Vec<f64> = at1.iter().map(|&k| x[k]).collect();
        let x0: Vec<f64> = at0.iter().map(|&k| x[k]).collect();
        let exact = dd_bounded(t0, &x0);
        let gamma = terms(t1, &x1);
        let (mut s32, mut s64, mut scratch) = (Vec::<f32>::new(), Vec::<f64>::new(), Vec::new());
        t1.eval_into::<f32>(&x1, &mut s32, &mut scratch);
        let mut scratch64 = Vec::new();
        t1.eval_into::<f64>(&x1, &mut s64, &mut scratch64);
        let w32: Vec<f64> = s32.iter().map(|&v| v as f64).collect();
        let b32 = float_bound(t1, &x1, &w32, true);
        let b64 = float_bound(t1, &x1, &s64, false);
        let orig = bit_exact.then(|| (t0.eval::<f32>(&x0), t0.eval::<f64>(&x0)));
        let mut undecided = 0;
        for (k, (name, slot)) in t1.outputs.iter().enumerate() {
            let (ref_val, ref_err) = exact[k];
            let got32 = w32[*slot as usize];
            let got64 = s64[*slot as usize];
            let v = |format: &'static str, computed: f64, error: f64, budget: f64, be: bool| Violation {
                function: after.name.clone(),
                output: name.clone(),
                format,
                sample: i,
                inputs: sub.names.iter().cloned().zip(x.iter().copied()).collect(),
                computed,
                exact: ref_val.round_f64(),
                error,
                budget,
                bit_exact: be,
            };
            if let Some((o32, o64)) = &orig {
                if !same_bits(got32, o32[k] as f64) {
                    return (undecided, Some(v("f32", got32, 0.0, o32[k] as f64, true)));
                }
                if !same_bits(got64, o64[k]) {
                    return (undecided, Some(v("f64", got64, 0.0, o64[k], true)));
                }
            }
            for (format, got, bound, u) in [("f32", got32, b32[k], U32), ("f64", got64, b64[k], U64)] {
                let a_priori = gamma.as_ref().map_or(0.0, |g| {
                    let (kk, m) = g.outputs[k];
                    if g.max_m >= if u == U32 { f32::MAX as f64 } else { f64::MAX } / 4.0 {
                        0.0
                    } else {
                        allowed(kk, m, u, t1.steps.len())
                    }
                });
                let budget = bound.max(a_priori) * (1.0 + 2f64.powi(-30)) + ref_err;
                if !budget.is_finite() || !ref_val.is_finite() || !got.is_finite() {
                    undecided += 1;
                    continue;
                }
                let error = (DD::from_f64(got) - ref_val).abs().round_f64();
                if error > budget {
                    return (undecided, Some(v(format, got, error, budget, false)));
                }
            }
        }
        (undecided, None)
    };
    let (mut results, mut checked) = (Vec::with_capacity(samples as usize), 0u64);
    while checked < u64::from(samples) {
        if checked > 0 && deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            break;
        }
        let end = (checked + CHECK_CHUNK).min(u64::from(samples));
        results.par_extend((checked..end).into_par_iter().map(per_point));
        checked = end;
    }
    let undecided = results.iter().map(|r| r.0).sum();
    let violation = results.into_iter().find_map(|r| r.1);
    Ok(CheckSummary {
        function: after.name.clone(),
        samples: checked,
        outputs: t1.outputs.len() as u64,
        undecided,
        violation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text;

    fn f(body: &str) -> Function {
        let src = format!(
            "func @f {{\n  phase parsed\n  input %q[1]\n  input %m[1]\n  input %l[1]\n  %S = sin %q[1]\n{body}}}\n"
        );
        text::parse(&src).unwrap().functions.remove(0)
    }

    #[test]
    fn a_wrong_rewrite_fails_and_sound_ones_pass() {
        let before = f("  %y = %m[1]*%l[1]*%S/(%l[1] + 3.0)\n  %z = %m[1]*0.1\n  output y = %y\n  output z = %z\n");
        // Reassociated: the same real function, other roundings.
        let same = f("  %y = %m[1]*(%l[1]*%S)/(3.0 + %l[1])\n  %z = 0.1*%m[1]\n  output y = %y\n  output z = %z\n");
        let r = check_function(&same, &before, false, 300, 1).unwrap();
        assert_eq!(r.violation, None, "{r:?}");
        assert_eq!((r.samples, r.outputs), (300, 2));
        // Dropping a factor changes the function.
        let wrong = f("  %y = %S*%m[1]/(3.0 + %l[1])\n  %z = 0.1*%m[1]\n  output y = %y\n  output z = %z\n");
        let v = check_function(&wrong, &before, false, 300, 1).unwrap().violation.expect("caught");
        assert_eq!((v.output.as_str(), v.format, v.sample), ("y", "f32", 0));
        assert!(v.error > v.budget);
        // Independent route: recompute the exact value in f64 at the reported point.
        let (q, m, l) = (v.inputs["q[1]"], v.inputs["m[1]"], v.inputs["l[1]"]);
        assert!((v.exact - m * l * q.sin() / (l + 3.0)).abs() < 1e-12 * v.exact.abs().max(1.0));
        // Bit-exact pipelines must not change a bit: the reassociation is caught there.
        let b = check_function(&same, &before, true, 50, 1).unwrap().violation.expect("not bit-exact");
        assert!(b.bit_exact);
        assert_eq!(check_function(&before, &before, true, 50, 1).unwrap().violation, None);
        let bit_exact = |p: &str| crate::PassManager::new(p, Default::default()).unwrap().is_bit_exact();
        assert!(bit_exact("atomise,accuracy<samples=3>") && !bit_exact("atomise,balance"));
        // Named pipelines are asked as their expansion: `default<ops>` holds rewrites.
        assert!(bit_exact("atomise,dce,asap-alap,place<pe=2>,sim") && !bit_exact("default<ops>"));
    }
}
