//! `-check`: after the pipeline, every function (or the one `-function` names) must keep the
//! numeric property of [`crate::accuracy::check`] against the module as it entered the
//! pipeline; the first output that breaks it ends the run with exit 1 (bad input: the rules
//! or passes changed the mathematics), before any output file is written.

use std::io::Write;

use robovec_ir::Module;

use super::Failure;
use crate::accuracy::check::{check_function, pipeline_is_bit_exact};

/// Checks `after` against `original` at `samples` points of `seed`; one line per function on
/// `stderr` when it passes.
///
/// # Errors
/// [`Failure::Input`] naming the function, output, format, point, computed and exact values
/// and the budget of the first violation, or an output missing from the original.
pub fn run(
    after: &Module,
    original: &Module,
    pipeline: &str,
    only: &Option<String>,
    samples: u32,
    seed: u64,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let bit_exact = pipeline_is_bit_exact(pipeline);
    for f in &after.functions {
        if only.as_ref().is_some_and(|n| n != &f.name) {
            continue;
        }
        let fail = |m: String| Failure::Input(format!("error: -check: {m}\n"));
        let before = original
            .function(&f.name)
            .ok_or_else(|| fail(format!("function @{} is not in the input of the pipeline", f.name)))?;
        let r = check_function(f, before, bit_exact, samples, seed).map_err(fail)?;
        if let Some(v) = r.violation {
            return Err(fail(format!("{v} (pipeline `{pipeline}`, {samples} samples, seed {seed})")));
        }
        let _ = writeln!(
            stderr,
            "@{}: check passed: {} outputs at {} samples (seed {seed}) within the error budget of the input{}{}",
            f.name,
            r.outputs,
            r.samples,
            if bit_exact { ", bit for bit" } else { "" },
            if r.undecided > 0 {
                format!(" ({} values undecided: unbounded budget)", r.undecided)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}
