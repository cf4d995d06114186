//! The numeric property every pipeline must keep (shared by the proptest suite and the
//! cargo-fuzz target `pipeline_numerics`; `-check` applies the same property at the command
//! line, `robovec_passes::accuracy::check`): run a pipeline on a `+ − ×` function, then
//! - the module verifies after every pass (the manager's `verify-each`);
//! - every output of the result stays within the error budget of `robovec_ir::numerics::budget`
//!   around the exact value of the **original** function, in binary32 and binary64:
//!   `|fl(after) − exact(before)| ≤ γ_K(after)·M(after) + γ_K(before)(2⁻¹⁰⁰)·M(before) + slack`,
//!   the second term covering the double-double reference (so an algebraically different
//!   rewrite fails, a reassociation within its rounding passes);
//! - pipelines made only of passes the registry declares bit-exact (`Props::bit_exact`, asked
//!   of the pipeline as built: `PassManager::is_bit_exact`, so a parameter list such as
//!   `sweep<pe=8,16>` is never split at its commas) reproduce the original bit for bit, except
//!   the sign of an exact zero (`atomise` writes `−t` as `0 − t`; docs/ir.md, "Unary minus
//!   semantics").
//!
//! Points whose `M` comes within a factor 4 of the format's largest value are not checked in
//! that format (the budget assumes no overflow).

use robovec_ir::numerics::budget::{allowed, gamma, terms, U32, U64};
use robovec_ir::numerics::{Tape, DD};
use robovec_ir::{Function, Module, Phase};

use robovec_backends::REGISTRY as PASSES;
use robovec_passes::{Instrumentation, PassContext, PassManager, Session};

/// Registered passes the property cannot build from default parameters because they need a
/// file (none today: `accuracy`'s `params` file is optional).
pub const NEEDS_FILE: &[&str] = &[];

/// Registered passes that add outputs the input function does not have, so the property (each
/// output against the input's) cannot judge them: `diff` (its derivative outputs are checked
/// against finite differences and Pinocchio in `tests/diff.rs` and `passes/src/diff/tests.rs`,
/// which also check its original outputs bit for bit).
pub const NEW_OUTPUTS: &[&str] = &["diff"];

/// Every registered pass the property exercises (all of `robovec_backends::REGISTRY` but
/// [`NEEDS_FILE`] and [`NEW_OUTPUTS`]).
pub fn checked_passes() -> Vec<&'static str> {
    PASSES.iter().map(|p| p.name).filter(|n| !NEEDS_FILE.contains(n) && !NEW_OUTPUTS.contains(n)).collect()
}

/// The registered passes declared bit-exact (`Props::bit_exact`), in registry order.
pub fn bit_exact_passes() -> Vec<&'static str> {
    PASSES.iter().map(|p| p.name).filter(|n| PASSES.props_of(n).is_some_and(|p| p.bit_exact)).collect()
}

/// The pipeline text for `names` with default parameters: `atomise` inserted before the first
/// pass that needs the atomised phase (the manager would reject it on parsed input), and the
/// pass a pass declares it needs right before it (`Props::needs_before`: `sim` after `place`)
/// inserted there.
pub fn pipeline_text(names: &[&str]) -> String {
    let mut out: Vec<&str> = Vec::new();
    let mut atomised = false;
    let mut push = |n: &'static str, out: &mut Vec<&'static str>| {
        let needs = PASSES.props_of(n).expect("registered pass").requires;
        if needs == Some(Phase::Atomised) && !atomised {
            out.push("atomise");
            atomised = true;
        }
        atomised |= n == "atomise";
        out.push(n);
    };
    for &n in names {
        let n = checked_passes().into_iter().find(|&x| x == n).expect("registered pass");
        if let Some(pre) = PASSES.props_of(n).and_then(|p| p.needs_before) {
            if out.last() != Some(&pre) {
                push(pre, &mut out);
            }
        }
        push(n, &mut out);
    }
    out.join(",")
}

fn same_bits<T: Copy + PartialEq + Into<f64>>(a: T, b: T, bits: impl Fn(T) -> u64) -> bool {
    bits(a) == bits(b) || (a.into() == 0.0 && b.into() == 0.0)
}

