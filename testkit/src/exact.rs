//! Exact minimum-makespan schedules of small DAGs (branch and bound): the optimal baseline the
//! list-scheduling placer is measured against (NOTES-anchors §6.2–§6.3: "a hand-written
//! branch-and-bound … for small DAGs", used in tests to measure the heuristic's gap).
//!
//! # Model (SPEC §5 without memories)
//! `n_add` ADD units run `add`/`sub`/`div`/`call`, `n_mul` MULTI units run `mul`. Units are
//! fully pipelined: each issues at most one op per cycle, whatever is in flight. An op may
//! issue at cycle `t` when every operand op has arrived (`issue + latency ≤ t`); inputs, trig
//! variables and constants are ready at 0. The makespan is the largest arrival `issue +
//! latency` (SPEC §4 "cycles"; 0 without ops). Memories, write ports and buffers are ignored, so
//! the optimum here is a lower bound on the cycles of any valid placement.
//!
//! # Algorithm
//! Depth-first branch and bound over cycles. A node is a decision cycle `t` with every op issued
//! so far issued before `t`; its children issue a set of ready ops at `t` and move to the next
//! cycle at which some op is ready.
//! - **Non-delay schedules suffice.** If a unit of a class is idle at `t` while an op of that
//!   class is ready, moving that op (issued later in an optimal schedule) to `t` keeps every
//!   constraint (its successors only see an earlier arrival) and the makespan. Hence each child
//!   issues exactly `min(units, ready)` ops of each class; which identical unit gets which op is
//!   irrelevant, so only the *set* is chosen.
//! - **Dominance (symmetry) pruning.** For ready ops `a`, `b` of one class with
//!   `succ(a) ⊆ succ(b)` and `lat(a) ≤ lat(b)`, swapping them (issue `b` now, `a` at `b`'s later
//!   cycle) keeps the schedule valid and the makespan; with ties broken by op index this is a
//!   strict partial order `b ≻ a`, and only sets closed upwards under it are tried (issuing `a`
//!   while leaving a ready `b ≻ a` is skipped). Ops with identical successors and latency are
//!   interchangeable, and sinks go after ops that feed something. Applied cycle by cycle from `t`
//!   on, the two exchanges turn any optimal completion into one the search enumerates.
//! - **Transpositions.** The future of a node depends only on the set of issued ops and the
//!   arrivals, relative to `t`, of those still in flight; a node whose state was already reached
//!   at an earlier or equal cycle is pruned (memo table).
//! - **Bound.** `max` of: arrivals already fixed; the critical path `est(o) + tail(o)` of every
//!   unissued op (`est` = earliest issue given the issues so far, `tail` = latency-weighted
//!   height including the op's own latency); and, per class and per release `r`, the resource
//!   bound `r + ⌊j / units⌋ + tail_j` over the unissued ops with `est ≥ r`, tails sorted in
//!   decreasing order (the best any assignment of those ops to `units` issue slots per cycle from
//!   `r` can do; with `r = t` and the smallest tail it is SPEC §4's
//!   `⌈remaining / N⌉ − 1 + lat + t`). A node whose bound reaches the incumbent is cut.
//! - **Incumbent.** The list schedule of [`height_list_cycles`] (largest tail first); the search
//!   stops early when it meets the root bound.
//!
//! # Complexity
//! Exponential in the worst case: a node has up to `∏_class C(ready, min(units, ready))`
//! children. Each node costs O(ops² + edges) (the resource bound). `node_limit` caps the nodes
//! visited. Measured (release): DAGs of 10–30 ops with 1–3 units of each class need at most a
//! few hundred nodes (most are settled at the root, list schedule = bound); random layered DAGs
//! of 40–100 ops need ≤ 35k nodes for N ≥ 2, and with N = 1 ≤ 1.4M nodes (≈ 10 µs each) for
//! 298 of 300, the other 2 exceeding 2M.

use std::collections::HashMap;

use robovec_ir::analysis::Latencies;
use robovec_ir::{Function, OpKind, Value};

const NONE: u32 = u32::MAX;

