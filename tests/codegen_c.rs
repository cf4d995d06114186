//! Issue 11, "Correct, by execution": the C that `codegen<c>` writes is compiled with the
//! system C compiler (`cc -O0 -ffp-contract=off`: gcc -O1 takes over a minute on the largest corpus function, -O0 2 s; x86-64 and AArch64 round the same at every level), run on pseudo-random inputs and compared
//! bit for bit with robovec's interpreter (`robovec_ir::interp::eval`) in f64 and f32.
//!
//! One build per test: every module of the test is one translation unit (`t<k>.c`, symbols
//! prefixed `t<k>` with `name=`), plus the user callbacks (C definitions of the interpreter's
//! documented stand-in, `callback_standin`) and a driver that reads the inputs as raw reals
//! and prints every output's bits in hex.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use robovec_ir::interp::{callback_standin, eval, pseudo_random_input, Float};
use robovec_ir::{Callee, Def, Module, TrigFn};
use robovec_passes::codegen::c::{split_callee, CodegenC};
use robovec_passes::codegen::input_values;
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::common::{corpus_files, is_loop_file, tmp};

/// A module to test, with a label for messages.
pub struct Case {
    label: String,
    m: Module,
}

/// Runs `pipeline` (which must not end in codegen) on `m`.
fn run_pipeline(mut m: Module, pipeline: &str) -> Module {
    let pm = PassManager::new(pipeline, Instrumentation::default()).unwrap();
    pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink()).unwrap();
    m
}

/// Every straight-line corpus file (C, Matlab, Python) after `pipeline`.
fn corpus_cases(pipeline: &str, only_c: bool) -> Vec<Case> {
    let files: Vec<PathBuf> = corpus_files()
        .into_iter()
        .filter(|p| !is_loop_file(p) && (!only_c || p.extension().is_some_and(|e| e == "c")))
        .collect();
    assert!(files.len() >= 20, "corpus: {} straight-line files", files.len());
    files
        .iter()
        .map(|p| {
            let (m, _) = robovec::driver::load(p.to_str().unwrap())
                .unwrap_or_else(|f| panic!("{}: {}", p.display(), f.message()));
            Case { label: p.file_name().unwrap().to_string_lossy().into_owned(), m: run_pipeline(m, pipeline) }
        })
        .collect()
}

fn cc(dir: &Path, files: &[String], opt: &str) -> PathBuf {
    let exe = dir.join("run");
    let mut cmd = Command::new("cc");
    cmd.current_dir(dir).args([opt, "-ffp-contract=off", "-w", "-o"]).arg(&exe).args(files).arg("-lm");
    let o = cmd.output().expect("a C compiler `cc` on PATH (.ci/run installs gcc)");
    assert!(o.status.success(), "cc failed in {}:\n{}", dir.display(), String::from_utf8_lossy(&o.stderr));
    exe
}

/// Callee, element and argument count of every user callback of `m`.
fn callback_uses(m: &Module, out: &mut Vec<(Callee, usize)>) {
    for f in &m.functions {
        for &v in &f.body {
            if let Def::Call(c, args) = &f.value(v).def {
                if !robovec_passes::codegen::c::is_sqrt(c, args.len()) && !out.iter().any(|(k, _)| k == c) {
                    out.push((c.clone(), args.len()));
                }
            }
        }
    }
}

fn lit<T: Float>(x: T, f32: bool) -> String {
    robovec_passes::codegen::literal::hex(x.to_f64(), f32)
}

