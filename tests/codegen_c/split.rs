//! `codegen<c;chunk=OPS;units=K>` (issue 28, item 5): functions of at least `2·OPS` statements
//! split into parts of at most `OPS` statements, the values one part computes and a later one
//! reads passed through the entry point's `live[]` array, optionally spread over K translation
//! units linked together.
//!
//! Every test compiles the split C (`cc -O0`, one at `-O1`, `-ffp-contract=off`) and compares
//! every output with robovec's interpreter bit for bit, as the unsplit tests of
//! `tests/codegen_c.rs` do: tiny chunks (`chunk=1`: every value read by a later statement
//! crosses a boundary; `chunk=7`: some do, some do not) so that every live-value path is taken,
//! for each ABI and batch width, in one file and in several.

use std::path::Path;

use robovec_backends::c::{Abi, BatchLayout, CodegenC, Precision, Trig};

use super::{
    batch_cases, check_plain, check_plain_tol, check_plain_with, corpus_cases, named_corpus_cases, plain, run_pipeline,
    Case, BATCH_FILES, BATCH_OUTPUTS,
};
use crate::common::{opt, stderr, tmp};

fn split(o: CodegenC, chunk: u32, units: u32) -> CodegenC {
    CodegenC { chunk, units, ..o }
}

/// The number of parts each function of `cases` is written as under `o`, from the report
/// entries the back end computes (its interfaces).
fn parts(cases: &[Case], o: &CodegenC) -> Vec<usize> {
    cases.iter().flat_map(|c| o.emit(&c.m).unwrap().interfaces).map(|i| i.parts).collect()
}

/// Every function of `cases` with at least twice the chunk's statements is split into at most
/// ⌈n / chunk⌉ parts (about equal sizes), and at least ⌈n / (chunk + 8)⌉: a part is longer than
/// the chunk only by the statements attached to its last one (at most the 8 later elements of
/// a native callback, or the second of a sin/cos pair); a shorter function is one part.
/// Returns the largest number of parts.
fn assert_split(cases: &[Case], o: &CodegenC) -> usize {
    let chunk = o.chunk as usize;
    let fs = cases.iter().flat_map(|c| &c.m.functions);
    let mut most = 0;
    for (f, p) in fs.zip(parts(cases, o)) {
        let n = statements(f, o);
        let (hi, lo) = if n < 2 * chunk { (1, 1) } else { (n.div_ceil(chunk), n.div_ceil(chunk + 8)) };
        assert!(lo <= p && p <= hi, "@{}: {n} statements, chunk {chunk}: {p} parts", f.name);
        most = most.max(p);
    }
    most
}

/// The statements of the body of `f` that the C writes (the trig values are inputs with
/// `trig=input`).
fn statements(f: &robovec_ir::Function, o: &CodegenC) -> usize {
    f.body.iter().filter(|&&v| !(o.trig == Trig::Input && matches!(f.value(v).def, robovec_ir::Def::Trig(..)))).count()
}

#[test]
fn split_plain_code_equals_the_interpreter_for_tiny_chunks_in_one_file_and_in_several() {
    let cases = batch_cases();
    for (chunk, units) in [(1, 1), (7, 1), (1, 3), (7, 4), (50, 2)] {
        for (f32, trig_input) in [(false, false), (true, true)] {
            let o = split(plain(f32, 1, trig_input), chunk, units);
            assert!(assert_split(&cases, &o) > 10, "chunk {chunk}: the functions are split");
            let dir = tmp(&format!("plain_{chunk}_{units}_{f32}"));
            let n =
                if f32 { check_plain::<f32>(&dir, &cases, &o, 11) } else { check_plain::<f64>(&dir, &cases, &o, 11) };
            assert!(n > BATCH_OUTPUTS, "chunk {chunk}: only {n} outputs compared");
            if units > 1 {
                let found = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).count();
                assert!(dir.join(format!("t0_{}.c", units - 1)).exists(), "{found} files in {}", dir.display());
            }
        }
    }
}

