//! `distribute<rounds=8;max-growth=1.5;slack=0;lat-*>`: distributes critical products over the
//! sums they multiply, `x·(t_1 ± … ± t_k)` → `x·t_1 ± … ± x·t_k`, so that the sum's terms join
//! the sum that reads the product and `balance` can reassociate across the product (Kuck,
//! Muraoka and Brent's use of distributivity; `NOTES-anchors.md` §4.2: opt-in, guarded by an ops
//! budget).
//!
//! Phase: atomised → atomised. A product `P` is a candidate when its cluster (see
//! [`super::cluster`]) has one use, by a `+`/`−` op, and its latest-ready factor `S` is a sum of
//! k ≥ 2 terms. Then `P` becomes `Σ ± t_j·Q`, with `Q` the product of `P`'s other factors (made
//! once), k new products and k − 1 adds/subs; `S` stays only if something else reads it. Each
//! round balances the function (the `balance` rewrite, as the next pass will), takes the
//! candidates whose product has at most `slack` cycles of slack there, latest first, while the
//! ops stay within `max-growth` × the input's, and keeps the round only if the balanced critical
//! path got shorter. Rounds stop when none does.
//!
//! The output is meant for `balance`: distributed sums come out as left-to-right cascades.
//! Numerics: distribution changes rounding like reassociation does, and keeps the magnitude
//! `M` (the value with absolute leaves and `−` as `+`), so the γ_D·M bound still applies.
//! Cost: per round, one `balance` rewrite and one O(values + operands) rebuild.

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{BinOp, Def, Function, Module, Operand, Phase, Value};

