//! The extended-precision reference: the correctly rounded binary32 and binary64 values of
//! each output's exact value, for the IR's own operation order and the given `f64` inputs.
//!
//! # Method
//! 1. **Fast path**: the tape in double-double ([`super::dd`], ≈ 106 bits) plus a running
//!    error bound (Wilkinson's running error analysis, Higham §3.3): for each step, an upper
//!    bound `e` on |double-double − exact| from the operands' bounds and one rounding of at
//!    most [`DD_UNIT`]·|result|:
//!    `e(a±b) = e_a + e_b + U|r|`, `e(a×b) = |a|e_b + |b|e_a + e_a e_b + U|r|`,
//!    `e(a/b) = (e_a + |r|e_b)/(|b| − e_b) + U|r|` (unbounded when `|b| ≤ e_b`),
//!    `e(√a) = min(√e_a, e_a/√(a − e_a)) + U|r|`, `e(sin a) = e_a + T` (1-Lipschitz; `T` the
//!    trig error), a callback stand-in (weights in [−1, 1]) `Σ e_k + (n+1)·U·Σ|a_k|`, exact
//!    negation and inputs. Every bound is inflated by 2⁻⁴⁰ relative for its own rounding.
//! 2. An output is **certified** when every real number within `e` of the double-double value
//!    rounds to the same binary32 and the same binary64 value: then that value is the correctly
//!    rounded exact result. (Exact NaN, e.g. `sqrt` of a certainly negative value, is certified
//!    too.)
//! 3. Otherwise (heavy cancellation, `|angle| > 2²⁰`, overflow in double-double) the sample is
//!    uncertain outputs are re-evaluated (only the steps they need) with astro-float at
//!    [`BIG_BITS`] = 256 bits with the same bound (`U = 2⁻²⁵⁵`, values whose inexact flag is
//!    clear are exact), then at 1024 bits where the 256-bit interval does not reach zero; an
//!    output still uncertain keeps its last value and is flagged `certified: false` (an
//!    interval around zero after 256 bits is, in practice, an exact zero reached through
//!    inexact steps such as `sin(a)·cos(b) − cos(b)·sin(a)`).
//!
//! On the corpus the fast path certifies almost every output (figures in docs/accuracy.md, "Error reference"); the
//! 256-bit path is the reference wherever it does not.

use astro_float::{BigFloat, RoundingMode};

use super::dd::{two_sum, DD, DD_TRIG_ABS, DD_UNIT};
use super::tape::{Step, Tape};
use crate::intrinsic::Intrinsic;
use crate::syntax::BinOp;

/// Precision of the certified path, bits.
pub const BIG_BITS: usize = 256;
/// Precision of the last-resort path, bits.
pub const HUGE_BITS: usize = 1024;
const INFLATE: f64 = 1.0 + 1.0 / (1u64 << 40) as f64;

/// The reference value of one output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefValue {
    /// Exact value correctly rounded to binary64 (NaN when the exact value is undefined).
    pub f64: f64,
    /// Exact value correctly rounded to binary32.
    pub f32: f32,
    /// True when the error bound proves both roundings correct.
    pub certified: bool,
    /// Precision that produced the value: 106 (double-double), 256 or 1024 bits.
    pub bits: u32,
    /// True when the final error bound reaches zero (`|value| ≤ bound`): the sign of the exact
    /// value is unknown; when also uncertified, typically an exact zero reached through
    /// inexact operations (`sin(a)·cos(b) − cos(b)·sin(a)`).
    pub near_zero: bool,
}

/// An enclosure of one output's exact value: every real number within [`Enclosure::radius`]
/// of [`Enclosure::center`] (the exact sum `hi + lo` of the double-double). The reference's
/// running error bound makes it rigorous: the exact value lies inside. What the absolute
/// errors of the accuracy measurement are bounded from ([`Enclosure::abs_error_bound`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Enclosure {
    /// The centre: the double-double (or the 256/1024-bit value rounded to a double-double)
    /// the reference computed; NaN when the exact value is undefined (`sqrt` of a negative
    /// value), non-finite on overflow.
    pub center: DD,
    /// Radius, same units as the value, `≥ 0`; infinite when the bound is unbounded (a
    /// divisor's interval through zero, an overflow).
    pub radius: f64,
}