#[test]
fn split_batches_equal_the_interpreter_for_every_width_precision_and_trig() {
    let cases = batch_cases();
    // (batch, f32, trig=input, chunk, units, vector width, layout=rows): the pairs of width and
    // precision `batched_lanes_…` does not compile, so that every pair is compiled once; each
    // trig mode in both precisions, both chunks, every unit count, each vector width and both
    // layouts (CI time: each line is a compile of every case in parts).
    let combos = [
        (2, true, false, 1, 1, "", false),
        (4, true, true, 7, 2, "-DROBOVEC_VBYTES=8", true),
        (8, false, true, 1, 3, "-DROBOVEC_VBYTES=64", false),
        (16, false, false, 7, 1, "", true),
    ];
    for (batch, f32, trig_input, chunk, units, width, rows) in combos {
        let dir = tmp(&format!("batch_{batch}_{f32}_{trig_input}_{chunk}_{units}_{rows}"));
        let mut o = split(plain(f32, batch, trig_input), chunk, units);
        if rows {
            o.layout = BatchLayout::Rows;
        }
        let extra: Vec<&str> = [width].into_iter().filter(|w| !w.is_empty()).collect();
        let n = if f32 {
            check_plain_with::<f32>(&dir, &cases, &o, 12, &extra)
        } else {
            check_plain_with::<f64>(&dir, &cases, &o, 12, &extra)
        };
        assert!(n > BATCH_OUTPUTS * batch as usize, "batch {batch}: only {n} outputs compared");
    }
}

/// The drop-in with its parts: inputs read by the entry point into `live[]` first, outputs
/// written by the last part, native callbacks whose later elements are read right after the
/// call, sensors (static functions and their dispatch).
#[test]
fn split_robotran_drop_ins_equal_the_interpreter() {
    let small = named_corpus_cases("atomise,zero-removal,balance", &BATCH_FILES);
    for (chunk, units) in [(1, 1), (7, 3), (3, 2)] {
        let o = CodegenC { abi: Abi::Robotran, chunk, units, ..CodegenC::default() };
        assert!(assert_split(&small, &o) > 10, "chunk {chunk}: the functions are split");
        let n = check_plain::<f64>(&tmp(&format!("robotran_{chunk}_{units}")), &small, &o, 13);
        assert!(n > 200, "chunk {chunk}: only {n} outputs compared");
    }
    // Every C file of the corpus, parts of 7 statements, in three units.
    let all = corpus_cases("atomise", true);
    let o = CodegenC { abi: Abi::Robotran, chunk: 7, units: 3, ..CodegenC::default() };
    let n = check_plain::<f64>(&tmp("robotran_corpus"), &all, &o, 14);
    assert!(n > 3_000, "only {n} outputs compared");
}

/// At `-O1` (where GCC inlines static functions called once, but not these: `noinline`) and
/// on the whole corpus, Matlab and Python files too.
#[test]
fn split_plain_code_equals_the_interpreter_on_every_corpus_file_at_o1() {
    let cases = corpus_cases("atomise,zero-removal,balance", false);
    let o = split(plain(false, 1, false), 25, 2);
    assert!(assert_split(&cases, &o) > 100, "the large functions are split");
    let n = check_plain_with::<f64>(&tmp("corpus_o1"), &cases, &o, 15, &["-O1"]);
    assert!(n > 5_000, "only {n} outputs compared");
}

/// Fused multiply-adds and `trig=inline` (a sin and a cos of one coordinate are computed by one
/// statement: never cut apart) in parts.
#[test]
fn split_contracted_and_inline_trig_code_equal_the_interpreter() {
    let cases: Vec<Case> =
        batch_cases().into_iter().map(|c| Case { label: c.label, m: run_pipeline(c.m, "contract") }).collect();
    for (batch, f32) in [(1, false), (8, true)] {
        let o = split(plain(f32, batch, true), 1, 2);
        let dir = tmp(&format!("contract_{batch}"));
        let n = if f32 { check_plain::<f32>(&dir, &cases, &o, 16) } else { check_plain::<f64>(&dir, &cases, &o, 16) };
        assert!(n > BATCH_OUTPUTS * batch as usize);
    }
    let cases = batch_cases();
    for (batch, f32, tol) in [(1, false, 1e-12), (4, true, 1e-4)] {
        let o = CodegenC {
            precision: if f32 { Precision::F32 } else { Precision::F64 },
            batch,
            trig: Trig::Inline,
            chunk: 1,
            units: 1,
            ..CodegenC::default()
        };
        let dir = tmp(&format!("inline_{batch}"));
        let (n, _) = if f32 {
            check_plain_tol::<f32>(&dir, &cases, &o, 17, &[], Some(tol))
        } else {
            check_plain_tol::<f64>(&dir, &cases, &o, 17, &[], Some(tol))
        };
        assert!(n > BATCH_OUTPUTS * batch as usize);
    }
}

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

