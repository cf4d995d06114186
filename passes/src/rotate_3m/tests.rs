use super::*;
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::text::parse;
use robovec_ir::verifier::verify_function;

const LAT: Latencies = Latencies { add: 12, mul: 7, div: 12, call: 12 };

fn cp(f: &Function) -> u32 {
    compute_timing(f, &LAT).1.asap_cycle
}

/// A rotation of `(x, y)` by joint `q` with `u` and `v` written as given (each an `add` or
/// `sub` of the two products, `cx`, `sy`, `sx`, `cy`, operands in the order given), beside a
/// chain of six additions on `z` that makes the critical path long enough for the pair to
/// have slack (`slack`: false puts the rotation on the critical path instead).
fn rotation(u: &str, v: &str, slack: bool) -> Function {
    let chain = if slack {
        "  %z1 = add %z, %x\n  %z2 = add %z1, %z\n  %z3 = add %z2, %z\n  %z4 = add %z3, %z\n  %z5 = add %z4, %z\n  \
         %z6 = add %z5, %z\n  output o[3] = %z6\n"
    } else {
        ""
    };
    let src = format!(
        "func @f {{\n  phase atomised\n  input %q\n  input %x\n  input %y\n  input %z\n  %c = cos %q\n  %s = sin %q\n  \
         %cx = mul %c, %x\n  %sy = mul %y, %s\n  %sx = mul %s, %x\n  %cy = mul %y, %c\n  %u = {u}\n  %v = {v}\n  \
         output o[1] = %u\n  output o[2] = %v\n{chain}}}\n"
    );
    let mut m = parse(&src).unwrap_or_else(|e| panic!("{e:?}\n{src}"));
    m.functions.remove(0)
}

/// The outputs of `f` at four pseudo-random points, in `f64`.
fn values(f: &Function) -> Vec<f64> {
    (1..=4).flat_map(|seed| eval::<f64>(f, |n| pseudo_random_input(n, seed)).into_iter().map(|(_, x)| x)).collect()
}

#[test]
fn every_sign_pattern_keeps_the_values_with_one_multiply_fewer() {
    let us = ["add %cx, %sy", "add %sy, %cx", "sub %cx, %sy", "sub %sy, %cx"];
    let vs = ["add %sx, %cy", "add %cy, %sx", "sub %sx, %cy", "sub %cy, %sx"];
    for u in us {
        for v in vs {
            let before = rotation(u, v, true);
            let mut after = before.clone();
            let r = rotate_function(&mut after, &LAT, Stop::All);
            assert!(verify_function(&after).is_empty(), "{u} / {v}: {:?}\n{after}", verify_function(&after));
            assert_eq!((r.pairs, r.rewritten), (1, 1), "{u} / {v}");
            let (b, a) = (before.op_counts(), after.op_counts());
            assert_eq!(a.mul + 1, b.mul, "{u} / {v}: one multiply fewer");
            assert_eq!(a.add + a.sub, b.add + b.sub + 1 + r.joint_sums as u64, "{u} / {v}\n{after}");
            assert!((1..=2).contains(&r.joint_sums), "{u} / {v}");
            assert_eq!(cp(&after), cp(&before), "{u} / {v}: critical path");
            for (x, y) in values(&before).into_iter().zip(values(&after)) {
                assert!((x - y).abs() <= 1e-14 * (1.0 + x.abs()), "{u} / {v}: {x} → {y}\n{after}");
            }
        }
    }
}

#[test]
fn a_pair_on_the_critical_path_is_left_as_it_is() {
    let before = rotation("sub %cx, %sy", "add %sx, %cy", false);
    let mut after = before.clone();
    let r = rotate_function(&mut after, &LAT, Stop::All);
    assert_eq!((r.pairs, r.rewritten), (1, 0));
    assert_eq!(after.to_string(), before.to_string());
}

#[test]
fn balanced_stops_when_the_muls_no_longer_outnumber_the_adds() {
    // Four products, two additions and six chain additions: the adds already outnumber the
    // muls, so `until=balanced` rewrites nothing and `until=all` rewrites the pair.
    let before = rotation("sub %cx, %sy", "add %sx, %cy", true);
    let mut f = before.clone();
    assert_eq!(rotate_function(&mut f, &LAT, Stop::Balanced).rewritten, 0);
    // With products of its own that the chain does not have, the muls outnumber the adds.
    let text = before.to_string().replace(
        "  output o[1]",
        "  %p1 = mul %x, %y\n  %p2 = mul %p1, %x\n  %p3 = mul %p2, %y\n  %p4 = mul %p3, %x\n  %p5 = mul %p4, %y\n  \
         %p6 = mul %p5, %x\n  output o[4] = %p6\n  output o[1]",
    );
    let mut f = parse(&text).unwrap().functions.remove(0);
    assert_eq!(rotate_function(&mut f, &LAT, Stop::Balanced).rewritten, 1, "{f}");
}

