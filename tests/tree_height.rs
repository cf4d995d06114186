//! The tree-height-reduction passes (issue 5) on every straight-line corpus file, checked by
//! means independent of the passes: a local sign-move checker for `zero-removal`, a separate
//! cluster extraction and greedy (Huffman-like) computation for `balance`, bit-exact
//! evaluation, the cycle-accurate simulator, and a rigorous rounding-error bound.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::interp::{eval, eval_values, pseudo_random_input};
use robovec_ir::{verifier, BinOp, Def, Function, Module, Operand};
use robovec_passes::atomise::atomise_function;
use robovec_passes::place::{place_function, PlaceOptions};
use robovec_passes::sim::verify_placement;
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::common::{corpus_files, is_loop_file};

/// Every atomised function with at least one op of every straight-line corpus file:
/// `(file @function, function)`.
pub fn corpus_functions() -> Vec<(String, Function)> {
    let mut v = Vec::new();
    for p in corpus_files().into_iter().filter(|p| !is_loop_file(p)) {
        let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        for f in &m.functions {
            let a = atomise_function(f);
            if a.op_counts().total > 0 {
                v.push((format!("{} @{}", p.file_name().unwrap().to_string_lossy(), f.name), a));
            }
        }
    }
    assert!(v.len() >= 60, "only {} corpus functions", v.len());
    v
}

/// Runs `pipeline` on a one-function module.
pub fn run(pipeline: &str, f: &Function) -> Function {
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut m = Module { functions: vec![f.clone()] };
    pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink()).unwrap_or_else(|e| panic!("{pipeline}: {e}"));
    m.functions.pop().unwrap()
}

fn cp(f: &Function, lat: &Latencies) -> u32 {
    compute_timing(f, lat).1.asap_cycle
}

fn is_zero_minus(f: &Function, v: robovec_ir::Value) -> bool {
    matches!(f.value(v).def, Def::Binary(BinOp::Sub, Operand::Const(c), _) if c == 0.0)
}

/// The `0 − x` ops of `f` that a local sign move removes without adding an op: every use of
/// the `0 − x` takes `−x` for free (`a + n` → `a − x`, `a − n` → `a + x`, a constant factor or
/// divisor takes the sign, `n·n` cancels) or becomes its own negation (`n − a` → `x + a`,
/// `n·a` → `x·a`, `n / a`) whose uses do the same, and no output or call needs a flipped value.
/// Such a move only replaces operands by earlier ones, so it never lengthens a path.
fn removable_zeros(f: &Function) -> Vec<String> {
    let n = f.values.len();
    let mut can_negate = vec![true; n];
    for o in &f.outputs {
        if let Operand::Value(v) = o.value {
            can_negate[v.index()] = false;
        }
    }
    // Backwards: a value can be negated when each of its uses absorbs or can be negated.
    let mut users: Vec<Vec<robovec_ir::Value>> = vec![Vec::new(); n];
    for &u in &f.body {
        f.value(u).def.for_each_value(|a| users[a.index()].push(u));
    }
    for &v in f.body.iter().rev() {
        for &u in &users[v.index()] {
            let ok = match &f.value(u).def {
                Def::Binary(op, a, b) => {
                    let (va, vb) = (*a == Operand::Value(v), *b == Operand::Value(v));
                    match op {
                        BinOp::Add if va && vb => can_negate[u.index()],
                        BinOp::Add => true,
                        BinOp::Sub if vb => true,
                        BinOp::Sub => can_negate[u.index()],
                        BinOp::Mul | BinOp::Div => {
                            (va && vb)
                                || matches!((a, b), (Operand::Const(_), _) | (_, Operand::Const(_)))
                                || can_negate[u.index()]
                        }
                    }
                }
                _ => false,
            };
            if !ok {
                can_negate[v.index()] = false;
                break;
            }
        }
    }
    f.body
        .iter()
        .filter(|&&v| is_zero_minus(f, v) && can_negate[v.index()])
        .map(|&v| f.name_of(v).to_string())
        .collect()
}

