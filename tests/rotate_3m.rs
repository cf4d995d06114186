//! `rotate-3m` on the corpus: Robotran's rotations by a joint's (cos, sin) found and written
//! in three multiplies, the critical path kept, the outputs within the rigorous rounding bound
//! of the equations, and the placed result simulated bit for bit.

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{verifier, Function};
use robovec_passes::place::{place_function, PlaceOptions};
use robovec_passes::rotate_3m::{rotate_function, Stop};
use robovec_passes::sim::verify_placement;

use crate::tree_height::{check_error_bound, corpus_functions, run};

fn cp(f: &Function) -> u32 {
    compute_timing(f, &Latencies::default()).1.asap_cycle
}

#[test]
fn rotations_on_the_corpus_lose_a_multiply_each_and_keep_path_and_bound() {
    let (mut files_with_pairs, mut rewritten, mut worst) = (0, 0, 0.0f64);
    let mut placed = 0;
    for (name, f) in corpus_functions() {
        let before = run("cse,zero-removal,balance,cse", &f);
        let mut after = before.clone();
        let r = rotate_function(&mut after, &Latencies::default(), Stop::All);
        assert!(verifier::verify_function(&after).is_empty(), "{name}: {:?}", verifier::verify_function(&after));
        assert_eq!(cp(&after), cp(&before), "{name}: the critical path changed");
        let (b, a) = (before.op_counts(), after.op_counts());
        assert_eq!(a.mul + r.rewritten as u64, b.mul, "{name}: one mul fewer per pair");
        assert_eq!(a.add + a.sub, b.add + b.sub + (r.rewritten + r.joint_sums) as u64, "{name}");
        assert!(r.rewritten <= r.pairs && r.joint_sums <= 2 * r.rewritten, "{name}: {r:?}");
        if r.rewritten == 0 {
            continue;
        }
        files_with_pairs += 1;
        rewritten += r.rewritten;
        if b.div + b.call == 0 && b.total < 20_000 {
            worst = worst.max(check_error_bound(&format!("{name} rotate-3m"), &before, &after));
        }
        if placed < 3 && b.total < 6_000 {
            // The placement of the rewritten function executes as the interpreter does.
            after.placement = Some(place_function(&after, &PlaceOptions::with_pes(4)));
            verify_placement(&after, &[3]).unwrap_or_else(|e| panic!("{name} rotate-3m: {e}"));
            placed += 1;
        }
    }
    println!("rotate-3m: {rewritten} pairs in {files_with_pairs} functions; worst error / bound {worst:.3}");
    // Every dynamics file rotates its bodies' vectors about the joint axes.
    assert!(files_with_pairs >= 15, "rotated pairs in only {files_with_pairs} functions");
    assert!(placed == 3, "only {placed} placements checked");
}

#[test]
fn balanced_stops_where_the_muls_no_longer_outnumber_the_adds() {
    for (name, f) in corpus_functions().into_iter().filter(|(n, _)| n.contains("dirdyna")).take(4) {
        let mut g = run("cse,zero-removal,balance,cse", &f);
        let before = g.op_counts();
        let r = rotate_function(&mut g, &Latencies::default(), Stop::Balanced);
        let c = g.op_counts();
        let add_side = |c: &robovec_ir::OpCounts| c.add + c.sub + c.div + c.call;
        if before.mul <= add_side(&before) {
            assert_eq!(r.rewritten, 0, "{name}");
        } else if r.rewritten < r.pairs {
            // Stopped early: balanced, or the remaining pairs would lengthen the path.
            let mut all = run("cse,zero-removal,balance,cse", &f);
            let r_all = rotate_function(&mut all, &Latencies::default(), Stop::All);
            assert!(c.mul <= add_side(&c) + 1 || r.rewritten == r_all.rewritten, "{name}: {r:?} {r_all:?}");
        }
    }
}

#[test]
fn with_pe_it_rewrites_only_where_the_multiplies_bound_the_placement() {
    let mut bound_by_muls = 0;
    for (name, f) in corpus_functions().into_iter().filter(|(n, _)| n.contains("dyna")) {
        let base = run("cse,zero-removal,balance,cse", &f);
        let ceil = |a: u64, n: u64| a.div_ceil(n);
        for n in [16u32, 32] {
            let mut g = base.clone();
            let c = base.op_counts();
            let add_side = c.add + c.sub + c.div + c.call;
            let path = u64::from(cp(&base));
            let bound = |muls: u64, adds: u64| ceil(muls, n.into()).max(ceil(adds, n.into())).max(path);
            let r = rotate_function(&mut g, &Latencies::default(), Stop::Placed(n));
            let muls_bind = ceil(c.mul, n.into()) > path.max(ceil(add_side, n.into()));
            assert_eq!(r.rewritten > 0, muls_bind && r.pairs > 0, "{name} N={n}: {r:?}");
            if r.rewritten > 0 {
                bound_by_muls += 1;
                let a = g.op_counts();
                // The resource bound falls (or the pairs that keep the path ran out).
                assert!(bound(a.mul, a.add + a.sub + a.div + a.call) < bound(c.mul, add_side), "{name} N={n}");
            }
        }
    }
    // coman, WALK-MAN and MX-5 `dirdyna` at N = 16.
    assert!(bound_by_muls >= 3, "only {bound_by_muls} placements bound by their multiplies");
}

