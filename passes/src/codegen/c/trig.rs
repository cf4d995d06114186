//! `trig=inline`: robovec's own sin/cos of the joint coordinates, emitted into the C file —
//! branch-free code on `robovec_vec` (every lane of a batch at once, GCC/Clang vector
//! extensions) or on one `double`/`float` at `batch=1`, the same operations either way.
//!
//! # Algorithm
//! 1. **Quadrant.** `k = round(x·2/π)` by the "magic number" trick: `t = x·(2/π) + 1.5·2^52`
//!    (`1.5·2^23` in `float`) rounds `x·2/π` to an integer held in the low bits of `t`'s
//!    significand, `k = t − 1.5·2^52` is that integer as a real and `t`'s bits reinterpreted as an
//!    integer give `k mod 4`. Exact for `|x·2/π| < 2^51` (`2^22`) in round-to-nearest without
//!    contraction or excess precision (the file says `#pragma STDC FP_CONTRACT OFF`; compile with
//!    `-ffp-contract=off`, never `-ffast-math`, which folds `(a + M) − M`).
//! 2. **Reduction** (Cody & Waite): `r = x − k·π/2` with π/2 split into pieces
//!    `A1 + A2 + B1 (+ B2) + C`. With `|k| < 2^kb` (see *Range*) every piece but `C` has at most
//!    `p − kb` significant bits (`p` = 53 or 24), so `k·A1`, `k·A2`, `k·B1`, `k·B2` are exact.
//!    `A1` and `A2` end at bit `2^−p`: when `k ≠ 0`, `|x| > 1/2` is a multiple of `2^−p`, so
//!    `x − k·A1` and then `− k·A2` are multiples of `2^−p` below 1 in magnitude, hence exact.
//!    The subtraction of each `k·B` keeps its rounding error (Knuth's TwoSum), and `k·C` is
//!    rounded; the result is `r` as an unevaluated sum `rh + rl`, accurate to about
//!    `2^−119` (`2^−63` in `float`) absolutely — far below an ulp of the smallest `|r|` that an
//!    argument within the range gives: `|r| ≥ 2^−60.5` for doubles below `2^20` (a lower bound
//!    per binade from the continued fraction of π/2: `‖kα‖ ≥ ‖q_n α‖` for `k < q_{n+1}`) and
//!    `|r| ≥ 2^−27.8` for floats below `2^11` (every float checked, in `__float128`). Without the
//!    TwoSum the error reaches 1.4 ulp.
//! 3. **Kernels** on `|r| ≤ R_MAX` ([`kernel_r_max`]: π/4 plus `2^−30`, resp. `2^−10` in
//!    `float`, covering the rounding of `k`), polynomials in Horner form:
//!    `sin r = r + r³·P(r²)`, `P` through `r^13` (`float`: `r^9`), and
//!    `cos r = 1 − r²/2 + r⁴·Q(r²)`, `Q` through `r^14` (`float`: `r^8`), near-minimax for the
//!    relative error of the result (see *Constants*): at most `2^−57.9` for `sin`, `2^−63.9` for
//!    `cos` (`float`: `2^−32.5`, `2^−33.0`), measured in the unit tests (Taylor polynomials of
//!    these degrees: about `2^−45` and `2^−49`). The low part enters to
//!    first order, `sin(rh + rl) ≈ sin rh + rl·w`, `w = 1 − rh²/2` rounded (shared with `cos`),
//!    `cos(rh + rl) ≈ cos rh − rl·rh`, and `1 − rh²/2` is summed with its rounding error (as
//!    fdlibm's `__kernel_cos` does). Where the C target has FMA (`__FMA__`: `-mfma`,
//!    `-march=haswell` or later), `ROBOVEC_MADD` evaluates each Horner step and the two
//!    products that end the kernels as one fused multiply-add (C99 `fma`, `robovec_fma` in a
//!    batch): 13 fewer instructions per `sincos` in `double` (the fused Horner error is no larger;
//!    `tests/codegen_c/trig.rs` measures both builds). The bits then depend on the target's FMA,
//!    within the same bound; the reduction keeps its exact unfused steps either way.
//! 4. **Quadrant selection** with bit operations, no per-lane branch: `q`'s bit 0 shifted to
//!    the sign bit gives (by a signed comparison with 0) the mask of odd `k`, under which sin and
//!    cos are swapped by xor with their difference; sin's sign bit is flipped by `q`'s bit 1
//!    (quadrants 2 and 3), cos's by bit 1 xor bit 0 (quadrants 1 and 2). `sin(−0) = −0`: the
//!    arithmetic gives `+0` for both zeros, and the sign of a zero `x` is or-ed in.
//!
//! When the IR has both `sin` and `cos` of one joint coordinate, the body computes both with
//! one `robovec_sincos_inline` (one reduction) at the first of the two statements.
//!
//! # Constants
//! Derived here at generation time, not copied from a table: π is [`PI_HEX`], its first 256
//! fraction bits in hexadecimal (the digits of π, checked in the unit tests against Machin's
//! formula `π/4 = 4·atan(1/5) − atan(1/239)` evaluated in exact integer arithmetic); the pieces
//! are cut from it by two's-complement integer arithmetic, each rounded to nearest at its
//! last bit (`A1` at `2^−(p−kb−1)`, `A2` at `2^−p`, `Bi` at `2^−(p+i·(p−kb))`, `C` to `p`
//! significant bits), so the remainders alternate in sign and the unit tests check that the
//! pieces sum to π/2 within `2^−139` (`2^−74`). The polynomial coefficients are derived here
//! too ([`KERNEL_TERMS`] of them): a weighted minimax fit (discrete Remez exchange in
//! double-double arithmetic, [`robovec_ir::numerics::DD`]) of `(sin r − r)/r³` and
//! `(cos r − 1 + r²/2)/r⁴` as polynomials in `z = r²` on 4096 Chebyshev-spaced points of
//! `(0, R_MAX²]`, the functions summed from their Taylor series; the weights `z/(sin r/r)` and
//! `z²/cos r` make the fitted error the relative error of `sin r` and `cos r`. The coefficients
//! are rounded to the format one at a time from the lowest power, the higher ones fitted again
//! after each rounding so that they absorb its error. The unit tests bound the result against
//! an independent double-double sin/cos and check the coefficients against `±1/n!`.
//!
//! # Range and accuracy
//! The inline code is used for `|x| ≤ L`, `L = 2^20` in `double` (`|k| < 2^20`) and `L = 2^11`
//! in `float` (`|k| < 2^11`). A batch with any lane beyond `L` (±∞ included) or NaN computes
//! those lanes with libm's `sin`/`cos` (`sinf`/`cosf`) one at a time; so NaN and ±∞ give NaN,
//! as libm does. The test is `x·x ≤ L²`: `L²` is exact and rounding is monotonic, so it holds
//! exactly when `|x| ≤ L` (false for NaN), in two operations. A batch tests all its lanes at
//! once, with one intrinsic when `robovec_vec` is one x86 register (`vptest` with AVX,
//! `pmovmskb` with SSE2, a mask compare with AVX-512F), otherwise with an and over the lanes;
//! then a rarely taken scalar loop.
//!
//! **Accuracy: error below 1 ulp of the exact value, so at most 1 ulp from the correctly
//! rounded result** (often the correctly rounded result itself), in `double` and in `float`.
//! Measured by `tests/codegen_c/trig.rs` against a reference accurate to about 2^−100 (exact
//! integer reduction, double-double series), on 40 000 arguments per set, sin and cos, largest
//! / mean error: uniform in `[−π, π]` 0.744 / 0.253 ulp (`float` 0.738 / 0.252), uniform in
//! `[−100, 100]` 0.739 / 0.253 (0.750 / 0.253), log-uniform from `2^−30` to `L` 0.735 / 0.236
//! (0.750 / 0.149), the nearest numbers to `k·π/2` and their neighbours (hard cases of the
//! reduction) 0.500 / 0.125 (0.500 / 0.175), special values 0.418 / 0.135 (0.366 / 0.126).
//! (With the earlier Taylor kernels through `r^17`/`r^18`, `float` `r^11`/`r^12`: 0.747, 0.723,
//! 0.725, 0.500 (0.760, 0.750, 0.750, 0.500), the same means.) The error analysis gives the same
//! picture: 0.5 ulp from the last addition, up to about 0.25 from `rh²` (the tail is at most
//! 0.1·|r|, resp. `r²/2` at most 0.31 in `cos`), a few hundredths from the rest, the kernels'
//! approximation error included (at most `2^−57.9` relative: 0.03 ulp).
//!
//! The results are not libm's bit for bit, so `trig=inline` code is **not** bit-exact with
//! robovec's interpreter (`-eval`, Rust's `sin`/`cos`, i.e. the system libm): outputs that
//! depend on sin/cos differ in their last bits (the tests compare them within a relative
//! tolerance). Batched lanes equal `batch=1` bit for bit (same operations, same order).
//!
//! # Sources
//! W. J. Cody and W. Waite, *Software Manual for the Elementary Functions*, Prentice-Hall,
//! 1980 (the split of π/2 and the additive reduction); J.-M. Muller, *Elementary Functions:
//! Algorithms and Implementation*, Birkhäuser, chapter "Range reduction" (why the pieces need
//! trailing zeros, the worst cases near multiples of π/2); D. E. Knuth, *The Art of Computer
//! Programming* vol. 2, §4.2.2 (TwoSum).

