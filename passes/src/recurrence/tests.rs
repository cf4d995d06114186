//! Hand-written chains: the restructured function is shorter, by the figure worked out by hand,
//! and computes the same numbers.

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::text::parse;
use robovec_ir::{verifier, Function};

use super::{restructure_function, Recurrence};

fn cp(f: &Function) -> u32 {
    compute_timing(f, &Latencies::default()).1.asap_cycle
}

fn close(f: &Function, g: &Function, seed: u64) {
    let input = |n: &str| pseudo_random_input(n, seed);
    for ((o, x), (_, y)) in eval::<f64>(f, input).iter().zip(&eval::<f64>(g, input)) {
        assert!((x - y).abs() <= 1e-13 * (1.0 + x.abs()), "{o}: {x} against {y}");
    }
}

/// `L` = a balanced sum of 8 inputs (ready at 36 cycles with add 12, mul 7), then three steps
/// of `x_k = x_{k−1}·c_k + d_k`.
const CHAIN: &str = "func @f { phase atomised
    input %a1 input %a2 input %a3 input %a4 input %a5 input %a6 input %a7 input %a8
    input %c1 input %c2 input %c3 input %d1 input %d2 input %d3
    %s1 = add %a1, %a2 %s2 = add %a3, %a4 %s3 = add %a5, %a6 %s4 = add %a7, %a8
    %s5 = add %s1, %s2 %s6 = add %s3, %s4 %L = add %s5, %s6
    %p1 = mul %L, %c1 %x1 = add %p1, %d1
    %p2 = mul %x1, %c2 %x2 = add %p2, %d2
    %p3 = mul %x2, %c3 %x3 = add %p3, %d3
    output o = %x3 }";

#[test]
fn a_chain_of_affine_steps_waits_for_its_late_start_through_one_product_and_one_add() {
    let f = parse(CHAIN).unwrap().functions.remove(0);
    // Balanced, each step still costs mul + add after L: 36 + 3 · 19 = 93.
    assert_eq!(cp(&f), 93);
    let (g, s) = restructure_function(&f, &Recurrence::default());
    assert!(verifier::verify_function(&g).is_empty(), "{g}");
    // x2's form is (c1·c2)·L + (c2·d1 + d2): the second term (ready 7 + 12 = 19) is summed
    // before L's product (43) is ready, so it is one term. x3 = (c1·c2·c3)·L + (c3·(c2·d1 + d2)
    // + d3): the coefficient is ready at 14, its product with L at 43; the other term at
    // 19 + 7 + 12 = 38; 43 + 12 = 55.
    assert_eq!(cp(&g), 55, "{g}");
    assert_eq!(s.cp, (93, 55));
    assert_eq!(s.rounds, 1);
    // L's 7 adds; c2·d1, + d2, · c3, + d3; c1·c3, · c2, · L; the last add: 15 ops for 13.
    assert_eq!((s.ops.0, g.op_counts().total), (13, 15), "{g}");
    for seed in 0..4 {
        close(&f, &g, seed);
    }
}

