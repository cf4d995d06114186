//! The URDF front end (issue 14): a robot description in, equations of motion out.
//!
//! [`parse`] reads and checks the tree (diagnostics with line and column); the symbolic
//! generator [`robovec_dynamics`] writes its inverse (`invdyna`) and direct (`dirdyna`) dynamics as
//! parsed-phase IR, the form the
//! Robotran front ends produce, so `robovec-opt robot.urdf -function=invdyna -passes=…` runs
//! like on a Robotran file. `--fold-params` folds the URDF's numbers into the equations;
//! by default they stay inputs in Robotran's layout and their values are
//! [`Loaded::params`](crate::Loaded::params) (written by `-params-out=FILE`).
//!
//! Only the functions `-function` names are generated ([`FrontOptions::functions`]; issue 28:
//! `-function=invdyna` on a 4,000-branch star no longer writes `dirdyna`'s 16 million
//! entries of `M`). `-time-limit` is checked per body of the generator's recursions
//! ([`robovec_dynamics::Request::deadline`]); once it is reached the load fails with
//! `time limit of 5 s reached while generating @dirdyna (body k of n)` at that body's
//! `<joint>` and no output is written: no pass can run on part of a function.
//!
//! A link that makes the mass matrix singular (no mass or no inertia about its joint's axis,
//! with what it carries) is named at its `<link>` with its joint when `fordyna` is asked for
//! ([`robovec_dynamics::Generated::singular`], issue 47), instead of the verifier's rejection of
//! the constant `inf` that `1/0` folds to.

mod domain;
mod parse;

use std::path::Path;

pub use parse::{parse, parse_with_limits, Limit, Parsed};

use robovec_dynamics::robot::JointKind;

use super::{FrontEnd, FrontError, FrontOptions, Loaded};

/// The registered URDF front end (`.urdf`).
pub struct Urdf;

impl FrontEnd for Urdf {
    fn name(&self) -> &'static str {
        "URDF"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["urdf"]
    }

    fn function_names(&self) -> Option<&'static [&'static str]> {
        Some(&robovec_dynamics::GENERATED_NAMES)
    }

    fn requires_utf8(&self) -> bool {
        true
    }

    /// Every model option: the generator builds the equations from the robot.
    fn options(&self) -> &'static [crate::registry::FrontOption] {
        &crate::registry::FrontOption::ALL
    }

    fn load(&self, _: &Path, text: &str, opts: &FrontOptions) -> Result<Loaded, Vec<FrontError>> {
        let Parsed { robot, limits, warnings } = parse_with_limits(text).map_err(|e| vec![e])?;
        let mut robot = robot;
        robot.cos_sin = opts.continuous_cos_sin;
        let robot = if opts.floating_base {
            robot.with_floating_base().map_err(|(name, span)| {
                vec![FrontError::new(span, format!("`{name}` is a name of robovec's floating base"), "this element")
                    .note("rename this URDF joint or link to use --floating-base")]
            })?
        } else if opts.free_flyer {
            robot.with_free_flyer().map_err(|(name, span)| {
                vec![FrontError::new(span, format!("`{name}` is a name of robovec's free flyer"), "this element")
                    .note("rename this URDF joint or link to use --free-flyer")]
            })?
        } else {
            robot
        };
        // A single rigid body moves on a free flyer or a floating base (a quadrotor).
        if !robot.joints.iter().any(|j| j.kind != JointKind::Fixed) {
            return Err(vec![FrontError::new(
                robot.links[robot.root].span,
                format!("robot `{}` has no moving joint", robot.name),
                "root link",
            )
            .note("expected at least one revolute, continuous or prismatic joint, or a moving base (--free-flyer, --floating-base)")]);
        }
        let request = robovec_dynamics::Request {
            gravity: opts.gravity,
            fold: opts.fold_params,
            functions: opts.functions.clone(),
            deadline: opts.deadline,
            tick_budget: None,
            formulation: opts.formulation,
        };
        let model = robovec_dynamics::Model { robot };
        let g = robovec_dynamics::generate_with(&model, &request).map_err(|stop| {
            // The joint of the body reached (the root link for a row of M's outputs).
            let order = model.robot.dfs_joints();
            let joint = match stop.at {
                robovec_dynamics::Reached::Body { body, .. } => body.checked_sub(1).and_then(|k| order.get(k)),
                robovec_dynamics::Reached::Row { .. } | robovec_dynamics::Reached::Step(_) => None,
            };
            let span = match joint {
                Some(&j) => model.robot.joints[j].span,
                None => model.robot.links[model.robot.root].span,
            };
            vec![FrontError::new(span, stop.to_string(), "reached here")
                .note("-time-limit covers loading too: nothing is written without a complete module")]
        })?;
        if let Some((function, singular)) = &g.singular {
            return Err(vec![singular_error(&model.robot, text, function, singular)]);
        }
        // `-eval`'s values for inputs not given: the model's own, and gravity as Pinocchio's
        // `Model::gravity` (−9.81 m/s² along z).
        // (With -gravity, no function has the inputs `g[k]`.)
        let mut input_defaults = g.params.clone().unwrap_or_default();
        input_defaults.extend([("g[1]".to_string(), 0.0), ("g[2]".to_string(), 0.0), ("g[3]".to_string(), -9.81)]);
        let defaults_source = "the URDF's parameters and Pinocchio's gravity (0, 0, -9.81)";
        let domain_defaults = match opts.domain {
            true => domain::defaults(&model.robot, &limits, &g.module, &input_defaults),
            false => Default::default(),
        };
        Ok(Loaded { module: g.module, params: g.params, input_defaults, defaults_source, domain_defaults, warnings })
    }
}

