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

use robovec_backends::c::{robotran, split_callee, Abi, BatchLayout, CodegenC, Precision, Trig};
use robovec_backends::input_values;
use robovec_ir::interp::{callback_standin, eval, pseudo_random_input, Float};
use robovec_ir::{Callee, Def, Module, TrigFn};
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::common::{corpus_files, including_unit, is_loop_file, tmp};

mod split;
mod trig;
mod warnings;

/// A module to test, with a label for messages.
pub struct Case {
    label: String,
    m: Module,
}

/// Runs `pipeline` (which must not end in codegen) on `m`.
fn run_pipeline(mut m: Module, pipeline: &str) -> Module {
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default()).unwrap();
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
    load_cases(&files, pipeline)
}

/// The C corpus files whose names start with one of `prefixes` (one file each, or the test
/// fails), after `pipeline`; only those are loaded.
fn named_corpus_cases(pipeline: &str, prefixes: &[&str]) -> Vec<Case> {
    let files: Vec<PathBuf> = corpus_files()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "c"))
        .filter(|p| prefixes.iter().any(|w| p.file_name().unwrap().to_string_lossy().starts_with(w)))
        .collect();
    assert_eq!(files.len(), prefixes.len(), "corpus files named {prefixes:?}: {files:?}");
    load_cases(&files, pipeline)
}

fn load_cases(files: &[PathBuf], pipeline: &str) -> Vec<Case> {
    files
        .iter()
        .map(|p| {
            let (m, _) = robovec::driver::load(p.to_str().unwrap())
                .unwrap_or_else(|f| panic!("{}: {}", p.display(), f.message()));
            Case { label: p.file_name().unwrap().to_string_lossy().into_owned(), m: run_pipeline(m, pipeline) }
        })
        .collect()
}

/// The corpus files of the batch and split tests: a forward dynamics (the `LᵀDL`'s divisions;
/// m454's, 257 statements before `atomise`: the tricycle's, 7× as long, made most of these
/// tests' C and of their CI time), native callbacks (the Segway's `extforces`), link forces
/// with a square root (Jeep) and sensors (m454).
const BATCH_FILES: [&str; 4] =
    ["m454__mbs_dirdyna", "frank_segway__mbs_extforces", "jeep__mbs_link", "m454__mbs_sensor"];

/// Compiles `files` in `dir` with `flags` (an optimisation level first, then e.g. a
/// `-DROBOVEC_VBYTES=` vector width) into `dir/run`.
fn cc(dir: &Path, files: &[String], flags: &[&str]) -> PathBuf {
    let exe = dir.join("run");
    // `cc=NAME` among the flags picks the compiler (`warnings.rs` runs the checks under Clang).
    let compiler = flags.iter().find_map(|f| f.strip_prefix("cc=")).unwrap_or("cc");
    let flags: Vec<&str> = flags.iter().copied().filter(|f| !f.starts_with("cc=")).collect();
    let mut cmd = Command::new(compiler);
    cmd.current_dir(dir).args(&flags).args(["-ffp-contract=off", "-w", "-o"]).arg(&exe).args(files).arg("-lm");
    let o = cmd
        .output()
        .unwrap_or_else(|e| panic!("C compiler `{compiler}` ({e}): scripts/test.sh installs gcc and clang"));
    assert!(o.status.success(), "cc failed in {}:\n{}", dir.display(), String::from_utf8_lossy(&o.stderr));
    exe
}

/// Callee, element and argument count of every user callback of `m`.
fn callback_uses(m: &Module, out: &mut Vec<(Callee, usize)>) {
    for f in &m.functions {
        for &v in &f.body {
            if let Def::Call(c, args) = &f.value(v).def {
                if !robovec_backends::c::is_intrinsic(c, args.len()) && !out.iter().any(|(k, _)| k == &**c) {
                    out.push(((**c).clone(), args.len()));
                }
            }
        }
    }
}

fn lit<T: Float>(x: T, f32: bool) -> String {
    robovec_backends::literal::hex(x.to_f64(), f32)
}

/// The stand-in of callee `c` on `n` operands `a[0..n]` as C statements ending in
/// `return`: weight `k` is the stand-in of the unit vector `e_k` (exact: the other terms are
/// signed zeros).
fn standin_c<T: Float>(c: &Callee, n: usize, f32: bool) -> String {
    let real = if f32 { "float" } else { "double" };
    let w = |k: usize| {
        let mut e = vec![T::from_f64(0.0); n];
        e[k] = T::from_f64(1.0);
        callback_standin(c, &e)
    };
    if n == 0 {
        return format!("return {};", lit(callback_standin::<T>(c, &[]), f32));
    }
    let mut b = format!("{real} acc = {} * a[0];", lit(w(0), f32));
    for k in 1..n {
        let _ = write!(b, " acc = acc + {} * a[{k}];", lit(w(k), f32));
    }
    b + " return acc;"
}

