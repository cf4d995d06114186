//! Placement of every straight-line corpus file at N ∈ {1, 2, 4, 8, 16, 32, 64}: each placement
//! is executed by the cycle-accurate simulator in f32 and f64 (bit for bit against the
//! interpreter), and its cycles are compared with the SPEC §4 lower bound and the tighter
//! bound `tight_lower_bound` (per PE type, the exact one-type relaxation with heads and tails
//! tightened through both types).
//!
//! Measured (release, 490 placements; `cargo run --release --example placement_quality`):
//! every placement is within 1.05 × the tight bound (worst: Mazda `cons_hJ` N=4, 150 cycles
//! against 143). 6 runs are above 1.05 × SPEC LB, and for each of them the tight bound proves
//! that no placement can be within 1.05 × SPEC LB (e.g. Mazda `invdyna` N=2: tight LB 1493 =
//! 1.19 × SPEC LB 1253; we place it in 1495); the test asserts exactly that. Feeding restarts
//! (`feed::Feed`) and the key-mutation search (`search`) brought Mazda `cons_hJ` from
//! 574/298/162 cycles at N=1/2/4 to 516 (= the tight bound: optimal)/271/150, and tricycle
//! `cons_hJ` N=2 from 197 to 190 (= the tight bound: optimal).

use robovec_ir::placement::Placement;
use robovec_ir::Function;
use robovec_passes::atomise::atomise_function;
use robovec_passes::place::dag::OpDag;
use robovec_passes::place::{
    cluster, cycles, lower_bound, memory, place_function, rebind, schedule, tight_lower_bound, PlaceOptions, Priority,
    Select,
};
use robovec_passes::sim::verify_placement;

use crate::common::{corpus_files, is_loop_file};

/// The placed function, its cycles, the SPEC §4 lower bound and the tight lower bound.
fn placed(f: &Function, n: u32, priority: Priority, select: Select) -> (Function, u32, u32, u32) {
    let (g, c) = placed_only(f, n, priority, select);
    let arch = PlaceOptions::with_pes(n).arch;
    (g, c, lower_bound(f, &arch), tight_lower_bound(f, &arch))
}

/// [`placed`] without the bounds: the placed function and its cycles.
fn placed_only(f: &Function, n: u32, priority: Priority, select: Select) -> (Function, u32) {
    let mut o = PlaceOptions::with_pes(n);
    o.priority = priority;
    o.select = select;
    let mut g = f.clone();
    g.placement = Some(place_function(f, &o));
    let c = cycles(&g, g.placement.as_ref().unwrap());
    (g, c)
}

