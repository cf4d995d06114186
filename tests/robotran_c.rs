//! The Robotran-C writer (`robovec_dynamics::robotran_c`, issue 14): every generated model, written
//! as Robotran 6.6 C by `robovec-gen --format c`, reads back through robovec's own C front end to
//! the same IR, evaluates bit for bit the same, and compiles and runs as C with the system
//! compiler against a stand-in `MbsData`.
//!
//! "The same IR" is the printed `.rvir` text of the function with two things normalised that
//! the C text does not carry (`robotran_c`'s module doc): the order of the `input` lines (the
//! C front end declares inputs in order of first use, the generator in order of creation) and
//! the `equations` count, which is checked separately: the C front end counts every statement
//! it read, so it is the generator's count plus one per output.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use robovec::export::{Export, Format, Source};
use robovec_dynamics::topology::{build, Topology};
use robovec_front::FrontOptions;
use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::Function;

use crate::common::{opt, stderr, tmp};

/// The printed function with its `input` lines sorted and its `equations` line dropped.
fn normalised(f: &Function) -> String {
    let text = f.to_string();
    let mut inputs: Vec<&str> = text.lines().filter(|l| l.starts_with("  input ")).collect();
    inputs.sort_unstable();
    let rest = text.lines().filter(|l| !l.starts_with("  input ") && !l.starts_with("  equations "));
    inputs.into_iter().chain(rest).collect::<Vec<_>>().join("\n")
}

/// Asserts that `back` (read from the written C) is `orig` (generated), and that both evaluate to
/// the same bits on three pseudo-random input points.
fn assert_same(orig: &Function, back: &Function, what: &str) {
    assert_eq!(normalised(orig), normalised(back), "{what}: the C front end read back another function");
    assert_eq!(
        back.equations,
        orig.equations.map(|n| n + orig.outputs.len() as u32),
        "{what}: statements read = temporaries + outputs"
    );
    for seed in 1..=3 {
        let a = eval::<f64>(orig, |n| pseudo_random_input(n, seed));
        let b = eval::<f64>(back, |n| pseudo_random_input(n, seed));
        assert_eq!(a.len(), b.len(), "{what}");
        for ((na, va), (nb, vb)) in a.iter().zip(&b) {
            assert_eq!((na, va.to_bits()), (nb, vb.to_bits()), "{what}: output {na} at seed {seed}");
        }
    }
}

/// Writes `function` of `source` as C into `dir` through the library entry of `robovec-gen`,
/// reads it back with the registered C front end and returns (generated, read back).
fn round_trip(dir: &Path, source: Source, function: &str, fold: bool, floating: bool) -> (Function, Function) {
    let c = dir.join(format!("mbs_{function}_model.c"));
    let e = Export {
        source: source.clone(),
        format: Format::C,
        function: function.into(),
        floating_base: floating,
        fold_params: fold,
        params_out: None,
        output: Some(c.clone()),
    };
    robovec::export::run(&e, &mut Vec::new()).unwrap_or_else(|f| panic!("{}", f.message()));
    let orig = match source {
        Source::Topology { topology, dof, seed } => {
            let robot = build(topology, dof, seed);
            let robot = if floating { robot.with_floating_base().unwrap() } else { robot };
            // Only the function written is generated, in the frames that suit it (as `robovec-gen`).
            let request = robovec_dynamics::Request {
                fold,
                functions: Some(vec![function.to_string()]),
                ..robovec_dynamics::Request::default()
            };
            robovec_dynamics::generate_with(&robovec_dynamics::Model { robot }, &request).expect("no deadline").module
        }
        Source::Urdf(p) => {
            let front = FrontOptions {
                fold_params: fold,
                floating_base: floating,
                functions: Some(vec![function.to_string()]),
                ..FrontOptions::default()
            };
            robovec::driver::load_with(&p.to_string_lossy(), &front)
                .unwrap_or_else(|f| panic!("{}", f.message()))
                .0
                .module
        }
    };
    let (back, _) = robovec::driver::load(&c.to_string_lossy()).unwrap_or_else(|f| panic!("{}", f.message()));
    assert_eq!(back.functions.len(), 1);
    (orig.function(function).expect("generated").clone(), back.functions[0].clone())
}

