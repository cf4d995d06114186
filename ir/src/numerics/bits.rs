//! Bits of error (Herbie's metric): `log2(1 + n)` where `n` is the number of floating-point
//! values between a computed result and the correctly rounded exact result, counted over the
//! bit patterns of the format (ordinal distance).
//!
//! Source: Herbie, `www/doc/2.2/error.html` and `src/syntax/float.rkt`; SPEC §6. Conventions:
//! - `0` and `-0` are the same point (0 apart);
//! - two identical non-finite results (same infinity, or NaN and NaN) are 0 apart;
//! - any other pair involving a NaN or an infinity counts as the maximum: 32 bits for
//!   binary32, 64 bits for binary64.
//!
//! 1 float apart is 1 bit, 3 apart is 2 bits, 7 apart is 3 bits; the largest finite distance
//! (−MAX to +MAX) is just under 32 (binary32) or 64 (binary64) bits.

/// Maximum bits of error in binary32 (a NaN or an infinity against anything else).
pub const MAX_BITS_F32: f64 = 32.0;
/// Maximum bits of error in binary64.
pub const MAX_BITS_F64: f64 = 64.0;

/// Position of a finite or infinite `f64` on the number line of binary64 bit patterns:
/// consecutive floats have consecutive ordinals, `0.0` and `-0.0` both map to 0.
pub fn ordinal_f64(x: f64) -> i64 {
    let b = x.to_bits();
    let mag = (b & 0x7fff_ffff_ffff_ffff) as i64;
    if b >> 63 == 1 {
        -mag
    } else {
        mag
    }
}

/// Position of an `f32` on the number line of binary32 bit patterns (see [`ordinal_f64`]).
pub fn ordinal_f32(x: f32) -> i64 {
    let b = x.to_bits();
    let mag = (b & 0x7fff_ffff) as i64;
    if b >> 31 == 1 {
        -mag
    } else {
        mag
    }
}

/// Number of binary64 steps between `a` and `b` (ordinal distance), units: ulps.
pub fn ulps_f64(a: f64, b: f64) -> u64 {
    (ordinal_f64(a) as i128 - ordinal_f64(b) as i128).unsigned_abs() as u64
}

/// Number of binary32 steps between `a` and `b`, units: ulps.
pub fn ulps_f32(a: f32, b: f32) -> u64 {
    (ordinal_f32(a) - ordinal_f32(b)).unsigned_abs()
}

/// Bits of error of `computed` against `exact` (the correctly rounded exact value), binary64.
pub fn bits_f64(computed: f64, exact: f64) -> f64 {
    if computed.is_nan() || exact.is_nan() {
        return if computed.is_nan() && exact.is_nan() { 0.0 } else { MAX_BITS_F64 };
    }
    if computed.is_infinite() || exact.is_infinite() {
        return if computed == exact { 0.0 } else { MAX_BITS_F64 };
    }
    ((ulps_f64(computed, exact) as f64) + 1.0).log2()
}

/// Bits of error of `computed` against `exact` (the correctly rounded exact value), binary32.
pub fn bits_f32(computed: f32, exact: f32) -> f64 {
    if computed.is_nan() || exact.is_nan() {
        return if computed.is_nan() && exact.is_nan() { 0.0 } else { MAX_BITS_F32 };
    }
    if computed.is_infinite() || exact.is_infinite() {
        return if computed == exact { 0.0 } else { MAX_BITS_F32 };
    }
    ((ulps_f32(computed, exact) as f64) + 1.0).log2()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The next float up, by bit manipulation (independent of the ordinal code).
    fn up(x: f64) -> f64 {
        if x == 0.0 {
            f64::from_bits(1)
        } else if x > 0.0 {
            f64::from_bits(x.to_bits() + 1)
        } else {
            f64::from_bits(x.to_bits() - 1)
        }
    }

    #[test]
    fn herbie_examples() {
        let x = 1.0f64;
        assert_eq!(bits_f64(x, x), 0.0);
        assert_eq!(bits_f64(up(x), x), 1.0);
        assert_eq!(bits_f64(up(up(up(x))), x), 2.0);
        let mut y = x;
        for _ in 0..7 {
            y = up(y);
        }
        assert_eq!(bits_f64(y, x), 3.0);
        assert_eq!(bits_f32(1.0 + f32::EPSILON, 1.0), 1.0);
        assert_eq!(bits_f32(1.0 + 3.0 * f32::EPSILON, 1.0), 2.0);
    }

    #[test]
    fn signed_zero_and_crossing_zero() {
        assert_eq!(bits_f64(0.0, -0.0), 0.0);
        assert_eq!(bits_f32(-0.0, 0.0), 0.0);
        // The smallest subnormals on either side of zero are 2 steps apart (via 0).
        let d = f64::from_bits(1);
        assert_eq!(ulps_f64(d, -d), 2);
        assert_eq!(bits_f64(d, -d), 3f64.log2());
        // Just below 1 and 1: binary32 has 2^23 floats in [0.5, 1).
        assert_eq!(ulps_f32(0.5, 1.0), 1 << 23);
        assert_eq!(bits_f32(0.5, 1.0), ((1u64 << 23) as f64 + 1.0).log2());
    }

    #[test]
    fn non_finite_is_maximal_unless_identical() {
        assert_eq!(bits_f64(f64::NAN, 1.0), 64.0);
        assert_eq!(bits_f64(1.0, f64::NAN), 64.0);
        assert_eq!(bits_f64(f64::NAN, f64::NAN), 0.0);
        assert_eq!(bits_f64(f64::INFINITY, f64::MAX), 64.0);
        assert_eq!(bits_f64(f64::INFINITY, f64::INFINITY), 0.0);
        assert_eq!(bits_f64(f64::NEG_INFINITY, f64::INFINITY), 64.0);
        assert_eq!(bits_f32(f32::NAN, 0.0), 32.0);
        assert_eq!(bits_f32(f32::INFINITY, f32::INFINITY), 0.0);
        // The widest finite gap stays below the maximum.
        assert!(bits_f64(-f64::MAX, f64::MAX) < 64.0 && bits_f64(-f64::MAX, f64::MAX) > 63.0);
        assert!(bits_f32(-f32::MAX, f32::MAX) < 32.0 && bits_f32(-f32::MAX, f32::MAX) > 31.0);
    }
}