/// The ops of a function as a DAG: op `i` is the `i`-th op of the body (topological order).
#[derive(Clone, Debug)]
struct Dag {
    /// The function value of each op.
    values: Vec<Value>,
    /// 0 = ADD unit, 1 = MULTI unit.
    class: Vec<usize>,
    /// Latency, cycles.
    lat: Vec<u32>,
    /// Distinct operand ops.
    preds: Vec<Vec<u32>>,
    /// Distinct user ops, increasing.
    succs: Vec<Vec<u32>>,
    /// Latency-weighted height including the op's own latency, cycles.
    tail: Vec<u32>,
}

impl Dag {
    fn new(f: &Function, lat: &Latencies) -> Dag {
        let mut index = vec![NONE; f.values.len()];
        let mut d = Dag { values: vec![], class: vec![], lat: vec![], preds: vec![], succs: vec![], tail: vec![] };
        for &v in &f.body {
            let Some(kind) = f.op_kind(v) else { continue };
            let i = d.values.len() as u32;
            index[v.index()] = i;
            let mut preds = Vec::new();
            f.value(v).def.for_each_value(|p| {
                let j = index[p.index()];
                if j != NONE && !preds.contains(&j) {
                    preds.push(j);
                }
            });
            d.values.push(v);
            d.class.push(usize::from(kind == OpKind::Mul));
            d.lat.push(lat.of(kind));
            d.preds.push(preds);
            d.succs.push(Vec::new());
        }
        for i in 0..d.len() {
            for k in 0..d.preds[i].len() {
                let p = d.preds[i][k] as usize;
                d.succs[p].push(i as u32);
            }
        }
        d.tail = vec![0; d.len()];
        for i in (0..d.len()).rev() {
            d.tail[i] = d.lat[i] + d.succs[i].iter().map(|&s| d.tail[s as usize]).max().unwrap_or(0);
        }
        d
    }

    fn len(&self) -> usize {
        self.values.len()
    }

    /// `b ≻ a`: issuing `b` before `a` is never worse (see the module doc).
    fn dominates(&self, b: usize, a: usize) -> bool {
        let sub = |x: usize, y: usize| {
            self.lat[x] <= self.lat[y] && self.succs[x].iter().all(|s| self.succs[y].binary_search(s).is_ok())
        };
        self.class[a] == self.class[b] && a != b && sub(a, b) && (!sub(b, a) || b < a)
    }
}

/// An optimal schedule found by [`solve`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Solution {
    /// Minimum makespan, cycles.
    pub cycles: u32,
    /// Issue cycle of every op, indexed by `Value::index()` (`None` for non-ops).
    pub issue: Vec<Option<u32>>,
    /// Search nodes visited (decision cycles), ops-independent count.
    pub nodes: u64,
}

/// The minimum makespan (cycles) of `f` on `n_add` ADD and `n_mul` MULTI units with latencies
/// `lat`, or `None` when the search visited more than `node_limit` nodes before proving
/// optimality. `f` must be atomised and verify; a class with ops needs at least one unit.
pub fn optimal_cycles(f: &Function, n_add: u32, n_mul: u32, lat: &Latencies, node_limit: u64) -> Option<u32> {
    solve(f, n_add, n_mul, lat, node_limit).map(|s| s.cycles)
}

/// Like [`optimal_cycles`], with an optimal schedule and the search effort.
pub fn solve(f: &Function, n_add: u32, n_mul: u32, lat: &Latencies, node_limit: u64) -> Option<Solution> {
    let dag = Dag::new(f, lat);
    let (cycles, issue_by_op, nodes) = branch_and_bound(&dag, [n_add, n_mul], node_limit, true)?;
    let mut issue = vec![None; f.values.len()];
    for (i, &v) in dag.values.iter().enumerate() {
        issue[v.index()] = Some(issue_by_op[i]);
    }
    Some(Solution { cycles, issue, nodes })
}

