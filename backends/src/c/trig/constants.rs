//! The constants of `trig=inline` (see the [parent module](super), *Constants*): π from
//! [`PI_HEX`], the Cody–Waite pieces of π/2 for `double` and `float`, cut from it by
//! two's-complement integer arithmetic, and the checks the reduction's exactness rests on.

use super::kernel::kernels;

/// π in hexadecimal: `3.` and 64 fraction digits (256 bits); the pieces of π/2 are cut from it.
pub const PI_HEX: &str = "3.243F6A8885A308D313198A2E03707344A4093822299F31D0082EFA98EC4E6C89";

/// Fraction bits of [`Big`] values: `I` stands for `I / 2^257`, so `PI_HEX` read as an integer
/// (`π·2^256`) is π/2 at this scale.
const SCALE: i32 = 257;

/// A two's-complement integer of 320 bits (little-endian limbs), enough for π/2·2^257.
type Big = [u64; 5];

fn big_from_i64(n: i64) -> Big {
    let ext = if n < 0 { u64::MAX } else { 0 };
    [n as u64, ext, ext, ext, ext]
}

fn big_sub(a: &Big, b: &Big) -> Big {
    let mut out = [0; 5];
    let mut borrow = false;
    for i in 0..5 {
        let (d, b1) = a[i].overflowing_sub(b[i]);
        let (d, b2) = d.overflowing_sub(u64::from(borrow));
        out[i] = d;
        borrow = b1 || b2;
    }
    out
}

fn big_is_neg(a: &Big) -> bool {
    a[4] >> 63 == 1
}

/// `a · 2^s`.
fn big_shl(a: &Big, s: u32) -> Big {
    let (words, bits) = ((s / 64) as usize, s % 64);
    let mut out = [0; 5];
    for i in words..5 {
        let lo = a[i - words] << bits;
        let carry = if bits > 0 && i > words { a[i - words - 1] >> (64 - bits) } else { 0 };
        out[i] = lo | carry;
    }
    out
}

/// `floor(a / 2^s)` (arithmetic shift).
fn big_sar(a: &Big, s: u32) -> Big {
    let fill = if big_is_neg(a) { u64::MAX } else { 0 };
    let (words, bits) = ((s / 64) as usize, s % 64);
    let word = |i: usize| if i < 5 { a[i] } else { fill };
    let mut out = [0; 5];
    for (i, o) in out.iter_mut().enumerate() {
        let lo = word(i + words) >> bits;
        let hi = if bits > 0 { word(i + words + 1) << (64 - bits) } else { 0 };
        *o = lo | hi;
    }
    out
}

/// The number of bits of `|a|`.
fn big_bit_len(a: &Big) -> u32 {
    let m = if big_is_neg(a) { big_sub(&[0; 5], a) } else { *a };
    (0..5).rev().find(|&i| m[i] != 0).map_or(0, |i| 64 * i as u32 + 64 - m[i].leading_zeros())
}

/// `round(a / 2^s)` (half up), which must fit in an `i64`.
fn big_round_shr(a: &Big, s: u32) -> i64 {
    assert!(s >= 1);
    let t = big_sar(a, s - 1);
    ((t[0] as i64) >> 1) + (t[0] & 1) as i64
}

/// π/2 at [`SCALE`], from [`PI_HEX`].
fn half_pi() -> Big {
    let mut a: Big = [0; 5];
    for d in PI_HEX.chars().filter(|&c| c != '.') {
        let d = d.to_digit(16).expect("hex digit") as u64;
        let mut carry = d as u128;
        for l in &mut a {
            let v = (*l as u128) * 16 + carry;
            *l = v as u64;
            carry = v >> 64;
        }
    }
    a
}

