//! `schedule-cpu<order=best|dfs|greedy;registers=R>`: reorders each function body into another
//! topological order that needs fewer registers on a CPU (issue 11, "one state, f64").
//!
//! Robotran writes its equations in derivation order: kinematics of every body, then forces,
//! then the mass matrix, so a value computed early is read hundreds of lines later and a C
//! compiler that keeps the source order (GCC does not schedule before register allocation on
//! x86 at `-O2`/`-O3`) spills it: 40 % of the instructions of coman's `dirdyna` are stack
//! spills. This pass changes only the order of the body: every value keeps its operation and
//! its operands, so every value — and every output — is bit-for-bit what it was.
//!
//! # Algorithms
//! - `dfs`: **Sethi–Ullman order on the DAG.** Each result gets the Sethi–Ullman label of its
//!   expression seen as a tree (Sethi & Ullman, "The generation of optimal code for arithmetic
//!   expressions", JACM 17(4), 1970; the DAG heuristic of Aho, Lam, Sethi & Ullman,
//!   *Compilers* 2nd ed. §8.10): a memory operand (input, trig initial variable, constant)
//!   needs 0 registers, an operation with operand needs `l ≥ r` needs `l` if `l > r` and `l + 1`
//!   if `l = r`, at least 1; a call with argument needs sorted `n₁ ≥ n₂ ≥ …` needs
//!   `maxᵢ(nᵢ + i − 1)`. Then a depth-first walk from the outputs, in output order, emits each
//!   value after its operands, visiting the operand that needs more registers first. A value
//!   shared by several outputs is emitted at its first use.
//! - `greedy`: **register-reducing list scheduling**, top down (the kill-count heuristic of
//!   register-pressure-aware list schedulers, e.g. Goodman & Hsu, "Code scheduling and
//!   register allocation in large basic blocks", ICS 1988; LLVM's `list-burr` is its bottom-up
//!   form). Among the operations whose operands are all computed, pick the one with the largest
//!   net change `(results it reads for the last time) − 1`; ties go to the operation that
//!   became ready last, which keeps working on the chain just started (depth-first locality).
//! - `best` (default): computes both and keeps, per function, whichever of the two and the
//!   original order has the smallest [`pressure::Pressure::excess`] at `registers` registers
//!   (then the smallest `max_live`, then the shortest total live range). So the pass never
//!   makes the pressure worse by that measure.
//!
//! Trig initial variables (`sin`/`cos` of an input) all go first, in their original order: with
//! `trig=libm` they are calls, which clobber every vector register under the System V and
//! AAPCS64 ABIs, so they belong where nothing is live yet; with `trig=input` they are loads;
//! with `trig=inline` they are inline vector code whose libm fallback is also a call.
//! Values no output needs keep their original relative order, after everything else.
//!
//! Runs on the atomised phase and keeps it; clears timing attributes. Cost: O(values +
//! operands) per order (the greedy keeps one stack per score with lazy deletion).

pub mod pressure;

use robovec_ir::{Def, Function, Module, Operand, Value};

use crate::params::ParamKind;
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};
use pressure::{is_result, pressure_of_order, Pressure};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "schedule-cpu",
    doc: "reorder each body (same ops, same operands: bit-exact) to cut register pressure on a CPU",
    params: &[
        ParamInfo {
            name: "order",
            kind: ParamKind::Choice { choices: &["best", "dfs", "greedy"], default: "best" },
            doc: "dfs: Sethi-Ullman depth-first from the outputs; greedy: kill-count list scheduling; best: the lower pressure of both and the original",
        },
        ParamInfo {
            name: "registers",
            kind: ParamKind::U32 { default: 16, min: 1, max: 1024 },
            doc: "registers the target has for values (16: x86-64 xmm/ymm), used by `best` to compare orders",
        },
    ],
    build: |p: &Params| {
        let order = match p.choice("order")? {
            "dfs" => Order::Dfs,
            "greedy" => Order::Greedy,
            _ => Order::Best,
        };
        Ok(Box::new(ScheduleCpu { order, registers: p.u32("registers")? as usize }))
    },
    props: crate::Props { requires: Some(robovec_ir::Phase::Atomised), at_time_limit: crate::AtTimeLimit::Skip, exact_in_reals: true, ..crate::Props::DEFAULT },
};

/// Which order the pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// Sethi–Ullman labels, depth-first from the outputs.
    Dfs,
    /// Kill-count greedy list scheduling.
    Greedy,
    /// The lowest pressure of `Dfs`, `Greedy` and the original order.
    Best,
}