/// The search on `dag`: (makespan, issue cycle per op, nodes), `None` past `node_limit`.
/// `incumbent = false` starts without the list schedule (tests use it to exercise the search).
fn branch_and_bound(dag: &Dag, units: [u32; 2], node_limit: u64, incumbent: bool) -> Option<(u32, Vec<u32>, u64)> {
    for (c, name) in [(0, "ADD"), (1, "MULTI")] {
        assert!(units[c] > 0 || !dag.class.contains(&c), "exact: ops need {name} units but there are none");
    }
    let n = dag.len();
    let (best, best_issue) = if incumbent || n == 0 { list_schedule(dag, units, false) } else { (u32::MAX, vec![]) };
    let dominators = (0..n).map(|a| (0..n).filter(|&b| dag.dominates(b, a)).map(|b| b as u32).collect()).collect();
    let mut s = Search {
        dag,
        units,
        dominators,
        issue: vec![NONE; n],
        remaining: n,
        best,
        best_issue,
        root_lb: 0,
        nodes: 0,
        limit: node_limit,
        aborted: false,
        memo: HashMap::new(),
    };
    s.root_lb = s.lower_bound(0);
    if n > 0 && s.root_lb < s.best {
        s.dfs(0);
    }
    if s.aborted {
        return None;
    }
    Some((s.best, s.best_issue, s.nodes))
}

/// Makespan (cycles) of the non-delay list schedule that issues, each cycle and per class, the
/// ready ops of largest latency-weighted height first (ties: body order) — the search's first
/// incumbent, and the classical "highest level first" heuristic without memories.
pub fn height_list_cycles(f: &Function, n_add: u32, n_mul: u32, lat: &Latencies) -> u32 {
    list_schedule(&Dag::new(f, lat), [n_add, n_mul], false).0
}

/// Greedy non-delay list schedule by decreasing tail, ties by body order (`late_first`: reverse
/// body order): (makespan, issue cycles).
fn list_schedule(d: &Dag, units: [u32; 2], late_first: bool) -> (u32, Vec<u32>) {
    let n = d.len();
    let mut issue = vec![NONE; n];
    let mut left = n;
    let mut t = 0;
    let mut makespan = 0;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(d.tail[i]), if late_first { n - i } else { i }));
    while left > 0 {
        let mut used = [0u32; 2];
        for &i in &order {
            let c = d.class[i];
            if issue[i] == NONE && used[c] < units[c] && ready_at(d, &issue, i) <= t {
                issue[i] = t;
                used[c] += 1;
                left -= 1;
                makespan = makespan.max(t + d.lat[i]);
            }
        }
        t += 1;
    }
    (makespan, issue)
}

/// Earliest cycle `i` can issue given the issued ops (`NONE` if a predecessor is unissued).
fn ready_at(d: &Dag, issue: &[u32], i: usize) -> u32 {
    let mut r = 0;
    for &p in &d.preds[i] {
        let p = p as usize;
        if issue[p] == NONE {
            return NONE;
        }
        r = r.max(issue[p] + d.lat[p]);
    }
    r
}

struct Search<'a> {
    dag: &'a Dag,
    units: [u32; 2],
    /// Ops `b ≻ a`, for each `a`.
    dominators: Vec<Vec<u32>>,
    issue: Vec<u32>,
    remaining: usize,
    best: u32,
    best_issue: Vec<u32>,
    root_lb: u32,
    nodes: u64,
    limit: u64,
    aborted: bool,
    /// State → earliest decision cycle it was reached at.
    memo: HashMap<Vec<u64>, u32>,
}

/// Largest memo table kept (entries); past it states are no longer recorded.
const MEMO_CAP: usize = 1 << 21;