#[test]
fn corpus_placements_simulate_and_stay_near_the_lower_bound() {
    let mut worst = (1.0f64, String::new());
    let mut worst_spec = (1.0f64, String::new());
    let mut over_spec = 0;
    let mut above = Vec::new();
    let mut runs = 0;
    let (mut words_pref, mut words_naive, mut buf_pref, mut buf_naive) = (0u64, 0u64, 0u64, 0u64);
    for p in corpus_files().into_iter().filter(|p| !is_loop_file(p)) {
        let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        for f in m.functions.iter().map(atomise_function) {
            if f.op_counts().total == 0 {
                continue;
            }
            for n in [1, 2, 4, 8, 16, 32, 64] {
                let (g, c, lb, tight) = placed(&f, n, Priority::Classical, Select::Preferential);
                verify_placement(&g, &[1]).unwrap_or_else(|e| panic!("{} @{} N={n}: {e}", p.display(), f.name));
                assert!(c >= tight && tight >= lb, "bounds are bounds");
                let name = format!("{} @{} N={n}", p.file_name().unwrap().to_string_lossy(), f.name);
                let ratio = c as f64 / tight as f64;
                if ratio > 1.05 {
                    above.push(format!("{name}: {c} cycles, tight LB {tight}, SPEC LB {lb}"));
                }
                if ratio > worst.0 {
                    worst = (ratio, name.clone());
                }
                let spec_ratio = c as f64 / lb as f64;
                if spec_ratio > 1.05 {
                    over_spec += 1;
                    // Issue 3's bar: above 1.05 × SPEC LB only where no placement can do better.
                    assert!(
                        tight as u64 * 100 > lb as u64 * 105,
                        "{name}: {c} cycles > 1.05 x SPEC LB {lb}, and the tight LB {tight} does not prove it necessary"
                    );
                }
                if spec_ratio > worst_spec.0 {
                    worst_spec = (spec_ratio, name);
                }
                runs += 1;
                // Naive selection, the baseline of issue 3's memory figures, at every other PE
                // count (CI time: it places and simulates once more).
                if !matches!(n, 1 | 4 | 16 | 64) {
                    continue;
                }
                let (h, _) = placed_only(&f, n, Priority::Classical, Select::Naive);
                verify_placement(&h, &[2]).unwrap_or_else(|e| panic!("{} @{} N={n} naive: {e}", p.display(), f.name));
                let sum = |g: &Function, buf: bool| {
                    let p = g.placement.as_ref().unwrap();
                    (if buf { &p.buffer_words } else { &p.pe_words }).iter().map(|&w| w as u64).sum::<u64>()
                };
                words_pref += sum(&g, false);
                words_naive += sum(&h, false);
                buf_pref += sum(&g, true);
                buf_naive += sum(&h, true);
            }
        }
    }
    println!("{runs} placements simulated; worst cycles / tight LB {:.4} ({})", worst.0, worst.1);
    println!("worst cycles / SPEC LB {:.4} ({}); {over_spec} runs above 1.05 x SPEC LB", worst_spec.0, worst_spec.1);
    println!("total PE memory words: preferential {words_pref}, naive {words_naive}; buffer words: preferential {buf_pref}, naive {buf_naive}");
    assert!(runs > 400);
    // Issue 3: preferential selection needs no more PE memory and buffer words than naive
    // (measured at N = 1, 4, 16, 64: 178351 vs 179779 PE memory words, 1002 vs 12953 buffer words).
    assert!(words_pref <= words_naive && buf_pref <= buf_naive, "preferential selection uses more memory than naive");
    println!("above 1.05 x tight lower bound:\n{}", above.join("\n"));
    assert!(above.is_empty(), "placements above 1.05 x tight LB:\n{}", above.join("\n"));
    assert!(over_spec <= 6, "{over_spec} runs above 1.05 x SPEC LB");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 48, ..Default::default() })]

    /// Random Robotran-like DAGs, random architectures and options: every placement verifies in
    /// the simulator (f32 and f64 equal to the interpreter bit for bit) and respects the bounds.
    #[test]
    fn random_dags_place_validly(
        n_ops in 1usize..400,
        seed in 0u64..1_000_000,
        n_add in 1u32..6,
        n_mul in 1u32..6,
        writes in 1u32..4,
        mobility in proptest::bool::ANY,
        naive in proptest::bool::ANY,
        improve in 0u32..3,
    ) {
        let f = robovec_testkit::dag_gen::generate(n_ops, seed);
        let mut o = PlaceOptions::with_pes(1);
        o.arch.n_add = n_add;
        o.arch.n_mul = n_mul;
        o.arch.writes = writes;
        o.priority = if mobility { Priority::Mobility } else { Priority::Classical };
        o.select = if naive { Select::Naive } else { Select::Preferential };
        o.improve = improve;
        let mut g = f.clone();
        g.placement = Some(place_function(&f, &o));
        let c = cycles(&g, g.placement.as_ref().unwrap());
        proptest::prop_assert!(c >= tight_lower_bound(&f, &o.arch));
        if let Err(e) = verify_placement(&g, &[seed]) {
            proptest::prop_assert!(false, "{e}");
        }
    }

    /// The list scheduler with a feeding bonus (restarts use 8–1000 cycles) places validly too.
    #[test]
    fn feeding_schedules_place_validly(n_ops in 1usize..300, seed in 0u64..1_000_000, n in 1u32..4, feed in 0u32..80) {
        let f = robovec_testkit::dag_gen::generate(n_ops, seed);
        let o = PlaceOptions::with_pes(n);
        let keys = schedule::seed_keys(&f, &o.arch, Priority::Classical);
        // Nodes in body order or in priority order (as `place` builds them): any numbering.
        let dag = if seed % 2 == 0 { OpDag::new(&f) } else { OpDag::ordered(&f, &keys) };
        let s = schedule::schedule(&dag, &o.arch, &dag.gather(&keys), Select::Preferential, feed).expect("buffers on");
        let mut g = f.clone();
        g.placement = memory::build(&f, &dag, &o.arch, &s, &|| false);
        // `-time-limit`: building the memories stops (at the grace) when told to.
        proptest::prop_assert!(memory::build(&f, &dag, &o.arch, &s, &|| true).is_none());
        proptest::prop_assert!(cycles(&g, g.placement.as_ref().unwrap()) >= tight_lower_bound(&f, &o.arch));
        if let Err(e) = verify_placement(&g, &[seed]) {
            proptest::prop_assert!(false, "{e}");
        }
    }
}