/// C definitions of the callbacks computing exactly [`callback_standin`]: weight `k` is the
/// stand-in of the unit vector `e_k` (exact: the other terms are signed zeros).
fn callbacks_c<T: Float>(uses: &[(Callee, usize)], f32: bool, robotran_abi: bool) -> String {
    let real = if f32 { "float" } else { "double" };
    let mut bases: Vec<(String, usize)> = Vec::new();
    for (c, _) in uses {
        let (base, idx) = split_callee(c).unwrap();
        let n = idx.len();
        if !bases.iter().any(|(b, _)| *b == base) {
            bases.push((base, n));
        }
    }
    let mut s = String::from("#include <stdlib.h>\n");
    for (base, nidx) in &bases {
        let idx_params: String = (1..=*nidx).map(|i| format!("int index{i}, ")).collect();
        let _ = writeln!(s, "{real} {base}({idx_params}int elem, int nargs, const {real} *a)\n{{");
        for (c, n) in uses.iter().filter(|(c, _)| split_callee(c).unwrap().0 == *base) {
            let idx = split_callee(c).unwrap().1;
            let mut cond: Vec<String> = idx.iter().enumerate().map(|(i, x)| format!("index{} == {x}", i + 1)).collect();
            cond.push(format!("elem == {}", c.elem.unwrap_or(0)));
            cond.push(format!("nargs == {n}"));
            let w = |k: usize| {
                let mut e = vec![T::from_f64(0.0); *n];
                if *n == 0 {
                    return callback_standin::<T>(c, &[]);
                }
                e[k] = T::from_f64(1.0);
                callback_standin(c, &e)
            };
            let body = if *n == 0 {
                format!("return {};", lit(w(0), f32))
            } else {
                let mut b = format!("{real} acc = {} * a[0];", lit(w(0), f32));
                for k in 1..*n {
                    let _ = write!(b, " acc = acc + {} * a[{k}];", lit(w(k), f32));
                }
                b + " return acc;"
            };
            let _ = writeln!(s, "  if ({}) {{ {body} }}", cond.join(" && "));
        }
        s += "  abort();\n}\n";
    }
    let _ = robotran_abi;
    s
}

/// The value of input `name` in lane `lane` under `seed`, as the test feeds it.
fn input_value(name: &str, seed: u64, lane: u32) -> f64 {
    pseudo_random_input(name, seed.wrapping_add(lane as u64 * 7919))
}

fn same<T: Float>(got: u64, want: T) -> bool {
    let w = want.to_f64();
    (w.is_nan() && f64::from_bits(got).is_nan()) || got == w.to_bits()
}

