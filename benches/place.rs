//! Placement speed: `place_function` at N = 16 (16 ADD + 16 MULTI PEs, classical priority,
//! preferential selection, the default forward-backward improvement — what
//! `-passes=atomise,place<pe=16>` runs) on
//!
//! - `walkman`: the largest corpus file, the Matlab direct dynamics of WALK-MAN
//!   (`../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m`, 37.6k ops
//!   after `atomise`);
//! - `synthetic_10k`, `synthetic_100k`, `synthetic_600k`: `dag_gen::generate(n, 1)`, Robotran-like
//!   DAGs whose critical path grows like √n (the largest seed system has 620k ops).
//!
//! Criterion times the first three (10 flat samples; it reports time and throughput in ops,
//! SPEC §1, per second). One 600k placement takes seconds and criterion needs at least 10
//! samples after a warm-up, so `synthetic_600k` is timed only by the plain summary printed at
//! the end: per workload, the median of separately timed runs (11, or 3 for 600k), ops/second,
//! and the time per op relative to `synthetic_10k` next to the n·log n prediction
//! `log n / log 10k`. Run with `cargo bench --bench place` (about a minute and a half).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use robovec_ir::Function;
use robovec_passes::place::{cycles, place_function, PlaceOptions};
use robovec_testkit::dag_gen::generate;

#[path = "common.rs"]
mod common;
use common::walkman;

fn ops(f: &Function) -> u64 {
    f.op_counts().total
}

fn bench(c: &mut Criterion) {
    let opts = PlaceOptions::with_pes(16);
    let workloads: Vec<(&str, Function, usize)> = vec![
        ("walkman", walkman(), 11),
        ("synthetic_10k", generate(10_000, 1), 11),
        ("synthetic_100k", generate(100_000, 1), 11),
        ("synthetic_600k", generate(600_000, 1), 3),
    ];

    let mut g = c.benchmark_group("place_n16");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (name, f, _) in workloads.iter().filter(|w| w.0 != "synthetic_600k") {
        g.throughput(Throughput::Elements(ops(f)));
        g.bench_function(*name, |b| b.iter_with_large_drop(|| place_function(black_box(f), &opts)));
    }
    g.finish();

    // Plain figures that do not need criterion's output.
    eprintln!("place bench (N = 16, classical, preferential, improve = {}):", opts.improve);
    eprintln!(
        "  {:<15} {:>8} {:>7} {:>11} {:>13} {:>14} {:>12}",
        "workload", "ops", "cycles", "median ms", "ops/second", "time/op ÷ 10k", "n log n says"
    );
    let mut per_op_10k = None;
    for (name, f, runs) in &workloads {
        let n = ops(f);
        let mut placed = None;
        let mut times: Vec<f64> = (0..*runs)
            .map(|_| {
                let t = Instant::now();
                let p = black_box(place_function(f, &opts));
                let dt = t.elapsed().as_secs_f64();
                placed = Some(p);
                dt
            })
            .collect();
        let p = placed.expect("at least one run");
        times.sort_by(f64::total_cmp);
        let med = times[times.len() / 2];
        let per_op = med / n as f64;
        if *name == "synthetic_10k" {
            per_op_10k = Some(per_op);
        }
        let (ratio, predicted) = match per_op_10k {
            Some(base) => (format!("{:.2}", per_op / base), format!("{:.2}", (n as f64).ln() / 10_000f64.ln())),
            None => ("-".into(), "-".into()),
        };
        eprintln!(
            "  {name:<15} {n:>8} {:>7} {:>11.1} {:>13.3e} {ratio:>14} {predicted:>12}",
            cycles(f, &p),
            med * 1e3,
            n as f64 / med
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
