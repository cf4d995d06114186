//! The defaults of the input domain a URDF gives its generated functions (issue 48; the
//! choices and their reasons are in docs/accuracy.md, "Certified ranges"):
//!
//! | input | default range | from |
//! |---|---|---|
//! | `q[i]` of a revolute or prismatic joint | `[lower, upper]` | its `<limit>` |
//! | `q[i]` of a continuous joint (one angle) | `[−π, π]` rounded outward | read only through `sin`/`cos` (checked: otherwise no default) |
//! | `q[i]`, `q[i+1]` of a continuous joint under `--continuous=cos-sin` | `[−1, 1]` each | a cosine and a sine |
//! | `qd[i]` | `[−velocity, velocity]` | its `<limit>` |
//! | `Qq[i]` (the torques `fordyna` takes) | `[−effort, effort]` | its `<limit>` |
//! | `qdd[i]` (the accelerations `invdyna` takes) | [`QDD_DEFAULT`] | a documented convention |
//! | Robotran's floating base `T1`–`T3` / `R1`–`R3` | [`BASE_POSITION`] m / `[−π, π]` (read through `sin`/`cos`) | a convention / the period |
//! | the free flyer: position, quaternion, velocity, acceleration | [`BASE_POSITION`] m, `[−1, 1]`, [`BASE_VELOCITY`], [`QDD_DEFAULT`] | conventions; a unit quaternion's components |
//! | parameters `dpt l m In`, gravity `g[k]` | the point `[x, x]` | the URDF's values, Pinocchio's gravity |
//!
//! A `<limit>` that is absent or holds a placeholder (`velocity="0"`, `lower` = `upper`: see
//! [`super::parse::Limit`]) gives no default: the input is then named by the driver's
//! diagnostic unless `-ranges=FILE` gives it.

use std::collections::BTreeMap;
use std::f64::consts::PI;

use robovec_dynamics::robot::{JointKind, Robot, FLOATING_BASE};
use robovec_ir::domain::Range;
use robovec_ir::{Def, Expr, Interval, Module, Operand};
use rustc_hash::{FxHashMap, FxHashSet};

use super::parse::Limit;

/// Default range of a joint acceleration `qdd[i]` (rad/s² or m/s²): ±100, above what robot
/// joints reach (industrial arms and humanoids stay within a few tens of rad/s²); a convention,
/// overridden by `-ranges=FILE`.
pub const QDD_DEFAULT: (f64, f64) = (-100.0, 100.0);

/// Default range of a floating base's or free flyer's position coordinates (m): ±100.
pub const BASE_POSITION: (f64, f64) = (-100.0, 100.0);

/// Default range of a free flyer's velocity coordinates (m/s, rad/s): ±10.
pub const BASE_VELOCITY: (f64, f64) = (-10.0, 10.0);

/// `[−π, π]` rounded outward: a full period of `sin` and `cos` (wider than 2π).
fn full_turn() -> Interval {
    Interval::new((-PI).next_down(), PI.next_up())
}

fn value_of(o: &Operand) -> Option<robovec_ir::Value> {
    match o {
        Operand::Value(v) => Some(*v),
        Operand::Const(_) => None,
    }
}

/// The inputs of `m`'s functions read other than as the angle of a `sin`/`cos` (by name).
fn read_directly(m: &Module) -> FxHashSet<String> {
    fn walk(e: &Expr, out: &mut Vec<robovec_ir::Value>) {
        match e {
            Expr::Operand(Operand::Value(v)) => out.push(*v),
            Expr::Operand(Operand::Const(_)) => {}
            Expr::Neg(x) => walk(x, out),
            Expr::Binary(_, a, b) => {
                walk(a, out);
                walk(b, out);
            }
            Expr::Call(_, args) => args.iter().for_each(|a| walk(a, out)),
        }
    }
    let mut names = FxHashSet::default();
    for f in &m.functions {
        let mut used = Vec::new();
        for &v in &f.body {
            match &f.value(v).def {
                Def::Input | Def::Trig(..) => {}
                Def::Binary(_, a, b) => used.extend([a, b].into_iter().filter_map(value_of)),
                Def::Call(_, args) => used.extend(args.iter().filter_map(value_of)),
                Def::Expr(e) => walk(e, &mut used),
            }
        }
        used.extend(f.outputs.iter().filter_map(|o| value_of(&o.value)));
        names.extend(
            used.into_iter().filter(|&v| matches!(f.value(v).def, Def::Input)).map(|v| f.name_of(v).to_string()),
        );
    }
    names
}