/// Emits every case with `o` (plain ABI), compiles one program, runs it on the inputs of
/// `seed` and compares every output of every lane with the interpreter in precision `T`.
/// Returns the number of output values compared.
fn check_plain<T: Float>(dir: &Path, cases: &[Case], o: &CodegenC, seed: u64) -> usize {
    let f32 = o.f32;
    let real = o.real();
    let w = o.batch;
    let mut files = vec!["main.c".to_string(), "callbacks.c".to_string()];
    let mut uses = Vec::new();
    let mut main = format!("#include <stdio.h>\n#include <string.h>\n#include <stdint.h>\n");
    let mut calls = String::new();
    let mut inputs: Vec<u8> = Vec::new();
    let mut want: Vec<(String, T)> = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let ok = CodegenC { name: Some(format!("t{k}")), ..o.clone() };
        let art = ok.emit(&case.m).unwrap_or_else(|e| panic!("{}: {e}", case.label));
        std::fs::write(dir.join(format!("t{k}.c")), &art.code.main).unwrap();
        files.push(format!("t{k}.c"));
        callback_uses(&case.m, &mut uses);
        for (f, iface) in case.m.functions.iter().zip(&art.interfaces) {
            let (ni, no) = (iface.inputs.len(), iface.outputs.len());
            let _ = writeln!(main, "void {}(const {real} *restrict in, {real} *restrict out);", iface.symbol);
            let _ = writeln!(
                calls,
                "  {{ static {real} in[{}], out[{}]; if (fread(in, sizeof *in, {}, stdin) != {}) return 1; {}(in, out); \
                 for (int i = 0; i < {}; i++) {{ double x = out[i]; uint64_t b; memcpy(&b, &x, 8); printf(\"%016llx\\n\", (unsigned long long)b); }} }}",
                (ni * w as usize).max(1),
                (no * w as usize).max(1),
                ni * w as usize,
                ni * w as usize,
                iface.symbol,
                no * w as usize
            );
            // Inputs of every lane; trig inputs are the interpreter's own sin/cos of their
            // joint coordinate in precision T.
            let ins = input_values(f, o.trig_input);
            let lane_value = |v: robovec_ir::Value, lane: u32| -> T {
                match f.value(v).def {
                    Def::Trig(t, q) => {
                        let x = T::from_f64(input_value(f.name_of(q), seed, lane));
                        match t {
                            TrigFn::Sin => x.sin(),
                            TrigFn::Cos => x.cos(),
                        }
                    }
                    _ => T::from_f64(input_value(f.name_of(v), seed, lane)),
                }
            };
            for &v in &ins {
                for lane in 0..w {
                    let x = lane_value(v, lane);
                    if f32 {
                        inputs.extend((x.to_f64() as f32).to_le_bytes());
                    } else {
                        inputs.extend(x.to_f64().to_le_bytes());
                    }
                }
            }
            let per_lane: Vec<Vec<(String, T)>> =
                (0..w).map(|lane| eval::<T>(f, |name| input_value(name, seed, lane))).collect();
            for j in 0..no {
                for lane in 0..w as usize {
                    let (n, x) = &per_lane[lane][j];
                    want.push((format!("{} @{} {n} lane {lane}", case.label, f.name), *x));
                }
            }
        }
    }
    main += &format!("int main(void)\n{{\n{calls}  return 0;\n}}\n");
    std::fs::write(dir.join("main.c"), main).unwrap();
    std::fs::write(dir.join("callbacks.c"), callbacks_c::<T>(&uses, f32, false)).unwrap();
    let exe = cc(dir, &files, "-O0");
    let mut child =
        Command::new(&exe).stdin(std::process::Stdio::piped()).stdout(std::process::Stdio::piped()).spawn().unwrap();
    std::io::Write::write_all(child.stdin.as_mut().unwrap(), &inputs).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{} exited with {:?}", exe.display(), out.status);
    let got: Vec<u64> =
        String::from_utf8(out.stdout).unwrap().lines().map(|l| u64::from_str_radix(l, 16).unwrap()).collect();
    assert_eq!(got.len(), want.len(), "number of outputs printed");
    let bad: Vec<String> = got
        .iter()
        .zip(&want)
        .filter(|(g, (_, x))| !same(**g, *x))
        .map(|(g, (what, x))| format!("{what}: C {:e} vs interpreter {:e}", f64::from_bits(*g), x.to_f64()))
        .take(10)
        .collect();
    assert!(bad.is_empty(), "{} ({}): outputs differ from the interpreter:\n{}", dir.display(), real, bad.join("\n"));
    want.len()
}

fn plain(f32: bool, batch: u32, trig_input: bool) -> CodegenC {
    CodegenC { f32, batch, trig_input, ..CodegenC::default() }
}

#[test]
fn plain_f64_equals_the_interpreter_bit_for_bit_on_every_corpus_file() {
    for (k, pipeline) in ["atomise", "atomise,zero-removal,balance"].into_iter().enumerate() {
        let cases = corpus_cases(pipeline, false);
        let n = check_plain::<f64>(&tmp(&format!("plain_f64_{k}")), &cases, &plain(false, 1, false), 1);
        assert!(n > 5_000, "{pipeline}: only {n} outputs compared");
    }
}

#[test]
fn plain_f32_equals_the_interpreter_bit_for_bit_on_every_corpus_file() {
    for (k, pipeline) in ["atomise", "atomise,zero-removal,balance"].into_iter().enumerate() {
        let cases = corpus_cases(pipeline, false);
        let n = check_plain::<f32>(&tmp(&format!("plain_f32_{k}")), &cases, &plain(true, 1, true), 2);
        assert!(n > 5_000, "{pipeline}: only {n} outputs compared");
    }
}