fn run_ok(args: &[&str]) {
    let o = opt(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
}

fn cc(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new("cc").current_dir(dir).args(args).output().expect("a C compiler `cc` on PATH")
}

/// `-o model.c` with `units=3` writes `model.c`, `model_1.c`, `model_2.c` and `model.h`; the
/// header and the report list them; they compile and link with a second model's file
/// (another symbol, unsplit) in one program that includes both headers, and both give what
/// the same models give unsplit (`chunk=0`), bit for bit.
#[test]
fn units_are_written_beside_dash_o_listed_and_link_beside_another_model() {
    let dir = tmp("units_cli");
    let (c, report) = (dir.join("model.c"), dir.join("r.json"));
    run_ok(&[
        PENDULUM,
        "-passes=atomise,codegen<c;chunk=4;units=3;name=pend>",
        "-o",
        c.to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    let names = ["model.c", "model_1.c", "model_2.c"];
    for n in names {
        let text = std::fs::read_to_string(dir.join(n)).unwrap();
        assert!(text.contains("Translation unit") && text.contains("model.c, model_1.c, model_2.c"), "{n}: {text}");
    }
    let h = std::fs::read_to_string(dir.join("model.h")).unwrap();
    assert!(h.contains("3 translation units: model.c, model_1.c, model_2.c"), "{h}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let sources: Vec<String> = names.iter().map(|n| dir.join(n).display().to_string()).collect();
    assert_eq!(r["codegen"]["sources"], serde_json::json!(sources), "{r}");
    assert_eq!(r["codegen"]["header"], serde_json::json!(dir.join("model.h").display().to_string()));
    let parts = r["codegen"]["parts"].as_u64().unwrap();
    assert!(parts >= 10, "{r}");
    // The parts outside the main file are external, the ones inside static.
    let main = std::fs::read_to_string(&c).unwrap();
    assert!(main.contains("static ROBOVEC_NOINLINE void pend_part1("), "{main}");
    let unit2 = std::fs::read_to_string(dir.join("model_2.c")).unwrap();
    assert!(unit2.contains(&format!("\nROBOVEC_NOINLINE void pend_part{parts}(")), "{unit2}");

    // A second model: the same function unsplit, symbol `whole`, in its own file.
    run_ok(&[PENDULUM, "-passes=atomise,codegen<c;chunk=0;name=whole>", "-o", dir.join("other.c").to_str().unwrap()]);
    let driver = "#include <stdio.h>\n#include \"model.h\"\n#include \"other.h\"\n\
                  int main(void) {\n  double in[pend_INPUTS], a[pend_OUTPUTS], b[whole_OUTPUTS];\n  \
                  for (int i = 0; i < pend_INPUTS; i++) in[i] = 0.37 * i - 1.1;\n  pend(in, a);\n  whole(in, b);\n  \
                  for (int j = 0; j < pend_OUTPUTS; j++) printf(\"%a %a\\n\", a[j], b[j]);\n  return 0;\n}\n";
    std::fs::write(dir.join("main.c"), driver).unwrap();
    let o = cc(
        &dir,
        &[
            "-O1",
            "-std=c99",
            "-Wall",
            "-ffp-contract=off",
            "-o",
            "run",
            "main.c",
            "model.c",
            "model_1.c",
            "model_2.c",
            "other.c",
            "-lm",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = std::process::Command::new(dir.join("run")).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 2, "{text}");
    for l in text.lines() {
        let (a, b) = l.split_once(' ').unwrap();
        assert_eq!(a, b, "split and unsplit differ: {text}");
    }
}

#[test]
fn several_units_need_a_file_and_parts() {
    let o = opt(&[PENDULUM, "-passes=atomise,codegen<c;units=2>", "-o", "-"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("give -o a file path"), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    let o = opt(&[PENDULUM, "-passes=atomise,codegen<c;units=2;chunk=0>", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("`chunk=0` makes no parts"), "{}", stderr(&o));
}

/// All or nothing: when a unit's path cannot be written (a folder is there), nothing is
/// written, the main file and the header included.
#[test]
fn a_unit_that_cannot_be_written_leaves_no_file() {
    let dir = tmp("units_fail");
    std::fs::create_dir(dir.join("model_2.c")).unwrap();
    let c = dir.join("model.c");
    let o = opt(&[PENDULUM, "-passes=atomise,codegen<c;chunk=5;units=3>", "-o", c.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("model_2.c"), "{}", stderr(&o));
    for n in ["model.c", "model_1.c", "model.h"] {
        assert!(!dir.join(n).exists(), "{n} written");
    }
}

/// The generated split code is warning-free C99 under GCC's `-Wall -Wextra -pedantic`
/// (units, static parts, the live array) in both ABIs, but for unused parameters (a part need
/// not use `out` or `live`): GCC never sees `#pragma STDC FP_CONTRACT OFF`, which it would warn
/// about (`-ffp-contract=off` does its work); after `dce`, as values nothing reads are unused
/// variables split or not.
#[test]
fn split_code_compiles_cleanly_in_c99() {
    let dir = tmp("c99");
    for (abi, file) in [("plain", "p.c"), ("robotran", "r.c")] {
        run_ok(&[
            PENDULUM,
            &format!("-passes=atomise,dce,codegen<c;abi={abi};chunk=4;units=2>"),
            "-o",
            dir.join(file).to_str().unwrap(),
        ]);
    }
    std::fs::write(dir.join("mbs_data.h"), robovec_backends::c::robotran::mbs_data_header()).unwrap();
    for f in ["p.c", "p_1.c", "r.c", "r_1.c"] {
        let o = cc(&dir, &["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-Wno-unused-parameter", "-c", f]);
        assert!(o.status.success(), "{f}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

/// GCC 12's SLP vectoriser fuses `x1 - c, x2 + d` over two products into `vfmaddsub` even under
/// `-ffp-contract=off` (`codegen::c::SLP_GUARD`): the generated file turns SLP off for GCC 12
/// with FMA, so its assembly at `-O2 -mfma` has no fused instruction. Compile-only (`-S`), at
/// `-O2` because GCC vectorises straight-line code from `-O2` on; on GCC 12 the test first
/// shows that the same file without the guard does get the fused instruction (so it checks
/// something), on other compilers only that none appears.
#[cfg(target_arch = "x86_64")]
#[test]
fn gcc_12_does_not_fuse_products_and_alternating_add_sub_in_generated_code() {
    let dir = tmp("slp_guard");
    let ir = dir.join("f.rvir");
    std::fs::write(
        &ir,
        "func @f {\n  phase atomised\n  input %a\n  input %b\n  input %c\n  input %d\n  input %e\n  input %g\n  \
         %x1 = mul %a, %c\n  %x2 = mul %b, %d\n  %y1 = sub %x1, %e\n  %y2 = add %x2, %g\n  \
         output y1 = %y1\n  output y2 = %y2\n}\n",
    )
    .unwrap();
    run_ok(&[ir.to_str().unwrap(), "-passes=codegen<c>", "-o", dir.join("f.c").to_str().unwrap()]);
    let code = std::fs::read_to_string(dir.join("f.c")).unwrap();
    assert!(code.contains(robovec_backends::c::SLP_GUARD), "{code}");
    let fused = |file: &str| {
        let o = cc(&dir, &["-O2", "-mfma", "-ffp-contract=off", "-S", "-o", "-", file]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let asm = String::from_utf8(o.stdout).unwrap();
        asm.contains("vfmaddsub") || asm.contains("vfmsubadd")
    };
    assert!(!fused("f.c"), "the generated file fuses");
    let version = cc(&dir, &["-dumpfullversion"]);
    let gcc12 = String::from_utf8_lossy(&version.stdout).starts_with("12.")
        && !String::from_utf8_lossy(&cc(&dir, &["--version"]).stdout).contains("clang");
    if gcc12 {
        std::fs::write(dir.join("bare.c"), code.replace(robovec_backends::c::SLP_GUARD, "")).unwrap();
        assert!(fused("bare.c"), "GCC 12 without the guard: the test input no longer triggers the fusion");
    }
}
