//! Streamed statistics of bits of error: memory independent of the number of samples.
//!
//! Bits of error are `log2(1 + n)` for an integer ordinal distance `n` (Herbie), so a
//! histogram over `n` is natural. [`Stream`] keeps, per output and format, the count, the
//! exact sum (fixed point, 2⁻⁶⁴ bits: integer additions, so the mean does not depend on the
//! order of the samples or the number of threads), the maximum, and a sparse histogram:
//! - `n < 64` (errors below 6.02 bits, nearly every value on the corpus): one bin per `n`,
//!   so percentiles there are exact;
//! - `n ≥ 64`: 32 bins per power of two of `n` (HDR-histogram style), each at most
//!   [`BIN_WIDTH_BITS`] ≈ 0.0444 bits wide.
//!
//! Each bin remembers the largest value it received; a percentile is the largest value of the
//! bin holding its rank (nearest rank, the ⌈p·n⌉-th smallest), hence within one bin width of
//! the exact percentile (and equal to it when the bin holds one `n`). Memory: at most 1920 bins
//! per output and format, in practice a few dozen.

use super::measure::BitsSummary;

/// Bins below which each ordinal distance `n` has a bin of its own.
pub const EXACT_BELOW: u64 = 64;
/// Bins per power of two of `n` above [`EXACT_BELOW`].
pub const SUB_BINS: u64 = 32;
/// The widest bin, bits: `log2(1 + 1/32)` (a bin spans `[n, n·(1 + 1/32))`).
pub const BIN_WIDTH_BITS: f64 = 0.044_394_119_358_453_4;

const FIXED: f64 = 18_446_744_073_709_551_616.0; // 2^64

/// The bin of a bits-of-error value.
pub fn bin_of(bits: f64) -> u16 {
    let n = (bits.exp2() - 1.0).round().max(0.0);
    let n = if n >= FIXED { u64::MAX } else { n as u64 };
    if n < EXACT_BELOW {
        n as u16
    } else {
        let e = 63 - n.leading_zeros() as u64; // ≥ 6
        let m = (n >> (e - 5)) & (SUB_BINS - 1);
        (EXACT_BELOW + (e - 6) * SUB_BINS + m) as u16
    }
}

/// Count, exact sum, maximum and histogram of a stream of bits-of-error values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stream {
    /// Values added (minus values removed).
    pub count: u64,
    /// Sum of the values, units of 2⁻⁶⁴ bits.
    sum: i128,
    /// Largest value ever added, bits.
    pub max: f64,
    /// `(bin, count, largest value seen in the bin)`, sorted by bin.
    bins: Vec<(u16, u64, f64)>,
}

fn fixed(bits: f64) -> i128 {
    (bits * FIXED).round() as i128
}

impl Stream {
    /// Adds one value.
    pub fn add(&mut self, bits: f64) {
        self.count += 1;
        self.sum += fixed(bits);
        self.max = self.max.max(bits);
        let b = bin_of(bits);
        match self.bins.binary_search_by_key(&b, |x| x.0) {
            Ok(i) => {
                self.bins[i].1 += 1;
                self.bins[i].2 = self.bins[i].2.max(bits);
            }
            Err(i) => self.bins.insert(i, (b, 1, bits)),
        }
    }

    /// Removes one value added before (the hill climbing replaces its starting points). The
    /// maximum and the bins' largest values keep it: they cover every value evaluated.
    pub fn remove(&mut self, bits: f64) {
        let b = bin_of(bits);
        if let Ok(i) = self.bins.binary_search_by_key(&b, |x| x.0) {
            self.count -= 1;
            self.sum -= fixed(bits);
            self.bins[i].1 -= 1;
            if self.bins[i].1 == 0 {
                self.bins.remove(i);
            }
        }
    }

    /// Adds every value of `o`.
    pub fn merge(&mut self, o: &Stream) {
        self.count += o.count;
        self.sum += o.sum;
        self.max = self.max.max(o.max);
        let mut out = Vec::with_capacity(self.bins.len() + o.bins.len());
        let (mut i, mut j) = (0, 0);
        while i < self.bins.len() || j < o.bins.len() {
            let a = self.bins.get(i).copied();
            let b = o.bins.get(j).copied();
            match (a, b) {
                (Some(x), Some(y)) if x.0 == y.0 => {
                    out.push((x.0, x.1 + y.1, x.2.max(y.2)));
                    i += 1;
                    j += 1;
                }
                (Some(x), Some(y)) if x.0 < y.0 => {
                    out.push(x);
                    i += 1;
                }
                (Some(x), None) => {
                    out.push(x);
                    i += 1;
                }
                (_, Some(y)) => {
                    out.push(y);
                    j += 1;
                }
                (None, None) => unreachable!(),
            }
        }
        self.bins = out;
    }

    /// Mean, bits (0 when empty).
    pub fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum as f64 / FIXED / self.count as f64
        }
    }

    /// The `p`-quantile by nearest rank (the ⌈p·n⌉-th smallest value), to within one bin
    /// (see the module doc); 0 when empty.
    pub fn percentile(&self, p: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let rank = ((p * self.count as f64).ceil() as u64).clamp(1, self.count);
        let mut seen = 0;
        for &(_, c, top) in &self.bins {
            seen += c;
            if seen >= rank {
                return top;
            }
        }
        self.max
    }

    /// Mean, 95th percentile, maximum.
    pub fn summary(&self) -> BitsSummary {
        if self.count == 0 {
            return BitsSummary::default();
        }
        BitsSummary { mean_bits: self.mean(), p95_bits: self.percentile(0.95), max_bits: self.max }
    }
}

