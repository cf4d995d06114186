//! The lowering: checks a [`Placement`] against every rule of the machine model and builds the
//! [`MachineProgram`] (see the module doc of [`super`] for the rules and choices).

use std::collections::HashMap;

use robovec_ir::machine::{
    Held as Key, Instr, MachineOp, MachineProgram, MemWrite, OutputLoc, PeProgram, ReadAddrs, Source, Step, Word,
};
use robovec_ir::placement::Placement;
use robovec_ir::syntax::{BinOp, Def, Operand};
use robovec_ir::{Function, Value};

use super::plan::{Plan, Run};
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
    let Plan { arrival, n_loads, mem_ev, reads, buf_ev, buf_of_write, buckets } = r.derive()?;
    // The program runs until its last event: the last arrival, or a later write from a buffer.
    let cycles = buckets.last;
    let n = f.values.len();
    let arch = p.arch;
    let n_pe = arch.n_pe();
    let issue = |v: Value| r.issue(v);
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
    let mut pes: Vec<PeProgram> = arch
        .pes()
        .enumerate()
        .map(|(s, pe)| PeProgram {
            pe,
            init: vec![None; p.pe_words[s] as usize],
            output_init: Vec::new(),
            steps: vec![Step::default(); cycles as usize + 1],
        })
        .collect();
    let mut issue_of: Vec<Option<(usize, u32)>> = vec![None; n];

    let mut mem = Words::new(&p.pe_words);
    let mut buf = Words::new(&p.buffer_words);
    let word = |k: Key| -> Word {
        match k {
            Key::Const(b) => Word::Const(f64::from_bits(b)),
            Key::Value(v) => match f.value(v).def {
                Def::Trig(t, a) => Word::Trig(t, f.name_of(a).to_string()),
                _ => Word::Input(f.name_of(v).to_string()),
            },
        }
    };
    // Output capture: each op output is captured once, at its arrival, into its producer's
    // output memory; outputs that are initial data or constants are loaded into slot 0's.
    let mut capture_at: Vec<Option<u32>> = vec![None; n];
    let mut output_words = vec![0u32; n_pe];
    let mut outputs = Vec::with_capacity(f.outputs.len());
    let mut init_out: HashMap<Key, u32> = HashMap::new();
    for o in &f.outputs {
        if let Operand::Value(v) = o.value {
            r.value_ok(v, "an output")?;
        }
        let (slot, addr) = match o.value {
            Operand::Value(v) if f.op_kind(v).is_some() => {
                let slot = r.slot(issue(v).pe);
                let a = *capture_at[v.index()].get_or_insert_with(|| {
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
    for (s, q) in pes.iter_mut().enumerate() {
        q.output_init.resize(output_words[s] as usize, None);
    }
    // Which values are captured outputs, a bit each: the arrivals test it before reading
    // `capture_at` (8 bytes a value, read in cycle order; issue 28).
    let mut is_output = vec![0u64; n.div_ceil(64)];
    for (i, c) in capture_at.iter().enumerate() {
        if c.is_some() {
            is_output[i / 64] |= 1 << (i % 64);
        }
    }
    for (&k, &a) in &init_out {
        pes[0].output_init[a as usize] = Some(word(k));
    }

    // The placement line of memory event `e` (a load, then the writes).
    let mem_span = |e: usize| if e < n_loads { p.spans.load(e) } else { p.spans.write(e - n_loads) };
    // Writes one PE memory word: bounds, reuse.
    let store = |mem: &mut Words, e: usize, now: i64, when: When| -> Result<(), SimError> {
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
            .src(mem_span(e)));
        }
        occupy(mem, (ev.slot, ev.addr), e, now, |x| mem_ev[x].time, |x| mem_ev[x].last_read).map_err(|(old, read)| {
            reuse_error("memory", ev.addr, r.name(mem_ev[old].key), r.name(ev.key), read)
                .at(when)
                .on(ev.pe)
                .src(mem_span(e))
        })
    };

    // Loads, before cycle 0.
    for (i, l) in p.loads.iter().enumerate() {
        store(&mut mem, i, -1, When::Load)?;
        pes[r.slot(l.pe)].init[l.addr as usize] = Some(word(Key::of(&l.operand)));
    }

    // Per-PE state of the current cycle, marked with the cycle (+ 1) it belongs to, so that
    // nothing is cleared between cycles: the result bus, write ports used, the buffer read, the
    // op issued.
    let mut bus: Vec<(u32, Value)> = vec![(0, Value::with_number(0)); n_pe];
    let mut ports: Vec<(u32, u32)> = vec![(0, 0); n_pe];
    let mut buf_reads: Vec<(u32, usize)> = vec![(0, 0); n_pe];
    let mut busy: Vec<(u32, Value)> = vec![(0, Value::with_number(0)); n_pe];
    for c in 0..=buckets.last {
        if buckets.is_empty(c) {
            continue;
        }
        r.poll()?;
        let now = When::Cycle(c);
        let mark = c + 1;
        // Results arriving now: one per PE (one result bus), captured when outputs.
        for &(v, pe) in buckets.arrivals.at(c) {
            let held = std::mem::replace(&mut bus[r.slot(pe)], (mark, v));
            if let Some(u) = (held.0 == mark).then_some(held.1) {
                return Err(SimError::new(
                    K::ResultCollision,
                    format!(
                        "arrives on {pe} in the same cycle as {}; a PE has one result bus (latencies differ)",
                        r.vname(u)
                    ),
                )
                .at(now)
                .on(pe)
                .of(r.vname(v))
                .src(p.spans.issue(v)));
            }
            if is_output[v.index() / 64] >> (v.index() % 64) & 1 == 1 {
                pes[r.slot(pe)].steps[c as usize].capture = capture_at[v.index()];
            }
        }
        // Results arriving now enter their producer's buffer.
        for &b in buckets.entries.at(c) {
            let ev = &buf_ev[b];
            if !arch.buffer {
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
                &mut buf,
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
            pes[ev.slot].steps[c as usize].buffer.store = Some(ev.addr);
        }

        // Writes into PE memories: direct (arrivals) and from buffers.
        for &wi in buckets.writes.at(c) {
            let w = &p.writes[wi];
            let v = w.value;
            let arr = arrival[v.index()].expect("ops arrive");
            let src = match buf_of_write[wi] {
                None => {
                    if c != arr {
                        return Err(SimError::new(
                            K::DirectWriteCycle,
                            format!("written directly into {} at cycle {c}, but it arrives at cycle {arr}", w.pe),
                        )
                        .at(now)
                        .on(w.pe)
                        .of(r.vname(v))
                        .src(p.spans.write(wi)));
                    }
                    Source::Result(r.slot(issue(v).pe))
                }
                Some(b) => {
                    let ev = &buf_ev[b];
                    if !arch.buffer {
                        return Err(SimError::new(
                            K::NoBuffer,
                            "written indirectly, but the architecture has no buffers",
                        )
                        .at(now)
                        .on(ev.pe)
                        .of(r.vname(v))
                        .src(p.spans.write(wi)));
                    }
                    if c < arr {
                        return Err(SimError::new(
                            K::BufferReadBeforeArrival,
                            format!("read from the buffer of {} at cycle {c}, before it arrives at cycle {arr}", ev.pe),
                        )
                        .at(now)
                        .on(ev.pe)
                        .of(r.vname(v))
                        .src(p.spans.write(wi)));
                    }
                    if let Some(other) = (buf_reads[ev.slot].0 == mark).then_some(buf_reads[ev.slot].1) {
                        let o = &buf_ev[other];
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
                            .src(p.spans.write(wi)));
                        }
                    }
                    buf_reads[ev.slot] = (mark, b);
                    if buf.get(ev.slot, ev.addr) != Some(b) {
                        return Err(SimError::new(
                            K::ReadMissing,
                            format!("address {} of the buffer of {} no longer holds it", ev.addr, ev.pe),
                        )
                        .at(now)
                        .on(ev.pe)
                        .of(r.vname(v))
                        .src(p.spans.write(wi)));
                    }
                    pes[ev.slot].steps[c as usize].buffer.read = Some(ev.addr);
                    Source::Buffer(ev.slot)
                }
            };
            let e = n_loads + wi;
            let slot = mem_ev[e].slot;
            if ports[slot].0 != mark {
                ports[slot] = (mark, 0);
            }
            ports[slot].1 += 1;
            let used = ports[slot].1;
            if used > arch.writes {
                return Err(SimError::new(
                    K::WritePorts,
                    format!(
                        "write number {used} into the memory of {} in one cycle; it has {} write ports",
                        w.pe, arch.writes
                    ),
                )
                .at(now)
                .on(w.pe)
                .of(r.vname(v))
                .src(p.spans.issue(v)));
            }
            store(&mut mem, e, c as i64, now)?;
            pes[slot].steps[c as usize].writes.push(MemWrite { addr: w.addr, src });
        }

        // Ops issued now read their operands and enter the pipeline.
        for item in buckets.issues.at(c) {
            let (v, kind) = (item.value, item.kind);
            let is = robovec_ir::placement::Issue { pe: item.pe, cycle: c };
            if !is.pe.accepts(kind) {
                return Err(SimError::new(
                    K::WrongPeType,
                    format!("{kind:?} op issued on {}, a PE of the wrong type", is.pe),
                )
                .at(now)
                .on(is.pe)
                .of(r.vname(v))
                .src(p.spans.issue(v)));
            }
            let held = busy[r.slot(is.pe)];
            if let Some(other) = (held.0 == mark).then_some(held.1) {
                return Err(SimError::new(
                    K::PeBusy,
                    format!("issued on {} in the same cycle as {}; one op per PE per cycle", is.pe, r.vname(other)),
                )
                .at(now)
                .on(is.pe)
                .of(r.vname(v))
                .src(p.spans.issue(v)));
            }
            busy[r.slot(is.pe)] = (mark, v);
            let mut addrs = ReadAddrs::new();
            for &(k, res, arrives) in reads.range(item.reads) {
                if let Key::Value(_) = k {
                    if let Some(a) = arrives.filter(|&a| a > c) {
                        return Err(SimError::new(
                            K::BeforeArrival,
                            format!(
                                "operand of {}, issued on {} at cycle {c}, arrives only at cycle {a}",
                                r.vname(v),
                                is.pe
                            ),
                        )
                        .at(now)
                        .on(is.pe)
                        .of(r.name(k))
                        .src(p.spans.issue(v)));
                    }
                }
                let missing = |why: String| {
                    SimError::new(
                        K::ReadMissing,
                        format!("operand of {} is not in the memory of {} ({why})", r.vname(v), is.pe),
                    )
                    .at(now)
                    .on(is.pe)
                    .of(r.name(k))
                    .src(p.spans.issue(v))
                };
                match res {
                    Err(None) => return Err(missing("never written or loaded there".into())),
                    Err(Some(t)) => return Err(missing(format!("written there only at cycle {t}"))),
                    Ok(e) => {
                        if mem.get(mem_ev[e].slot, mem_ev[e].addr) != Some(e) {
                            return Err(missing(format!("overwritten at address {}", mem_ev[e].addr)));
                        }
                        addrs.push(mem_ev[e].addr);
                    }
                }
            }
            let op = match item.bin {
                Some(BinOp::Add) => MachineOp::Add,
                Some(BinOp::Sub) => MachineOp::Sub,
                Some(BinOp::Mul) => MachineOp::Mul,
                Some(BinOp::Div) => MachineOp::Div,
                None => match &f.value(v).def {
                    Def::Call(callee, _) => MachineOp::Call(callee.clone()),
                    _ => unreachable!("ops are binary or calls"),
                },
            };
            pes[r.slot(is.pe)].steps[c as usize].issue = Some(Instr { op, reads: addrs });
            issue_of[v.index()] = Some((r.slot(is.pe), c));
        }
    }

    let program = MachineProgram {
        arch,
        cycles,
        pe_words: p.pe_words.clone(),
        buffer_words: p.buffer_words.clone(),
        output_words,
        pes,
        outputs,
        issue_of,
    };
    let occupancy = Occupancy {
        max_words_per_memory: peak(
            n_pe,
            mem_ev.iter().map(|e| (e.slot, e.time, e.last_read.unwrap_or(e.time).max(e.time))),
        ),
        max_buffer_words: peak(
            n_pe,
            buf_ev.iter().map(|b| (b.slot, b.arrival as i64, b.last_read.max(b.arrival) as i64)),
        ),
    };
    Ok((program, occupancy))
}
