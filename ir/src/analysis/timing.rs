//! ASAP / ALAP (unit weights) and ASAPCycle / ALAPCycle (latency weights), seed §2.2 and
//! SPEC §4.
//!
//! Inputs and trig initial variables are ready at 0. For an operation `o` with operands `p`:
//! `ASAP(o) = 1 + max ASAP(p)`, `ASAPCycle(o) = lat(o) + max ASAPCycle(p)` (0 for inputs).
//! The critical path is the largest ASAP / ASAPCycle. Backwards, an op with no operation user
//! gets `ALAP = max ASAP` and `ALAPCycle = max ASAPCycle`; otherwise
//! `ALAP(o) = min ALAP(u) − 1` and `ALAPCycle(o) = min (ALAPCycle(u) − lat(u))` over users `u`.
//! Mobility = ALAP − ASAP. Cost: O(values + operands), one forward and one backward sweep in
//! body order (which is topological); no user graph.

use crate::function::Function;
use crate::latency::Latencies;
use crate::syntax::{Def, Timing};
use crate::Value;

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
    let mut table = Table { f, timing: vec![None; f.values.len()] };
    let sum = sweep(&f.body, f.values.len(), &mut table, lat);
    (table.timing, sum)
}

/// [`compute_timing`] written into `f` (`ValueData::timing` of every value: `None` for inputs
/// and trig variables), without a table of every value's timing beside the function: 16
/// bytes of work memory per value instead of ~90 for that table and a user graph (issue 10
/// §3). Each op's timing is written when the backward sweep finalises it, while its
/// definition is in the cache (issue 28: one pass over the values less). Returns the critical
/// path.
pub fn annotate_timing(f: &mut Function, lat: &Latencies) -> TimingSummary {
    for i in 0..f.inputs.len() {
        let v = f.inputs[i];
        f.value_mut(v).timing = None;
    }
    let body = std::mem::take(&mut f.body);
    let sum = sweep(&body, f.values.len(), f, lat);
    f.body = body;
    sum
}

/// Where the sweeps read definitions and write each value's timing.
trait Levels {
    fn def(&self, v: Value) -> &Def;
    fn set(&mut self, v: Value, t: Option<Timing>);
}

/// [`compute_timing`]'s table beside the function.
struct Table<'a> {
    f: &'a Function,
    timing: Vec<Option<Timing>>,
}

impl Levels for Table<'_> {
    fn def(&self, v: Value) -> &Def {
        &self.f.value(v).def
    }
    fn set(&mut self, v: Value, t: Option<Timing>) {
        self.timing[v.index()] = t;
    }
}

impl Levels for Function {
    fn def(&self, v: Value) -> &Def {
        &self.value(v).def
    }
    fn set(&mut self, v: Value, t: Option<Timing>) {
        self.value_mut(v).timing = t;
    }
}

/// The forward (ASAP) and backward (ALAP) sweeps over `body` (body order, topological), each
/// body value's timing set when final. The backward sweep needs no user lists: visiting ops
/// in reverse body order (reverse topological), each op pushes its own bound to its operands,
/// so an op's bound is final when it is visited. Work memory: four `u32` per value (`n`
/// values, indexed by `Value::index()`). Cost: O(values + operands).
fn sweep(body: &[Value], n: usize, s: &mut impl Levels, lat: &Latencies) -> TimingSummary {
    let mut asap = vec![0u32; n];
    let mut asap_c = vec![0u32; n];
    let mut sum = TimingSummary::default();
    for &v in body {
        let def = s.def(v);
        let Some(kind) = def.op_kind() else { continue };
        let (mut a, mut c) = (0, 0);
        def.for_each_value(|p| {
            a = a.max(asap[p.index()]);
            c = c.max(asap_c[p.index()]);
        });
        asap[v.index()] = a + 1;
        asap_c[v.index()] = c + lat.of(kind);
        sum.asap = sum.asap.max(a + 1);
        sum.asap_cycle = sum.asap_cycle.max(c + lat.of(kind));
    }
    // Before an op is visited: the smallest bound pushed by its op users (`u32::MAX`: none);
    // after: its ALAP level.
    let mut alap = vec![u32::MAX; n];
    let mut alap_c = vec![u32::MAX; n];
    for &v in body.iter().rev() {
        let def = s.def(v);
        let Some(kind) = def.op_kind() else {
            s.set(v, None);
            continue;
        };
        let l = sum.asap.min(alap[v.index()]);
        let lc = sum.asap_cycle.min(alap_c[v.index()]);
        let lat_v = lat.of(kind);
        def.for_each_value(|p| {
            alap[p.index()] = alap[p.index()].min(l - 1);
            alap_c[p.index()] = alap_c[p.index()].min(lc - lat_v);
        });
        let i = v.index();
        let (a, ac) = (asap[i], asap_c[i]);
        s.set(v, Some(Timing { asap: a, alap: l, asap_cycle: ac, alap_cycle: lc, mobility: l - a }));
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::DepGraph;

    /// The definition with user lists (`DepGraph`), as ALAP is stated in the module doc.
    fn by_user_lists(f: &Function, lat: &Latencies) -> Vec<Option<Timing>> {
        let (t, sum) = compute_timing(f, lat);
        let g = DepGraph::build(f);
        let mut alap = vec![(u32::MAX, u32::MAX); f.values.len()];
        let mut out = vec![None; f.values.len()];
        for &v in f.body.iter().rev() {
            if f.op_kind(v).is_none() {
                continue;
            }
            let (mut l, mut lc) = (sum.asap, sum.asap_cycle);
            for u in g.users(v) {
                if let Some(k) = f.op_kind(u) {
                    l = l.min(alap[u.index()].0 - 1);
                    lc = lc.min(alap[u.index()].1 - lat.of(k));
                }
            }
            alap[v.index()] = (l, lc);
            let mine = t[v.index()].expect("an op has a timing");
            out[v.index()] = Some(Timing { alap: l, alap_cycle: lc, mobility: l - mine.asap, ..mine });
        }
        out
    }

    #[test]
    fn pushing_bounds_to_operands_equals_the_user_list_definition() {
        // Shared operands, an operand read twice, a call, ops off the critical path.
        let m = crate::text::parse(
            "func @f { phase atomised input %a input %b input %q %C = cos %q %x = mul %a, %b %y = add %x, %x \
             %z = div %y, %C %w = mul %a, %C %s = call @sqrt(%w) %u = sub %s, %x %k = mul %z, %u \
             output o = %k output p = %w output r = %y }",
        )
        .expect("parses");
        let f = &m.functions[0];
        let lat = Latencies { add: 12, mul: 7, div: 20, call: 30 };
        let (t, sum) = compute_timing(f, &lat);
        assert_eq!(t, by_user_lists(f, &lat));
        // k = mul(z, u): u = sub(call(mul), x) ends at 7 + 30 + 12 = 49, z = div(add(mul)) at 39.
        assert_eq!((sum.asap, sum.asap_cycle), (4, 7 + 30 + 12 + 7));
        let mut g = f.clone();
        assert_eq!(annotate_timing(&mut g, &lat), sum);
        assert_eq!(g.values.iter().map(|d| d.timing).collect::<Vec<_>>(), t);
        assert!(t[g.lookup("C").expect("trig").index()].is_none());
    }
}
