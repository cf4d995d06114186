//! Closed intervals of reals with outward-rounded arithmetic (interval arithmetic, Moore 1966;
//! the directed roundings of IEEE 754 done without switching the rounding mode).
//!
//! An [`Interval`] `[lo, hi]` (binary64 endpoints, `lo ≤ hi`, never NaN; `lo = −∞` or
//! `hi = +∞` for an unbounded side) **encloses** a set of reals. Every operation returns an
//! interval that encloses the exact result of the operation on every pair of reals in its
//! operands' enclosures (the real image), with the endpoints rounded **outward**: the lower
//! endpoint is rounded toward −∞ and the upper toward +∞.
//!
//! **Outward rounding without a rounding mode.** Rust computes in round-to-nearest only. Each
//! endpoint is computed in round-to-nearest and its rounding error is then found exactly with
//! an error-free transformation — TwoSum for `+`/`−` (Knuth; exact without overflow, subnormal
//! results included), the fused multiply-add for `×`, `/` and `√` (`a·b − p`, `a − q·b` and
//! `s·s − x` are exact in binary64 away from underflow) — and the endpoint is moved one float
//! outward ([`f64::next_down`], [`f64::next_up`]) only when the error points outward. Near the
//! underflow threshold (results below 2⁻⁹⁶⁰ in magnitude) or on overflow the endpoint is moved
//! outward unconditionally (or to ±∞ / ±`f64::MAX`), which is always sound. So each endpoint
//! is the directed rounding of the exact endpoint: the tightest float enclosure of the real
//! image.
//!
//! **What an enclosure contains.** Since round-to-nearest is monotone, a binary64 operation
//! applied to operands inside their enclosures gives a result inside the outward-rounded
//! enclosure too; so an enclosure computed value by value contains both the exact (real)
//! value of a function over a domain and the value the interpreter computes in binary64 in
//! the IR's order ([`crate::interp`]). (Not the binary32 value: its roundings are coarser.)
//!
//! `sin` and `cos` ([`Interval::sin`], [`Interval::cos`]) are enclosed from the angle's
//! interval: the values at the ends, and ±1 where a crest `π/2 + kπ` lies inside, widened by
//! [`LIBM_ULPS`] ulps for the error of the C library's `sin`/`cos`, which the interpreter calls.

use serde::Serialize;

/// Ulps of error assumed of the platform's binary64 `sin` and `cos` (glibc documents at most
/// 1 ulp on x86-64 and AArch64 — its manual's "Known Maximum Errors in Math Functions"; musl
/// and macOS are within 1 ulp too). Enclosures of `sin`/`cos` are widened by four times that
/// (plus one float for the widening's own rounding), so a libm up to 4 ulps off stays inside.
pub const LIBM_ULPS: f64 = 4.0;

/// Below this magnitude (2⁻⁹⁶⁰) a product, quotient or square root may lose bits to
/// underflow, so the fused multiply-add no longer gives its error exactly: its endpoint is
/// moved outward unconditionally.
const TINY: f64 = 1.0252524436350518e-289;

/// A closed interval `[lo, hi]` of reals (see the module doc): `lo ≤ hi`, neither NaN; `lo`
/// may be −∞ and `hi` +∞, never `lo = +∞` nor `hi = −∞`. Units are those of the value it
/// encloses. Serialises as the JSON pair `[lo, hi]` (an infinite side as `null`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower endpoint.
    pub lo: f64,
    /// Upper endpoint.
    pub hi: f64,
}

impl Serialize for Interval {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let side = |x: f64| x.is_finite().then_some(x);
        [side(self.lo), side(self.hi)].serialize(s)
    }
}

impl std::fmt::Display for Interval {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{:e}, {:e}]", self.lo, self.hi)
    }
}

/// Where an interval lies with respect to 0: `lo ≥ 0`, `hi ≤ 0` (and not the first), or 0
/// strictly inside.
#[derive(Clone, Copy)]
enum Sign {
    Pos,
    Neg,
    Mixed,
}

/// `a + b` rounded down (toward −∞).
#[inline]
fn add_down(a: f64, b: f64) -> f64 {
    let s = a + b;
    if s.is_nan() {
        return f64::NEG_INFINITY;
    }
    if s == f64::INFINITY && a.is_finite() && b.is_finite() {
        return f64::MAX;
    }
    if !s.is_finite() {
        return s;
    }
    // TwoSum: s + e = a + b exactly.
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    if e < 0.0 {
        s.next_down()
    } else {
        s
    }
}

