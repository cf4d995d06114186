//! The search of `mode=hard`: a few rounds of deterministic hill climbing on the binary32
//! error, from the worst hard points.
//!
//! Objective of a point: the largest binary32 error over the outputs (bits), ties broken by the
//! mean. From each of the `climb-points` worst points, each round tries 8 neighbours — 1 to 3
//! inputs changed: an angle moved by ±2^−k (k uniform in [2, 30]), any other input scaled by
//! 1 ± 2^−k (k in [1, 24]), or (1 in 8) redrawn as a hard value — rounded to binary32, and
//! moves to the best neighbour that is worse than the current point. Known inputs (`params`)
//! never move; an input of the run's domain stays inside its range (each new value is clamped
//! into it and rounded to binary32 inward: [`super::inputs::Range::settle`]). Every point has its own generator, so the result does not depend on threads.
//! `-time-limit` (issue 28): each climb reads the clock once per round and stops there; the
//! rounds done are in `stopped_early` (and the result then depends on the machine's speed).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use super::acc::{Acc, Kept};
use super::inputs::{draw_hard, rng_for, Family, Range};
use super::measure::{errors_at, PointErrors, Subject, Workspace};
use super::Options;

const NEIGHBOURS: u64 = 8;

fn objective(e: &PointErrors) -> (f64, f64) {
    (e.max_f32(), e.mean_f32())
}

fn better(a: &PointErrors, b: &PointErrors) -> bool {
    objective(a).partial_cmp(&objective(b)) == Some(std::cmp::Ordering::Greater)
}

/// Climbs from the `climb-points` worst points of `acc`, replacing them (in the worst list
/// and in the statistics) by what it found. At most `budget` evaluations: the rounds are cut
/// to what it pays for. Returns the number of evaluations and, when rounds were cut, a note.
pub fn climb(
    sub: &Subject,
    ranges: &[Range],
    o: &Options,
    skip: &[bool],
    acc: &mut Acc,
    budget: u64,
) -> (u64, Option<String>) {
    let free: Vec<usize> = (0..ranges.len()).filter(|&i| !o.known.contains_key(&sub.names[i])).collect();
    let n_starts = (o.climb_points as usize).min(acc.worst.len());
    if o.climb_rounds == 0 || free.is_empty() || n_starts == 0 {
        return (0, None);
    }
    let per_round = n_starts as u64 * NEIGHBOURS;
    let rounds = (o.climb_rounds as u64).min(budget / per_round);
    let note = (rounds < o.climb_rounds as u64).then(|| {
        format!(
            "work budget: {rounds} of {} hill-climbing rounds (max-work = {} op evaluations)",
            o.climb_rounds, o.max_work
        )
    });
    let starts: Vec<Kept> = acc.worst[..n_starts].to_vec();
    // `-time-limit`: each climb checks the clock once per round (8 evaluations) and stops there.
    let rounds_done = AtomicU64::new(0);
    let found: Vec<Kept> = starts
        .par_iter()
        .map_init(Workspace::default, |ws, k| {
            let mut rng = rng_for(o.seed, 2, k.index);
            let (mut x, mut e) = (k.point.clone(), k.errs.clone());
            for _ in 0..rounds {
                if o.deadline.is_some_and(|d| Instant::now() >= d) {
                    break;
                }
                rounds_done.fetch_add(1, Ordering::Relaxed);
                let mut best: Option<(Vec<f64>, PointErrors)> = None;
                for _ in 0..NEIGHBOURS {
                    let mut y = x.clone();
                    for _ in 0..1 + rng.below(3) {
                        let k = free[rng.below(free.len() as u64) as usize];
                        let sign = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                        // Rounded to binary32, and inside the domain's range when it has one.
                        y[k] = ranges[k].settle(if rng.below(8) == 0 {
                            draw_hard(&mut rng, &ranges[k])
                        } else if ranges[k].family == Family::Angle {
                            y[k] + sign * 2f64.powf(-(2.0 + 28.0 * rng.unit()))
                        } else {
                            y[k] * (1.0 + sign * 2f64.powf(-(1.0 + 23.0 * rng.unit())))
                        });
                    }
                    let ey = errors_at(sub, &y, ws, Some(skip));
                    if best.as_ref().is_none_or(|(_, b)| better(&ey, b)) {
                        best = Some((y, ey));
                    }
                }
                if let Some((y, ey)) = best {
                    if better(&ey, &e) {
                        (x, e) = (y, ey);
                    }
                }
            }
            Kept { index: k.index, point: x, errs: e }
        })
        .collect();
    for (j, (s, f)) in starts.iter().zip(found).enumerate() {
        acc.remove(&s.errs);
        acc.add_stats(&f.errs);
        acc.worst[j] = f;
    }
    acc.sort_worst();
    let done = rounds_done.into_inner();
    let planned = n_starts as u64 * rounds;
    let note = if done < planned {
        let cut = format!("time limit: {done} of {planned} hill-climbing rounds ({n_starts} climbs of {rounds})");
        Some(note.map_or(cut.clone(), |n| format!("{n}; {cut}")))
    } else {
        note
    };
    (done * NEIGHBOURS, note)
}

#[cfg(test)]
mod tests {
    use crate::accuracy::{measure_function, Mode, Options};
    use robovec_testkit::expr_gen;

    #[test]
    fn climbing_is_deterministic_and_never_loses_the_worst_point() {
        for seed in [1, 2, 3] {
            let f = expr_gen::generate(seed);
            let o = Options { samples: 64, mode: Mode::Hard, climb_rounds: 0, ..Options::default() };
            let flat = measure_function(&f, &o);
            let o = Options { climb_rounds: 4, ..o };
            let a = measure_function(&f, &o);
            let b = measure_function(&f, &o);
            assert_eq!(
                a.worst.iter().map(|w| &w.inputs).collect::<Vec<_>>(),
                b.worst.iter().map(|w| &w.inputs).collect::<Vec<_>>()
            );
            assert_eq!(a.evaluations, 64 + 8 * 4 * 8);
            assert!(a.worst[0].max_f32_bits >= flat.worst[0].max_f32_bits, "seed {seed}");
        }
    }
}
