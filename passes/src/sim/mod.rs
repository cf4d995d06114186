//! `sim<seeds>`: a cycle-accurate simulator of placed functions, and the pass that checks every
//! placement with it against the interpreter, bit for bit, in f32 and f64.
//!
//! The simulator reads only the [`Placement`] (never the placer): it lowers it once into the
//! public machine program ([`robovec_machine::program::lower`], which checks every rule of the machine
//! model of [`robovec_ir::placement`] and keeps the diagnostics below), then executes that
//! program cycle by cycle ([`robovec_machine::exec::execute`]) — the same program `codegen<fpga>`
//! encodes:
//!
//! - **before cycle 0** the initial words: inputs as `T::from_f64(input(name))`, trig initial
//!   variables as `sin`/`cos` of their input computed in `T` (as [`interp`] does), constants as
//!   `T::from_f64(c)`;
//! - **each cycle `c`**, in this order: results arriving at `c` (issued at `c − latency`) enter
//!   their producer's buffer and output memory; buffers are read; PE memories take their
//!   writes (direct from a result arriving now, or indirect from a buffer read now); the ops
//!   issued at `c` read their operands from the issuing PE's memory and enter the pipeline,
//!   computed in `T` by [`interp::eval_binop`] / [`interp::eval_call`];
//! - **at the end** the outputs are read from the output memories.
//!
//! The choices where the machine model is silent (read addresses, constants, calls, word
//! occupancy, buffer entries, outputs, error order) are listed in [`robovec_machine::program`]'s module
//! doc. Errors are [`SimError`] (= [`robovec_machine::program::MachineError`]): the first broken rule,
//! with cycle, PE, value and the span of the offending line when the placement was read from
//! text.
//!
//! [`interp`]: robovec_ir::interp
//! [`interp::eval_binop`]: robovec_ir::interp::eval_binop
//! [`interp::eval_call`]: robovec_ir::interp::eval_call

use std::collections::HashMap;

use robovec_ir::interp::{eval, pseudo_random_input, Float};
use robovec_ir::machine::{MachineOp, MachineProgram};
use robovec_ir::placement::Placement;
use robovec_ir::{Function, Module};

use robovec_machine::exec::execute_until;
use robovec_machine::program::{lower_measured, lower_measured_until, Occupancy};
pub use robovec_machine::program::{MachineError as SimError, MachineErrorKind as SimErrorKind, When};

use crate::params::ParamKind;
use crate::{
    try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker,
};

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
    /// Placements (one per function) simulated: those whose first seed completed
    /// (`-time-limit` may stop `sim` before a function's, or before a function).
    pub placements: usize,
    /// Input sets (seeds `0..seeds`), each simulated in every precision: the number asked, or
    /// the fewest simulated for one placement when `-time-limit` stopped `sim` between seeds;
    /// 0 when no placement was simulated.
    pub seeds: u32,
    /// Precisions simulated and compared with the interpreter.
    pub precisions: Vec<&'static str>,
    /// True: every output equalled the interpreter's bit for bit (a mismatch fails the pass).
    pub bit_exact: bool,
    /// One entry per function simulated (none for a function `-time-limit` left unsimulated).
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
    /// `sim: simulated N placements bit-exact in f32 and f64 (S seeds)`, or `sim: simulated
    /// no placement` (`-time-limit` stopped it before any first seed completed).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let plural = |n: usize, w: &str| if n == 1 { format!("{n} {w}") } else { format!("{n} {w}s") };
        if self.placements == 0 {
            return write!(f, "sim: simulated no placement");
        }
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
    let (m, occ) = lower_measured(f, p)?;
    run(f, &m, &occ, input, &Ticker::default())
}

/// Executes lowered program `m` of `f` on `input` (called once per input, in `f.inputs`
/// order) and gathers the figures; one tick of `ticker` per cycle.
fn run<T: Float>(
    f: &Function,
    m: &MachineProgram,
    occ: &Occupancy,
    mut input: impl FnMut(&str) -> f64,
    ticker: &Ticker,
) -> Result<SimOutcome<T>, SimError> {
    let values: HashMap<&str, f64> = f.inputs.iter().map(|&v| (f.name_of(v), input(f.name_of(v)))).collect();
    let x = execute_until::<T>(m, |n| values.get(n).copied().unwrap_or(f64::NAN), &|| ticker.tick())?;
    Ok(statistics(m, occ, x.outputs))
}

