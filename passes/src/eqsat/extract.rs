//! Extraction by ready time (SPEC §6, seed §2.4; NOTES-anchors §3.4).
//!
//! **Cost.** The cost of a term is the pair `(ready, ops)`, compared lexicographically:
//! `ready` (cycles) is the ASAPCycle its root would have — a leaf `x_i` is ready at the
//! ASAPCycle of the value it stands for, a constant at 0, an op at its latency (`lat-add` for
//! `+ - neg`, where `neg` is SPEC §3's `0 - x`; `lat-mul` for `*`) plus the latest of its
//! operands — and `ops` (ops) counts its operations as a tree. `max` is idempotent, so the
//! greedy per-class choice of egg's [`egg::Extractor`] is exact for `ready`; `ops` counts a
//! shared sub-term once per use and is only the tie-break (the real count of the extracted DAG is
//! [`count_ops`]).
//!
//! **Op budget.** The lexicographic optimum may need more ops than the window had (distribution
//! adds multiplies). [`pareto_extract`] keeps, per e-class, every `(ready, ops)` pair not
//! dominated by another with `ops` at most a limit, and returns the earliest-ready term within
//! the limit: the best term under the budget, where the lexicographic choice would be rejected.

use std::collections::HashMap;

use egg::{CostFunction, Id, Language, RecExpr};

use super::lang::{leaf_index, Arith, EGraph};

/// A term's cost: (ready time in cycles, ops counted as a tree), ordered lexicographically.
pub type Cost = (u32, u32);

/// Cost function for egg's extractor: ready time from leaf ready times and op latencies.
#[derive(Clone, Debug)]
pub struct ReadyCost<'a> {
    /// Ready time of leaf `x_i` (cycles), indexed by `i`.
    pub leaf_ready: &'a [u32],
    /// Latency of `+`, `-` and `neg` (cycles; SPEC §1 `lat-add`).
    pub lat_add: u32,
    /// Latency of `*` (cycles; SPEC §1 `lat-mul`).
    pub lat_mul: u32,
}

impl ReadyCost<'_> {
    /// The cost of `node` given its children's costs.
    pub fn node_cost(&self, node: &Arith, mut child: impl FnMut(Id) -> Cost) -> Cost {
        let lat = match node {
            Arith::Num(_) => return (0, 0),
            Arith::Leaf(s) => return (leaf_index(*s).and_then(|i| self.leaf_ready.get(i)).copied().unwrap_or(0), 0),
            Arith::Mul(_) => self.lat_mul,
            Arith::Add(_) | Arith::Sub(_) | Arith::Neg(_) => self.lat_add,
        };
        node.fold((lat, 1), |(r, o), c| {
            let (cr, co) = child(c);
            (r.max(lat + cr), o + co)
        })
    }

    /// The cost of a whole term (its last node is the root).
    pub fn expr_cost(&self, e: &RecExpr<Arith>) -> Cost {
        let mut costs: Vec<Cost> = Vec::with_capacity(e.as_ref().len());
        for n in e.as_ref() {
            let c = self.node_cost(n, |i| costs[usize::from(i)]);
            costs.push(c);
        }
        *costs.last().unwrap_or(&(0, 0))
    }
}

impl CostFunction<Arith> for ReadyCost<'_> {
    type Cost = Cost;
    fn cost<C: FnMut(Id) -> Cost>(&mut self, enode: &Arith, costs: C) -> Cost {
        self.node_cost(enode, costs)
    }
}

/// Ops of a term as a DAG (each distinct op node once), ops.
pub fn count_ops(e: &RecExpr<Arith>) -> u32 {
    let mut seen = std::collections::HashSet::new();
    let nodes = e.as_ref();
    // Canonicalise bottom-up so equal sub-terms at different indices count once.
    let mut canon: Vec<usize> = Vec::with_capacity(nodes.len());
    let mut index: HashMap<Arith, usize> = HashMap::new();
    let mut ops = 0;
    for (i, n) in nodes.iter().enumerate() {
        let key = n.clone().map_children(|c| Id::from(canon[usize::from(c)]));
        let k = *index.entry(key.clone()).or_insert(i);
        canon.push(k);
        if !n.is_leaf() && seen.insert(key) {
            ops += 1;
        }
    }
    ops
}