/// C definitions of the callbacks computing exactly [`callback_standin`]: the adapter form
/// `REAL user_X(int index1, …, int elem, int nargs, const REAL *a)` (plain ABI), or with
/// `robotran_abi` MBsysC's native signatures (`double *user_ExtForces(double PxF[4], double
/// RxF[4][4], …, MbsData *s, double tsim, int ixF)`, `double user_LinkForces(double Z, double
/// Zd, MbsData *s, double tsim, int ilnk)`), which flatten their arrays back into the IR's
/// operand order (row-major elements from index 1, then `tsim`; the C front end's order) and
/// return the stand-in of every element read (a static 1-based vector).
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
    if robotran_abi {
        s += "#include \"mbs_data.h\"\n";
    }
    for (base, nidx) in &bases {
        let mine = || uses.iter().filter(|(c, _)| split_callee(c).unwrap().0 == *base);
        if robotran_abi {
            assert_eq!(*nidx, 1, "{base}: one integer index");
            if base.ends_with("ExtForces") {
                let _ = writeln!(
                    s,
                    "double *{base}(double PxF[4], double RxF[4][4], double VxF[4], double OMxF[4], double AxF[4], \
                     double OMPxF[4], MbsData *s, double tsim, int ixF)\n{{\n  static double r[10]; double a[25]; int n = 0; (void)s;\n  \
                     for (int i = 1; i <= 3; i++) a[n++] = PxF[i];\n  \
                     for (int i = 1; i <= 3; i++) for (int j = 1; j <= 3; j++) a[n++] = RxF[i][j];\n  \
                     for (int i = 1; i <= 3; i++) a[n++] = VxF[i];\n  for (int i = 1; i <= 3; i++) a[n++] = OMxF[i];\n  \
                     for (int i = 1; i <= 3; i++) a[n++] = AxF[i];\n  for (int i = 1; i <= 3; i++) a[n++] = OMPxF[i];\n  \
                     a[n++] = tsim;\n  for (int i = 0; i < 10; i++) r[i] = 0.0 / 0.0;"
                );
                for (c, n) in mine() {
                    assert_eq!(*n, 25, "{}: operands", c.name);
                    let (ix, elem) = (split_callee(c).unwrap().1[0], c.elem.unwrap());
                    let body = standin_c::<T>(c, *n, f32).replace("return acc;", &format!("r[{elem}] = acc;"));
                    let _ = writeln!(s, "  if (ixF == {ix}) {{ {body} }}");
                }
                s += "  return r;\n}\n";
            } else {
                let _ = writeln!(
                    s,
                    "double {base}(double Z, double Zd, MbsData *s, double tsim, int ilnk)\n{{\n  \
                     double a[3] = {{Z, Zd, tsim}}; (void)s;"
                );
                for (c, n) in mine() {
                    assert_eq!((*n, c.elem), (3, None), "{}: operands", c.name);
                    let ix = split_callee(c).unwrap().1[0];
                    let _ = writeln!(s, "  if (ilnk == {ix}) {{ {} }}", standin_c::<T>(c, *n, f32));
                }
                s += "  abort();\n}\n";
            }
            continue;
        }
        let idx_params: String = (1..=*nidx).map(|i| format!("int index{i}, ")).collect();
        let _ = writeln!(s, "{real} {base}({idx_params}int elem, int nargs, const {real} *a)\n{{");
        for (c, n) in mine() {
            let idx = split_callee(c).unwrap().1;
            let mut cond: Vec<String> = idx.iter().enumerate().map(|(i, x)| format!("index{} == {x}", i + 1)).collect();
            cond.push(format!("elem == {}", c.elem.unwrap_or(0)));
            cond.push(format!("nargs == {n}"));
            let _ = writeln!(s, "  if ({}) {{ {} }}", cond.join(" && "), standin_c::<T>(c, *n, f32));
        }
        s += "  abort();\n}\n";
    }
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
    check_plain_with::<T>(dir, cases, o, seed, &[])
}

/// [`check_plain`] with extra C compiler flags (`-DROBOVEC_VBYTES=N`: the batch's vector width).
fn check_plain_with<T: Float>(dir: &Path, cases: &[Case], o: &CodegenC, seed: u64, extra: &[&str]) -> usize {
    check_plain_tol::<T>(dir, cases, o, seed, extra, None).0
}