/// The machine figures of program `m` with the outputs an execution computed.
fn statistics<T>(m: &MachineProgram, occ: &Occupancy, outputs: Vec<(String, T)>) -> SimOutcome<T> {
    let mut issued_add = vec![0u32; m.cycles as usize];
    let mut issued_mul = vec![0u32; m.cycles as usize];
    for q in &m.pes {
        for (c, st) in q.steps.iter().enumerate() {
            match &st.issue {
                Some(i) if matches!(i.op, MachineOp::Mul) => issued_mul[c] += 1,
                Some(_) => issued_add[c] += 1,
                None => {}
            }
        }
    }
    SimOutcome {
        outputs,
        cycles: m.cycles,
        writes_direct: m.writes_direct(),
        writes_indirect: m.writes_indirect(),
        max_words_per_memory: occ.max_words_per_memory.clone(),
        max_buffer_words: occ.max_buffer_words.clone(),
        issued_per_cycle_add: issued_add,
        issued_per_cycle_mul: issued_mul,
    }
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
    verify_until(f, p, seeds, &Ticker::default())
}

/// [`verify_with`] that stops when `ticker` says so (`-time-limit`, issue 28): it ticks once
/// per value, write and cycle of the lowering ([`lower_measured_until`]) and per cycle of each
/// simulated run, and reads the clock ([`Ticker::check`]) before each of a seed's steps (f64
/// run, f64 interpreter, f32 run, f32 interpreter). A stop after the first seed completed
/// drops the seed in progress: the report's `seeds` are those simulated.
///
/// # Errors
/// As [`verify_placement`]; [`SimErrorKind::Stopped`] when `ticker` stopped the lowering or
/// the first seed (nothing was checked).
pub fn verify_until(f: &Function, p: &Placement, seeds: &[u64], ticker: &Ticker) -> Result<SimReport, SimError> {
    verify_in(f, p, seeds, None, ticker)
}

/// [`verify_until`] with the input domain a function on fixed-point PEs draws its inputs in
/// (issue 49; binary32 PEs ignore it).
///
/// # Errors
/// As [`verify_until`]; for a function on fixed-point PEs without `domain`, [`SimErrorKind::Formats`].
pub fn verify_in(
    f: &Function,
    p: &Placement,
    seeds: &[u64],
    domain: Option<&robovec_ir::domain::Domain>,
    ticker: &Ticker,
) -> Result<SimReport, SimError> {
    let (m, occ) = lower_measured_until(f, p, &|| ticker.tick())?;
    verify_lowered(f, &m, &occ, seeds, domain, ticker)
}

/// The inputs of seed `seed` for a function on fixed-point PEs: a point of the input domain
/// (`error_bound::domain_point`: the corners for seeds 0 and 1, then ends and uniform draws),
/// where the range proof excludes every overflow.
///
/// # Errors
/// [`SimErrorKind::Formats`] without a domain, or with an input the domain does not cover.
fn fixed_inputs(
    f: &Function,
    seed: u64,
    domain: Option<&robovec_ir::domain::Domain>,
) -> Result<HashMap<String, f64>, SimError> {
    let dom = domain.ok_or_else(|| {
        SimError::new(
            SimErrorKind::Formats,
            format!("@{} runs on fixed-point PEs: sim draws its inputs in the input domain (-ranges=FILE, or a URDF's limits), which this run does not have", f.name),
        )
    })?;
    let mut ranges = Vec::with_capacity(f.inputs.len());
    for &v in &f.inputs {
        let r = dom.get(f.name_of(v)).ok_or_else(|| {
            SimError::new(SimErrorKind::Formats, format!("input `{}` has no range in the domain", f.name_of(v)))
        })?;
        ranges.push(r.interval);
    }
    let mut rng = robovec_ir::rng::SplitMix64::new(0x5eed ^ seed);
    let xs = crate::error_bound::domain_point(&ranges, seed, &mut rng);
    Ok(f.inputs.iter().zip(xs).map(|(&v, x)| (f.name_of(v).to_string(), x)).collect())
}

