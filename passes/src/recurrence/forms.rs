//! Linear forms over late pivots, and the builder that writes their ops.
//!
//! A [`Form`] stands for `Σ ± c_i · p_i`: each [`Term`] holds a coefficient `c_i` and a pivot
//! `p_i`, both operands of the function being built (a coefficient `1.0` is no product). The
//! restructuring keeps the pivots late and the coefficients early: a consumer of a form starts
//! its own coefficients (the products and sums along its paths from the pivots) before the
//! pivots are ready, and the pivots then pass through one product and a time-balanced sum.
//!
//! [`Builder`] writes the ops of the new function with their ready times (cycles, the pass's
//! latencies), hash-consed so that a coefficient product asked for twice is made once. Values
//! carry a sign ([`Signed`]) that the consumers absorb (`a + (−b)` is `a − b`, `(−a)·b` is
//! `−(a·b)`), as `zero-removal` and `balance` do; a sign reaches an op only at an output or a
//! call ([`Builder::plain`]).

use std::collections::HashMap;

use robovec_ir::analysis::Latencies;
use robovec_ir::{BinOp, Def, Function, Operand, Phase, Span, Value};

use crate::tree_height::shape::{greedy, root_time, BNode};

/// An operand of the new function with a sign the consumers absorb: the value is `−op` when
/// `neg`. Constants carry their sign in the constant (`neg` is false).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Signed {
    pub neg: bool,
    pub op: Operand,
}

impl Signed {
    pub fn plus(op: Operand) -> Signed {
        Signed { neg: false, op }
    }

    pub fn negated(self) -> Signed {
        match self.op {
            Operand::Const(k) => Signed::plus(Operand::Const(-k)),
            op => Signed { neg: !self.neg, op },
        }
    }
}

/// `± coef · pivot` (`coef` is `Const(1.0)` for a term without product).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Term {
    pub neg: bool,
    pub coef: Operand,
    pub pivot: Operand,
}

const ONE: Operand = Operand::Const(1.0);

fn same(a: Operand, b: Operand) -> bool {
    match (a, b) {
        (Operand::Value(x), Operand::Value(y)) => x == y,
        (Operand::Const(x), Operand::Const(y)) => x.to_bits() == y.to_bits(),
        _ => false,
    }
}

/// A sum of terms (see the module doc); at most the pass's `max-terms` after [`Builder::cap`].
#[derive(Clone, Debug, Default)]
pub(super) struct Form {
    pub terms: Vec<Term>,
}

impl Form {
    /// The form of a value used as it is.
    pub fn scalar(s: Signed) -> Form {
        Form { terms: vec![Term { neg: s.neg, coef: ONE, pivot: s.op }] }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    V(u32),
    C(u64),
}

fn key(o: Operand) -> Key {
    match o {
        Operand::Value(v) => Key::V(v.index() as u32),
        Operand::Const(k) => Key::C(k.to_bits()),
    }
}

/// Writes the new function: ops with ready times, hash-consed.
pub(super) struct Builder {
    pub out: Function,
    /// Ready time of each value of `out` (cycles): 0 for inputs and trig variables.
    time: Vec<u32>,
    pub lat: Latencies,
    memo: HashMap<(BinOp, Key, Key), Value>,
    made: u64,
}

impl Builder {
    pub fn new(name: &str, lat: Latencies) -> Builder {
        Builder { out: Function::new(name, Phase::Atomised), time: Vec::new(), lat, memo: HashMap::new(), made: 0 }
    }

    /// Ready time of `o` in cycles (constants: 0).
    pub fn t(&self, o: Operand) -> u32 {
        match o {
            Operand::Value(v) => self.time[v.index()],
            Operand::Const(_) => 0,
        }
    }

    pub fn input(&mut self, name: &str, span: Span) -> Value {
        let v = self.out.add_input(name, span).expect("input names are unique");
        self.set_time(v, 0);
        v
    }

    fn set_time(&mut self, v: Value, t: u32) {
        if self.time.len() <= v.index() {
            self.time.resize(v.index() + 1, 0);
        }
        self.time[v.index()] = t;
    }

    /// Defines `def` named after `base` (the original value's name, or `base.rN` when taken),
    /// ready `ready` cycles.
    pub fn define(&mut self, base: &str, def: Def, span: Span, ready: u32) -> Value {
        let base = stem(base);
        let v = if self.out.lookup(base).is_none() {
            self.out.define(base.to_string(), def, span).expect("free name")
        } else {
            loop {
                self.made += 1;
                let name = format!("{base}.r{}", self.made);
                if self.out.lookup(&name).is_none() {
                    break self.out.define(name, def, span).expect("free name");
                }
            }
        };
        self.set_time(v, ready);
        v
    }

