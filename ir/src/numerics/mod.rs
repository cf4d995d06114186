//! Numerical honesty (SPEC §6): an extended-precision reference for any function and
//! Herbie's bits-of-error metric.
//!
//! - [`tape`]: a function (either phase) flattened into single steps in the interpreter's
//!   operation order; evaluates in `f32`, `f64` or double-double without per-sample
//!   allocation, bit for bit like [`crate::interp`].
//! - [`dd`]: double-double arithmetic (≈ 106 bits), the fast reference.
//! - [`big`]: astro-float at ≥ 256 bits, the certified reference.
//! - [`reference`](mod@reference): the correctly rounded binary32/binary64 value of every output's exact
//!   value, certified by a running error bound; double-double first, 256 then 1024 bits where
//!   the bound does not prove the double-double rounding right.
//! - [`bits`]: bits of error, `log2(1 + ordinal distance)` (Herbie).
//! - [`budget`]: the rigorous `γ_K·M` error budget of `+ − ×` functions (Higham ch. 3).
//!
//! "Exact" means: the real-number value of the IR's expression on the given `f64` inputs, with
//! `sin`/`cos`/`sqrt` and the fused multiply-adds exact and user callbacks replaced by the interpreter's stand-in (a linear
//! form with exact weights) evaluated exactly.

pub mod big;
pub mod bits;
pub mod budget;
pub mod dd;
pub mod reference;
pub mod tape;

pub use bits::{bits_f32, bits_f64};
pub use dd::DD;
pub use reference::{Enclosure, RefValue, Reference};
pub use tape::Tape;
