//! The image words of a [`MachineProgram`], bit by bit, and their decoding: what the FPGA
//! back end writes into its instruction, crossbar, buffer-instruction and capture memories
//! ([`crate::design`]), and what [`robovec_ir::machine`]'s module doc calls the encoding.
//!
//! One word per PE slot per cycle `0..=cycles` in each of four images (the seed's 52-bit
//! instruction word, §1.3.1, is the default instruction layout). Fields are unsigned, LSB
//! first; unused bits are 0. With `n_pe` PEs:
//! - `aw` = address bits of a PE memory = ⌈log2 pe_words⌉ of the *target* (11 for the
//!   DE10-Nano's 2048-word M10K memories), [`bits_for`];
//! - `bw` = buffer address bits = ⌈log2 buffer_words⌉ of the target;
//! - `ow` = output-memory address bits = ⌈log2 max output words⌉ of the program;
//! - `sw` = crossbar select bits = ⌈log2(2·n_pe + 1)⌉.
//!
//! Every width is at least 1 bit (a 1-word memory still has a 1-bit address field).
//!
//! ## Instruction word (per PE, per cycle; `instr_width` bits, 52 on the DE10-Nano)
//! | bits            | field                                                      |
//! |-----------------|------------------------------------------------------------|
//! | `[0, aw)`       | read address A (first operand)                             |
//! | `[aw, 2aw)`     | read address B (second operand)                            |
//! | `[2aw, 3aw)`    | write address of port 0                                    |
//! | `[3aw, 4aw)`    | write address of port 1                                    |
//! | `4aw`           | we0: port 0 writes                                         |
//! | `4aw + 1`       | we1: port 1 writes                                         |
//! | `4aw + 2`       | issue valid                                                |
//! | `4aw + 3`       | sub: 1 = `a − b` on an ADD PE; on a MULTI PE 1 only for a multiply-add: negate the addend (`fms`) |
//! | `[4aw + 4, instr_width)` | 0 (with `aw` = 11: 48 bits used of 52)            |
//!
//! A program with a fused multiply-add ([`MachineOp::Mac`], fixed-point MULTI PEs; [`Layout::mac`])
//! has three more fields after those, and an instruction word of at least `5aw + 6` bits (61 on
//! the DE10-Nano, which widens its 52-bit word for such a program):
//!
//! | bits            | field                                                      |
//! |-----------------|------------------------------------------------------------|
//! | `[4aw + 4, 5aw + 4)` | read address C (the addend)                           |
//! | `5aw + 4`       | negate product (`fnma`)                                    |
//! | `5aw + 5`       | mac: the op is `±a·b ± c` (with sub = negate addend); 0 = `a·b` |
//!
//! so that a program without one has the same words as before. The op is implied by the PE
//! type and these bits (ADD: add/sub, MULTI: mul, or with the mac bit `fma`, `fms`, `fnma`).
//! A write port's data comes from the crossbar word of the same memory and cycle.
//!
//! ## Crossbar word (per PE memory, per cycle; `2·sw` bits)
//! `[0, sw)` select of port 0, `[sw, 2sw)` select of port 1, each: 0 = none,
//! `1..=n_pe` = the result arriving now from PE slot `s − 1`,
//! `n_pe + 1..=2·n_pe` = the word read now from the buffer of PE slot `s − n_pe − 1`.
//! A port's select is non-zero exactly when its write enable is set.
//!
//! ## Buffer instruction word (per PE, per cycle; `2·bw + 2` bits)
//! `[0, bw)` store address, `[bw, 2bw)` read address, bit `2bw` store enable (the result
//! arriving now on this PE is stored), bit `2bw + 1` read enable.
//!
//! ## Output capture word (per PE, per cycle; `ow + 1` bits)
//! `[0, ow)` output-memory address, bit `ow` enable (the result arriving now on this PE is
//! captured there).
//!
//! ## Data words
//! Initial PE-memory and output-memory contents are binary32 ([`word_binary32`]).
//!
//! [`decode`] inverts [`encode`] exactly: `decode(encode(p)) == steps of p` for every program
//! `encode` accepts; it rejects words with bits set outside their fields, a select beyond
//! `2·n_pe`, a write enable without a select (or the reverse), a sub bit on a MULTI PE without the
//! mac bit, or the mac fields on an ADD PE.

