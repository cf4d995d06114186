//! The certified slow path: a [`Tape`] evaluated with `astro-float` at `p ≥ 256` bits, each
//! operation correctly rounded to nearest (relative error ≤ 2^(1−p)), and exact rounding of a
//! multi-word value to binary32 or binary64.

use astro_float::{BigFloat, Consts, RoundingMode, Sign};

use super::tape::{Step, Tape};
use crate::intrinsic::Intrinsic;
use crate::syntax::{BinOp, TrigFn};

const RM: RoundingMode = RoundingMode::ToEven;

/// `x` correctly rounded (to nearest, ties to even) to a binary format with `p` significant
/// bits and smallest normal exponent `emin`, largest `emax`, returned as an `f64` (exact for
/// binary32 and binary64).
fn round_big(x: &BigFloat, p: i64, emin: i64, emax: i64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x.is_inf() {
        return if x.is_inf_pos() { f64::INFINITY } else { f64::NEG_INFINITY };
    }
    let Some((words, _, sign, e, _)) = x.as_raw_parts() else { return f64::NAN };
    let neg = sign == Sign::Neg;
    let signed = |v: f64| if neg { -v } else { v };
    let Some(&top) = words.last() else { return signed(0.0) };
    if top == 0 {
        return signed(0.0);
    }
    // x = 0.1xxx… × 2^e, i.e. in [2^(e−1), 2^e); astro keeps mantissas normalised except at the
    // smallest exponent, far below anything binary64 can hold.
    let lz = top.leading_zeros() as i64;
    let (top, sticky_from_top) = if lz == 0 {
        (top, false)
    } else {
        let below = if words.len() > 1 { words[words.len() - 2] } else { 0 };
        ((top << lz) | (below >> (64 - lz)), below << lz != 0)
    };
    let sticky =
        sticky_from_top || words[..words.len().saturating_sub(if lz == 0 { 1 } else { 2 })].iter().any(|&w| w != 0);
    let big_e = e as i64 - 1 - lz; // x ∈ [2^E, 2^(E+1))
    if big_e > emax {
        return signed(f64::INFINITY);
    }
    let keep = p - (emin - big_e).max(0);
    let min_sub_exp = emin - p + 1;
    if keep < 0 {
        return signed(0.0);
    }
    if keep == 0 {
        // x ∈ [2^(min_sub_exp − 1), 2^min_sub_exp): half the smallest subnormal or more.
        let exactly_half = top == 1 << 63 && !sticky;
        return signed(if exactly_half { 0.0 } else { ldexp(1.0, min_sub_exp) });
    }
    let shift = 64 - keep;
    let mut q = top >> shift;
    let rem = top & ((1u64 << shift) - 1);
    let half = 1u64 << (shift - 1);
    if rem > half || (rem == half && (sticky || q & 1 == 1)) {
        q += 1;
    }
    let v = ldexp(q as f64, big_e - keep + 1);
    if v.is_finite() && v.abs() >= ldexp(2.0, emax) {
        return signed(f64::INFINITY);
    }
    signed(v)
}

/// `x · 2^k` without intermediate overflow or underflow (`x` an integer below 2⁶⁴).
fn ldexp(x: f64, k: i64) -> f64 {
    let mut v = x;
    let mut k = k;
    while k > 1000 {
        v *= 2f64.powi(1000);
        k -= 1000;
    }
    while k < -1000 {
        v *= 2f64.powi(-1000);
        k += 1000;
    }
    v * 2f64.powi(k as i32)
}

/// `x` correctly rounded to binary64.
pub fn to_f64(x: &BigFloat) -> f64 {
    round_big(x, 53, -1022, 1023)
}

/// `x` correctly rounded to binary32.
pub fn to_f32(x: &BigFloat) -> f32 {
    round_big(x, 24, -126, 127) as f32
}

/// `x` exactly, at `bits` of precision.
///
/// astro-float 0.9.6's own `BigFloat::from_f64` halves binary64 subnormals (found by this
/// module's tests); they are scaled into the normal range first and scaled back exactly.
pub fn from_f64(x: f64, bits: usize) -> BigFloat {
    if x != 0.0 && x.abs() < f64::MIN_POSITIVE {
        BigFloat::from_f64(x * 2f64.powi(64), bits).mul(&BigFloat::from_f64(2f64.powi(-64), bits), bits, RM)
    } else {
        BigFloat::from_f64(x, bits)
    }
}

