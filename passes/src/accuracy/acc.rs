//! The running tally of a measurement: [`Acc`], the statistics of the points measured so far
//! (per-output bits of error, reference paths, per-point means) and the worst points [`Kept`]
//! with their inputs. The streamed run ([`super::stream`]) folds samples into it chunk by chunk
//! and the hill climbing ([`super::hard`]) replaces points in it; every merge is
//! order-independent (see [`super::stream`]'s module doc).

use std::cmp::Ordering;

use super::measure::PointErrors;
use super::stats::{Moments, Stream};

/// How many (output, point) reference values each path produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ReferenceCounts {
    /// Certified by double-double (≈ 106 bits).
    pub double_double: u64,
    /// Certified at 256 bits.
    pub bits_256: u64,
    /// Certified at 1024 bits.
    pub bits_1024: u64,
    /// Not certified (the 1024-bit value is used; typically an exact zero reached by inexact
    /// cancellation, e.g. `sin(a) − sin(a)`).
    pub uncertified: u64,
}

/// A point kept among the worst.
#[derive(Clone, Debug)]
pub struct Kept {
    /// Sample index.
    pub index: u64,
    /// Value of every coordinate ([`super::measure::Subject::names`]).
    pub point: Vec<f64>,
    /// Its errors.
    pub errs: PointErrors,
}

/// Worst first: larger (max f32 bits, mean f32 bits), then lower index.
fn order(a: &Kept, b: &Kept) -> Ordering {
    let (oa, ob) = ((a.errs.max_f32(), a.errs.mean_f32()), (b.errs.max_f32(), b.errs.mean_f32()));
    ob.0.total_cmp(&oa.0).then(ob.1.total_cmp(&oa.1)).then(a.index.cmp(&b.index))
}

/// Running statistics of a set of points.
#[derive(Clone, Debug, Default)]
pub struct Acc {
    /// Per output, binary32 bits.
    pub f32: Vec<Stream>,
    /// Per output, binary64 bits.
    pub f64: Vec<Stream>,
    /// Reference paths over every (output, point).
    pub reference: ReferenceCounts,
    /// The mean binary32 bits of each point (its confidence interval).
    pub point_means: Moments,
    /// Per output, the largest binary32 absolute error of every point added, in the output's
    /// units (upper bounds; `+∞` for a non-finite result: [`PointErrors::abs_f32`]). A
    /// maximum: order-independent, and kept by [`Acc::remove`].
    pub max_abs_f32: Vec<f64>,
    /// The same in binary64.
    pub max_abs_f64: Vec<f64>,
    /// The worst points, worst first (at most `keep`).
    pub worst: Vec<Kept>,
    keep: usize,
}

fn count_reference(r: &mut ReferenceCounts, e: &PointErrors, sign: i64) {
    for &(bits, ok, _) in &e.reference {
        let c = match (bits, ok) {
            (_, false) => &mut r.uncertified,
            (106, true) => &mut r.double_double,
            (256, true) => &mut r.bits_256,
            (_, true) => &mut r.bits_1024,
        };
        *c = c.wrapping_add_signed(sign);
    }
}

impl Acc {
    /// Empty statistics for `n` outputs, keeping the `keep` worst points.
    pub fn new(n: usize, keep: usize) -> Acc {
        Acc {
            f32: vec![Stream::default(); n],
            f64: vec![Stream::default(); n],
            max_abs_f32: vec![0.0; n],
            max_abs_f64: vec![0.0; n],
            keep,
            ..Acc::default()
        }
    }

    /// Adds point `index` (`point` is called only when the point is kept).
    pub fn add(&mut self, index: u64, point: impl FnOnce() -> Vec<f64>, errs: PointErrors) {
        self.add_stats(&errs);
        self.keep_point(Kept { index, point: Vec::new(), errs }, point);
    }

    /// Adds the errors of a point to the counts, sums, maxima and histograms only.
    pub fn add_stats(&mut self, errs: &PointErrors) {
        for (k, (&a, &b)) in errs.f32.iter().zip(&errs.f64).enumerate() {
            self.f32[k].add(a);
            self.f64[k].add(b);
        }
        for (m, &a) in self.max_abs_f32.iter_mut().zip(&errs.abs_f32) {
            *m = m.max(a);
        }
        for (m, &a) in self.max_abs_f64.iter_mut().zip(&errs.abs_f64) {
            *m = m.max(a);
        }
        count_reference(&mut self.reference, errs, 1);
        self.point_means.add(errs.mean_f32(), 1);
    }

    /// Re-sorts the worst points (after the hill climbing changed some).
    pub fn sort_worst(&mut self) {
        self.worst.sort_by(order);
    }

    fn keep_point(&mut self, mut k: Kept, point: impl FnOnce() -> Vec<f64>) {
        if self.keep == 0 {
            return;
        }
        if self.worst.len() == self.keep && order(&k, self.worst.last().expect("full")) != Ordering::Less {
            return;
        }
        if k.point.is_empty() {
            k.point = point();
        }
        let at = self.worst.partition_point(|w| order(w, &k) == Ordering::Less);
        self.worst.insert(at, k);
        self.worst.truncate(self.keep);
    }

    /// Takes the errors of a point out of the counts, sums and histograms (not the maxima).
    pub fn remove(&mut self, errs: &PointErrors) {
        for (k, (&a, &b)) in errs.f32.iter().zip(&errs.f64).enumerate() {
            self.f32[k].remove(a);
            self.f64[k].remove(b);
        }
        count_reference(&mut self.reference, errs, -1);
        self.point_means.add(errs.mean_f32(), -1);
    }

    /// Both sets of points.
    pub fn merge(mut self, o: Acc) -> Acc {
        for (a, b) in self.f32.iter_mut().zip(&o.f32) {
            a.merge(b);
        }
        for (a, b) in self.f64.iter_mut().zip(&o.f64) {
            a.merge(b);
        }
        for (a, b) in self.max_abs_f32.iter_mut().zip(&o.max_abs_f32) {
            *a = a.max(*b);
        }
        for (a, b) in self.max_abs_f64.iter_mut().zip(&o.max_abs_f64) {
            *a = a.max(*b);
        }
        let r = &mut self.reference;
        r.double_double += o.reference.double_double;
        r.bits_256 += o.reference.bits_256;
        r.bits_1024 += o.reference.bits_1024;
        r.uncertified += o.reference.uncertified;
        self.point_means.merge(&o.point_means);
        for k in o.worst {
            self.keep_point(k, Vec::new);
        }
        self
    }

    /// Points summarised.
    pub fn samples(&self) -> u64 {
        self.f32.first().map_or(0, |s| s.count)
    }
}
