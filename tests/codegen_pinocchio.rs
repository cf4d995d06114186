//! Issue 30: `codegen<c;abi=pinocchio>` — the URDF generator's functions as
//! `NAME_rnea(q, v, a, tau)`, `NAME_crba(q, M)`, `NAME_nle(q, v, nle)` and
//! `NAME_aba(q, v, tau, qdd)` over Pinocchio's vectors, gravity (0, 0, −9.81) folded.
//!
//! The generated C is compiled with the system C compiler and called by a small C driver:
//! - with Pinocchio's own vectors (`scripts/pinocchio_oracle.py`'s `q_pinocchio`, `qd`, `qdd`,
//!   `tau`), its results against Pinocchio's `rnea`, `crba` (symmetrised), `nonLinearEffects`
//!   and `aba`, relative error ≤ 1e-10, one state and `batch=4` (skipped with a note without
//!   Pinocchio's environment, as `tests/pinocchio.rs`);
//! - without Pinocchio, bit for bit against robovec's interpreter (`-eval`'s evaluation) given
//!   the same state and `g` = (0, 0, −9.81), at `-O0 -ffp-contract=off`, one state, `batch=4`
//!   split into parts (`chunk=`), and `trig=inline` within a relative error;
//! - options and inputs that have no place in Pinocchio's signature are diagnostics.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use robovec_backends::c::{pinocchio::GRAVITY, Abi, BatchLayout, CodegenC, Trig};
use robovec_backends::literal::hex;
use robovec_front::FrontOptions;
use robovec_ir::interp::pseudo_random_input;
use robovec_ir::Module;
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::common::{opt, stderr, tmp};
use crate::pinocchio::{oracle, Base};

/// One state in Pinocchio's vectors (`q` nq long, the others nv long).
#[derive(Clone, Debug)]
struct StateIn {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
}

/// The C functions' results for one state, by the array they write (`tau`, `M`, `nle`, `qdd`).
type Results = BTreeMap<&'static str, Vec<f64>>;

/// Every function of the URDF at `path` (invdyna, dirdyna, fordyna), parameters folded, after
/// `pipeline`.
fn load(path: &str, pipeline: &str) -> Module {
    load_on(path, pipeline, false, false)
}

/// [`load`], on Pinocchio's free flyer when `free_flyer`, continuous joints as Pinocchio's
/// `(cos, sin)` pairs when `cos_sin` (`--continuous=cos-sin`).
fn load_on(path: &str, pipeline: &str, free_flyer: bool, cos_sin: bool) -> Module {
    let (loaded, _) = robovec::driver::load_with(
        path,
        &FrontOptions {
            fold_params: true,
            free_flyer,
            continuous_cos_sin: cos_sin,
            functions: Some(robovec_dynamics::FUNCTION_NAMES.iter().map(|s| s.to_string()).collect()),
            ..FrontOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{path}: {}", e.message()));
    let mut m = loaded.module;
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default()).unwrap();
    pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink()).unwrap();
    m
}

/// The arrays of each C function, output last (the test's own table, independent of the emitter's).
const FUNCTIONS: &[(&str, &[&str], &str)] = &[
    ("rnea", &["q", "v", "a"], "tau"),
    ("crba", &["q"], "M"),
    ("nle", &["q", "v"], "nle"),
    ("aba", &["q", "v", "t"], "qdd"),
];