/// `2^e` as an `f64` (normal range).
pub(super) fn pow2(e: i32) -> f64 {
    assert!((-1022..=1023).contains(&e));
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// The Cody–Waite split of π/2 for one format, and the polynomial coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Constants {
    /// Significand bits: 53 (`double`) or 24 (`float`).
    pub p: u32,
    /// `|k| < 2^kb` for `|x| ≤ L = 2^kb`.
    pub kb: u32,
    /// `A1`, `A2`: `x − k·A1 − k·A2` is exact.
    pub heads: [f64; 2],
    /// `B1` (`float`: `B1`, `B2`): `k·Bi` exact, subtracted with TwoSum.
    pub tails: Vec<f64>,
    /// `C`: the rest of π/2 to `p` bits; `k·C` rounds.
    pub last: f64,
    /// `sin`: the coefficients of `r³, r⁵, …` (`−1/3!, 1/5!, …`).
    pub sin: Vec<f64>,
    /// `cos`: the coefficients of `r⁴, r⁶, …` (`1/4!, −1/6!, …`).
    pub cos: Vec<f64>,
}

impl Constants {
    /// The constants of `double` (`f32 = false`) or `float`.
    pub fn new(f32: bool) -> Constants {
        let (p, kb, n_tails) = if f32 { (24, 11, 2) } else { (53, 20, 1) };
        let m = p - kb;
        let mut rest = half_pi();
        // Cuts the piece of `rest` ending at bit 2^lsb (rounded to nearest there).
        let cut = |rest: &mut Big, lsb: i32| -> f64 {
            let s = (lsb + SCALE) as u32;
            let n = big_round_shr(rest, s);
            *rest = big_sub(rest, &big_shl(&big_from_i64(n), s));
            n as f64 * pow2(lsb)
        };
        let heads = [cut(&mut rest, -(m as i32 - 1)), cut(&mut rest, -(p as i32))];
        let tails: Vec<f64> = (1..=n_tails).map(|i| cut(&mut rest, -((p + i * m) as i32))).collect();
        // C: p significant bits from the leading bit of what is left.
        let lead = big_bit_len(&rest) as i32 - 1 - SCALE;
        let last = cut(&mut rest, lead - (p as i32 - 1));
        let (sin, cos) = kernels(f32);
        let c = Constants { p, kb, heads, tails, last, sin, cos };
        c.check();
        c
    }

    /// `L`: the inline code's range `|x| ≤ L`.
    pub fn limit(&self) -> f64 {
        pow2(self.kb as i32)
    }