/// One seed of a function on fixed-point PEs: the machine's integers against `-eval`'s
/// formatted evaluation ([`robovec_ir::format::eval_values`]), bit for bit.
fn compare_fixed(
    f: &Function,
    m: &MachineProgram,
    occ: &Occupancy,
    seed: u64,
    domain: Option<&robovec_ir::domain::Domain>,
    ticker: &Ticker,
) -> Result<SimOutcome<f64>, SimError> {
    if ticker.check() {
        return Err(SimError::stopped().at(When::Load));
    }
    let xs = fixed_inputs(f, seed, domain)?;
    let input = |n: &str| xs.get(n).copied().unwrap_or(f64::NAN);
    let x = robovec_machine::exec::execute_fixed_until(m, input, &|| ticker.tick())?;
    let reference = robovec_ir::format::eval_values(f, input).map_err(|e| {
        SimError::new(SimErrorKind::Formats, format!("-eval stops on a fixed-point overflow at seed {seed}: {e:?}"))
    })?;
    for ((name, s), o) in x.outputs.iter().zip(&f.outputs) {
        let e = match o.value {
            robovec_ir::Operand::Value(v) => reference[v.index()],
            robovec_ir::Operand::Const(c) => c,
        };
        if s.to_bits() != e.to_bits() {
            return Err(mismatch(name, *s, e, &format!("fixed point, seed {seed}"), o.span));
        }
    }
    Ok(statistics(m, occ, x.outputs))
}

