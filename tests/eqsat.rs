//! `eqsat` on the corpus and from the command line.
//!
//! On every straight-line corpus function (atomised): the rewritten IR verifies, its critical
//! path is no longer, it has no more ops than the op budget allows, it evaluates close to the
//! original (f64, against a rounding-error bound computed here), and it still places at N = 8
//! and simulates bit for bit (`place` + `sim`).
//!
//! Test time (debug build, 2 cores; a few seconds): windows of 5 leaves; a function of more than
//! 600 ops is sampled — `dce` keeps its first 3 outputs and what they need — so large files
//! (Walkman, CoMan, Mazda, Jeep dirdyna) cost a fraction of their size; of a file with more than
//! 4 functions (the sensor files) every third function is checked. The op-budget run (budget 1)
//! is made on functions of at most 300 ops after sampling.
//!
//! **Error bound.** Over + − × with exact leaves, a result computed with at most D roundings on
//! any path satisfies |fl − exact| ≤ γ_D·M, γ_k = k·u/(1 − k·u), u = 2⁻⁵³, where M is the
//! expression evaluated with |leaves| and − as + (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, §3.1). Both forms obey it, so |new − old| ≤ γ_D·(M_old + M_new) with D the larger
//! depth (constants folded by the pass are counted as roundings of the original's depth). Leaves
//! are inputs, constants and trig values (computed identically in both forms). Outputs that
//! depend on a `div` or a call (5 files) use a first-order running error bound instead:
//! E(a±b) = Ea + Eb + u|r|, E(a·b) = |a|Eb + |b|Ea + EaEb + u|r|,
//! E(a/b) = (Ea + |r|Eb)/(|b| − Eb) + u|r|, E(√a) = min(√Ea, Ea/√a) + u|r|, and a callback's
//! stand-in Σ wₖaₖ (|wₖ| ≤ 1): ΣEₖ + γ₂ₙ·Σ|aₖ|.

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::interp::{eval_values, pseudo_random_input};
use robovec_ir::{verifier, BinOp, Def, Function, Module, Operand};
use robovec_passes::atomise::atomise_function;
use robovec_passes::dce::Dce;
use robovec_passes::eqsat::rules::rules;
use robovec_passes::eqsat::{eqsat_function, EqsatOptions};
use robovec_passes::place::{place_function, PlaceOptions};
use robovec_passes::sim::verify_placement;
use robovec_passes::{Pass, PassContext};

use crate::common::{corpus_files, is_loop_file};

const U: f64 = 1.0 / 9007199254740992.0; // 2^-53

fn gamma(k: u32) -> f64 {
    let ku = k as f64 * U;
    ku / (1.0 - ku)
}

/// Per value: (M, D, running error bound E, depends on a div or call).
fn bounds(f: &Function, vals: &[f64]) -> Vec<(f64, u32, f64, bool)> {
    let mut b = vec![(0.0, 0u32, 0.0, false); f.values.len()];
    for v in &f.inputs {
        b[v.index()] = (vals[v.index()].abs(), 0, 0.0, false);
    }
    let get = |b: &[(f64, u32, f64, bool)], o: &Operand| match o {
        Operand::Value(x) => (b[x.index()], vals[x.index()]),
        Operand::Const(c) => ((c.abs(), 0, 0.0, false), *c),
    };
    for &v in &f.body {
        let r = vals[v.index()].abs();
        b[v.index()] = match &f.value(v).def {
            Def::Binary(op, x, y) => {
                let (((ma, da, ea, ta), a), ((mb, db, eb, tb), bb)) = (get(&b, x), get(&b, y));
                let (m, e) = match op {
                    BinOp::Add | BinOp::Sub => (ma + mb, ea + eb + U * r),
                    BinOp::Mul => (ma * mb, a.abs() * eb + bb.abs() * ea + ea * eb + U * r),
                    BinOp::Div => {
                        let e = if bb.abs() > eb { (ea + r * eb) / (bb.abs() - eb) + U * r } else { f64::INFINITY };
                        (r, e)
                    }
                };
                (m, 1 + da.max(db), e * (1.0 + 1e-6), ta || tb || *op == BinOp::Div)
            }
            Def::Call(c, args) => {
                let a: Vec<_> = args.iter().map(|o| get(&b, o)).collect();
                let e = if c.name == "sqrt" && a.len() == 1 {
                    let (((_, _, ea, _), x),) = (a[0],);
                    let s = if x > 0.0 { (ea / x.sqrt()).min(ea.sqrt()) } else { ea.sqrt() };
                    s + U * r
                } else {
                    let se: f64 = a.iter().map(|((_, _, e, _), _)| e).sum();
                    se + gamma(2 * a.len() as u32 + 1) * a.iter().map(|(_, x)| x.abs()).sum::<f64>()
                };
                (r, 0, e * (1.0 + 1e-6), true)
            }
            _ => (r, 0, 0.0, false), // trig: the same value in both forms
        };
    }
    b
}