use robovec_ir::intrinsic::Intrinsic;
use robovec_ir::machine::{
    BufferOp, Instr, MachineOp, MachineProgram, MemWrite, ReadAddrs, Source, Step, StepWrites, Word,
};
use robovec_ir::TrigFn;

/// Field widths of the four image words, bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Layout {
    /// PEs (ADD then MULTI).
    pub n_pe: usize,
    /// ADD PEs (slots `0..n_add`).
    pub n_add: usize,
    /// PE-memory address bits.
    pub aw: u32,
    /// Buffer address bits.
    pub bw: u32,
    /// Output-memory address bits.
    pub ow: u32,
    /// Crossbar select bits.
    pub sw: u32,
    /// Instruction-memory word width, bits (≥ [`Layout::instr_bits`], ≤ 64).
    pub instr_width: u32,
    /// The program issues fused multiply-adds ([`MachineOp::Mac`]): the instruction word has the
    /// read address C, negate-product and mac fields after its `4aw + 4` bits (module doc).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub mac: bool,
}

/// ⌈log2 n⌉, at least 1: the address bits of an `n`-word memory.
pub fn bits_for(n: u64) -> u32 {
    if n <= 2 {
        1
    } else {
        64 - (n - 1).leading_zeros()
    }
}

impl Layout {
    /// The layout for program `p` on a target with PE memories of `pe_words` words, buffers of
    /// `buffer_words` words and `instr_width`-bit instruction words (seed §1.3.1: 2048, —, 52).
    /// A program with fused multiply-adds gets the mac fields and a word of at least their
    /// `5aw + 6` bits ([`Layout::mac`]).
    ///
    /// # Errors
    /// [`EncodeError::WordTooWide`] when the instruction word needs more than `instr_width` bits
    /// or any word more than 64.
    pub fn new(p: &MachineProgram, pe_words: u32, buffer_words: u32, instr_width: u32) -> Result<Layout, EncodeError> {
        let n_pe = p.n_pe();
        let mac =
            p.pes.iter().flat_map(|pe| &pe.steps).any(|s| matches!(s.issue, Some(Instr { op: MachineOp::Mac(_), .. })));
        let aw = bits_for(pe_words as u64);
        let l = Layout {
            n_pe,
            n_add: p.arch.n_add as usize,
            aw,
            bw: bits_for(buffer_words as u64),
            ow: bits_for(p.output_words.iter().copied().max().unwrap_or(0) as u64),
            sw: bits_for(2 * n_pe as u64 + 1),
            instr_width: if mac { instr_width.max(5 * aw + 6) } else { instr_width },
            mac,
        };
        let need = [
            ("instruction", l.instr_bits(), l.instr_width.min(64)),
            ("crossbar", l.crossbar_bits(), 64),
            ("buffer instruction", l.buffer_bits(), 64),
            ("output capture", l.capture_bits(), 64),
        ];
        for (word, bits, width) in need {
            if bits > width {
                return Err(EncodeError::WordTooWide { word, bits, width });
            }
        }
        Ok(l)
    }

    /// Used bits of an instruction word: `4aw + 4`, `5aw + 6` with the mac fields.
    pub fn instr_bits(&self) -> u32 {
        if self.mac {
            5 * self.aw + 6
        } else {
            4 * self.aw + 4
        }
    }

    /// Bits of a crossbar word: `2sw`.
    pub fn crossbar_bits(&self) -> u32 {
        2 * self.sw
    }

    /// Bits of a buffer instruction word: `2bw + 2`.
    pub fn buffer_bits(&self) -> u32 {
        2 * self.bw + 2
    }

    /// Bits of an output capture word: `ow + 1`.
    pub fn capture_bits(&self) -> u32 {
        self.ow + 1
    }
}

/// The four control images: `[slot][cycle]`, one `u64` per word (the low bits of the word's
/// width; see the module doc).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Images {
    /// Field widths.
    pub layout: Layout,
    /// Instruction memory of each PE.
    pub instr: Vec<Vec<u64>>,
    /// Crossbar memory of each PE memory.
    pub crossbar: Vec<Vec<u64>>,
    /// Buffer instruction memory of each PE.
    pub buffer: Vec<Vec<u64>>,
    /// Output capture memory of each PE.
    pub capture: Vec<Vec<u64>>,
}

