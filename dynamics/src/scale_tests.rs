//! Issue 28 item 2: the generator writes only the functions asked for, at a cost that follows
//! the ops it writes, and stops at its deadline. Sizes are structural counts (values, ops,
//! outputs) computed from the robot, never times.

use robovec_ir::time_limit::Deadline;
use robovec_ir::{Def, Expr, Function, Operand};

use crate::robot::Robot;
use crate::topology::{build, Topology};
use crate::{generate_with, Model, Reached, Request, FUNCTION_NAMES};

fn request(functions: Option<&[&str]>) -> Request {
    Request { functions: functions.map(|f| f.iter().map(|s| s.to_string()).collect()), ..Request::default() }
}

fn names(r: &Request, robot: &crate::robot::Robot) -> Vec<String> {
    let g = generate_with(&Model { robot: robot.clone() }, r).expect("no deadline");
    g.module.functions.iter().map(|f| f.name.clone()).collect()
}

#[test]
fn only_the_functions_asked_for_are_built() {
    let robot = build(Topology::SemiSerial, 9, 2);
    assert_eq!(names(&request(None), &robot), ["invdyna", "dirdyna"], "Robotran's pair by default");
    assert_eq!(names(&request(Some(&["fordyna"])), &robot), ["fordyna"]);
    assert_eq!(names(&request(Some(&["invdyna"])), &robot), ["invdyna"]);
    assert_eq!(names(&request(Some(&["dirdyna"])), &robot), ["dirdyna"]);
    assert_eq!(names(&request(Some(&["fordyna", "dirdyna", "invdyna"])), &robot), FUNCTION_NAMES, "module order");
    assert!(names(&request(Some(&["sensor_1"])), &robot).is_empty(), "a name the generator does not write");
    // Asked alone, a function's frames are chosen for its own ops: never more than when both
    // functions choose together.
    let ops = |r: &Request, name: &str| {
        let g = generate_with(&Model { robot: robot.clone() }, r).expect("no deadline");
        g.module.function(name).expect("built").op_counts().total
    };
    for name in ["invdyna", "dirdyna"] {
        assert!(ops(&request(Some(&[name])), name) <= ops(&request(None), name), "{name}");
    }
}

/// Values (inputs, trig variables, temporaries), expression ops and outputs of `f`.
fn size(f: &Function) -> (usize, u64, usize) {
    (f.values.len(), f.op_counts().total, f.outputs.len())
}

/// `a / b` within 1 % of 2.
fn doubles(a: usize, b: usize) -> bool {
    let r = a as f64 / b as f64;
    (1.98..=2.02).contains(&r)
}

/// `robot` with every joint off the base and its subtree copied (names suffixed `b`): the
/// same branches twice, so that whatever the generator writes per branch doubles exactly.
fn doubled(robot: &Robot) -> Robot {
    let mut out = robot.clone();
    let mut copy_of: Vec<Option<usize>> = vec![None; robot.links.len()];
    copy_of[robot.root] = Some(robot.root);
    for j in robot.dfs_joints() {
        let joint = &robot.joints[j];
        let mut link = robot.links[joint.child].clone();
        link.name += "b";
        out.links.push(link);
        copy_of[joint.child] = Some(out.links.len() - 1);
        let mut copy = joint.clone();
        copy.name += "b";
        copy.parent = copy_of[joint.parent].expect("parents first");
        copy.child = out.links.len() - 1;
        out.joints.push(copy);
    }
    out
}