/// Emits `m` with `o` (name `model`) into `dir`, checks the header's sizes against `nq`, `nv`,
/// compiles it with a driver that calls every function on `states` (in calls of `o.batch`
/// lanes, outputs pre-filled with NaN) and returns each state's results.
fn run_c(
    dir: &Path,
    m: &Module,
    o: &CodegenC,
    nq: usize,
    nv: usize,
    states: &[StateIn],
    flags: &[&str],
) -> Vec<Results> {
    let w = o.batch as usize;
    assert_eq!(states.len() % w, 0);
    let art = o.emit(m).unwrap_or_else(|e| panic!("emit: {e}"));
    let header = &art.code.companions[0].1;
    assert!(header.contains(&format!("#define model_NQ {nq}\n#define model_NV {nv}\n")), "{header}");
    let symbols: Vec<&str> = art.interfaces.iter().map(|i| i.symbol.as_str()).collect();
    assert_eq!(symbols, ["model_rnea", "model_crba", "model_nle", "model_aba"]);
    std::fs::write(dir.join("model.c"), &art.code.main).unwrap();
    std::fs::write(dir.join("model.h"), header).unwrap();
    let mut files = vec!["main.c".to_string(), "model.c".to_string()];
    for (u, text) in art.code.units.iter().enumerate() {
        let name = format!("model_{}.c", u + 1);
        std::fs::write(dir.join(&name), text).unwrap();
        files.push(name);
    }
    let table = |name: &str, rows: Vec<&Vec<f64>>, len: usize| {
        let mut s = format!("static const double {name}[{}][{len}] = {{\n", rows.len());
        for r in rows {
            assert_eq!(r.len(), len, "{name}: length");
            let items: Vec<String> = r.iter().map(|x| hex(*x, false)).collect();
            let _ = writeln!(s, "  {{{}}},", items.join(", "));
        }
        s + "};\n"
    };
    let mut c = String::from(
        "#include <stdio.h>\n#include <string.h>\n#include <stdint.h>\n#include \"model.h\"\n\
         static void put(double x) { uint64_t b; memcpy(&b, &x, 8); printf(\"%016llx\\n\", (unsigned long long)b); }\n",
    );
    c += &table("Q", states.iter().map(|s| &s.q).collect(), nq);
    c += &table("V", states.iter().map(|s| &s.v).collect(), nv);
    c += &table("A", states.iter().map(|s| &s.a).collect(), nv);
    c += &table("T", states.iter().map(|s| &s.tau).collect(), nv);
    let _ = write!(
        c,
        "/* Element k of state l of an array of n elements a state. */\n#define AT(k, l, n) {}\n\
         int main(void)\n{{\n  enum {{ W = {w}, NQ = model_NQ, NV = model_NV }};\n  for (int s0 = 0; s0 < {}; s0 += W) {{\n    \
         static double q[NQ * W], v[NV * W], a[NV * W], t[NV * W], tau[NV * W], M[NV * NV * W], nle[NV * W], qdd[NV * W];\n    \
         memset(tau, 0xff, sizeof tau); memset(M, 0xff, sizeof M); memset(nle, 0xff, sizeof nle); memset(qdd, 0xff, sizeof qdd);\n    \
         for (int l = 0; l < W; l++) {{\n      \
         for (int k = 0; k < NQ; k++) q[AT(k, l, NQ)] = Q[s0 + l][k];\n      \
         for (int k = 0; k < NV; k++) {{ v[AT(k, l, NV)] = V[s0 + l][k]; a[AT(k, l, NV)] = A[s0 + l][k]; t[AT(k, l, NV)] = T[s0 + l][k]; }}\n    }}\n",
        if o.layout == BatchLayout::Rows { "((l) * (n) + (k))" } else { "((k) * W + (l))" },
        states.len()
    );
    for (f, ins, out) in FUNCTIONS {
        let _ = writeln!(c, "    model_{f}({}, {out});", ins.join(", "));
    }
    c += "    for (int l = 0; l < W; l++) {\n";
    for (_, _, out) in FUNCTIONS {
        let n = if *out == "M" { "NV * NV" } else { "NV" };
        let _ = writeln!(c, "      for (int k = 0; k < {n}; k++) put({out}[AT(k, l, {n})]);");
    }
    c += "    }\n  }\n  return 0;\n}\n";
    std::fs::write(dir.join("main.c"), c).unwrap();
    let exe = dir.join("run");
    let cc = Command::new("cc")
        .current_dir(dir)
        .args(flags)
        .args(["-std=c99", "-ffp-contract=off", "-Wall", "-Werror", "-o"])
        .arg(&exe)
        .args(&files)
        .arg("-lm")
        .output()
        .expect("a C compiler `cc` on PATH");
    assert!(cc.status.success(), "cc failed in {}:\n{}", dir.display(), String::from_utf8_lossy(&cc.stderr));
    let out = Command::new(&exe).output().unwrap();
    assert!(out.status.success(), "{} exited with {:?}", exe.display(), out.status);
    let words: Vec<f64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| f64::from_bits(u64::from_str_radix(l, 16).unwrap()))
        .collect();
    let per_state = 3 * nv + nv * nv;
    assert_eq!(words.len(), per_state * states.len(), "values printed");
    words
        .chunks(per_state)
        .map(|x| {
            let mut r = Results::new();
            r.insert("tau", x[..nv].to_vec());
            r.insert("M", x[nv..nv + nv * nv].to_vec());
            r.insert("nle", x[nv + nv * nv..2 * nv + nv * nv].to_vec());
            r.insert("qdd", x[2 * nv + nv * nv..].to_vec());
            r
        })
        .collect()
}

