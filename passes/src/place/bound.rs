//! Lower bounds on the cycles of any valid placement (SPEC §4, §5), used to grade the list
//! scheduler (`cycles / LB`).
//!
//! - [`lower_bound`] is SPEC §4's LB: critical path, or each PE type's op count over its PEs.
//! - [`tight_lower_bound`] solves, per PE type, the relaxation in which only that type's issue
//!   slots are scarce: unit-time jobs with integer release dates (heads) and delivery times
//!   (tails) on N identical machines, `P | r_j, p_j = 1 | max(s_j + q_j)`, which the
//!   earliest-due-date list rule solves exactly (Jackson's rule extended to identical machines
//!   for unit jobs; Brucker, *Scheduling Algorithms*, §5.1). Heads and tails are first
//!   tightened through the other PE type: an op cannot issue before the ops it depends on,
//!   themselves competing for their PEs, have arrived — the same relaxation solved on its
//!   ancestors (and, backwards, on its descendants for tails; Carlier & Pinson's head/tail
//!   adjustments in spirit).
//!
//! Every bound here is valid for the architecture's resource model (PEs issue one op per cycle,
//! latencies fixed); memories and write ports only make real placements longer.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use robovec_ir::analysis::compute_timing;
use robovec_ir::placement::PeArray;
use robovec_ir::{Function, OpKind, Value};

/// Ops that run on the ADD side (add, sub, div, call) and on the MULTI side (mul, and the
/// fused multiply-adds in fixed point: [`Function::op_kind`]).
pub fn ops_per_side(f: &Function) -> (u64, u64) {
    let c = f.op_counts();
    let mac = f.body.iter().filter(|&&v| f.is_fixed_mac(v)).count() as u64;
    (c.add + c.sub + c.div + c.call - mac, c.mul + mac)
}

/// The lower bound LB of SPEC §4: max(ASAPCycle critical path, ⌈n_add_side/N_add⌉ − 1 + lat_add,
/// ⌈n_mul/N_mul⌉ − 1 + lat_mul), in cycles. No valid placement has fewer cycles.
pub fn lower_bound(f: &Function, arch: &PeArray) -> u32 {
    let (_, cp) = compute_timing(f, &arch.lat);
    let (na, nm) = ops_per_side(f);
    let side = |n: u64, pes: u32, lat: u32| if n == 0 { 0 } else { (n.div_ceil(pes as u64) - 1) as u32 + lat };
    cp.asap_cycle.max(side(na, arch.n_add, arch.lat.add)).max(side(nm, arch.n_mul, arch.lat.mul))
}

/// The smallest possible `max_j (s_j + tail_j)` over unit jobs `(release r_j, tail_j)` issued at
/// integer cycles `s_j ≥ r_j`, at most `n_pe` per cycle: the earliest-due-date rule (largest
/// tail first among released jobs) is optimal for this problem. Sorts `jobs` by release.
/// Cost: O(k log k) for k jobs. Returns 0 for no job.
pub fn edf_bound(jobs: &mut [(u32, u32)], n_pe: u32) -> u32 {
    jobs.sort_unstable_by_key(|&(r, _)| r);
    let mut heap: BinaryHeap<u32> = BinaryHeap::new();
    let (mut i, mut t, mut best) = (0, 0u32, 0u32);
    while i < jobs.len() || !heap.is_empty() {
        if heap.is_empty() {
            t = t.max(jobs[i].0);
        }
        while i < jobs.len() && jobs[i].0 <= t {
            heap.push(jobs[i].1);
            i += 1;
        }
        for _ in 0..n_pe {
            let Some(q) = heap.pop() else { break };
            best = best.max(t + q);
        }
        t += 1;
    }
    best
}

/// The dependence DAG in the form the bounds need: ops only, in topological order.
struct Dag {
    /// Op per node, in body (topological) order.
    ops: Vec<Value>,
    /// Side per node: `true` for the MULTI side.
    mul: Vec<bool>,
    /// Latency per node, cycles.
    lat: Vec<u32>,
    /// Distinct op operands per node (node indices, all smaller).
    preds: Vec<Vec<u32>>,
    /// Distinct op users per node (node indices, all larger).
    succs: Vec<Vec<u32>>,
}

