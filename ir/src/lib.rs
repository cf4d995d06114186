//! robovec's SSA IR (placeholder doc, completed below).
pub mod count;
pub mod entities;
pub mod function;
pub mod interp;
pub mod span;
pub mod syntax;
pub mod text;

pub use entities::Value;
pub use function::{Function, Module, OpCounts};
pub use span::Span;
pub use syntax::*;
