//! The cluster rewriter shared by `zero-removal`, `swap` and `balance`.
//!
//! # Representation
//! Values are rebuilt in body order into a new function. Each original value `v` gets a
//! *signed representation* `rep(v) = (w, neg)`: `v = −w` when `neg`, else `v = w`, with `w` an
//! operand of the new function ready at a known cycle. A negation is an op only when it is
//! *materialised*: `flip(v) = 0 − w`, made at most once per value and shared.
//!
//! # One cluster (additive or multiplicative, see [`super::cluster`])
//! 1. **Terms.** Each leaf occurrence becomes a term: its operand `w`, its sign (additive:
//!    coefficient sign × `rep` sign; product: `rep` sign), its ready cycle. Additive zeros and
//!    factors ±1 are dropped (exact in IEEE; a −1 flips the product's sign). A constant term's
//!    sign is free (the constant is negated instead).
//! 2. **Tree.** The [`Shape`] builds a binary tree over the terms' ready times.
//! 3. **Signs.** Sums: a pair of `+` terms is `add`, a `+` and a `−` term `sub` (either
//!    order, so the pair's sign is free), two `−` terms `add` carrying `−`. A sum is negative
//!    only when every term is `−` and none is free. Products: the parity of the `−` factors,
//!    absorbed by a constant factor if there is one.
//! 4. **Negative result.** If the sign can be carried into every consumer for free
//!    ([`super::sign::absorbs`]), `rep` is negative and no op is made. Otherwise the cheapest
//!    of these is chosen (fewest new ops, then earliest): keep the result negative, with
//!    `flip(root)` for consumers that need the true sign (outputs, calls, and all non-additive
//!    uses when there are two or more, so that a sign never fans out to products; in the
//!    cautious rebuild, every consumer, so that no sign leaves its cluster); or flip one
//!    negative term (using its existing `flip`, or making it), which makes the result positive.
//!    Options that would be ready later than the original op are taken only when nothing else
//!    is.
//! 5. **Emit.** New ops reuse the names of the cluster's original ops (the root keeps the
//!    root's name); a materialised negation of `v` is named `v` when free, else `v.neg`.
//!
//! `div` carries signs like a one-op product; `call` arguments and outputs get true signs.
//! Cost: O(n log k) for n values and clusters of up to k terms (each cluster is built a few
//! times when it has negative terms to choose from).

use robovec_ir::analysis::Latencies;
use robovec_ir::{BinOp, Def, Function, Operand, Phase, Value};

use super::cluster::{Class, Clusters, TreeLeaf, TreeNode};
use super::shape::{build, contract, root_time, BNode, Shape};
use super::sign::absorbs;

/// What one rebuild did (units: ops).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RebuildStats {
    /// Clusters rebuilt.
    pub clusters: u64,
    /// Additive zero terms and ±1 factors dropped.
    pub dropped_terms: u64,
    /// Negations materialised (`0 − w` ops made).
    pub negations: u64,
}

#[derive(Clone, Copy, Debug)]
pub(super) struct Rep {
    pub(super) op: Operand,
    pub(super) neg: bool,
}

/// A term of the cluster being built.
#[derive(Clone, Copy, Debug)]
pub(super) struct Term {
    /// The original leaf value (None for constants).
    pub(super) src: Option<Value>,
    pub(super) op: Operand,
    pub(super) neg: bool,
    pub(super) ready: u32,
    /// The term's signed constant value when it is a constant (its sign is then free).
    pub(super) konst: Option<f64>,
}

