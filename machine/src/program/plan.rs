//! The plan: everything the lowering derives from a [`Placement`] before running it — arrival
//! cycles, every PE memory write (loads and `Write`s) with the reads that use it, every buffer
//! entry with its reads, and the events of each cycle.

use std::collections::HashMap;

use robovec_ir::placement::{Issue, Pe, Placement};
use robovec_ir::syntax::{BinOp, Def, OpKind, Operand};
use robovec_ir::{Function, Value};

use robovec_ir::machine::Held as Key;

use crate::error::{MachineError as SimError, MachineErrorKind as K, When};

/// Longest run the lowering accepts, cycles (guards the per-cycle steps).
const MAX_CYCLES: u32 = 50_000_000;

/// The key of an operand's word.
pub(super) fn key_of(o: &Operand) -> Key {
    Key::of(o)
}

/// One write into a PE memory word (a load, time −1, or a `Write`, time = its cycle).
pub(super) struct MemEvent {
    pub slot: usize,
    pub pe: Pe,
    pub addr: u32,
    pub time: i64,
    pub key: Key,
    /// Latest cycle an op reads this word (reads resolved statically, see `resolve`).
    pub last_read: Option<i64>,
}

/// A memory event as the reads search them: its write cycle, PE slot and index in `mem_ev`.
#[derive(Clone, Copy)]
struct EvRef {
    time: i64,
    slot: u32,
    event: u32,
}

/// A value entering its producer's buffer at arrival and read back by indirect writes.
pub(super) struct BufEvent {
    pub slot: usize,
    pub pe: Pe,
    pub addr: u32,
    pub value: Value,
    pub arrival: u32,
    pub last_read: u32,
    /// The first indirect write reading it (`Placement::writes` index), for diagnostics.
    pub write: usize,
}

/// Items grouped by cycle, each cycle's in the order given (a stable counting sort):
/// `items[start[c]..start[c + 1]]`. Flat arrays, so walking the cycles in order reads memory
/// in order (a map of per-cycle vectors costs a cache miss per item on 600k-op programs).
pub(super) struct ByCycle<T> {
    start: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy> ByCycle<T> {
    /// Groups `pairs` (cycle, item) by cycle; every cycle is ≤ `last`.
    fn new(last: u32, pairs: &[(u32, T)]) -> Self {
        let mut start = vec![0u32; last as usize + 2];
        for &(c, _) in pairs {
            start[c as usize + 1] += 1;
        }
        for c in 0..=last as usize {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items: Vec<Option<T>> = vec![None; pairs.len()];
        for &(c, t) in pairs {
            items[fill[c as usize] as usize] = Some(t);
            fill[c as usize] += 1;
        }
        ByCycle { start, items: items.into_iter().map(|t| t.expect("every slot filled")).collect() }
    }

    /// The items of cycle `c` (empty past the last cycle).
    pub fn at(&self, c: u32) -> &[T] {
        match (self.start.get(c as usize), self.start.get(c as usize + 1)) {
            (Some(&a), Some(&b)) => &self.items[a as usize..b as usize],
            _ => &[],
        }
    }
}

/// Events per cycle, in the order they happen within a cycle.
pub(super) struct Buckets {
    /// The last cycle with an event.
    pub last: u32,
    /// Ops whose results arrive, with their PE, in body order.
    pub arrivals: ByCycle<(Value, Pe)>,
    /// Buffer entries (`BufEvent` indices) of results arriving.
    pub entries: ByCycle<usize>,
    /// `Placement::writes` indices written into PE memories.
    pub writes: ByCycle<usize>,
    /// Ops issued, in body order, with what the lowering needs of them (so that its walk in
    /// cycle order reads them here rather than by value: issue 28).
    pub issues: ByCycle<IssueItem>,
}

/// An op issued, as the lowering's cycle loop reads it.
#[derive(Clone, Copy)]
pub(super) struct IssueItem {
    /// The op.
    pub value: Value,
    /// Its PE.
    pub pe: Pe,
    /// Its kind.
    pub kind: OpKind,
    /// Its operation when binary (`None`: a call).
    pub bin: Option<BinOp>,
    /// Its reads: `Reads::list[reads.0..reads.1]`.
    pub reads: (u32, u32),
}

impl Buckets {
    /// True when nothing happens at cycle `c`.
    pub fn is_empty(&self, c: u32) -> bool {
        self.arrivals.at(c).is_empty()
            && self.entries.at(c).is_empty()
            && self.writes.at(c).is_empty()
            && self.issues.at(c).is_empty()
    }
}

/// Each op's operand reads, flat: op `v` reads `list[at[v].0..at[v].1]`, in operand order,
/// each with the operand's arrival cycle when it is an op.
pub(super) struct Reads {
    at: Vec<(u32, u32)>,
    list: Vec<(Key, Read, Option<u32>)>,
}

impl Reads {
    /// The reads `range` of an op ([`IssueItem::reads`]).
    pub fn range(&self, range: (u32, u32)) -> &[(Key, Read, Option<u32>)] {
        &self.list[range.0 as usize..range.1 as usize]
    }
}

/// A read of an operand: the memory event it reads, or the first cycle the value is written
/// into that memory later (`None`: never).
pub(super) type Read = Result<usize, Option<i64>>;

pub(super) struct Run<'a> {
    pub f: &'a Function,
    pub p: &'a Placement,
    /// The caller's hook, called once per value, write or cycle bucket of the long loops:
    /// true stops the lowering with [`K::Stopped`].
    pub stop: &'a dyn Fn() -> bool,
}

impl Run<'_> {
    /// `Err(Stopped)` when the caller's hook says stop (one call).
    pub fn poll(&self) -> Result<(), SimError> {
        if (self.stop)() {
            Err(SimError::stopped())
        } else {
            Ok(())
        }
    }

