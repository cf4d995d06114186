//! Numeric literals that round-trip exactly: C99 hexadecimal floating constants.
//!
//! `0x1.8p+1` is exactly 3; every finite `f64` has one, and a binary32 value (widened to
//! `f64` exactly) written with the `f` suffix is that `float`. Decimal `%.17g` would also
//! round-trip in `f64`, but hex cannot be mis-rounded by any conforming compiler.

/// The C hex literal of `x` (finite): `0x1.8p+1`, `-0x1p-3`, `0x0p+0`, `-0x0p+0`; subnormals
/// as `0x0.…p-1022`. `float_suffix` appends `f` (the value must then be exact in binary32,
/// which holds for any `f32` widened to `f64`).
///
/// # Panics
/// When `x` is not finite (IR constants are finite: the verifier checks it).
pub fn hex(x: f64, float_suffix: bool) -> String {
    assert!(x.is_finite(), "IR constants are finite, got {x}");
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { "-" } else { "" };
    let exp = ((bits >> 52) & 0x7ff) as i64;
    let mant = bits & ((1u64 << 52) - 1);
    let (lead, e) = match exp {
        0 if mant == 0 => (0, 0),
        0 => (0, -1022),
        _ => (1, exp - 1023),
    };
    let mut frac = format!("{mant:013x}");
    while frac.ends_with('0') {
        frac.pop();
    }
    let dot = if frac.is_empty() { String::new() } else { format!(".{frac}") };
    let suffix = if float_suffix { "f" } else { "" };
    format!("{sign}0x{lead}{dot}p{e:+}{suffix}")
}

/// A constant as a C operand in the back end's precision: [`hex`] of `x` (with `f32`, of `x`
/// rounded to binary32, as the interpreter rounds it, with the `f` suffix), parenthesised when
/// negative so that it can follow an operator (`x * (-0x1p-3)`).
pub fn operand(x: f64, f32: bool) -> String {
    let l = if f32 { hex(x as f32 as f64, true) } else { hex(x, false) };
    if l.starts_with('-') {
        format!("({l})")
    } else {
        l
    }
}

#[cfg(test)]
mod tests {
    use super::hex;

    /// Reads back a literal printed by [`hex`] (independently of it: mantissa digit by digit).
    fn parse(s: &str) -> f64 {
        let (neg, s) = s.strip_prefix('-').map_or((false, s), |r| (true, r));
        let s = s.strip_suffix('f').unwrap_or(s).strip_prefix("0x").unwrap();
        let (m, e) = s.split_once('p').unwrap();
        let (int, frac) = m.split_once('.').unwrap_or((m, ""));
        let mut v = int.parse::<f64>().unwrap();
        for (i, d) in frac.chars().enumerate() {
            v += d.to_digit(16).unwrap() as f64 * 16f64.powi(-(i as i32 + 1));
        }
        let e: i32 = e.parse().unwrap();
        // Scale in two steps so subnormal results are exact.
        let v = v * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
        if neg {
            -v
        } else {
            v
        }
    }

    #[test]
    fn literals_round_trip_exactly() {
        assert_eq!(hex(3.0, false), "0x1.8p+1");
        assert_eq!(hex(-0.125, false), "-0x1p-3");
        assert_eq!(hex(0.0, false), "0x0p+0");
        assert_eq!(hex(-0.0, false), "-0x0p+0");
        assert_eq!(hex(0.1f32 as f64, true), "0x1.99999ap-4f");
        for x in [0.1, 1.0 / 3.0, f64::MAX, f64::MIN_POSITIVE, 5e-324, -2.5e-310, 1e300, 123456.789] {
            let back = parse(&hex(x, false));
            assert_eq!(back.to_bits(), x.to_bits(), "{x} -> {}", hex(x, false));
        }
    }
}
