//! The URDF front end through `robovec-opt` (issue 14): the generated inverse dynamics of the
//! double pendulum against the hand-derived Robotran-format file of the same model, the
//! parameter file round trip through `specialize` and `-eval`, and diagnostics.

use std::collections::BTreeMap;

use robovec_front::FrontOptions;

use crate::common::{opt, stderr, tmp};

const URDF: &str = "examples/double_pendulum/double_pendulum.urdf";
const HAND: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

fn path(rel: &str) -> String {
    format!("{}/{rel}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn double_pendulum_matches_the_hand_derived_file() {
    let (gen, _) = robovec::driver::load_with(&path(URDF), &FrontOptions::default()).expect("URDF loads");
    let params = gen.params.clone().expect("symbolic parameters have values");
    // The values of the URDF, under the hand-written file's names (README beside it).
    for (name, x) in [("m[1]", 1.3), ("m[2]", 0.7), ("l[2][1]", 0.4), ("l[2][2]", 0.35), ("dpt[2][2]", 0.8)] {
        assert_eq!(params.get(name), Some(&x), "{name}");
    }
    assert_eq!(params.get("In[1][1]"), Some(&0.05));
    assert_eq!(params.get("In[1][2]"), Some(&0.03));
    let (hand, _) = robovec::driver::load(&path(HAND)).expect("example loads");
    let (g, h) = (&gen.module.functions[0], &hand.functions[0]);
    let mut rng = robovec_ir::rng::SplitMix64::new(11);
    for _ in 0..20 {
        let mut given: BTreeMap<String, f64> = params.clone();
        given.extend([("g[1]".into(), 0.0), ("g[2]".into(), 0.0), ("g[3]".into(), -9.81)]);
        for i in 1..=2 {
            for v in ["q", "qd", "qdd"] {
                given.insert(format!("{v}[{i}]"), 4.0 * rng.unit() - 2.0);
            }
        }
        let a = robovec::eval::evaluate(g, &given, false).outputs;
        let b = robovec::eval::evaluate(h, &given, false).outputs;
        for k in ["Qq[1]", "Qq[2]"] {
            assert!((a[k] - b[k]).abs() <= 1e-12 * b[k].abs().max(1.0), "{k}: generated {} hand {}", a[k], b[k]);
        }
    }
    // The generator's folding keeps the equations as small as the hand derivation's.
    let ops = |f: &robovec_ir::Function| robovec_passes::atomise::atomise_function(f).op_counts().total;
    assert!(ops(g) <= ops(h), "generated {} ops, hand-derived {}", ops(g), ops(h));
}

/// `dirdyna` against `invdyna` without any outside reference: `Qq(q, qd, qdd) = M(q) qdd +
/// c(q, qd)` at random states (random gravity too), with the URDF's parameters given and
/// folded; `M` symmetric.
#[test]
fn direct_dynamics_agrees_with_inverse_dynamics() {
    for (urdf, n) in [(URDF, 2), ("examples/three_link_arm/three_link_arm.urdf", 3)] {
        for fold in [false, true] {
            let (gen, _) =
                robovec::driver::load_with(&path(urdf), &FrontOptions { fold_params: fold, ..FrontOptions::default() })
                    .expect("URDF loads");
            let fs = &gen.module.functions;
            let (inv, dir) = (&fs[0], &fs[1]);
            assert_eq!((inv.name.as_str(), dir.name.as_str()), ("invdyna", "dirdyna"));
            assert_eq!(dir.outputs.len(), n * n + n, "{urdf}: M and c");
            let mut rng = robovec_ir::rng::SplitMix64::new(5);
            for _ in 0..10 {
                let mut given: BTreeMap<String, f64> = gen.params.clone().unwrap_or_default();
                for k in 1..=3 {
                    given.insert(format!("g[{k}]"), 20.0 * rng.unit() - 10.0);
                }
                for i in 1..=n {
                    for v in ["q", "qd", "qdd"] {
                        given.insert(format!("{v}[{i}]"), 4.0 * rng.unit() - 2.0);
                    }
                }
                let qq = robovec::eval::evaluate(inv, &given, false).outputs;
                let mc = robovec::eval::evaluate(dir, &given, false).outputs;
                for i in 1..=n {
                    let mut rhs = mc[&format!("c[{i}]")];
                    for j in 1..=n {
                        let (mij, mji) = (mc[&format!("M[{i}][{j}]")], mc[&format!("M[{j}][{i}]")]);
                        assert_eq!(mij, mji, "{urdf}: M[{i}][{j}] symmetric");
                        rhs += mij * given[&format!("qdd[{j}]")];
                    }
                    let lhs = qq[&format!("Qq[{i}]")];
                    assert!(
                        (lhs - rhs).abs() <= 1e-12 * lhs.abs().max(1.0),
                        "{urdf} (fold {fold}) Qq[{i}] {lhs} vs M qdd + c {rhs}"
                    );
                }
            }
        }
    }
}

#[test]
fn runs_like_a_robotran_file() {
    let o = opt(&[URDF, "-function=invdyna", "-passes=atomise", "-stats", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("@invdyna: equations 16, ops 41"), "{}", stderr(&o));
}

#[test]
fn parameter_file_feeds_specialize_and_eval() {
    let d = tmp("params");
    let p = d.join("params.json");
    let s = d.join("state.json");
    std::fs::write(&s, r#"{"q[1]": 0.3, "q[2]": -1.1, "qd[1]": 0.7, "qd[2]": 0.2, "qdd[1]": -0.4, "qdd[2]": 1.5, "g[1]": 0, "g[2]": 0, "g[3]": -9.81}"#).unwrap();
    let o = opt(&[URDF, "-passes=", "-o", "/dev/null", &format!("-params-out={}", p.display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: BTreeMap<String, f64> = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    assert_eq!(json.get("m[2]"), Some(&0.7));
    let eval = |args: &[&str]| -> BTreeMap<String, f64> {
        let o = opt(args);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        serde_json::from_value(v["outputs"].clone()).unwrap()
    };
    let spec = format!("-passes=atomise,specialize<params={}>", p.display());
    for (function, outputs) in [("-function=invdyna", 2), ("-function=dirdyna", 6)] {
        let a = eval(&[URDF, function, &spec, &format!("-eval={}", s.display())]);
        let b = eval(&[URDF, function, "--fold-params", "-passes=atomise", &format!("-eval={}", s.display())]);
        assert_eq!(a.len(), outputs, "{function}");
        for (k, x) in &a {
            assert!((x - b[k]).abs() <= 1e-12 * x.abs().max(1.0), "{k}: {x} vs {}", b[k]);
        }
    }
}

/// An inertia tensor no rigid body has (`ixy² > ixx·iyy`, as in TIAGo's URDF) is a located
/// warning on stderr, and the run goes on with the tensor as written (exit 0), as Pinocchio's
/// reader takes it.
#[test]
fn an_unphysical_inertia_tensor_is_a_located_warning() {
    let d = tmp("unphysical");
    let f = d.join("tensor.urdf");
    std::fs::write(
        &f,
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"><inertial><mass value=\"1\"/>\n<inertia ixx=\"1\" ixy=\"3\" iyy=\"1\" izz=\"1\"/></inertial></link>\n\
         <joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/></joint>\n</robot>\n",
    )
    .unwrap();
    let out = d.join("out.rvir");
    let o = opt(&[f.to_str().unwrap(), "-passes=atomise", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("warning: inertia tensor is not positive semi-definite") && e.contains("tensor.urdf:4:1"),
        "{e}"
    );
    assert!(std::fs::read_to_string(&out).unwrap().contains("func @invdyna"));
}

#[test]
fn bad_urdf_is_a_located_diagnostic() {
    let d = tmp("bad");
    let f = d.join("bad.urdf");
    std::fs::write(&f, "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"><inertial><mass value=\"-1\"/></inertial></link>\n</robot>\n").unwrap();
    let o = opt(&[f.to_str().unwrap(), "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("negative mass -1") && e.contains("bad.urdf:3:"), "{e}");
    // A parameter file only exists for inputs that state parameter values.
    let o = opt(&[HAND, "-passes=", "-o", "/dev/null", &format!("-params-out={}", d.join("p.json").display())]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!d.join("p.json").exists());
    let sdf = d.join("robot.sdf");
    std::fs::write(&sdf, "<sdf/>").unwrap();
    let o = opt(&[sdf.to_str().unwrap(), "-passes="]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(".urdf"), "{}", stderr(&o));
    // A URDF joint named like a floating-base joint cannot take --floating-base.
    let clash = d.join("clash.urdf");
    std::fs::write(
        &clash,
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<joint name=\"R2\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/></joint>\n</robot>\n",
    )
    .unwrap();
    let o = opt(&[clash.to_str().unwrap(), "--floating-base", "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("`R2` is a name of robovec's floating base") && e.contains("clash.urdf:4:1"), "{e}");
    assert!(opt(&[clash.to_str().unwrap(), "-passes=atomise", "-o", "/dev/null"]).status.success());
    // A link named `world` (the base's fixed root): the diagnostic points at that `<link>`.
    std::fs::write(
        &clash,
        "<robot name=\"r\">\n<link name=\"a\"/>\n  <link name=\"world\"/>\n<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"world\"/></joint>\n</robot>\n",
    )
    .unwrap();
    let o = opt(&[clash.to_str().unwrap(), "--floating-base", "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("`world` is a name of robovec's floating base") && e.contains("clash.urdf:3:3"), "{e}");
}

/// `robovec-gen` writes a topology family's robot as the library's URDF text (file and stdout
/// alike), `robovec-opt` reads it, and bad usage exits 2 with nothing written.
#[test]
fn robovec_gen_writes_a_topology_as_urdf_that_robovec_opt_reads() {
    use robovec_dynamics::topology::{build, Topology};
    let gen = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_robovec-gen")).args(args).output().expect("robovec-gen runs")
    };
    let d = tmp("robovec_gen");
    let file = d.join("semi.urdf");
    let o = gen(&["--topology", "semi-serial", "--dof", "9", "--seed", "4", "-o", file.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let want = robovec_dynamics::urdf_out::write_urdf(&build(Topology::SemiSerial, 9, 4));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), want);
    let o = gen(&["--topology", "semi-serial", "--dof", "9", "--seed", "4"]);
    assert_eq!(String::from_utf8_lossy(&o.stdout), want);
    // The same equations as the generator writes straight from the robot.
    let direct =
        robovec_dynamics::generate(&robovec_dynamics::Model { robot: build(Topology::SemiSerial, 9, 4) }, false);
    let rvir = d.join("direct.rvir");
    std::fs::write(&rvir, direct.module.to_string()).unwrap();
    let stats = |input: &str| {
        let o = opt(&[input, "-function=dirdyna", "-passes=atomise", "-stats", "-o", "/dev/null"]);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o).lines().find(|l| l.starts_with("@dirdyna")).expect("stats line").to_string()
    };
    assert_eq!(stats(file.to_str().unwrap()), stats(rvir.to_str().unwrap()));
    // Bad usage: exit 2, no file.
    for bad in [&["--topology", "tree", "--dof", "3"][..], &["--topology", "serial", "--dof", "0"], &["--dof", "3"]] {
        let out = d.join("bad.urdf");
        let mut args = bad.to_vec();
        args.extend(["-o", out.to_str().unwrap()]);
        let o = gen(&args);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// Issue 28 item 2: `-function` reaches the generator, which builds only that function; a name
/// it does not write is refused before any work, as against a loaded module.
#[test]
fn function_builds_only_the_function_asked_for() {
    use robovec_dynamics::topology::{build, Topology};
    let d = tmp("only_asked");
    // A star: its dirdyna has n² outputs, its invdyna n.
    let urdf = d.join("star.urdf");
    std::fs::write(&urdf, robovec_dynamics::urdf_out::write_urdf(&build(Topology::Star, 60, 3))).unwrap();
    let urdf = urdf.to_str().unwrap();
    let funcs = |args: &[&str]| -> Vec<String> {
        let out = d.join("out.rvir");
        let mut all = vec![urdf, "-passes=atomise", "-o", out.to_str().unwrap()];
        all.extend(args);
        let o = opt(&all);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        text.lines()
            .filter_map(|l| l.strip_prefix("func @"))
            .map(|l| l.split([' ', '{']).next().unwrap().to_string())
            .collect()
    };
    assert_eq!(funcs(&[]), ["invdyna", "dirdyna"]);
    assert_eq!(funcs(&["-function=invdyna"]), ["invdyna"]);
    assert_eq!(funcs(&["-function=dirdyna"]), ["dirdyna"]);
    // -params-out writes the parameters the functions built read.
    let p = d.join("p.json");
    let o = opt(&[urdf, "-function=invdyna", "-passes=", "-o", "/dev/null", &format!("-params-out={}", p.display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: BTreeMap<String, f64> = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    assert!(json.contains_key("m[60]") && json.keys().all(|k| !k.starts_with("q")), "{json:?}");
    // An unknown name: usage error naming what the generator writes, nothing written.
    let out = d.join("none.rvir");
    let o = opt(&[urdf, "-function=sensor_1", "-passes=atomise", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no function `sensor_1` in the input; functions: invdyna, dirdyna, fordyna"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// A URDF is XML, read as UTF-8: an invalid byte is refused at its line and column (issue 29:
/// it was read as `?` and accepted), with exit 1 and nothing written.
#[test]
fn a_urdf_with_invalid_utf8_is_refused_where_the_byte_is() {
    let d = tmp("bad_utf8");
    let text = std::fs::read(path("examples/three_link_arm/three_link_arm.urdf")).unwrap();
    let at = text.windows(6).position(|w| w == b"name=\"").unwrap() + 6;
    let bad = d.join("bad.urdf");
    std::fs::write(&bad, [&text[..at], b"\xff", &text[at..]].concat()).unwrap();
    let out = d.join("out.rvir");
    let o = opt(&[bad.to_str().unwrap(), "-passes=atomise", "-o", out.to_str().unwrap()]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("error: invalid UTF-8 (byte 0xff): a URDF file is read as UTF-8"), "{e}");
    let line = text[..at].iter().filter(|&&b| b == b'\n').count() + 1;
    let col = at - text[..at].iter().rposition(|&b| b == b'\n').map_or(0, |k| k + 1) + 1;
    assert!(e.contains(&format!("bad.urdf:{line}:{col}")), "{e}");
    assert!(!out.exists());
}

/// A name holding a line break comes back from robovec-gen as a character reference, so a
/// reader gets the same name (issue 29: it came back as a raw newline, which XML readers turn
/// into a space).
#[test]
fn robovec_gen_writes_line_breaks_in_names_as_character_references() {
    let d = tmp("newline_names");
    let text = std::fs::read_to_string(path("examples/three_link_arm/three_link_arm.urdf")).unwrap();
    let text = text
        .replace("<robot name=\"three_link_arm\">", "<robot name=\"three&#10;arm\">")
        .replace("\"base\"", "\"base&#10;x\"");
    let input = d.join("nl.urdf");
    std::fs::write(&input, &text).unwrap();
    let out = d.join("out.urdf");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_robovec-gen"))
        .args(["--urdf", input.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let back = std::fs::read_to_string(&out).unwrap();
    assert!(back.contains("<robot name=\"three&#10;arm\">") && back.contains("<link name=\"base&#10;x\">"), "{back}");
    assert!(back.contains("<parent link=\"base&#10;x\"/>"), "{back}");
}

/// `--free-flyer` and `-gravity` from the command line: the free flyer's numbering (seven
/// configuration coordinates, six velocity ones, the URDF's joints after), `-gravity` writing
/// the numbers where the inputs `g[k]` were (the same `Qq` as those inputs given the same
/// values), and the diagnostics: `--free-flyer` with `--floating-base` and a malformed
/// `-gravity` exit 2, a URDF joint named `root_joint` exits 1 at that joint.
#[test]
fn free_flyer_and_gravity_options() {
    let arm = path("examples/three_link_arm/three_link_arm.urdf");
    let load = |gravity: Option<[f64; 3]>| {
        let opts = FrontOptions { free_flyer: true, gravity, fold_params: true, ..FrontOptions::default() };
        robovec::driver::load_with(&arm, &opts).expect("URDF loads").0
    };
    let (inputs, folded) = (load(None), load(Some([0.5, -1.0, -9.81])));
    let names = |m: &robovec_front::Loaded| -> Vec<String> {
        let f = &m.module.functions[0];
        f.inputs.iter().map(|&v| f.name_of(v).to_string()).collect()
    };
    let with_g = names(&inputs);
    for k in 1..=3 {
        assert!(with_g.contains(&format!("g[{k}]")), "{with_g:?}");
    }
    // The quaternion and the base's six rates are inputs; the position enters no dynamics.
    for name in ["q[4]", "q[7]", "q[8]", "q[10]", "qd[1]", "qd[6]", "qd[9]", "qdd[9]"] {
        assert!(with_g.contains(&name.to_string()), "{name} in {with_g:?}");
    }
    assert!(!with_g.iter().any(|n| n == "q[1]" || n == "q[11]" || n == "qd[10]"), "{with_g:?}");
    assert!(!names(&folded).iter().any(|n| n.starts_with("g[")), "{:?}", names(&folded));
    let f = &inputs.module.functions[0];
    assert_eq!(f.outputs.len(), 9, "Qq[1..9]");
    let mut rng = robovec_ir::rng::SplitMix64::new(3);
    let mut given: BTreeMap<String, f64> =
        [("g[1]", 0.5), ("g[2]", -1.0), ("g[3]", -9.81)].into_iter().map(|(k, x)| (k.to_string(), x)).collect();
    for i in 1..=10 {
        given.insert(format!("q[{i}]"), 2.0 * rng.unit() - 1.0);
    }
    for i in 1..=9 {
        given.insert(format!("qd[{i}]"), 2.0 * rng.unit() - 1.0);
        given.insert(format!("qdd[{i}]"), 2.0 * rng.unit() - 1.0);
    }
    let a = robovec::eval::evaluate(f, &given, false).outputs;
    let b = robovec::eval::evaluate(&folded.module.functions[0], &given, false).outputs;
    assert_eq!(a, b, "-gravity writes the numbers the inputs would carry");

    let o = opt(&[&arm, "--free-flyer", "--floating-base", "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--free-flyer") && stderr(&o).contains("--floating-base"), "{}", stderr(&o));
    for bad in ["-gravity=0,-9.81", "-gravity=0,0,x", "-gravity=0,0,inf"] {
        let o = opt(&[&arm, bad, "-passes=atomise"]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("expected three finite numbers"), "{bad}: {}", stderr(&o));
    }
    let o = opt(&[&arm, "--free-flyer", "-gravity=0,0,-1.62", "-passes=atomise", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let d = tmp("free_flyer_clash");
    let clash = d.join("clash.urdf");
    std::fs::write(
        &clash,
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n  <joint name=\"root_joint\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/></joint>\n</robot>\n",
    )
    .unwrap();
    let o = opt(&[clash.to_str().unwrap(), "--free-flyer", "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("`root_joint` is a name of robovec's free flyer") && e.contains("clash.urdf:4:3"), "{e}");
}

/// Issue 31 item 4: `--formulation=depth` writes the same `invdyna`, `dirdyna` and `fordyna` as the default
/// formulation (to 1e-10 of the outputs' largest magnitude, at random states with the URDF's
/// parameters given: the rigorous rounding bound is checked in `robovec_dynamics::depth`'s unit
/// tests) on the examples and a branched study robot, fixed, on the floating base and on the
/// free flyer, and the same `fordyna` (`M qdd = Qq − c` solved on either's `M` and `c`); a
/// shorter critical path on a 30-dof chain.
#[test]
fn depth_formulation_agrees_with_the_default_one() {
    use robovec_dynamics::topology::{build, Topology};
    use robovec_dynamics::Formulation;
    let d = tmp("depth_formulation");
    let semi = d.join("semi.urdf");
    std::fs::write(&semi, robovec_dynamics::urdf_out::write_urdf(&build(Topology::SemiSerial, 12, 2))).unwrap();
    let serial = d.join("serial.urdf");
    std::fs::write(&serial, robovec_dynamics::urdf_out::write_urdf(&build(Topology::Serial, 30, 1))).unwrap();
    let urdfs = [path(URDF), path("examples/three_link_arm/three_link_arm.urdf"), semi.to_str().unwrap().to_string()];
    for urdf in &urdfs {
        for (floating_base, free_flyer) in [(false, false), (true, false), (false, true)] {
            let load = |formulation| {
                // `fordyna` on the fixed base only: these robots' root links have no mass, so on a
                // moving base `M` is singular (the unit tests give the base a mass).
                let fixed = !(floating_base || free_flyer);
                let names = robovec_dynamics::FUNCTION_NAMES.iter().filter(|&&f| fixed || f != "fordyna");
                let functions = Some(names.map(|f| f.to_string()).collect());
                let opts =
                    FrontOptions { floating_base, free_flyer, formulation, functions, ..FrontOptions::default() };
                robovec::driver::load_with(urdf, &opts).expect("URDF loads").0
            };
            let (ops, depth) = (load(Formulation::Ops), load(Formulation::Depth));
            let mut rng = robovec_ir::rng::SplitMix64::new(7);
            for _ in 0..4 {
                let mut given: BTreeMap<String, f64> = ops.params.clone().unwrap_or_default();
                given.extend(depth.params.clone().unwrap_or_default());
                for k in 1..=3 {
                    given.insert(format!("g[{k}]"), 20.0 * rng.unit() - 10.0);
                }
                for i in 1..=40 {
                    for v in ["q", "qd", "qdd"] {
                        given.insert(format!("{v}[{i}]"), 4.0 * rng.unit() - 2.0);
                    }
                }
                if free_flyer {
                    // A unit quaternion q[4..7]: both formulations assume a rotation.
                    let n = (4..=7).map(|i| given[&format!("q[{i}]")].powi(2)).sum::<f64>().sqrt();
                    (4..=7).for_each(|i| *given.get_mut(&format!("q[{i}]")).unwrap() /= n);
                }
                for (a, b) in ops.module.functions.iter().zip(&depth.module.functions) {
                    assert_eq!(a.name, b.name);
                    let x = robovec::eval::evaluate(a, &given, false).outputs;
                    let y = robovec::eval::evaluate(b, &given, false).outputs;
                    assert_eq!(x.len(), y.len(), "{urdf} {}", a.name);
                    let norm = x.values().fold(1.0f64, |m, v| m.max(v.abs()));
                    for (k, v) in &x {
                        assert!(
                            (v - y[k]).abs() <= 1e-10 * norm,
                            "{urdf} floating {floating_base} free flyer {free_flyer} {k}: {v} vs {}",
                            y[k]
                        );
                    }
                }
            }
        }
    }
    // The critical path (cycles, from -stats): shorter with the depth formulation, `invdyna`
    // after `atomise`, `fordyna` (whose factorisation is as deep as the chain either way) once
    // its sums are balanced.
    let cycles = |function: &str, formulation: &str, passes: &str| {
        let o = opt(&[serial.to_str().unwrap(), function, formulation, passes, "-stats"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let s = stderr(&o);
        let at = s.rfind(" cycles").expect("-stats line");
        s[..at].rsplit(' ').next().unwrap().parse::<u32>().unwrap()
    };
    for (function, passes) in
        [("-function=invdyna", "-passes=atomise"), ("-function=fordyna", "-passes=atomise,cse,zero-removal,balance")]
    {
        let (by_ops, by_depth) =
            (cycles(function, "--formulation=ops", passes), cycles(function, "--formulation=depth", passes));
        assert!(2 * by_depth < by_ops, "30-dof chain {function}: {by_ops} cycles by ops, {by_depth} by depth");
    }
    let out = d.join("fd.rvir");
    let o = opt(&[URDF, "--formulation=fast", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Issue 47: a joint axis of length 1e308 was accepted and the joint silently dropped out of
/// the equations (`Qq[2] = 0`: `1e308 / ‖v‖ = 1e308 / inf = 0`), while `0 0 0` was refused.
/// Every axis that cannot be normalised in binary64 is bad input (exit 1) at the `xyz` value,
/// as non-finite numbers in any attribute robovec reads are.
#[test]
fn hostile_numbers_in_a_urdf_are_located_diagnostics() {
    let d = tmp("hostile");
    let text = std::fs::read_to_string(path(URDF)).unwrap();
    let axis = "<axis xyz=\"1 0 0\"/>";
    // The second joint's axis (j2), and other attributes on their own lines.
    let at = text.rfind(axis).expect("the example has an x axis");
    let with_axis = |xyz: &str| format!("{}<axis xyz=\"{xyz}\"/>{}", &text[..at], &text[at + axis.len()..]);
    let origin = "<origin xyz=\"0 0.8 0\"/>";
    // (what, the hostile text, the attribute whose value the diagnostic spans, its message)
    let cases: Vec<(&str, String, &str, &str)> = vec![
        ("axis 1e308", with_axis("1e308 0 0"), "xyz", "joint axis cannot be normalised: its squared length overflows"),
        (
            "axis 1e-200",
            with_axis("0 1e-200 0"),
            "xyz",
            "joint axis cannot be normalised: its squared length underflows",
        ),
        ("axis inf", with_axis("inf 0 0"), "xyz", "attribute `xyz` must hold 3 finite numbers"),
        ("axis nan", with_axis("1 nan 0"), "xyz", "attribute `xyz` must hold 3 finite numbers"),
        ("axis 0", with_axis("0 0 0"), "xyz", "joint axis has length 0"),
        (
            "mass inf",
            text.replacen("<mass value=\"0.7\"/>", "<mass value=\"inf\"/>", 1),
            "value",
            "attribute `value` must hold 1 finite numbers",
        ),
        (
            "inertia nan",
            text.replacen("iyy=\"0.005\"", "iyy=\"NaN\"", 1),
            "iyy",
            "attribute `iyy` must hold 1 finite numbers",
        ),
        (
            "origin 1e999",
            text.replacen(origin, "<origin xyz=\"0 1e999 0\"/>", 1),
            "xyz",
            "attribute `xyz` must hold 3 finite numbers",
        ),
        (
            "rpy -inf",
            text.replacen(origin, "<origin xyz=\"0 0.8 0\" rpy=\"0 -inf 0\"/>", 1),
            "rpy",
            "attribute `rpy` must hold 3 finite numbers",
        ),
    ];
    for (what, bad, attr, message) in cases {
        assert_ne!(bad, text, "{what}: the fixture changed nothing");
        let f = d.join("hostile.urdf");
        std::fs::write(&f, &bad).unwrap();
        // The diagnostic is at the attribute's value on the line that changed (1-based; ASCII).
        let (line, changed) =
            bad.lines().zip(text.lines()).enumerate().find(|(_, (a, b))| a != b).map(|(k, (a, _))| (k + 1, a)).unwrap();
        let col = changed.find(&format!("{attr}=\"")).unwrap() + attr.len() + 3;
        let o = opt(&[f.to_str().unwrap(), "-passes=atomise", "-o", d.join("out.rvir").to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{what}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(message), "{what}: {e}");
        assert!(
            e.contains(&format!("hostile.urdf:{line}:{col}\n")),
            "{what}: expected hostile.urdf:{line}:{col} in {e}"
        );
        assert!(!e.contains("panicked"), "{what}: {e}");
        assert!(!d.join("out.rvir").exists(), "{what}");
    }
    // A large axis whose squared length is still a normal number is normalised: the same
    // equations as `1 0 0`.
    let big = format!("{}<axis xyz=\"1e150 0 0\"/>{}", &text[..at], &text[at + axis.len()..]);
    let f = d.join("big.urdf");
    std::fs::write(&f, big).unwrap();
    let a = opt(&[f.to_str().unwrap(), "-function=invdyna", "-passes=atomise", "-o", "-"]);
    let b = opt(&[URDF, "-function=invdyna", "-passes=atomise", "-o", "-"]);
    assert!(a.status.success() && b.status.success(), "{}", stderr(&a));
    assert_eq!(a.stdout, b.stdout);
}

/// Issue 47: a link that makes the mass matrix singular (a leaf with mass 0, or without
/// `<inertial>`) under `-function=fordyna` is named with its joint at its `<link>` (before: the
/// verifier's `constant inf is not finite (on input)`, no file, no link, no cause); `dirdyna`
/// (`M` itself) and `invdyna` are written.
#[test]
fn a_singular_mass_matrix_names_the_link_and_its_joint() {
    for (file, what) in [
        ("tests/inputs/singular/massless_leaf.urdf", "has mass 0 and no inertia about its joint's axis"),
        ("tests/inputs/singular/no_inertial_leaf.urdf", "has no `<inertial>`"),
    ] {
        let text = std::fs::read_to_string(path(file)).unwrap();
        let line_of = |needle: &str| text.lines().position(|l| l.contains(needle)).expect(needle) + 1;
        for extra in [&[][..], &["--fold-params"], &["--formulation=depth"], &["--free-flyer"]] {
            let mut args = vec![file, "-function=fordyna", "-passes=atomise", "-o", "/dev/null"];
            args.extend(extra);
            let o = opt(&args);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(1), "{file} {extra:?}: {e}");
            // On the free flyer the base's six coordinates come first.
            let row = if extra.contains(&"--free-flyer") { 9 } else { 3 };
            let message = format!(
                "error: link `l3` (joint `j3`) {what}: the mass matrix is singular (a zero pivot in row {row} of M, qdd[{row}])"
            );
            assert!(e.starts_with(&message), "{file} {extra:?}: {e}");
            assert!(e.contains(&format!("{file}:{}:3", line_of("<link name=\"l3\""))), "{file}: at the link: {e}");
            assert!(e.contains(&format!("joint `j3` (line {}) moves it", line_of("<joint name=\"j3\""))), "{e}");
            assert!(e.contains("give link `l3` an <inertial> with a positive mass"), "{e}");
            assert!(!e.contains("verifier"), "{e}");
        }
        for function in ["-function=dirdyna", "-function=invdyna"] {
            let o = opt(&[file, function, "-passes=atomise", "-o", "/dev/null"]);
            assert!(o.status.success(), "{file} {function}: {}", stderr(&o));
        }
    }
}

/// Issue 47: `-eval` of a function whose values go non-finite (a zero mass given for a link
/// in a parameter file from `-params-out`) still prints its JSON (`null` outputs, exit 0) but
/// warns, naming the first value that is not finite, what it read, and the outputs affected.
#[test]
fn eval_warns_at_the_first_value_that_is_not_finite() {
    let d = tmp("non_finite");
    let arm = path("examples/three_link_arm/three_link_arm.urdf");
    let params = d.join("params.json");
    let o =
        opt(&[&arm, "-function=fordyna", "-passes=", "-o", "/dev/null", &format!("-params-out={}", params.display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The telescope (prismatic, `q[3]`) moves the forearm and the tool fixed to it: body 3,
    // whose mass is the pivot of row 3 of M. Zero it, with the state.
    let mut values: BTreeMap<String, f64> = serde_json::from_slice(&std::fs::read(&params).unwrap()).unwrap();
    assert!(values["m[3]"] > 0.0);
    values.insert("m[3]".into(), 0.0);
    for (k, x) in [("q[1]", 0.3), ("q[2]", -0.5), ("q[3]", 0.1), ("qd[1]", 0.2), ("qd[2]", 0.1), ("qd[3]", -0.3)] {
        values.insert(k.into(), x);
    }
    for k in 1..=3 {
        values.insert(format!("Qq[{k}]"), 1.0);
    }
    let zero = d.join("zero_mass.json");
    std::fs::write(&zero, serde_json::to_string(&values).unwrap()).unwrap();
    let o = opt(&[&arm, "-function=fordyna", "-passes=atomise", &format!("-eval={}", zero.display())]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(json["outputs"]["qdd[3]"].is_null(), "{json}");
    let warning =
        e.lines().find(|l| l.starts_with("warning: @fordyna: %")).unwrap_or_else(|| panic!("no warning: {e}"));
    // The first value that is not finite is the reciprocal of a pivot that is 0 …
    assert!(warning.contains(" is inf (the first value that is not finite; %"), "{warning}");
    assert!(warning.contains(" = 0)") || warning.contains(" = 0,"), "it read a zero: {warning}");
    // … and every output past it is named.
    assert!(warning.contains("qdd[3]") && warning.ends_with("not finite"), "{warning}");
    // With the file's own mass, no warning.
    let o = opt(&[&arm, "-function=fordyna", "-passes=atomise", &format!("-eval={}", params.display())]);
    assert!(o.status.success() && !stderr(&o).contains("not finite"), "{}", stderr(&o));
}

/// The warning of an `.rvir` function gives its definition's line (a Robotran file's too).
#[test]
fn eval_locates_the_first_value_that_is_not_finite_in_its_file() {
    let d = tmp("non_finite_rvir");
    let f = d.join("f.rvir");
    std::fs::write(&f, "func @f {\n  phase parsed\n  input %m\n  input %x\n  %a = %x*%x\n  %inv = 1/%m\n  %y = %a*%inv\n  output y = %y\n  output z = %a\n}\n")
        .unwrap();
    let given = d.join("in.json");
    std::fs::write(&given, r#"{"m": 0, "x": 2}"#).unwrap();
    let o = opt(&[f.to_str().unwrap(), &format!("-eval={}", given.display())]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains(
            "warning: @f: %inv = 1.0/%m is inf (the first value that is not finite; %m = 0): output y is not finite\n"
        ),
        "{e}"
    );
    assert!(e.contains(&format!("  --> {}:6:3\n", f.display())), "{e}");
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((json["outputs"]["y"].is_null(), json["outputs"]["z"].as_f64()), (true, Some(4.0)));
}
