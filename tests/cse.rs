//! `cse` on every straight-line corpus function (atomised, and after
//! `zero-removal,balance`): every output keeps its bits in f64 and f32, the op count drops by
//! what the pass dropped, and no op equal to an earlier one is left — checked here by
//! rebuilding each op's key from its printed operands, independently of the pass's hashing.

use std::collections::HashSet;

use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::{BinOp, Def, Function, Module, Operand};
use robovec_passes::cse::cse_function;

use crate::common::{corpus_files, is_loop_file};

fn pipeline(m: &mut Module, p: &str) {
    let mut cx = robovec_passes::PassContext::default();
    for e in robovec_passes::pipeline::parse_pipeline(p).unwrap() {
        robovec_passes::build_pass(&e).unwrap().run(m, &mut cx).unwrap();
    }
}

/// The op of `v` as text with sorted operands for `+` and `*`; `None` for calls and inputs.
fn op_text(f: &Function, v: robovec_ir::Value) -> Option<String> {
    let o = |x: &Operand| match x {
        Operand::Value(v) => format!("%{}", f.name_of(*v)),
        Operand::Const(c) => format!("{:#x}", c.to_bits()),
    };
    match &f.value(v).def {
        Def::Binary(op, a, b) => {
            let (mut x, mut y) = (o(a), o(b));
            if matches!(op, BinOp::Add | BinOp::Mul) && y < x {
                std::mem::swap(&mut x, &mut y);
            }
            Some(format!("{} {x} {y}", op.mnemonic()))
        }
        Def::Trig(t, a) => Some(format!("{t:?} %{}", f.name_of(*a))),
        _ => None,
    }
}

fn bits<T: Into<f64> + Copy>(v: &[(String, T)]) -> Vec<(String, u64)> {
    v.iter().map(|(n, x)| (n.clone(), (*x).into().to_bits())).collect()
}

#[test]
fn merged_ops_keep_every_output_bit_and_leave_no_repeat() {
    let files: Vec<_> = corpus_files().into_iter().filter(|p| !is_loop_file(p)).collect();
    let (mut before_total, mut after_total) = (0usize, 0usize);
    for p in &files {
        for pre in ["atomise", "atomise,zero-removal,balance"] {
            let (mut m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|e| panic!("{}", e.message()));
            pipeline(&mut m, pre);
            for f in &m.functions {
                let mut g = f.clone();
                let dropped = cse_function(&mut g);
                let label = format!("{} {} after {pre}", p.display(), f.name);
                assert!(robovec_ir::verifier::verify_function(&g).is_empty(), "{label}: does not verify");
                assert_eq!(g.body.len() + dropped, f.body.len(), "{label}");
                assert_eq!(g.outputs.len(), f.outputs.len(), "{label}");
                for seed in 0..2 {
                    let inp = |n: &str| pseudo_random_input(n, seed);
                    assert_eq!(bits(&eval::<f64>(f, inp)), bits(&eval::<f64>(&g, inp)), "{label}: f64");
                    assert_eq!(bits(&eval::<f32>(f, inp)), bits(&eval::<f32>(&g, inp)), "{label}: f32");
                }
                let mut seen = HashSet::new();
                for &v in &g.body {
                    if let Some(t) = op_text(&g, v) {
                        assert!(seen.insert(t.clone()), "{label}: `{t}` is left twice");
                    }
                }
                if pre == "atomise" {
                    before_total += f.body.len();
                    after_total += g.body.len();
                }
            }
        }
    }
    // The corpus repeats ops: something must merge (a pass that merges nothing passes the
    // checks above too).
    assert!(after_total < before_total * 95 / 100, "{before_total} -> {after_total} ops");
}

#[test]
fn coman_dirdyna_after_cse_places_in_fewer_cycles() {
    // The same placement search on fewer ops: cycles at N = 2 must not grow and ops must drop.
    let p = crate::common::corpus_dir().join("c/coman_longarms__mbs_dirdyna_coman_robotran.c");
    let run = |pipe: &str| {
        let dir = crate::common::tmp(&format!("cse_place_{}", pipe.len()));
        let report = dir.join("r.json");
        let o = crate::common::opt(&[
            p.to_str().unwrap(),
            &format!("-passes={pipe}"),
            &format!("-report={}", report.display()),
            "-o",
            "/dev/null",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        (r["stats"]["ops"]["total"].as_u64().unwrap(), r["placement"]["cycles"].as_u64().unwrap())
    };
    let (ops0, cyc0) = run("atomise,place<pe=2;search=0;restarts=0>");
    let (ops1, cyc1) = run("atomise,cse,place<pe=2;search=0;restarts=0>");
    assert!(ops1 < ops0 * 90 / 100, "{ops0} -> {ops1} ops");
    assert!(cyc1 < cyc0, "{cyc0} -> {cyc1} cycles");
}
