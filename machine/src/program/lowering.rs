//! The lowering: checks a [`Placement`] against every rule of the machine model and builds the
//! [`MachineProgram`] (see the module doc of [`super`] for the rules and choices).

use std::collections::HashMap;

use robovec_ir::machine::{
    Held as Key, Instr, MachineOp, MachineProgram, MemWrite, OutputLoc, PeProgram, ReadAddrs, Source, Step, Word,
};
use robovec_ir::placement::Placement;
use robovec_ir::syntax::{BinOp, Def, Operand};
use robovec_ir::{Function, Value};

use super::plan::{IssueItem, Plan, Run};
use crate::error::{MachineError as SimError, MachineErrorKind as K, When};

/// Peak occupancy the lowering measured: the largest number of words each memory holds at
/// once, by [`robovec_ir::placement::Pe::slot`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Occupancy {
    /// Peak words per PE memory.
    pub max_words_per_memory: Vec<u32>,
    /// Peak words per buffer.
    pub max_buffer_words: Vec<u32>,
}

/// Largest program the lowering builds, steps (PEs × cycles): bounds its memory (a step is
/// about 90 bytes) on absurd placements.
pub const MAX_STEPS: u64 = 16 << 20;

/// Marks word `at` as holding event `new` from `now`; `start`/`last` give an event's write
/// time and last read. Errors name the old event when it is still needed or was written in
/// the same cycle.
fn occupy(
    words: &mut Words,
    at: (usize, u32),
    new: usize,
    now: i64,
    start: impl Fn(usize) -> i64,
    last: impl Fn(usize) -> Option<i64>,
) -> Result<(), (usize, Option<i64>)> {
    if let Some(old) = words.get(at.0, at.1) {
        if start(old) == now {
            return Err((old, None));
        }
        if let Some(r) = last(old).filter(|&r| r >= now) {
            return Err((old, Some(r)));
        }
    }
    words.set(at.0, at.1, new);
    Ok(())
}

/// What each word of every PE memory (or buffer) holds: an event index, dense by slot and
/// address (addresses are checked against the reported sizes before they are set).
struct Words {
    /// First word of each slot in `held`.
    base: Vec<usize>,
    held: Vec<u32>,
}

impl Words {
    const EMPTY: u32 = u32::MAX;

    fn new(words: &[u32]) -> Self {
        let mut base = Vec::with_capacity(words.len() + 1);
        let mut total = 0usize;
        for &w in words {
            base.push(total);
            total += w as usize;
        }
        base.push(total);
        Words { base, held: vec![Self::EMPTY; total] }
    }

    fn index(&self, slot: usize, addr: u32) -> Option<usize> {
        let i = self.base.get(slot)? + addr as usize;
        (i < *self.base.get(slot + 1)?).then_some(i)
    }

    /// The event word `addr` of `slot` holds (`None`: nothing yet, or no such word).
    fn get(&self, slot: usize, addr: u32) -> Option<usize> {
        let h = self.held[self.index(slot, addr)?];
        (h != Self::EMPTY).then_some(h as usize)
    }

    fn set(&mut self, slot: usize, addr: u32, event: usize) {
        let i = self.index(slot, addr).expect("address checked against the reported size");
        self.held[i] = event as u32;
    }
}

fn reuse_error(what: &str, addr: u32, old: String, new: String, read: Option<i64>) -> SimError {
    match read {
        None => SimError::new(
            K::AddressReused,
            format!("{what} address {addr} is written twice in one cycle ({old}, then {new})"),
        ),
        Some(r) => SimError::new(
            K::AddressReused,
            format!(
                "{what} address {addr} is written with {new} while it holds {old}, which is read at cycle {r} \
                 (address reused while its value is still needed)"
            ),
        ),
    }
    .of(new)
}

