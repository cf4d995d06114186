//! A placement: which processing element issues each operation in which cycle, and where every
//! value lives in every PE memory and buffer (seed ch. 1 and §2.3, SPEC §4–§5).
//!
//! # Machine model (the contract between `place`, `sim` and the report)
//! - `n_add` ADD PEs and `n_mul` MULTI PEs, fully pipelined: each issues at most one op per
//!   cycle. `add`/`sub` run on ADD PEs, `mul` on MULTI PEs, `div` and `call` on ADD PEs.
//! - An op issued at cycle `t` with latency `L` (SPEC §1: includes interconnect and write) has
//!   its result **arrive** at cycle `t + L`. Arrival is the only moment the result can be
//!   written *directly* into PE memories, and the moment it enters the producer's buffer.
//! - Every PE `p` owns a PE memory. An op issues on `p` at cycle `t` only if both operands are in
//!   `p`'s memory at `t`: loaded before cycle 0, or written at a cycle `≤ t` (a word written at
//!   cycle `c` is readable from cycle `c` on). Per cycle a PE memory takes at most `writes`
//!   writes (direct and from a buffer together) and serves the 2 reads of the op issued there.
//! - **Direct write**: at arrival cycle `a`, into any PE memory (crossbar fan-out), one write
//!   slot of that memory at `a`.
//! - **Indirect write** (only with `buffer = true`): the result is held in the producer's buffer
//!   memory from `a`; at a later cycle `b ≥ a` the buffer is read (at most one buffer read per
//!   buffer per cycle; one read may fan out to several memories) and the value is written into
//!   the target PE memory at `b`, one write slot of that memory at `b`.
//! - Initial data (inputs, trig initial variables, constants) is loaded before cycle 0 into the
//!   PE memories that read it ([`Load`]).
//! - Addresses: a word of a PE memory or buffer holds one value from its write (or load) until
//!   its last read; it may be written again only in a later cycle than that last read.
//! - **cycles** = the largest arrival cycle (0 without ops); a lone add takes 12 cycles.
//!
//! The verifier checks every rule above except word lifetimes (address reuse) whenever a
//! placement is read or left by a pass ([`crate::verifier::placement`]); the lowering into the
//! machine program (`robovec_machine::program::lower`, which `sim` executes and `codegen<fpga>`
//! encodes) checks them all.
//!
//! A placement is the placer's decision at the level of values, carried by the `.rvir` text;
//! the address- and cycle-level program the hardware runs is derived from it once, in
//! [`crate::machine`] (see there why the split is here).
//!
//! Memory sizes (`pe_words`, `buffer_words`) are the number of addresses each memory uses
//! (addresses are `0..words`), which the placer keeps equal to the largest number of words the
//! memory holds at once.

use crate::entities::Value;
use crate::latency::Latencies;
use crate::span::Span;
use crate::syntax::{OpKind, Operand};

/// A processing element: its type and index within the type (`add0`, `mul3`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Pe {
    /// ADD PE `i` (add, sub, div, call).
    Add(u32),
    /// MULTI PE `i` (mul).
    Mul(u32),
}

impl Pe {
    /// The PE type an op kind runs on.
    pub fn runs(kind: OpKind, index: u32) -> Pe {
        match kind {
            OpKind::Mul => Pe::Mul(index),
            _ => Pe::Add(index),
        }
    }

    /// True when ops of `kind` run on this PE's type.
    pub fn accepts(self, kind: OpKind) -> bool {
        matches!(
            (self, kind),
            (Pe::Mul(_), OpKind::Mul) | (Pe::Add(_), OpKind::Add | OpKind::Sub | OpKind::Div | OpKind::Call)
        )
    }

    /// Dense index over all PEs: ADD PEs `0..n_add`, then MULTI PEs.
    pub fn slot(self, n_add: u32) -> usize {
        match self {
            Pe::Add(i) => i as usize,
            Pe::Mul(i) => (n_add + i) as usize,
        }
    }
}

impl std::fmt::Display for Pe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pe::Add(i) => write!(f, "add{i}"),
            Pe::Mul(i) => write!(f, "mul{i}"),
        }
    }
}

