//! The design of one placed function: its configuration (PEs, latencies, word widths) and its
//! memory images, from which the Verilog top, the testbench, the manifest and the image files
//! are written ([`crate::emit`]). [`build`] makes it from a placement (the machine program,
//! encoded); [`images`] writes and reads the memory images; the fixed Verilog (`hdl/`) and the
//! `simulate` script are [`HDL_LIBRARY`], [`SYNTH_STUBS`] and [`SIMULATE`].

pub mod build;
pub mod images;
pub mod routes;

use std::fmt::Write;

use serde::Serialize;

use images::Image;
use routes::{selects, Interconnect, Routes};

pub use crate::program::fixed::PeKind;
use crate::target::PeMemory;

/// Bit widths of the design's words (the encoding of [`crate::encode`], LSB first).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Widths {
    /// PE memory address bits (`aw`, ⌈log2 pe_words⌉ of the target: 11 on the DE10-Nano).
    pub aw: u32,
    /// Buffer address bits (`bw`).
    pub bw: u32,
    /// Crossbar select bits (`sw` = ⌈log2(2·n_pe + 1)⌉).
    pub sw: u32,
    /// Output memory address bits (`ow`).
    pub ow: u32,
    /// Program counter bits (`cw`: cycles `0..=cycles + 1` fit).
    pub cw: u32,
    /// Instruction word bits (the target's `instr_width`, 52 on the DE10-Nano; `4·aw + 4` used).
    pub instr: u32,
}

impl Widths {
    /// Crossbar word bits: two selects.
    pub fn xbar(&self) -> u32 {
        2 * self.sw
    }
    /// Buffer instruction word bits: store and read addresses, store and read enables.
    pub fn bufi(&self) -> u32 {
        2 * self.bw + 2
    }
    /// Output capture word bits: address and enable.
    pub fn capt(&self) -> u32 {
        self.ow + 1
    }
}

/// Bits needed to address `n` words (at least 1).
pub fn addr_bits(n: u64) -> u32 {
    if n <= 2 {
        1
    } else {
        64 - (n - 1).leading_zeros()
    }
}

/// Where a word of initial data comes from.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Source {
    /// An input of the function, by canonical name (SPEC §2).
    Input {
        /// Input name (`q[1]`).
        input: String,
    },
    /// A trig initial value: `sin`/`cos` of an input, computed in binary32 by the host.
    Trig {
        /// Its name in the IR (`S4`).
        name: String,
        /// `sin` or `cos`.
        trig: &'static str,
        /// The input it is of.
        of: String,
    },
    /// A constant: its binary32 word (the `f64` literal rounded to nearest).
    Const {
        /// The literal.
        value: f64,
        /// Its binary32 bits, `0x…`.
        bits: String,
    },
}

/// A word of initial data: PE slot, address, source.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoadWord {
    /// Fixed-point PEs (issue 49): the fractional bits of the word's value (`k · 2^-f`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fraction: Option<i32>,
    /// PE slot ([`robovec_ir::placement::Pe::slot`]).
    pub slot: usize,
    /// PE name (`add0`, `mul1`).
    pub pe: String,
    /// Address in the PE memory (or output memory).
    pub addr: u32,
    /// What is loaded.
    #[serde(flatten)]
    pub source: Source,
}

/// Where an output is read after `done`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct OutputWord {
    /// Output name (SPEC §2).
    pub name: String,
    /// PE slot whose output memory holds it.
    pub slot: usize,
    /// PE name.
    pub pe: String,
    /// Output memory address.
    pub addr: u32,
    /// Fixed-point PEs (issue 49): the fractional bits of the output's format (`k · 2^-f`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fraction: Option<i32>,
}

/// The memory images of one PE.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PeImages {
    /// Slot (ADD PEs first, then MULTI PEs).
    pub slot: usize,
    /// Name (`add0`).
    pub pe: String,
    /// True for a MULTI PE.
    pub is_mul: bool,
    /// True for a MULTI PE that issues fused multiply-adds (fixed point, [`crate::encode`]'s mac
    /// fields): its unit is `fix_mac` (`rv_pe`'s `MAC = 1`), its PE memory has a third read and
    /// its control word the read address C, negate-product and mac bits after the shift word.
    pub mac: bool,
    /// Instruction memory, one word per cycle `0..=cycles`.
    pub instr: Image,
    /// Crossbar memory (this PE memory's two write selects), one word per cycle: the
    /// crossbar's selects ([`crate::encode`]), or with a specialised interconnect each port's
    /// route index ([`routes`]: port 0 in the low [`Routes::select_bits`], port 1 above).
    pub xbar: Image,
    /// Buffer instruction memory, one word per cycle.
    pub bufi: Image,
    /// Output capture memory, one word per cycle.
    pub capt: Image,
    /// Initial PE memory contents (constants; input words are 0 here and filled by `simulate`
    /// or the host from the load map).
    pub data: Image,
    /// Initial output memory contents (outputs that are constants; input outputs 0).
    pub out: Image,
    /// Buffer words (depth of the buffer memory).
    pub buffer_words: u32,
    /// Fixed-point PEs (issue 49): the shift memory, one [`robovec_ir::machine::FixShifts`]
    /// word per cycle (14 bits).
    pub fix: Option<Image>,
    /// Fixed-point PEs: the shifts its issued ops use ([`build::shift_ranges`]), which size its
    /// unit's shifters.
    pub shift_ranges: Option<build::ShiftRanges>,
}

