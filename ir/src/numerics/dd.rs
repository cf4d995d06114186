//! Double-double arithmetic (≈ 106 bits): a value is an unevaluated sum `hi + lo` of two
//! `f64` with `hi = fl(hi + lo)`.
//!
//! Algorithms: TwoSum (Knuth), Dekker's TwoProduct with Veltkamp splitting (no FMA: it is a
//! library call on baseline x86-64), and the accurate double-word algorithms of Joldeș, Muller,
//! Popescu, "Tight and rigorous error bounds for basic building blocks of double-word
//! arithmetic", ACM TOMS 44(2), 2017 (Alg. 6 for `+`, a no-FMA variant of Alg. 10 for `×`).
//! Each operation here has a relative error below [`DD_UNIT`] = 2⁻¹⁰⁰ (the published bounds
//! are 3·2⁻¹⁰⁶ for `+` and ≤ 7·2⁻¹⁰⁶ for `×`, `/`, `sqrt`; 2⁻¹⁰⁰ leaves a margin for the no-FMA
//! variants). `sin`/`cos` reduce by π/2 in triple-double and sum a Taylor series: absolute
//! error below [`DD_TRIG_ABS`] for `|x| ≤ 2²⁰`; beyond that they return NaN (the reference
//! then falls back to the 256-bit path).
//!
//! Overflow: TwoProduct splits by 2²⁷ + 1, so operands above ≈ 2⁹⁹⁵ give non-finite results;
//! the reference treats a non-finite double-double as uncertain.

use std::sync::OnceLock;

use crate::interp::Float;

/// Bound on the relative error of one double-double operation (`+ - × / sqrt`), units: 1.
pub const DD_UNIT: f64 = 1.0 / (1u128 << 100) as f64;
/// Bound on the absolute error of [`DD::sin`] / [`DD::cos`] for `|x| ≤ 2²⁰`.
pub const DD_TRIG_ABS: f64 = 1.0 / (1u128 << 98) as f64;

/// A double-double number `hi + lo`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct DD {
    /// Leading part: the value rounded to binary64.
    pub hi: f64,
    /// Trailing part, `|lo| ≤ ulp(hi) / 2`.
    pub lo: f64,
}

/// TwoSum (Knuth): `(s, e)` with `s = fl(a + b)` and `s + e = a + b` exactly (barring overflow).
#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

#[inline]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

impl DD {
    /// The exact value of an `f64`.
    pub const fn from_f64(x: f64) -> DD {
        DD { hi: x, lo: 0.0 }
    }

    /// True when both parts are finite.
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// `|self|`.
    pub fn abs(self) -> DD {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }

    /// `self × b` for an `f64` `b`.
    pub fn mul_f64(self, b: f64) -> DD {
        let (p, e) = two_prod(self.hi, b);
        let (hi, lo) = fast_two_sum(p, e + self.lo * b);
        DD { hi, lo }
    }

    /// The value correctly rounded to binary64 (`hi`, since `hi = fl(hi + lo)`).
    pub fn round_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// The value `hi + lo` correctly rounded to binary32 (no double rounding: when `hi` lies
    /// exactly halfway between two binary32 values, the sign of `lo` decides).
    pub fn round_f32(self) -> f32 {
        let hi = self.round_f64();
        let lo = self.lo - (hi - self.hi);
        let r = hi as f32;
        if !r.is_finite() || lo == 0.0 {
            return r;
        }
        let d = hi - r as f64;
        if d == 0.0 {
            return r;
        }
        let other = if d > 0.0 { next_up_f32(r) } else { next_down_f32(r) };
        if !other.is_finite() {
            return r;
        }
        let mid = (r as f64 + other as f64) * 0.5;
        if mid == hi && (lo > 0.0) == (d > 0.0) {
            other
        } else {
            r
        }
    }

    /// Square root (relative error below [`DD_UNIT`]); NaN for negative values.
    pub fn sqrt(self) -> DD {
        if self.hi <= 0.0 {
            return DD::from_f64(self.hi.sqrt());
        }
        let s = self.hi.sqrt();
        let (p, e) = two_prod(s, s);
        let r = (self.hi - p - e + self.lo) / (2.0 * s);
        let (hi, lo) = fast_two_sum(s, r);
        DD { hi, lo }
    }

    /// Sine (absolute error below [`DD_TRIG_ABS`] for `|x| ≤ 2²⁰`, NaN beyond).
    pub fn sin(self) -> DD {
        let (k, r) = match reduce(self) {
            Some(x) => x,
            None => return DD::from_f64(f64::NAN),
        };
        match k & 3 {
            0 => sin_series(r),
            1 => cos_series(r),
            2 => -sin_series(r),
            _ => -cos_series(r),
        }
    }