/// [`check_plain_with`], comparing bit for bit (`tol: None`) or within a relative error
/// (`trig=inline`, whose sin/cos are not libm's): output `y` of a function whose outputs have mean
/// magnitude `m` may differ from the interpreter's `x` by `tol · (|x| + m)` (the `m` term allows
/// for cancellation: an output near zero made of large terms). Returns the number of outputs
/// compared and the largest `|y − x| / (|x| + m)` seen.
fn check_plain_tol<T: Float>(
    dir: &Path,
    cases: &[Case],
    o: &CodegenC,
    seed: u64,
    extra: &[&str],
    tol: Option<f64>,
) -> (usize, f64) {
    let f32 = o.f32();
    let real = o.real();
    let w = o.batch;
    // Per unit index, the cases' files: `t{k}.c` at 0, `t{k}_{u}.c` (unit `u` of case `k`) at `u`.
    let mut units: Vec<Vec<String>> = vec![Vec::new()];
    let mut uses = Vec::new();
    let robotran_abi = o.abi == Abi::Robotran;
    let mut main = String::from("#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\n#include <stdint.h>\n");
    if robotran_abi {
        std::fs::write(dir.join("mbs_data.h"), robotran::mbs_data_header()).unwrap();
        main += &robotran_globals(cases);
    }
    let mut calls = String::new();
    let mut inputs: Vec<u8> = Vec::new();
    let mut want: Vec<(String, T)> = Vec::new();
    // Per output, the function it belongs to (an index into `scale`).
    let mut group: Vec<usize> = Vec::new();
    let mut scale: Vec<f64> = Vec::new();
    for (k, case) in cases.iter().enumerate() {
        let ok = CodegenC { name: Some(format!("t{k}")), ..o.clone() };
        let art = ok.emit(&case.m).unwrap_or_else(|e| panic!("{}: {e}", case.label));
        std::fs::write(dir.join(format!("t{k}.c")), &art.code.main).unwrap();
        units[0].push(format!("t{k}.c"));
        // `units=K`: the further translation units, linked with the rest.
        for (u, text) in art.code.units.iter().enumerate() {
            let name = format!("t{k}_{}.c", u + 1);
            std::fs::write(dir.join(&name), text).unwrap();
            if units.len() <= u + 1 {
                units.push(Vec::new());
            }
            units[u + 1].push(name);
        }
        callback_uses(&case.m, &mut uses);
        for (f, iface) in case.m.functions.iter().zip(&art.interfaces) {
            let (ni, no) = (iface.inputs.len(), iface.outputs.len());
            if robotran_abi {
                let proto =
                    art.code.companions[0].1.lines().find(|l| l.starts_with(&format!("void {}(", iface.symbol)));
                let proto = proto.expect("prototype in the header");
                if !main.contains(proto) {
                    main += proto;
                    main += "\n";
                }
                calls += &robotran_call(f, iface);
            } else {
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
            }
            // Inputs of every lane; trig inputs are the interpreter's own sin/cos of their
            // joint coordinate in precision T.
            let ins = input_values(f, o.trig == Trig::Input);
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
            // Element i of lane l at i*W + l, or at l*n + i with `layout=rows` (n elements a
            // state: the inputs, or the outputs).
            let rows = w > 1 && o.layout == BatchLayout::Rows;
            let order = |n: usize| -> Vec<(usize, u32)> {
                if rows {
                    (0..w).flat_map(|l| (0..n).map(move |i| (i, l))).collect()
                } else {
                    (0..n).flat_map(|i| (0..w).map(move |l| (i, l))).collect()
                }
            };
            for (i, lane) in order(ins.len()) {
                let x = lane_value(ins[i], lane);
                if f32 {
                    inputs.extend((x.to_f64() as f32).to_le_bytes());
                } else {
                    inputs.extend(x.to_f64().to_le_bytes());
                }
            }
            let per_lane: Vec<Vec<(String, T)>> =
                (0..w).map(|lane| eval::<T>(f, |name| input_value(name, seed, lane))).collect();
            let mut mag = (0.0, 0usize);
            for (j, lane) in order(no) {
                let (n, x) = &per_lane[lane as usize][j];
                want.push((format!("{} @{} {n} lane {lane}", case.label, f.name), *x));
                group.push(scale.len());
                if x.to_f64().is_finite() {
                    mag = (mag.0 + x.to_f64().abs(), mag.1 + 1);
                }
            }
            scale.push(mag.0 / mag.1.max(1) as f64);
        }
    }
    let init = if robotran_abi { "  robovec_test_alloc();\n" } else { "" };
    main += &format!("int main(void)\n{{\n{init}{calls}  return 0;\n}}\n");
    std::fs::write(dir.join("main.c"), main).unwrap();
    std::fs::write(dir.join("callbacks.c"), callbacks_c::<T>(&uses, f32, robotran_abi)).unwrap();
    let flags: Vec<&str> = ["-O0"].into_iter().chain(extra.iter().copied()).collect();
    // One translation unit per unit index: every case's main file in one, their second units in
    // another, … (each case's units still linked across translation units).
    let mut files = vec!["main.c".to_string(), "callbacks.c".to_string()];
    files.extend(units.iter().enumerate().map(|(u, names)| including_unit(dir, &format!("unit{u}.c"), names)));
    let exe = cc(dir, &files, &flags);
    let mut child =
        Command::new(&exe).stdin(std::process::Stdio::piped()).stdout(std::process::Stdio::piped()).spawn().unwrap();
    std::io::Write::write_all(child.stdin.as_mut().unwrap(), &inputs).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{} exited with {:?}", exe.display(), out.status);
    let got: Vec<u64> =
        String::from_utf8(out.stdout).unwrap().lines().map(|l| u64::from_str_radix(l, 16).unwrap()).collect();
    assert_eq!(got.len(), want.len(), "number of outputs printed");
    let mut worst = 0.0f64;
    let mut bad: Vec<String> = Vec::new();
    for (i, (g, (what, x))) in got.iter().zip(&want).enumerate() {
        if same(*g, *x) {
            continue;
        }
        let (y, x) = (f64::from_bits(*g), x.to_f64());
        let rel = (y - x).abs() / (x.abs() + scale[group[i]]);
        worst = worst.max(if rel.is_nan() { f64::INFINITY } else { rel });
        if !tol.is_some_and(|t| rel <= t) && bad.len() < 10 {
            bad.push(format!("{what}: C {y:e} vs interpreter {x:e}"));
        }
    }
    assert!(bad.is_empty(), "{} ({}): outputs differ from the interpreter:\n{}", dir.display(), real, bad.join("\n"));
    (want.len(), worst)
}

/// Largest index in any input or output name of the cases, plus one.
fn array_size(cases: &[Case]) -> usize {
    let mut k = 1;
    for c in cases {
        for f in &c.m.functions {
            let names = f.inputs.iter().map(|&v| f.name_of(v)).chain(f.outputs.iter().map(|o| o.name.as_str()));
            for n in names {
                for part in n.split('[').skip(1) {
                    k = k.max(part.trim_end_matches(']').parse::<usize>().unwrap_or(0) + 1);
                }
            }
        }
    }
    k
}

/// Globals of the robotran-ABI driver: one `MbsData`, one `MbsSensor` and the output arrays,
/// every dimension `array_size` long.
fn robotran_globals(cases: &[Case]) -> String {
    let k = array_size(cases);
    let mut s = format!(
        "#include \"mbs_data.h\"\nstatic double *v1(void) {{ return calloc({k}, sizeof(double)); }}\n\
         static double **v2(void) {{ double **r = calloc({k}, sizeof *r); for (int i = 0; i < {k}; i++) r[i] = v1(); return r; }}\n\
         static MbsData s; static MbsSensor sens; static double tsim;\n"
    );
    let outs: &[(&str, usize)] = &[
        ("M", 2),
        ("c", 1),
        ("Qq", 1),
        ("h", 1),
        ("Jac", 2),
        ("Jdqd", 1),
        ("frc", 2),
        ("trq", 2),
        ("Flnk", 1),
        ("Flink", 1),
        ("Z", 1),
        ("Zd", 1),
    ];
    let mut alloc = String::new();
    for (n, d) in outs {
        let _ = writeln!(s, "static double {}out_{n};", "*".repeat(*d));
        let _ = writeln!(alloc, "  out_{n} = v{d}();");
    }
    for (n, d) in robotran::MBS_FIELDS {
        let _ = writeln!(alloc, "  s.{n} = v{d}();");
    }
    for (n, d) in robotran::SENSOR_FIELDS {
        let _ = writeln!(alloc, "  sens.{n} = v{d}();");
    }
    let _ = write!(s, "static void robovec_test_alloc(void)\n{{\n{alloc}}}\n");
    s
}