/// What [`encode`]/[`Layout::new`] reject: what the FPGA's words cannot express.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EncodeError {
    /// An op with no FPGA unit (`div`, `call`, a multiply-add in a layout without the mac
    /// fields or on an ADD PE): the instruction word has only add/sub, mul and multiply-add.
    #[error("cycle {cycle}, PE slot {slot}: `{op}` has no unit on the FPGA (only add, sub, mul and, on MULTI PEs, fma, fms, fnma)")]
    NoUnit {
        /// PE slot.
        slot: usize,
        /// Issue cycle.
        cycle: u32,
        /// The op (`div` or `call @name`).
        op: String,
    },
    /// More writes into one PE memory in one cycle than the word's two ports.
    #[error(
        "cycle {cycle}, PE slot {slot}: {writes} writes into one PE memory; the instruction word has 2 write ports"
    )]
    TooManyWrites {
        /// PE slot.
        slot: usize,
        /// Cycle.
        cycle: u32,
        /// Writes in that cycle.
        writes: usize,
    },
    /// An instruction with other than two read addresses (three for a multiply-add).
    #[error("cycle {cycle}, PE slot {slot}: an instruction reads {reads} operands; the word has 2 read addresses (3 for a multiply-add)")]
    Reads {
        /// PE slot.
        slot: usize,
        /// Cycle.
        cycle: u32,
        /// Read addresses of the instruction.
        reads: usize,
    },
    /// An address or slot that does not fit its field.
    #[error("cycle {cycle}, PE slot {slot}: {what} {value} does not fit in {bits} bits")]
    FieldOverflow {
        /// PE slot.
        slot: usize,
        /// Cycle.
        cycle: u32,
        /// The field (`read address`, `buffer address`, `crossbar source`…).
        what: &'static str,
        /// The value.
        value: u64,
        /// Field width, bits.
        bits: u32,
    },
    /// A word wider than its memory.
    #[error("the {word} word needs {bits} bits, more than the {width} available")]
    WordTooWide {
        /// The word (`instruction`, `crossbar`…).
        word: &'static str,
        /// Bits needed.
        bits: u32,
        /// Bits available.
        width: u32,
    },
}

/// What [`decode`] rejects: an image word no program encodes to.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{image} image, PE slot {slot}, cycle {cycle}: {message}")]
pub struct DecodeError {
    /// The image (`instruction`, `crossbar`, `buffer`, `capture`).
    pub image: &'static str,
    /// PE slot.
    pub slot: usize,
    /// Cycle (word index).
    pub cycle: usize,
    /// What is wrong.
    pub message: String,
}

fn mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

fn field(what: &'static str, value: u64, bits: u32, slot: usize, cycle: u32) -> Result<u64, EncodeError> {
    if value > mask(bits) {
        Err(EncodeError::FieldOverflow { slot, cycle, what, value, bits })
    } else {
        Ok(value)
    }
}

/// The crossbar select of a source: `1 + s` for a result, `1 + n_pe + s` for a buffer read.
pub fn select(src: Source, n_pe: usize) -> u64 {
    match src {
        Source::Result(s) => 1 + s as u64,
        Source::Buffer(s) => 1 + (n_pe + s) as u64,
    }
}

