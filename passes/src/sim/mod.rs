//! `sim<seeds>`: a cycle-accurate simulator of placed functions, and the pass that checks every
//! placement with it against the interpreter, bit for bit, in f32 and f64.
//!
//! The simulator reads only the [`Placement`] (never the placer) and enforces the machine model
//! of [`robovec_ir::placement`]. From the placement it derives each PE's instruction stream
//! (which op issues when, reading which addresses of its memory), each PE memory's writes and
//! each buffer's entries and reads, then runs:
//!
//! - **before cycle 0** the loads: inputs as `T::from_f64(input(name))`, trig initial variables
//!   as `sin`/`cos` of their input computed in `T` (as [`interp`] does), constants as
//!   `T::from_f64(c)`;
//! - **each cycle `c`**, in this order:
//!   1. results arriving at `c` (issued at `c − latency`) enter their producer's buffer at the
//!      `buffer_addr` of their indirect writes (one entry per value);
//!   2. the writes of cycle `c`, in `Placement::writes` order: direct writes (the value must
//!      arrive at `c`) and buffer reads (the value must have arrived; one distinct buffer
//!      address read per buffer per cycle, fanning out to any number of memories), each taking
//!      one write port of its target memory;
//!   3. the ops issued at `c` read their operands from the issuing PE's memory and enter the
//!      pipeline, computed in `T` by [`interp::eval_binop`] / [`interp::eval_call`].
//!
//! # Choices where the machine model is silent
//! - **Read addresses.** A placement does not list them: an op on PE `p` at cycle `c` reads
//!   an operand at the address of the latest load or write of that operand into `p` at a cycle
//!   `≤ c` (loads count as cycle −1; on a tie, the first in placement order). That read counts
//!   as a read of that word when checking address reuse.
//! - **Constants** live in memories like inputs: an operand `2.0` must be loaded into the PE's
//!   memory; constants are matched by their `f64` bits (`0.0` and `-0.0` differ).
//! - **Calls** read all their operands in their issue cycle, even more than 2 (a call with
//!   more than 2 operands is the only op that reads more than 2 words per cycle); a call
//!   without operands reads nothing.
//! - **Occupancy.** A word is occupied from its write (loads: before cycle 0) to its last read,
//!   or only in its write cycle when it is never read; a buffer word from arrival to its last
//!   buffer read. Writing an occupied word in a cycle ≤ its last read is an error ("address
//!   reused while its value is still needed"), and so is writing one word twice in one cycle.
//!   An overwrite of a word an op still needs is reported there, at the overwriting write,
//!   not at the later read. `max_words_per_memory`/`max_buffer_words` are the peaks of these
//!   intervals, so they never exceed a correct `pe_words`/`buffer_words`.
//! - **Buffer entries.** A value enters its producer's buffer once: all its indirect writes
//!   must name the same `buffer_addr`. Loads are not writes: they take no write port.
//! - **Outputs** are taken from the pipeline (an op output must have been issued; an input or
//!   trig output is its initial value); they need not be written into any memory.
//! - **Errors.** Structural errors (sizes, unknown PEs or values, missing issues, issues or
//!   writes of non-ops, loads of op results, a value in two buffer addresses) come first;
//!   all other errors are found in time order and the first one is returned.
//!
//! [`interp`]: robovec_ir::interp
//! [`interp::eval_binop`]: robovec_ir::interp::eval_binop
//! [`interp::eval_call`]: robovec_ir::interp::eval_call

mod error;
mod machine;
mod plan;

use robovec_ir::interp::{eval, pseudo_random_input, Float};
use robovec_ir::placement::Placement;
use robovec_ir::{Function, Module};

pub use error::{SimError, SimErrorKind, When};

use crate::params::ParamKind;
use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};