/// The driver's block for one function of the robotran ABI: reads the inputs into `s`, calls,
/// prints the outputs' bits.
fn robotran_call(f: &robovec_ir::Function, iface: &robovec_backends::Interface) -> String {
    let ni = iface.inputs.len();
    let mut b =
        format!("  {{ static double in[{}]; if (fread(in, sizeof *in, {ni}, stdin) != {ni}) return 1;\n", ni.max(1));
    let sensor = f.name.contains("sensor_");
    for (i, n) in iface.inputs.iter().enumerate() {
        let target = match n.as_str() {
            "tsim" if sensor => "s.tsim".to_string(),
            "tsim" => "tsim".to_string(),
            _ => format!("s.{n}"),
        };
        let _ = writeln!(b, "    {target} = in[{i}];");
    }
    if sensor {
        let k: u32 = f.name.rsplit('_').next().unwrap().parse().unwrap();
        let _ = writeln!(b, "    {}(&sens, &s, {k});", iface.symbol);
    } else {
        let _ = writeln!(b, "    {}({}&s, tsim);", iface.symbol, robotran_out_args(f));
    }
    for n in &iface.outputs {
        let x = match n.strip_prefix("sens.") {
            Some(r) => format!("sens.{r}"),
            None if n == "flag_stop" => "(double)s.flag_stop".to_string(),
            None => format!("out_{n}"),
        };
        let _ = writeln!(
            b,
            "    {{ double x = {x}; uint64_t u; memcpy(&u, &x, 8); printf(\"%016llx\\n\", (unsigned long long)u); }}"
        );
    }
    b + "  }\n"
}

/// The output arguments of a Robotran function kind, in its signature's order (GRAMMAR-NOTES
/// §1.3), independently of the emitter's table.
fn robotran_out_args(f: &robovec_ir::Function) -> String {
    let flink = f.outputs.iter().any(|o| o.name.starts_with("Flink["));
    let list: &[&str] = match f.name.as_str() {
        "dirdyna" => &["M", "c"],
        "invdyna" => &["Qq"],
        "cons_hJ" => &["h", "Jac"],
        "cons_jdqd" => &["Jdqd"],
        "link" if flink => &["frc", "trq", "Flink", "Z", "Zd"],
        "link" => &["frc", "trq", "Flnk", "Z", "Zd"],
        "link3D" | "extforces" => &["frc", "trq"],
        other => panic!("no Robotran signature known to the test for @{other}"),
    };
    list.iter().map(|n| format!("out_{n}, ")).collect()
}

fn plain(f32: bool, batch: u32, trig_input: bool) -> CodegenC {
    CodegenC {
        precision: precision(f32),
        batch,
        trig: if trig_input { Trig::Input } else { Trig::Libm },
        ..CodegenC::default()
    }
}

fn precision(f32: bool) -> Precision {
    if f32 {
        Precision::F32
    } else {
        Precision::F64
    }
}

// The three corpus-wide tests below each compile every file once (CI time: a corpus compile
// is about 12 s of GCC), after one of the two pipelines whose IR differs most: `atomise` alone
// (Robotran's own statements, split into ops) and with `zero-removal,balance` (negations
// folded, sums rebalanced).

#[test]
fn plain_f64_equals_the_interpreter_bit_for_bit_on_every_corpus_file() {
    let cases = corpus_cases("atomise", false);
    let n = check_plain::<f64>(&tmp("plain_f64"), &cases, &plain(false, 1, false), 1);
    assert!(n > 5_000, "only {n} outputs compared");
}

#[test]
fn plain_f32_equals_the_interpreter_bit_for_bit_on_every_corpus_file() {
    let cases = corpus_cases("atomise,zero-removal,balance", false);
    let n = check_plain::<f32>(&tmp("plain_f32"), &cases, &plain(true, 1, true), 2);
    assert!(n > 5_000, "only {n} outputs compared");
}

#[test]
fn robotran_drop_in_equals_the_interpreter_bit_for_bit_on_every_c_corpus_file() {
    let cases = corpus_cases("atomise,zero-removal,balance", true);
    let o = CodegenC { abi: Abi::Robotran, ..CodegenC::default() };
    let n = check_plain::<f64>(&tmp("robotran"), &cases, &o, 3);
    assert!(n > 3_000, "only {n} outputs compared");
}

/// The drop-in with `trig=inline` (robovec's own sin/cos in place of libm's, the one-state gain
/// docs/benchmarks.md measures): every output of every C corpus file within a small relative
/// error of the interpreter's, with Robotran's signatures, `MbsData` fields and native callbacks,
/// and split into parts (`default<ops>` then a small `chunk`, so that the trig block and the
/// parts meet).
#[test]
fn robotran_drop_in_with_inline_trig_agrees_with_the_interpreter() {
    let cases = corpus_cases("default<ops>", true);
    for (k, chunk) in [0, 500].into_iter().enumerate() {
        let o = CodegenC { abi: Abi::Robotran, trig: Trig::Inline, chunk, ..CodegenC::default() };
        let (n, worst) = check_plain_tol::<f64>(&tmp(&format!("robotran_inline_{k}")), &cases, &o, 7, &[], Some(1e-12));
        eprintln!("abi=robotran trig=inline chunk={chunk}: {n} outputs, largest relative difference {worst:e}");
        assert!(n > 3_000, "only {n} outputs compared");
    }
}

/// Fewer outputs than [`batch_cases`] has (410) per state: a floor the batch tests check that they
/// compared (every lane's).
const BATCH_OUTPUTS: usize = 350;

/// Small corpus files (callbacks, sqrt, sensors, trig) and random DAGs, for the batched forms.
fn batch_cases() -> Vec<Case> {
    let mut cases = named_corpus_cases("atomise,zero-removal,balance", &BATCH_FILES);
    for seed in 0..6 {
        let f = robovec_testkit::dag_gen::generate(300, seed);
        cases.push(Case { label: format!("dag_gen seed {seed}"), m: Module { functions: vec![f] } });
        let f = robovec_testkit::expr_gen::generate(seed);
        let m = run_pipeline(Module { functions: vec![f] }, "atomise");
        cases.push(Case { label: format!("expr_gen seed {seed}"), m });
    }
    cases
}

