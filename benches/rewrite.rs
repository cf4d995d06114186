//! Speed of the cluster rewrites `zero-removal` and `balance` (`robovec_passes::tree_height::rewrite`,
//! what the passes run per function, including the whole-function contract check) on
//!
//! - `walkman`: the largest corpus file, the Matlab direct dynamics of WALK-MAN
//!   (`../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m`, 37.6k ops
//!   after `atomise`);
//! - `synthetic_100k`, `synthetic_600k`: `dag_gen::generate(n, 1)`, Robotran-like DAGs (the
//!   largest seed system has 620k ops).
//!
//! Criterion times walkman and 100k (10 flat samples; throughput in ops per second, ops = SPEC
//! §1 operations of the input). A 600k rewrite takes about a second, so `synthetic_600k` is
//! timed by the plain summary printed at the end: median of separately timed runs, ops/second,
//! and the time per op relative to walkman (≈ 1 when the cost is linear). Run with
//! `cargo bench --bench rewrite`.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use robovec_ir::analysis::Latencies;
use robovec_ir::Function;
use robovec_passes::tree_height::{rewrite, Shape};
use robovec_testkit::dag_gen::generate;

#[path = "common.rs"]
mod common;
use common::walkman;

fn bench(c: &mut Criterion) {
    let lat = Latencies::default();
    let workloads: Vec<(&str, Function, usize)> = vec![
        ("walkman", walkman(), 11),
        ("synthetic_100k", generate(100_000, 1), 7),
        ("synthetic_600k", generate(600_000, 1), 3),
    ];
    let shapes = [("zero-removal", Shape::Keep), ("balance", Shape::Balance)];

    let mut g = c.benchmark_group("rewrite");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, f, _) in workloads.iter().filter(|w| w.0 != "synthetic_600k") {
        g.throughput(Throughput::Elements(f.op_counts().total));
        for (pass, shape) in shapes {
            g.bench_function(format!("{pass}/{name}"), |b| {
                b.iter_with_large_drop(|| rewrite(black_box(f), shape, &lat))
            });
        }
    }
    g.finish();

    eprintln!("rewrite bench (default latencies; median of timed runs):");
    eprintln!(
        "  {:<13} {:<15} {:>8} {:>11} {:>13} {:>15} {:>18}",
        "pass", "workload", "ops", "median ms", "ops/second", "time/op ÷ walkman", "critical path"
    );
    for (pass, shape) in shapes {
        let mut per_op_walkman = None;
        for (name, f, runs) in &workloads {
            let n = f.op_counts().total;
            let mut out = None;
            let mut times: Vec<f64> = (0..*runs)
                .map(|_| {
                    let t = Instant::now();
                    let r = black_box(rewrite(f, shape, &lat));
                    let dt = t.elapsed().as_secs_f64();
                    out = Some(r);
                    dt
                })
                .collect();
            times.sort_by(f64::total_cmp);
            let med = times[times.len() / 2];
            let per_op = med / n as f64;
            let base = *per_op_walkman.get_or_insert(per_op);
            let (_, o) = out.expect("one run");
            eprintln!(
                "  {pass:<13} {name:<15} {n:>8} {:>11.1} {:>13.3e} {:>17.2} {:>9} -> {:>6}",
                med * 1e3,
                n as f64 / med,
                per_op / base,
                o.asap_cycle.0,
                o.asap_cycle.1
            );
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
