//! Analyses shared by passes: the dependence graph and ready times (ASAP/ALAP).
//!
//! Analyses are derived data: they are computed from a function on demand and never stored in
//! it, except the timing attributes that the `asap-alap` pass writes on purpose (and that any
//! pass changing the function clears with [`crate::Function::clear_timing`]).

pub mod dep_graph;
pub mod timing;

pub use crate::latency::Latencies;
pub use dep_graph::DepGraph;
pub use timing::{annotate_timing, compute_timing, TimingSummary};
