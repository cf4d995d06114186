//! The machine program: a placed function lowered once into what the seed's architecture
//! executes cycle by cycle (seed ch. 1 §1.1–§1.3, §2.3; SPEC §5) — per PE the instruction
//! stream, per buffer its store/read instructions, per PE memory the crossbar selection, the
//! output capture, the initial contents of every memory and the output map. `sim` executes it,
//! `codegen<fpga>` encodes it (`robovec_machine::encode`), the verifier checks it
//! ([`crate::verifier::machine`]). The types live here, next to [`crate::placement`], so that
//! the verifier can see them; the lowering, the executor and the encoding are the machine's,
//! in the `robovec-machine` crate.
//!
//! # Why a placement and a machine program
//! [`crate::placement::Placement`] (with [`PeArray`], the PE array it is made for) is the *decision* a placer makes, at the
//! level of values: which PE issues each op when, which value goes to which address of which
//! memory. It is part of the textual IR (`placement { … }` in `.rvir`), small, and checkable
//! without time order (the placed verifier check). The machine program is *derived* from it
//! and holds no value: per PE slot and per cycle the addresses read and written, the crossbar
//! selects, the buffer and output-capture instructions — exactly the words of the FPGA images.
//! It is never printed in `.rvir` (it is recomputed from the placement by
//! `robovec_machine::program::lower`), so the split is: `placement.rs` = what the user or the
//! placer decides and the text format carries; `machine` = the one lowering every consumer
//! executes or encodes.
//!
//! # Timing (the contract of [`crate::placement`])
//! An op issued at cycle `t` on PE slot `s` with latency `L` has its result **arrive** at
//! `t + L` on `s`'s result bus: in that cycle it may be written into any PE memory (crossbar
//! source [`Source::Result`]`(s)`), enter `s`'s buffer ([`BufferOp::store`]) and be captured into
//! `s`'s output memory ([`Step::capture`]). Within a cycle the hardware **writes before it
//! reads** (the seed's double-pumped M10K): in cycle `c`, in this order,
//! 1. results arriving at `c` are stored in buffers and captured in output memories;
//! 2. each buffer is read at its [`BufferOp::read`] address (a word stored in step 1 is
//!    readable now);
//! 3. each PE memory takes its writes ([`Step::writes`], one per write port);
//! 4. each PE issues its instruction, reading its operands from its own memory (a word written
//!    in step 3 is readable now).
//!
//! Steps cover cycles `0..=cycles` (`cycles` = the largest arrival, 0 without ops); a lone add
//! takes 12 cycles on the default latencies.
//!
//! # Ops the hardware has
//! The FPGA has an add/sub unit on ADD PEs and a multiplier on MULTI PEs only. The machine
//! program also carries `div` and `call` (on ADD PEs, as the machine model allows) so that
//! `sim` can execute every placement; the image encoding (`robovec_machine::encode`) rejects them
//! with `EncodeError::NoUnit` (so `codegen<fpga>` reports them), and so it rejects a step
//! with more than two writes or an address wider than the layout's fields.
//!
//! # Data words
//! A [`Word`] says what a memory word holds (an input, a trig value of an input, a constant),
//! not its bits: the bits are the device's (binary32 on the seed's FPGA:
//! `robovec_machine::encode::word_binary32`), so no number format lives here.
//!
//! The image encoding is documented bit by bit in `robovec_machine::encode`.

use crate::placement::{Pe, PeArray};
use crate::syntax::{Callee, Operand, TrigFn};
use crate::Value;
use smallvec::SmallVec;

/// An instruction's read addresses, inline up to two (the binary ops; a call with more spills
/// to the heap).
pub type ReadAddrs = SmallVec<[u32; 2]>;

/// A step's PE-memory writes, inline up to two (the seed's two write ports; more ports spill to
/// the heap).
pub type StepWrites = SmallVec<[MemWrite; 2]>;

