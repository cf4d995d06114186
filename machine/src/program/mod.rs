//! The lowering of a placed function into its [`MachineProgram`] (issue 12, "one lowering,
//! many consumers"). `sim` is [`lower`] then [`crate::exec::execute`]; `codegen<fpga>` is
//! [`lower`] then [`crate::encode`].
//!
//! The program's types live in the IR crate ([`robovec_ir::machine`]) next to
//! [`robovec_ir::placement`], so that the verifier's lowered check
//! ([`robovec_ir::verifier::machine`]) can see them; the lowering lives here because it is the
//! check of every machine-model rule that needs time order (word lifetimes), with `sim`'s
//! diagnostics ([`MachineError`], re-exported by `sim` as `SimError`).
//!
//! # What the lowering checks (in this order)
//! - **Structure** (no time order): sizes, value and PE references, issues of non-ops, missing
//!   issues, loads of non-initial data, writes of non-ops, nested expressions, latencies ≥ 1.
//! - Then **in time order** (the first error is returned): loads (before cycle 0); then each
//!   cycle `c`: results arriving at `c` (at most one per PE: [`MachineErrorKind::ResultCollision`])
//!   enter their producer's buffer at the `buffer_addr` of their indirect writes; the writes of
//!   cycle `c` in `Placement::writes` order — direct writes (the value must arrive at `c`) and
//!   buffer reads (the value must have arrived; one distinct buffer address read per buffer per
//!   cycle, fanning out to any number of memories), each taking one write port of its target
//!   memory; the ops issued at `c` read their operands from the issuing PE's memory.
//! - Every program it returns passes the verifier's lowered check (run always, not only with
//!   debug assertions: it is one tag-level execution of the steps, measured at about the cost
//!   of the lowering itself, see the issue note), else [`MachineErrorKind::Unverified`].
//!
//! # Choices where the machine model is silent
//! - **Read addresses.** A placement does not list them: an op on PE `p` at cycle `c` reads
//!   an operand at the address of the latest load or write of that operand into `p` at a cycle
//!   `≤ c` (loads count as cycle −1; on a tie, the first in placement order). That read counts
//!   as a read of that word when checking address reuse.
//! - **Constants** live in memories like inputs: an operand `2.0` must be loaded into the PE's
//!   memory; constants are matched by their `f64` bits (`0.0` and `-0.0` differ) — the one
//!   memory-word key [`robovec_ir::machine::Held`] of the placer, lowering and verifier.
//! - **Calls** read all their operands in their issue cycle, even more than 2 (a call with
//!   more than 2 operands is the only op that reads more than 2 words per cycle); a call
//!   without operands reads nothing.
//! - **Occupancy.** A word is occupied from its write (loads: before cycle 0) to its last read,
//!   or only in its write cycle when it is never read; a buffer word from arrival to its last
//!   buffer read. Writing an occupied word in a cycle ≤ its last read is an error ("address
//!   reused while its value is still needed"), and so is writing one word twice in one cycle.
//!   An overwrite of a word an op still needs is reported there, at the overwriting write,
//!   not at the later read. [`Occupancy`] holds the peaks of these intervals, so they never
//!   exceed a correct `pe_words`/`buffer_words`.
//! - **Buffer entries.** A value enters its producer's buffer once: all its indirect writes
//!   must name the same `buffer_addr`. Loads are not writes: they take no write port.
//! - **Write ports** are numbered in `Placement::writes` order within a cycle.
//! - **Outputs.** An output that is an op result is captured at its arrival into its
//!   producer's output memory (addresses in `Function::outputs` order, one per value); an
//!   output that is an input, a trig value or a constant is loaded into the output memory of
//!   slot 0 (one word per distinct value). Outputs need not be written into any PE memory.
//! - **`div` and `call`** are lowered (the machine model runs them on ADD PEs, and `sim`
//!   executes them); the FPGA has no unit for them, so [`crate::encode`] — and
//!   with it `codegen<fpga>` — rejects them with a typed error, as it rejects targets whose
//!   words cannot hold the program. The lowering rejects what no machine of the model can do.
//! - **Size.** At most [`MAX_STEPS`] steps (PEs × cycles) are built.
//!
//! # Interrupting it
//! [`lower_measured_until`] (and [`lower_until`]) take a `stop` hook, called once per value,
//! write and cycle in the plan, the steps and the verifier's lowered check: when it returns
//! true the lowering returns [`MachineErrorKind::Stopped`] and no program. `sim` and
//! `codegen<fpga>` pass their `-time-limit` ticker there; [`lower`] never stops.

pub mod fixed;
mod lowering;
mod plan;

use robovec_ir::machine::MachineProgram;
use robovec_ir::placement::Placement;
use robovec_ir::verifier::machine::verify_machine_until;
use robovec_ir::Function;

pub use lowering::{Occupancy, MAX_STEPS};

pub use crate::error::{MachineError, MachineErrorKind, When};

/// Lowers placement `p` of `f` into its machine program, checking every rule of the machine
/// model (see the module doc), then the verifier's lowered check.
///
/// # Errors
/// The first rule the placement breaks, with the cycle, PE, value and, when the placement was
/// read from text, the span of the offending line.
pub fn lower(f: &Function, p: &Placement) -> Result<MachineProgram, MachineError> {
    lower_measured(f, p).map(|(m, _)| m)
}

/// [`lower`], also returning the peak occupancy of every memory.
///
/// # Errors
/// As [`lower`].
pub fn lower_measured(f: &Function, p: &Placement) -> Result<(MachineProgram, Occupancy), MachineError> {
    lower_measured_until(f, p, &|| false)
}

/// [`lower`] that gives up when `stop` returns true (the caller's time limit, `-time-limit`).
///
/// # Errors
/// [`MachineErrorKind::Stopped`] when `stop` returned true, else as [`lower`].
pub fn lower_until(f: &Function, p: &Placement, stop: &dyn Fn() -> bool) -> Result<MachineProgram, MachineError> {
    lower_measured_until(f, p, stop).map(|(m, _)| m)
}

/// [`lower_measured`] that gives up when `stop` returns true (the caller's time limit,
/// `-time-limit`). `stop` is called once per value in each pass of the plan over the
/// function, once per write, once per cycle with events while building the steps, and once
/// per op and per cycle in the verifier's lowered check: a few indirect calls per op, so a
/// hook that reads the clock only every so many calls costs nothing measurable.
///
/// # Errors
/// [`MachineErrorKind::Stopped`] when `stop` returned true (nothing else returns it), else
/// as [`lower`].
pub fn lower_measured_until(
    f: &Function,
    p: &Placement,
    stop: &dyn Fn() -> bool,
) -> Result<(MachineProgram, Occupancy), MachineError> {
    let (mut m, occ) = lowering::lower(f, p, stop)?;
    fixed::attach(f, &mut m)?;
    let errs = verify_machine_until(f, &m, stop).ok_or_else(MachineError::stopped)?;
    if let Some(e) = errs.first() {
        return Err(MachineError::new(
            MachineErrorKind::Unverified,
            format!("the lowered program fails the verifier ({} violations; first: {})", errs.len(), e.message),
        ));
    }
    Ok((m, occ))
}

#[cfg(test)]
mod tests;