/// Largest number of words live at once per slot; `items` are `(slot, start, end)`, inclusive.
/// Each slot's start/end events are sorted once, in a vector sized from a first count (no
/// growth).
fn peak(n: usize, items: impl Iterator<Item = (usize, i64, i64)> + Clone) -> Vec<u32> {
    let mut count = vec![0usize; n];
    for (s, _, _) in items.clone() {
        count[s] += 2;
    }
    let mut ev: Vec<Vec<(i64, i32)>> = count.into_iter().map(Vec::with_capacity).collect();
    for (s, a, b) in items {
        ev[s].push((a, 1));
        ev[s].push((b + 1, -1));
    }
    ev.into_iter()
        .map(|mut e| {
            e.sort_unstable();
            let (mut cur, mut best) = (0i64, 0i64);
            for (_, d) in e {
                cur += d as i64;
                best = best.max(cur);
            }
            best as u32
        })
        .collect()
}

/// Lowers `p` of `f`; see [`super::lower`]. Calls `stop` once per value, write and cycle
/// bucket ([`super::lower_measured_until`]).
pub(super) fn lower(
    f: &Function,
    p: &Placement,
    stop: &dyn Fn() -> bool,
) -> Result<(MachineProgram, Occupancy), SimError> {
    let r = Run { f, p, stop };
    let plan = r.derive()?;
    let mut l = Lowering::new(r, &plan)?;
    let outputs = l.outputs()?;
    l.loads()?;
    for c in 0..=plan.buckets.last {
        l.cycle(c)?;
    }
    Ok(l.finish(outputs))
}

/// One lowering under way: the [`Plan`] of a placement and the [`MachineProgram`] being built
/// from it, walked in time order — [`Lowering::outputs`], [`Lowering::loads`] (before cycle 0),
/// then [`Lowering::cycle`] for each cycle `0..=last`. Each step checks the rules of its
/// events and returns the first one broken as a located [`SimError`] (cycle, PE, value, span of
/// the placement line). Times are machine cycles; sizes and addresses are words.
struct Lowering<'a> {
    /// The function, its placement and the caller's stop hook.
    r: Run<'a>,
    /// What [`Run::derive`] found: arrivals, memory and buffer events, reads, events per cycle.
    plan: &'a Plan,
    /// The program of each PE, by slot: initial memory, output memory, one step per cycle.
    pes: Vec<PeProgram>,
    /// The (slot, cycle) each op issues at, by value index ([`MachineProgram::issue_of`]).
    issue_of: Vec<Option<(usize, u32)>>,
    /// The memory event (index in `plan.mem_ev`) each PE memory word holds now.
    mem: Words,
    /// The buffer entry (index in `plan.buf_ev`) each buffer word holds now.
    buf: Words,
    /// The output-memory address each op output is captured at, by value index.
    capture_at: Vec<Option<u32>>,
    /// Which values are captured outputs, a bit each: the arrivals test it before reading
    /// `capture_at` (8 bytes a value, read in cycle order; issue 28).
    is_output: Vec<u64>,
    /// Words of each PE's output memory, by slot.
    output_words: Vec<u32>,
    // Per-PE state of the current cycle, by slot, each marked with the cycle (+ 1) it belongs
    // to, so that nothing is cleared between cycles.
    /// The result on the PE's result bus.
    bus: Vec<(u32, Value)>,
    /// Write ports of the PE's memory used.
    ports: Vec<(u32, u32)>,
    /// The buffer entry read from the PE's buffer.
    buf_reads: Vec<(u32, usize)>,
    /// The op issued on the PE.
    busy: Vec<(u32, Value)>,
}

/// The word a load puts into a memory: a constant, a trig value (by its argument) or an input.
fn word(f: &Function, k: Key) -> Word {
    match k {
        Key::Const(b) => Word::Const(f64::from_bits(b)),
        Key::Value(v) => match f.value(v).def {
            Def::Trig(t, a) => Word::Trig(t, f.name_of(a).to_string()),
            _ => Word::Input(f.name_of(v).to_string()),
        },
    }
}

