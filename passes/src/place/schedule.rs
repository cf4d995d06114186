//! List scheduling with operand routing (seed §2.3; SPEC §5): cycle by cycle, ready ops in
//! priority order are assigned to a free PE of their type (of their PE cluster with
//! `place<clusters=G>`, [`super::cluster`]: one ready list per cluster and side) on which both
//! operands can be in the PE memory at the issue cycle — already there, written directly at the
//! operand's arrival, or written later from the producer's buffer.
//!
//! Ready rule: an op is ready at cycle `t` when every operand op has arrived (`issue + latency
//! ≤ t`). Writes are booked when the consumer is placed, at the producer's arrival cycle `a`
//! (direct) or at the earliest cycle `b ∈ [a, t]` at which the producer's buffer can be read
//! and the target memory has a free write port (indirect) — the seed's "placed on hold until we
//! find a cycle where we have an empty writing slot". Bookings are decided at compile time, so a
//! booking in a past cycle is legal as long as that cycle's ports are still free.
//!
//! Cost: each op enters and leaves the ready list ([`ReadyQueue`]) once (plus rare deferrals),
//! and each placement tries at most the free PEs of its type: O(n log n + n·N) for n ops and N
//! PEs per type; idle cycles are skipped. Every per-op array is indexed by [`Node`] (see
//! [`OpDag`]: with nodes in priority order, the ops taken one after the other are neighbours in
//! memory).

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use robovec_ir::analysis::compute_timing;
use robovec_ir::placement::{Pe, PeArray};
use robovec_ir::{Function, Operand, Value};

use super::cluster::pes_in;
use super::dag::{Key, Node, OpDag, NO_NODE};
use super::feed::Feed;
use super::ready::ReadyQueue;
use super::{Priority, Select};
use robovec_ir::analysis::Latencies;

/// How an operand reaches the PE memory that reads it (seed §2.3, Table 2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Route {
    /// Already in the memory (initial data, or written for an earlier consumer).
    Pe,
    /// Written directly at the producer's arrival cycle.
    Direct,
    /// Written from the producer's buffer at the given cycle.
    Indirect(u32),
}

/// Preference of seed Table 2.1 (1 best … 9 worst) for the routes of the left and right operand.
pub fn preference(left: Route, right: Route) -> u32 {
    let r = |x: Route| match x {
        Route::Pe => 0,
        Route::Direct => 1,
        Route::Indirect(_) => 2,
    };
    const TABLE: [[u32; 3]; 3] = [[1, 2, 5], [3, 4, 7], [6, 8, 9]];
    TABLE[r(left)][r(right)]
}

/// A booked write of an op's result into a PE memory.
#[derive(Clone, Copy, Debug)]
pub struct Booking {
    /// Producer op.
    pub node: Node,
    /// Target memory (PE slot).
    pub target: usize,
    /// Write cycle.
    pub cycle: u32,
    /// True when it goes through the producer's buffer.
    pub indirect: bool,
}

/// The schedule: issues and bookings (addresses come later, see `memory.rs`), indexed by
/// [`Node`] of the [`OpDag`] it was made with.
pub struct Schedule {
    /// `(pe slot, issue cycle)` per node.
    pub issue: Vec<(u32, u32)>,
    /// Arrival cycle (issue + latency) per node.
    pub arrival: Vec<u32>,
    /// Every write booked, in booking order.
    pub bookings: Vec<Booking>,
}

/// Per-cycle port usage, grown on demand.
struct Ports {
    /// `writes[slot][cycle]`: writes booked into that PE memory in that cycle.
    writes: Vec<Vec<u8>>,
    /// `buffer_read[slot][cycle]`: node + 1 read from that PE's buffer in that cycle (0 = free).
    buffer_read: Vec<Vec<u32>>,
}