/// `a + b` rounded up (toward +∞).
#[inline]
fn add_up(a: f64, b: f64) -> f64 {
    -add_down(-a, -b)
}

/// `a · b` rounded down; `0 · ±∞ = 0` (a zero endpoint is an exact zero, an infinite one an
/// unbounded side: their product is bounded by 0).
#[inline]
fn mul_down(a: f64, b: f64) -> f64 {
    if a == 0.0 || b == 0.0 {
        return 0.0;
    }
    let p = a * b;
    if p.is_nan() {
        return f64::NEG_INFINITY;
    }
    if !p.is_finite() {
        return if p > 0.0 && a.is_finite() && b.is_finite() { f64::MAX } else { p };
    }
    if p.abs() < TINY {
        return p.next_down();
    }
    let e = a.mul_add(b, -p);
    if e < 0.0 {
        p.next_down()
    } else {
        p
    }
}

/// `a · b` rounded up.
#[inline]
fn mul_up(a: f64, b: f64) -> f64 {
    -mul_down(-a, b)
}

/// `a / b` rounded down (`b ≠ 0`; `±∞ / ±∞` is unbounded: −∞).
fn div_down(a: f64, b: f64) -> f64 {
    if a == 0.0 {
        return 0.0;
    }
    let q = a / b;
    if q.is_nan() {
        return f64::NEG_INFINITY;
    }
    if !q.is_finite() {
        return if q > 0.0 && a.is_finite() { f64::MAX } else { q };
    }
    if q.abs() < TINY || b.is_infinite() || q == 0.0 {
        return q.next_down();
    }
    // r = a − q·b exactly; the exact quotient is q + r/b.
    let r = -q.mul_add(b, -a);
    if r != 0.0 && (r < 0.0) != (b < 0.0) {
        q.next_down()
    } else {
        q
    }
}

/// `a / b` rounded up.
fn div_up(a: f64, b: f64) -> f64 {
    -div_down(-a, b)
}

impl Interval {
    /// Every real: `[−∞, +∞]` (an opaque callback's value).
    pub const ENTIRE: Interval = Interval { lo: f64::NEG_INFINITY, hi: f64::INFINITY };

    /// `[lo, hi]`.
    ///
    /// # Panics
    /// When `lo > hi` or either is NaN (callers check values they read: [`crate::domain`]).
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Interval {
        assert!(lo <= hi, "an interval needs lo <= hi, got [{lo}, {hi}]");
        Interval { lo, hi }
    }

    /// The point interval `[x, x]` (a constant, a parameter at its value).
    #[inline]
    pub fn point(x: f64) -> Interval {
        Interval { lo: x, hi: x }
    }

    /// `hi − lo` rounded up (+∞ when unbounded).
    pub fn width(self) -> f64 {
        add_up(self.hi, -self.lo)
    }