#[test]
fn a_rotation_chain_collects_the_terms_of_each_pivot() {
    // (u, w) rotated three times after a late start: each component stays a form over the two
    // pivots u and w (like terms collected), not 2^k terms.
    let src = "func @f { phase atomised
        input %a1 input %a2 input %a3 input %a4 input %c1 input %s1 input %c2 input %s2 input %c3 input %s3
        %t1 = add %a1, %a2 %t2 = add %a3, %a4 %u = mul %t1, %t2 %w = sub %t1, %t2
        %y1.a = mul %u, %c1 %y1.b = mul %w, %s1 %y1 = add %y1.a, %y1.b
        %z1.a = mul %w, %c1 %z1.b = mul %u, %s1 %z1 = sub %z1.a, %z1.b
        %y2.a = mul %y1, %c2 %y2.b = mul %z1, %s2 %y2 = add %y2.a, %y2.b
        %z2.a = mul %z1, %c2 %z2.b = mul %y1, %s2 %z2 = sub %z2.a, %z2.b
        %y3.a = mul %y2, %c3 %y3.b = mul %z2, %s3 %y3 = add %y3.a, %y3.b
        %z3.a = mul %z2, %c3 %z3.b = mul %y2, %s3 %z3 = sub %z3.a, %z3.b
        output y = %y3 output z = %z3 }";
    let f = parse(src).unwrap().functions.remove(0);
    // u at 19, w at 24; each rotation mul + add after w: 24 + 3 · 19 = 81.
    assert_eq!(cp(&f), 81);
    // The values off the critical path by 5 cycles (u and the products of u) join from the
    // start with slack=5.
    let (g, s) = restructure_function(&f, &Recurrence { slack: 5, ..Recurrence::default() });
    assert!(verifier::verify_function(&g).is_empty(), "{g}");
    // Each of y2, z2 is a form over the two pivots u and w, like terms collected: the u
    // coefficient (c1·c2 − s1·s2 or s1·c2 + c1·s2) is ready at 19, not before u, so it is
    // multiplied out (ready 26); the w coefficient (19) is earlier than w (24) and stays. y3 and
    // z3 each hold four terms: c3· and s3· the multiplied-out u terms (33), and w times the
    // w coefficients scaled by c3 and s3 (26, not before w: multiplied out, 33). Four terms at
    // 33 sum in two levels: 57.
    assert_eq!(cp(&g), 57, "{g}");
    assert_eq!(s.cp, (81, 57));
    // 22 ops; the forms add 8.
    assert_eq!((s.ops.0, s.ops.1), (22, 30), "{g}");
    for seed in 0..4 {
        close(&f, &g, seed);
    }
}

#[test]
fn nothing_to_gain_leaves_the_function_as_it_was() {
    let src = "func @f { phase atomised input %a input %b input %c
        %p = mul %a, %b %o = add %p, %c output o = %o }";
    let f = parse(src).unwrap().functions.remove(0);
    let (g, s) = restructure_function(&f, &Recurrence::default());
    assert_eq!(g.to_string(), f.to_string());
    assert_eq!(s.rounds, 0);
}

#[test]
fn the_ops_budget_holds_and_a_round_over_it_retries_on_the_end_of_the_critical_path() {
    let f = parse(CHAIN).unwrap().functions.remove(0);
    // 13 · 1.1 = 14 ops: the whole chain restructured (15 ops) is over. The retry takes the
    // values ready in the last half of the 93-cycle path (x1 at 55 and after) and writes x3 =
    // (c2·c3)·x1 + (c3·d2 + d3): 14 ops; x1 at 55, its product at 62, the other term at 19,
    // x3 at 74.
    let (g, s) = restructure_function(&f, &Recurrence { max_growth: 1.1, ..Recurrence::default() });
    assert_eq!((g.op_counts().total, cp(&g)), (14, 74), "{g}");
    assert!(s.rounds >= 1);
    close(&f, &g, 3);
    // No room at all: the function as it was.
    let (g, s) = restructure_function(&f, &Recurrence { max_growth: 1.0, ..Recurrence::default() });
    assert_eq!((s.rounds, g.to_string()), (0, f.to_string()));
}

#[test]
fn a_chain_from_the_inputs_is_cut_where_its_coefficients_can_start_early() {
    // Eight rotations of (x, y) from the inputs: every step's coefficient chain would be as long
    // as the step chain itself, so restructuring from the start gains nothing. Restructuring
    // only the second half makes the values at the half-way point the pivots, and the second
    // half's coefficients (products of its rotations) start at 0 beside the first half: about
    // half the chain plus one product and the adds.
    let mut src = String::from("func @f { phase atomised input %x0 input %y0");
    for k in 1..=8 {
        src += &format!(" input %c{k} input %s{k}");
    }
    for k in 1..=8 {
        let j = k - 1;
        src += &format!(
            " %x{k}.a = mul %x{j}, %c{k} %x{k}.b = mul %y{j}, %s{k} %x{k} = sub %x{k}.a, %x{k}.b \
              %y{k}.a = mul %x{j}, %s{k} %y{k}.b = mul %y{j}, %c{k} %y{k} = add %y{k}.a, %y{k}.b"
        );
    }
    src += " output x = %x8 output y = %y8 }";
    let f = parse(&src).unwrap().functions.remove(0);
    assert_eq!(cp(&f), 8 * 19);
    let (g, s) = restructure_function(&f, &Recurrence::default());
    assert!(verifier::verify_function(&g).is_empty(), "{g}");
    assert!(cp(&g) * 100 <= 85 * cp(&f), "{} -> {}", cp(&f), cp(&g));
    assert!(g.op_counts().total as f64 <= 1.5 * s.ops.0 as f64);
    for seed in 0..4 {
        close(&f, &g, seed);
    }
}

