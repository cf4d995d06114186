//! Test support for robovec (issue 11: oracles and generators out of the production library).
//!
//! - [`copies`]: independent copies of a Robotran Matlab function (the scale benchmark's input);
//! - [`dag_gen`]: synthetic Robotran-like atomised DAGs of a chosen size (tests and benchmarks);
//! - [`expr_gen`]: random parsed-phase expression DAGs (property tests, fuzzing);
//! - [`exact`]: exact minimum-makespan schedules of small DAGs (branch and bound), the oracle the
//!   placer's gap is measured against;
//! - [`numeric_check`]: the numeric property every pipeline must keep (property tests, fuzzing).
//!
//! Every pseudo-random draw comes from the workspace's one generator,
//! [`robovec_ir::rng::SplitMix64`]. This crate is a dev-dependency only (`publish = false`);
//! `robovec-passes` lists it as one for its own unit tests, a cycle Cargo allows for
//! dev-dependencies (this crate's types are `robovec_ir` ones, so they line up).
#![deny(missing_docs)]

pub mod copies;
pub mod dag_gen;
pub mod exact;
pub mod expr_gen;
pub mod numeric_check;
