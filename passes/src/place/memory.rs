//! From a schedule to a [`Placement`]: initial-data loads, write addresses and memory sizes.
//!
//! Each PE memory holds items — initial data (loaded before cycle 0) and written results — from
//! their write until their last read on that PE; each buffer holds a result from its arrival
//! until its last buffer read. Addresses are assigned by the interval-graph greedy (items by
//! start cycle, reusing the lowest address whose item ended strictly earlier), which uses
//! exactly as many addresses as the largest number of items alive at once: the reported
//! memory size is that maximum (seed §1.3, §2.3). Cost: O(items log items).

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use robovec_ir::machine::Held;
use robovec_ir::placement::{Issue, Load, Pe, PeArray, Placement, Write};
use robovec_ir::{Function, Operand};

use super::dag::{Node, OpDag};
use super::schedule::{initial_operands, Schedule};

/// The PE of a dense slot.
pub fn pe_of(arch: &PeArray, slot: usize) -> Pe {
    if slot < arch.n_add as usize {
        Pe::Add(slot as u32)
    } else {
        Pe::Mul((slot - arch.n_add as usize) as u32)
    }
}

/// Assigns addresses to `(start, end)` items (inclusive cycles; an address is reused only by an
/// item starting after the previous one's end). Returns the addresses and the word count.
fn allocate(items: &[(u32, u32)]) -> (Vec<u32>, u32) {
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| (items[i].0, i));
    let mut busy: BinaryHeap<Reverse<(u32, u32)>> = BinaryHeap::new(); // (end, addr)
    let mut free: BinaryHeap<Reverse<u32>> = BinaryHeap::new();
    let mut words = 0;
    let mut addr = vec![0; items.len()];
    for i in order {
        let (start, end) = items[i];
        while let Some(&Reverse((e, a))) = busy.peek() {
            if e >= start {
                break;
            }
            busy.pop();
            free.push(Reverse(a));
        }
        let a = free.pop().map(|Reverse(a)| a).unwrap_or_else(|| {
            words += 1;
            words - 1
        });
        addr[i] = a;
        busy.push(Reverse((end, a)));
    }
    (addr, words)
}

