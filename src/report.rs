//! The JSON report (`-report=FILE`, SPEC §7) and the `-eval` output.

use std::collections::BTreeMap;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{interp, Def, Function, OpCounts, Phase};
use robovec_passes::atomise::atomise_function;
use robovec_passes::PassRecord;
use serde::Serialize;

/// `stats` of SPEC §7: the IR at the end of the pipeline.
#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// Equations of the source function (SPEC §1), `null` when unknown.
    pub equations: Option<u32>,
    /// Ops by kind (SPEC §1, §3).
    pub ops: OpCounts,
    /// Initial variables: inputs plus trig variables (SPEC §1).
    pub inputs: u64,
    /// Of which trig initial variables (`sin`/`cos` of a joint coordinate).
    pub trig: u64,
    /// Outputs.
    pub outputs: u64,
    /// Critical path in unit steps (largest ASAP).
    pub asap: u32,
    /// Critical path in cycles (largest ASAPCycle) under `latencies`.
    pub asap_cycle: u32,
    /// Number Y = ops / asap_cycle (seed §3.2); 0 when there is no op.
    pub y: f64,
    /// Latencies used for `asap_cycle`, cycles.
    pub latencies: Latencies,
}

/// Computes the stats of `f`. A parsed-phase function is measured on its atomised form (SPEC
/// §3), so the figures are the same before and after `atomise`.
pub fn stats(f: &Function, lat: &Latencies) -> Stats {
    let atomised;
    let g = if f.phase == Phase::Parsed {
        atomised = atomise_function(f);
        &atomised
    } else {
        f
    };
    let ops = g.op_counts();
    let (_, t) = compute_timing(g, lat);
    let trig = g.body.iter().filter(|&&v| matches!(g.value(v).def, Def::Trig(..))).count() as u64;
    Stats {
        equations: f.equations,
        ops,
        inputs: g.inputs.len() as u64 + trig,
        trig,
        outputs: g.outputs.len() as u64,
        asap: t.asap,
        asap_cycle: t.asap_cycle,
        y: if t.asap_cycle == 0 { 0.0 } else { ops.total as f64 / t.asap_cycle as f64 },
        latencies: *lat,
    }
}

/// `placement` of SPEC §7: figures of the placement on the PE architecture (SPEC §4).
#[derive(Clone, Debug, Serialize)]
pub struct PlacementReport {
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// add/sub latency, cycles.
    pub lat_add: u32,
    /// mul latency, cycles.
    pub lat_mul: u32,
    /// Cycles of the placement (largest arrival).
    pub cycles: u32,
    /// Lower bound LB (SPEC §4), cycles.
    pub lower_bound: u32,
    /// cycles / LB (1 is optimal).
    pub cycles_over_lower_bound: f64,
    /// A tighter lower bound (`place::tight_lower_bound`: per PE type, the exact one-type
    /// relaxation with heads and tails tightened through both types), cycles; extra key.
    pub tight_lower_bound: u32,
    /// ops / (cycles × (n_add + n_mul)) (seed §3.4).
    pub parallelisation_rate: f64,
    /// Words of each PE memory: ADD PEs, then MULTI PEs.
    pub pe_memory_words: Vec<u32>,
    /// Words of each buffer memory, same order.
    pub buffer_words: Vec<u32>,
    /// Results written directly into a PE memory at arrival.
    pub writes_direct: u64,
    /// Results written into a PE memory from a buffer.
    pub writes_indirect: u64,
    /// Occupation rate per cycle of each PE type: issued ops / N, rolling mean over 50 cycles
    /// (seed §3.6).
    pub occupation: Occupation,
}

/// Per-cycle occupation rates (0 to 1), one entry per cycle.
#[derive(Clone, Debug, Serialize)]
pub struct Occupation {
    /// ADD PEs.
    pub add: Vec<f64>,
    /// MULTI PEs.
    pub mul: Vec<f64>,
}

/// The placement figures of `f`, if it is placed.
pub fn placement_report(f: &Function) -> Option<PlacementReport> {
    use robovec_passes::place::{cycles, issues_per_cycle, lower_bound, occupation, tight_lower_bound};
    let p = f.placement.as_ref()?;
    let a = &p.arch;
    let c = cycles(f, p);
    let lb = lower_bound(f, a);
    let (add, mul) = issues_per_cycle(f, p);
    let indirect = p.writes.iter().filter(|w| w.buffer_addr.is_some()).count() as u64;
    let ops = f.op_counts().total as f64;
    Some(PlacementReport {
        n_add: a.n_add,
        n_mul: a.n_mul,
        lat_add: a.lat.add,
        lat_mul: a.lat.mul,
        cycles: c,
        lower_bound: lb,
        cycles_over_lower_bound: if lb == 0 { 1.0 } else { c as f64 / lb as f64 },
        tight_lower_bound: tight_lower_bound(f, a),
        parallelisation_rate: if c == 0 { 0.0 } else { ops / (c as f64 * (a.n_add + a.n_mul) as f64) },
        pe_memory_words: p.pe_words.clone(),
        buffer_words: p.buffer_words.clone(),
        writes_direct: p.writes.len() as u64 - indirect,
        writes_indirect: indirect,
        occupation: Occupation { add: occupation(&add, a.n_add, 50), mul: occupation(&mul, a.n_mul, 50) },
    })
}