/// What a memory word holds: a value of the function or a constant, by its `f64` bits (`0.0`
/// and `-0.0` differ). The one memory-word key of the placer, the lowering and the verifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Held {
    /// An input, trig initial variable or op result.
    Value(Value),
    /// A constant, by `f64::to_bits`.
    Const(u64),
}

impl Held {
    /// The key of an operand.
    pub fn of(o: &Operand) -> Held {
        match o {
            Operand::Value(v) => Held::Value(*v),
            Operand::Const(c) => Held::Const(c.to_bits()),
        }
    }
}

/// Initial contents of one word of a PE memory or output memory (loaded before cycle 0).
#[derive(Clone, Debug, PartialEq)]
pub enum Word {
    /// The input of this canonical name (SPEC §2), supplied at run time.
    Input(String),
    /// `sin`/`cos` of the named input, computed by the host in the run's precision.
    Trig(TrigFn, String),
    /// A constant (its binary32 rounding in the images).
    Const(f64),
}

/// The operation an instruction issues. `Add`/`Sub` run on ADD PEs, `Mul` and `Mac` on MULTI PEs; `Div`
/// and `Call` (ADD PEs) exist in the machine model for `sim` but not on the FPGA.
#[derive(Clone, Debug, PartialEq)]
pub enum MachineOp {
    /// `a + b` (ADD PE, sub bit 0).
    Add,
    /// `a − b` (ADD PE, sub bit 1).
    Sub,
    /// `a · b` (MULTI PE).
    Mul,
    /// `a / b` (ADD PE; no FPGA unit).
    Div,
    /// A call (ADD PE; no FPGA unit), reading all its operands in its issue cycle.
    Call(Box<Callee>),
    /// A fused multiply-add in fixed point (`fma`, `fms`, `fnma`; MULTI PE, issue 49): the
    /// product of the first two operands plus or minus the third, all three read in the issue
    /// cycle, rounded once ([`FixShifts::apply_fused`]); the MULTI latency.
    Mac(Box<Callee>),
}

/// One instruction: the op issued this cycle and the addresses of its operands in the issuing
/// PE's memory, in operand order (two for binary ops; a call reads as many as it has).
#[derive(Clone, Debug, PartialEq)]
pub struct Instr {
    /// The op.
    pub op: MachineOp,
    /// Read addresses (words of this PE's memory).
    pub reads: ReadAddrs,
}

/// Where a PE-memory write takes its data (the crossbar select).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Source {
    /// The result arriving now from PE slot `s` (a direct write).
    Result(usize),
    /// The word read now from PE slot `s`'s buffer (an indirect write).
    Buffer(usize),
}

/// One write into this PE's memory in one cycle, on one write port.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemWrite {
    /// Address written.
    pub addr: u32,
    /// Crossbar source.
    pub src: Source,
}

/// The buffer memory's instruction in one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BufferOp {
    /// Store the result arriving now on this PE at this buffer address.
    pub store: Option<u32>,
    /// Read this buffer address now (the crossbar source [`Source::Buffer`] of this PE).
    pub read: Option<u32>,
}

/// What one PE (its issue port, PE memory, buffer and output memory) does in one cycle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Step {
    /// The instruction issued, if any.
    pub issue: Option<Instr>,
    /// Writes into this PE's memory, in write-port order (at most `arch.writes`).
    pub writes: StepWrites,
    /// The buffer's instruction.
    pub buffer: BufferOp,
    /// Capture the result arriving now on this PE at this output-memory address.
    pub capture: Option<u32>,
}

/// The program of one PE slot.
#[derive(Clone, Debug, PartialEq)]
pub struct PeProgram {
    /// The PE ([`Pe::slot`] order: ADD PEs first).
    pub pe: Pe,
    /// Initial contents of the PE memory by address (`pe_words` entries; `None`: not loaded).
    pub init: Vec<Option<Word>>,
    /// Initial contents of the output memory by address (`output_words` entries): outputs that
    /// are inputs, trig values or constants; `None` for captured words.
    pub output_init: Vec<Option<Word>>,
    /// One step per cycle `0..=cycles`.
    pub steps: Vec<Step>,
}