/// Runs `pipeline` on `before` (a verified `+ − ×` function) and checks the property at every
/// point (input values in `before`'s input order). Returns the function after the pipeline.
///
/// # Errors
/// A message naming the pipeline, the output, the point and the figures.
pub fn check(before: &Function, pipeline: &str, points: &[Vec<f64>]) -> Result<Function, String> {
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default())
        .map_err(|e| format!("{pipeline}: {e}"))?;
    let bit_exact = pm.is_bit_exact();
    let m = Module { functions: vec![before.clone()] };
    // A domain covering every point (for the passes that need one, `range`): each input's
    // hull over the points, or [-1, 1] without points.
    let ranges = before
        .inputs
        .iter()
        .enumerate()
        .map(|(k, &v)| {
            let xs = points.iter().map(|p| p[k]);
            let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
            let interval =
                if lo <= hi { robovec_ir::Interval::new(lo, hi) } else { robovec_ir::Interval::new(-1.0, 1.0) };
            (before.name_of(v).to_string(), robovec_ir::domain::Range { interval, source: "the points".into() })
        })
        .collect();
    let cx = PassContext { domain: Some(robovec_ir::domain::Domain { ranges }), ..PassContext::default() };
    let mut session = Session::new(pm, m, cx);
    session.run_quiet().map_err(|e| format!("{pipeline}: {e}"))?;
    let after = session.module.functions.pop().ok_or_else(|| format!("{pipeline}: the function disappeared"))?;
    let (t0, t1) = (Tape::new(before), Tape::new(&after));
    // Where each output and input of `after` sits in `before`: a state copy (`Qq[1]#2`,
    // `q[1]#2`, made by `interleave`) sits where its base name does, so every state is checked
    // against the original function at the same point.
    let base = |n: &str| robovec_ir::split_state(n).0.to_string();
    let out_at: Vec<usize> = t1
        .outputs
        .iter()
        .map(|(n, _)| {
            let n = if t0.outputs.iter().any(|(m, _)| m == n) { n.clone() } else { base(n) };
            t0.outputs.iter().position(|(m, _)| *m == n).ok_or_else(|| format!("{pipeline}: new output {n}"))
        })
        .collect::<Result<_, _>>()?;
    let in_at: Vec<usize> = t1
        .inputs
        .iter()
        .map(|n| {
            let n = if t0.inputs.iter().any(|m| m == n) { n.clone() } else { base(n) };
            t0.inputs.iter().position(|m| *m == n).ok_or_else(|| format!("{pipeline}: new input {n}"))
        })
        .collect::<Result<_, _>>()?;
    for x in points {
        let x1: Vec<f64> = in_at.iter().map(|&i| x[i]).collect();
        let exact = t0.eval::<DD>(x);
        let (Some(b0), Some(b1)) = (terms(&t0, x), terms(&t1, &x1)) else {
            return Err(format!("{pipeline}: only + - * functions have a budget"));
        };
        let (y32, y64) = (t1.eval::<f32>(&x1), t1.eval::<f64>(&x1));
        let (z32, z64) = (t0.eval::<f32>(x), t0.eval::<f64>(x));
        for (k, &o) in out_at.iter().enumerate() {
            let name = &t1.outputs[k].0;
            if bit_exact
                && !(same_bits(y32[k], z32[o], |v: f32| v.to_bits() as u64) && same_bits(y64[k], z64[o], f64::to_bits))
            {
                return Err(format!(
                    "{pipeline}: {name} changed: f32 {:e} → {:e}, f64 {:e} → {:e} at {x:?}",
                    z32[o], y32[k], z64[o], y64[k]
                ));
            }
            let (k1, m1) = b1.outputs[k];
            let (k0, m0) = b0.outputs[o];
            let ref_err = gamma(k0, robovec_ir::numerics::dd::DD_UNIT) * m0;
            for (got, u, max) in [(y32[k] as f64, U32, f32::MAX as f64), (y64[k], U64, f64::MAX)] {
                if b1.max_m.max(b0.max_m) >= max / 4.0 {
                    continue;
                }
                let err = (DD::from_f64(got) - exact[o]).abs().round_f64();
                let budget = allowed(k1, m1, u, t1.steps.len()) + ref_err;
                if err.is_nan() || budget.is_nan() || err > budget {
                    return Err(format!(
                        "{pipeline}: {name} in {} is {err:e} from the exact value {:e}, above the budget \
                         {budget:e} (K = {k1}, M = {m1:e}) at {x:?}",
                        if u == U32 { "f32" } else { "f64" },
                        exact[o].round_f64()
                    ));
                }
            }
        }
    }
    Ok(after)
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text;

    #[test]
    fn bit_exact_comes_from_the_registry_and_parameter_lists_are_not_split() {
        assert_eq!(
            bit_exact_passes(),
            [
                "atomise",
                "dce",
                "asap-alap",
                "place",
                "sim",
                "sweep",
                "accuracy",
                "interleave",
                "diff",
                "depth-bound",
                "range",
                "error-bound"
            ]
        );
        // `split(',')` read `sweep<pe=8,16>` as `sweep<pe=8` and `16>`: not bit-exact.
        let pm = PassManager::with_registry(
            robovec_backends::REGISTRY,
            "atomise,sweep<pe=8,16>",
            Instrumentation::default(),
        )
        .unwrap();
        assert!(pm.is_bit_exact());
        let pm = PassManager::with_registry(
            robovec_backends::REGISTRY,
            "atomise,sweep<pe=8,16>,balance",
            Instrumentation::default(),
        )
        .unwrap();
        assert!(!pm.is_bit_exact());
    }

    #[test]
    fn pipeline_text_inserts_atomise_once() {
        assert_eq!(pipeline_text(&["dce", "place", "sim"]), "dce,atomise,place,sim");
        assert_eq!(pipeline_text(&["sim", "dce", "sim"]), "atomise,place,sim,dce,place,sim");
        assert_eq!(pipeline_text(&["atomise", "asap-alap"]), "atomise,asap-alap");
        assert_eq!(pipeline_text(&["accuracy"]), "accuracy");
    }

    #[test]
    fn a_wrong_rewrite_is_caught_and_a_reassociation_is_not() {
        // Reassociating (a + b) + c into a + (b + c) stays within budget; changing a constant
        // does not. The "pipelines" here are empty; the functions stand for their results.
        let before =
            "func @f {\n  phase parsed\n  input %a\n  input %b\n  input %c\n  %y = %a + %b + %c\n  output y = %y\n}\n";
        let f0 = text::parse(before).unwrap().functions.remove(0);
        let points = vec![vec![1.0, 1e-8, -1.0], vec![3.0, 0.1f32 as f64, 1e-3f32 as f64]];
        check(&f0, "dce", &points).unwrap();
        let reassoc = before.replace("%a + %b + %c", "%a + (%b + %c)");
        let f1 = text::parse(&reassoc).unwrap().functions.remove(0);
        assert!(same_outputs_within_budget(&f0, &f1, &points).is_ok());
        let wrong = before.replace("%a + %b + %c", "%a + %b + %c*1.5");
        let f2 = text::parse(&wrong).unwrap().functions.remove(0);
        assert!(same_outputs_within_budget(&f0, &f2, &points).is_err());
    }

    /// The budget part of [`check`] applied to two given functions (for the test above).
    fn same_outputs_within_budget(f0: &Function, f1: &Function, points: &[Vec<f64>]) -> Result<(), String> {
        let (t0, t1) = (Tape::new(f0), Tape::new(f1));
        for x in points {
            let exact = t0.eval::<DD>(x)[0];
            let (k, m) = terms(&t1, x).unwrap().outputs[0];
            let got = t1.eval::<f32>(x)[0] as f64;
            let err = (DD::from_f64(got) - exact).abs().round_f64();
            if err > allowed(k, m, U32, t1.steps.len()) + 1e-30 {
                return Err(format!("{err:e}"));
            }
        }
        Ok(())
    }
}
