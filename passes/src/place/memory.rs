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

use robovec_ir::placement::{Arch, Issue, Load, Pe, Placement, Write};
use robovec_ir::{Function, Operand, Value};

use super::schedule::{initial_operands, Schedule};

/// The PE of a dense slot.
pub fn pe_of(arch: &Arch, slot: usize) -> Pe {
    if slot < arch.n_add as usize {
        Pe::Add(slot as u32)
    } else {
        Pe::Mul((slot - arch.n_add as usize) as u32)
    }
}

/// An item stored in one memory: an initial operand or a result.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Value(u32),
    Const(u64),
}

fn key(o: &Operand) -> Key {
    match o {
        Operand::Value(v) => Key::Value(v.index() as u32),
        Operand::Const(c) => Key::Const(c.to_bits()),
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

/// Builds the placement of `f` from its schedule.
pub fn build(f: &Function, arch: &Arch, s: &Schedule) -> Placement {
    let n_pe = arch.n_pe();
    // Last read cycle of each item on each PE.
    let mut last: HashMap<(usize, Key), u32> = HashMap::new();
    let mut loads_wanted: Vec<Vec<Operand>> = vec![Vec::new(); n_pe];
    for &v in &f.body {
        let Some((q, t)) = s.issue[v.index()] else { continue };
        let mut operands = Vec::new();
        f.value(v).def.for_each_value(|a| operands.push(Operand::Value(a)));
        if let robovec_ir::Def::Binary(_, a, b) = &f.value(v).def {
            operands.extend([a, b].into_iter().filter(|o| matches!(o, Operand::Const(_))).copied());
        } else if let robovec_ir::Def::Call(_, args) = &f.value(v).def {
            operands.extend(args.iter().filter(|o| matches!(o, Operand::Const(_))).copied());
        }
        for o in &operands {
            let e = last.entry((q, key(o))).or_insert(t);
            *e = (*e).max(t);
        }
        for o in initial_operands(f, v) {
            if !loads_wanted[q].iter().any(|x| key(x) == key(&o)) {
                loads_wanted[q].push(o);
            }
        }
    }
    let mut loads = Vec::new();
    let mut writes = Vec::new();
    let mut pe_words = vec![0; n_pe];
    let mut per_memory: Vec<Vec<usize>> = vec![Vec::new(); n_pe];
    for (i, b) in s.bookings.iter().enumerate() {
        per_memory[b.target].push(i);
    }
    let mut buffer_addr: HashMap<u32, u32> = HashMap::new();
    let mut buffer_words = vec![0; n_pe];
    // Buffers: one item per value that is read from its producer's buffer.
    let mut buffer_items: Vec<Vec<(Value, u32, u32)>> = vec![Vec::new(); n_pe];
    {
        let mut span: HashMap<u32, (usize, u32, u32)> = HashMap::new();
        for b in s.bookings.iter().filter(|b| b.indirect) {
            let (p, _) = s.issue[b.value.index()].expect("issued");
            let e = span.entry(b.value.index() as u32).or_insert((p, s.arrival[b.value.index()], b.cycle));
            e.2 = e.2.max(b.cycle);
        }
        let mut vals: Vec<_> = span.into_iter().collect();
        vals.sort_by_key(|(v, _)| *v);
        for (v, (p, start, end)) in vals {
            buffer_items[p].push((Value::with_number(v), start, end));
        }
    }
    for (p, items) in buffer_items.iter().enumerate() {
        let spans: Vec<(u32, u32)> = items.iter().map(|&(_, a, b)| (a, b)).collect();
        let (addrs, words) = allocate(&spans);
        buffer_words[p] = words;
        for (&(v, _, _), a) in items.iter().zip(addrs) {
            buffer_addr.insert(v.index() as u32, a);
        }
    }
    for q in 0..n_pe {
        let mut spans = Vec::new();
        for o in &loads_wanted[q] {
            spans.push((0, last[&(q, key(o))]));
        }
        for &i in &per_memory[q] {
            let b = &s.bookings[i];
            spans.push((b.cycle, last[&(q, Key::Value(b.value.index() as u32))]));
        }
        let (addrs, words) = allocate(&spans);
        pe_words[q] = words;
        let pe = pe_of(arch, q);
        for (o, &addr) in loads_wanted[q].iter().zip(&addrs) {
            loads.push(Load { pe, addr, operand: *o });
        }
        for (&i, &addr) in per_memory[q].iter().zip(&addrs[loads_wanted[q].len()..]) {
            let b = &s.bookings[i];
            let buffer_addr = b.indirect.then(|| buffer_addr[&(b.value.index() as u32)]);
            writes.push(Write { value: b.value, pe, addr, cycle: b.cycle, buffer_addr });
        }
    }
    writes.sort_by_key(|w| (w.cycle, w.pe, w.addr));
    let issue = s.issue.iter().map(|x| x.map(|(q, cycle)| Issue { pe: pe_of(arch, q), cycle })).collect();
    Placement { arch: *arch, issue, loads, writes, pe_words, buffer_words }
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
