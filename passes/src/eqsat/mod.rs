//! `eqsat<window;budget;iters;nodes;time-ms;distribute;rules;lat-add;lat-mul>`: equality
//! saturation (egg) over bounded windows of associative clusters, extracted by ready time
//! (SPEC §6 "equality saturation", seed §2.4; Willsey et al., "egg: Fast and Extensible
//! Equality Saturation", POPL 2021).
//!
//! Phase: atomised → atomised. Input and output verify; outputs keep their names and values
//! up to rounding (every rewrite but commutation and sign moves changes rounding, SPEC §6).
//!
//! Algorithm, per function:
//! 1. [`window::find_windows`]: trees of single-use `add`/`sub`/`mul` ops (one associative
//!    cluster or a few connected ones), cut into windows of at most `window` leaf occurrences.
//! 2. In body order (topological), keep every value's ready time (ASAPCycle, cycles, SPEC §4)
//!    of the IR *as rewritten so far*, so leaf ready times are exact. At a window's root: put
//!    the window's term in an e-graph, run egg's [`egg::Runner`] with the built-in
//!    [`rules::rules`] (plus `rules=FILE`) under the `iters`/`nodes`/`time-ms` limits, then
//!    extract by ready time ([`extract`]): lexicographic (ready, ops) with egg's extractor,
//!    or, when that needs more than `ops + budget` ops, the best term within the budget.
//! 3. Replace the window only when the extracted term is ready no later than the original
//!    (with the same leaf times), within the op budget, and strictly better in ready time or in
//!    ops. A leftover `neg` is SPEC §3's `0 - x` and counts as an op.
//!
//! Contracts: never lengthens the critical path (each root is ready no later, by induction in
//! topological order); never adds more than `budget` ops per window; idempotent up to the
//! e-graph limits. Cost: per window, bounded by the runner limits (`nodes` e-nodes, `time-ms`);
//! per function, bounded by the work budget [`WORK_ENODES`] (the e-nodes of all windows
//! together) and by `-time-limit` ([`crate::PassContext::deadline`]). When either stops the
//! run, the windows not yet tried keep their form (the IR stays valid), the stats say
//! `stopped after K of N windows: …` and the pass adds a note to the context.

pub mod extract;
pub mod lang;
pub mod rules;
pub mod rules_file;
pub mod window;

mod apply;
#[cfg(test)]
mod tests;

use std::path::PathBuf;

use robovec_ir::analysis::Latencies;
use robovec_ir::{Module, Phase};

use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};

pub use apply::{eqsat_function, eqsat_function_within, EqsatStats, StopCounts, MIN_WINDOW_WORK, WORK_ENODES};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "eqsat",
    doc: "egg equality saturation over bounded windows of +/-/* clusters, extracted by ready time",
    params: &[
        ParamInfo {
            name: "window",
            default: "8",
            doc: "max leaf occurrences per window, leaves (2..=64; ops ≤ window − 1)",
        },
        ParamInfo {
            name: "budget",
            default: "0",
            doc: "max extra ops per window, ops (0: never more ops than the window had)",
        },
        ParamInfo { name: "iters", default: "30", doc: "egg runner iteration limit per window, iterations" },
        ParamInfo { name: "nodes", default: "10000", doc: "egg runner e-node limit per window, e-nodes" },
        ParamInfo { name: "time-ms", default: "100", doc: "egg runner time limit per window, milliseconds" },
        ParamInfo { name: "distribute", default: "on", doc: "distributivity/factoring rules: on or off" },
        ParamInfo { name: "rules", default: "none", doc: "file of extra rules (docs/eqsat-rules.md)" },
        ParamInfo { name: "lat-add", default: "12", doc: "add/sub latency for extraction, cycles" },
        ParamInfo { name: "lat-mul", default: "7", doc: "mul latency for extraction, cycles" },
    ],
    build: |p: &Params| {
        let distribute = match p.get("distribute") {
            None | Some("on" | "true" | "1") => true,
            Some("off" | "false" | "0") => false,
            Some(v) => {
                return Err(PassError::BadParameter {
                    pass: "eqsat".into(),
                    message: format!("parameter `distribute` must be `on` or `off`, found `{v}`"),
                })
            }
        };
        Ok(Box::new(Eqsat {
            opts: EqsatOptions {
                window: p.u32_in("window", 6, 2, 64)? as usize,
                budget: p.u32_in("budget", 0, 0, 10_000)?,
                iters: p.u32_in("iters", 30, 1, 10_000)? as usize,
                nodes: p.u32_in("nodes", 10_000, 10, 10_000_000)? as usize,
                time_ms: p.u32_in("time-ms", 100, 1, 600_000)? as u64,
                distribute,
                rules_file: p.get("rules").map(PathBuf::from),
                lat: p.latencies()?,
                work_enodes: WORK_ENODES,
            },
        }))
    },
};

/// Options of the `eqsat` pass (see [`INFO`] for the parameters they come from).
#[derive(Clone, Debug)]
pub struct EqsatOptions {
    /// Max leaf occurrences per window, leaves (≥ 2).
    pub window: usize,
    /// Max extra ops per window, ops.
    pub budget: u32,
    /// Runner iteration limit per window.
    pub iters: usize,
    /// Runner e-node limit per window, e-nodes.
    pub nodes: usize,
    /// Runner time limit per window, milliseconds.
    pub time_ms: u64,
    /// Whether the distributivity/factoring rules are on.
    pub distribute: bool,
    /// Extra rules file (`rules=FILE`).
    pub rules_file: Option<PathBuf>,
    /// Latencies for extraction (cycles); `add` and `mul` are used.
    pub lat: Latencies,
    /// Work budget of one function, e-nodes over all its windows ([`WORK_ENODES`] in the
    /// pass; smaller in tests).
    pub work_enodes: u64,
}

impl Default for EqsatOptions {
    fn default() -> Self {
        EqsatOptions {
            window: 6,
            budget: 0,
            iters: 30,
            nodes: 10_000,
            time_ms: 100,
            distribute: true,
            rules_file: None,
            lat: Latencies::default(),
            work_enodes: WORK_ENODES,
        }
    }
}

/// The `eqsat` pass.
pub struct Eqsat {
    /// Options.
    pub opts: EqsatOptions,
}

impl Pass for Eqsat {
    fn name(&self) -> &'static str {
        "eqsat"
    }

    fn requires(&self) -> Option<Phase> {
        Some(Phase::Atomised)
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let mut rules = rules::rules(self.opts.distribute);
        if let Some(path) = &self.opts.rules_file {
            let extra = rules_file::load(path, &rules)
                .map_err(|message| PassError::Failed { pass: "eqsat".into(), message })?;
            rules.extend(extra);
        }
        for f in &mut m.functions {
            let stats = eqsat_function_within(f, &self.opts, &rules, cx.deadline);
            if let Some(why) = &stats.stopped_early {
                let what = format!("after {} of {} windows of @{}: {why}", stats.windows_tried, stats.windows_total, f.name);
                cx.note_stop("eqsat", &what);
            }
            cx.eqsat.push(stats);
        }
        Ok(())
    }
}
