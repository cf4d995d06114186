//! The list-scheduling placer (`place`) against the exact optimum (`exact`, branch and bound)
//! on random small atomised DAGs (NOTES-anchors §6.2: "use them in tests to measure the
//! heuristic's gap on random small DAGs").
//!
//! The exact optimum ignores memories, write ports and buffers, so it is a lower bound on the
//! cycles of every valid placement: `place` must never beat it (a soundness check of the placer
//! on top of `sim`), and the two SPEC §4 bounds must never exceed it (a soundness check of the
//! bounds). The gap `list / optimum − 1` is printed per N, priority and improvement setting
//! (`cargo test --test root exact_gap -- --nocapture`).

use robovec_ir::analysis::Latencies;
use robovec_ir::rng::SplitMix64;
use robovec_ir::verifier::verify_function;
use robovec_ir::{BinOp, Def, Function, Operand, Phase, Span, Value};
use robovec_passes::place::{cycles, lower_bound, place_function, tight_lower_bound, PlaceOptions, Priority, Select};
use robovec_testkit::dag_gen::generate;
use robovec_testkit::exact::optimal_cycles;

/// A random layered DAG of `m` ops (add/sub/mul): ops sorted into 3–6 levels; an op's first
/// operand is an op of an earlier level (90 %, mostly the level just before), its second one
/// too half of the time, else an input. Wider and more entangled than the Robotran-like
/// generator at this size, so that the PEs are contended.
fn layered(rng: &mut SplitMix64, m: usize) -> Function {
    let mut f = Function::new("layered", Phase::Atomised);
    let inputs: Vec<Value> = (1..=4).map(|i| f.add_input(format!("q[{i}]"), Span::DUMMY).unwrap()).collect();
    let levels = 3 + rng.below(4);
    let mut level: Vec<u64> = (0..m).map(|_| rng.below(levels)).collect();
    level.sort_unstable();
    let mut ops: Vec<Value> = Vec::new();
    for k in 0..m {
        // Ops of earlier levels are 0..below; those of the level just before are prev..below.
        let below = level.partition_point(|&l| l < level[k]);
        let prev = level.partition_point(|&l| l + 1 < level[k]);
        let mut pick = |per_mille: u64| {
            if below > 0 && rng.chance(per_mille) {
                let j = if prev < below && rng.chance(800) {
                    prev + rng.below((below - prev) as u64) as usize
                } else {
                    rng.below(below as u64) as usize
                };
                Operand::Value(ops[j])
            } else {
                Operand::Value(inputs[rng.below(4) as usize])
            }
        };
        let (a, b) = (pick(900), pick(500));
        let op = [BinOp::Add, BinOp::Sub, BinOp::Mul, BinOp::Mul][rng.below(4) as usize];
        ops.push(f.define(format!("t{k}"), Def::Binary(op, a, b), Span::DUMMY).unwrap());
    }
    let mut used = vec![false; f.values.len()];
    for &v in &ops {
        f.value(v).def.for_each_value(|p| used[p.index()] = true);
    }
    for (i, &v) in ops.iter().filter(|v| !used[v.index()]).enumerate() {
        f.set_output(format!("Qq[{}]", i + 1), Operand::Value(v), Span::DUMMY);
    }
    f
}

/// 120 Robotran-like DAGs (`dag_gen`) and 120 layered ones, 10–30 ops each.
fn dags() -> Vec<Function> {
    let mut rng = SplitMix64::new(2026);
    let mut v = Vec::new();
    for seed in 0..120u64 {
        v.push(generate(10 + (seed % 21) as usize, seed));
        let m = 10 + rng.below(21) as usize;
        v.push(layered(&mut rng, m));
    }
    v
}

/// Gap statistics of one placer setting.
#[derive(Default)]
struct Gaps {
    sum: f64,
    worst: f64,
    count: u32,
    optimal: u32,
}

impl Gaps {
    fn add(&mut self, list: u32, opt: u32) {
        let g = list as f64 / opt as f64 - 1.0;
        self.sum += g;
        self.worst = self.worst.max(g);
        self.count += 1;
        self.optimal += u32::from(list == opt);
    }

