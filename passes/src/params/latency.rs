//! The latency parameters (`lat-add`, `lat-mul`, `lat-div`, `lat-call`; SPEC §1) that several
//! passes declare, and the overrides they give the pipeline's latencies.

use robovec_ir::analysis::Latencies;

use super::{ParamInfo, ParamKind};

/// The add/sub latency parameter (SPEC §1), cycles.
pub const LAT_ADD: ParamInfo = ParamInfo {
    name: "lat-add",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "add/sub latency, cycles; when not given, the pipeline's (-target; de10-nano: 10 pipeline + 2 write)",
};
/// The mul latency parameter (SPEC §1), cycles.
pub const LAT_MUL: ParamInfo = ParamInfo {
    name: "lat-mul",
    kind: ParamKind::U32Target { builtin: 7, min: 1, max: 10_000 },
    doc: "mul latency, cycles; when not given, the pipeline's (-target; de10-nano: 5 pipeline + 2 write)",
};
/// The div latency parameter (SPEC §1), cycles.
pub const LAT_DIV: ParamInfo = ParamInfo {
    name: "lat-div",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "div latency, cycles (ADD side); when not given, the pipeline's (-target)",
};
/// The call latency parameter (SPEC §1), cycles.
pub const LAT_CALL: ParamInfo = ParamInfo {
    name: "lat-call",
    kind: ParamKind::U32Target { builtin: 12, min: 1, max: 10_000 },
    doc: "call (sqrt, callbacks) latency, cycles (ADD side); when not given, the pipeline's (-target)",
};
/// The four latency parameters, for passes that take only them.
pub const LATENCY_PARAMS: &[ParamInfo] = &[LAT_ADD, LAT_MUL, LAT_DIV, LAT_CALL];

/// Latencies given explicitly on one pass (`lat-add`, `lat-mul`, `lat-div`, `lat-call`), cycles;
/// `None` where not given. An explicit latency overrides the pipeline's latencies (the
/// target's, `-target`) from that pass on: see [`crate::PassContext::latencies_for`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatencyOverride {
    /// `lat-add`.
    pub add: Option<u32>,
    /// `lat-mul`.
    pub mul: Option<u32>,
    /// `lat-div`.
    pub div: Option<u32>,
    /// `lat-call`.
    pub call: Option<u32>,
}

impl LatencyOverride {
    /// True when no latency was given.
    pub fn is_empty(&self) -> bool {
        *self == LatencyOverride::default()
    }

    /// `base` with the given latencies replaced.
    pub fn apply(&self, base: &Latencies) -> Latencies {
        Latencies {
            add: self.add.unwrap_or(base.add),
            mul: self.mul.unwrap_or(base.mul),
            div: self.div.unwrap_or(base.div),
            call: self.call.unwrap_or(base.call),
        }
    }

    /// The parameters as written in a pipeline (`lat-add=6;lat-mul=4`).
    pub fn text(&self) -> String {
        let parts = [("lat-add", self.add), ("lat-mul", self.mul), ("lat-div", self.div), ("lat-call", self.call)];
        parts.iter().filter_map(|(k, v)| v.map(|v| format!("{k}={v}"))).collect::<Vec<_>>().join(";")
    }
}
