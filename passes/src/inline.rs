//! `inline<max-uses=K;max-size=S>`: duplicates shared sums and products into their consumers so
//! that clusters cross equation boundaries (tree-height reduction on a DAG, `NOTES-anchors.md`
//! §4.2 "shared sub-expressions": a shared value is a leaf of every cluster that reads it, and
//! duplication trades ops for height).
//!
//! Phase: atomised → atomised. A value `v` is inlined when it is an additive or multiplicative
//! op, not an output, with 2 ≤ uses ≤ K: every use by an op of the same class (`+ −` into
//! `+ −`, `*` into `*`) gets its own copy of `v`'s cluster tree (the tree as already inlined:
//! values are visited in body order), so that `v`'s terms become terms of the consumer's
//! cluster and a following `balance` can pair them with the consumer's other terms. Uses of
//! another kind keep the original; an original left without uses is dropped. K = 1 changes
//! nothing (a value with one use is already inside its consumer's cluster). Copies are named
//! `v.dup`, `v.dup.1`, … A copied tree larger than `max-size` ops is not copied (this bounds the
//! growth of nested duplication, which is otherwise exponential in the nesting depth).
//!
//! Contract: outputs keep their values exactly (a copy computes the same ops in the same order);
//! the op count grows by the copies' ops, reported on the `-stats` line; the critical path does
//! not change until `balance` runs. Cost: O(values + operands + ops copied).

use std::collections::HashMap;

use robovec_ir::{Def, Function, Module, Operand, Phase, Value};

use crate::params::ParamKind;
use crate::tree_height::cluster::{Class, Clusters};
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "inline",
    doc: "duplicate sums/products used at most K times into same-kind consumers, so clusters cross equations",
    params: &[
        ParamInfo {
            name: "max-uses",
            kind: ParamKind::U32 { default: 2, min: 1, max: 1_000_000 },
            doc: "K: inline values with 2..=K uses (1 = no change)",
        },
        ParamInfo {
            name: "max-size",
            kind: ParamKind::U32 { default: 64, min: 1, max: 1 << 30 },
            doc: "largest cluster tree copied, ops",
        },
    ],
    build: |p: &Params| Ok(Box::new(Inline { max_uses: p.u32("max-uses")?, max_size: p.u32("max-size")? })),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// The `inline` pass.
#[derive(Debug)]
pub struct Inline {
    /// K: values with 2..=K uses are inlined.
    pub max_uses: u32,
    /// Largest copied tree, ops.
    pub max_size: u32,
}

/// What inlining did to one function (units: values, uses, ops).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InlineStats {
    /// Values duplicated.
    pub values: u64,
    /// Uses that received a copy.
    pub copies: u64,
    /// Ops before and after.
    pub ops: (u64, u64),
    /// Ops added: ops copied minus the originals left without uses.
    pub added: u64,
}

impl Pass for Inline {
    fn name(&self) -> &'static str {
        "inline"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        // The work ticks per value; a stop before a function is found inside it (the first
        // tick says stop), so that function is named as kept.
        let skipped = |f: &Function, _| Some(format!("in @{} (kept as it was)", f.name));
        let parts = each_function(m, cx, "inline", Before::Ticked, skipped, |f, _, ticker| {
            let Some((g, s)) = inline_within(f, self.max_uses, self.max_size, ticker) else {
                return Step::Stopped { what: format!("in @{} (kept as it was)", f.name), kept: None };
            };
            *f = g;
            Step::Done(format!(
                "@{}: {} values copied into {} uses, ops {} -> {} ({} ops added)",
                f.name, s.values, s.copies, s.ops.0, s.ops.1, s.added
            ))
        });
        cx.remark(
            "inline",
            m,
            format!("inline<max-uses={};max-size={}>: {}", self.max_uses, self.max_size, parts.join("; ")),
        );
        Ok(())
    }
}

/// Inlines the values of `f` (atomised, verified) with 2..=`max_uses` uses into their
/// same-class consumers (see the module doc).
pub fn inline_function(f: &Function, max_uses: u32, max_size: u32) -> (Function, InlineStats) {
    inline_within(f, max_uses, max_size, &Ticker::default()).expect("a ticker without a limit never stops")
}

