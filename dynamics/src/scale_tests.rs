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

/// The ops after `atomise,cse` as counted before issue 47: a pruned copy, atomised, its repeats
/// merged by the `cse` pass, then counted (the reference the new count must equal).
fn ops_after_cse_by_copy(f: &Function) -> u64 {
    let mut f = f.clone();
    let live = f.live_values(&[]);
    f.retain(|_, v| live[v.index()]);
    let mut f = robovec_passes::atomise::atomise_owned(f);
    robovec_passes::cse::cse_function(&mut f);
    f.op_counts().total
}

/// Issue 47: the op count that chooses `fordyna`'s formulation is computed without rewriting a
/// copy, and equals the count by a copy put through `atomise,cse`; the ops as written bound it
/// (what lets the ABA skip it when the factorisation cannot win).
#[test]
fn the_ops_after_cse_are_counted_in_place_and_bounded_by_the_ops_written() {
    for (t, dof) in [(Topology::Serial, 9), (Topology::SemiSerial, 14), (Topology::Star, 12), (Topology::Parallel, 11)]
    {
        let robot = build(t, dof, 5);
        let model = Model { robot: robot.clone() };
        let layout = crate::Layout::of(&model.robot);
        for how in [crate::fordyna::Formulation::Ltdl, crate::fordyna::Formulation::Aba] {
            let mut b = crate::sym::Builder::new("fordyna", Default::default());
            crate::fordyna::fordyna_with(&model, &layout, &mut b, how).expect("no deadline");
            let counted = b.ops_after_cse();
            assert_eq!(counted, ops_after_cse_by_copy(&b.f), "{t} {dof} {how:?}");
            assert!(counted <= b.f.op_counts().total, "{t} {dof} {how:?}");
            assert_eq!(b.ops_after_cse_until(), Ok(counted));
        }
    }
}