#[test]
fn batched_lanes_equal_the_interpreter_bit_for_bit_for_every_width_precision_trig_and_layout() {
    let cases = batch_cases();
    // Every width once, each pair of precision and trig mode once, and each vector width: the
    // one chosen for the compiler's target (SSE2 or NEON here: 16 bytes, several chunks of lanes
    // per call), one lane of f64 per chunk (8 bytes), or the whole batch in one vector that the
    // compiler splits (64 bytes, as with AVX-512). `split::split_batches_…` compiles the other
    // pairs of width and precision, the same lanes in parts (CI time: each pair is a compile of
    // every case).
    // Half of them with `layout=rows` (state l's element i at `in[l*n + i]`).
    let combos = [
        (2, false, false, "", false),
        (4, false, true, "-DROBOVEC_VBYTES=8", true),
        (8, true, false, "-DROBOVEC_VBYTES=64", false),
        (16, true, true, "", true),
    ];
    for (batch, f32, trig_input, width, rows) in combos {
        let dir = tmp(&format!("batch_{batch}_{f32}_{trig_input}"));
        let layout = if rows { BatchLayout::Rows } else { BatchLayout::Lanes };
        let o = CodegenC { layout, ..plain(f32, batch, trig_input) };
        let extra: Vec<&str> = [width].into_iter().filter(|w| !w.is_empty()).collect();
        let n = if f32 {
            check_plain_with::<f32>(&dir, &cases, &o, 4, &extra)
        } else {
            check_plain_with::<f64>(&dir, &cases, &o, 4, &extra)
        };
        assert!(n > BATCH_OUTPUTS * batch as usize, "batch {batch}: only {n} outputs compared");
    }
}

#[test]
fn scalar_forms_equal_the_interpreter_on_random_dags() {
    let cases = batch_cases();
    for (f32, trig_input) in [(false, true), (true, false)] {
        let dir = tmp(&format!("scalar_{f32}_{trig_input}"));
        let o = plain(f32, 1, trig_input);
        let n = if f32 { check_plain::<f32>(&dir, &cases, &o, 5) } else { check_plain::<f64>(&dir, &cases, &o, 5) };
        assert!(n > BATCH_OUTPUTS, "only {n} outputs compared");
    }
}

/// `contract`'s fused multiply-adds are C99 `fma` in the C (`robovec_fma` in a batch: one FMA
/// intrinsic where the target has FMA, `fma` per lane otherwise): every output equals the
/// interpreter's (`mul_add`) bit for bit, scalar and batched, in both precisions, compiled for
/// a generic target and for the host's own (`-march=native`: the FMA intrinsics on an x86-64
/// with FMA or AVX-512).
#[test]
fn contracted_functions_equal_the_interpreter_bit_for_bit() {
    let cases: Vec<Case> =
        batch_cases().into_iter().map(|c| Case { label: c.label, m: run_pipeline(c.m, "contract") }).collect();
    let fused = cases.iter().flat_map(|c| &c.m.functions).filter(|f| robovec_backends::c::has_fused(f)).count();
    assert!(fused >= 12, "only {fused} functions have fused multiply-adds");
    for (batch, f32, native) in
        [(1, false, false), (1, true, true), (4, false, true), (8, true, false), (8, false, true)]
    {
        let dir = tmp(&format!("contract_{batch}_{f32}_{native}"));
        let o = plain(f32, batch, true);
        let extra: &[&str] = if native { &["-march=native"] } else { &[] };
        let n = if f32 {
            check_plain_with::<f32>(&dir, &cases, &o, 6, extra)
        } else {
            check_plain_with::<f64>(&dir, &cases, &o, 6, extra)
        };
        assert!(n > BATCH_OUTPUTS * batch as usize, "batch {batch}: only {n} outputs compared");
    }
}

/// `trig=inline`: not libm's sin/cos, so not bit-exact; every output within a small relative error
/// of the interpreter's, for the batch cases (corpus functions and random DAGs) in both
/// precisions, scalar and batched (`trig.rs` measures the sin/cos themselves).
#[test]
fn inline_trig_agrees_with_the_interpreter_to_a_small_relative_error() {
    let cases = batch_cases();
    let mut worsts = Vec::new();
    for (batch, f32, tol, width) in
        [(1, false, 1e-12, ""), (4, false, 1e-12, "-DROBOVEC_VBYTES=32"), (8, true, 1e-4, "")]
    {
        let dir = tmp(&format!("inline_{batch}_{f32}"));
        let o = CodegenC { precision: precision(f32), batch, trig: Trig::Inline, ..CodegenC::default() };
        let extra: Vec<&str> = [width].into_iter().filter(|w| !w.is_empty()).collect();
        let (n, worst) = if f32 {
            check_plain_tol::<f32>(&dir, &cases, &o, 6, &extra, Some(tol))
        } else {
            check_plain_tol::<f64>(&dir, &cases, &o, 6, &extra, Some(tol))
        };
        eprintln!("trig=inline batch={batch} f32={f32}: {n} outputs, largest relative difference {worst:e}");
        assert!(n > BATCH_OUTPUTS * batch as usize, "only {n} outputs compared");
        worsts.push(worst);
    }
    // Not bit-exact: some outputs do differ (else this would test nothing new). Not in every
    // configuration: the inline sin/cos are often the correctly rounded results, as glibc's are,
    // and the scalar f64 outputs of these cases all agree with libm's.
    assert!(worsts.iter().any(|&w| w > 0.0), "every output bit-exact with libm's trig? {worsts:?}");
}

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

