//! A lower bound of what any certified bound must say: the error of one execution the
//! rounding model allows, found at a point of the domain.
//!
//! Every certified bound of the field (robovec's [`super::bound()`], Daisy, FPTaylor, Satire,
//! RoboPrec) models each rounding as an unknown `δ` with `|δ| ≤ ½ ulp` of the result in its
//! format (half a step in fixed point), and bounds the output's error over **every** choice of
//! the `δ`s and every point of the domain. So if one choice at one point gives an output error
//! `W`, no bound sound under the model can be below `W`. This module builds such a choice:
//!
//! 1. At the point, the function is computed as it will be ([`robovec_ir::format::eval_values`]:
//!    each value in its format). An op whose computed result differs from its exact result on
//!    the same operands *rounds here*; one that does not (a product by 2, a sum that fits, a
//!    representable quotient) keeps `δ = 0`, so the choice stays allowed even to an analysis
//!    that knows which ops are exact.
//! 2. The gradient `∂o/∂z` of the output `o` with respect to every value `z` is taken by
//!    reverse-mode differentiation in binary64 at the point.
//! 3. The execution is run again in double-double ([`robovec_ir::numerics::DD`], ≈ 2⁻¹⁰⁰
//!    relative per op), every op that rounds at the point replaced by its exact result on the
//!    execution's operands plus `±(1 − 2⁻²⁰)·½ ulp` of it, signed as `∂o/∂z` (and once more
//!    with every sign flipped; the larger error is kept). Conversions (a binary64 operand read
//!    by a binary32 op), inputs and constants round as the computation rounds them.
//! 4. The error is measured against the certified reference ([`Reference`]: the exact value
//!    correctly rounded to binary64), less half an ulp of it.
//!
//! To first order the execution's error is `|e₀ ± Σ_z |∂o/∂z|·½ ulp(z)|`: every rounding
//! aligned, which is what sampling (roundings of pseudo-random signs, `√N` of `N` of them)
//! does not see. Cost at one point: one forward run, then per output one reverse sweep and two
//! double-double runs, `O(outputs · ops)`.
//!
//! What it is for: the tightness of [`super::bound()`] (bound / witness is the pessimism of the
//! analysis, witness / sampled error the part no model-based certification can remove), and
//! a soundness test far stronger than sampling (a bound below a witness is a bug).

use robovec_ir::format::{eval_values, fix_constant, integer_op, Format, FormatError};
use robovec_ir::interp::{eval_def, Float};
use robovec_ir::numerics::{RefValue, Reference, Tape, DD};
use robovec_ir::{BinOp, Def, Function, Intrinsic, Operand, TrigFn, Value};

use super::Formats;

/// Shrinks each chosen rounding inside the model's `½ ulp`, units: 1 (the double-double
/// result the rounding is added to is within 2⁻¹⁰⁰ of the exact op's).
const INSIDE: f64 = 1.0 - 1.0 / (1u64 << 20) as f64;

/// Adversarial executions of one function (module doc), reused across points.
pub struct Witness {
    /// The function with every value's format set as the mode says.
    f: Function,
    tape: Tape,
    reference: Reference,
    refs: Vec<RefValue>,
    /// Per output, in `f.outputs` order: its value and its position among the tape's
    /// outputs (the reference's order); `None` for a constant output.
    outputs: Vec<Option<(Value, usize)>>,
}

impl Witness {
    /// Prepares `f` (atomised) computed as `mode` says: [`Formats::F64`] every value binary64,
    /// [`Formats::F32`] every value binary32 (inputs and constants rounded to it),
    /// [`Formats::Mixed`] each value in its IR format.
    pub fn new(f: &Function, mode: Formats) -> Witness {
        let mut g = f.clone();
        match mode {
            Formats::Mixed => {}
            Formats::F64 => g.clear_formats(),
            Formats::F32 => {
                let all: Vec<Value> = g.inputs.iter().chain(&g.body).copied().collect();
                for v in all {
                    g.set_format(v, Format::Binary32);
                }
            }
        }
        let mut plain = f.clone();
        plain.clear_formats();
        let tape = Tape::new(&plain);
        let outputs = f
            .outputs
            .iter()
            .map(|o| match o.value {
                Operand::Value(v) => {
                    Some((v, tape.outputs.iter().position(|(name, _)| *name == o.name).expect("an output of the tape")))
                }
                Operand::Const(_) => None,
            })
            .collect();
        Witness { tape, f: g, reference: Reference::new(), refs: Vec::new(), outputs }
    }