    /// The conditions the reduction's exactness rests on (module doc, step 2).
    fn check(&self) {
        let bits = |x: f64| -> u32 {
            // Significant bits of x (an integer times a power of two).
            let m = (x.abs().to_bits() & ((1 << 52) - 1)) | (1 << 52);
            53 - m.trailing_zeros()
        };
        let m = self.p - self.kb;
        for &x in self.heads.iter().chain(&self.tails) {
            assert!(bits(x) <= m, "piece {x:e} has {} bits, more than {m}", bits(x));
        }
        assert!(bits(self.last) <= self.p);
        // |k| < 2^kb for |x| ≤ L; x − k·A1 stays below 1 in magnitude (so it is exact).
        let k_max = (self.limit() * std::f64::consts::FRAC_2_PI).round() + 1.0;
        assert!(k_max < pow2(self.kb as i32));
        let rem_a1 = (std::f64::consts::FRAC_PI_2 - self.heads[0]).abs() + pow2(-(self.p as i32));
        assert!(k_max * rem_a1 + std::f64::consts::FRAC_PI_4 + 0.01 < 1.0, "x − k·A1 can reach 1");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `floor(π·2^bits)` by Machin's formula `π = 16·atan(1/5) − 4·atan(1/239)`, in integer
    /// arithmetic on 32-bit limbs (most significant first) with 32 guard bits: independent of
    /// [`PI_HEX`].
    fn machin_pi(bits: u32) -> Vec<u32> {
        let limbs = (bits / 32 + 2) as usize; // one integer limb, the fraction, one guard limb
        let div = |a: &mut Vec<u32>, d: u64| {
            let mut r = 0u64;
            for l in a.iter_mut() {
                let v = (r << 32) | u64::from(*l);
                *l = (v / d) as u32;
                r = v % d;
            }
        };
        let add = |a: &mut Vec<u32>, b: &[u32], sub: bool| {
            let mut carry = 0i64;
            for i in (0..a.len()).rev() {
                let v = i64::from(a[i]) + if sub { -i64::from(b[i]) } else { i64::from(b[i]) } + carry;
                a[i] = v.rem_euclid(1 << 32) as u32;
                carry = v.div_euclid(1 << 32);
            }
        };
        let is_zero = |a: &[u32]| a.iter().all(|&l| l == 0);
        // atan(1/x) · mult at the scale 2^(32·(limbs−1)).
        let atan = |x: u64, mult: u32| -> Vec<u32> {
            let mut power = vec![0u32; limbs];
            power[0] = mult;
            div(&mut power, x);
            let mut sum = vec![0u32; limbs];
            let mut n = 0u64;
            while !is_zero(&power) {
                let mut term = power.clone();
                div(&mut term, 2 * n + 1);
                add(&mut sum, &term, n % 2 == 1);
                div(&mut power, x * x);
                n += 1;
            }
            sum
        };
        let mut pi = atan(5, 16);
        add(&mut pi, &atan(239, 4), true);
        pi.truncate(limbs - 1); // drop the guard limb
        pi
    }

    #[test]
    fn pi_hex_is_pi_by_machins_formula() {
        let pi = machin_pi(256);
        let hex: String =
            std::iter::once(format!("{:X}", pi[0])).chain(pi[1..=8].iter().map(|l| format!("{l:08X}"))).collect();
        assert_eq!(hex, PI_HEX.replace('.', ""));
    }

    /// The pieces' sum, exactly, at [`SCALE`].
    fn sum(c: &Constants) -> Big {
        let mut acc: Big = [0; 5];
        for &x in c.heads.iter().chain(&c.tails).chain([&c.last]) {
            let (m, e) = (x.abs().to_bits() & ((1 << 52) - 1) | (1 << 52), ((x.abs().to_bits() >> 52) as i32) - 1075);
            let n = big_shl(&big_from_i64(m as i64), (e + SCALE) as u32);
            acc = if x < 0.0 { big_sub(&acc, &n) } else { big_sub(&acc, &big_sub(&[0; 5], &n)) };
        }
        acc
    }

    /// Machin's `π·2^256` as a [`Big`] (= π/2 at [`SCALE`]).
    fn machin_half_pi() -> Big {
        let mut a: Big = [0; 5];
        for &l in &machin_pi(256) {
            a = big_shl(&a, 32);
            a[0] |= u64::from(l);
        }
        a
    }

    #[test]
    fn the_pieces_sum_to_half_pi_far_beyond_the_format() {
        assert_eq!(machin_half_pi(), half_pi());
        for (f32, want) in [(false, -139), (true, -74)] {
            let c = Constants::new(f32);
            let err = big_sub(&machin_half_pi(), &sum(&c));
            let err_bits = big_bit_len(&err) as i32 - SCALE;
            assert!(err_bits <= want, "f32={f32}: |π/2 − Σ pieces| < 2^{err_bits}");
            // A1 + A2 is π/2 to the format's precision.
            let hi = c.heads[0] + c.heads[1];
            assert!((hi - std::f64::consts::FRAC_PI_2).abs() <= pow2(-(c.p as i32)), "f32={f32}: {hi:e}");
        }
    }

    #[test]
    fn double_split_has_the_documented_shape() {
        let c = Constants::new(false);
        assert_eq!(c.limit(), 1048576.0);
        assert_eq!((c.sin.len(), c.cos.len(), c.tails.len()), (6, 6, 1));
        let f = Constants::new(true);
        assert_eq!((f.limit(), f.sin.len(), f.cos.len(), f.tails.len()), (2048.0, 4, 3, 2));
    }
}
