//! The latencies of the op kinds, in cycles ([`Latencies`]): what timing
//! ([`crate::analysis::timing`]), placements ([`crate::placement::PeArray`]) and targets read.
//! Also reachable as `analysis::Latencies`.

use crate::syntax::OpKind;

/// Latencies in cycles from issue to a result usable by a dependent op, including 2 cycles of
/// interconnect and memory write (SPEC §1; seed §2.2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Latencies {
    /// `add`/`sub` (default 12 = 10 + 2).
    pub add: u32,
    /// `mul` (default 7 = 5 + 2).
    pub mul: u32,
    /// `div` (default 12, on the ADD side).
    pub div: u32,
    /// `call` (`sqrt`, callbacks; default 12).
    pub call: u32,
}

impl Default for Latencies {
    fn default() -> Self {
        Latencies { add: 12, mul: 7, div: 12, call: 12 }
    }
}

impl Latencies {
    /// Latency of an op kind, in cycles.
    pub fn of(&self, k: OpKind) -> u32 {
        match k {
            OpKind::Add | OpKind::Sub => self.add,
            OpKind::Mul => self.mul,
            OpKind::Div => self.div,
            OpKind::Call => self.call,
        }
    }
}
