//! Numerical truth for the URDF front end (issue 14): robovec's generated inverse dynamics
//! `Qq` against `pinocchio.rnea`, and its direct dynamics `M`, `c` against `pinocchio.crba`
//! (symmetrized by the oracle) and `pinocchio.nonLinearEffects`, its forward dynamics `qdd`
//! (`-function=fordyna`, from Pinocchio's `tau`) against `pinocchio.aba`, on random states, relative
//! error ≤ 1e-10 (∞-norm of the difference over the ∞-norm of Pinocchio's values).
//!
//! Pinocchio (PyPI `pin`) and `example-robot-data` live in a virtual environment that `scripts/test.sh`
//! creates at `target/pinocchio-venv` (or the Python named by `ROBOVEC_PINOCCHIO_PYTHON`);
//! `scripts/pinocchio_oracle.py` prints the reference states and torques as JSON. In CI
//! (`CI` set) a missing environment fails the test; elsewhere it is skipped with a note.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use robovec_front::FrontOptions;

pub(crate) fn python() -> Option<PathBuf> {
    let p = std::env::var_os("ROBOVEC_PINOCCHIO_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/pinocchio-venv/bin/python"));
    if p.exists() {
        return Some(p);
    }
    let msg = format!(
        "Pinocchio's environment is missing at {} (scripts/test.sh creates it: python3 -m venv target/pinocchio-venv && \
         target/pinocchio-venv/bin/pip install pin example-robot-data)",
        p.display()
    );
    assert!(std::env::var_os("CI").is_none(), "{msg}");
    eprintln!("note: skipped: {msg}");
    None
}

/// One state of `scripts/pinocchio_oracle.py`'s JSON: robovec's coordinates `q` (one angle per
/// joint), Pinocchio's own configuration vector, and Pinocchio's results.
#[derive(Clone, serde::Deserialize)]
pub(crate) struct State {
    pub(crate) q: Vec<f64>,
    /// Pinocchio's own configuration vector (a continuous joint's `(cos, sin)`).
    pub(crate) q_pinocchio: Vec<f64>,
    pub(crate) qd: Vec<f64>,
    pub(crate) qdd: Vec<f64>,
    pub(crate) tau: Vec<f64>,
    #[serde(rename = "M")]
    pub(crate) mass: Vec<Vec<f64>>,
    pub(crate) nle: Vec<f64>,
    pub(crate) aba: Vec<f64>,
    /// `computeRNEADerivatives`' ∂τ/∂q and ∂τ/∂v at (q, v, a), row-major nv × nv.
    pub(crate) dtau_dq: Vec<Vec<f64>>,
    pub(crate) dtau_dv: Vec<Vec<f64>>,
    /// `computeABADerivatives`' ∂q̈/∂q, ∂q̈/∂v and M⁻¹ (both triangles) at (q, v, τ).
    pub(crate) ddq_dq: Vec<Vec<f64>>,
    pub(crate) ddq_dv: Vec<Vec<f64>>,
    #[serde(rename = "Minv")]
    pub(crate) minv: Vec<Vec<f64>>,
}

/// `scripts/pinocchio_oracle.py`'s JSON.
#[derive(serde::Deserialize)]
pub(crate) struct Oracle {
    pub(crate) path: String,
    joints: Vec<String>,
    pub(crate) gravity: Vec<f64>,
    pub(crate) states: Vec<State>,
}

/// The robot's base: fixed, Robotran's six-joint floating base (`--floating-base`, Pinocchio's
/// composite root joint) or Pinocchio's free flyer (`--free-flyer`, `JointModelFreeFlyer`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Base {
    Fixed,
    Floating,
    FreeFlyer,
}

impl Base {
    /// The oracle script's word.
    fn word(self) -> &'static str {
        match self {
            Base::Fixed => "fixed",
            Base::Floating => "floating",
            Base::FreeFlyer => "free-flyer",
        }
    }
}

