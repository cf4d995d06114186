//! ASAP / ALAP (unit weights) and ASAPCycle / ALAPCycle (latency weights), seed §2.2 and
//! SPEC §4.
//!
//! Inputs and trig initial variables are ready at 0. For an operation `o` with operands `p`:
//! `ASAP(o) = 1 + max ASAP(p)`, `ASAPCycle(o) = lat(o) + max ASAPCycle(p)` (0 for inputs).
//! The critical path is the largest ASAP / ASAPCycle. Backwards, an op with no operation user
//! gets `ALAP = max ASAP` and `ALAPCycle = max ASAPCycle`; otherwise
//! `ALAP(o) = min ALAP(u) − 1` and `ALAPCycle(o) = min (ALAPCycle(u) − lat(u))` over users `u`.
//! Mobility = ALAP − ASAP. Cost: O(values + operands), one forward and one backward sweep in
//! body order (which is topological).

use super::dep_graph::DepGraph;
use crate::function::Function;
use crate::syntax::{OpKind, Timing};

/// Latencies in cycles from issue to a result usable by a dependent op, including 2 cycles of
/// interconnect and memory write (SPEC §1; seed §2.2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Latencies {
    /// `add`/`sub` (default 12 = 10 + 2).
    pub add: u32,
    /// `mul` (default 7 = 5 + 2).
    pub mul: u32,
    /// `div` (default 12, on the ADD side).
    pub div: u32,
    /// `call` (`sqrt`, callbacks; default 12).
    pub call: u32,
}

impl Default for Latencies {
    fn default() -> Self {
        Latencies { add: 12, mul: 7, div: 12, call: 12 }
    }
}

impl Latencies {
    /// Latency of an op kind, in cycles.
    pub fn of(&self, k: OpKind) -> u32 {
        match k {
            OpKind::Add | OpKind::Sub => self.add,
            OpKind::Mul => self.mul,
            OpKind::Div => self.div,
            OpKind::Call => self.call,
        }
    }
}

/// Critical path figures of a function (SPEC §4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TimingSummary {
    /// Largest ASAP over all ops (unit steps).
    pub asap: u32,
    /// Largest ASAPCycle over all ops (cycles).
    pub asap_cycle: u32,
}

/// Computes the timing of every operation of `f` (indexed by `Value::index()`; `None` for
/// inputs and trig variables) and the critical path. `f` must verify and be atomised
/// (parsed-phase expressions are treated as ready at 0, i.e. ignored).
pub fn compute_timing(f: &Function, lat: &Latencies) -> (Vec<Option<Timing>>, TimingSummary) {
    let n = f.values.len();
    let mut t: Vec<Option<Timing>> = vec![None; n];
    let mut asap = vec![0u32; n];
    let mut asap_c = vec![0u32; n];
    let mut sum = TimingSummary::default();
    for &v in &f.body {
        let Some(kind) = f.op_kind(v) else { continue };
        let (mut a, mut c) = (0, 0);
        f.value(v).def.for_each_value(|p| {
            a = a.max(asap[p.index()]);
            c = c.max(asap_c[p.index()]);
        });
        asap[v.index()] = a + 1;
        asap_c[v.index()] = c + lat.of(kind);
        sum.asap = sum.asap.max(a + 1);
        sum.asap_cycle = sum.asap_cycle.max(c + lat.of(kind));
    }
    let g = DepGraph::build(f);
    let mut alap = vec![u32::MAX; n];
    let mut alap_c = vec![u32::MAX; n];
    for &v in f.body.iter().rev() {
        let Some(_) = f.op_kind(v) else { continue };
        let (mut l, mut lc) = (sum.asap, sum.asap_cycle);
        for u in g.users(v) {
            if let Some(k) = f.op_kind(u) {
                l = l.min(alap[u.index()] - 1);
                lc = lc.min(alap_c[u.index()] - lat.of(k));
            }
        }
        alap[v.index()] = l;
        alap_c[v.index()] = lc;
        let (a, ac) = (asap[v.index()], asap_c[v.index()]);
        t[v.index()] = Some(Timing { asap: a, alap: l, asap_cycle: ac, alap_cycle: lc, mobility: l - a });
    }
    (t, sum)
}
