//! Fixed-point PEs (issue 49 item 1): which PEs a function runs on, and the fixed-point side of
//! its machine program ([`FixedProgram`]: the shifts of every op, the fractions of the words).
//!
//! A PE array is of one kind. A function without numeric formats runs on the seed's binary32
//! PEs (`-eval-precision=f32`'s arithmetic). A function whose every value is `fix<w,f>` with
//! `w ≤ 32` ([`FIX_WORD_BITS`], the PE memories' word) and whose every op is an `add`, `sub` or
//! `mul` that is an integer op ([`robovec_ir::format::integer_op`]: exact on the operands'
//! integers, then rounded once) runs on fixed-point PEs: the ADD PE aligns one operand by a
//! constant shift and adds, the MULTI PE multiplies; both round to the result's format
//! ([`FixShifts`]). That is what `precision<target=mcu>` chooses (32-bit words), and what
//! `-eval` computes bit for bit. Anything else (a binary32 value beside fixed-point ones, a
//! word wider than 32 bits, a quotient or root) is refused with the value named: the array has
//! no unit for it.

use robovec_ir::format::{integer_op, Format};
use robovec_ir::machine::{FixShifts, FixedProgram, MachineProgram};
use robovec_ir::{BinOp, Def, Function, Value};

use crate::error::{MachineError, MachineErrorKind};

/// Bits of a fixed-point PE's memory word: the widest `fix<w,f>` a fixed-point PE array holds.
pub const FIX_WORD_BITS: u32 = 32;

/// The kind of PE a function runs on (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeKind {
    /// The seed's binary32 PEs (a function without numeric formats).
    Binary32,
    /// Fixed-point PEs (every value `fix<w ≤ 32, f>`, every op an integer `add`/`sub`/`mul`).
    Fixed,
}

impl PeKind {
    /// `binary32` or `fixed`.
    pub fn as_str(self) -> &'static str {
        match self {
            PeKind::Binary32 => "binary32",
            PeKind::Fixed => "fixed",
        }
    }
}

fn refuse(f: &Function, v: Value, why: &str) -> String {
    format!(
        "@{}: `%{}` ({}) {why}; a PE array is of one kind: binary32 PEs for a function without numeric formats, fixed-point PEs when every value is fix<w,f> with w <= {FIX_WORD_BITS} and every op an integer add, sub, mul or fused multiply-add (precision<target=mcu> chooses such formats)",
        f.name,
        f.name_of(v),
        f.format(v)
    )
}

/// The kind of PE `f` runs on (module doc).
///
/// # Errors
/// The first value that keeps `f` off both kinds, named, with the rule.
pub fn pe_kind(f: &Function) -> Result<PeKind, String> {
    if !f.has_formats() {
        return Ok(PeKind::Binary32);
    }
    for v in f.inputs.iter().chain(&f.body).copied() {
        match f.format(v) {
            Format::Fix { width, .. } if width <= FIX_WORD_BITS => {}
            Format::Fix { .. } => {
                return Err(refuse(f, v, &format!("is wider than the PE word of {FIX_WORD_BITS} bits")))
            }
            _ => return Err(refuse(f, v, "is not fixed point while the function has numeric formats")),
        }
        match &f.value(v).def {
            Def::Input | Def::Trig(..) => {}
            Def::Binary(BinOp::Add | BinOp::Sub | BinOp::Mul, ..) => {
                if integer_op(f, v).is_none() {
                    return Err(refuse(f, v, "is not an integer op (its operands are not all fixed point or constants, or its intermediate is beyond 62 bits)"));
                }
            }
            Def::Call(..) if f.is_fixed_mac(v) => {
                if shifts(f, v).is_none() {
                    return Err(refuse(f, v, "is not an integer op (its operands are not all fixed point or constants, or its intermediate is beyond 62 bits)"));
                }
            }
            _ => {
                return Err(refuse(
                    f,
                    v,
                    "is not an add, sub, mul or fused multiply-add: the fixed-point PEs have no unit for it",
                ))
            }
        }
    }
    Ok(PeKind::Fixed)
}