/// Count, sum and sum of squares of per-point values (the mean binary32 bits of each point),
/// exact in fixed point: the 95% confidence interval of the mean.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Moments {
    /// Values.
    pub count: u64,
    sum: i128,
    sq: i128,
}

impl Moments {
    /// Adds (`sign` = 1) or removes (`sign` = −1) a value (bits, 0 ≤ x ≤ 64).
    pub fn add(&mut self, x: f64, sign: i64) {
        self.count = self.count.wrapping_add_signed(sign);
        self.sum += sign as i128 * fixed(x);
        self.sq += sign as i128 * fixed(x * x);
    }

    /// Both sets of values.
    pub fn merge(&mut self, o: &Moments) {
        self.count += o.count;
        self.sum += o.sum;
        self.sq += o.sq;
    }

    /// Mean.
    pub fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum as f64 / FIXED / self.count as f64
        }
    }

    /// Half-width of the 95% confidence interval of the mean: 1.96·s/√n, `s` the sample
    /// standard deviation (0 for fewer than 2 values).
    pub fn ci95(&self) -> f64 {
        if self.count < 2 {
            return 0.0;
        }
        let n = self.count as f64;
        let mean = self.mean();
        let var = ((self.sq as f64 / FIXED) - n * mean * mean).max(0.0) / (n - 1.0);
        1.96 * (var / n).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::measure::summarise;

    #[test]
    fn bins_are_exact_below_64_and_at_most_the_documented_width_above() {
        for n in 0..64u64 {
            assert_eq!(bin_of(((n + 1) as f64).log2()), n as u16);
        }
        assert!((BIN_WIDTH_BITS - (33.0f64 / 32.0).log2()).abs() < 1e-15);
        // The lower end of every bin above 64 is n0 = (32 + m)·2^(e−5); the next bin starts at
        // (33 + m)·2^(e−5): the widest ratio is 33/32.
        let mut last = 0;
        for n in (64u64..1 << 20).step_by(7) {
            let b = bin_of(((n + 1) as f64).log2());
            assert!(b >= last, "bins grow with n");
            last = b;
        }
        assert_eq!(bin_of(64.0), bin_of(64.0 - 1e-12));
        assert!(bin_of(64.0) < 1920);
    }

    #[test]
    fn streamed_statistics_equal_the_batch_computation() {
        // Values as the metric produces them: log2(1 + n), small n mostly, a few large ones.
        let mut rng = robovec_ir::rng::SplitMix64::new(5);
        let xs: Vec<f64> = (0..5000)
            .map(|_| {
                let n = match rng.below(10) {
                    0 => rng.below(1 << 40),
                    1 => rng.below(5000),
                    _ => rng.below(9),
                };
                ((n + 1) as f64).log2()
            })
            .collect();
        // Split in three streams merged in another order: the same figures.
        let mut parts = [Stream::default(), Stream::default(), Stream::default()];
        for (i, &x) in xs.iter().enumerate() {
            parts[i % 3].add(x);
        }
        let mut s = parts[2].clone();
        s.merge(&parts[0]);
        s.merge(&parts[1]);
        let mut t = parts[0].clone();
        t.merge(&parts[1]);
        t.merge(&parts[2]);
        assert_eq!(s, t, "merging is order-independent");
        let batch = summarise(&mut xs.clone());
        let got = s.summary();
        assert_eq!(s.count, 5000);
        assert!((got.mean_bits - batch.mean_bits).abs() < 1e-12, "{got:?} {batch:?}");
        assert_eq!(got.max_bits, batch.max_bits);
        assert!(got.p95_bits >= batch.p95_bits && got.p95_bits - batch.p95_bits <= BIN_WIDTH_BITS);
        // Other quantiles too (nearest rank, computed independently on the sorted values).
        let mut sorted = xs.clone();
        sorted.sort_by(f64::total_cmp);
        for p in [0.01, 0.5, 0.9, 0.95, 0.99, 0.999, 1.0] {
            let exact = sorted[((p * 5000.0f64).ceil() as usize).clamp(1, 5000) - 1];
            let q = s.percentile(p);
            assert!(q >= exact && q - exact <= BIN_WIDTH_BITS, "p{p}: {q} vs {exact}");
            if exact < 6.0 {
                assert_eq!(q, exact, "exact below 64 ulps");
            }
        }
        // The confidence interval from the moments equals the textbook formula.
        let mut m = Moments::default();
        xs.iter().for_each(|&x| m.add(x, 1));
        let mean = xs.iter().sum::<f64>() / 5000.0;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / 4999.0;
        assert!((m.ci95() - 1.96 * (var / 5000.0).sqrt()).abs() < 1e-9 * m.ci95().max(1.0), "{}", m.ci95());
        // Removing a value undoes its count and sum.
        let mut r = s.clone();
        r.add(17.5);
        r.remove(17.5);
        assert_eq!((r.count, r.mean()), (s.count, s.mean()));
    }
}