impl Ports {
    fn writes_at(&self, slot: usize, c: u32) -> u8 {
        self.writes[slot].get(c as usize).copied().unwrap_or(0)
    }
    fn buffer_at(&self, slot: usize, c: u32) -> u32 {
        self.buffer_read[slot].get(c as usize).copied().unwrap_or(0)
    }
    fn add_write(&mut self, slot: usize, c: u32) {
        let v = &mut self.writes[slot];
        if v.len() <= c as usize {
            v.resize(c as usize + 1, 0);
        }
        v[c as usize] += 1;
    }
    fn set_buffer(&mut self, slot: usize, c: u32, j: Node) {
        let v = &mut self.buffer_read[slot];
        if v.len() <= c as usize {
            v.resize(c as usize + 1, 0);
        }
        v[c as usize] = j + 1;
    }
}

/// The PE memories each node's result has been written into: four inline per node (8 bytes,
/// beside its neighbours'; most results go to one to three memories), the rest in a side table.
struct Located {
    inline: Vec<[u16; 4]>,
    more: HashMap<Node, Vec<usize>>,
}

impl Located {
    const EMPTY: u16 = u16::MAX;

    fn new(n: usize) -> Located {
        Located { inline: vec![[Self::EMPTY; 4]; n], more: HashMap::new() }
    }

    fn contains(&self, j: Node, q: usize) -> bool {
        let row = &self.inline[j as usize];
        row.contains(&(q as u16)) || (row[3] != Self::EMPTY && self.more.get(&j).is_some_and(|m| m.contains(&q)))
    }

    fn push(&mut self, j: Node, q: usize) {
        let row = &mut self.inline[j as usize];
        match row.iter_mut().find(|s| **s == Self::EMPTY) {
            Some(s) => *s = q as u16,
            None => self.more.entry(j).or_default().push(q),
        }
    }
}

/// Issue cycle of a node not issued yet.
const UNISSUED: u32 = u32::MAX;

struct Ctx<'a> {
    arch: &'a PeArray,
    /// `(pe slot, issue cycle)` per node, cycle [`UNISSUED`] before.
    issue: Vec<(u32, u32)>,
    arrival: Vec<u32>,
    located: Located,
    ports: Ports,
    bookings: Vec<Booking>,
    /// `routed[q · 2n + s]`: source `s` (PE `p`'s result `p`, its buffer read `n + p`) is
    /// already written into memory `q` ([`Select::Routes`]).
    routed: Vec<bool>,
}

/// Writes and buffer reads that earlier operands of the same op plan, not yet booked.
#[derive(Default)]
struct Planned {
    /// Write cycles into the target memory.
    writes: Vec<u32>,
    /// `(producer slot, cycle, node)` buffer reads.
    reads: Vec<(usize, u32, Node)>,
}