/// Encodes the step of PE `slot` in `cycle` into its four words (instruction, crossbar,
/// buffer, capture).
///
/// # Errors
/// See [`EncodeError`].
pub fn encode_step(l: &Layout, slot: usize, cycle: u32, s: &Step) -> Result<[u64; 4], EncodeError> {
    let aw = l.aw;
    if s.writes.len() > 2 {
        return Err(EncodeError::TooManyWrites { slot, cycle, writes: s.writes.len() });
    }
    let mut instr = 0u64;
    let mut xbar = 0u64;
    if let Some(Instr { op, reads }) = &s.issue {
        // (sub, negate product, mac)
        let (sub, negp, mac) = match op {
            MachineOp::Add | MachineOp::Mul => (0, 0, false),
            MachineOp::Sub => (1, 0, false),
            MachineOp::Div => return Err(EncodeError::NoUnit { slot, cycle, op: "div".into() }),
            MachineOp::Call(c) => return Err(EncodeError::NoUnit { slot, cycle, op: format!("call @{}", c.name) }),
            MachineOp::Mac(c) => {
                let no_unit = || EncodeError::NoUnit { slot, cycle, op: format!("multiply-add @{}", c.name) };
                if !l.mac || slot < l.n_add {
                    return Err(no_unit());
                }
                match Intrinsic::of(c, reads.len()) {
                    Some(Intrinsic::Fma) => (0, 0, true),
                    Some(Intrinsic::Fms) => (1, 0, true),
                    Some(Intrinsic::Fnma) => (0, 1, true),
                    _ => return Err(no_unit()),
                }
            }
        };
        if reads.len() != if mac { 3 } else { 2 } {
            return Err(EncodeError::Reads { slot, cycle, reads: reads.len() });
        }
        instr |= field("read address", reads[0] as u64, aw, slot, cycle)?;
        instr |= field("read address", reads[1] as u64, aw, slot, cycle)? << aw;
        instr |= 1 << (4 * aw + 2);
        instr |= sub << (4 * aw + 3);
        if mac {
            instr |= field("read address", reads[2] as u64, aw, slot, cycle)? << (4 * aw + 4);
            instr |= negp << (5 * aw + 4);
            instr |= 1 << (5 * aw + 5);
        }
    }
    for (port, w) in s.writes.iter().enumerate() {
        let p = port as u32;
        instr |= field("write address", w.addr as u64, aw, slot, cycle)? << ((2 + p) * aw);
        instr |= 1 << (4 * aw + p);
        let sel = field("crossbar source", select(w.src, l.n_pe), l.sw, slot, cycle)?;
        if sel > 2 * l.n_pe as u64 {
            return Err(EncodeError::FieldOverflow { slot, cycle, what: "crossbar source", value: sel, bits: l.sw });
        }
        xbar |= sel << (p * l.sw);
    }
    let mut buf = 0u64;
    if let Some(a) = s.buffer.store {
        buf |= field("buffer address", a as u64, l.bw, slot, cycle)?;
        buf |= 1 << (2 * l.bw);
    }
    if let Some(a) = s.buffer.read {
        buf |= field("buffer address", a as u64, l.bw, slot, cycle)? << l.bw;
        buf |= 1 << (2 * l.bw + 1);
    }
    let cap = match s.capture {
        Some(a) => field("output address", a as u64, l.ow, slot, cycle)? | (1 << l.ow),
        None => 0,
    };
    Ok([instr, xbar, buf, cap])
}