fn same_or_zeros(x: f64, y: f64) -> bool {
    x.to_bits() == y.to_bits() || (x == 0.0 && y == 0.0)
}

#[test]
fn zero_removal_is_exact_never_longer_and_leaves_no_removable_zero() {
    let lats = [
        Latencies::default(),
        Latencies { add: 1, mul: 1, div: 1, call: 1 },
        Latencies { add: 3, mul: 11, div: 5, call: 2 },
        Latencies { add: 20, mul: 2, div: 30, call: 9 },
    ];
    let (mut zeros_before, mut zeros_after, mut ops_before, mut ops_after) = (0, 0, 0, 0);
    for (name, f) in corpus_functions() {
        let count_zeros = |g: &Function| g.body.iter().filter(|&&v| is_zero_minus(g, v)).count();
        for lat in &lats {
            let pipeline = format!(
                "zero-removal<lat-add={};lat-mul={};lat-div={};lat-call={}>",
                lat.add, lat.mul, lat.div, lat.call
            );
            let g = run(&pipeline, &f);
            assert!(g.op_counts().total <= f.op_counts().total, "{name} {pipeline}: ops");
            assert!(cp(&g, lat) <= cp(&f, lat), "{name} {pipeline}: critical path {} > {}", cp(&g, lat), cp(&f, lat));
            assert_eq!(removable_zeros(&g), Vec::<String>::new(), "{name} {pipeline}: removable zeros remain");
        }
        let g = run("zero-removal", &f);
        for lat in &lats {
            assert!(cp(&g, lat) <= cp(&f, lat), "{name}: zero-removal (default latencies) is longer under {lat:?}");
        }
        zeros_before += count_zeros(&f);
        zeros_after += count_zeros(&g);
        ops_before += f.op_counts().total;
        ops_after += g.op_counts().total;
        for seed in [1, 2] {
            let input = |n: &str| pseudo_random_input(n, seed);
            for ((o, x), (_, y)) in eval::<f64>(&f, input).iter().zip(&eval::<f64>(&g, input)) {
                assert!(same_or_zeros(*x, *y), "{name} {o} seed {seed}: {x:e} vs {y:e}");
            }
            for ((o, x), (_, y)) in eval::<f32>(&f, input).iter().zip(&eval::<f32>(&g, input)) {
                assert!(same_or_zeros(*x as f64, *y as f64), "{name} {o} f32 seed {seed}: {x:e} vs {y:e}");
            }
        }
    }
    println!("zero-removal: `0 - x` ops {zeros_before} -> {zeros_after}, ops {ops_before} -> {ops_after}");
    assert!(zeros_after * 10 < zeros_before, "most zeros go");
}

#[test]
fn the_checker_flags_a_removable_zero() {
    let m = robovec_ir::text::parse(
        "func @f { phase atomised input %a input %b %n = sub 0.0, %a %s = add %b, %n %m = sub 0.0, %b %t = mul %m, %a output o = %s output p = %t }",
    )
    .unwrap();
    assert_eq!(removable_zeros(&m.functions[0]), vec!["n".to_string()]);
}

