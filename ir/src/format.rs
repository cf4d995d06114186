//! Numeric formats of values (issue 48 item 4): binary64 (the default of every value), binary32,
//! and signed fixed point `fix<w,f>`. A function's values carry one each
//! ([`crate::Function::format`]); the text form writes it after the definition
//! (`%x = mul %a, %b : fix<32,20>`, `input %q[1] : f32`), binary64 not written.
//!
//! # Semantics (what `-eval` computes and the back ends must reproduce bit for bit)
//! Every value of every format is a binary64 number (binary32 widens exactly; `fix<w,f>` has
//! `w ≤ 53`). An op **computes in its value's format**:
//! - **binary64**: in binary64 on its operands' values (IEEE 754, round to nearest even; `sin`,
//!   `cos`, `sqrt` and calls as the binary64 functions).
//! - **binary32**: every operand is first rounded to binary32 (a constant too, as a C `float`
//!   literal; a binary64 or fixed-point operand to nearest even), then the op is the IEEE
//!   binary32 operation: `+ - * /`, `sqrt` and the fused ops rounded once in binary32 (`fmaf`),
//!   `sin`/`cos` the C library's `sinf`/`cosf`, a callback in binary64 on the rounded operands
//!   then rounded ([`binary32_op`]). That is C's `float` arithmetic exactly: `float x = a * b;`
//!   with `float` operands, so a function whose values are all binary32 computes what
//!   `-eval-precision=f32` and `codegen<c;precision=f32>` compute, and `codegen<c>` writes
//!   binary32 values as `float` vectors (twice the lanes of `double`).
//! - **`fix<w,f>`**, an **integer op** ([`integer_op`]): `add`, `sub`, `mul`, `fma`, `fms` and
//!   `fnma` whose operands are all fixed-point values or constants (one value at least), and
//!   whose exact intermediate fits [`INTEGER_BITS`]: computed **exactly** on the operands'
//!   mantissas (two's complement integers, aligned by shifts), then rounded once to the value's
//!   format as storing rounds. A constant is first read as a 32-bit fixed-point word
//!   ([`fix_constant`]: 32 significant bits, `0.1` as `858993459 · 2^-33`; `0.5`, `3` exactly).
//!   What an MCU's `int32_t`/`int64_t` code and a PE compute: `codegen<c>` writes it so.
//! - **`fix<w,f>`**, any other op (`/`, `sqrt`, `sin`, `cos`, a callback, or an operand in a
//!   binary format): in binary64 on its operands' values, then **stored** ([`Format::store`]).
//!
//! Storing:
//! - **binary64**: as it is; **binary32**: rounded to nearest, ties to even.
//! - **`fix<w,f>`**: a value is `k · 2^-f` with `k` a `w`-bit two's complement integer,
//!   `-2^(w-1) ≤ k < 2^(w-1)`; storing rounds to nearest, **ties toward +∞** (`k = ⌊x · 2^f +
//!   1/2⌋`, computed without rounding the half step in: what adding half a step and an
//!   arithmetic right shift give in a PE or on a microcontroller). A result outside the `w`
//!   bits is an overflow, never wrapped: the interpreter stops with the value
//!   ([`eval_values`]), and the range proof excludes it.
//!
//! Sources: the Q format of fixed-point DSP practice (Texas Instruments' `Qm.n`, here written
//! by total width and fractional bits as Daisy and RoboPrec write `Fixed(w, f)`); IEEE 754-2019
//! for the binary formats.

use std::fmt;

/// Largest width of a fixed-point format, bits: every value is a binary64 number (a 32-bit
/// microcontroller word, the 18- and 27-bit DSP operands of ECP5 and Cyclone V fit).
pub const FIX_MAX_WIDTH: u32 = 53;
/// Range of the fractional bits of a fixed-point format (negative: a scale `2^|f|` per step).
pub const FIX_FRACTION_RANGE: std::ops::RangeInclusive<i32> = -64..=126;

/// The numeric format of one value (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Format {
    /// IEEE 754 binary64 (`double`): every value's default.
    #[default]
    Binary64,
    /// IEEE 754 binary32 (`float`).
    Binary32,
    /// Signed fixed point: `width` bits two's complement, `fraction` fractional bits.
    Fix {
        /// Total bits, sign included (1 ..= [`FIX_MAX_WIDTH`]).
        width: u32,
        /// Fractional bits ([`FIX_FRACTION_RANGE`]).
        fraction: i32,
    },
}