/// The interconnect routes of a placement as `codegen<fpga;interconnect=specialised>` counts
/// them, from its writes alone: distinct (source, PE memory) pairs, a source being the
/// producer's result (direct write) or its buffer (indirect).
fn routes(p: &Placement) -> usize {
    let src = |w: &robovec_ir::placement::Write| (p.issue[w.value.index()].expect("an op").pe, w.buffer_addr.is_some());
    p.writes.iter().map(|w| (src(w), w.pe)).collect::<std::collections::HashSet<_>>().len()
}

/// A list schedule for fewer routes (`select=routes`) of `f`, its placement, then the same
/// schedule rebound for `rounds` rounds and its placement.
fn rebound(f: &Function, arch: robovec_ir::placement::PeArray, rounds: u32) -> (Placement, Placement, rebind::Rebound) {
    let keys = schedule::seed_keys(f, &arch, Priority::Classical);
    let dag = OpDag::ordered(f, &keys);
    let mut s = schedule::schedule(&dag, &arch, &dag.gather(&keys), Select::Routes, 0).expect("buffers on");
    let before = memory::build(f, &dag, &arch, &s, &|| false).expect("not stopped");
    let r = rebind::rebind(&dag, &arch, &mut s, rounds, &|| false);
    (before, memory::build(f, &dag, &arch, &s, &|| false).expect("not stopped"), r)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 512, ..Default::default() })]

    /// `place<select=routes;rebind=R>` (issue 49): rebinding ops between PEs, in their cycle or
    /// their slack, keeps the cycles, never adds a route (counted from the placement's writes,
    /// not by the rebinding), and the placement still verifies and simulates bit for bit —
    /// through 1 or 2 write ports per memory (one port sends results through the buffers, where
    /// swaps can collide), buffers on or off, any mix of PEs.
    #[test]
    fn rebinding_keeps_the_cycles_and_the_bits_and_never_adds_routes(
        n_ops in 1usize..400,
        seed in 0u64..1_000_000,
        n_add in 1u32..7,
        n_mul in 1u32..7,
        writes in 1u32..3,
        buffer in proptest::bool::ANY,
        rounds in 1u32..6,
    ) {
        let f = robovec_testkit::dag_gen::generate(n_ops, seed);
        let mut arch = PlaceOptions::with_pes(1).arch;
        (arch.n_add, arch.n_mul, arch.writes, arch.buffer) = (n_add, n_mul, writes, buffer);
        let keys = schedule::seed_keys(&f, &arch, Priority::Classical);
        let dag = OpDag::ordered(&f, &keys);
        // Without buffers a list schedule may get stuck: nothing to rebind then.
        if schedule::schedule(&dag, &arch, &dag.gather(&keys), Select::Routes, 0).is_err() {
            return Ok(());
        }
        let (before, after, r) = rebound(&f, arch, rounds);
        proptest::prop_assert_eq!(cycles(&f, &after), cycles(&f, &before));
        proptest::prop_assert_eq!((routes(&before), routes(&after)), (r.routes_before as usize, r.routes_after as usize));
        proptest::prop_assert!(routes(&after) <= routes(&before));
        let mut g = f.clone();
        g.placement = Some(after);
        if let Err(e) = verify_placement(&g, &[seed]) {
            proptest::prop_assert!(false, "{e}");
        }
    }
}