impl PeImages {
    /// The images, in file order (the shift memory last, on fixed-point PEs).
    pub fn images(&self) -> Vec<&Image> {
        let mut v = vec![&self.instr, &self.xbar, &self.bufi, &self.capt, &self.data, &self.out];
        v.extend(&self.fix);
        v
    }
}

/// Everything the back end writes for one function.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// Function name.
    pub function: String,
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// ADD PE latency, cycles from issue to arrival (SPEC §1: unit stages + 2).
    pub lat_add: u32,
    /// MULTI PE latency, cycles.
    pub lat_mul: u32,
    /// Last cycle of the program (the largest arrival, `ir/src/placement.rs`).
    pub cycles: u32,
    /// Word widths.
    pub widths: Widths,
    /// Per PE, in slot order.
    pub pes: Vec<PeImages>,
    /// The function's inputs, canonical names, in order.
    pub inputs: Vec<String>,
    /// Fixed-point PEs: each input's format's fractional bits, by name (empty otherwise).
    pub input_fractions: std::collections::BTreeMap<String, i32>,
    /// Initial PE memory words that are inputs, trig values or constants.
    pub loads: Vec<LoadWord>,
    /// Initial output memory words (outputs that are inputs, trig values or constants).
    pub output_loads: Vec<LoadWord>,
    /// The output map.
    pub outputs: Vec<OutputWord>,
    /// The specialised interconnect's routes; `None`: the crossbar ([`routes`]).
    pub routes: Option<Routes>,
    /// The kind of PEs: binary32 (the seed's) or fixed point (issue 49; words are the values'
    /// 32-bit integers, [`crate::program::fixed`]).
    pub pe_kind: PeKind,
    /// How each PE memory is built: the seed's double-pumped block RAM (`rv_pe_mem`) or banks
    /// with a live-value table (`rv_pe_mem_lvt`, the ECP5's), the same behaviour cycle for cycle.
    pub pe_memory: PeMemory,
    /// Independent states one run computes (the function's `states`, issue 49 item 3: state
    /// k's inputs and outputs are named `name#k`).
    pub states: u32,
    /// Bits of the data word (PE memories, interconnect, buffers, output memories, units): 32
    /// for binary32 PEs, the function's widest format for fixed-point ones
    /// ([`crate::program::fixed::word_bits`]).
    pub word_bits: u32,
    /// Bits of a lane of the control memory ([`Design::control_lanes`]): the family's widest
    /// block-RAM word.
    pub control_lane_bits: u32,
    /// The widest word whose product is one DSP multiplier of the family (27 on the Cyclone V,
    /// 18 on the ECP5): a fixed-point MULTI PE of a wider word registers four partial products
    /// before their sum (`fix_mul`'s `ONE`).
    pub multiplier_word: u32,
    /// The deepest output memory built in the family's LUT RAM (`rv_out_lutram`, the Cyclone
    /// V's MLAB: [`crate::target::Family::lutram_words`]); deeper ones, and all with 0, are block
    /// RAM (`rv_out_mem`).
    pub out_lutram_words: u32,
}

/// A PE's control word ([`Design::controls`]): per cycle the instruction (its four addresses
/// `pa` bits each), the write-port selects, the buffer instruction, the output capture and the
/// shift word, at bits `[offset, offset + width)` of the design's control memory
/// ([`Design::control_lanes`]).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Control {
    /// Bits of each address field of the instruction: the PE memory's address bits.
    pub pa: u32,
    /// Bits of each buffer address of the buffer instruction: the PE's buffer's (at least 1).
    pub pb: u32,
    /// Bits of the output-memory address of the capture word: the PE's output memory's (at
    /// least 1).
    pub po: u32,
    /// The shift word's fields on a fixed-point PE ([`FixField`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fix: Option<FixField>,
    /// Bits of the write-port selects (port 0, port 1, the shared multiplexer's; 0: none):
    /// [`Design::lane_select_bits`].
    pub select_bits: [u32; 3],
    /// Bits of the whole word (`4·pa + 4` + selects + `2·pb + 2` buffer + `po + 1` capture [+
    /// the shift word's [`FixField::bits`]] [+ `pa + 2` mac fields]).
    pub width: u32,
    /// The bit of the design's control word where this PE's starts: the widths of the PEs
    /// before it in slot order ([`Design::control_offsets`]).
    pub offset: u32,
}

/// The shift word of a fixed-point PE in its control word, cut to the shifts its program uses
/// ([`build::ShiftRanges`], `rv_pe`'s `RMAX`, `AMAX`, `SMIN`, `SMAX`): from bit 0, on an ADD PE
/// the floor of its finer operand (`floor_bits`, [`build::FloorShifts`]), the alignment
/// (`align_bits`: an ADD PE's lift of the coarser operand; none on a MULTI PE without fused ops,
/// which never aligns), the align-b bit (on the PEs that align), the rounding shift less
/// `shift_min` (`shift_bits`, at least 1; an ADD PE's rounding of the floored sum). The `fix`
/// image keeps the full 14-bit word.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct FixField {
    /// Whether the PE applies its ops' [`build::FloorShifts`] (ADD PEs): the field holds the
    /// floor, the lift and the floored sum's rounding instead of the alignment and rounding.
    pub floors: bool,
    /// Bits of the floor: ⌈log₂(RMAX + 1)⌉ (0 when no op floors, and on MULTI PEs).
    pub floor_bits: u32,
    /// Bits of the alignment: ⌈log₂(AMAX + 1)⌉, at least 1, on the PEs that align (ADD PEs,
    /// PEs with fused multiply-adds); 0 on the others.
    pub align_bits: u32,
    /// Whether the align-b bit is there (ADD PEs and PEs with fused multiply-adds).
    pub align_b: bool,
    /// Bits of `s − shift_min`: ⌈log₂(SMAX − SMIN + 1)⌉, at least 1.
    pub shift_bits: u32,
    /// The smallest rounding shift (SMIN), the field's zero.
    pub shift_min: i32,
}