impl Dag {
    fn build(f: &Function, arch: &PeArray) -> Dag {
        let mut node = vec![u32::MAX; f.values.len()];
        let mut dag = Dag { ops: Vec::new(), mul: Vec::new(), lat: Vec::new(), preds: Vec::new(), succs: Vec::new() };
        for &v in &f.body {
            let Some(k) = f.op_kind(v) else { continue };
            let id = dag.ops.len() as u32;
            node[v.index()] = id;
            let mut preds = Vec::new();
            f.value(v).def.for_each_value(|a| {
                let p = node[a.index()];
                if p != u32::MAX && !preds.contains(&p) {
                    preds.push(p);
                }
            });
            for &p in &preds {
                dag.succs[p as usize].push(id);
            }
            dag.ops.push(v);
            dag.mul.push(k == OpKind::Mul);
            dag.lat.push(arch.lat.of(k));
            dag.preds.push(preds);
            dag.succs.push(Vec::new());
        }
        dag
    }
}

/// Ancestor visits allowed for head/tail tightening per call (a few tens of ms at most): beyond it
/// the remaining ops keep their untightened (still valid) heads and tails.
const TIGHTEN_BUDGET: u64 = 1_000_000;

/// Tightens `head[j]` (a lower bound on node j's issue cycle) for every node, in topological
/// order `order`: the ancestors of each PE type must all have delivered into j, so j's issue is
/// at least the EDF bound of those ancestors with releases `head[a]` and tails `d(a, j)`, the
/// longest path from a's issue to j's issue (edge weight `w(p, c)`). `edges_in[x as usize]` are the
/// nodes x depends on in this direction. Stops tightening when `budget` ancestor visits are
/// spent.
fn tighten(
    dag: &Dag,
    arch: &PeArray,
    order: &[u32],
    edges_in: &[Vec<u32>],
    w: &dyn Fn(u32, u32) -> u32,
    head: &mut [u32],
    budget: &mut u64,
) {
    let n = dag.ops.len();
    let mut rank = vec![0u32; n];
    for (i, &x) in order.iter().enumerate() {
        rank[x as usize] = i as u32;
    }
    let mut dist = vec![0u32; n];
    let mut stamp = vec![u32::MAX; n];
    let mut anc: Vec<u32> = Vec::new();
    let mut stack: Vec<u32> = Vec::new();
    let mut jobs: [Vec<(u32, u32)>; 2] = [Vec::new(), Vec::new()];
    for (step, &j) in order.iter().enumerate() {
        if edges_in[j as usize].is_empty() {
            continue;
        }
        // Collect the ancestors of j.
        anc.clear();
        stack.clear();
        stack.push(j);
        stamp[j as usize] = step as u32;
        while let Some(x) = stack.pop() {
            for &p in &edges_in[x as usize] {
                if stamp[p as usize] != step as u32 {
                    stamp[p as usize] = step as u32;
                    dist[p as usize] = 0;
                    anc.push(p);
                    stack.push(p);
                }
            }
        }
        if *budget < anc.len() as u64 {
            return;
        }
        *budget -= anc.len() as u64;
        // Longest paths to j, ancestors taken latest first.
        anc.sort_unstable_by_key(|&a| Reverse(rank[a as usize]));
        for &p in &edges_in[j as usize] {
            dist[p as usize] = dist[p as usize].max(w(p, j));
        }
        for &x in &anc {
            let dx = dist[x as usize];
            for &p in &edges_in[x as usize] {
                dist[p as usize] = dist[p as usize].max(dx + w(p, x));
            }
        }
        jobs[0].clear();
        jobs[1].clear();
        for &a in &anc {
            jobs[dag.mul[a as usize] as usize].push((head[a as usize], dist[a as usize]));
        }
        let pes = [arch.n_add, arch.n_mul];
        for side in 0..2 {
            head[j as usize] = head[j as usize].max(edf_bound(&mut jobs[side], pes[side]));
        }
    }
}