/// The PE array a placement is made for: how many PEs of each type, their latencies, the
/// write ports of a PE memory and whether buffers exist — what the placer, the verifier, the
/// lowering and `sim` read of the machine (the `placement n_add=… n_mul=…` header of `.rvir`).
///
/// It is one view of the machine, not the device: the device (capacities, per-unit costs,
/// memory sizes, clock) is `robovec_machine::target::Target`, and `Target::pe_array(n_add, n_mul,
/// buffer)` builds the array of that device's latencies and write ports. A pass parameter
/// (`place<lat-add=…>`) may override a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PeArray {
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// Latencies, cycles.
    pub lat: Latencies,
    /// Write ports per PE memory per cycle (default 2, seed §1.1.2).
    pub writes: u32,
    /// Whether results may wait in buffer memories (indirect writes).
    pub buffer: bool,
}

impl PeArray {
    /// Number of PEs of both types.
    pub fn n_pe(&self) -> usize {
        (self.n_add + self.n_mul) as usize
    }

    /// All PEs, ADD first.
    pub fn pes(&self) -> impl Iterator<Item = Pe> + '_ {
        (0..self.n_add).map(Pe::Add).chain((0..self.n_mul).map(Pe::Mul))
    }
}

/// Where and when an op issues.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Issue {
    /// The PE.
    pub pe: Pe,
    /// Issue cycle (0-based).
    pub cycle: u32,
}

/// Initial data loaded into a PE memory before cycle 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Load {
    /// Target memory.
    pub pe: Pe,
    /// Address in it.
    pub addr: u32,
    /// An input or trig value of the function, or a constant.
    pub operand: Operand,
}

/// A write of an op's result into a PE memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Write {
    /// The op whose result is written.
    pub value: Value,
    /// Target PE memory.
    pub pe: Pe,
    /// Address in it.
    pub addr: u32,
    /// Cycle of the write into the PE memory (the arrival cycle when direct).
    pub cycle: u32,
    /// For an indirect write: the producer's buffer address (the value enters it at arrival
    /// and is read at `cycle`).
    pub buffer_addr: Option<u32>,
}

/// Source spans of a placement's lines when it was read from text (all empty when a pass made
/// it). Diagnostics only: they take no part in equality.
#[derive(Clone, Debug, Default)]
pub struct PlacementSpans {
    /// The whole `placement … { … }` block.
    pub block: Span,
    /// The `issue` line of each op, indexed by `Value::index()`.
    pub issue: Vec<Span>,
    /// The line of each load, in `Placement::loads` order.
    pub loads: Vec<Span>,
    /// The line of each write, in `Placement::writes` order.
    pub writes: Vec<Span>,
}

impl PlacementSpans {
    /// The span of `v`'s `issue` line (`Span::DUMMY` when unknown).
    pub fn issue(&self, v: Value) -> Span {
        self.issue.get(v.index()).copied().unwrap_or(Span::DUMMY)
    }

    /// The span of load `i` (`Span::DUMMY` when unknown).
    pub fn load(&self, i: usize) -> Span {
        self.loads.get(i).copied().unwrap_or(Span::DUMMY)
    }

    /// The span of write `i` (`Span::DUMMY` when unknown).
    pub fn write(&self, i: usize) -> Span {
        self.writes.get(i).copied().unwrap_or(Span::DUMMY)
    }
}

/// A complete placement of one function.
///
/// Equality compares the placement itself, never its [`PlacementSpans`].
#[derive(Clone, Debug)]
pub struct Placement {
    /// The PE array placed on.
    pub arch: PeArray,
    /// Issue of every op, indexed by `Value::index()` (`None` for non-ops).
    pub issue: Vec<Option<Issue>>,
    /// Initial data.
    pub loads: Vec<Load>,
    /// Result writes, in cycle order.
    pub writes: Vec<Write>,
    /// Words used by each PE memory, indexed by [`Pe::slot`].
    pub pe_words: Vec<u32>,
    /// Words used by each PE's buffer, indexed by [`Pe::slot`].
    pub buffer_words: Vec<u32>,
    /// Where each line was read from, for diagnostics (default when made by a pass).
    pub spans: PlacementSpans,
}

impl PartialEq for Placement {
    fn eq(&self, o: &Placement) -> bool {
        self.arch == o.arch
            && self.issue == o.issue
            && self.loads == o.loads
            && self.writes == o.writes
            && self.pe_words == o.pe_words
            && self.buffer_words == o.buffer_words
    }
}

impl Placement {
    /// The latency of an op kind on this architecture.
    pub fn latency(&self, kind: OpKind) -> u32 {
        self.arch.lat.of(kind)
    }
}