/// The defaults of the domain of `m` (the functions generated for `robot`, which is the robot
/// as generated: with its floating base or free flyer), from the URDF's `limits` (by joint
/// name) and the values of its parameters and gravity `values` (`Loaded::input_defaults`).
/// Only inputs some function of `m` has are given.
pub fn defaults(
    robot: &Robot,
    limits: &FxHashMap<String, Limit>,
    m: &Module,
    values: &BTreeMap<String, f64>,
) -> BTreeMap<String, Range> {
    let layout = robovec_dynamics::Layout::of(robot);
    let direct = read_directly(m);
    let mut out = BTreeMap::new();
    let mut put = |name: String, i: Interval, source: String| {
        out.insert(name, Range { interval: i, source });
    };
    let span = |(lo, hi): (f64, f64)| Interval::new(lo, hi);
    for (b, &j) in robot.dfs_joints().iter().enumerate() {
        let joint = &robot.joints[j];
        let (Some(qi), Some(vi)) = (layout.q_index[b], layout.v_index[b]) else { continue };
        let name = &joint.name;
        let limit = limits.get(name).copied().unwrap_or_default();
        let base = FLOATING_BASE.contains(&name.as_str()) && !joint.continuous && !limits.contains_key(name);
        match joint.kind {
            JointKind::FreeFlyer => {
                for k in 0..3 {
                    put(format!("q[{}]", qi + k), span(BASE_POSITION), "default: free-flyer position".into());
                }
                for k in 3..7 {
                    put(format!("q[{}]", qi + k), span((-1.0, 1.0)), "default: unit quaternion component".into());
                }
                for k in 0..6 {
                    put(format!("qd[{}]", vi + k), span(BASE_VELOCITY), "default: free-flyer velocity".into());
                    put(format!("qdd[{}]", vi + k), span(QDD_DEFAULT), "default: acceleration".into());
                }
                continue;
            }
            JointKind::Fixed => continue,
            JointKind::Prismatic if base => {
                put(format!("q[{qi}]"), span(BASE_POSITION), format!("default: floating-base position {name}"));
            }
            JointKind::Revolute if base || joint.continuous => {
                let q = format!("q[{qi}]");
                if robot.cos_sin && joint.continuous {
                    let why = format!("default: cos/sin pair of continuous joint `{name}`");
                    put(q, span((-1.0, 1.0)), why.clone());
                    put(format!("q[{}]", qi + 1), span((-1.0, 1.0)), why);
                } else if !direct.contains(&q) {
                    let why = format!("default: a full turn, joint `{name}` is read only through sin/cos");
                    put(q, full_turn(), why);
                }
            }
            JointKind::Revolute | JointKind::Prismatic => {
                if let Some(p) = limit.position {
                    put(format!("q[{qi}]"), span(p), format!("URDF <limit> of joint `{name}`"));
                }
            }
        }
        if let Some(v) = limit.velocity {
            put(format!("qd[{vi}]"), span((-v, v)), format!("URDF <limit velocity> of joint `{name}`"));
        }
        if let Some(e) = limit.effort {
            put(format!("Qq[{vi}]"), span((-e, e)), format!("URDF <limit effort> of joint `{name}`"));
        }
        put(format!("qdd[{vi}]"), span(QDD_DEFAULT), "default: acceleration".into());
    }
    for (name, &x) in values {
        let from = if name.starts_with("g[") { "default: Pinocchio's gravity" } else { "URDF parameter value" };
        put(name.clone(), Interval::point(x), from.into());
    }
    let inputs: FxHashSet<&str> = m.functions.iter().flat_map(|f| f.inputs.iter().map(|&v| f.name_of(v))).collect();
    out.retain(|n, _| inputs.contains(n.as_str()));
    out
}
