//! The measurement, streamed: samples are drawn, measured and folded into running statistics
//! chunk by chunk, so memory does not grow with `samples` (only the `worst-count` /
//! `climb-points` worst points are kept with their inputs and errors).
//!
//! Every statistic merges in an order-independent way (counts, exact fixed-point sums, maxima,
//! histograms; worst points ordered by objective then index), so results are deterministic
//! and independent of the number of threads and of the chunking.
//!
//! # Work budget
//! One sample costs `ops` = steps of the measured tape + steps of the reference tape (each
//! evaluated in binary32, binary64 and double-double). A run may spend at most
//! `max-work` = [`super::Options::max_work`] op evaluations (default 2·10¹⁰, ~10 minutes on
//! two cores): the samples measured are `min(samples, max(32, max-work / ops))`, and hill
//! climbing runs only the rounds the rest of the budget pays for. Either cut is reported
//! (`stopped_early` in the report, a line on stderr). A deadline (the driver's time limit) is
//! checked once per chunk; stopping there is also reported.

use std::time::Instant;

use rayon::prelude::*;

use super::acc::Acc;
use super::inputs::{self, range_in, rng_for};
use super::measure::{errors_at, skip_after_probes, PointErrors, Subject, Workspace, PROBES};
use super::{Mode, Options};

/// What a streamed run produced.
pub struct Run {
    /// The statistics.
    pub acc: Acc,
    /// Structural zeros (per output; see [`skip_after_probes`]).
    pub skip: Vec<bool>,
    /// Points evaluated, hill-climbing neighbours included.
    pub evaluations: u64,
    /// Why the run measured less than asked, if it did.
    pub stopped_early: Option<String>,
}

/// Samples per chunk: about 2²⁶ op evaluations (≈ 0.5 s on two cores), 256 to 65536 samples.
fn chunk_len(ops: u64) -> u64 {
    ((1u64 << 26) / ops.max(1)).clamp(256, 65536)
}

/// Measures `sub` under `o` (see the module doc).
pub fn run(sub: &Subject, o: &Options) -> Run {
    let ops = (sub.tape.steps.len() + sub.reference.steps.len()).max(1) as u64;
    run_chunked(sub, o, chunk_len(ops))
}