/// The machine operation of an issued op.
fn machine_op(f: &Function, item: &IssueItem) -> MachineOp {
    match item.bin {
        Some(BinOp::Add) => MachineOp::Add,
        Some(BinOp::Sub) => MachineOp::Sub,
        Some(BinOp::Mul) => MachineOp::Mul,
        Some(BinOp::Div) => MachineOp::Div,
        None => match &f.value(item.value).def {
            Def::Call(callee, _) if f.is_fixed_mac(item.value) => MachineOp::Mac(callee.clone()),
            Def::Call(callee, _) => MachineOp::Call(callee.clone()),
            _ => unreachable!("ops are binary or calls"),
        },
    }
}

impl<'a> Lowering<'a> {
    /// Starts lowering `plan`: checks that the program has at most [`MAX_STEPS`] steps (PEs ×
    /// cycles, the program running until the plan's last event: the last arrival, or a later
    /// write from a buffer), then sets up every PE's program (`pe_words` words of initial
    /// memory, one empty step per cycle), empty memories and buffers, and the per-cycle state.
    fn new(r: Run<'a>, plan: &'a Plan) -> Result<Self, SimError> {
        let (f, p) = (r.f, r.p);
        let cycles = plan.buckets.last;
        let n = f.values.len();
        let n_pe = p.arch.n_pe();
        let steps = (n_pe as u64) * (cycles as u64 + 1);
        if steps > MAX_STEPS {
            return Err(SimError::new(
                K::Malformed,
                format!(
                    "the program would have {steps} steps ({n_pe} PEs × {} cycles), more than the {MAX_STEPS} \
                     the lowering builds",
                    cycles as u64 + 1
                ),
            ));
        }
        let pes = p
            .arch
            .pes()
            .enumerate()
            .map(|(s, pe)| PeProgram {
                pe,
                init: vec![None; p.pe_words[s] as usize],
                output_init: Vec::new(),
                steps: vec![Step::default(); cycles as usize + 1],
            })
            .collect();
        Ok(Lowering {
            r,
            plan,
            pes,
            issue_of: vec![None; n],
            mem: Words::new(&p.pe_words),
            buf: Words::new(&p.buffer_words),
            capture_at: vec![None; n],
            is_output: vec![0u64; n.div_ceil(64)],
            output_words: vec![0u32; n_pe],
            bus: vec![(0, Value::with_number(0)); n_pe],
            ports: vec![(0, 0); n_pe],
            buf_reads: vec![(0, 0); n_pe],
            busy: vec![(0, Value::with_number(0)); n_pe],
        })
    }

    /// Places every output (in `Function::outputs` order) in an output memory: an op result is
    /// captured at its arrival into its producer's output memory (one word per value); an
    /// input, trig value or constant is loaded into the output memory of slot 0 (one word per
    /// distinct value). Checks that each output's value exists and, for the loaded ones, that
    /// there is a PE. Sizes the output memories (words) and fills their initial words.
    fn outputs(&mut self) -> Result<Vec<OutputLoc>, SimError> {
        let (r, f) = (&self.r, self.r.f);
        let n_pe = r.p.arch.n_pe();
        let mut outputs = Vec::with_capacity(f.outputs.len());
        let mut init_out: HashMap<Key, u32> = HashMap::new();
        let output_words = &mut self.output_words;
        for o in &f.outputs {
            if let Operand::Value(v) = o.value {
                r.value_ok(v, "an output")?;
            }
            let (slot, addr) = match o.value {
                Operand::Value(v) if f.op_kind(v).is_some() => {
                    let slot = r.slot(r.issue(v).pe);
                    let a = *self.capture_at[v.index()].get_or_insert_with(|| {
                        output_words[slot] += 1;
                        output_words[slot] - 1
                    });
                    (slot, a)
                }
                _ => {
                    if n_pe == 0 {
                        return Err(SimError::new(K::Malformed, "no PE holds an output memory")
                            .at(When::End)
                            .of(format!("output `{}`", o.name))
                            .src(o.span));
                    }
                    let k = Key::of(&o.value);
                    let a = *init_out.entry(k).or_insert_with(|| {
                        output_words[0] += 1;
                        output_words[0] - 1
                    });
                    (0, a)
                }
            };
            outputs.push(OutputLoc { name: o.name.clone(), slot, addr });
        }
        for (s, q) in self.pes.iter_mut().enumerate() {
            q.output_init.resize(self.output_words[s] as usize, None);
        }
        for (i, c) in self.capture_at.iter().enumerate() {
            if c.is_some() {
                self.is_output[i / 64] |= 1 << (i % 64);
            }
        }
        for (&k, &a) in &init_out {
            self.pes[0].output_init[a as usize] = Some(word(f, k));
        }
        Ok(outputs)
    }

