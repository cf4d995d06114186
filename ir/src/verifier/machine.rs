//! Lowered checks of the verifier: a [`MachineProgram`] computes its function. Run by
//! `robovec_machine::program::lower` on every program it builds (always, not only in debug
//! builds: it costs one pass over the steps, see the lowering's module doc for the figure).
//! [`verify_machine_until`] gives up when its caller's `stop` hook says so (a time limit).
//!
//! The check executes the program on *tags* instead of numbers: every word holds the
//! [`Held`] key of the value or constant it contains. Checklist (each item is one
//! [`VerifierError`] message, at most [`MAX_ERRORS`] listed):
//! - shape: one program per PE in [`crate::placement::Pe::slot`] order, `cycles + 1` steps
//!   each, one initial word per PE-memory and output-memory address, sizes per slot;
//! - provenance: every op of the function issues at exactly the `(slot, cycle)` recorded in
//!   `issue_of`, whose step issues an instruction of the op's kind on a PE of its type, and no
//!   other step issues;
//! - every read address is below `pe_words` and holds, at the issue cycle (after that cycle's
//!   writes), the op's operand in operand order;
//! - every write: at most `arch.writes` per memory per cycle, no address twice in one cycle,
//!   address below `pe_words`, its source exists (a result arriving now on that slot, or a
//!   buffer read now on that slot, with `arch.buffer`);
//! - buffers: a store needs a result arriving now, a read an address holding a value, both
//!   below `buffer_words`; at most one result arrives per PE per cycle;
//! - output capture needs a result arriving now, below `output_words`;
//! - the output map is complete: one location per output of the function, in order, holding
//!   that output's value at the end.

use std::collections::HashMap;

use super::{Location, VerifierError};
use crate::function::Function;
use crate::machine::{Held, MachineOp, MachineProgram, Source, Word};
use crate::placement::Pe;
use crate::span::Span;
use crate::syntax::{BinOp, Def, Operand, TrigFn};
use crate::Value;

/// Largest number of lowered-program violations listed per function.
pub const MAX_ERRORS: usize = 20;

struct Errs<'a> {
    f: &'a Function,
    errs: Vec<VerifierError>,
    more: usize,
}

impl Errs<'_> {
    fn push(&mut self, message: String) {
        if self.errs.len() < MAX_ERRORS {
            self.errs.push(VerifierError {
                function: self.f.name.clone(),
                location: Location::Machine,
                message: format!("machine program: {message}"),
                span: Span::DUMMY,
            });
        } else {
            self.more += 1;
        }
    }
}

fn name(f: &Function, h: Option<Held>) -> String {
    match h {
        Some(Held::Value(v)) if v.index() < f.values.len() => format!("%{}", f.name_of(v)),
        Some(Held::Value(v)) => format!("{v}"),
        Some(Held::Const(b)) => format!("{:?}", f64::from_bits(b)),
        None => "nothing".into(),
    }
}

/// The trig initial variables of `f` by function and argument: `(sin, %q1) → %S1` (one pass
/// over the body, so that reading the initial words stays linear in the program).
fn trig_values(f: &Function) -> HashMap<(TrigFn, Value), Value> {
    let mut trig = HashMap::new();
    for &v in &f.body {
        if let Def::Trig(t, a) = f.value(v).def {
            // The first such value, as a search of the body would find.
            trig.entry((t, a)).or_insert(v);
        }
    }
    trig
}

/// The tag of an initial word, or why there is none; `trig` is [`trig_values`] of `f`.
fn held_of(f: &Function, trig: &HashMap<(TrigFn, Value), Value>, w: &Word) -> Result<Held, String> {
    let input = |n: &str| match f.lookup(n) {
        Some(v) if matches!(f.value(v).def, Def::Input) => Ok(v),
        _ => Err(format!("initial word names `{n}`, which is not an input")),
    };
    match w {
        Word::Const(c) => Ok(Held::Const(c.to_bits())),
        Word::Input(n) => input(n).map(Held::Value),
        Word::Trig(t, n) => {
            let x = input(n)?;
            trig.get(&(*t, x)).copied().map(Held::Value).ok_or_else(|| {
                let fun = if *t == TrigFn::Sin { "sin" } else { "cos" };
                format!("initial word `{fun} {n}` is not a value of the function")
            })
        }
    }
}