use std::fmt::Write as _;

use std::sync::OnceLock;

use robovec_ir::numerics::DD;

use crate::codegen::literal;

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
fn pow2(e: i32) -> f64 {
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

/// The number of coefficients `(sin, cos)` of the kernel polynomials, `[double, float]`: `sin`
/// through `r^13` and `cos` through `r^14` in `double`, `sin` through `r^9` and `cos` through
/// `r^8` in `float` — the fewest that keep the approximation error far below half an ulp (see
/// the unit test `kernel_polynomials_are_within_their_bound`; one fewer gives `2^−53.3` for the
/// `double` `cos`, `2^−27.9` for the `float` `sin`).
pub const KERNEL_TERMS: [(usize, usize); 2] = [(6, 6), (4, 3)];

/// The kernels' coefficients `(sin, cos)` of one format ([`kernel_poly`]), derived once.
fn kernels(f32: bool) -> (Vec<f64>, Vec<f64>) {
    static CACHE: [OnceLock<(Vec<f64>, Vec<f64>)>; 2] = [OnceLock::new(), OnceLock::new()];
    let i = usize::from(f32);
    CACHE[i]
        .get_or_init(|| {
            let (ms, mc) = KERNEL_TERMS[i];
            (kernel_poly(3, ms, f32), kernel_poly(4, mc, f32))
        })
        .clone()
}

/// The kernels' domain: `|r| ≤ R_MAX` with `R_MAX = π/4 + 2^−30` in `double` (the rounding of
/// `k` lets `|r|` exceed π/4 by about `2^−32`) and `π/4 + 2^−10` in `float` (about `2^−13`
/// there); `z = r²` in `[0, R_MAX²]`.
pub fn kernel_r_max(f32: bool) -> f64 {
    std::f64::consts::FRAC_PI_4 + if f32 { pow2(-10) } else { pow2(-30) }
}

/// `(sin r − r)/r³` (`first = 3`) or `(cos r − 1 + r²/2)/r⁴` (`first = 4`) as a function of
/// `z = r²`: the Taylor series `∓Σ (−1)^n z^n / (2n + first)!` (`−1/3! + z/5! − …`,
/// `1/4! − z/6! + …`), summed in double-double until
/// the terms fall below `2^−110` of the sum (`0 ≤ z < 1`). Units: 1.
fn kernel_series(first: u32, z: DD) -> DD {
    let fact: f64 = (1..=first).map(f64::from).product();
    let sign = if first == 3 { -1.0 } else { 1.0 };
    let mut term = DD::from_f64(sign) / DD::from_f64(fact);
    let mut sum = term;
    let mut n = first;
    loop {
        term = -(term * z) / DD::from_f64(f64::from((n + 1) * (n + 2)));
        sum = sum + term;
        n += 2;
        if term.hi.abs() < sum.hi.abs() * pow2(-110) {
            return sum;
        }
    }
}

/// `(f(z), w(z))` of one kernel at `z`: the function the polynomial approximates (see
/// [`kernel_series`]) and the weight that turns its error into the relative error of the
/// result, `z/(sin r / r)` for `sin`, `z²/cos r` for `cos`.
fn kernel_target(first: u32, z: DD) -> (DD, DD) {
    let f = kernel_series(first, z);
    let one = DD::from_f64(1.0);
    let w = if first == 3 { z / (one + z * f) } else { (z * z) / (one - z.mul_f64(0.5) + z * z * f) };
    (f, w)
}

/// The weighted minimax polynomial `Σ_{j<m} c_j z^j` for the values `g` with weights `w` on the
/// points `z` (discrete Remez exchange, double-double): minimises `max |w·(g − p)|`.
fn remez(z: &[DD], g: &[DD], w: &[DD], m: usize) -> Vec<DD> {
    let n = z.len();
    let one = DD::from_f64(1.0);
    let zero = DD::from_f64(0.0);
    // Start from the Chebyshev points of order m + 1 on the grid (Chebyshev-spaced itself).
    let mut refs: Vec<usize> = (0..=m).map(|i| ((i as f64 + 0.5) / (m as f64 + 1.0) * n as f64) as usize).collect();
    let mut coef = vec![zero; m];
    for _ in 0..40 {
        // Σ c_j z_i^j + (−1)^i E / w_i = g_i: m + 1 equations, Gaussian elimination.
        let mut a: Vec<Vec<DD>> = refs
            .iter()
            .enumerate()
            .map(|(i, &k)| {
                let mut row = Vec::with_capacity(m + 2);
                let mut p = one;
                for _ in 0..m {
                    row.push(p);
                    p = p * z[k];
                }
                let e = one / w[k];
                row.push(if i % 2 == 0 { e } else { -e });
                row.push(g[k]);
                row
            })
            .collect();
        for col in 0..=m {
            let piv = (col..=m).max_by(|&i, &j| a[i][col].hi.abs().total_cmp(&a[j][col].hi.abs())).unwrap();
            a.swap(col, piv);
            let pivot = a[col].clone();
            for (r, row) in a.iter_mut().enumerate() {
                if r != col {
                    let f = row[col] / pivot[col];
                    for (x, &v) in row.iter_mut().zip(&pivot).skip(col) {
                        *x = *x - f * v;
                    }
                }
            }
        }
        coef = (0..m).map(|j| a[j][m + 1] / a[j][j]).collect();
        // The weighted error on the grid; the extremum of each run of one sign.
        let err: Vec<f64> = (0..n).map(|k| (w[k] * (g[k] - horner_dd(&coef, z[k]))).hi).collect();
        let mut ext: Vec<usize> = Vec::new();
        for k in 0..n {
            match ext.last() {
                Some(&e) if (err[e] > 0.0) == (err[k] > 0.0) => {
                    if err[k].abs() > err[e].abs() {
                        *ext.last_mut().unwrap() = k;
                    }
                }
                _ => ext.push(k),
            }
        }
        while ext.len() > m + 1 {
            if err[ext[0]].abs() < err[ext[ext.len() - 1]].abs() {
                ext.remove(0);
            } else {
                ext.pop();
            }
        }
        if ext.len() < m + 1 || ext == refs {
            break;
        }
        refs = ext;
    }
    coef
}

/// `Σ c_j z^j` in double-double (Horner).
fn horner_dd(c: &[DD], z: DD) -> DD {
    c.iter().rev().fold(DD::from_f64(0.0), |acc, &x| acc * z + x)
}

/// The kernel polynomial of `sin` (`first = 3`: coefficients of `r³, r⁵, …`) or `cos`
/// (`first = 4`: `r⁴, r⁶, …`) with `m` coefficients, each rounded to the format: weighted
/// minimax ([`remez`]) on 4096 Chebyshev-spaced points of `z ∈ (0, R_MAX²]`; the coefficients
/// are rounded one at a time from the lowest power, the higher ones re-optimised after each
/// rounding so they absorb its error.
fn kernel_poly(first: u32, m: usize, f32: bool) -> Vec<f64> {
    let n = 4096;
    let zmax = DD::from_f64(kernel_r_max(f32)) * DD::from_f64(kernel_r_max(f32));
    let z: Vec<DD> = (0..n)
        .map(|k| zmax.mul_f64((1.0 - (std::f64::consts::PI * (k as f64 + 0.5) / n as f64).cos()) * 0.5))
        .collect();
    let (f, w): (Vec<DD>, Vec<DD>) = z.iter().map(|&z| kernel_target(first, z)).unzip();
    let mut rounded: Vec<f64> = Vec::with_capacity(m);
    for j in 0..m {
        // What is left to approximate, over z^j, with the weight times z^j.
        let done: Vec<DD> = rounded.iter().map(|&c| DD::from_f64(c)).collect();
        let (g, wj): (Vec<DD>, Vec<DD>) = (0..n)
            .map(|k| {
                let mut zj = DD::from_f64(1.0);
                for _ in 0..j {
                    zj = zj * z[k];
                }
                ((f[k] - horner_dd(&done, z[k])) / zj, w[k] * zj)
            })
            .collect();
        let c = remez(&z, &g, &wj, m - j)[0];
        rounded.push(if f32 { f64::from(c.round_f32()) } else { c.round_f64() });
    }
    rounded
}

/// The C helpers `robovec_sincos_inline(x, &s, &c)`, `robovec_sin_inline(x)` and
/// `robovec_cos_inline(x)`: on `robovec_vec` with `vector` (a batch: the vector helpers are
/// already written), otherwise on one `double` (`float` with `f32`). Marked `ROBOVEC_UNUSED`
/// ([`super::UNUSED_HELPERS`] defines it before them).
pub(crate) fn helpers(f32: bool, vector: bool) -> String {
    let c = Constants::new(f32);
    let real = if f32 { "float" } else { "double" };
    let v = if vector { "robovec_vec" } else { real };
    let u = match (vector, f32) {
        (true, _) => "robovec_uvec",
        (false, true) => "unsigned int",
        (false, false) => "unsigned long long",
    };
    let lit = |x: f64| literal::operand(x, f32);
    let bits = |e: &str| if vector { format!("({u})({e})") } else { format!("robovec_bits({e})") };
    let as_real = |e: &str| if vector { format!("({v})({e})") } else { format!("robovec_real({e})") };
    let mask = |e: &str| if vector { format!("({u})({e})") } else { format!("-({u})({e})") };
    let sfx = if f32 { "f" } else { "" };
    // A constant as a `v`: `robovec_fma` takes vectors.
    let lit_v = |x: f64| if vector { format!("robovec_splat({})", lit(x)) } else { lit(x) };
    let horner = |cs: &[f64]| -> String {
        let mut s = lit_v(cs[cs.len() - 1]);
        for &x in cs[..cs.len() - 1].iter().rev() {
            s = format!("ROBOVEC_MADD(z, {s}, {})", lit_v(x));
        }
        s
    };
    let magic = if f32 { 1.5 * pow2(23) } else { 1.5 * pow2(52) };
    let two_pi = if f32 { f64::from(std::f32::consts::FRAC_2_PI) } else { std::f64::consts::FRAC_2_PI };
    let sign_shift = if f32 { 31 } else { 63 };
    let (half, one, l) = (lit(0.5), lit(1.0), c.limit());

    let mut s = format!(
        "/* trig=inline: sin/cos by robovec's own branch-free code (passes/src/codegen/c/trig.rs): k = round(x*2/pi),\n \
         * r = x - k*pi/2 by Cody-Waite with pi/2 split into exact pieces, minimax polynomials on |r| <= pi/4, quadrant\n \
         * by masks; |x| > {} or NaN: libm. Within 1 ulp of the correctly rounded result; not libm's bits.\n \
         * Where the target has FMA (-mfma, -march=haswell or later) the polynomials use it: fewer instructions,\n \
         * other bits (also within 1 ulp). */\n\
         #if defined(__FMA__)\n#define ROBOVEC_MADD(a, b, c) {}(a, b, c)\n#else\n#define ROBOVEC_MADD(a, b, c) ((a) * (b) + (c))\n#endif\n",
        if f32 { "2^11" } else { "2^20" },
        if vector { "robovec_fma".to_string() } else { format!("fma{sfx}") }
    );
    if vector {
        // ROBOVEC_VEC_BYTES and <immintrin.h> come with the vector type (body::vector_helpers).
        let _ = writeln!(
            s,
            "typedef unsigned {int} robovec_uvec __attribute__((vector_size(ROBOVEC_VL * sizeof({real}))));\n\
             typedef {int} robovec_ivec __attribute__((vector_size(ROBOVEC_VL * sizeof({real}))));",
            int = if f32 { "int" } else { "long long" }
        );
    } else {
        let _ = writeln!(
            s,
            "static inline ROBOVEC_UNUSED {u} robovec_bits({real} x) {{ {u} i; memcpy(&i, &x, sizeof i); return i; }}\n\
             static inline ROBOVEC_UNUSED {real} robovec_real({u} i) {{ {real} x; memcpy(&x, &i, sizeof x); return x; }}"
        );
    }
    // The scalar form's reduction and polynomials are a branch-free kernel, so that a loop of
    // them vectorises (`robovec_sincos_n`); the vector form tests its lanes' range inside.
    let kernel = if vector { "robovec_sincos_inline" } else { "robovec_sincos_kernel" };
    let _ = writeln!(s, "static inline ROBOVEC_UNUSED void {kernel}({v} x, {v} *sin_out, {v} *cos_out)\n{{");
    let _ = writeln!(
        s,
        "  /* k = round(x*2/pi): adding 1.5*2^{} rounds to an integer, whose low bits are t's. */\n  \
         const {v} t = x * {} + {};\n  const {v} k = t - {};\n  const {u} q = {};",
        if f32 { 23 } else { 52 },
        lit(two_pi),
        lit(magic),
        lit(magic),
        bits("t")
    );
    let _ = writeln!(
        s,
        "  /* r = rh + rl = x - k*pi/2: k*A1, k*A2 and both subtractions exact; k*B exact, its subtraction by TwoSum. */\n  \
         const {v} y1 = x - k * {};\n  const {v} h0 = y1 - k * {};",
        lit(c.heads[0]),
        lit(c.heads[1])
    );
    for (i, &b) in c.tails.iter().enumerate() {
        let (h, n) = (format!("h{i}"), i + 1);
        let _ = writeln!(
            s,
            "  const {v} b{n} = k * {};\n  const {v} h{n} = {h} + b{n};\n  const {v} a{n} = h{n} - b{n};\n  \
             const {v} e{n} = ({h} - a{n}) + (b{n} - (h{n} - a{n}));",
            lit(-b)
        );
    }
    let n = c.tails.len();
    let errs: Vec<String> = (1..=n).map(|i| format!("e{i}")).collect();
    let errs = if n > 1 { format!("({})", errs.join(" + ")) } else { errs[0].clone() };
    let _ = writeln!(s, "  const {v} rh = h{n};\n  const {v} rl = {errs} + k * {};", lit(-c.last));
    let _ = writeln!(
        s,
        "  /* sin(rh + rl) ~ rh + rh^3 P(rh^2) + rl (1 - rh^2/2); cos(rh + rl) ~ 1 - rh^2/2 + rh^4 Q(rh^2) - rl rh. */\n  \
         const {v} z = rh * rh;\n  const {v} hz = {half} * z;\n  const {v} w = {one} - hz;\n  \
         const {v} ps = {};\n  const {v} sr = rh + ROBOVEC_MADD(rh * z, ps, rl * w);\n  \
         const {v} pc = {};\n  const {v} cr = w + ((({one} - w) - hz) + ROBOVEC_MADD(z * z, pc, -(rh * rl)));",
        horner(&c.sin),
        horner(&c.cos)
    );
    let _ = writeln!(
        s,
        "  /* q = k mod 4: odd q swaps sin and cos (xor with their difference under a mask); sin is negated for\n   \
         * q = 2, 3, cos for q = 1, 2 (sign-bit xor); sin(-0) = -0 (sr is +0 there). */\n  \
         const {u} qs = q << {sign_shift};\n  const {u} swap = {};\n  const {u} ss = (q >> 1) << {sign_shift};\n  \
         const {u} d = ({sb} ^ {cb}) & swap;\n  const {u} zero = {};\n  \
         {v} s = {};\n  {v} c = {};",
        if vector { format!("({u})((robovec_ivec)qs < 0)") } else { format!("-(qs >> {sign_shift})") },
        mask(&format!("x == {}", lit(0.0))),
        as_real(&format!("({} ^ d ^ ss) | (zero & {})", bits("sr"), bits("x"))),
        as_real(&format!("{} ^ d ^ ss ^ qs", bits("cr"))),
        sb = bits("sr"),
        cb = bits("cr"),
    );
    let in_range = format!("x * x <= {}", lit(l * l));
    if vector {
        let _ = writeln!(
            s,
            "  /* Lanes with |x| > L or NaN (rare): libm. x*x <= L^2 is |x| <= L exactly (L^2 exact, rounding\n   \
             * monotonic) and false for NaN; one test of all lanes, by an intrinsic where the vector is one register;\n   \
             * marked unlikely, so that the compiler puts the libm calls out of the straight-line path. */\n  \
             const {u} in = {};\n\
             #if defined(__AVX__) && ROBOVEC_VEC_BYTES == 32\n  \
             if (__builtin_expect(!_mm256_testc_si256((__m256i)in, _mm256_set1_epi32(-1)), 0))\n\
             #elif defined(__SSE2__) && ROBOVEC_VEC_BYTES == 16\n  \
             if (__builtin_expect(_mm_movemask_epi8((__m128i)in) != 0xffff, 0))\n\
             #elif defined(__AVX512F__) && ROBOVEC_VEC_BYTES == 64\n  \
             if (__builtin_expect(_mm512_cmpneq_epi32_mask((__m512i)in, _mm512_set1_epi32(-1)) != 0, 0))\n\
             #else\n  \
             {elem} all = in[0];\n  for (int lane = 1; lane < ROBOVEC_VL; lane++) all &= in[lane];\n  if (__builtin_expect(!all, 0))\n\
             #endif\n    \
             for (int lane = 0; lane < ROBOVEC_VL; lane++)\n      \
             if (!in[lane]) {{ s[lane] = sin{sfx}(x[lane]); c[lane] = cos{sfx}(x[lane]); }}",
            mask(&in_range),
            elem = if f32 { "unsigned int" } else { "unsigned long long" },
        );
    }
    let _ = writeln!(s, "  *sin_out = s;\n  *cos_out = c;\n}}");
    if !vector {
        let far = format!("!(x[i] * x[i] <= {})", lit(l * l));
        let _ = writeln!(
            s,
            "static inline ROBOVEC_UNUSED void robovec_sincos_inline({v} x, {v} *sin_out, {v} *cos_out)\n{{\n  \
             robovec_sincos_kernel(x, sin_out, cos_out);\n  \
             /* |x| > L or NaN (rare): libm (x*x <= L^2 is |x| <= L exactly, false for NaN). */\n  \
             if (__builtin_expect(!({in_range}), 0)) {{ *sin_out = sin{sfx}(x); *cos_out = cos{sfx}(x); }}\n}}\n\
             /* The sin and cos of the n arguments x (one state's coordinates): the kernel's loop has no branch, so\n \
             * the compiler vectorises it (-O3; -O2 of GCC 12+ and Clang too, n being a multiple of the lanes: callers\n \
             * pad it to {pad}); then the arguments beyond L or NaN (rare) take libm. The same bits as\n \
             * robovec_sincos_inline per argument. */\n\
             static inline ROBOVEC_UNUSED void robovec_sincos_n(const {v} *restrict x, {v} *restrict sin_out, {v} *restrict cos_out, int n)\n{{\n  \
             int i, far = 0;\n  \
             for (i = 0; i < n; i++) robovec_sincos_kernel(x[i], &sin_out[i], &cos_out[i]);\n  \
             for (i = 0; i < n; i++) far |= {far};\n  \
             if (__builtin_expect(far, 0))\n    \
             for (i = 0; i < n; i++)\n      \
             if ({far}) {{ sin_out[i] = sin{sfx}(x[i]); cos_out[i] = cos{sfx}(x[i]); }}\n}}",
            pad = block_pad(f32),
        );
    }
    let _ = writeln!(
        s,
        "static inline ROBOVEC_UNUSED {v} robovec_sin_inline({v} x) {{ {v} s, c; robovec_sincos_inline(x, &s, &c); return s; }}\n\
         static inline ROBOVEC_UNUSED {v} robovec_cos_inline({v} x) {{ {v} s, c; robovec_sincos_inline(x, &s, &c); return c; }}\n"
    );
    s
}

/// `trig=inline`, one state: the length of the argument array of `robovec_sincos_n` is a
/// multiple of this (64 bytes: the lanes of the widest vector, AVX-512), so that every vector
/// width divides it and the loop needs no scalar remainder.
pub(crate) fn block_pad(f32: bool) -> usize {
    if f32 {
        16
    } else {
        8
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

    /// The largest relative error of the kernel polynomials with the rounded coefficients,
    /// `r + r³·p(r²)` against `sin r` and `1 − r²/2 + r⁴·q(r²)` against `cos r`, on 20 000
    /// evenly spaced `r` in `(0, R_MAX]`, evaluated exactly enough (double-double) that only the
    /// approximation error shows; the reference is [`DD::sin`] / [`DD::cos`] (reduction in
    /// triple-double and Taylor series, absolute error below 2^−98), independent of the series
    /// the coefficients were fitted to.
    fn kernel_errors(c: &Constants, f32: bool) -> (f64, f64) {
        let to_dd = |cs: &[f64]| cs.iter().map(|&x| DD::from_f64(x)).collect::<Vec<_>>();
        let (ps, pc) = (to_dd(&c.sin), to_dd(&c.cos));
        let n = 20_000;
        let (mut es, mut ec) = (0.0f64, 0.0f64);
        for i in 1..=n {
            let r = DD::from_f64(kernel_r_max(f32) * i as f64 / n as f64);
            let z = r * r;
            let s = r + r * z * horner_dd(&ps, z);
            let c = DD::from_f64(1.0) - z.mul_f64(0.5) + z * z * horner_dd(&pc, z);
            let (ts, tc) = (r.sin(), r.cos());
            es = es.max(((s - ts) / ts).hi.abs());
            ec = ec.max(((c - tc) / tc).hi.abs());
        }
        (es, ec)
    }

    #[test]
    fn kernel_polynomials_are_within_their_bound() {
        // (f32, bounds on the relative error of sin and cos): far below half an ulp (2^−53,
        // resp. 2^−24 relative at most).
        for (f32, bound_sin, bound_cos) in [(false, -57.5f64, -63.0f64), (true, -32.0, -32.5)] {
            let c = Constants::new(f32);
            let (es, ec) = kernel_errors(&c, f32);
            eprintln!("f32={f32}: sin 2^{:.2}, cos 2^{:.2}", es.log2(), ec.log2());
            assert!(es < bound_sin.exp2() && ec < bound_cos.exp2(), "f32={f32}: sin {es:e}, cos {ec:e}");
        }
    }

    #[test]
    fn kernel_coefficients_are_near_the_taylor_ones() {
        // Minimax moves each coefficient a little from ±1/n!, more the higher the power; the
        // signs alternate like the series'.
        for f32 in [false, true] {
            let c = Constants::new(f32);
            for (first, cs) in [(3u32, &c.sin), (4, &c.cos)] {
                for (j, &x) in cs.iter().enumerate() {
                    let n = first + 2 * j as u32;
                    let fact: f64 = (1..=n).map(f64::from).product();
                    let sign = if j % 2 == 0 { -1.0 } else { 1.0 } * if first == 4 { -1.0 } else { 1.0 };
                    let rel = x * fact * sign - 1.0;
                    eprintln!("f32={f32} r^{n}: {x:e} (1/n! · (1 {rel:+e}))");
                    let tol = if j > 0 {
                        0.1
                    } else if f32 {
                        pow2(-18)
                    } else {
                        pow2(-40)
                    };
                    assert!(rel.abs() < tol, "f32={f32} r^{n}: {x:e}, relative to ±1/{n}! {rel:e}");
                }
            }
        }
    }
}