impl Ctx<'_> {
    fn issued(&self, j: Node) -> bool {
        self.issue[j as usize].1 != UNISSUED
    }

    /// Route of operand node `v` into memory `q` for an issue at `t`, on top of `planned`.
    fn route(&self, v: Node, q: usize, t: u32, planned: &Planned) -> Option<Route> {
        if self.located.contains(v, q) {
            return Some(Route::Pe);
        }
        let a = self.arrival[v as usize];
        let used =
            |c: u32| self.ports.writes_at(q, c) as u32 + planned.writes.iter().filter(|&&x| x == c).count() as u32;
        if used(a) < self.arch.writes {
            return Some(Route::Direct);
        }
        if !self.arch.buffer {
            return None;
        }
        let p = self.issue[v as usize].0 as usize;
        let tag = v + 1;
        let buffer_free = |b: u32| {
            let booked = self.ports.buffer_at(p, b);
            (booked == 0 || booked == tag) && planned.reads.iter().all(|&(pp, bb, w)| pp != p || bb != b || w == v)
        };
        (a..=t).find(|&b| used(b) < self.arch.writes && buffer_free(b)).map(Route::Indirect)
    }

    /// Routes of the operands `ops` (nodes, [`NO_NODE`] for initial data) of one op into `q`
    /// at `t`, written into `out`; false if one cannot get there. `planned` is scratch space.
    fn routes(&self, ops: &[Node], q: usize, t: u32, planned: &mut Planned, out: &mut Vec<Route>) -> bool {
        out.clear();
        planned.writes.clear();
        planned.reads.clear();
        for (i, &v) in ops.iter().enumerate() {
            if v == NO_NODE || ops[..i].contains(&v) {
                out.push(Route::Pe); // initial data (loaded), or the same value as an earlier operand
                continue;
            }
            let Some(r) = self.route(v, q, t, planned) else { return false };
            match r {
                Route::Direct => planned.writes.push(self.arrival[v as usize]),
                Route::Indirect(b) => {
                    planned.writes.push(b);
                    planned.reads.push((self.issue[v as usize].0 as usize, b, v));
                }
                Route::Pe => {}
            }
            out.push(r);
        }
        true
    }

    /// The interconnect source of a write by `route` of node `v` (`p` for PE `p`'s result, `n + p`
    /// for its buffer read), `None` for an operand already in the memory.
    fn source(&self, v: Node, route: Route) -> Option<usize> {
        let p = self.issue[v as usize].0 as usize;
        match route {
            Route::Pe => None,
            Route::Direct => Some(p),
            Route::Indirect(_) => Some(self.arch.n_pe() + p),
        }
    }

    /// Sources that `routes` of operands `ops` would add to memory `q`'s routes. It runs for
    /// every free PE of every op placed, so it allocates nothing: an op has a few operands,
    /// and a source counts once, at its first operand.
    fn new_routes(&self, ops: &[Node], routes: &[Route], q: usize) -> u32 {
        let n2 = 2 * self.arch.n_pe();
        let source = |i: usize| (ops[i] != NO_NODE).then(|| self.source(ops[i], routes[i])).flatten();
        let fresh = |i: usize| source(i).filter(|&s| !self.routed[q * n2 + s]);
        (0..ops.len().min(routes.len()))
            .filter(|&i| fresh(i).is_some_and(|s| (0..i).all(|j| source(j) != Some(s))))
            .count() as u32
    }

    fn commit(&mut self, ops: &[Node], routes: &[Route], q: usize) {
        for (&v, &r) in ops.iter().zip(routes) {
            if v == NO_NODE {
                continue;
            }
            let (cycle, indirect) = match r {
                Route::Pe => continue,
                Route::Direct => (self.arrival[v as usize], false),
                Route::Indirect(b) => (b, true),
            };
            if self.located.contains(v, q) {
                continue; // the same value twice in one op
            }
            if let Some(s) = self.source(v, r).filter(|_| !self.routed.is_empty()) {
                let n2 = 2 * self.arch.n_pe();
                self.routed[q * n2 + s] = true;
            }
            self.ports.add_write(q, cycle);
            if indirect {
                let p = self.issue[v as usize].0 as usize;
                self.ports.set_buffer(p, cycle, v);
            }
            self.located.push(v, q);
            self.bookings.push(Booking { node: v, target: q, cycle, indirect });
        }
    }
}

/// Priority keys of the seed's orders (smaller = scheduled first), indexed by value index.
pub fn seed_keys(f: &Function, arch: &PeArray, priority: Priority) -> Vec<Key> {
    let (timing, _) = compute_timing(f, &arch.lat);
    (0..f.values.len())
        .map(|i| match timing[i] {
            Some(t) => match priority {
                Priority::Classical => (t.alap_cycle, t.asap_cycle, i as u32),
                Priority::Mobility => (t.alap_cycle - t.asap_cycle, t.alap_cycle, i as u32),
            },
            None => (0, 0, i as u32),
        })
        .collect()
}