/// Why a fixed-point result cannot be stored (see [`Format::store`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StoreError {
    /// The rounded value needs more than the format's bits.
    Overflow,
    /// The value is not finite (a fixed-point format has no infinity or NaN).
    NotFinite,
}

impl Format {
    /// A fixed-point format, checked: `None` outside the widths and fractions above.
    pub fn fix(width: u32, fraction: i32) -> Option<Format> {
        ((1..=FIX_MAX_WIDTH).contains(&width) && FIX_FRACTION_RANGE.contains(&fraction))
            .then_some(Format::Fix { width, fraction })
    }

    /// The step between two neighbouring values of a fixed-point format, `2^-f` (`None` for the
    /// binary formats, whose step depends on the value).
    pub fn fix_step(&self) -> Option<f64> {
        match *self {
            Format::Fix { fraction, .. } => Some(2f64.powi(-fraction)),
            _ => None,
        }
    }

    /// The closed interval of a fixed-point format's values, `[-2^(w-1), 2^(w-1) - 1] · 2^-f`
    /// (`None` for the binary formats).
    pub fn fix_range(&self) -> Option<(f64, f64)> {
        match *self {
            Format::Fix { width, fraction } => {
                let scale = 2f64.powi(-fraction);
                let top = 2f64.powi(width as i32 - 1);
                Some((-top * scale, (top - 1.0) * scale))
            }
            _ => None,
        }
    }

    /// `x` stored in this format (module doc): binary64 as it is, binary32 rounded to nearest
    /// even, fixed point rounded to nearest with ties toward +∞.
    ///
    /// # Errors
    /// For a fixed-point format, [`StoreError::NotFinite`] or [`StoreError::Overflow`].
    pub fn store(&self, x: f64) -> Result<f64, StoreError> {
        match *self {
            Format::Binary64 => Ok(x),
            Format::Binary32 => Ok(x as f32 as f64),
            Format::Fix { width, fraction } => {
                if !x.is_finite() {
                    return Err(StoreError::NotFinite);
                }
                // x · 2^f is exact (a power of two) unless it overflows or underflows, which
                // only a value far outside any width (or far below the step) reaches: both are
                // checked below on the rounded integer. `y − ⌊y⌋` is exact, so the tie test is
                // (`⌊y + 1/2⌋` in binary64 would round 0.5 − 2⁻⁶⁰ + 1/2 up to 1).
                let y = scale_by(x, fraction);
                let k = y.floor() + if y - y.floor() >= 0.5 { 1.0 } else { 0.0 };
                let top = 2f64.powi(width as i32 - 1);
                if k < -top || k >= top {
                    return Err(StoreError::Overflow);
                }
                Ok(scale_by(k, -fraction))
            }
        }
    }

    /// The mantissa `k` of a value `x` of this fixed-point format (`x = k · 2^-f`); `None` for
    /// a binary format or a value not of the format.
    pub fn mantissa(&self, x: f64) -> Option<i64> {
        let Format::Fix { width, fraction } = *self else { return None };
        let k = scale_by(x, fraction);
        let top = 2f64.powi(width as i32 - 1);
        (k.fract() == 0.0 && k >= -top && k < top).then_some(k as i64)
    }

    /// True for the default, binary64.
    pub fn is_default(&self) -> bool {
        *self == Format::Binary64
    }
}

/// `x · 2^e`, exact while the result is normal (a product by a power of two).
fn scale_by(x: f64, e: i32) -> f64 {
    // Two steps keep 2^e finite for |e| up to 2 × 1023.
    let half = e / 2;
    x * 2f64.powi(half) * 2f64.powi(e - half)
}

impl fmt::Display for Format {
    /// `f64`, `f32`, `fix<32,20>`: the text form's spelling.
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Format::Binary64 => out.write_str("f64"),
            Format::Binary32 => out.write_str("f32"),
            Format::Fix { width, fraction } => write!(out, "fix<{width},{fraction}>"),
        }
    }
}

impl std::str::FromStr for Format {
    type Err = String;

    /// Reads [`Format`]'s `Display` spelling back.
    fn from_str(s: &str) -> Result<Format, String> {
        match s {
            "f64" => return Ok(Format::Binary64),
            "f32" => return Ok(Format::Binary32),
            _ => {}
        }
        let bad = || {
            format!(
                "`{s}` is not a format: expected f64, f32 or fix<W,F> (W in 1..={FIX_MAX_WIDTH} bits, F in {}..={} fractional bits)",
                FIX_FRACTION_RANGE.start(),
                FIX_FRACTION_RANGE.end()
            )
        };
        let inner = s.strip_prefix("fix<").and_then(|r| r.strip_suffix('>')).ok_or_else(bad)?;
        let (w, f) = inner.split_once(',').ok_or_else(bad)?;
        let (w, f) = (w.trim().parse::<u32>().map_err(|_| bad())?, f.trim().parse::<i32>().map_err(|_| bad())?);
        Format::fix(w, f).ok_or_else(bad)
    }
}

