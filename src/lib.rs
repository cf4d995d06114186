//! robovec: the driver library behind `robovec-opt` and `robovec-gen` — the command line and
//! the outputs: load → passes → write.
//!
//! The IR lives in `robovec-ir`, the passes and the pass manager in `robovec-passes`, the front
//! ends in `robovec-front` and the symbolic generator (robot model, topology families, writers,
//! the study's cases) in `robovec-dynamics`. This crate parses the command line ([`cli`],
//! [`options`]), checks every option before any work ([`preflight`]), loads the input through
//! the front-end registry and runs the pipeline ([`driver::run`]) over the input domain ([`ranges`]), and writes IR, reports
//! ([`report_dir`]), evaluations ([`eval`]) and diagnostics ([`diagnostics`]) under one output
//! policy ([`output`]), with progress bars on a terminal ([`progress_bars`]). `robovec-gen`'s
//! commands are here too: one robot written as URDF or Robotran C ([`export`]) and the study's
//! folder ([`study`]). The library crates never import this one.

pub mod allocator;
pub mod cli;
pub mod cpu_time;
pub mod diagnostics;
pub mod driver;
pub mod eval;
pub mod export;
pub mod options;
pub mod output;
pub mod preflight;
pub mod progress_bars;
pub mod ranges;
pub mod report_dir;
pub mod study;