/// The ready lists for `keys`: per PE cluster of `dag` ([`OpDag::clusters`]), the ADD side's
/// and the MULTI side's.
fn ready_lists(dag: &OpDag, keys: &[Key]) -> Vec<[ReadyQueue; 2]> {
    let max_first = keys.iter().map(|k| k.0).max().unwrap_or(0);
    let cap = keys.len() + 1024;
    (0..dag.clusters()).map(|_| [ReadyQueue::new(max_first, cap), ReadyQueue::new(max_first, cap)]).collect()
}

/// The ready list of node `v`: its cluster's, its side's.
fn ready_of<'r>(ready: &'r mut [[ReadyQueue; 2]], dag: &OpDag, v: Node) -> &'r mut ReadyQueue {
    &mut ready[dag.cluster(v) as usize][dag.is_mul(v) as usize]
}

/// New interconnect routes (sources a PE memory did not receive yet) an op may add when it
/// leaves its cluster (`place<steal=S>`, with `select=routes`): one. Measured on the MX-5's
/// `dirdyna` at 72 + 72 PEs in 24 clusters, `steal=16`: no limit, 166 cycles and 2,058
/// multiplexer inputs; one, 160 and 1,643; none, 170 and 1,626 (no stealing: 176 and 1,535).
const STEAL_ROUTES: u32 = 1;

/// What issuing an op updates besides [`Ctx`]: the arrival queue and the feeding bonus.
struct Issued<'a, 'k> {
    arrivals: &'a mut BinaryHeap<Reverse<(u32, Node)>>,
    feed: &'a mut Feed<'k>,
    lowered: &'a mut Vec<(Key, Node)>,
}

impl Issued<'_, '_> {
    /// Issues node `v` on slot `q` at cycle `t`: its operands' `routes` committed (booked), its
    /// arrival queued, and the ready users whose keys the feeding bonus lowered re-queued.
    #[allow(clippy::too_many_arguments)]
    fn issue(
        &mut self,
        ctx: &mut Ctx<'_>,
        dag: &OpDag,
        v: Node,
        routes: &[Route],
        q: usize,
        t: u32,
        pending: &[u32],
        ready: &mut [[ReadyQueue; 2]],
    ) {
        ctx.commit(dag.operands_of(v), routes, q);
        let lat = ctx.arch.lat.of(dag.kind(v));
        ctx.issue[v as usize] = (q as u32, t);
        ctx.arrival[v as usize] = t + lat;
        self.arrivals.push(Reverse((t + lat, v)));
        self.feed.issued(dag, |u| ctx.issued(u), v, self.lowered);
        for (k, u) in self.lowered.drain(..) {
            if pending[u as usize] == 0 {
                ready_of(ready, dag, u).push(k, u);
            }
        }
    }
}

/// Schedules every op of `dag` on `arch`, ready ops taken in increasing `keys` order (indexed
/// by node; ties by node), with the feeding bonus `feed` in cycles (see [`Feed`]; 0 = the
/// seed's static order).
///
/// # Errors
/// Only without buffers: an op whose operand can no longer reach any PE memory of its type.
pub fn schedule(dag: &OpDag, arch: &PeArray, keys: &[Key], select: Select, feed: u32) -> Result<Schedule, String> {
    schedule_until(dag, arch, keys, select, feed, &|| false).map(|s| s.expect("never stopped"))
}