/// A value whose result does not fit its format: where [`eval_values`] stopped.
#[derive(Clone, Debug, PartialEq)]
pub struct FormatError {
    /// The value.
    pub value: crate::Value,
    /// Its binary64 result before storing.
    pub result: f64,
    /// Why it cannot be stored.
    pub error: StoreError,
}

/// The values of every value of `f` (indexed by `Value::index()`) computed in their formats
/// (module doc): inputs given by `input(name)` in binary64 and stored in their formats; a
/// binary32 value's op in binary32 on its operands rounded to binary32 ([`binary32_op`]);
/// every other op in binary64 on its operands' values, then stored. A function without
/// formats gives exactly [`crate::interp::eval_values`]`::<f64>`.
///
/// # Errors
/// The first value in program order whose result a fixed-point format cannot hold.
pub fn eval_values(f: &crate::Function, mut input: impl FnMut(&str) -> f64) -> Result<Vec<f64>, FormatError> {
    let mut vals = vec![f64::NAN; f.values.len()];
    let store =
        |v: crate::Value, x: f64| f.format(v).store(x).map_err(|error| FormatError { value: v, result: x, error });
    for &v in &f.inputs {
        vals[v.index()] = store(v, input(f.name_of(v)))?;
    }
    for &v in &f.body {
        let def = &f.value(v).def;
        let get = |o: &crate::Operand| match *o {
            crate::Operand::Value(x) => vals[x.index()],
            crate::Operand::Const(c) => c,
        };
        let r = match f.format(v) {
            Format::Binary32 => binary32_op(def, get),
            Format::Fix { width, fraction } => match integer_op(f, v) {
                Some(op) => {
                    let k = op.eval(|w| vals[w.index()]);
                    let top = 1i128 << (width - 1);
                    if k < -top || k >= top {
                        let result = scale_by(k as f64, -fraction);
                        return Err(FormatError { value: v, result, error: StoreError::Overflow });
                    }
                    vals[v.index()] = scale_by(k as f64, -fraction);
                    continue;
                }
                None => crate::interp::eval_def(def, get),
            },
            _ => crate::interp::eval_def(def, get),
        };
        vals[v.index()] = store(v, r)?;
    }
    Ok(vals)
}

/// The largest magnitude, in bits, of an [`integer_op`]'s exact intermediate (every term
/// aligned, their sum, or the result shifted left): `|K| ≤ 2^62`, so with a shift of at most
/// 62 the rounding's half step keeps it in a C `int64_t` (`2^62 + 2^61 < 2^63`): the product
/// of two 32-bit words, `2^31 · 2^31`, is one.
pub const INTEGER_BITS: u32 = 62;

/// Width of the word a constant operand of an integer op is read as, bits ([`fix_constant`]).
pub const CONSTANT_WIDTH: u32 = 32;

/// A constant as an integer op reads it (module doc): the 32-bit fixed-point word nearest to
/// it (ties toward +∞), with the most fractional bits that keep it in 32 bits, then trailing
/// zero bits removed: `(k, f)` with `c ≈ k · 2^-f`, `|k| ≤ 2^31` (`0.1` → `(858993459, 33)`,
/// `0.5` → `(1, 1)`, `-3` → `(-3, 0)`, `0` → `(0, 0)`). `None` for a constant no 32-bit
/// word holds (above `2^95`) or not finite. The fraction stays in [`FIX_FRACTION_RANGE`], so a
/// constant below `2^-127` reads as 0 (its whole value is the conversion error, which the error
/// bound counts).
pub fn fix_constant(c: f64) -> Option<(i64, i32)> {
    if !c.is_finite() {
        return None;
    }
    if c == 0.0 {
        return Some((0, 0));
    }
    // |c| = m · 2^e with m in [0.5, 1): c · 2^(31 − e) has magnitude in [2^30, 2^31).
    let e = c.abs().log2().floor() as i32 + 1;
    let (lo, hi) = (*FIX_FRACTION_RANGE.start(), *FIX_FRACTION_RANGE.end());
    let start = (CONSTANT_WIDTH as i32 - 1 - e + 1).clamp(lo, hi);
    let word = (lo..=start).rev().find_map(|f| {
        let fmt = Format::Fix { width: CONSTANT_WIDTH, fraction: f };
        fmt.store(c).ok().map(|x| (scale_by(x, f) as i64, f))
    })?;
    let (mut k, mut f) = word;
    while k != 0 && k % 2 == 0 && f > lo {
        k /= 2;
        f -= 1;
    }
    if k == 0 {
        f = 0;
    }
    Some((k, f))
}

