//! `eqsat<window;budget;iters;nodes;time-ms;distribute;scope;slack;rounds;rules;lat-add;lat-mul>`: equality
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
//! **`scope=critical`** (depth-aware windows, issue 31 item 2): step 1 takes instead one window
//! per `add`/`sub`/`mul` value within `slack` cycles of the critical path
//! ([`critical::find_critical_windows`]), grown through the operands that are themselves within
//! `slack`, shared or not, the latest first: the windows overlap and reach across the shared
//! values (a velocity read by three products, a force read by its parent and a torque) where
//! cluster windows stop, which is where recurrences keep their depth. Each shared interior
//! value is also a leaf of its window (unioned with its node), so extraction may read it as
//! already computed; the ops budget counts the net change (new ops − the ops read nowhere
//! else). A root is replaced only when its new term is ready earlier than the root as it is
//! now. Then another run (up to `rounds`) while the last one shortened the critical path. Its
//! cost is per critical value, not per op: on a 161 025-op serial robot (130 dof, `dirdyna`
//! after `balance`) cluster windows try 43 913 windows in 2.2 s and shorten nothing;
//! `scope=critical;budget=2` tries 7 838 in 8 runs (6.9 s) and takes the critical path 7671 →
//! 5663 cycles for 1.2 % more ops.
//!
//! Contracts: never lengthens the critical path (each root is ready no later, by induction in
//! topological order); never adds more than `budget` ops per window; idempotent up to the
//! e-graph limits. Cost: per window, bounded by the runner limits (`nodes` e-nodes, `time-ms`);
//! per function, bounded by the work budget [`WORK_ENODES`] (the e-nodes of all windows
//! together) and by `-time-limit` ([`crate::PassContext::deadline`]). When either stops the
//! run, the windows not yet tried keep their form (the IR stays valid), the stats say
//! `stopped after K of N windows: …` and the pass adds a note to the context.

pub mod critical;
pub mod extract;
pub mod lang;
pub mod rules;
pub mod rules_file;
pub mod stats;
pub mod window;

mod apply;
#[cfg(test)]
mod tests;

use std::path::PathBuf;

use robovec_ir::analysis::Latencies;
use robovec_ir::Module;

use crate::params::ParamKind;
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

pub use apply::{eqsat_function, eqsat_function_within, MIN_WINDOW_WORK, WORK_ENODES};
pub use stats::{EqsatStats, StopCounts};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "eqsat",
    doc: "egg equality saturation over bounded windows of +/-/* clusters, extracted by ready time",
    params: &[
        ParamInfo {
            name: "window",
            kind: ParamKind::U32 { default: 6, min: 2, max: 64 },
            doc: "max leaf occurrences per window, leaves (ops ≤ window − 1)",
        },
        ParamInfo {
            name: "budget",
            kind: ParamKind::U32 { default: 0, min: 0, max: 10_000 },
            doc: "max extra ops per window, ops (0: never more ops than the window had)",
        },
        ParamInfo {
            name: "iters",
            kind: ParamKind::U32 { default: 30, min: 1, max: 10_000 },
            doc: "egg runner iteration limit per window, iterations",
        },
        ParamInfo {
            name: "nodes",
            kind: ParamKind::U32 { default: 10_000, min: 10, max: 10_000_000 },
            doc: "egg runner e-node limit per window, e-nodes",
        },
        ParamInfo {
            name: "time-ms",
            kind: ParamKind::U32 { default: 100, min: 1, max: 600_000 },
            doc: "egg runner time limit per window, milliseconds",
        },
        ParamInfo {
            name: "distribute",
            kind: ParamKind::Flag { default: true },
            doc: "distributivity/factoring rules: on or off",
        },
        ParamInfo {
            name: "scope",
            kind: ParamKind::Choice { choices: &["clusters", "critical"], default: "clusters" },
            doc: "windows: clusters (trees of single-use ops, a partition of the function) or critical (one per \
                  value within `slack` of the critical path, grown through shared critical values)",
        },
        ParamInfo {
            name: "slack",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "scope=critical: the largest slack of a window's root and interior values, cycles",
        },
        ParamInfo {
            name: "rounds",
            kind: ParamKind::U32 { default: 8, min: 1, max: 1000 },
            doc: "scope=critical: runs over the critical windows while the last one shortened the critical path",
        },
        ParamInfo { name: "rules", kind: ParamKind::Path, doc: "file of extra rules (docs/eqsat-rules.md)" },
        ParamInfo { doc: "add/sub latency for extraction, cycles", ..crate::params::LAT_ADD },
        ParamInfo { doc: "mul latency for extraction, cycles", ..crate::params::LAT_MUL },
    ],
    build: |p: &Params| Ok(Box::new(Eqsat { opts: options_from(p)?, lat: p.latency_override()? })),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        ..crate::Props::DEFAULT
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
    /// Critical windows ([`critical::find_critical_windows`], `scope=critical`) instead of
    /// cluster windows.
    pub critical: bool,
    /// `scope=critical`: largest slack of a window's values, cycles.
    pub slack: u32,
    /// `scope=critical`: runs at most (another while the last shortened the critical path).
    pub rounds: u32,
    /// Work budget of one function, e-nodes over all its windows ([`WORK_ENODES`] in the
    /// pass; smaller in tests).
    pub work_enodes: u64,
}