/// Runs the oracle script on `urdf` (a path or `erd:…`): `states` random states from `seed`, on
/// `base`.
pub(crate) fn oracle(py: &Path, urdf: &str, states: usize, seed: u64, base: Base) -> Oracle {
    let base = base.word();
    let out = Command::new(py)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["scripts/pinocchio_oracle.py", urdf, &states.to_string(), &seed.to_string(), base])
        .output()
        .expect("run the oracle script");
    assert!(out.status.success(), "oracle failed on {urdf}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("oracle JSON")
}

/// Pinocchio's values of `function`'s outputs in state `s`, by output name.
fn expected(function: &str, s: &State) -> BTreeMap<String, f64> {
    let n = s.qd.len();
    let mut e = BTreeMap::new();
    for i in 0..n {
        if function == "invdyna" {
            e.insert(format!("Qq[{}]", i + 1), s.tau[i]);
        } else if function == "fordyna" {
            e.insert(format!("qdd[{}]", i + 1), s.aba[i]);
        } else {
            e.insert(format!("c[{}]", i + 1), s.nle[i]);
            for j in 0..n {
                e.insert(format!("M[{}][{}]", i + 1, j + 1), s.mass[i][j]);
            }
        }
    }
    e
}

/// Worst relative error of robovec's `Qq` (invdyna), `M`, `c` (dirdyna) and `qdd` (fordyna), with symbolic
/// parameters given their values and with parameters folded, against Pinocchio over the
/// oracle's states.
fn compare(urdf: &str, dof: usize) -> f64 {
    compare_on(urdf, dof, Base::Fixed)
}

/// [`compare`] on `base`: `dof` counts the velocity coordinates, the base's six included (which
/// Pinocchio holds in one root joint); with the free flyer `q` has one more (the quaternion).
fn compare_on(urdf: &str, dof: usize, base: Base) -> f64 {
    compare_with(urdf, dof, base, false)
}

/// [`compare_on`]; `cos_sin`: loaded with `--continuous=cos-sin` and given Pinocchio's own
/// configuration vector.
fn compare_with(urdf: &str, dof: usize, base: Base, cos_sin: bool) -> f64 {
    compare_formulation(urdf, dof, base, cos_sin, robovec_dynamics::Formulation::Ops)
}

