//! robovec's SSA IR for Robotran equations of motion.
//!
//! # Model
//! A [`Module`] holds the [`Function`]s read from one file (one per Robotran function:
//! `dirdyna`, `invdyna`, `cons_hJ`, `sensor_3`, …). A function has:
//! - **inputs**: values known before the equations run — joint coordinates `q[i] qd[i] qdd[i]`,
//!   model parameters `dpt[k][j] l[k][b] m[b] In[k][b] g[k] frc[k][b] …`, `tsim` (SPEC §1–§2);
//! - a **body** of definitions in order: trig initial variables (`%C4 = cos %q[4]`, not
//!   operations), binary operations (`add sub mul div`), calls (the [`intrinsic`]s `sqrt`, `fma`, `fms`,
//!   `fnma`, and opaque user callbacks),
//!   and — in the parsed phase only — nested expressions (one Robotran equation each);
//! - **outputs**: named results (`M[1][2]`, `c[3]`, `Qq[1]`, `sens.P[1]`), each a value or a
//!   constant.
//!
//! - **states** ([`Function::states`], default 1): how many independent states one evaluation
//!   computes. `interleave<states=K>` copies every input, value and output of a function K
//!   times for throughput (issue 49 item 3); state 0 keeps every name, state `k ≥ 1`'s names
//!   carry the suffix `#k` (`%q[4]#2`, `output Qq[1]#2`; [`state_name`], [`split_state`]),
//!   which no front end nor pass writes otherwise. The text form prints `states K` after
//!   `equations N` when K > 1; the verifier rejects `states 0`. The input domain gives a
//!   suffixed input its base name's range ([`domain::Domain::get`]).
//!
//! # SSA rules
//! Every value has one definition and a name unique in its function (Robotran names are kept;
//! values made by passes get names derived from the value they serve, `AF24.1`). A value is
//! read only after its definition; the body order is a topological order. There is no control
//! flow: a function is one straight-line block.
//!
//! # Phases ([`Phase`])
//! - `parsed`: any definition form, including nested expressions (`%x = -%a*%b + %c`).
//! - `atomised`: every body value is `sin`/`cos` of an input, one binary op or one call on
//!   operands (inputs, constants, earlier values) — the seed's eq. 2.2 form (seed §2.1).
//!
//! The [`verifier`] checks these rules; [`text`] reads and writes the `.rvir` form;
//! [`interp`] evaluates any function in `f64` or `f32`; [`analysis`] holds the dependence
//! graph and ASAP/ALAP timing; [`numerics`] holds the extended-precision reference and the
//! bits-of-error metric (SPEC §6); [`rng`] is the one pseudo-random generator.
#![deny(missing_docs)]

pub mod analysis;
pub mod count;
pub mod diagnostic;
pub mod domain;
pub mod entities;
pub mod float;
pub mod format;
pub mod function;
pub mod interp;
pub mod interval;
pub mod intrinsic;
pub mod latency;
pub mod machine;
pub mod numerics;
pub mod placement;
pub mod rng;
pub mod span;
pub mod syntax;
mod syntax_impl;
pub mod text;
pub mod time_limit;
pub mod transform;
pub mod verifier;

pub use count::OpCounts;
pub use diagnostic::SourceError;
pub use entities::Value;
pub use function::{split_state, state_name, Function, Module};
pub use interval::Interval;
pub use intrinsic::Intrinsic;
pub use span::Span;
pub use syntax::*;