/// The seeds of [`verify_until`] on `f`'s lowered program `m` (occupancy `occ`).
///
/// # Errors
/// As [`verify_until`], the lowering apart.
fn verify_lowered(
    f: &Function,
    m: &MachineProgram,
    occ: &Occupancy,
    seeds: &[u64],
    domain: Option<&robovec_ir::domain::Domain>,
    ticker: &Ticker,
) -> Result<SimReport, SimError> {
    let seeds: &[u64] = if seeds.is_empty() { &[0] } else { seeds };
    let mut report: Option<SimReport> = None;
    for (i, &seed) in seeds.iter().enumerate() {
        let both = match m.fixed {
            Some(_) => compare_fixed(f, m, occ, seed, domain, ticker),
            None => compare::<f64>(f, m, occ, seed, "f64", ticker)
                .and_then(|o| compare::<f32>(f, m, occ, seed, "f32", ticker).map(|_| o)),
        };
        let o = match both {
            Ok(o) => o,
            Err(e) if e.kind == SimErrorKind::Stopped && i > 0 => {
                if let Some(r) = report.as_mut() {
                    r.seeds.truncate(i);
                }
                break;
            }
            Err(e) => return Err(e),
        };
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

fn compare<T: Float>(
    f: &Function,
    m: &MachineProgram,
    occ: &Occupancy,
    seed: u64,
    precision: &str,
    ticker: &Ticker,
) -> Result<SimOutcome<T>, SimError> {
    if ticker.check() {
        return Err(SimError::stopped().at(When::Load));
    }
    let input = |n: &str| pseudo_random_input(n, seed);
    let sim = run::<T>(f, m, occ, input, ticker)?;
    if ticker.check() {
        return Err(SimError::stopped().at(When::End));
    }
    let reference = eval::<T>(f, input);
    for (((name, s), (_, e)), o) in sim.outputs.iter().zip(&reference).zip(&f.outputs) {
        let (s, e) = (s.to_f64(), e.to_f64());
        if s.to_bits() != e.to_bits() && !(s.is_nan() && e.is_nan()) {
            return Err(mismatch(name, s, e, &format!("{precision}, seed {seed}"), o.span));
        }
    }
    Ok(sim)
}

/// Output `name` simulated as `s` where the interpreter gives `e` (`what`: the precision and
/// seed), located at the output's line.
fn mismatch(name: &str, s: f64, e: f64, what: &str, span: robovec_ir::Span) -> SimError {
    SimError::new(SimErrorKind::Mismatch, format!("simulated {s:?} but the interpreter gives {e:?} ({what})"))
        .at(When::End)
        .of(format!("output `{name}`"))
        .src(span)
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "sim",
    doc: "simulate each placement cycle by cycle and check its outputs against the interpreter (f32 and f64; fixed-point PEs: their integers at points of the input domain)",
    params: &[ParamInfo {
        name: "seeds",
        kind: ParamKind::U32 { default: 3, min: 1, max: 10_000 },
        doc: "number of pseudo-random input sets (seeds 0..n), each simulated in f32 and f64",
    }],
    build: |p: &Params| Ok(Box::new(Sim { seeds: p.u32("seeds")? })),
    props: crate::Props {
        at_time_limit: crate::AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        formats: true,
        needs_before: Some("place"),
        ..crate::Props::DEFAULT
    },
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

    /// `-time-limit` stops `sim` wherever it is (the lowering, a simulated run, between the
    /// steps of a seed: [`verify_until`]), with a note. A function stopped after its first
    /// seed completed keeps the seeds simulated; one stopped before is not simulated (not
    /// counted, no figures); no further function starts. The stats then give the placements
    /// simulated and the fewest seeds simulated.
    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let seeds: Vec<u64> = (0..self.seeds as u64).collect();
        let fail = |message: String| PassError::Failed { pass: "sim".into(), message };
        if let Some(f) = m.functions.iter().find(|f| f.placement.is_none()) {
            return Err(fail(format!("function @{} has no placement; run `place` first", f.name)));
        }
        let before = |f: &Function, _| Some(format!("before @{}", f.name));
        let domain = cx.domain.clone();
        // binary32 PEs (simulated in f32 and f64), fixed-point PEs
        let mut kinds = [false, false];
        let simulated = try_each_function(m, cx, "sim", AtTimeLimit::Skip, Before::Clock, before, |f, _, ticker| {
            let fail_on = |e: SimError| fail(format!("@{}: {e}", f.name)).at(e.span);
            let p = f.placement.as_ref().expect("every function is placed (checked above)");
            let not_simulated = |stage: &str| Step::Stopped {
                what: format!("in @{0} before its first seed completed ({stage}; @{0} not simulated)", f.name),
                kept: None,
            };
            let (mach, occ) = match lower_measured_until(f, p, &|| ticker.tick()) {
                Ok(x) => x,
                Err(e) if e.kind == SimErrorKind::Stopped => return Ok(not_simulated("lowering")),
                Err(e) => return Err(fail_on(e)),
            };
            kinds[usize::from(mach.fixed.is_some())] = true;
            let r = match verify_lowered(f, &mach, &occ, &seeds, domain.as_ref(), ticker) {
                Ok(r) => r,
                Err(e) if e.kind == SimErrorKind::Stopped => return Ok(not_simulated("seed 0")),
                Err(e) => return Err(fail_on(e)),
            };
            let stats = SimFunctionStats {
                function: f.name.clone(),
                cycles: r.cycles,
                outputs: r.outputs,
                writes_direct: r.writes_direct,
                writes_indirect: r.writes_indirect,
            };
            let n = r.seeds.len() as u32;
            Ok(match r.seeds.len() < seeds.len() {
                true => Step::Stopped {
                    what: format!("after {} of {} seeds of @{}", r.seeds.len(), seeds.len(), f.name),
                    kept: Some((stats, n)),
                },
                false => Step::Done((stats, n)),
            })
        })?;
        let fewest = simulated.iter().map(|(_, n)| *n).min().unwrap_or(self.seeds);
        let functions: Vec<SimFunctionStats> = simulated.into_iter().map(|(s, _)| s).collect();
        cx.emit(SimStats {
            placements: functions.len(),
            seeds: if functions.is_empty() { 0 } else { fewest },
            precisions: match kinds {
                [_, false] => vec!["f32", "f64"],
                [false, true] => vec!["fixed point"],
                [true, true] => vec!["f32", "f64", "fixed point"],
            },
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

    /// The `sim` object of `function`'s report; none when `function` was not simulated
    /// (`-time-limit`: the note in `stopped_early` says why).
    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let mut s = self.clone();
        s.functions.retain(|x| x.function == function);
        if s.functions.is_empty() {
            return None;
        }
        Some(crate::ReportEntry::new("sim", &s, crate::Merge::Last))
    }
}

#[cfg(test)]
mod machine_tests;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod agree;