    /// The loads, before cycle 0 (time −1), in placement order: each stores its word into its
    /// PE's memory ([`Self::store`]) and sets that word of the PE's initial memory.
    fn loads(&mut self) -> Result<(), SimError> {
        let p = self.r.p;
        for (i, l) in p.loads.iter().enumerate() {
            self.store(i, -1, When::Load)?;
            self.pes[self.r.slot(l.pe)].init[l.addr as usize] = Some(word(self.r.f, Key::of(&l.operand)));
        }
        Ok(())
    }

    /// Stores memory event `e` (a load at time −1, or a write at cycle `now`) into its PE
    /// memory word, reported at `when`: the address must be below the memory's reported size
    /// (words), and the word's old value neither written in the same cycle nor read at a cycle
    /// ≥ `now` (address reuse).
    fn store(&mut self, e: usize, now: i64, when: When) -> Result<(), SimError> {
        let (r, p, plan) = (&self.r, self.r.p, self.plan);
        let mem_ev = &plan.mem_ev;
        // The placement line of memory event `e` (a load, then the writes).
        let span = |e: usize| if e < plan.n_loads { p.spans.load(e) } else { p.spans.write(e - plan.n_loads) };
        let ev = &mem_ev[e];
        let words = p.pe_words[ev.slot];
        if ev.addr >= words {
            return Err(SimError::new(
                K::AddressOutOfRange,
                format!(
                    "written at address {} of the memory of {}, which reports {words} words (memory larger than reported)",
                    ev.addr, ev.pe
                ),
            )
            .at(when)
            .on(ev.pe)
            .of(r.name(ev.key))
            .src(span(e)));
        }
        occupy(&mut self.mem, (ev.slot, ev.addr), e, now, |x| mem_ev[x].time, |x| mem_ev[x].last_read).map_err(
            |(old, read)| {
                reuse_error("memory", ev.addr, r.name(mem_ev[old].key), r.name(ev.key), read)
                    .at(when)
                    .on(ev.pe)
                    .src(span(e))
            },
        )
    }

    /// Cycle `c`, when anything happens then (an empty cycle is skipped, without polling the
    /// stop hook): the results arriving, their buffer entries, the writes into PE memories and
    /// the ops issued, in that order.
    fn cycle(&mut self, c: u32) -> Result<(), SimError> {
        if self.plan.buckets.is_empty(c) {
            return Ok(());
        }
        self.r.poll()?;
        self.arrivals(c)?;
        self.buffer_entries(c)?;
        self.writes(c)?;
        self.issues(c)
    }

    /// The results arriving at cycle `c`, in body order: at most one per PE (a PE has one
    /// result bus); an output is captured into its producer's output memory at this cycle.
    fn arrivals(&mut self, c: u32) -> Result<(), SimError> {
        let (r, plan) = (&self.r, self.plan);
        let mark = c + 1;
        for &(v, pe) in plan.buckets.arrivals.at(c) {
            let held = std::mem::replace(&mut self.bus[r.slot(pe)], (mark, v));
            if let Some(u) = (held.0 == mark).then_some(held.1) {
                return Err(SimError::new(
                    K::ResultCollision,
                    format!(
                        "arrives on {pe} in the same cycle as {}; a PE has one result bus (latencies differ)",
                        r.vname(u)
                    ),
                )
                .at(When::Cycle(c))
                .on(pe)
                .of(r.vname(v))
                .src(r.p.spans.issue(v)));
            }
            if self.is_output[v.index() / 64] >> (v.index() % 64) & 1 == 1 {
                self.pes[r.slot(pe)].steps[c as usize].capture = self.capture_at[v.index()];
            }
        }
        Ok(())
    }