/// The report of SPEC §7 (fields not produced by this pipeline are omitted).
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Input path.
    pub input: String,
    /// Function described.
    pub function: String,
    /// Normalised pipeline text.
    pub pipeline: String,
    /// One record per pass run.
    pub passes: Vec<PassRecord>,
    /// Figures of the final IR.
    pub stats: Stats,
    /// Figures of the placement, when the pipeline placed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<PlacementReport>,
    /// Rows of `sweep` runs for this function, when the pipeline swept.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sweep: Vec<robovec_passes::sweep::SweepRow>,
    /// The last `accuracy` measurement of this function, when the pipeline measured (SPEC §7).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub accuracy: Option<robovec_passes::accuracy::AccuracyReport>,
    /// The rows of `-pareto`, when given (speed against error, `crate::pareto`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pareto: Vec<crate::pareto::ParetoRow>,
    /// What the last `sim` run checked (its `functions` restricted to this function), when
    /// the pipeline simulated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim: Option<robovec_passes::sim::SimStats>,
    /// What every `eqsat` run did to this function (windows, stop reasons, time per window),
    /// when the pipeline ran `eqsat`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub eqsat: Vec<robovec_passes::eqsat::EqsatStats>,
    /// Passes that stopped early (`-time-limit` or a work budget reached), one line each, as
    /// printed on stderr after `note: `.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stopped_early: Vec<String>,
}

/// `-eval` output: every input used and every output, in the evaluation precision.
#[derive(Clone, Debug, Serialize)]
pub struct EvalResult {
    /// `f64` or `f32` (`-eval-precision`).
    pub precision: &'static str,
    /// Input name → value used (in `f32`: the binary32 value, printed as a number).
    pub inputs: BTreeMap<String, f64>,
    /// Output name → value (in `f32`: the binary32 result, printed as a number).
    pub outputs: BTreeMap<String, f64>,
    /// User callbacks evaluated with the interpreter's stand-in (absent when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub callback_standins: Vec<String>,
}

/// Evaluates `f` on `given` inputs in binary64, or in binary32 when `single` (inputs rounded
/// to binary32 first, every operation in binary32 in the IR's order, as the FPGA computes);
/// inputs not given get deterministic pseudo-random values in [-1, 1]
/// (`robovec_ir::interp::pseudo_random_input` with seed 0).
pub fn evaluate(f: &Function, given: &BTreeMap<String, f64>, single: bool) -> EvalResult {
    let mut inputs = BTreeMap::new();
    let value = |name: &str| given.get(name).copied().unwrap_or_else(|| interp::pseudo_random_input(name, 0));
    let outputs: BTreeMap<String, f64> = if single {
        interp::eval::<f32>(f, |name| {
            let x = value(name) as f32 as f64;
            inputs.insert(name.to_string(), x);
            x
        })
        .into_iter()
        .map(|(k, v)| (k, v as f64))
        .collect()
    } else {
        interp::eval::<f64>(f, |name| {
            let x = value(name);
            inputs.insert(name.to_string(), x);
            x
        })
        .into_iter()
        .collect()
    };
    EvalResult {
        precision: if single { "f32" } else { "f64" },
        inputs,
        outputs,
        callback_standins: robovec_ir::numerics::Tape::new(f).standin_callees(),
    }
}

/// The `-stats` lines on stderr: each rewriting pass's note, then per function (only
/// `function` when given) its figures (equations, ops by kind, inputs, outputs, critical path in
/// ops and cycles, number Y) and, when placed, its placement's (cycles, lower bound, rate, PE
/// memory and buffer words, direct/indirect writes), then every `eqsat` run's and every `sim`
/// run's line.
pub fn stats_text(module: &robovec_ir::Module, cx: &robovec_passes::PassContext, function: Option<&str>) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for note in &cx.notes {
        let _ = writeln!(out, "{note}");
    }
    for f in module.functions.iter().filter(|f| function.is_none_or(|n| n == f.name)) {
        let s = stats(f, &cx.latencies);
        let _ = writeln!(
            out,
            "@{}: equations {}, ops {} (add {}, sub {}, mul {}, div {}, call {}), inputs {}, outputs {}, \
             critical path {} ops / {} cycles, Y = {:.2}",
            f.name,
            s.equations.map_or("?".to_string(), |e| e.to_string()),
            s.ops.total,
            s.ops.add,
            s.ops.sub,
            s.ops.mul,
            s.ops.div,
            s.ops.call,
            s.inputs,
            s.outputs,
            s.asap,
            s.asap_cycle,
            s.y
        );
        if let Some(p) = placement_report(f) {
            let max = |v: &[u32]| v.iter().copied().max().unwrap_or(0);
            let _ = writeln!(
                out,
                "@{}: placed on {} ADD + {} MULTI PEs: {} cycles, lower bound {} (x{:.3}), parallelisation rate {:.3}, \
                 PE memory up to {} words, buffer up to {} words, writes {} direct / {} indirect",
                f.name,
                p.n_add,
                p.n_mul,
                p.cycles,
                p.lower_bound,
                p.cycles_over_lower_bound,
                p.parallelisation_rate,
                max(&p.pe_memory_words),
                max(&p.buffer_words),
                p.writes_direct,
                p.writes_indirect
            );
        }
    }
    for e in cx.eqsat.iter().filter(|e| function.is_none_or(|n| n == e.function)) {
        let _ = writeln!(out, "{e}");
    }
    for s in &cx.sim {
        let _ = writeln!(out, "{s}");
    }
    out
}
