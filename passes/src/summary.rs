//! The summary of the IR at the end of a pipeline, in numbers: the report's `stats` and
//! `placement` (SPEC §7) and the `-stats` lines, with what the run's artifacts add to them.
//! (The pictures of `-report-dir` are drawn from the report by `robovec`'s `report_dir`.)

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{Def, Function, Module, OpCounts, Phase};
use serde::Serialize;

use crate::atomise::atomise_function;
use crate::place::report::{placement_report, PlacementReport};
use crate::PassContext;

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
    /// Where `latencies` come from: `target de10-nano` (the `-target`), or the pass that gave
    /// them last (`asap-alap<lat-add=6;lat-mul=4>`); extra key. `None` outside a run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latencies_from: Option<String>,
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
        latencies_from: None,
    }
}

/// The figures of one function at the end of the pipeline — its `stats` and, when placed, its
/// `placement` (SPEC §7) — computed once and read by both the report and `-stats`.
#[derive(Clone, Debug)]
pub struct Figures {
    /// The function's name.
    pub function: String,
    /// Its `stats`.
    pub stats: Stats,
    /// Its `placement` figures, when it is placed.
    pub placement: Option<PlacementReport>,
}

impl Figures {
    /// The figures of `f` under the run's latencies (a function on fixed-point PEs: the
    /// target's `fix_pe` latencies, [`crate::function_latencies`]).
    pub fn of(f: &Function, cx: &PassContext) -> Figures {
        let lat = crate::function_latencies(&cx.target, f, cx.latencies, &crate::LatencyOverride::default());
        let from = match lat == cx.latencies {
            true => cx.latencies_source(),
            false => format!("target {} fixed-point PEs", cx.target.name),
        };
        let stats = Stats { latencies_from: Some(from), ..stats(f, &lat) };
        Figures { function: f.name.clone(), stats, placement: placement_report(f, &cx.target) }
    }

    /// The report entries (SPEC §7) that describe the function itself: `stats`, and
    /// `placement` when it is placed.
    pub fn report_entries(&self) -> Vec<(&'static str, serde_json::Value)> {
        let mut out = vec![("stats", serde_json::to_value(&self.stats).expect("stats serialise"))];
        if let Some(p) = &self.placement {
            out.push(("placement", serde_json::to_value(p).expect("placement figures serialise")));
        }
        out
    }
}

/// The figures of every function of `module` (only `function` when given), in module order.
pub fn figures(module: &Module, cx: &PassContext, function: Option<&str>) -> Vec<Figures> {
    module.functions.iter().filter(|f| function.is_none_or(|n| n == f.name)).map(|f| Figures::of(f, cx)).collect()
}

/// What `-stats` says of a placement's time per state after its latency: nothing for one
/// state, ` (4 states: 273 ns per state)` for several (issue 49 item 3).
pub fn per_state(states: u32, ns_per_state: f64) -> String {
    if states > 1 {
        format!(" ({states} states: {ns_per_state:.0} ns per state)")
    } else {
        String::new()
    }
}

/// The `-stats` lines on stderr: each rewriting pass's note, then per function of `figures`
/// (see [`figures`]; artifacts' lines are restricted to `function` when given) its figures (equations, ops by kind, inputs, outputs, critical path in
/// ops and cycles, number Y) and, when placed, its placement's (cycles, lower bound, rate, PE
/// memory and buffer words, direct/indirect writes), then every `eqsat` run's and every `sim`
/// run's line (each artifact's [`crate::Artifact::stats_text`]).
pub fn stats_text(figures: &[Figures], cx: &PassContext, function: Option<&str>) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for note in cx.lines(crate::Severity::Remark) {
        let _ = writeln!(out, "{note}");
    }
    for g in figures {
        let s = &g.stats;
        let _ = writeln!(
            out,
            "@{}: equations {}, ops {} (add {}, sub {}, mul {}, div {}, call {}), inputs {}, outputs {}, \
             critical path {} ops / {} cycles, Y = {:.2} (latencies add {}, mul {}: {})",
            g.function,
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
            s.y,
            s.latencies.add,
            s.latencies.mul,
            s.latencies_from.as_deref().unwrap_or("given")
        );
        if let Some(p) = &g.placement {
            let max = |v: &[u32]| v.iter().copied().max().unwrap_or(0);
            let _ = writeln!(
                out,
                "@{}: placed on {} ADD + {} MULTI PEs: {} cycles, lower bound {} (x{:.3}), parallelisation rate {:.3}, \
                 PE memory up to {} words, buffer up to {} words, writes {} direct / {} indirect; \
                 {:.3} µs at {} MHz{} (latencies add {}, mul {})",
                g.function,
                p.n_add,
                p.n_mul,
                p.cycles,
                p.lower_bound,
                p.cycles_over_lower_bound,
                p.parallelisation_rate,
                max(&p.pe_memory_words),
                max(&p.buffer_words),
                p.writes_direct,
                p.writes_indirect,
                p.us,
                p.clock_mhz,
                per_state(p.states, p.ns_per_state),
                p.lat_add,
                p.lat_mul
            );
        }
    }
    for a in cx.artifacts() {
        out += &a.stats_text(function);
    }
    out
}