    /// `a op b`, made once per operand pair (operands of `+` and `*` in a canonical order).
    pub fn bin(&mut self, op: BinOp, a: Operand, b: Operand, base: &str, span: Span) -> Operand {
        let (a, b) = match op {
            BinOp::Add | BinOp::Mul if key_order(a) > key_order(b) => (b, a),
            _ => (a, b),
        };
        if let (Operand::Const(x), Operand::Const(y)) = (a, b) {
            if let Some(z) = fold_exactly(op, x, y) {
                return Operand::Const(z);
            }
        }
        let k = (op, key(a), key(b));
        if let Some(&v) = self.memo.get(&k) {
            return Operand::Value(v);
        }
        let ready = self.t(a).max(self.t(b)) + self.lat.of(op.kind());
        let v = self.define(base, Def::Binary(op, a, b), span, ready);
        self.memo.insert(k, v);
        Operand::Value(v)
    }

    /// `a + b` with signs absorbed.
    pub fn add(&mut self, a: Signed, b: Signed, base: &str, span: Span) -> Signed {
        if a.op == Operand::Const(0.0) {
            return b;
        }
        if b.op == Operand::Const(0.0) {
            return a;
        }
        if a.neg == b.neg {
            Signed { neg: a.neg, op: self.bin(BinOp::Add, a.op, b.op, base, span) }
        } else if !a.neg {
            Signed::plus(self.bin(BinOp::Sub, a.op, b.op, base, span))
        } else {
            Signed::plus(self.bin(BinOp::Sub, b.op, a.op, base, span))
        }
    }

    /// `a · b` with signs absorbed (factors ±1 dropped).
    pub fn mul(&mut self, a: Signed, b: Signed, base: &str, span: Span) -> Signed {
        for (x, y) in [(a, b), (b, a)] {
            if x.op == ONE {
                return if x.neg { y.negated() } else { y };
            }
            if x.op == Operand::Const(-1.0) {
                return if x.neg { y } else { y.negated() };
            }
        }
        Signed { neg: a.neg ^ b.neg, op: self.bin(BinOp::Mul, a.op, b.op, base, span) }
    }

    /// `s` as an operand without sign: `0 − x` when negative.
    pub fn plain(&mut self, s: Signed, base: &str, span: Span) -> Operand {
        if s.neg {
            self.bin(BinOp::Sub, Operand::Const(0.0), s.op, base, span)
        } else {
            s.op
        }
    }

    /// Ready time of a term's product (cycles).
    pub fn term_time(&self, t: &Term) -> u32 {
        if t.coef == ONE {
            self.t(t.pivot)
        } else {
            self.t(t.coef).max(self.t(t.pivot)) + self.lat.mul
        }
    }

    /// Ready time of the form's sum built two-earliest-first (Golumbic 1976), without making it.
    pub fn form_time(&self, f: &Form) -> u32 {
        let ready: Vec<u32> = f.terms.iter().map(|t| self.term_time(t)).collect();
        root_time(&greedy(&ready, self.lat.add), &ready, self.lat.add)
    }

    fn term_value(&mut self, t: &Term, base: &str, span: Span) -> Signed {
        self.mul(Signed { neg: t.neg, op: t.coef }, Signed::plus(t.pivot), base, span)
    }

    /// Writes the form's value: one product per term, then the two-earliest-first sum.
    pub fn materialise(&mut self, f: &Form, base: &str, span: Span) -> Signed {
        let items: Vec<Signed> = f.terms.iter().map(|t| self.term_value(t, base, span)).collect();
        self.sum(items, base, span)
    }

    /// The two-earliest-first sum of `items` (zero when empty): `balance`'s tree
    /// ([`greedy`]) over their ready times.
    pub fn sum(&mut self, items: Vec<Signed>, base: &str, span: Span) -> Signed {
        let ready: Vec<u32> = items.iter().map(|s| self.t(s.op)).collect();
        let mut made = items;
        for node in greedy(&ready, self.lat.add).into_iter().skip(ready.len()) {
            let BNode::Pair(a, b) = node else { unreachable!("the terms come first") };
            let s = self.add(made[a as usize], made[b as usize], base, span);
            made.push(s);
        }
        made.pop().unwrap_or(Signed::plus(Operand::Const(0.0)))
    }