    /// The inputs' names in the order [`Witness::errors_at`] reads them.
    pub fn inputs(&self) -> &[String] {
        &self.tape.inputs
    }

    /// At the point `xs` (one value per [`Witness::inputs`], binary64), for each output in
    /// `f.outputs` order, a lower bound of the error of the adversarial execution (module
    /// doc), absolute, in the output's units: `None` for a constant output, an output whose
    /// reference is not certified or whose execution is not finite.
    ///
    /// # Errors
    /// A fixed-point value that overflows its format at this point (the computation itself
    /// is undefined there).
    pub fn errors_at(&mut self, xs: &[f64]) -> Result<Vec<Option<f64>>, FormatError> {
        Ok(self.errors_at_until(xs, || false)?.expect("never stopped"))
    }

    /// [`Witness::errors_at`], calling `tick` `1 + ops/1024` times per output (about one call
    /// per 2,000 double-double ops: [`robovec_ir::time_limit::Ticker`]'s step) and stopping
    /// with `Ok(None)` when it returns true.
    ///
    /// # Errors
    /// As [`Witness::errors_at`].
    pub fn errors_at_until(
        &mut self,
        xs: &[f64],
        mut tick: impl FnMut() -> bool,
    ) -> Result<Option<Vec<Option<f64>>>, FormatError> {
        let f = &self.f;
        let ticks_per_output = 1 + f.body.len() / 1024;
        let names = &self.tape.inputs;
        let input = |name: &str| xs[names.iter().position(|n| n == name).expect("an input of the tape")];
        let actual = eval_values(f, input)?;
        let exact_vals = robovec_ir::interp::eval_values::<f64>(f, input);
        self.reference.eval(&self.tape, xs, &mut self.refs);
        // Which ops round at this point, and their half step's format.
        let n = f.values.len();
        let mut rounds = vec![false; n];
        for &z in &f.body {
            let r = eval_def::<DD>(&f.value(z).def, |o| read(f, z, o, &|x: Value| DD::from_f64(actual[x.index()])));
            rounds[z.index()] = DD::from_f64(actual[z.index()]) != r;
        }
        let mut out = Vec::with_capacity(self.outputs.len());
        for o in &self.outputs {
            for _ in 0..ticks_per_output {
                if tick() {
                    return Ok(None);
                }
            }
            let Some((o, at)) = *o else {
                out.push(None);
                continue;
            };
            let r = self.refs[at];
            if !r.certified || !r.f64.is_finite() {
                out.push(None);
                continue;
            }
            let grad = gradient(f, &exact_vals, o);
            let cone = cone_of(f, o);
            let mut worst: Option<f64> = None;
            for sign in [1.0, -1.0] {
                let w = execution(f, &cone, &actual, &rounds, &grad, sign)[o.index()];
                let e = (w - DD::from_f64(r.f64)).to_f64().abs();
                let half_ulp = (r.f64.abs().next_up() - r.f64.abs()) / 2.0;
                if e.is_finite() {
                    let e = (e - half_ulp).max(0.0);
                    worst = Some(worst.map_or(e, |w| w.max(e)));
                }
            }
            out.push(worst);
        }
        Ok(Some(out))
    }
}

