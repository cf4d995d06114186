//! `inline` and `specialize` (issue 5) on hand-written cases, the corpus and the command line.

use std::collections::BTreeMap;
use std::process::Command;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::text::parse;
use robovec_ir::{verifier, Def, Function};
use robovec_passes::place::{place_function, PlaceOptions};
use robovec_passes::sim::verify_placement;

use crate::common::corpus_dir;
use crate::tree_height::{check_error_bound, corpus_functions, run};

fn cp(f: &Function) -> u32 {
    compute_timing(f, &Latencies::default()).1.asap_cycle
}

#[test]
fn inline_lets_balance_pair_terms_across_equations() {
    // s = (a + b) + c is shared by t = s + x and u = s - y. Balanced alone: s at 24, t and u at
    // 36. Inlined, t's cluster is {a, b, c, x} and u's {a, b, c, -y}: two levels, 24 cycles, for
    // one more copy of s (2 ops).
    let src = "func @f { phase atomised input %a input %b input %c input %x input %y
        %s.1 = add %a, %b %s = add %s.1, %c
        %t = add %s, %x
        %u = sub %s, %y
        output o1 = %t output o2 = %u }";
    let f = parse(src).unwrap().functions.remove(0);
    let g = run("inline<max-uses=2>", &f);
    assert!(verifier::verify_function(&g).is_empty());
    assert_eq!(g.op_counts().total, f.op_counts().total + 2, "one more copy of s's 2 ops");
    let input = |n: &str| pseudo_random_input(n, 5);
    assert_eq!(eval::<f64>(&f, input), eval::<f64>(&g, input), "copies compute the same ops");
    let b0 = run("balance", &f);
    let b1 = run("inline<max-uses=2>,balance", &f);
    assert_eq!((cp(&b0), cp(&b1)), (36, 24));
    assert_eq!((b0.op_counts().total, b1.op_counts().total), (4, 6));
    // K = 1 changes nothing.
    assert_eq!(run("inline<max-uses=1>", &f).to_string(), f.to_string());
}

#[test]
fn inline_and_balance_on_the_corpus_are_exact_shorter_and_simulate() {
    let opts = PlaceOptions::with_pes(8);
    let (mut ops0, mut ops1, mut better) = (0, 0, 0);
    for (name, f) in corpus_functions() {
        let g = run("inline<max-uses=3>", &f);
        assert!(verifier::verify_function(&g).is_empty(), "{name}");
        let input = |n: &str| pseudo_random_input(n, 7);
        for ((o, x), (_, y)) in eval::<f64>(&f, input).iter().zip(&eval::<f64>(&g, input)) {
            assert_eq!(x.to_bits(), y.to_bits(), "{name} {o}: inlining copies ops exactly");
        }
        let b0 = run("balance", &f);
        let mut b1 = run("inline<max-uses=3>,balance", &f);
        assert!(cp(&b1) <= cp(&b0), "{name}: inline,balance {} > balance {}", cp(&b1), cp(&b0));
        better += (cp(&b1) < cp(&b0)) as u32;
        ops0 += f.op_counts().total;
        ops1 += b1.op_counts().total;
        b1.placement = Some(place_function(&b1, &opts));
        verify_placement(&b1, &[3]).unwrap_or_else(|e| panic!("{name} inline,balance: {e}"));
    }
    println!("inline<max-uses=3>,balance: ops {ops0} -> {ops1}; shorter than balance alone on {better} functions");
    assert!(better >= 10);
}

#[test]
fn distribute_shortens_a_product_of_a_sum_inside_a_sum() {
    // o = (a + b + c)·x + y: balanced, the sum is ready at 24, the product at 31, o at 43.
    // Distributed, o = a·x + b·x + c·x + y: products at 7, two levels of adds: 31, for two
    // more muls.
    let src = "func @f { phase atomised input %a input %b input %c input %x input %y
        %s.1 = add %a, %b %s = add %s.1, %c %p = mul %s, %x %o = add %p, %y output o = %o }";
    let f = parse(src).unwrap().functions.remove(0);
    let b0 = run("balance", &f);
    let b1 = run("distribute,balance", &f);
    assert_eq!((cp(&b0), cp(&b1)), (43, 31));
    assert_eq!((b0.op_counts().total, b1.op_counts().total), (4, 6));
    let input = |n: &str| pseudo_random_input(n, 9);
    let (x, y) = (eval::<f64>(&f, input)[0].1, eval::<f64>(&b1, input)[0].1);
    assert!((x - y).abs() <= 1e-14 * (1.0 + x.abs()), "{x} {y}");
}

