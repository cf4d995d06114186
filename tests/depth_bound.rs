//! `depth-bound` (issue 31): the lower bound on the critical path of every `+ − ×` program is a
//! property of the function, not of the program — the same before and after every rewrite, and
//! never above a critical path robovec reaches — and it proves where the 0.25× goal
//! cannot be met.

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::Function;
use robovec_passes::depth_bound::{bound_function, output_bounds, output_bounds_in, FunctionBound};

use crate::tree_height::{corpus_functions, run};

fn bound(f: &Function) -> FunctionBound {
    bound_function(f, &Latencies::default(), 4096, || false)
}

fn cp(f: &Function) -> u32 {
    compute_timing(f, &Latencies::default()).1.asap_cycle
}

/// Knee `dirdyna`: `c[2]` expanded by hand (and by SymPy) is
/// `−trq23 − trq24 − (l33 + q3)·frc13 − (q3 + q4)·frc14 + g3·S2·(l33·m3 + m3·q3 + m4·q3 + m4·q4)
///  + 2·qd2·qd3·(l33·m3 + m3·q3 + m4·q3 + m4·q4) + 2·m4·qd2·qd4·(q3 + q4)`:
/// 16 monomials in the 13 inputs other than q2 (read by sin and cos), of degree 4 (`g3·S2·m3·l33`
/// has x-degree 3, `qd2·qd3·m3·l33` 4), with `trq23` alone: a sum at the root, whose operands,
/// ready by cycle t − 12, hold at most N(t − 12) monomials (N(26) = 16, N(24) = 4). So no
/// program reaches c[2] before cycle 38, above 0.25 × the 136 cycles of `atomise`.
#[test]
fn knee_dirdyna_cannot_reach_a_quarter_of_its_critical_path() {
    let (_, f) = corpus_functions()
        .into_iter()
        .find(|(n, _)| n.starts_with("knee__mbs_dirdyna"))
        .expect("the knee model's dirdyna is in the corpus");
    assert_eq!(cp(&f), 136);
    let b = bound(&f);
    assert_eq!((b.outputs, b.outputs_expanded), (10, 10));
    let o = b.binding.clone().unwrap();
    assert_eq!((o.output.as_str(), o.monomials, o.degree, o.variables, o.sum_root), ("c[2]", 16, 4, 13, true));
    assert_eq!(b.lower_bound_cycles, 38);
    assert!(4 * b.lower_bound_cycles > cp(&f), "the 0.25× goal is out of reach");
    // `default<depth>` reaches 69 cycles; the bound is below it and unchanged by the rewrite.
    let d = run("default<depth>", &f);
    assert!(cp(&d) >= b.lower_bound_cycles);
    assert_eq!(bound(&d), FunctionBound { critical_path_cycles: cp(&d), ..b });
}

#[test]
fn the_bound_is_the_functions_and_below_every_rewrite_on_the_small_corpus_models() {
    // Functions of at most 2000 ops (expanded within the default limit in milliseconds): the
    // bound after each rewriting pipeline is the atomised function's, and never above the
    // critical path the pipeline reached.
    let mut checked = 0;
    for (name, f) in corpus_functions().into_iter().filter(|(_, f)| f.op_counts().total <= 2000) {
        let b = bound(&f);
        assert!(b.lower_bound_cycles <= cp(&f), "{name}");
        for p in ["cse,zero-removal,balance,cse", "default<depth>", "default<depth>,eqsat<scope=critical;budget=2>"] {
            let r = run(p, &f);
            let after = bound(&r);
            assert_eq!(
                (after.lower_bound_cycles, after.outputs_expanded, &after.binding),
                (b.lower_bound_cycles, b.outputs_expanded, &b.binding),
                "{name} after {p}"
            );
            assert!(cp(&r) >= after.lower_bound_cycles, "{name} after {p}: {} < {}", cp(&r), after.lower_bound_cycles);
        }
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} small corpus functions");
}