/// `a + b` for `a, b ≥ 0`, rounded upward (to `+∞` on overflow).
fn add_up(a: f64, b: f64) -> f64 {
    let (s, e) = two_sum(a, b);
    if e > 0.0 {
        s.next_up()
    } else {
        s
    }
}

impl Enclosure {
    /// An exact value: radius 0.
    pub fn exact(center: DD) -> Enclosure {
        Enclosure { center, radius: 0.0 }
    }

    /// An upper bound, rounded upward, of `|x − v|` over every `v` in the enclosure — so of
    /// the absolute error of a computed value `x` against the exact value. The distance to the
    /// centre is split exactly by error-free transformations (TwoSum) into a leading binary64
    /// term and two remainders, whose magnitudes are summed with the radius rounding upward:
    /// with a radius of 0 and no remainders (as for `x − hi` with `lo = 0`, or any `x` within
    /// a few ulps of a centre whose parts are representable together) the result is
    /// `|x − (hi + lo)|` itself; otherwise it is at most a few ulps of binary64 above. Infinite
    /// when `x` or the centre is not finite (NaN included) or the radius is infinite.
    pub fn abs_error_bound(&self, x: f64) -> f64 {
        let c = self.center;
        if !(x.is_finite() && c.is_finite() && self.radius >= 0.0 && self.radius.is_finite()) {
            return f64::INFINITY;
        }
        // x − hi − lo = y + z + q exactly.
        let (s, t) = two_sum(x, -c.hi);
        let (u, w) = two_sum(t, -c.lo);
        let (a, b) = two_sum(s, u);
        let (p, q) = two_sum(b, w);
        let (y, z) = two_sum(a, p);
        let r = add_up(add_up(add_up(y.abs(), z.abs()), q.abs()), self.radius);
        if r.is_nan() {
            f64::INFINITY
        } else {
            r
        }
    }
}

/// Reusable buffers for reference evaluations (one per thread; no allocation per sample once
/// warm, except on the rare 256-bit path).
#[derive(Default)]
pub struct Reference {
    dd: Vec<DD>,
    scratch: Vec<DD>,
    val: Vec<f64>,
    err: Vec<f64>,
    encl: Vec<Enclosure>,
}

