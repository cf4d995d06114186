//! Running `eqsat` on one function: windows in topological order, saturation, extraction,
//! the replacement decision, and the rebuilt body.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use egg::{Extractor, Id, Language, RecExpr, Runner, StopReason};
use robovec_ir::analysis::compute_timing;
use robovec_ir::{BinOp, Def, Function, Operand, Span, Value};

use super::critical::find_critical_windows;
use super::extract::{count_ops, pareto_extract, ReadyCost};
use super::lang::{leaf_index, leaf_symbol, Arith, ConstantFold, Rewrite};
use super::stats::EqsatStats;
use super::window::{find_windows, Window};
use super::EqsatOptions;
use crate::Deadline;

/// Work budget of one function, e-nodes (`EqsatOptions::work_enodes` of the pass): the
/// e-graphs of all its windows together hold at most about this many e-nodes (each window's runner gets `min(nodes, what is left)` as its node limit).
/// When less than [`MIN_WINDOW_WORK`] is left, the remaining windows are kept as they are and
/// the run says so (`stopped_early`). Saturation and extraction cost about 5–10 µs per e-node
/// (measured on the corpus), so the budget bounds a function's eqsat work to about 15–30 s
/// whatever the parameters. The defaults stay far below it on every corpus file (WALK-MAN
/// `dirdyna`, the largest: 4.9·10⁵ e-nodes; COMAN `dirdyna`: 4.6·10⁵); `window=64;nodes=1000000`
/// takes Segway `dirdyna` to 8.8·10⁵ (about 6 s) and COMAN `dirdyna` to the budget (today's main
/// ran it for 170 s).
pub const WORK_ENODES: u64 = 3_000_000;

/// Least budget left for another window to be saturated, e-nodes.
pub const MIN_WINDOW_WORK: u64 = 1_000;

/// Rewrites `f` (atomised, verified) window by window; see the module doc of `eqsat`.
pub fn eqsat_function(f: &mut Function, o: &EqsatOptions, rules: &[Rewrite]) -> EqsatStats {
    eqsat_function_within(f, o, rules, None)
}

/// [`eqsat_function`] that stops saturating windows once `deadline` is reached or the work
/// budget `o.work_enodes` ([`WORK_ENODES`] by default) is spent (each runner's time limit is also cut to the time left).
/// Windows not tried keep their form, so the result verifies either way; `stopped_early` says
/// why the run stopped.
pub fn eqsat_function_within(
    f: &mut Function,
    o: &EqsatOptions,
    rules: &[Rewrite],
    deadline: Option<Deadline>,
) -> EqsatStats {
    let mut st = one_run(f, o, rules, deadline, 0);
    if !o.critical {
        return st;
    }
    // Critical windows: another run while the last one shortened the critical path (its
    // windows made other values critical), within the rounds, the work budget and the deadline.
    let mut before = st.cp_before;
    while st.rounds < o.rounds && st.stopped_early.is_none() && st.cp_after < before {
        before = st.cp_after;
        let r = one_run(f, o, rules, deadline, st.enodes_total);
        st.absorb(r);
    }
    st
}

