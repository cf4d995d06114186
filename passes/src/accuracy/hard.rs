//! The search of `mode=hard`: a few rounds of deterministic hill climbing on the binary32
//! error, from the worst hard points.
//!
//! Objective of a point: the largest binary32 error over the outputs (bits), ties broken by the
//! mean. From each of the `climb-points` worst points, each round tries 8 neighbours — 1 to 3
//! inputs changed: an angle moved by ±2^−k (k uniform in [2, 30]), any other input scaled by
//! 1 ± 2^−k (k in [1, 24]), or (1 in 8) redrawn as a hard value — rounded to binary32, and
//! moves to the best neighbour that is worse than the current point. Known inputs (`params`)
//! never move. Every point has its own generator, so the result does not depend on threads.

use rayon::prelude::*;
use robovec_ir::numerics::Tape;

use super::inputs::{draw_hard, rng_for, unit, Family, Range};
use super::measure::{errors_at, PointErrors, Workspace};
use super::Options;

const NEIGHBOURS: u32 = 8;

fn objective(e: &PointErrors) -> (f64, f64) {
    (e.max_f32(), e.mean_f32())
}

fn better(a: &PointErrors, b: &PointErrors) -> bool {
    objective(a).partial_cmp(&objective(b)) == Some(std::cmp::Ordering::Greater)
}

/// Indices of the `n` worst points (largest objective first; ties by lower index).
pub fn worst_indices(errs: &[PointErrors], n: usize) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..errs.len()).collect();
    idx.sort_by(|&a, &b| {
        let (oa, ob) = (objective(&errs[a]), objective(&errs[b]));
        ob.0.total_cmp(&oa.0).then(ob.1.total_cmp(&oa.1)).then(a.cmp(&b))
    });
    idx.truncate(n);
    idx
}

/// Climbs from the worst points, replacing them in `points`/`errs` by what it found; returns
/// the number of extra evaluations.
pub fn climb(
    tape: &Tape,
    ranges: &[Range],
    o: &Options,
    skip: &[bool],
    points: &mut [Vec<f64>],
    errs: &mut [PointErrors],
) -> u64 {
    let free: Vec<usize> = (0..ranges.len()).filter(|&i| !o.known.contains_key(&tape.inputs[i])).collect();
    if o.climb_rounds == 0 || free.is_empty() {
        return 0;
    }
    let starts = worst_indices(errs, o.climb_points as usize);
    let found: Vec<(usize, Vec<f64>, PointErrors)> = starts
        .par_iter()
        .map_init(Workspace::default, |ws, &i| {
            let mut rng = rng_for(o.seed, 2, i as u64);
            let (mut x, mut e) = (points[i].clone(), errs[i].clone());
            for _ in 0..o.climb_rounds {
                let mut best: Option<(Vec<f64>, PointErrors)> = None;
                for _ in 0..NEIGHBOURS {
                    let mut y = x.clone();
                    for _ in 0..1 + rng.below(3) {
                        let k = free[rng.below(free.len() as u64) as usize];
                        let sign = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                        y[k] = if rng.below(8) == 0 {
                            draw_hard(&mut rng, &ranges[k])
                        } else if ranges[k].family == Family::Angle {
                            y[k] + sign * 2f64.powf(-(2.0 + 28.0 * unit(&mut rng)))
                        } else {
                            y[k] * (1.0 + sign * 2f64.powf(-(1.0 + 23.0 * unit(&mut rng))))
                        } as f32 as f64;
                    }
                    let ey = errors_at(tape, &y, ws, Some(skip));
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
            (i, x, e)
        })
        .collect();
    for (i, x, e) in found {
        points[i] = x;
        errs[i] = e;
    }
    starts.len() as u64 * o.climb_rounds as u64 * NEIGHBOURS as u64
}

#[cfg(test)]
mod tests {
    use crate::accuracy::{measure_function, Mode, Options};
    use crate::expr_gen;

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