/// The cluster of PE `pe` of `arch` among `g`, computed here: the `i`-th PE of a side of `n`
/// is in cluster `⌊i·g/n⌋`.
fn pe_cluster_of(arch: &robovec_ir::placement::PeArray, pe: robovec_ir::placement::Pe, g: u32) -> u32 {
    use robovec_ir::placement::Pe;
    let (i, n) = match pe {
        Pe::Add(i) => (i, arch.n_add),
        Pe::Mul(i) => (i, arch.n_mul),
    };
    i * g / n
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 224, ..Default::default() })]

    /// `place<clusters=G>` (issue 49): every op issues on a PE of the cluster its part names —
    /// with `steal=S`, outside it only when its latest start (its key's first component) is at
    /// most `S` cycles after its issue —, the schedule is no shorter than the tight bound of the
    /// whole array, and the placement simulates bit for bit; for any mix of PEs, any G up to the
    /// smaller side, any S or none, buffers on or off (the pass's own placement, with restarts,
    /// too).
    #[test]
    fn clustered_placements_keep_each_op_in_its_cluster_and_the_bits(
        n_ops in 1usize..400,
        seed in 0u64..1_000_000,
        n_add in 1u32..9,
        n_mul in 1u32..9,
        g_pick in 0u32..64,
        steal in proptest::option::weighted(0.43, 0u32..40),
        windows in 1u32..5,
        buffer in proptest::bool::ANY,
    ) {
        let f = robovec_testkit::dag_gen::generate(n_ops, seed);
        let g = 1 + g_pick % n_add.min(n_mul);
        let mut o = PlaceOptions::with_pes(1);
        (o.arch.n_add, o.arch.n_mul, o.arch.buffer, o.select, o.clusters, o.steal, o.windows) =
            (n_add, n_mul, buffer, Select::Routes, g, steal, windows);
        let keys = schedule::seed_keys(&f, &o.arch, Priority::Classical);
        let mut dag = OpDag::ordered(&f, &keys);
        let alap: Vec<u32> = dag.gather(&keys).iter().map(|k| k.0).collect();
        let shape = cluster::Shape { n_add, n_mul, clusters: g, windows };
        let part = cluster::partition(&dag, &alap, shape).expect("METIS partitions");
        proptest::prop_assert_eq!(part.len(), dag.len());
        proptest::prop_assert!(part.iter().all(|&c| c < g));
        dag.set_clusters(g, part.clone());
        dag.set_steal(steal);
        let keys = dag.gather(&keys);
        let Ok(s) = schedule::schedule(&dag, &o.arch, &keys, Select::Routes, 0) else {
            proptest::prop_assert!(!buffer, "with buffers a placement always exists");
            return Ok(());
        };
        let mut h = f.clone();
        h.placement = memory::build(&f, &dag, &o.arch, &s, &|| false);
        let p = h.placement.as_ref().unwrap();
        for (j, &v) in dag.ops.iter().enumerate() {
            let at = p.issue[v.index()].expect("an op issues");
            if pe_cluster_of(&o.arch, at.pe, g) != part[j] {
                let Some(slack) = steal else {
                    proptest::prop_assert!(false, "op {} on {:?}, outside cluster {}", j, at.pe, part[j]);
                    continue;
                };
                proptest::prop_assert!(
                    keys[j].0 <= at.cycle + slack,
                    "op {} left cluster {} at cycle {} with latest start {}", j, part[j], at.cycle, keys[j].0
                );
            }
        }
        proptest::prop_assert!(cycles(&h, p) >= tight_lower_bound(&f, &o.arch));
        if let Err(e) = verify_placement(&h, &[seed]) {
            proptest::prop_assert!(false, "{e}");
        }
        if let Ok(p) = robovec_passes::place::try_place_function(&f, &o) {
            h.placement = Some(p);
            if let Err(e) = verify_placement(&h, &[seed]) {
                proptest::prop_assert!(false, "the pass: {e}");
            }
        } else {
            proptest::prop_assert!(!buffer, "with buffers a placement always exists");
        }
    }
}

