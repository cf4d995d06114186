//! Numeric formats in the IR (issue 48 item 4, `robovec_ir::format`): the text form writes and
//! reads them back, the verifier refuses them outside atomised functions, passes that do not
//! understand them refuse a formatted function, and `-eval` computes every value in its format
//! (expected values worked out by hand below, not read from the output).

use crate::common::{opt, stderr, tmp};
use proptest::prelude::*;
use robovec_ir::format::Format;
use robovec_ir::text::parse;
use robovec_ir::{verifier, Module};

const FIXED: &str = "func @f {
  phase atomised
  input %a : fix<16,8>
  input %b : f32
  %p = mul %a, %b : fix<16,4>
  %s = add %p, 0.03 : fix<8,2>
  %t = div %s, 3.0 : f32
  %u = sin %a : fix<12,10>
  %v = mul %b, 0.3 : f32
  output y = %s
  output z = %t
  output w = %u
  output x = %v
}
";

#[test]
fn formats_print_and_read_back_and_binary64_is_not_written() {
    let m = parse(FIXED).expect("parses");
    let f = &m.functions[0];
    let fmt = |n: &str| f.format(f.lookup(n).unwrap());
    assert_eq!(fmt("a"), Format::fix(16, 8).unwrap());
    assert_eq!(fmt("b"), Format::Binary32);
    assert_eq!(fmt("t"), Format::Binary32);
    assert!(verifier::verify(&m).is_ok());
    let text = m.to_string();
    assert!(text.contains("  %p = mul %a, %b : fix<16,4>\n"), "{text}");
    assert!(text.contains("  input %b : f32\n"), "{text}");
    assert_eq!(parse(&text).unwrap(), m, "the text reads back to the same module");
    // Without formats nothing is written: the text of every file before issue 48 is unchanged.
    let plain = parse("func @g { phase atomised input %a %x = add %a, 1.0 output y = %x }").unwrap();
    assert!(!plain.to_string().contains(':') && !plain.functions[0].has_formats());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// Any assignment of formats to a random function's values survives printing and parsing.
    #[test]
    fn random_formats_round_trip(n_ops in 5usize..200, seed in 0u64..1000, picks in proptest::collection::vec(0u32..4, 1..64)) {
        let mut f = robovec_testkit::dag_gen::generate(n_ops, seed);
        let values: Vec<_> = f.inputs.iter().chain(&f.body).copied().collect();
        for (k, &v) in values.iter().enumerate() {
            let format = match picks[k % picks.len()] {
                0 => Format::Binary64,
                1 => Format::Binary32,
                2 => Format::fix(32, (k % 40) as i32 - 8).unwrap(),
                _ => Format::fix(1 + (k as u32 % 53), 3).unwrap(),
            };
            f.set_format(v, format);
        }
        let m = Module { functions: vec![f] };
        let text = m.to_string();
        let back = parse(&text).map_err(|e| TestCaseError::fail(format!("{e:?}")))?;
        // The same text (spans aside, the same module), and every value's format.
        prop_assert_eq!(back.to_string(), text);
        let (f, g) = (&m.functions[0], &back.functions[0]);
        for &v in &values {
            prop_assert_eq!(g.format(g.lookup(f.name_of(v)).unwrap()), f.format(v));
        }
    }
}

#[test]
fn a_bad_format_is_a_located_parse_error() {
    let e = parse("func @f { phase atomised input %a : fix<64,3> output y = %a }").unwrap_err();
    let text = format!("{e:?}");
    assert!(text.contains("expected f64, f32 or fix<W,F>"), "{text}");
    assert!(text.contains("not a numeric format"), "{text}");
}

#[test]
fn a_format_needs_an_atomised_function() {
    let m = parse("func @f { input %a %x = %a*2.0 : f32 output y = %x }").unwrap();
    let errs = verifier::verify(&m).unwrap_err();
    assert!(errs[0].message.contains("`%x` has the numeric format f32, but a format needs an atomised function"));
}