    /// Cosine (absolute error below [`DD_TRIG_ABS`] for `|x| ≤ 2²⁰`, NaN beyond).
    pub fn cos(self) -> DD {
        let (k, r) = match reduce(self) {
            Some(x) => x,
            None => return DD::from_f64(f64::NAN),
        };
        match k & 3 {
            0 => cos_series(r),
            1 => -sin_series(r),
            2 => -cos_series(r),
            _ => sin_series(r),
        }
    }
}

fn next_up_f32(x: f32) -> f32 {
    if x == 0.0 {
        f32::from_bits(1)
    } else if x > 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

fn next_down_f32(x: f32) -> f32 {
    -next_up_f32(-x)
}

/// π/2 as a sum of three binary64 values (fdlibm's `pio2_1`, `pio2_2`, `pio2_3` with full
/// 53-bit parts).
const PIO2: [f64; 3] = [std::f64::consts::FRAC_PI_2, 6.123233995736766e-17, -1.4973849048591698e-33];

/// `x = k·π/2 + r` with `|r| ≤ π/4` (approximately), for `|x| ≤ 2²⁰`.
fn reduce(x: DD) -> Option<(i64, DD)> {
    if !x.is_finite() || x.hi.abs() > (1u64 << 20) as f64 {
        return None;
    }
    let k = (x.hi / PIO2[0]).round();
    let mut r = x;
    for p in PIO2 {
        r = r - DD::from_f64(k).mul_f64(p);
    }
    Some((k as i64, r))
}

/// Taylor coefficients 1/n! for n = 0..=31 as double-doubles.
fn inv_factorials() -> &'static [DD; 32] {
    static T: OnceLock<[DD; 32]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [DD::from_f64(1.0); 32];
        for n in 1..32 {
            t[n] = t[n - 1] / DD::from_f64(n as f64);
        }
        t
    })
}

/// `Σ_{n} (-1)^n c_{2n+off} r^{2n}` by Horner in r², for |r| ≤ 0.8 (terms up to r³¹/31!).
fn series(r2: DD, off: usize) -> DD {
    let c = inv_factorials();
    let mut acc = DD::from_f64(0.0);
    let mut n = (31 - off) / 2;
    loop {
        let term = if n & 1 == 0 { c[2 * n + off] } else { -c[2 * n + off] };
        acc = acc * r2 + term;
        if n == 0 {
            return acc;
        }
        n -= 1;
    }
}

fn sin_series(r: DD) -> DD {
    series(r * r, 1) * r
}

fn cos_series(r: DD) -> DD {
    series(r * r, 0)
}

impl std::ops::Neg for DD {
    type Output = DD;
    #[inline]
    fn neg(self) -> DD {
        DD { hi: -self.hi, lo: -self.lo }
    }
}

impl std::ops::Add for DD {
    type Output = DD;
    /// Joldeș–Muller–Popescu Alg. 6 (AccurateDWPlusDW).
    #[inline]
    fn add(self, y: DD) -> DD {
        let (sh, sl) = two_sum(self.hi, y.hi);
        let (th, tl) = two_sum(self.lo, y.lo);
        let (vh, vl) = fast_two_sum(sh, sl + th);
        let (hi, lo) = fast_two_sum(vh, tl + vl);
        if hi == 0.0 {
            // Exact cancellation: keep IEEE's sign of a zero sum.
            return DD { hi: self.hi + y.hi, lo: 0.0 };
        }
        DD { hi, lo }
    }
}

impl std::ops::Sub for DD {
    type Output = DD;
    #[inline]
    fn sub(self, y: DD) -> DD {
        self + -y
    }
}

impl std::ops::Mul for DD {
    type Output = DD;
    /// Joldeș–Muller–Popescu Alg. 10 (DWTimesDW1) with Dekker's TwoProduct.
    #[inline]
    fn mul(self, y: DD) -> DD {
        let (ch, cl1) = two_prod(self.hi, y.hi);
        let tl = self.hi * y.lo + self.lo * y.hi;
        let (hi, lo) = fast_two_sum(ch, cl1 + tl);
        if hi == 0.0 {
            return DD { hi: ch, lo: 0.0 };
        }
        DD { hi, lo }
    }
}