/// Ready time of every value when each maximal `+ −` or `*` cluster of `f` (interior values:
/// one use, by an op of the same kind, not an output) is evaluated as the greedy
/// two-earliest-first tree over its leaves, zero constants included; critical path = max.
fn greedy_bound(f: &Function, lat: &Latencies) -> u32 {
    let n = f.values.len();
    let kind = |v: robovec_ir::Value| match f.value(v).def {
        Def::Binary(BinOp::Add | BinOp::Sub, ..) => 1,
        Def::Binary(BinOp::Mul, ..) => 2,
        _ => 0,
    };
    let mut uses = vec![0u32; n];
    let mut user = vec![None; n];
    for &v in &f.body {
        f.value(v).def.for_each_value(|a| {
            uses[a.index()] += 1;
            user[a.index()] = Some(v);
        });
    }
    let mut output = vec![false; n];
    for o in &f.outputs {
        if let Operand::Value(v) = o.value {
            output[v.index()] = true;
        }
    }
    let interior: Vec<bool> = (0..n)
        .map(|i| {
            let v = robovec_ir::Value::with_number(i as u32);
            kind(v) != 0 && uses[i] == 1 && !output[i] && user[i].is_some_and(|u| kind(u) == kind(v))
        })
        .collect();
    let mut time = vec![0u32; n];
    let mut best = 0;
    for &v in &f.body {
        if interior[v.index()] {
            continue;
        }
        let t = match (kind(v), &f.value(v).def) {
            (0, Def::Binary(op, a, b)) => lat.of(op.kind()) + [a, b].iter().map(|o| leaf_time(o, &time)).max().unwrap(),
            (0, Def::Call(_, args)) => lat.call + args.iter().map(|o| leaf_time(o, &time)).max().unwrap_or(0),
            (0, _) => 0,
            (k, _) => {
                let mut leaves = Vec::new();
                let mut stack = vec![Operand::Value(v)];
                while let Some(o) = stack.pop() {
                    match o {
                        Operand::Value(x) if x == v || interior[x.index()] => {
                            let Def::Binary(_, a, b) = f.value(x).def else { unreachable!() };
                            stack.extend([a, b]);
                        }
                        o => leaves.push(leaf_time(&o, &time)),
                    }
                }
                huffman(&leaves, if k == 1 { lat.add } else { lat.mul })
            }
        };
        time[v.index()] = t;
        best = best.max(t);
    }
    best
}

fn leaf_time(o: &Operand, time: &[u32]) -> u32 {
    match o {
        Operand::Value(x) => time[x.index()],
        Operand::Const(_) => 0,
    }
}

fn huffman(ready: &[u32], lat: u32) -> u32 {
    let mut h: BinaryHeap<Reverse<u32>> = ready.iter().map(|&r| Reverse(r)).collect();
    while h.len() > 1 {
        let (Reverse(a), Reverse(b)) = (h.pop().unwrap(), h.pop().unwrap());
        h.push(Reverse(a.max(b) + lat));
    }
    h.pop().map_or(0, |Reverse(r)| r)
}

#[test]
fn balance_reaches_the_per_cluster_greedy_bound() {
    let lat = Latencies::default();
    let mut rows = Vec::new();
    for (name, f) in corpus_functions() {
        let bound = greedy_bound(&f, &lat);
        let c0 = cp(&f, &lat);
        assert!(bound <= c0, "{name}: the bound is at most the original");
        let z = run("zero-removal", &f);
        let s = run("zero-removal,swap", &f);
        let b = run("balance", &f);
        for (pass, g) in [("zero-removal", &z), ("swap", &s), ("balance", &b)] {
            assert!(verifier::verify_function(g).is_empty(), "{name} {pass}");
            assert!(g.op_counts().total <= f.op_counts().total, "{name} {pass}: ops");
        }
        assert!(cp(&z, &lat) <= c0 && cp(&s, &lat) <= cp(&z, &lat), "{name}: swap after zero removal");
        let cb = cp(&b, &lat);
        assert!(cb <= bound, "{name}: balance {cb} cycles > per-cluster greedy {bound}");
        // With other latencies too.
        let lat2 = Latencies { add: 5, mul: 9, div: 7, call: 3 };
        let b2 = run("balance<lat-add=5;lat-mul=9;lat-div=7;lat-call=3>", &f);
        assert!(cp(&b2, &lat2) <= greedy_bound(&f, &lat2), "{name}: balance with other latencies");
        rows.push(format!("{name}: {c0} -> bound {bound}, balance {cb} ({:.2})", cb as f64 / c0 as f64));
    }
    println!("{}", rows.join("\n"));
}

#[test]
fn rewritten_corpus_places_and_simulates_bit_exactly() {
    let opts = PlaceOptions::with_pes(8);
    let mut n = 0;
    for (name, f) in corpus_functions() {
        for pipeline in ["zero-removal", "zero-removal,swap", "balance"] {
            let mut g = run(pipeline, &f);
            g.placement = Some(place_function(&g, &opts));
            verify_placement(&g, &[1]).unwrap_or_else(|e| panic!("{name} {pipeline}: {e}"));
            n += 1;
        }
    }
    println!("{n} rewritten functions placed at N = 8 and simulated bit for bit");
}

