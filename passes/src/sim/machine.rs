//! The machine: runs a [`Plan`] cycle by cycle (see the module doc of [`super`] for the rules).

use std::collections::HashMap;

use robovec_ir::interp::{eval_binop, eval_call, Float};
use robovec_ir::placement::{Pe, Placement};
use robovec_ir::syntax::{Def, Operand, TrigFn};
use robovec_ir::{Function, Value};

use super::error::{SimError, SimErrorKind as K, When};
use super::plan::{Key, Plan, Run};
use super::SimOutcome;

/// Marks word `at` as holding event `new` from `now`; `start`/`last` give an event's write
/// time and last read. Errors name the old event when it is still needed or was written in
/// the same cycle.
fn occupy(
    words: &mut HashMap<(usize, u32), usize>,
    at: (usize, u32),
    new: usize,
    now: i64,
    start: impl Fn(usize) -> i64,
    last: impl Fn(usize) -> Option<i64>,
) -> Result<(), (usize, Option<i64>)> {
    if let Some(&old) = words.get(&at) {
        if start(old) == now {
            return Err((old, None));
        }
        if let Some(r) = last(old).filter(|&r| r >= now) {
            return Err((old, Some(r)));
        }
    }
    words.insert(at, new);
    Ok(())
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
fn peak(n: usize, items: impl Iterator<Item = (usize, i64, i64)>) -> Vec<u32> {
    let mut ev: Vec<Vec<(i64, i32)>> = vec![Vec::new(); n];
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

/// Simulates `p` on `f`; see [`super::simulate`].
pub(super) fn run<T: Float>(
    f: &Function,
    p: &Placement,
    mut input: impl FnMut(&str) -> f64,
) -> Result<SimOutcome<T>, SimError> {
    let r = Run { f, p };
    let Plan { arrival, cycles, n_loads, mem_ev, reads, buf_ev, buf_of_write, buckets } = r.derive()?;
    let n = f.values.len();
    let arch = p.arch;
    let issue = |v: Value| r.issue(v);

    // Initial data in precision T, exactly as `interp` computes it.
    let mut init: Vec<Option<T>> = vec![None; n];
    for &v in &f.inputs {
        init[v.index()] = Some(T::from_f64(input(f.name_of(v))));
    }
    for &v in &f.body {
        if let Def::Trig(t, a) = f.value(v).def {
            let x = init[a.index()].unwrap_or(T::from_f64(f64::NAN));
            init[v.index()] = Some(match t {
                TrigFn::Sin => x.sin(),
                TrigFn::Cos => x.cos(),
            });
        }
    }

    let mut mem: HashMap<(usize, u32), usize> = HashMap::new();
    let mut mem_data: Vec<Option<T>> = vec![None; mem_ev.len()];
    let mut buf: HashMap<(usize, u32), usize> = HashMap::new();
    let mut buf_data: Vec<Option<T>> = vec![None; buf_ev.len()];
    let mut result: Vec<Option<T>> = vec![None; n];
    let mut issued_add = vec![0u32; cycles as usize];
    let mut issued_mul = vec![0u32; cycles as usize];

    // The placement line of memory event `e` (a load, then the writes).
    let mem_span = |e: usize| if e < n_loads { p.spans.load(e) } else { p.spans.write(e - n_loads) };
    // Writes one PE memory word: bounds, reuse.
    let store = |mem: &mut HashMap<(usize, u32), usize>, e: usize, now: i64, when: When| -> Result<(), SimError> {
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
        mem_data[i] = Some(match l.operand {
            Operand::Const(c) => T::from_f64(c),
            Operand::Value(v) => init[v.index()].expect("checked: loads are inputs or trig"),
        });
    }

    for (&c, bucket) in &buckets {
        let now = When::Cycle(c);
        // Results arriving now enter their producer's buffer.
        for &b in &bucket.entries {
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
            buf_data[b] = Some(result[ev.value.index()].expect("issued before arrival"));
        }

        // Writes into PE memories: direct (arrivals) and from buffers.
        let mut ports: HashMap<usize, u32> = HashMap::new();
        let mut buf_reads: HashMap<usize, usize> = HashMap::new();
        for &wi in &bucket.writes {
            let w = &p.writes[wi];
            let v = w.value;
            let arr = arrival[v.index()].expect("ops arrive");
            let data = match buf_of_write[wi] {
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
                    result[v.index()].expect("issued before arrival")
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
                    if let Some(&other) = buf_reads.get(&ev.slot) {
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
                    buf_reads.insert(ev.slot, b);
                    if buf.get(&(ev.slot, ev.addr)) != Some(&b) {
                        return Err(SimError::new(
                            K::ReadMissing,
                            format!("address {} of the buffer of {} no longer holds it", ev.addr, ev.pe),
                        )
                        .at(now)
                        .on(ev.pe)
                        .of(r.vname(v))
                        .src(p.spans.write(wi)));
                    }
                    buf_data[b].expect("entered at arrival")
                }
            };
            let e = n_loads + wi;
            let slot = mem_ev[e].slot;
            let used = ports.entry(slot).or_insert(0);
            *used += 1;
            if *used > arch.writes {
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
            mem_data[e] = Some(data);
        }

        // Ops issued now read their operands and enter the pipeline.
        let mut busy: HashMap<usize, Value> = HashMap::new();
        for &v in &bucket.issues {
            let is = issue(v);
            let kind = f.op_kind(v).expect("issued values are ops");
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
            if let Some(&other) = busy.get(&r.slot(is.pe)) {
                return Err(SimError::new(
                    K::PeBusy,
                    format!("issued on {} in the same cycle as {}; one op per PE per cycle", is.pe, r.vname(other)),
                )
                .at(now)
                .on(is.pe)
                .of(r.vname(v))
                .src(p.spans.issue(v)));
            }
            busy.insert(r.slot(is.pe), v);
            let mut args: Vec<T> = Vec::new();
            for &(k, res) in &reads[v.index()] {
                if let Key::Value(u) = k {
                    if let Some(a) = arrival[u.index()].filter(|&a| a > c) {
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
                        if mem.get(&(mem_ev[e].slot, mem_ev[e].addr)) != Some(&e) {
                            return Err(missing(format!("overwritten at address {}", mem_ev[e].addr)));
                        }
                        args.push(mem_data[e].expect("written"));
                    }
                }
            }
            result[v.index()] = Some(match &f.value(v).def {
                Def::Binary(op, _, _) => eval_binop(*op, args[0], args[1]),
                Def::Call(callee, _) => eval_call(callee, &args),
                _ => unreachable!("ops are binary or calls"),
            });
            match is.pe {
                Pe::Add(_) => issued_add[c as usize] += 1,
                Pe::Mul(_) => issued_mul[c as usize] += 1,
            }
        }
    }

    let mut outputs = Vec::with_capacity(f.outputs.len());
    for o in &f.outputs {
        let x = match o.value {
            Operand::Const(c) => T::from_f64(c),
            Operand::Value(v) => {
                r.value_ok(v, "an output")?;
                match result[v.index()].or(init[v.index()]) {
                    Some(x) => x,
                    None => {
                        return Err(SimError::new(
                            K::OutputUnavailable,
                            format!("output `{}` was never computed", o.name),
                        )
                        .at(When::End)
                        .of(r.vname(v))
                        .src(o.span))
                    }
                }
            }
        };
        outputs.push((o.name.clone(), x));
    }

    let n_pe = arch.n_pe();
    Ok(SimOutcome {
        outputs,
        cycles,
        writes_direct: p.writes.iter().filter(|w| w.buffer_addr.is_none()).count() as u32,
        writes_indirect: p.writes.iter().filter(|w| w.buffer_addr.is_some()).count() as u32,
        max_words_per_memory: peak(
            n_pe,
            mem_ev.iter().map(|e| (e.slot, e.time, e.last_read.unwrap_or(e.time).max(e.time))),
        ),
        max_buffer_words: peak(
            n_pe,
            buf_ev.iter().map(|b| (b.slot, b.arrival as i64, b.last_read.max(b.arrival) as i64)),
        ),
        issued_per_cycle_add: issued_add,
        issued_per_cycle_mul: issued_mul,
    })
}