/// One run over the windows of `f` (see [`eqsat_function_within`]), after earlier runs of the
/// same function spent `spent` e-nodes of the work budget.
fn one_run(
    f: &mut Function,
    o: &EqsatOptions,
    rules: &[Rewrite],
    deadline: Option<Deadline>,
    spent: u64,
) -> EqsatStats {
    let work = o.work_enodes.saturating_sub(spent);
    let mut st = EqsatStats {
        rounds: 1,
        function: f.name.clone(),
        ops_before: f.op_counts().total,
        cp_before: compute_timing(f, &o.lat).1.asap_cycle,
        ..EqsatStats::default()
    };
    let windows = if o.critical {
        find_critical_windows(f, o.window, &compute_timing(f, &o.lat).0, o.slack)
    } else {
        find_windows(f, o.window)
    };
    st.windows_total = windows.len() as u32;
    let n = f.values.len();
    let mut at_root: Vec<Option<usize>> = vec![None; n];
    let mut inside = vec![false; n];
    for (i, w) in windows.iter().enumerate() {
        at_root[w.root.index()] = Some(i);
        if !o.critical {
            w.interior.iter().for_each(|v| inside[v.index()] = true);
        }
    }
    let mut ready = vec![0u32; n];
    let mut plans: Vec<Option<RecExpr<Arith>>> = vec![None; windows.len()];
    for &v in &f.body {
        if inside[v.index()] {
            continue; // computed with its window's root
        }
        if let Some(i) = at_root[v.index()] {
            let w = &windows[i];
            let leaf_ready: Vec<u32> = w.leaves.iter().map(|l| ready[l.index()]).collect();
            if st.stopped_early.is_none() {
                if let Some(d) = deadline.filter(|d| d.reached()) {
                    st.stopped_early = Some(d.reason());
                } else if work.saturating_sub(st.enodes_total) < MIN_WINDOW_WORK {
                    let b = o.work_enodes;
                    st.stopped_early = Some(format!("work budget of {b} e-nodes per function reached"));
                }
            }
            if st.stopped_early.is_some() {
                // Kept as it is: its ready time from the leaves, as written.
                let cf = ReadyCost { leaf_ready: &leaf_ready, lat_add: o.lat.add, lat_mul: o.lat.mul };
                ready[v.index()] = cf.expr_cost(&w.expr).0;
                continue;
            }
            let limits = Limits {
                nodes: (o.nodes as u64).min(work.saturating_sub(st.enodes_total)) as usize,
                time: deadline
                    .map_or(Duration::from_millis(o.time_ms), |d| d.time_left().min(Duration::from_millis(o.time_ms))),
            };
            // A critical window's interior values may have been rewritten already: the root
            // as it is now is its op on its operands as they are.
            let now = o.critical.then(|| {
                let mut r = 0;
                f.value(v).def.for_each_value(|p| r = r.max(ready[p.index()]));
                r + f.op_kind(v).map_or(0, |k| o.lat.of(k))
            });
            let t0 = Instant::now();
            let (r, plan) = saturate(w, &leaf_ready, now, o, limits, rules, &mut st);
            let dt = t0.elapsed().as_secs_f64() * 1e3;
            st.windows_tried += 1;
            st.total_ms += dt;
            st.max_ms = st.max_ms.max(dt);
            ready[v.index()] = r;
            if plan.is_some() {
                st.windows_replaced += 1;
            }
            plans[i] = plan;
            continue;
        }
        let Some(kind) = f.op_kind(v) else { continue };
        let mut r = 0;
        f.value(v).def.for_each_value(|p| r = r.max(ready[p.index()]));
        ready[v.index()] = r + o.lat.of(kind);
    }
    st.mean_ms = if st.windows_tried > 0 { st.total_ms / st.windows_tried as f64 } else { 0.0 };
    rebuild(f, &windows, &plans, !o.critical);
    if o.critical {
        // Interior values read only by replaced roots are dead now.
        let live = f.live_values(&[]);
        f.retain(|g, v| live[v.index()] || matches!(g.value(v).def, Def::Input));
    }
    st.ops_after = f.op_counts().total;
    st.cp_after = compute_timing(f, &o.lat).1.asap_cycle;
    st
}

/// The runner limits of one window: `nodes` and `time-ms` cut to the budget and time left.
#[derive(Clone, Copy)]
struct Limits {
    nodes: usize,
    time: Duration,
}

/// Saturates one window; returns the root's ready time (cycles) and the replacement, if any.
fn saturate(
    w: &Window,
    leaf_ready: &[u32],
    now: Option<u32>,
    o: &EqsatOptions,
    limits: Limits,
    rules: &[Rewrite],
    st: &mut EqsatStats,
) -> (u32, Option<RecExpr<Arith>>) {
    let cf = ReadyCost { leaf_ready, lat_add: o.lat.add, lat_mul: o.lat.mul };
    let orig_ready = now.unwrap_or_else(|| cf.expr_cost(&w.expr).0);
    let mut runner: Runner<Arith, ConstantFold> =
        Runner::default().with_iter_limit(o.iters).with_node_limit(limits.nodes).with_time_limit(limits.time);
    if w.aliases.is_empty() {
        runner = runner.with_expr(&w.expr);
    } else {
        // The expression node by node, then each shared interior node unioned with its leaf.
        let mut ids: Vec<Id> = Vec::with_capacity(w.expr.as_ref().len());
        for node in w.expr.as_ref() {
            let id = runner.egraph.add(node.clone().map_children(|c| ids[usize::from(c)]));
            ids.push(id);
        }
        for &(i, k) in &w.aliases {
            let leaf = runner.egraph.add(Arith::Leaf(leaf_symbol(k)));
            runner.egraph.union(ids[i], leaf);
        }
        runner.egraph.rebuild();
        runner.roots.push(*ids.last().expect("non-empty window"));
    }
    let runner = runner.run(rules);
    st.enodes_total += runner.egraph.total_number_of_nodes() as u64;
    match &runner.stop_reason {
        Some(StopReason::Saturated) => st.stops.saturated += 1,
        Some(StopReason::IterationLimit(_)) => st.stops.iteration_limit += 1,
        Some(StopReason::NodeLimit(_)) => st.stops.node_limit += 1,
        Some(StopReason::TimeLimit(_)) => st.stops.time_limit += 1,
        Some(StopReason::Other(_)) | None => st.stops.other += 1,
    }
    st.max_enodes = st.max_enodes.max(runner.egraph.total_number_of_nodes());
    let root: Id = runner.roots[0];
    let limit = w.freed + o.budget;
    let (_, mut best) = Extractor::new(&runner.egraph, cf.clone()).find_best(root);
    if count_ops(&best) > limit {
        match pareto_extract(&runner.egraph, root, &cf, limit, 64) {
            Some((_, e)) => {
                st.budget_fallbacks += 1;
                best = e
            }
            None => return (orig_ready, None),
        }
    }
    let (new_ready, _) = cf.expr_cost(&best);
    let new_ops = count_ops(&best);
    let better = new_ready < orig_ready || new_ops < w.freed;
    if new_ready <= orig_ready && new_ops <= limit && better {
        (new_ready, Some(best))
    } else {
        (orig_ready, None)
    }
}