/// The shifts of fixed-point op `v` ([`FixShifts`]), from its integer op: for `a ± b` the
/// operand aligned to the finer fraction; for a fused multiply-add (`±a·b ± c`, its terms the
/// product and the addend) `align_b` means the addend is aligned to the product's fraction,
/// else the product to the addend's.
///
/// # Panics
/// Never for a function [`pe_kind`] calls fixed.
pub fn shifts(f: &Function, v: Value) -> Option<FixShifts> {
    let op = integer_op(f, v)?;
    let shift = i8::try_from(op.shift).ok()?;
    match op.terms.as_slice() {
        [a, b] => {
            let (la, lb) = (op.fraction - a.fraction(), op.fraction - b.fraction());
            let (align, align_b) = if lb > 0 { (lb, true) } else { (la, false) };
            Some(FixShifts { align: u8::try_from(align).ok()?, align_b, shift })
        }
        [_] => Some(FixShifts { align: 0, align_b: false, shift }),
        _ => None,
    }
}

/// Attaches the fixed-point side to `m`, the program of `f`, when `f` runs on fixed-point PEs
/// (`m.fixed` stays `None` for binary32 PEs).
///
/// # Errors
/// [`MachineErrorKind::Formats`] when `f`'s formats fit neither kind of PE ([`pe_kind`]).
pub fn attach(f: &Function, m: &mut MachineProgram) -> Result<(), MachineError> {
    if pe_kind(f).map_err(|e| MachineError::new(MachineErrorKind::Formats, e))? == PeKind::Binary32 {
        return Ok(());
    }
    let frac = |v: Value| match f.format(v) {
        Format::Fix { fraction, .. } => fraction,
        _ => 0,
    };
    let mut fx = FixedProgram {
        shifts: m.pes.iter().map(|p| vec![None; p.steps.len()]).collect(),
        word_bits: word_bits(f),
        ..FixedProgram::default()
    };
    for &v in &f.inputs {
        fx.inputs.insert(f.name_of(v).to_string(), frac(v));
    }
    for &v in &f.body {
        match &f.value(v).def {
            Def::Trig(t, x) => {
                fx.trig.insert((*t, f.name_of(*x).to_string()), frac(v));
            }
            Def::Binary(..) | Def::Call(..) => {
                let Some((slot, c)) = m.issue_of.get(v.index()).copied().flatten() else { continue };
                let sh = shifts(f, v).ok_or_else(|| {
                    MachineError::new(MachineErrorKind::Formats, format!("no integer op for `%{}`", f.name_of(v)))
                })?;
                fx.shifts[slot][c as usize] = Some(sh);
            }
            _ => {}
        }
    }
    // an output that is a constant is loaded as the constant's word, at its own fraction
    let by_name: std::collections::HashMap<&str, i32> = f
        .outputs
        .iter()
        .map(|o| {
            let fr = match o.value {
                robovec_ir::Operand::Value(v) => frac(v),
                robovec_ir::Operand::Const(c) => robovec_ir::format::fix_constant(c).map_or(0, |(_, f)| f),
            };
            (o.name.as_str(), fr)
        })
        .collect();
    fx.outputs = m.outputs.iter().map(|o| by_name.get(o.name.as_str()).copied().unwrap_or(0)).collect();
    m.fixed = Some(fx);
    Ok(())
}

/// Bits of the data word of `f`'s fixed-point PEs: its widest `fix<w,f>`, or more when a constant
/// operand's or output's word ([`robovec_ir::format::fix_constant`]: up to 32 bits) needs more;
/// at least 2. The PE memories, interconnect and units are this wide (issue 49: a product of
/// words of at most 27 bits takes one Cyclone V DSP block, docs/fpga.md).
pub fn word_bits(f: &Function) -> u32 {
    let constant = |c: f64| robovec_ir::format::fix_constant(c).map_or(FIX_WORD_BITS, |(k, _)| signed_bits(k));
    let values = f.inputs.iter().chain(&f.body).map(|&v| match f.format(v) {
        Format::Fix { width, .. } => width,
        _ => FIX_WORD_BITS,
    });
    let operands = f.body.iter().flat_map(|&v| f.value(v).def.operands()).chain(f.outputs.iter().map(|o| o.value));
    let constants = operands.filter_map(|o| match o {
        robovec_ir::Operand::Const(c) => Some(constant(c)),
        robovec_ir::Operand::Value(_) => None,
    });
    values.chain(constants).fold(2, u32::max).min(FIX_WORD_BITS)
}

/// Bits of `k` in two's complement (the sign bit included): 1 for 0 and −1.
pub fn signed_bits(k: i64) -> u32 {
    let m = if k < 0 { !k } else { k };
    65 - m.leading_zeros()
}

