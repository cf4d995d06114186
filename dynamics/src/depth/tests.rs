//! The depth formulation against the body-frame RNEA (values, under a derived rounding
//! tolerance) and its critical path against the tree's depth.

use std::collections::BTreeMap;

use robovec_ir::interp;
use robovec_ir::latency::Latencies;
use robovec_ir::numerics::budget::U64;
use robovec_ir::numerics::tape::{Step, Tape};
use robovec_ir::{BinOp, Function};

use crate::robot::{Inertial, JointKind, Origin, Robot};
use crate::sym::Builder;
use crate::topology::{build, Topology};
use crate::{Layout, Model, Stopped};

type Writer = fn(&Model, &Layout, &mut Builder) -> Result<(), Stopped>;

/// `robot`'s function by `write`, parameters as inputs.
fn function(robot: &Robot, name: &str, write: Writer) -> Function {
    let model = Model { robot: robot.clone() };
    let layout = Layout::of(&model.robot);
    let mut b = Builder::new(name, Default::default());
    write(&model, &layout, &mut b).expect("no deadline");
    b.finish()
}

/// Every revolute joint continuous and read as Pinocchio's `(cos θ, sin θ)` pair, so the trig
/// values are inputs (the error budget has no `sin`/`cos`).
pub(crate) fn cos_sin(mut robot: Robot) -> Robot {
    for j in &mut robot.joints {
        j.continuous = j.kind == JointKind::Revolute;
    }
    robot.cos_sin = true;
    robot
}

/// A state drawn with `seed`: parameters at their values, `(cos θ, sin θ)` of a drawn angle,
/// a unit quaternion, the rest uniform in ±3 (gravity in ±10).
pub(crate) fn state(robot: &Robot, seed: u64) -> BTreeMap<String, f64> {
    let layout = Layout::of(robot);
    let mut given = layout.values.clone();
    let draw = |name: &str| 3.0 * interp::pseudo_random_input(name, seed);
    for i in 1..=layout.nq {
        given.insert(format!("q[{i}]"), draw(&format!("q[{i}]")));
    }
    for (i, &j) in robot.dfs_joints().iter().enumerate() {
        let (joint, Some(qi)) = (&robot.joints[j], layout.q_index[i]) else { continue };
        if joint.kind == JointKind::Revolute && joint.continuous {
            let th = draw(&format!("theta{qi}"));
            given.insert(format!("q[{qi}]"), th.cos());
            given.insert(format!("q[{}]", qi + 1), th.sin());
        } else if joint.kind == JointKind::FreeFlyer {
            let quat: Vec<f64> = (3..7).map(|k| draw(&format!("q[{}]", qi + k))).collect();
            let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
            for (k, x) in quat.iter().enumerate() {
                given.insert(format!("q[{}]", qi + 3 + k), x / norm);
            }
        }
    }
    for i in 1..=layout.nv {
        for v in ["qd", "qdd"] {
            let name = format!("{v}[{i}]");
            given.insert(name.clone(), draw(&name));
        }
    }
    for k in 1..=3 {
        given.insert(format!("g[{k}]"), 10.0 / 3.0 * draw(&format!("g[{k}]")));
    }
    given
}

/// The worst `|x − y| / (1 + max |y|)` over the outputs of `x` and three states ([`state`], with
/// the torques `Qq` drawn too when `torques`), `y`'s output of the same name taken as 0 where
/// `y` writes none (`diff` writes no column for a coordinate the function does not read).
///
/// # Panics
/// When `y` writes an output `x` does not, or an input is missing.
pub(crate) fn worst_relative(robot: &Robot, x: &Function, y: &Function, torques: bool) -> f64 {
    let nv = Layout::of(robot).nv;
    let mut worst: f64 = 0.0;
    for seed in 1..=3 {
        let mut given = state(robot, seed);
        if torques {
            for i in 1..=nv {
                given.insert(format!("Qq[{i}]"), 3.0 * interp::pseudo_random_input(&format!("Qq[{i}]"), seed));
            }
        }
        let at = |name: &str| *given.get(name).unwrap_or_else(|| panic!("input {name}"));
        let a: BTreeMap<String, f64> = interp::eval::<f64>(x, at).into_iter().collect();
        let b: BTreeMap<String, f64> = interp::eval::<f64>(y, at).into_iter().collect();
        assert!(b.keys().all(|n| a.contains_key(n)), "every output of the reference is written");
        let scale = b.values().fold(0.0f64, |m, v| m.max(v.abs()));
        for (name, v) in &a {
            worst = worst.max((v - b.get(name).copied().unwrap_or(0.0)).abs() / (1.0 + scale));
        }
    }
    worst
}