use super::cluster::{Class, Clusters};
use super::{rewrite_within, Shape};
use crate::params::ParamKind;
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "distribute",
    doc: "distribute critical products over the sums they multiply, within an ops budget (run balance after)",
    params: &[
        ParamInfo {
            name: "rounds",
            kind: ParamKind::U32 { default: 8, min: 0, max: 1000 },
            doc: "rounds of (balance, pick critical products, distribute)",
        },
        ParamInfo {
            name: "max-growth",
            kind: ParamKind::F64 { default: 1.5, min: 1.0, max: 100.0 },
            doc: "largest ops / input ops",
        },
        ParamInfo {
            name: "slack",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "distribute products with at most this slack after balance, cycles",
        },
        crate::params::LAT_ADD,
        crate::params::LAT_MUL,
        crate::params::LAT_DIV,
        crate::params::LAT_CALL,
    ],
    build: |p: &Params| {
        Ok(Box::new(Distribute {
            rounds: p.u32("rounds")?,
            max_growth: p.f64("max-growth")?,
            slack: p.u32("slack")?,
            lat: p.latencies()?,
            given: p.latency_override()?,
        }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// The `distribute` pass.
#[derive(Clone, Debug)]
pub struct Distribute {
    /// Rounds at most.
    pub rounds: u32,
    /// Largest ops / input ops.
    pub max_growth: f64,
    /// Largest slack of a distributed product after balance, cycles.
    pub slack: u32,
    /// Latencies, cycles (the pass replaces them at run time by the pipeline's with
    /// `given` applied, [`PassContext::latencies_for`]).
    pub lat: Latencies,
    /// Latencies given on the pass.
    pub given: crate::LatencyOverride,
}

impl Pass for Distribute {
    fn name(&self) -> &'static str {
        "distribute"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let opts = Distribute { lat: cx.latencies_for("distribute", &self.given), ..self.clone() };
        let parts = each_function(
            m,
            cx,
            "distribute",
            Before::Ticked,
            |_, _| None,
            |f, _, ticker| {
                let ops0 = f.op_counts().total;
                let (g, s, stopped) = distribute_within(f, &opts, ticker);
                *f = g;
                let part = format!(
                "@{}: {} products distributed in {} rounds, ops {ops0} -> {}, balanced critical path {} -> {} cycles",
                f.name,
                s.products,
                s.rounds,
                f.op_counts().total,
                s.cp.0,
                s.cp.1
            );
                match stopped {
                    true => Step::Stopped {
                        what: format!("in @{} after {} rounds (kept)", f.name, s.rounds),
                        kept: Some(part),
                    },
                    false => Step::Done(part),
                }
            },
        );
        cx.remark("distribute", m, format!("distribute: {}", parts.join("; ")));
        Ok(())
    }
}

/// What distribution did to one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DistributeStats {
    /// Products distributed.
    pub products: u64,
    /// Rounds kept.
    pub rounds: u32,
    /// Critical path after `balance`, before and after distributing (cycles).
    pub cp: (u32, u32),
}

/// Distributes critical products of `f` (atomised, verified) as [`Distribute`] says.
pub fn distribute_function(f: &Function, opts: &Distribute) -> (Function, DistributeStats) {
    let (g, stats, _) = distribute_within(f, opts, &Ticker::default());
    (g, stats)
}

/// [`distribute_function`] that stops when `ticker` says so (`-time-limit`): the rounds done
/// are kept (a round stopped in its `balance` is dropped); the flag is true when it stopped.
pub fn distribute_within(f: &Function, opts: &Distribute, ticker: &Ticker) -> (Function, DistributeStats, bool) {
    let budget = (f.op_counts().total as f64 * opts.max_growth).floor() as u64;
    let mut cur = f.clone();
    let Some((mut balanced, _)) = rewrite_within(&cur, Shape::Balance, &opts.lat, ticker) else {
        return (cur, DistributeStats::default(), true);
    };
    let mut cp = compute_timing(&balanced, &opts.lat).1.asap_cycle;
    let mut stats = DistributeStats { cp: (cp, cp), ..DistributeStats::default() };
    for _ in 0..opts.rounds {
        if ticker.check() {
            break;
        }
        let picks = pick(&cur, &balanced, opts, budget);
        if picks.is_empty() {
            break;
        }
        let n = picks.len() as u64;
        let next = apply(&cur, &picks);
        let Some((b, _)) = rewrite_within(&next, Shape::Balance, &opts.lat, ticker) else { break };
        let c = compute_timing(&b, &opts.lat).1.asap_cycle;
        if c >= cp || next.op_counts().total > budget {
            break;
        }
        (cur, balanced, cp) = (next, b, c);
        stats.products += n;
        stats.rounds += 1;
    }
    stats.cp.1 = cp;
    (cur, stats, ticker.stopped())
}

/// A product to distribute: its cluster's root and the sum factor.
struct Pick {
    root: Value,
    sum: Value,
}

/// Candidates of `f` whose product is critical in `balanced` (matched by name: `balance` keeps
/// cluster roots' names), latest first, within the ops budget.
fn pick(f: &Function, balanced: &Function, opts: &Distribute, budget: u64) -> Vec<Pick> {
    let cl = Clusters::new(f);
    let (timing, _) = compute_timing(balanced, &opts.lat);
    let time_of = |v: Value| -> Option<(u32, u32)> {
        let b = balanced.lookup(f.name_of(v))?;
        timing[b.index()].map(|t| (t.asap_cycle, t.alap_cycle))
    };
    let mut picks = Vec::new();
    for &p in &f.body {
        if cl.class[p.index()] != Class::Multiplicative
            || !cl.is_root(p)
            || cl.uses[p.index()] != 1
            || cl.is_output[p.index()]
        {
            continue;
        }
        let Some((asap, alap)) = time_of(p) else { continue };
        if alap - asap > opts.slack {
            continue;
        }
        let tree = cl.tree(f, p);
        // The latest factor must be a sum of at least two terms.
        let mut best: Option<(u32, Value)> = None;
        let mut other_latest = 0;
        for l in &tree.leaves {
            let t = match l.operand {
                Operand::Value(x) if f.op_kind(x).is_some() => time_of(x).map_or(0, |t| t.0),
                _ => 0,
            };
            match (l.operand, best) {
                (Operand::Value(x), b) if cl.class[x.index()] == Class::Additive && b.is_none_or(|(bt, _)| t > bt) => {
                    if let Some((bt, _)) = b {
                        other_latest = other_latest.max(bt);
                    }
                    best = Some((t, x));
                }
                _ => other_latest = other_latest.max(t),
            }
        }
        let Some((t, s)) = best else { continue };
        if t < other_latest || cl.tree(f, s).leaves.len() < 2 {
            continue;
        }
        picks.push((asap, p, s));
    }
    // A user that is an add/sub: the distributed terms join its cluster.
    let mut user_additive = vec![false; f.values.len()];
    for &u in &f.body {
        if cl.class[u.index()] == Class::Additive {
            f.value(u).def.for_each_value(|a| user_additive[a.index()] = true);
        }
    }
    picks.retain(|&(_, p, _)| user_additive[p.index()]);
    picks.sort_by_key(|&(asap, p, _)| (std::cmp::Reverse(asap), p));
    let mut ops = f.op_counts().total;
    let mut out = Vec::new();
    for (_, root, sum) in picks {
        // k products replace one; the sum's k − 1 adds move into the user's sum, or are
        // duplicated there when something else still reads the sum.
        let k = cl.tree(f, sum).leaves.len() as u64;
        let extra = if cl.uses[sum.index()] == 1 { k - 1 } else { 2 * k - 2 };
        if ops + extra > budget {
            continue;
        }
        ops += extra;
        out.push(Pick { root, sum });
    }
    out
}

/// `f` with every pick distributed; values left without uses are dropped.
fn apply(f: &Function, picks: &[Pick]) -> Function {
    let cl = Clusters::new(f);
    let mut chosen: Vec<Option<Value>> = vec![None; f.values.len()];
    for p in picks {
        chosen[p.root.index()] = Some(p.sum);
    }
    let mut out = Function::new(f.name.clone(), Phase::Atomised);
    out.equations = f.equations;
    out.states = f.states;
    out.span = f.span;
    let mut map: Vec<Operand> = vec![Operand::Const(f64::NAN); f.values.len()];
    let m = |o: Operand, map: &[Operand]| match o {
        Operand::Value(x) => map[x.index()],
        c => c,
    };
    for &v in &f.inputs {
        let d = f.value(v);
        map[v.index()] = Operand::Value(out.add_input(d.name.clone(), d.span).expect("unique input names"));
    }
    for &v in &f.body {
        let d = f.value(v);
        let span = d.span;
        if let Some(sum) = chosen[v.index()] {
            // Q = product of the other factors (constants included), then Σ ± t_j·Q.
            let ptree = cl.tree(f, v);
            let mut q: Option<Operand> = None;
            let mut skipped = false;
            for l in &ptree.leaves {
                if !skipped && l.operand == Operand::Value(sum) {
                    skipped = true;
                    continue;
                }
                let o = m(l.operand, &map);
                q = Some(match q {
                    None => o,
                    Some(a) => {
                        Operand::Value(out.define_fresh(&format!("{}.q", d.name), Def::Binary(BinOp::Mul, a, o), span))
                    }
                });
            }
            let q = q.unwrap_or(Operand::Const(1.0));
            let stree = cl.tree(f, sum);
            let mut terms: Vec<(Operand, bool)> = stree
                .leaves
                .iter()
                .map(|l| {
                    let t = Def::Binary(BinOp::Mul, m(l.operand, &map), q);
                    (Operand::Value(out.define_fresh(&format!("{}.d", d.name), t, span)), l.negative)
                })
                .collect();
            // A positive term first, so the cascade needs no zero unless all are negative.
            if let Some(i) = terms.iter().position(|t| !t.1) {
                terms.swap(0, i);
            }
            let (first, neg) = terms[0];
            let mut acc = if neg {
                Operand::Value(out.define_fresh(
                    &format!("{}.d", d.name),
                    Def::Binary(BinOp::Sub, Operand::Const(0.0), first),
                    span,
                ))
            } else {
                first
            };
            let last = terms.len() - 1;
            for (i, &(t, neg)) in terms.iter().enumerate().skip(1) {
                let op = if neg { BinOp::Sub } else { BinOp::Add };
                let name = if i == last { d.name.clone() } else { out.fresh_name(&format!("{}.d", d.name)) };
                let name = if out.lookup(&name).is_some() { out.fresh_name(&name) } else { name };
                acc = Operand::Value(out.define(name, Def::Binary(op, acc, t), span).expect("fresh name"));
            }
            map[v.index()] = acc;
            continue;
        }
        let def = match &d.def {
            Def::Trig(t, a) => {
                let Operand::Value(a) = map[a.index()] else { unreachable!("trig reads an input") };
                Def::Trig(*t, a)
            }
            Def::Binary(op, a, b) => Def::Binary(*op, m(*a, &map), m(*b, &map)),
            Def::Call(c, args) => Def::Call(c.clone(), args.iter().map(|o| m(*o, &map)).collect()),
            other => other.clone(),
        };
        let name = if out.lookup(&d.name).is_some() { out.fresh_name(&d.name) } else { d.name.clone() };
        map[v.index()] = Operand::Value(out.define(name, def, span).expect("fresh name"));
    }
    for o in &f.outputs {
        out.set_output(o.name.clone(), m(o.value, &map), o.span);
    }
    // Drop what distribution left without uses (the input's own dead code stays).
    let roots: Vec<Value> = f
        .body
        .iter()
        .filter(|v| cl.uses[v.index()] == 0)
        .filter_map(|v| match map[v.index()] {
            Operand::Value(x) => Some(x),
            Operand::Const(_) => None,
        })
        .collect();
    let live = out.live_values(&roots);
    out.retain(|g, v| live[v.index()] || matches!(g.value(v).def, Def::Input));
    out
}