/// The operand `o` as the op of `z` reads it, the values from `value`: a binary32 op reads a
/// wider value or a constant rounded to binary32, a fixed-point integer op a constant as
/// [`fix_constant`] holds it ([`robovec_ir::format`]'s semantics); everything else as is.
fn read(f: &Function, z: Value, o: &Operand, value: &impl Fn(Value) -> DD) -> DD {
    match (f.format(z), *o) {
        (Format::Binary32, Operand::Const(c)) => DD::from_f64(c as f32 as f64),
        (Format::Binary32, Operand::Value(x)) if f.format(x) != Format::Binary32 => {
            DD::from_f64(value(x).to_f64() as f32 as f64)
        }
        (Format::Fix { .. }, Operand::Const(c)) if integer_op(f, z).is_some() => {
            let (k, frac) = fix_constant(c).expect("an integer op's constant has a word");
            DD::from_f64(k as f64 * 2f64.powi(-frac))
        }
        (_, Operand::Const(c)) => DD::from_f64(c),
        (_, Operand::Value(x)) => value(x),
    }
}

/// Half a step of `format` at `r` (the largest error of rounding `r` to nearest in it): half
/// an ulp of `r`'s binade in binary64/binary32 (half the subnormal step below the normal
/// range), `2^(−f−1)` in `fix<w,f>`.
fn half_step(format: Format, r: f64) -> f64 {
    let (precision, min_exp) = match format {
        Format::Binary64 => (53, -1022),
        Format::Binary32 => (24, -126),
        Format::Fix { fraction, .. } => return 2f64.powi(-fraction - 1),
    };
    let e = binade(r).max(min_exp);
    let k = e - precision;
    if (-1022..=1023).contains(&k) {
        // 2^k, a normal binary64: its biased exponent alone.
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        2f64.powi(k)
    }
}

/// `⌊log₂|r|⌋` of a finite nonzero `r`, read from its exponent bits (a subnormal's from its
/// leading bit); −1075 for 0 (below every binade), and 2048 for ±∞ and NaN (above every one:
/// their half step is +∞).
fn binade(r: f64) -> i32 {
    let bits = r.abs().to_bits();
    let biased = (bits >> 52) as i32;
    match biased {
        0 if bits == 0 => -1075,
        0 => -1011 - bits.leading_zeros() as i32,
        0x7ff => 2048,
        _ => biased - 1023,
    }
}

/// Every value of the execution whose rounding ops (`rounds`) each add `sign·sign(grad)`
/// times (just under) half a step of their result, in double-double; inputs as `actual`. Only
/// the body values in `cone` (body order, closed under operands: [`cone_of`]) are computed,
/// the rest are NaN.
fn execution(f: &Function, cone: &[Value], actual: &[f64], rounds: &[bool], grad: &[f64], sign: f64) -> Vec<DD> {
    let mut w = vec![DD::from_f64(f64::NAN); f.values.len()];
    for &v in &f.inputs {
        w[v.index()] = DD::from_f64(actual[v.index()]);
    }
    for &z in cone {
        let r = eval_def::<DD>(&f.value(z).def, |o| read(f, z, o, &|x: Value| w[x.index()]));
        w[z.index()] = if rounds[z.index()] {
            let s = if grad[z.index()] < 0.0 { -sign } else { sign };
            r + DD::from_f64(s * INSIDE * half_step(f.format(z), r.to_f64()))
        } else {
            r
        };
    }
    w
}

/// The body values `out` depends on, `out` included, in body order: an output's execution
/// computes its cone only (values outside it stay NaN and are never read), so a function's
/// outputs cost the sum of their cones' sizes.
fn cone_of(f: &Function, out: Value) -> Vec<Value> {
    let mut in_cone = vec![false; f.values.len()];
    in_cone[out.index()] = true;
    f.mark_operands(&mut in_cone);
    f.body.iter().copied().filter(|z| in_cone[z.index()]).collect()
}

/// `∂out/∂z` for every value `z` of `f` (by [`Value::index`]) at the binary64 values `vals`,
/// by reverse-mode differentiation (0 where `out` does not depend on `z`).
pub fn gradient(f: &Function, vals: &[f64], out: Value) -> Vec<f64> {
    let mut adj = vec![0.0; f.values.len()];
    adj[out.index()] = 1.0;
    for &z in f.body.iter().rev() {
        let a = adj[z.index()];
        if a == 0.0 {
            continue;
        }
        local_partials(&f.value(z).def, vals, |v, d| adj[v.index()] += a * d);
    }
    adj
}

