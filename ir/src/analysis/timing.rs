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
use crate::syntax::Timing;

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
    let mut timing = vec![None; f.values.len()];
    let sum = sweep(f, &mut timing, lat);
    (timing, sum)
}

/// [`compute_timing`] written into `f` ([`Function::timing`] of every value: `None` for inputs
/// and trig variables). The table is beside the values, so the sweeps stream the definitions
/// and write 24 bytes per value in order (issue 28). Returns the critical path.
pub fn annotate_timing(f: &mut Function, lat: &Latencies) -> TimingSummary {
    let (table, sum) = compute_timing(f, lat);
    f.set_timings(table);
    sum
}

/// The forward (ASAP) and backward (ALAP) sweeps over the body (body order, topological),
/// into `timing` (indexed by value index, all `None` on entry). The backward sweep needs no
/// user lists: visiting ops in reverse body order (reverse topological), each op pushes its
/// own bound to its operands, so an op's bound is final when it is visited. The bounds live in
/// the operands' own entries (ALAP fields, `u32::MAX` = none yet), so `timing` is the only
/// work memory (fresh memory is page faults on large functions: issue 28). Cost:
/// O(values + operands).
fn sweep(f: &Function, timing: &mut [Option<Timing>], lat: &Latencies) -> TimingSummary {
    let mut sum = TimingSummary::default();
    let level = |t: &Option<Timing>| t.map_or((0, 0), |t| (t.asap, t.asap_cycle));
    for &v in &f.body {
        let def = &f.value(v).def;
        let Some(kind) = f.op_kind(v) else { continue };
        let (mut a, mut c) = (0, 0);
        def.for_each_value(|p| {
            let (pa, pc) = level(&timing[p.index()]);
            a = a.max(pa);
            c = c.max(pc);
        });
        let (a, c) = (a + 1, c + lat.of(kind));
        timing[v.index()] = Some(Timing { asap: a, asap_cycle: c, alap: u32::MAX, alap_cycle: u32::MAX, mobility: 0 });
        sum.asap = sum.asap.max(a);
        sum.asap_cycle = sum.asap_cycle.max(c);
    }
    for &v in f.body.iter().rev() {
        let def = &f.value(v).def;
        let Some(kind) = f.op_kind(v) else { continue };
        let t = timing[v.index()].as_mut().expect("ops have a level");
        t.alap = t.alap.min(sum.asap);
        t.alap_cycle = t.alap_cycle.min(sum.asap_cycle);
        t.mobility = t.alap - t.asap;
        let (l, lc, lat_v) = (t.alap, t.alap_cycle, lat.of(kind));
        def.for_each_value(|p| {
            if let Some(t) = timing[p.index()].as_mut() {
                t.alap = t.alap.min(l - 1);
                t.alap_cycle = t.alap_cycle.min(lc - lat_v);
            }
        });
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::DepGraph;
    use crate::Value;

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
        let annotated: Vec<_> = (0..g.values.len()).map(|i| g.timing(Value::with_number(i as u32))).collect();
        assert_eq!(annotated, t);
        assert!(t[g.lookup("C").expect("trig").index()].is_none());
    }
}