#[test]
fn every_topology_family_reads_back_to_the_same_ir() {
    let dir = tmp("families");
    let mut checked = 0;
    for topology in Topology::ALL {
        for dof in [4, 9, 23] {
            for function in ["invdyna", "dirdyna"] {
                for fold in [false, true] {
                    for floating in [false, true] {
                        let what = format!("{} {dof} {function} fold={fold} floating={floating}", topology.name());
                        let source = Source::Topology { topology, dof, seed: 1 };
                        let (orig, back) = round_trip(&dir, source, function, fold, floating);
                        assert_same(&orig, &back, &what);
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * 3 * 2 * 2 * 2);
}

/// A file of example-robot-data in Pinocchio's environment (`None`, with a note, where the
/// environment is missing outside CI: see `tests/pinocchio.rs`).
fn erd(rel: &str) -> Option<PathBuf> {
    let venv = crate::pinocchio::python()?.parent()?.parent()?.to_path_buf();
    let found = std::fs::read_dir(venv.join("lib")).ok()?.flatten().find_map(|e| {
        let p = e.path().join("site-packages/cmeel.prefix/share/example-robot-data/robots").join(rel);
        p.exists().then_some(p)
    });
    Some(found.unwrap_or_else(|| panic!("example-robot-data's {rel} is missing under {}", venv.display())))
}

#[test]
fn examples_and_example_robot_data_read_back_to_the_same_ir() {
    let dir = tmp("robots");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut robots = vec![
        (root.join("examples/double_pendulum/double_pendulum.urdf"), false),
        (root.join("examples/three_link_arm/three_link_arm.urdf"), false),
        (root.join("examples/three_link_arm/three_link_arm.urdf"), true),
    ];
    for (rel, floating) in [
        ("ur_description/urdf/ur5_robot.urdf", false),
        ("panda_description/urdf/panda.urdf", false),
        ("solo_description/robots/solo12.urdf", true),
    ] {
        robots.extend(erd(rel).map(|p| (p, floating)));
    }
    for (urdf, floating) in robots {
        for function in ["invdyna", "dirdyna"] {
            for fold in [false, true] {
                let what = format!("{} {function} fold={fold} floating={floating}", urdf.display());
                let (orig, back) = round_trip(&dir, Source::Urdf(urdf.clone()), function, fold, floating);
                assert_same(&orig, &back, &what);
            }
        }
    }
}

fn gen(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robovec-gen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("robovec-gen runs")
}

/// The `-stats` line of `@function` (`@dirdyna: equations …, ops …`).
fn stats_line(out: &std::process::Output, function: &str) -> String {
    let err = stderr(out);
    let prefix = format!("@{function}: equations");
    let line = err.lines().find(|l| l.starts_with(&prefix)).unwrap_or_else(|| panic!("no stats line in {err}"));
    // The equation count differs by construction (module doc); the rest must not.
    line.split_once(", ").map_or(line, |(_, rest)| rest).to_string()
}

#[test]
fn robovec_gen_writes_c_that_robovec_opt_reads_like_the_urdf() {
    let dir = tmp("cli");
    let urdf = "examples/three_link_arm/three_link_arm.urdf";
    let c = dir.join("mbs_dirdyna_arm.c");
    let params = dir.join("params.json");
    let o = gen(&[
        "--urdf",
        urdf,
        "--format",
        "c",
        "--function",
        "dirdyna",
        "--params-out",
        params.to_str().unwrap(),
        "-o",
        c.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&c).unwrap();
    assert!(text.contains("void mbs_dirdyna(double **M,double *c,\nMbsData *s, double tsim)"), "{text}");
    assert!(text.contains("#include \"mbs_dirdyna_arm.h\""));
    let h = std::fs::read_to_string(dir.join("mbs_dirdyna_arm.h")).unwrap();
    assert!(h.lines().all(|l| l.starts_with("double    ") && l.ends_with(';')), "{h}");
    for (i, l) in text.lines().enumerate() {
        assert!(l.len() <= 130, "line {} is {} columns", i + 1, l.len());
    }

    let pipeline = "-passes=atomise,zero-removal,balance";
    let from_c = opt(&[c.to_str().unwrap(), pipeline, "-stats", "-o", "/dev/null"]);
    let from_urdf = opt(&[urdf, "-function=dirdyna", pipeline, "-stats", "-o", "/dev/null"]);
    assert!(from_c.status.success() && from_urdf.status.success(), "{}{}", stderr(&from_c), stderr(&from_urdf));
    assert_eq!(stats_line(&from_c, "dirdyna"), stats_line(&from_urdf, "dirdyna"));

    let opt_params = dir.join("opt-params.json");
    let o = opt(&[urdf, "-function=dirdyna", "-params-out", opt_params.to_str().unwrap(), "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |p: &Path| serde_json::from_slice::<BTreeMap<String, f64>>(&std::fs::read(p).unwrap()).unwrap();
    assert_eq!(read(&params), read(&opt_params));
    // Every parameter the C file reads has its value in the JSON file.
    for name in read(&params).keys() {
        assert!(text.contains(&format!("s->{name}")), "{name} is not read by the C file");
    }
}

#[test]
fn robovec_gen_refuses_bad_input_and_usage_and_writes_nothing() {
    let dir = tmp("refusals");
    let c = dir.join("x.c");
    let cs = c.to_str().unwrap();
    // C needs -o FILE.c (two files); --params-out with folded parameters is meaningless.
    for args in [
        vec!["--topology", "serial", "--dof", "3", "--format", "c", "--function", "invdyna"],
        vec!["--topology", "serial", "--dof", "3", "--format", "c", "--function", "invdyna", "-o", "x.urdf"],
        vec![
            "--topology",
            "serial",
            "--dof",
            "3",
            "--format",
            "c",
            "--fold-params",
            "--params-out",
            "p.json",
            "-o",
            cs,
        ],
        vec!["--topology", "serial", "--dof", "3", "--format", "c", "--function", "sensor", "-o", cs],
        vec!["--topology", "serial", "--urdf", "a.urdf", "-o", cs],
        // --function belongs to C (required there), not to the URDF writer.
        vec!["--topology", "serial", "--dof", "3", "--format", "c", "-o", cs],
        vec!["--topology", "serial", "--dof", "3", "--function", "dirdyna", "-o", "x.urdf"],
    ] {
        let o = gen(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
    let bad = dir.join("bad.urdf");
    std::fs::write(&bad, "<robot name=\"r\">\n  <link name=\"a\"/>\n  <joint name=\"j\" type=\"revolute\">\n    <parent link=\"a\"/>\n  </joint>\n</robot>\n").unwrap();
    let o = gen(&["--urdf", bad.to_str().unwrap(), "--format", "c", "--function", "invdyna", "-o", cs]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.urdf:3:"), "{}", stderr(&o));
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(left, vec![std::ffi::OsString::from("bad.urdf")], "nothing written after a failure");
}

/// The stand-in for Robotran's `mbs_data.h`: the fields the dynamics files read, 1-based as in
/// Robotran (index 0 unused).
const MBS_DATA_H: &str =
    "typedef struct MbsData {\n  double *q, *qd, *qdd, *g, *m;\n  double **dpt, **l, **In, **frc, **trq;\n} MbsData;\n";

/// `robovec-gen` C, compiled by the system compiler (`-O0 -ffp-contract=off`, warnings as
/// errors) with a `main` that fills `MbsData` with the inputs, prints the outputs' bits
/// and is compared bit for bit with the interpreter on the generated function.
#[test]
fn written_c_compiles_and_runs_bit_exact() {
    let dir = tmp("compile");
    for (topology, function, floating) in
        [(Topology::Serial, "dirdyna", true), (Topology::SemiSerial, "invdyna", false)]
    {
        let source = Source::Topology { topology, dof: 7, seed: 3 };
        let (orig, _) = round_trip(&dir, source, function, false, floating);
        let seed = 11;
        let mut main = String::from(
            "#include <stdint.h>\n#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\n#include \"mbs_data.h\"\n",
        );
        // An output's bits, in hex (as tests/codegen_c.rs reads them).
        main.push_str("static void bits(const char *name, double x) { uint64_t b; memcpy(&b, &x, 8); printf(\"%s %016llx\\n\", name, (unsigned long long)b); }\n");
        let (outputs, sig) = if function == "invdyna" {
            ("Qq", "void mbs_invdyna(double *Qq, MbsData *s, double tsim);\n")
        } else {
            ("M c", "void mbs_dirdyna(double **M, double *c, MbsData *s, double tsim);\n")
        };
        main.push_str(sig);
        main.push_str("static double *vec(void) { return calloc(64, sizeof(double)); }\n");
        main.push_str("static double **mat(void) { double **m = calloc(64, sizeof(double *)); for (int i = 0; i < 64; i++) m[i] = vec(); return m; }\n");
        main.push_str("int main(void) {\n  MbsData d; MbsData *s = &d;\n");
        main.push_str("  d.q = vec(); d.qd = vec(); d.qdd = vec(); d.g = vec(); d.m = vec();\n");
        main.push_str("  d.dpt = mat(); d.l = mat(); d.In = mat(); d.frc = mat(); d.trq = mat();\n");
        for &v in &orig.inputs {
            let name = orig.name_of(v);
            main.push_str(&format!("  s->{name} = {:e};\n", pseudo_random_input(name, seed)));
        }
        if outputs == "Qq" {
            main.push_str("  double *Qq = vec();\n  mbs_invdyna(Qq, s, 0.0);\n");
        } else {
            main.push_str("  double **M = mat(); double *c = vec();\n  mbs_dirdyna(M, c, s, 0.0);\n");
        }
        for o in &orig.outputs {
            main.push_str(&format!("  bits(\"{0}\", {0});\n", o.name));
        }
        main.push_str("  return 0;\n}\n");
        std::fs::write(dir.join("mbs_data.h"), MBS_DATA_H).unwrap();
        std::fs::write(dir.join("mbs_project_interface.h"), "").unwrap();
        std::fs::write(dir.join("main.c"), main).unwrap();
        let exe = dir.join("run");
        let c = format!("mbs_{function}_model.c");
        let out = Command::new("cc")
            .current_dir(&dir)
            .args(["-std=c99", "-O0", "-ffp-contract=off", "-Wall", "-Werror", "-o"])
            .arg(&exe)
            .args(["main.c", &c, "-lm"])
            .output()
            .expect("cc runs");
        assert!(out.status.success(), "cc: {}", String::from_utf8_lossy(&out.stderr));
        let run = Command::new(&exe).output().unwrap();
        assert!(run.status.success());
        let printed: Vec<(String, u64)> = String::from_utf8(run.stdout)
            .unwrap()
            .lines()
            .map(|l| {
                let (n, x) = l.split_once(' ').unwrap();
                (n.to_string(), u64::from_str_radix(x, 16).unwrap())
            })
            .collect();
        let want = eval::<f64>(&orig, |n| format!("{:e}", pseudo_random_input(n, seed)).parse().unwrap());
        assert_eq!(printed.len(), want.len());
        for ((n, x), (m, y)) in printed.iter().zip(&want) {
            assert_eq!((n, *x), (m, y.to_bits()), "{function}: {n}");
        }
    }
}

/// robovec-gen's outputs are distinct files, checked before any work (issue 29: `-o x.c
/// --params-out x.h` replaced the header that `x.c` includes with the JSON, exit 0).
#[test]
fn robovec_gen_refuses_two_outputs_on_one_file() {
    let d = crate::common::tmp("gen_collide");
    let c = d.join("x.c");
    for other in [d.join("x.h"), d.join("sub/../x.c")] {
        let o = gen(&[
            "--topology",
            "serial",
            "--dof",
            "3",
            "--format",
            "c",
            "--function",
            "dirdyna",
            "-o",
            c.to_str().unwrap(),
            "--params-out",
            other.to_str().unwrap(),
        ]);
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains(&format!("--params-out `{}` are the same file", other.display())), "{e}");
        assert!(std::fs::read_dir(&d).unwrap().next().is_none(), "nothing written: {e}");
    }
}