/// One non-dominated way to compute an e-class: its cost, the node (index in the class) and
/// the cost each child must meet.
#[derive(Clone, Debug)]
struct Entry {
    cost: Cost,
    node: usize,
    child_costs: Vec<Cost>,
}

/// The earliest-ready term of `root` with at most `max_ops` ops (counted as a tree), with its
/// cost; `None` when no term fits. Per e-class the Pareto front has at most `max_ops + 1`
/// entries; iterates over the classes to a fixpoint (at most `rounds` sweeps).
pub fn pareto_extract(
    eg: &EGraph,
    root: Id,
    cf: &ReadyCost,
    max_ops: u32,
    rounds: usize,
) -> Option<(Cost, RecExpr<Arith>)> {
    let mut front: HashMap<Id, Vec<Entry>> = HashMap::new();
    for _ in 0..rounds {
        let mut changed = false;
        for class in eg.classes() {
            let mut cands: Vec<Entry> = front.get(&class.id).cloned().unwrap_or_default();
            for (ni, node) in class.nodes.iter().enumerate() {
                let kids: Vec<Id> = node.children().iter().map(|&c| eg.find(c)).collect();
                let fronts: Option<Vec<Vec<Cost>>> =
                    kids.iter().map(|k| front.get(k).map(|v| v.iter().map(|e| e.cost).collect())).collect();
                let Some(fronts) = fronts else { continue };
                // Every combination of child entries (fronts are small: ops bound their size).
                let mut combos: Vec<Vec<Cost>> = vec![Vec::new()];
                for f in &fronts {
                    combos =
                        combos.iter().flat_map(|c| f.iter().map(move |x| [c.clone(), vec![*x]].concat())).collect();
                }
                for cc in combos {
                    let mut k = 0;
                    let cost = cf.node_cost(node, |_| {
                        k += 1;
                        cc[k - 1]
                    });
                    if cost.1 <= max_ops {
                        cands.push(Entry { cost, node: ni, child_costs: cc });
                    }
                }
            }
            cands.sort_by_key(|e| e.cost);
            let mut kept: Vec<Entry> = Vec::new();
            for e in cands {
                if kept.iter().all(|k| k.cost.1 > e.cost.1) {
                    kept.push(e);
                }
            }
            let old: Vec<Cost> = front.get(&class.id).map(|v| v.iter().map(|e| e.cost).collect()).unwrap_or_default();
            if old != kept.iter().map(|e| e.cost).collect::<Vec<_>>() {
                changed = true;
                front.insert(class.id, kept);
            }
        }
        if !changed {
            break;
        }
    }
    let root = eg.find(root);
    let best = front.get(&root)?.first()?.clone();
    // Rebuild: a child entry meeting the required cost exists (fronts only improve).
    let mut expr = RecExpr::default();
    let mut memo: HashMap<(Id, Cost), Id> = HashMap::new();
    let id = build(eg, &front, root, best.cost, &mut expr, &mut memo, 0)?;
    debug_assert_eq!(usize::from(id) + 1, expr.as_ref().len());
    Some((best.cost, expr))
}

fn build(
    eg: &EGraph,
    front: &HashMap<Id, Vec<Entry>>,
    class: Id,
    need: Cost,
    expr: &mut RecExpr<Arith>,
    memo: &mut HashMap<(Id, Cost), Id>,
    depth: usize,
) -> Option<Id> {
    if let Some(&id) = memo.get(&(class, need)) {
        return Some(id);
    }
    if depth > 10_000 {
        return None;
    }
    let e = front.get(&class)?.iter().find(|e| e.cost.0 <= need.0 && e.cost.1 <= need.1)?.clone();
    let node = &eg[class].nodes[e.node];
    let mut k = 0;
    let mut ok = true;
    let n = node.clone().map_children(|c| {
        k += 1;
        match build(eg, front, eg.find(c), e.child_costs[k - 1], expr, memo, depth + 1) {
            Some(id) => id,
            None => {
                ok = false;
                c
            }
        }
    });
    if !ok {
        return None;
    }
    let id = expr.add(n);
    memo.insert((class, need), id);
    Some(id)
}