/// What one simulated run computed and measured.
#[derive(Clone, Debug, PartialEq)]
pub struct SimOutcome<T> {
    /// Outputs in `f.outputs` order, computed in precision `T`.
    pub outputs: Vec<(String, T)>,
    /// Largest arrival cycle (0 without ops).
    pub cycles: u32,
    /// Direct writes performed.
    pub writes_direct: u32,
    /// Indirect writes (buffer reads into a PE memory) performed.
    pub writes_indirect: u32,
    /// Largest number of words each PE memory held at once, indexed by `Pe::slot`.
    pub max_words_per_memory: Vec<u32>,
    /// Largest number of words each buffer held at once, indexed by `Pe::slot`.
    pub max_buffer_words: Vec<u32>,
    /// Ops issued on ADD PEs in each cycle `0..cycles`.
    pub issued_per_cycle_add: Vec<u32>,
    /// Ops issued on MULTI PEs in each cycle `0..cycles`.
    pub issued_per_cycle_mul: Vec<u32>,
}

/// The result of [`verify_placement`]: the machine figures (identical in every run) and what
/// was compared.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SimReport {
    /// Largest arrival cycle.
    pub cycles: u32,
    /// Direct writes.
    pub writes_direct: u32,
    /// Indirect writes.
    pub writes_indirect: u32,
    /// Peak words per PE memory, indexed by `Pe::slot`.
    pub max_words_per_memory: Vec<u32>,
    /// Peak words per buffer, indexed by `Pe::slot`.
    pub max_buffer_words: Vec<u32>,
    /// ADD-PE issues per cycle.
    pub issued_per_cycle_add: Vec<u32>,
    /// MULTI-PE issues per cycle.
    pub issued_per_cycle_mul: Vec<u32>,
    /// Seeds of the pseudo-random inputs, each simulated in f32 and f64.
    pub seeds: Vec<u64>,
    /// Outputs compared per run.
    pub outputs: usize,
}

/// What one run of the `sim` pass checked: printed by `-stats` and written as the report's
/// `sim` object (issue 10 item 5).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SimStats {
    /// Placements (one per function) simulated.
    pub placements: usize,
    /// Input sets (seeds `0..seeds`), each simulated in every precision.
    pub seeds: u32,
    /// Precisions simulated and compared with the interpreter.
    pub precisions: Vec<&'static str>,
    /// True: every output equalled the interpreter's bit for bit (a mismatch fails the pass).
    pub bit_exact: bool,
    /// One entry per function simulated.
    pub functions: Vec<SimFunctionStats>,
}

/// The machine figures `sim` measured on one function's placement.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SimFunctionStats {
    /// Function name.
    pub function: String,
    /// Largest arrival cycle, cycles.
    pub cycles: u32,
    /// Outputs compared per run.
    pub outputs: usize,
    /// Direct writes.
    pub writes_direct: u32,
    /// Indirect writes.
    pub writes_indirect: u32,
}

impl std::fmt::Display for SimStats {
    /// `sim: simulated N placements bit-exact in f32 and f64 (S seeds)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plural = |n: usize, w: &str| if n == 1 { format!("{n} {w}") } else { format!("{n} {w}s") };
        write!(
            f,
            "sim: simulated {} {} in {} ({})",
            plural(self.placements, "placement"),
            if self.bit_exact { "bit-exact" } else { "with mismatches" },
            self.precisions.join(" and "),
            plural(self.seeds as usize, "seed")
        )
    }
}

/// Simulates placement `p` of `f` cycle by cycle in precision `T`; `input(name)` gives each
/// input's value (called once per input, in `f.inputs` order).
///
/// # Errors
/// The first rule of the machine model the placement breaks (see the module doc).
pub fn simulate<T: Float>(
    f: &Function,
    p: &Placement,
    input: impl FnMut(&str) -> f64,
) -> Result<SimOutcome<T>, SimError> {
    machine::run(f, p, input)
}

/// Simulates `f.placement` in f64 and f32 on `interp::pseudo_random_input(name, seed)` for each
/// seed (seed 0 when `seeds` is empty) and requires every output to equal `interp::eval` bit
/// for bit (two NaNs count as equal).
///
/// # Errors
/// [`SimErrorKind::NoPlacement`], any simulation error, or [`SimErrorKind::Mismatch`] naming
/// the first differing output.
pub fn verify_placement(f: &Function, seeds: &[u64]) -> Result<SimReport, SimError> {
    let p = f.placement.as_ref().ok_or_else(|| {
        SimError::new(SimErrorKind::NoPlacement, format!("function @{} has no placement; run `place` first", f.name))
    })?;
    verify_with(f, p, seeds)
}