/// The error of a mass matrix the generator found singular ([`robovec_dynamics::Generated::singular`],
/// issue 47): the link whose joint's pivot is zero, at its `<link>` element, with its joint and
/// what to give it. Before, the verifier rejected the constant `inf` of `1/0` with no file, link
/// or cause.
fn singular_error(
    robot: &robovec_dynamics::robot::Robot,
    text: &str,
    function: &str,
    s: &robovec_dynamics::sym::Singular,
) -> FrontError {
    let layout = robovec_dynamics::Layout::of(robot);
    let order = robot.dfs_joints();
    // The joint whose velocity coordinates hold the pivot's.
    let body = (0..order.len()).find(|&i| {
        let nv = robot.joints[order[i]].kind.nv();
        layout.v_index[i].is_some_and(|first| (first..first + nv).contains(&s.coordinate))
    });
    let row = format!("row {0} of M, qdd[{0}]", s.coordinate);
    let Some(body) = body else {
        let root = &robot.links[robot.root];
        return FrontError::new(
            root.span,
            format!("the mass matrix is singular (a zero pivot in {row})"),
            "this robot",
        )
        .note(format!("@{function} would divide by it: give every moving link an <inertial>"));
    };
    let joint = &robot.joints[order[body]];
    let link = &robot.links[joint.child];
    // Links below it: the pivot is the inertia of the whole subtree the joint moves.
    let carries = robot.joints.iter().any(|j| j.parent == joint.child);
    let prismatic = joint.kind == JointKind::Prismatic;
    let own = match link.inertial {
        None => "has no `<inertial>`",
        Some(i) if i.mass == 0.0 && prismatic => "has mass 0",
        Some(i) if i.mass == 0.0 => "has mass 0 and no inertia about its joint's axis",
        Some(_) if prismatic => "has no mass along its joint's axis",
        Some(_) => "has no inertia about its joint's axis (its mass lies on the axis)",
    };
    let carried = if carries { ", nor do the links it carries" } else { "" };
    let about = if prismatic { "" } else { " and inertia about the joint's axis" };
    let (line, _) = robovec_ir::span::line_col(text, joint.span.start as usize);
    FrontError::new(
        link.span,
        format!(
            "link `{}` (joint `{}`) {own}{carried}: the mass matrix is singular (a zero pivot in {row})",
            link.name, joint.name
        ),
        "this link",
    )
    .note(format!(
        "joint `{}` (line {line}) moves it; @{function} would divide by that pivot, 1/{}",
        joint.name, s.pivot
    ))
    .note(format!(
        "give link `{}` an <inertial> with a positive mass{about}, or make joint `{}` fixed",
        link.name, joint.name
    ))
}

#[cfg(test)]
mod tests;
