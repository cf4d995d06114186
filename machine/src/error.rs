//! What the lowering ([`crate::program`]) and the executor ([`crate::exec`]) reject — and so
//! `sim`, which executes what it lowers: one [`MachineError`] naming when, where and which
//! value. `sim` re-exports these types as `SimError` and `SimErrorKind`.

use robovec_ir::placement::Pe;
use robovec_ir::Span;

/// When an error happened in the simulated run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum When {
    /// While loading initial data, before cycle 0.
    Load,
    /// In this cycle.
    Cycle(u32),
    /// After the last cycle (outputs).
    End,
}

impl std::fmt::Display for When {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            When::Load => write!(f, "before cycle 0"),
            When::Cycle(c) => write!(f, "cycle {c}"),
            When::End => write!(f, "at the end"),
        }
    }
}

/// The rule a placement breaks (one per check of the lowering), or what `sim` found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MachineErrorKind {
    /// The function or placement cannot be simulated at all (vector sizes, unknown values,
    /// a zero latency, parsed-phase expressions).
    Malformed,
    /// `verify_placement` on a function without a placement.
    NoPlacement,
    /// A PE index beyond the architecture's `n_add`/`n_mul`.
    NoSuchPe,
    /// An op issued on a PE of the wrong type (`mul` on an ADD PE…).
    WrongPeType,
    /// Two ops issued on one PE in one cycle.
    PeBusy,
    /// An op of the function has no issue.
    MissingIssue,
    /// An issue or a result write of a value that is not an op.
    NotAnOp,
    /// A load of a value that is not initial data (an op result).
    BadLoad,
    /// An op reads a value its PE memory does not hold in that cycle (never written, written
    /// later, or overwritten).
    ReadMissing,
    /// An op issued before one of its operands arrives.
    BeforeArrival,
    /// More than `arch.writes` writes into one PE memory in one cycle.
    WritePorts,
    /// More than one distinct buffer read of one buffer in one cycle.
    BufferReads,
    /// One value entering its producer's buffer at two addresses.
    BufferEntries,
    /// An indirect write on an architecture without buffers.
    NoBuffer,
    /// A direct write in a cycle other than the value's arrival.
    DirectWriteCycle,
    /// A buffer read before the value arrives in the buffer.
    BufferReadBeforeArrival,
    /// A memory or buffer address at or beyond the reported `pe_words`/`buffer_words`.
    AddressOutOfRange,
    /// An address written while the value it holds still has a read in this or a later cycle,
    /// or written twice in one cycle.
    AddressReused,
    /// An output whose value was never computed. Kept for `sim`'s callers; the lowering no
    /// longer produces it (an unissued op is [`MachineErrorKind::MissingIssue`] first, and
    /// every output of an issued op is captured at its arrival).
    OutputUnavailable,
    /// A simulated output differs from the interpreter (`sim`'s `verify_placement`).
    Mismatch,
    /// Two results arrive on one PE in one cycle (ops of different latencies, `div`/`call`
    /// against `add`): a PE has one result bus, so the crossbar, buffer and output capture
    /// could not tell them apart.
    ResultCollision,
    /// The lowered program fails the verifier's lowered check (a lowering bug), or an
    /// executed program is inconsistent (a word read before anything was written there).
    Unverified,
    /// The function's numeric formats fit no kind of PE array (issue 49: binary32 PEs without
    /// numeric formats, fixed-point PEs when every value is a `fix<w ≤ 32, f>` integer op;
    /// [`crate::program::fixed::pe_kind`]).
    Formats,
    /// The caller's `stop` hook returned true (its time limit, `-time-limit`): the lowering
    /// ([`crate::program::lower_measured_until`]) or the execution
    /// ([`crate::exec::execute_until`]) gave up, nothing is returned. Says nothing about the
    /// placement. Only a `stop` hook returning true produces it ([`MachineError::stopped`]).
    Stopped,
}

/// A placement the lowering rejects (or a `sim` mismatch): the first broken rule, with the cycle, the PE and the
/// value involved when there are such. Displays as `cycle 7, add0, %x: message`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}", self.render())]
pub struct MachineError {
    /// The broken rule.
    pub kind: MachineErrorKind,
    /// When, if the error has a time.
    pub when: Option<When>,
    /// The PE (memory, buffer or issuing PE) involved.
    pub pe: Option<Pe>,
    /// The value involved, as printed (`%AF24`, a constant `2.0`, or an output name).
    pub value: Option<String>,
    /// What is wrong, lower case.
    pub message: String,
    /// The offending `.rvir` line (an `issue`, `load` or `write` line, a definition or an
    /// output) when the placement was read from text; `Span::DUMMY` otherwise.
    pub span: Span,
}

impl MachineError {
    /// An error of `kind` saying `message`, without time, PE, value or span (add them with
    /// [`MachineError::at`], [`MachineError::on`], [`MachineError::of`], [`MachineError::src`]).
    pub fn new(kind: MachineErrorKind, message: impl Into<String>) -> MachineError {
        MachineError { kind, when: None, pe: None, value: None, message: message.into(), span: Span::DUMMY }
    }

    /// The error of a lowering or execution its caller's `stop` hook interrupted
    /// ([`MachineErrorKind::Stopped`]): `stopped: time limit`.
    pub fn stopped() -> MachineError {
        MachineError::new(MachineErrorKind::Stopped, "stopped: time limit")
    }

    /// This error at `when`.
    pub fn at(mut self, when: When) -> MachineError {
        self.when = Some(when);
        self
    }

    /// This error on PE `pe`.
    pub fn on(mut self, pe: Pe) -> MachineError {
        self.pe = Some(pe);
        self
    }

    /// This error about `value` (as printed: `%AF24`, a constant `2.0`, or an output name).
    pub fn of(mut self, value: impl Into<String>) -> MachineError {
        self.value = Some(value.into());
        self
    }

    /// This error at `.rvir` span `span`.
    pub fn src(mut self, span: Span) -> MachineError {
        self.span = span;
        self
    }

    fn render(&self) -> String {
        let mut parts: Vec<String> = Vec::new();
        if let Some(w) = self.when {
            parts.push(w.to_string());
        }
        if let Some(p) = self.pe {
            parts.push(p.to_string());
        }
        if let Some(v) = &self.value {
            parts.push(v.clone());
        }
        if parts.is_empty() {
            self.message.clone()
        } else {
            format!("{}: {}", parts.join(", "), self.message)
        }
    }
}