/// [`compare_with`] for the generator's `formulation`.
fn compare_formulation(
    urdf: &str,
    dof: usize,
    base: Base,
    cos_sin: bool,
    formulation: robovec_dynamics::Formulation,
) -> f64 {
    let Some(py) = python() else { return 0.0 };
    let functions: Vec<String> = robovec_dynamics::FUNCTION_NAMES.iter().map(|s| s.to_string()).collect();
    let o = oracle(&py, urdf, 8, 7, base);
    let floating = base != Base::Fixed;
    assert_eq!(o.joints.len() + if floating { 5 } else { 0 }, dof, "{}: joints {:?}", o.path, o.joints);
    let mut worst: f64 = 0.0;
    for fold in [false, true] {
        let (loaded, _) = robovec::driver::load_with(
            &o.path,
            &FrontOptions {
                fold_params: fold,
                floating_base: base == Base::Floating,
                free_flyer: base == Base::FreeFlyer,
                continuous_cos_sin: cos_sin,
                functions: Some(functions.clone()),
                formulation,
                ..FrontOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{}: {}", o.path, e.message()));
        assert_eq!(loaded.params.is_some(), !fold);
        let names: Vec<&str> = loaded.module.functions.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, functions);
        for (f, s) in loaded.module.functions.iter().flat_map(|f| o.states.iter().map(move |s| (f, s))) {
            let want = expected(&f.name, s);
            assert_eq!(f.outputs.len(), want.len(), "{}: outputs", f.name);
            let mut given: BTreeMap<String, f64> = loaded.params.clone().unwrap_or_default();
            for (k, g) in o.gravity.iter().enumerate() {
                given.insert(format!("g[{}]", k + 1), *g);
            }
            assert_eq!(s.q.len(), dof + usize::from(base == Base::FreeFlyer), "configuration coordinates");
            let q = if cos_sin { &s.q_pinocchio } else { &s.q };
            for (i, q) in q.iter().enumerate() {
                given.insert(format!("q[{}]", i + 1), *q);
            }
            for i in 0..dof {
                given.insert(format!("qd[{}]", i + 1), s.qd[i]);
                given.insert(format!("qdd[{}]", i + 1), s.qdd[i]);
                given.insert(format!("Qq[{}]", i + 1), s.tau[i]);
            }
            // Every input must be given: no pseudo-random stand-in may enter the comparison.
            for &v in &f.inputs {
                assert!(given.contains_key(f.name_of(v)), "input {} not given", f.name_of(v));
            }
            let r = robovec::eval::evaluate(f, &given, false);
            // Per group (Qq, M, c): ∞-norm of the difference over Pinocchio's ∞-norm.
            for group in ["Qq[", "M[", "c[", "qdd["] {
                let keys: Vec<&String> = want.keys().filter(|k| k.starts_with(group)).collect();
                if keys.is_empty() {
                    continue;
                }
                let norm = keys.iter().fold(0.0f64, |m, k| m.max(want[*k].abs()));
                let diff = keys.iter().fold(0.0f64, |m, k| m.max((r.outputs[*k] - want[*k]).abs()));
                let rel = diff / norm;
                assert!(
                    rel <= 1e-10,
                    "{} {} {group} (fold {fold}): relative error {rel:e}\n robovec {:?}\n pinocchio {:?}",
                    o.path,
                    f.name,
                    r.outputs,
                    want
                );
                worst = worst.max(rel);
            }
        }
    }
    worst
}

#[test]
fn three_link_arm_matches_pinocchio_rnea_crba_nle() {
    let e = compare("examples/three_link_arm/three_link_arm.urdf", 3);
    eprintln!("three_link_arm: worst relative error {e:e}");
}

#[test]
fn ur5_matches_pinocchio_rnea_crba_nle() {
    let e = compare("erd:ur_description/urdf/ur5_robot.urdf", 6);
    eprintln!("ur5: worst relative error {e:e}");
}

#[test]
fn panda_matches_pinocchio_rnea_crba_nle() {
    let e = compare("erd:panda_description/urdf/panda.urdf", 9);
    eprintln!("panda: worst relative error {e:e}");
}

/// Every built-in topology family (`robovec_dynamics::topology`) at 4, 9 and 23 dof, written as a
/// URDF by `gen::urdf_out` and loaded by Pinocchio and by robovec's URDF front end: `Qq`, `M`,
/// `c` within 1e-10 of Pinocchio's, and the front end's IR from the written file is the IR
/// generated straight from the robot (the writer loses nothing the generator reads).
#[test]
fn topology_families_match_pinocchio_rnea_crba_nle() {
    use robovec_dynamics::topology::{build, Topology};
    let dir = crate::common::tmp("topology");
    for t in Topology::ALL {
        for dof in [4, 9, 23] {
            let robot = build(t, dof, 1);
            let path = dir.join(format!("{t}_{dof}.urdf"));
            std::fs::write(&path, robovec_dynamics::urdf_out::write_urdf(&robot)).unwrap();
            let path = path.to_str().unwrap();
            let direct = robovec_dynamics::generate(&robovec_dynamics::Model { robot }, false);
            let (loaded, _) = robovec::driver::load_with(path, &FrontOptions::default())
                .unwrap_or_else(|e| panic!("{path}: {}", e.message()));
            assert_eq!(loaded.module.to_string(), direct.module.to_string(), "{path}: IR after the URDF round trip");
            assert_eq!(loaded.params, direct.params, "{path}: parameter values after the URDF round trip");
            let e = compare(path, dof);
            eprintln!("{t} {dof}: worst relative error {e:e}");
        }
    }
}

/// A 60-joint serial chain, where `fordyna` is the articulated-body algorithm (the `LᵀDL`
/// factorisation is cubic in a chain's depth; `robovec_dynamics::fordyna` keeps the fewer ops):
/// its `qdd` against `pinocchio.aba`, with `Qq`, `M` and `c` as for the other robots.
#[test]
fn long_chain_forward_dynamics_by_the_aba_matches_pinocchio() {
    use robovec_dynamics::topology::{build, Topology};
    let robot = build(Topology::Serial, 60, 1);
    let path = crate::common::tmp("long_chain").join("serial_60.urdf");
    std::fs::write(&path, robovec_dynamics::urdf_out::write_urdf(&robot)).unwrap();
    let e = compare(path.to_str().unwrap(), 60);
    eprintln!("serial 60: worst relative error {e:e}");
    // On the free flyer: the ABA's 6 × 6 solve at the root.
    let e = compare_on(path.to_str().unwrap(), 60 + 6, Base::FreeFlyer);
    eprintln!("serial 60 free flyer: worst relative error {e:e}");
}

/// `--formulation=depth` (world-frame parallel-prefix Newton–Euler and CRBA): `Qq`, `M`, `c` and `qdd`
/// within 1e-10 of Pinocchio's on a serial chain deep enough for several prefix levels, a
/// branched robot (Panda's fingers), Solo-12 on the free flyer and Talos on the floating base.
#[test]
fn depth_formulation_matches_pinocchio_rnea_crba_nle_aba() {
    use robovec_dynamics::topology::{build, Topology};
    use robovec_dynamics::Formulation::Depth;
    let robot = build(Topology::Serial, 23, 1);
    let path = crate::common::tmp("depth_formulation").join("serial_23.urdf");
    std::fs::write(&path, robovec_dynamics::urdf_out::write_urdf(&robot)).unwrap();
    for (urdf, dof, base) in [
        (path.to_str().unwrap(), 23, Base::Fixed),
        ("erd:panda_description/urdf/panda.urdf", 9, Base::Fixed),
        ("erd:solo_description/robots/solo12.urdf", 12 + 6, Base::FreeFlyer),
        ("erd:talos_data/robots/talos_reduced.urdf", 32 + 6, Base::Floating),
    ] {
        let e = compare_formulation(urdf, dof, base, false, Depth);
        eprintln!("{urdf} {base:?} depth formulation: worst relative error {e:e}");
    }
}

/// Robotran's floating base (`--floating-base`: T1–T3, R1–R3 as `q[1..6]`) against Pinocchio's
/// composite root joint PX PY PZ RX RY RZ: the three-link arm (its root link has a mass, which
/// now moves), Solo-12, a quadruped (6 + 12 coordinates), and Talos, a humanoid (6 + 32).
#[test]
fn floating_base_matches_pinocchio_composite_root_joint() {
    let e = compare_on("examples/three_link_arm/three_link_arm.urdf", 3 + 6, Base::Floating);
    eprintln!("three_link_arm floating: worst relative error {e:e}");
    let e = compare_on("erd:solo_description/robots/solo12.urdf", 12 + 6, Base::Floating);
    eprintln!("solo12 floating: worst relative error {e:e}");
    let e = compare_on("erd:talos_data/robots/talos_reduced.urdf", 32 + 6, Base::Floating);
    eprintln!("talos floating: worst relative error {e:e}");
}

/// Pinocchio's free flyer (`--free-flyer`: position and unit quaternion as `q[1..7]`, the base's
/// velocity in its frame as `qd[1..6]`) against `buildModelFromUrdf(path, JointModelFreeFlyer())`
/// at random states with random unit quaternions: the three-link arm (its root link's mass now
/// moves), UR5 and Panda set free (arms without a floating base in practice, but the same
/// equations), Solo-12 (6 + 12 velocity coordinates), Talos (6 + 32) and xArm 7, whose
/// massless root `world` holds `link_base` by a fixed joint at its origin (the base's mass was
/// once dropped there), SO-101, whose joint rotations are written a few µrad from half and
/// quarter turns, and a quadrotor's single body: `Qq` (`rnea`), `M`, `c` (`crba`, `nonLinearEffects`) and `qdd` (`aba`)
/// within 1e-10.
#[test]
fn free_flyer_matches_pinocchio_free_flyer_root_joint() {
    for (urdf, joints) in [
        ("examples/three_link_arm/three_link_arm.urdf", 3),
        ("erd:ur_description/urdf/ur5_robot.urdf", 6),
        ("erd:panda_description/urdf/panda.urdf", 9),
        ("erd:solo_description/robots/solo12.urdf", 12),
        ("erd:talos_data/robots/talos_reduced.urdf", 32),
        ("erd:xarm_description/urdf/xarm7.urdf", 7),
        // Joint rotations a few µrad from a half or a quarter turn (`rpy="3.14159 4.18253e-17
        // -3.14159"`): the body frames of `robovec_dynamics::frames` once turned 1.6e-11 rad
        // away from the URDF's there (q̈ off by 2.4e-9).
        ("erd:so_arm_description/urdf/so101.urdf", 6),
        // One rigid body, no joint (a quadrotor): only the free flyer moves it.
        ("erd:hector_description/robots/quadrotor_base.urdf", 0),
    ] {
        let e = compare_on(urdf, joints + 6, Base::FreeFlyer);
        eprintln!("{urdf} free flyer: worst relative error {e:e}");
    }
}

/// URDFs with inertia tensors no rigid body has, which Pinocchio's reader takes as written:
/// TIAGo's (`ixy² > ixx·iyy`) and iCub's (`ixx="-5.42101e-20"` on massless links). robovec
/// warns and uses them as written, and matches Pinocchio (they were refused).
#[test]
fn unphysical_inertia_tensors_are_used_as_pinocchio_uses_them() {
    for (urdf, dof) in
        [("erd:tiago_description/robots/tiago_no_hand.urdf", 12), ("erd:icub_description/robots/icub_reduced.urdf", 29)]
    {
        let e = compare(urdf, dof);
        eprintln!("{urdf}: worst relative error {e:e}");
    }
}

/// TIAGo Pro on the free flyer (6 + 33 velocity coordinates; see the test below), with its
/// wheels' configuration as angles and as Pinocchio's `(cos, sin)` pairs (`--continuous=cos-sin`:
/// Pinocchio's `q` itself, 4 + 1 entries longer than `qd`).
#[test]
fn mobile_manipulator_matches_pinocchio_free_flyer() {
    let e = compare_on("erd:tiago_pro_description/robots/tiago_pro.urdf", 33 + 6, Base::FreeFlyer);
    eprintln!("tiago_pro free flyer: worst relative error {e:e}");
    let e = compare_with("erd:tiago_pro_description/robots/tiago_pro.urdf", 33 + 6, Base::FreeFlyer, true);
    eprintln!("tiago_pro free flyer, cos-sin: worst relative error {e:e}");
}

/// `--continuous=cos-sin` on a fixed base: the three-link arm (one continuous joint) and a
/// serial chain whose joints are all continuous, given Pinocchio's `q` as it is.
#[test]
fn continuous_joints_as_pinocchios_cos_sin_pairs() {
    let e = compare_with("examples/three_link_arm/three_link_arm.urdf", 3, Base::Fixed, true);
    eprintln!("three_link_arm cos-sin: worst relative error {e:e}");
    let robot = robovec_dynamics::topology::build(robovec_dynamics::topology::Topology::Serial, 9, 1);
    let path = crate::common::tmp("cos_sin").join("serial_9.urdf");
    std::fs::write(&path, robovec_dynamics::urdf_out::write_urdf(&robot)).unwrap();
    let e = compare_with(path.to_str().unwrap(), 9, Base::Fixed, true);
    eprintln!("serial 9 cos-sin: worst relative error {e:e}");
}

/// A mobile manipulator: PAL's TIAGo Pro (example-robot-data; omnidirectional base on four
/// continuous wheel joints, a prismatic torso, a head and two 7-dof arms with grippers: 33
/// moving joints) on Robotran's floating base (6 + 33 coordinates), against Pinocchio's composite
/// root joint. (The older TIAGo's URDF is refused: see docs/generator.md, an inertia tensor no body has.)
#[test]
fn mobile_manipulator_matches_pinocchio_composite_root_joint() {
    let e = compare_on("erd:tiago_pro_description/robots/tiago_pro.urdf", 33 + 6, Base::Floating);
    eprintln!("tiago_pro floating: worst relative error {e:e}");
}

/// The contract between `benches/pinocchio/export_model.py` and the bench's C++ harness (which
/// rebuilds Pinocchio's configuration from robovec's coordinates for its `long double`
/// reference): on TIAGo Pro (floating base, continuous wheel joints), `states.txt` has the sizes
/// the JSON names, the six base coordinates first, one coordinate per velocity, `nq − nv`
/// continuous joints whose configuration is `(cos x, sin x)`, every other entry `x` itself, and
/// the oracle's ranges; `model.txt` is a Boost text archive.
#[test]
fn bench_export_states_follow_the_harness_layout() {
    let Some(py) = python() else { return };
    let dir = crate::common::tmp("export");
    let out = Command::new(&py)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .arg("benches/pinocchio/export_model.py")
        .args(["erd:tiago_pro_description/robots/tiago_pro.urdf", dir.to_str().unwrap(), "3", "5", "floating"])
        .output()
        .expect("run export_model.py");
    assert!(out.status.success(), "export_model.py: {}", String::from_utf8_lossy(&out.stderr));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).expect("export JSON");
    let (nq, nv) = (info["nq"].as_u64().unwrap() as usize, info["nv"].as_u64().unwrap() as usize);
    assert_eq!(nv, 33 + 6);
    let archive = std::fs::read_to_string(dir.join("model.txt")).unwrap();
    assert!(archive.contains("serialization::archive"), "model.txt: {}", &archive[..archive.len().min(80)]);
    let text = std::fs::read_to_string(dir.join("states.txt")).unwrap();
    let w: Vec<f64> = text.split_whitespace().map(|t| t.parse().unwrap()).collect();
    assert_eq!(&w[..3], &[3.0, nq as f64, nv as f64]);
    assert_eq!(&w[3..6], &[0.0, 0.0, -9.81]);
    let layout: Vec<(usize, u8)> = w[6..6 + 2 * nv].chunks(2).map(|c| (c[0] as usize, c[1] as u8)).collect();
    let continuous = layout.iter().filter(|l| l.1 == 1).count();
    assert!(continuous > 0, "TIAGo Pro's wheels are continuous joints");
    assert_eq!(nq - nv, continuous);
    assert_eq!(&layout[..6], &[(0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (5, 0)]);
    let mut states = w[6 + 2 * nv..].chunks(nv + nq + 2 * nv);
    for _ in 0..3 {
        let s = states.next().expect("3 states");
        assert_eq!(s.len(), nv + nq + 2 * nv);
        let (x, rest) = s.split_at(nv);
        let (q, va) = rest.split_at(nq);
        let mut covered = vec![false; nq];
        for (&(i, kind), &xi) in layout.iter().zip(x) {
            assert!(xi.abs() <= std::f64::consts::PI);
            if kind == 1 {
                assert!((q[i] - xi.cos()).abs() <= 1e-15 && (q[i + 1] - xi.sin()).abs() <= 1e-15);
                covered[i + 1] = true;
            } else {
                assert_eq!(q[i], xi);
            }
            covered[i] = true;
        }
        assert!(covered.iter().all(|&c| c), "every configuration entry comes from a coordinate");
        assert!(va.iter().all(|t| t.abs() <= 2.0));
    }
    assert!(states.next().is_none());
}
