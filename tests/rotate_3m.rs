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