/// A random chain of `steps` rotations of a 3-vector by joint angles (real `cos`/`sin` of
/// inputs), each about a random axis, by `q` or `−q`, the products in a random operand order
/// and each new component summed with an input in a random position and sign: Robotran's
/// velocity sweep with its rotations' terms spread over larger sums. `slack`: beside it a
/// chain of additions long enough that every rotation has the slack its rewrite needs.
fn rotations(seed: u64, steps: usize, slack: bool) -> Function {
    let mut rng = robovec_ir::rng::SplitMix64::new(seed);
    let mut pick = |n: u64| rng.next_u64() % n;
    let mut text = String::from("func @f { phase atomised\ninput %x0 input %x1 input %x2\n");
    let mut x = ["x0".to_string(), "x1".into(), "x2".into()];
    for k in 1..=steps {
        text += &format!("input %q{k} input %r{k}\n%C{k} = cos %q{k}\n%S{k} = sin %q{k}\n");
        let axis = pick(3) as usize;
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        let minus = pick(2) == 0; // by q or by −q
        let mul =
            |a: &str, b: &str, flip: bool| if flip { format!("mul %{b}, %{a}") } else { format!("mul %{a}, %{b}") };
        let mut y = x.clone();
        for (c, (p1, t1, p2, t2)) in [(i, (&x[i], "C", &x[j], "S")), (j, (&x[j], "C", &x[i], "S"))] {
            let name = format!("y{k}_{c}");
            text += &format!("%{name}.a = {}\n", mul(&format!("{t1}{k}"), p1, pick(2) == 0));
            text += &format!("%{name}.b = {}\n", mul(&format!("{t2}{k}"), p2, pick(2) == 0));
            // (i: c·x_i ∓ s·x_j; j: c·x_j ± s·x_i)
            let sub = (c == i) != minus;
            let sum = match (sub, pick(3)) {
                (false, 0) => format!("%{name}.s = add %{name}.a, %{name}.b\n%{name} = add %{name}.s, %r{k}\n"),
                (false, 1) => format!("%{name}.s = add %{name}.a, %r{k}\n%{name} = add %{name}.s, %{name}.b\n"),
                (false, _) => format!("%{name}.s = sub %r{k}, %{name}.a\n%{name} = sub %{name}.b, %{name}.s\n"),
                (true, 0) => format!("%{name}.s = sub %{name}.a, %{name}.b\n%{name} = sub %{name}.s, %r{k}\n"),
                (true, 1) => format!("%{name}.s = sub %r{k}, %{name}.b\n%{name} = add %{name}.s, %{name}.a\n"),
                (true, _) => format!("%{name}.s = sub %{name}.b, %r{k}\n%{name} = sub %{name}.a, %{name}.s\n"),
            };
            text += &sum;
            y[c] = name;
        }
        text += &format!("output o{k} = %{}\n", y[pick(3) as usize]);
        x = y;
    }
    if slack {
        text += "%z0 = add %x0, %x1\n";
        for k in 1..4 * steps + 2 {
            text += &format!("%z{k} = add %z{}, %x2\n", k - 1);
        }
        text += &format!("output z = %z{}\n", 4 * steps + 1);
    }
    text += &format!("output a0 = %{} output a1 = %{} output a2 = %{} }}", x[0], x[1], x[2]);
    robovec_ir::text::parse(&text).unwrap_or_else(|e| panic!("{e:?}\n{text}")).functions.remove(0)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, ..Default::default() })]

    /// On random rotation chains: every rotation is found (one pair per step) and, given the
    /// slack, rewritten; the result
    /// verifies, keeps the critical path, has one `mul` fewer per rewritten pair, stays within
    /// the rigorous rounding bound of the input, and places and simulates bit for bit.
    #[test]
    fn rotate_3m_keeps_path_and_numbers_on_random_rotation_chains(seed in proptest::prelude::any::<u64>(), steps in 1usize..10, balanced in proptest::bool::ANY, slack in proptest::bool::ANY) {
        let f = rotations(seed, steps, slack);
        let before = if balanced { run("balance", &f) } else { f.clone() };
        let mut after = before.clone();
        let r = rotate_function(&mut after, &Latencies::default(), Stop::All);
        proptest::prop_assert!(verifier::verify_function(&after).is_empty(), "{:?}", verifier::verify_function(&after));
        if !balanced {
            proptest::prop_assert_eq!(r.pairs, steps);
            if slack {
                proptest::prop_assert_eq!(r.rewritten, steps, "every rotation has the slack");
            }
        }
        proptest::prop_assert_eq!(cp(&after), cp(&before));
        proptest::prop_assert_eq!(after.op_counts().mul + r.rewritten as u64, before.op_counts().mul);
        check_error_bound(&format!("rotations seed {seed}"), &f, &after);
        after.placement = Some(place_function(&after, &PlaceOptions::with_pes(2)));
        verify_placement(&after, &[seed]).map_err(|e| proptest::test_runner::TestCaseError::fail(e.to_string()))?;
    }
}
