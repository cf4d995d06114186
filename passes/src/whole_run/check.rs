//! `-check`: after the pipeline, every function (or the one `-function` names) must keep the
//! numeric property of [`crate::accuracy::check`] against the module as it entered the
//! pipeline; the first output that breaks it ends the run with exit 1 (bad input: the rules
//! or passes changed the mathematics), before any output file is written. Under
//! `-time-limit` it checks chunks of points until the limit (the first chunk always runs; a
//! function not started by then is skipped), with a note saying how many points it checked.

use std::io::Write;

use robovec_ir::Module;

use super::Failure;
use crate::accuracy::check::check_function_until;
use crate::PassManager;

/// Checks `after`, the result of `pipeline`, against `original` at `samples` points of `seed`
/// (bit for bit when the pipeline is declared bit-exact, [`PassManager::is_bit_exact`]); one
/// line per function on `stderr` when it passes.
///
/// # Errors
/// [`Failure::Input`] naming the function, output, format, point, computed and exact values
/// and the budget of the first violation, or an output missing from the original.
#[allow(clippy::too_many_arguments)]
pub fn run(
    after: &Module,
    original: &Module,
    pipeline: &PassManager,
    only: &Option<String>,
    samples: u32,
    seed: u64,
    deadline: Option<crate::Deadline>,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let bit_exact = pipeline.is_bit_exact();
    let pipeline = pipeline.pipeline_text();
    for f in &after.functions {
        if only.as_ref().is_some_and(|n| n != &f.name) {
            continue;
        }
        if let Some(d) = deadline.filter(crate::Deadline::reached) {
            let _ = writeln!(stderr, "note: -check skipped @{}: {} before it started", f.name, d.reason());
            continue;
        }
        let fail = |m: String| Failure::Input(format!("error: -check: {m}\n"));
        let before = original
            .function(&f.name)
            .ok_or_else(|| fail(format!("function @{} is not in the input of the pipeline", f.name)))?;
        let r = check_function_until(f, before, bit_exact, samples, seed, deadline.map(|d| d.end())).map_err(fail)?;
        if r.samples < u64::from(samples) {
            let why = deadline.map(|d| d.reason()).unwrap_or_default();
            let _ =
                writeln!(stderr, "note: -check stopped after {} of {samples} samples of @{}: {why}", r.samples, f.name);
        }
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
