//! Placement checks of the verifier (issue 10 item 4): the rules of the machine model
//! ([`crate::placement`]) that need no simulation, checked in O(ops + loads + writes) with
//! hash maps, so they run whenever a placed `.rvir` is read and after every pass.
//!
//! Checklist (each item is one [`VerifierError`] message when broken):
//! - phase: a placement only on an atomised function (no nested expression remains);
//! - shape: one memory and one buffer size per PE, `n_add`, `n_mul` and every latency ≥ 1;
//! - every op issued exactly once, and nothing but ops issued or written;
//! - every issue, load and write names an existing PE (index below `n_add`/`n_mul`), and an op
//!   issues on a PE of its type ([`Pe::accepts`]);
//! - a PE issues at most one op per cycle;
//! - loads are initial data (inputs, trig values, constants);
//! - a direct write happens at its value's arrival (issue + latency); an indirect write needs
//!   `buffer=1`, happens at a cycle ≥ arrival, and a value enters its producer's buffer at one
//!   address; at most one distinct address is read per buffer per cycle;
//! - at most `writes` writes into one PE memory per cycle;
//! - every operand of an op is in the issuing PE's memory at its issue cycle: loaded, or
//!   written there at a cycle ≤ the issue (a valid write is never before arrival);
//! - every address is below the reported size (`pe_words`, `buffer_words`).
//!
//! Not checked here (the simulator `sim` does, since it needs every word's lifetime): a word
//! rewritten while its value is still to be read, and the values computed. The first
//! [`MAX_ERRORS`] violations of a function are listed, then a count of the rest.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::{Location, VerifierError};
use crate::function::Function;
use crate::machine::Held as Key;
use crate::placement::{Pe, Placement};
use crate::span::Span;
use crate::syntax::{Def, OpKind, Operand, Phase};
use crate::Value;

/// Largest number of placement violations listed per function.
pub const MAX_ERRORS: usize = 20;

/// A multiply-rotate hasher (the Fx hash of rustc) for the small integer keys of these maps:
/// the default SipHash costs more than the checks themselves on 600k-op placements.
#[derive(Default, Clone, Copy)]
struct Fx(u64);

impl Hasher for Fx {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u8(&mut self, x: u8) {
        self.write_u64(x as u64)
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64)
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64)
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type Map<K, V> = HashMap<K, V, BuildHasherDefault<Fx>>;

fn map<K, V>(capacity: usize) -> Map<K, V> {
    Map::with_capacity_and_hasher(capacity, Default::default())
}

/// The memory-word key shared with the placer and the lowering.
fn key_of(o: &Operand) -> Key {
    Key::of(o)
}

struct Sink<'f> {
    f: &'f Function,
    errs: Vec<VerifierError>,
    more: usize,
}

impl Sink<'_> {
    fn push(&mut self, span: Span, message: String) {
        if self.errs.len() < MAX_ERRORS {
            let span = if span == Span::DUMMY {
                self.f.placement.as_ref().map_or(Span::DUMMY, |p| p.spans.block)
            } else {
                span
            };
            self.errs.push(VerifierError {
                function: self.f.name.clone(),
                location: Location::Placement,
                message,
                span,
            });
        } else {
            self.more += 1;
        }
    }
}

/// Checks `f.placement` (nothing when there is none); returns every violation found.
pub fn verify_placement(f: &Function) -> Vec<VerifierError> {
    verify_placement_until(f, &mut || false).expect("never stopped")
}

/// [`verify_placement`] that calls `stop` about once per issue, op, load and write and gives
/// up (`None`) at the first `true` (`-time-limit`: [`super::verify_until`]).
pub fn verify_placement_until(f: &Function, stop: &mut dyn FnMut() -> bool) -> Option<Vec<VerifierError>> {
    let Some(p) = &f.placement else { return Some(Vec::new()) };
    let mut s = Sink { f, errs: Vec::new(), more: 0 };
    check(f, p, &mut s, stop)?;
    let Sink { mut errs, more, .. } = s;
    if more > 0 {
        errs.push(VerifierError {
            function: f.name.clone(),
            location: Location::Placement,
            message: format!("placement: {more} more violations not listed"),
            span: p.spans.block,
        });
    }
    Some(errs)
}

