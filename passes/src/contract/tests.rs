use super::*;
use robovec_ir::interp::eval;
use robovec_ir::text::parse;
use robovec_ir::verifier::verify_function;

fn run(src: &str) -> (Function, Contracted) {
    let mut m = parse(src).unwrap();
    let mut f = m.functions.remove(0);
    let c = contract_function(&mut f);
    assert!(verify_function(&f).is_empty(), "{:?}", verify_function(&f));
    (f, c)
}

/// The body lines of `f`'s printed form.
fn body(f: &Function) -> Vec<String> {
    f.to_string().lines().map(str::trim).filter(|l| l.starts_with('%') && l.contains(" = ")).map(String::from).collect()
}

const HEAD: &str = "func @f {\n  phase atomised\n  input %a\n  input %b\n  input %c\n  input %d\n";

#[test]
fn each_form_of_addition_absorbs_its_multiply() {
    let src = format!(
        "{HEAD}  %m1 = mul %a, %b\n  %r1 = add %m1, %c\n  %m2 = mul %a, %c\n  %r2 = add %d, %m2\n  \
         %m3 = mul %b, %c\n  %r3 = sub %m3, %d\n  %m4 = mul %b, 0.5\n  %r4 = sub %d, %m4\n  \
         output o1 = %r1\n  output o2 = %r2\n  output o3 = %r3\n  output o4 = %r4\n}}\n"
    );
    let (f, c) = run(&src);
    assert_eq!(
        body(&f),
        [
            "%r1 = call @fma(%a, %b, %c)",
            "%r2 = call @fma(%a, %c, %d)",
            "%r3 = call @fms(%b, %c, %d)",
            "%r4 = call @fnma(%b, 0.5, %d)"
        ]
    );
    assert_eq!(c, Contracted { fma: 2, fms: 1, fnma: 1, muls_removed: 4 });
}

#[test]
fn a_multiply_with_a_use_that_is_no_addition_stays() {
    // %m1 is an output, %m2 feeds a multiply, %m3 is added to itself: none is fused.
    let src = format!(
        "{HEAD}  %m1 = mul %a, %b\n  %r1 = add %m1, %c\n  %m2 = mul %a, %c\n  %r2 = add %m2, %d\n  \
         %p = mul %m2, %d\n  %m3 = mul %c, %d\n  %r3 = add %m3, %m3\n  \
         output o1 = %r1\n  output o2 = %r2\n  output o3 = %p\n  output o4 = %r3\n  output o5 = %m1\n}}\n"
    );
    let (f, c) = run(&src);
    assert_eq!(c, Contracted::default());
    assert_eq!(body(&f).len(), 7, "nothing removed");
}

#[test]
fn a_multiply_read_by_several_additions_is_fused_into_each() {
    let src = format!(
        "{HEAD}  %m = mul %a, %b\n  %r1 = add %m, %c\n  %r2 = sub %d, %m\n  output o1 = %r1\n  output o2 = %r2\n}}\n"
    );
    let (f, c) = run(&src);
    assert_eq!(body(&f), ["%r1 = call @fma(%a, %b, %c)", "%r2 = call @fnma(%a, %b, %d)"]);
    assert_eq!(c.muls_removed, 1);
}

#[test]
fn an_addition_of_two_multiplies_absorbs_the_earlier_and_keeps_the_other_whole() {
    // %r = %m1 + %m2: the earlier %m1 is absorbed, %m2 stays as the addend.
    let src = format!("{HEAD}  %m1 = mul %a, %b\n  %m2 = mul %c, %d\n  %r = add %m1, %m2\n  output o = %r\n}}\n");
    let (f, _) = run(&src);
    assert_eq!(body(&f), ["%m2 = mul %c, %d", "%r = call @fma(%a, %b, %m2)"]);
    // %m1 is read by two additions: it fuses into both; %m2's addition is then a fused op,
    // so %m2 stays a multiply (GCC's order).
    let src = format!(
        "{HEAD}  %m1 = mul %a, %b\n  %m2 = mul %c, %d\n  %r1 = add %m2, %m1\n  %r2 = sub %m1, %c\n  \
         output o1 = %r1\n  output o2 = %r2\n}}\n"
    );
    let (f, c) = run(&src);
    assert_eq!(body(&f), ["%m2 = mul %c, %d", "%r1 = call @fma(%a, %b, %m2)", "%r2 = call @fms(%a, %b, %c)"]);
    assert_eq!(c, Contracted { fma: 1, fms: 1, fnma: 0, muls_removed: 1 });
    // An earlier multiply with a use that is no addition leaves the later one to be fused.
    let src = format!(
        "{HEAD}  %m1 = mul %a, %b\n  %m2 = mul %c, %d\n  %r1 = add %m1, %m2\n  %p = mul %m1, %c\n  \
         output o1 = %r1\n  output o2 = %p\n}}\n"
    );
    let (f, _) = run(&src);
    assert_eq!(body(&f), ["%m1 = mul %a, %b", "%r1 = call @fma(%c, %d, %m1)", "%p = mul %m1, %c"]);
}

#[test]
fn fused_values_are_one_rounding_of_the_exact_expression() {
    // a·b = 1 − 2⁻⁶⁰ exactly: unfused, a·b − 1 is 0; fused, −2⁻⁶⁰ (and c − a·b = 2⁻⁶⁰).
    let src = format!(
        "{HEAD}  %m = mul %a, %b\n  %r1 = sub %m, %c\n  %r2 = sub %c, %m\n  %r3 = add %m, %d\n  \
         output o1 = %r1\n  output o2 = %r2\n  output o3 = %r3\n}}\n"
    );
    let inputs = |n: &str| match n {
        "a" => 1.0 + 2f64.powi(-30),
        "b" => 1.0 - 2f64.powi(-30),
        "c" => 1.0,
        _ => -1.0,
    };
    let before = eval::<f64>(&parse(&src).unwrap().functions[0], inputs);
    assert!(before.iter().all(|(_, x)| *x == 0.0), "{before:?}");
    let (f, _) = run(&src);
    let after = eval::<f64>(&f, inputs);
    let t = 2f64.powi(-60);
    assert_eq!(after, [("o1".to_string(), -t), ("o2".to_string(), t), ("o3".to_string(), -t)]);
}

#[test]
fn synthetic_dags_keep_their_values_and_lose_one_op_per_multiply_removed() {
    for seed in 0..6 {
        let g = robovec_testkit::dag_gen::generate(3000, seed);
        let ops = |f: &Function| f.body.iter().filter(|&&v| !matches!(f.value(v).def, Def::Trig(..))).count();
        let mut f = g.clone();
        let c = contract_function(&mut f);
        assert!(verify_function(&f).is_empty());
        assert!(c.fma + c.fms + c.fnma >= c.muls_removed && c.muls_removed > 100, "seed {seed}: {c:?}");
        assert_eq!(ops(&f), ops(&g) - c.muls_removed, "seed {seed}");
        let input = |n: &str| robovec_ir::interp::pseudo_random_input(n, seed);
        let (x, y) = (eval::<f64>(&g, input), eval::<f64>(&f, input));
        for ((n, a), (_, b)) in x.iter().zip(&y) {
            assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "seed {seed} {n}: {a} vs {b}");
        }
        // Contracting again finds nothing: every fusable multiply is gone.
        assert_eq!(contract_function(&mut f.clone()).muls_removed, 0);
    }
}