/// ∞-norm of `got − want` over the ∞-norm of `want`.
fn rel(got: &[f64], want: &[f64]) -> f64 {
    assert_eq!(got.len(), want.len());
    let norm = want.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = got.iter().zip(want).fold(0.0f64, |m, (g, w)| m.max((g - w).abs()));
    if diff.is_nan() {
        f64::INFINITY
    } else {
        diff / norm
    }
}

/// The `abi=pinocchio` C of the URDF `urdf` (a path or `erd:…`) called with Pinocchio's vectors
/// against Pinocchio's results, one state per call and `batch=4`; `continuous`: the model has
/// continuous joints, whose Pinocchio configuration is (cos θ, sin θ), and is loaded with
/// `--continuous=cos-sin`; either way the C gets Pinocchio's configuration vector itself.
/// Returns the worst relative error.
fn against_pinocchio(py: &Path, label: &str, urdf: &str, continuous: bool) -> f64 {
    against_pinocchio_on(py, label, urdf, continuous, false)
}

/// [`against_pinocchio`], on the free flyer (`--free-flyer`, `JointModelFreeFlyer`) when
/// `free_flyer`: `q` has `nv + 1` entries (position, quaternion x y z w, joints).
fn against_pinocchio_on(py: &Path, label: &str, urdf: &str, continuous: bool, free_flyer: bool) -> f64 {
    let base = if free_flyer { Base::FreeFlyer } else { Base::Fixed };
    let o = oracle(py, urdf, 8, 11, base);
    assert_eq!(o.gravity, GRAVITY, "Pinocchio's default gravity is what abi=pinocchio folds");
    let nv = o.states[0].qd.len();
    let states: Vec<StateIn> = o
        .states
        .iter()
        .map(|s| {
            // Pinocchio's own configuration vector: with continuous joints, their (cos, sin)
            // pairs (the model loaded with --continuous=cos-sin).
            if continuous {
                assert!(s.q_pinocchio.len() > s.q.len(), "{label}: continuous joints");
            } else {
                assert_eq!(s.q_pinocchio, s.q, "{label}: Pinocchio's q is one coordinate per joint");
            }
            StateIn { q: s.q_pinocchio.clone(), v: s.qd.clone(), a: s.qdd.clone(), tau: s.tau.clone() }
        })
        .collect();
    let m = load_on(&o.path, "atomise,cse", free_flyer, continuous);
    let nq = states[0].q.len();
    let mut worst: f64 = 0.0;
    for batch in [1, 4] {
        let dir = tmp(&format!("pinocchio_{label}_{batch}"));
        let co = CodegenC { abi: Abi::Pinocchio, batch, ..CodegenC::default() };
        // A correctness build (-O0): at -O1 GCC took 55 % of the test's time (Talos' C).
        let got = run_c(&dir, &m, &co, nq, nv, &states, &["-O0"]);
        for (k, (r, s)) in got.iter().zip(&o.states).enumerate() {
            let mass: Vec<f64> = s.mass.iter().flatten().copied().collect();
            for (what, g, want) in [
                ("tau", &r["tau"], &s.tau),
                ("M", &r["M"], &mass),
                ("nle", &r["nle"], &s.nle),
                ("qdd", &r["qdd"], &s.aba),
            ] {
                let e = rel(g, want);
                assert!(
                    e <= 1e-10,
                    "{label} batch={batch} state {k} {what}: relative error {e:e}\n C {g:?}\n Pinocchio {want:?}"
                );
                worst = worst.max(e);
            }
        }
    }
    worst
}