    pub fn name(&self, k: Key) -> String {
        match k {
            Key::Value(v) => format!("%{}", self.f.name_of(v)),
            Key::Const(b) => format!("{:?}", f64::from_bits(b)),
        }
    }

    pub fn vname(&self, v: Value) -> String {
        self.name(Key::Value(v))
    }

    fn pe_exists(&self, pe: Pe) -> bool {
        match pe {
            Pe::Add(i) => i < self.p.arch.n_add,
            Pe::Mul(i) => i < self.p.arch.n_mul,
        }
    }

    pub fn slot(&self, pe: Pe) -> usize {
        pe.slot(self.p.arch.n_add)
    }

    pub fn value_ok(&self, v: Value, what: &str) -> Result<(), SimError> {
        if v.index() < self.f.values.len() {
            Ok(())
        } else {
            Err(SimError::new(K::Malformed, format!("{what} refers to {v}, which the function does not have")))
        }
    }

    fn no_pe(&self, pe: Pe, when: When, what: &str) -> SimError {
        let a = self.p.arch;
        SimError::new(
            K::NoSuchPe,
            format!("{what} uses PE {pe}, which does not exist ({} ADD and {} MULTI PEs)", a.n_add, a.n_mul),
        )
        .at(when)
        .on(pe)
    }

