//! `trig=inline` (`passes/src/codegen/c/trig/`): the emitted sin/cos, compiled
//! (`cc -O1 -ffp-contract=off`, one program, for a generic target and with `-march=native`, and at
//! `-O2 -march=native`), against a reference computed here in exact
//! integer arithmetic (the reduction) and double-double (the series) — accurate to about
//! 2^−100, far beyond the ulp being measured; batched lanes equal `batch=1` bit for bit, and
//! one state's block of coordinates (`robovec_sincos_n`) equals one call per coordinate;
//! libm's exact results beyond the range and on NaN/±∞; `sin(±0) = ±0`.

use std::process::{Command, Stdio};

use robovec_backends::c::trig::{Constants, PI_HEX};
use robovec_backends::c::{CodegenC, Precision, Trig};
use robovec_ir::rng::SplitMix64;

use crate::common::tmp;

/// `hi + lo`, `|lo| ≤ ulp(hi)/2`.
#[derive(Clone, Copy, Debug)]
struct Dd(f64, f64);

fn fast_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd(s, b - (s - a))
}

fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd(s, (a - (s - bb)) + (b - bb))
}

impl Dd {
    fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }

    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.0, o.0);
        let t = two_sum(self.1, o.1);
        let u = fast_two_sum(s.0, s.1 + t.0);
        fast_two_sum(u.0, u.1 + t.1)
    }

    fn mul(self, o: Dd) -> Dd {
        let p = self.0 * o.0;
        let e = self.0.mul_add(o.0, -p); // exact: a true FMA
        fast_two_sum(p, e + (self.0 * o.1 + self.1 * o.0))
    }

    /// `self / d` for a small integer `d`.
    fn div_int(self, d: f64) -> Dd {
        let q1 = self.0 / d;
        let p = q1 * d;
        let r = ((self.0 - p) - q1.mul_add(d, -p)) + self.1;
        fast_two_sum(q1, r / d)
    }
}

/// `2^e` for any exponent of a finite non-zero `f64` (subnormal powers too).
fn pow2(e: i32) -> f64 {
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        f64::from_bits(1 << (e + 1074))
    }
}

/// A non-negative integer of 384 bits, little-endian limbs.
type Big = [u64; 6];

/// π/2 · 2^257 (π's hex digits as an integer; the passes' unit tests check them against
/// Machin's formula).
fn half_pi() -> Big {
    let mut a: Big = [0; 6];
    for d in PI_HEX.chars().filter(|&c| c != '.') {
        a = mul_small(&a, 16);
        a[0] += u64::from(d.to_digit(16).unwrap());
    }
    a
}

fn mul_small(a: &Big, m: u64) -> Big {
    let mut out = [0; 6];
    let mut carry = 0u128;
    for i in 0..6 {
        let v = a[i] as u128 * m as u128 + carry;
        out[i] = v as u64;
        carry = v >> 64;
    }
    assert_eq!(carry, 0);
    out
}

fn shl(a: &Big, s: u32) -> Big {
    let (w, b) = ((s / 64) as usize, s % 64);
    let mut out = [0; 6];
    for i in w..6 {
        out[i] = a[i - w] << b | if b > 0 && i > w { a[i - w - 1] >> (64 - b) } else { 0 };
    }
    out
}

fn greater_eq(a: &Big, b: &Big) -> bool {
    (0..6).rev().find(|&i| a[i] != b[i]).is_none_or(|i| a[i] > b[i])
}

/// `a − b` for `a ≥ b`.
fn sub(a: &Big, b: &Big) -> Big {
    let mut out = [0; 6];
    let mut borrow = 0u64;
    for i in 0..6 {
        let (d, b1) = a[i].overflowing_sub(b[i]);
        let (d, b2) = d.overflowing_sub(borrow);
        out[i] = d;
        borrow = u64::from(b1 || b2);
    }
    out
}

/// `a · 2^−257` as a double-double (its top 120 bits).
fn to_dd(a: &Big) -> Dd {
    let len = (0..6).rev().find(|&i| a[i] != 0).map_or(0, |i| 64 * i as u32 + 64 - a[i].leading_zeros());
    if len == 0 {
        return Dd(0.0, 0.0);
    }
    let sh = len.saturating_sub(120);
    let (w, b) = ((sh / 64) as usize, sh % 64);
    let word = |i: usize| if i < 6 { a[i] as u128 } else { 0 };
    let mut top = (word(w) >> b) | (word(w + 1) << (64 - b));
    if b > 0 {
        top |= word(w + 2) << (128 - b);
    }
    let top = top & ((1u128 << 120) - 1);
    let hi = top as f64;
    let lo = (top as i128 - hi as i128) as f64;
    let scale = pow2(sh as i32 - 257);
    fast_two_sum(hi * scale, lo * scale)
}

