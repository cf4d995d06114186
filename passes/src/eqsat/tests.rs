//! Rule tests in egg's `start => goal` style (egg `src/test.rs`, `test_fn!`; limits overridable
//! with `EGG_ITER_LIMIT` / `EGG_NODE_LIMIT`), `#[should_panic]` tests for rewrites that must not
//! fire, rule files, windows, and extraction by ready time on hand-computed examples.

use egg::{RecExpr, Runner};
use robovec_ir::text::parse;
use robovec_ir::{Def, Function, Module, Operand};

use super::lang::{Arith, ConstantFold, Rewrite};
use super::rules::rules;
use super::rules_file::{parse_rules, render, to_rewrites};
use super::window::find_windows;
use super::{eqsat_function, EqsatOptions, EqsatStats};

fn env_limit(var: &str, default: usize) -> usize {
    std::env::var(var).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Saturates `start` with `rules` and asserts every goal landed in the start's e-class.
fn check(rules: &[Rewrite], start: &str, goals: &[&str]) {
    let s: RecExpr<Arith> = start.parse().unwrap();
    let runner: Runner<Arith, ConstantFold> = Runner::default()
        .with_iter_limit(env_limit("EGG_ITER_LIMIT", 30))
        .with_node_limit(env_limit("EGG_NODE_LIMIT", 10_000))
        .with_expr(&s)
        .run(rules);
    for g in goals {
        let g: RecExpr<Arith> = g.parse().unwrap();
        assert!(!runner.egraph.equivs(&s, &g).is_empty(), "{start} did not reach {g} (stop: {:?})", runner.stop_reason);
    }
}

macro_rules! rule_test {
    ($(#[$m:meta])* $name:ident, $rules:expr, $start:literal => $($goal:literal),+ $(,)?) => {
        $(#[$m])*
        #[test]
        fn $name() {
            check(&$rules, $start, &[$($goal),+])
        }
    };
}

rule_test!(factor, rules(true), "(+ (* x0 x1) (* x0 x2))" => "(* x0 (+ x1 x2))");
rule_test!(factor_sub, rules(true), "(- (* x1 x0) (* x2 x0))" => "(* x0 (- x1 x2))");
rule_test!(distribute, rules(true), "(* x0 (+ x1 x2))" => "(+ (* x0 x1) (* x0 x2))");
rule_test!(assoc_add, rules(true), "(+ (+ x0 x1) x2)" => "(+ x0 (+ x1 x2))");
rule_test!(balance_four, rules(false), "(+ (+ (+ x0 x1) x2) x3)" => "(+ (+ x0 x1) (+ x2 x3))");
rule_test!(assoc_mul, rules(false), "(* (* x0 x1) x2)" => "(* x0 (* x1 x2))", "(* (* x2 x0) x1)");
rule_test!(sub_is_add_neg, rules(false), "(- x0 x1)" => "(+ x0 (neg x1))", "(+ (neg x1) x0)");
rule_test!(neg_neg, rules(false), "(neg (neg x0))" => "x0");
rule_test!(neg_out_of_mul, rules(false), "(* (neg x0) x1)" => "(neg (* x0 x1))", "(* x0 (neg x1))");
rule_test!(zero_sub_absorbed, rules(false), "(+ x2 (- 0 (* x0 x1)))" => "(- x2 (* x0 x1))");
rule_test!(signed_cluster, rules(false), "(- (- x0 x1) (- x2 x3))" => "(- (+ x0 x3) (+ x1 x2))");
rule_test!(fold_mul_zero, rules(false), "(+ (* x0 0) x1)" => "x1");
rule_test!(fold_mul_one, rules(false), "(* x0 1)" => "x0");
rule_test!(fold_add_zero, rules(false), "(+ x0 0)" => "x0");
rule_test!(fold_constants, rules(false), "(* (* 2 x0) 3)" => "(* 6 x0)");
rule_test!(fold_minus_one, rules(false), "(* -1 (* 2 x0))" => "(* -2 x0)", "(neg (* 2 x0))");
rule_test!(
    #[should_panic(expected = "did not reach")]
    no_distribution_when_off,
    rules(false),
    "(* x0 (+ x1 x2))" => "(+ (* x0 x1) (* x0 x2))"
);
rule_test!(
    #[should_panic(expected = "did not reach")]
    no_unsound_cancellation,
    rules(true),
    "(- x0 x1)" => "(- x1 x0)"
);

const RULES_FILE: &str = "# Extra rules\ndouble: (* 2 ?x) => (+ ?x ?x)\n\ndrop-one: (* ?a ?b) => ?a if is-one ?b  # conditional\nnz: (* ?a ?b) => (* ?b ?a) if nonzero ?a and not-const ?b\n";

fn file_rules() -> Vec<Rewrite> {
    to_rewrites(&parse_rules(RULES_FILE, &[]).unwrap()).unwrap()
}

rule_test!(file_rule_fires, file_rules(), "(* 2 x0)" => "(+ x0 x0)");
rule_test!(file_rule_condition_holds, file_rules(), "(* x0 1)" => "x0");
rule_test!(
    #[should_panic(expected = "did not reach")]
    file_rule_condition_fails,
    file_rules(),
    "(* x0 3)" => "x0"
);
rule_test!(
    #[should_panic(expected = "did not reach")]
    file_rule_second_condition_fails,
    file_rules(),
    "(* x0 3)" => "(* 3 x0)"
);

/// (line, column, message) of a bad rules text, rendered as the driver prints it.
fn bad(text: &str) -> String {
    let errs = parse_rules(text, &["comm-add".to_string()]).expect_err("must be rejected");
    render("extra.rules", text, &errs)
}

#[test]
fn bad_rule_files_name_line_column_and_expectation() {
    let r = bad("ok: (+ ?a ?b) => (+ ?b ?a)\nbroken (* ?a 1) => ?a\n");
    assert!(r.contains("extra.rules:2:1") && r.contains("expected a rule name followed by `:`"), "{r}");
    // Column 12 is the `?c` (1-based): "x: (+ ?a ?b) => ?c" → `?c` starts at byte 16 → col 17.
    let r = bad("x: (+ ?a ?b) => ?c\n");
    assert!(r.contains("extra.rules:1:17") && r.contains("`?c` is not bound"), "{r}");
    let r = bad("\n\ny: (/ ?a ?b) => ?a\n");
    assert!(r.contains("extra.rules:3:5") && r.contains("one of `+`, `-`, `*`, `neg`"), "{r}");
    let r = bad("z: (+ ?a) => ?a\n");
    assert!(r.contains("extra.rules:1:9") && r.contains("expected an operand"), "{r}");
    let r = bad("w: (* ?a 1) ?a\n");
    assert!(r.contains("extra.rules:1:13") && r.contains("expected `=>`"), "{r}");
    let r = bad("v: (* ?a ?b) => ?a if positive ?b\n");
    assert!(r.contains("extra.rules:1:23") && r.contains("`const`, `not-const`, `nonzero`, `is-one`"), "{r}");
    let r = bad("comm-add: (+ ?a ?b) => (+ ?b ?a)\n");
    assert!(r.contains("extra.rules:1:1") && r.contains("defined twice"), "{r}");
    let r = bad("u: ?a => (+ ?a 0)\n");
    assert!(r.contains("bare variable"), "{r}");
    let r = bad("t: (+ a 1) => 1\n");
    assert!(r.contains("extra.rules:1:7") && r.contains("finite number"), "{r}");
    // Every error of the file is reported, not just the first.
    let r = bad("a (x)\nb: (\n");
    assert_eq!(r.matches("error:").count(), 2, "{r}");
}

fn func(src: &str) -> Module {
    parse(src).unwrap()
}

fn run(m: &mut Module, o: &EqsatOptions) -> EqsatStats {
    let r = rules(o.distribute);
    let f = &mut m.functions[0];
    let s = eqsat_function(f, o, &r);
    assert!(robovec_ir::verifier::verify_function(f).is_empty(), "{f}");
    s
}

/// The operand tree of `o` as an s-expression over value names.
fn tree(f: &Function, o: Operand) -> String {
    match o {
        Operand::Const(c) => format!("{c:?}"),
        Operand::Value(v) => match &f.value(v).def {
            Def::Binary(op, a, b) => format!("({} {} {})", op.symbol(), tree(f, *a), tree(f, *b)),
            _ => f.name_of(v).to_string(),
        },
    }
}

#[test]
fn chain_of_four_leaves_extracts_to_depth_two() {
    // ((a+b)+c)+d, all leaves ready at 0: 3 adds deep = 36 cycles; balanced 2 deep = 24.
    let mut m = func(
        "func @f { phase atomised input %a input %b input %c input %d %t1 = add %a, %b %t2 = add %t1, %c %t3 = add %t2, %d output o = %t3 }",
    );
    let s = run(&mut m, &EqsatOptions::default());
    assert_eq!((s.cp_before, s.cp_after), (36, 24));
    assert_eq!((s.ops_before, s.ops_after), (3, 3));
    assert_eq!((s.windows_tried, s.windows_replaced), (1, 1));
    let f = &m.functions[0];
    let t = tree(f, f.outputs[0].value);
    assert_eq!(t.matches("(+").count(), 3, "{t}");
    assert!(t.starts_with("(+ (+") && t.contains(") (+ "), "both root operands are sums: {t}");
}

#[test]
fn late_leaf_stays_near_the_root() {
    // %d = ((p²)²)² is ready at 21 (3 dependent muls, each value used twice: no window can
    // shorten it); it is an output too, so a leaf of the sum.
    // ((d+a)+b)+c as written: 33, 45, 57. Huffman on ready times [0,0,0,21]: 12, 24, then
    // 24 vs 21 → 36, with %d an operand of the root.
    let mut m = func(
        "func @f { phase atomised input %a input %b input %c input %p
          %d1 = mul %p, %p %d2 = mul %d1, %d1 %d = mul %d2, %d2
          %t1 = add %d, %a %t2 = add %t1, %b %t3 = add %t2, %c output o = %t3 output dd = %d }",
    );
    let s = run(&mut m, &EqsatOptions::default());
    assert_eq!((s.cp_before, s.cp_after), (57, 36));
    let f = &m.functions[0];
    let Operand::Value(root) = f.outputs[0].value else { panic!() };
    let Def::Binary(_, x, y) = f.value(root).def else { panic!() };
    let d = Operand::Value(f.lookup("d").unwrap());
    assert!(x == d || y == d, "late leaf at the root: {}", tree(f, f.outputs[0].value));
}

#[test]
fn op_budget_gates_distribution() {
    // w + x*(y+z) with y ready at 21 (%y = ((p²)²)², also an output): as written 33, 40, 52.
    // Distributed and reassociated, (w + x*z) + x*y: x*y at 28, w + x*z at 19, root 40 — one
    // more mul. Budget 0 keeps 52 (no 3-op form is faster); budget 1 reaches 40 with 4 ops.
    let src = "func @f { phase atomised input %w input %x input %z input %p
          %y1 = mul %p, %p %y2 = mul %y1, %y1 %y = mul %y2, %y2
          %u = add %y, %z %v = mul %x, %u %t = add %w, %v output o = %t output yy = %y }";
    let mut m = func(src);
    let s = run(&mut m, &EqsatOptions::default());
    assert_eq!((s.cp_before, s.cp_after, s.ops_after), (52, 52, 6));
    assert_eq!(s.windows_replaced, 0);
    let mut m = func(src);
    let s = run(&mut m, &EqsatOptions { budget: 1, ..EqsatOptions::default() });
    assert_eq!((s.cp_before, s.cp_after, s.ops_before, s.ops_after), (52, 40, 6, 7));
    let mut m = func(src);
    let s = run(&mut m, &EqsatOptions { distribute: false, budget: 5, ..EqsatOptions::default() });
    assert_eq!(s.cp_after, 52, "without distributivity nothing helps");
}

#[test]
fn folded_window_becomes_its_leaf_or_constant() {
    // %u = a*0 + b is b: the window's root disappears and its uses read %b.
    let mut m = func(
        "func @f { phase atomised input %a input %b %t = mul %a, 0.0 %u = add %t, %b %v = mul %u, %a output o = %u output p = %v }",
    );
    run(&mut m, &EqsatOptions::default());
    let f = &m.functions[0];
    assert_eq!(
        f.name_of(match f.outputs[0].value {
            Operand::Value(v) => v,
            c => panic!("{c:?}"),
        }),
        "b"
    );
    assert_eq!(tree(f, f.outputs[1].value), "(* b a)");
    assert_eq!(f.op_counts().total, 1);
    // (2*3 + 0) * a: one window of 3 ops that folds to one mul.
    let mut m =
        func("func @f { phase atomised input %a %t = mul 2.0, 3.0 %u = add %t, 0.0 %v = mul %u, %a output o = %v }");
    run(&mut m, &EqsatOptions::default());
    let f = &m.functions[0];
    let t = tree(f, f.outputs[0].value);
    assert!(t == "(* 6.0 a)" || t == "(* a 6.0)", "{t}");
}

#[test]
fn unabsorbed_negation_is_a_sub_from_zero() {
    // -(a*b) - (c*d) as written: t = a*b, n = 0 - t, e = c*d, r = n - e (4 ops, 7+12+12 = 31).
    // Best: 0 - (a*b + c*d) = 31 cycles with 4 ops, or (0 - a*b) - c*d: no 3-op form exists,
    // since a sign must survive at the root; the window is kept, never grown.
    let mut m = func(
        "func @f { phase atomised input %a input %b input %c input %d %t = mul %a, %b %n = sub 0.0, %t %e = mul %c, %d %r = sub %n, %e output o = %r }",
    );
    let s = run(&mut m, &EqsatOptions::default());
    assert_eq!((s.cp_before, s.ops_before), (31, 4));
    assert!(s.cp_after <= 31 && s.ops_after <= 4, "{s}");
    // With a + in front the sign is absorbed: x + (0 - a*b) → x - a*b (3 ops → 2).
    let mut m = func(
        "func @f { phase atomised input %a input %b input %x %t = mul %a, %b %n = sub 0.0, %t %r = add %x, %n output o = %r }",
    );
    let s = run(&mut m, &EqsatOptions::default());
    assert_eq!((s.ops_before, s.ops_after, s.cp_before, s.cp_after), (3, 2, 31, 19));
    let f = &m.functions[0];
    assert_eq!(tree(f, f.outputs[0].value), "(- x (* a b))");
}

#[test]
fn long_cascades_split_into_bounded_windows() {
    // A 20-term sum: 19 single-use adds in one tree, cut into windows of ≤ 6 leaves.
    let mut src = String::from("func @f { phase atomised");
    for i in 0..20 {
        src += &format!(" input %x{i}");
    }
    src += " %s1 = add %x0, %x1";
    for i in 2..20 {
        src += &format!(" %s{i} = add %s{}, %x{i}", i - 1);
    }
    src += " output o = %s19 }";
    let m = func(&src);
    let f = &m.functions[0];
    let ws = find_windows(f, 6);
    assert!(
        ws.iter().all(|w| w.size <= 6 && w.ops == w.size - 1),
        "{:?}",
        ws.iter().map(|w| w.size).collect::<Vec<_>>()
    );
    assert_eq!(ws.iter().map(|w| w.ops).sum::<u32>(), 19, "every op in exactly one window");
    assert_eq!(ws.last().unwrap().root, f.lookup("s19").unwrap());
    // Windows are topologically ordered: each window's leaves are defined before its root.
    let pos = |v| f.body.iter().position(|&x| x == v);
    for w in &ws {
        assert!(w.leaves.iter().all(|&l| pos(l).is_none_or(|p| p < pos(w.root).unwrap())));
    }
    let mut m = func(&src);
    let s = run(&mut m, &EqsatOptions { window: 6, ..EqsatOptions::default() });
    // Top-down cuts: s19 takes x15..x19 + s14, s14 takes x10..x14 + s9, s9 takes x5..x9 + s4,
    // s4 is x0..x4. Huffman per window: x0..x4 → 36; [36, 0×5] → 48; [48, 0×5] → 60;
    // [60, 0×5] → 72 cycles, against 19 adds deep = 228.
    assert_eq!(ws.iter().map(|w| w.size).collect::<Vec<_>>(), [5, 6, 6, 6]);
    assert_eq!((s.cp_before, s.cp_after), (228, 72));
    assert_eq!(s.ops_after, 19);
}

/// A chain of `n` adds of products: many windows, each saturating to a few hundred e-nodes.
fn chain(n: usize) -> String {
    let mut src = String::from("func @chain { phase atomised");
    for i in 0..=n {
        src += &format!(" input %x{i}");
    }
    src += " %s0 = mul %x0, %x1";
    for i in 1..=n {
        src += &format!(" %p{i} = mul %x{i}, %x{} %s{i} = add %s{}, %p{i}", (i + 3) % (n + 1), i - 1);
    }
    src + &format!(" output o = %s{n} }}")
}

#[test]
fn the_work_budget_stops_the_run_between_windows_and_says_so() {
    let unlimited = run(&mut func(&chain(200)), &EqsatOptions { window: 8, ..EqsatOptions::default() });
    assert!(unlimited.stopped_early.is_none());
    assert_eq!(unlimited.windows_tried, unlimited.windows_total);
    assert!(unlimited.windows_total >= 4 && unlimited.enodes_total > 3_000, "{unlimited}");
    // Half of what the whole run needs: some windows are tried, not all.
    let work = unlimited.enodes_total / 2;
    assert!(work > 2 * super::MIN_WINDOW_WORK, "{unlimited}");
    let mut m = func(&chain(200));
    let s = run(&mut m, &EqsatOptions { window: 8, work_enodes: work, ..EqsatOptions::default() });
    let why = s.stopped_early.clone().expect("stopped by the budget");
    assert_eq!(why, format!("work budget of {work} e-nodes per function reached"));
    assert!(s.windows_tried >= 1 && s.windows_tried < s.windows_total, "{s}");
    assert!(s.enodes_total <= work + 10_000, "{s}");
    assert!(s.to_string().contains(&format!("stopped after {} of {} windows", s.windows_tried, s.windows_total)));
    // The windows not tried keep their ops: the critical path is no longer than before.
    assert!(s.cp_after <= s.cp_before && s.ops_after <= s.ops_before, "{s}");
}

#[test]
fn a_reached_deadline_tries_no_window_and_keeps_the_function() {
    let mut m = func(&chain(40));
    let before = m.to_string();
    let r = rules(true);
    let past = crate::Deadline::after_seconds(1e-9);
    std::thread::sleep(std::time::Duration::from_millis(2));
    let s = super::eqsat_function_within(&mut m.functions[0], &EqsatOptions::default(), &r, Some(past));
    assert_eq!(s.windows_tried, 0, "{s}");
    assert_eq!(s.stopped_early.as_deref(), Some("time limit of 0.000000001 s reached"));
    assert!(robovec_ir::verifier::verify_function(&m.functions[0]).is_empty());
    assert_eq!(m.to_string(), before, "no window tried, nothing rewritten");
}

/// Running sums `s_k = s_{k−1} + x_{k+2}` over six inputs, every sum an output: a chain of
/// shared values, so cluster windows hold one op each.
fn running_sums() -> Module {
    func(
        "func @f { phase atomised input %x1 input %x2 input %x3 input %x4 input %x5 input %x6 \
         %s1 = add %x1, %x2 %s2 = add %s1, %x3 %s3 = add %s2, %x4 %s4 = add %s3, %x5 %s5 = add %s4, %x6 \
         output o1 = %s1 output o2 = %s2 output o3 = %s3 output o4 = %s4 output o5 = %s5 }",
    )
}

#[test]
fn critical_windows_reach_across_shared_values() {
    // Cluster windows: every sum is an output, so no window has two ops; the chain stays
    // 5 adds deep (60 cycles).
    let s = run(&mut running_sums(), &EqsatOptions::default());
    assert_eq!((s.windows_total, s.cp_after), (0, 60), "{s}");
    // Critical windows (slack 0: every sum), one extra op each. In body order: s3's window
    // reads s1 (ready 12) and x3, x4: s1 + (x3 + x4) is ready at 24 instead of 36, 2 ops for the
    // 1 freed. s4 is then 24 + 12 = 36, which no term beats. s5 = s3 + (x5 + x6) is ready at
    // 36 instead of 48. Critical path 60 -> 36 cycles, ops 5 -> 7.
    let o = EqsatOptions { critical: true, budget: 1, ..EqsatOptions::default() };
    let mut m = running_sums();
    let s = run(&mut m, &o);
    assert_eq!((s.cp_before, s.cp_after), (60, 36), "{s}");
    assert_eq!((s.ops_before, s.ops_after), (5, 7), "{s}");
    let f = &m.functions[0];
    let input = |name: &str| (name[1..].parse::<f64>().unwrap()).powi(2);
    let out = robovec_ir::interp::eval::<f64>(f, input);
    let expect = [5.0, 14.0, 30.0, 55.0, 91.0];
    assert_eq!(out.iter().map(|(_, y)| *y).collect::<Vec<_>>(), expect, "{f}");
    // Without the extra op, no rewrite fits: every window needs 2 ops where it frees 1.
    let s0 = run(&mut running_sums(), &EqsatOptions { critical: true, ..EqsatOptions::default() });
    assert_eq!((s0.cp_after, s0.ops_after), (60, 5), "{s0}");
}