#[test]
fn the_bound_is_unchanged_by_the_rewrites_on_random_dags() {
    // Synthetic body chains (forward and backward sweeps, shared values): the polynomial of
    // every output, and so its bound, survives `default<depth>`, a wider `recurrence` and `eqsat` (with distributivity). Which
    // outputs expand within 256 monomials depends on the program (its intermediate values), so
    // the outputs expanded in both are compared.
    let (mut compared, mut largest) = (0, 0);
    for seed in 0..12 {
        let f = robovec_testkit::dag_gen::generate(300, seed);
        let bounds = |f: &Function| output_bounds(f, &Latencies::default(), 256, || false);
        let before = bounds(&f);
        for p in ["default<depth>", "recurrence<max-growth=3;max-terms=8>", "eqsat"] {
            let r = run(p, &f);
            let after = bounds(&r);
            for a in &after {
                assert!(cp(&r) >= a.lower_bound_cycles, "seed {seed} {p} {}", a.output);
                if let Some(b) = before.iter().find(|b| b.output == a.output) {
                    assert_eq!(a, b, "seed {seed} {p}");
                    compared += 1;
                    largest = largest.max(a.monomials);
                }
            }
        }
    }
    assert!(compared >= 100 && largest >= 32, "only {compared} outputs compared, the largest of {largest} monomials");
}