/// [`verify_placement`] with an explicit placement.
///
/// # Errors
/// As [`verify_placement`].
pub fn verify_with(f: &Function, p: &Placement, seeds: &[u64]) -> Result<SimReport, SimError> {
    let seeds: &[u64] = if seeds.is_empty() { &[0] } else { seeds };
    let mut report = None;
    for &seed in seeds {
        let o = compare::<f64>(f, p, seed, "f64")?;
        compare::<f32>(f, p, seed, "f32")?;
        report.get_or_insert(SimReport {
            cycles: o.cycles,
            writes_direct: o.writes_direct,
            writes_indirect: o.writes_indirect,
            max_words_per_memory: o.max_words_per_memory,
            max_buffer_words: o.max_buffer_words,
            issued_per_cycle_add: o.issued_per_cycle_add,
            issued_per_cycle_mul: o.issued_per_cycle_mul,
            seeds: seeds.to_vec(),
            outputs: o.outputs.len(),
        });
    }
    Ok(report.expect("at least one seed"))
}

fn compare<T: Float>(f: &Function, p: &Placement, seed: u64, precision: &str) -> Result<SimOutcome<T>, SimError> {
    let input = |n: &str| pseudo_random_input(n, seed);
    let sim = simulate::<T>(f, p, input)?;
    let reference = eval::<T>(f, input);
    for (((name, s), (_, e)), o) in sim.outputs.iter().zip(&reference).zip(&f.outputs) {
        let (s, e) = (s.to_f64(), e.to_f64());
        if s.to_bits() != e.to_bits() && !(s.is_nan() && e.is_nan()) {
            return Err(SimError::new(
                SimErrorKind::Mismatch,
                format!("simulated {s:?} but the interpreter gives {e:?} ({precision}, seed {seed})"),
            )
            .at(When::End)
            .of(format!("output `{name}`"))
            .src(o.span));
        }
    }
    Ok(sim)
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "sim",
    doc: "simulate each placement cycle by cycle and check its outputs against the interpreter (f32 and f64)",
    params: &[ParamInfo {
        name: "seeds",
        kind: ParamKind::U32 { default: 3, min: 1, max: 10_000 },
        doc: "number of pseudo-random input sets (seeds 0..n), each simulated in f32 and f64",
    }],
    build: |p: &Params| Ok(Box::new(Sim { seeds: p.u32("seeds")? })),
};

/// The `sim` pass: checks, never changes, the module.
#[derive(Debug)]
pub struct Sim {
    /// Number of input sets (seeds `0..seeds`).
    pub seeds: u32,
}

impl Pass for Sim {
    fn name(&self) -> &'static str {
        "sim"
    }

    fn preserves_timing(&self) -> bool {
        true
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let seeds: Vec<u64> = (0..self.seeds as u64).collect();
        let mut functions = Vec::new();
        for f in &m.functions {
            let fail = |message: String| PassError::Failed { pass: "sim".into(), message };
            let p = f
                .placement
                .as_ref()
                .ok_or_else(|| fail(format!("function @{} has no placement; run `place` first", f.name)))?;
            let r = verify_with(f, p, &seeds).map_err(|e| fail(format!("@{}: {e}", f.name)).at(e.span))?;
            functions.push(SimFunctionStats {
                function: f.name.clone(),
                cycles: r.cycles,
                outputs: r.outputs,
                writes_direct: r.writes_direct,
                writes_indirect: r.writes_indirect,
            });
        }
        cx.emit(SimStats {
            placements: functions.len(),
            seeds: self.seeds,
            precisions: vec!["f32", "f64"],
            bit_exact: true,
            functions,
        });
        Ok(())
    }
}

impl crate::Artifact for SimStats {
    fn pass(&self) -> &'static str {
        "sim"
    }

    fn stats_text(&self, _function: Option<&str>) -> String {
        format!("{self}\n")
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let mut s = self.clone();
        s.functions.retain(|x| x.function == function);
        Some(crate::ReportEntry::new("sim", &s, crate::Merge::Last))
    }
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod agree;