#[test]
fn eval_computes_each_value_in_its_format() {
    let dir = tmp("formats-eval");
    let file = dir.join("f.rvir");
    std::fs::write(&file, FIXED).unwrap();
    let inputs = dir.join("in.json");
    // a = 1.3 → fix<16,8>: floor(1.3·256 + 0.5)/256 = 333/256 = 1.30078125;
    // b = 0.7 → binary32: 0.699999988079071044921875.
    std::fs::write(&inputs, r#"{"a": 1.3, "b": 0.7}"#).unwrap();
    let o = opt(&[file.to_str().unwrap(), "-passes=dce", &format!("-eval={}", inputs.display()), "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let a = 333.0 / 256.0;
    let b = 0.7f32 as f64;
    // p = a·b in binary64 (b is binary32), stored in fix<16,4> (steps of 1/16); s = p + 0.03,
    // an integer op: exact on p's integer and 0.03's 32-bit word, rounded once to fix<8,2>.
    let p = (a * b * 16.0 + 0.5).floor() / 16.0;
    let s = ((p + 0.03) * 4.0 + 0.5).floor() / 4.0;
    let t = (s / 3.0) as f32 as f64;
    let u = (a.sin() * 1024.0 + 0.5).floor() / 1024.0;
    assert_eq!((p, s), (0.9375, 1.0), "by hand: a·b = 0.91055 → 15/16; 0.9375 + 0.03 = 0.9675 → 4/4");
    assert_eq!(json["precision"], "formats");
    assert_eq!(json["outputs"]["y"].as_f64(), Some(s));
    assert_eq!(json["outputs"]["z"].as_f64(), Some(t));
    assert_eq!(json["outputs"]["w"].as_f64(), Some(u));
    // A binary32 op reads its constant as a binary32 (C's `0.3f`) and rounds once: 0.7f·0.3f,
    // whose binary32 product differs from rounding the binary64 0.7f·0.3 (0.21000001 against 0.21).
    let v = (0.7f32 * 0.3f32) as f64;
    assert_ne!(v, (b * 0.3) as f32 as f64, "the case tells the two readings apart");
    assert_eq!(json["outputs"]["x"].as_f64(), Some(v));
    assert_eq!(json["inputs"]["a"].as_f64(), Some(1.3), "the inputs as given");
    // An overflow stops with the value, located: a = 100 needs more than fix<16,4>'s 2^11.
    std::fs::write(&inputs, r#"{"a": 127.9, "b": 100.0}"#).unwrap();
    let o = opt(&[file.to_str().unwrap(), "-passes=dce", &format!("-eval={}", inputs.display()), "-o", "/dev/null"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("error: @f: %p = 12789.84375 ") && e.contains("overflows fix<16,4> (values -2048 ..= 2047.9375)"),
        "{e}"
    );
    assert!(e.contains(&format!("--> {}:5:3", file.display())), "{e}");
    // The formats say the precision: -eval-precision=f32 is bad usage.
    let o =
        opt(&[file.to_str().unwrap(), "-passes=dce", &format!("-eval={}", inputs.display()), "-eval-precision=f32"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn a_pass_that_does_not_understand_formats_refuses_them() {
    let dir = tmp("formats-refuse");
    let file = dir.join("f.rvir");
    std::fs::write(&file, FIXED).unwrap();
    let o = opt(&[file.to_str().unwrap(), "-passes=cse", "-o", "/dev/null"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains(
            "pass `cse`: @f has values in numeric formats (`%a` is fix<16,8>), which this pass does not understand"
        ),
        "{e}"
    );
    // `dce` keeps them: the output has them still.
    let out = dir.join("out.rvir");
    let o = opt(&[file.to_str().unwrap(), "-passes=dce", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), FIXED);
}

/// The C back end computes every value in its format bit for bit as `-eval` does: 48 random
/// functions with every op the IR has, random values in binary32 and fixed point, 16 points
/// of their domain each, compiled at -O1; the expected bits are the interpreter's
/// (`robovec_ir::format::eval_values`). One state per call.
#[test]
fn c_computes_every_format_bit_for_bit_as_eval() {
    c_bit_exact("formats-c", 1, "-O1", false, Mix::Random);
}

/// Fixed point everywhere it fits (16- to 40-bit formats): the C computes most values as
/// integer ops (`int32_t` where the whole intermediate fits 31 bits, `int64_t` otherwise,
/// `robovec_veci` vectors in a batch), bit for bit as `-eval`'s exact integers, at one state
/// (`-std=c99 -Wall -Wextra -Werror`) and `batch=4`.
#[test]
fn c_computes_fixed_point_as_integers_bit_for_bit() {
    let ops = c_bit_exact("formats-c-fix", 1, "-O1", false, Mix::FixedPoint);
    assert!(ops.integer >= 300 && ops.int32 >= 30 && ops.int64 >= 30, "{ops:?}");
    c_bit_exact("formats-c-fix4", 4, "-O1", false, Mix::FixedPoint);
}

/// As [`c_computes_every_format_bit_for_bit_as_eval`] with `batch=8` (`float` and `double`
/// vectors side by side, converted where formats meet) and `batch=2`, at -O1 (a correctness build) with the
/// machine's own vector instructions (its FMA where it has one).
#[test]
fn c_batches_compute_every_format_bit_for_bit_as_eval() {
    c_bit_exact("formats-c-batch8", 8, "-O1", false, Mix::Random);
    c_bit_exact("formats-c-batch2", 2, "-O1", false, Mix::Random);
}

/// With `trig=inline` (robovec's own sin/cos: binary32 values in `float` code, the others in
/// `double` code on half vectors) the C is not bit-exact, but every output stays within the
/// certified mixed-format bound *for that code* (`error-bound<trig=inline>`: its binary32 sin/cos
/// allowed 1 ulp, not the C library's 4) of the certified exact value, at `batch=8` with the
/// machine's vectors and `batch=2` with SSE2 only; `-Wall -Wextra -Werror` clean.
#[test]
fn c_batches_with_inline_trig_stay_within_the_certified_bound() {
    c_bit_exact("formats-c-inline8", 8, "-O1", true, Mix::Random);
    c_bit_exact("formats-c-inline2", 2, "-O1", true, Mix::Random);
}

/// Which formats [`c_bit_exact`] gives the random functions' values.
#[derive(Clone, Copy, PartialEq)]
enum Mix {
    /// `crate::error_bound::with_random_formats`: binary32, fixed point or binary64.
    Random,
    /// `crate::error_bound::with_fixed_point_formats`: fixed point wherever the range is finite.
    FixedPoint,
}

/// How many ops of the compiled functions were integer ops, by the C type they compute in.
#[derive(Debug, Default)]
struct IntegerOps {
    integer: usize,
    int32: usize,
    int64: usize,
}

/// The bit-exact campaign at `batch` lanes (each call evaluates `batch` points,
/// lane-contiguous for even seeds, as rows for odd ones), compiled with `opt_level` (and `-march=native` in a batch of 8); with
/// `inline_trig`, `trig=inline` and each output within its `trig=inline` bound of the exact value.
/// Returns the count of integer ops compiled (one state: by intermediate type).
fn c_bit_exact(dir_name: &str, batch: usize, opt_level: &str, inline_trig: bool, mix: Mix) -> IntegerOps {
    use robovec_backends::c::{BatchLayout, CodegenC};
    use robovec_ir::rng::SplitMix64;
    use robovec_ir::Operand;
    use std::fmt::Write as _;
    let dir = tmp(dir_name);
    let mut main = String::from("#include <stdio.h>\n#include <string.h>\n#include <stdint.h>\n");
    let mut calls = String::new();
    let mut files = vec!["main.c".to_string()];
    let mut input_bytes: Vec<u8> = Vec::new();
    // (what, -eval's value, allowed distance: 0 for bit-exact).
    let mut want: Vec<(String, f64, f64)> = Vec::new();
    let mut cases = 0;
    let mut ops = IntegerOps::default();
    for seed in 0..48u64 {
        let (f, dom) = crate::range::random_function(seed * 7919 + 1, 4 + (seed as usize % 40));
        let g = match mix {
            Mix::Random => crate::error_bound::with_random_formats(&f, &dom, seed),
            Mix::FixedPoint => crate::error_bound::with_fixed_point_formats(&f, &dom, seed),
        };
        if robovec_passes::error_bound::bound::check_fixed_formats(&g, &dom).is_err() {
            continue;
        }
        for &v in &g.body {
            if let Some(op) = robovec_ir::format::integer_op(&g, v) {
                ops.integer += 1;
                if op.bits <= 30 && op.shift <= 30 {
                    ops.int32 += 1;
                } else {
                    ops.int64 += 1;
                }
            }
        }
        let m = Module { functions: vec![g.clone()] };
        let trig = if inline_trig { robovec_backends::c::Trig::Inline } else { robovec_backends::c::Trig::Libm };
        // Odd seeds read and write their batch as rows (`layout=rows`: state k's element i at
        // `[k*n + i]`), even ones lane-contiguous.
        let rows = batch > 1 && seed % 2 == 1;
        let layout = if rows { BatchLayout::Rows } else { BatchLayout::Lanes };
        let o = CodegenC { name: Some(format!("t{seed}")), batch: batch as u32, trig, layout, ..CodegenC::default() };
        // With inline trig: the bound for robovec's own sin/cos (binary32 allowed 1 ulp), which
        // the C must meet against the certified exact value.
        let bounds = if inline_trig {
            use robovec_passes::error_bound::bound::{bound_with_adjoints, OutputAdjoints};
            use robovec_passes::error_bound::{Formats, TrigImpl};
            let x = robovec_passes::range::enclose_with(&g, &dom, Some(16), || false).unwrap();
            let adjoints = OutputAdjoints::new(&g, &x);
            bound_with_adjoints(&g, &x, Formats::Mixed, 0, adjoints.as_ref(), TrigImpl::Inline, || false).unwrap()
        } else {
            Vec::new()
        };
        let tape = robovec_ir::numerics::Tape::new(&g);
        let mut reference = robovec_ir::numerics::Reference::new();
        let mut refs = Vec::new();
        let art = o.emit(&m).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        std::fs::write(dir.join(format!("t{seed}.c")), &art.code.main).unwrap();
        files.push(format!("t{seed}.c"));
        let iface = &art.interfaces[0];
        let (ni, no) = (iface.inputs.len(), iface.outputs.len());
        let _ = writeln!(main, "void {}(const double *restrict in, double *restrict out);", iface.symbol);
        let mut rng = SplitMix64::new(seed);
        // Points where -eval computes (no fixed-point overflow), `batch` per call.
        let mut points: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
        for _ in 0..4 * batch.max(4) {
            let point = crate::range::uniform_point(&iface.inputs, &dom, &mut rng);
            let at = |n: &str| point[iface.inputs.iter().position(|x| x == n).unwrap()];
            if let Ok(vals) = robovec_ir::format::eval_values(&g, at) {
                points.push((point, vals));
            }
        }
        let calls_made = points.len() / batch;
        for group in points.chunks_exact(batch) {
            if rows {
                for (point, _) in group {
                    input_bytes.extend(point.iter().flat_map(|x| x.to_le_bytes()));
                }
            } else {
                for i in 0..ni {
                    for (point, _) in group {
                        input_bytes.extend(point[i].to_le_bytes());
                    }
                }
            }
            // The certified exact outputs at each point (inline trig only), by output name.
            let exact: Vec<Vec<(String, Option<f64>)>> = if inline_trig {
                group
                    .iter()
                    .map(|(point, _)| {
                        let xs: Vec<f64> = tape
                            .inputs
                            .iter()
                            .map(|n| point[iface.inputs.iter().position(|x| x == n).unwrap()])
                            .collect();
                        reference.eval(&tape, &xs, &mut refs);
                        tape.outputs
                            .iter()
                            .zip(&refs)
                            .map(|((n, _), r)| (n.clone(), (r.certified && r.f64.is_finite()).then_some(r.f64)))
                            .collect()
                    })
                    .collect()
            } else {
                Vec::new()
            };
            // Output j of state k, in the order the C writes them: `[j*batch + k]`, or
            // `[k*no + j]` as rows.
            let order: Vec<(usize, usize)> = if rows {
                (0..group.len()).flat_map(|k| (0..no).map(move |j| (j, k))).collect()
            } else {
                (0..no).flat_map(|j| (0..group.len()).map(move |k| (j, k))).collect()
            };
            for (j, k) in order {
                let (name, out) = (&iface.outputs[j], &g.outputs[j]);
                let (point, vals) = &group[k];
                let (y, allowed) = match out.value {
                    // Against the exact value, within the bound and the reference's half ulp
                    // (an uncertified reference is not compared: allowed ∞).
                    Operand::Value(v) if inline_trig => {
                        match exact[k].iter().find(|(n, _)| n == name).and_then(|(_, r)| *r) {
                            Some(r) => (r, bounds[v.index()] + r.abs() * f64::EPSILON / 2.0),
                            None => (vals[v.index()], f64::INFINITY),
                        }
                    }
                    Operand::Value(v) => (vals[v.index()], 0.0),
                    Operand::Const(c) => (c, 0.0),
                };
                want.push((format!("seed {seed} {name} at {point:?}"), y, allowed));
            }
        }
        let _ = writeln!(
            calls,
            "  for (int k = 0; k < {calls_made}; k++) {{ double in[{}], out[{}]; if (fread(in, 8, {}, stdin) != {}) return 1; \
             {}(in, out); for (int i = 0; i < {}; i++) {{ uint64_t b; memcpy(&b, &out[i], 8); printf(\"%016llx\\n\", \
             (unsigned long long)b); }} }}",
            (ni * batch).max(1),
            (no * batch).max(1),
            ni * batch,
            ni * batch,
            iface.symbol,
            no * batch
        );
        cases += 1;
    }
    assert!(cases >= 30, "only {cases} functions with fitting formats");
    main += "int main(void)\n{\n";
    main += &calls;
    main += "  return 0;\n}\n";
    std::fs::write(dir.join("main.c"), main).unwrap();
    let mut flags = vec![opt_level, "-std=c99", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-Wno-psabi"];
    if batch == 8 {
        flags.push("-march=native");
    }
    // The functions' files in one translation unit beside `main.c`: one by one they were 48
    // compiles of ~0.85 s at `-O1 -march=native` (71 s of CI for a pair of widths), together ~2.7 s.
    let unit = crate::common::including_unit(&dir, "functions.c", &files[1..]);
    let exe = crate::common::compile_c(&dir, &flags, &["main.c", &unit]);
    let got = crate::common::run_hex_lines(&exe, &input_bytes);
    assert_eq!(got.len(), want.len());
    let mut checked = 0;
    for (g, (what, y, allowed)) in got.iter().zip(&want) {
        let c = f64::from_bits(*g);
        let same = *g == y.to_bits() || (y.is_nan() && c.is_nan());
        if *allowed > 0.0 && allowed.is_finite() {
            assert!(
                (c - y).abs() <= *allowed,
                "batch={batch}: {what}: C gives {c:e}, -eval {y:e}, allowed {allowed:e}"
            );
            checked += 1;
        } else if *allowed == 0.0 {
            assert!(same, "batch={batch}: {what}: C gives {c:e}, -eval {y:e}");
            checked += 1;
        }
    }
    assert!(checked * 2 >= want.len(), "only {checked} of {} outputs checked", want.len());
    ops
}

/// Formats with options that cannot honour them are refused (exit 1), naming both.
#[test]
fn c_refuses_formats_with_options_that_cannot_honour_them() {
    let dir = tmp("formats-c-refused");
    let input = dir.join("f.rvir");
    std::fs::write(&input, FIXED).unwrap();
    for (opts, why) in [
        ("abi=robotran", "has values in numeric formats, which codegen<c> writes with abi=plain"),
        // Float arrays need binary32 outputs: `y` is fixed point.
        ("precision=f32", "output `y` is not a binary32 value"),
    ] {
        let o = opt(&[input.to_str().unwrap(), &format!("-passes=codegen<c;{opts}>"), "-o", "/dev/null"]);
        assert_eq!(o.status.code(), Some(1), "{opts}: {}", stderr(&o));
        assert!(stderr(&o).contains(why), "{opts}: {}", stderr(&o));
    }
    let o = opt(&[input.to_str().unwrap(), "-passes=codegen<c>", "-o", dir.join("f.c").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let c = std::fs::read_to_string(dir.join("f.c")).unwrap();
    assert!(
        c.contains("robovec_fix_from(") && c.contains("const float t = (float)((double)s * 0x1p-2) / 0x1.8p+1f;"),
        "{c}"
    );
}

/// Formats with `abi=pinocchio` (Pinocchio's `double` vectors, the formats inside): a URDF's RNEA
/// after `precision` compiles cleanly (`-Wall -Wextra -Werror -std=c99`) at one state and in
/// batches, with `trig=libm` and `trig=inline`, and its entry point has Pinocchio's signature.
#[test]
fn pinocchio_abi_writes_formats() {
    let dir = tmp("formats-pinocchio");
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/three_link_arm/three_link_arm.urdf");
    // The arm's second joint has no velocity limit in its URDF.
    let ranges = dir.join("ranges.json");
    std::fs::write(&ranges, r#"{"qd[*]": [-5, 5]}"#).unwrap();
    let ranges = format!("-ranges={}", ranges.display());
    for (batch, trig) in [(1, "libm"), (4, "inline"), (8, "libm")] {
        let c = dir.join(format!("arm_{batch}_{trig}.c"));
        let o = opt(&[
            urdf,
            "-function=invdyna",
            "--fold-params",
            &ranges,
            &format!("-passes=atomise,cse,precision<budget=1e-5>,codegen<c;abi=pinocchio;batch={batch};trig={trig}>"),
            "-o",
            c.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(stderr(&o).contains(" f32"), "precision chose binary32 somewhere: {}", stderr(&o));
        let text = std::fs::read_to_string(&c).unwrap();
        assert!(text.contains("void model_rnea(const double *restrict q, const double *restrict v, const double *restrict a, double *restrict tau)"), "{text}");
        assert!(text.contains(if batch > 1 { "robovec_vec32" } else { "const float " }), "binary32 temporaries");
        let cc = std::process::Command::new("cc")
            .args(["-O1", "-std=c99", "-Wall", "-Wextra", "-Werror", "-Wno-psabi", "-ffp-contract=off", "-c", "-o"])
            .arg(dir.join(format!("arm_{batch}_{trig}.o")))
            .arg(&c)
            .output()
            .expect("cc");
        assert!(cc.status.success(), "batch={batch} trig={trig}: {}", String::from_utf8_lossy(&cc.stderr));
    }
}

/// Formats with `precision=f32`: the plain ABI's arrays are `float` (data already in binary32),
/// the values computed in their formats. A URDF arm's RNEA all in binary32 after `precision`
/// (one input kept binary64 by hand, to read a float into a double), at one state and
/// `batch=8` (`-O2 -march=native`), equals `-eval` at the same float inputs bit for bit; the
/// interface says `f32`; an output not in binary32 is refused (above).
#[test]
fn formats_with_float_arrays_equal_eval() {
    use robovec_backends::c::CodegenC;
    use robovec_ir::format::Format;
    use std::fmt::Write as _;
    let dir = tmp("formats-float-io");
    let ranges = dir.join("r.json");
    std::fs::write(&ranges, r#"{"qd[*]": [-3, 3]}"#).unwrap();
    let ir = dir.join("arm.rvir");
    let o = opt(&[
        concat!(env!("CARGO_MANIFEST_DIR"), "/examples/three_link_arm/three_link_arm.urdf"),
        "-function=invdyna",
        "--fold-params",
        &format!("-ranges={}", ranges.display()),
        "-passes=default<ops>,precision<budget=1e-3>",
        "-o",
        ir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut m = parse(&std::fs::read_to_string(&ir).unwrap()).unwrap();
    let g = &mut m.functions[0];
    assert!(g
        .outputs
        .iter()
        .all(|o| matches!(o.value, robovec_ir::Operand::Value(v) if g.format(v) == Format::Binary32)));
    let q1 = g.inputs.iter().copied().find(|&v| g.name_of(v) == "q[1]").unwrap();
    g.set_format(q1, Format::Binary64);
    let g = g.clone();
    let mut rng = robovec_ir::rng::SplitMix64::new(7);
    for batch in [1usize, 8] {
        let o = CodegenC {
            name: Some("arm".into()),
            batch: batch as u32,
            precision: robovec_backends::c::Precision::F32,
            ..CodegenC::default()
        };
        let art = o.emit(&m).unwrap();
        let iface = &art.interfaces[0];
        assert_eq!(iface.precision, robovec_backends::c::Precision::F32);
        assert!(art.code.main.contains("void arm(const float *restrict in, float *restrict out)"));
        let (ni, no) = (iface.inputs.len(), iface.outputs.len());
        std::fs::write(dir.join("arm.c"), &art.code.main).unwrap();
        let calls = 8;
        let mut bytes = Vec::new();
        let mut want = Vec::new();
        let mut points = Vec::new();
        for _ in 0..calls * batch {
            let p: Vec<f32> = iface
                .inputs
                .iter()
                .map(|n| {
                    let u = rng.unit() as f32;
                    if n.starts_with("qd") {
                        6.0 * u - 3.0
                    } else if n.starts_with("qdd") {
                        20.0 * u - 10.0
                    } else if n.starts_with("q[") {
                        3.0 * u - 1.5
                    } else if n == "g[3]" {
                        -9.81
                    } else {
                        0.0
                    }
                })
                .collect();
            points.push(p);
        }
        for call in points.chunks(batch) {
            for i in 0..ni {
                for p in call {
                    bytes.extend(p[i].to_le_bytes());
                }
            }
            for (j, out) in g.outputs.iter().enumerate() {
                for p in call {
                    let at = |n: &str| p[iface.inputs.iter().position(|m| m == n).unwrap()] as f64;
                    let vals = robovec_ir::format::eval_values(&g, at).unwrap();
                    let robovec_ir::Operand::Value(v) = out.value else { unreachable!() };
                    want.push((format!("batch {batch} {} at {p:?}", iface.outputs[j]), vals[v.index()] as f32));
                }
            }
        }
        let mut main = String::from("#include <stdio.h>\n#include <string.h>\n#include <stdint.h>\n");
        let _ = writeln!(
            main,
            "void arm(const float *restrict in, float *restrict out);\nint main(void)\n{{\n  float in[{}], out[{}];\n  \
             while (fread(in, 4, {}, stdin) == {}) {{\n    arm(in, out);\n    for (int i = 0; i < {}; i++) {{ uint32_t b; \
             memcpy(&b, &out[i], 4); printf(\"%08x\\n\", (unsigned)b); }}\n  }}\n  return 0;\n}}",
            ni * batch, no * batch, ni * batch, ni * batch, no * batch
        );
        std::fs::write(dir.join("main.c"), main).unwrap();
        let mut flags = vec!["-O2", "-std=c99", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-Wno-psabi"];
        if batch == 8 {
            flags.push("-march=native");
        }
        let got = crate::common::run_hex_lines(&crate::common::compile_c(&dir, &flags, &["main.c", "arm.c"]), &bytes);
        assert_eq!(got.len(), want.len());
        for (&g, (what, y)) in got.iter().zip(&want) {
            assert_eq!(g, u64::from(y.to_bits()), "{what}: C gives {}, -eval {y}", f32::from_bits(g as u32));
        }
    }
}

/// The 1-ulp allowance of `error-bound<trig=inline>` against the C it certifies, where nothing
/// else in the bound gives slack: `y = sin x` and `cos x` in binary32 at 512 points, each input a
/// point range holding a binary32 number (its store exact), half of them beside multiples of
/// π/2 (the range reduction's hard cases), up to 2¹¹. Each output's bound is then the trig
/// allowance alone (`2⁻²³·|y|` and the tiny absolute part); the compiled `trig=inline` code, one
/// state and `batch=8`, must be within it of the certified exact value. (The kernel's largest
/// error over every binary32 argument is 0.57 of it: `scripts/trig_ulps.sh`; an allowance of
/// zero fails here.)
#[test]
fn inline_trig_meets_its_one_ulp_allowance_in_the_bound() {
    use robovec_backends::c::{CodegenC, Precision, Trig};
    use robovec_passes::error_bound::bound::bound_with_adjoints;
    use robovec_passes::error_bound::{Formats, TrigImpl};
    use std::fmt::Write as _;
    let n = 512;
    let mut rng = robovec_ir::rng::SplitMix64::new(11);
    // `x` moved by `k` binary32 steps (down for negative `k`).
    let steps = |x: f32, k: i32| (0..k.abs()).fold(x, |x, _| if k > 0 { x.next_up() } else { x.next_down() });
    let xs: Vec<f32> = (0..n)
        .map(|k| {
            let x = if k % 2 == 0 {
                ((rng.unit() * 2.0 - 1.0) * 2048.0) as f32
            } else {
                let j = (rng.unit() * 2600.0) as i64 - 1300;
                let near = j as f64 * std::f64::consts::FRAC_PI_2;
                steps(near as f32, k % 7 - 3)
            };
            x.clamp(-2048.0, 2048.0)
        })
        .collect();
    let mut ir = String::from("func @t {\n  phase atomised\n");
    for k in 0..n {
        let _ = writeln!(ir, "  input %x[{}]", k + 1);
    }
    for k in 1..=n {
        let _ = writeln!(ir, "  %S{k} = sin %x[{k}]\n  %C{k} = cos %x[{k}]");
    }
    for k in 1..=n {
        let _ = writeln!(ir, "  output s[{k}] = %S{k}\n  output c[{k}] = %C{k}");
    }
    ir += "}\n";
    let m = robovec_ir::text::parse(&ir).unwrap();
    let f = &m.functions[0];
    let mut dom = robovec_ir::domain::Domain::default();
    for (k, &x) in xs.iter().enumerate() {
        dom.ranges.insert(format!("x[{}]", k + 1), crate::range::range(f64::from(x), f64::from(x)));
    }
    let x = robovec_passes::range::enclose_with(f, &dom, Some(16), || false).unwrap();
    let bounds = bound_with_adjoints(f, &x, Formats::F32, 0, None, TrigImpl::Inline, || false).unwrap();
    let tape = robovec_ir::numerics::Tape::new(f);
    let at: Vec<f64> = tape.inputs.iter().map(|name| dom.get(name).unwrap().interval.lo).collect();
    let mut refs = Vec::new();
    robovec_ir::numerics::Reference::new().eval(&tape, &at, &mut refs);
    let dir = tmp("inline-trig-allowance");
    for (batch, flags) in [(1u32, &["-O1"][..]), (8, &["-O2", "-march=native"])] {
        let o = CodegenC {
            name: Some("t".into()),
            batch,
            precision: Precision::F32,
            trig: Trig::Inline,
            ..CodegenC::default()
        };
        let art = o.emit(&m).unwrap();
        let iface = &art.interfaces[0];
        std::fs::write(dir.join("t.c"), &art.code.main).unwrap();
        let w = batch as usize;
        // Each input in every lane; the outputs of lane 0 printed.
        let main = format!(
            "#include <stdio.h>\n#include <stdint.h>\n#include <string.h>\nvoid t(const float *restrict in, float *restrict out);\n\
             int main(void)\n{{\n  static float in[{ni}], out[{no}];\n  if (fread(in, 4, {ni}, stdin) != {ni}) return 1;\n  \
             t(in, out);\n  for (int i = 0; i < {nout}; i++) {{ for (int l = 0; l < {w}; l++) {{ double d = out[i * {w} + l]; \
             uint64_t b; memcpy(&b, &d, 8); printf(\"%016llx\\n\", (unsigned long long)b); }} }}\n  return 0;\n}}\n",
            ni = iface.inputs.len() * w,
            no = iface.outputs.len() * w,
            nout = iface.outputs.len(),
        );
        std::fs::write(dir.join("main.c"), main).unwrap();
        let mut input = Vec::new();
        for name in &iface.inputs {
            let v = dom.get(name).unwrap().interval.lo as f32;
            for _ in 0..w {
                input.extend(v.to_le_bytes());
            }
        }
        let mut all = vec!["-std=c99", "-ffp-contract=off", "-Wno-psabi"];
        all.extend(flags);
        let got = crate::common::run_hex_lines(&crate::common::compile_c(&dir, &all, &["main.c", "t.c"]), &input);
        assert_eq!(got.len(), iface.outputs.len() * w);
        let mut worst: f64 = 0.0;
        for (i, name) in iface.outputs.iter().enumerate() {
            let o = f.outputs.iter().find(|o| &o.name == name).unwrap();
            let robovec_ir::Operand::Value(v) = o.value else { panic!() };
            let r = &refs[tape.outputs.iter().position(|(n, _)| n == name).unwrap()];
            assert!(r.certified, "{name}");
            let b = bounds[v.index()];
            for l in 0..w {
                let c = f64::from_bits(got[i * w + l]);
                let err = (c - r.f64).abs() - r.f64.abs() * f64::EPSILON / 2.0;
                assert!(
                    err <= b,
                    "batch={batch}: {name} lane {l}: {c:e} is {err:e} from the exact {:e}, bound {b:e}",
                    r.f64
                );
                worst = worst.max(err / b);
            }
        }
        // The allowance is used: the worst output takes a good part of it.
        assert!(worst > 0.2, "batch={batch}: the largest error is only {worst} of its bound");
    }
}