impl std::ops::Div for DD {
    type Output = DD;
    /// Long division with two correction steps (QD library's `accurate_div`).
    fn div(self, y: DD) -> DD {
        let q1 = self.hi / y.hi;
        if !q1.is_finite() || q1 == 0.0 {
            return DD::from_f64(q1);
        }
        let r = self - y.mul_f64(q1);
        let q2 = r.hi / y.hi;
        let r = r - y.mul_f64(q2);
        let q3 = r.hi / y.hi;
        let (h, l) = fast_two_sum(q1, q2);
        DD { hi: h, lo: l } + DD::from_f64(q3)
    }
}

/// Lets the interpreter's generic code ([`crate::interp::callback_standin`]) and the tape run
/// in double-double.
impl Float for DD {
    fn from_f64(x: f64) -> Self {
        DD::from_f64(x)
    }
    fn to_f64(self) -> f64 {
        self.round_f64()
    }
    fn sqrt(self) -> Self {
        DD::sqrt(self)
    }
    fn sin(self) -> Self {
        DD::sin(self)
    }
    fn cos(self) -> Self {
        DD::cos(self)
    }
    /// `self·b + c` in double-double: two roundings of ≈ 2⁻¹⁰⁶, not one (a reference, not
    /// an emulation of binary64's fused rounding).
    fn mul_add(self, b: Self, c: Self) -> Self {
        self * b + c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_keep_what_f64_loses() {
        // (1 + 2^-80) - 1 is 2^-80 exactly; binary64 gives 0.
        let x = DD::from_f64(1.0) + DD::from_f64(2f64.powi(-80));
        let d = x - DD::from_f64(1.0);
        assert_eq!(d.round_f64(), 2f64.powi(-80));
        // 0.1 + 0.2 - 0.3 with the binary64 inputs: exact value 2^-56 + 2^-57 (= 5.551115123125783e-17 + …)
        let s = DD::from_f64(0.1) + DD::from_f64(0.2) - DD::from_f64(0.3);
        // 0.1 = 3602879701896397·2^-55, 0.2 = 3602879701896397·2^-54, 0.3 = 5404319552844595·2^-54:
        // 0.1 + 0.2 − 0.3 = (3602879701896397 + 2·3602879701896397 − 2·5404319552844595)·2^-55 = 1·2^-55.
        assert_eq!(s.round_f64(), 2f64.powi(-55));
    }

    #[test]
    fn products_are_exact_to_106_bits() {
        // (2^27 + 1)^2 = 2^54 + 2^28 + 1 needs 55 bits.
        let a = DD::from_f64(134_217_729.0);
        let p = a * a;
        assert_eq!(p.hi, 18_014_398_777_917_440.0); // 2^54 + 2^28 (ties to even)
        assert_eq!(p.lo, 1.0);
    }

    #[test]
    fn rounding_to_binary32_breaks_ties_with_lo() {
        // 1 + 2^-24 is halfway between 1 and 1 + 2^-23 in binary32.
        let mid = 1.0 + 2f64.powi(-24);
        assert_eq!(DD { hi: mid, lo: 0.0 }.round_f32(), 1.0); // tie to even
        assert_eq!(DD { hi: mid, lo: 1e-30 }.round_f32(), 1.0 + f32::EPSILON);
        assert_eq!(DD { hi: mid, lo: -1e-30 }.round_f32(), 1.0);
        assert_eq!(DD { hi: -mid, lo: -1e-30 }.round_f32(), -1.0 - f32::EPSILON);
    }

    #[test]
    fn trig_matches_known_values() {
        // sin(π/6) = 1/2 up to the error of π/6 in binary64: use exact identities instead.
        for x in [0.1, 0.5, 1.0, 2.0, 3.0, -3.1, 10.0, 1000.0] {
            let (s, c) = (DD::from_f64(x).sin(), DD::from_f64(x).cos());
            let one = s * s + c * c - DD::from_f64(1.0);
            assert!(one.round_f64().abs() < 1e-30, "sin²+cos²−1 = {:e} at {x}", one.round_f64());
            assert!((s.round_f64() - x.sin()).abs() <= f64::EPSILON * x.sin().abs(), "sin {x}");
            assert!((c.round_f64() - x.cos()).abs() <= f64::EPSILON * x.cos().abs(), "cos {x}");
        }
        assert!(DD::from_f64(1e7).sin().hi.is_nan());
    }

    #[test]
    fn division_and_sqrt_invert_products() {
        let a = DD::from_f64(1.0) / DD::from_f64(3.0);
        let back = a * DD::from_f64(3.0) - DD::from_f64(1.0);
        assert!(back.round_f64().abs() < 1e-31);
        let r = DD::from_f64(2.0).sqrt();
        assert!((r * r - DD::from_f64(2.0)).round_f64().abs() < 1e-31);
    }
}