    /// Checks everything that has no time order: sizes, value and PE references, issues of
    /// non-ops, missing issues, loads of non-initial data, writes of non-ops.
    fn check_structure(&self) -> Result<(), SimError> {
        let (f, p) = (self.f, self.p);
        let n_pe = p.arch.n_pe();
        if p.pe_words.len() != n_pe || p.buffer_words.len() != n_pe {
            return Err(SimError::new(
                K::Malformed,
                format!(
                    "placement lists {} PE memory and {} buffer sizes for {n_pe} PEs",
                    p.pe_words.len(),
                    p.buffer_words.len()
                ),
            ));
        }
        for k in [OpKind::Add, OpKind::Mul, OpKind::Div, OpKind::Call] {
            if p.latency(k) == 0 {
                return Err(SimError::new(K::Malformed, format!("latency of {k:?} is 0; latencies must be ≥ 1")));
            }
        }
        if let Some(i) = p.issue.iter().skip(f.values.len()).position(Option::is_some) {
            let v = Value::with_number((f.values.len() + i) as u32);
            return Err(SimError::new(K::Malformed, format!("issue of {v}, which the function does not have")));
        }
        for &v in &f.body {
            if matches!(f.value(v).def, Def::Expr(_)) {
                return Err(SimError::new(K::Malformed, "is a nested expression; run `atomise` before `sim`")
                    .of(self.vname(v))
                    .src(f.value(v).span));
            }
        }
        for (i, is) in p.issue.iter().enumerate() {
            let Some(is) = is else { continue };
            let v = Value::with_number(i as u32);
            if f.op_kind(v).is_none() {
                return Err(SimError::new(K::NotAnOp, "is issued but is not an op")
                    .at(When::Cycle(is.cycle))
                    .on(is.pe)
                    .of(self.vname(v))
                    .src(p.spans.issue(v)));
            }
            if !self.pe_exists(is.pe) {
                return Err(self.no_pe(is.pe, When::Cycle(is.cycle), "issue").of(self.vname(v)).src(p.spans.issue(v)));
            }
        }
        for &v in &f.body {
            if f.op_kind(v).is_some() && p.issue.get(v.index()).copied().flatten().is_none() {
                return Err(SimError::new(K::MissingIssue, "op is never issued")
                    .of(self.vname(v))
                    .src(f.value(v).span));
            }
        }
        for (i, l) in p.loads.iter().enumerate() {
            if !self.pe_exists(l.pe) {
                return Err(self
                    .no_pe(l.pe, When::Load, "load")
                    .of(self.name(key_of(&l.operand)))
                    .src(p.spans.load(i)));
            }
            if let Operand::Value(v) = l.operand {
                self.value_ok(v, "a load")?;
                if !matches!(f.value(v).def, Def::Input | Def::Trig(..)) {
                    return Err(SimError::new(K::BadLoad, "loaded, but it is an op result, not initial data")
                        .at(When::Load)
                        .on(l.pe)
                        .of(self.vname(v))
                        .src(p.spans.load(i)));
                }
            }
        }
        for (i, w) in p.writes.iter().enumerate() {
            self.value_ok(w.value, "a write")?;
            if !self.pe_exists(w.pe) {
                return Err(self
                    .no_pe(w.pe, When::Cycle(w.cycle), "write")
                    .of(self.vname(w.value))
                    .src(p.spans.write(i)));
            }
            if f.op_kind(w.value).is_none() {
                return Err(SimError::new(K::NotAnOp, "written as a result, but it is not an op")
                    .at(When::Cycle(w.cycle))
                    .on(w.pe)
                    .of(self.vname(w.value))
                    .src(p.spans.write(i)));
            }
        }
        Ok(())
    }
}

/// What [`derive`] finds; indices of `mem_ev` are loads (`0..n_loads`), then `Placement::writes`.
pub(super) struct Plan {
    /// Arrival cycle of every op, by value index.
    pub arrival: Vec<Option<u32>>,
    /// Number of loads.
    pub n_loads: usize,
    /// PE memory writes.
    pub mem_ev: Vec<MemEvent>,
    /// Each op's operand reads.
    pub reads: Reads,
    /// Buffer entries.
    pub buf_ev: Vec<BufEvent>,
    /// The buffer entry each indirect write reads.
    pub buf_of_write: Vec<Option<usize>>,
    /// Events per cycle.
    pub buckets: Buckets,
}

