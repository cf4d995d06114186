//! Tree-height reduction (issue 5; seed §2.4, SPEC §6; `NOTES-anchors.md` §4): the
//! rewrites that shorten the critical path by moving signs and reassociating sums and products.
//!
//! | pass | file | what |
//! |---|---|---|
//! | `zero-removal` | [`zero_removal`] | removes the `0 − x` ops of SPEC §3 by moving signs (seed §2.4.1) |
//! | `swap` | [`swap`] | reorders each cluster's terms, latest nearest the root (seed §2.4.2) |
//! | `balance` | [`balance`] | rebuilds each cluster as the two-earliest-first tree (seed §2.4.3) |
//! | `distribute` | [`distribute`] | opt-in: distributes critical products over sums, within an ops budget |
//!
//! Two passes that prepare the ground live beside this folder: `inline<max-uses=K>`
//! ([`crate::inline`]: duplicates values used ≤ K times into their consumers' clusters, reading
//! [`cluster`]) and `specialize<params=FILE>` ([`crate::specialize`]: folds known model
//! parameters, then drops dead code).
//!
//! The first three share [`cluster`] (maximal associative clusters), [`sign`] (where a sign
//! can go for free), [`shape`] (the tree of one cluster) and [`rebuild`] (the rewriter that
//! carries signs; its `emit` half writes the ops). All run on the atomised phase and keep it.
//!
//! # Contract of the cluster rewrites
//! For every function: the op count never increases, the critical path (`asap_cycle` under
//! the pass's latencies) never increases, and outputs keep their values up to reassociation —
//! bit for bit (up to the sign of a zero) for `zero-removal`, whose sign moves are exact in
//! IEEE 754. [`rewrite`] enforces the first two: if a rebuild would break them (the sign
//! analysis is one sign at a time, so two negations meeting can cost an op), it retries without
//! trusting the analysis and, failing that, keeps the function as it was.
//!
//! The retry, the *cautious* rebuild, moves no sign out of its cluster: a negative result gets
//! its true sign there (for a `0 − x` that is the `0 − x` again), so every value is at hand
//! with its true sign, as in the input, and signs move only within a cluster (`(0 − a) + b` →
//! `b − a`). A sign carried out can cost more than the zero it removes: shared, it reaches
//! each consumer, and every one that cannot take it pays an op; carried through products into
//! a sum where it meets another one, the negation left there lengthens paths that had none
//! (tests `a_shared_negation_keeps_its_zero_in_the_cautious_rebuild`,
//! `signs_carried_through_products_keep_their_zeros_in_the_cautious_rebuild`).

pub mod balance;
pub mod cluster;
pub mod distribute;
mod emit;
pub mod rebuild;
pub mod shape;
pub mod sign;
pub mod swap;
pub mod zero_removal;

#[cfg(test)]
mod tests;

use robovec_ir::analysis::Latencies;
use robovec_ir::Function;

use crate::Ticker;

pub use rebuild::RebuildStats;
pub use shape::Shape;

/// What [`rewrite`] did to one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    /// Counters of the rebuild that was kept.
    pub stats: RebuildStats,
    /// Ops before and after.
    pub ops: (u64, u64),
    /// Critical path (`asap_cycle`, cycles) before and after.
    pub asap_cycle: (u32, u32),
    /// 0: the first rebuild was kept; 1: the cautious one; 2: none (function unchanged).
    pub fallback: u8,
}

/// Rebuilds every cluster of `f` (atomised, verified) with `shape` under latencies `lat`,
/// keeping the contract above.
pub fn rewrite(f: &Function, shape: Shape, lat: &Latencies) -> (Function, Outcome) {
    rewrite_within(f, shape, lat, &Ticker::default()).expect("a ticker without a limit never stops")
}

/// [`rewrite`] that stops when `ticker` says so (`-time-limit`; one tick per value rebuilt):
/// `None`, and the caller keeps `f` as it was.
pub fn rewrite_within(f: &Function, shape: Shape, lat: &Latencies, ticker: &Ticker) -> Option<(Function, Outcome)> {
    let ops = f.op_counts().total;
    let orig = rebuild::ready_times(f, lat);
    let cp = f.body.iter().filter(|&&v| f.op_kind(v).is_some()).map(|&v| orig[v.index()]).max().unwrap_or(0);
    for (fallback, trust) in [(0u8, true), (1, false)] {
        let (g, stats, g_cp) = rebuild::rebuild(f, shape, lat, &orig, trust, ticker)?;
        let g_ops = g.op_counts().total;
        if g_ops <= ops && g_cp <= cp {
            return Some((g, Outcome { stats, ops: (ops, g_ops), asap_cycle: (cp, g_cp), fallback }));
        }
    }
    let mut g = f.clone();
    g.clear_timing();
    Some((g, Outcome { stats: RebuildStats::default(), ops: (ops, ops), asap_cycle: (cp, cp), fallback: 2 }))
}

/// One line for `-stats` summarising `outcomes` of a pass over a module.
pub fn summary(pass: &str, outcomes: &[(String, Outcome)]) -> String {
    let mut parts = Vec::new();
    for (name, o) in outcomes {
        let fb = match o.fallback {
            0 => String::new(),
            1 => ", cautious rebuild".into(),
            _ => ", unchanged (no rebuild kept the contract)".into(),
        };
        parts.push(format!(
            "@{name}: ops {} -> {}, critical path {} -> {} cycles, {} clusters, {} terms dropped, {} negations made{fb}",
            o.ops.0, o.ops.1, o.asap_cycle.0, o.asap_cycle.1, o.stats.clusters, o.stats.dropped_terms, o.stats.negations
        ));
    }
    format!("{pass}: {}", parts.join("; "))
}
