//! The bound on hand-built functions whose polynomials and best programs are derived by hand.

use super::*;
use robovec_ir::text::parse;

fn lat() -> Latencies {
    Latencies { add: 12, mul: 7, div: 12, call: 12 }
}

fn balance(m: &mut Module) {
    let pm = crate::PassManager::new("balance", crate::Instrumentation::default()).unwrap();
    pm.run(m, &mut PassContext::default(), &mut std::io::sink()).unwrap();
}

fn bound(text: &str) -> FunctionBound {
    let m = parse(text).unwrap();
    bound_function(&m.functions[0], &lat(), 4096, || false)
}

fn out(m: &Module, name: &str) -> OutputBound {
    let f = &m.functions[0];
    let ex = expand::expand(f, 4096, || false);
    let o = f.outputs.iter().find(|o| o.name == name).unwrap();
    output_bound(name, &ex.of(o.value).unwrap(), &lat())
}

#[test]
fn a_chain_of_four_sums_is_bounded_by_its_balanced_tree() {
    // ((a + b) + c) + d: 36 cycles; 4 monomials of degree 1, every variable alone: a sum at the
    // root over two polynomials ready at 12 (≤ 2 monomials each): 24, what `balance` reaches.
    let text = "func @f { phase atomised input %a input %b input %c input %d \
                %x = add %a, %b %y = add %x, %c %z = add %y, %d output o = %z }";
    let b = bound(text);
    assert_eq!((b.critical_path_cycles, b.lower_bound_cycles), (36, 24));
    let o = b.binding.unwrap();
    assert_eq!((o.monomials, o.degree, o.variables, o.sum_root), (4, 1, 4, true));
    let mut m = parse(text).unwrap();
    balance(&mut m);
    assert_eq!(compute_timing(&m.functions[0], &lat()).1.asap_cycle, 24);
}

#[test]
fn an_expanded_product_of_sums_may_end_in_a_product() {
    // ac + ad + bc + bd = (a + b)(c + d): no variable alone, 4 monomials ≤ N(19) = N(12)² = 4.
    let b = bound(
        "func @f { phase atomised input %a input %b input %c input %d \
         %p = mul %a, %c %q = mul %a, %d %r = mul %b, %c %s = mul %b, %d \
         %t = add %p, %q %u = add %r, %s %v = add %t, %u output o = %v }",
    );
    let o = b.binding.unwrap();
    assert_eq!((o.monomials, o.degree, o.sum_root, o.lower_bound_cycles), (4, 2, false, 19));
    assert_eq!(b.critical_path_cycles, 31);
}

#[test]
fn exact_cancellations_leave_no_monomial() {
    // x·y − y·x + z = z; (s² + c²)·x − x = 0 with s, c the sine and cosine of q (q is a
    // θ-input: read by trig variables, not an x-variable).
    let m = parse(
        "func @f { phase atomised input %x input %y input %z input %q %S = sin %q %C = cos %q \
         %a = mul %x, %y %b = mul %y, %x %c = sub %a, %b %d = add %c, %z \
         %s2 = mul %S, %S %c2 = mul %C, %C %one = add %s2, %c2 %e = mul %one, %x %g = sub %e, %x \
         %h = mul %S, %x %k = mul %C, %x %l = add %h, %k \
         output o = %d output p = %g output r = %l }",
    )
    .unwrap();
    assert_eq!(out(&m, "o").monomials, 1);
    assert_eq!(out(&m, "o").lower_bound_cycles, 0);
    assert_eq!(out(&m, "p").monomials, 0);
    // (sin q + cos q)·x: one monomial, x, with a coefficient that is a function of q.
    let r = out(&m, "r");
    assert_eq!((r.monomials, r.degree, r.variables), (1, 1, 1));
}

#[test]
fn division_by_an_x_variable_and_oversized_products_are_not_expanded() {
    // o = a / b: not a polynomial in b. p = (a + b)(c + d)(e + g): 8 monomials, over a limit of
    // 4. r = a / sin q: a polynomial, a over a θ-function.
    let text = "func @f { phase atomised input %a input %b input %c input %d input %e input %g input %q \
                %S = sin %q %o = div %a, %b %x = add %a, %b %y = add %c, %d %z = add %e, %g \
                %xy = mul %x, %y %p = mul %xy, %z %r = div %a, %S \
                output o = %o output p = %p output r = %r }";
    let m = parse(text).unwrap();
    let f = &m.functions[0];
    let small = bound_function(f, &lat(), 4, || false);
    assert_eq!((small.outputs, small.outputs_expanded), (3, 1));
    assert_eq!(small.binding.unwrap().output, "r");
    let large = bound_function(f, &lat(), 4096, || false);
    assert_eq!(large.outputs_expanded, 2);
    // p: 8 monomials of degree 3, no variable alone: N(t) ≥ 8 first at t = 26 (N(19) = 4).
    let p = large.binding.unwrap();
    assert_eq!((p.output.as_str(), p.monomials, p.degree, p.lower_bound_cycles), ("p", 8, 3, 26));
}

#[test]
fn the_bound_is_the_same_before_and_after_rewrites() {
    // The bound is a property of the function computed, not of the program: after `balance`
    // the polynomials, and so the bound, are the same.
    let text = "func @f { phase atomised input %a input %b input %c input %d input %e \
                %x = mul %a, %b %y = add %x, %c %z = mul %y, %d %w = sub %z, %e %v = mul %w, %w \
                output o = %v output p = %w }";
    let before = bound(text);
    let mut m = parse(text).unwrap();
    balance(&mut m);
    let after = bound_function(&m.functions[0], &lat(), 4096, || false);
    assert_eq!(before.lower_bound_cycles, after.lower_bound_cycles);
    assert_eq!(before.binding, after.binding);
    assert!(after.critical_path_cycles >= after.lower_bound_cycles);
}

#[test]
fn a_stopped_expansion_bounds_the_outputs_it_reached() {
    // Stopped before the third body value: `p` (made from the first two) is expanded, `o` is not.
    let text = "func @f { phase atomised input %a input %b input %c \
                %x = add %a, %b %p = mul %x, %c %o = add %p, %a output p = %p output o = %o }";
    let m = parse(text).unwrap();
    let mut asked = 0;
    let b = bound_function(&m.functions[0], &lat(), 4096, || {
        asked += 1;
        asked > 2
    });
    assert_eq!((b.outputs, b.outputs_expanded), (2, 1));
    // p = ac + bc: 2 monomials of degree 2, no variable alone: N(12) = 2 → 12, degree 2 → 7.
    assert_eq!((b.binding.as_ref().unwrap().output.as_str(), b.lower_bound_cycles), ("p", 12));
}