fn output_bounds(f: &Function, input: impl Fn(&str) -> f64) -> Vec<(f64, (f64, u32, f64, bool))> {
    let vals = eval_values::<f64>(f, input);
    let b = bounds(f, &vals);
    f.outputs
        .iter()
        .map(|o| match o.value {
            Operand::Value(v) => (vals[v.index()], b[v.index()]),
            Operand::Const(c) => (c, (c.abs(), 0, 0.0, false)),
        })
        .collect()
}

/// A function of at most ~1,500 ops: itself, or its first 6 outputs and what they need.
fn sampled(a: Function) -> (Function, bool) {
    if a.op_counts().total <= 600 {
        return (a, false);
    }
    let keep: Vec<String> = a.outputs.iter().take(3).map(|o| o.name.clone()).collect();
    let mut m = Module { functions: vec![a] };
    Dce { keep: Some(keep) }.run(&mut m, &mut PassContext::default()).unwrap();
    (m.functions.pop().unwrap(), true)
}

#[test]
fn corpus_eqsat_is_valid_no_slower_within_budget_close_and_simulates() {
    let lat = Latencies::default();
    let (rules0, opts) = (rules(true), EqsatOptions { window: 5, ..EqsatOptions::default() });
    let (mut funcs, mut sampled_n, mut outputs, mut via_running) = (0, 0, 0, 0);
    let mut te = 0.0;
    let (mut cp_sum, mut cp_new_sum, mut worst) = (0u64, 0u64, (0.0f64, String::new()));
    let (mut critical_from, mut critical_sum) = (0u64, 0u64);
    for p in corpus_files().into_iter().filter(|p| !is_loop_file(p)) {
        let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        // Sensor files repeat one prefix in every function: every third function is enough.
        let step = if m.functions.len() > 4 { 3 } else { 1 };
        for f in m.functions.iter().step_by(step) {
            let (a, s) = sampled(atomise_function(f));
            let t1 = std::time::Instant::now();
            if a.op_counts().total == 0 {
                continue;
            }
            let name = format!("{} @{}", p.file_name().unwrap().to_string_lossy(), f.name);
            let mut g = a.clone();
            let st = eqsat_function(&mut g, &opts, &rules0);
            assert!(verifier::verify_function(&g).is_empty(), "{name}: rewritten IR does not verify");
            let (cp0, cp1) = (compute_timing(&a, &lat).1.asap_cycle, compute_timing(&g, &lat).1.asap_cycle);
            assert!(cp1 <= cp0, "{name}: critical path {cp0} -> {cp1}");
            assert_eq!((st.cp_before, st.cp_after), (cp0, cp1), "{name}: reported critical paths");
            assert!(g.op_counts().total <= a.op_counts().total, "{name}: budget 0 added ops");
            assert_eq!(g.outputs.len(), a.outputs.len());
            for seed in 1..=2u64 {
                let input = |n: &str| pseudo_random_input(n, seed);
                let (old, new) = (output_bounds(&a, input), output_bounds(&g, input));
                for (k, ((y0, (m0, d0, e0, t0)), (y1, (m1, d1, e1, t1)))) in old.iter().zip(&new).enumerate() {
                    let bound = if *t0 || *t1 {
                        via_running += 1;
                        e0 + e1
                    } else {
                        gamma(*d0.max(d1)) * (m0 + m1)
                    };
                    let diff = (y1 - y0).abs();
                    assert!(
                        diff <= bound,
                        "{name} {} seed {seed}: {y0:e} vs {y1:e}, bound {bound:e}",
                        a.outputs[k].name
                    );
                    if bound > 0.0 && diff / bound > worst.0 {
                        worst = (diff / bound, format!("{name} {}", a.outputs[k].name));
                    }
                    outputs += 1;
                }
            }
            te += t1.elapsed().as_secs_f64();
            let mut placed = g.clone();
            placed.placement = Some(place_function(&g, &PlaceOptions::with_pes(8)));
            verify_placement(&placed, &[1]).unwrap_or_else(|e| panic!("{name}: N=8: {e}"));
            if g.op_counts().total <= 300 {
                let mut h = a.clone();
                let o1 = EqsatOptions { budget: 1, ..opts.clone() };
                let st1 = eqsat_function(&mut h, &o1, &rules0);
                assert!(verifier::verify_function(&h).is_empty(), "{name}: budget 1");
                assert!(h.op_counts().total <= a.op_counts().total + st1.windows_replaced as u64, "{name}: budget 1");
                assert!(compute_timing(&h, &lat).1.asap_cycle <= cp0, "{name}: budget 1 critical path");
                // Critical windows: overlapping, across shared values; each replaced window adds
                // at most `budget` ops net, and no root gets later.
                let mut c = a.clone();
                let oc = EqsatOptions { critical: true, slack: 12, budget: 2, ..opts.clone() };
                let sc = eqsat_function(&mut c, &oc, &rules0);
                assert!(verifier::verify_function(&c).is_empty(), "{name}: critical windows");
                assert!(
                    c.op_counts().total <= a.op_counts().total + 2 * sc.windows_replaced as u64,
                    "{name}: critical windows over budget: {sc}"
                );
                let cpc = compute_timing(&c, &lat).1.asap_cycle;
                assert!(cpc <= cp0 && sc.cp_after == cpc, "{name}: critical windows {cp0} -> {cpc}");
                critical_sum += cpc as u64;
                critical_from += cp0 as u64;
            }
            funcs += 1;
            sampled_n += s as usize;
            cp_sum += cp0 as u64;
            cp_new_sum += cp1 as u64;
        }
    }
    assert!(funcs >= 30, "only {funcs} functions");
    assert!(cp_new_sum < cp_sum * 9 / 10, "eqsat should shorten critical paths: {cp_sum} -> {cp_new_sum}");
    assert!(critical_sum < critical_from, "critical windows shortened nothing: {critical_from} -> {critical_sum}");
    println!(
        "{funcs} functions ({sampled_n} sampled), {outputs} outputs checked ({via_running} by the running bound); \
         critical paths {cp_sum} -> {cp_new_sum} cycles (critical windows on the small ones: \
         {critical_from} -> {critical_sum}); worst |new - old| / bound {:.3} at {}; eqsat + checks {te:.2} s",
        worst.0, worst.1
    );
}