impl FixField {
    /// Bits of the field in the control word.
    pub fn bits(&self) -> u32 {
        self.floor_bits + self.align_bits + u32::from(self.align_b) + self.shift_bits
    }

    /// The field of a 14-bit shift word `w` (`fix` image: `[0,6)` align, bit 6 align b, `[7,14)`
    /// s in two's complement), in [`build::FloorShifts`] form on an ADD PE.
    pub fn pack(&self, w: u64) -> u64 {
        let sh = robovec_ir::machine::FixShifts::from_word(w);
        let (floor, align, s) = if self.floors {
            let f = build::FloorShifts::of(sh);
            (u64::from(f.floor), u64::from(f.lift), i64::from(f.round))
        } else {
            (0, u64::from(sh.align & 63), i64::from(sh.shift))
        };
        let shift = (s - i64::from(self.shift_min)) as u64;
        debug_assert!(floor < 1 << self.floor_bits || floor == 0, "a floor beyond the PE's range");
        debug_assert!(align < 1 << self.align_bits || align == 0, "an alignment beyond the PE's range");
        debug_assert!(shift < 1 << self.shift_bits, "a rounding shift beyond the PE's range");
        let mut at = 0;
        let mut out = 0u64;
        for (v, bits) in [
            (floor, self.floor_bits),
            (align, self.align_bits),
            (u64::from(sh.align_b), u32::from(self.align_b)),
            (shift, self.shift_bits),
        ] {
            out |= (v & ((1 << bits) - 1)) << at;
            at += bits;
        }
        out
    }
}

/// The fixed Verilog files, `(name, text)`: the FP unit models, the memories and the PE.
pub const HDL_LIBRARY: &[(&str, &str)] = &[
    ("fp_units.v", include_str!("hdl/fp_units.v")),
    ("fix_units.v", include_str!("hdl/fix_units.v")),
    ("rv_mem.v", include_str!("hdl/rv_mem.v")),
    ("rv_lib.v", include_str!("hdl/rv_lib.v")),
];

/// Black-box stubs of the FP units and memories for the Yosys resource estimate.
pub const SYNTH_STUBS: &str = include_str!("hdl/synth_stubs.v");

/// The `simulate` script written into `DIR` (Python 3 standard library + Icarus Verilog).
pub const SIMULATE: &str = include_str!("simulate.py");

impl Design {
    /// PEs of both types.
    pub fn n_pe(&self) -> usize {
        (self.n_add + self.n_mul) as usize
    }

    /// Whether PE `p`'s output memory is built in LUT RAM (`rv_out_lutram`): its image has at
    /// most [`Design::out_lutram_words`] words and no initial contents (no output of the PE is
    /// an input or a constant: Yosys 0.23 maps no initialised memory to MLAB cells). Else block
    /// RAM (`rv_out_mem`).
    pub fn out_in_lutram(&self, p: &PeImages) -> bool {
        p.out.words.len().max(1) as u64 <= u64::from(self.out_lutram_words)
            && !self.output_loads.iter().any(|l| l.slot == p.slot)
    }

    /// The interconnect the design has.
    pub fn interconnect(&self) -> Interconnect {
        match self.routes {
            Some(_) => Interconnect::Specialised,
            None => Interconnect::Crossbar,
        }
    }

    /// The design with interconnect `i`: for [`Interconnect::Specialised`], each write port's
    /// multiplexer over the sources its program routes, its crossbar image re-encoded as route
    /// indices ([`routes`]); the crossbar otherwise. Idempotent.
    pub fn with_interconnect(mut self, i: Interconnect) -> Design {
        let global: Vec<Vec<u64>> = (0..self.pes.len()).map(|s| self.crossbar_words(s)).collect();
        match i {
            Interconnect::Crossbar => {
                for (p, words) in self.pes.iter_mut().zip(global) {
                    p.xbar.width = self.widths.xbar();
                    p.xbar.words = words;
                }
                self.routes = None;
            }
            Interconnect::Specialised => {
                // each source on one write port, or the shared multiplexer, where the cycles
                // allow it (fewer inputs)
                let mut global = global;
                let shared: Vec<Vec<u32>> = self
                    .pes
                    .iter_mut()
                    .zip(global.iter_mut())
                    .map(|(p, words)| {
                        routes::assign_write_ports(&mut p.instr.words, words, self.widths.aw, self.widths.sw)
                    })
                    .collect();
                let refs: Vec<&[u64]> = global.iter().map(|w| w.as_slice()).collect();
                let r = Routes::of_crossbar(self.n_pe(), self.widths.sw, &refs, &shared);
                for (s, (p, words)) in self.pes.iter_mut().zip(&global).enumerate() {
                    p.xbar.width = r.word_bits(s);
                    p.xbar.words = words
                        .iter()
                        .map(|&w| {
                            r.encode(s, selects(w, self.widths.sw)).expect("every select of the image is a route")
                        })
                        .collect();
                }
                self.routes = Some(r);
            }
        }
        self
    }