#[test]
fn options_that_cannot_go_together_are_bad_usage() {
    for bad in ["abi=robotran;batch=4", "abi=robotran;precision=f32", "abi=robotran;trig=input"] {
        let o = crate::common::opt(&[PENDULUM, &format!("-passes=atomise,codegen<c;{bad}>")]);
        let err = crate::common::stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("`abi=robotran` cannot go with") && err.contains(bad.split(';').nth(1).unwrap()), "{err}");
        assert!(o.stdout.is_empty(), "no code written on bad usage");
    }
    let o = crate::common::opt(&[PENDULUM, "-passes=atomise,codegen<c;batch=3>"]);
    assert_eq!(o.status.code(), Some(2), "{}", crate::common::stderr(&o));
    let o = crate::common::opt(&[PENDULUM, "-passes=atomise,codegen<c;name=not-c>"]);
    assert_eq!(o.status.code(), Some(2), "{}", crate::common::stderr(&o));
    assert!(crate::common::stderr(&o).contains("one C identifier"));
}

#[test]
fn a_function_in_the_parsed_phase_gets_the_phase_diagnostic() {
    let o = crate::common::opt(&[PENDULUM, "-passes=codegen<c>"]);
    let err = crate::common::stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("needs phase Atomised") && err.contains("run `atomise` first"), "{err}");
    assert!(o.stdout.is_empty());
}

#[test]
fn an_unknown_function_kind_has_no_robotran_signature() {
    let dir = tmp("unknown_kind");
    let ir = dir.join("f.rvir");
    std::fs::write(&ir, "func @foo {\n  input %q[1]\n  %x = %q[1] * %q[1]\n  output c[1] = %x\n}\n").unwrap();
    let o = crate::common::opt(&[ir.to_str().unwrap(), "-passes=atomise,codegen<c;abi=robotran>"]);
    let err = crate::common::stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("@foo: no Robotran signature is known"), "{err}");
}

