//! The ready list of the list schedulers: a priority queue of `(Key, Node)`, smallest first,
//! bucketed by the key's first component.
//!
//! The first component is a cycle (ALAPCycle, a backward start time, a mobility), so it takes
//! at most about as many values as the schedule has cycles, while the ready list holds up to
//! about a tenth of the ops (WALK-MAN × 64 at N = 32: 288k of 2.35M). One binary heap of that
//! size costs about 20 levels of cache misses per pop; here each first component has its own
//! small heap, and a bitmap of the non-empty buckets finds the smallest. First components past
//! the last bucket share it (ordered by the whole key there), so any keys work.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::dag::{Key, Node};

/// Ready ops by increasing `(Key, Node)`.
pub struct ReadyQueue {
    buckets: Vec<BinaryHeap<Reverse<(Key, Node)>>>,
    /// Bit `b` set when bucket `b` is not empty.
    occupied: Vec<u64>,
    /// No bucket below this one is occupied.
    low: usize,
    len: usize,
}

impl ReadyQueue {
    /// A queue for keys whose first components are mostly at most `max_first` (the bucket
    /// count is `max_first + 1`, capped at `cap`; larger first components share the last).
    pub fn new(max_first: u32, cap: usize) -> ReadyQueue {
        let n = (max_first as usize).saturating_add(1).clamp(1, cap.max(1));
        ReadyQueue {
            buckets: (0..n).map(|_| BinaryHeap::new()).collect(),
            occupied: vec![0; n.div_ceil(64)],
            low: n,
            len: 0,
        }
    }

    fn bucket(&self, k: &Key) -> usize {
        (k.0 as usize).min(self.buckets.len() - 1)
    }

    /// Adds `j` with key `k`.
    pub fn push(&mut self, k: Key, j: Node) {
        let b = self.bucket(&k);
        self.buckets[b].push(Reverse((k, j)));
        self.occupied[b / 64] |= 1 << (b % 64);
        self.low = self.low.min(b);
        self.len += 1;
    }

    /// Removes and returns the smallest entry.
    pub fn pop(&mut self) -> Option<(Key, Node)> {
        if self.len == 0 {
            return None;
        }
        let mut w = self.low / 64;
        let mut bits = self.occupied[w] & (!0u64 << (self.low % 64));
        while bits == 0 {
            w += 1;
            bits = self.occupied[w];
        }
        let b = w * 64 + bits.trailing_zeros() as usize;
        self.low = b;
        let Reverse(e) = self.buckets[b].pop().expect("occupied bucket");
        if self.buckets[b].is_empty() {
            self.occupied[w] &= !(1 << (b % 64));
        }
        self.len -= 1;
        Some(e)
    }

    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pops come out in the order of a sorted list, with pushes interleaved, lowered first
    /// components and first components past the last bucket.
    #[test]
    fn pops_in_key_order() {
        let mut q = ReadyQueue::new(100, 70);
        let mut reference = Vec::new();
        let mut x = 12345u64;
        for step in 0..5000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if !x.is_multiple_of(3) {
                let k = ((x % 200) as u32, (x >> 8) as u32 % 5, step);
                q.push(k, step);
                reference.push((k, step));
            } else {
                reference.sort_unstable_by(|a, b| b.cmp(a));
                assert_eq!(q.pop(), reference.pop());
            }
        }
        reference.sort_unstable_by(|a, b| b.cmp(a));
        while let Some(e) = reference.pop() {
            assert_eq!(q.pop(), Some(e));
        }
        assert!(q.is_empty() && q.pop().is_none());
    }
}