/// The outputs of `f` at `given` in binary64, each with a running error bound (J. H.
/// Wilkinson's running error analysis, N. J. Higham, *Accuracy and Stability of Numerical
/// Algorithms*, 2nd ed., §3.3, to first order in `u`): an op `z = fl(x ∘ y)` carries
/// `e_z = e_x + e_y + u|z|` (add, sub) or `|x|·e_y + |y|·e_x + u|z|` (mul). The bound is the
/// distance to the exact value at the exact unit point nearest the inputs: the inputs named in
/// `inexact` (cos/sin pairs, the quaternion) start at `2u|x|` (a float pair with `c² + s² =
/// 1 + δ`, `|δ| ≤ 3u`, is within `|x|·|δ|/2 + O(u²)` of the unit circle), the others are
/// exact.
fn eval_with_bound(f: &Function, given: &BTreeMap<String, f64>, inexact: &[String]) -> BTreeMap<String, (f64, f64)> {
    let tape = Tape::new(f);
    let mut x: Vec<f64> = Vec::new();
    let mut e: Vec<f64> = Vec::new();
    for n in &tape.inputs {
        let v = *given.get(n).unwrap_or_else(|| panic!("input {n} not given"));
        x.push(v);
        e.push(if inexact.contains(n) { 2.0 * U64 * v.abs() } else { 0.0 });
    }
    for &c in &tape.consts {
        x.push(c);
        e.push(0.0);
    }
    for s in &tape.steps {
        let (v, err) = match *s {
            Step::Bin(op, a, b) => {
                let (a, b) = (a as usize, b as usize);
                let v = interp::eval_binop(op, x[a], x[b]);
                let err = match op {
                    BinOp::Add | BinOp::Sub => e[a] + e[b],
                    BinOp::Mul => x[a].abs() * e[b] + x[b].abs() * e[a],
                    BinOp::Div => unreachable!("no division"),
                };
                (v, err + U64 * v.abs())
            }
            Step::Neg(a) => (-x[a as usize], e[a as usize]),
            Step::Trig(..) | Step::Call(..) => unreachable!("+ − × only"),
        };
        x.push(v);
        e.push(err);
    }
    tape.outputs.iter().map(|(n, s)| (n.clone(), (x[*s as usize], e[*s as usize]))).collect()
}

/// The largest `|depth − rnea| / tolerance` over four states and every output of `invdyna`
/// and `dirdyna` (`M` by the CRBA against the world-frame composites, `c`). Tolerance: the sum of both running error bounds
/// ([`eval_with_bound`]), plus `10⁻³` of it for the terms of second order in `u`. Derivation:
/// both formulations are the same polynomial wherever `cos² + sin² = 1` (and the quaternion has
/// unit norm), so at the exact unit point nearest the inputs they have one exact value, from
/// which each computed output is within its bound.
fn worst_ratio(robot: &Robot) -> f64 {
    let robot = cos_sin(robot.clone());
    let layout = Layout::of(&robot);
    let mut inexact = Vec::new();
    for (i, &j) in robot.dfs_joints().iter().enumerate() {
        let (joint, Some(qi)) = (&robot.joints[j], layout.q_index[i]) else { continue };
        match joint.kind {
            JointKind::Revolute => inexact.extend([qi, qi + 1].map(|k| format!("q[{k}]"))),
            JointKind::FreeFlyer => inexact.extend((3..7).map(|k| format!("q[{}]", qi + k))),
            _ => {}
        }
    }
    let mut worst: f64 = 0.0;
    let pairs: [(&str, Writer, Writer, &str); 2] = [
        ("invdyna", crate::rnea::invdyna, super::invdyna, "Qq["),
        ("dirdyna", crate::dirdyna::dirdyna, super::dirdyna, ""),
    ];
    for (name, ops, depth, prefix) in pairs {
        let (f0, f1) = (function(&robot, name, ops), function(&robot, name, depth));
        assert_eq!(f0.outputs.len(), f1.outputs.len(), "{name}");
        for seed in 1..=4 {
            let given = state(&robot, seed);
            let (a, b) = (eval_with_bound(&f0, &given, &inexact), eval_with_bound(&f1, &given, &inexact));
            let mut nonzero = false;
            for (k, &(x0, b0)) in a.iter().filter(|(k, _)| k.starts_with(prefix)) {
                let (x1, b1) = b[k];
                let tol = (b0 + b1) * (1.0 + 1e-3);
                nonzero |= x0.abs() > 1e-3;
                worst = worst.max((x1 - x0).abs() / tol);
            }
            assert!(nonzero, "{name}: every output is zero");
        }
    }
    worst
}