/// [`schedule`] that calls `stop` once per op taken from a ready list and once per cycle
/// (`-time-limit`, [`crate::Ticker::tick`]) and gives up when it says so: `Ok(None)`.
///
/// # Errors
/// As [`schedule`].
pub fn schedule_until(
    dag: &OpDag,
    arch: &PeArray,
    keys: &[Key],
    select: Select,
    feed: u32,
    stop: &dyn Fn() -> bool,
) -> Result<Option<Schedule>, String> {
    let n = dag.len();
    let mut feed = Feed::new(dag, keys, feed, false);
    let mut lowered = Vec::new();
    let mut pending = dag.n_distinct.clone();
    let mut ctx = Ctx {
        arch,
        issue: vec![(0, UNISSUED); n],
        arrival: vec![0; n],
        located: Located::new(n),
        ports: Ports { writes: vec![Vec::new(); arch.n_pe()], buffer_read: vec![Vec::new(); arch.n_pe()] },
        bookings: Vec::new(),
        routed: if select == Select::Routes { vec![false; 2 * arch.n_pe() * arch.n_pe()] } else { Vec::new() },
    };
    let mut ready = ready_lists(dag, keys);
    for v in 0..n as Node {
        if pending[v as usize] == 0 {
            ready_of(&mut ready, dag, v).push(feed.key[v as usize], v);
        }
    }
    let mut arrivals: BinaryHeap<Reverse<(u32, Node)>> = BinaryHeap::new();
    // PE slots per cluster and side (`cluster::pes_in`).
    let g = dag.clusters();
    let pes_of = |c: u32, mul: bool| -> Vec<usize> {
        if mul {
            pes_in(c, arch.n_mul, g).map(|i| Pe::Mul(i).slot(arch.n_add)).collect()
        } else {
            pes_in(c, arch.n_add, g).map(|i| Pe::Add(i).slot(arch.n_add)).collect()
        }
    };
    let pes: Vec<[Vec<usize>; 2]> = (0..g).map(|c| [pes_of(c, false), pes_of(c, true)]).collect();
    let (mut planned, mut routes, mut best_routes) = (Planned::default(), Vec::new(), Vec::new());
    let mut free: Vec<usize> = Vec::new();
    // each cluster's and side's PEs left idle in the current cycle (for `steal`)
    let mut idle: Vec<[Vec<usize>; 2]> = vec![[Vec::new(), Vec::new()]; g as usize];
    let mut deferred = Vec::new();
    let mut placed = 0usize;
    let mut t: u32 = 0;
    let mut stalled_since: Option<u32> = None;
    while placed < n {
        if stop() {
            return Ok(None);
        }
        while let Some(&Reverse((c, v))) = arrivals.peek() {
            if c > t {
                break;
            }
            arrivals.pop();
            for &u in dag.users_of(v) {
                pending[u as usize] -= 1;
                if pending[u as usize] == 0 {
                    ready_of(&mut ready, dag, u).push(feed.key[u as usize], u);
                }
            }
        }
        let mut progress = false;
        for (ty, c) in (0..2).flat_map(|ty| (0..g as usize).map(move |c| (ty, c))) {
            if pes[c][ty].is_empty() {
                continue;
            }
            free.clear();
            free.extend_from_slice(&pes[c][ty]);
            deferred.clear();
            while !free.is_empty() {
                if stop() {
                    return Ok(None);
                }
                let Some((k, v)) = ready[c][ty].pop() else { break };
                if k != feed.key[v as usize] || ctx.issued(v) {
                    continue; // stale entry (the key was lowered since)
                }
                let operands = dag.operands_of(v);
                let mut best: Option<(u32, usize)> = None;
                for (i, &q) in free.iter().enumerate() {
                    if !ctx.routes(operands, q, t, &mut planned, &mut routes) {
                        continue;
                    }
                    let table = || {
                        let at = |j: usize| routes.get(j).copied().unwrap_or(Route::Pe);
                        preference(at(0), at(1)) + routes.iter().skip(2).filter(|r| **r != Route::Pe).count() as u32
                    };
                    // Routes: Table 2.1 first, the new routes (at most one per operand) break ties.
                    let score = match select {
                        Select::Naive => 0,
                        Select::Preferential => table(),
                        Select::Routes => table() * 64 + ctx.new_routes(operands, &routes, q).min(63),
                    };
                    if best.is_none_or(|(s, _)| score < s) {
                        best = Some((score, i));
                        std::mem::swap(&mut routes, &mut best_routes);
                        let done = match select {
                            Select::Naive => true,
                            Select::Preferential => score <= 1,
                            Select::Routes => score <= 64,
                        };
                        if done {
                            break;
                        }
                    }
                }
                match best {
                    Some((_, i)) => {
                        let q = free.swap_remove(i);
                        let mut s = Issued { arrivals: &mut arrivals, feed: &mut feed, lowered: &mut lowered };
                        s.issue(&mut ctx, dag, v, &best_routes, q, t, &pending, &mut ready);
                        placed += 1;
                        progress = true;
                        free.sort_unstable();
                    }
                    None => deferred.push((k, v)),
                }
            }
            for (k, v) in deferred.drain(..) {
                ready[c][ty].push(k, v);
            }
            if dag.steal().is_some() {
                idle[c][ty].clone_from(&free);
            }
        }
        // Urgent ops of other clusters on the PEs their own clusters left idle (`steal`).
        if let Some(slack) = dag.steal() {
            for (ty, c) in (0..2).flat_map(|ty| (0..g as usize).map(move |c| (ty, c))) {
                let mut free = std::mem::take(&mut idle[c][ty]);
                for o in (1..g as usize).map(|d| (c + d) % g as usize) {
                    if free.is_empty() {
                        break;
                    }
                    deferred.clear();
                    while !free.is_empty() {
                        if stop() {
                            return Ok(None);
                        }
                        let Some((k, v)) = ready[o][ty].pop() else { break };
                        if k != feed.key[v as usize] || ctx.issued(v) {
                            continue; // stale entry
                        }
                        if k.0 > t.saturating_add(slack) {
                            deferred.push((k, v)); // the rest of that list is less urgent
                            break;
                        }
                        let operands = dag.operands_of(v);
                        let mut best: Option<(u32, usize)> = None;
                        for (i, &q) in free.iter().enumerate() {
                            if !ctx.routes(operands, q, t, &mut planned, &mut routes) {
                                continue;
                            }
                            let fresh = if select == Select::Routes { ctx.new_routes(operands, &routes, q) } else { 0 };
                            if fresh <= STEAL_ROUTES && best.is_none_or(|(s, _)| fresh < s) {
                                best = Some((fresh, i));
                                std::mem::swap(&mut routes, &mut best_routes);
                            }
                        }
                        match best {
                            Some((_, i)) => {
                                let q = free.swap_remove(i);
                                let mut s = Issued { arrivals: &mut arrivals, feed: &mut feed, lowered: &mut lowered };
                                s.issue(&mut ctx, dag, v, &best_routes, q, t, &pending, &mut ready);
                                placed += 1;
                                progress = true;
                            }
                            None => deferred.push((k, v)),
                        }
                    }
                    for (k, v) in deferred.drain(..) {
                        ready[o][ty].push(k, v);
                    }
                }
            }
        }
        if progress {
            stalled_since = None;
        } else if arrivals.is_empty() && stalled_since.is_none() {
            stalled_since = Some(t);
        }
        if let Some(s) = stalled_since {
            if t > s + 1 {
                return Err("no PE memory can receive an operand any more (without buffers a result can only be \
                            written at its arrival); use buffer=on or more write ports"
                    .into());
            }
        }
        // Next cycle; skip idle stretches when nothing is ready.
        t += 1;
        if ready.iter().flatten().all(ReadyQueue::is_empty) {
            if let Some(&Reverse((c, _))) = arrivals.peek() {
                t = t.max(c);
            }
        }
    }
    Ok(Some(Schedule { issue: ctx.issue, arrival: ctx.arrival, bookings: ctx.bookings }))
}