/// Rebuilds `f` with `shape`. The result verifies, computes the same outputs up to
/// reassociation (`Keep`: bit for bit, up to the sign of zero) and is never ready later than
/// `f` op by op when the sign analysis holds (callers check the whole function).
///
/// `trust_absorbs` false is the cautious rebuild: no sign is taken as absorbed and none leaves
/// its cluster (a negative result gets its true sign there, step 4), so every value is at hand
/// with its true sign, as in `f`, and signs move only within a cluster.
/// `orig` is the ASAPCycle of every value of `f` under `lat` ([`ready_times`]). Returns the new
/// function, what was done, and its critical path (`asap_cycle`, cycles); `None` when `ticker`
/// (one tick per value) says stop (`-time-limit`): the caller keeps `f`.
pub fn rebuild(
    f: &Function,
    shape: Shape,
    lat: &Latencies,
    orig: &[u32],
    trust_absorbs: bool,
    ticker: &crate::Ticker,
) -> Option<(Function, RebuildStats, u32)> {
    let cl = Clusters::new(f);
    if ticker.check() {
        return None;
    }
    let absorb = if trust_absorbs { absorbs(f, &cl) } else { vec![false; f.values.len()] };
    if ticker.check() {
        return None;
    }
    let mut out = Function::new(f.name.clone(), Phase::Atomised);
    out.equations = f.equations;
    out.states = f.states;
    out.span = f.span;
    let mut e = Engine {
        f,
        cl: &cl,
        absorb: &absorb,
        cautious: !trust_absorbs,
        orig,
        shape,
        lat: *lat,
        out,
        ready: Vec::new(),
        rep: vec![None; f.values.len()],
        flip: vec![None; f.values.len()],
        stats: RebuildStats::default(),
    };
    for &v in &f.inputs {
        let d = f.value(v);
        let nv = e.out.add_input(d.name.clone(), d.span).expect("input names are unique");
        e.ready.push(0);
        e.rep[v.index()] = Some(Rep { op: Operand::Value(nv), neg: false });
    }
    for &v in &f.body {
        if ticker.tick() {
            return None;
        }
        e.value(v);
    }
    for o in &f.outputs {
        let value = match o.value {
            Operand::Value(v) => e.positive(v),
            c => c,
        };
        e.out.set_output(o.name.clone(), value, o.span);
    }
    // Ready times of ops are their ASAPCycles, so the critical path is the latest of them.
    let cp = e.out.body.iter().filter(|&&v| e.out.op_kind(v).is_some()).map(|&v| e.ready[v.index()]).max().unwrap_or(0);
    Some((e.out, e.stats, cp))
}

/// ASAPCycle of every value of `f` (atomised) under `lat`: inputs, trig variables and
/// constants 0, an op its latency after its latest operand (SPEC §4). O(values + operands).
pub fn ready_times(f: &Function, lat: &Latencies) -> Vec<u32> {
    let mut t = vec![0u32; f.values.len()];
    for &v in &f.body {
        if let Some(k) = f.op_kind(v) {
            let mut r = 0;
            f.value(v).def.for_each_value(|a| r = r.max(t[a.index()]));
            t[v.index()] = r + lat.of(k);
        }
    }
    t
}

pub(super) struct Engine<'a> {
    pub(super) f: &'a Function,
    pub(super) cl: &'a Clusters,
    pub(super) absorb: &'a [bool],
    /// The cautious rebuild: no sign is taken as absorbed and none leaves its cluster
    /// ([`Engine::needs_flip`]).
    pub(super) cautious: bool,
    pub(super) orig: &'a [u32],
    pub(super) shape: Shape,
    pub(super) lat: Latencies,
    pub(super) out: Function,
    /// Ready cycle of each value of `out`.
    pub(super) ready: Vec<u32>,
    pub(super) rep: Vec<Option<Rep>>,
    pub(super) flip: Vec<Option<Operand>>,
    pub(super) stats: RebuildStats,
}

/// A way to finish a cluster: the terms to use (some flipped) and what it costs.
pub(super) struct Plan {
    pub(super) terms: Vec<Term>,
    pub(super) tree: Vec<BNode>,
    pub(super) time: u32,
    pub(super) negative: bool,
    /// New negations this plan makes.
    pub(super) cost: u32,
}