#[test]
fn the_command_line_prints_the_bound_and_the_report_holds_it() {
    let dir = crate::common::tmp("cli");
    let report = dir.join("report.json");
    let knee = crate::common::corpus_dir().join("matlab/knee__mbs_dirdyna_Knee.m");
    let o = crate::common::opt(&[
        knee.to_str().unwrap(),
        "-passes=atomise,depth-bound",
        &format!("-report={}", report.display()),
        "-o",
        dir.join("out.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    let err = crate::common::stderr(&o);
    assert!(
        err.contains(
            "depth-bound @dirdyna: critical path 136 cycles, lower bound 38 cycles (c[2]: 16 monomials of degree 4 \
             in 13 x-variables, a sum at the root); 10 of 10 outputs expanded (latencies add 12, mul 7)"
        ),
        "{err}"
    );
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let b = &r["depth_bound"];
    assert_eq!((b["lower_bound_cycles"].as_u64(), b["critical_path_cycles"].as_u64()), (Some(38), Some(136)));
    assert_eq!(b["binding"]["output"], "c[2]");
    // An analysis: the IR written is atomise's.
    let plain = crate::common::opt(&[knee.to_str().unwrap(), "-passes=atomise", "-o", "-"]);
    assert_eq!(std::fs::read(dir.join("out.rvir")).unwrap(), plain.stdout);
}

/// Issue 47: after `contract` the bound read `lower bound 0 cycles (… 1 monomials of degree 0
/// in 0 x-variables)`: the fused ops were taken for calls, their operands for θ-inputs. Now
/// they are expanded: the `+ − ×` bound is the function's (the same as without `contract`),
/// and the bound printed beside the contracted program's critical path is over programs with
/// fused ops too, at most that critical path and equal to the same model's bound before.
#[test]
fn contract_keeps_the_functions_bound_and_bounds_the_fused_program() {
    let mut checked = 0;
    for (name, f) in corpus_functions().into_iter().filter(|(_, f)| f.op_counts().total <= 2000) {
        let b = bound(&f);
        let c = run("contract", &f);
        if c.op_counts().call == f.op_counts().call {
            // Nothing fused: the same program.
            assert_eq!(bound(&c), b, "{name}");
            continue;
        }
        let a = bound(&c);
        let lat = Latencies::default();
        assert_eq!(a.fma_latency, Some(lat.call), "{name}");
        assert_eq!(a.plus_minus_times_cycles, Some(b.lower_bound_cycles), "{name}");
        assert_eq!(a.outputs_expanded, b.outputs_expanded, "{name}");
        // The polynomials are the same: every output's monomials, degree and variables.
        let plain = |f: &Function| output_bounds_in(f, &lat, None, 4096, || false);
        assert_eq!(plain(&c), plain(&f), "{name}");
        let fma = |f: &Function| output_bounds_in(f, &lat, Some(lat.call), 4096, || false);
        assert_eq!(fma(&c), fma(&f), "{name}");
        assert_eq!(fma(&f).iter().map(|o| o.lower_bound_cycles).max(), Some(a.lower_bound_cycles), "{name}");
        assert!(a.lower_bound_cycles <= cp(&c), "{name}: {} > {}", a.lower_bound_cycles, cp(&c));
        assert!(a.lower_bound_cycles <= b.lower_bound_cycles, "{name}");
        if name.starts_with("knee__mbs_dirdyna") {
            // c[2] (16 monomials, degree 4, a sum at the root): 38 over + − ×; with fused ops of
            // latency 12 one fma at cycle 31 can hold N(19)² + N(19) = 20 monomials (count.rs).
            let o = a.binding.clone().unwrap();
            assert_eq!((o.output.as_str(), o.monomials, o.degree, o.variables), ("c[2]", 16, 4, 13));
            assert_eq!((a.lower_bound_cycles, a.plus_minus_times_cycles), (31, Some(38)));
        }
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} small corpus functions");
}

#[test]
fn contract_keeps_the_bound_on_random_dags() {
    // Every output that expands: the same polynomial after `contract`; its bound over + − ×
    // and fused ops the same as the unfused function's in that model, never above the
    // contracted critical path, never above the + − × bound.
    let lat = Latencies::default();
    let (mut compared, mut fused) = (0, 0);
    for seed in 0..16 {
        let f = robovec_testkit::dag_gen::generate(300, seed);
        let c = run("contract", &f);
        fused += c.op_counts().call - f.op_counts().call;
        for model in [None, Some(lat.call), Some(1), Some(30)] {
            let before = output_bounds_in(&f, &lat, model, 256, || false);
            let after = output_bounds_in(&c, &lat, model, 256, || false);
            for a in &after {
                if let Some(b) = before.iter().find(|b| b.output == a.output) {
                    assert_eq!(a, b, "seed {seed} model {model:?}");
                    compared += 1;
                }
            }
        }
        let b = bound(&c);
        assert!(b.lower_bound_cycles <= cp(&c), "seed {seed}: {} > {}", b.lower_bound_cycles, cp(&c));
        assert!(b.lower_bound_cycles <= b.plus_minus_times_cycles.unwrap_or(u32::MAX), "seed {seed}");
    }
    assert!(compared >= 200 && fused >= 100, "only {compared} outputs compared, {fused} fused ops");
}

#[test]
fn the_command_line_bound_after_contract_names_its_model() {
    let dir = crate::common::tmp("contract");
    let knee = crate::common::corpus_dir().join("matlab/knee__mbs_dirdyna_Knee.m");
    let small = dir.join("small.rvir");
    // u = (d − a·b)² + a·b + c (see the unit test in `passes/src/depth_bound/tests.rs`).
    std::fs::write(
        &small,
        "func @f {\n  phase atomised\n  input %a\n  input %b\n  input %c\n  input %d\n  %m = mul %a, %b\n  %o = add %m, %c\n  \
         %p = sub %d, %m\n  %pp = mul %p, %p\n  %u = add %pp, %o\n  output u = %u\n}\n",
    )
    .unwrap();
    let line = |input: &std::path::Path, passes: &str| {
        let o = crate::common::opt(&[input.to_str().unwrap(), passes, "-o", "/dev/null"]);
        assert!(o.status.success(), "{passes}: {}", crate::common::stderr(&o));
        crate::common::stderr(&o).lines().find(|l| l.starts_with("depth-bound @")).unwrap().to_string()
    };
    let plain = line(&knee, "-passes=atomise,depth-bound");
    let fused = line(&knee, "-passes=atomise,contract,depth-bound");
    assert!(plain.contains("lower bound 38 cycles (c[2]: 16 monomials of degree 4 in 13 x-variables"), "{plain}");
    assert!(
        fused.contains(
            "lower bound 31 cycles over programs of + − × and fused multiply-add ops (c[2]: 16 monomials of \
             degree 4 in 13 x-variables, a sum at the root); 10 of 10 outputs expanded (latencies add 12, mul 7, \
             fma 12); over + − × ops alone: 38 cycles"
        ),
        "{fused}"
    );
    let plain = line(&small, "-passes=atomise,depth-bound");
    let fused = line(&small, "-passes=atomise,contract,depth-bound");
    assert_eq!(
        plain,
        "depth-bound @f: critical path 38 cycles, lower bound 31 cycles (u: 5 monomials of degree 4 in 4 \
         x-variables, a sum at the root); 1 of 1 outputs expanded (latencies add 12, mul 7)"
    );
    assert_eq!(
        fused,
        "depth-bound @f: critical path 24 cycles, lower bound 24 cycles over programs of + − × and fused \
         multiply-add ops (u: 5 monomials of degree 4 in 4 x-variables, a sum at the root); 1 of 1 outputs \
         expanded (latencies add 12, mul 7, fma 12); over + − × ops alone: 31 cycles"
    );
}

/// A small atomised function over four inputs: each op `(kind, a, b)` reads two earlier
/// values (inputs first), `kind` 0 add, 1 sub, 2–3 mul (so products often feed sums); the
/// last two values are the outputs.
fn small_dag(ops: &[(u8, usize, usize)]) -> Function {
    let mut text = String::from("func @f {\n  phase atomised\n  input %x0\n  input %x1\n  input %x2\n  input %x3\n");
    let name = |k: usize| if k < 4 { format!("%x{k}") } else { format!("%v{}", k - 4) };
    for (i, &(kind, a, b)) in ops.iter().enumerate() {
        let op = ["add", "sub", "mul", "mul"][kind as usize % 4];
        text += &format!("  %v{i} = {op} {}, {}\n", name(a % (i + 4)), name(b % (i + 4)));
    }
    let n = ops.len() + 4;
    text += &format!("  output o = {}\n  output p = {}\n}}\n", name(n - 1), name(n - 2));
    robovec_ir::text::parse(&text).unwrap_or_else(|e| panic!("{e:?}\n{text}")).functions.remove(0)
}

proptest::proptest! {
    #![proptest_config(proptest::test_runner::Config { cases: 256, ..Default::default() })]
    /// After `contract`, at any latencies: the bound never exceeds the critical path, equals
    /// the bound of the same model (fused ops of the `call` latency) before `contract`, and its
    /// `+ − ×` figure is the bound before `contract`.
    #[test]
    fn a_bound_after_contract_is_below_the_critical_path_and_the_functions(
        ops in proptest::collection::vec((0u8..4, 0usize..64, 0usize..64), 2..14),
        add in 1u32..20, mul in 1u32..20, call in 1u32..30,
    ) {
        let lat = Latencies { add, mul, div: 12, call };
        let f = small_dag(&ops);
        let c = run("contract", &f);
        let before = bound_function(&f, &lat, 4096, || false);
        let after = bound_function(&c, &lat, 4096, || false);
        let cp_after = compute_timing(&c, &lat).1.asap_cycle;
        proptest::prop_assert!(after.lower_bound_cycles <= cp_after, "{} > {cp_after}\n{c}", after.lower_bound_cycles);
        proptest::prop_assert!(before.lower_bound_cycles <= before.critical_path_cycles);
        proptest::prop_assert_eq!(after.outputs_expanded, before.outputs_expanded);
        let fused = c.op_counts().call > 0;
        if fused {
            let model = output_bounds_in(&f, &lat, Some(call), 4096, || false);
            proptest::prop_assert_eq!(Some(after.lower_bound_cycles), model.iter().map(|o| o.lower_bound_cycles).max().or(Some(0)));
            proptest::prop_assert_eq!(after.plus_minus_times_cycles, Some(before.lower_bound_cycles));
            proptest::prop_assert!(after.lower_bound_cycles <= before.lower_bound_cycles);
        } else {
            proptest::prop_assert_eq!(after.lower_bound_cycles, before.lower_bound_cycles);
        }
    }
}