/// A mass on the base link: a floating robot's base carries one.
fn massive_base(mut r: Robot) -> Robot {
    let root = r.root;
    r.links[root].inertial = Some(Inertial {
        mass: 4.5,
        com: [0.05, -0.02, 0.1],
        inertia: [[0.3, 0.01, -0.02], [0.01, 0.25, 0.03], [-0.02, 0.03, 0.2]],
    });
    r
}

/// `Qq`, `M` and `c` of the depth formulation equal the body-frame RNEA's and CRBA's within
/// the derived tolerance on every topology family (chains, branches, many short chains, a star), on
/// Robotran's floating base (prismatic joints), on the free flyer, with fixed joints between
/// moving ones and on a chain of dense URDF rotations with oblique axes.
#[test]
fn depth_formulation_equals_the_rnea_within_rounding() {
    let mut robots: Vec<(String, Robot)> = Vec::new();
    for t in Topology::EVERY {
        robots.push((t.to_string(), build(t, 11, 3)));
        robots.push((format!("{t} floating"), massive_base(build(t, 7, 4)).with_floating_base().unwrap()));
        robots.push((format!("{t} free flyer"), massive_base(build(t, 7, 5)).with_free_flyer().unwrap()));
    }
    let mut with_fixed = build(Topology::SemiSerial, 8, 5);
    with_fixed.joints[2].kind = JointKind::Fixed;
    with_fixed.joints[5].kind = JointKind::Fixed;
    robots.push(("fixed joints".into(), with_fixed));
    let mut dense = build(Topology::Serial, 9, 6);
    for (i, j) in dense.joints.iter_mut().enumerate() {
        let x = i as f64;
        j.origin = Origin::from_xyz_rpy(j.origin.xyz, [0.3 * x - 1.0, 0.2 * x - 0.7, 1.1 * x]);
        let a = [0.3, -0.5 + 0.1 * x, 0.8];
        let n = a.iter().map(|v| v * v).sum::<f64>().sqrt();
        j.axis = a.map(|v| v / n);
    }
    robots.push(("dense rpy, oblique axes".into(), dense.clone()));
    let mut prismatic = dense;
    for j in prismatic.joints.iter_mut().step_by(3) {
        j.kind = JointKind::Prismatic;
    }
    robots.push(("prismatic joints".into(), prismatic));
    for (what, r) in &robots {
        let w = worst_ratio(r);
        eprintln!("{what}: worst |depth − rnea| / tolerance = {w:.2e}");
        assert!(w <= 1.0, "{what}: |depth − rnea| is {w} times the tolerance");
    }
}

/// The critical path (ASAPCycle after `atomise`) of `invdyna` of a serial chain of `dof` bodies.
fn critical_path(dof: usize, write: Writer) -> u32 {
    let f = function(&build(Topology::Serial, dof, 1), "invdyna", write);
    robovec_passes::summary::stats(&f, &Latencies::default()).asap_cycle
}

/// Quadrupling a chain (16 → 64 bodies) quadruples the body-frame RNEA's critical path but
/// grows the depth formulation's by far less (its prefixes gain two levels each): the ratio
/// is below 2, and the depth formulation is the shorter from 16 bodies on.
#[test]
fn depth_formulation_critical_path_grows_logarithmically() {
    let (d16, d64) = (critical_path(16, super::invdyna), critical_path(64, super::invdyna));
    let (r16, r64) = (critical_path(16, crate::rnea::invdyna), critical_path(64, crate::rnea::invdyna));
    let (depth_ratio, rnea_ratio) = (d64 as f64 / d16 as f64, r64 as f64 / r16 as f64);
    eprintln!("critical path, serial 16 / 64: depth {d16} / {d64}, RNEA {r16} / {r64}");
    assert!(rnea_ratio > 3.5, "RNEA {r16} → {r64}");
    assert!(depth_ratio < 2.0, "depth {d16} → {d64}");
    assert!(d16 < r16 && d64 < r64, "depth {d16}, {d64}; RNEA {r16}, {r64}");
}