/// Calls `give(operand, ∂z/∂operand)` for each value operand of the op `def` of an atomised
/// value `z`, at the binary64 values `vals` (by [`Value::index`]): `1`, `−1` for sums, the other
/// factor for products, `1/b` and `−a/b²` for `a/b`, `1/(2√a)`, `cos a` and `−sin a`, the
/// fused ops' factors. A callback, an input or an expression gives none. An operand read
/// twice is given twice (the partials add up).
pub fn local_partials(def: &Def, vals: &[f64], mut give: impl FnMut(Value, f64)) {
    let val = |o: &Operand| match o {
        Operand::Value(v) => vals[v.index()],
        Operand::Const(c) => *c,
    };
    let mut give = |o: &Operand, d: f64| {
        if let Operand::Value(v) = o {
            give(*v, d);
        }
    };
    match def {
        Def::Trig(t, p) => {
            let q = vals[p.index()];
            give(&Operand::Value(*p), if *t == TrigFn::Sin { q.cos() } else { -q.sin() });
        }
        Def::Binary(op, p, q) => match op {
            BinOp::Add => {
                give(p, 1.0);
                give(q, 1.0);
            }
            BinOp::Sub => {
                give(p, 1.0);
                give(q, -1.0);
            }
            BinOp::Mul => {
                give(p, val(q));
                give(q, val(p));
            }
            BinOp::Div => {
                give(p, 1.0 / val(q));
                give(q, -val(p) / (val(q) * val(q)));
            }
        },
        Def::Call(c, args) => match Intrinsic::of(c, args.len()) {
            Some(Intrinsic::Sqrt) => give(&args[0], 0.5 / val(&args[0]).sqrt()),
            Some(i) => {
                let s = if i == Intrinsic::Fnma { -1.0 } else { 1.0 };
                give(&args[0], s * val(&args[1]));
                give(&args[1], s * val(&args[0]));
                give(&args[2], if i == Intrinsic::Fms { -1.0 } else { 1.0 });
            }
            None => {}
        },
        Def::Input | Def::Expr(_) => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The binade read from the bits is `⌊log₂|r|⌋` (computed here exactly, by halving and
    /// doubling: powers of two are exact), and the half step is 2^(binade − precision).
    #[test]
    fn binades_and_half_steps_from_the_bits() {
        let floor_log2 = |r: f64| {
            let (mut m, mut e) = (r.abs(), 0i32);
            while m >= 2.0 {
                m /= 2.0;
                e += 1;
            }
            while m < 1.0 {
                m *= 2.0;
                e -= 1;
            }
            e
        };
        let mut rng = robovec_ir::rng::SplitMix64::new(5);
        let mut cases = vec![1.0, 2.0, 3.0, 0.75, f64::MAX, f64::MIN_POSITIVE, 5e-324, 1e-310, -7.5, 2f64.next_down()];
        cases.extend(
            (0..2000).map(|_| f64::from_bits(rng.next_u64() & !(0x7ffu64 << 52) | (rng.below(2046) + 1) << 52)),
        );
        cases.extend((0..200).map(|_| f64::from_bits(rng.next_u64() >> 12)).filter(|x| *x != 0.0));
        for r in cases {
            assert_eq!(binade(r), floor_log2(r), "{r:e}");
            let e = floor_log2(r);
            assert_eq!(half_step(Format::Binary64, r), 2f64.powi(e.max(-1022) - 53), "{r:e}");
            assert_eq!(half_step(Format::Binary32, r), 2f64.powi(e.max(-126) - 24), "{r:e}");
        }
        assert_eq!(half_step(Format::Binary64, 0.0), 2f64.powi(-1022 - 53));
        assert_eq!(half_step(Format::Binary64, f64::INFINITY), f64::INFINITY);
    }
}