/// Replaces every planned window: new ops go just before the root (all leaves precede it),
/// interior values disappear, and a root whose new form is a leaf or a constant is replaced by
/// it in every use.
fn rebuild(f: &mut Function, windows: &[Window], plans: &[Option<RecExpr<Arith>>], drop_interior: bool) {
    let n = f.values.len();
    let mut dropped = vec![false; n];
    let mut plan_at: Vec<Option<usize>> = vec![None; n];
    for (i, w) in windows.iter().enumerate() {
        if plans[i].is_some() {
            if drop_interior {
                w.interior.iter().for_each(|v| dropped[v.index()] = true);
            }
            plan_at[w.root.index()] = Some(i);
        }
    }
    let mut subst: Vec<Option<Operand>> = vec![None; n];
    let sub = |subst: &[Option<Operand>], o: Operand| match o {
        Operand::Value(v) => subst[v.index()].unwrap_or(o),
        c => c,
    };
    let old = std::mem::take(&mut f.body);
    for v in old {
        if dropped[v.index()] {
            continue;
        }
        if let Some(i) = plan_at[v.index()] {
            let (w, plan) = (&windows[i], plans[i].as_ref().expect("planned"));
            let base = f.name_of(v).to_string();
            let mut made: Vec<Operand> = Vec::with_capacity(plan.as_ref().len());
            let mut memo: HashMap<OpKey, Operand> = HashMap::new();
            let last = plan.as_ref().len() - 1;
            for (k, node) in plan.as_ref().iter().enumerate() {
                let get = |id: &Id| made[usize::from(*id)];
                let (op, a, b) = match node {
                    Arith::Leaf(s) => {
                        made.push(sub(&subst, Operand::Value(w.leaves[leaf_index(*s).expect("window leaf")])));
                        continue;
                    }
                    Arith::Num(c) => {
                        made.push(Operand::Const(c.get()));
                        continue;
                    }
                    Arith::Add([a, b]) => (BinOp::Add, get(a), get(b)),
                    Arith::Sub([a, b]) => (BinOp::Sub, get(a), get(b)),
                    Arith::Mul([a, b]) => (BinOp::Mul, get(a), get(b)),
                    Arith::Neg(a) => (BinOp::Sub, Operand::Const(0.0), get(a)),
                };
                let key = (op, operand_key(a), operand_key(b));
                if k != last {
                    if let Some(&x) = memo.get(&key) {
                        made.push(x);
                        continue;
                    }
                    let x = Operand::Value(f.define_fresh(&base, Def::Binary(op, a, b), Span::DUMMY));
                    memo.insert(key, x);
                    made.push(x);
                } else {
                    f.value_mut(v).def = Def::Binary(op, a, b);
                    f.body.push(v);
                    made.push(Operand::Value(v));
                }
            }
            let top = *made.last().expect("non-empty plan");
            if top != Operand::Value(v) {
                subst[v.index()] = Some(top);
            }
            continue;
        }
        let mut def = f.value(v).def.clone();
        match &mut def {
            Def::Binary(_, a, b) => {
                *a = sub(&subst, *a);
                *b = sub(&subst, *b);
            }
            Def::Call(_, args) => args.iter_mut().for_each(|a| *a = sub(&subst, *a)),
            _ => {}
        }
        f.value_mut(v).def = def;
        f.body.push(v);
    }
    for o in &mut f.outputs {
        o.value = sub(&subst, o.value);
    }
    let keep: std::collections::HashSet<Value> = f.body.iter().chain(&f.inputs).copied().collect();
    f.retain(|_, v| keep.contains(&v));
}

/// A hashable key of one binary op on two operands (dedups the ops of a materialised window).
type OpKey = (BinOp, (bool, u64), (bool, u64));

/// A hashable key of an operand: (is a constant, value index or constant bits).
fn operand_key(o: Operand) -> (bool, u64) {
    match o {
        Operand::Value(v) => (false, v.index() as u64),
        Operand::Const(c) => (true, c.to_bits()),
    }
}