/// [`inline_function`] that gives up when `ticker` says so (`-time-limit`; one tick per
/// value): `None`, and the caller keeps `f`.
pub fn inline_within(f: &Function, max_uses: u32, max_size: u32, ticker: &Ticker) -> Option<(Function, InlineStats)> {
    let cl = Clusters::new(f);
    let n = f.values.len();
    let candidate: Vec<bool> = (0..n)
        .map(|i| cl.class[i] != Class::Other && !cl.is_output[i] && (2..=max_uses).contains(&cl.uses[i]))
        .collect();
    let mut out = Function::new(f.name.clone(), Phase::Atomised);
    out.equations = f.equations;
    out.states = f.states;
    out.span = f.span;
    let mut cx = Copier {
        out,
        map: vec![Operand::Const(f64::NAN); n],
        private: Vec::new(),
        size: Vec::new(),
        next: HashMap::new(),
    };
    let mut stats = InlineStats { ops: (f.op_counts().total, 0), ..InlineStats::default() };
    let mut copied = vec![false; n];
    for &v in &f.inputs {
        let d = f.value(v);
        let nv = cx.out.add_input(d.name.clone(), d.span).expect("input names are unique");
        cx.push(nv, false, 0);
        cx.map[v.index()] = Operand::Value(nv);
    }
    for &v in &f.body {
        if ticker.tick() {
            return None;
        }
        let d = f.value(v);
        let class = cl.class[v.index()];
        let mut def = d.def.clone();
        if let Def::Binary(_, a, b) = &mut def {
            for o in [a, b] {
                *o = match *o {
                    Operand::Value(x) if candidate[x.index()] && cl.class[x.index()] == class => {
                        let Operand::Value(root) = cx.map[x.index()] else { unreachable!("ops map to values") };
                        if cx.size[root.index()] <= max_size {
                            copied[x.index()] = true;
                            stats.copies += 1;
                            cx.copy_root(root, f.name_of(x))
                        } else {
                            cx.map[x.index()]
                        }
                    }
                    Operand::Value(x) => cx.map[x.index()],
                    c => c,
                };
            }
        } else {
            def = match def {
                Def::Trig(t, a) => {
                    let Operand::Value(a) = cx.map[a.index()] else { unreachable!("trig reads an input") };
                    Def::Trig(t, a)
                }
                other => map_operands(other, &cx.map),
            };
        }
        // Interior values stay private to their consumer's tree.
        let private = cl.interior[v.index()];
        let mut size = 0;
        if let Def::Binary(_, a, b) = &def {
            size = 1 + [a, b].iter().map(|o| cx.private_size(**o)).sum::<u32>();
        }
        let name = if cx.out.lookup(&d.name).is_some() { cx.out.fresh_name(&d.name) } else { d.name.clone() };
        let nv = cx.out.define(name, def, d.span).expect("name is free");
        cx.push(nv, private, size);
        cx.map[v.index()] = Operand::Value(nv);
    }
    for o in &f.outputs {
        let value = match o.value {
            Operand::Value(x) => cx.map[x.index()],
            c => c,
        };
        cx.out.set_output(o.name.clone(), value, o.span);
    }
    stats.values = copied.iter().filter(|&&c| c).count() as u64;
    // Keep what the input kept (even its dead code); drop the originals left without uses.
    let keep: Vec<Value> = f
        .body
        .iter()
        .filter(|&&v| cl.uses[v.index()] == 0)
        .map(|&v| cx.map[v.index()])
        .filter_map(|o| match o {
            Operand::Value(x) => Some(x),
            Operand::Const(_) => None,
        })
        .collect();
    let mut g = cx.out;
    drop_dead(&mut g, &keep);
    stats.ops.1 = g.op_counts().total;
    stats.added = stats.ops.1.saturating_sub(stats.ops.0);
    Some((g, stats))
}

fn map_operands(def: Def, map: &[Operand]) -> Def {
    let m = |o: &Operand| match o {
        Operand::Value(x) => map[x.index()],
        c => *c,
    };
    match def {
        Def::Binary(op, a, b) => Def::Binary(op, m(&a), m(&b)),
        Def::Call(c, args) => Def::Call(c, args.iter().map(m).collect()),
        other => other,
    }
}

/// Removes values that neither an output nor a value of `keep` needs.
fn drop_dead(f: &mut Function, keep: &[Value]) {
    let live = f.live_values(keep);
    // Inputs stay: inlining does not change which inputs a function reads.
    f.retain(|g, v| live[v.index()] || matches!(g.value(v).def, Def::Input));
}

struct Copier {
    out: Function,
    /// Operand of each original value in `out`.
    map: Vec<Operand>,
    /// Per value of `out`: used once, by the op of the tree it belongs to.
    private: Vec<bool>,
    /// Per value of `out`: ops of its private tree (itself included).
    size: Vec<u32>,
    next: HashMap<String, u32>,
}

impl Copier {
    fn push(&mut self, v: Value, private: bool, size: u32) {
        debug_assert_eq!(v.index(), self.private.len());
        self.private.push(private);
        self.size.push(size);
    }

    fn private_size(&self, o: Operand) -> u32 {
        match o {
            Operand::Value(x) if self.private[x.index()] => self.size[x.index()],
            _ => 0,
        }
    }

    /// A copy of the tree of `root` (a value of `out`): its private ops are copied, its leaves
    /// shared. Returns the copy's root, itself private to the op being built.
    fn copy_root(&mut self, root: Value, base: &str) -> Operand {
        let Def::Binary(op, a, b) = self.out.value(root).def.clone() else { unreachable!("candidates are ops") };
        let ca = self.copy_operand(a, base);
        let cb = self.copy_operand(b, base);
        let size = 1 + self.private_size(ca) + self.private_size(cb);
        let k = self.next.entry(base.to_string()).or_insert(0);
        let mut name = if *k == 0 { format!("{base}.dup") } else { format!("{base}.dup.{k}") };
        *k += 1;
        if self.out.lookup(&name).is_some() {
            name = self.out.fresh_name(&name);
        }
        let span = self.out.value(root).span;
        let v = self.out.define(name, Def::Binary(op, ca, cb), span).expect("name is free");
        self.push(v, true, size);
        Operand::Value(v)
    }

    fn copy_operand(&mut self, o: Operand, base: &str) -> Operand {
        match o {
            Operand::Value(x) if self.private[x.index()] => self.copy_root(x, base),
            o => o,
        }
    }
}
