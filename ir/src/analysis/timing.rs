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
    let (s, sum) = sweep(f, lat);
    let mut t: Vec<Option<Timing>> = vec![None; f.values.len()];
    for &v in &f.body {
        if f.op_kind(v).is_some() {
            t[v.index()] = Some(s.timing(v));
        }
    }
    (t, sum)
}

/// [`compute_timing`] written into `f` (`ValueData::timing` of every value: `None` for inputs
/// and trig variables), without a table of every value's timing beside the function: 16
/// bytes of work memory per value instead of ~90 for that table and a user graph (issue 10
/// §3). Returns the critical path.
pub fn annotate_timing(f: &mut Function, lat: &Latencies) -> TimingSummary {
    let (s, sum) = sweep(f, lat);
    for i in 0..f.values.len() {
        let v = Value::with_number(i as u32);
        let timing = f.op_kind(v).map(|_| s.timing(v));
        f.value_mut(v).timing = timing;
    }
    sum
}

/// The four levels of every value, indexed by `Value::index()` (meaningful for ops).
struct Levels {
    asap: Vec<u32>,
    asap_c: Vec<u32>,
    alap: Vec<u32>,
    alap_c: Vec<u32>,
}

impl Levels {
    fn timing(&self, v: Value) -> Timing {
        let i = v.index();
        let (asap, alap) = (self.asap[i], self.alap[i]);
        Timing { asap, alap, asap_cycle: self.asap_c[i], alap_cycle: self.alap_c[i], mobility: alap - asap }
    }
}

/// The forward (ASAP) and backward (ALAP) sweeps in body order. The backward sweep needs no
/// user lists: visiting ops in reverse body order (reverse topological), each op pushes its
/// own bound to its operands, so an op's bound is final when it is visited. Work memory: four
/// `u32` per value. Cost: O(values + operands).
fn sweep(f: &Function, lat: &Latencies) -> (Levels, TimingSummary) {
    let n = f.values.len();
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
    // Before an op is visited: the smallest bound pushed by its op users (`u32::MAX`: none);
    // after: its ALAP level.
    let mut alap = vec![u32::MAX; n];
    let mut alap_c = vec![u32::MAX; n];
    for &v in f.body.iter().rev() {
        let Some(kind) = f.op_kind(v) else { continue };
        let l = sum.asap.min(alap[v.index()]);
        let lc = sum.asap_cycle.min(alap_c[v.index()]);
        alap[v.index()] = l;
        alap_c[v.index()] = lc;
        let lat_v = lat.of(kind);
        f.value(v).def.for_each_value(|p| {
            alap[p.index()] = alap[p.index()].min(l - 1);
            alap_c[p.index()] = alap_c[p.index()].min(lc - lat_v);
        });
    }
    (Levels { asap, asap_c, alap, alap_c }, sum)
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