/// The `schedule-cpu` pass.
#[derive(Debug)]
pub struct ScheduleCpu {
    /// Which order to write.
    pub order: Order,
    /// Registers assumed by `Best` when comparing orders.
    pub registers: usize,
}

impl Pass for ScheduleCpu {
    fn name(&self) -> &'static str {
        "schedule-cpu"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        // The clock is read between functions and between the orders `best` compares (each
        // O(n log n)); a function not started keeps its order.
        let skipped = |f: &Function, _| Some(format!("before @{} (kept in its order)", f.name));
        let parts = each_function(m, cx, "schedule-cpu", Before::Clock, skipped, |f, _, ticker| {
            let before = pressure_of_order(f, &f.body, self.registers);
            let (order, which) = schedule_within(f, self.order, self.registers, ticker);
            let after = pressure_of_order(f, &order, self.registers);
            let part = format!(
                "@{} max-live {} -> {}, excess over {} registers {} -> {} ({which})",
                f.name, before.max_live, after.max_live, self.registers, before.excess, after.excess
            );
            f.body = order;
            // Renumber into the canonical order (inputs, then body) the text reader produces.
            f.retain(|_, _| true);
            f.clear_timing();
            Step::Done(part)
        });
        cx.remark("schedule-cpu", m, format!("schedule-cpu: {}", parts.join("; ")));
        Ok(())
    }
}

/// A body order of a function (`dfs_order`, `greedy_order`).
type OrderFn = fn(&Function) -> Vec<Value>;

/// The body order `order` asks for (a permutation of `f.body` that is a topological order),
/// with the name of the order chosen (`dfs`, `greedy` or `original`).
pub fn schedule(f: &Function, order: Order, registers: usize) -> (Vec<Value>, &'static str) {
    schedule_within(f, order, registers, &Ticker::default())
}