    /// The results arriving at cycle `c` that enter their producer's buffer: the architecture
    /// must have buffers, the address must be below the buffer's reported size (words), and
    /// the word's old entry neither entered in the same cycle nor read at a cycle ≥ `c`.
    fn buffer_entries(&mut self, c: u32) -> Result<(), SimError> {
        let (r, p, plan) = (&self.r, self.r.p, self.plan);
        let buf_ev = &plan.buf_ev;
        let now = When::Cycle(c);
        for &b in plan.buckets.entries.at(c) {
            let ev = &buf_ev[b];
            if !p.arch.buffer {
                return Err(SimError::new(K::NoBuffer, "written indirectly, but the architecture has no buffers")
                    .at(now)
                    .on(ev.pe)
                    .of(r.vname(ev.value))
                    .src(p.spans.write(ev.write)));
            }
            let words = p.buffer_words[ev.slot];
            if ev.addr >= words {
                return Err(SimError::new(
                    K::AddressOutOfRange,
                    format!(
                        "enters address {} of the buffer of {}, which reports {words} words (memory larger than reported)",
                        ev.addr, ev.pe
                    ),
                )
                .at(now)
                .on(ev.pe)
                .of(r.vname(ev.value))
                .src(p.spans.write(ev.write)));
            }
            occupy(
                &mut self.buf,
                (ev.slot, ev.addr),
                b,
                c as i64,
                |x| buf_ev[x].arrival as i64,
                |x| Some(buf_ev[x].last_read as i64),
            )
            .map_err(|(old, read)| {
                reuse_error("buffer", ev.addr, r.vname(buf_ev[old].value), r.vname(ev.value), read)
                    .at(now)
                    .on(ev.pe)
                    .src(p.spans.write(ev.write))
            })?;
            self.pes[ev.slot].steps[c as usize].buffer.store = Some(ev.addr);
        }
        Ok(())
    }

    /// The writes into PE memories at cycle `c`, in `Placement::writes` order: each takes its
    /// source ([`Self::write_source`]), then one write port of its target memory (at most
    /// `arch.writes` per memory per cycle), then stores its word ([`Self::store`]).
    fn writes(&mut self, c: u32) -> Result<(), SimError> {
        let (p, plan) = (self.r.p, self.plan);
        let mark = c + 1;
        for &wi in plan.buckets.writes.at(c) {
            let w = &p.writes[wi];
            let v = w.value;
            let src = self.write_source(wi, c)?;
            let e = plan.n_loads + wi;
            let slot = plan.mem_ev[e].slot;
            let ports = &mut self.ports[slot];
            if ports.0 != mark {
                *ports = (mark, 0);
            }
            ports.1 += 1;
            let used = ports.1;
            if used > p.arch.writes {
                return Err(SimError::new(
                    K::WritePorts,
                    format!(
                        "write number {used} into the memory of {} in one cycle; it has {} write ports",
                        w.pe, p.arch.writes
                    ),
                )
                .at(When::Cycle(c))
                .on(w.pe)
                .of(self.r.vname(v))
                .src(p.spans.issue(v)));
            }
            self.store(e, c as i64, When::Cycle(c))?;
            self.pes[slot].steps[c as usize].writes.push(MemWrite { addr: w.addr, src });
        }
        Ok(())
    }