#[test]
fn pinocchio_abi_c_called_with_pinocchios_vectors_matches_pinocchio() {
    let Some(py) = crate::pinocchio::python() else { return };
    let e = against_pinocchio(&py, "three_link_arm", "examples/three_link_arm/three_link_arm.urdf", true);
    eprintln!("three_link_arm: worst relative error {e:e}");
    let e = against_pinocchio(&py, "ur5", "erd:ur_description/urdf/ur5_robot.urdf", false);
    eprintln!("ur5: worst relative error {e:e}");
    let e = against_pinocchio(&py, "panda", "erd:panda_description/urdf/panda.urdf", false);
    eprintln!("panda: worst relative error {e:e}");
    // The free flyer: Pinocchio's q (position, unit quaternion x y z w, joints) as it is.
    let e = against_pinocchio_on(&py, "solo12_ff", "erd:solo_description/robots/solo12.urdf", false, true);
    eprintln!("solo12 free flyer: worst relative error {e:e}");
    let e = against_pinocchio_on(&py, "talos_ff", "erd:talos_data/robots/talos_reduced.urdf", false, true);
    eprintln!("talos free flyer: worst relative error {e:e}");
    use robovec_dynamics::topology::{build, Topology};
    let dir = tmp("topology");
    for t in Topology::ALL {
        let path = dir.join(format!("{t}_9.urdf"));
        std::fs::write(&path, robovec_dynamics::urdf_out::write_urdf(&build(t, 9, 1))).unwrap();
        // The writer's joints are continuous: Pinocchio's q is (cos, sin) for each.
        let e = against_pinocchio(&py, &format!("{t}_9"), path.to_str().unwrap(), true);
        eprintln!("{t} 9: worst relative error {e:e}");
    }
}

/// Pseudo-random states (`-eval`'s inputs) for a model of `nq`, `nv`.
fn random_states(n: usize, nq: usize, nv: usize, seed: u64) -> Vec<StateIn> {
    (0..n as u64)
        .map(|s| {
            let x = |base: &str, k: usize| pseudo_random_input(&format!("{base}[{}]", k + 1), seed + 101 * s);
            StateIn {
                q: (0..nq).map(|k| x("q", k)).collect(),
                v: (0..nv).map(|k| x("qd", k)).collect(),
                a: (0..nv).map(|k| x("qdd", k)).collect(),
                tau: (0..nv).map(|k| x("Qq", k)).collect(),
            }
        })
        .collect()
}

/// robovec's interpreter on the same state: `Qq` of invdyna, `M` and `c` of dirdyna, `qdd` of
/// fordyna, with `g` = (0, 0, −9.81), as the C arrays.
fn interpreted(m: &Module, s: &StateIn, nv: usize) -> Results {
    let mut given = BTreeMap::new();
    for (k, g) in GRAVITY.iter().enumerate() {
        given.insert(format!("g[{}]", k + 1), *g);
    }
    for (k, x) in s.q.iter().enumerate() {
        given.insert(format!("q[{}]", k + 1), *x);
    }
    for k in 0..nv {
        given.insert(format!("qd[{}]", k + 1), s.v[k]);
        given.insert(format!("qdd[{}]", k + 1), s.a[k]);
        given.insert(format!("Qq[{}]", k + 1), s.tau[k]);
    }
    let out = |f: &str| {
        let f = m.function(f).unwrap();
        for &v in &f.inputs {
            assert!(given.contains_key(f.name_of(v)), "input {} not given", f.name_of(v));
        }
        robovec::eval::evaluate(f, &given, false).outputs
    };
    let (inv, dir, fwd) = (out("invdyna"), out("dirdyna"), out("fordyna"));
    let list =
        |o: &BTreeMap<String, f64>, base: &str| -> Vec<f64> { (1..=nv).map(|k| o[&format!("{base}[{k}]")]).collect() };
    let mut r = Results::new();
    r.insert("tau", list(&inv, "Qq"));
    r.insert(
        "M",
        (1..=nv).flat_map(|i| (1..=nv).map(move |j| (i, j))).map(|(i, j)| dir[&format!("M[{i}][{j}]")]).collect(),
    );
    r.insert("nle", list(&dir, "c"));
    r.insert("qdd", list(&fwd, "qdd"));
    r
}