    /// The 32-bit multiplexer inputs of the design's write ports (two per PE memory): `2·n_pe`
    /// per port for the crossbar, the routes for a specialised interconnect
    /// ([`Routes::mux_inputs`]).
    pub fn mux_inputs(&self) -> u64 {
        let n = self.n_pe() as u64;
        match &self.routes {
            Some(r) => r.mux_inputs(),
            None => n * 2 * (2 * n),
        }
    }

    /// Multiplexer inputs of write port `port` (0 or 1) of PE `slot`'s memory: `2·n_pe` for the
    /// crossbar, the port's routes for a specialised interconnect (at least 1: a port without
    /// routes is a constant 0).
    pub fn port_inputs(&self, slot: usize, port: usize) -> usize {
        match &self.routes {
            Some(r) => r.port_inputs(slot, port).max(1),
            None => 2 * self.n_pe(),
        }
    }

    /// Inputs of PE `slot`'s shared multiplexer ([`routes::assign_write_ports`]): 0 without one
    /// (and for the crossbar).
    pub fn shared_inputs(&self, slot: usize) -> usize {
        self.routes.as_ref().map_or(0, |r| r.shared[slot].len())
    }

    /// PE `slot`'s crossbar memory as the crossbar's selects ([`crate::encode`]'s words),
    /// whatever the interconnect.
    pub fn crossbar_words(&self, slot: usize) -> Vec<u64> {
        let p = &self.pes[slot];
        let Some(r) = &self.routes else { return p.xbar.words.clone() };
        let sw = self.widths.sw;
        p.xbar
            .words
            .iter()
            .map(|&w| {
                let [g0, g1] = r.decode(slot, w).expect("a route index within the port's routes");
                g0 | (g1 << sw)
            })
            .collect()
    }

    /// The Verilog expression of port `port`'s multiplexer sources on PE `slot` (most
    /// significant word first), their count and select bits: the whole bus `sources` for the
    /// crossbar, the routed words for a specialised design (`32'h0` alone for a port without
    /// routes: its select is always 0; `DW'h0` with the design's word bits); the count is the
    /// port's own sources (at least 1 without a shared multiplexer, whose output `rv_pe` adds:
    /// [`Design::port_inputs`] counts it).
    fn port_sources(&self, slot: usize, port: usize) -> (String, usize, u32) {
        let k = self.port_inputs(slot, port);
        let bits = self.lane_select_bits(slot)[port];
        let Some(r) = &self.routes else { return ("sources".into(), k, bits) };
        let list = &r.ports[slot][port];
        // a port's own sources; with a shared multiplexer a port may have none (`rv_pe` adds
        // the shared output as its last input)
        let k_own = if r.has_shared(slot) { list.len() } else { list.len().max(1) };
        if list.is_empty() {
            return (format!("{}'h0", self.word_bits), k_own, bits);
        }
        (self.source_words(list), k_own, bits)
    }

    /// The bits of PE `slot`'s write-port selects in its control word (port 0, port 1, the
    /// shared multiplexer's): `rv_mux` takes the 0-based index of its input, so a port of `k`
    /// inputs ([`Design::port_inputs`], the shared output included) has `⌈log₂ k⌉` bits (at
    /// least 1), the shared multiplexer of `k` sources `⌈log₂ k⌉` (at least 1; 0 without one),
    /// and the crossbar's port `⌈log₂(2·n_pe)⌉`. There is no "none" code: the instruction's
    /// write enables say which ports write. The separate `xbar` image keeps its 1-based selects
    /// with 0 for none ([`Design::image_selects`]); a 2^j-input port takes j bits, not j + 1,
    /// and its multiplexer needs no gate (issue 49: WALK-MAN's 305 multiplexers, 23,380 → about
    /// 19,490 ALM by Yosys).
    pub fn lane_select_bits(&self, slot: usize) -> [u32; 3] {
        match &self.routes {
            None => {
                let b = addr_bits(2 * self.n_pe() as u64);
                [b, b, 0]
            }
            Some(r) => {
                let shared = match r.shared[slot].len() {
                    0 => 0,
                    k => addr_bits(k as u64),
                };
                [addr_bits(self.port_inputs(slot, 0) as u64), addr_bits(self.port_inputs(slot, 1) as u64), shared]
            }
        }
    }

    /// The selects of PE `slot`'s `xbar` image word `word`: port 0's, port 1's and the shared
    /// multiplexer's, each 1-based with 0 for none (the crossbar's selects `1..=2·n_pe`, or a
    /// specialised design's route indices, [`Routes::encode`]).
    pub fn image_selects(&self, slot: usize, word: u64) -> [u64; 3] {
        match &self.routes {
            None => {
                let [g0, g1] = selects(word, self.widths.sw);
                [g0, g1, 0]
            }
            Some(r) => r.fields(slot, word),
        }
    }

    /// The Verilog concatenation of crossbar selects `list` (most significant word first):
    /// `resultS` / `bufferS` per select.
    fn source_words(&self, list: &[u32]) -> String {
        let n = self.n_pe();
        let words: Vec<String> = list
            .iter()
            .rev()
            .map(|&g| {
                let g = g as usize;
                if g <= n {
                    format!("result{}", g - 1)
                } else {
                    format!("buffer{}", g - n - 1)
                }
            })
            .collect();
        format!("{{{}}}", words.join(", "))
    }

