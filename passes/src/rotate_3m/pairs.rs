//! Finding the rotated pairs of a function: four products `c·x`, `s·y`, `s·x`, `c·y` of one
//! joint's cosine `c` and sine `s`, each read once, as terms of sums (module doc of
//! [`super`]).
//!
//! A *sum* is a cluster of `add`/`sub` ops whose inner ops are read once, by the cluster
//! (tree-height reduction's additive clusters, [`Clusters`], seed §2.3); each of its leaves enters it with a sign,
//! the product of the signs on its path (the right operand of a `sub` flips it). `u` is any
//! sum with a term `±c·x` and a term `±s·y` (`x ≠ y`), `v` any sum with `±s·x` and `±c·y`;
//! `u` and `v` may be one sum. Cost: O(values + operands) plus, per sum and joint, the
//! products of its `cos` and `sin` terms (a few in Robotran's sums).

use std::collections::{HashMap, HashSet};

use robovec_ir::{BinOp, Def, Function, Operand, TrigFn, Value};

use crate::tree_height::cluster::Clusters;

/// A product `trig·other` read once, as a term of a sum.
#[derive(Clone, Copy, Debug)]
pub(super) struct Term {
    /// The product's value.
    pub value: Value,
    /// The trig value (`c` or `s`).
    pub trig: Value,
    /// The other factor.
    pub other: Value,
    /// The `add`/`sub` that reads it.
    pub reader: Value,
    /// The sum it is a term of (the cluster's root).
    pub root: Value,
    /// +1 or −1: its sign in the sum.
    pub sign: i8,
}

/// One rotated pair: `u ∋ α·c·x + β·s·y` and `v ∋ γ·s·x + δ·c·y`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair {
    /// `c·x`, `s·y` (in `u`), `s·x`, `c·y` (in `v`).
    pub cx: Term,
    pub sy: Term,
    pub sx: Term,
    pub cy: Term,
}

impl Pair {
    /// The `add`/`sub` ops that read the four products.
    pub fn readers(&self) -> [Value; 4] {
        [self.cx.reader, self.sy.reader, self.sx.reader, self.cy.reader]
    }

    /// The joint sums `s ± c` its two sides read, as `(s, c, plus)`: `u`'s `s − αβ·c` and
    /// `v`'s `s − γδ·c` (`plus` when the side's two signs differ; module doc of [`super`]).
    pub fn joint_sums(&self) -> [(Value, Value, bool); 2] {
        let (s, c) = (self.sy.trig, self.cx.trig);
        [(s, c, self.cx.sign != self.sy.sign), (s, c, self.cy.sign != self.sx.sign)]
    }
}

/// The position of each value in `f`'s body, counted from 1 (inputs: 0).
pub(super) fn body_positions(f: &Function) -> Vec<usize> {
    let mut position = vec![0usize; f.values.len()];
    for (i, &v) in f.body.iter().enumerate() {
        position[v.index()] = i + 1;
    }
    position
}

/// The rotated pairs of `f`, each product in one pair at most, in the body order of the
/// first product of each sum and joint. `position`: [`body_positions`] of `f`.
pub(super) fn find(f: &Function, position: &[usize]) -> Vec<Pair> {
    // The sums are tree-height reduction's additive clusters.
    let clusters = Clusters::new(f);
    let uses = &clusters.uses;
    // What each operand of an `add`/`sub` is a term of: (its reader, the sum's root, its sign
    // there). Reverse body order visits an op before the ops it reads, so an interior op's
    // sign is known when its own operands take theirs.
    let mut sign = vec![1i8; f.values.len()];
    let mut reader: Vec<Option<(Value, Value, i8)>> = vec![None; f.values.len()];
    for &v in f.body.iter().rev() {
        let Def::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) = f.value(v).def else { continue };
        let Some(root) = clusters.root_of[v.index()] else { continue };
        for (k, x) in [a, b].into_iter().enumerate() {
            if let Operand::Value(x) = x {
                let flip = if op == BinOp::Sub && k == 1 { -1 } else { 1 };
                let s = sign[v.index()] * flip;
                if clusters.interior[x.index()] {
                    sign[x.index()] = s;
                }
                reader[x.index()] = Some((v, root, s));
            }
        }
    }
    // Every product of a trig value read once by a sum: its term.
    let mut terms: HashMap<(Value, Value), Term> = HashMap::new();
    // Per (sum, joint): its cos terms and its sin terms.
    let mut by_sum: HashMap<(Value, Value), (Vec<Term>, Vec<Term>)> = HashMap::new();
    let mut order: Vec<(Value, Value)> = Vec::new();
    for &m in &f.body {
        if uses[m.index()] != 1 {
            continue;
        }
        let Def::Binary(BinOp::Mul, Operand::Value(a), Operand::Value(b)) = f.value(m).def else { continue };
        let Some((by, root, sign)) = reader[m.index()] else { continue };
        let trig = [(a, b), (b, a)].into_iter().find_map(|(t, other)| match f.value(t).def {
            // (A trig value is a body value; the joint sums go right after it.)
            Def::Trig(kind, angle) if t != other && position[t.index()] > 0 => Some((kind, angle, t, other)),
            _ => None,
        });
        let Some((kind, angle, t, other)) = trig else { continue };
        let term = Term { value: m, trig: t, other, reader: by, root, sign };
        // Two products of the same factors (no `cse` before): the first is the partner.
        terms.entry((t, other)).or_insert(term);
        let e = by_sum.entry((root, angle)).or_insert_with(|| {
            order.push((root, angle));
            (Vec::new(), Vec::new())
        });
        if kind == TrigFn::Cos { &mut e.0 } else { &mut e.1 }.push(term);
    }
    let mut taken: HashSet<Value> = HashSet::new();
    let mut out = Vec::new();
    for key in order {
        let (coss, sins) = &by_sum[&key];
        for cx in coss {
            for sy in sins {
                let free = |t: &Term| !taken.contains(&t.value);
                if sy.other == cx.other || !free(cx) || !free(sy) {
                    continue;
                }
                let (Some(sx), Some(cy)) = (terms.get(&(sy.trig, cx.other)), terms.get(&(cx.trig, sy.other))) else {
                    continue;
                };
                if sx.root != cy.root || !free(sx) || !free(cy) {
                    continue;
                }
                // The new values go right before the first reader: x, y, c and s must be there.
                let pair = Pair { cx: *cx, sy: *sy, sx: *sx, cy: *cy };
                let first = pair.readers().into_iter().map(|r| position[r.index()]).min().unwrap_or(0);
                let last_factor = [cx.other, sy.other, cx.trig, sy.trig].into_iter().map(|v| position[v.index()]).max();
                if last_factor.is_some_and(|l| l >= first) {
                    continue;
                }
                taken.extend([cx.value, sy.value, sx.value, cy.value]);
                out.push(pair);
            }
        }
    }
    out
}