/// Decodes the four words of PE `slot` in one cycle back into its step.
///
/// # Errors
/// See [`DecodeError`].
pub fn decode_step(l: &Layout, slot: usize, cycle: usize, words: [u64; 4]) -> Result<Step, DecodeError> {
    let [instr, xbar, buf, cap] = words;
    let err = |image: &'static str, message: String| DecodeError { image, slot, cycle, message };
    let aw = l.aw;
    let get = |w: u64, at: u32, bits: u32| (w >> at) & mask(bits);
    let bit = |w: u64, at: u32| (w >> at) & 1 == 1;
    for (image, w, bits) in [
        ("instruction", instr, l.instr_bits()),
        ("crossbar", xbar, l.crossbar_bits()),
        ("buffer", buf, l.buffer_bits()),
        ("capture", cap, l.capture_bits()),
    ] {
        if w & !mask(bits) != 0 {
            return Err(err(image, format!("bits set beyond the {bits} used bits ({w:#x})")));
        }
    }
    let is_add = slot < l.n_add;
    // the mac fields (only in a layout that has them: else they are beyond the used bits)
    let (rc, negp, mac) = if l.mac {
        (get(instr, 4 * aw + 4, aw), bit(instr, 5 * aw + 4), bit(instr, 5 * aw + 5))
    } else {
        (0, false, false)
    };
    let issue = if bit(instr, 4 * aw + 2) {
        let sub = bit(instr, 4 * aw + 3);
        let (a, b) = (get(instr, 0, aw) as u32, get(instr, aw, aw) as u32);
        if mac {
            let fused = match (is_add, negp, sub) {
                (true, ..) => return Err(err("instruction", "mac bit set on an ADD PE".into())),
                (false, false, false) => Intrinsic::Fma,
                (false, false, true) => Intrinsic::Fms,
                (false, true, false) => Intrinsic::Fnma,
                (false, true, true) => return Err(err("instruction", "negate-product and sub bits both set".into())),
            };
            Some(Instr {
                op: MachineOp::Mac(Box::new(fused.callee())),
                reads: ReadAddrs::from_slice(&[a, b, rc as u32]),
            })
        } else {
            if rc != 0 || negp {
                return Err(err("instruction", "read address C or negate-product bit without the mac bit".into()));
            }
            let op = match (is_add, sub) {
                (true, false) => MachineOp::Add,
                (true, true) => MachineOp::Sub,
                (false, false) => MachineOp::Mul,
                (false, true) => {
                    return Err(err("instruction", "sub bit set on a MULTI PE without the mac bit".into()))
                }
            };
            Some(Instr { op, reads: [a, b].into() })
        }
    } else {
        if get(instr, 0, 2 * aw) != 0 || bit(instr, 4 * aw + 3) || rc != 0 || negp || mac {
            return Err(err("instruction", "read addresses, sub or mac fields without issue valid".into()));
        }
        None
    };
    let mut writes = StepWrites::new();
    for p in 0..2u32 {
        let we = bit(instr, 4 * aw + p);
        let addr = get(instr, (2 + p) * aw, aw) as u32;
        let sel = get(xbar, p * l.sw, l.sw);
        match (we, sel) {
            (false, 0) => {
                if addr != 0 {
                    return Err(err("instruction", format!("write address of port {p} without write enable")));
                }
            }
            (true, 0) => return Err(err("crossbar", format!("port {p} writes but selects no source"))),
            (false, _) => return Err(err("crossbar", format!("port {p} selects a source but does not write"))),
            (true, s) => {
                let n = l.n_pe as u64;
                let src = if s <= n {
                    Source::Result((s - 1) as usize)
                } else if s <= 2 * n {
                    Source::Buffer((s - n - 1) as usize)
                } else {
                    return Err(err("crossbar", format!("select {s} of port {p} beyond 2·{n}")));
                };
                writes.push(MemWrite { addr, src });
            }
        }
    }
    let store = bit(buf, 2 * l.bw).then(|| get(buf, 0, l.bw) as u32);
    let read = bit(buf, 2 * l.bw + 1).then(|| get(buf, l.bw, l.bw) as u32);
    if (store.is_none() && get(buf, 0, l.bw) != 0) || (read.is_none() && get(buf, l.bw, l.bw) != 0) {
        return Err(err("buffer", "address without enable".into()));
    }
    let capture = bit(cap, l.ow).then(|| get(cap, 0, l.ow) as u32);
    if capture.is_none() && cap != 0 {
        return Err(err("capture", "address without enable".into()));
    }
    Ok(Step { issue, writes, buffer: BufferOp { store, read }, capture })
}

/// Encodes every step of `p` with layout `l`.
///
/// # Errors
/// The first step (slot order, then cycle) that the words cannot express ([`EncodeError`]).
pub fn encode(p: &MachineProgram, l: &Layout) -> Result<Images, EncodeError> {
    let n = p.n_pe();
    let mut im = Images {
        layout: *l,
        instr: vec![Vec::new(); n],
        crossbar: vec![Vec::new(); n],
        buffer: vec![Vec::new(); n],
        capture: vec![Vec::new(); n],
    };
    for (slot, pe) in p.pes.iter().enumerate() {
        for (cycle, s) in pe.steps.iter().enumerate() {
            let [i, x, b, c] = encode_step(l, slot, cycle as u32, s)?;
            im.instr[slot].push(i);
            im.crossbar[slot].push(x);
            im.buffer[slot].push(b);
            im.capture[slot].push(c);
        }
    }
    Ok(im)
}

/// The program `p`'s images carry back: `p` with every PE's steps replaced by what [`encode`]
/// then [`decode`] give (equal to `p` when the encoding keeps every field: what the encoding's
/// tests compare).
///
/// # Errors
/// The text of the [`EncodeError`] or [`DecodeError`] met on the way.
pub fn through_images(p: &MachineProgram, l: &Layout) -> Result<MachineProgram, String> {
    let images = encode(p, l).map_err(|e| e.to_string())?;
    let steps = decode(&images).map_err(|e| e.to_string())?;
    let mut back = p.clone();
    for (pe, s) in back.pes.iter_mut().zip(steps) {
        pe.steps = s;
    }
    Ok(back)
}

