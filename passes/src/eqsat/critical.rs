//! Critical windows (`scope=critical`, issue 31 item 2): one window per value near the critical
//! path, grown through shared values, which cluster windows ([`super::window`]) stop at.

use robovec_ir::{Function, Operand, Value};

use super::window::{arith, emit_with_ids, tree, TNode, Window};

/// The critical windows of `f` (atomised, verified; `timing` its timing): one per `add`/`sub`/`mul`
/// value with at most `slack` cycles of slack (ALAPCycle − ASAPCycle, SPEC §4), in body order. A
/// window grows from its root through the operands that are themselves such values, **shared
/// or not**, the latest operand first (breadth-first by ready time), until it has `cap` leaf
/// occurrences: it reaches across the values that end a cluster window (a rotated velocity read
/// by three products, a force read by its parent and by a torque), which is where a recurrence
/// keeps its depth. Windows overlap; an interior value keeps its own definition for its other
/// uses (the duplicated ops count against the budget: [`Window::freed`] holds only the ops
/// read nowhere else). Cost: O(windows · cap).
pub fn find_critical_windows(
    f: &Function,
    cap: usize,
    timing: &[Option<robovec_ir::Timing>],
    slack: u32,
) -> Vec<Window> {
    let cap = cap.max(2);
    let n = f.values.len();
    let uses = f.use_counts();
    let mut pos = vec![0usize; n];
    for (i, &v) in f.body.iter().enumerate() {
        pos[v.index()] = i;
    }
    let ready = |v: Value| timing[v.index()].map_or(0, |t| t.asap_cycle);
    let critical =
        |v: Value| arith(f, v).is_some() && timing[v.index()].is_some_and(|t| t.alap_cycle - t.asap_cycle <= slack);
    let mut out = Vec::new();
    for &r in &f.body {
        if !critical(r) {
            continue;
        }
        // Grow: the latest expandable leaf first, while the window has fewer than `cap` slots.
        let mut expanded: Vec<Value> = vec![r];
        let mut slots = 2usize;
        let mut frontier: std::collections::BinaryHeap<(u32, u32)> = std::collections::BinaryHeap::new();
        let (_, a, b) = arith(f, r).expect("critical values are arith");
        for o in [a, b] {
            if let Operand::Value(v) = o {
                if critical(v) {
                    frontier.push((ready(v), v.index() as u32));
                }
            }
        }
        while slots < cap {
            let Some((_, i)) = frontier.pop() else { break };
            let v = Value::with_number(i);
            if expanded.contains(&v) {
                continue;
            }
            expanded.push(v);
            slots += 1;
            let (_, a, b) = arith(f, v).expect("critical values are arith");
            for o in [a, b] {
                if let Operand::Value(x) = o {
                    if critical(x) {
                        frontier.push((ready(x), x.index() as u32));
                    }
                }
            }
        }
        if expanded.len() < 2 {
            continue;
        }
        // The tree: expanded values are ops (repeated where the window reads them twice).
        let nodes = tree(f, r, |v, len| expanded.contains(&v) && len < 4 * cap);
        let cut = vec![false; nodes.len()];
        let (mut w, ids) = emit_with_ids(&nodes, &cut, 0);
        // Ops freed: the root, and (in reverse body order, users first) each expanded value
        // whose every use is by a freed value.
        let mut by_pos = expanded.clone();
        by_pos.sort_by_key(|v| std::cmp::Reverse(pos[v.index()]));
        let mut freed_uses: std::collections::HashMap<Value, u32> = std::collections::HashMap::new();
        let mut freed_set: Vec<Value> = Vec::new();
        for v in by_pos {
            if v != r && freed_uses.get(&v).copied().unwrap_or(0) < uses[v.index()] {
                continue;
            }
            freed_set.push(v);
            f.value(v).def.for_each_value(|x| {
                if expanded.contains(&x) {
                    *freed_uses.entry(x).or_default() += 1;
                }
            });
        }
        let freed = |v: &Value| freed_set.contains(v);
        w.interior.sort_by_key(|v| v.index());
        w.interior.dedup();
        w.freed = freed_set.len() as u32;
        // Shared interior values become leaves too (aliases of their nodes).
        for (i, node) in nodes.iter().enumerate() {
            if let TNode::Op(v, ..) = node {
                if i == 0 || freed(v) {
                    continue;
                }
                let k = w.leaves.iter().position(|l| l == v).unwrap_or_else(|| {
                    w.leaves.push(*v);
                    w.leaves.len() - 1
                });
                w.aliases.push((usize::from(ids[i].expect("emitted")), k));
            }
        }
        out.push(w);
    }
    out
}
