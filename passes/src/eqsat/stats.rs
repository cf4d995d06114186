//! What one `eqsat` run did to one function: windows, egg's stop reasons, times, e-nodes, ops
//! and critical path (printed by `-stats`, listed in the report's `eqsat` entries, SPEC §7).

/// How the egg runs of a function stopped (egg `StopReason`), in windows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct StopCounts {
    /// No rule could add anything.
    pub saturated: u32,
    /// `iters` reached.
    pub iteration_limit: u32,
    /// `nodes` reached.
    pub node_limit: u32,
    /// `time-ms` reached.
    pub time_limit: u32,
    /// Any other reason.
    pub other: u32,
}

/// What `eqsat` did to one function (printed by `-stats`).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct EqsatStats {
    /// Function name.
    pub function: String,
    /// Windows saturated, windows.
    pub windows_tried: u32,
    /// Windows replaced by their extracted form, windows.
    pub windows_replaced: u32,
    /// Windows where egg's lexicographic extraction was over the op budget and the Pareto
    /// extraction within the budget was used, windows.
    pub budget_fallbacks: u32,
    /// Stop reasons of the runs.
    pub stops: StopCounts,
    /// Total wall time of saturation + extraction, milliseconds.
    pub total_ms: f64,
    /// Mean wall time per window, milliseconds.
    pub mean_ms: f64,
    /// Largest wall time of one window, milliseconds.
    pub max_ms: f64,
    /// Largest e-graph of a window, e-nodes.
    pub max_enodes: usize,
    /// Ops before / after, ops.
    pub ops_before: u64,
    /// Ops after, ops.
    pub ops_after: u64,
    /// Critical path (largest ASAPCycle, SPEC §4) before, cycles.
    pub cp_before: u32,
    /// Critical path after, cycles.
    pub cp_after: u32,
    /// Windows found in the function, windows (`windows_tried` is smaller when the run
    /// stopped early).
    pub windows_total: u32,
    /// E-nodes of all the windows' e-graphs together, e-nodes (about at most the work budget,
    /// [`WORK_ENODES`](super::apply::WORK_ENODES) by default: egg checks its node limit between rules).
    pub enodes_total: u64,
    /// Runs over the windows (`rounds`; 1 for cluster windows).
    pub rounds: u32,
    /// Why the run stopped before trying every window (the `-time-limit` or the work budget
    /// reached); the windows not tried are kept unchanged.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped_early: Option<String>,
}

impl std::fmt::Display for EqsatStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = &self.stops;
        write!(
            f,
            "@{}: eqsat: windows {} tried, {} replaced ({} within budget by Pareto extraction); stop reasons: \
             saturated {}, iteration limit {}, node limit {}, time limit {}, other {}; time {:.1} ms total, \
             {:.3} ms mean / {:.3} ms max per window; largest e-graph {} e-nodes; ops {} -> {}; critical path \
             {} -> {} cycles",
            self.function,
            self.windows_tried,
            self.windows_replaced,
            self.budget_fallbacks,
            s.saturated,
            s.iteration_limit,
            s.node_limit,
            s.time_limit,
            s.other,
            self.total_ms,
            self.mean_ms,
            self.max_ms,
            self.max_enodes,
            self.ops_before,
            self.ops_after,
            self.cp_before,
            self.cp_after
        )?;
        if self.rounds > 1 {
            write!(f, "; {} rounds", self.rounds)?;
        }
        if let Some(why) = &self.stopped_early {
            write!(f, "; stopped after {} of {} windows: {why}", self.windows_tried, self.windows_total)?;
        }
        Ok(())
    }
}

impl EqsatStats {
    /// Adds the counts of a later run `r` of the same function: its runs, windows, stops, times
    /// and e-nodes; the ops and the critical path after it; its stop reason.
    pub(super) fn absorb(&mut self, r: EqsatStats) {
        self.rounds += r.rounds;
        self.windows_total += r.windows_total;
        self.windows_tried += r.windows_tried;
        self.windows_replaced += r.windows_replaced;
        self.budget_fallbacks += r.budget_fallbacks;
        let (s, t) = (&mut self.stops, r.stops);
        (s.saturated, s.iteration_limit, s.node_limit, s.time_limit, s.other) = (
            s.saturated + t.saturated,
            s.iteration_limit + t.iteration_limit,
            s.node_limit + t.node_limit,
            s.time_limit + t.time_limit,
            s.other + t.other,
        );
        self.total_ms += r.total_ms;
        self.max_ms = self.max_ms.max(r.max_ms);
        self.max_enodes = self.max_enodes.max(r.max_enodes);
        self.enodes_total += r.enodes_total;
        self.mean_ms = if self.windows_tried > 0 { self.total_ms / self.windows_tried as f64 } else { 0.0 };
        (self.ops_after, self.cp_after, self.stopped_early) = (r.ops_after, r.cp_after, r.stopped_early);
    }
}
