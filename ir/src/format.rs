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
//! - **`fix<w,f>`**: in binary64 on its operands' values, then **stored** ([`Format::store`]).
//!
//! Storing:
//! - **binary64**: as it is; **binary32**: rounded to nearest, ties to even.
//! - **`fix<w,f>`**: a value is `k · 2^-f` with `k` a `w`-bit two's complement integer,
//!   `-2^(w-1) ≤ k < 2^(w-1)`; storing rounds to nearest, **ties toward +∞** (`floor(x · 2^f +
//!   1/2)`: what adding half a step and an arithmetic right shift give in a PE or on a
//!   microcontroller). `add`/`sub` of fixed-point operands are exact in binary64 while the
//!   operands' mantissas and scales fit 53 bits together, and so is `mul` while the product of
//!   the mantissas does (two 26-bit words); past that the binary64 rounding comes first, which
//!   the error bound counts. A result outside the `w` bits is an overflow, never wrapped: the
//!   interpreter stops with the value ([`eval_values`]), and the range proof excludes it.
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
                // checked below on the rounded integer.
                let k = (scale_by(x, fraction) + 0.5).floor();
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
    let store = |v: crate::Value, x: f64| f.format(v).store(x).map_err(|error| FormatError { value: v, result: x, error });
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
            _ => crate::interp::eval_def(def, get),
        };
        vals[v.index()] = store(v, r)?;
    }
    Ok(vals)
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
    fn binary32_rounds_to_nearest_even() {
        let x = 1.0 + 2f64.powi(-24); // halfway between 1 and the next binary32
        assert_eq!(Format::Binary32.store(x), Ok(1.0));
        let y = 1.0 + 3.0 * 2f64.powi(-24); // halfway between 1 + 2^-23 and 1 + 2^-22
        assert_eq!(Format::Binary32.store(y), Ok(1.0 + 2f64.powi(-22)));
        assert_eq!(Format::Binary64.store(0.1), Ok(0.1));
    }
}
