//! `diff<wrt=…;mode=auto|forward|reverse>`: derivative outputs `d<out>_d<in>[i][j]` of every
//! output with respect to the inputs `wrt` names (issue 50 item 1). The transform, its rules,
//! names and modes are [`robovec_ir::transform::diff`]'s (its module doc); this pass adds the
//! registry entry, the check that every `wrt` entry names an input of some function, the
//! `-time-limit` policy (required: it changes the outputs) and the remark.

pub use robovec_ir::transform::diff::{derivative_name, differentiate, matches, Failure, Mode};
use robovec_ir::Module;

use crate::params::ParamKind;
use crate::time_limit::TickerError;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

#[cfg(test)]
mod tests;

/// The words of `mode=`.
const MODES: &[&str] = &["auto", "forward", "reverse"];

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "diff",
    doc: "derivative outputs d<out>_d<in>[i][j] of every output with respect to the inputs named in wrt",
    params: &[
        ParamInfo {
            name: "wrt",
            kind: ParamKind::Names,
            doc: "inputs to differentiate with respect to: names (`q[4]`) or families (`q,qd`), comma-separated; \
                  every input when not given (the full Jacobian)",
        },
        ParamInfo {
            name: "mode",
            kind: ParamKind::Choice { choices: MODES, default: "auto" },
            doc:
                "forward (ops x inputs), reverse (ops x outputs), or auto: the one that carries fewer derivative terms",
        },
    ],
    build: |p: &Params| {
        let mode = match p.choice("mode")? {
            "forward" => Some(Mode::Forward),
            "reverse" => Some(Mode::Reverse),
            _ => None,
        };
        Ok(Box::new(Diff { wrt: p.names("wrt")?.unwrap_or_default(), mode }))
    },
    // Existing outputs keep their value; the new ones are exact in the reals (the derivative of
    // the function as written), so `error-bound` after it bounds their rounding.
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        bit_exact: true,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// The `diff` pass.
#[derive(Debug)]
pub struct Diff {
    /// The `wrt` entries: input names or families, in the order the outputs take.
    pub wrt: Vec<String>,
    /// The mode; `None`: by shape (`auto`).
    pub mode: Option<Mode>,
}

impl Pass for Diff {
    fn name(&self) -> &'static str {
        "diff"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let bad = |message: String| PassError::BadParameter { pass: "diff".into(), message };
        for e in &self.wrt {
            if !m.functions.iter().any(|f| f.inputs.iter().any(|&v| matches(e, f.name_of(v)))) {
                let mut names: Vec<&str> =
                    m.functions.iter().flat_map(|f| f.inputs.iter().map(|&v| f.name_of(v))).collect();
                names.truncate(12);
                return Err(bad(format!("no input matches `{e}` (inputs are like: {})", names.join(", "))));
            }
        }
        let parts = try_each_function(
            m,
            cx,
            "diff",
            AtTimeLimit::Required,
            Before::Clock,
            |_, _| None,
            |f, _, ticker| {
                let before = f.op_counts().total;
                let outputs = f.outputs.len();
                let mode = differentiate(f, &self.wrt, self.mode, ticker).map_err(|e| match e {
                    Failure::Stopped => ticker.error("diff", &format!("in @{}", f.name)),
                    Failure::Message(message) => PassError::Failed { pass: "diff".into(), message },
                })?;
                Ok(Step::Done(format!(
                    "@{}: {} derivatives ({mode:?}), ops {before} -> {}",
                    f.name,
                    f.outputs.len() - outputs,
                    f.op_counts().total
                )))
            },
        )?;
        cx.remark("diff", m, format!("diff: {}", parts.join("; ")));
        Ok(())
    }
}