/// Without Pinocchio: the `abi=pinocchio` C equals robovec's interpreter bit for bit (the
/// gravity it folds is the interpreter's `g`), for the three-link arm and a 9-dof tree, one state,
/// `batch=4` as rows (`layout=rows`) with functions split into parts of 40 statements over two
/// translation units, and `trig=inline` (robovec's own sin/cos: within 1e-12 of the output's
/// magnitude).
#[test]
fn pinocchio_abi_c_equals_the_interpreter_bit_for_bit() {
    use robovec_dynamics::topology::{build, Topology};
    let dir = tmp("eval_models");
    let tree = dir.join("semiserial_9.urdf");
    std::fs::write(&tree, robovec_dynamics::urdf_out::write_urdf(&build(Topology::SemiSerial, 9, 1))).unwrap();
    for (label, path, n) in
        [("arm", "examples/three_link_arm/three_link_arm.urdf", 3), ("tree", tree.to_str().unwrap(), 9)]
    {
        let m = load(path, "atomise,cse,zero-removal,balance");
        let states = random_states(8, n, n, 5);
        let want: Vec<Results> = states.iter().map(|s| interpreted(&m, s, n)).collect();
        for (batch, chunk, units, trig, tol, layout) in [
            (1, 4000, 1, Trig::Libm, None, BatchLayout::Lanes),
            (4, 40, 2, Trig::Libm, None, BatchLayout::Rows),
            (2, 4000, 1, Trig::Inline, Some(1e-12), BatchLayout::Lanes),
        ] {
            let d = tmp(&format!("eval_{label}_{batch}_{chunk}"));
            let o = CodegenC { abi: Abi::Pinocchio, batch, chunk, units, trig, layout, ..CodegenC::default() };
            let got = run_c(&d, &m, &o, n, n, &states, &["-O0"]);
            for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                for (what, x) in w {
                    let y = &g[what];
                    match tol {
                        None => assert!(
                            x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits()),
                            "{label} batch={batch} chunk={chunk} state {k} {what}: C {y:?} vs interpreter {x:?}"
                        ),
                        Some(t) => {
                            let e = rel(y, x);
                            assert!(e <= t, "{label} trig=inline state {k} {what}: relative error {e:e}");
                        }
                    }
                }
            }
        }
    }
}

const ARM: &str = "examples/three_link_arm/three_link_arm.urdf";

