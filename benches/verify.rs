//! Verifier cost on placed IR (issue 10 item 4: the placement checks run whenever a placed
//! `.rvir` is read and after every pass under `-verify-each`, so they must stay O(ops)).
//!
//! Workloads, each placed at N = 16 without restarts or search (the placement's shape, not its
//! quality, matters here):
//! - `walkman`: the largest corpus file (`../shared/corpus/robotran/matlab/
//!   walkman__mbs_dirdyna_walkman_robotran.m`, 37.6k ops after `atomise`);
//! - `synthetic_600k`: `dag_gen::generate(600_000, 1)`, the size of the largest seed system.
//!
//! Prints, per workload, the median of 7 runs of the whole verifier
//! (`robovec_ir::verifier::verify_function`) and of its placement checks alone
//! (`verifier::placement::verify_placement`), and the time per op; then the lowering into the
//! machine program (`robovec_machine::program::lower`, which always runs the lowered check) and
//! the lowered check alone (`verifier::machine::verify_machine`), to size what running the
//! check on every lowering costs (issue 12). Run with `cargo bench --bench verify`.

use std::time::Instant;

use robovec_ir::verifier::{machine::verify_machine, placement::verify_placement, verify_function};
use robovec_ir::Function;
use robovec_machine::program::lower;
use robovec_passes::place::{place_function, PlaceOptions};
use robovec_testkit::dag_gen::generate;

#[path = "common.rs"]
mod common;
use common::walkman;

fn placed(mut f: Function) -> Function {
    let mut o = PlaceOptions::with_pes(16);
    o.restarts = 0;
    o.search = 0;
    f.placement = Some(place_function(&f, &o));
    f
}

fn median_ms(mut run: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..7)
        .map(|_| {
            let t0 = Instant::now();
            run();
            t0.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[3]
}

fn main() {
    for (name, f) in [("walkman", placed(walkman())), ("synthetic_600k", placed(generate(600_000, 1)))] {
        let ops = f.op_counts().total;
        assert!(verify_function(&f).is_empty(), "{name}: the placer's placement verifies");
        let all = median_ms(|| assert!(verify_function(&f).is_empty()));
        let place = median_ms(|| assert!(verify_placement(&f).is_empty()));
        println!(
            "{name:>15}: {ops} ops, {} writes, {} loads: verifier {all:.1} ms, of which placement checks {place:.1} ms \
             ({:.0} ns/op)",
            f.placement.as_ref().unwrap().writes.len(),
            f.placement.as_ref().unwrap().loads.len(),
            place * 1e6 / ops as f64
        );
        let p = f.placement.as_ref().unwrap();
        let m = lower(&f, p).expect("the placer's placement lowers");
        let lowering = median_ms(|| drop(lower(&f, p).unwrap()));
        let lowered = median_ms(|| assert!(verify_machine(&f, &m).is_empty()));
        println!(
            "{name:>15}: {} cycles × {} PEs: lowering {lowering:.1} ms, of which the lowered check {lowered:.1} ms ({:.0}%)",
            m.cycles,
            m.n_pe(),
            100.0 * lowered / lowering
        );
    }
}
