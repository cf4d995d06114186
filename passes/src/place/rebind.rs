//! Interconnect-aware rebinding after scheduling (`place<select=routes;rebind=R>`, issue 49):
//! the schedule's length stays, ops move between PEs of their type so that each PE memory
//! receives from fewer sources — fewer inputs on the specialised interconnect's write-port
//! multiplexers, three quarters of a fixed-point design's logic (docs/fpga.md).
//!
//! The list scheduler binds an op to a PE when it issues it, before its consumers exist; the
//! routes it makes are the pairs (source, PE memory) of every booked write, a source being a
//! PE's result or its buffer read (`codegen<fpga;interconnect=specialised>` gives each pair a
//! multiplexer input). Rebinding is the binding step of high-level synthesis redone after
//! scheduling, for interconnect (Pangrle, "On the complexity of connectivity binding", IEEE
//! TCAD 1991, shows the exact problem NP-complete; Huang, Chen, Lin & Hsu, "Data path allocation
//! based on bipartite weighted matching", DAC 1990, bind cycle by cycle): an op may **move** to
//! a PE of its type idle in its cycle, **swap** PEs with the op issued there, or be **retimed**
//! to an idle PE in another cycle of its slack. Each change is checked against the machine
//! model of `robovec_ir::placement`:
//! - the op's operands are booked into its new PE memory (reusing a write already there, a
//!   direct write at the operand's arrival or a buffer read before the issue, preferring a
//!   source that memory already receives), within the memory's `writes` ports per cycle and
//!   one buffer read per buffer per cycle; writes into its old memory that no other op there
//!   reads are removed;
//! - its own result's writes keep their targets and cycles (a move, a swap; their source
//!   becomes the new PE's result or buffer, whose buffer reads must be free), or are booked
//!   anew for its users' memories by their issues (a retime).
//!
//! Memory words (addresses) are assigned afterwards by [`super::memory`], as for any schedule.
//! The search is [`rebind`]'s. Cost per round: O(n) tries for n ops, each touching the op's
//! operands, its users and its result's writes — linear in ops, like one list schedule.

use super::dag::{Node, OpDag};
use super::schedule::{Booking, Schedule};
use robovec_ir::placement::PeArray;

/// What a rebinding did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rebound {
    /// Distinct routes (source, PE memory) before.
    pub routes_before: u32,
    /// Distinct routes after.
    pub routes_after: u32,
    /// Moves, swaps and retimes kept.
    pub moves: u32,
    /// Rounds run.
    pub rounds: u32,
}

/// An entry of the undo log: the inverse of one change.
enum Undo {
    /// A booking was pushed (pop it).
    Added,
    /// Booking `i` was removed (revive it).
    Killed(u32),
    /// Node `j` issued on slot `old` before.
    Bound(Node, u32),
    /// Node `j` issued on `(slot, cycle)` before (its result's writes were rebooked).
    Retimed(Node, u32, u32),
}

/// The rebinding state: the schedule's issues and live bookings with the per-cycle port use and
/// the route counts they imply. A change may break a port limit for a while (a swap binds one
/// op before the other leaves); `overfull` and `shared` count the breaks, and a change is kept
/// only when both are back to zero.
struct State<'a> {
    dag: &'a OpDag,
    arch: &'a PeArray,
    n_pe: usize,
    issue: Vec<(u32, u32)>,
    arrival: Vec<u32>,
    end: u32,
    bookings: Vec<Booking>,
    live: Vec<bool>,
    /// Booking indices per node (dead ones included; filtered by `live`).
    of_node: Vec<Vec<u32>>,
    /// `busy[slot][t]`: node + 1 issued there (0 = idle).
    busy: Vec<Vec<u32>>,
    /// `writes[slot][c]`: writes into that memory in that cycle.
    writes: Vec<Vec<u8>>,
    /// `buffer[slot][c]`: the nodes read from that buffer in that cycle, with their bookings.
    buffer: Vec<Vec<Vec<(Node, u16)>>>,
    /// `count[memory · 2N + source]`: live bookings through that route.
    count: Vec<u32>,
    /// Distinct routes (non-zero counts).
    routes: u32,
    /// Σ count²: larger when the same writes use fewer, fuller routes.
    sq: i64,
    /// Live buffer reads (indirect writes).
    indirect: u32,
    /// Memory cycles with more writes than ports.
    overfull: u32,
    /// Buffer reads beside another node's in the same buffer and cycle.
    shared: u32,
    log: Vec<Undo>,
}