/// [`schedule`] where `best` compares no further order once `ticker` says stop
/// (`-time-limit`): the best of those compared (the original order first).
pub fn schedule_within(f: &Function, order: Order, registers: usize, ticker: &Ticker) -> (Vec<Value>, &'static str) {
    match order {
        Order::Dfs => (dfs_order(f), "dfs"),
        Order::Greedy => (greedy_order(f), "greedy"),
        Order::Best => {
            let key = |p: Pressure| (p.excess, p.max_live, p.total);
            let mut best = (f.body.clone(), "original");
            let mut best_key = key(pressure_of_order(f, &f.body, registers));
            let orders: [(OrderFn, &'static str); 2] = [(dfs_order, "dfs"), (greedy_order, "greedy")];
            for (make, name) in orders {
                if ticker.check() {
                    break;
                }
                let o = make(f);
                let k = key(pressure_of_order(f, &o, registers));
                if k < best_key {
                    best_key = k;
                    best = (o, name);
                }
            }
            best
        }
    }
}

/// The result operands of `v`, each once, in operand order.
fn result_operands(f: &Function, v: Value) -> Vec<Value> {
    let mut ops = Vec::new();
    f.value(v).def.for_each_value(|a| {
        if is_result(f, a) && !ops.contains(&a) {
            ops.push(a)
        }
    });
    ops
}

/// Trig initial variables first (original order), then `rest`, then the body values `rest`
/// missed (those no output needs) in their original order.
fn assemble(f: &Function, rest: Vec<Value>) -> Vec<Value> {
    let mut placed = vec![false; f.values.len()];
    let mut order: Vec<Value> = f.body.iter().copied().filter(|&v| !is_result(f, v)).collect();
    order.iter().for_each(|v| placed[v.index()] = true);
    for v in rest {
        if !placed[v.index()] {
            placed[v.index()] = true;
            order.push(v);
        }
    }
    order.extend(f.body.iter().copied().filter(|v| !placed[v.index()]));
    order
}

/// Sethi–Ullman labels of every result, registers (0 for anything else).
pub fn sethi_ullman_labels(f: &Function) -> Vec<u32> {
    let mut need = vec![0u32; f.values.len()];
    for &v in &f.body {
        if !is_result(f, v) {
            continue;
        }
        let mut ns: Vec<u32> = Vec::new();
        let mut push = |o: &Operand| ns.push(if let Operand::Value(a) = o { need[a.index()] } else { 0 });
        match &f.value(v).def {
            Def::Binary(_, a, b) => {
                push(a);
                push(b)
            }
            Def::Call(_, args) => args.iter().for_each(&mut push),
            _ => {}
        }
        ns.sort_unstable_by(|a, b| b.cmp(a));
        let label = ns.iter().enumerate().map(|(i, &n)| n + i as u32).max().unwrap_or(0);
        need[v.index()] = label.max(1);
    }
    need
}

/// The `dfs` order (see the module doc).
pub fn dfs_order(f: &Function) -> Vec<Value> {
    let need = sethi_ullman_labels(f);
    let mut done = vec![false; f.values.len()];
    let mut out = Vec::with_capacity(f.body.len());
    // Explicit stack: (value, its result operands by decreasing need, next operand).
    let mut stack: Vec<(Value, Vec<Value>, usize)> = Vec::new();
    for o in &f.outputs {
        let Operand::Value(root) = o.value else { continue };
        if !is_result(f, root) || done[root.index()] {
            continue;
        }
        let children = |v: Value| {
            let mut c = result_operands(f, v);
            // Stable: equal needs keep operand order.
            c.sort_by(|a, b| need[b.index()].cmp(&need[a.index()]));
            c
        };
        done[root.index()] = true;
        stack.push((root, children(root), 0));
        while let Some((v, kids, next)) = stack.last_mut() {
            if let Some(&k) = kids.get(*next) {
                *next += 1;
                if !done[k.index()] {
                    done[k.index()] = true;
                    let c = children(k);
                    stack.push((k, c, 0));
                }
            } else {
                out.push(*v);
                stack.pop();
            }
        }
    }
    assemble(f, out)
}

/// The `greedy` order (see the module doc).
pub fn greedy_order(f: &Function) -> Vec<Value> {
    const BUCKETS: usize = 8;
    let n = f.values.len();
    // Only what the outputs need: the rest goes last (`assemble`).
    let needed = f.live_values(&[]);
    let schedulable = |v: Value| needed[v.index()] && is_result(f, v);
    let operands: Vec<Vec<Value>> = (0..n)
        .map(|i| Value::with_number(i as u32))
        .map(|v| if schedulable(v) { result_operands(f, v) } else { Vec::new() })
        .collect();
    let mut users: Vec<Vec<Value>> = vec![Vec::new(); n];
    let mut pending = vec![0u32; n];
    for &v in f.body.iter().filter(|&&v| schedulable(v)) {
        for &a in &operands[v.index()] {
            users[a.index()].push(v);
        }
        pending[v.index()] = operands[v.index()].len() as u32;
    }
    let mut remaining: Vec<u32> = users.iter().map(|u| u.len() as u32).collect();
    let mut scheduled = vec![false; n];
    let mut stamp = vec![0u32; n];
    let mut buckets: Vec<Vec<(Value, u32)>> = vec![Vec::new(); BUCKETS];
    let score = |v: Value, remaining: &[u32]| -> usize {
        // kills − 1, shifted by one so that it indexes a bucket.
        let kills = operands[v.index()].iter().filter(|a| remaining[a.index()] == 1).count();
        kills.min(BUCKETS - 1)
    };
    let push = |v: Value, remaining: &[u32], stamp: &mut [u32], buckets: &mut [Vec<(Value, u32)>]| {
        stamp[v.index()] += 1;
        buckets[score(v, remaining)].push((v, stamp[v.index()]));
    };
    for &v in f.body.iter().filter(|&&v| schedulable(v) && pending[v.index()] == 0) {
        push(v, &remaining, &mut stamp, &mut buckets);
    }
    let mut out = Vec::with_capacity(f.body.len());
    loop {
        let mut pick = None;
        for b in (0..BUCKETS).rev() {
            while let Some((v, s)) = buckets[b].pop() {
                if !scheduled[v.index()] && s == stamp[v.index()] {
                    pick = Some(v);
                    break;
                }
            }
            if pick.is_some() {
                break;
            }
        }
        let Some(v) = pick else { break };
        scheduled[v.index()] = true;
        out.push(v);
        for &a in &operands[v.index()] {
            remaining[a.index()] -= 1;
            if remaining[a.index()] == 1 {
                // Its last reader now kills it: that reader's score goes up.
                if let Some(&u) = users[a.index()].iter().find(|u| !scheduled[u.index()]) {
                    if pending[u.index()] == 0 {
                        push(u, &remaining, &mut stamp, &mut buckets);
                    }
                }
            }
        }
        for &u in &users[v.index()] {
            pending[u.index()] -= 1;
            if pending[u.index()] == 0 {
                push(u, &remaining, &mut stamp, &mut buckets);
            }
        }
    }
    assemble(f, out)
}

#[cfg(test)]
mod tests;
