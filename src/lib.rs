//! robovec: the driver library behind `robovec-opt` (front ends, command line, reports).
//!
//! The IR lives in `robovec-ir`, the passes in `robovec-passes`; this crate reads Robotran
//! files (C, Matlab, Python) into IR modules and runs pipelines on them.

pub mod front;