/// γ_k = k·u / (1 − k·u) (Higham, *Accuracy and Stability of Numerical Algorithms*, §3.1).
fn gamma(k: u32, u: f64) -> f64 {
    let ku = k as f64 * u;
    ku / (1.0 - ku)
}

/// Per value of `f`: (M, D) — the value with absolute leaves and `−` as `+` (in f64), and the
/// number of rounded ops on the longest path to it.
fn magnitude_and_depth(f: &Function, input: impl Fn(&str) -> f64) -> (Vec<f64>, Vec<u32>) {
    let vals = eval_values::<f64>(f, &input);
    let mut m: Vec<f64> = vals.iter().map(|x| x.abs()).collect();
    let mut d = vec![0u32; f.values.len()];
    for &v in &f.body {
        if let Def::Binary(op, a, b) = f.value(v).def {
            let get = |o: Operand, m: &[f64], d: &[u32]| match o {
                Operand::Value(x) => (m[x.index()], d[x.index()]),
                Operand::Const(c) => (c.abs(), 0),
            };
            let ((ma, da), (mb, db)) = (get(a, &m, &d), get(b, &m, &d));
            m[v.index()] = if op == BinOp::Mul { ma * mb } else { ma + mb };
            d[v.index()] = 1 + da.max(db);
        }
    }
    (m, d)
}

/// Checks that the binary32 evaluation of `g` (a rewrite of `f`, + − × only) stays within
/// γ_{D+2}(2⁻²⁴)·M of the f64 evaluation of `f`, plus that reference's own bound
/// γ_{D₀+2}(2⁻⁵³)·M₀ (Higham's bound for a computed sum/product tree; the +2 covers the rounding
/// of leaves: constants and binary32 sin/cos). Inputs are exactly representable in binary32.
/// Returns the largest error / budget.
pub fn check_error_bound(what: &str, f: &Function, g: &Function) -> f64 {
    let mut worst = 0.0f64;
    for seed in [1, 2] {
        let input = |n: &str| pseudo_random_input(n, seed) as f32 as f64;
        let reference = eval::<f64>(f, input);
        let computed = eval::<f32>(g, input);
        let (m0, d0) = magnitude_and_depth(f, input);
        let (m1, d1) = magnitude_and_depth(g, input);
        for ((o, x), ((_, y), (of, og))) in reference.iter().zip(computed.iter().zip(f.outputs.iter().zip(&g.outputs)))
        {
            let at = |op: &Operand, m: &[f64], d: &[u32]| match op {
                Operand::Value(v) => (m[v.index()], d[v.index()]),
                Operand::Const(k) => (k.abs(), 0),
            };
            let ((mf, df), (mg, dg)) = (at(&of.value, &m0, &d0), at(&og.value, &m1, &d1));
            let budget = gamma(dg + 2, 2f64.powi(-24)) * mg * (1.0 + 1e-9) + gamma(df + 2, 2f64.powi(-53)) * mf;
            let err = (*y as f64 - x).abs();
            assert!(err <= budget, "{what} {o} seed {seed}: error {err:e} > budget {budget:e}");
            if budget > 0.0 {
                worst = worst.max(err / budget);
            }
        }
    }
    worst
}

#[test]
fn reassociation_stays_within_the_rounding_error_bound() {
    let (mut checked, mut worst) = (0, (0.0f64, String::new()));
    for (name, f) in corpus_functions() {
        let c = f.op_counts();
        if c.div + c.call > 0 {
            continue; // the bound covers + − × only
        }
        for pipeline in ["zero-removal,swap", "balance", "inline<max-uses=3>,balance"] {
            let g = run(pipeline, &f);
            let w = check_error_bound(&format!("{name} {pipeline}"), &f, &g);
            if w > worst.0 {
                worst = (w, format!("{name} {pipeline}"));
            }
            checked += 1;
        }
    }
    println!("{checked} rewritten functions within γ_D·M; worst error / budget {:.3} ({})", worst.0, worst.1);
    assert!(checked >= 100);
}
