//! robovec: the driver library behind `robovec-opt` — front ends, command line, reports.
//!
//! The IR lives in `robovec-ir`, the passes in `robovec-passes`; this crate reads Robotran
//! files (C, Matlab, Python) into IR modules ([`front`]), runs pipelines on them
//! ([`driver::run`]) and writes reports and evaluations ([`eval`]).

pub mod cli;
pub mod diagnostics;
pub mod driver;
pub mod eval;
pub mod front;
pub mod gen;
pub mod options;
pub mod output;
pub mod preflight;
pub mod progress;
pub mod report_dir;
pub mod study;