fn at<T: Clone + Default>(v: &mut Vec<T>, c: u32) -> &mut T {
    if v.len() <= c as usize {
        v.resize(c as usize + 1, T::default());
    }
    &mut v[c as usize]
}

impl<'a> State<'a> {
    fn new(dag: &'a OpDag, arch: &'a PeArray, s: &Schedule) -> State<'a> {
        let n_pe = arch.n_pe();
        let mut st = State {
            dag,
            arch,
            n_pe,
            issue: s.issue.clone(),
            arrival: s.arrival.clone(),
            end: s.arrival.iter().copied().max().unwrap_or(0),
            bookings: Vec::with_capacity(s.bookings.len()),
            live: Vec::with_capacity(s.bookings.len()),
            of_node: vec![Vec::new(); dag.len()],
            busy: vec![Vec::new(); n_pe],
            writes: vec![Vec::new(); n_pe],
            buffer: vec![Vec::new(); n_pe],
            count: vec![0; 2 * n_pe * n_pe],
            routes: 0,
            sq: 0,
            indirect: 0,
            overfull: 0,
            shared: 0,
            log: Vec::new(),
        };
        for (j, &(q, t)) in s.issue.iter().enumerate() {
            *at(&mut st.busy[q as usize], t) = j as u32 + 1;
        }
        for b in &s.bookings {
            st.push(*b);
        }
        st.log.clear();
        st
    }

    /// True when every port limit holds.
    fn legal(&self) -> bool {
        self.overfull == 0 && self.shared == 0
    }

    /// The route index of a booking as the producer is bound now.
    fn route(&self, b: &Booking) -> usize {
        let p = self.issue[b.node as usize].0 as usize;
        b.target * 2 * self.n_pe + if b.indirect { self.n_pe + p } else { p }
    }

    /// Occupies (or frees) the ports of a live booking and counts its route.
    fn occupy(&mut self, b: Booking, up: bool) {
        let ports = self.arch.writes;
        let w = at(&mut self.writes[b.target], b.cycle);
        if up {
            *w += 1;
            self.overfull += (*w as u32 > ports) as u32;
        } else {
            self.overfull -= (*w as u32 > ports) as u32;
            *w -= 1;
        }
        if b.indirect {
            if up {
                self.indirect += 1;
            } else {
                self.indirect -= 1;
            }
            let p = self.issue[b.node as usize].0 as usize;
            let reads = at(&mut self.buffer[p], b.cycle);
            let k = reads.iter().position(|r| r.0 == b.node);
            match (k, up) {
                (Some(k), true) => reads[k].1 += 1,
                (None, true) => {
                    reads.push((b.node, 1));
                    self.shared += (reads.len() > 1) as u32;
                }
                (Some(k), false) => {
                    reads[k].1 -= 1;
                    if reads[k].1 == 0 {
                        reads.swap_remove(k);
                        self.shared -= (!reads.is_empty()) as u32;
                    }
                }
                (None, false) => unreachable!("a live buffer read is counted"),
            }
        }
        let r = self.route(&b);
        if up {
            self.sq += 2 * self.count[r] as i64 + 1;
            self.count[r] += 1;
            self.routes += (self.count[r] == 1) as u32;
        } else {
            self.sq -= 2 * self.count[r] as i64 - 1;
            self.count[r] -= 1;
            self.routes -= (self.count[r] == 0) as u32;
        }
    }

    fn push(&mut self, b: Booking) {
        self.occupy(b, true);
        self.of_node[b.node as usize].push(self.bookings.len() as u32);
        self.bookings.push(b);
        self.live.push(true);
        self.log.push(Undo::Added);
    }

    fn kill(&mut self, i: u32) {
        let b = self.bookings[i as usize];
        self.occupy(b, false);
        self.live[i as usize] = false;
        self.log.push(Undo::Killed(i));
    }

    /// Can memory `m` take one more write at `c`?
    fn write_free(&self, m: usize, c: u32) -> bool {
        (self.writes[m].get(c as usize).copied().unwrap_or(0) as u32) < self.arch.writes
    }

    /// Can PE `p`'s buffer be read for node `j` at `c`?
    fn buffer_free(&self, p: usize, c: u32, j: Node) -> bool {
        match self.buffer[p].get(c as usize).map(Vec::as_slice) {
            None | Some([]) => true,
            Some([(v, _)]) => *v == j,
            Some(_) => false,
        }
    }

    /// Live booking of `u` into memory `m`.
    fn booking(&self, u: Node, m: usize) -> Option<u32> {
        self.of_node[u as usize]
            .iter()
            .copied()
            .find(|&i| self.live[i as usize] && self.bookings[i as usize].target == m)
    }

    /// Removes the writes of `x`'s operands into its memory that no other op there reads.
    fn drop_operands(&mut self, x: Node) {
        let m = self.issue[x as usize].0;
        for u in self.dag.distinct_operands(x) {
            let still = self.dag.users_of(u).iter().any(|&y| y != x && self.issue[y as usize].0 == m);
            if !still {
                if let Some(i) = self.booking(u, m as usize) {
                    self.kill(i);
                }
            }
        }
    }

    /// Books `x`'s operands into its (new) memory by its issue cycle; false when one cannot
    /// get there.
    fn add_operands(&mut self, x: Node) -> bool {
        let (m, t) = self.issue[x as usize];
        let m = m as usize;
        for u in self.dag.distinct_operands(x) {
            if let Some(i) = self.booking(u, m) {
                if self.bookings[i as usize].cycle <= t {
                    continue;
                }
                self.kill(i); // written too late for x: book it earlier for every reader
            }
            let Some(b) = self.best_booking(u, m, t) else { return false };
            self.push(b);
        }
        true
    }

    /// The write of `u` into memory `m` by cycle `t`: an existing route first (direct, then the
    /// earliest buffer read), then a new one (the same order).
    fn best_booking(&self, u: Node, m: usize, t: u32) -> Option<Booking> {
        let a = self.arrival[u as usize];
        let p = self.issue[u as usize].0 as usize;
        let n2 = 2 * self.n_pe;
        let direct = Booking { node: u, target: m, cycle: a, indirect: false };
        let direct_ok = a <= t && self.write_free(m, a);
        let indirect = || {
            if !self.arch.buffer {
                return None;
            }
            (a..=t).find(|&b| self.write_free(m, b) && self.buffer_free(p, b, u)).map(|b| Booking {
                node: u,
                target: m,
                cycle: b,
                indirect: true,
            })
        };
        if direct_ok && self.count[m * n2 + p] > 0 {
            return Some(direct);
        }
        if self.count[m * n2 + self.n_pe + p] > 0 {
            if let Some(b) = indirect() {
                return Some(b);
            }
        }
        if direct_ok {
            return Some(direct);
        }
        indirect()
    }

    /// Frees or occupies the ports of `x`'s live result writes.
    fn occupy_result(&mut self, x: Node, up: bool) {
        for k in 0..self.of_node[x as usize].len() {
            let i = self.of_node[x as usize][k] as usize;
            if self.live[i] {
                self.occupy(self.bookings[i], up);
            }
        }
    }

    /// Issues `x` on slot `to` (same cycle); its result's writes follow.
    fn set_slot(&mut self, x: Node, to: u32) {
        let t = self.issue[x as usize].1;
        self.occupy_result(x, false);
        self.place_at(x, to, t);
        self.occupy_result(x, true);
    }

    fn bind(&mut self, x: Node, to: u32) {
        let from = self.issue[x as usize].0;
        self.set_slot(x, to);
        self.log.push(Undo::Bound(x, from));
    }

    /// Undoes every change after log length `mark`.
    fn undo(&mut self, mark: usize) {
        while self.log.len() > mark {
            match self.log.pop().expect("longer than mark") {
                Undo::Added => {
                    let b = self.bookings.pop().expect("a pushed booking");
                    self.live.pop();
                    self.of_node[b.node as usize].pop();
                    self.occupy(b, false);
                }
                Undo::Killed(i) => {
                    self.live[i as usize] = true;
                    self.occupy(self.bookings[i as usize], true);
                }
                Undo::Bound(x, from) => self.set_slot(x, from),
                Undo::Retimed(x, q, t) => self.place_at(x, q, t),
            }
        }
    }

    /// Issues `x` on `(q, t)`, its result's writes left as they are (none live, or occupied
    /// again by the caller).
    fn place_at(&mut self, x: Node, q: u32, t: u32) {
        let (p, t0) = self.issue[x as usize];
        if self.busy[p as usize].get(t0 as usize) == Some(&(x + 1)) {
            self.busy[p as usize][t0 as usize] = 0;
        }
        self.issue[x as usize] = (q, t);
        self.arrival[x as usize] = t + self.arch.lat.of(self.dag.kind(x));
        *at(&mut self.busy[q as usize], t) = x + 1;
    }

    /// The cycles `x` may issue in without moving another op: its operands' arrivals to its
    /// users' issues (and the schedule's end) less its latency.
    fn window(&self, x: Node) -> (u32, u32) {
        let lat = self.arch.lat.of(self.dag.kind(x));
        let early = self.dag.distinct_operands(x).map(|u| self.arrival[u as usize]).max().unwrap_or(0);
        let late = self.dag.users_of(x).iter().map(|&y| self.issue[y as usize].1).min().unwrap_or(self.end);
        (early, late.min(self.end).saturating_sub(lat))
    }

    /// Moves `x` to `(q, t)`, `q` idle at `t`: its operands and its result are booked anew.
    fn try_retime(&mut self, x: Node, q: u32, t: u32) -> bool {
        self.drop_operands(x);
        for k in 0..self.of_node[x as usize].len() {
            let i = self.of_node[x as usize][k];
            if self.live[i as usize] {
                self.kill(i);
            }
        }
        let (p, t0) = self.issue[x as usize];
        self.place_at(x, q, t);
        self.log.push(Undo::Retimed(x, p, t0));
        if !self.add_operands(x) {
            return false;
        }
        // One write per memory its users read it in, by the earliest of them there.
        let mut by: Vec<(u32, u32)> = self.dag.users_of(x).iter().map(|&y| self.issue[y as usize]).collect();
        by.sort_unstable();
        by.dedup_by_key(|&mut (m, _)| m);
        for (m, t) in by {
            let Some(b) = self.best_booking(x, m as usize, t) else { return false };
            self.push(b);
        }
        self.legal()
    }

    /// Moves `x` to slot `q`, idle in its cycle, or swaps it with `y`, the op issued there.
    /// False (changes left for [`State::undo`]) when the machine model does not allow it.
    fn try_move(&mut self, x: Node, q: u32, y: Option<Node>) -> bool {
        let p = self.issue[x as usize].0;
        self.drop_operands(x);
        if let Some(y) = y {
            self.drop_operands(y);
            self.bind(y, p);
        }
        self.bind(x, q);
        self.legal() && self.add_operands(x) && y.is_none_or(|y| self.add_operands(y)) && self.legal()
    }
}