    /// PE `slot`'s shared multiplexer for the top: its sources' concatenation, count and select
    /// bits; `None` without one.
    fn shared_sources(&self, slot: usize) -> Option<(String, usize, u32)> {
        let r = self.routes.as_ref()?;
        let list = &r.shared[slot];
        (!list.is_empty()).then(|| (self.source_words(list), list.len(), self.lane_select_bits(slot)[2]))
    }

    /// Bits of the exact intermediate of PE `slot`'s fixed-point unit
    /// ([`build::intermediate_bits`] over the shifts of its program); 64 for binary32 PEs.
    pub fn intermediate_bits(&self, slot: usize) -> u32 {
        let p = &self.pes[slot];
        match &p.fix {
            Some(img) if p.mac => build::mac_intermediate_bits(
                self.word_bits,
                img.words.iter().map(|&w| robovec_ir::machine::FixShifts::from_word(w)),
            ),
            Some(img) => build::intermediate_bits(
                self.word_bits,
                p.is_mul,
                img.words.iter().map(|&w| robovec_ir::machine::FixShifts::from_word(w)),
            ),
            None => 64,
        }
    }

    /// Each PE's control word, in slot order: per cycle its instruction word with each address field cut
    /// to the PE memory's address bits (`[0,pa)` read A, `[pa,2pa)` read B, `[2pa,3pa)` write-0
    /// address, `[3pa,4pa)` write-1 address, then we0, we1, issue valid, sub), its write-port
    /// selects (the `xbar` image's, each one less: 0-based in [`Design::lane_select_bits`]
    /// bits, 0 where the port does not write), its buffer instruction (`bufi`), its output
    /// capture (`capt`) and, on fixed-point PEs, its shift word (`fix` cut to the PE's shifts,
    /// [`FixField`]; on an ADD PE an op whose `b` is the finer operand reads A and B swapped), in
    /// that order from bit 0, then on a PE with fused multiply-adds ([`PeImages::mac`]) the read
    /// address C (`pa` bits), the negate-product bit and the mac bit (the instruction's
    /// `[4aw+4, 5aw+6)`). The separate images are the same fields one memory each (the
    /// manifest's `memories`); the HDL reads the word from the design's control memory
    /// ([`Design::control_lanes`]), at bit [`Control::offset`].
    pub fn controls(&self) -> Vec<Control> {
        let (offsets, _) = self.control_offsets();
        offsets
            .into_iter()
            .enumerate()
            .map(|(slot, offset)| {
                let (pa, width) = self.control_width(slot);
                let (pb, po, fix) = self.control_fields(slot);
                Control { pa, pb, po, fix, select_bits: self.lane_select_bits(slot), width, offset }
            })
            .collect()
    }

    /// The bit of the design's control word where each PE's word starts (indexed by slot: the
    /// widths of the PEs before it, [`Design::control_width`]), and the word's width in bits.
    pub fn control_offsets(&self) -> (Vec<u32>, u32) {
        let mut at = 0u32;
        let offsets = (0..self.pes.len())
            .map(|slot| {
                let o = at;
                at += self.control_width(slot).1;
                o
            })
            .collect();
        (offsets, at)
    }

    /// The design's control memory: per cycle every PE's control word ([`Design::controls`])
    /// side by side in slot order, split into lanes of [`Design::control_lane_bits`] (`ctrl0`,
    /// `ctrl1`, …; bit 0 of the word in lane 0), each one block-RAM memory addressed by the
    /// program counter. Every PE steps through the same cycle, so the PEs share the lanes: a
    /// block holds whole lanes of the family's widest word at any depth, where one memory per
    /// PE wasted the rest of its last block (WALK-MAN's 50-bit words at 299 cycles took three
    /// 20-bit-wide M10K a PE, two and a half shared).
    pub fn control_lanes(&self) -> Vec<Image> {
        let depth = self.cycles as usize + 1;
        let mut lanes: Vec<Image> = self
            .control_lane_widths()
            .into_iter()
            .enumerate()
            .map(|(k, width)| Image { name: Design::control_lane_name(k), width, words: vec![0; depth] })
            .collect();
        for (slot, &base) in self.control_offsets().0.iter().enumerate() {
            self.write_control(slot, base, &mut lanes);
        }
        lanes
    }

    /// The widths of the control memory's lanes ([`Design::control_lanes`], without their
    /// words): [`Design::control_lane_bits`] each but the last. Each lane has a word per cycle
    /// `0..=cycles`.
    pub fn control_lane_widths(&self) -> Vec<u32> {
        let (_, width) = self.control_offsets();
        let lane = self.control_lane_bits.max(1);
        (0..width.div_ceil(lane)).map(|k| lane.min(width - k * lane)).collect()
    }

    /// The image name of the control memory's lane `k` (`ctrlK`).
    pub fn control_lane_name(k: usize) -> String {
        format!("ctrl{k}")
    }