/// One factor of an [`IntegerOp`]'s term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntFactor {
    /// A fixed-point value: its mantissa `k` at its format's `fraction` (`k · 2^-fraction`).
    Value {
        /// The value.
        value: crate::Value,
        /// Its format's fractional bits.
        fraction: i32,
        /// Its format's width, bits.
        width: u32,
    },
    /// A constant read as a 32-bit word ([`fix_constant`]): `mantissa · 2^-fraction`.
    Const {
        /// The word's integer.
        mantissa: i64,
        /// Its fractional bits.
        fraction: i32,
    },
}

impl IntFactor {
    /// The factor's fractional bits.
    pub fn fraction(&self) -> i32 {
        match *self {
            IntFactor::Value { fraction, .. } | IntFactor::Const { fraction, .. } => fraction,
        }
    }

    /// `b` with `|mantissa| ≤ 2^b` (a `fix<w,f>` value: `w − 1`; a constant: ⌈log2 |k|⌉).
    pub fn bits(&self) -> u32 {
        match *self {
            IntFactor::Value { width, .. } => width - 1,
            IntFactor::Const { mantissa, .. } => 64 - (mantissa.unsigned_abs().max(1) - 1).leading_zeros(),
        }
    }
}

/// One term of an [`IntegerOp`]: `±` the product of its factors (one or two).
#[derive(Clone, Debug, PartialEq)]
pub struct IntTerm {
    /// Subtracted instead of added.
    pub negative: bool,
    /// The factors (one, or two for a product).
    pub factors: Vec<IntFactor>,
}

impl IntTerm {
    /// The product's fractional bits (the sum of the factors').
    pub fn fraction(&self) -> i32 {
        self.factors.iter().map(IntFactor::fraction).sum()
    }

    /// `b` with `|product| ≤ 2^b`.
    pub fn bits(&self) -> u32 {
        self.factors.iter().map(IntFactor::bits).sum()
    }
}

/// A fixed-point value's op computed exactly on integers (module doc): the exact result is
/// `K · 2^-fraction` with `K = Σ ±term · 2^(fraction − term's fraction)`, then rounded to the
/// value's format `fix<w,f>` by `shift = fraction − f` bits (`⌊(K + 2^(shift−1)) / 2^shift⌋`
/// when `shift > 0`, `K · 2^-shift` otherwise).
#[derive(Clone, Debug, PartialEq)]
pub struct IntegerOp {
    /// The terms (two for `add`, `sub` and the fused ops, one for `mul`).
    pub terms: Vec<IntTerm>,
    /// Fractional bits of the exact result: the finest term's.
    pub fraction: i32,
    /// `fraction − f`: bits the rounding removes (added when negative).
    pub shift: i32,
    /// `b` bounding the intermediate: `|K| ≤ 2^b`, and `|K · 2^-shift| ≤ 2^b` when `shift ≤ 0`
    /// (at most [`INTEGER_BITS`]; with `shift > 0` the rounding adds `2^(shift−1)`, at most 2^61).
    pub bits: u32,
}

impl IntegerOp {
    /// The rounded mantissa of the result (before the overflow check), from the operands'
    /// values `get` gives (each on its format's grid). Exact: `i128` holds every intermediate.
    pub fn eval(&self, get: impl Fn(crate::Value) -> f64) -> i128 {
        let mut k: i128 = 0;
        for t in &self.terms {
            let mut p: i128 = 1;
            for x in &t.factors {
                p *= match *x {
                    IntFactor::Value { value, fraction, .. } => scale_by(get(value), fraction) as i128,
                    IntFactor::Const { mantissa, .. } => mantissa as i128,
                };
            }
            p <<= self.fraction - t.fraction();
            k += if t.negative { -p } else { p };
        }
        match self.shift {
            s if s > 0 => (k + (1i128 << (s - 1))) >> s,
            s => k << -s,
        }
    }
}

