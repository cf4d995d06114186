//! The one pseudo-random generator of the workspace: [`SplitMix64`] (Steele, Lea and Flood,
//! "Fast splittable pseudorandom number generators", OOPSLA 2014).
//!
//! Everything in robovec that draws pseudo-random numbers uses it, so a seed means the same
//! stream everywhere: `accuracy`'s sampled inputs (issue 8), `place`'s restarts and key
//! search, [`crate::interp::pseudo_random_input`] (one draw from a hash of the input name), the
//! synthetic C files of the scaling benchmark, and the test generators of `robovec-testkit`.
//! Deterministic for a seed, no external crate, not cryptographic. Cost: a few integer
//! operations per draw.

/// splitmix64: 64 bits of state, one draw per [`SplitMix64::next_u64`].
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed` (every seed, zero included, gives a full-period stream).
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform integer in `0..n` (`n > 0`; multiply-high, bias below 2⁻³² for small `n`).
    pub fn below(&mut self, n: u64) -> u64 {
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }

    /// True with probability `per_mille / 1000`.
    pub fn chance(&mut self, per_mille: u64) -> bool {
        self.below(1000) < per_mille
    }

    /// A uniform number in [0, 1) (the top 53 random bits of one draw).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_draws_match_the_reference_implementation() {
        // The reference splitmix64.c (prng.di.unimi.it) seeded with 1234567, transcribed
        // independently (Python, arbitrary-precision integers masked to 64 bits).
        let mut r = SplitMix64::new(1234567);
        assert_eq!(
            [r.next_u64(), r.next_u64(), r.next_u64()],
            [6457827717110365317, 3203168211198807973, 9817491932198370423]
        );
    }

    #[test]
    fn below_and_unit_stay_in_range() {
        let mut r = SplitMix64::new(0);
        for n in [1u64, 2, 3, 10, 1000, u64::MAX] {
            for _ in 0..100 {
                assert!(r.below(n) < n);
            }
        }
        let mut seen = [0u32; 4];
        for _ in 0..4000 {
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
            seen[(u * 4.0) as usize] += 1;
        }
        assert!(seen.iter().all(|&c| (800..1200).contains(&c)), "{seen:?}");
    }
}