/// The options of checked parameters `p` (defaults and ranges from [`INFO`]).
fn options_from(p: &Params) -> Result<EqsatOptions, PassError> {
    Ok(EqsatOptions {
        window: p.u32("window")? as usize,
        budget: p.u32("budget")?,
        iters: p.u32("iters")? as usize,
        nodes: p.u32("nodes")? as usize,
        time_ms: p.u32("time-ms")? as u64,
        distribute: p.flag("distribute")?,
        rules_file: p.path("rules")?.map(PathBuf::from),
        lat: p.latencies()?,
        critical: p.choice("scope")? == "critical",
        slack: p.u32("slack")?,
        rounds: p.u32("rounds")?,
        work_enodes: WORK_ENODES,
    })
}

impl Default for EqsatOptions {
    /// The defaults declared in [`INFO`].
    fn default() -> Self {
        options_from(&Params::defaults(&INFO)).expect("declared defaults are valid")
    }
}

/// The `eqsat` pass.
#[derive(Debug)]
pub struct Eqsat {
    /// Options (`opts.lat` is replaced at run time by the pipeline's latencies with `lat`
    /// applied, [`PassContext::latencies_for`]).
    pub opts: EqsatOptions,
    /// Latencies given on the pass.
    pub lat: crate::LatencyOverride,
}

impl Pass for Eqsat {
    fn name(&self) -> &'static str {
        "eqsat"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let mut rules = rules::rules(self.opts.distribute);
        if let Some(path) = &self.opts.rules_file {
            let extra = rules_file::load(path, &rules)
                .map_err(|message| PassError::Failed { pass: "eqsat".into(), message })?;
            rules.extend(extra);
        }
        let opts = EqsatOptions { lat: cx.latencies_for("eqsat", &self.lat), ..self.opts.clone() };
        // Each function gets at most the time left, and its own e-node budget: a stop cuts that
        // function's search short (a note each) and the next one is tried with what is left.
        let deadline = cx.deadline;
        let runs = each_function(
            m,
            cx,
            "eqsat",
            Before::Ticked,
            |_, _| None,
            |f, _, _| {
                let stats = eqsat_function_within(f, &opts, &rules, deadline);
                match &stats.stopped_early {
                    Some(why) => Step::Cut {
                        note: format!(
                            "after {} of {} windows of @{}: {why}",
                            stats.windows_tried, stats.windows_total, f.name
                        ),
                        result: stats,
                    },
                    None => Step::Done(stats),
                }
            },
        );
        cx.emit(EqsatRun { functions: runs });
        Ok(())
    }
}

/// What one `eqsat` run did, one entry per function: printed by `-stats`, listed in the
/// report's `eqsat` (entries of the reported function).
#[derive(Clone, Debug)]
pub struct EqsatRun {
    /// Per function: windows, stop reasons, time per window, critical path before and after.
    pub functions: Vec<EqsatStats>,
}

impl crate::Artifact for EqsatRun {
    fn pass(&self) -> &'static str {
        "eqsat"
    }

    fn stats_text(&self, function: Option<&str>) -> String {
        self.functions.iter().filter(|e| function.is_none_or(|n| n == e.function)).map(|e| format!("{e}\n")).collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let runs: Vec<&EqsatStats> = self.functions.iter().filter(|e| e.function == function).collect();
        Some(crate::ReportEntry::new("eqsat", &runs, crate::Merge::Append))
    }
}