/// Builds the placement of `f` from its schedule `s` (indexed by the nodes of `dag`, built
/// from `f`): the memories' addresses, loads and writes. Calls `stop` about once per op, per
/// booking and per load (`-time-limit`: the first schedule's grace, [`super::try_place_function_progress`])
/// and gives up (`None`) at the first `true`.
pub fn build(f: &Function, dag: &OpDag, arch: &PeArray, s: &Schedule, stop: &dyn Fn() -> bool) -> Option<Placement> {
    let n_pe = arch.n_pe();
    let n = dag.len();
    // Bookings of each node (compressed rows), to find the one an op reads on its PE.
    let mut at = vec![0u32; n + 1];
    for b in &s.bookings {
        at[b.node as usize + 1] += 1;
    }
    for i in 0..n {
        at[i + 1] += at[i];
    }
    let mut fill = at.clone();
    let mut by_node = vec![0u32; s.bookings.len()];
    for (i, b) in s.bookings.iter().enumerate() {
        by_node[fill[b.node as usize] as usize] = i as u32;
        fill[b.node as usize] += 1;
    }
    // Last read cycle of each booking, and of each initial item loaded into each PE memory.
    let mut last_booking = vec![0u32; s.bookings.len()];
    let mut loads_wanted: Vec<Vec<Operand>> = vec![Vec::new(); n_pe];
    let mut load_index: Vec<HashMap<Held, usize>> = vec![HashMap::new(); n_pe];
    let mut last_load: Vec<Vec<u32>> = vec![Vec::new(); n_pe];
    // In node order (operands are near their users there), then the loads in body order.
    for j in 0..n as Node {
        if stop() {
            return None;
        }
        let (q, t) = s.issue[j as usize];
        for a in dag.distinct_operands(j) {
            let row = &by_node[at[a as usize] as usize..at[a as usize + 1] as usize];
            if let Some(&i) = row.iter().find(|&&i| s.bookings[i as usize].target == q as usize) {
                last_booking[i as usize] = last_booking[i as usize].max(t);
            }
        }
    }
    for &v in &f.body {
        if stop() {
            return None;
        }
        let Some(j) = dag.node(v) else { continue };
        let (q, t) = s.issue[j as usize];
        let q = q as usize;
        for o in initial_operands(f, v) {
            let i = *load_index[q].entry(Held::of(&o)).or_insert_with(|| {
                loads_wanted[q].push(o);
                last_load[q].push(0);
                loads_wanted[q].len() - 1
            });
            last_load[q][i] = last_load[q][i].max(t);
        }
    }
    let mut loads = Vec::new();
    let mut writes = Vec::new();
    let mut pe_words = vec![0; n_pe];
    let mut per_memory: Vec<Vec<usize>> = vec![Vec::new(); n_pe];
    for (i, b) in s.bookings.iter().enumerate() {
        per_memory[b.target].push(i);
    }
    // Buffers: one item per op that is read from its producer's buffer, from its arrival to
    // its last buffer read.
    let mut buffer_end: Vec<Option<u32>> = vec![None; n];
    for b in s.bookings.iter().filter(|b| b.indirect) {
        let e = buffer_end[b.node as usize].get_or_insert(b.cycle);
        *e = (*e).max(b.cycle);
    }
    let mut buffer_items: Vec<Vec<(usize, u32, u32)>> = vec![Vec::new(); n_pe];
    for (j, end) in buffer_end.iter().enumerate() {
        if let Some(end) = *end {
            let p = s.issue[j].0 as usize;
            buffer_items[p].push((j, s.arrival[j], end));
        }
    }
    let mut buffer_addr = vec![0u32; n];
    let mut buffer_words = vec![0; n_pe];
    for (p, items) in buffer_items.iter().enumerate() {
        let spans: Vec<(u32, u32)> = items.iter().map(|&(_, a, b)| (a, b)).collect();
        let (addrs, words) = allocate(&spans);
        buffer_words[p] = words;
        for (&(j, _, _), a) in items.iter().zip(addrs) {
            buffer_addr[j] = a;
        }
    }
    for q in 0..n_pe {
        let mut spans: Vec<(u32, u32)> = last_load[q].iter().map(|&e| (0, e)).collect();
        spans.extend(per_memory[q].iter().map(|&i| (s.bookings[i].cycle, last_booking[i])));
        if stop() {
            return None;
        }
        let (addrs, words) = allocate(&spans);
        pe_words[q] = words;
        let pe = pe_of(arch, q);
        for (o, &addr) in loads_wanted[q].iter().zip(&addrs) {
            loads.push(Load { pe, addr, operand: *o });
        }
        for (&i, &addr) in per_memory[q].iter().zip(&addrs[loads_wanted[q].len()..]) {
            let b = &s.bookings[i];
            let buffer_addr = b.indirect.then(|| buffer_addr[b.node as usize]);
            writes.push(Write { value: dag.ops[b.node as usize], pe, addr, cycle: b.cycle, buffer_addr });
        }
    }
    writes.sort_unstable_by_key(|w| (w.cycle, w.pe, w.addr));
    let mut issue = vec![None; f.values.len()];
    for (&v, &(q, cycle)) in dag.ops.iter().zip(&s.issue) {
        issue[v.index()] = Some(Issue { pe: pe_of(arch, q as usize), cycle });
    }
    Some(Placement { arch: *arch, issue, loads, writes, pe_words, buffer_words, spans: Default::default() })
}

#[cfg(test)]
mod tests {
    use super::allocate;

    #[test]
    fn addresses_equal_the_largest_overlap() {
        // [0,3] [1,2] [3,5] [4,4]: at cycle 3 two items live ([0,3], [3,5]); [3,5] cannot reuse
        // [0,3]'s address (ends at 3) but can reuse [1,2]'s.
        let (addr, words) = allocate(&[(0, 3), (1, 2), (3, 5), (4, 4)]);
        assert_eq!(words, 2);
        assert_eq!(addr, vec![0, 1, 1, 0]);
    }
}
