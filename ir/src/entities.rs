//! Entity references: `u32` newtypes indexing a function's arenas (as in Cranelift's
//! `ir/entities.rs`: small, `Copy`, no lifetimes, cheap side tables).
//!
//! A [`Value`] prints as its index (`v12`) in debug output; the text form (`.rvir`) names values
//! by their Robotran names (`%AlF15`), which the function stores beside each value.

/// An SSA value of one [`crate::Function`]: an input, a trig initial variable or a definition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Value(u32);

impl Value {
    /// The value with index `n`; for use by the parser and by passes that build functions.
    pub fn with_number(n: u32) -> Value {
        Value(n)
    }

    /// The value's index into its function's arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "v{}", self.0)
    }
}