/// A lower bound at least as tight as [`lower_bound`]: per PE type, the exact optimum of the
/// one-type relaxation ([`edf_bound`]) with heads (earliest issue) and tails (latency plus the
/// longest path after the result) tightened through both PE types (see the module doc).
///
/// Valid: in any placement, an op issues no earlier than its head, and at least its tail
/// remains after its issue; the relaxation drops only constraints. Cost: O(n log n) plus the
/// bounded tightening (at most `TIGHTEN_BUDGET` = 10⁶ ancestor visits).
pub fn tight_lower_bound(f: &Function, arch: &PeArray) -> u32 {
    let Some((dag, head, rhead)) = heads_and_tails(f, arch) else { return 0 };
    let mut best = lower_bound(f, arch);
    let mut jobs: [Vec<(u32, u32)>; 2] = [Vec::new(), Vec::new()];
    for j in 0..dag.ops.len() {
        jobs[dag.mul[j] as usize].push((head[j], rhead[j] + 1));
        // A single op: its head, then its tail.
        best = best.max(head[j] + rhead[j] + 1);
    }
    best.max(edf_bound(&mut jobs[0], arch.n_add)).max(edf_bound(&mut jobs[1], arch.n_mul))
}

/// Tightened heads and tails per op, indexed by value index (`None` for non-ops): the head
/// is a lower bound on the op's issue cycle; the tail `ρ` says that at least `ρ + 1` cycles
/// remain from its issue to the end of any placement (its latency included). Both account for
/// the PEs of both types (see the module doc); list scheduling uses the tails as priorities.
pub fn tightened_heads_tails(f: &Function, arch: &PeArray) -> Vec<Option<(u32, u32)>> {
    let mut out = vec![None; f.values.len()];
    if let Some((dag, head, rhead)) = heads_and_tails(f, arch) {
        for (j, v) in dag.ops.iter().enumerate() {
            out[v.index()] = Some((head[j], rhead[j]));
        }
    }
    out
}

/// The DAG with tightened heads and reverse heads (`None` without ops).
fn heads_and_tails(f: &Function, arch: &PeArray) -> Option<(Dag, Vec<u32>, Vec<u32>)> {
    let dag = Dag::build(f, arch);
    let n = dag.ops.len();
    if n == 0 {
        return None;
    }
    let (timing, cp) = compute_timing(f, &arch.lat);
    let t = |j: usize| timing[dag.ops[j].index()].expect("op has timing");
    // Heads: earliest issue. Reverse heads: ρ_j = E − 1 − s_j ≥ lat_j + tail_j − 1.
    let mut head: Vec<u32> = (0..n).map(|j| t(j).asap_cycle - dag.lat[j]).collect();
    let mut rhead: Vec<u32> = (0..n).map(|j| dag.lat[j] + (cp.asap_cycle - t(j).alap_cycle) - 1).collect();
    let mut budget = TIGHTEN_BUDGET;
    let forward: Vec<u32> = (0..n as u32).collect();
    tighten(&dag, arch, &forward, &dag.preds, &|p, _| dag.lat[p as usize], &mut head, &mut budget);
    let backward: Vec<u32> = (0..n as u32).rev().collect();
    tighten(&dag, arch, &backward, &dag.succs, &|_, c| dag.lat[c as usize], &mut rhead, &mut budget);
    Some((dag, head, rhead))
}

#[cfg(test)]
mod tests {
    use super::edf_bound;

    #[test]
    fn edf_bound_by_hand() {
        // Three jobs released at 0 with tails 5, 5, 1 on one machine: best order 5, 5, 1 ends at
        // max(0 + 5, 1 + 5, 2 + 1) = 6.
        assert_eq!(edf_bound(&mut [(0, 5), (0, 1), (0, 5)], 1), 6);
        // Two machines: both long tails at cycle 0 → 5; the short one at 1 → 2.
        assert_eq!(edf_bound(&mut [(0, 5), (0, 1), (0, 5)], 2), 5);
        // Release gaps are skipped: (10, 1) ends at 11.
        assert_eq!(edf_bound(&mut [(0, 1), (10, 1)], 1), 11);
        // Four unit-tail jobs released at 0 on one machine: the last issues at 3, ends at 4.
        assert_eq!(edf_bound(&mut [(0, 1); 4], 1), 4);
        assert_eq!(edf_bound(&mut [], 3), 0);
    }
}
