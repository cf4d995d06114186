//! `swap<lat-add;lat-mul;lat-div;lat-call>`: tree swapping (seed §2.4.2; SPEC §6).
//!
//! Phase: atomised → atomised. Every cluster keeps its tree's shape ([`Shape::Swap`]) but its
//! terms are reassigned to the leaf slots so that the latest-ready terms sit nearest the root,
//! sign-aware (signs are carried as `zero-removal` does; a `+`/`−` pair becomes a `sub` in the
//! right order, so no zero is needed); in products any order is allowed. Ready times are
//! exact because clusters are rebuilt in body (topological) order. With one latency per cluster
//! this assignment minimises the cluster's ready time over its shape's assignments, so the
//! critical path never grows.
//!
//! Contract: as `zero-removal`'s, except that outputs change by reassociation rounding.
//! Cost: O(values + operands + Σ k log k) over clusters of k terms.

use super::zero_removal::{ClusterRewrite, LATENCY_PARAMS};
use super::Shape;
use crate::{Params, PassInfo};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "swap",
    doc: "reorder each cluster's terms so the latest-ready sit nearest the root, shape kept (seed §2.4.2)",
    params: LATENCY_PARAMS,
    build: |p: &Params| Ok(Box::new(ClusterRewrite { name: "swap", shape: Shape::Swap, lat: p.latency_override()? })),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};