#[test]
fn a_star_costs_what_it_writes_and_its_mass_matrix_is_diagonal() {
    let generate = |robot: Robot| {
        let g = generate_with(&Model { robot }, &request(None)).expect("no deadline");
        let [inv, dir] = [0, 1].map(|k| g.module.functions[k].clone());
        (inv, dir)
    };
    let (n, m) = (150, 300);
    let star = build(Topology::Star, n, 4);
    let ((inv_n, dir_n), (inv_m, dir_m)) = (generate(star.clone()), generate(doubled(&star)));
    for (what, a, b) in [("invdyna", size(&inv_m), size(&inv_n)), ("dirdyna", size(&dir_m), size(&dir_n))] {
        assert!(doubles(a.0, b.0), "{what}: values {} → {}", b.0, a.0);
        assert!(doubles(a.1 as usize, b.1 as usize), "{what}: ops {} → {}", b.1, a.1);
    }
    // The outputs are Robotran's layout: every entry of M (both triangles), then c.
    assert_eq!(dir_m.outputs.len(), m * m + m);
    assert_eq!(inv_m.outputs.len(), m);
    // M of a star is diagonal: every entry off the diagonal is the constant 0 and the
    // temporaries of M are its diagonal's (one bound value per body, no per-pair value).
    for o in &dir_m.outputs {
        let Some(rest) = o.name.strip_prefix("M[") else { continue };
        let (i, j) = rest.trim_end_matches(']').split_once("][").expect("M[i][j]");
        if i == j {
            assert!(matches!(o.value, Operand::Value(_)), "{}: a value", o.name);
        } else {
            assert_eq!(o.value, Operand::Const(0.0), "{}", o.name);
        }
    }
    let entry = |name: &str| name.strip_prefix('M').is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
    let entries = dir_m.body.iter().filter(|&&v| entry(dir_m.name_of(v))).count();
    assert!(entries <= m, "at most one bound entry per diagonal element: {entries}");
}

#[test]
fn a_hub_with_many_children_costs_what_it_writes() {
    // The star on Robotran's floating base: the base moves, so its force and composite sum
    // every branch's.
    let ops = |robot: &Robot, name: &str| {
        let robot = robot.clone().with_floating_base().expect("free names");
        let r = request(Some(&[name]));
        let g = generate_with(&Model { robot }, &r).expect("no deadline");
        g.module.functions[0].op_counts().total as usize
    };
    let star = build(Topology::Star, 100, 4);
    for name in FUNCTION_NAMES {
        let (a, b) = (ops(&star, name), ops(&doubled(&star), name));
        // The base's six coordinates cost the same for both; dirdyna's six base rows of M are
        // one entry per branch: linear too.
        assert!(doubles(b, a), "{name}: ops {a} → {b}");
    }
}

#[test]
fn the_deadline_stops_the_generation_at_a_body() {
    let robot = build(Topology::Serial, 40, 1);
    let past = Deadline::after_seconds(0.0);
    for name in FUNCTION_NAMES {
        let r = Request { deadline: Some(past), ..request(Some(&[name])) };
        let stop = generate_with(&Model { robot: robot.clone() }, &r).expect_err("the deadline has passed");
        let Reached::Body { body, bodies: 40 } = stop.at else { panic!("{stop:?}") };
        assert_eq!(stop.function, name);
        assert!((1..=40).contains(&body), "{stop:?}");
        assert_eq!(stop.to_string(), format!("time limit of 0 s reached while generating @{name} (body {body} of 40)"));
    }
    let far = Request { deadline: Some(Deadline::after_seconds(3600.0)), ..request(None) };
    assert!(generate_with(&Model { robot }, &far).is_ok());
}

/// Depth of an expression tree (an operand is 1).
fn depth(e: &Expr) -> usize {
    match e {
        Expr::Operand(_) => 1,
        Expr::Neg(a) => 1 + depth(a),
        Expr::Binary(_, a, b) => 1 + depth(a).max(depth(b)),
        Expr::Call(_, args) => 1 + args.iter().map(depth).max().unwrap_or(0),
    }
}

#[test]
fn a_hub_s_sums_are_bound_in_chunks_so_no_expression_is_deep() {
    // 300 branches off a moving base: its force, moment and composite sum 300 children.
    let robot = build(Topology::Star, 300, 4).with_floating_base().expect("free names");
    let g = generate_with(&Model { robot }, &request(None)).expect("no deadline");
    for f in &g.module.functions {
        let deepest = f
            .body
            .iter()
            .filter_map(|&v| match &f.value(v).def {
                Def::Expr(e) => Some(depth(e)),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        // Unbound, the base's sums would be 300 deep; bound, a chunk of SUM_CHUNK children.
        assert!(deepest < 150, "@{}: an expression {deepest} deep", f.name);
    }
}