/// The ticks a step takes: the least tick budget with which `run` completes, less one (a
/// budget of `k` stops the step at its `k`-th tick, so it completes once `k` exceeds them).
fn ticks_of(mut run: impl FnMut(u64) -> bool) -> u64 {
    let (mut lo, mut hi) = (1u64, 1u64);
    while !run(hi) {
        (lo, hi) = (hi + 1, hi * 2);
    }
    // `run(hi)` completes, `run(lo - 1)` does not.
    while lo < hi {
        let mid = (lo + hi) / 2;
        if run(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    assert!(!run(lo - 1) || lo == 1, "a smaller budget stops it");
    lo - 1
}

/// Issue 47: the steps over a whole generated function tick once per element of each of their
/// loops, so that `-time-limit` stops them at its next 1024 steps: the op count after
/// `atomise,cse` (which took 19 s on a 10,000-joint chain without looking at the clock) and
/// the compaction of `Builder::finish` (25 million outputs of a 5,000-branch star's `dirdyna`).
/// Each count is the sum of the loops' lengths, from the function's sizes.
#[test]
fn every_step_over_a_whole_function_ticks_once_per_element() {
    let robot = build(Topology::SemiSerial, 30, 2);
    let model = Model { robot };
    let layout = crate::Layout::of(&model.robot);
    let mut b = crate::sym::Builder::new("fordyna", Default::default());
    crate::fordyna::fordyna_with(&model, &layout, &mut b, crate::fordyna::Formulation::Ltdl).expect("no deadline");
    let with_budget = |k: u64| {
        let mut c = b.fresh();
        c.f = b.f.clone();
        c.tick_budget = Some(k);
        c
    };
    // Liveness, then the pruning: its walk of inputs and body, the kept values moved and
    // renumbered, the output and name indexes.
    let compaction = |f: &Function| {
        let live = f.live_values(&[]);
        let kept = live.iter().filter(|&&l| l).count() as u64;
        let (o, n) = (f.outputs.len() as u64, (f.inputs.len() + f.body.len()) as u64);
        ((o + f.body.len() as u64) + n + 3 * kept + o, live)
    };
    let (finish, _) = compaction(&b.f);
    assert_eq!(ticks_of(|k| with_budget(k).finish_until().is_ok()), finish);
    let atomised = robovec_passes::atomise::atomise_function(&b.f);
    let (prune, live) = compaction(&atomised);
    let kept_body = atomised.body.iter().filter(|v| live[v.index()]).count() as u64;
    // Atomising (an equation), the pruning, the merges and the op count (a kept op each).
    let count = b.f.body.len() as u64 + prune + 2 * kept_body;
    assert_eq!(ticks_of(|k| with_budget(k).ops_after_cse_until().is_ok()), count);
    // Each stop names its step.
    let stop = with_budget(count / 2).ops_after_cse_until().expect_err("stops");
    assert_eq!(
        stop.to_string(),
        "time limit of 0 s reached while generating @fordyna (counting its ops after atomise,cse)"
    );
    let stop = with_budget(finish / 2).finish_until().expect_err("stops");
    assert_eq!(stop.at, Reached::Step("compacting it"));
}

/// A tick budget reaches `generate_with`'s steps over whole functions whatever the clock says:
/// each function of a 40-joint chain stops in its first one (the writers check the deadline per
/// body, which a budget does not set), and a budget above every loop's length changes nothing.
#[test]
fn a_tick_budget_stops_the_generation_in_its_steps_over_whole_functions() {
    let robot = build(Topology::Serial, 40, 1);
    for (name, step) in [("invdyna", "compacting it"), ("dirdyna", "compacting it"), ("fordyna", "counting its ops")] {
        let r = Request { tick_budget: Some(100), ..request(Some(&[name])) };
        let stop = generate_with(&Model { robot: robot.clone() }, &r).expect_err("a budget of 100 ticks");
        assert_eq!((stop.function.as_str(), stop.at), (name, Reached::Step(step)));
        let r = Request { tick_budget: Some(1 << 40), ..request(Some(&[name])) };
        let g = generate_with(&Model { robot: robot.clone() }, &r).expect("a budget above every loop");
        let reference = generate_with(&Model { robot: robot.clone() }, &request(Some(&[name]))).expect("no limit");
        assert_eq!(g.module, reference.module, "{name}");
    }
}

/// Issue 47: a leaf without mass makes `M` singular; the generator records the coordinate of
/// the zero pivot (before, `fordyna` held the constant `inf` that the verifier rejected),
/// whichever formulation it writes, on a fixed base or a free flyer, while `dirdyna` (`M`
/// itself) and `invdyna` have none.
#[test]
fn a_massless_leaf_makes_a_zero_pivot_the_generator_names() {
    let mut robot = build(Topology::SemiSerial, 8, 3);
    // The last joint's child is a leaf (chains are built one after the other).
    let leaf = robot.joints.last().expect("joints").child;
    robot.links[leaf].inertial = None;
    let nq = 8;
    let all = request(Some(&["invdyna", "dirdyna", "fordyna"]));
    let g = generate_with(&Model { robot: robot.clone() }, &all).expect("no deadline");
    assert_eq!(g.singular.map(|(f, s)| (f, s.coordinate, s.pivot)), Some(("fordyna".to_string(), nq, 0.0)));
    let g = generate_with(&Model { robot: robot.clone() }, &request(Some(&["invdyna", "dirdyna"]))).expect("ok");
    assert_eq!(g.singular, None);
    let model = Model { robot: robot.clone() };
    let layout = crate::Layout::of(&model.robot);
    for how in [crate::fordyna::Formulation::Ltdl, crate::fordyna::Formulation::Aba] {
        let mut b = crate::sym::Builder::new("fordyna", Default::default());
        crate::fordyna::fordyna_with(&model, &layout, &mut b, how).expect("no deadline");
        assert_eq!(b.singular.map(|s| s.coordinate), Some(nq), "{how:?}");
    }
    // On a free flyer (a massive base) the leaf's coordinate comes after the base's six.
    let mut free = robot.clone();
    let root = free.root;
    free.links[root].inertial = Some(crate::robot::Inertial {
        mass: 3.0,
        com: [0.0; 3],
        inertia: [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
    });
    let free = free.with_free_flyer().expect("free names");
    let g = generate_with(&Model { robot: free }, &request(Some(&["fordyna"]))).expect("no deadline");
    assert_eq!(g.singular.map(|(_, s)| s.coordinate), Some(nq + 6));
    // With every link massive, no pivot is zero.
    let g = generate_with(&Model { robot: build(Topology::SemiSerial, 8, 3) }, &all).expect("no deadline");
    assert_eq!(g.singular, None);
}
