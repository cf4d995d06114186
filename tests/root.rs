//! The single integration-test binary (naga's `tests/root.rs` layout).
//!
//! Tests that need the Robotran corpus read it from `../shared/corpus/robotran` and fail — not
//! skip — when it is missing.

mod common;

mod accuracy;
mod accuracy_domain;
mod architecture;
mod artifacts;
mod bounds;
mod c_names;
mod cli;
mod codegen_c;
mod codegen_pinocchio;
mod corpus;
mod cse;
mod depth_bound;
mod diagnostics;
mod diff;
mod eqsat;
mod error_bound;
mod error_reference;
mod exact_gap;
mod example;
mod filetests;
mod formats;
mod fpga;
mod inline_specialize;
mod interleave;
mod numerics;
#[cfg(unix)]
mod outputs;
mod params;
mod passes_reference;
mod pinocchio;
mod placement;
mod placement_verify;
mod precision;
mod props;
mod range;
mod recurrence;
mod report_dir;
mod robotran_c;
mod rotate_3m;
mod roundtrip;
mod schedule_cpu;
mod study;
mod target;
mod time_limit_load;
mod tree_height;
mod urdf;