    /// True when `x` lies in the interval.
    #[inline]
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// True when both ends are finite.
    #[inline]
    pub fn is_bounded(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The smallest interval holding both.
    #[inline]
    pub fn hull(self, o: Interval) -> Interval {
        Interval { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }

    /// `max(|lo|, |hi|)`: the largest magnitude of the enclosed values.
    #[inline]
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest magnitude of the enclosed values: `lo` when all are positive, `-hi` when
    /// all are negative, 0 when the interval holds 0.
    pub fn mig(self) -> f64 {
        if self.lo > 0.0 {
            self.lo
        } else if self.hi < 0.0 {
            -self.hi
        } else {
            0.0
        }
    }

    /// An interval from two endpoints computed outward, NaN-free by construction.
    #[inline]
    fn of(lo: f64, hi: f64) -> Interval {
        debug_assert!(!lo.is_nan() && !hi.is_nan() && lo <= hi, "[{lo}, {hi}]");
        Interval { lo, hi }
    }

    /// Where the interval lies with respect to 0 (Moore's cases of a product).
    #[inline]
    fn sign(self) -> Sign {
        if self.lo >= 0.0 {
            Sign::Pos
        } else if self.hi <= 0.0 {
            Sign::Neg
        } else {
            Sign::Mixed
        }
    }

    /// The enclosure of `a · a` for one value `a` (not `a · b` with both in the same interval:
    /// the square is never negative, so `[−1, 2]²` is `[0, 4]`, not `[−2, 4]`).
    pub fn sqr(self) -> Interval {
        if self.lo >= 0.0 {
            Interval::of(mul_down(self.lo, self.lo), mul_up(self.hi, self.hi))
        } else if self.hi <= 0.0 {
            Interval::of(mul_down(self.hi, self.hi), mul_up(self.lo, self.lo))
        } else {
            Interval::of(0.0, mul_up(self.lo, self.lo).max(mul_up(self.hi, self.hi)))
        }
    }

    /// The enclosure of `a / b`, or `None` when `b`'s interval contains 0 (the quotient is then
    /// unbounded or undefined: the caller reports it).
    pub fn checked_div(self, o: Interval) -> Option<Interval> {
        if o.contains(0.0) {
            return None;
        }
        let (a, b) = (self, o);
        let lo = div_down(a.lo, b.lo).min(div_down(a.lo, b.hi)).min(div_down(a.hi, b.lo)).min(div_down(a.hi, b.hi));
        let hi = div_up(a.lo, b.lo).max(div_up(a.lo, b.hi)).max(div_up(a.hi, b.lo)).max(div_up(a.hi, b.hi));
        Some(Interval::of(lo, hi))
    }

    /// The enclosure of `√a`, or `None` when `a`'s interval holds negative numbers (whose
    /// square root is NaN: the caller reports it).
    pub fn sqrt(self) -> Option<Interval> {
        if self.lo < 0.0 {
            return None;
        }
        let down = |x: f64| {
            let s = x.sqrt();
            if x == 0.0 || s.is_infinite() {
                return s;
            }
            // s·s − x exactly (s ≥ 2⁻⁵³⁷ for any positive x: no underflow in s·s but for
            // subnormal x, where the move is unconditional).
            let e = s.mul_add(s, -x);
            if e > 0.0 || x < TINY {
                s.next_down().max(0.0)
            } else {
                s
            }
        };
        let up = |x: f64| {
            let s = x.sqrt();
            if x == 0.0 || s.is_infinite() {
                return s;
            }
            let e = s.mul_add(s, -x);
            if e < 0.0 || x < TINY {
                s.next_up()
            } else {
                s
            }
        };
        Some(Interval::of(down(self.lo), up(self.hi)))
    }

    /// The enclosure of the fused `a · b + c`.
    pub fn fma(self, b: Interval, c: Interval) -> Interval {
        self * b + c
    }

    /// The enclosure of `sin a` (see the module doc): `[−1, 1]` when the interval spans a
    /// period or is unbounded.
    pub fn sin(self) -> Interval {
        trig(self, false)
    }

    /// The enclosure of `cos a`: `sin(a + π/2)` with the crests shifted (computed directly,
    /// not through an addition).
    pub fn cos(self) -> Interval {
        trig(self, true)
    }
}

impl std::ops::Add for Interval {
    type Output = Interval;
    /// The enclosure of `a + b`.
    #[inline]
    fn add(self, o: Interval) -> Interval {
        Interval::of(add_down(self.lo, o.lo), add_up(self.hi, o.hi))
    }
}

impl std::ops::Sub for Interval {
    type Output = Interval;
    /// The enclosure of `a − b`.
    #[inline]
    fn sub(self, o: Interval) -> Interval {
        Interval::of(add_down(self.lo, -o.hi), add_up(self.hi, -o.lo))
    }
}

impl std::ops::Neg for Interval {
    type Output = Interval;
    /// The enclosure of `−a` (exact).
    #[inline]
    fn neg(self) -> Interval {
        Interval { lo: -self.hi, hi: -self.lo }
    }
}

impl std::ops::Mul for Interval {
    type Output = Interval;
    /// The enclosure of `a · b`: the least and greatest products of the ends, rounded outward.
    /// By the operands' signs (Moore's nine cases) the ends that give them are known, so one
    /// product is rounded down and one up; only when both operands hold zero inside are all
    /// four products compared. Directed rounding is monotone, so the rounded extreme products
    /// are the extremes of the four rounded products (or inside them, and still enclosing,
    /// where an exact zero meets a product that underflows).
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        use Sign::{Mixed, Neg, Pos};
        let (a, b) = (self, o);
        // The ends whose products are the least and the greatest.
        let ((la, lb), (ha, hb)) = match (a.sign(), b.sign()) {
            (Pos, Pos) => ((a.lo, b.lo), (a.hi, b.hi)),
            (Pos, Neg) => ((a.hi, b.lo), (a.lo, b.hi)),
            (Pos, Mixed) => ((a.hi, b.lo), (a.hi, b.hi)),
            (Neg, Pos) => ((a.lo, b.hi), (a.hi, b.lo)),
            (Neg, Neg) => ((a.hi, b.hi), (a.lo, b.lo)),
            (Neg, Mixed) => ((a.lo, b.hi), (a.lo, b.lo)),
            (Mixed, Pos) => ((a.lo, b.hi), (a.hi, b.hi)),
            (Mixed, Neg) => ((a.hi, b.lo), (a.lo, b.lo)),
            (Mixed, Mixed) => {
                let lo = mul_down(a.lo, b.hi).min(mul_down(a.hi, b.lo));
                let hi = mul_up(a.lo, b.lo).max(mul_up(a.hi, b.hi));
                return Interval::of(lo, hi);
            }
        };
        Interval::of(mul_down(la, lb), mul_up(ha, hb))
    }
}

/// `v` moved outward by [`LIBM_ULPS`] ulps of `v` and one float, clamped to `[−1, 1]`.
fn widen_libm(v: f64, up: bool) -> f64 {
    let margin = v.abs() * (LIBM_ULPS * f64::EPSILON) + f64::MIN_POSITIVE;
    let w = if up { (v + margin).next_up() } else { (v - margin).next_down() };
    w.clamp(-1.0, 1.0)
}

/// The enclosure of `sin` (`cos` when `cos` is true) over `a`.
fn trig(a: Interval, cos: bool) -> Interval {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let full = Interval::new(-1.0, 1.0);
    // Beyond 2^40 rad the crest search below loses its resolution: no claim but [−1, 1].
    if !a.is_bounded() || a.mag() > (1u64 << 40) as f64 || a.width() >= TAU {
        return full;
    }
    let f = |x: f64| if cos { x.cos() } else { x.sin() };
    let (ya, yb) = (f(a.lo), f(a.hi));
    let mut lo = widen_libm(ya.min(yb), false);
    let mut hi = widen_libm(ya.max(yb), true);
    // Crests: sin has its maxima at π/2 + 2kπ and minima at −π/2 + 2kπ; cos at 2kπ and π + 2kπ.
    // A crest is taken as inside when it lies within `tol` of the interval (the crest's and
    // the quotient's rounding errors are far below it): a crest wrongly taken only widens the
    // enclosure to ±1, which stays sound.
    let tol = 1e-9 * a.mag().max(1.0);
    let crest_inside = |c0: f64| {
        // Crests at c0 + 2kπ: the first k with c0 + 2kπ ≥ lo − tol.
        let k = ((a.lo - tol - c0) / TAU).ceil();
        let c = c0 + k * TAU;
        c <= a.hi + tol || c0 + (k - 1.0) * TAU >= a.lo - tol
    };
    let (max_at, min_at) = if cos { (0.0, PI) } else { (FRAC_PI_2, -FRAC_PI_2) };
    if crest_inside(max_at) {
        hi = 1.0;
    }
    if crest_inside(min_at) {
        lo = -1.0;
    }
    Interval::new(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directed_roundings_round_only_when_inexact() {
        // 0.1 + 0.2 is inexact: the interval holds the float on each side of the exact sum.
        let s = Interval::point(0.1) + Interval::point(0.2);
        assert!(s.lo < s.hi && s.hi == s.lo.next_up(), "{s}");
        // Exact sums and products stay points.
        assert_eq!(Interval::point(1.5) + Interval::point(2.25), Interval::point(3.75));
        assert_eq!(Interval::point(3.0) * Interval::point(0.5), Interval::point(1.5));
        // 1/3: the two floats around it.
        let q = Interval::point(1.0).checked_div(Interval::point(3.0)).unwrap();
        assert!(q.lo == 1.0 / 3.0 && q.hi == q.lo.next_up(), "{q}");
        assert!(q.lo * 3.0 <= 1.0 && q.hi * 3.0 >= 1.0);
        assert_eq!(Interval::point(4.0).sqrt(), Some(Interval::point(2.0)));
        let r = Interval::point(2.0).sqrt().unwrap();
        assert!(r.lo.mul_add(r.lo, -2.0) < 0.0 && r.hi.mul_add(r.hi, -2.0) > 0.0, "{r}");
    }

    #[test]
    fn products_and_quotients_take_the_extreme_ends() {
        let a = Interval::new(-2.0, 3.0);
        let b = Interval::new(-5.0, 4.0);
        assert_eq!(a * b, Interval::new(-15.0, 12.0));
        assert_eq!(a.sqr(), Interval::new(0.0, 9.0));
        assert_eq!(a - b, Interval::new(-6.0, 8.0));
        assert_eq!(a.checked_div(b), None, "a divisor range through 0");
        assert_eq!(a.checked_div(Interval::new(2.0, 4.0)), Some(Interval::new(-1.0, 1.5)));
        assert_eq!(Interval::new(-1.0, 1.0).sqrt(), None);
        assert_eq!(Interval::ENTIRE * Interval::point(0.0), Interval::point(0.0));
        let big = Interval::point(f64::MAX) + Interval::point(f64::MAX);
        assert_eq!((big.lo, big.hi), (f64::MAX, f64::INFINITY), "overflow stays enclosed");
    }

    /// An end drawn to hit the sign cases: zeros of both signs, infinities, ±1 and wide floats.
    fn end() -> impl proptest::strategy::Strategy<Value = f64> {
        use proptest::prelude::*;
        prop_oneof![
            Just(0.0),
            Just(-0.0),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(1.0),
            Just(-1.0),
            -1e6..1e6f64,
            proptest::num::f64::NORMAL,
        ]
    }

    proptest::proptest! {
        /// The product by sign cases is the four rounded products' min and max (Moore's
        /// definition), and holds the products of the ends and of points inside.
        #[test]
        fn products_by_sign_cases_are_the_four_products_extremes(
            (a0, a1, b0, b1) in (end(), end(), end(), end()), (s, t) in (0.0..=1.0f64, 0.0..=1.0f64)
        ) {
            let (a, b) = (Interval::new(a0.min(a1), a0.max(a1)), Interval::new(b0.min(b1), b0.max(b1)));
            // Never `lo = +∞` nor `hi = −∞` (the type's invariant).
            proptest::prop_assume!(a.lo < f64::INFINITY && a.hi > f64::NEG_INFINITY);
            proptest::prop_assume!(b.lo < f64::INFINITY && b.hi > f64::NEG_INFINITY);
            let p = a * b;
            let ends = [(a.lo, b.lo), (a.lo, b.hi), (a.hi, b.lo), (a.hi, b.hi)];
            let lo = ends.iter().map(|&(x, y)| mul_down(x, y)).fold(f64::INFINITY, f64::min);
            let hi = ends.iter().map(|&(x, y)| mul_up(x, y)).fold(f64::NEG_INFINITY, f64::max);
            let tiny = ends.iter().any(|&(x, y)| x != 0.0 && y != 0.0 && (x * y).abs() < TINY);
            if tiny {
                proptest::prop_assert!(p.lo >= lo && p.hi <= hi, "{a} · {b} = {p}, four products [{lo:e}, {hi:e}]");
            } else {
                proptest::prop_assert_eq!((p.lo, p.hi), (lo, hi), "{} · {}", a, b);
            }
            let inside = |i: Interval, s: f64| if i.is_bounded() { i.lo + s * (i.hi - i.lo) } else { i.lo.max(-1.0).min(i.hi) };
            let (x, y) = (inside(a, s), inside(b, t));
            if x.is_finite() && y.is_finite() {
                proptest::prop_assert!(p.contains(x * y), "{x} · {y} outside {p}");
            }
        }
    }

    #[test]
    fn sin_and_cos_take_the_crests_inside() {
        let s = Interval::new(0.0, 3.0).sin();
        assert_eq!(s.hi, 1.0, "π/2 is inside");
        assert!(s.lo <= 0.0 && s.lo > -1e-300, "{s}");
        let c = Interval::new(0.0, 3.0).cos();
        assert!(c.lo <= 3f64.cos() && c.lo > 3f64.cos() - 2e-15 && c.hi == 1.0, "{c}");
        let m = Interval::new(0.2, 0.4).sin();
        assert!(m.lo <= 0.2f64.sin() && m.hi >= 0.4f64.sin() && m.hi - m.lo < 0.2, "{m}");
        assert_eq!(Interval::new(-10.0, 10.0).sin(), Interval::new(-1.0, 1.0));
        let far = Interval::new(1000.0, 1000.5).cos();
        assert!(far.contains(1000.25f64.cos()) && far.lo > -1.0, "{far}");
        // Crests far from 0: 4.5π (a crest of sin, 1) lies in [14, 14.2].
        assert_eq!(Interval::new(14.0, 14.2).sin().hi, 1.0);
        assert!(Interval::new(14.2, 14.4).sin().hi < 1.0);
    }
}
