//! Windows: the bounded pieces of a function that `eqsat` saturates one at a time.
//!
//! **Trees.** An `add`/`sub`/`mul` value is *interior* when it has exactly one use, is not an
//! output and its user is itself an `add`/`sub`/`mul`; every other `add`/`sub`/`mul` is a
//! *root*. The tree of a root is the root plus the interior values reachable from it through
//! operands; its leaves are everything else it reads — inputs, trig variables, constants,
//! values with several uses, outputs, `div`s and calls (LLVM Reassociate's rule: a shared value
//! is a leaf of every cluster that reads it). A tree thus holds one maximal associative cluster
//! (a signed `+`/`-` cluster or a `*` cluster) or several connected ones — a `+` cluster whose
//! leaves are single-use `*` clusters — so that distributivity and factoring can act.
//!
//! **Splitting.** Full AC saturation of `n` leaves needs about `3^n` e-nodes (NOTES-anchors
//! §3.3), so a tree with more than `cap` leaf occurrences is cut into windows top-down: a window
//! grows from its root breadth-first, each expanded op turning one leaf slot into two, until it
//! has `cap` slots; the ops left on its frontier root further windows, cut the same way. Every
//! window then has at most `cap` leaf occurrences and `cap − 1` ops. On a left-to-right cascade
//! of `n` terms the root window takes the last `cap − 1` terms plus the rest of the cascade as
//! one (late) leaf, which extraction puts near the root; the cascade's remainder is cut likewise,
//! so the small leftover window sits at the bottom, where it is ready early. (Cutting bottom-up
//! instead leaves the small window on top of a full one and costs one more level: measured on
//! the Segway dirdyna, 497 instead of 377 cycles at `window=8`.)
//!
//! Windows are listed in body order of their roots, which is a topological order of windows:
//! every leaf of a window is defined before its root, and no window's value is read inside
//! another window except as that window's leaf. Cost: O(values + operands).

use egg::RecExpr;
use robovec_ir::{BinOp, Def, Function, Operand, Value};

use super::lang::{leaf_symbol, Arith, Const};

/// One window: a tree of single-use `add`/`sub`/`mul` ops computing `root`.
#[derive(Clone, Debug)]
pub struct Window {
    /// The value the window computes; it keeps its name, so its uses are untouched.
    pub root: Value,
    /// The other values the window defines (removed when the window is replaced).
    pub interior: Vec<Value>,
    /// Distinct value leaves in first-occurrence order; leaf `i` is the symbol `x{i}`.
    pub leaves: Vec<Value>,
    /// The window as written (the atomised cascade), root last.
    pub expr: RecExpr<Arith>,
    /// Ops of the window as written (interior + root), ops.
    pub ops: u32,
    /// Ops that disappear when the window is replaced (ops): all of [`Window::ops`] for a
    /// cluster window; for a critical window ([`super::critical::find_critical_windows`]) the root and the
    /// interior values read only inside the window.
    pub freed: u32,
    /// Shared interior values of a critical window that are also leaves: (index of the
    /// interior node in [`Window::expr`], leaf index). Saturation unions the two, so that
    /// extraction may read the value as it is already computed (no op, its own ready time)
    /// instead of recomputing it. Empty for a cluster window.
    pub aliases: Vec<(usize, usize)>,
    /// Leaf occurrences (value and constant), at most the `cap` of [`find_windows`].
    pub size: u32,
}

pub(super) fn arith(f: &Function, v: Value) -> Option<(BinOp, Operand, Operand)> {
    match f.value(v).def {
        Def::Binary(op @ (BinOp::Add | BinOp::Sub | BinOp::Mul), a, b) => Some((op, a, b)),
        _ => None,
    }
}

/// A node of a tree: an operand leaf or an op (value, operator, operand nodes).
pub(super) enum TNode {
    Leaf(Operand),
    Op(Value, BinOp, usize, usize),
}

/// The windows of `f` (atomised, verified), at most `cap` (≥ 2) leaf occurrences each, in body
/// order of their roots. Windows of one op without a constant operand are left out: no rule can
/// improve them.
pub fn find_windows(f: &Function, cap: usize) -> Vec<Window> {
    let cap = cap.max(2);
    let n = f.values.len();
    let mut uses = vec![0u32; n];
    let mut user: Vec<Option<Value>> = vec![None; n];
    for &v in &f.body {
        f.value(v).def.for_each_value(|a| {
            uses[a.index()] += 1;
            user[a.index()] = Some(v);
        });
    }
    for o in &f.outputs {
        if let Operand::Value(v) = o.value {
            uses[v.index()] += 2; // an output is never interior
        }
    }
    let interior = |v: Value| {
        arith(f, v).is_some() && uses[v.index()] == 1 && user[v.index()].is_some_and(|u| arith(f, u).is_some())
    };
    let mut out = Vec::new();
    for &r in &f.body {
        if arith(f, r).is_none() || interior(r) {
            continue;
        }
        let nodes = tree(f, r, |v, _| interior(v));
        let cut = split(&nodes, cap);
        let mut here: Vec<Window> = (0..nodes.len()).filter(|&i| cut[i]).map(|i| emit(&nodes, &cut, i)).collect();
        here.retain(|w| w.ops >= 2 || w.expr.as_ref().iter().any(|n| matches!(n, Arith::Num(_))));
        out.extend(here);
    }
    let mut pos = vec![0usize; n];
    for (i, &v) in f.body.iter().enumerate() {
        pos[v.index()] = i;
    }
    out.sort_by_key(|w| pos[w.root.index()]);
    out
}