    /// Where write `wi` at cycle `c` takes its value: a direct write takes the result bus of
    /// the value's PE, at the value's arrival cycle exactly; an indirect one reads its buffer
    /// entry ([`Self::buffer_read`]).
    fn write_source(&mut self, wi: usize, c: u32) -> Result<Source, SimError> {
        let (r, plan) = (&self.r, self.plan);
        let w = &r.p.writes[wi];
        let v = w.value;
        let arr = plan.arrival[v.index()].expect("ops arrive");
        match plan.buf_of_write[wi] {
            None => {
                if c != arr {
                    return Err(SimError::new(
                        K::DirectWriteCycle,
                        format!("written directly into {} at cycle {c}, but it arrives at cycle {arr}", w.pe),
                    )
                    .at(When::Cycle(c))
                    .on(w.pe)
                    .of(r.vname(v))
                    .src(r.p.spans.write(wi)));
                }
                Ok(Source::Result(r.slot(r.issue(v).pe)))
            }
            Some(b) => self.buffer_read(wi, b, arr, c),
        }
    }

    /// Indirect write `wi` at cycle `c` reading buffer entry `b` of a value arriving at cycle
    /// `arr`: the architecture must have buffers, the value must have arrived (`c ≥ arr`), the
    /// buffer must not be read at another address in this cycle (one buffer read per cycle,
    /// fanning out to any number of memories), and the entry must still be in its word. Sets
    /// the buffer read of the PE's step.
    fn buffer_read(&mut self, wi: usize, b: usize, arr: u32, c: u32) -> Result<Source, SimError> {
        let (r, plan) = (&self.r, self.plan);
        let v = r.p.writes[wi].value;
        let now = When::Cycle(c);
        let ev = &plan.buf_ev[b];
        if !r.p.arch.buffer {
            return Err(SimError::new(K::NoBuffer, "written indirectly, but the architecture has no buffers")
                .at(now)
                .on(ev.pe)
                .of(r.vname(v))
                .src(r.p.spans.write(wi)));
        }
        if c < arr {
            return Err(SimError::new(
                K::BufferReadBeforeArrival,
                format!("read from the buffer of {} at cycle {c}, before it arrives at cycle {arr}", ev.pe),
            )
            .at(now)
            .on(ev.pe)
            .of(r.vname(v))
            .src(r.p.spans.write(wi)));
        }
        let mark = c + 1;
        if let Some(other) = (self.buf_reads[ev.slot].0 == mark).then_some(self.buf_reads[ev.slot].1) {
            let o = &plan.buf_ev[other];
            if o.addr != ev.addr {
                return Err(SimError::new(
                    K::BufferReads,
                    format!(
                        "buffer of {} read twice in one cycle (address {} for {}, address {} for {}); \
                         one buffer read per cycle",
                        ev.pe,
                        o.addr,
                        r.vname(o.value),
                        ev.addr,
                        r.vname(v)
                    ),
                )
                .at(now)
                .on(ev.pe)
                .of(r.vname(v))
                .src(r.p.spans.write(wi)));
            }
        }
        self.buf_reads[ev.slot] = (mark, b);
        if self.buf.get(ev.slot, ev.addr) != Some(b) {
            return Err(SimError::new(
                K::ReadMissing,
                format!("address {} of the buffer of {} no longer holds it", ev.addr, ev.pe),
            )
            .at(now)
            .on(ev.pe)
            .of(r.vname(v))
            .src(r.p.spans.write(wi)));
        }
        self.pes[ev.slot].steps[c as usize].buffer.read = Some(ev.addr);
        Ok(Source::Buffer(ev.slot))
    }

    /// The ops issued at cycle `c`, in body order: each on a PE of its type, at most one per
    /// PE per cycle, reading its operands from that PE's memory ([`Self::operand_addrs`]).
    /// Sets the PE's instruction at this cycle and the op's issue (slot, cycle).
    fn issues(&mut self, c: u32) -> Result<(), SimError> {
        let plan = self.plan;
        let now = When::Cycle(c);
        let mark = c + 1;
        for item in plan.buckets.issues.at(c) {
            let (r, v, kind, pe) = (&self.r, item.value, item.kind, item.pe);
            if !pe.accepts(kind) {
                return Err(SimError::new(
                    K::WrongPeType,
                    format!("{kind:?} op issued on {pe}, a PE of the wrong type"),
                )
                .at(now)
                .on(pe)
                .of(r.vname(v))
                .src(r.p.spans.issue(v)));
            }
            let slot = r.slot(pe);
            let held = self.busy[slot];
            if let Some(other) = (held.0 == mark).then_some(held.1) {
                return Err(SimError::new(
                    K::PeBusy,
                    format!("issued on {pe} in the same cycle as {}; one op per PE per cycle", r.vname(other)),
                )
                .at(now)
                .on(pe)
                .of(r.vname(v))
                .src(r.p.spans.issue(v)));
            }
            self.busy[slot] = (mark, v);
            let reads = self.operand_addrs(item, c)?;
            let op = machine_op(self.r.f, item);
            self.pes[slot].steps[c as usize].issue = Some(Instr { op, reads });
            self.issue_of[v.index()] = Some((slot, c));
        }
        Ok(())
    }