/// `x = k·π/2 + r` with `r` to about 2^−110 relative (`|x| ≤ 2^22`).
fn reduce(x: f64, half_pi: &Big) -> (i64, Dd) {
    let ax = x.abs();
    if ax < 0.75 {
        return (0, Dd(x, 0.0));
    }
    let k = (ax * std::f64::consts::FRAC_2_PI).round() as u64;
    let bits = ax.to_bits();
    let (m, e) = ((bits & ((1 << 52) - 1)) | (1 << 52), (bits >> 52) as i32 - 1075);
    let xb = shl(&[m, 0, 0, 0, 0, 0], (e + 257) as u32);
    let kb = mul_small(half_pi, k);
    let r = if greater_eq(&xb, &kb) { to_dd(&sub(&xb, &kb)) } else { to_dd(&sub(&kb, &xb)).neg() };
    if x < 0.0 {
        (-(k as i64), r.neg())
    } else {
        (k as i64, r)
    }
}

/// sin and cos of `|r| ≤ π/4 + ε` by their Taylor series in double-double.
fn sin_cos_dd(r: Dd) -> (Dd, Dd) {
    let r2 = r.mul(r);
    let series = |first: Dd, mut n: f64| {
        let (mut term, mut sum) = (first, first);
        while term.0 != 0.0 && term.0.abs() > sum.0.abs() * 1e-36 {
            term = term.mul(r2).div_int((n + 1.0) * (n + 2.0)).neg();
            sum = sum.add(term);
            n += 2.0;
        }
        sum
    };
    (series(r, 1.0), series(Dd(1.0, 0.0), 0.0))
}

/// The reference `(sin x, cos x)`.
fn reference(x: f64, half_pi: &Big) -> (Dd, Dd) {
    let (k, r) = reduce(x, half_pi);
    let (s, c) = sin_cos_dd(r);
    match k.rem_euclid(4) {
        0 => (s, c),
        1 => (c, s.neg()),
        2 => (s.neg(), c.neg()),
        _ => (c.neg(), s),
    }
}

