//! Pipeline throughput on the largest corpus file, the Matlab direct dynamics of WALK-MAN
//! (`../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m`, 55 joints):
//!
//! - `parse`: Matlab front end, bytes → parsed-phase module;
//! - `atomise`: the `atomise` pass alone (verifier off), on a clone of the parsed module;
//! - `asap-alap`: the `asap-alap` pass alone (verifier off), on a clone of the atomised module;
//! - `parse+atomise+asap-alap`: what `robovec-opt FILE -passes=atomise,asap-alap` does before
//!   writing output: parse, verify the input, run both passes with `-verify-each` (default on).
//!
//! Criterion reports each time; the whole pipeline also reports throughput in ops/second (ops =
//! binary operations after atomisation, SPEC §1), and a plain line with the median is printed at
//! the end. Run with `cargo bench --bench pipeline` (about 30 s: 10 samples, 3 s each).

use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use robovec_front::{parse_str, Language};
use robovec_ir::{verifier, Module};
use robovec_passes::{Instrumentation, PassContext, PassManager};

const FILE: &str = "../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m";

fn source() -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(FILE);
    std::fs::read(&p).unwrap_or_else(|e| panic!("cannot read {} (the corpus must sit at ../shared): {e}", p.display()))
}

fn parse(bytes: &[u8]) -> Module {
    match parse_str(Language::Matlab, bytes, None) {
        Ok(m) => m,
        Err(errs) => panic!("the Matlab front end rejects {FILE}: {} errors, first: {:?}", errs.len(), errs.first()),
    }
}

fn manager(pipeline: &str, verify_each: bool) -> PassManager {
    let instr = Instrumentation { verify_each, ..Instrumentation::default() };
    PassManager::with_registry(robovec_backends::REGISTRY, pipeline, instr).expect("pipeline parses")
}

fn run(pm: &PassManager, m: &mut Module) {
    pm.run(m, &mut PassContext::default(), &mut std::io::sink()).expect("pipeline runs");
}

/// The whole `robovec-opt FILE -passes=atomise,asap-alap` work, output aside.
fn whole(bytes: &[u8], pm: &PassManager) -> Module {
    let mut m = parse(bytes);
    verifier::verify(&m).expect("input verifies");
    run(pm, &mut m);
    m
}

fn ops(m: &Module) -> u64 {
    m.functions.iter().map(|f| f.op_counts().total).sum()
}

fn bench(c: &mut Criterion) {
    let bytes = source();
    let parsed = parse(&bytes);
    let atomise = manager("atomise", false);
    let asap_alap = manager("asap-alap", false);
    let pipeline = manager("atomise,asap-alap", true);
    let mut atomised = parsed.clone();
    run(&atomise, &mut atomised);
    let n_ops = ops(&atomised);
    eprintln!(
        "pipeline bench: {FILE}: {} bytes, {} function(s), {} equations, {n_ops} ops after atomise",
        bytes.len(),
        parsed.functions.len(),
        parsed.functions.iter().filter_map(|f| f.equations).sum::<u32>()
    );

    let mut g = c.benchmark_group("walkman_dirdyna_m");
    g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3));
    g.bench_function("parse", |b| b.iter(|| parse(black_box(&bytes))));
    g.bench_function("atomise", |b| {
        b.iter_batched(|| parsed.clone(), |mut m| run(&atomise, &mut m), BatchSize::LargeInput)
    });
    g.bench_function("asap-alap", |b| {
        b.iter_batched(|| atomised.clone(), |mut m| run(&asap_alap, &mut m), BatchSize::LargeInput)
    });
    g.throughput(Throughput::Elements(n_ops));
    g.bench_function("parse+atomise+asap-alap", |b| b.iter(|| whole(black_box(&bytes), &pipeline)));
    g.finish();

    // A plain figure that does not need criterion's output: median of 11 timed runs.
    let mut times: Vec<f64> = (0..11)
        .map(|_| {
            let t = Instant::now();
            black_box(whole(&bytes, &pipeline));
            t.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    let med = times[times.len() / 2];
    eprintln!(
        "pipeline bench: parse+atomise+asap-alap median {:.2} ms over 11 runs = {:.3e} ops/second ({n_ops} ops)",
        med * 1e3,
        n_ops as f64 / med
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
