//! robovec's machine: the seed's FPGA architecture (seed ch. 1 §1.1–§1.3 and §2.3; SPEC §1, §4
//! and §5) — `N` ADD and `N` MULTI pipelined processing elements, each with its PE memory,
//! buffer memory and output memory, joined by a crossbar, on a DE10-Nano (Cyclone V) — as one
//! crate, the home of everything that knows the hardware (as Cranelift's `isa/` or naga's
//! `back/`).
//!
//! # What is where
//! - [`target`]: the device description ([`target::Target`]: latencies, write ports, memory
//!   sizes, capacities, per-unit costs, clock; the built-in `de10-nano` and `ecp5-85f` and JSON
//!   target files of `-target=`), its analytic resource estimate ([`target::Target::estimate`]), the one M10K
//!   model ([`target::m10k_blocks`]) and the PE array a placement is made for
//!   ([`target::Target::pe_array`]).
//! - [`program`]: a placed function lowered into its machine program (the one lowering every
//!   consumer executes or encodes), checking every rule of the machine model; [`error`]: what
//!   it rejects.
//! - [`exec`]: the machine program executed on numbers (what `sim` runs).
//! - [`encode`]: the image words of a machine program, bit by bit, and their decoding.
//! - [`design`]: the FPGA design of a placed function (memory images, the generated Verilog
//!   top and testbench, the fixed `hdl/` library, the `simulate` script); [`resources`]: its
//!   ALM / M10K / DSP estimate (Yosys or analytic); [`pnr`]: its place and route on an ECP5
//!   with the open flow (measured LUT4, EBR, MULT18X18D and Fmax, and a bitstream); [`emit`]: its
//!   files, as `codegen<fpga>` writes them.
//!
//! What stays in the IR crate: the placement ([`robovec_ir::placement`], with the PE array
//! [`robovec_ir::placement::PeArray`]) and the machine-program types
//! ([`robovec_ir::machine`]), which the verifier checks and the passes read. The passes
//! (`place`, `sim`, `sweep`, `codegen<fpga>`) live in `robovec-passes` and call into this crate.
#![deny(missing_docs)]

pub mod design;
pub mod emit;
pub mod encode;
pub mod error;
pub mod exec;
pub mod pnr;
pub mod program;
pub mod resources;
pub mod target;