#[test]
fn dash_o_writes_the_c_file_its_header_and_the_report_entry() {
    let dir = tmp("dash_o");
    let c = dir.join("model.c");
    let report = dir.join("r.json");
    let o = crate::common::opt(&[
        PENDULUM,
        "-passes=atomise,zero-removal,balance,codegen<c;abi=plain>",
        "-o",
        c.to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
    let code = std::fs::read_to_string(&c).unwrap();
    assert!(code.contains("#pragma STDC FP_CONTRACT OFF") && code.contains("-ffp-contract=off"), "{code}");
    assert!(code.contains("void invdyna(const double *restrict in, double *restrict out)"), "{code}");
    assert!(!code.contains("func @"), "C, not IR");
    let h = std::fs::read_to_string(dir.join("model.h")).unwrap();
    assert!(h.contains("void invdyna(const double *restrict in, double *restrict out);"), "{h}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    // One function: its entries are at the top of the report (SPEC §7).
    assert_eq!(r["function"], "invdyna", "{r}");
    let cg = &r["codegen"];
    assert_eq!(cg["symbol"], "invdyna", "{r}");
    assert_eq!(cg["abi"], "plain");
    assert_eq!(cg["precision"], "f64");
    assert_eq!(cg["batch"], 1);
    // The IR's input order (first use in the source: q[1], q[2], then s->g[3] …).
    let inputs: Vec<&str> = cg["inputs"].as_array().unwrap().iter().map(|x| x.as_str().unwrap()).collect();
    assert_eq!(&inputs[..3], ["q[1]", "q[2]", "g[3]"]);
    assert_eq!(inputs.len(), 14);
    assert_eq!(cg["outputs"], serde_json::json!(["Qq[1]", "Qq[2]"]));
    // The header documents the same order.
    assert!(h.contains("in[0] q[1], in[1] q[2], in[2] g[3]"), "{h}");

    // Without -o the C goes to stdout (and no header is written anywhere).
    let o = crate::common::opt(&[PENDULUM, "-passes=atomise,codegen<c;precision=f32;batch=4>"]);
    assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.starts_with("/* Generated by robovec codegen<c;abi=plain;precision=f32;batch=4;trig=libm>"), "{out}");
    assert!(out.contains("#define ROBOVEC_W 4\n"), "{out}");
    assert!(
        out.contains("typedef float robovec_vec __attribute__((vector_size(ROBOVEC_VL * sizeof(float))));"),
        "{out}"
    );
    assert!(
        out.contains("for (int robovec_chunk = 0; robovec_chunk < ROBOVEC_W / ROBOVEC_VL; robovec_chunk++) {"),
        "{out}"
    );
}

/// `trig=inline` on the CLI: the report's `codegen.trig` says so, the inputs are the IR's only, and
/// the file holds the helpers and one fused call per coordinate (one block of all of them for one
/// state).
#[test]
fn trig_inline_is_in_the_report_and_the_file() {
    let dir = tmp("trig_inline_cli");
    let c = dir.join("model.c");
    let report = dir.join("r.json");
    for batch in [1, 4] {
        let o = crate::common::opt(&[
            PENDULUM,
            &format!("-passes=atomise,cse,codegen<c;batch={batch};trig=inline>"),
            "-o",
            c.to_str().unwrap(),
            &format!("-report={}", report.display()),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        assert_eq!(r["codegen"]["trig"], "inline", "{r}");
        assert_eq!(r["codegen"]["inputs"].as_array().unwrap().len(), 14, "{r}");
        let code = std::fs::read_to_string(&c).unwrap();
        assert!(code.starts_with(&format!(
            "/* Generated by robovec codegen<c;abi=plain;precision=f64;batch={batch};trig=inline>"
        )));
        assert!(code.contains("static inline ROBOVEC_UNUSED void robovec_sincos_inline("), "{code}");
        // The pendulum has sin and cos of q[1] and q[2]: one state computes them in one block (both
        // arguments, padded to 8), a batch with two fused calls; no libm sin/cos call in the body.
        if batch == 1 {
            assert_eq!(code.matches("robovec_sincos_n(robovec_ta, robovec_ts, robovec_tc, 8);").count(), 1, "{code}");
            assert_eq!(code.matches("  robovec_sincos_inline(q_").count(), 0, "{code}");
        } else {
            assert_eq!(code.matches("  robovec_sincos_inline(q_").count(), 2, "{code}");
        }
        let body = &code[code.find("void invdyna(").unwrap()..];
        assert!(!body.contains("sin(") && !body.contains("cos("), "{body}");
    }
}

/// `abi=robotran` calls MBsysC's native callbacks: operands that do not fit the native
/// signature, elements of one call with different operands and unknown callbacks are
/// diagnostics (exit 1), while `abi=plain` (adapter form) writes all three.
#[test]
fn robotran_callbacks_that_do_not_fit_the_native_signature_are_diagnostics() {
    let dir = tmp("native_callbacks");
    let cases = [
        ("short", "  %a[1] = call @user_ExtForces.1[1](%q[1], %tsim)\n", "has 2 operands; Robotran's user_ExtForces takes 25"),
        (
            "unknown",
            "  %a[1] = call @user_LinkForces.1(%q[1], %q[1], %tsim)\n  %b = call @user_LinkForces.2(%q[1], %tsim, %tsim)\n  \
             %a[2] = call @user_Other.1(%q[1])\n",
            "callback `user_Other` has no known Robotran signature",
        ),
        (
            "elems",
            "  %a[1] = call @user_LinkForces.1[1](%q[1], %q[1], %tsim)\n  %a[2] = %q[1] * %q[1]\n  %b = %a[2] * %q[1]\n",
            "returns one number, not a vector",
        ),
    ];
    for (label, body, want) in cases {
        let ir = dir.join(format!("{label}.rvir"));
        let outs =
            if label == "short" { "  output c[1] = %a[1]\n" } else { "  output c[1] = %a[1]\n  output c[2] = %a[2]\n" };
        std::fs::write(&ir, format!("func @dirdyna {{\n  input %q[1]\n  input %tsim\n{body}{outs}}}\n")).unwrap();
        let o = crate::common::opt(&[ir.to_str().unwrap(), "-passes=atomise,codegen<c;abi=robotran>"]);
        let err = crate::common::stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{label}: {err}");
        assert!(err.contains(want), "{label}: {err}");
        let out = dir.join(format!("{label}.c"));
        let o = crate::common::opt(&[
            ir.to_str().unwrap(),
            "-passes=atomise,codegen<c;abi=plain>",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{label} plain: {}", crate::common::stderr(&o));
    }
}

/// Two elements of one `user_ExtForces` instance read with different operands cannot be one
/// native call: a diagnostic, not C that calls it with the first element's operands.
#[test]
fn robotran_elements_of_one_callback_with_different_operands_are_a_diagnostic() {
    let dir = tmp("native_callbacks_differ");
    let ops = |x: &str| std::iter::repeat_n(x, 24).chain(["%tsim"]).collect::<Vec<_>>().join(", ");
    let ir = dir.join("f.rvir");
    std::fs::write(
        &ir,
        format!(
            "func @extforces {{\n  input %q[1]\n  input %q[2]\n  input %tsim\n  %a[1] = call @user_ExtForces.1[1]({})\n  \
             %a[2] = call @user_ExtForces.1[2]({})\n  output frc[1][1] = %a[1]\n  output frc[2][1] = %a[2]\n}}\n",
            ops("%q[1]"),
            ops("%q[2]")
        ),
    )
    .unwrap();
    let o = crate::common::opt(&[ir.to_str().unwrap(), "-passes=atomise,codegen<c;abi=robotran>"]);
    let err = crate::common::stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("the elements of callback `user_ExtForces(…, 1)` have different operands"), "{err}");
}

/// The plain ABI reads each input just before its first use and writes each output right after
/// the statement that computes it (outputs that are inputs last): the order that keeps GCC's
/// frame of coman's batched `dirdyna` in L1 (`plain.rs`'s module doc).
#[test]
fn plain_code_reads_inputs_at_first_use_and_writes_outputs_when_computed() {
    let dir = tmp("order");
    let ir = dir.join("f.rvir");
    std::fs::write(
        &ir,
        "func @f {\n  phase atomised\n  input %x\n  input %y\n  input %z\n  %m1 = mul %x, %y\n  \
         %m2 = mul %m1, %z\n  output o1 = %m1\n  output o2 = %m2\n  output o3 = %y\n}\n",
    )
    .unwrap();
    for (batch, load, store) in [
        (1, ["in[0]", "in[1]", "in[2]"], ["out[0]", "out[1]", "out[2]"]),
        (4, ["in + 0 ", "in + 4 ", "in + 8 "], ["out + 0 ", "out + 4 ", "out + 8 "]),
    ] {
        let c = dir.join(format!("f{batch}.c"));
        let o = crate::common::opt(&[
            ir.to_str().unwrap(),
            &format!("-passes=codegen<c;abi=plain;batch={batch}>"),
            "-o",
            c.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
        let code = std::fs::read_to_string(&c).unwrap();
        let at = |needle: &str| code.find(needle).unwrap_or_else(|| panic!("no `{needle}` in\n{code}"));
        let (m1, m2) = (at("m1 = x * y;"), at("m2 = m1 * z;"));
        // x and y before m1, z between m1 and m2; o1 between m1 and m2, o2 after m2, o3 last.
        assert!(at(load[0]) < m1 && at(load[1]) < m1, "{code}");
        assert!(m1 < at(load[2]) && at(load[2]) < m2, "{code}");
        assert!(m1 < at(store[0]) && at(store[0]) < at(load[2]), "{code}");
        assert!(m2 < at(store[1]) && at(store[1]) < at(store[2]), "{code}");
        assert_eq!(code.matches(load[1]).count(), 1, "y is read once: {code}");
    }
}

/// `slp=4` ([`robovec_backends::c`]'s packs of four isomorphic ops): the three-link arm's
/// `aba_derivatives` on the free flyer (9 × 9 matrices: two packs of four columns a row to
/// seed), in one function, and with `contract` (vector FMAs) in parts of 300 statements (a
/// pack's vector read in its own part, its members gathered in a later one),
/// equal the interpreter bit for bit, under GCC generic and `-march=native` (FMA, AVX) and
/// under Clang; the files compile under both with `-std=c99 -Wall -Wextra -pedantic -Werror`;
/// packs are written, vector FMAs among them. `slp=4` with `batch=4` or `precision=f32` is bad
/// usage.
#[test]
fn slp_packs_equal_the_interpreter_bit_for_bit() {
    let options = robovec_front::FrontOptions {
        fold_params: true,
        free_flyer: true,
        functions: Some(vec!["aba_derivatives".into()]),
        ..Default::default()
    };
    let (loaded, _) = robovec::driver::load_with("examples/three_link_arm/three_link_arm.urdf", &options)
        .unwrap_or_else(|e| panic!("{}", e.message()));
    for (pipeline, chunk) in [("default<ops>", 0), ("atomise,cse,zero-removal,contract,schedule-cpu", 300)] {
        let m = run_pipeline(loaded.module.clone(), pipeline);
        let cases = vec![Case { label: format!("three_link_arm after {pipeline}"), m }];
        {
            let o = CodegenC { slp: 4, chunk, ..CodegenC::default() };
            let code = o.emit(&cases[0].m).unwrap().code.main;
            let packs = code.matches("const robovec_v4 robovec_p").count() + code.matches("robovec_fma4(&").count();
            assert!(packs >= 40, "{pipeline}, chunk={chunk}: {packs} packs");
            if pipeline.contains("contract") {
                assert!(code.contains("robovec_fma4(&"), "vector FMAs");
            }
            let dir = tmp(&format!("slp_{}_{chunk}", pipeline.len()));
            std::fs::write(dir.join("t.c"), &code).unwrap();
            for compiler in ["gcc", "clang"] {
                let out = Command::new(compiler)
                    .current_dir(&dir)
                    .args(["-std=c99", "-O0", "-Wall", "-Wextra", "-pedantic", "-Werror", "-c", "t.c", "-o", "t.o"])
                    .output()
                    .unwrap_or_else(|e| panic!("{compiler} ({e}): scripts/test.sh installs gcc and clang"));
                assert!(out.status.success(), "{compiler}:\n{}", String::from_utf8_lossy(&out.stderr));
            }
            for extra in [&["-O1"][..], &["-O1", "cc=clang", "-march=native"]] {
                let n = check_plain_with::<f64>(&dir, &cases, &o, 3, extra);
                assert!(n >= 3 * 9 * 9, "{n} outputs compared");
            }
        }
    }
    // Mixed packs: four columns of different ops (a fused multiply-add, a product that is −0, a
    // fused multiply-subtract, a fused negated multiply-add) as one vector FMA, the product
    // with −0 for its addend (+0 would turn its −0 into +0), the last lane's product read
    // through a vector of signs.
    let mut t = String::from("func @mixed {\n  phase atomised\n  input %a0\n  input %b0\n");
    for j in 1..=4 {
        t += &format!("  input %x{j}\n  input %w{j}\n  input %r{j}\n");
    }
    t += "  %a = mul %a0, %a0\n  %b = mul %b0, %b0\n  %z = sub %x2, %x2\n  %m = sub %z, %b\n  \
          %nz = mul %z, %m\n  %ww = mul %w2, %w2\n";
    for (j, x, w) in [(1, "x1", "w1"), (2, "nz", "ww"), (3, "x3", "w3"), (4, "x4", "w4")] {
        t += &format!("  %p{j} = mul %a, %{x}\n  %q{j} = mul %b, %{w}\n");
    }
    t += "  %y1 = call @fma(%p1, %q1, %r1)\n  %y2 = mul %p2, %q2\n  %y3 = call @fms(%p3, %q3, %r3)\n  \
          %y4 = call @fnma(%p4, %q4, %r4)\n";
    for j in 1..=4 {
        t += &format!("  output y[1][{j}] = %y{j}\n");
    }
    t += "}\n";
    let m = robovec_ir::text::parse(&t).unwrap_or_else(|e| panic!("{e:?}"));
    let o = CodegenC { slp: 4, ..CodegenC::default() };
    let code = o.emit(&m).unwrap().code.main;
    assert!(code.contains("robovec_fma4(&"), "{code}");
    assert!(code.contains("* (robovec_v4){1.0, 1.0, 1.0, -1.0}"), "{code}");
    assert!(code.contains("(-0x0p+0)"), "{code}");
    // Sums and differences only: a vector product by 1 then a vector sum, no FMA, the
    // subtrahends through a vector of signs.
    let addsub = t
        .replace("%y1 = call @fma(%p1, %q1, %r1)", "%y1 = add %p1, %q1")
        .replace("%y2 = mul %p2, %q2", "%y2 = sub %p2, %q2")
        .replace("%y3 = call @fms(%p3, %q3, %r3)", "%y3 = add %q3, %p3")
        .replace("%y4 = call @fnma(%p4, %q4, %r4)", "%y4 = sub %p4, %q4")
        .replace("func @mixed", "func @addsub");
    let m2 = robovec_ir::text::parse(&addsub).unwrap_or_else(|e| panic!("{e:?}"));
    let code2 = o.emit(&m2).unwrap().code.main;
    assert!(!code2.contains("robovec_fma4(&robovec_p"), "{code2}");
    assert!(code2.contains("* (robovec_v4){1.0, -1.0, 1.0, -1.0}"), "{code2}");
    let cases = vec![Case { label: "mixed lanes".into(), m }, Case { label: "sums and differences".into(), m: m2 }];
    let dir = tmp("slp_mixed");
    for extra in [&["-O1"][..], &["-O1", "cc=clang", "-march=native"], &["-O1", "-march=native"]] {
        for seed in 0..3 {
            assert_eq!(check_plain_with::<f64>(&dir, &cases, &o, seed, extra), 8);
        }
    }
    for bad in ["slp=4;batch=4", "slp=4;precision=f32"] {
        let o = crate::common::opt(&[PENDULUM, &format!("-passes=atomise,codegen<c;{bad}>")]);
        let err = crate::common::stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("`slp=4`") && err.contains(bad.split(';').nth(1).unwrap()), "{err}");
    }
}