/// Evaluates `tape` at `bits` of precision; returns every slot's value. With `mask`, only the
/// steps `i` with `mask[i]` are computed (see [`Tape::cone`]); the others are NaN.
///
/// # Panics
/// If astro-float cannot build its constant cache (an allocation failure).
pub fn eval(tape: &Tape, inputs: &[f64], bits: usize, mask: Option<&[bool]>) -> Vec<BigFloat> {
    let mut cc = Consts::new().expect("astro-float constants");
    let mut slots: Vec<BigFloat> = Vec::with_capacity(tape.slots());
    slots.extend(inputs.iter().map(|&x| from_f64(x, bits)));
    slots.extend(tape.consts.iter().map(|&x| from_f64(x, bits)));
    for (i, s) in tape.steps.iter().enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            slots.push(astro_float::NAN);
            continue;
        }
        let r = match *s {
            Step::Bin(op, a, b) => {
                let (a, b) = (&slots[a as usize], &slots[b as usize]);
                match op {
                    BinOp::Add => a.add(b, bits, RM),
                    BinOp::Sub => a.sub(b, bits, RM),
                    BinOp::Mul => a.mul(b, bits, RM),
                    BinOp::Div => a.div(b, bits, RM),
                }
            }
            Step::Neg(a) => slots[a as usize].neg(),
            Step::Trig(TrigFn::Sin, a) => slots[a as usize].sin(bits, RM, &mut cc),
            Step::Trig(TrigFn::Cos, a) => slots[a as usize].cos(bits, RM, &mut cc),
            Step::Call(c, start, len) => {
                let args: Vec<&BigFloat> =
                    tape.args[start as usize..(start + len) as usize].iter().map(|&x| &slots[x as usize]).collect();
                let callee = &tape.callees[c as usize];
                match Intrinsic::of(callee, args.len()) {
                    Some(Intrinsic::Sqrt) => args[0].sqrt(bits, RM),
                    // One rounding, as fused: the product of two `bits`-bit values is exact
                    // at `2·bits`, so only the sum rounds (and sets the inexact flag).
                    Some(Intrinsic::Fma) => args[0].mul(args[1], 2 * bits, RM).add(args[2], bits, RM),
                    Some(Intrinsic::Fms) => args[0].mul(args[1], 2 * bits, RM).sub(args[2], bits, RM),
                    Some(Intrinsic::Fnma) => args[2].sub(&args[0].mul(args[1], 2 * bits, RM), bits, RM),
                    None => standin(callee, &args, bits),
                }
            }
        };
        slots.push(r);
    }
    slots
}

/// [`crate::interp::callback_standin`] at `bits` of precision (same weights, same order).
fn standin(callee: &crate::syntax::Callee, args: &[&BigFloat], bits: usize) -> BigFloat {
    // The weights are exact small dyadic numbers: take them from the f64 stand-in on unit vectors.
    let w = |k: usize| {
        let mut e = vec![0.0f64; args.len()];
        e[k] = 1.0;
        BigFloat::from_f64(crate::interp::callback_standin::<f64>(callee, &e), bits)
    };
    if args.is_empty() {
        return BigFloat::from_f64(crate::interp::callback_standin::<f64>(callee, &[]), bits);
    }
    let mut acc = w(0).mul(args[0], bits, RM);
    for (k, a) in args.iter().enumerate().skip(1) {
        acc = acc.add(&w(k).mul(a, bits, RM), bits, RM);
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_multiword_values_is_exact() {
        let p = 256;
        for x in [1.0, -3.5, 0.1, 1e300, -2.5e-310, f64::MIN_POSITIVE, 5e-324, 123456.789] {
            assert_eq!(to_f64(&from_f64(x, p)).to_bits(), x.to_bits(), "{x}");
            assert_eq!(to_f32(&from_f64(x, p)).to_bits(), (x as f32).to_bits(), "{x} as f32");
        }
        // 1 + 2^-60: rounds to 1 in binary64, and 1 + 2^-53 + 2^-60 rounds up (above the tie).
        let one = BigFloat::from_f64(1.0, p);
        let tiny = BigFloat::from_f64(2f64.powi(-60), p);
        assert_eq!(to_f64(&one.add(&tiny, p, RM)), 1.0);
        let tie = BigFloat::from_f64(2f64.powi(-53), p);
        assert_eq!(to_f64(&one.add(&tie, p, RM)), 1.0); // exact tie → even
        assert_eq!(to_f64(&one.add(&tie, p, RM).add(&tiny, p, RM)), 1.0 + f64::EPSILON);
        // binary32: 1 + 2^-24 (tie → 1) and 1 + 2^-24 + 2^-60 (→ 1 + 2^-23): no double rounding.
        let t32 = BigFloat::from_f64(2f64.powi(-24), p);
        assert_eq!(to_f32(&one.add(&t32, p, RM)), 1.0);
        assert_eq!(to_f32(&one.add(&t32, p, RM).add(&tiny, p, RM)), 1.0 + f32::EPSILON);
        // Overflow and underflow thresholds.
        let max = BigFloat::from_f64(f64::MAX, p);
        assert_eq!(to_f64(&max.mul(&BigFloat::from_f64(2.0, p), p, RM)), f64::INFINITY);
        assert_eq!(to_f32(&BigFloat::from_f64(f32::MAX as f64 * 1.5, p)), f32::INFINITY);
        assert_eq!(to_f32(&BigFloat::from_f64(1e-46, p)), 0.0);
    }
}