fn opt(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_robovec-opt")).args(args).output().expect("robovec-opt runs")
}

#[test]
fn cli_runs_the_example_rules_and_prints_eqsat_stats() {
    let o = opt(&["tests/ir/eqsat/late_leaf.rvir", "-passes=eqsat<rules=examples/rules/exact.rules>", "-stats"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("@f: eqsat: windows 2 tried, 2 replaced"), "{err}");
    assert!(err.contains("stop reasons: saturated 2, iteration limit 0, node limit 0, time limit 0, other 0"), "{err}");
    assert!(err.contains("critical path 57 -> 36 cycles"), "{err}");
}

#[test]
fn report_carries_eqsat_windows_and_stop_reasons() {
    let dir = std::env::temp_dir().join(format!("robovec-eqsat-report-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let report = dir.join("report.json");
    let o = opt(&[
        "tests/ir/eqsat/late_leaf.rvir",
        "-passes=eqsat",
        &format!("-report={}", report.display()),
        "-o",
        dir.join("out.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let e = &r["eqsat"][0];
    assert_eq!(e["function"], "f");
    assert_eq!(e["windows_tried"], 2, "{e}");
    assert_eq!(e["stops"]["saturated"], 2, "{e}");
    assert_eq!((e["cp_before"].as_u64(), e["cp_after"].as_u64()), (Some(57), Some(36)), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cli_bad_rules_file_is_an_input_error_with_a_located_diagnostic() {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("eqsat-rules");
    std::fs::create_dir_all(&d).unwrap();
    let bad = d.join("bad.rules");
    std::fs::write(&bad, "# fine\nok: (+ ?a 0) => ?a\nnope: (* ?a ?b) => (* ?b ?c)\n").unwrap();
    let out = d.join("out.rvir");
    let o = opt(&[
        "tests/ir/eqsat/late_leaf.rvir",
        &format!("-passes=eqsat<rules={}>", bad.display()),
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // Line 3, column 26 is the `?c` of `(* ?b ?c)` (0-based byte 25 of the line).
    assert!(err.contains(&format!("{}:3:26", bad.display())), "{err}");
    assert!(err.contains("variable `?c` is not bound by the left-hand side"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "no output on bad input");
    let o = opt(&["tests/ir/eqsat/late_leaf.rvir", "-passes=eqsat<rules=/nonexistent/x.rules>"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read rules file"));
}