/// What is known to be exact besides inputs and constants.
enum Known<'a> {
    /// Double-double values: a `+ − ×` of two exact plain doubles (`lo = 0`) is error-free
    /// (TwoSum, TwoProduct).
    DoubleDouble(&'a [DD]),
    /// astro-float: values whose inexact flag is clear.
    Big(&'a [bool]),
    /// Nothing: every step rounds (a binary32/binary64 evaluation).
    Nothing,
}

/// Fills `err` with the running error bound of every slot (see the module doc); `val` holds
/// each slot's computed value as an `f64` (sign and magnitude).
fn propagate(tape: &Tape, val: &[f64], known: Known, u: f64, trig_abs: f64, err: &mut Vec<f64>) {
    err.clear();
    err.resize(tape.inputs.len() + tape.consts.len(), 0.0);
    propagate_from(tape, val, known, u, trig_abs, 0.0, err)
}

/// [`propagate`] from given leaf errors (`err` holds one per input and constant), adding
/// `floor` (an absolute underflow allowance) to every rounded step.
fn propagate_from(tape: &Tape, val: &[f64], known: Known, u: f64, trig_abs: f64, floor: f64, err: &mut Vec<f64>) {
    for s in &tape.steps {
        let slot = err.len();
        let r = val[slot];
        let ru = u * r.abs();
        let exact = match known {
            Known::DoubleDouble(dd) => {
                let plain = |x: u32| err[x as usize] == 0.0 && dd[x as usize].lo == 0.0;
                matches!(*s, Step::Bin(BinOp::Add | BinOp::Sub | BinOp::Mul, a, b) if plain(a) && plain(b))
            }
            Known::Big(exact) => exact[slot],
            Known::Nothing => false,
        };
        let e = match *s {
            _ if exact => 0.0,
            Step::Bin(op, a, b) => {
                let (ea, eb, va, vb) = (err[a as usize], err[b as usize], val[a as usize], val[b as usize]);
                match op {
                    BinOp::Add | BinOp::Sub => ea + eb + ru,
                    BinOp::Mul => va.abs() * eb + vb.abs() * ea + ea * eb + ru,
                    BinOp::Div => {
                        let d = vb.abs() - eb;
                        if d > 0.0 {
                            (ea + r.abs() * eb) / d + 2.0 * ru
                        } else {
                            f64::INFINITY
                        }
                    }
                }
            }
            Step::Neg(a) => err[a as usize],
            Step::Trig(_, a) => err[a as usize] + trig_abs,
            Step::Call(c, start, len) => {
                let args = &tape.args[start as usize..(start + len) as usize];
                let intrinsic = Intrinsic::of(&tape.callees[c as usize], args.len());
                if intrinsic == Some(Intrinsic::Sqrt) {
                    let (va, ea) = (val[args[0] as usize], err[args[0] as usize]);
                    if r.is_nan() && va + ea < 0.0 {
                        0.0 // the exact argument is negative: the exact result is NaN too
                    } else if va - ea > 0.0 {
                        (ea.sqrt()).min(ea / (va - ea).sqrt()) + ru
                    } else {
                        ea.sqrt() + ru
                    }
                } else if intrinsic.is_some() {
                    // ±a·b ± c: the product's error, the addend's, and a rounding of the
                    // product and of the sum (two for a double-double evaluation, one fused).
                    let [a, b, c] = [0, 1, 2].map(|k| args[k] as usize);
                    let (va, vb) = (val[a].abs(), val[b].abs());
                    va * err[b] + vb * err[a] + err[a] * err[b] + err[c] + u * va * vb + ru
                } else {
                    let sum_e: f64 = args.iter().map(|&x| err[x as usize]).sum();
                    let sum_a: f64 = args.iter().map(|&x| val[x as usize].abs()).sum();
                    sum_e + (args.len() + 1) as f64 * u * sum_a
                }
            }
        };
        let e = if e == 0.0 && floor == 0.0 {
            0.0
        } else if e.is_nan() || !r.is_finite() {
            f64::INFINITY
        } else {
            e * INFLATE + floor
        };
        err.push(e);
    }
}

impl Reference {
    /// An empty workspace.
    pub fn new() -> Reference {
        Reference::default()
    }

    /// The reference values of every output of `tape` at `inputs` (one `f64` per tape input),
    /// written to `out` in output order.
    pub fn eval(&mut self, tape: &Tape, inputs: &[f64], out: &mut Vec<RefValue>) {
        self.eval_with(tape, inputs, out, None)
    }

    /// Like [`Reference::eval`]; outputs `k` with `skip_big[k]` whose double-double bound
    /// reaches zero are not re-evaluated at 256 bits (they stay uncertified, `near_zero`). The
    /// accuracy pass sets it for outputs where 256 bits never helped on probe samples
    /// (structural zeros), to save the slow path.
    pub fn eval_with(&mut self, tape: &Tape, inputs: &[f64], out: &mut Vec<RefValue>, skip_big: Option<&[bool]>) {
        tape.eval_into::<DD>(inputs, &mut self.dd, &mut self.scratch);
        self.val.clear();
        self.val.extend(self.dd.iter().map(|x| x.hi));
        propagate(tape, &self.val, Known::DoubleDouble(&self.dd), DD_UNIT, DD_TRIG_ABS, &mut self.err);
        out.clear();
        self.encl.clear();
        self.encl.extend(
            tape.outputs.iter().map(|&(_, s)| Enclosure { center: self.dd[s as usize], radius: self.err[s as usize] }),
        );
        let mut redo = Vec::new();
        for (k, &(_, s)) in tape.outputs.iter().enumerate() {
            let (v, e) = (self.dd[s as usize], self.err[s as usize]);
            let certified = dd_certified(v, e);
            let near_zero = e > 0.0 && v.hi.abs() <= e;
            let skip = near_zero && skip_big.is_some_and(|m| m[k]);
            if !certified && !skip {
                redo.push(k);
            }
            out.push(RefValue { f64: v.round_f64(), f32: v.round_f32(), certified, bits: 106, near_zero });
        }
        for bits in [BIG_BITS, HUGE_BITS] {
            if redo.is_empty() {
                break;
            }
            for (&k, (b, e)) in redo.iter().zip(eval_big_enclosed(tape, inputs, bits, &redo)) {
                out[k] = b;
                self.encl[k] = e;
            }
            // 1024 bits only where 256 could not decide a rounding away from zero: an interval
            // around zero at 256 bits is an exact zero for all practical purposes.
            redo.retain(|&k| !out[k].certified && !out[k].near_zero);
        }
    }

    /// An enclosure of the exact value of every output of the last [`Reference::eval`] or
    /// [`Reference::eval_with`], in output order: the double-double value and its running
    /// error bound, or, for outputs re-evaluated at 256 or 1024 bits, that value and its bound.
    pub fn enclosures(&self) -> &[Enclosure] {
        &self.encl
    }
}

/// The double-double value of every output of `tape` at `inputs` and a bound on its distance
/// from the exact value (infinite when unbounded): the reference of the error budget check.
pub fn dd_bounded(tape: &Tape, inputs: &[f64]) -> Vec<(DD, f64)> {
    let (mut dd, mut scratch, mut err) = (Vec::new(), Vec::new(), Vec::new());
    tape.eval_into::<DD>(inputs, &mut dd, &mut scratch);
    let val: Vec<f64> = dd.iter().map(|x| x.hi).collect();
    propagate(tape, &val, Known::DoubleDouble(&dd), DD_UNIT, DD_TRIG_ABS, &mut err);
    tape.outputs.iter().map(|&(_, s)| (dd[s as usize], err[s as usize])).collect()
}

/// A rigorous bound on |computed − exact| for every output of `tape` evaluated in binary32
/// (`single`) or binary64 at `inputs`, from the computed slots (`slots[i]` as `f64`; Wilkinson's
/// running error analysis, Higham §3.3, as in the module doc): inputs and constants start with
/// their own rounding to the format; each step adds `u'·|r|` with `u' = u·(1 + 2⁻²⁰)` (unit
/// roundoff, widened for the computed `r`), trig results `2⁻²²` (binary32) or `2⁻⁵¹`
/// (binary64) absolute (two ulps of 1: libm's sin/cos are within one), and `2⁻¹⁴⁹` or
/// `2⁻¹⁰⁷⁴` for underflow. Infinite where a divisor's interval reaches zero or a value
/// overflows.
pub fn float_bound(tape: &Tape, inputs: &[f64], slots: &[f64], single: bool) -> Vec<f64> {
    let (u, trig, floor) = if single {
        (2f64.powi(-24), 2f64.powi(-22), 2f64.powi(-149))
    } else {
        (2f64.powi(-53), 2f64.powi(-51), 2f64.powi(-1074))
    };
    let round = |x: f64| if single { x as f32 as f64 } else { x };
    let mut err: Vec<f64> = inputs.iter().chain(&tape.consts).map(|&x| (x - round(x)).abs() * INFLATE).collect();
    propagate_from(tape, slots, Known::Nothing, u * (1.0 + 2f64.powi(-20)), trig, floor, &mut err);
    tape.outputs.iter().map(|&(_, s)| err[s as usize]).collect()
}

fn dd_certified(v: DD, e: f64) -> bool {
    if e == 0.0 {
        return true;
    }
    if !e.is_finite() || !v.is_finite() {
        return false;
    }
    // Also cover the rounding of v ± e in double-double.
    let e = DD::from_f64(e * INFLATE + 2.0 * DD_UNIT * v.hi.abs());
    let (lo, hi) = (v - e, v + e);
    lo.round_f64() == hi.round_f64() && lo.round_f32() == hi.round_f32()
}

/// The reference values of the outputs `outputs` (indices into `tape.outputs`) at `inputs`,
/// computed at `bits` of precision with astro-float (only the steps they need) and certified
/// by the same running error bound (`U = 2^(1−bits)`).
pub fn eval_big(tape: &Tape, inputs: &[f64], bits: usize, outputs: &[usize]) -> Vec<RefValue> {
    eval_big_enclosed(tape, inputs, bits, outputs).into_iter().map(|(r, _)| r).collect()
}

/// [`eval_big`] with an enclosure of each exact value: the `bits`-bit value rounded to a
/// double-double (`hi` the value rounded to binary64, `lo` the rest rounded to binary64), with
/// the running error bound plus a bound on that rounding (`2⁻¹⁰⁴·|hi| + 2⁻¹⁰⁷³`, 0 when the
/// rest is 0).
fn eval_big_enclosed(tape: &Tape, inputs: &[f64], bits: usize, outputs: &[usize]) -> Vec<(RefValue, Enclosure)> {
    let mask = tape.cone(outputs);
    let slots = super::big::eval(tape, inputs, bits, Some(&mask));
    let val: Vec<f64> = slots.iter().map(super::big::to_f64).collect();
    let u = 2f64.powi(1 - bits as i32);
    let exact: Vec<bool> = slots.iter().map(|x| !x.inexact() && !x.is_nan()).collect();
    let mut err = Vec::new();
    propagate(tape, &val, Known::Big(&exact), u, u, &mut err);
    outputs
        .iter()
        .map(|&k| {
            let s = tape.outputs[k].1;
            let v = &slots[s as usize];
            let e = err[s as usize];
            let certified = e == 0.0 || {
                let e = BigFloat::from_f64(e * INFLATE + 4.0 * u * val[s as usize].abs(), bits);
                let lo = v.sub(&e, bits, RoundingMode::Down);
                let hi = v.add(&e, bits, RoundingMode::Up);
                !e.is_inf()
                    && super::big::to_f64(&lo) == super::big::to_f64(&hi)
                    && super::big::to_f32(&lo) == super::big::to_f32(&hi)
            };
            let r = RefValue {
                f64: super::big::to_f64(v),
                f32: super::big::to_f32(v),
                certified: certified && !val[s as usize].is_infinite(),
                bits: bits as u32,
                near_zero: err[s as usize] > 0.0 && val[s as usize].abs() <= err[s as usize],
            };
            (r, big_enclosure(v, e, bits))
        })
        .collect()
}

/// The enclosure of a `bits`-bit value `v` whose distance from the exact value is at most `e`.
fn big_enclosure(v: &BigFloat, e: f64, bits: usize) -> Enclosure {
    let hi = super::big::to_f64(v);
    if !hi.is_finite() {
        return Enclosure { center: DD { hi, lo: 0.0 }, radius: f64::INFINITY };
    }
    // |v − hi| ≤ 2⁻⁵³·|hi| (or half the smallest subnormal), so the rest holds in `bits` bits
    // and rounds to `lo` within 2⁻⁵³ of itself: |v − hi − lo| ≤ 2⁻¹⁰⁶·|hi| + 2⁻¹⁰⁷⁴ with room.
    let rest = v.sub(&super::big::from_f64(hi, bits), bits, RoundingMode::ToEven);
    let lo = super::big::to_f64(&rest);
    let extra = if rest.is_zero() { 0.0 } else { 2f64.powi(-104) * hi.abs() + 2f64.powi(-1073) };
    let radius = if e.is_nan() { f64::INFINITY } else { add_up(e, extra) };
    Enclosure { center: DD { hi, lo }, radius }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text;

    #[test]
    fn float_bound_covers_the_binary32_and_binary64_errors() {
        let src = "func @f {\n  phase parsed\n  input %a\n  input %b\n  %S = sin %a\n  %C = cos %b\n  \
                   %y = (%S*%b - 0.1*%C)/(%a*%a + 0.3) + @sqrt(%b*%b + 1.7) - %S*%C\n  output y = %y\n}\n";
        let t = Tape::new(&text::parse(src).unwrap().functions[0]);
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let (a, b) = ((i as f64 * 0.37).sin() * 3.0, (i as f64 * 0.11).cos() * 5.0 + 0.5);
            let x = [a, b];
            let (exact, e) = dd_bounded(&t, &x)[0];
            let (mut s32, mut s64, mut scr32, mut scr64) = (Vec::<f32>::new(), Vec::new(), Vec::new(), Vec::new());
            t.eval_into::<f32>(&x, &mut s32, &mut scr32);
            t.eval_into::<f64>(&x, &mut s64, &mut scr64);
            let w32: Vec<f64> = s32.iter().map(|&v| v as f64).collect();
            let slot = t.outputs[0].1 as usize;
            for (got, bound) in
                [(w32[slot], float_bound(&t, &x, &w32, true)[0]), (s64[slot], float_bound(&t, &x, &s64, false)[0])]
            {
                let err = (DD::from_f64(got) - exact).abs().round_f64();
                assert!(err <= bound + e, "point {i}: error {err:e} above the bound {bound:e}");
                worst = worst.max(err / bound);
            }
        }
        // Not vacuous: the bound is within a few hundred times the real error somewhere.
        assert!(worst > 1e-3, "{worst}");
    }

    fn tape(src: &str) -> Tape {
        let m = text::parse(src).unwrap();
        crate::verifier::verify(&m).unwrap();
        Tape::new(&m.functions[0])
    }

    #[test]
    fn a_sum_with_known_exact_value() {
        // (1e16 + 1) - 1e16 + 0.5: binary64 loses the 1 (gives 0.5), the exact value is 1.5.
        let t = tape(
            "func @f {\n  phase atomised\n  input %a\n  input %b\n  input %c\n  %s = add %a, %b\n  \
             %d = sub %s, %a\n  %r = add %d, %c\n  output y = %r\n}\n",
        );
        let x = [1e16, 1.0, 0.5];
        assert_eq!(t.eval::<f64>(&x)[0], 0.5);
        let mut r = Reference::new();
        let mut out = Vec::new();
        r.eval(&t, &x, &mut out);
        assert_eq!(out[0], RefValue { f64: 1.5, f32: 1.5, certified: true, bits: 106, near_zero: false });
        // Every step is error-free in double-double: the enclosure is the exact value, and the
        // binary64 result 0.5 is exactly 1 away.
        // (1e16 + 1 is a double-double with lo = 1, so the subtraction's rounding bound enters:
        // the radius is tiny but not 0.)
        let enc = r.enclosures()[0];
        assert_eq!(enc.center, DD::from_f64(1.5));
        assert!(enc.radius > 0.0 && enc.radius < 2f64.powi(-90), "{enc:?}");
        let b = enc.abs_error_bound(0.5);
        assert!((1.0..=1.0 + 2f64.powi(-51)).contains(&b), "{b}");
        assert_eq!(eval_big(&t, &x, 256, &[0])[0], RefValue { bits: 256, ..out[0] });
    }

    #[test]
    fn cancellation_beyond_double_double_falls_back_to_256_bits() {
        // x + 2^60 with x = 1 + 2^-52 needs 113 bits: double-double drops the 2^-52, its bound
        // (≈ 2^-40) swamps the final 2^-70, so the 256-bit path (where every step is exact)
        // decides: ((x + 2^60) − 2^60 − x + 2^-70)·2^60 = 2^-10.
        let t = tape(
            "func @f {\n  phase atomised\n  input %x\n  input %big\n  input %y\n  %s = add %x, %big\n  \
             %d = sub %s, %big\n  %z = sub %d, %x\n  %r = add %z, %y\n  %p = mul %r, %big\n  output o = %p\n}\n",
        );
        let x = [1.0 + 2f64.powi(-52), 2f64.powi(60), 2f64.powi(-70)];
        let mut r = Reference::new();
        let mut out = Vec::new();
        r.eval(&t, &x, &mut out);
        assert_eq!(
            out[0],
            RefValue { f64: 2f64.powi(-10), f32: 2f32.powi(-10), certified: true, bits: 256, near_zero: false }
        );
        // binary64 in the same order loses x entirely in the first sum: −x·2^60.
        assert_eq!(t.eval::<f64>(&x)[0], -x[0] * x[1]);
        // The enclosure comes from the 256-bit path: the exact 2^-10 with radius 0 (every
        // step exact there), so the error bound of the binary64 result is exactly its distance
        // |−x·2^60 − 2^-10| rounded upward.
        let enc = r.enclosures()[0];
        assert_eq!((enc.center.hi + enc.center.lo, enc.radius), (2f64.powi(-10), 0.0));
        let got = -x[0] * x[1];
        assert_eq!(enc.abs_error_bound(got), (x[0] * x[1]).next_up());
        assert_eq!(enc.abs_error_bound(f64::NAN), f64::INFINITY);
    }

    #[test]
    fn enclosure_bounds_are_upper_bounds_rounded_upward() {
        // |x − (hi + lo)| exact when it is a binary64 number; a radius adds on top, upward.
        let c = DD { hi: 1.0, lo: 2f64.powi(-70) };
        let e = Enclosure { center: c, radius: 0.0 };
        assert_eq!(e.abs_error_bound(1.0), 2f64.powi(-70));
        let b = e.abs_error_bound(3.0);
        assert!((2.0..=2.0 + 2f64.powi(-50)).contains(&b), "2 − 2^-70 rounded upward, with a remainder: {b}");
        let e = Enclosure { center: c, radius: 2f64.powi(-80) };
        let b = e.abs_error_bound(1.0);
        assert_eq!(b, 2f64.powi(-70) + 2f64.powi(-80), "a representable sum: exact");
        // Near cancellation: x − hi = 0 exactly, the distance is |lo|.
        let e = Enclosure::exact(DD { hi: 0.1, lo: -1e-18 });
        assert_eq!(e.abs_error_bound(0.1), 1e-18);
        assert_eq!(Enclosure { center: c, radius: f64::INFINITY }.abs_error_bound(1.0), f64::INFINITY);
        assert_eq!(Enclosure::exact(DD::from_f64(f64::NAN)).abs_error_bound(1.0), f64::INFINITY);
    }

    #[test]
    fn sqrt_of_a_negative_value_is_a_certified_nan() {
        let t = tape("func @f {\n  phase atomised\n  input %a\n  %r = call @sqrt(%a)\n  output o = %r\n}\n");
        let mut out = Vec::new();
        Reference::new().eval(&t, &[-2.0], &mut out);
        assert!(out[0].f64.is_nan() && out[0].f32.is_nan() && out[0].certified);
        Reference::new().eval(&t, &[2.0], &mut out);
        assert_eq!(out[0].f64, std::f64::consts::SQRT_2);
        assert_eq!(out[0].f32, std::f32::consts::SQRT_2);
    }

    #[test]
    fn exact_zeros_are_certified_by_exact_big_arithmetic_or_flagged() {
        // t = a·b·a (159 bits) is rounded in double-double, so t − t = 0 has a nonzero bound
        // there; at 256 bits t is exact and the zero is certified.
        let t = tape(
            "func @f {\n  phase atomised\n  input %a\n  input %b\n  %s = mul %a, %b\n  %t = mul %s, %a\n  \
             %d = sub %t, %t\n  output o = %d\n}\n",
        );
        let mut out = Vec::new();
        Reference::new().eval(&t, &[0.1, 0.3], &mut out);
        assert_eq!(out[0], RefValue { f64: 0.0, f32: 0.0, certified: true, bits: 256, near_zero: false });
        // sin(a) − sin(a) is inexact at any precision: the zero stays uncertain (flagged), and
        // 1024 bits are not tried for an interval around zero.
        let t = tape("func @f {\n  phase atomised\n  input %a\n  %s = sin %a\n  %d = sub %s, %s\n  output o = %d\n}\n");
        Reference::new().eval(&t, &[0.1], &mut out);
        assert_eq!(out[0], RefValue { f64: 0.0, f32: 0.0, certified: false, bits: 256, near_zero: true });
    }
}