    /// The memory addresses op `item`, issued at cycle `c`, reads its operands at, in operand
    /// order: an op operand must have arrived (arrival ≤ `c`), and every operand must be in
    /// the issuing PE's memory — written or loaded there at a cycle ≤ `c` and not overwritten
    /// since (the read addresses the lowering chooses: see the module doc of [`super`]).
    fn operand_addrs(&self, item: &IssueItem, c: u32) -> Result<ReadAddrs, SimError> {
        let (r, plan) = (&self.r, self.plan);
        let (v, pe) = (item.value, item.pe);
        let now = When::Cycle(c);
        let mut addrs = ReadAddrs::new();
        for &(k, res, arrives) in plan.reads.range(item.reads) {
            if let Key::Value(_) = k {
                if let Some(a) = arrives.filter(|&a| a > c) {
                    return Err(SimError::new(
                        K::BeforeArrival,
                        format!("operand of {}, issued on {pe} at cycle {c}, arrives only at cycle {a}", r.vname(v)),
                    )
                    .at(now)
                    .on(pe)
                    .of(r.name(k))
                    .src(r.p.spans.issue(v)));
                }
            }
            let missing = |why: String| {
                SimError::new(K::ReadMissing, format!("operand of {} is not in the memory of {pe} ({why})", r.vname(v)))
                    .at(now)
                    .on(pe)
                    .of(r.name(k))
                    .src(r.p.spans.issue(v))
            };
            match res {
                Err(None) => return Err(missing("never written or loaded there".into())),
                Err(Some(t)) => return Err(missing(format!("written there only at cycle {t}"))),
                Ok(e) => {
                    let ev = &plan.mem_ev[e];
                    if self.mem.get(ev.slot, ev.addr) != Some(e) {
                        return Err(missing(format!("overwritten at address {}", ev.addr)));
                    }
                    addrs.push(ev.addr);
                }
            }
        }
        Ok(addrs)
    }

    /// The program (its `cycles`: the plan's last cycle, one step per cycle `0..=cycles`) and
    /// the peak occupancy of every memory and buffer, words: a memory word is occupied from its
    /// write (loads: cycle −1) to its last read (or only in its write cycle when never read), a
    /// buffer word from arrival to its last read.
    fn finish(self, outputs: Vec<OutputLoc>) -> (MachineProgram, Occupancy) {
        let (p, plan) = (self.r.p, self.plan);
        let n_pe = p.arch.n_pe();
        let program = MachineProgram {
            arch: p.arch,
            cycles: plan.buckets.last,
            pe_words: p.pe_words.clone(),
            buffer_words: p.buffer_words.clone(),
            output_words: self.output_words,
            pes: self.pes,
            outputs,
            issue_of: self.issue_of,
            fixed: None,
        };
        let occupancy = Occupancy {
            max_words_per_memory: peak(
                n_pe,
                plan.mem_ev.iter().map(|e| (e.slot, e.time, e.last_read.unwrap_or(e.time).max(e.time))),
            ),
            max_buffer_words: peak(
                n_pe,
                plan.buf_ev.iter().map(|b| (b.slot, b.arrival as i64, b.last_read.max(b.arrival) as i64)),
            ),
        };
        (program, occupancy)
    }
}