#[test]
fn the_placement_bound_divides_the_resource_bound_by_the_fill() {
    // CHAIN has 10 adds (7 in the sum L, one per step) and 3 muls, critical path 93 cycles.
    let f = parse(CHAIN).unwrap().functions.remove(0);
    assert_eq!((f.op_counts().add, f.op_counts().mul), (10, 3));
    assert_eq!(super::bound(&f, 93, 0, 0.5), 93, "pe = 0: the critical path alone");
    assert_eq!(super::bound(&f, 93, 1, 1.0), 93, "10 add slots on 1 PE: under the path");
    assert_eq!(super::bound(&f, 5, 1, 1.0), 10, "the resource bound: 10 adds on 1 ADD PE");
    assert_eq!(super::bound(&f, 4, 2, 1.0), 5, "⌈10 / 2⌉ = 5");
    assert_eq!(super::bound(&f, 5, 1, 0.9), 12, "10 / 0.9 = 11.1, rounded up");
    assert_eq!(super::bound(&f, 5, 2, 0.4), 13, "⌈10 / 2⌉ / 0.4 = 12.5, rounded up");
}

#[test]
fn thinning_keeps_the_last_states_the_first_and_every_other_before() {
    // As the rounds push them: the last TAIL = 6 states stay, and once more than 2·SNAPSHOTS = 8
    // precede them, every other of those goes (the first stays).
    let f = parse(CHAIN).unwrap().functions.remove(0);
    let mut s: Vec<(u32, Function)> = Vec::new();
    let rounds = |s: &Vec<(u32, Function)>| s.iter().map(|x| x.0).collect::<Vec<_>>();
    for r in 0..15 {
        s.push((r, f.clone()));
        super::thin(&mut s);
        if r == 13 {
            assert_eq!(s.len(), 14, "8 + 6: nothing dropped");
        }
    }
    assert_eq!(rounds(&s), [0, 2, 4, 6, 8, 9, 10, 11, 12, 13, 14]);
    for r in 15..19 {
        s.push((r, f.clone()));
        super::thin(&mut s);
    }
    assert_eq!(rounds(&s), [0, 4, 8, 10, 12, 13, 14, 15, 16, 17, 18]);
}

#[test]
fn with_pe_the_result_places_no_slower_than_the_balanced_input() {
    // The affine chain on 1 PE of each kind, where the ops as much as the path bound the
    // placement: the state returned is the fastest placed of those the rounds kept, the
    // balanced input among them.
    let f = parse(CHAIN).unwrap().functions.remove(0);
    let po = {
        let mut o = crate::place::PlaceOptions::with_pes(1);
        (o.improve, o.restarts, o.search) = (0, 0, 0);
        o
    };
    let placed = |g: &Function| crate::place::cycles(g, &crate::place::place_function(g, &po));
    let (b, _) = crate::tree_height::rewrite_within(
        &f,
        crate::tree_height::Shape::Balance,
        &Latencies::default(),
        &crate::Ticker::default(),
    )
    .unwrap();
    let (g, _) = restructure_function(&f, &Recurrence { pe: 1, ..Recurrence::default() });
    assert!(verifier::verify_function(&g).is_empty(), "{g}");
    assert!(placed(&g) <= placed(&b), "{} placed against {} balanced", placed(&g), placed(&b));
    close(&f, &g, 3);
}