/// The CLI: `-o` writes the C and its header (C99, C++-callable prototypes without
/// `restrict`), the report names the symbol and Pinocchio's argument order, `name=` sets the
/// prefix, and `-function=fordyna` gives `NAME_aba`.
#[test]
fn dash_o_writes_pinocchios_signatures_and_the_report() {
    let dir = tmp("cli");
    let c = dir.join("arm.c");
    let report = dir.join("r.json");
    let o = opt(&[
        ARM,
        "--fold-params",
        "-function=dirdyna",
        "-passes=atomise,cse,codegen<c;abi=pinocchio;name=arm>",
        "-o",
        c.to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let h = std::fs::read_to_string(dir.join("arm.h")).unwrap();
    for want in [
        "#ifndef ROBOVEC_arm_crba_H",
        "extern \"C\" {",
        "#define arm_NQ 3\n#define arm_NV 3\n",
        "void arm_crba(const double *q, double *M);",
        "void arm_nle(const double *q, const double *v, double *nle);",
    ] {
        assert!(h.contains(want), "no `{want}` in\n{h}");
    }
    assert!(!h.contains("rnea") && !h.contains("restrict"), "{h}");
    let code = std::fs::read_to_string(&c).unwrap();
    assert!(code.contains("void arm_crba(const double *restrict q, double *restrict M)\n{"), "{code}");
    // The mass matrix reads no velocity; gravity is a constant of nle.
    let crba = &code[code.find("void arm_crba(").unwrap()..code.find("void arm_nle(").unwrap()];
    assert!(!crba.contains("v[") && !crba.contains("g_"), "{crba}");
    assert!(code.contains("const double g_3 = (-0x1.39eb851eb851fp+3);"), "{code}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["codegen"]["symbol"], "arm_crba", "{r}");
    assert_eq!(r["codegen"]["abi"], "pinocchio");
    assert_eq!(r["codegen"]["inputs"], serde_json::json!(["q[1]", "q[2]", "q[3]"]));
    assert_eq!(r["codegen"]["outputs"].as_array().unwrap().len(), 9);
    // The C file compiles as C99 with every warning.
    let cc =
        Command::new("cc").current_dir(&dir).args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-c", "arm.c"]).output();
    let cc = cc.expect("cc");
    assert!(cc.status.success(), "{}", String::from_utf8_lossy(&cc.stderr));
    // Default prefix `model`; the forward dynamics as `model_aba`.
    let o = opt(&[ARM, "--fold-params", "-function=fordyna", "-passes=atomise,codegen<c;abi=pinocchio;batch=2>"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(
        out.contains("void model_aba(const double *restrict q, const double *restrict v, const double *restrict tau, double *restrict qdd)"),
        "{out}"
    );
}

/// Parameters left as inputs, a function that is no URDF dynamics (a Robotran file's, or any
/// other), `trig=input` and `precision=f32`, and a mass matrix with missing entries are
/// diagnostics; no code is written.
#[test]
fn what_has_no_place_in_pinocchios_signature_is_refused() {
    let pin = "-passes=atomise,codegen<c;abi=pinocchio>";
    let check = |args: &[&str], code: i32, wants: &[&str]| {
        let o = opt(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        for w in wants {
            assert!(err.contains(w), "{args:?}: no `{w}` in {err}");
        }
        assert!(o.stdout.is_empty(), "no code written");
    };
    check(&[ARM, pin], 1, &["@invdyna: model parameters are inputs (", "--fold-params", "specialize<params=FILE>"]);
    check(
        &["examples/double_pendulum/mbs_invdyna_double_pendulum.c", pin],
        1,
        &["@invdyna: model parameters are inputs", "--fold-params"],
    );
    let dir = tmp("errors");
    let ir = dir.join("f.rvir");
    std::fs::write(&ir, "func @sensor_1 {\n  input %q[1]\n  %x = %q[1] * %q[1]\n  output sens.P[1] = %x\n}\n").unwrap();
    check(&[ir.to_str().unwrap(), pin], 1, &["@sensor_1: abi=pinocchio writes the URDF generator's @invdyna"]);
    let ir = dir.join("g.rvir");
    std::fs::write(
        &ir,
        "func @invdyna {\n  input %q[1]\n  input %tsim\n  %x = %q[1] * %tsim\n  output Qq[1] = %x\n}\n",
    )
    .unwrap();
    check(&[ir.to_str().unwrap(), pin], 1, &["input `tsim` has no place in Pinocchio's signature"]);
    check(
        &[ARM, "--fold-params", "-function=dirdyna", "-passes=atomise,dce<outputs=M[1][1],c>,codegen<c;abi=pinocchio>"],
        1,
        &["model_crba writes M[0..9) but the function has no output M[1][2]"],
    );
    for (bad, why) in [("trig=input", "take no sin/cos"), ("precision=f32", "are doubles")] {
        let p = format!("-passes=atomise,codegen<c;abi=pinocchio;{bad}>");
        check(&[ARM, "--fold-params", &p], 2, &[&format!("`abi=pinocchio` cannot go with `{bad}`"), why]);
    }
}

/// A mass matrix given as its upper triangle only (as Robotran writes it) is mirrored: every
/// element of `M` is written, the lower one from the upper.
#[test]
fn one_triangle_of_the_mass_matrix_is_mirrored() {
    let dir = tmp("mirror");
    let ir = dir.join("f.rvir");
    std::fs::write(
        &ir,
        "func @dirdyna {\n  input %q[1]\n  input %q[2]\n  input %qd[2]\n  %a = %q[1] * %q[2]\n  %b = %a + %q[2]\n  \
         %c = %qd[2] * %a\n  output M[1][1] = %a\n  output M[1][2] = %b\n  output M[2][2] = 2.0\n  output c[1] = %c\n  \
         output c[2] = %q[1]\n}\n",
    )
    .unwrap();
    let c = dir.join("f.c");
    let o = opt(&[ir.to_str().unwrap(), "-passes=atomise,codegen<c;abi=pinocchio>", "-o", c.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let code = std::fs::read_to_string(&c).unwrap();
    for want in ["M[0] = a;", "M[1] = b;", "M[2] = b;", "M[3] = 0x1p+1;", "nle[0] = c;", "nle[1] = q_1;"] {
        assert!(code.contains(want), "no `{want}` in\n{code}");
    }
}
