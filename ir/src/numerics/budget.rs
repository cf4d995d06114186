//! A rigorous error budget for functions of `+ − ×` (and unary minus), for checking that a
//! rewrite keeps every output within what its rounding can explain (Higham, *Accuracy and
//! Stability of Numerical Algorithms*, 2nd ed., Lemma 3.1 and §3.1–§4.2).
//!
//! For an output `e` evaluated in a binary format with unit roundoff `u` (2⁻²⁴ binary32,
//! 2⁻⁵³ binary64), without overflow or underflow:
//!
//! `|fl(e) − e| ≤ γ_K · M(e)`, with `γ_k = k·u / (1 − k·u)`,
//!
//! - `M(e)`: `e` evaluated exactly with every input and constant replaced by its absolute value
//!   and every `−` by `+` (the sum of the absolute values of the monomials of `e`). `M` is the
//!   same for any association, commutation or distribution of the same polynomial, so it is the
//!   same before and after reassociating rewrites.
//! - `K(e)`: the number of roundings a monomial of `e` can accumulate, by structure:
//!   `K(leaf) = 0`, `K(a ± b) = max(K(a), K(b)) + 1`, `K(a × b) = K(a) + K(b) + 1`,
//!   `K(−a) = K(a)`, and for a fused multiply-add (`@fma`, `@fms`, `@fnma`: `±a·b ± c` rounded
//!   once) `K = max(K(a) + K(b), K(c)) + 1`, `M = M(a)·M(b) + M(c)`. Proof: each rounded op multiplies the monomials below it by one `(1 + δ)`,
//!   `|δ| ≤ u`; a product multiplies the monomials of both factors, so their factor counts add;
//!   Lemma 3.1 bounds a product of `k` such factors by `1 + θ_k`, `|θ_k| ≤ γ_k`.
//!
//!   `K` is the longest path in rounded ops (the depth `D`) for sums, but not for products:
//!   `((a + b)·(c + d))` has depth 2 and `K = 3`, and errors of `3u` relative are reachable, so a
//!   depth-only budget would be wrong for products of sums.
//!
//! The check adds the error of the reference itself (double-double, `u = 2⁻¹⁰⁰`, same bound)
//! and a tiny absolute slack for gradual underflow (`ops · 2^(emin − p + 1) · max(1, M)`).

use super::dd::{DD, DD_UNIT};
use super::tape::{Step, Tape};
use crate::intrinsic::Intrinsic;
use crate::syntax::BinOp;

/// Unit roundoff of binary32.
pub const U32: f64 = 1.0 / (1u64 << 24) as f64;
/// Unit roundoff of binary64.
pub const U64: f64 = 1.0 / (1u64 << 53) as f64;

/// `γ_k = k·u / (1 − k·u)`; infinite when `k·u ≥ 1` (Higham eq. 3.8).
pub fn gamma(k: u64, u: f64) -> f64 {
    let ku = k as f64 * u;
    if ku >= 1.0 {
        f64::INFINITY
    } else {
        ku / (1.0 - ku)
    }
}

/// The budget terms of a tape at one input point.
#[derive(Clone, Debug, PartialEq)]
pub struct Terms {
    /// `(K, M)` of every output, in output order (`M` an upper bound).
    pub outputs: Vec<(u64, f64)>,
    /// The largest `M` over every step: when it is far below a format's largest finite value,
    /// no intermediate result can overflow in that format (`|fl(x)| ≤ (1 + γ_K)·M(x)`).
    pub max_m: f64,
}

/// `K` and an upper bound of `M` for every output of `tape` at `inputs` (see the module doc),
/// or `None` when the tape has a division, a call other than a fused multiply-add or a trig
/// variable (no such budget).
pub fn terms(tape: &Tape, inputs: &[f64]) -> Option<Terms> {
    let n = tape.inputs.len() + tape.consts.len();
    let mut k: Vec<u64> = vec![0; n];
    let mut m: Vec<DD> = inputs.iter().chain(&tape.consts).map(|x| DD::from_f64(x.abs())).collect();
    for s in &tape.steps {
        let (kk, mm) = match *s {
            Step::Bin(op, a, b) => {
                let (ka, kb, ma, mb) = (k[a as usize], k[b as usize], m[a as usize], m[b as usize]);
                match op {
                    BinOp::Add | BinOp::Sub => (ka.max(kb).saturating_add(1), ma + mb),
                    BinOp::Mul => (ka.saturating_add(kb).saturating_add(1), ma * mb),
                    BinOp::Div => return None,
                }
            }
            Step::Neg(a) => (k[a as usize], m[a as usize]),
            // ±a·b ± c rounded once: the product's monomials carry a's and b's factors and the
            // one rounding, c's its own and that rounding.
            Step::Call(c, start, len)
                if Intrinsic::of(&tape.callees[c as usize], len as usize).is_some_and(|i| i.is_fused()) =>
            {
                let [a, b, c] = [0, 1, 2].map(|j| tape.args[start as usize + j] as usize);
                (k[a].saturating_add(k[b]).max(k[c]).saturating_add(1), m[a] * m[b] + m[c])
            }
            Step::Trig(..) | Step::Call(..) => return None,
        };
        k.push(kk);
        m.push(mm);
    }
    // M is a sum of products of non-negative numbers: double-double is within K·2⁻¹⁰⁰ of it.
    let up = |kk: u64, mm: DD| mm.round_f64() * (1.0 + gamma(kk, DD_UNIT)) * (1.0 + 1.0 / (1u64 << 40) as f64);
    Some(Terms {
        outputs: tape.outputs.iter().map(|&(_, s)| (k[s as usize], up(k[s as usize], m[s as usize]))).collect(),
        max_m: k.iter().zip(&m).map(|(&kk, &mm)| up(kk, mm)).fold(0.0, f64::max),
    })
}

