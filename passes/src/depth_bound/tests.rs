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

/// Issue 47: after `contract` the fused ops were calls, their operands θ-inputs, and the bound
/// 0 cycles. Now they are expanded (the polynomials, and the `+ − ×` bound, are the unfused
/// function's) and the bound is over programs of `+ − ×` and fused ops of latency `lat-call`,
/// never above the contracted program's critical path.
#[test]
fn fused_multiply_adds_are_expanded_and_bounded_with_their_latency() {
    // m = a·b; o = m + c; p = d − m; u = p·p + o = d² − 2abd + a²b² + ab + c; r = S·a − b.
    let text = "func @f { phase atomised input %a input %b input %c input %d input %q %S = sin %q \
                %m = mul %a, %b %o = add %m, %c %p = sub %d, %m %pp = mul %p, %p %u = add %pp, %o \
                %sa = mul %S, %a %r = sub %sa, %b output o = %o output u = %u output r = %r }";
    let plain = parse(text).unwrap();
    let mut fused = plain.clone();
    let c = crate::contract::contract_function(&mut fused.functions[0]);
    assert_eq!((c.fma, c.fms, c.fnma, c.muls_removed), (2, 1, 1, 3), "{}", fused.functions[0]);
    let (f0, f1) = (&plain.functions[0], &fused.functions[0]);
    let before = bound_function(f0, &lat(), 4096, || false);
    let after = bound_function(f1, &lat(), 4096, || false);
    // The unfused program: a·b at 7, p at 19, p·p at 26, u at 38.
    assert_eq!((before.critical_path_cycles, before.fma_latency, before.plus_minus_times_cycles), (38, None, None));
    // u: 5 monomials of degree 4 with c alone: over + − ×, a sum at t with 2·N(t − 12) ≥ 5 and
    // D(t − 12) ≥ 4: t − 12 = 19 (N(19) = 4, D(14) = 4), so 31.
    assert_eq!(before.lower_bound_cycles, 31);
    let ub = before.binding.clone().unwrap();
    assert_eq!((ub.output.as_str(), ub.monomials, ub.degree, ub.variables, ub.sum_root), ("u", 5, 4, 4, true));
    // The fused program: o and p at 12 (one fma each), u = fma(p, p, o) at 24 — below 31.
    assert_eq!(after.critical_path_cycles, 24);
    // Same polynomials (a, b, c, d stay x-variables: before the fix they were θ-inputs) ...
    let outs = |f: &Function| output_bounds_in(f, &lat(), None, 4096, || false);
    assert_eq!(outs(f0), outs(f1));
    assert_eq!(after.plus_minus_times_cycles, Some(31));
    // ... and over + − × and fma ops (latency 12): u by a fused op at t with N(t−12)² + N(t−12)
    // ≥ 5 and 2·D(t−12) ≥ 4: t − 12 = 12 (N(12) = 2, D(12) = 2), so 24 = the critical path.
    assert_eq!((after.lower_bound_cycles, after.fma_latency), (24, Some(12)));
    assert_eq!(after.binding.as_ref().map(|b| (b.output.as_str(), b.monomials)), Some(("u", 5)));
    // The same model on the unfused function gives the same bound: a property of the function.
    let model = |f: &Function| output_bounds_in(f, &lat(), Some(12), 4096, || false);
    assert_eq!(model(f0), model(f1));
    assert_eq!(model(f0).iter().map(|o| o.lower_bound_cycles).max(), Some(24));
    // o = a·b + c: one fused op, 12 cycles; r = S·a − b: 2 monomials of degree 1, b alone.
    let o = model(f1).into_iter().find(|o| o.output == "o").unwrap();
    assert_eq!((o.monomials, o.degree, o.sum_root, o.lower_bound_cycles), (2, 2, true, 12));
    let r = model(f1).into_iter().find(|o| o.output == "r").unwrap();
    assert_eq!((r.monomials, r.degree, r.variables, r.sum_root), (2, 1, 2, true));
    // The line says which model.
    let line = after.to_string();
    assert!(
        line.contains("lower bound 24 cycles over programs of + − × and fused multiply-add ops (u: 5 monomials")
            && line.ends_with("(latencies add 12, mul 7, fma 12); over + − × ops alone: 31 cycles"),
        "{line}"
    );
    assert!(!before.to_string().contains("fma"), "{before}");
}

#[test]
fn a_sqrt_still_makes_its_argument_a_theta_input_under_a_fused_op() {
    // w = fma(√(e²), a, a) = (|e| + 1)·a: e is read by a call (a θ-input; squared, so that the
    // square root of its samples is real), a stays an x-variable.
    let text = "func @f { phase atomised input %a input %e %e2 = mul %e, %e %s = call @sqrt(%e2) \
                %w = call @fma(%s, %a, %a) output w = %w }";
    let b = bound(text);
    let w = b.binding.unwrap();
    assert_eq!((w.monomials, w.degree, w.variables), (1, 1, 1));
    // e² at 7, √ at 19, the fma at 31; a alone is ready at 0.
    assert_eq!((b.lower_bound_cycles, b.critical_path_cycles, b.fma_latency), (0, 31, Some(12)));
}