/// The integer word of a loaded value `x` in `fix<·,fraction>`: `⌊x·2^f + ½⌋` computed exactly
/// (what storing rounds to, [`Format::store`]); `None` when it does not fit 32 bits.
pub fn word_of(x: f64, fraction: i32) -> Option<i64> {
    let fmt = Format::fix(FIX_WORD_BITS, fraction)?;
    let stored = fmt.store(x).ok()?;
    fmt.mantissa(stored)
}

/// The value `k · 2^-fraction` of a word (exact: `|k| < 2^32`).
pub fn value_of(k: i64, fraction: i32) -> f64 {
    k as f64 * (-f64::from(fraction)).exp2()
}

/// A constant's word: [`robovec_ir::format::fix_constant`]'s integer.
pub fn constant_word(c: f64) -> Option<i64> {
    robovec_ir::format::fix_constant(c).map(|(k, _)| k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::machine::FixShifts;
    use robovec_ir::text::parse;

    fn func(text: &str) -> Function {
        parse(text).unwrap().functions.remove(0)
    }

    #[test]
    fn a_function_is_binary32_fixed_or_refused_with_the_value_named() {
        let plain = func("func @f { phase atomised input %a input %b %x = mul %a, %b output o = %x }");
        assert_eq!(pe_kind(&plain), Ok(PeKind::Binary32));
        let fixed = func(
            "func @f { phase atomised input %a : fix<32,20> input %b : fix<16,8> %x = mul %a, %b : fix<32,24> %y = sub %x, 0.5 : fix<32,24> output o = %y }",
        );
        assert_eq!(pe_kind(&fixed), Ok(PeKind::Fixed));
        let mixed = func(
            "func @f { phase atomised input %a : fix<32,20> input %b : f32 %x = mul %a, %b : fix<32,24> output o = %x }",
        );
        let e = pe_kind(&mixed).unwrap_err();
        assert!(e.contains("`%b` (f32) is not fixed point"), "{e}");
        let wide = func("func @f { phase atomised input %a : fix<40,20> %x = add %a, %a : fix<32,10> output o = %x }");
        assert!(pe_kind(&wide).unwrap_err().contains("`%a` (fix<40,20>) is wider than the PE word of 32 bits"));
        let quotient =
            func("func @f { phase atomised input %a : fix<32,20> %x = div %a, %a : fix<32,10> output o = %x }");
        assert!(pe_kind(&quotient).unwrap_err().contains("is not an add, sub, mul or fused multiply-add"));
    }

    #[test]
    fn the_shifts_align_the_coarser_operand_and_round_to_the_result() {
        // a: 20 fractional bits, b: 8; the sum is exact at 20 bits: b shifted left by 12; the
        // result at 16 bits: 4 bits rounded off
        let f = func(
            "func @f { phase atomised input %a : fix<32,20> input %b : fix<16,8> %x = add %a, %b : fix<32,16> %y = sub %b, %a : fix<32,22> %z = mul %a, %b : fix<32,24> output o = %x output p = %y output q = %z }",
        );
        let v = |n: &str| f.lookup(n).unwrap();
        assert_eq!(shifts(&f, v("x")), Some(FixShifts { align: 12, align_b: true, shift: 4 }));
        // b − a: b is the coarser, first operand; the result finer than the exact one: shift −2
        assert_eq!(shifts(&f, v("y")), Some(FixShifts { align: 12, align_b: false, shift: -2 }));
        // a · b at 28 bits, stored at 24
        assert_eq!(shifts(&f, v("z")), Some(FixShifts { align: 0, align_b: false, shift: 4 }));
        for s in [shifts(&f, v("x")).unwrap(), shifts(&f, v("y")).unwrap(), shifts(&f, v("z")).unwrap()] {
            assert_eq!(FixShifts::from_word(s.word()), s);
            assert!(s.word() < 1 << FixShifts::BITS);
        }
        // the rounding: to nearest, ties toward +∞, as storing rounds
        let r = FixShifts { align: 0, align_b: false, shift: 2 };
        assert_eq!([r.round(6), r.round(-6), r.round(5), r.round(-5)], [2, -1, 1, -1]);
        assert_eq!(FixShifts { shift: -3, ..r }.round(-5), -40);
    }

    #[test]
    fn words_are_stored_integers() {
        assert_eq!(word_of(0.75, 2), Some(3));
        assert_eq!(word_of(-0.125, 2), Some(0), "−0.5 step rounds toward +∞");
        assert_eq!(word_of(0.125, 2), Some(1));
        assert_eq!(word_of(2.0f64.powi(31), 0), None);
        assert_eq!(constant_word(0.5), Some(1));
        assert_eq!(constant_word(-3.0), Some(-3));
    }
}