/// Where an output is read after the run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutputLoc {
    /// Output name (SPEC §2).
    pub name: String,
    /// PE slot whose output memory holds it.
    pub slot: usize,
    /// Output-memory address.
    pub addr: u32,
}

/// The shifts of one op on a fixed-point PE (issue 49): the op is computed exactly on its
/// operands' integers `ka`, `kb` (words of values `k · 2^-f`), aligned by `align` bits, then
/// rounded by `shift` bits to the result's format ([`crate::format::IntegerOp`]: ADD PE
/// `K = (ka << la) ± (kb << lb)` with one of `la`, `lb` zero; MULTI PE `K = ka · kb`; then
/// `(K + 2^(shift−1)) >> shift` for `shift > 0`, `K << −shift` otherwise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FixShifts {
    /// Bits the aligned operand is shifted left (0..=62).
    pub align: u8,
    /// The aligned operand is `b` (else `a`).
    pub align_b: bool,
    /// Bits the exact result's fraction exceeds the result's (−62..=62).
    pub shift: i8,
}

impl FixShifts {
    /// Bits of [`FixShifts::word`].
    pub const BITS: u32 = 14;

    /// The shift word of the design's shift memory: `[0,6)` align, bit 6 `align_b`, `[7,14)`
    /// shift in two's complement.
    pub fn word(&self) -> u64 {
        u64::from(self.align & 63) | (u64::from(self.align_b) << 6) | ((u64::from(self.shift as u8) & 127) << 7)
    }

    /// The shifts of a shift word ([`FixShifts::word`]'s inverse on its 14 bits).
    pub fn from_word(w: u64) -> FixShifts {
        let s = ((w >> 7) & 127) as i16;
        let shift = (if s >= 64 { s - 128 } else { s }) as i8;
        FixShifts { align: (w & 63) as u8, align_b: (w >> 6) & 1 == 1, shift }
    }

    /// The rounded result of the exact intermediate `k` (exact in `i128`).
    pub fn round(&self, k: i128) -> i128 {
        match self.shift {
            s if s > 0 => (k + (1i128 << (s - 1))) >> s,
            s => k << -s,
        }
    }

    /// What a fixed-point PE computes for `op` on the operands' integers `a`, `b`: the exact
    /// `(a << la) ± (b << lb)` or `a · b`, then [`FixShifts::round`]; `None` for an op no
    /// fixed-point unit has (`div`, `call`). The executor and the units' tests use it.
    pub fn apply(&self, op: &MachineOp, a: i64, b: i64) -> Option<i128> {
        let (a, b) = (i128::from(a), i128::from(b));
        let (xa, xb) = if self.align_b { (a, b << self.align) } else { (a << self.align, b) };
        let k = match op {
            MachineOp::Add => xa + xb,
            MachineOp::Sub => xa - xb,
            MachineOp::Mul => a * b,
            MachineOp::Div | MachineOp::Call(_) | MachineOp::Mac(_) => return None,
        };
        Some(self.round(k))
    }

    /// What a fixed-point MULTI PE computes for a fused multiply-add on the operands' integers
    /// `a`, `b`, `c`: the exact `±(a·b << lp) ± (c << lc)` (`align_b`: the addend `c` is
    /// shifted, else the product), then [`FixShifts::round`]; `negate_product` for `fnma`,
    /// `negate_addend` for `fms` ([`crate::format::integer_op`]'s terms, so `-eval` computes the
    /// same integer).
    pub fn apply_fused(&self, negate_product: bool, negate_addend: bool, a: i64, b: i64, c: i64) -> i128 {
        let p = i128::from(a) * i128::from(b);
        let c = i128::from(c);
        let (xp, xc) = if self.align_b { (p, c << self.align) } else { (p << self.align, c) };
        let xp = if negate_product { -xp } else { xp };
        let xc = if negate_addend { -xc } else { xc };
        self.round(xp + xc)
    }
}

