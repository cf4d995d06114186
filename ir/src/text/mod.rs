//! The `.rvir` text form: logos lexer, lalrpop grammar, name resolution, printer.
//!
//! ```text
//! func @invdyna {
//!   phase atomised
//!   equations 2
//!   input %q[2]
//!   input %g[3]
//!   %S2 = sin %q[2]
//!   %AF12 = mul %g[3], %S2 {asap=1, alap=1, asap_cycle=7, alap_cycle=7, mobility=0}
//!   output Qq[1] = %AF12
//! }
//! ```
//! An interleaved function (`interleave<states=K>`) says `states K` after `equations N`, and
//! its state copies' names end in `#k` (`%q[2]#1`, `output Qq[1]#1`): the lexer accepts one
//! such suffix at the end of a value or output name.
//! Parsed-phase definitions are infix expressions: `%x = -%a*%b + (%c - 2.0)`; a unary minus
//! stands at the start of a sum and covers the product term after it (SPEC §3).

pub mod ast;
pub mod error;
pub mod lexer;
pub mod parser;
pub mod placement;
pub mod printer;

pub use error::ParseError;
pub use parser::parse;

/// Prints a constant so that it reads back to the same bits (Rust's shortest round-trip form):
/// the one spelling of constants in the body ([`printer`]) and in placement lines
/// ([`placement`]).
///
/// # Errors
/// What `out` returns.
pub fn write_const(out: &mut impl std::fmt::Write, x: f64) -> std::fmt::Result {
    write!(out, "{x:?}")
}