/// [`run`] with `chunk` samples per chunk (the results do not depend on it).
pub fn run_chunked(sub: &Subject, o: &Options, chunk: u64) -> Run {
    let n_out = sub.n_outputs();
    let ranges: Vec<inputs::Range> = sub.names.iter().map(|n| range_in(n, o.domain.as_ref())).collect();
    let hard = o.mode == Mode::Hard;
    let stream = hard as u64;
    let keep = o.worst_count.max(if hard { o.climb_points } else { 0 }) as usize;
    let draw = |i: u64| inputs::point(&sub.names, &ranges, &o.known, &mut rng_for(o.seed, stream, i), hard);
    let ops = (sub.tape.steps.len() + sub.reference.steps.len()).max(1) as u64;
    let mut stopped_early = None;
    let mut n = o.samples as u64;
    let affordable = (o.max_work / ops).max(PROBES as u64);
    if affordable < n {
        stopped_early = Some(format!(
            "work budget: measured {affordable} of {n} samples (max-work = {} op evaluations, {ops} ops per sample)",
            o.max_work
        ));
        n = affordable;
    }
    let probes = n.min(PROBES as u64);
    let probe_errs: Vec<PointErrors> =
        (0..probes).into_par_iter().map_init(Workspace::default, |ws, i| errors_at(sub, &draw(i), ws, None)).collect();
    let skip = skip_after_probes(&probe_errs, n_out);
    let mut acc = Acc::new(n_out, keep);
    for (i, e) in probe_errs.into_iter().enumerate() {
        acc.add(i as u64, || draw(i as u64), e);
    }
    let mut start = probes;
    while start < n {
        if o.deadline.is_some_and(|d| Instant::now() >= d) {
            stopped_early = Some(format!("time limit: measured {start} of {} samples", o.samples));
            n = start;
            break;
        }
        let end = (start + chunk).min(n);
        let part = (start..end)
            .into_par_iter()
            .fold(
                || (Workspace::default(), Acc::new(n_out, keep)),
                |(mut ws, mut a), i| {
                    let e = errors_at(sub, &draw(i), &mut ws, Some(&skip));
                    a.add(i, || draw(i), e);
                    (ws, a)
                },
            )
            .map(|(_, a)| a)
            .reduce(|| Acc::new(n_out, keep), Acc::merge);
        acc = acc.merge(part);
        start = end;
        o.progress.set(start);
    }
    let mut evaluations = n;
    if hard {
        let left = o.max_work.saturating_sub(n * ops) / ops;
        let (extra, note) = super::hard::climb(sub, &ranges, o, &skip, &mut acc, left);
        evaluations += extra;
        if let Some(note) = note {
            stopped_early = Some(stopped_early.map_or(note.clone(), |s| format!("{s}; {note}")));
        }
    }
    acc.worst.truncate(o.worst_count as usize);
    Run { acc, skip, evaluations, stopped_early }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::measure::summarise;
    use crate::accuracy::stats::BIN_WIDTH_BITS;
    use crate::accuracy::{measure_function, Options};
    use robovec_testkit::expr_gen;

    #[test]
    fn streamed_run_equals_a_batch_computation_and_ignores_chunking() {
        for seed in [1, 4] {
            let f = expr_gen::generate(seed);
            let o = Options { samples: 700, seed: 3, ..Options::default() };
            let r = measure_function(&f, &o);
            // Batch, independently: every point kept, sorted summaries (the former code path).
            let sub = Subject::new(&f, None).unwrap();
            let ranges: Vec<inputs::Range> = sub.names.iter().map(|n| inputs::range_of(n)).collect();
            let mut ws = Workspace::default();
            let errs: Vec<PointErrors> = (0..700)
                .map(|i| {
                    let p = inputs::point(&sub.names, &ranges, &o.known, &mut rng_for(3, 0, i), false);
                    errors_at(&sub, &p, &mut ws, None)
                })
                .collect();
            let mut all32: Vec<f64> = errs.iter().flat_map(|e| e.f32.iter().copied()).collect();
            let mut all64: Vec<f64> = errs.iter().flat_map(|e| e.f64.iter().copied()).collect();
            for (got, want) in [(r.f32, summarise(&mut all32)), (r.f64, summarise(&mut all64))] {
                assert!((got.mean_bits - want.mean_bits).abs() < 1e-12, "{got:?} {want:?}");
                assert_eq!(got.max_bits, want.max_bits);
                assert!(got.p95_bits >= want.p95_bits && got.p95_bits - want.p95_bits <= BIN_WIDTH_BITS);
            }
            let total: u64 = errs.iter().map(|e| e.f32.len() as u64).sum();
            let rc = r.reference.counts;
            assert_eq!(rc.double_double + rc.bits_256 + rc.bits_1024 + rc.uncertified, total);
            // The worst point is the batch's worst.
            let worst = errs.iter().map(|e| e.max_f32()).fold(0.0, f64::max);
            assert_eq!(r.worst[0].max_f32_bits, worst);
            // Another chunking and one thread: the same statistics and worst points.
            let a = run(&sub, &o);
            let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            let b = pool.install(|| run_chunked(&sub, &o, 7));
            assert_eq!((&a.acc.f32, &a.acc.f64, a.acc.reference), (&b.acc.f32, &b.acc.f64, b.acc.reference));
            assert_eq!(a.acc.point_means, b.acc.point_means);
            let idx = |r: &Run| r.acc.worst.iter().map(|k| k.index).collect::<Vec<_>>();
            assert_eq!(idx(&a), idx(&b));
            assert_eq!(chunk_len(1), 65536);
            assert_eq!(chunk_len(1 << 30), 256);
        }
    }
}