/// Constant or value read by an op, for load bookkeeping.
pub fn initial_operands(f: &Function, v: Value) -> Vec<Operand> {
    let mut out = Vec::new();
    match &f.value(v).def {
        robovec_ir::Def::Binary(_, a, b) => out.extend([*a, *b]),
        robovec_ir::Def::Call(_, args) => out.extend(args.iter().copied()),
        _ => {}
    }
    out.retain(|o| match o {
        Operand::Const(_) => true,
        Operand::Value(x) => f.op_kind(*x).is_none(),
    });
    out
}

/// Backward ("right-justified") list schedule in the pure resource model of SPEC §5 (PEs and
/// latencies, no memories): ops are issued in reverse time, an op as soon as all its users are,
/// taken in increasing `keys` order (indexed by node), each on its PE cluster's PEs of its side
/// ([`OpDag::clusters`]; one cluster: all `n_add` or `n_mul`). Returns each op's reverse issue cycle
/// `r` (`s = T − r` is a forward start of a schedule that ends together for every sink),
/// indexed by node.
///
/// Used by forward-backward improvement (Tormos & Lova 2001; "justification", Valls et al.
/// 2005): scheduling forward again in decreasing `r` order packs the resources better than
/// ALAP order when both PE types are saturated. `feed` is the feeding bonus in cycles (see
/// [`Feed`]), applied in reverse time: an op that is the last unissued user of an op of the
/// other type goes earlier. Cost: O(n log n).
pub fn backward_starts(dag: &OpDag, n_add: u32, n_mul: u32, lat: &Latencies, keys: &[Key], feed: u32) -> Vec<u32> {
    let n = dag.len();
    let mut feed = Feed::new(dag, keys, feed, true);
    let (mut lowered, mut in_ready, mut placed) = (Vec::new(), vec![false; n], vec![false; n]);
    let mut pending: Vec<u32> = (0..n as Node).map(|j| dag.n_users(j)).collect();
    let mut earliest = vec![0u32; n]; // reverse ready time before the op's own latency
    let mut r = vec![0u32; n];
    let mut waiting: BinaryHeap<Reverse<(u32, Node)>> = BinaryHeap::new();
    for v in 0..n as Node {
        if pending[v as usize] == 0 {
            waiting.push(Reverse((lat.of(dag.kind(v)), v)));
        }
    }
    let mut ready = ready_lists(dag, keys);
    let g = dag.clusters();
    let caps: Vec<[usize; 2]> = (0..g).map(|c| [pes_in(c, n_add, g).count(), pes_in(c, n_mul, g).count()]).collect();
    let mut done = 0;
    let mut t = 0u32;
    while done < n {
        while let Some(&Reverse((c, v))) = waiting.peek() {
            if c > t {
                break;
            }
            waiting.pop();
            in_ready[v as usize] = true;
            ready_of(&mut ready, dag, v).push(feed.key[v as usize], v);
        }
        for (ty, c) in (0..2).flat_map(|ty| (0..g as usize).map(move |c| (ty, c))) {
            let mut issued = 0;
            while issued < caps[c][ty] {
                let Some((k, v)) = ready[c][ty].pop() else { break };
                if k != feed.key[v as usize] || placed[v as usize] {
                    continue; // stale entry (the key was lowered since)
                }
                issued += 1;
                r[v as usize] = t;
                placed[v as usize] = true;
                done += 1;
                feed.issued(dag, |u| placed[u as usize], v, &mut lowered);
                for (k, u) in lowered.drain(..) {
                    if in_ready[u as usize] {
                        ready_of(&mut ready, dag, u).push(k, u);
                    }
                }
                // Operands: ready in reverse time once every user is placed, after their latency.
                for a in dag.distinct_operands(v) {
                    earliest[a as usize] = earliest[a as usize].max(t + 1);
                    pending[a as usize] -= 1;
                    if pending[a as usize] == 0 {
                        let k = dag.kind(a);
                        waiting.push(Reverse((earliest[a as usize] + lat.of(k) - 1, a)));
                    }
                }
            }
        }
        t += 1;
        if ready.iter().flatten().all(ReadyQueue::is_empty) {
            if let Some(&Reverse((c, _))) = waiting.peek() {
                t = t.max(c);
            }
        }
    }
    r
}