#[test]
fn products_read_elsewhere_or_of_two_joints_are_not_pairs() {
    // `cx` also read by an output: rewriting would keep it and gain nothing.
    let mut f = rotation("sub %cx, %sy", "add %sx, %cy", true);
    let text = f.to_string().replace("  output o[1]", "  output o[9] = %cx\n  output o[1]");
    f = parse(&text).unwrap().functions.remove(0);
    assert_eq!(rotate_function(&mut f, &LAT, Stop::All).pairs, 0);
    // The sine of another joint.
    let text = rotation("sub %cx, %sy", "add %sx, %cy", true).to_string().replace("  %s = sin %q\n", "  %s = sin %z\n");
    let mut f = parse(&text).unwrap().functions.remove(0);
    assert_eq!(rotate_function(&mut f, &LAT, Stop::All).pairs, 0);
}

/// `rotation`'s function with `u` and `v` given as several ops (`%r1`, `%r2` are inputs):
/// the products as terms of larger sums, with the signs of nested `sub`s.
fn rotation_in_sums(u: &str, v: &str) -> Function {
    let src = format!(
        "func @f {{\n  phase atomised\n  input %q\n  input %x\n  input %y\n  input %z\n  input %r1\n  input %r2\n  \
         %c = cos %q\n  %s = sin %q\n  %cx = mul %c, %x\n  %sy = mul %y, %s\n  %sx = mul %s, %x\n  %cy = mul %y, %c\n\
         {u}{v}  output o[1] = %u\n  output o[2] = %v\n  %z1 = add %z, %x\n  %z2 = add %z1, %z\n  %z3 = add %z2, %z\n  \
         %z4 = add %z3, %z\n  %z5 = add %z4, %z\n  %z6 = add %z5, %z\n  %z7 = add %z6, %z\n  output o[3] = %z7\n}}\n"
    );
    let mut m = parse(&src).unwrap_or_else(|e| panic!("{e:?}\n{src}"));
    m.functions.remove(0)
}

#[test]
fn products_that_are_terms_of_larger_sums_are_pairs_too() {
    let cases = [
        // u = (c·x + r1) − s·y, v = s·x + (c·y + r2)
        ("  %u1 = add %cx, %r1\n  %u = sub %u1, %sy\n", "  %v1 = add %cy, %r2\n  %v = add %sx, %v1\n"),
        // u = r1 − (c·x − s·y): −c·x + s·y; v = (r2 − s·x) − c·y: −s·x − c·y
        ("  %u1 = sub %cx, %sy\n  %u = sub %r1, %u1\n", "  %v1 = sub %r2, %sx\n  %v = sub %v1, %cy\n"),
        // u and v in one sum: (c·x − s·y) + (s·x + c·y) + r1, v = r2 alone
        (
            "  %u1 = sub %cx, %sy\n  %u2 = add %sx, %cy\n  %u3 = add %u1, %u2\n  %u = add %u3, %r1\n",
            "  %v = add %r2, %r1\n",
        ),
        // c·x and s·y in sums two levels apart: ((c·x + r1) + r2) − (r1 − s·y)
        (
            "  %u1 = add %cx, %r1\n  %u2 = add %u1, %r2\n  %u3 = sub %r1, %sy\n  %u = sub %u2, %u3\n",
            "  %v1 = sub %sx, %r2\n  %v = sub %v1, %cy\n",
        ),
    ];
    for (u, v) in cases {
        let before = rotation_in_sums(u, v);
        let mut after = before.clone();
        let r = rotate_function(&mut after, &LAT, Stop::All);
        assert!(verify_function(&after).is_empty(), "{u}{v}: {:?}\n{after}", verify_function(&after));
        assert_eq!((r.pairs, r.rewritten), (1, 1), "{u}{v}\n{after}");
        assert_eq!(after.op_counts().mul + 1, before.op_counts().mul, "{u}{v}");
        assert_eq!(cp(&after), cp(&before), "{u}{v}: critical path");
        for (x, y) in values(&before).into_iter().zip(values(&after)) {
            assert!((x - y).abs() <= 1e-13 * (1.0 + x.abs()), "{u}{v}: {x} → {y}\n{after}");
        }
    }
}