/// The integer op of `v` when its value is fixed point and its op is one (module doc: `add`,
/// `sub`, `mul`, `fma`, `fms`, `fnma` on fixed-point values and constants, one value at least,
/// the intermediate within [`INTEGER_BITS`] and the shift below 63); `None` otherwise (the op
/// computes in binary64, then stores).
pub fn integer_op(f: &crate::Function, v: crate::Value) -> Option<IntegerOp> {
    use crate::{BinOp, Def, Intrinsic, Operand};
    let Format::Fix { fraction: f_out, .. } = f.format(v) else { return None };
    let factor = |o: &Operand| -> Option<IntFactor> {
        match *o {
            Operand::Value(w) => match f.format(w) {
                Format::Fix { width, fraction } => Some(IntFactor::Value { value: w, fraction, width }),
                _ => None,
            },
            Operand::Const(c) => fix_constant(c).map(|(mantissa, fraction)| IntFactor::Const { mantissa, fraction }),
        }
    };
    let term = |negative: bool, os: &[&Operand]| -> Option<IntTerm> {
        Some(IntTerm { negative, factors: os.iter().map(|o| factor(o)).collect::<Option<Vec<_>>>()? })
    };
    let (terms, operands): (Vec<IntTerm>, Vec<&Operand>) = match &f.value(v).def {
        Def::Binary(BinOp::Add, a, b) => (vec![term(false, &[a])?, term(false, &[b])?], vec![a, b]),
        Def::Binary(BinOp::Sub, a, b) => (vec![term(false, &[a])?, term(true, &[b])?], vec![a, b]),
        Def::Binary(BinOp::Mul, a, b) => (vec![term(false, &[a, b])?], vec![a, b]),
        Def::Call(c, args) => {
            let (a, b, cc) = match args.as_slice() {
                [a, b, c] => (a, b, c),
                _ => return None,
            };
            let (neg_product, neg_addend) = match Intrinsic::of(c, args.len())? {
                Intrinsic::Fma => (false, false),
                Intrinsic::Fms => (false, true),
                Intrinsic::Fnma => (true, false),
                Intrinsic::Sqrt => return None,
            };
            (vec![term(neg_product, &[a, b])?, term(neg_addend, &[cc])?], vec![a, b, cc])
        }
        _ => return None,
    };
    if !operands.iter().any(|o| matches!(o, Operand::Value(_))) {
        return None;
    }
    let fraction = terms.iter().map(IntTerm::fraction).max()?;
    let aligned = terms.iter().map(|t| t.bits() as i64 + (fraction - t.fraction()) as i64).max()?;
    // The sum of two terms: one bit more.
    let sum = aligned + (terms.len() as i64 - 1);
    let shift = fraction - f_out;
    // Rounding multiplies by 2^-shift (shift ≤ 0) or adds half a step (shift > 0), which
    // `|K| ≤ 2^62` and a shift ≤ 62 keep below 2^63: 2^62 + 2^61.
    let bits = if shift > 0 { sum } else { sum - shift as i64 };
    (bits <= INTEGER_BITS as i64 && (-62..=62).contains(&shift)).then_some(IntegerOp {
        terms,
        fraction,
        shift,
        bits: bits as u32,
    })
}