fn check(f: &Function, p: &Placement, s: &mut Sink<'_>, stop: &mut dyn FnMut() -> bool) -> Option<()> {
    let a = p.arch;
    let n = f.values.len();
    let name = |v: Value| if v.index() < n { format!("%{}", f.name_of(v)) } else { format!("{v}") };
    let kname = |k: Key| match k {
        Key::Value(v) => name(v),
        Key::Const(b) => format!("{:?}", f64::from_bits(b)),
    };
    // Phase and shape: later checks index by them.
    if f.phase != Phase::Atomised {
        s.push(
            p.spans.block,
            format!("placement on a function in phase {:?}; only an atomised function can be placed", f.phase),
        );
        return Some(());
    }
    if let Some(&v) = f.body.iter().find(|&&v| matches!(f.value(v).def, Def::Expr(_))) {
        s.push(f.value(v).span, format!("placement on a function with a nested expression (`%{}`)", f.name_of(v)));
        return Some(());
    }
    let n_pe = a.n_pe();
    if a.n_add == 0 || a.n_mul == 0 {
        s.push(p.spans.block, format!("placement needs n_add ≥ 1 and n_mul ≥ 1, found {} and {}", a.n_add, a.n_mul));
    }
    if p.pe_words.len() != n_pe || p.buffer_words.len() != n_pe {
        s.push(
            p.spans.block,
            format!(
                "placement lists {} PE memory and {} buffer sizes for {n_pe} PEs",
                p.pe_words.len(),
                p.buffer_words.len()
            ),
        );
        return Some(());
    }
    for k in [OpKind::Add, OpKind::Mul, OpKind::Div, OpKind::Call] {
        if p.latency(k) == 0 {
            s.push(p.spans.block, format!("placement: latency of {k:?} is 0; latencies must be ≥ 1"));
            return Some(());
        }
    }
    let exists = |q: Pe| match q {
        Pe::Add(i) => i < a.n_add,
        Pe::Mul(i) => i < a.n_mul,
    };
    let no_pe = |q: Pe| format!("PE {q} does not exist ({} ADD and {} MULTI PEs)", a.n_add, a.n_mul);

    // Issues: every op exactly once (a `Vec<Option<Issue>>` cannot hold two), nothing else.
    let mut arrival: Vec<Option<u64>> = vec![None; n];
    let mut busy: Map<(usize, u32), Value> = map(p.issue.len());
    for (i, is) in p.issue.iter().enumerate() {
        if stop() {
            return None;
        }
        let Some(is) = is else { continue };
        let v = Value::with_number(i as u32);
        let span = p.spans.issue(v);
        let Some(kind) = (i < n).then(|| f.op_kind(v)).flatten() else {
            s.push(span, format!("{} is issued but is not an op", name(v)));
            continue;
        };
        if !exists(is.pe) {
            s.push(span, format!("{} is issued on {}", name(v), no_pe(is.pe)));
            continue;
        }
        if !is.pe.accepts(kind) {
            s.push(span, format!("{} ({kind:?}) is issued on {}, a PE of the wrong type", name(v), is.pe));
        }
        if let Some(other) = busy.insert((is.pe.slot(a.n_add), is.cycle), v) {
            s.push(
                span,
                format!(
                    "{} is issued on {} at cycle {} together with {}; a PE issues at most one op per cycle",
                    name(v),
                    is.pe,
                    is.cycle,
                    name(other)
                ),
            );
        }
        arrival[i] = Some(is.cycle as u64 + p.latency(kind) as u64);
    }
    for &v in &f.body {
        if stop() {
            return None;
        }
        if f.op_kind(v).is_some() && p.issue.get(v.index()).copied().flatten().is_none() {
            s.push(f.value(v).span, format!("op {} is never issued in the placement", name(v)));
        }
    }

    // Loads and writes: first cycle each key is in each PE memory (loads: −1).
    let mut present: Map<(usize, Key), i64> = map(p.loads.len() + p.writes.len());
    for (i, l) in p.loads.iter().enumerate() {
        if stop() {
            return None;
        }
        let span = p.spans.load(i);
        let k = key_of(&l.operand);
        if !exists(l.pe) {
            s.push(span, format!("load of {} into {}", kname(k), no_pe(l.pe)));
            continue;
        }
        if let Operand::Value(v) = l.operand {
            if v.index() >= n || !matches!(f.value(v).def, Def::Input | Def::Trig(..)) {
                s.push(span, format!("load of {}, which is not initial data (input, trig value or constant)", name(v)));
                continue;
            }
        }
        let slot = l.pe.slot(a.n_add);
        if l.addr >= p.pe_words[slot] {
            s.push(
                span,
                format!(
                    "load of {} at address {} of the memory of {}, which reports {} words",
                    kname(k),
                    l.addr,
                    l.pe,
                    p.pe_words[slot]
                ),
            );
        }
        present.insert((slot, k), -1);
    }
    let mut ports: Map<(usize, u32), u32> = map(p.writes.len());
    let mut buf_addr: Map<Value, u32> = map(0);
    let mut buf_read: Map<(usize, u32), (u32, Value)> = map(0);
    for (i, w) in p.writes.iter().enumerate() {
        if stop() {
            return None;
        }
        let span = p.spans.write(i);
        let v = w.value;
        if !exists(w.pe) {
            s.push(span, format!("write of {} into {}", name(v), no_pe(w.pe)));
            continue;
        }
        let Some(arr) = arrival.get(v.index()).copied().flatten() else {
            if v.index() < n && f.op_kind(v).is_some() {
                continue; // Never issued: reported above.
            }
            s.push(span, format!("write of {}, which is not an op result", name(v)));
            continue;
        };
        let slot = w.pe.slot(a.n_add);
        match w.buffer_addr {
            None if w.cycle as u64 != arr => s.push(
                span,
                format!(
                    "direct write of {} into {} at cycle {}, but it arrives at cycle {arr}",
                    name(v),
                    w.pe,
                    w.cycle
                ),
            ),
            None => {}
            Some(b) => {
                let producer = p.issue[v.index()].expect("arrived, so issued").pe;
                let pslot = producer.slot(a.n_add);
                if !a.buffer {
                    s.push(span, format!("indirect write of {}, but the architecture has no buffers", name(v)));
                } else if (w.cycle as u64) < arr {
                    s.push(
                        span,
                        format!(
                            "write of {} from the buffer of {producer} at cycle {}, before it arrives at cycle {arr}",
                            name(v),
                            w.cycle
                        ),
                    );
                }
                if b >= p.buffer_words[pslot] {
                    s.push(
                        span,
                        format!(
                            "{} enters address {b} of the buffer of {producer}, which reports {} words",
                            name(v),
                            p.buffer_words[pslot]
                        ),
                    );
                }
                if let Some(&first) = buf_addr.get(&v) {
                    if first != b {
                        s.push(
                            span,
                            format!("{} enters the buffer of {producer} at two addresses ({first} and {b})", name(v)),
                        );
                    }
                } else {
                    buf_addr.insert(v, b);
                }
                if let Some(&(other, u)) = buf_read.get(&(pslot, w.cycle)) {
                    if other != b {
                        s.push(
                            span,
                            format!(
                                "buffer of {producer} read at two addresses in cycle {} ({other} for {}, {b} for {}); \
                                 one buffer read per cycle",
                                w.cycle,
                                name(u),
                                name(v)
                            ),
                        );
                    }
                } else {
                    buf_read.insert((pslot, w.cycle), (b, v));
                }
            }
        }
        if w.addr >= p.pe_words[slot] {
            s.push(
                span,
                format!(
                    "write of {} at address {} of the memory of {}, which reports {} words",
                    name(v),
                    w.addr,
                    w.pe,
                    p.pe_words[slot]
                ),
            );
        }
        let used = ports.entry((slot, w.cycle)).or_insert(0);
        *used += 1;
        if *used == a.writes + 1 {
            s.push(
                span,
                format!(
                    "{} writes into the memory of {} in cycle {}; it has {} write ports",
                    a.writes + 1,
                    w.pe,
                    w.cycle,
                    a.writes
                ),
            );
        }
        let t = present.entry((slot, Key::Value(v))).or_insert(i64::MAX);
        *t = (*t).min(w.cycle as i64);
    }

    // Operands present at issue.
    for &v in &f.body {
        if stop() {
            return None;
        }
        let Some(is) = p.issue.get(v.index()).copied().flatten() else { continue };
        if !exists(is.pe) {
            continue;
        }
        let pair;
        let ops: &[Operand] = match &f.value(v).def {
            Def::Binary(_, x, y) => {
                pair = [*x, *y];
                &pair
            }
            Def::Call(_, args) => args,
            _ => &[],
        };
        let slot = is.pe.slot(a.n_add);
        for o in ops {
            let k = key_of(o);
            let why = match present.get(&(slot, k)) {
                Some(&t) if t <= is.cycle as i64 => continue,
                Some(&t) => format!("written there only at cycle {t}"),
                None => "never loaded or written there".to_string(),
            };
            s.push(
                p.spans.issue(v),
                format!(
                    "operand {} of {} is not in the memory of {} at cycle {} ({why})",
                    kname(k),
                    name(v),
                    is.pe,
                    is.cycle
                ),
            );
        }
    }
    Some(())
}
