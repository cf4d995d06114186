//! `diff<wrt=…>` (issue 50 item 1) on the Robotran corpus: the stiffness `∂Qq/∂q` of every
//! `invdyna` and the Jacobians of every `dirdyna`, in both modes, against central finite
//! differences of the function itself (the interpreter, binary64). The unit tests in
//! `passes/src/diff/tests.rs` cover every rule and random DAGs.

use std::collections::HashMap;

use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::Function;

use crate::common::{corpus_files, is_loop_file, opt_to_ir, tmp};

/// The corpus `invdyna` and `dirdyna` files the front ends read.
fn dynamics_files() -> Vec<std::path::PathBuf> {
    let files: Vec<_> = corpus_files()
        .into_iter()
        .filter(|p| !is_loop_file(p))
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.contains("_invdyna_") || n.contains("_dirdyna_")
        })
        .collect();
    assert!(files.len() >= 8, "{files:?}");
    files
}

/// The largest `|d − fd| / (1 + |d|)` over every output of `f` and every `q[i]`, `d` from `g`'s
/// output `d<O>_dq<o's indices>[i]` and `fd` the central difference of `f` with step
/// `1e-6·max(1, |q[i]|)`; also the number of derivatives compared.
fn worst(f: &Function, g: &Function) -> (f64, usize) {
    let x0: HashMap<String, f64> =
        f.inputs.iter().map(|&v| (f.name_of(v).to_string(), pseudo_random_input(f.name_of(v), 3))).collect();
    let d: HashMap<String, f64> = eval::<f64>(g, |n| x0[n]).into_iter().collect();
    let (mut worst, mut n) = (0.0f64, 0);
    for &x in &f.inputs {
        let xn = f.name_of(x);
        let Some(index) = xn.strip_prefix("q[") else { continue };
        let h = 1e-6 * x0[xn].abs().max(1.0);
        let at = |dx: f64| -> HashMap<String, f64> {
            eval::<f64>(f, |m| if m == xn { x0[m] + dx } else { x0[m] }).into_iter().collect()
        };
        let (up, down) = (at(h), at(-h));
        for o in &f.outputs {
            let fd = (up[&o.name] - down[&o.name]) / (2.0 * h);
            let (family, rest) = o.name.split_at(o.name.find('[').unwrap_or(o.name.len()));
            let name = format!("d{family}_dq{rest}[{index}");
            let got = *d.get(&name).unwrap_or_else(|| panic!("no derivative output {name}"));
            worst = worst.max((got - fd).abs() / (1.0 + got.abs()));
            n += 1;
        }
    }
    (worst, n)
}

#[test]
fn corpus_jacobians_match_central_finite_differences_in_both_modes() {
    let dir = tmp("corpus");
    for p in dynamics_files() {
        let file = p.to_str().unwrap();
        let (_, m) = opt_to_ir(&dir, &[file, "-passes=atomise,cse"]);
        let f = &m.functions[0];
        for mode in ["forward", "reverse"] {
            let (r, g) = opt_to_ir(&dir, &[file, &format!("-passes=atomise,cse,diff<wrt=q;mode={mode}>")]);
            let g = &g.functions[0];
            let (w, n) = worst(f, g);
            eprintln!("{} {mode}: {n} derivatives, worst {w:.1e}", p.file_name().unwrap().to_string_lossy());
            assert!(n > 0, "{file}: no derivative compared");
            assert!(w < 1e-6, "{file} {mode}: a derivative {w:e} off the finite difference");
            assert!(r["stats"]["ops"]["total"].as_u64().unwrap() > 0);
        }
    }
}

/// An `-eval` input file at `path` for oracle state `s`: gravity, `q` (all of Pinocchio's
/// configuration coordinates robovec takes), `qd`, `qdd` and `Qq` (τ); each function reads what
/// it needs of them.
fn state_file(path: &std::path::Path, gravity: &[f64], s: &crate::pinocchio::State) -> std::path::PathBuf {
    let mut given = serde_json::Map::new();
    let mut put = |family: &str, x: &[f64]| {
        for (i, v) in x.iter().enumerate() {
            given.insert(format!("{family}[{}]", i + 1), (*v).into());
        }
    };
    put("g", gravity);
    put("q", &s.q);
    put("qd", &s.qd);
    put("qdd", &s.qdd);
    put("Qq", &s.tau);
    std::fs::write(path, serde_json::Value::Object(given).to_string()).unwrap();
    path.to_path_buf()
}

