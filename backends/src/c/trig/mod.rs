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
//!
//! # Layout
//! - `constants.rs`: π from [`PI_HEX`] and the Cody–Waite pieces of π/2 cut from it in integer
//!   arithmetic ([`Constants`]).
//! - `kernel.rs`: the kernel polynomials' coefficients (weighted minimax by Remez exchange in
//!   double-double).
//! - this file: the C text of the helpers.

mod constants;
mod kernel;

use std::fmt::Write as _;

use crate::literal;

use constants::pow2;
pub use constants::{Constants, PI_HEX};
pub use kernel::{kernel_r_max, KERNEL_TERMS};

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
        "/* trig=inline: sin/cos by robovec's own branch-free code (passes/src/codegen/c/trig/): k = round(x*2/pi),\n \
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

/// The vector helpers of [`helpers`] for the binary32 values of a batch whose values carry
/// numeric formats (`robovec_vec32` beside `robovec_vec`, [`super::body::format_vector_helpers`]):
/// the `float` code under names ending in `32` (`robovec_sincos_inline32`,
/// `robovec_sin_inline32`, …, on `robovec_vec32`, with `robovec_fma32`), so that both forms
/// live in one file. Within 1 ulp of binary32, as `precision=f32`'s.
pub(crate) fn helpers_vec32() -> String {
    const NAMES: [&str; 10] = [
        "robovec_vec",
        "robovec_uvec",
        "robovec_ivec",
        "robovec_sincos_inline",
        "robovec_sin_inline",
        "robovec_cos_inline",
        "robovec_fma",
        "robovec_splat",
        "ROBOVEC_MADD",
        "ROBOVEC_VEC_BYTES",
    ];
    renamed(&helpers(true, true), |word| NAMES.contains(&word).then(|| format!("{word}32")))
}

/// `text` with every C identifier `rename` maps replaced by its new name (whole identifiers
/// only: `robovec_vec` is renamed, `robovec_vec32` is not): the helpers of [`helpers`] under
/// other names, so that two forms of them live in one file.
fn renamed(text: &str, rename: impl Fn(&str) -> Option<String>) -> String {
    let mut out = String::with_capacity(text.len() + 1024);
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        match rename(word) {
            Some(new) => out.push_str(&new),
            None => out.push_str(word),
        }
        word.clear();
    };
    for ch in text.chars() {
        if ch.is_ascii_alphanumeric() || ch == '_' {
            word.push(ch);
        } else {
            flush(&mut word, &mut out);
            out.push(ch);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// `trig=inline` in a batch whose values carry numeric formats: [`helpers`]' `double` code on
/// `robovec_vech`, half a `robovec_vec` (its `double` vectors have the lanes of the `float`
/// ones, twice the target's register: 8 with AVX2), and `robovec_sincos_inline`,
/// `robovec_sin_inline`, `robovec_cos_inline` on `robovec_vec` calling it on each half. The
/// kernel's 64-bit integer lane operations on a vector of twice the register are scalarised by
/// GCC 12 without AVX-512 (the Segway's `dirdyna` with 51 binary64 values at `batch=8`: mixed
/// 1.23× binary64 `batch=4` with the whole-vector kernel); on halves they are one register.
/// The same operations per lane: the same bits as the whole-vector form.
pub(crate) fn helpers_halves() -> String {
    const RENAMED: [(&str, &str); 11] = [
        ("robovec_vec", "robovec_vech"),
        ("robovec_uvec", "robovec_uvech"),
        ("robovec_ivec", "robovec_ivech"),
        ("robovec_sincos_inline", "robovec_sincos_inlineh"),
        ("robovec_sin_inline", "robovec_sin_inlineh"),
        ("robovec_cos_inline", "robovec_cos_inlineh"),
        ("robovec_fma", "robovec_fmah"),
        ("robovec_splat", "robovec_splath"),
        ("ROBOVEC_MADD", "ROBOVEC_MADDH"),
        ("ROBOVEC_VEC_BYTES", "ROBOVEC_VECH_BYTES"),
        ("ROBOVEC_VL", "ROBOVEC_HL"),
    ];
    let mut out = renamed(&helpers(false, true), |word| {
        RENAMED.iter().find(|(from, _)| *from == word).map(|(_, to)| to.to_string())
    });
    out.push_str(
        "/* The whole robovec_vec: its two halves. */\n\
         static inline ROBOVEC_UNUSED void robovec_sincos_inline(robovec_vec x, robovec_vec *sin_out, robovec_vec *cos_out)\n{\n  \
         robovec_vech x0, x1, s0, s1, c0, c1;\n  \
         memcpy(&x0, &x, sizeof x0);\n  memcpy(&x1, (const char *)&x + sizeof x0, sizeof x1);\n  \
         robovec_sincos_inlineh(x0, &s0, &c0);\n  robovec_sincos_inlineh(x1, &s1, &c1);\n  \
         memcpy(sin_out, &s0, sizeof s0);\n  memcpy((char *)sin_out + sizeof s0, &s1, sizeof s1);\n  \
         memcpy(cos_out, &c0, sizeof c0);\n  memcpy((char *)cos_out + sizeof c0, &c1, sizeof c1);\n}\n\
         static inline ROBOVEC_UNUSED robovec_vec robovec_sin_inline(robovec_vec x) { robovec_vec s, c; robovec_sincos_inline(x, &s, &c); return s; }\n\
         static inline ROBOVEC_UNUSED robovec_vec robovec_cos_inline(robovec_vec x) { robovec_vec s, c; robovec_sincos_inline(x, &s, &c); return c; }\n\n",
    );
    out
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
