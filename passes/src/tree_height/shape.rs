//! Tree shapes for one cluster: the binary tree over its terms that a rewrite emits.
//!
//! - [`Shape::Keep`]: the original tree, with dropped terms (additive zeros, factors ±1)
//!   contracted away (seed §2.4.1, zero removal);
//! - [`Shape::Swap`]: the original tree's shape with the terms reassigned to its leaf slots,
//!   latest-ready terms in the shallowest slots (seed §2.4.2, tree swapping);
//! - [`Shape::Balance`]: the two-earliest-first greedy (Golumbic 1976, "Combinatorial
//!   Merging", IEEE TC C-25(11); Huffman-like; `NOTES-anchors.md` §4.2), optimal for one
//!   latency per cluster (seed §2.4.3, SPEC §6).
//!
//! With one latency `L` per cluster, a tree's root is ready at `max_i (r_i + L·depth_i)`; the
//! swap assignment (largest `r` with smallest depth) minimises it over assignments to a fixed
//! shape (exchange argument), and the greedy minimises it over all shapes. Cost: O(k log k) for
//! k terms.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Which tree a rewrite builds for each cluster.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// The original tree, dropped terms contracted.
    Keep,
    /// The original shape, terms reordered by ready time.
    Swap,
    /// The two-earliest-first greedy tree.
    Balance,
}

/// A node of a built tree; children come before their parent and the root is last.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BNode {
    /// Term `i`.
    Term(u32),
    /// An op on two earlier nodes (left, right).
    Pair(u32, u32),
}

/// The shape of the original tree over the kept terms: `BNode`s whose `Term(i)` are the kept
/// terms in their original left-to-right order (`kept[leaf]` = term index, `None` when dropped),
/// and the original op behind each `Pair`, in order. Empty when no term is kept.
pub fn contract(nodes: &[super::cluster::TreeNode], kept: &[Option<u32>]) -> (Vec<BNode>, Vec<robovec_ir::Value>) {
    use super::cluster::TreeNode;
    let mut out = Vec::new();
    let mut origin = Vec::new();
    let mut map: Vec<Option<u32>> = Vec::with_capacity(nodes.len());
    for n in nodes {
        let m = match *n {
            TreeNode::Leaf(l) => kept[l as usize].map(|t| {
                out.push(BNode::Term(t));
                out.len() as u32 - 1
            }),
            TreeNode::Op { a, b, value, .. } => match (map[a as usize], map[b as usize]) {
                (Some(x), Some(y)) => {
                    out.push(BNode::Pair(x, y));
                    origin.push(value);
                    Some(out.len() as u32 - 1)
                }
                (x, y) => x.or(y),
            },
        };
        map.push(m);
    }
    // A vanished child pushed nothing, so the root is the last node pushed.
    debug_assert!(map.last().copied().flatten().is_none_or(|r| r as usize + 1 == out.len()));
    (out, origin)
}

/// Ready time of the root of `tree` (cycles): terms ready at `ready[i]`, every pair taking
/// `lat` cycles after its later child. 0 for an empty tree.
pub fn root_time(tree: &[BNode], ready: &[u32], lat: u32) -> u32 {
    let mut t: Vec<u32> = Vec::with_capacity(tree.len());
    for n in tree {
        t.push(match *n {
            BNode::Term(i) => ready[i as usize],
            BNode::Pair(a, b) => t[a as usize].max(t[b as usize]) + lat,
        });
    }
    t.last().copied().unwrap_or(0)
}

/// Depth of every node below the root (root 0), indexed like `tree`.
fn depths(tree: &[BNode]) -> Vec<u32> {
    let mut d = vec![0u32; tree.len()];
    for i in (0..tree.len()).rev() {
        if let BNode::Pair(a, b) = tree[i] {
            d[a as usize] = d[i] + 1;
            d[b as usize] = d[i] + 1;
        }
    }
    d
}