/// The fixed-point side of a program whose PEs compute in fixed point (issue 49): a function
/// whose every op is an integer op of `fix<w,f>` values with `w ≤ 32`. Words are the values'
/// integers `k` (`word_bits`-bit two's complement); the fractions say what each loaded word and
/// output means (`k · 2^-f`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixedProgram {
    /// Bits of the PEs' data word: the widest `fix<w,f>` of the function, or more when a
    /// constant's word ([`crate::format::fix_constant`]) needs more (≤ 32; 0 in a default
    /// record, which nothing lowers to).
    pub word_bits: u32,
    /// Per PE slot, per cycle `0..=cycles`: the shifts of the op issued there.
    pub shifts: Vec<Vec<Option<FixShifts>>>,
    /// Fractional bits of each input's format, by canonical name.
    pub inputs: std::collections::BTreeMap<String, i32>,
    /// Fractional bits of each trig value's format, by (`sin`/`cos`, input name).
    pub trig: std::collections::BTreeMap<(TrigFn, String), i32>,
    /// Fractional bits of each output's format, in [`MachineProgram::outputs`] order.
    pub outputs: Vec<i32>,
}

impl FixedProgram {
    /// The fractional bits of a loaded word (a constant: [`crate::format::fix_constant`]'s);
    /// `None` for an input or trig value without a fixed-point format, or a constant no 32-bit
    /// word holds.
    pub fn fraction(&self, w: &Word) -> Option<i32> {
        match w {
            Word::Input(n) => self.inputs.get(n).copied(),
            Word::Trig(t, n) => self.trig.get(&(*t, n.clone())).copied(),
            Word::Const(c) => crate::format::fix_constant(*c).map(|(_, f)| f),
        }
    }
}

/// A lowered function: what the machine executes.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineProgram {
    /// PE counts, latencies (cycles), write ports, buffers.
    pub arch: PeArray,
    /// Last cycle with an event: the largest arrival (0 without ops), or a later write from a
    /// buffer; steps cover `0..=cycles`.
    pub cycles: u32,
    /// Words of each PE memory (addresses `0..pe_words`), by slot.
    pub pe_words: Vec<u32>,
    /// Words of each buffer, by slot.
    pub buffer_words: Vec<u32>,
    /// Words of each output memory, by slot.
    pub output_words: Vec<u32>,
    /// Programs by slot.
    pub pes: Vec<PeProgram>,
    /// Every output of the function, in `Function::outputs` order.
    pub outputs: Vec<OutputLoc>,
    /// Provenance (not encoded): the `(slot, cycle)` where each op issues, by
    /// `Value::index()` (`None` for non-ops). Lets the verifier name values.
    pub issue_of: Vec<Option<(usize, u32)>>,
    /// Fixed-point PEs: the shifts of every op and the fractions of the words (`None`: binary32
    /// PEs, the seed's).
    pub fixed: Option<FixedProgram>,
}

impl MachineProgram {
    /// Number of PEs (ADD then MULTI).
    pub fn n_pe(&self) -> usize {
        self.pes.len()
    }

    /// The latency of an op on this program's architecture, cycles.
    pub fn latency(&self, op: &MachineOp) -> u32 {
        let l = &self.arch.lat;
        match op {
            MachineOp::Add | MachineOp::Sub => l.add,
            MachineOp::Mul | MachineOp::Mac(_) => l.mul,
            MachineOp::Div => l.div,
            MachineOp::Call(_) => l.call,
        }
    }

    /// Direct writes (crossbar source a result) in the whole program.
    pub fn writes_direct(&self) -> u32 {
        self.count_writes(|s| matches!(s, Source::Result(_)))
    }

    /// Indirect writes (crossbar source a buffer read) in the whole program.
    pub fn writes_indirect(&self) -> u32 {
        self.count_writes(|s| matches!(s, Source::Buffer(_)))
    }

    fn count_writes(&self, pick: impl Fn(Source) -> bool) -> u32 {
        self.pes.iter().flat_map(|p| &p.steps).flat_map(|s| &s.writes).filter(|w| pick(w.src)).count() as u32
    }
}