#[test]
fn distribute_on_the_corpus_is_shorter_within_budget_bound_and_simulates() {
    let opts = PlaceOptions::with_pes(8);
    let (mut ops0, mut ops1, mut shorter, mut worst) = (0, 0, 0, 0.0f64);
    for (name, f) in corpus_functions() {
        let b = run("inline<max-uses=8>,balance", &f);
        let mut d = run("inline<max-uses=8>,distribute,balance", &f);
        assert!(verifier::verify_function(&d).is_empty(), "{name}");
        assert!(cp(&d) <= cp(&b), "{name}: distribute made it longer");
        assert!(
            d.op_counts().total as f64 <= 1.5 * run("inline<max-uses=8>", &f).op_counts().total as f64,
            "{name}: budget"
        );
        shorter += (cp(&d) < cp(&b)) as u32;
        ops0 += f.op_counts().total;
        ops1 += d.op_counts().total;
        let c = f.op_counts();
        if c.div + c.call == 0 {
            worst = worst.max(check_error_bound(&format!("{name} distribute"), &f, &d));
        }
        d.placement = Some(place_function(&d, &opts));
        verify_placement(&d, &[5]).unwrap_or_else(|e| panic!("{name} distribute: {e}"));
    }
    println!("inline<max-uses=8>,distribute,balance: ops {ops0} -> {ops1}; shorter than without distribute on {shorter} functions; worst error / bound {worst:.3}");
    assert!(shorter >= 10);
}

fn segway_dirdyna() -> Function {
    let p = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c");
    let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
    robovec_passes::atomise::atomise_function(&m.functions[0])
}

fn write_params(name: &str, params: &BTreeMap<String, f64>) -> String {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("inline_specialize");
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, serde_json::to_string(params).unwrap()).unwrap();
    p.display().to_string()
}

#[test]
fn specialize_on_the_segway_matches_the_original_with_the_same_parameters() {
    let f = segway_dirdyna();
    // Every model parameter known (pseudo-random), no external forces, and dpt[3][2] = 0.
    let mut params = BTreeMap::new();
    for &v in &f.inputs {
        let n = f.name_of(v);
        let x = if n.starts_with("frc") || n.starts_with("trq") || n == "dpt[3][2]" {
            0.0
        } else if ["dpt", "l[", "m[", "In[", "g["].iter().any(|p| n.starts_with(p)) {
            pseudo_random_input(n, 11)
        } else {
            continue;
        };
        params.insert(n.to_string(), x);
    }
    let g = run(&format!("specialize<params={}>", write_params("segway.json", &params)), &f);
    assert!(verifier::verify_function(&g).is_empty());
    assert!(g.inputs.iter().all(|&v| !params.contains_key(g.name_of(v))), "known inputs are gone");
    assert!(g.body.iter().all(|&v| !matches!(g.value(v).def, Def::Input)));
    let (n0, n1) = (f.op_counts().total, g.op_counts().total);
    assert!(n1 + 100 < n0, "no forces and a zero offset remove terms: {n0} -> {n1}");
    let input = |n: &str| params.get(n).copied().unwrap_or_else(|| pseudo_random_input(n, 4));
    for ((o, x), (_, y)) in eval::<f64>(&f, input).iter().zip(&eval::<f64>(&g, input)) {
        assert!((x - y).abs() <= 1e-12 * (1.0 + x.abs()), "{o}: {x:e} vs {y:e}");
    }
    // The zero offset alone removes every term it multiplies.
    let only: BTreeMap<String, f64> = [("dpt[3][2]".to_string(), 0.0)].into();
    let h = run(&format!("specialize<params={}>", write_params("dpt.json", &only)), &f);
    assert!(h.lookup("dpt[3][2]").is_none());
    assert!(h.op_counts().total < n0);
    println!("segway dirdyna specialised: {n0} -> {n1} ops; dpt[3][2] = 0 alone: {}", h.op_counts().total);
}

fn opt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robovec-opt")).args(args).output().expect("robovec-opt runs")
}

#[test]
fn cli_reports_what_the_rewrites_did_and_rejects_bad_parameter_files() {
    let ex = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";
    let o = opt(&[ex, "-passes=atomise,zero-removal,inline<max-uses=3>,balance", "-stats", "-o", "-"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("zero-removal: @invdyna: ops 48 -> 44"), "{err}");
    assert!(err.contains("inline<max-uses=3;max-size=64>: @invdyna:") && err.contains("ops added"), "{err}");
    assert!(err.contains("balance: @invdyna:"), "{err}");

    let bad = write_params("placeholder.json", &BTreeMap::new());
    std::fs::write(&bad, "{\"m[1]\": \"heavy\"}").unwrap();
    for (file, needle) in [(bad.as_str(), "line 1, column"), ("/nonexistent/p.json", "cannot read")] {
        let o = opt(&[ex, &format!("-passes=atomise,specialize<params={file}>"), "-o", "-"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains("specialize") && err.contains(needle), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let o = opt(&[ex, "-passes=atomise,specialize<params=>", "-o", "-"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("`params` needs a file name"));
    let o = opt(&[ex, "-passes=atomise,specialize", "-stats", "-o", "-"]);
    assert!(o.status.success(), "without parameters only constants fold (and dead code goes)");
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("specialize<params=none>: @invdyna: 0 inputs known, ops 48 -> 45")
    );
    for bad in ["inline<max-uses=0>", "distribute<max-growth=0.5>", "balance<lat-add=0>", "swap<pe=3>"] {
        let o = opt(&[ex, &format!("-passes=atomise,{bad}"), "-o", "-"]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
    }
    let o = opt(&["--print-passes"]);
    let listed = String::from_utf8_lossy(&o.stdout);
    for pass in
        ["zero-removal", "swap", "balance", "inline", "max-uses", "distribute", "max-growth", "specialize", "params"]
    {
        assert!(listed.contains(pass), "--print-passes lacks {pass}:\n{listed}");
    }
}