    /// Writes PE `slot`'s control word ([`Design::controls`]) at bit `base` of `lanes` (each
    /// [`Design::control_lane_bits`] wide but the last).
    fn write_control(&self, slot: usize, base: u32, lanes: &mut [Image]) {
        let p = &self.pes[slot];
        let aw = self.widths.aw;
        let (pa, _) = self.control_width(slot);
        let (pb, po, fix) = self.control_fields(slot);
        let (bw, ow) = (self.widths.bw, self.widths.ow);
        let lane = self.control_lane_bits.max(1);
        let select_bits = self.lane_select_bits(slot);
        let cycles = p.instr.words.len();
        let mask = |bits: u32| if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 };
        for c in 0..cycles {
            let mut at = base;
            // `bits` low bits of `value` at bit `at` of the word, split where a lane ends
            let mut put = |value: u64, bits: u32| {
                let (mut value, mut bits) = (value & mask(bits), bits);
                while bits > 0 {
                    let (k, off) = ((at / lane) as usize, at % lane);
                    let take = bits.min(lane - off);
                    lanes[k].words[c] |= (value & mask(take)) << off;
                    value = if take >= 64 { 0 } else { value >> take };
                    bits -= take;
                    at += take;
                }
            };
            let w = p.instr.words[c];
            let issues = w >> (4 * aw + 2) & 1 == 1;
            // An ADD PE reads its finer operand at A and the coarser at B (`fix_add_sub` floors
            // one and lifts the other): an op that aligns `a` (`b` the finer) reads them swapped,
            // and the align-b bit of its shift field says which one `sub` negates.
            let swap = match (&p.fix, fix) {
                (Some(img), Some(fx)) => fx.floors && issues && img.words[c] >> 6 & 1 == 0,
                _ => false,
            };
            for k in 0..4 {
                let k_read = if swap && k < 2 { 1 - k } else { k };
                let field = w >> (k_read * aw) & mask(aw);
                debug_assert!(field <= mask(pa), "an address beyond the PE memory's words");
                put(field & mask(pa), pa);
            }
            put(w >> (4 * aw) & 0xf, 4);
            // each select 0-based (`rv_mux` has no "none" code: the write enables say which
            // ports write, and a port that does not write reads its first input)
            let selects = self.image_selects(slot, p.xbar.words[c]);
            for (l, bits) in selects.into_iter().zip(select_bits) {
                put(l.saturating_sub(1), bits);
            }
            // the buffer instruction and the capture word with their addresses cut to pb and po
            let b = p.bufi.words[c];
            debug_assert!(b & mask(2 * bw) <= mask(pb) | mask(pb) << bw, "a buffer address beyond the buffer");
            put(b, pb);
            put(b >> bw, pb);
            put(b >> (2 * bw), 2);
            let o = p.capt.words[c];
            debug_assert!(o & mask(ow) <= mask(po), "an output address beyond the output memory");
            put(o, po);
            put(o >> ow, 1);
            if let (Some(img), Some(fx)) = (&p.fix, fix) {
                // an idle cycle's shift word is 0, maybe outside the issued ops' ranges
                put(if issues { fx.pack(img.words[c]) } else { 0 }, fx.bits());
            }
            if p.mac {
                let rc = w >> (4 * aw + 4) & mask(aw);
                debug_assert!(rc <= mask(pa), "an address beyond the PE memory's words");
                put(rc & mask(pa), pa);
                put(w >> (5 * aw + 4) & 3, 2);
            }
        }
    }

    /// PE `slot`'s buffer-address bits `pb`, output-address bits `po` and shift field in its
    /// control word ([`Control`]).
    pub fn control_fields(&self, slot: usize) -> (u32, u32, Option<FixField>) {
        let p = &self.pes[slot];
        let pb = addr_bits(u64::from(p.buffer_words.max(1))).clamp(1, self.widths.bw.max(1));
        let po = addr_bits(p.out.words.len().max(1) as u64).clamp(1, self.widths.ow.max(1));
        let fix = p.fix.as_ref().map(|_| {
            let r = p.shift_ranges.unwrap_or(build::ShiftRanges::FULL);
            let aligns = !p.is_mul || p.mac;
            let align_bits = if aligns { addr_bits(u64::from(r.align_max) + 1) } else { 0 };
            let span = (i32::from(r.shift_max) - i32::from(r.shift_min)) as u64 + 1;
            let floors = !p.is_mul;
            FixField {
                floors,
                floor_bits: if floors && r.floor_max > 0 { addr_bits(u64::from(r.floor_max) + 1) } else { 0 },
                align_bits,
                align_b: aligns,
                shift_bits: addr_bits(span).max(1),
                shift_min: i32::from(r.shift_min),
            }
        });
        (pb, po, fix)
    }

    /// PE `slot`'s control word without building it: `(pa, width)` of [`Design::controls`], the
    /// bits of each address field and of the whole word.
    pub fn control_width(&self, slot: usize) -> (u32, u32) {
        let p = &self.pes[slot];
        let pa = addr_bits(p.data.words.len().max(1) as u64).min(self.widths.aw);
        let (pb, po, fix) = self.control_fields(slot);
        let selects: u32 = self.lane_select_bits(slot).iter().sum();
        let fields = selects + 2 * pb + 2 + po + 1 + fix.map_or(0, |f| f.bits());
        let mac = if p.mac { pa + 2 } else { 0 };
        (pa, 4 * pa + 4 + fields + mac)
    }

    /// The flip-flops of the design outside its units and memories (`hdl/rv_lib.v`), an upper
    /// estimate: per PE its registered control word ([`Design::control_width`]), four words
    /// (the result, the buffer read fetched a clock early and the result it may bypass to, and a
    /// one-word buffer's register) and 24 bits of flags, shift word and bypass decisions, and the
    /// read register of an output memory in LUT RAM ([`Design::out_in_lutram`]: a word); and the
    /// program counter with `run` and `done`. Counted in bits; the Cyclone V's ALM packs two a
    /// half ([`crate::resources::YosysCells::alm`]).
    pub fn flip_flops(&self) -> u64 {
        let per_pe: u64 = self
            .pes
            .iter()
            .map(|p| {
                let words = 4 + u64::from(self.out_in_lutram(p));
                u64::from(self.control_width(p.slot).1) + words * u64::from(self.word_bits) + 24
            })
            .sum();
        per_pe + u64::from(self.widths.cw) + 2
    }

    /// Every image the design writes: each PE's ([`PeImages::images`], in slot order), then
    /// the control memory's lanes ([`Design::control_lanes`]).
    pub fn images(&self) -> Vec<Image> {
        let mut v: Vec<Image> = self.pes.iter().flat_map(|p| p.images().into_iter().cloned()).collect();
        v.extend(self.control_lanes());
        v
    }

    /// Bits of the output read port's PE select.
    fn pe_bits(&self) -> u32 {
        addr_bits(self.n_pe() as u64)
    }

    /// The generated top `robovec_top` (synthesizable Verilog-2005): control, one `rv_pe` per
    /// PE, the crossbar bus and an output read port (`out_pe`, `out_addr` → `out_data` one clock
    /// later, read after `done`). `dir` prefixes the image file names (`""`: the simulator's working folder).
    pub fn top(&self, dir: &str) -> String {
        let w = self.widths;
        let n = self.n_pe();
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// robovec codegen<fpga>: function `{}`, {} ADD + {} MULTI {} PEs, {} cycles, {} interconnect (generated; do not edit).",
            self.function,
            self.n_add,
            self.n_mul,
            self.pe_kind.as_str(),
            self.cycles,
            self.interconnect().as_str()
        );
        s += "// Ports: start (one clock high while idle) runs the program once; done rises after its last\n";
        s += "// cycle; the outputs are then read through out_pe / out_addr (manifest.json's output map):\n";
        s += "// out_data is the word they named at the previous clock edge (block-RAM output memories).\n";
        s += "// host_* is not provided: new inputs are written into the PE memory images (load map).\n";
        let _ = writeln!(
            s,
            "module robovec_top (\n  input  wire clk,\n  input  wire rst,\n  input  wire start,\n  output wire done,\n  output wire busy,\n  input  wire [{}:0] out_pe,\n  input  wire [{}:0] out_addr,\n  output reg  [31:0] out_data\n);",
            self.pe_bits() - 1,
            w.ow - 1
        );
        let _ = writeln!(s, "  wire run;\n  wire [{0}:0] pc, fetch;\n  assign busy = run;", w.cw - 1);
        let _ = writeln!(
            s,
            "  rv_control #(.CW({}), .CYCLES({})) ctl (.clk(clk), .rst(rst), .start(start), .run(run), .done(done), .pc(pc), .fetch(fetch));",
            w.cw, self.cycles
        );
        let dw = self.word_bits;
        for p in &self.pes {
            let _ = writeln!(s, "  wire [{1}:0] result{0}, buffer{0}, out{0};", p.slot, dw - 1);
        }
        if self.routes.is_some() {
            s += "  // specialised interconnect: each write port multiplexes only the results and buffer reads\n";
            s += "  // its program routes (manifest.json's `routes`; select 0 = no write, i = the i-th source),\n";
            s += "  // and a memory's shared multiplexer (`shared`, src2) is the last input of both its ports\n";
        } else {
            let mut bus: Vec<String> = (0..n).rev().map(|i| format!("buffer{i}")).collect();
            bus.extend((0..n).rev().map(|i| format!("result{i}")));
            let _ = writeln!(
                s,
                "  // crossbar sources: select s = 1..{n} is result s-1, {}..{} is buffer s-{}",
                n + 1,
                2 * n,
                n + 1
            );
            let _ = writeln!(s, "  wire [{}:0] sources = {{{}}};", 2 * dw as usize * n - 1, bus.join(", "));
        }
        // the control memory (`Design::control_lanes`): every PE's control word side by side,
        // one block-RAM lane of `control_lane_bits` bits after the other, read at `fetch`
        let widths = self.control_lane_widths();
        let _ = writeln!(s, "  wire [{}:0] ctrl_word;", widths.iter().sum::<u32>().max(1) - 1);
        let mut at = 0;
        for (k, width) in widths.into_iter().enumerate() {
            let _ = writeln!(
                s,
                "  rv_rom #(.WIDTH({width}), .DEPTH({}), .AW({}), .FILE(\"{dir}{}.hex\")) u_ctrl{k} (.clk(clk), .addr(fetch), .q(ctrl_word[{at} +: {width}]));",
                self.cycles + 1,
                w.cw,
                Design::control_lane_name(k)
            );
            at += width;
        }
        for (p, control) in self.pes.iter().zip(self.controls()) {
            let lat = if p.is_mul { self.lat_mul } else { self.lat_add };
            let f = |i: &Image| format!("\"{dir}{}.hex\"", i.name);
            let (src0, n0, sw0) = self.port_sources(p.slot, 0);
            let (src1, n1, sw1) = self.port_sources(p.slot, 1);
            let (src2, n2, sw2) = self.shared_sources(p.slot).unwrap_or_else(|| (format!("{dw}'h0"), 0, 0));
            let mut fix = match &p.fix {
                Some(_) => {
                    let r = p.shift_ranges.unwrap_or(build::ShiftRanges::FULL);
                    let floor = if p.is_mul { String::new() } else { format!(".RMAX({}), ", r.floor_max) };
                    format!(
                        ".FIX(1), .DW({dw}), .KW({}), {floor}.AMAX({}), .SMIN({}), .SMAX({}), .ONE({}), ",
                        self.intermediate_bits(p.slot),
                        r.align_max,
                        r.shift_min,
                        r.shift_max,
                        self.multiplier_word
                    )
                }
                None => String::new(),
            };
            if self.pe_memory == PeMemory::LiveValueTable {
                fix += ".LVT(1), ";
            }
            if p.mac {
                fix += ".MAC(1), ";
            }
            if self.out_in_lutram(p) {
                fix += ".OUT_LUTRAM(1), ";
            }
            if let Some(fx) = control.fix {
                if fx.floors {
                    fix += &format!(".FRB({}), ", fx.floor_bits);
                }
                fix += &format!(".FAB({}), .FALB({}), .FSB({}), ", fx.align_bits, u8::from(fx.align_b), fx.shift_bits);
            }
            let _ = writeln!(
                s,
                "  rv_pe #({fix}.IS_MUL({mul}), .LAT({lat}), .N0({n0}), .SW0({sw0}), .N1({n1}), .SW1({sw1}), .N2({n2}), .SW2({sw2}), .AW({aw}), .BW({bw}), .OW({ow}),\n        .MEM_DEPTH({md}), .BUF_DEPTH({bd}), .OUT_DEPTH({od}), .PA({pa}), .PB({pb}), .PO({po}), .CTW({ctw}),\n        .DATA_FILE({fd}), .OUT_FILE({fo}))\n    {name} (.clk(clk), .run(run), .ctrl_word(ctrl_word[{off} +: {ctw}]), .src0({src0}), .src1({src1}), .src2({src2}), .result(result{k}), .buf_read(buffer{k}),\n        .out_addr(out_addr), .out_data(out{k}));",
                mul = u8::from(p.is_mul),
                aw = w.aw,
                bw = w.bw,
                ow = w.ow,
                pa = control.pa,
                pb = control.pb,
                po = control.po,
                ctw = control.width,
                off = control.offset,
                md = p.data.words.len().max(1),
                bd = p.buffer_words.max(1),
                od = p.out.words.len().max(1),
                fd = f(&p.data),
                fo = f(&p.out),
                name = p.pe,
                k = p.slot,
            );
        }
        // the output memories read in a clock (block RAM): the PE select is registered with them
        let _ = writeln!(
            s,
            "  reg [{}:0] out_pe_q;\n  initial out_pe_q = 0;\n  always @(posedge clk) out_pe_q <= out_pe;",
            self.pe_bits() - 1
        );
        s += "  always @* begin\n    case (out_pe_q)\n";
        // a narrower word is read out sign-extended to 32 bits
        let extend = |k: usize| match dw {
            32 => format!("out{k}"),
            _ => format!("{{{{{}{{out{k}[{}]}}}}, out{k}}}", 32 - dw, dw - 1),
        };
        for p in &self.pes {
            let _ = writeln!(s, "      {}: out_data = {};", p.slot, extend(p.slot));
        }
        s += "      default: out_data = 32'h0;\n    endcase\n  end\nendmodule\n";
        s
    }

    /// The testbench `testbench` for Icarus Verilog: pulses `start`, waits for `done`, writes
    /// every output memory to `capturedS.hex` and prints `robovec-done CYCLES CLOCKS` (CYCLES =
    /// the last cycle executed, CLOCKS = clocks with `run` high = CYCLES + 1).
    pub fn testbench(&self) -> String {
        let mut s = String::new();
        s += "`timescale 1ns/1ps\n// robovec codegen<fpga> testbench (generated; `simulate` runs it).\nmodule testbench;\n";
        s += "  reg clk = 0, rst = 0, start = 0;\n  wire done, busy;\n  integer clocks = 0;\n";
        let _ = writeln!(
            s,
            "  robovec_top dut (.clk(clk), .rst(rst), .start(start), .done(done), .busy(busy), .out_pe({}'d0), .out_addr({}'d0), .out_data());",
            self.pe_bits(),
            self.widths.ow
        );
        s += "  always #5 clk = ~clk;\n  always @(posedge clk) if (busy) clocks = clocks + 1;\n";
        s += "  initial begin\n    @(negedge clk); start = 1; @(negedge clk); start = 0;\n    while (!done) @(negedge clk);\n";
        for p in &self.pes {
            let out = if self.out_in_lutram(p) { "g_out_lutram" } else { "g_out_bram" };
            let _ = writeln!(s, "    $writememh(\"captured{}.hex\", dut.{}.{out}.u_out.mem);", p.slot, p.pe);
        }
        s += "    $display(\"robovec-done %0d %0d\", clocks - 1, clocks);\n    $finish;\n  end\n";
        let _ = writeln!(
            s,
            "  initial begin\n    #(64'd10 * {});\n    $display(\"robovec-timeout\");\n    $finish;\n  end\nendmodule",
            u64::from(self.cycles) + 16
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn address_bits() {
        assert_eq!([addr_bits(1), addr_bits(2), addr_bits(3), addr_bits(2048), addr_bits(2049)], [1, 1, 2, 11, 12]);
        // crossbar of the seed's 8 PEs: 17 selects → 5 bits
        assert_eq!(addr_bits(2 * 8 + 1), 5);
    }
}
