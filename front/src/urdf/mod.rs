//! The URDF front end (issue 14): a robot description in, equations of motion out.
//!
//! [`parse`] reads and checks the tree (diagnostics with line and column); the symbolic
//! generator [`robovec_dynamics`] writes its inverse (`invdyna`) and direct (`dirdyna`) dynamics as
//! parsed-phase IR, the form the
//! Robotran front ends produce, so `robovec-opt robot.urdf -function=invdyna -passes=…` runs
//! like on a Robotran file. `--fold-params` folds the URDF's numbers into the equations;
//! by default they stay inputs in Robotran's layout and their values are
//! [`Loaded::params`](crate::Loaded::params) (written by `-params-out=FILE`).

mod parse;

use std::path::Path;

pub use parse::parse;

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

    fn load(&self, _: &Path, text: &str, opts: &FrontOptions) -> Result<Loaded, Vec<FrontError>> {
        let robot = parse(text).map_err(|e| vec![e])?;
        if !robot.joints.iter().any(|j| j.kind != JointKind::Fixed) {
            return Err(vec![FrontError::new(
                robot.links[robot.root].span,
                format!("robot `{}` has no moving joint", robot.name),
                "root link",
            )
            .note("expected at least one revolute, continuous or prismatic joint")]);
        }
        let robot = if opts.floating_base {
            robot.with_floating_base().map_err(|(name, span)| {
                vec![FrontError::new(span, format!("`{name}` is a name of robovec's floating base"), "this element")
                    .note("rename this URDF joint or link to use --floating-base")]
            })?
        } else {
            robot
        };
        let g = robovec_dynamics::generate(&robovec_dynamics::Model { robot }, opts.fold_params);
        Ok(Loaded { module: g.module, params: g.params })
    }
}

#[cfg(test)]
mod tests;