fn op_matches(op: &MachineOp, def: &Def) -> bool {
    match (op, def) {
        (MachineOp::Add, Def::Binary(BinOp::Add, _, _))
        | (MachineOp::Sub, Def::Binary(BinOp::Sub, _, _))
        | (MachineOp::Mul, Def::Binary(BinOp::Mul, _, _))
        | (MachineOp::Div, Def::Binary(BinOp::Div, _, _)) => true,
        (MachineOp::Call(c) | MachineOp::Mac(c), Def::Call(d, _)) => c == d,
        _ => false,
    }
}

fn operands(def: &Def) -> Vec<Operand> {
    match def {
        Def::Binary(_, a, b) => vec![*a, *b],
        Def::Call(_, args) => args.clone(),
        _ => Vec::new(),
    }
}

/// Checks that `p` computes `f` (see the module doc); returns every violation (at most
/// [`MAX_ERRORS`] plus one count of the rest), empty when the program verifies.
pub fn verify_machine(f: &Function, p: &MachineProgram) -> Vec<VerifierError> {
    verify_machine_until(f, p, &|| false).unwrap_or_default()
}

/// [`verify_machine`] that calls `stop` once per op of `f` and once per cycle of `p` and gives
/// up when it returns true (a caller's time limit): `None` then, the check incomplete.
pub fn verify_machine_until(f: &Function, p: &MachineProgram, stop: &dyn Fn() -> bool) -> Option<Vec<VerifierError>> {
    let mut e = Errs { f, errs: Vec::new(), more: 0 };
    check(f, p, &mut e, stop)?;
    if e.more > 0 {
        let more = e.more;
        e.errs.push(VerifierError {
            function: f.name.clone(),
            location: Location::Machine,
            message: format!("machine program: … and {more} more violations"),
            span: Span::DUMMY,
        });
    }
    Some(e.errs)
}

