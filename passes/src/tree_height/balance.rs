//! `balance<lat-add;lat-mul;lat-div;lat-call>`: tree-height reduction (seed §2.4.3; SPEC §6;
//! `NOTES-anchors.md` §4.2).
//!
//! Phase: atomised → atomised. Every maximal associative cluster (a `+`/`−` cluster with signs
//! or a `*` cluster; a value with several uses, an output or an op of another kind is a leaf,
//! see [`super::cluster`]) is rebuilt as the two-earliest-first tree over its terms' ready times
//! ([`Shape::Balance`]; Golumbic, "Combinatorial Merging", IEEE TC C-25(11), 1976): pop the two
//! earliest terms, combine them, push the result ready `lat` later. With one latency per
//! cluster this gives the earliest possible root, and since clusters are rebuilt in topological
//! order their terms' ready times are exact, so each cluster is optimal given its operands (not
//! globally: shared values stay leaves; `inline` trades ops for crossing them).
//!
//! No op is added: a cluster of k terms uses k − 1 ops (additive zeros and factors ±1 are
//! dropped). Signs: two `+` terms combine with `add`, a `+` and a `−` with `sub`, two `−` with
//! `add` carrying the sign, which goes to the consumers as in `zero-removal`; a `0 − x` stays
//! only where a sign reaches an output or call and cannot be absorbed.
//!
//! Contract: the op count and the critical path (`asap_cycle` under the given latencies) never
//! increase ([`super::rewrite`]); outputs change by reassociation rounding only.
//! Cost: O(values + operands + Σ k log k) over clusters of k terms.

use super::zero_removal::{ClusterRewrite, LATENCY_PARAMS};
use super::Shape;
use crate::{Params, PassInfo};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "balance",
    doc: "tree-height reduction: rebuild each associative cluster as the two-earliest-first tree (seed §2.4.3)",
    params: LATENCY_PARAMS,
    build: |p: &Params| {
        Ok(Box::new(ClusterRewrite { name: "balance", shape: Shape::Balance, lat: p.latency_override()? }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};
