use super::*;
use proptest::prelude::*;
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::text::parse;
use robovec_ir::time_limit::Ticker;
use robovec_ir::verifier::verify_function;
use robovec_ir::{split_state, Def, Function, Module, Operand, TrigFn};
use std::collections::HashMap;

/// Every rule of the module doc: trig with and without the other trig variable, `+ − × /`,
/// `sqrt`, the fused family, a constant output, an input used directly as an output.
const SRC: &str = "func @f {
  phase atomised
  input %q[1]
  input %q[2]
  input %qd[1]
  input %m
  %S1 = sin %q[1]
  %C1 = cos %q[1]
  %C2 = cos %q[2]
  %a = mul %S1, %qd[1]
  %b = div %a, %C2
  %c = sub 0.0, %b
  %d = mul %c, %m
  %e = add %d, %C1
  %r = add %e, 3.0
  %s = call @sqrt(%r)
  %t = call @fma(%s, %q[2], %a)
  %u = call @fms(%t, %m, %qd[1])
  %w = call @fnma(%u, %C1, %q[2])
  %k = mul %q[1], 2.5
  output Qq[1] = %w
  output Qq[2] = %k
  output Qq[3] = %s
  output T = %q[2]
  output c[1] = 1.5
  output z = %m
}
";

fn point(name: &str) -> f64 {
    pseudo_random_input(name, 7) * 0.8
}

/// Central finite differences of `f`'s outputs against `g`'s derivative outputs, for each input
/// `wrt` matches: the largest `|d − fd| / (1 + |d|)`.
fn worst_against_finite_differences(f: &Function, g: &Function, wrt: &[&str]) -> f64 {
    let base: HashMap<String, f64> =
        f.inputs.iter().map(|&v| (f.name_of(v).to_string(), point(f.name_of(v)))).collect();
    let got: HashMap<String, f64> = eval::<f64>(g, |n| base[n]).into_iter().collect();
    let mut worst = 0.0f64;
    for &x in &f.inputs {
        let xn = f.name_of(x);
        if !wrt.iter().any(|e| matches(e, xn)) {
            continue;
        }
        let h = 1e-6 * base[xn].abs().max(1.0);
        let at = |dx: f64| -> HashMap<String, f64> {
            eval::<f64>(f, |n| if n == xn { base[n] + dx } else { base[n] }).into_iter().collect()
        };
        let (up, down) = (at(h), at(-h));
        for o in &f.outputs {
            if split_state(&o.name).1 != split_state(xn).1 {
                continue;
            }
            let fd = (up[&o.name] - down[&o.name]) / (2.0 * h);
            let name = derivative_name(&o.name, xn);
            let d = *got.get(&name).unwrap_or_else(|| panic!("no output {name}"));
            // The difference quotient's own rounding: ε·|f|/h from each evaluation, times up to
            // 10³ for the rounding the evaluation of up to 300 ops accumulates (a random DAG
            // with outputs of 5.5·10⁶ measured 1.4·10⁻⁵ here otherwise: seed 18160559881201453304).
            let noise = 1e3 * f64::EPSILON * up[&o.name].abs().max(down[&o.name].abs()) / h;
            worst = worst.max(((d - fd).abs() - noise).max(0.0) / (1.0 + d.abs()));
        }
    }
    worst
}

fn diffed(src: &Function, wrt: &[&str], mode: Option<Mode>) -> (Function, Mode) {
    let mut g = src.clone();
    let wrt: Vec<String> = wrt.iter().map(|s| s.to_string()).collect();
    let mode = differentiate(&mut g, &wrt, mode, &Ticker::default()).unwrap();
    assert!(verify_function(&g).is_empty(), "{:?}\n{g}", verify_function(&g));
    (g, mode)
}

#[test]
fn every_rule_matches_finite_differences_in_both_modes() {
    let f = parse(SRC).unwrap().functions.remove(0);
    for mode in [Mode::Forward, Mode::Reverse] {
        let (g, _) = diffed(&f, &["q", "qd", "m"], Some(mode));
        // 6 outputs × 4 inputs
        assert_eq!(g.outputs.len(), 6 + 24, "{mode:?}");
        let worst = worst_against_finite_differences(&f, &g, &["q", "qd", "m"]);
        assert!(worst < 1e-6, "{mode:?}: {worst}");
        // The original outputs keep their values bit for bit.
        let a = eval::<f64>(&f, point);
        let b = eval::<f64>(&g, point);
        for (n, y) in a {
            assert_eq!(b.iter().find(|(m, _)| *m == n).unwrap().1.to_bits(), y.to_bits(), "{n}");
        }
    }
}