/// Pushes every violation on `e`; `None` when `stop` returned true.
fn check(f: &Function, p: &MachineProgram, e: &mut Errs, stop: &dyn Fn() -> bool) -> Option<()> {
    let a = p.arch;
    let n_pe = a.n_pe();
    let steps = p.cycles as usize + 1;
    // Shape first, so the rest can index infallibly.
    if p.pes.len() != n_pe || p.pe_words.len() != n_pe || p.buffer_words.len() != n_pe || p.output_words.len() != n_pe {
        e.push(format!(
            "{} PE programs, {} memory, {} buffer and {} output-memory sizes for {n_pe} PEs",
            p.pes.len(),
            p.pe_words.len(),
            p.buffer_words.len(),
            p.output_words.len()
        ));
        return Some(());
    }
    let mut shape_ok = true;
    for (s, (q, pe)) in p.pes.iter().zip(a.pes()).enumerate() {
        if q.pe != pe {
            e.push(format!("slot {s} holds the program of {}, expected {pe}", q.pe));
            shape_ok = false;
        }
        if q.steps.len() != steps {
            e.push(format!("{pe} has {} steps for cycles 0..={}", q.steps.len(), p.cycles));
            shape_ok = false;
        }
        if q.init.len() != p.pe_words[s] as usize || q.output_init.len() != p.output_words[s] as usize {
            e.push(format!(
                "{pe} has {} initial words for {} PE-memory words and {} for {} output words",
                q.init.len(),
                p.pe_words[s],
                q.output_init.len(),
                p.output_words[s]
            ));
            shape_ok = false;
        }
    }
    if p.issue_of.len() != f.values.len() {
        e.push(format!("provenance lists {} values, the function has {}", p.issue_of.len(), f.values.len()));
        shape_ok = false;
    }
    if !shape_ok {
        return Some(());
    }

    // Provenance: which value each (slot, cycle) issue computes; and the results arriving per
    // (slot, cycle), found in the same walk (each op's step read once: in body order the steps
    // are scattered over the program; issue 28), their violations reported after the
    // provenance's.
    let mut issued_value: Vec<Vec<Option<Value>>> = vec![vec![None; steps]; n_pe];
    let mut arriving: Vec<Vec<Option<Value>>> = vec![vec![None; steps]; n_pe];
    let mut arrival_errs: Vec<String> = Vec::new();
    for &v in &f.body {
        if stop() {
            return None;
        }
        let Some(kind) = f.op_kind(v) else {
            if p.issue_of[v.index()].is_some() {
                e.push(format!("%{} is not an op but has an issue", f.name_of(v)));
            }
            continue;
        };
        match p.issue_of[v.index()] {
            None => e.push(format!("op %{} is never issued", f.name_of(v))),
            Some((s, c)) if s >= n_pe || c as usize >= steps => {
                e.push(format!("op %{} issues at slot {s}, cycle {c}, outside the program", f.name_of(v)))
            }
            Some((s, c)) => {
                let pe = p.pes[s].pe;
                match &p.pes[s].steps[c as usize].issue {
                    None => {
                        e.push(format!("op %{} should issue on {pe} at cycle {c}, which issues nothing", f.name_of(v)))
                    }
                    Some(i) => {
                        if !op_matches(&i.op, &f.value(v).def) {
                            e.push(format!("cycle {c}, {pe}: issues {:?} for op %{}", i.op, f.name_of(v)));
                        }
                        if !pe.accepts(kind) {
                            e.push(format!("cycle {c}, {pe}: {kind:?} op %{} on a PE of the wrong type", f.name_of(v)));
                        }
                        if let Some(u) = issued_value[s][c as usize].replace(v) {
                            e.push(format!("cycle {c}, {pe}: issues both %{} and %{}", f.name_of(u), f.name_of(v)));
                        }
                        let at = c as usize + p.latency(&i.op) as usize;
                        if at >= steps {
                            let m =
                                format!("%{} arrives at cycle {at}, after the last cycle {}", f.name_of(v), p.cycles);
                            arrival_errs.push(m);
                        } else if let Some(u) = arriving[s][at].replace(v) {
                            arrival_errs.push(format!(
                                "cycle {at}, {pe}: %{} and %{} arrive in one cycle (one result bus per PE)",
                                f.name_of(u),
                                f.name_of(v)
                            ));
                        }
                    }
                }
            }
        }
    }
    for (s, q) in p.pes.iter().enumerate() {
        for (c, st) in q.steps.iter().enumerate() {
            if st.issue.is_some() && issued_value[s][c].is_none() {
                e.push(format!("cycle {c}, {}: issues an instruction of no op of the function", q.pe));
            }
        }
    }

    // Initial contents.
    let trig = trig_values(f);
    let tags = |init: &[Option<Word>], e: &mut Errs| -> Vec<Option<Held>> {
        init.iter()
            .map(|w| {
                w.as_ref().and_then(|w| match held_of(f, &trig, w) {
                    Ok(h) => Some(h),
                    Err(m) => {
                        e.push(m);
                        None
                    }
                })
            })
            .collect()
    };
    let mut mem: Vec<Vec<Option<Held>>> = p.pes.iter().map(|q| tags(&q.init, e)).collect();
    let mut out: Vec<Vec<Option<Held>>> = p.pes.iter().map(|q| tags(&q.output_init, e)).collect();
    let mut buf: Vec<Vec<Option<Held>>> = p.buffer_words.iter().map(|&w| vec![None; w as usize]).collect();
    for m in arrival_errs {
        e.push(m);
    }

    let mut bus: Vec<Option<Held>> = vec![None; n_pe];
    for c in 0..steps {
        if stop() {
            return None;
        }
        // 1. Arrivals enter buffers and output memories.
        for (s, q) in p.pes.iter().enumerate() {
            let st = &q.steps[c];
            let now = arriving[s][c].map(Held::Value);
            if let Some(addr) = st.buffer.store {
                if !a.buffer {
                    e.push(format!("cycle {c}, {}: buffer store without buffers", q.pe));
                } else if now.is_none() {
                    e.push(format!("cycle {c}, {}: buffer store, but no result arrives", q.pe));
                } else if addr >= p.buffer_words[s] {
                    e.push(format!("cycle {c}, {}: buffer address {addr} ≥ {} words", q.pe, p.buffer_words[s]));
                } else {
                    buf[s][addr as usize] = now;
                }
            }
            if let Some(addr) = st.capture {
                if now.is_none() {
                    e.push(format!("cycle {c}, {}: output capture, but no result arrives", q.pe));
                } else if addr >= p.output_words[s] {
                    e.push(format!("cycle {c}, {}: output address {addr} ≥ {} words", q.pe, p.output_words[s]));
                } else {
                    out[s][addr as usize] = now;
                }
            }
        }
        // 2. Buffer reads.
        for (s, q) in p.pes.iter().enumerate() {
            bus[s] = None;
            if let Some(addr) = q.steps[c].buffer.read {
                match buf[s].get(addr as usize) {
                    None => e.push(format!("cycle {c}, {}: buffer read at {addr} ≥ {} words", q.pe, p.buffer_words[s])),
                    Some(None) => e.push(format!("cycle {c}, {}: buffer read at {addr}, which holds nothing", q.pe)),
                    Some(h) => bus[s] = *h,
                }
            }
        }
        // 3. PE-memory writes.
        for (s, q) in p.pes.iter().enumerate() {
            let st = &q.steps[c];
            if st.writes.len() > a.writes as usize {
                e.push(format!("cycle {c}, {}: {} writes, {} write ports", q.pe, st.writes.len(), a.writes));
            }
            for (i, w) in st.writes.iter().enumerate() {
                if st.writes[..i].iter().any(|x| x.addr == w.addr) {
                    e.push(format!("cycle {c}, {}: address {} written twice", q.pe, w.addr));
                }
                let data = match w.src {
                    Source::Result(t) if t < n_pe => arriving[t][c].map(Held::Value),
                    Source::Buffer(t) if t < n_pe && a.buffer => bus[t],
                    Source::Buffer(t) if t < n_pe => {
                        e.push(format!("cycle {c}, {}: write from a buffer without buffers", q.pe));
                        continue;
                    }
                    _ => {
                        e.push(format!("cycle {c}, {}: write source {:?} names no PE", q.pe, w.src));
                        continue;
                    }
                };
                if data.is_none() {
                    e.push(format!("cycle {c}, {}: write source {:?} carries nothing this cycle", q.pe, w.src));
                } else if w.addr >= p.pe_words[s] {
                    e.push(format!("cycle {c}, {}: write address {} ≥ {} words", q.pe, w.addr, p.pe_words[s]));
                } else {
                    mem[s][w.addr as usize] = data;
                }
            }
        }
        // 4. Issues read their operands.
        for (s, q) in p.pes.iter().enumerate() {
            let (Some(i), Some(v)) = (&q.steps[c].issue, issued_value[s][c]) else { continue };
            let want = operands(&f.value(v).def);
            if want.len() != i.reads.len() {
                e.push(format!(
                    "cycle {c}, {}: %{} reads {} words, the op has {} operands",
                    q.pe,
                    f.name_of(v),
                    i.reads.len(),
                    want.len()
                ));
                continue;
            }
            for (k, (&addr, o)) in i.reads.iter().zip(&want).enumerate() {
                let got = mem[s].get(addr as usize).copied();
                match got {
                    None => e.push(format!("cycle {c}, {}: read address {addr} ≥ {} words", q.pe, p.pe_words[s])),
                    Some(h) if h != Some(Held::of(o)) => e.push(format!(
                        "cycle {c}, {}: operand {k} of %{} reads address {addr}, which holds {} instead of {}",
                        q.pe,
                        f.name_of(v),
                        name(f, h),
                        name(f, Some(Held::of(o)))
                    )),
                    Some(_) => {}
                }
            }
        }
    }

    // The output map.
    if p.outputs.len() != f.outputs.len() {
        e.push(format!("{} output locations for {} outputs", p.outputs.len(), f.outputs.len()));
        return Some(());
    }
    for (loc, o) in p.outputs.iter().zip(&f.outputs) {
        if loc.name != o.name {
            e.push(format!("output location `{}` where output `{}` was expected", loc.name, o.name));
            continue;
        }
        let got = out.get(loc.slot).and_then(|m| m.get(loc.addr as usize)).copied();
        match got {
            None => e.push(format!("output `{}` at slot {}, address {}: no such word", o.name, loc.slot, loc.addr)),
            Some(h) if h != Some(Held::of(&o.value)) => e.push(format!(
                "output `{}` reads {} at {}, address {}, instead of {}",
                o.name,
                name(f, h),
                p.pes.get(loc.slot).map_or(Pe::Add(u32::MAX), |q| q.pe),
                loc.addr,
                name(f, Some(Held::of(&o.value)))
            )),
            Some(_) => {}
        }
    }
    Some(())
}