    /// `a ± b`, like terms (same pivot, both coefficients not constants) collected.
    pub fn add_forms(&mut self, mut a: Form, b: &Form, negate: bool, base: &str, span: Span) -> Form {
        for t in &b.terms {
            let t = Term { neg: t.neg ^ negate, ..*t };
            let like = a.terms.iter().position(|u| {
                same(u.pivot, t.pivot)
                    && matches!(u.pivot, Operand::Value(_))
                    && !(matches!(u.coef, Operand::Const(_)) && matches!(t.coef, Operand::Const(_)))
            });
            match like {
                Some(i) => {
                    let u = a.terms[i];
                    let c = self.add(Signed { neg: u.neg, op: u.coef }, Signed { neg: t.neg, op: t.coef }, base, span);
                    a.terms[i] = Term { neg: c.neg, coef: c.op, pivot: u.pivot };
                }
                None => a.terms.push(t),
            }
        }
        a
    }

    /// `s · f`: every coefficient multiplied by `s`.
    pub fn scale(&mut self, f: &Form, s: Signed, base: &str, span: Span) -> Form {
        let terms = f
            .terms
            .iter()
            .map(|t| {
                let c = self.mul(Signed { neg: t.neg, op: t.coef }, s, base, span);
                Term { neg: c.neg, coef: c.op, pivot: t.pivot }
            })
            .collect();
        Form { terms }
    }

    /// Multiplies out the terms whose coefficient is not earlier than their pivot (the pivot is
    /// no longer the late part), then merges the two earliest terms into one while their sum is
    /// ready before the latest term, or while there are more than `max_terms`.
    pub fn tidy(&mut self, mut f: Form, max_terms: usize, base: &str, span: Span) -> Form {
        for t in &mut f.terms {
            if t.coef != ONE && self.t(t.coef) >= self.t(t.pivot) {
                let p = self.mul(Signed::plus(t.coef), Signed::plus(t.pivot), base, span);
                *t = Term { neg: t.neg ^ p.neg, coef: ONE, pivot: p.op };
            }
        }
        let latest = f.terms.iter().map(|t| self.term_time(t)).max().unwrap_or(0);
        while f.terms.len() > 1 {
            let mut idx: Vec<usize> = (0..f.terms.len()).collect();
            idx.sort_by_key(|&i| (self.term_time(&f.terms[i]), i));
            // Merge when over the limit, or when the two earliest are summed before the latest
            // term is ready (no later for the form, one term fewer for its consumers).
            let free = self.term_time(&f.terms[idx[1]]) + self.lat.add <= latest;
            if f.terms.len() <= max_terms.max(1) && !free {
                break;
            }
            let (i, j) = (idx[0].min(idx[1]), idx[0].max(idx[1]));
            let tj = f.terms.swap_remove(j);
            let ti = f.terms[i];
            let (x, y) = (self.term_value(&ti, base, span), self.term_value(&tj, base, span));
            let s = self.add(x, y, base, span);
            f.terms[i] = Term { neg: s.neg, coef: ONE, pivot: s.op };
        }
        f
    }
}

fn key_order(o: Operand) -> (u8, u64) {
    match o {
        Operand::Const(k) => (0, k.to_bits()),
        Operand::Value(v) => (1, v.index() as u64),
    }
}

/// `base` without the `.rN` suffixes that earlier rounds added.
fn stem(base: &str) -> &str {
    let mut s = base;
    while let Some(i) = s.rfind(".r") {
        let tail = &s[i + 2..];
        if tail.is_empty() || !tail.bytes().all(|c| c.is_ascii_digit()) {
            break;
        }
        s = &s[..i];
    }
    s
}

/// `x op y` when it is exact in binary64 and a binary32 number too, so that folding it changes
/// no rounding in either format (a folded inexact constant would be one rounding that the
/// function's depth no longer counts); `None` otherwise (the op is written).
fn fold_exactly(op: BinOp, x: f64, y: f64) -> Option<f64> {
    let (z, exact) = match op {
        BinOp::Mul => {
            let z = x * y;
            (z, x.mul_add(y, -z) == 0.0)
        }
        BinOp::Add | BinOp::Sub => {
            let y = if op == BinOp::Sub { -y } else { y };
            let z = x + y;
            let yv = z - x;
            (z, (x - (z - yv)) + (y - yv) == 0.0)
        }
        BinOp::Div => return None,
    };
    (exact && z.is_finite() && (z as f32) as f64 == z).then_some(z)
}