impl Run<'_> {
    /// The issue of op `v` (checked to exist).
    pub fn issue(&self, v: Value) -> Issue {
        self.p.issue[v.index()].expect("checked: every op is issued")
    }

    /// Checks the structure and derives the plan.
    pub fn derive(&self) -> Result<Plan, SimError> {
        let r = self;
        let (f, p) = (self.f, self.p);
        r.poll()?;
        r.check_structure()?;
        let n = f.values.len();
        let issue = |v: Value| r.issue(v);

        // Arrivals.
        let mut arrival: Vec<Option<u32>> = vec![None; n];
        let mut cycles = 0u32;
        for &v in &f.body {
            r.poll()?;
            let Some(kind) = f.op_kind(v) else { continue };
            let is = issue(v);
            let a = is.cycle.checked_add(p.latency(kind)).filter(|&a| a <= MAX_CYCLES).ok_or_else(|| {
                SimError::new(K::Malformed, format!("arrives after cycle {MAX_CYCLES}, too late to lower"))
                    .at(When::Cycle(is.cycle))
                    .on(is.pe)
                    .of(r.vname(v))
                    .src(p.spans.issue(v))
            })?;
            arrival[v.index()] = Some(a);
            cycles = cycles.max(a);
        }

        // PE memory writes: loads first, then `Write`s.
        let n_loads = p.loads.len();
        let mut mem_ev: Vec<MemEvent> = p
            .loads
            .iter()
            .map(|l| MemEvent {
                slot: r.slot(l.pe),
                pe: l.pe,
                addr: l.addr,
                time: -1,
                key: key_of(&l.operand),
                last_read: None,
            })
            .chain(p.writes.iter().map(|w| MemEvent {
                slot: r.slot(w.pe),
                pe: w.pe,
                addr: w.addr,
                time: w.cycle as i64,
                key: Key::Value(w.value),
                last_read: None,
            }))
            .collect();
        // The events of each key, in event order: grouped by value index for op results and
        // inputs (CSR, so the lookups below follow the body's locality), in a map for constants.
        // Each entry carries what finding a read compares (time, slot), and the latest read of
        // a value's events is kept beside the entries, so the reads never touch `mem_ev`
        // (in cycle order: scattered against the body's order on large functions; issue 28).
        let mut val_start = vec![0u32; n + 1];
        for e in &mem_ev {
            if let Key::Value(v) = e.key {
                val_start[v.index() + 1] += 1;
            }
        }
        for i in 0..n {
            val_start[i + 1] += val_start[i];
        }
        let mut fill = val_start.clone();
        let mut val_ev = vec![EvRef { time: 0, slot: 0, event: 0 }; val_start[n] as usize];
        let mut const_ev: HashMap<(usize, u64), Vec<EvRef>> = HashMap::new();
        for (i, e) in mem_ev.iter().enumerate() {
            let entry = EvRef { time: e.time, slot: e.slot as u32, event: i as u32 };
            match e.key {
                Key::Value(v) => {
                    val_ev[fill[v.index()] as usize] = entry;
                    fill[v.index()] += 1;
                }
                Key::Const(b) => const_ev.entry((e.slot, b)).or_default().push(entry),
            }
        }
        drop(fill);
        // Latest read of each entry of `val_ev` (`i64::MIN`: none).
        let mut val_last = vec![i64::MIN; val_ev.len()];

        // Reads: an op on PE p at cycle c reads each operand from the latest write of it into p at
        // a cycle ≤ c (the first such write on a tie).
        let mut reads = Reads { at: vec![(0, 0); n], list: Vec::new() };
        let mut keys: Vec<Key> = Vec::new();
        for &v in &f.body {
            r.poll()?;
            keys.clear();
            match &f.value(v).def {
                Def::Binary(_, a, b) => keys.extend([key_of(a), key_of(b)]),
                Def::Call(_, args) => keys.extend(args.iter().map(key_of)),
                _ => continue,
            }
            let is = issue(v);
            let (slot, c) = (r.slot(is.pe), is.cycle as i64);
            let from = reads.list.len() as u32;
            for &k in &keys {
                let (base, list): (usize, &[EvRef]) = match k {
                    Key::Value(u) => {
                        let (a, b) = (val_start[u.index()] as usize, val_start[u.index() + 1] as usize);
                        (a, &val_ev[a..b])
                    }
                    Key::Const(b) => (0, const_ev.get(&(slot, b)).map_or(&[], Vec::as_slice)),
                };
                // (time, position in `list`) of the read write.
                let mut best: Option<(i64, usize)> = None;
                let mut first_later: Option<i64> = None;
                for (i, ev) in list.iter().enumerate() {
                    if ev.slot as usize != slot {
                        continue;
                    }
                    if ev.time <= c {
                        if !matches!(best, Some((t, _)) if t >= ev.time) {
                            best = Some((ev.time, i));
                        }
                    } else {
                        first_later = Some(first_later.map_or(ev.time, |t| t.min(ev.time)));
                    }
                }
                let res = match best {
                    Some((_, i)) => {
                        let e = list[i].event as usize;
                        if let Key::Value(_) = k {
                            let last = &mut val_last[base + i];
                            *last = (*last).max(c);
                        } else {
                            let lr = &mut mem_ev[e].last_read;
                            *lr = Some(lr.map_or(c, |x| x.max(c)));
                        }
                        Ok(e)
                    }
                    None => Err(first_later),
                };
                let arrives = match k {
                    Key::Value(u) => arrival[u.index()],
                    Key::Const(_) => None,
                };
                reads.list.push((k, res, arrives));
            }
            reads.at[v.index()] = (from, reads.list.len() as u32);
        }
        for (ev, &last) in val_ev.iter().zip(&val_last) {
            if last != i64::MIN {
                mem_ev[ev.event as usize].last_read = Some(last);
            }
        }
        drop((val_ev, val_last));

        // Buffer entries: one per indirect-written value, at its producer's buffer, from arrival.
        let mut buf_ev: Vec<BufEvent> = Vec::with_capacity(p.writes.len());
        // The buffer entry of each value (`usize::MAX`: none yet), by `Value::index()`.
        let mut buf_of_value: Vec<usize> = vec![usize::MAX; n];
        let mut buf_of_write: Vec<Option<usize>> = vec![None; p.writes.len()];
        for (i, w) in p.writes.iter().enumerate() {
            r.poll()?;
            let Some(addr) = w.buffer_addr else { continue };
            let is = issue(w.value);
            let arr = arrival[w.value.index()].expect("ops arrive");
            let b = match buf_of_value[w.value.index()] {
                usize::MAX => {
                    buf_ev.push(BufEvent {
                        slot: r.slot(is.pe),
                        pe: is.pe,
                        addr,
                        value: w.value,
                        arrival: arr,
                        last_read: 0,
                        write: i,
                    });
                    buf_of_value[w.value.index()] = buf_ev.len() - 1;
                    buf_ev.len() - 1
                }
                b => b,
            };
            if buf_ev[b].addr != addr {
                return Err(SimError::new(
                    K::BufferEntries,
                    format!("enters the buffer of {} at two addresses ({} and {addr})", is.pe, buf_ev[b].addr),
                )
                .at(When::Cycle(arr))
                .on(is.pe)
                .of(r.vname(w.value))
                .src(p.spans.write(i)));
            }
            buf_ev[b].last_read = buf_ev[b].last_read.max(w.cycle);
            buf_of_write[i] = Some(b);
        }

        // The schedule, cycle by cycle.
        let mut last = cycles;
        for (i, w) in p.writes.iter().enumerate() {
            if w.cycle > MAX_CYCLES {
                return Err(SimError::new(
                    K::Malformed,
                    format!("written after cycle {MAX_CYCLES}, too late to lower"),
                )
                .at(When::Cycle(w.cycle))
                .on(w.pe)
                .of(r.vname(w.value))
                .src(p.spans.write(i)));
            }
            last = last.max(w.cycle);
        }
        let mut issued: Vec<(u32, IssueItem)> = Vec::with_capacity(f.body.len());
        let mut arriving: Vec<(u32, (Value, Pe))> = Vec::with_capacity(f.body.len());
        for &v in &f.body {
            r.poll()?;
            let def = &f.value(v).def;
            if let Some(kind) = f.op_kind(v) {
                let is = issue(v);
                let bin = match def {
                    Def::Binary(op, _, _) => Some(*op),
                    _ => None,
                };
                let item = IssueItem { value: v, pe: is.pe, kind, bin, reads: reads.at[v.index()] };
                issued.push((is.cycle, item));
                arriving.push((arrival[v.index()].expect("ops arrive"), (v, is.pe)));
            }
        }
        let entries: Vec<(u32, usize)> = buf_ev.iter().enumerate().map(|(i, b)| (b.arrival, i)).collect();
        let writes: Vec<(u32, usize)> = p.writes.iter().enumerate().map(|(i, w)| (w.cycle, i)).collect();
        let buckets = Buckets {
            last,
            arrivals: ByCycle::new(last, &arriving),
            entries: ByCycle::new(last, &entries),
            writes: ByCycle::new(last, &writes),
            issues: ByCycle::new(last, &issued),
        };
        Ok(Plan { arrival, n_loads, mem_ev, reads, buf_ev, buf_of_write, buckets })
    }
}