/// Decodes images back into the steps of every PE slot (`[slot][cycle]`).
///
/// # Errors
/// The first word no program encodes to, or images of different lengths ([`DecodeError`]).
pub fn decode(im: &Images) -> Result<Vec<Vec<Step>>, DecodeError> {
    let l = &im.layout;
    let mut out = Vec::with_capacity(l.n_pe);
    for slot in 0..l.n_pe {
        let lens = [im.instr.get(slot), im.crossbar.get(slot), im.buffer.get(slot), im.capture.get(slot)]
            .map(|v| v.map(Vec::len));
        let Some(n) = lens[0].filter(|&n| lens.iter().all(|&m| m == Some(n))) else {
            return Err(DecodeError {
                image: "instruction",
                slot,
                cycle: 0,
                message: format!("images of this PE are missing or differ in length: {lens:?}"),
            });
        };
        let mut steps = Vec::with_capacity(n);
        for c in 0..n {
            let words = [im.instr[slot][c], im.crossbar[slot][c], im.buffer[slot][c], im.capture[slot][c]];
            steps.push(decode_step(l, slot, c, words)?);
        }
        out.push(steps);
    }
    Ok(out)
}

/// The binary32 bits of a data word (module doc of [`robovec_ir::machine`], "Data words"),
/// `input(name)` giving each input's value: inputs and constants rounded to nearest
/// (`x as f32`, as `-eval-precision=f32` and `interp`'s `Float::from_f64` for `f32` do), trig
/// values as `sin`/`cos` in `f32` of the rounded input (what `interp::eval::<f32>` computes).
pub fn word_binary32(w: &Word, input: impl Fn(&str) -> f64) -> u32 {
    match w {
        Word::Input(n) => (input(n) as f32).to_bits(),
        Word::Trig(t, n) => {
            let x = input(n) as f32;
            match t {
                TrigFn::Sin => x.sin().to_bits(),
                TrigFn::Cos => x.cos().to_bits(),
            }
        }
        Word::Const(c) => (*c as f32).to_bits(),
    }
}

/// The binary32 initial contents of PE slot `slot`'s memory in `p`, one word per address (0
/// where nothing is loaded), `input(name)` giving each input ([`word_binary32`]).
///
/// # Panics
/// When `slot` is not below [`MachineProgram::n_pe`].
pub fn pe_image(p: &MachineProgram, slot: usize, input: impl Fn(&str) -> f64) -> Vec<u32> {
    p.pes[slot].init.iter().map(|w| w.as_ref().map_or(0, |w| word_binary32(w, &input))).collect()
}

