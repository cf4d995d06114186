//! Helpers shared by the integration tests.
#![allow(dead_code, reason = "each test module uses a different subset")]

use std::path::PathBuf;

/// `../shared/corpus/robotran`; panics (so the test fails) when it is missing.
pub fn corpus_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/robotran");
    assert!(d.is_dir(), "the Robotran corpus is missing at {} (CI needs ../shared beside the repository)", d.display());
    d
}

/// Every corpus source file (`.c`, `.m`, `.py`), sorted.
pub fn corpus_files() -> Vec<PathBuf> {
    let mut v = Vec::new();
    for sub in ["c", "matlab", "python"] {
        for e in std::fs::read_dir(corpus_dir().join(sub)).expect("corpus folder") {
            let p = e.expect("dir entry").path();
            if p.extension().is_some_and(|x| x == "c" || x == "m" || x == "py") {
                v.push(p);
            }
        }
    }
    v.sort();
    assert!(v.len() >= 30, "corpus looks incomplete: {} files", v.len());
    v
}

/// True for the files with loops (accelred/invdynared), which front ends reject.
pub fn is_loop_file(p: &std::path::Path) -> bool {
    let n = p.file_name().unwrap().to_string_lossy();
    n.contains("accelred") || n.contains("invdynared")
}

/// Runs `robovec-opt` with `args` from the package root (so `examples/…` paths resolve).
pub fn opt(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("robovec-opt runs")
}

/// The stderr of a run, as text.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh, empty folder `CARGO_TARGET_TMPDIR/<calling test file>/<name>` (removed first).
#[track_caller]
pub fn tmp(name: &str) -> PathBuf {
    let caller = std::path::Path::new(std::panic::Location::caller().file());
    let group = caller.file_stem().map_or_else(|| "tests".into(), |s| s.to_string_lossy().into_owned());
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(group).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `dir/unit` as a translation unit that `#include`s `files` (in `dir`), as a program that
/// holds several generated files in one does (their helpers once, `ROBOVEC_HELPERS`), and
/// returns `unit`. Compiled one by one, each small generated file's helpers (and
/// `<immintrin.h>` in a batch) were most of the C tests' compile time.
pub fn including_unit(dir: &std::path::Path, unit: &str, files: &[String]) -> String {
    let text: String = files.iter().map(|f| format!("#include \"{f}\"\n")).collect();
    std::fs::write(dir.join(unit), text).unwrap();
    unit.to_string()
}

/// Compiles `files` (C, in `dir`) with the system compiler, `flags` and `-lm` into `dir/run`,
/// and returns its path; the compiler's message is the panic's when it fails.
pub fn compile_c(dir: &std::path::Path, flags: &[&str], files: &[&str]) -> PathBuf {
    let exe = dir.join("run");
    let o = std::process::Command::new("cc")
        .current_dir(dir)
        .args(flags)
        .arg("-o")
        .arg(&exe)
        .args(files)
        .arg("-lm")
        .output()
        .expect("cc (scripts/test.sh installs gcc)");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    exe
}

/// Runs `exe` with `input` on its stdin (it must exit 0) and reads its stdout: one hexadecimal
/// integer a line, the bits of a result as a test's C driver prints them.
pub fn run_hex_lines(exe: &std::path::Path, input: &[u8]) -> Vec<u64> {
    use std::io::Write as _;
    let mut child = std::process::Command::new(exe)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{} failed", exe.display());
    String::from_utf8(out.stdout).unwrap().lines().map(|l| u64::from_str_radix(l, 16).unwrap()).collect()
}

/// The path of a robot of `example-robot-data` (`rel` under its `robots/` folder) in the
/// Pinocchio environment `scripts/test.sh` creates (`target/pinocchio-venv`); `None` (a note)
/// when the environment is missing outside CI, a panic in CI.
pub fn robot_urdf(rel: &str) -> Option<PathBuf> {
    crate::pinocchio::python()?;
    let lib = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/pinocchio-venv/lib");
    let found = std::fs::read_dir(&lib)
        .ok()?
        .flatten()
        .map(|d| d.path().join("site-packages/cmeel.prefix/share/example-robot-data/robots").join(rel));
    let path = found.into_iter().find(|p| p.exists());
    assert!(path.is_some() || std::env::var_os("CI").is_none(), "{rel} is not in {}", lib.display());
    path
}

/// Runs `robovec-opt` on `args` with `-report` and `-o` into `dir` (`report.json`, `out.rvir`),
/// asserts exit 0, and returns the report and the module written.
pub fn opt_to_ir(dir: &std::path::Path, args: &[&str]) -> (serde_json::Value, robovec_ir::Module) {
    let (ir, report) = (dir.join("out.rvir"), dir.join("report.json"));
    let report_arg = format!("-report={}", report.display());
    let mut all = args.to_vec();
    all.extend([report_arg.as_str(), "-o", ir.to_str().unwrap()]);
    let o = opt(&all);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let m = robovec_ir::text::parse(&std::fs::read_to_string(&ir).unwrap()).unwrap();
    (r, m)
}
