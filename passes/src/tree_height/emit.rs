//! Emitting a finished cluster: signs per node and the ops that realise them (step 3 and 5
//! of [`super::rebuild`]).

use robovec_ir::{BinOp, Def, Operand, Value};

use super::cluster::Class;
use super::rebuild::{Engine, Plan, Rep, Term};
use super::shape::BNode;

impl Engine<'_> {
    /// Emits `plan` for the cluster (or `div`) of `root`; `names` are the original ops whose
    /// names the new ops take, in order (the last new op takes `root`'s name).
    pub(super) fn emit_plan(&mut self, root: Value, class: Class, plan: Plan, parity: bool, names: &[Value]) {
        let Plan { terms, tree, negative, .. } = plan;
        let span = self.f.value(root).span;
        let rep = match tree.len() {
            0 => {
                let one = if parity { -1.0 } else { 1.0 };
                Rep { op: Operand::Const(if class == Class::Additive { 0.0 } else { one }), neg: false }
            }
            1 => {
                let t = terms[0];
                match t.konst {
                    Some(k) => Rep { op: Operand::Const(if parity { -k } else { k }), neg: false },
                    None => Rep { op: t.op, neg: t.neg ^ parity },
                }
            }
            _ => {
                let want = self.desired_signs(class, &terms, &tree, parity);
                let pairs = tree.iter().filter(|n| matches!(n, BNode::Pair(..))).count();
                let mut k = 0;
                let mut made: Vec<(Operand, bool)> = Vec::with_capacity(tree.len());
                for (i, n) in tree.iter().enumerate() {
                    let r = match *n {
                        BNode::Term(t) => {
                            let t = terms[t as usize];
                            match t.konst {
                                Some(c) => (Operand::Const(if want[i] { -c } else { c }), want[i]),
                                None => (t.op, t.neg),
                            }
                        }
                        BNode::Pair(a, b) => {
                            let ((oa, sa), (ob, sb)) = (made[a as usize], made[b as usize]);
                            k += 1;
                            let name = if k == pairs { root } else { names.get(k - 1).copied().unwrap_or(root) };
                            let name = self.f.name_of(name).to_string();
                            let (def, s) = pair_def(class, oa, sa, ob, sb, want[i]);
                            (Operand::Value(self.emit(&name, def, span)), s)
                        }
                    };
                    made.push(r);
                }
                let (op, s) = made[tree.len() - 1];
                Rep { op, neg: s ^ (parity && class != Class::Additive) }
            }
        };
        debug_assert!(!negative || rep.neg || matches!(rep.op, Operand::Const(_)));
        self.rep[root.index()] = Some(rep);
        if rep.neg && !self.absorb[root.index()] && self.needs_flip(root) {
            self.flip_of(root);
        }
    }

    /// The sign each node of `tree` should have (additive: free nodes follow their parent, the
    /// root is `+` when free; products and `div`: the first constant cancels the parity).
    fn desired_signs(&self, class: Class, terms: &[Term], tree: &[BNode], parity: bool) -> Vec<bool> {
        let mut want = vec![false; tree.len()];
        if class != Class::Additive {
            let p = terms.iter().filter(|t| t.konst.is_none()).fold(parity, |p, t| p ^ t.neg);
            if let Some(i) = tree.iter().position(|n| matches!(n, BNode::Term(t) if terms[*t as usize].konst.is_some()))
            {
                want[i] = p;
            }
            return want;
        }
        // Achievable sign per node: Some(s) fixed, None free.
        let mut ach: Vec<Option<bool>> = Vec::with_capacity(tree.len());
        for n in tree {
            ach.push(match *n {
                BNode::Term(t) => {
                    let t = &terms[t as usize];
                    if t.konst.is_some() {
                        None
                    } else {
                        Some(t.neg)
                    }
                }
                BNode::Pair(a, b) => match (ach[a as usize], ach[b as usize]) {
                    (Some(x), Some(y)) if x == y => Some(x),
                    _ => None,
                },
            });
        }
        let last = tree.len() - 1;
        want[last] = ach[last].unwrap_or(false);
        for i in (0..tree.len()).rev() {
            if let BNode::Pair(a, b) = tree[i] {
                for c in [a as usize, b as usize] {
                    want[c] = ach[c].unwrap_or(want[i]);
                }
            }
        }
        want
    }
}

/// The op combining computed values `a` (true sign `sa`) and `b` (`sb`) with result sign
/// `want` where the signs allow a choice; returns the definition and its true sign.
fn pair_def(class: Class, a: Operand, sa: bool, b: Operand, sb: bool, want: bool) -> (Def, bool) {
    match class {
        Class::Additive => match (sa, sb) {
            (x, y) if x == y => (Def::Binary(BinOp::Add, a, b), x),
            // a − b has the sign of the `+` operand; b − a the other.
            (false, true) => (if want { Def::Binary(BinOp::Sub, b, a) } else { Def::Binary(BinOp::Sub, a, b) }, want),
            (true, false) => (if want { Def::Binary(BinOp::Sub, a, b) } else { Def::Binary(BinOp::Sub, b, a) }, want),
            _ => unreachable!(),
        },
        Class::Multiplicative => (Def::Binary(BinOp::Mul, a, b), sa ^ sb),
        Class::Other => (Def::Binary(BinOp::Div, a, b), sa ^ sb),
    }
}