/// The binary32 initial contents of PE slot `slot`'s output memory in `p` (0 for captured
/// words).
///
/// # Panics
/// When `slot` is not below [`MachineProgram::n_pe`].
pub fn output_image(p: &MachineProgram, slot: usize, input: impl Fn(&str) -> f64) -> Vec<u32> {
    p.pes[slot].output_init.iter().map(|w| w.as_ref().map_or(0, |w| word_binary32(w, &input))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(n_pe: usize, n_add: usize) -> Layout {
        Layout { n_pe, n_add, aw: 11, bw: 4, ow: 3, sw: bits_for(2 * n_pe as u64 + 1), instr_width: 52, mac: false }
    }

    fn mac_layout(n_pe: usize, n_add: usize) -> Layout {
        Layout { mac: true, instr_width: 61, ..layout(n_pe, n_add) }
    }

    #[test]
    fn widths_follow_the_seed_word() {
        assert_eq!([bits_for(1), bits_for(2), bits_for(3), bits_for(2048), bits_for(2049)], [1, 1, 2, 11, 12]);
        // 2·n_pe + 1 selects: 8 PEs → 17 → 5 bits; 2 PEs → 5 → 3 bits.
        assert_eq!((bits_for(17), bits_for(5)), (5, 3));
        let l = layout(2, 1);
        assert_eq!((l.instr_bits(), l.crossbar_bits(), l.buffer_bits(), l.capture_bits()), (48, 6, 10, 4));
    }

    #[test]
    fn every_field_round_trips() {
        let l = layout(4, 2);
        let step = Step {
            issue: Some(Instr { op: MachineOp::Sub, reads: [2047, 5].into() }),
            writes: StepWrites::from_vec(vec![
                MemWrite { addr: 7, src: Source::Buffer(3) },
                MemWrite { addr: 2046, src: Source::Result(0) },
            ]),
            buffer: BufferOp { store: Some(15), read: Some(9) },
            capture: Some(6),
        };
        let w = encode_step(&l, 1, 3, &step).unwrap();
        // Hand-computed: A = 2047, B = 5 << 11, write-0 address 7 << 22, write-1 2046 << 33,
        // we0, we1, valid, sub at 44..=47; selects 1 + 4 + 3 = 8 and 1 + 0 = 1 (sw = 4).
        let instr = 2047 | (5 << 11) | (7 << 22) | (2046u64 << 33) | (0b1111 << 44);
        assert_eq!(w, [instr, 8 | (1 << 4), 15 | (9 << 4) | (0b11 << 8), 6 | (1 << 3)]);
        assert_eq!(decode_step(&l, 1, 3, w).unwrap(), step);
        // A MULTI PE (slot 2) decodes the same valid bit as a mul.
        let mul = Step { issue: Some(Instr { op: MachineOp::Mul, reads: [1, 2].into() }), ..Step::default() };
        let w = encode_step(&l, 2, 0, &mul).unwrap();
        assert_eq!(decode_step(&l, 2, 0, w).unwrap(), mul);
        assert_eq!(encode_step(&l, 0, 0, &Step::default()).unwrap(), [0; 4]);
    }

    #[test]
    fn encode_and_decode_reject_what_the_words_cannot_hold() {
        let l = layout(2, 1);
        let too_far = Step { issue: Some(Instr { op: MachineOp::Add, reads: [2048, 0].into() }), ..Step::default() };
        assert!(matches!(
            encode_step(&l, 0, 4, &too_far),
            Err(EncodeError::FieldOverflow { what: "read address", value: 2048, bits: 11, .. })
        ));
        let w = MemWrite { addr: 0, src: Source::Result(0) };
        let three = Step { writes: StepWrites::from_vec(vec![w, w, w]), ..Step::default() };
        assert!(matches!(encode_step(&l, 0, 0, &three), Err(EncodeError::TooManyWrites { writes: 3, .. })));
        let call = Step { issue: Some(Instr { op: MachineOp::Div, reads: [0, 0].into() }), ..Step::default() };
        assert!(matches!(encode_step(&l, 0, 0, &call), Err(EncodeError::NoUnit { .. })));
        // Decode: a bit beyond the 48 used, a sub bit on a MULTI PE, a select beyond 2·n_pe,
        // a write enable without a select.
        assert!(decode_step(&l, 0, 0, [1 << 50, 0, 0, 0]).unwrap_err().message.contains("beyond"));
        assert!(decode_step(&l, 1, 0, [0b1100 << 44, 0, 0, 0]).unwrap_err().message.contains("MULTI"));
        assert!(decode_step(&l, 0, 0, [1 << 44, 5, 0, 0]).unwrap_err().message.contains("beyond 2·2"));
        assert!(decode_step(&l, 0, 0, [1 << 44, 0, 0, 0]).unwrap_err().message.contains("selects no source"));
    }

    #[test]
    fn multiply_adds_take_read_c_and_two_bits_after_the_seed_word() {
        let (l, plain) = (mac_layout(2, 1), layout(2, 1));
        assert_eq!(l.instr_bits(), 61);
        let mac = |i: Intrinsic| Step {
            issue: Some(Instr {
                op: MachineOp::Mac(Box::new(i.callee())),
                reads: ReadAddrs::from_slice(&[3, 4, 2047]),
            }),
            ..Step::default()
        };
        // read C at 44..55, negate product at 55, mac at 56; sub (47) negates the addend
        let base = 3 | (4 << 11) | (1 << 46) | (2047u64 << 48) | (1 << 60);
        for (i, bits) in [(Intrinsic::Fma, 0), (Intrinsic::Fms, 1u64 << 47), (Intrinsic::Fnma, 1 << 59)] {
            let w = encode_step(&l, 1, 0, &mac(i)).unwrap();
            assert_eq!(w, [base | bits, 0, 0, 0], "{i:?}");
            assert_eq!(decode_step(&l, 1, 0, w).unwrap(), mac(i));
        }
        // a program without multiply-adds keeps the seed's word; a multiply-add needs the
        // mac fields and a MULTI PE
        let mul = Step { issue: Some(Instr { op: MachineOp::Mul, reads: [1, 2].into() }), ..Step::default() };
        assert_eq!(encode_step(&l, 1, 0, &mul).unwrap(), encode_step(&plain, 1, 0, &mul).unwrap());
        assert!(matches!(encode_step(&plain, 1, 0, &mac(Intrinsic::Fma)), Err(EncodeError::NoUnit { .. })));
        assert!(matches!(encode_step(&l, 0, 0, &mac(Intrinsic::Fma)), Err(EncodeError::NoUnit { .. })));
        // decode: the mac bit on an ADD PE, negate product with sub, C without the mac bit
        assert!(decode_step(&l, 0, 0, [base, 0, 0, 0]).unwrap_err().message.contains("ADD"));
        assert!(decode_step(&l, 1, 0, [base | 1 << 47 | 1 << 59, 0, 0, 0]).is_err());
        assert!(decode_step(&l, 1, 0, [base & !(1 << 60), 0, 0, 0]).unwrap_err().message.contains("without the mac"));
        assert!(decode_step(&plain, 1, 0, [base, 0, 0, 0]).unwrap_err().message.contains("beyond"));
    }

    use proptest::prelude::*;

    /// Any step a program on `layout(n_pe, n_add)` can hold on an ADD (`is_add`) or MULTI PE: 0–2 writes from
    /// any source, optional issue of the PE's ops, buffer and capture instructions.
    fn any_step(n_pe: usize, is_add: bool) -> impl Strategy<Value = Step> {
        any_step_of(n_pe, is_add, false)
    }

    /// [`any_step`] with fused multiply-adds on a MULTI PE when `mac` (a [`mac_layout`]).
    fn any_step_of(n_pe: usize, is_add: bool, mac: bool) -> impl Strategy<Value = Step> {
        let addr = 0u32..2048;
        let src = (any::<bool>(), 0..n_pe).prop_map(|(b, s)| if b { Source::Buffer(s) } else { Source::Result(s) });
        let write = (addr.clone(), src).prop_map(|(addr, src)| MemWrite { addr, src });
        let op = if is_add {
            prop_oneof![Just(MachineOp::Add), Just(MachineOp::Sub)].boxed()
        } else {
            Just(MachineOp::Mul).boxed()
        };
        let fused = prop_oneof![Just(Intrinsic::Fma), Just(Intrinsic::Fms), Just(Intrinsic::Fnma)];
        let fused = (fused, addr.clone(), addr.clone(), addr.clone()).prop_map(|(i, a, b, c)| Instr {
            op: MachineOp::Mac(Box::new(i.callee())),
            reads: ReadAddrs::from_slice(&[a, b, c]),
        });
        let binary = (op, addr.clone(), addr.clone()).prop_map(|(op, a, b)| Instr { op, reads: [a, b].into() });
        let instr = if mac && !is_add { prop_oneof![binary, fused].boxed() } else { binary.boxed() };
        let issue = proptest::option::of(instr);
        let small = || proptest::option::of(0u32..16);
        (issue, proptest::collection::vec(write, 0..=2), small(), small(), proptest::option::of(0u32..8)).prop_map(
            |(issue, writes, store, read, capture)| Step {
                issue,
                writes: writes.into(),
                buffer: BufferOp { store, read },
                capture,
            },
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        #[test]
        fn decode_inverts_encode_on_any_step(
            (n_pe, slot, step) in (1usize..=8)
                .prop_flat_map(|n| (Just(n), 0..n))
                .prop_flat_map(|(n, s)| (Just(n), Just(s), any_step(n, s < n.div_ceil(2))))
        ) {
            let l = layout(n_pe, n_pe.div_ceil(2));
            let w = encode_step(&l, slot, 0, &step).unwrap();
            prop_assert_eq!(decode_step(&l, slot, 0, w).unwrap(), step);
        }

        #[test]
        fn decode_inverts_encode_on_any_step_with_multiply_adds(
            (n_pe, slot, step) in (2usize..=8)
                .prop_flat_map(|n| (Just(n), 0..n))
                .prop_flat_map(|(n, s)| (Just(n), Just(s), any_step_of(n, s < n.div_ceil(2), true)))
        ) {
            let l = mac_layout(n_pe, n_pe.div_ceil(2));
            let w = encode_step(&l, slot, 0, &step).unwrap();
            prop_assert!(w[0] >> l.instr_bits() == 0);
            prop_assert_eq!(decode_step(&l, slot, 0, w).unwrap(), step);
        }
    }
}