/// `|y − t|` in ulps of the format (`p` significand bits, least normal exponent `emin`) at `t`.
fn ulps(y: f64, t: Dd, p: i32, emin: i32) -> f64 {
    if t.0 == 0.0 {
        return if y == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let e = (((t.0.abs().to_bits() >> 52) as i32) - 1023).max(emin);
    ((y - t.0) - t.1).abs() / pow2(e - (p - 1))
}

/// The arguments of one precision: labelled sets, every one a multiple of 8 long.
fn arguments(f32: bool, l: f64, half_pi: &Big) -> Vec<(&'static str, Vec<f64>)> {
    let mut g = SplitMix64::new(if f32 { 32 } else { 64 });
    let round = |x: f64| if f32 { x as f32 as f64 } else { x };
    let n = 40_000;
    let mut sets: Vec<(&'static str, Vec<f64>)> = vec![
        ("uniform [-pi, pi]", (0..n).map(|_| round((g.unit() * 2.0 - 1.0) * std::f64::consts::PI)).collect()),
        ("uniform [-100, 100]", (0..n).map(|_| round((g.unit() * 2.0 - 1.0) * 100.0)).collect()),
        (
            "log-uniform 2^-30 .. L",
            (0..n)
                .map(|_| {
                    let sign = if g.chance(500) { -1.0 } else { 1.0 };
                    round(sign * (g.unit() * (30.0 + l.log2()) - 30.0).exp2()).clamp(-l, l)
                })
                .collect(),
        ),
    ];
    // The nearest numbers to k·π/2 and their neighbours: the reduction's hard cases.
    let k_max = (l * std::f64::consts::FRAC_2_PI) as u64;
    let mut near = Vec::new();
    for k in (1..=2000).chain((0..2000).map(|_| 1 + g.below(k_max))) {
        let x = round(to_dd(&mul_small(half_pi, k)).0);
        let next = |x: f64, up: bool| {
            if f32 {
                let y = x as f32;
                (if up { y.next_up() } else { y.next_down() }) as f64
            } else if up {
                x.next_up()
            } else {
                x.next_down()
            }
        };
        let (d1, u1) = (next(x, false), next(x, true));
        for y in [x, d1, u1, next(d1, false), next(u1, true), -x, -u1] {
            if y.abs() <= l {
                near.push(y);
            }
        }
    }
    sets.push(("near k*pi/2", near));
    // Zeros, subnormals, the range's ends, beyond it, ±∞, NaN.
    let (tiny, below_l, above_l) = if f32 {
        let l32 = l as f32;
        (f32::from_bits(1) as f64, l32.next_down() as f64, l32.next_up() as f64)
    } else {
        (f64::from_bits(1), l.next_down(), l.next_up())
    };
    let sub_max = if f32 { f32::from_bits(0x7fffff) as f64 } else { f64::from_bits((1 << 52) - 1) };
    let mut special = vec![0.0, -0.0, tiny, -tiny, sub_max, -sub_max, l, -l, below_l, -below_l, above_l, -above_l];
    special.extend([f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN, 1e6, 3e7, 1e10, -1e15, 1e30]);
    if !f32 {
        special.extend([1e200, f64::MAX, -f64::MAX, 2.0 * l, 1e300]);
    }
    sets.push(("special", special.into_iter().map(round).collect()));
    for (_, xs) in &mut sets {
        while xs.len() % 8 != 0 {
            xs.push(0.5);
        }
    }
    sets
}

/// A function with the sin and cos of `q[1]` (one fused call), only the sin of `q[2]` and
/// only the cos of `q[3]` (the single helpers): outputs `s`, `c`, `s2`, `c3`.
const IR: &str = "func @sc {\n  phase atomised\n  input %q[1]\n  input %q[2]\n  input %q[3]\n  %S1 = sin %q[1]\n  \
                  %C1 = cos %q[1]\n  %S2 = sin %q[2]\n  %C3 = cos %q[3]\n  output s = %S1\n  output c = %C1\n  \
                  output s2 = %S2\n  output c3 = %C3\n}\n";

/// The sin and cos of `q[1]` only (one coordinate: no block, one `robovec_sincos_inline` call), the
/// outputs of [`IR`] with all three inputs equal.
const IR_ONE: &str = "func @sc {\n  phase atomised\n  input %q[1]\n  %S1 = sin %q[1]\n  %C1 = cos %q[1]\n  \
                      output s = %S1\n  output c = %C1\n  output s2 = %S1\n  output c3 = %C1\n}\n";

/// The C driver of symbol `sym`: reads a count and that many reals, writes the 4 outputs of each.
fn driver(sym: &str, real: &str, w: u32) -> String {
    format!(
        "void {sym}(const {real} *restrict in, {real} *restrict out);\n\
         static int run_{sym}(void)\n{{\n  unsigned long long n;\n  if (fread(&n, 8, 1, stdin) != 1) return 1;\n  \
         for (unsigned long long i = 0; i < n; i += {w}) {{\n    {real} x[{w}], in[3 * {w}], out[4 * {w}];\n    \
         if (fread(x, sizeof x[0], {w}, stdin) != {w}) return 1;\n    \
         for (int l = 0; l < {w}; l++) in[l] = in[{w} + l] = in[2 * {w} + l] = x[l];\n    {sym}(in, out);\n    \
         for (int l = 0; l < {w}; l++) {{ {real} o[4] = {{out[l], out[{w} + l], out[2 * {w} + l], out[3 * {w} + l]}}; \
         fwrite(o, sizeof o[0], 4, stdout); }}\n  }}\n  return 0;\n}}\n"
    )
}

/// Compiled for a generic target (no FMA: the polynomials as products and sums) and for the
/// host's own (`-march=native`: with FMA where the host has it, `ROBOVEC_MADD` fuses them), at
/// -O1 and -O2 (where the block's loop is vectorised).
#[test]
fn inline_sin_cos_are_within_one_ulp_and_lanes_equal_the_scalar_code() {
    // -O2: the block's loop vectorised (GCC 12+, Clang), whose lanes must give the same bits.
    for (k, flags) in [&["-O1"][..], &["-O1", "-march=native"], &["-O2", "-march=native"]].into_iter().enumerate() {
        check_inline_sin_cos(&format!("trig_inline_{k}"), flags);
    }
}

/// The test above for one set of C compiler flags.
fn check_inline_sin_cos(dir: &str, flags: &[&str]) {
    let dir = tmp(dir);
    let m = robovec_ir::text::parse(IR).unwrap_or_else(|e| panic!("{e:?}"));
    let m_one = robovec_ir::text::parse(IR_ONE).unwrap_or_else(|e| panic!("{e:?}"));
    // (symbol, f32, batch, one coordinate): per precision one state with a block of three
    // coordinates, a batch, and one state with one coordinate (one call, no block).
    let forms = [
        ("d1", false, 1, false),
        ("d4", false, 4, false),
        ("d1one", false, 1, true),
        ("s1", true, 1, false),
        ("s8", true, 8, false),
        ("s1one", true, 1, true),
    ];
    let mut main = String::from("#include <stdio.h>\n");
    let mut files = vec!["main.c".to_string()];
    for (sym, f32, w, one) in forms {
        let precision = if f32 { Precision::F32 } else { Precision::F64 };
        let o = CodegenC { precision, batch: w, trig: Trig::Inline, name: Some(sym.into()), ..CodegenC::default() };
        let art = o.emit(if one { &m_one } else { &m }).unwrap();
        assert_eq!(art.interfaces[0].inputs, if one { &["q[1]"][..] } else { &["q[1]", "q[2]", "q[3]"][..] });
        assert_eq!(art.interfaces[0].trig, Trig::Inline);
        let c = &art.code.main;
        let (real, n) = if f32 { ("float", 16) } else { ("double", 8) };
        match (w, one) {
            (1, false) => {
                let zeros = vec![if f32 { "0x0p+0f" } else { "0x0p+0" }; n - 3].join(", ");
                let block = format!(
                    "  const {real} robovec_ta[{n}] = {{q_1, q_2, q_3, {zeros}}};\n  {real} robovec_ts[{n}], robovec_tc[{n}];\n  \
                     robovec_sincos_n(robovec_ta, robovec_ts, robovec_tc, {n});\n  const {real} S1 = robovec_ts[0];\n  \
                     const {real} C1 = robovec_tc[0];\n  const {real} S2 = robovec_ts[1];\n  const {real} C3 = robovec_tc[2];\n"
                );
                assert!(c.contains(&block), "{block}\n{c}");
                assert!(!c.contains("robovec_sincos_inline(q_"), "{c}");
            }
            (1, true) => assert!(c.contains("  robovec_sincos_inline(q_1, &S1, &C1);\n"), "{c}"),
            _ => {
                assert!(c.contains("robovec_sincos_inline(q_1, &S1, &C1);"), "{c}");
                assert!(c.contains("robovec_sin_inline(q_2)") && c.contains("robovec_cos_inline(q_3)"), "{c}");
            }
        }
        std::fs::write(dir.join(format!("{sym}.c")), c).unwrap();
        files.push(format!("{sym}.c"));
        main += &driver(sym, o.real(), w);
    }
    main += "int main(void) { return run_d1() || run_d4() || run_d1one() || run_s1() || run_s8() || run_s1one(); }\n";
    std::fs::write(dir.join("main.c"), main).unwrap();
    let exe = super::cc(&dir, &files, flags);

    let hp = half_pi();
    let (c64, c32) = (Constants::new(false), Constants::new(true));
    let args64 = arguments(false, c64.limit(), &hp);
    let args32 = arguments(true, c32.limit(), &hp);
    let all = |sets: &[(&str, Vec<f64>)]| -> Vec<f64> { sets.iter().flat_map(|(_, v)| v.iter().copied()).collect() };
    let (x64, x32) = (all(&args64), all(&args32));
    let mut input = Vec::new();
    for (xs, f32) in [(&x64, false), (&x64, false), (&x64, false), (&x32, true), (&x32, true), (&x32, true)] {
        input.extend((xs.len() as u64).to_le_bytes());
        for &x in xs {
            if f32 {
                input.extend((x as f32).to_le_bytes());
            } else {
                input.extend(x.to_le_bytes());
            }
        }
    }
    let mut child = Command::new(&exe).stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || std::io::Write::write_all(&mut stdin, &input).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success(), "{} exited with {:?}", exe.display(), out.status);
    let bytes = out.stdout;
    assert_eq!(bytes.len(), x64.len() * 4 * 8 * 3 + x32.len() * 4 * 4 * 3, "outputs written");
    let (b64, b32) = bytes.split_at(x64.len() * 4 * 8 * 3);
    let read64: Vec<u64> = b64.chunks(8).map(|c| u64::from_le_bytes(c.try_into().unwrap())).collect();
    let read32: Vec<u64> = b32.chunks(4).map(|c| u64::from(u32::from_le_bytes(c.try_into().unwrap()))).collect();
    let as_f = |b: u64, f32: bool| if f32 { f64::from(f32::from_bits(b as u32)) } else { f64::from_bits(b) };

    let mut report = String::new();
    for (f32, xs, sets, got, l) in
        [(false, &x64, &args64, &read64, c64.limit()), (true, &x32, &args32, &read32, c32.limit())]
    {
        let n = xs.len();
        let (scalar, rest) = got.split_at(4 * n);
        let (batch, one) = rest.split_at(4 * n);
        let label = if f32 { "f32" } else { "f64" };
        // Lanes of the batch and one call per coordinate equal the block bit for bit; the
        // single sin/cos equal the fused.
        for i in 0..n {
            assert_eq!(&scalar[4 * i..4 * i + 4], &batch[4 * i..4 * i + 4], "{label} x = {:e}: batch ≠ scalar", xs[i]);
            assert_eq!(&scalar[4 * i..4 * i + 4], &one[4 * i..4 * i + 4], "{label} x = {:e}: block ≠ one call", xs[i]);
            let r = &scalar[4 * i..4 * i + 4];
            assert_eq!((r[0], r[1]), (r[2], r[3]), "{label} x = {:e}: sin/cos alone ≠ fused", xs[i]);
        }
        let (p, emin) = if f32 { (24, -126) } else { (53, -1022) };
        let mut at = 0;
        for (name, set) in sets.iter() {
            let (mut max, mut sum, mut count) = (0.0f64, 0.0, 0usize);
            for (j, &x) in set.iter().enumerate() {
                let i = at + j;
                let (s, c) = (as_f(scalar[4 * i], f32), as_f(scalar[4 * i + 1], f32));
                if x.is_nan() || x.is_infinite() {
                    assert!(s.is_nan() && c.is_nan(), "{label}: sin/cos({x}) = {s}, {c}");
                    continue;
                }
                if x.abs() > l {
                    // libm's own result, bit for bit (Rust's sin/cos are the system libm's).
                    let want = if f32 {
                        (f64::from((x as f32).sin()), f64::from((x as f32).cos()))
                    } else {
                        (x.sin(), x.cos())
                    };
                    assert_eq!((s.to_bits(), c.to_bits()), (want.0.to_bits(), want.1.to_bits()), "{label} x = {x:e}");
                    continue;
                }
                if x == 0.0 {
                    assert_eq!((s.to_bits(), c), (x.to_bits(), 1.0), "{label}: sin/cos({x:e})");
                }
                let (ts, tc) = reference(x, &hp);
                // The reference itself: within an ulp of libm's (a check of this file's code).
                let libm =
                    if f32 { [f64::from((x as f32).sin()), f64::from((x as f32).cos())] } else { [x.sin(), x.cos()] };
                for (t, lm) in [(ts, libm[0]), (tc, libm[1])] {
                    assert!(ulps(lm, t, p, emin) <= 1.0, "{label} x = {x:e}: reference {t:?} vs libm {lm:e}");
                }
                for (y, t) in [(s, ts), (c, tc)] {
                    let e = ulps(y, t, p, emin);
                    max = max.max(e);
                    sum += e;
                    count += 1;
                }
            }
            at += set.len();
            if count > 0 {
                let _ = std::fmt::Write::write_fmt(
                    &mut report,
                    format_args!(
                        "{flags:?} {label} {name}: {count} results (sin and cos), max {max:.3} ulp, mean {:.4} ulp\n",
                        sum / count as f64
                    ),
                );
            }
            // The documented bound (trig.rs, docs/codegen-c.md): below 1 ulp of the exact value, hence at
            // most 1 ulp from the correctly rounded result.
            assert!(max < 1.0, "{label} {name}: {max} ulp\n{report}");
        }
    }
    eprint!("{report}");
}