impl Search<'_> {
    fn dfs(&mut self, t: u32) {
        self.nodes += 1;
        if self.nodes > self.limit {
            self.aborted = true;
            return;
        }
        let d = self.dag;
        if self.remaining == 0 {
            let ms = (0..d.len()).map(|i| self.issue[i] + d.lat[i]).max().unwrap_or(0);
            if ms < self.best {
                self.best = ms;
                self.best_issue.clone_from(&self.issue);
            }
            return;
        }
        if self.lower_bound(t) >= self.best {
            return;
        }
        let key = self.state_key(t);
        let full = self.memo.len() >= MEMO_CAP;
        match self.memo.get_mut(&key) {
            Some(seen) if *seen <= t => return,
            Some(seen) => *seen = t,
            None if !full => {
                self.memo.insert(key, t);
            }
            None => {}
        }
        let mut ready: [Vec<usize>; 2] = [vec![], vec![]];
        for i in 0..d.len() {
            if self.issue[i] == NONE && ready_at(d, &self.issue, i) <= t {
                ready[d.class[i]].push(i);
            }
        }
        let sets = [self.choices(&mut ready[0], 0), self.choices(&mut ready[1], 1)];
        for a in &sets[0] {
            for m in &sets[1] {
                for &i in a.iter().chain(m) {
                    self.issue[i] = t;
                }
                self.remaining -= a.len() + m.len();
                let next = if self.remaining == 0 { t + 1 } else { self.next_cycle(t) };
                self.dfs(next);
                self.remaining += a.len() + m.len();
                for &i in a.iter().chain(m) {
                    self.issue[i] = NONE;
                }
                if self.aborted || self.best <= self.root_lb {
                    return;
                }
            }
        }
    }

    /// The sets of `min(units, ready)` ready ops of class `c` closed upwards under `≻`, best
    /// first (ready ops sorted by decreasing tail, sets in lexicographic order).
    fn choices(&self, ready: &mut [usize], c: usize) -> Vec<Vec<usize>> {
        let d = self.dag;
        ready.sort_by_key(|&i| (std::cmp::Reverse(d.tail[i]), i));
        let k = (self.units[c] as usize).min(ready.len());
        let mut out = Vec::new();
        let mut idx: Vec<usize> = (0..k).collect();
        loop {
            let set: Vec<usize> = idx.iter().map(|&j| ready[j]).collect();
            let closed = set.iter().all(|&a| {
                self.dominators[a].iter().all(|&b| set.contains(&(b as usize)) || !ready.contains(&(b as usize)))
            });
            if closed {
                out.push(set);
            }
            // Next k-combination of 0..ready.len().
            let Some(p) = (0..k).rev().find(|&p| idx[p] < ready.len() - k + p) else { break };
            idx[p] += 1;
            for q in p + 1..k {
                idx[q] = idx[q - 1] + 1;
            }
        }
        out
    }

    /// The next cycle after `t` at which an unissued op is ready (some remain).
    fn next_cycle(&self, t: u32) -> u32 {
        (0..self.dag.len())
            .filter(|&i| self.issue[i] == NONE)
            .map(|i| ready_at(self.dag, &self.issue, i))
            .filter(|&r| r != NONE)
            .map(|r| r.max(t + 1))
            .min()
            .expect("an unissued op has all predecessors issued")
    }

    /// Issued set and in-flight arrivals relative to `t`.
    fn state_key(&self, t: u32) -> Vec<u64> {
        let n = self.dag.len();
        let mut key = vec![0u64; n.div_ceil(64)];
        for i in 0..n {
            if self.issue[i] != NONE {
                key[i / 64] |= 1 << (i % 64);
                let arrival = self.issue[i] + self.dag.lat[i];
                if arrival > t {
                    key.push(((i as u64) << 32) | u64::from(arrival - t));
                }
            }
        }
        key
    }

    /// A lower bound on the makespan of every completion of the current node (see module doc).
    fn lower_bound(&self, t: u32) -> u32 {
        let d = self.dag;
        let n = d.len();
        let mut lb = 0;
        let mut est = vec![0u32; n];
        let mut items: [Vec<(u32, u32)>; 2] = [vec![], vec![]];
        for i in 0..n {
            if self.issue[i] != NONE {
                lb = lb.max(self.issue[i] + d.lat[i]);
                continue;
            }
            let mut e = t;
            for &p in &d.preds[i] {
                let p = p as usize;
                let a = if self.issue[p] != NONE { self.issue[p] } else { est[p] } + d.lat[p];
                e = e.max(a);
            }
            est[i] = e;
            lb = lb.max(e + d.tail[i]);
            items[d.class[i]].push((e, d.tail[i]));
        }
        for c in 0..2 {
            let units = self.units[c].max(1);
            let items = &mut items[c];
            items.sort_unstable_by(|x, y| y.cmp(x)); // release decreasing
            let mut tails: Vec<u32> = Vec::with_capacity(items.len()); // decreasing
            let mut k = 0;
            while k < items.len() {
                let r = items[k].0;
                while k < items.len() && items[k].0 == r {
                    let q = items[k].1;
                    let pos = tails.partition_point(|&x| x >= q);
                    tails.insert(pos, q);
                    k += 1;
                }
                for (j, &q) in tails.iter().enumerate() {
                    lb = lb.max(r + j as u32 / units + q);
                }
            }
        }
        lb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::rng::SplitMix64;
    use robovec_ir::{BinOp, Def, Operand, Phase, Span};

    const LAT: Latencies = Latencies { add: 12, mul: 7, div: 12, call: 12 };

    /// A function from `(op, a, b)` triples: operand `k ≥ 0` is op `k`, `-1 - j` is input `x{j}`.
    fn func(spec: &[(BinOp, i32, i32)]) -> Function {
        let mut f = Function::new("t", Phase::Atomised);
        let inputs: Vec<Value> = (0..4).map(|j| f.add_input(format!("x{j}"), Span::DUMMY).unwrap()).collect();
        let mut ops: Vec<Value> = Vec::new();
        for (k, &(op, a, b)) in spec.iter().enumerate() {
            let o = |x: i32| Operand::Value(if x >= 0 { ops[x as usize] } else { inputs[(-1 - x) as usize] });
            let v = f.define(format!("o{k}"), Def::Binary(op, o(a), o(b)), Span::DUMMY).unwrap();
            ops.push(v);
        }
        f.set_output("y", Operand::Value(*ops.last().unwrap_or(&inputs[0])), Span::DUMMY);
        f
    }

    /// A random DAG of `m` ops: kinds add/sub/mul/div, operands an earlier op (60 %) or an input.
    fn random_function(rng: &mut SplitMix64, m: usize) -> Function {
        let kinds = [BinOp::Add, BinOp::Sub, BinOp::Mul, BinOp::Mul, BinOp::Div];
        let spec: Vec<(BinOp, i32, i32)> = (0..m)
            .map(|k| {
                let n_kinds = if rng.chance(100) { 5 } else { 4 };
                let kind = kinds[rng.below(n_kinds) as usize];
                let mut pick = || {
                    if k > 0 && rng.chance(600) {
                        rng.below(k as u64) as i32
                    } else {
                        -1 - rng.below(4) as i32
                    }
                };
                (kind, pick(), pick())
            })
            .collect();
        func(&spec)
    }

    fn opt(f: &Function, n_add: u32, n_mul: u32) -> u32 {
        optimal_cycles(f, n_add, n_mul, &LAT, 10_000_000).expect("within the node limit")
    }

    /// Checks that `s` is a valid schedule of `f` with makespan `s.cycles`.
    fn check_schedule(f: &Function, n_add: u32, n_mul: u32, lat: &Latencies, s: &Solution) {
        let mut per_cycle: HashMap<(u32, bool), u32> = HashMap::new();
        let mut makespan = 0;
        for &v in &f.body {
            let Some(kind) = f.op_kind(v) else { continue };
            let t = s.issue[v.index()].expect("every op issues");
            f.value(v).def.for_each_value(|p| {
                if let Some(k) = f.op_kind(p) {
                    assert!(s.issue[p.index()].unwrap() + lat.of(k) <= t, "operand not arrived");
                }
            });
            let slot = per_cycle.entry((t, kind == OpKind::Mul)).or_default();
            *slot += 1;
            assert!(*slot <= if kind == OpKind::Mul { n_mul } else { n_add }, "too many issues at {t}");
            makespan = makespan.max(t + lat.of(kind));
        }
        assert_eq!(makespan, s.cycles);
    }

    /// Issued mask and in-flight (op, cycles to arrival) → relative makespan.
    type Memo = HashMap<(u64, Vec<(usize, u32)>), u32>;

    /// Minimum makespan by exhaustive dynamic programming over all schedules (`non_delay`:
    /// only those issuing `min(units, ready)` ops of each class every cycle), without bounds
    /// or dominance. States: issued set + in-flight (op, cycles to arrival); value: makespan
    /// relative to the state's cycle. ≤ 64 ops.
    fn exhaustive(d: &Dag, units: [u32; 2], non_delay: bool) -> u32 {
        fn go(d: &Dag, units: [u32; 2], non_delay: bool, mask: u64, flight: Vec<(usize, u32)>, memo: &mut Memo) -> u32 {
            let all = if d.len() == 64 { u64::MAX } else { (1u64 << d.len()) - 1 };
            if mask == all {
                return flight.iter().map(|x| x.1).max().unwrap_or(0);
            }
            if let Some(&v) = memo.get(&(mask, flight.clone())) {
                return v;
            }
            let mut ready: [Vec<usize>; 2] = [vec![], vec![]];
            for i in 0..d.len() {
                let done = |p: &u32| mask >> p & 1 == 1 && !flight.iter().any(|x| x.0 == *p as usize);
                if mask >> i & 1 == 0 && d.preds[i].iter().all(done) {
                    ready[d.class[i]].push(i);
                }
            }
            let subsets = |c: usize| -> Vec<Vec<usize>> {
                let r = &ready[c];
                let k = (units[c] as usize).min(r.len());
                (0u32..1 << r.len())
                    .filter(|b| b.count_ones() as usize <= k && (!non_delay || b.count_ones() as usize == k))
                    .map(|b| (0..r.len()).filter(|j| b >> j & 1 == 1).map(|j| r[j]).collect())
                    .collect()
            };
            let mut best = u32::MAX;
            for a in subsets(0) {
                for m in subsets(1) {
                    if a.is_empty() && m.is_empty() && flight.is_empty() {
                        continue; // waiting with nothing in flight only shifts the schedule
                    }
                    let mut mask2 = mask;
                    let mut fl = flight.clone();
                    for &i in a.iter().chain(&m) {
                        mask2 |= 1 << i;
                        fl.push((i, d.lat[i]));
                    }
                    let v = if mask2 == all {
                        fl.iter().map(|x| x.1).max().unwrap_or(0)
                    } else {
                        let mut next: Vec<(usize, u32)> =
                            fl.iter().filter(|x| x.1 > 1).map(|&(i, o)| (i, o - 1)).collect();
                        next.sort_unstable();
                        1 + go(d, units, non_delay, mask2, next, memo)
                    };
                    best = best.min(v);
                }
            }
            memo.insert((mask, flight), best);
            best
        }
        go(d, units, non_delay, 0, vec![], &mut HashMap::new())
    }

    #[test]
    fn hand_computed_optima() {
        use BinOp::*;
        // No ops: 0 cycles.
        assert_eq!(opt(&func(&[]), 1, 1), 0);
        // A lone add: 12 cycles (SPEC §4).
        assert_eq!(opt(&func(&[(Add, -1, -2)]), 1, 1), 12);
        // 4 independent adds on 1 ADD unit: issues 0..3, last arrival 3 + 12.
        let four = func(&[(Add, -1, -2), (Add, -1, -3), (Sub, -2, -3), (Add, -3, -4)]);
        assert_eq!(opt(&four, 1, 1), 15);
        assert_eq!(opt(&four, 2, 1), 13);
        assert_eq!(opt(&four, 4, 1), 12);
        // A chain mul → add: 7 + 12.
        assert_eq!(opt(&func(&[(Mul, -1, -2), (Add, 0, -3)]), 1, 1), 19);
        // Two products summed: muls at 0 and 1 on one MULTI unit, add at 8: 20; with 2 units 19.
        let dot = func(&[(Mul, -1, -2), (Mul, -3, -4), (Add, 0, 1)]);
        assert_eq!(opt(&dot, 1, 1), 20);
        assert_eq!(opt(&dot, 1, 2), 19);
    }

    #[test]
    fn greedy_by_height_is_not_always_optimal() {
        use BinOp::*;
        // One ADD unit. A = o0 heads a chain of 3 muls (tail 12 + 21 = 33); B = o1 feeds 11 adds
        // (tail 24). Highest tail first issues A at 0 and B at 1: B's adds issue at 13..23 and
        // arrive at 35. Issuing B first delays A's chain by one cycle (34) but the adds finish
        // at 34. Heights are distinct where it matters (the 11 adds are interchangeable), so no
        // tie-break rescues the greedy.
        let mut spec = vec![(Add, -1, -2), (Add, -2, -3)];
        spec.extend((0..11).map(|i| (Add, 1, -1 - (i % 4))));
        spec.extend([(Mul, 0, -1), (Mul, 13, -2), (Mul, 14, -3)]);
        let f = func(&spec);
        assert_eq!(height_list_cycles(&f, 1, 1, &LAT), 35);
        assert_eq!(list_schedule(&Dag::new(&f, &LAT), [1, 1], true).0, 35);
        let s = solve(&f, 1, 1, &LAT, 1_000_000).unwrap();
        assert_eq!(s.cycles, 34);
        assert_eq!(s.issue[f.lookup("o1").unwrap().index()], Some(0));
        // The tie case found by random search: three adds with equal tails (19) right after a
        // mul; the optimum first issues the one with three successors, highest-tail-first with
        // either body-order tie-break does not.
        let f = func(&[(Mul, -1, -2), (Add, -2, 0), (Add, -2, 0), (Mul, 2, 1), (Add, 0, 0), (Mul, 2, -3), (Mul, 2, 4)]);
        assert_eq!(height_list_cycles(&f, 1, 1, &LAT), 29);
        assert_eq!(list_schedule(&Dag::new(&f, &LAT), [1, 1], true).0, 29);
        assert_eq!(opt(&f, 1, 1), 28);
    }

    #[test]
    fn schedules_are_valid_and_match_the_lower_bounds() {
        let mut rng = SplitMix64::new(11);
        for _ in 0..60 {
            let m = 5 + rng.below(20) as usize;
            let f = random_function(&mut rng, m);
            for n in 1..=3 {
                let s = solve(&f, n, n, &LAT, 10_000_000).expect("within the node limit");
                check_schedule(&f, n, n, &LAT, &s);
                assert!(s.cycles <= height_list_cycles(&f, n, n, &LAT));
                let (_, t) = robovec_ir::analysis::compute_timing(&f, &LAT);
                assert!(s.cycles >= t.asap_cycle);
            }
        }
    }

    #[test]
    fn matches_exhaustive_search_on_small_dags() {
        let mut rng = SplitMix64::new(5);
        let lats = [LAT, Latencies { add: 3, mul: 2, div: 4, call: 3 }, Latencies { add: 1, mul: 2, div: 1, call: 1 }];
        for case in 0..150 {
            let m = 1 + rng.below(8) as usize;
            let f = random_function(&mut rng, m);
            let lat = lats[case % lats.len()];
            let d = Dag::new(&f, &lat);
            for units in [[1, 1], [2, 1], [1, 2], [2, 2], [3, 3]] {
                let bb = solve(&f, units[0], units[1], &lat, 10_000_000).unwrap();
                check_schedule(&f, units[0], units[1], &lat, &bb);
                let nd = exhaustive(&d, units, true);
                assert_eq!(bb.cycles, nd, "case {case} units {units:?}: b&b vs all non-delay schedules");
                let raw = branch_and_bound(&d, units, 10_000_000, false).unwrap();
                assert_eq!(raw.0, nd, "case {case} units {units:?}: b&b without the list-schedule incumbent");
                if m <= 6 {
                    let any = exhaustive(&d, units, false);
                    assert_eq!(nd, any, "case {case} units {units:?}: non-delay vs all schedules");
                }
            }
        }
    }

    #[test]
    fn node_limit_gives_up() {
        let mut rng = SplitMix64::new(1);
        let f = (0..200)
            .map(|_| random_function(&mut rng, 30))
            .find(|f| solve(f, 1, 1, &LAT, 10_000_000).unwrap().nodes > 1)
            .expect("some DAG that needs a search");
        assert_eq!(optimal_cycles(&f, 1, 1, &LAT, 1), None);
    }
}
