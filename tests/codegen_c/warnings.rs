//! Generated C lives in other people's programs, whose builds often turn warnings into errors:
//! every configuration of `codegen<c>` compiles under GCC and Clang with `-std=c99 -Wall
//! -Wextra -pedantic -Werror` (helpers a function does not use, parameters a part or a function
//! of constants does not read, values Robotran computes and never uses, the contraction
//! pragma GCC does not know), and under Clang the outputs equal the interpreter's bit for bit,
//! as under GCC (`tests/codegen_c.rs`).

use std::process::Command;

use robovec_backends::c::{robotran, Abi, BatchLayout, CodegenC, Trig};

use super::{
    batch_cases, check_plain_tol, check_plain_with, corpus_cases, named_corpus_cases, plain, run_pipeline, Case,
    BATCH_OUTPUTS,
};
use crate::common::tmp;

/// Both compilers, each with the flags of a strict project build, and how far each goes.
/// GCC compiles to an object: it reports unused static functions and constants only once
/// its call graph is built, after the front end (`-fsyntax-only` misses them). Clang's
/// warnings at `-O0` all come from its front end (unused functions included), so it stops
/// there (`-fsyntax-only`): the same diagnostics at a fifth of the time. Clang's object code
/// is compiled and run by `clang_builds_equal_the_interpreter`.
const COMPILERS: [(&str, &str); 2] = [("gcc", "-c"), ("clang", "-fsyntax-only")];
const STRICT: [&str; 6] = ["-std=c99", "-O0", "-Wall", "-Wextra", "-pedantic", "-Werror"];

/// Corpus files that hold what warns: a value nothing reads (Jeep's `extforces` computes
/// `Dz413` and never uses it), a function of constants with no input (car43's `link3D`),
/// callbacks (Jeep, the Segway's `extforces`), sensors and a square root (m454, the tricycle).
fn warning_cases() -> Vec<Case> {
    let wanted = [
        "jeep__mbs_extforces",
        "car43__mbs_link3D",
        "frank_segway__mbs_extforces",
        "m454__mbs_sensor",
        "tricycle__mbs_gensensor",
        "frank_segway__mbs_invdyna",
    ];
    named_corpus_cases("atomise", &wanted)
}

#[test]
fn every_configuration_compiles_warning_free_under_gcc_and_clang() {
    let dir = tmp("warnings");
    std::fs::write(dir.join("mbs_data.h"), robotran::mbs_data_header()).unwrap();
    let configs: Vec<(&str, CodegenC)> = vec![
        ("plain", CodegenC::default()),
        ("trig=inline", CodegenC { trig: Trig::Inline, ..CodegenC::default() }),
        ("batch=4", plain(false, 4, false)),
        ("batch=8 f32 trig=input layout=rows", CodegenC { layout: BatchLayout::Rows, ..plain(true, 8, true) }),
        ("batch=4 trig=inline chunk=300", CodegenC { batch: 4, trig: Trig::Inline, chunk: 300, ..CodegenC::default() }),
        ("chunk=300", CodegenC { chunk: 300, ..CodegenC::default() }),
        ("abi=robotran", CodegenC { abi: Abi::Robotran, ..CodegenC::default() }),
        ("abi=robotran chunk=300", CodegenC { abi: Abi::Robotran, chunk: 300, ..CodegenC::default() }),
        ("abi=robotran trig=inline", CodegenC { abi: Abi::Robotran, trig: Trig::Inline, ..CodegenC::default() }),
    ];
    let mut compiled = 0;
    let atomised = warning_cases();
    // Fused multiply-adds (`contract`) under the configurations that write them differently:
    // C99 `fma` in one state, `robovec_fma` on vectors of doubles and of floats, and Robotran's
    // ABI (CI time: each configuration is twelve compiles).
    let fused = ["plain", "batch=4", "batch=8 f32 trig=input layout=rows", "abi=robotran"];
    for pipeline in ["default<ops>", "default<ops>,contract"] {
        let cases: Vec<Case> =
            atomised.iter().map(|c| Case { label: c.label.clone(), m: run_pipeline(c.m.clone(), pipeline) }).collect();
        for (label, o) in configs.iter().filter(|(l, _)| !pipeline.ends_with("contract") || fused.contains(l)) {
            for case in &cases {
                let art = o.emit(&case.m).unwrap_or_else(|e| panic!("{} {label}: {e}", case.label));
                let file = dir.join("t.c");
                std::fs::write(&file, &art.code.main).unwrap();
                for (compiler, stage) in COMPILERS {
                    let out = Command::new(compiler)
                        .current_dir(&dir)
                        .args(STRICT)
                        .args([stage, "t.c", "-o", "t.o"])
                        .output()
                        .unwrap_or_else(|e| panic!("{compiler} ({e}): scripts/test.sh installs gcc and clang"));
                    assert!(
                        out.status.success(),
                        "{} after {pipeline}, {label}, {compiler}:\n{}",
                        case.label,
                        String::from_utf8_lossy(&out.stderr)
                    );
                    compiled += 1;
                }
            }
        }
    }
    assert_eq!(compiled, (9 + fused.len()) * 6 * 2);
}

/// Clang's build of the generated C computes what the interpreter computes, bit for bit (one
/// state and a batch in f32), and within the inline sin/cos' error with `trig=inline`.
#[test]
fn clang_builds_equal_the_interpreter() {
    let cases = batch_cases();
    let n = check_plain_with::<f64>(&tmp("clang_f64"), &cases, &plain(false, 1, false), 8, &["cc=clang"]);
    assert!(n > BATCH_OUTPUTS, "only {n} outputs compared");
    let n = check_plain_with::<f32>(&tmp("clang_f32_batch"), &cases, &plain(true, 8, true), 8, &["cc=clang"]);
    assert!(n > BATCH_OUTPUTS * 8, "only {n} outputs compared");
    let o = CodegenC { abi: Abi::Robotran, trig: Trig::Inline, chunk: 500, ..CodegenC::default() };
    let (n, _) = check_plain_tol::<f64>(
        &tmp("clang_robotran"),
        &corpus_cases("default<ops>", true),
        &o,
        8,
        &["cc=clang"],
        Some(1e-12),
    );
    assert!(n > 3_000, "only {n} outputs compared");
}