/// The outputs of `robovec-opt URDF --fold-params FLAGS -function=FUNCTION -passes=PASSES
/// -eval=FILE`.
fn eval_urdf(urdf: &str, flags: &[&str], function: &str, passes: &str, file: &std::path::Path) -> HashMap<String, f64> {
    let (function_arg, passes_arg, eval_arg) =
        (format!("-function={function}"), format!("-passes={passes}"), format!("-eval={}", file.display()));
    let mut args = vec![urdf, "--fold-params"];
    args.extend_from_slice(flags);
    args.extend([function_arg.as_str(), passes_arg.as_str(), eval_arg.as_str(), "-o", "/dev/null"]);
    let out = crate::common::opt(&args);
    assert!(out.status.success(), "{urdf} {function}: {}", crate::common::stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["outputs"].as_object().unwrap().iter().map(|(k, x)| (k.clone(), x.as_f64().unwrap())).collect()
}

/// The ∞-norm of `prefix[i][j]` − `want[i-1][j-1]` over `want`'s ∞-norm; an output missing
/// panics, naming it.
fn matrix_error(got: &HashMap<String, f64>, prefix: &str, want: &[Vec<f64>]) -> f64 {
    let norm = want.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut diff = 0.0f64;
    for (i, row) in want.iter().enumerate() {
        for (j, w) in row.iter().enumerate() {
            let name = format!("{prefix}[{}][{}]", i + 1, j + 1);
            let d = got.get(&name).unwrap_or_else(|| panic!("no output {name}"));
            diff = diff.max((d - w).abs());
        }
    }
    diff / norm.max(f64::MIN_POSITIVE)
}

/// `diff` on the URDF generator's functions (fixed base, parameters folded) against Pinocchio's
/// analytical derivatives on random states: `invdyna` differentiated with respect to `q, qd`
/// is `computeRNEADerivatives`' ∂τ/∂q, ∂τ/∂v; `fordyna` with respect to `q, qd, Qq` is
/// `computeABADerivatives`' ∂q̈/∂q, ∂q̈/∂v and M⁻¹; and the generator's `rnea_derivatives`,
/// `aba_derivatives` and `minv` (`-function=`, Pinocchio's output names) through `default<ops>`
/// give the same. Each matrix within 1e-9 relative (∞-norm of the difference over Pinocchio's
/// ∞-norm).
#[test]
fn robot_derivatives_match_pinocchio() {
    use crate::pinocchio::{oracle, python, Base};
    let Some(py) = python() else { return };
    let dir = tmp("pinocchio");
    for urdf in [
        "examples/three_link_arm/three_link_arm.urdf",
        "erd:ur_description/urdf/ur5_robot.urdf",
        "erd:panda_description/urdf/panda.urdf",
    ] {
        let o = oracle(&py, urdf, 3, 11, Base::Fixed);
        for (k, s) in o.states.iter().enumerate() {
            let n = s.qd.len();
            let file = state_file(&dir.join(format!("state{k}.json")), &o.gravity, s);
            let run = |function: &str, passes: &str| eval_urdf(&o.path, &[], function, passes, &file);
            let check = |got: &HashMap<String, f64>, prefix: &str, want: &Vec<Vec<f64>>| {
                let rel = matrix_error(got, prefix, want);
                assert!(rel <= 1e-9, "{urdf} state {k} {prefix}: relative error {rel:e}");
                eprintln!("{urdf} state {k} {prefix}: {rel:.1e}");
            };
            let rnea = run("invdyna", "atomise,cse,diff<wrt=q,qd>");
            check(&rnea, "dQq_dq", &s.dtau_dq);
            check(&rnea, "dQq_dqd", &s.dtau_dv);
            let aba = run("fordyna", "atomise,cse,diff<wrt=q,qd,Qq>");
            check(&aba, "dqdd_dq", &s.ddq_dq);
            check(&aba, "dqdd_dqd", &s.ddq_dv);
            check(&aba, "dqdd_dQq", &s.minv);
            // The generator's derivative functions under Pinocchio's names, through `default<ops>`.
            let rnea = run("rnea_derivatives", "default<ops>");
            assert_eq!(rnea.len(), 2 * n * n, "{urdf}: rnea_derivatives' outputs");
            check(&rnea, "dtau_dq", &s.dtau_dq);
            check(&rnea, "dtau_dv", &s.dtau_dv);
            let aba = run("aba_derivatives", "default<ops>");
            assert_eq!(aba.len(), 3 * n * n, "{urdf}: aba_derivatives' outputs");
            check(&aba, "ddq_dq", &s.ddq_dq);
            check(&aba, "ddq_dv", &s.ddq_dv);
            check(&aba, "Minv", &s.minv);
            let minv = run("minv", "default<ops>");
            assert_eq!(minv.len(), n * n, "{urdf}: minv's outputs");
            check(&minv, "Minv", &s.minv);
        }
    }
}

/// A robot with a massless tip (alexander's lower body: no equation reads the last joint's
/// velocity, so `invdyna` has no input `qd[13]`): the generator's `rnea_derivatives`,
/// `aba_derivatives` and `minv` are still whole `nv × nv` matrices (the column of zeros was once
/// missing from `dtau_dv`), equal to Pinocchio's within 1e-9 relative.
#[test]
fn derivative_functions_are_whole_when_a_velocity_is_not_read() {
    use crate::pinocchio::{oracle, python, Base};
    let Some(py) = python() else { return };
    let dir = tmp("pinocchio_unread");
    let o = oracle(&py, "erd:alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf", 2, 11, Base::Fixed);
    for (k, s) in o.states.iter().enumerate() {
        let n = s.qd.len();
        let file = state_file(&dir.join(format!("state{k}.json")), &o.gravity, s);
        let invdyna = eval_urdf(&o.path, &[], "invdyna", "default<ops>", &file);
        assert!(invdyna.contains_key(&format!("Qq[{n}]")), "the premise: {n} coordinates");
        for (function, checks) in [
            ("rnea_derivatives", vec![("dtau_dq", &s.dtau_dq), ("dtau_dv", &s.dtau_dv)]),
            ("aba_derivatives", vec![("ddq_dq", &s.ddq_dq), ("ddq_dv", &s.ddq_dv), ("Minv", &s.minv)]),
            ("minv", vec![("Minv", &s.minv)]),
        ] {
            let got = eval_urdf(&o.path, &[], function, "default<ops>", &file);
            assert_eq!(got.len(), checks.len() * n * n, "{function}: whole matrices");
            for (prefix, want) in checks {
                let rel = matrix_error(&got, prefix, want);
                assert!(rel <= 1e-9, "state {k} {prefix}: relative error {rel:e}");
            }
        }
    }
}

/// `codegen<c;abi=pinocchio>` on the generator's derivative functions: UR5's
/// `model_rnea_derivatives(q, v, a, dtau_dq, dtau_dv)`, `model_aba_derivatives(q, v, tau,
/// ddq_dq, ddq_dv, Minv)` and `model_minv(q, Minv)` (three files, linked together), one state a
/// call and `batch=4` (lane `l` of element `k` at `[k*4 + l]`), compiled by the system compiler
/// at -O0 (a correctness build; `-O1` took 60 % of the test's time) and called with
/// Pinocchio's vectors, against Pinocchio within 1e-9; on the fixed base and on the free flyer
/// (`q`: 13 numbers, every matrix 12 × 12, along the tangent space).
#[test]
fn pinocchio_abi_derivative_functions_in_c_match_pinocchio() {
    use crate::pinocchio::{python, Base};
    let Some(py) = python() else { return };
    for (base, flag, label) in [(Base::Fixed, None, "fixed"), (Base::FreeFlyer, Some("--free-flyer"), "free")] {
        pinocchio_abi_derivatives_in_c(&py, base, flag, label);
    }
}

/// [`pinocchio_abi_derivative_functions_in_c_match_pinocchio`] on one base (`flag` robovec's).
fn pinocchio_abi_derivatives_in_c(
    py: &std::path::Path,
    base: crate::pinocchio::Base,
    flag: Option<&str>,
    base_label: &str,
) {
    use crate::pinocchio::oracle;
    let o = oracle(py, "erd:ur_description/urdf/ur5_robot.urdf", 4, 5, base);
    let n = o.states[0].qd.len();
    let nn = n * n;
    for w in [1usize, 4] {
        let dir = tmp(&format!("pinocchio_c_{base_label}_{w}"));
        let mut files = vec!["main.c".to_string()];
        for function in ["rnea_derivatives", "aba_derivatives", "minv"] {
            let c = dir.join(format!("{function}.c"));
            let (function_arg, passes_arg) =
                (format!("-function={function}"), format!("-passes=default<ops>,codegen<c;abi=pinocchio;batch={w}>"));
            let mut args = vec![o.path.as_str(), "--fold-params"];
            args.extend(flag);
            args.extend([function_arg.as_str(), passes_arg.as_str(), "-o", c.to_str().unwrap()]);
            let out = crate::common::opt(&args);
            assert!(out.status.success(), "{function}: {}", crate::common::stderr(&out));
            files.push(format!("{function}.c"));
        }
        // The states' vectors, lane-interleaved: group g holds states g*w .. g*w + w.
        let lanes = |x: fn(&crate::pinocchio::State) -> &Vec<f64>, g: usize| -> String {
            let len = x(&o.states[0]).len();
            let v: Vec<String> = (0..len)
                .flat_map(|k| (0..w).map(move |l| (k, l)))
                .map(|(k, l)| format!("{:e}", x(&o.states[g * w + l])[k]))
                .collect();
            v.join(", ")
        };
        let mut main = format!(
            "#include <stdio.h>\n#include \"rnea_derivatives.h\"\n#include \"aba_derivatives.h\"\n#include \"minv.h\"\n\
             enum {{ W = {w}, NN = {nn} }};\n\
             static void put(const double *x, int l) {{ for (int i = 0; i < NN; i++) printf(\"%.17g\\n\", x[i * W + l]); }}\nint main(void)\n{{\n"
        );
        for g in 0..o.states.len() / w {
            main += &format!(
                "  {{\n    const double q[] = {{{}}}, v[] = {{{}}}, a[] = {{{}}}, tau[] = {{{}}};\n    \
                 static double dq[NN * W], dv[NN * W], ddq[NN * W], ddv[NN * W], mi[NN * W], mi2[NN * W];\n    \
                 model_rnea_derivatives(q, v, a, dq, dv);\n    model_aba_derivatives(q, v, tau, ddq, ddv, mi);\n    model_minv(q, mi2);\n    \
                 for (int l = 0; l < W; l++) {{ put(dq, l); put(dv, l); put(ddq, l); put(ddv, l); put(mi, l); put(mi2, l); }}\n  }}\n",
                lanes(|s| &s.q, g),
                lanes(|s| &s.qd, g),
                lanes(|s| &s.qdd, g),
                lanes(|s| &s.tau, g),
            );
        }
        main += "  return 0;\n}\n";
        std::fs::write(dir.join("main.c"), main).unwrap();
        let files: Vec<&str> = files.iter().map(String::as_str).collect();
        let exe = crate::common::compile_c(&dir, &["-O0", "-std=c99", "-Wall", "-Werror"], &files);
        let out = std::process::Command::new(&exe).output().unwrap();
        assert!(out.status.success());
        let got: Vec<f64> = String::from_utf8(out.stdout).unwrap().lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(got.len(), o.states.len() * 6 * nn);
        for (k, (s, chunk)) in o.states.iter().zip(got.chunks(6 * nn)).enumerate() {
            for (m, (label, want)) in [
                ("dtau_dq", &s.dtau_dq),
                ("dtau_dv", &s.dtau_dv),
                ("ddq_dq", &s.ddq_dq),
                ("ddq_dv", &s.ddq_dv),
                ("Minv", &s.minv),
                ("minv's Minv", &s.minv),
            ]
            .into_iter()
            .enumerate()
            {
                let flat: Vec<f64> = want.iter().flatten().copied().collect();
                let norm = flat.iter().fold(0.0f64, |x, y| x.max(y.abs()));
                let c = &chunk[m * nn..(m + 1) * nn];
                let diff = c.iter().zip(&flat).fold(0.0f64, |x, (a, b)| x.max((a - b).abs()));
                assert!(
                    diff / norm <= 1e-9,
                    "{base_label} batch={w} state {k} {label}: relative error {:e}",
                    diff / norm
                );
            }
        }
    }
}

/// Where a configuration coordinate is not a velocity coordinate, the generator's
/// `rnea_derivatives` and `aba_derivatives` differentiate along Pinocchio's tangent space
/// (`integrate(model, q, dq)`): UR5 on a free flyer (`--free-flyer`; q: 13 numbers, v: 12) and
/// the three-link arm's continuous joints as `(cos θ, sin θ)` pairs (`--continuous=cos-sin`; q:
/// 6 numbers, v: 3), each given Pinocchio's own `q`, against `computeRNEADerivatives` and
/// `computeABADerivatives` entry for entry, within 1e-9 relative per matrix.
#[test]
fn derivatives_are_along_pinocchios_tangent_space() {
    use crate::pinocchio::{oracle, python, Base};
    let Some(py) = python() else { return };
    let dir = tmp("tangent");
    for (urdf, base, flag) in [
        ("erd:ur_description/urdf/ur5_robot.urdf", Base::FreeFlyer, "--free-flyer"),
        ("examples/three_link_arm/three_link_arm.urdf", Base::Fixed, "--continuous=cos-sin"),
    ] {
        let o = oracle(&py, urdf, 3, 13, base);
        for (k, s) in o.states.iter().enumerate() {
            let nv = s.qd.len();
            assert!(s.q_pinocchio.len() > nv, "{urdf}: more configuration than velocity coordinates");
            let state = crate::pinocchio::State { q: s.q_pinocchio.clone(), ..s.clone() };
            let file = state_file(&dir.join(format!("state{k}.json")), &o.gravity, &state);
            for (function, checks) in [
                ("rnea_derivatives", vec![("dtau_dq", &s.dtau_dq), ("dtau_dv", &s.dtau_dv)]),
                ("aba_derivatives", vec![("ddq_dq", &s.ddq_dq), ("ddq_dv", &s.ddq_dv), ("Minv", &s.minv)]),
            ] {
                let got = eval_urdf(&o.path, &[flag], function, "default<ops>", &file);
                assert_eq!(got.len(), checks.len() * nv * nv, "{urdf} {function}: nv × nv matrices");
                for (prefix, want) in checks {
                    let rel = matrix_error(&got, prefix, want);
                    assert!(rel <= 1e-9, "{urdf} state {k} {prefix}: relative error {rel:e}");
                    eprintln!("{urdf} {flag} state {k} {prefix}: {rel:.1e}");
                }
            }
        }
    }
}

/// The derivative functions' trig variables keep their coordinate's names (`%C4 = cos %q[4]`,
/// `%S4`), which `codegen<c;trig=input>` takes as inputs and the bench feeds by name: Panda's
/// `aba_derivatives` reads `cos q[1]` through `rnea_derivatives` where its `fordyna` does not
/// (its first axis is along gravity), and that variable was once named after the pass.
#[test]
fn derivative_functions_name_their_trig_variables_by_coordinate() {
    use crate::pinocchio::{oracle, python, Base};
    let Some(py) = python() else { return };
    let o = oracle(&py, "erd:panda_description/urdf/panda.urdf", 1, 1, Base::Fixed);
    let dir = tmp("trig_names");
    for function in ["rnea_derivatives", "aba_derivatives", "minv"] {
        let out_path = dir.join(format!("{function}.rvir"));
        let function_arg = format!("-function={function}");
        let out = crate::common::opt(&[
            &o.path,
            "--fold-params",
            "-gravity=0,0,-9.81",
            &function_arg,
            "-passes=atomise,cse",
            "-o",
            out_path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{function}: {}", crate::common::stderr(&out));
        let text = std::fs::read_to_string(&out_path).unwrap();
        let mut seen = 0;
        for line in text.lines() {
            let Some((name, def)) = line.trim().split_once(" = ") else { continue };
            for (fun, letter) in [("cos %q[", 'C'), ("sin %q[", 'S')] {
                if let Some(i) = def.strip_prefix(fun).and_then(|r| r.strip_suffix(']')) {
                    assert_eq!(name, format!("%{letter}{i}"), "{function}: {line}");
                    seen += 1;
                }
            }
        }
        assert!(seen >= 12, "{function}: {seen} trig variables");
    }
}