impl Engine<'_> {
    fn ready_of(&self, o: Operand) -> u32 {
        match o {
            Operand::Value(v) => self.ready[v.index()],
            Operand::Const(_) => 0,
        }
    }

    fn rep(&self, v: Value) -> Rep {
        self.rep[v.index()].expect("operands are rebuilt before their users")
    }

    pub(super) fn emit(&mut self, name: &str, def: Def, span: robovec_ir::Span) -> Value {
        let mut r = 0;
        def.for_each_value(|a| r = r.max(self.ready[a.index()]));
        if let Some(k) = def.op_kind() {
            r += self.lat.of(k);
        }
        let v = match self.out.define(name, def.clone(), span) {
            Ok(v) => v,
            Err(_) => self.out.define_fresh(name, def, span),
        };
        self.ready.push(r);
        v
    }

    /// `0 − w` for the original value `v` (made once).
    pub(super) fn flip_of(&mut self, v: Value) -> Operand {
        self.flip_named(v, v)
    }

    /// `0 − w` for the original value `v` (made once), named after `name` when it is free.
    fn flip_named(&mut self, v: Value, name: Value) -> Operand {
        if let Some(o) = self.flip[v.index()] {
            return o;
        }
        let w = self.rep(v).op;
        let name = self.f.name_of(name);
        let name = if self.out.lookup(name).is_none() { name.to_string() } else { format!("{name}.neg") };
        let span = self.f.value(v).span;
        let n = Operand::Value(self.emit(&name, Def::Binary(BinOp::Sub, Operand::Const(0.0), w), span));
        self.stats.negations += 1;
        self.flip[v.index()] = Some(n);
        n
    }

    /// True when `root`'s result, negative and not absorbed, needs its true sign made in its
    /// own cluster (`flip(root)`, shared by the consumers that need it, or one flipped term;
    /// step 4 of the module doc): always in the cautious rebuild, else when it is an output or
    /// a call argument or has two or more non-additive uses.
    pub(super) fn needs_flip(&self, root: Value) -> bool {
        self.cautious || self.cl.is_strict(root) || self.cl.non_additive_uses[root.index()] >= 2
    }

    /// `v` with its true sign.
    fn positive(&mut self, v: Value) -> Operand {
        let r = self.rep(v);
        if r.neg {
            self.flip_of(v)
        } else {
            r.op
        }
    }

    fn value(&mut self, v: Value) {
        let d = self.f.value(v);
        match &d.def {
            Def::Input => unreachable!("inputs are not in the body"),
            Def::Trig(t, a) => {
                let Operand::Value(a) = self.rep(*a).op else { unreachable!("trig reads an input") };
                let nv = self.emit(&d.name, Def::Trig(*t, a), d.span);
                self.rep[v.index()] = Some(Rep { op: Operand::Value(nv), neg: false });
            }
            Def::Call(c, args) => {
                let args = args
                    .iter()
                    .map(|o| match o {
                        Operand::Value(x) => self.positive(*x),
                        c => *c,
                    })
                    .collect();
                let nv = self.emit(&d.name, Def::Call(c.clone(), args), d.span);
                self.rep[v.index()] = Some(Rep { op: Operand::Value(nv), neg: false });
            }
            Def::Binary(BinOp::Div, a, b) => self.div(v, *a, *b),
            Def::Binary(..) if self.cl.interior[v.index()] => {}
            Def::Binary(..) => self.cluster(v),
            Def::Expr(_) => unreachable!("atomised functions hold no expressions"),
        }
    }

    fn term(&self, o: Operand, coefficient_neg: bool) -> Term {
        match o {
            Operand::Const(c) => {
                Term { src: None, op: o, neg: false, ready: 0, konst: Some(if coefficient_neg { -c } else { c }) }
            }
            Operand::Value(x) => {
                let r = self.rep(x);
                Term { src: Some(x), op: r.op, neg: r.neg ^ coefficient_neg, ready: self.ready_of(r.op), konst: None }
            }
        }
    }

    /// The term `t` used through its flipped value: opposite sign, ready when the flip is.
    fn flipped(&self, t: &Term) -> (Term, u32) {
        let x = t.src.expect("only value terms flip");
        match self.flip[x.index()] {
            Some(o) => (Term { op: o, neg: !t.neg, ready: self.ready_of(o), ..*t }, 0),
            None => (Term { neg: !t.neg, ready: t.ready + self.lat.add, ..*t }, 1),
        }
    }

    fn cluster(&mut self, root: Value) {
        self.stats.clusters += 1;
        let tree = self.cl.tree(self.f, root);
        let class = tree.class;
        let mut parity = false;
        let mut kept: Vec<Option<u32>> = Vec::with_capacity(tree.leaves.len());
        let mut terms = Vec::new();
        for &TreeLeaf { operand, negative, .. } in &tree.leaves {
            let drop = match (class, operand) {
                (Class::Additive, Operand::Const(c)) => c == 0.0,
                (Class::Multiplicative, Operand::Const(c)) if c.abs() == 1.0 => {
                    parity ^= c < 0.0;
                    true
                }
                _ => false,
            };
            if drop {
                self.stats.dropped_terms += 1;
                kept.push(None);
            } else {
                kept.push(Some(terms.len() as u32));
                terms.push(self.term(operand, negative));
            }
        }
        let (original, origins) = contract(&tree.nodes, &kept);
        let names: Vec<Value> = if self.shape == Shape::Balance {
            tree.nodes
                .iter()
                .filter_map(|n| match n {
                    TreeNode::Op { value, .. } if *value != root => Some(*value),
                    _ => None,
                })
                .collect()
        } else {
            origins
        };
        let lat = if class == Class::Additive { self.lat.add } else { self.lat.mul };
        let plan = self.choose(root, class, terms, parity, &original, lat);
        self.emit_plan(root, class, plan, parity, &names);
    }

    fn div(&mut self, v: Value, a: Operand, b: Operand) {
        let terms = vec![self.term(a, false), self.term(b, false)];
        let original = [BNode::Term(0), BNode::Term(1), BNode::Pair(0, 1)];
        let plan = self.choose(v, Class::Other, terms, false, &original, self.lat.div);
        self.emit_plan(v, Class::Other, plan, false, &[v]);
    }

    /// Sign of a finished set of terms: `Some(neg)` when forced, `None` when free.
    fn sign(class: Class, terms: &[Term], parity: bool) -> Option<bool> {
        if terms.iter().any(|t| t.konst.is_some()) {
            return None;
        }
        match class {
            Class::Additive => {
                let neg = terms.first().is_some_and(|t| t.neg);
                terms.iter().all(|t| t.neg == neg).then_some(neg)
            }
            _ => Some(terms.iter().fold(parity, |p, t| p ^ t.neg)),
        }
    }

    fn plan(&self, class: Class, terms: Vec<Term>, parity: bool, original: &[BNode], lat: u32, cost: u32) -> Plan {
        let ready: Vec<u32> = terms.iter().map(|t| t.ready).collect();
        let tree = match (terms.len(), class) {
            (0, _) => Vec::new(),
            (_, Class::Other) => original.to_vec(),
            _ => build(self.shape, original, &ready, lat),
        };
        let time = root_time(&tree, &ready, lat);
        let negative = Self::sign(class, &terms, parity).unwrap_or(false);
        Plan { terms, tree, time, negative, cost }
    }

    /// Picks how to finish the cluster of `root` (step 4 of the module doc).
    fn choose(
        &mut self,
        root: Value,
        class: Class,
        terms: Vec<Term>,
        parity: bool,
        original: &[BNode],
        lat: u32,
    ) -> Plan {
        let base = self.plan(class, terms, parity, original, lat, 0);
        if !base.negative || self.absorb[root.index()] {
            return base;
        }
        let orig = self.orig[root.index()];
        let needs_flip = self.needs_flip(root);
        let keep_time = base.time + if needs_flip { self.lat.add } else { 0 };
        // (valid, cost, time, which): which = None keeps the result negative. Keeping it
        // without a flip only defers the sign to the one non-additive consumer, which cannot
        // absorb it either, so that counts as an op too: a flip that costs no time wins.
        let mut best = (keep_time <= orig || !needs_flip, 1, keep_time, None);
        let mut candidates: Vec<usize> =
            (0..base.terms.len()).filter(|&i| base.terms[i].neg && base.terms[i].src.is_some()).collect();
        candidates.sort_by_key(|&i| {
            let t = &base.terms[i];
            (self.flip[t.src.expect("value").index()].is_none(), t.ready, i)
        });
        candidates.truncate(4);
        let mut plans = Vec::new();
        for i in candidates {
            let mut terms = base.terms.clone();
            let (t, cost) = self.flipped(&terms[i]);
            terms[i] = t;
            let p = self.plan(class, terms, parity, original, lat, cost);
            if p.negative {
                continue;
            }
            let key = (p.time <= orig, p.cost, p.time, Some(plans.len()));
            if better(key, best) {
                best = key;
            }
            plans.push((i, p));
        }
        match best.3 {
            None => base,
            Some(k) => {
                let (i, mut p) = plans.swap_remove(k);
                if p.cost > 0 {
                    let src = p.terms[i].src.expect("value term");
                    // With one term the root makes no op: its name is free for the flip.
                    let o = self.flip_named(src, if p.tree.len() == 1 { root } else { src });
                    p.terms[i].op = o;
                    p.terms[i].ready = self.ready_of(o);
                }
                p
            }
        }
    }
}

/// Lexicographic preference: valid first, then fewer ops, then earlier, then a positive
/// result (`Some`) over a negative one.
fn better(a: (bool, u32, u32, Option<usize>), b: (bool, u32, u32, Option<usize>)) -> bool {
    (!a.0, a.1, a.2, a.3.is_none()) < (!b.0, b.1, b.2, b.3.is_none())
}