/// Partners (other PEs of the op's type, drawn at random) each op tries per round.
pub const TRIES: u32 = 8;

/// Rounds without fewer routes after which the rebinding stops.
pub const PATIENCE: u32 = 16;

/// Rebinds the ops of schedule `s` (made for `dag` on `arch`) to fewer interconnect routes for
/// at most `rounds` rounds; `stop` (called about once per op) ends it early, keeping what was
/// done. The schedule's cycles (its largest arrival) never change.
///
/// A round takes every op and tries [`TRIES`] other PEs of its type, drawn at random
/// (deterministic xorshift): half the time in its own cycle (a move to an idle PE or a swap
/// with the op issued there), half the time in a cycle of its window — from its operands'
/// arrival to its users' issue less its latency — where that PE is idle. A change is kept when
/// it is legal, adds no buffer read (a buffer word costs more logic than a multiplexer input:
/// 1.2 against 0.35 ALM a bit on the DE10-Nano, `Family::design_logic`) and lowers the routes,
/// or keeps them and either removes a buffer read or concentrates the same writes on fewer,
/// fuller routes (Σ bookings² per route does not fall): the binding then drifts across the
/// plateaus toward routes that can empty. Measured with the estimate (64 rounds): the Jeep's
/// `dirdyna` at 40 + 46 PEs, 2,677 → 2,433 multiplexer inputs, 42,526 → 40,450 ALM; WALK-MAN's
/// at 27 + 27, 3,223 → 2,882 and 43,732 → 39,280. Strict improvement alone keeps 5 % and 1 %
/// fewer routes; without the buffer rule WALK-MAN's routes fell 6 % but its buffers took 99
/// more words and its estimate rose 3 %. It stops after [`PATIENCE`] rounds without fewer
/// routes.
pub fn rebind(dag: &OpDag, arch: &PeArray, s: &mut Schedule, rounds: u32, stop: &dyn Fn() -> bool) -> Rebound {
    let mut st = State::new(dag, arch, s);
    let mut out = Rebound { routes_before: st.routes, ..Rebound::default() };
    let sides: [Vec<u32>; 2] = [(0..arch.n_add).collect(), (arch.n_add..arch.n_add + arch.n_mul).collect()];
    let mut rng = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move |below: u32| {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng % below.max(1) as u64) as u32
    };
    let (mut best, mut since) = (st.routes, 0);
    'rounds: for _ in 0..rounds {
        out.rounds += 1;
        for x in 0..dag.len() as Node {
            if stop() {
                break 'rounds;
            }
            let side = &sides[dag.is_mul(x) as usize];
            if side.len() < 2 {
                continue;
            }
            for _ in 0..TRIES {
                let q = side[next(side.len() as u32) as usize];
                let (p, t) = st.issue[x as usize];
                let (mark, before, sq, ind) = (st.log.len(), st.routes, st.sq, st.indirect);
                let legal = if next(2) == 0 {
                    if q == p {
                        continue;
                    }
                    let y = st.busy[q as usize].get(t as usize).copied().unwrap_or(0).checked_sub(1);
                    st.try_move(x, q, y)
                } else {
                    let (lo, hi) = st.window(x);
                    let t2 = lo + next(hi.saturating_sub(lo) + 1);
                    if t2 == t || hi < lo || st.busy[q as usize].get(t2 as usize).is_some_and(|&b| b != 0) {
                        continue;
                    }
                    st.try_retime(x, q, t2)
                };
                let kept = st.routes < before || (st.routes == before && (st.sq >= sq || st.indirect < ind));
                if legal && st.indirect <= ind && kept {
                    st.log.clear();
                    out.moves += 1;
                } else {
                    st.undo(mark);
                }
            }
        }
        if st.routes < best {
            (best, since) = (st.routes, 0);
        } else {
            since += 1;
            if since == PATIENCE {
                break;
            }
        }
    }
    out.routes_after = st.routes;
    s.bookings = st.bookings.iter().zip(&st.live).filter_map(|(b, &l)| l.then_some(*b)).collect();
    s.arrival = st.arrival;
    s.issue = st.issue;
    out
}