/// The tree rooted at `r` in pre-order (node 0 the root): an `add`/`sub`/`mul` value `v` is an
/// op node when `expand(v, nodes so far)` says so (the root always is), every other operand a
/// leaf; a value read twice is walked twice. Explicit stack: cascades can be thousands deep.
pub(super) fn tree(f: &Function, r: Value, mut expand: impl FnMut(Value, usize) -> bool) -> Vec<TNode> {
    let mut nodes: Vec<TNode> = Vec::new();
    let mut stack: Vec<(Operand, Option<(usize, bool)>)> = vec![(Operand::Value(r), None)];
    let mut parent_slot: Vec<Option<(usize, bool)>> = Vec::new();
    while let Some((o, slot)) = stack.pop() {
        let i = nodes.len();
        match o {
            Operand::Value(v) if arith(f, v).is_some() && (v == r || expand(v, i)) => {
                let (op, a, b) = arith(f, v).expect("checked");
                nodes.push(TNode::Op(v, op, usize::MAX, usize::MAX));
                stack.push((b, Some((i, false))));
                stack.push((a, Some((i, true))));
            }
            o => nodes.push(TNode::Leaf(o)),
        }
        parent_slot.push(slot);
    }
    for (i, slot) in parent_slot.iter().enumerate() {
        if let Some((p, left)) = *slot {
            if let TNode::Op(_, _, a, b) = &mut nodes[p] {
                *(if left { a } else { b }) = i;
            }
        }
    }
    nodes
}

/// Cuts a tree (node 0 = root) into windows of at most `cap` leaf occurrences, top-down: each
/// window grows from its root breadth-first, expanding an op (one leaf slot becomes two) while
/// the window stays within `cap`; the ops left on its frontier root windows of their own.
/// Returns which nodes root a window.
fn split(nodes: &[TNode], cap: usize) -> Vec<bool> {
    let mut cut = vec![false; nodes.len()];
    let mut roots = vec![0usize];
    while let Some(r) = roots.pop() {
        cut[r] = true;
        let mut slots = 1;
        let mut frontier = std::collections::VecDeque::from([r]);
        while let Some(i) = frontier.pop_front() {
            if let TNode::Op(_, _, a, b) = nodes[i] {
                if i == r || slots < cap {
                    slots += 1;
                    frontier.extend([a, b]);
                } else {
                    roots.push(i);
                }
            }
        }
    }
    cut
}

/// The window rooted at tree node `top`, stopping at other cut nodes (which become leaves).
fn emit(nodes: &[TNode], cut: &[bool], top: usize) -> Window {
    emit_with_ids(nodes, cut, top).0
}

/// [`emit`], also returning each tree node's index in the window's expression.
pub(super) fn emit_with_ids(nodes: &[TNode], cut: &[bool], top: usize) -> (Window, Vec<Option<egg::Id>>) {
    let TNode::Op(root, ..) = nodes[top] else { unreachable!("windows are rooted at ops") };
    let mut w = Window {
        root,
        interior: Vec::new(),
        leaves: Vec::new(),
        expr: RecExpr::default(),
        ops: 0,
        freed: 0,
        aliases: Vec::new(),
        size: 0,
    };
    // Post-order with an explicit stack; `ids[i]` is node i's id in `expr`.
    let mut ids = vec![None; nodes.len()];
    let mut stack = vec![(top, false)];
    while let Some((i, expanded)) = stack.pop() {
        let node = &nodes[i];
        match node {
            TNode::Op(v, op, a, b) if i == top || !cut[i] => {
                if !expanded {
                    stack.extend([(i, true), (*b, false), (*a, false)]);
                    continue;
                }
                let (x, y) = (ids[*a].expect("operand first"), ids[*b].expect("operand first"));
                ids[i] = Some(w.expr.add(match op {
                    BinOp::Add => Arith::Add([x, y]),
                    BinOp::Sub => Arith::Sub([x, y]),
                    _ => Arith::Mul([x, y]),
                }));
                w.ops += 1;
                w.freed += 1;
                if i != top {
                    w.interior.push(*v);
                }
            }
            TNode::Op(v, ..) | TNode::Leaf(Operand::Value(v)) => {
                let k = w.leaves.iter().position(|l| l == v).unwrap_or_else(|| {
                    w.leaves.push(*v);
                    w.leaves.len() - 1
                });
                ids[i] = Some(w.expr.add(Arith::Leaf(leaf_symbol(k))));
                w.size += 1;
            }
            TNode::Leaf(Operand::Const(c)) => {
                ids[i] = Some(w.expr.add(Arith::Num(Const::new(*c).expect("verified constants are finite"))));
                w.size += 1;
            }
        }
    }
    (w, ids)
}