/// The op `def` of a binary32 value, on operands `get` gives in binary64 (module doc): each
/// operand (constants included) rounded to binary32, then `+ - * /`, `sqrt`, the fused ops,
/// `sin` and `cos` as IEEE binary32 operations and the C library's `sinf`/`cosf` (what C's
/// `float` arithmetic computes), a callback in binary64 on the rounded operands; the result
/// rounded to binary32, widened exactly.
pub fn binary32_op(def: &crate::Def, get: impl Fn(&crate::Operand) -> f64) -> f64 {
    let narrow = |o: &crate::Operand| get(o) as f32;
    match def {
        crate::Def::Call(c, args) if crate::intrinsic::Intrinsic::of(c, args.len()).is_none() => {
            let a: Vec<f64> = args.iter().map(|o| narrow(o) as f64).collect();
            crate::interp::eval_call(c, &a) as f32 as f64
        }
        _ => crate::interp::eval_def::<f32>(def, narrow) as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spelling_reads_back_and_bad_ones_say_what_is_expected() {
        for f in [Format::Binary64, Format::Binary32, Format::fix(32, 20).unwrap(), Format::fix(8, -3).unwrap()] {
            assert_eq!(f.to_string().parse::<Format>(), Ok(f));
        }
        for bad in ["f16", "fix<54,3>", "fix<0,1>", "fix<32,200>", "fix<32>", "fix<a,b>", "fix32,3"] {
            let e = bad.parse::<Format>().unwrap_err();
            assert!(e.contains("expected f64, f32 or fix<W,F>"), "{bad}: {e}");
        }
    }

    #[test]
    fn fixed_point_rounds_to_nearest_with_ties_up_and_refuses_overflow() {
        let q = Format::fix(8, 2).unwrap(); // steps of 0.25, values -32 ..= 31.75
        assert_eq!(q.fix_range(), Some((-32.0, 31.75)));
        assert_eq!(q.store(1.1), Ok(1.0));
        assert_eq!(q.store(1.125), Ok(1.25), "a tie rounds up");
        // Just below a tie: ⌊y + 1/2⌋ in binary64 would round y + 1/2 = 1 − 2^-54 up to 1.
        let fine = Format::fix(8, 0).unwrap();
        assert_eq!(fine.store(0.5f64.next_down()), Ok(0.0));
        assert_eq!(q.store(-1.125), Ok(-1.0), "a tie rounds toward +inf");
        assert_eq!(q.store(-1.2), Ok(-1.25));
        assert_eq!(q.store(31.75), Ok(31.75));
        assert_eq!(q.store(31.875), Err(StoreError::Overflow), "rounds to 32, one step past the top");
        assert_eq!(q.store(-32.0), Ok(-32.0));
        assert_eq!(q.store(-32.2), Err(StoreError::Overflow));
        assert_eq!(q.store(f64::NAN), Err(StoreError::NotFinite));
        assert_eq!(q.mantissa(-1.25), Some(-5));
        assert_eq!(q.mantissa(0.1), None);
        // A negative fraction: steps of 8.
        let coarse = Format::fix(4, -3).unwrap();
        assert_eq!((coarse.store(13.0), coarse.store(11.9)), (Ok(16.0), Ok(8.0)));
        assert_eq!(coarse.fix_range(), Some((-64.0, 56.0)));
    }

    #[test]
    fn constants_read_as_32_bit_words() {
        // 0.1 · 2^34 = 1717986918.4 → 1717986918 = 2 · 858993459 (odd).
        assert_eq!(fix_constant(0.1), Some((858_993_459, 33)));
        // 0.03 · 2^36 = 2061584302.08 → 2061584302 = 2 · 1030792151.
        assert_eq!(fix_constant(0.03), Some((1_030_792_151, 35)));
        assert_eq!(fix_constant(0.5), Some((1, 1)));
        assert_eq!(fix_constant(-3.0), Some((-3, 0)));
        assert_eq!(fix_constant(-1.0), Some((-1, 0)), "-2^31 · 2^-31 fits the word");
        assert_eq!(fix_constant(0.0), Some((0, 0)));
        assert_eq!(fix_constant(1e-40), Some((0, 0)), "below 2^-127: read as 0");
        assert_eq!(fix_constant(2f64.powi(94)), Some((1 << 30, -64)), "the coarsest word");
        assert_eq!(fix_constant(2f64.powi(100)), None, "no 32-bit word holds it");
        assert_eq!(fix_constant(f64::INFINITY), None);
        // 1 − 2^-40 rounds up to 2^31 · 2^-31 at 31 fractional bits, one past the word: 30 bits.
        assert_eq!(fix_constant(1.0 - 2f64.powi(-40)), Some((1, 0)));
    }

    /// The op of value `name` in `src` (an atomised function).
    fn op_of(src: &str, name: &str) -> (crate::Function, Option<IntegerOp>) {
        let f = crate::text::parse(src).expect("parses").functions.remove(0);
        let v = f.inputs.iter().chain(&f.body).copied().find(|&v| f.name_of(v) == name).expect("named");
        let op = integer_op(&f, v);
        (f, op)
    }

    #[test]
    fn an_integer_op_is_exact_before_its_one_rounding() {
        // a = 2^27 + 3, b = 2^27 + 1: a·b = 2^54 + 2^29 + 3 (≡ 3 mod 8), stored with steps of 8:
        // exactly 2^51 + 2^26 + 0.375 steps → 2^54 + 2^29. In binary64 the product would round
        // to 2^54 + 2^29 + 4 (ulp 4), a tie at 2^51 + 2^26 + 0.5 steps, rounded up: + 8.
        let src = "func @f { phase atomised input %a : fix<29,0> input %b : fix<29,0> \
                   %p = mul %a, %b : fix<53,-3> output y = %p }";
        let (f, op) = op_of(src, "p");
        let op = op.expect("an integer op");
        assert_eq!((op.fraction, op.shift, op.bits), (0, 3, 56), "28 + 28 bits");
        let (a, b) = (2f64.powi(27) + 3.0, 2f64.powi(27) + 1.0);
        let vals = eval_values(&f, |n| if n == "a" { a } else { b }).unwrap();
        let p = vals[f.body[0].index()];
        assert_eq!(p, 2f64.powi(54) + 2f64.powi(29));
        let binary64 = Format::fix(53, -3).unwrap().store(a * b).unwrap();
        assert_eq!(binary64, p + 8.0, "the case tells the two semantics apart");
    }

    #[test]
    fn integer_ops_align_round_toward_plus_infinity_and_read_constant_words() {
        // a = 1.3 → fix<8,2>: 5.2 → 5 (1.25); b = -0.7 → fix<8,3>: -5.6 → -6 (-0.75).
        // p = a·b = -30 · 2^-5 exactly; to fix<8,1>: (-30 + 8) >> 4 = floor(-1.375) = -2 → -1.0.
        // s = p − 0.1: 0.1 is 858993459 · 2^-33; -1 − 0.1000000000931 = -1.1000000000931,
        //   · 2^6 = -70.40000000596 → -70 → -1.09375.
        // t = fnma(a, b, 0.75) = -(a·b) + 0.75 = 0.9375 + 0.75 = 1.6875 exactly, to fix<6,2>:
        //   6.75 steps → 7 → 1.75; u = fms(a, a, 2.0) = 1.5625 − 2 = -0.4375 → fix<6,3>: -3.5
        //   steps, a tie, toward +∞: -3 → -0.375.
        let src = "func @f { phase atomised input %a : fix<8,2> input %b : fix<8,3> \
                   %p = mul %a, %b : fix<8,1> %s = sub %p, 0.1 : fix<12,6> \
                   %t = call @fnma(%a, %b, 0.75) : fix<6,2> %u = call @fms(%a, %a, 2.0) : fix<6,3> \
                   output p = %p output s = %s output t = %t output u = %u }";
        let f = crate::text::parse(src).expect("parses").functions.remove(0);
        for &v in &f.body {
            assert!(integer_op(&f, v).is_some(), "{}", f.name_of(v));
        }
        let vals = eval_values(&f, |n| if n == "a" { 1.3 } else { -0.7 }).unwrap();
        let got: Vec<f64> = f.body.iter().map(|v| vals[v.index()]).collect();
        assert_eq!(got, [-1.0, -1.09375, 1.75, -0.375]);
    }

    #[test]
    fn other_ops_and_wide_intermediates_compute_in_binary64() {
        let head = "func @f { phase atomised input %a : fix<40,10> input %b : fix<40,10> input %c : f32";
        for (def, why) in [
            ("div %a, %b : fix<40,10>", "a quotient"),
            ("mul %a, %c : fix<40,10>", "a binary32 operand"),
            ("mul %a, %b : fix<53,20>", "39 + 39 bits, past 62"),
            ("call @fma(%a, %b, %a) : fix<53,20>", "past 62"),
            ("add %a, %b : f64", "a binary64 value"),
        ] {
            let (_, op) = op_of(&format!("{head} %x = {def} output y = %x }}"), "x");
            assert!(op.is_none(), "{why}");
        }
        let (_, op) = op_of(&format!("{head} %x = add %a, %b : fix<41,10> output y = %x }}"), "x");
        assert_eq!(op.map(|o| (o.shift, o.bits)), Some((0, 40)), "39 bits and a carry");
        // Two 32-bit words: |k_a · k_b| ≤ 2^31 · 2^31 = 2^62, the widest product kept.
        let words = "func @f { phase atomised input %a : fix<32,29> input %b : fix<32,20>";
        let (_, op) = op_of(&format!("{words} %x = mul %a, %b : fix<32,16> output y = %x }}"), "x");
        assert_eq!(op.map(|o| (o.shift, o.bits)), Some((33, 62)));
        let (_, op) = op_of(&format!("{words} %x = call @fma(%a, %b, %b) : fix<32,16> output y = %x }}"), "x");
        assert!(op.is_none(), "a product of two words and a sum: 63 bits");
    }

    #[test]
    fn binary32_rounds_to_nearest_even() {
        let x = 1.0 + 2f64.powi(-24); // halfway between 1 and the next binary32
        assert_eq!(Format::Binary32.store(x), Ok(1.0));
        let y = 1.0 + 3.0 * 2f64.powi(-24); // halfway between 1 + 2^-23 and 1 + 2^-22
        assert_eq!(Format::Binary32.store(y), Ok(1.0 + 2f64.powi(-22)));
        assert_eq!(Format::Binary64.store(0.1), Ok(0.1));
    }
}

/// Integer ops against exact arithmetic computed independently: the operands' values and the
/// constants' words as 512-bit floats (exact: every intermediate has fewer bits), the exact
/// result, then `⌊x · 2^f + 1/2⌋` there.
#[cfg(test)]
mod exact {
    use super::*;
    use astro_float::{BigFloat, RoundingMode};
    use proptest::prelude::*;

    const P: usize = 512;
    const RM: RoundingMode = RoundingMode::ToEven;

    fn big(x: f64) -> BigFloat {
        crate::numerics::big::from_f64(x, P)
    }

    /// `value` as an integer op reads it, exactly: a fixed-point operand's value as it is, a
    /// constant as its 32-bit word ([`fix_constant`], checked by hand above).
    fn read(value: f64, constant: bool) -> BigFloat {
        if constant {
            let (k, f) = fix_constant(value).expect("a word");
            big(k as f64).mul(&big(2f64.powi(-f)), P, RM)
        } else {
            big(value)
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2000, max_global_rejects: 100_000, ..ProptestConfig::default() })]
        #[test]
        fn integer_ops_round_the_exact_result_once(
            op in 0usize..6,
            widths in prop::array::uniform3(2u32..=34),
            fractions in prop::array::uniform3(-8i32..=50),
            units in prop::array::uniform3(-1.0f64..1.0),
            constant in prop::option::of((0usize..3, 0.0f64..100.0)),
            out in (2u32..=53, -8i32..=60),
        ) {
            // The operands: a k · 2^-f of each format (k uniform in its width), or a constant.
            let vals: Vec<f64> = (0..3).map(|i| {
                let top = 2f64.powi(widths[i] as i32 - 1);
                let k = (units[i] * top).floor().clamp(-top, top - 1.0);
                k * 2f64.powi(-fractions[i])
            }).collect();
            let text = |i: usize| match constant {
                Some((j, c)) if j == i => format!("{c:?}"),
                _ => ["%a", "%b", "%c"][i].to_string(),
            };
            let value = |i: usize| match constant {
                Some((j, c)) if j == i => read(c, true),
                _ => read(vals[i], false),
            };
            let (def, exact) = match op {
                0 => (format!("add {}, {}", text(0), text(1)), value(0).add(&value(1), P, RM)),
                1 => (format!("sub {}, {}", text(0), text(1)), value(0).sub(&value(1), P, RM)),
                2 => (format!("mul {}, {}", text(0), text(1)), value(0).mul(&value(1), P, RM)),
                k => {
                    let ab = value(0).mul(&value(1), P, RM);
                    let name = ["fma", "fms", "fnma"][k - 3];
                    let x = match k {
                        3 => ab.add(&value(2), P, RM),
                        4 => ab.sub(&value(2), P, RM),
                        _ => value(2).sub(&ab, P, RM),
                    };
                    (format!("call @{name}({}, {}, {})", text(0), text(1), text(2)), x)
                }
            };
            let src = format!(
                "func @f {{ phase atomised input %a : fix<{},{}> input %b : fix<{},{}> input %c : fix<{},{}> \
                 %x = {def} : fix<{},{}> output y = %x }}",
                widths[0], fractions[0], widths[1], fractions[1], widths[2], fractions[2], out.0, out.1
            );
            let f = crate::text::parse(&src).expect("parses").functions.remove(0);
            let x = f.body[0];
            prop_assume!(integer_op(&f, x).is_some());
            // The expected integer: ⌊exact · 2^f + 1/2⌋, exactly.
            let scaled = exact.mul(&big(2f64.powi(out.1)), P, RM).add(&big(0.5), P, RM).floor();
            let top = 2f64.powi(out.0 as i32 - 1);
            let fits = scaled.cmp(&big(-top)).is_some_and(|c| c >= 0) && scaled.cmp(&big(top)).is_some_and(|c| c < 0);
            let names = ["a", "b", "c"];
            match eval_values(&f, |n| vals[names.iter().position(|m| *m == n).unwrap()]) {
                Ok(v) => {
                    prop_assert!(fits, "{src}: -eval gives {} but the exact result overflows", v[x.index()]);
                    let got = big(v[x.index()]).mul(&big(2f64.powi(out.1)), P, RM);
                    prop_assert_eq!(got.cmp(&scaled), Some(0), "{}: -eval {} at {:?}", src, v[x.index()], vals);
                }
                Err(e) => prop_assert!(!fits && e.error == StoreError::Overflow, "{src}: {e:?}"),
            }
        }
    }
}