/// The budget `γ_K(u)·M` plus the underflow slack for a tape of `ops` steps in a format with
/// unit roundoff `u` (binary32 or binary64).
pub fn allowed(k: u64, m: f64, u: f64, ops: usize) -> f64 {
    let tiny = if u == U32 { 2f64.powi(-149) } else { 2f64.powi(-1074) };
    gamma(k, u) * m + ops as f64 * tiny * m.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text;

    fn tape(src: &str) -> Tape {
        Tape::new(&text::parse(src).unwrap().functions[0])
    }

    #[test]
    fn k_and_m_by_hand() {
        // y = (a + b)·(c − d) − 2·a : K = max(1 + 1 + 1, 1) + 1 = 4; M = (|a|+|b|)(|c|+|d|) + 2|a|.
        let t = tape(
            "func @f {\n  phase parsed\n  input %a\n  input %b\n  input %c\n  input %d\n  \
             %y = (%a + %b)*(%c - %d) - 2.0*%a\n  output y = %y\n}\n",
        );
        let r = terms(&t, &[1.0, -2.0, 3.0, 5.0]).unwrap().outputs;
        assert_eq!(r[0].0, 4);
        // M is inflated by 2^-40 relative (its own rounding): 26 up to 1e-10.
        assert!(r[0].1 >= 26.0 && r[0].1 - 26.0 < 1e-10, "{r:?}");
        // Unary minus is exact: K(−a·b) = 1.
        let t = tape("func @f {\n  phase parsed\n  input %a\n  input %b\n  %y = -%a*%b\n  output y = %y\n}\n");
        assert_eq!(
            terms(&t, &[2.0, 3.0]).unwrap().outputs[0],
            (1, 6.0 * (1.0 + gamma(1, DD_UNIT)) * (1.0 + 2f64.powi(-40)))
        );
        // Fused: y = fma(a, b, c) rounds once (K = 1, M = |a||b| + |c|); z = (y·d) − e fused
        // again: K = max(1 + 0, 0) + 1 = 2, M = M(y)|d| + |e|.
        let t = tape(
            "func @f {\n  phase atomised\n  input %a\n  input %b\n  input %c\n  input %d\n  \
             %y = call @fma(%a, %b, %c)\n  %z = call @fms(%y, %d, %a)\n  output y = %y\n  output z = %z\n}\n",
        );
        let r = terms(&t, &[1.0, -2.0, 3.0, 5.0]).unwrap().outputs;
        assert_eq!((r[0].0, r[1].0), (1, 2));
        assert!(r[0].1 >= 5.0 && r[0].1 - 5.0 < 1e-10 && r[1].1 >= 26.0 && r[1].1 - 26.0 < 1e-10, "{r:?}");
        // A square root has no such budget.
        let t = tape("func @f {\n  phase atomised\n  input %a\n  %y = call @sqrt(%a)\n  output y = %y\n}\n");
        assert!(terms(&t, &[2.0]).is_none());
    }

    #[test]
    fn products_of_sums_need_more_than_the_depth() {
        // (a + b)·(c + d) has depth 2 but K = 3: search binary32 inputs (a, c in [1, 2), b, d
        // just under half an ulp of 1) for a result whose error exceeds γ₂·M; none may exceed
        // γ₃·M. The exact value (products of 25-bit numbers) is exact in double-double.
        let t = tape(
            "func @f {\n  phase parsed\n  input %a\n  input %b\n  input %c\n  input %d\n  \
             %y = (%a + %b)*(%c + %d)\n  output y = %y\n}\n",
        );
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut over_depth, mut worst) = (0, 0.0f64);
        for _ in 0..200_000 {
            let one_plus = |r: u64| 1.0 + (r % (1 << 23)) as f64 * 2f64.powi(-23);
            let half_ulp = |r: u64| (0.5 + 0.5 * (r % 1000) as f64 / 1000.0) * 2f64.powi(-24) as f32 as f64;
            let x =
                [one_plus(next()), half_ulp(next()) as f32 as f64, one_plus(next()), half_ulp(next()) as f32 as f64];
            let (k, m) = terms(&t, &x).unwrap().outputs[0];
            assert_eq!(k, 3);
            let exact = t.eval::<DD>(&x)[0];
            let err = (DD::from_f64(t.eval::<f32>(&x)[0] as f64) - exact).abs().round_f64();
            assert!(err <= gamma(3, U32) * m, "error {err:e} above γ₃·M at {x:?}");
            over_depth += (err > gamma(2, U32) * m) as u32;
            worst = worst.max(err / (U32 * m));
        }
        assert!(over_depth > 0, "no case above γ₂·M found; worst error {worst:.3}·u·M");
    }

    #[test]
    fn division_has_no_budget() {
        let t = tape("func @f {\n  phase atomised\n  input %a\n  %y = div %a, 3.0\n  output y = %y\n}\n");
        assert!(terms(&t, &[1.0]).is_none());
    }
}