/// `shape` with its terms reassigned so that the latest-ready terms sit in the shallowest slots
/// (ties keep the original order). Minimises [`root_time`] over assignments to this shape.
pub fn swap(shape: &[BNode], ready: &[u32]) -> Vec<BNode> {
    let d = depths(shape);
    let mut slots: Vec<usize> = (0..shape.len()).filter(|&i| matches!(shape[i], BNode::Term(_))).collect();
    // Deepest slot first; among equal depths, left to right.
    slots.sort_by_key(|&i| (Reverse(d[i]), i));
    let mut terms: Vec<u32> = (0..ready.len() as u32).collect();
    terms.sort_by_key(|&t| (ready[t as usize], t));
    let mut out = shape.to_vec();
    for (&slot, &t) in slots.iter().zip(&terms) {
        out[slot] = BNode::Term(t);
    }
    out
}

/// The two-earliest-first greedy tree over terms ready at `ready` (ties: earlier-made node
/// first, so equal inputs pair in their original order). Empty when there is no term.
pub fn greedy(ready: &[u32], lat: u32) -> Vec<BNode> {
    let mut out: Vec<BNode> = (0..ready.len() as u32).map(BNode::Term).collect();
    let mut heap: BinaryHeap<Reverse<(u32, u32)>> =
        ready.iter().enumerate().map(|(i, &r)| Reverse((r, i as u32))).collect();
    while heap.len() > 1 {
        let Reverse((ra, a)) = heap.pop().expect("two entries");
        let Reverse((rb, b)) = heap.pop().expect("two entries");
        out.push(BNode::Pair(a, b));
        heap.push(Reverse((ra.max(rb) + lat, out.len() as u32 - 1)));
    }
    // Terms first, then pairs in creation order: children before parents, the root last.
    out
}

/// The tree of `shape` over terms ready at `ready`; `original` is the contracted original tree
/// (used by `Keep` and `Swap`).
pub fn build(shape: Shape, original: &[BNode], ready: &[u32], lat: u32) -> Vec<BNode> {
    match shape {
        Shape::Keep => original.to_vec(),
        Shape::Swap => swap(original, ready),
        Shape::Balance => greedy(ready, lat),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the least root time over all binary trees on the given ready times.
    fn optimum(ready: &[u32], lat: u32) -> u32 {
        if ready.len() == 1 {
            return ready[0];
        }
        let mut best = u32::MAX;
        for i in 0..ready.len() {
            for j in i + 1..ready.len() {
                let mut rest: Vec<u32> =
                    ready.iter().enumerate().filter(|&(k, _)| k != i && k != j).map(|(_, &r)| r).collect();
                rest.push(ready[i].max(ready[j]) + lat);
                best = best.min(optimum(&rest, lat));
            }
        }
        best
    }

    #[test]
    fn greedy_is_optimal_on_small_instances() {
        let mut s = robovec_ir::rng::SplitMix64::new(7);
        for _ in 0..400 {
            let k = 1 + s.below(6) as usize;
            let lat = [1, 7, 12][s.below(3) as usize];
            let ready: Vec<u32> = (0..k).map(|_| s.below(40) as u32).collect();
            let t = greedy(&ready, lat);
            assert_eq!(t.iter().filter(|n| matches!(n, BNode::Pair(..))).count(), k - 1);
            assert_eq!(root_time(&t, &ready, lat), optimum(&ready, lat), "{ready:?} lat {lat}");
        }
    }

    #[test]
    fn closed_form_when_ready_times_are_multiples_of_the_latency() {
        // T* = L·⌈log2 Σ 2^(r_i/L)⌉ (NOTES-anchors §4.2).
        let lat = 12;
        let ready = [0, 0, 0, 12, 24, 24, 36];
        let sum: u32 = ready.iter().map(|r| 1u32 << (r / lat)).sum();
        let expect = lat * (32 - (sum - 1).leading_zeros());
        assert_eq!(root_time(&greedy(&ready, lat), &ready, lat), expect);
    }

    #[test]
    fn swap_puts_late_terms_near_the_root() {
        // ((t0 + t1) + t2) + t3, t0 ready late: it moves to the top.
        let cascade = vec![BNode::Term(0), BNode::Term(1), BNode::Pair(0, 1), BNode::Term(2), BNode::Pair(2, 3)];
        let cascade = [cascade, vec![BNode::Term(3), BNode::Pair(4, 5)]].concat();
        let ready = [50, 0, 10, 20];
        assert_eq!(root_time(&cascade, &ready, 12), 86);
        let s = swap(&cascade, &ready);
        assert_eq!(root_time(&s, &ready, 12), 62);
        assert_eq!(s[5], BNode::Term(0), "the late term is the root's right operand");
    }
}