    fn mean(&self) -> f64 {
        self.sum / self.count as f64
    }
}

#[test]
fn list_scheduling_vs_optimum() {
    let lat = Latencies::default();
    let dags = dags();
    // (N, priority, improve) → gaps.
    let mut table: Vec<((u32, Priority, u32), Gaps)> = Vec::new();
    for n in 1..=3 {
        for priority in [Priority::Classical, Priority::Mobility] {
            for improve in [0, PlaceOptions::with_pes(n).improve] {
                table.push(((n, priority, improve), Gaps::default()));
            }
        }
    }
    for f in &dags {
        assert!(verify_function(f).is_empty(), "generated DAG does not verify:\n{f}");
        for n in 1..=3 {
            let opt =
                optimal_cycles(f, n, n, &lat, 5_000_000).unwrap_or_else(|| panic!("N={n}: search too long:\n{f}"));
            let arch = PlaceOptions::with_pes(n).arch;
            let (lb, tight) = (lower_bound(f, &arch), tight_lower_bound(f, &arch));
            assert!(lb <= tight && tight <= opt, "N={n}: LB {lb}, tight LB {tight}, optimum {opt}:\n{f}");
            for ((tn, priority, improve), gaps) in table.iter_mut().filter(|(k, _)| k.0 == n) {
                let opts = PlaceOptions {
                    priority: *priority,
                    select: Select::Preferential,
                    improve: *improve,
                    // improve = 0 is the seed's algorithm alone: no restarts or search either.
                    restarts: if *improve == 0 { 0 } else { PlaceOptions::with_pes(*tn).restarts },
                    search: if *improve == 0 { 0 } else { PlaceOptions::with_pes(*tn).search },
                    ..PlaceOptions::with_pes(*tn)
                };
                let p = place_function(f, &opts);
                let list = cycles(f, &p);
                assert!(list >= opt, "N={n} {priority:?} improve={improve}: placement in {list} < optimum {opt}:\n{f}");
                robovec_passes::sim::verify_with(f, &p, &[1])
                    .unwrap_or_else(|e| panic!("sim rejects the placement: {e:?}\n{f}"));
                gaps.add(list, opt);
            }
        }
    }
    println!("list scheduling (preferential) vs exact optimum, {} DAGs of 10–30 ops:", dags.len());
    println!("  N  priority   improve  mean gap  worst gap  optimal");
    for ((n, priority, improve), g) in &table {
        println!(
            "  {n}  {:<9}  {improve:>7}  {:>7.2}%  {:>8.2}%  {:>3}/{}",
            format!("{priority:?}"),
            100.0 * g.mean(),
            100.0 * g.worst,
            g.optimal,
            g.count
        );
    }
    // Measured at the commit that added this test (placer with forward-backward improvement,
    // seeds fixed, so the figures are deterministic):
    //   N=1: classical mean 0.15 % / worst 3.12 % (226/240 optimal) without improvement,
    //        0.05 % / 3.12 % (235/240) with improve=2; mobility 0.15 % / 3.12 % and
    //        0.08 % / 3.12 % (233/240);
    //   N=2: 0.01 % / 2.70 % (239/240) for every setting;  N=3: always optimal.
    // The bounds leave about 3× (worst) and 6× (mean) room for placer changes; a regression
    // past them means the list scheduler lost ground against the optimum, not noise.
    for ((n, priority, improve), g) in &table {
        assert!(g.worst <= WORST_GAP, "N={n} {priority:?} improve={improve}: worst gap {:.1}%", 100.0 * g.worst);
        assert!(g.mean() <= MEAN_GAP, "N={n} {priority:?} improve={improve}: mean gap {:.2}%", 100.0 * g.mean());
    }
}

/// Largest accepted `list / optimum − 1` on any DAG (measured worst: 3.1 %).
const WORST_GAP: f64 = 0.10;
/// Largest accepted mean gap per setting (measured: ≤ 0.15 %).
const MEAN_GAP: f64 = 0.01;