/// On the Jeep's `dirdyna` at 12 + 12 PEs in 4 clusters, the interconnect has far fewer routes
/// than unclustered (the placement's (source, memory) pairs: at most 60 %) at no more than a
/// quarter more cycles, and the placement simulates bit for bit; with `steal=16` it takes fewer
/// cycles than without and keeps the routes within that 60 %; METIS kept each part's ops of
/// each side within 10 % of its cluster's share.
#[test]
fn clusters_cut_the_routes_on_a_corpus_function() {
    let src = crate::common::corpus_dir().join("c").join("jeep__mbs_dirdyna_Jeep.c");
    let (m, _) = robovec::driver::load(src.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
    let f = atomise_function(m.functions.iter().find(|f| f.name == "dirdyna").expect("@dirdyna"));
    let mut o = PlaceOptions::with_pes(12);
    o.arch.lat = robovec_ir::latency::Latencies { add: 3, mul: 3, div: 3, call: 3 };
    (o.select, o.restarts, o.search) = (Select::Routes, 0, 0);
    let flat = place_function(&f, &o);
    o.clusters = 4;
    let clustered = place_function(&f, &o);
    let (a, b) = (routes(&flat), routes(&clustered));
    let (ca, cb) = (cycles(&f, &flat), cycles(&f, &clustered));
    println!("Jeep dirdyna 12 + 12: {a} routes in {ca} cycles, {b} in {cb} cycles in 4 clusters");
    assert!(b * 100 <= a * 60, "{a} routes unclustered, {b} in clusters");
    assert!(cb * 4 <= ca * 5, "{ca} cycles unclustered, {cb} in clusters");
    // urgent ops leaving their cluster (`steal=16`): fewer cycles, the routes still at most
    // 60 % of the unclustered placement's
    o.steal = Some(16);
    let stolen = place_function(&f, &o);
    let (c, cc) = (routes(&stolen), cycles(&f, &stolen));
    println!("  with steal=16: {c} routes in {cc} cycles");
    assert!(cc < cb && c * 100 <= a * 60, "steal=16: {c} routes in {cc} cycles; {b} in {cb} without; {a} unclustered");
    let mut g = f.clone();
    g.placement = Some(stolen);
    verify_placement(&g, &[1, 2]).unwrap_or_else(|e| panic!("{e}"));
    g.placement = Some(clustered);
    verify_placement(&g, &[1, 2]).unwrap_or_else(|e| panic!("{e}"));
    // the parts' balance, counted here from the partition
    let keys = schedule::seed_keys(&f, &o.arch, Priority::Classical);
    let dag = OpDag::ordered(&f, &keys);
    let alap: Vec<u32> = dag.gather(&keys).iter().map(|k| k.0).collect();
    let part =
        cluster::partition(&dag, &alap, cluster::Shape { n_add: 12, n_mul: 12, clusters: 4, windows: 1 }).unwrap();
    for mul in [false, true] {
        let side: Vec<usize> = (0..dag.len()).filter(|&j| dag.is_mul(j as u32) == mul).collect();
        for c in 0..4 {
            let here = side.iter().filter(|&&j| part[j] == c).count();
            assert!(here * 4 * 100 <= side.len() * 110, "part {c}: {here} of {} ops (mul: {mul})", side.len());
        }
    }
}

/// `place<windows=W>` (issue 49): on the Jeep's `dirdyna` at 24 + 24 PEs in 24 clusters
/// (`steal=16`), four time windows spread the ops due in each quarter of the function (by
/// latest start) over the clusters — the most any part holds of a quarter's ops of a side,
/// against its share, falls — so the schedule takes at least 10 % fewer cycles; each part's
/// whole load stays within 10 % of its share, and the placement simulates bit for bit.
#[test]
fn time_windows_spread_each_stretch_of_ops_over_the_clusters() {
    let src = crate::common::corpus_dir().join("c").join("jeep__mbs_dirdyna_Jeep.c");
    let (m, _) = robovec::driver::load(src.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
    let f = atomise_function(m.functions.iter().find(|f| f.name == "dirdyna").expect("@dirdyna"));
    let g = 24;
    let mut o = PlaceOptions::with_pes(g);
    o.arch.lat = robovec_ir::latency::Latencies { add: 3, mul: 3, div: 3, call: 3 };
    (o.select, o.restarts, o.search, o.clusters, o.steal) = (Select::Routes, 0, 0, g, Some(16));
    let one = place_function(&f, &o);
    o.windows = 4;
    let four = place_function(&f, &o);
    let (c1, c4) = (cycles(&f, &one), cycles(&f, &four));
    println!("Jeep dirdyna 24 + 24 in 24 clusters: {c1} cycles with one window, {c4} with four");
    assert!(c4 * 10 <= c1 * 9, "{c1} cycles with one window, {c4} with four");
    let mut h = f.clone();
    h.placement = Some(four);
    verify_placement(&h, &[1, 2]).unwrap_or_else(|e| panic!("{e}"));
    // Each part's overload of a quarter: its ops of a side among that side's quarter (by latest
    // start, from the function's own timing), times G, over the quarter's ops.
    let (timing, _) = robovec_ir::analysis::compute_timing(&f, &o.arch.lat);
    let keys = schedule::seed_keys(&f, &o.arch, Priority::Classical);
    let dag = OpDag::ordered(&f, &keys);
    let latest: Vec<u32> = dag.ops.iter().map(|v| timing[v.index()].expect("an op's timing").alap_cycle).collect();
    let overload = |windows: u32| {
        let shape = cluster::Shape { n_add: g, n_mul: g, clusters: g, windows };
        let part = cluster::partition(&dag, &latest, shape).expect("METIS partitions");
        let mut worst = 0.0f64;
        for mul in [false, true] {
            let mut side: Vec<usize> = (0..dag.len()).filter(|&j| dag.is_mul(j as u32) == mul).collect();
            let total = side.len();
            for c in 0..g {
                let here = side.iter().filter(|&&j| part[j] == c).count();
                assert!(here * g as usize * 100 <= total * 110, "windows={windows}: part {c} holds {here} of {total}");
            }
            side.sort_by_key(|&j| latest[j]);
            for quarter in side.chunks(total.div_ceil(4)) {
                for c in 0..g {
                    let here = quarter.iter().filter(|&&j| part[j] == c).count();
                    worst = worst.max(here as f64 * f64::from(g) / quarter.len() as f64);
                }
            }
        }
        worst
    };
    let (w1, w4) = (overload(1), overload(4));
    println!("  the most a part holds of a quarter, against its share: {w1:.2} with one window, {w4:.2} with four");
    assert!(w4 < w1, "overload {w4:.2} with four windows, {w1:.2} with one");
}

/// On m454's `dirdyna` at 8 + 8 PEs (27-bit words are not needed: the routes are the
/// placement's), rebinding removes routes the list scheduler made — at least 5 % of them — at
/// the same cycles; stopped before its first op, it changes nothing.
#[test]
fn rebinding_removes_routes_on_a_corpus_function() {
    let src = crate::common::corpus_dir().join("c").join("m454__mbs_dirdyna_m454_project.c");
    let (m, _) = robovec::driver::load(src.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
    let f = atomise_function(m.functions.iter().find(|f| f.name == "dirdyna").expect("@dirdyna"));
    let mut arch = PlaceOptions::with_pes(8).arch;
    arch.lat = robovec_ir::latency::Latencies { add: 3, mul: 3, div: 3, call: 3 };
    let (before, after, r) = rebound(&f, arch, 64);
    let (b, a) = (routes(&before), routes(&after));
    println!("m454 dirdyna 8 + 8: {b} routes, {a} rebound ({} moves in {} rounds)", r.moves, r.rounds);
    assert_eq!(cycles(&f, &after), cycles(&f, &before));
    assert!(a * 100 <= b * 95, "{b} routes, {a} after rebinding");
    let mut g = f.clone();
    g.placement = Some(after);
    verify_placement(&g, &[1, 2]).unwrap_or_else(|e| panic!("{e}"));
    // Stopped at once: the schedule is left as it was.
    let keys = schedule::seed_keys(&f, &arch, Priority::Classical);
    let dag = OpDag::ordered(&f, &keys);
    let s = schedule::schedule(&dag, &arch, &dag.gather(&keys), Select::Routes, 0).expect("buffers on");
    let mut t = schedule::schedule(&dag, &arch, &dag.gather(&keys), Select::Routes, 0).expect("buffers on");
    let r = rebind::rebind(&dag, &arch, &mut t, 64, &|| true);
    assert_eq!((r.moves, r.routes_after), (0, r.routes_before));
    assert_eq!(t.issue, s.issue);
}

/// Feeding (`schedule::Feed`) on the Jacobian where both PE types are saturated: Mazda
/// `cons_hJ` at N=1 has 505 ADD-side ops and 508 products, and the seed's ALAP order starves
/// the ADD PE. One list schedule with a 16-cycle feeding bonus beats the seed's order by more
/// than 5%, and the default placement (whose restarts try the bonuses, then the key-mutation
/// search) is within 1.05 × the SPEC §4 bound at N = 1, 2 and 4.
#[test]
fn feeding_keeps_both_pe_types_busy_on_mazda_cons_hj() {
    let p = crate::common::corpus_dir().join("python/mazda_mx5__mbs_cons_hJ_Robotran_Mazda_MX5.py");
    let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|e| panic!("{}", e.message()));
    let f = atomise_function(&m.functions[0]);
    let o = PlaceOptions::with_pes(1);
    let dag = OpDag::new(&f);
    let keys = dag.gather(&schedule::seed_keys(&f, &o.arch, Priority::Classical));
    let end = |feed| {
        let s = schedule::schedule(&dag, &o.arch, &keys, Select::Preferential, feed).expect("buffers on");
        s.arrival.iter().copied().max().unwrap()
    };
    let (seed_order, fed) = (end(0), end(16));
    assert!(fed * 100 < seed_order * 95, "feeding {fed} cycles vs the seed's order {seed_order}");
    for n in [1, 2, 4] {
        let (g, c, lb, _) = placed(&f, n, Priority::Classical, Select::Preferential);
        assert!(c * 100 <= lb * 105, "N={n}: {c} cycles, SPEC LB {lb}");
        verify_placement(&g, &[7]).unwrap();
    }
}