#[test]
fn names_constants_and_structural_zeros() {
    let f = parse(SRC).unwrap().functions.remove(0);
    let (g, _) = diffed(&f, &["q"], Some(Mode::Forward));
    let out = |n: &str| g.outputs.iter().find(|o| o.name == n).unwrap_or_else(|| panic!("{n}")).value;
    // ∂(2.5·q[1])/∂q[1] = 2.5, a constant: no op; ∂/∂q[2] is zero by structure.
    assert_eq!(out("dQq_dq[2][1]"), Operand::Const(2.5));
    assert_eq!(out("dQq_dq[2][2]"), Operand::Const(0.0));
    assert_eq!(out("dT_dq[2]"), Operand::Const(1.0));
    assert_eq!(out("dT_dq[1]"), Operand::Const(0.0));
    assert_eq!(out("dc_dq[1][1]"), Operand::Const(0.0));
    // The outputs follow the originals, grouped by output, in wrt order.
    let names: Vec<&str> = g.outputs.iter().skip(6).take(4).map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["dQq_dq[1][1]", "dQq_dq[1][2]", "dQq_dq[2][1]", "dQq_dq[2][2]"]);
    // sin q[2] was needed for ∂cos q[2]: made once, as a trig variable.
    let sines: Vec<_> = g.body.iter().filter(|&&v| matches!(g.value(v).def, Def::Trig(TrigFn::Sin, _))).collect();
    assert_eq!(sines.len(), 2);
    // The text form prints and reads back.
    let text = Module { functions: vec![g.clone()] }.to_string();
    assert_eq!(parse(&text).unwrap().to_string(), text);
    // auto takes the mode that writes fewer ops here (it counts derivative terms, not ops).
    for wrt in [&["q", "qd", "m"][..], &["q"], &["m"]] {
        let ops = |m| diffed(&f, wrt, Some(m)).0.op_counts().total;
        let (fw, rv) = (ops(Mode::Forward), ops(Mode::Reverse));
        let chosen = diffed(&f, wrt, None).1;
        assert!(ops(chosen) <= fw.min(rv), "{wrt:?}: {chosen:?}, forward {fw} ops, reverse {rv}");
    }
}

#[test]
fn reverse_is_chosen_for_few_outputs_and_gives_the_same_derivatives() {
    let f =
        parse("func @f { phase atomised input %a input %b input %c %x = mul %a, %b %y = mul %x, %c output y = %y }")
            .unwrap()
            .functions
            .remove(0);
    let (r, mode) = diffed(&f, &["a", "b", "c"], None);
    assert_eq!(mode, Mode::Reverse);
    let (fw, _) = diffed(&f, &["a", "b", "c"], Some(Mode::Forward));
    let x: HashMap<String, f64> = eval::<f64>(&r, point).into_iter().collect();
    let y: HashMap<String, f64> = eval::<f64>(&fw, point).into_iter().collect();
    for n in ["dy_da", "dy_db", "dy_dc"] {
        assert!((x[n] - y[n]).abs() <= 1e-15 * y[n].abs().max(1.0), "{n}: {} {}", x[n], y[n]);
    }
    // ∂y/∂c = a·b is x itself: no op.
    assert_eq!(r.outputs.iter().find(|o| o.name == "dy_dc").unwrap().value, Operand::Value(r.lookup("x").unwrap()));
}

#[test]
fn a_callback_on_the_path_and_a_taken_name_are_errors() {
    let f = parse("func @f { phase atomised input %q[1] input %p %x = call @user_ExtForces.1[2](%q[1]) %y = call @user_ExtForces.1[3](%p) output Qq[1] = %x output Qq[2] = %y }")
        .unwrap()
        .functions
        .remove(0);
    let mut g = f.clone();
    let e = differentiate(&mut g, &["q".into()], None, &Ticker::default()).unwrap_err();
    assert!(
        matches!(&e, Failure::Message(m) if m.contains("`%x` calls the user callback `@user_ExtForces.1`")),
        "{e:?}"
    );
    // A callback off the path has derivative zero.
    let off = parse("func @f { phase atomised input %q[1] input %p %x = mul %q[1], %q[1] %y = call @user_ExtForces.1[3](%p) output Qq[1] = %x output Qq[2] = %y }")
        .unwrap()
        .functions
        .remove(0);
    let (g, _) = diffed(&off, &["q"], None);
    assert_eq!(g.outputs.iter().find(|o| o.name == "dQq_dq[2][1]").unwrap().value, Operand::Const(0.0));
    let taken = parse("func @f { phase atomised input %a %x = mul %a, %a output y = %x output dy_da = %a }").unwrap();
    let e = differentiate(&mut taken.functions[0].clone(), &["a".into()], None, &Ticker::default()).unwrap_err();
    assert!(matches!(&e, Failure::Message(m) if m.contains("`dy_da`")), "{e:?}");
}

#[test]
fn interleaved_states_are_differentiated_per_state() {
    let f = parse(SRC).unwrap().functions.remove(0);
    let two = crate::interleave::interleave_function(&f, 2).unwrap();
    let (g, _) = diffed(&two, &["q"], None);
    assert!(g.outputs.iter().any(|o| o.name == "dQq_dq[1][2]#1"));
    assert_eq!(g.outputs.len(), 12 + 2 * 6 * 2);
    assert!(worst_against_finite_differences(&two, &g, &["q"]) < 1e-6);
}

#[test]
fn the_pass_refuses_an_unknown_family_and_takes_every_input_without_wrt() {
    let mut m = parse(SRC).unwrap();
    let e = Diff { wrt: vec!["qdd".into()], mode: None }.run(&mut m, &mut PassContext::default()).unwrap_err();
    assert!(e.to_string().contains("no input matches `qdd`"), "{e}");
    // Without wrt: every input, the full Jacobian (6 outputs × 4 inputs).
    Diff { wrt: vec![], mode: None }.run(&mut m, &mut PassContext::default()).unwrap();
    assert_eq!(m.functions[0].outputs.len(), 6 + 24);
    assert!(m.functions[0].outputs.iter().any(|o| o.name == "dQq_dm[1]"));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random Robotran-like DAGs (products, sums, negations, trig variables of the joint
    /// angles): both modes against central finite differences, with respect to `q` and `m`.
    #[test]
    fn random_dags_match_finite_differences(seed in any::<u64>(), n in 20usize..300) {
        let f = robovec_testkit::dag_gen::generate(n, seed);
        for mode in [Mode::Forward, Mode::Reverse] {
            let (g, _) = diffed(&f, &["q", "m"], Some(mode));
            let worst = worst_against_finite_differences(&f, &g, &["q", "m"]);
            prop_assert!(worst < 1e-5, "{:?} n={} seed={}: {}", mode, n, seed, worst);
        }
    }
}

#[test]
fn the_time_limit_in_the_sweep_is_a_stop_in_both_modes() {
    let f = robovec_testkit::dag_gen::generate(200, 1);
    for mode in [Mode::Forward, Mode::Reverse] {
        let e = differentiate(&mut f.clone(), &["q".into()], Some(mode), &Ticker::new(None, Some(5))).unwrap_err();
        assert!(matches!(e, Failure::Stopped), "{mode:?}: {e:?}");
    }
}

/// The random DAG whose outputs reach 5.5·10⁶: the difference quotient's rounding, not the
/// derivative, is what differs there (found by CI's run of the property test above).
#[test]
fn a_dag_with_large_outputs_matches_finite_differences_within_their_rounding() {
    let f = robovec_testkit::dag_gen::generate(200, 18160559881201453304);
    for mode in [Mode::Forward, Mode::Reverse] {
        let (g, _) = diffed(&f, &["q", "m"], Some(mode));
        let worst = worst_against_finite_differences(&f, &g, &["q", "m"]);
        assert!(worst < 1e-5, "{mode:?}: {worst}");
    }
}
