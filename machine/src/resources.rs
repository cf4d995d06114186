//! The resource estimate of a design: ALM / M10K / DSP against the device, and the time per
//! evaluation at the target clock (`DIR/resources.json`, the report's `fpga` entry).
//!
//! Three parts are added:
//! - **Logic** (crossbar multiplexers, control, buffers, output memories, address decoding):
//!   Yosys `synth_intel_alm -family cyclonev -noflatten` on the generated top with the FP units
//!   and the M10K memories as black boxes (`hdl/synth_stubs.v`), see "Hierarchical synthesis"
//!   below. Yosys reports Mistral cells, not ALMs; ALMs are packed as Quartus would at best: a
//!   6-input LUT fills an ALM, two smaller LUTs or two arithmetic bits share one, and an ALM
//!   holds two registers; a Yosys MLAB cell (32 × 1 bit) is half an ALM of a 640-bit MLAB, so
//!   `alm = max(LUT6 + ⌈(LUT2…LUT5 + ARITH)/2⌉, ⌈FF/2⌉) + ⌈MLAB/2⌉`. Yosys' DSP cells
//!   count as DSP blocks (`MISTRAL_MUL27X27` one, `MISTRAL_MUL18X18` half, `MISTRAL_MUL9X9`
//!   a third). Without `yosys` (or with `resources=estimate`) the
//!   logic is the target's analytic model of a design in its family's Yosys flow
//!   (`design_logic`, [`design_logic_alm`]: per write port by its multiplexer inputs, per PE by
//!   its buffer words, at the design's word; measured and checked against Yosys as
//!   [`crate::target::Family::design_logic`] says, at or above it) plus `pe_word_alm` per PE-memory
//!   word and `output_word_alm` per output word; a target without `design_logic` (the ECP5)
//!   keeps the seed-form model ([`crate::target`], seed Table 1.4):
//!   `crossbar_alm · n_pe · writes · 2n_pe + pe_memory_alm · n_pe + control_alm +
//!   output_word_alm · output words` (a specialised interconnect, [`crate::design::routes`]:
//!   `crossbar_alm` times its multiplexer inputs, [`Routes::mux_inputs`], in place of the first
//!   term). The last term is 0 on the built-in targets: the output memories are block RAM
//!   (`rv_out_mem`, counted with the memories below; they were 32-bit registers with an
//!   asynchronous read multiplexer, 16 ALM a word on the DE10-Nano, until issue 49 — on the
//!   Jeep's `dirdyna` at 20 + 20 PEs, Yosys' logic fell from 24,246 to 21,393 ALM). With
//!   fixed-point PEs of narrower words (`word_bits` < 32, issue 49) the multiplexer and
//!   output-word terms take `word_bits / 32` of those costs.
//! - **FP units**: the target's per-unit costs (seed §1.3.1 / Table 1.4: ADD PE 360 ALM, 2 DSP;
//!   MULTI PE 100 ALM, 3 DSP) times the PEs of each type; fixed-point PEs per PE: where Yosys
//!   runs, its count of the PE's unit ([`yosys_unit_cells`]: each distinct configuration of
//!   `hdl/fix_units.v` mapped once, `units_from: "yosys"`), else the fit by their word,
//!   intermediate widths and shifts ([`fixed_unit`]).
//! - **Memories**: every PE memory, instruction, crossbar, buffer-instruction and capture memory,
//!   and the output memory of each PE that holds outputs, as M10K blocks from its size ([`crate::target::m10k_blocks`] by the block configurations,
//!   [`M10kFit::Configurations`]; PE memories true dual-port).
//!
//! ## Hierarchical synthesis
//! Where the time went: the crossbar was written `sources[32*(sel-1) +: 32]`, a variable
//! part-select of the whole `64·n_pe`-bit bus that Yosys maps (`techmap` of `$shiftx`) as a
//! barrel shifter over the bus, about `64·n_pe · 32 · log2` 2:1 multiplexers per write port
//! before `opt`/`abc` shrink it back to a 32-bit `2n_pe+1`-way multiplexer. At 4 + 4 PEs that
//! was 52 s of CPU (opt_expr 21 %, techmap 16 %); at 8 + 8 the `techmap` of the 32 shifters
//! alone passed 1.6 GB and the run did not finish in 25 min (`abc9` was never the problem: it
//! maps the 4 + 4 design in under a second). Two changes, the Verilog staying functionally the
//! same (the iverilog bit-for-bit tests of `tests/fpga.rs` unchanged):
//! - the write-port multiplexer is its own module `rv_mux` (`hdl/rv_lib.v`): a balanced
//!   tree of 2:1 multiplexers on the bits of `sel - 1`, gated to 0 outside `1..=2n_pe`, which
//!   Yosys packs four data inputs to a LUT6 (17-way × 32 bits: 161 LUT6 + 32 small LUTs, the
//!   barrel-shifter form gave 160 + 33 after minutes); since issue 49 the tree is on the bits
//!   of a 0-based `sel` and ungated (the write enable says whether the port writes), a 2^j-way
//!   port j select bits;
//! - Yosys maps the design without flattening (`-noflatten`): each distinct module once (the
//!   crossbar port is one module for all `2·n_pe` ports; each PE is its own module since its
//!   images differ), then the mapped netlist is flattened only to count its cells (`stat`
//!   sums modules × instances; Yosys 0.23's `stat -json` does not write a nested hierarchy
//!   as valid JSON).
//!
//! Checked against flat synthesis of the same Verilog (Yosys 0.23; logic ALM by the bound
//! above; registers identical): Segway `dirdyna` at 2 + 2 PEs 2281 hierarchical against 2135
//! flat (+6.8 %: flattening merges each PE's output-memory read with the top's output
//! multiplexer), at 4 + 4 PEs 4548 against 4486 (+1.4 %); the double pendulum at 2 + 2 PEs is
//! `tests/fpga.rs`' check (within 30 %: when the multiplexer module was renamed and given a
//! source bus per port, the same logic, ABC's flat mapping of the pendulum moved from 933 to
//! 1193 ALM and the hierarchical one from 996 to 949: the tool's spread, not the method's).
//! The barrel-shifter form flattened gave 4402 at 4 + 4.
//! Yosys CPU times on the 2-core development machine (wall times were 3–10× longer: the machine
//! was shared with other builds), Segway `dirdyna`: 2 + 2 PEs 16 s (flat 22 s), 4 + 4 19 s
//! (flat 44 s), 8 + 8 27 s, 16 + 16 50 s; WALK-MAN `dirdyna` at 4 + 4, whose 1306 outputs make
//! output memories of about 160 words per PE, 114 s. The time now grows with the PEs and their
//! output memories (the crossbar port is mapped once), not with the square of the PEs; 32 + 32
//! passed 100 s of CPU (docs/fpga.md has the measured table). So `resources=auto` runs Yosys up
//! to 32 + 32 PEs ([`AUTO_YOSYS_MAX_PES`]), the largest N of issue 12's table.
//!
//! ## Against the seed's Table 1.4 (8 PE: 4 ADD + 4 MULTI)
//! The seed totals 4413 ALM, 120 M10K, 20 DSP for its 23-dof railway bogie (987 cycles). The
//! bogie is not in the corpus; the Segway `dirdyna` placed on the same configuration
//! (`place<pe=4>`, 720 cycles, 6.0 µs at 120 MHz) measures, with Yosys 0.23:
//! **6388 ALM, 88 M10K, 20 DSP** (fits: 15 % / 16 % / 18 % of the device).
//! - *DSP*: 20, equal by construction (the FP units are the seed's per-unit costs).
//! - *ALM*: +45 % (6388 against 4413). The FP units are the seed's (1840 ALM); the rest, 4548 ALM
//!   from Yosys (3578 LUT6, 1673 smaller LUTs, 106 arithmetic bits, 4016 registers, 160 MLAB
//!   slices) against the seed's 2573 (crossbar 2080 + PE memories 24 + the 469 the table does
//!   not itemise), is 1.8×: (a) our crossbar has two 17-way 32-bit multiplexers per PE memory
//!   (one per write port, 16 in all, about 180 ALM each), where the seed reports 110–150 ALM
//!   per PE for its multiplexers; (b) the buffers and output memories are read in the cycle
//!   they are addressed (store-then-read in one clock), so they are registers and MLAB slices
//!   (with their address decoding and output multiplexers), where the seed spends one M10K per
//!   buffer and has no output memories; (c) the packing bound above is pessimistic against
//!   Quartus' fitter, which packs two LUTs of up to 8 inputs in total per ALM and retimes.
//! - *M10K*: −27 % (88 against 120), and differently spread: instruction memories 6 each
//!   (a 721 × 52 ROM: the 52-bit word needs 6 blocks in any configuration; the seed reports
//!   3–4, below its own bit count ⌈48128/10240⌉ = 5), crossbar 1 per PE memory (8 against the
//!   seed's 20), buffer instructions and captures 1 each, PE memories 2 each because they hold
//!   only the 64 words the placement uses (the seed's fixed 2048 × 32 takes 7, which we agree
//!   with for a full memory), buffers none (MLABs).
//!
//! The PE memory's depth is the words the placement uses (rounded up to what the blocks hold),
//! not the target's 2048: a placement that uses fewer words takes fewer M10K.

use std::path::PathBuf;
use std::process::Command;

use serde::Serialize;

use crate::design::build::ShiftRanges;
#[cfg(doc)]
use crate::design::routes::Routes;
use crate::design::{Design, HDL_LIBRARY, SYNTH_STUBS};
use crate::pnr::PnrFigures;
use crate::target::{m10k_blocks, Family, M10kFit, PeMemory, Target, Units};

/// Cost of one unit in device resources.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct UnitCost {
    /// ALMs.
    pub alm: u64,
    /// DSP blocks.
    pub dsp: u64,
    /// M10K blocks.
    pub m10k: u64,
}

/// What the estimate needs from the target (see [`crate::target`]; built by [`cost_model`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CostModel {
    /// Target name.
    pub target: String,
    /// The target's FPGA family: the units of every figure, its block-RAM configurations and
    /// how PE memories are built.
    pub family: Family,
    /// Device capacity: ALMs, M10K blocks, DSP blocks.
    pub capacity: UnitCost,
    /// One ADD PE's floating-point unit.
    pub fp_add: UnitCost,
    /// One MULTI PE's floating-point unit.
    pub fp_mul: UnitCost,
    /// One fixed-point ADD PE's unit (issue 49; the target's `fix_pe.add`).
    pub fix_add: UnitCost,
    /// One fixed-point MULTI PE's unit (`fix_pe.mul`).
    pub fix_mul: UnitCost,
    /// Analytic logic (without Yosys): ALMs per (PE-memory write port × crossbar source).
    pub crossbar_alm: f64,
    /// Analytic logic: ALMs per PE memory.
    pub pe_memory_alm: f64,
    /// Analytic logic: ALMs per PE-memory word.
    pub pe_word_alm: f64,
    /// Analytic logic: control ALMs.
    pub control_alm: f64,
    /// Analytic logic: ALMs per output-memory word (32 registers).
    pub output_word_alm: f64,
    /// Analytic logic of a generated design in the family's Yosys flow (the target's
    /// `design_logic`): used in place of `crossbar_alm`, `pe_memory_alm` and `control_alm`.
    pub design_logic: Option<crate::target::DesignLogic>,
    /// Write ports per PE memory.
    pub writes: u32,
    /// Clock, MHz.
    pub clock_mhz: f64,
    /// The part `resources=pnr` places for (the target's `pnr`).
    pub pnr: Option<crate::pnr::PnrPart>,
}

/// One memory's M10K count.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MemoryCost {
    /// Image name (`pe0_instr`).
    pub name: String,
    /// Words.
    pub words: u64,
    /// Bits per word.
    pub width: u32,
    /// M10K blocks (0 for a memory in LUT RAM).
    pub m10k: u64,
    /// True for a memory built in the family's LUT RAM ([`crate::design::Design::out_in_lutram`]:
    /// the Cyclone V's MLAB), whose ALMs are logic: Yosys counts its cells, the analytic
    /// estimate [`lutram_alm`] of it.
    pub lutram: bool,
}

/// ALMs of a `words` × `width` memory in MLAB cells (32 words × 1 bit, two an ALM: Yosys
/// `synth_intel_alm`'s `MISTRAL_MLAB`, [`YosysCells::alm`]): `⌈⌈words/32⌉·width / 2⌉`.
pub fn lutram_alm(words: u64, width: u32) -> u64 {
    (words.max(1).div_ceil(32) * u64::from(width)).div_ceil(2)
}

/// Yosys' cell counts for the logic around the black boxes.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct YosysCells {
    /// 6-input LUTs.
    pub lut6: u64,
    /// LUTs of 2 to 5 inputs.
    pub lut_small: u64,
    /// Arithmetic (carry-chain) bits.
    pub arith: u64,
    /// Registers.
    pub ff: u64,
    /// DSP blocks.
    pub dsp: u64,
    /// MLAB bit slices (Yosys' `MISTRAL_MLAB`: 32 words × 1 bit; an MLAB is a LAB of 10 ALMs
    /// holding 640 bits, so a slice is half an ALM).
    pub mlab: u64,
}

impl YosysCells {
    /// ALMs (see the module doc).
    pub fn alm(&self) -> u64 {
        (self.lut6 + (self.lut_small + self.arith).div_ceil(2)).max(self.ff.div_ceil(2)) + self.mlab.div_ceil(2)
    }
}

/// The estimate (`DIR/resources.json`, the report's `fpga.resources`). The three counts are
/// in the target family's units ([`Resources::units`]: ALM, M10K, DSP blocks on the Cyclone V;
/// LUT4, EBR, MULT18X18D on the ECP5), under SPEC §8's keys `alm`, `m10k`, `dsp`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Resources {
    /// Logic (ALMs on the Cyclone V, LUT4 slots on the ECP5): logic + FP units.
    pub alm: u64,
    /// Block RAMs (M10K, or EBR): memories + FP units.
    pub m10k: u64,
    /// DSP blocks (or MULT18X18D): FP units + logic.
    pub dsp: u64,
    /// What `alm`, `m10k` and `dsp` count.
    pub units: Units,
    /// True when all three are within the device.
    pub fits: bool,
    /// Cycles per evaluation (the program's last cycle, SPEC §4).
    pub cycles: u32,
    /// Clock, MHz: the target's declared clock, or with `resources=pnr` the Fmax nextpnr
    /// measured.
    pub clock_mhz: f64,
    /// Time per evaluation, µs: `cycles / clock_mhz`.
    pub us: f64,
    /// `resources=pnr`: the Fmax of `clk` nextpnr-ecp5 measured after routing, MHz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fmax_mhz: Option<f64>,
    /// Device capacity.
    pub capacity: UnitCost,
    /// `yosys` (logic synthesized), `estimate` (no yosys on PATH: analytic crossbar cost) or
    /// `pnr` (the whole design synthesized, placed and routed: every count is nextpnr's).
    pub logic_from: &'static str,
    /// Logic ALMs (from Yosys or the estimate).
    pub logic_alm: u64,
    /// `yosys` when Yosys mapped every fixed-point unit ([`yosys_unit_cells`]), else
    /// `estimate` (the target's costs or their fit; `pnr`: the flow counted the whole design).
    pub units_from: &'static str,
    /// Yosys' cells when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub yosys: Option<YosysCells>,
    /// `resources=pnr`: the place-and-route figures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pnr: Option<PnrFigures>,
    /// The PEs' units, ALMs / DSP / M10K: the target's per-unit costs (binary32, seed Table
    /// 1.4), the fit of [`fixed_unit`] (fixed point), or Yosys' count of each ([`units_from`]).
    ///
    /// [`units_from`]: Resources::units_from
    pub fp_units: UnitCost,
    /// Per memory M10K.
    pub memories: Vec<MemoryCost>,
}

/// Every block-RAM memory of the design and its blocks in `family`'s configurations. A PE memory
/// is one simple dual-port memory at twice the clock ([`PeMemory::DoublePumped`]) or four simple
/// dual-port banks ([`PeMemory::LiveValueTable`]: the memory's blocks are four banks').
pub fn memory_costs(d: &Design, family: Family) -> Vec<MemoryCost> {
    let mut v = Vec::new();
    let (pe_tdp, banks): (bool, u64) = match d.pe_memory {
        PeMemory::DoublePumped => (false, 1),
        PeMemory::LiveValueTable => (false, 4),
    };
    // the control memory's lanes (`Design::control_lanes`): every PE's instruction, selects,
    // buffer and capture words and shift word, fetched together
    // (their shapes only: their words are not needed to count blocks)
    let words = u64::from(d.cycles) + 1;
    for (k, width) in d.control_lane_widths().into_iter().enumerate() {
        v.push(MemoryCost {
            name: Design::control_lane_name(k),
            words,
            width,
            m10k: m10k_blocks(words, width, M10kFit::Configurations { true_dual_port: false, family }),
            lutram: false,
        });
    }
    for p in &d.pes {
        // the output memory (`rv_out_mem`) of a PE that holds outputs: one simple dual-port
        // memory (a PE without outputs has a constant one, which synthesis removes)
        // (or LUT RAM, `Design::out_in_lutram`: no block)
        let holds = d.outputs.iter().any(|o| o.slot == p.slot) || d.output_loads.iter().any(|l| l.slot == p.slot);
        let out = holds.then_some((&p.out, false, 1));
        let lutram = |img: &crate::design::images::Image| std::ptr::eq(img, &p.out) && d.out_in_lutram(p);
        // a MAC PE's third read (`rv_pe`'s MAC = 1): a copy of the PE memory taking the same
        // writes, one read port used (the live-value table's copy keeps two of its four banks)
        let copy = p.mac.then_some((&p.data, pe_tdp, banks.div_ceil(2), "_c"));
        let out = out.map(|(i, t, b)| (i, t, b, ""));
        for (img, true_dual_port, banks, suffix) in [(&p.data, pe_tdp, banks, "")].into_iter().chain(copy).chain(out) {
            let words = img.words.len().max(1) as u64;
            let lutram = lutram(img);
            v.push(MemoryCost {
                name: format!("{}{suffix}", img.name),
                words,
                width: img.width,
                m10k: if lutram {
                    0
                } else {
                    banks * m10k_blocks(words, img.width, M10kFit::Configurations { true_dual_port, family })
                },
                lutram,
            });
        }
    }
    v
}

/// The cost model of target `t` (its capacities, per-unit costs and clock; the analytic logic
/// per PE from its crossbar, PE memory and control costs, used without Yosys).
pub fn cost_model(t: &Target) -> CostModel {
    let unit = |u: &crate::target::UnitCost| UnitCost {
        alm: u.alm.ceil() as u64,
        dsp: u64::from(u.dsp),
        m10k: u64::from(u.m10k),
    };
    CostModel {
        target: t.name.clone(),
        family: t.family,
        capacity: UnitCost { alm: u64::from(t.alm), m10k: u64::from(t.m10k), dsp: u64::from(t.dsp) },
        fp_add: unit(&t.fp_add),
        fp_mul: unit(&t.fp_mul),
        fix_add: UnitCost {
            alm: t.fix_pe.add.alm.ceil() as u64,
            dsp: u64::from(t.fix_pe.add.dsp),
            m10k: u64::from(t.fix_pe.add.m10k),
        },
        fix_mul: UnitCost {
            alm: t.fix_pe.mul.alm.ceil() as u64,
            dsp: u64::from(t.fix_pe.mul.dsp),
            m10k: u64::from(t.fix_pe.mul.m10k),
        },
        crossbar_alm: t.crossbar_alm,
        pe_memory_alm: t.pe_memory_alm,
        pe_word_alm: t.pe_word_alm,
        control_alm: t.control_alm,
        output_word_alm: t.output_word_alm,
        design_logic: t.design_logic,
        writes: t.writes,
        clock_mhz: t.clock_mhz,
        pnr: t.pnr.clone(),
    }
}

/// Largest design (ADD + MULTI PEs) that `resources=auto` ([`Logic::Auto`]) gives to Yosys:
/// 32 + 32, the largest N of issue 12's table. Since the crossbar is a tree of 2:1 multiplexers
/// in one module that the hierarchical synthesis maps once (module doc), Yosys' time grows with
/// the PEs and their output memories, not with the square of the PEs: measured Yosys 0.23 CPU
/// times are in the module doc (Segway `dirdyna`: 8 + 8 PEs 27 s, 16 + 16 50 s). Larger designs
/// get the analytic estimate and a note; `resources=yosys` runs Yosys whatever the size.
pub const AUTO_YOSYS_MAX_PES: u32 = 64;

/// Where the logic ALMs come from (`codegen<fpga;resources=auto|yosys|estimate>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Logic {
    /// Yosys when it can be run and the design has at most [`AUTO_YOSYS_MAX_PES`] PEs, else the
    /// analytic estimate.
    Auto,
    /// Yosys at any size; an error when it cannot be run.
    Yosys,
    /// The analytic estimate (deterministic and fast).
    Estimate,
    /// The whole design synthesized (Yosys `synth_ecp5`), placed and routed (nextpnr-ecp5) and
    /// packed into a bitstream (ecppack): measured LUT4, EBR, MULT18X18D and Fmax
    /// ([`crate::pnr`]). ECP5 targets only.
    Pnr,
}

impl Logic {
    /// Every word of `resources=`, in the variants' order.
    pub const WORDS: &'static [&'static str] = &["auto", "yosys", "estimate", "pnr"];

    /// The value's word (`resources=auto`).
    pub const fn as_str(self) -> &'static str {
        match self {
            Logic::Auto => "auto",
            Logic::Yosys => "yosys",
            Logic::Estimate => "estimate",
            Logic::Pnr => "pnr",
        }
    }

    /// The value written `word`, if any.
    pub fn from_word(word: &str) -> Option<Logic> {
        [Logic::Auto, Logic::Yosys, Logic::Estimate, Logic::Pnr].into_iter().find(|l| l.as_str() == word)
    }

    /// True when a design of `n_pes` PEs (ADD + MULTI) gets the analytic estimate without
    /// trying Yosys' hierarchical count: `Estimate`, `Auto` beyond [`AUTO_YOSYS_MAX_PES`], and
    /// `Pnr` (whose figures are the flow's, [`crate::pnr`]).
    pub fn skips_yosys(self, n_pes: u32) -> bool {
        match self {
            Logic::Estimate | Logic::Pnr => true,
            Logic::Auto => n_pes > AUTO_YOSYS_MAX_PES,
            Logic::Yosys => false,
        }
    }
}

/// How Yosys maps the design (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Synthesis {
    /// `synth_intel_alm -noflatten`: each distinct module mapped once, `stat` sums
    /// instances × cells over the hierarchy (the estimate's method).
    Hierarchical,
    /// `synth_intel_alm` flattening the design first (the reference the hierarchical method is
    /// checked against; slow beyond 4 + 4 PEs).
    Flat,
}

/// Words of all output memories (each PE's output memory depth, at least 1).
pub fn output_words(d: &Design) -> u64 {
    d.pes.iter().map(|p| p.out.words.len().max(1) as u64).sum()
}

/// Runs Yosys on the design's top with black boxes, hierarchically (see the module doc);
/// `None` when `yosys` cannot be run.
///
/// # Errors
/// A message when Yosys runs but fails (its last lines), or its statistics do not parse.
pub fn yosys_cells(d: &Design) -> Result<Option<YosysCells>, String> {
    yosys_cells_with(d, Synthesis::Hierarchical)
}

/// Yosys' counts of a design (`codegen<fpga;resources=yosys>`, or `auto` within its limit).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct YosysDesign {
    /// The logic around the black boxes ([`yosys_cells`]).
    pub logic: YosysCells,
    /// Each PE's fixed-point unit by slot ([`yosys_unit_cells`]); `None` with binary32 PEs,
    /// whose units are the target's costs.
    pub units: Option<Vec<YosysCells>>,
}

/// [`yosys_cells`] and [`yosys_unit_cells`] of `d`; `None` when Yosys cannot be run.
///
/// # Errors
/// As [`yosys_cells`].
pub fn yosys_design(d: &Design) -> Result<Option<YosysDesign>, String> {
    let Some(logic) = yosys_cells(d)? else { return Ok(None) };
    Ok(Some(YosysDesign { logic, units: yosys_unit_cells(d)? }))
}

/// [`yosys_cells`] with the mapping chosen.
///
/// # Errors
/// As [`yosys_cells`].
pub fn yosys_cells_with(d: &Design, how: Synthesis) -> Result<Option<YosysCells>, String> {
    let Some(dir) = TempDir::new() else { return Ok(None) };
    let mut files = vec![("synth_stubs.v", SYNTH_STUBS.to_string())];
    files.push(("rv_lib.v", hdl_file("rv_lib.v")));
    files.push(("robovec_top.v", d.top("")));
    // Hierarchical: map each distinct module once, then flatten the mapped netlist (a copy of
    // its cells, seconds) so that `stat -json` has one module: Yosys 0.23's `stat -json` writes
    // a nested hierarchy's instance tree as plain text into the JSON.
    let (map_flag, after_map) = match how {
        Synthesis::Hierarchical => (" -noflatten", "flatten\n"),
        Synthesis::Flat => ("", ""),
    };
    let script = format!(
        "read_verilog synth_stubs.v\nread_verilog rv_lib.v\nread_verilog robovec_top.v\nhierarchy -top robovec_top\n\
         synth_intel_alm -family cyclonev{map_flag} -top robovec_top\n{after_map}tee -q -o stat.json stat -json\n"
    );
    run_yosys(&dir, &files, &script)
}

/// The text of `hdl/NAME` (empty when the library has no such file).
fn hdl_file(name: &str) -> String {
    HDL_LIBRARY.iter().find(|(n, _)| *n == name).map(|x| x.1.to_string()).unwrap_or_default()
}

/// Writes `files` into `dir`, runs Yosys' `script` there, which writes `stat.json`, and parses
/// it; `None` when a file cannot be written or `yosys` cannot be started.
fn run_yosys(dir: &TempDir, files: &[(&str, String)], script: &str) -> Result<Option<YosysCells>, String> {
    for (n, t) in files.iter().map(|(n, t)| (*n, t.as_str())).chain([("synth.ys", script)]) {
        if std::fs::write(dir.0.join(n), t).is_err() {
            return Ok(None);
        }
    }
    let out = match Command::new("yosys").args(["-q", "-s", "synth.ys"]).current_dir(&dir.0).output() {
        Ok(o) => o,
        Err(_) => return Ok(None),
    };
    if !out.status.success() {
        let text = String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
        let tail: Vec<&str> = text.lines().rev().take(8).collect();
        return Err(format!("yosys failed: {}", tail.into_iter().rev().collect::<Vec<_>>().join("\n")));
    }
    let stat =
        std::fs::read_to_string(dir.0.join("stat.json")).map_err(|e| format!("yosys wrote no statistics: {e}"))?;
    parse_stat(&stat).map(Some)
}

/// A fixed-point PE's unit as `rv_pe` instantiates it (`hdl/fix_units.v`): the module and its
/// parameters. The PEs of one configuration have the same unit, which Yosys maps once.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct UnitConfig {
    /// `fix_add_sub`, `fix_mul` or `fix_mac`.
    pub module: &'static str,
    /// The module's parameters by name, in `rv_pe`'s order (`LATENCY` in cycles, widths in
    /// bits, shifts in bits).
    pub params: Vec<(&'static str, i64)>,
}

impl UnitConfig {
    /// The unit of PE `p` of `d` with the parameters `rv_pe` gives it ([`Design::top`]);
    /// `None` for a binary32 PE (its unit is costed from the target, seed Table 1.4).
    pub fn of(d: &Design, p: &crate::design::PeImages) -> Option<UnitConfig> {
        p.fix.as_ref()?;
        let r = p.shift_ranges.unwrap_or(ShiftRanges::FULL);
        let latency = i64::from(if p.is_mul { d.lat_mul } else { d.lat_add }) - 2;
        let (dw, kw) = (i64::from(d.word_bits), i64::from(d.intermediate_bits(p.slot)));
        let (amax, smin, smax, one) =
            (i64::from(r.align_max), i64::from(r.shift_min), i64::from(r.shift_max), i64::from(d.multiplier_word));
        let head = [("LATENCY", latency), ("DW", dw), ("KW", kw)];
        let (module, tail): (&'static str, Vec<(&'static str, i64)>) = match (p.is_mul, p.mac) {
            (true, true) => ("fix_mac", vec![("AMAX", amax), ("SMIN", smin), ("SMAX", smax), ("ONE", one)]),
            (true, false) => ("fix_mul", vec![("SMIN", smin), ("SMAX", smax), ("ONE", one)]),
            (false, _) => {
                ("fix_add_sub", vec![("RMAX", i64::from(r.floor_max)), ("AMAX", amax), ("SMIN", smin), ("SMAX", smax)])
            }
        };
        Some(UnitConfig { module, params: head.into_iter().chain(tail).collect() })
    }

    /// A top module `name` around the unit, every port of it a port of the top (the unit's
    /// inputs free, so nothing is folded away that its PE might drive).
    fn wrapper(&self, name: &str) -> String {
        let dw = self.params.iter().find(|(n, _)| *n == "DW").map_or(32, |x| x.1);
        let (ports, conn) = match self.module {
            "fix_mac" => (
                "input wire [DW-1:0] a, input wire [DW-1:0] b, input wire [DW-1:0] c, input wire mac, input wire negp, input wire sub, input wire [13:0] sh",
                ".a(a), .b(b), .c(c), .mac(mac), .negp(negp), .sub(sub), .sh(sh)",
            ),
            "fix_mul" => ("input wire [DW-1:0] a, input wire [DW-1:0] b, input wire [13:0] sh", ".a(a), .b(b), .sh(sh)"),
            _ => (
                "input wire [DW-1:0] a, input wire [DW-1:0] b, input wire sub, input wire [19:0] sh",
                ".a(a), .b(b), .sub(sub), .sh(sh)",
            ),
        };
        let params = self.params.iter().map(|(n, v)| format!(".{n}({v})")).collect::<Vec<_>>().join(", ");
        format!(
            "module {name} #(parameter integer DW = {dw}) (input wire clk, {ports}, output wire [DW-1:0] y);\n  {} #({params}) u (.clk(clk), {conn}, .y(y));\nendmodule\n",
            self.module
        )
    }
}

/// Yosys' cells of each PE's fixed-point unit (`resources=yosys`, issue 49): every distinct
/// [`UnitConfig`] of `d` mapped once by `synth_intel_alm` on its own (on as many threads as
/// the machine has cores; a configuration already mapped by this process is not mapped again),
/// indexed by PE slot. The analytic [`fixed_unit`] is a fit within 15 % on typical ADD units;
/// this is the count itself: on the MX-5's `dirdyna` at 81 + 81 PEs (26-bit words) 14,459 ALM
/// in 45 distinct units against the fit's 17,320. The unit's inputs are the wrapper's ports, so
/// the count is the unit's whole logic (in the design its PE may hold some inputs constant).
/// `None` when `d` has binary32 PEs or Yosys cannot be run.
///
/// # Errors
/// A message when Yosys runs but fails, or its statistics do not parse.
pub fn yosys_unit_cells(d: &Design) -> Result<Option<Vec<YosysCells>>, String> {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static MAPPED: OnceLock<Mutex<HashMap<UnitConfig, YosysCells>>> = OnceLock::new();
    let Some(configs) = d.pes.iter().map(|p| UnitConfig::of(d, p)).collect::<Option<Vec<_>>>() else {
        return Ok(None);
    };
    let mapped = MAPPED.get_or_init(|| Mutex::new(HashMap::new()));
    let mut todo: Vec<UnitConfig> = {
        let known = mapped.lock().map_err(|_| "yosys unit cache poisoned")?;
        configs.iter().filter(|c| !known.contains_key(c)).cloned().collect()
    };
    todo.sort();
    todo.dedup();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(todo.len()).max(1);
    let results: Vec<Result<Option<()>, String>> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| -> Result<Option<()>, String> {
                    let Some(dir) = TempDir::new() else { return Ok(None) };
                    let library = [("fp_units.v", hdl_file("fp_units.v")), ("fix_units.v", hdl_file("fix_units.v"))];
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(c) = todo.get(i) else { return Ok(Some(())) };
                        let mut files = library.to_vec();
                        files.push(("unit.v", c.wrapper("robovec_unit")));
                        let script = "read_verilog fp_units.v\nread_verilog fix_units.v\nread_verilog unit.v\n\
                                      synth_intel_alm -family cyclonev -top robovec_unit\ntee -q -o stat.json stat -json\n";
                        let Some(cells) = run_yosys(&dir, &files, script)? else { return Ok(None) };
                        mapped.lock().map_err(|_| "yosys unit cache poisoned")?.insert(c.clone(), cells);
                    }
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap_or_else(|_| Err("a yosys worker panicked".into()))).collect()
    });
    for r in results {
        if r?.is_none() {
            return Ok(None);
        }
    }
    let known = mapped.lock().map_err(|_| "yosys unit cache poisoned")?;
    Ok(configs.iter().map(|c| known.get(c).cloned()).collect())
}

/// Cell counts from `stat -json` (the `design` totals: for a hierarchical design, every
/// module's cells times its instances, black boxes included as cells).
///
/// # Errors
/// A message when the JSON does not have `design.num_cells_by_type`.
pub fn parse_stat(json: &str) -> Result<YosysCells, String> {
    let v: serde_json::Value = serde_json::from_str(json).map_err(|e| format!("yosys statistics: {e}"))?;
    let cells = v
        .pointer("/design/num_cells_by_type")
        .and_then(|c| c.as_object())
        .ok_or("yosys statistics: no design.num_cells_by_type")?;
    let mut y = YosysCells::default();
    // DSP blocks in sixths: a Cyclone V variable-precision block is one 27 × 27 multiplier, two
    // 18 × 18 or three 9 × 9 (Cyclone V Device Handbook, "Variable Precision DSP Blocks")
    let mut sixths = 0;
    for (k, n) in cells {
        let n = n.as_u64().unwrap_or(0);
        match k.as_str() {
            "MISTRAL_ALUT6" => y.lut6 += n,
            "MISTRAL_ALUT2" | "MISTRAL_ALUT3" | "MISTRAL_ALUT4" | "MISTRAL_ALUT5" | "MISTRAL_NOT" => y.lut_small += n,
            "MISTRAL_ALUT_ARITH" => y.arith += n,
            "MISTRAL_FF" => y.ff += n,
            "MISTRAL_MLAB" => y.mlab += n,
            "MISTRAL_MUL9X9" => sixths += 2 * n,
            "MISTRAL_MUL18X18" => sixths += 3 * n,
            k if k.starts_with("MISTRAL_MUL") => sixths += 6 * n,
            _ => {}
        }
    }
    y.dsp = u64::div_ceil(sixths, 6);
    Ok(y)
}

/// Levels of a shifter over `span + 1` shift amounts: ⌈log₂(span + 1)⌉ (0 for one amount).
fn levels(span: i32) -> f64 {
    if span <= 0 {
        0.0
    } else {
        f64::from(32 - (span as u32).leading_zeros())
    }
}

/// The structure of a fixed-point unit (`hdl/fix_units.v`) of `dw`-bit words, a `kw`-bit
/// intermediate and the shifts `r`, in ALM of the Cyclone V: least squares on Yosys 0.23
/// `synth_intel_alm` of the units at `LATENCY` 2 (one-multiplier products) or 3 (split ones):
/// - ADD, in its floored form (`fix_add_sub`, [`crate::design::build::FloorShifts`]; 36
///   configurations of DW 16–32, floors up to 0–62 bits, lifts up to 0–63, roundings of 1 to
///   128 amounts): `1.36·(KW + DW)` (registers, the adder, the rounding's increment)
///   `+ 0.50·KW·Lr` (the floor shifter, `Lr = ⌈log₂(RMAX + 1)⌉` levels)
///   `+ 0.26·KW·La` (the lift shifter, `La = ⌈log₂(AMAX + 1)⌉`)
///   `+ 0.25·(DW + 1)·Ls` (the rounding shifter, `Ls = ⌈log₂(SMAX − SMIN + 1)⌉`)
///   `+ 0.32·DW` when it floors (the carry in of a negated floored operand); from 13 % under to
///   31 % over Yosys, 11 % RMS (docs/fpga.md "ADD units in floored form");
/// - MULTI: `0.38·(KW + DW) + 0.6·(DW + 1)·(Ls − 1)`, plus `1.3·KW` for a product split in four
///   partial products (their sum); within 20 ALM of Yosys where `Ls ≤ 4` (a design's MULTI PEs
///   round by 3 to 9 amounts), 30 % under it at the full range.
fn unit_structure(dw: u32, is_mul: bool, kw: u32, r: ShiftRanges, family: Family) -> f64 {
    let (dw, kw) = (f64::from(dw.min(64)), f64::from(kw.min(64)));
    let ls = levels(i32::from(r.shift_max) - i32::from(r.shift_min));
    if is_mul {
        let split = if dw > f64::from(family.one_multiplier_word()) { 1.3 * kw } else { 0.0 };
        0.38 * (kw + dw) + 0.6 * (dw + 1.0) * (ls - 1.0).max(0.0) + split
    } else {
        let lr = levels(i32::from(r.floor_max));
        let la = levels(i32::from(r.align_max));
        let sticky = if r.floor_max > 0 { 0.32 * dw } else { 0.0 };
        1.36 * (kw + dw) + 0.50 * kw * lr + 0.26 * kw * la + 0.25 * (dw + 1.0) * ls + sticky
    }
}

/// One fixed-point PE's unit for `dw`-bit words, a `kw`-bit exact intermediate
/// ([`crate::design::build::intermediate_bits`]) and the shifts `r` of its program
/// ([`crate::design::build::shift_ranges`]): the target's `fix_pe` cost, which is the 32-bit
/// word's with a 64-bit intermediate and [`ShiftRanges::FULL`], scaled by the unit's structure
/// against that one's (`unit_structure`: registers and adders grow with the widths, each
/// shifter with its levels). On the ECP5 the target's `fix_pe.add` is the reference that
/// scales to Yosys' `synth_ecp5` LUT4 counts of the ADD PEs designs have (the full-range unit
/// itself maps to 3,177 LUT4: its two 6-level shifters over 64 bits cost more in LUT4 than the
/// structure says; a typical WALK-MAN ADD PE, 26-bit words flooring by ≤ 18, lifting by ≤ 1,
/// rounding by 0 … 1, is 435 LUT4 and 157 ALM).
/// A MULTI PE's multipliers follow the family's DSP modes: on the Cyclone V one
/// variable-precision block for a product of words of at most 27 bits (27 × 27 mode: Yosys maps
/// it to one `MISTRAL_MUL27X27`), on the ECP5 one MULT18X18D for words of at most 18 bits;
/// wider products take the target's `fix_pe.mul.dsp` (the four 16 × 16 partial products of
/// `hdl/fix_units.v`).
pub fn fixed_unit(m: &CostModel, dw: u32, is_mul: bool, kw: u32, r: ShiftRanges) -> UnitCost {
    let unit = if is_mul { m.fix_mul } else { m.fix_add };
    let full = unit_structure(32, is_mul, 64, ShiftRanges::FULL, m.family);
    let this = unit_structure(dw, is_mul, kw, r, m.family);
    let alm = (unit.alm as f64 * this / full).ceil().max(0.0) as u64;
    let dsp = if is_mul && unit.dsp > 0 && dw <= m.family.one_multiplier_word() { 1 } else { unit.dsp };
    UnitCost { alm, dsp, m10k: unit.m10k }
}

/// A fixed-point MULTI PE's unit with fused multiply-adds (`fix_mac` in `hdl/fix_units.v`) for
/// `dw`-bit words, a `kw`-bit exact intermediate
/// ([`crate::design::build::mac_intermediate_bits`]) and the shifts `r` of its program: the
/// MULTI unit ([`fixed_unit`]) plus the addend's path — its register, the swap of the aligned
/// term, the alignment shifter (`La = ⌈log₂(AMAX + 1)⌉` levels), the two negations and the
/// `kw`-bit adder — costed like the ADD unit (the target's `fix_pe.add` scaled by
/// `unit_structure`) at `2.48·KW + 0.46·KW·La` structure units: on the Cyclone V
/// `2.4·KW + 0.45·KW·La` ALM, fitted to Yosys 0.23 `synth_intel_alm` of `fix_mac` less `fix_mul`
/// at `LATENCY = 2`, 27-bit words, rounding by 25 to 30 bits (KW 64: 155, 278, 317 ALM more for
/// AMAX 0, 15, 47; KW 56, AMAX 15: 268), within 13 % of those. The same DSP blocks as the
/// product's.
pub fn fixed_mac_unit(m: &CostModel, dw: u32, kw: u32, r: ShiftRanges) -> UnitCost {
    let mul = fixed_unit(m, dw, true, kw, r);
    let full = unit_structure(32, false, 64, ShiftRanges::FULL, m.family);
    let kwf = f64::from(kw.min(64));
    let adder = 2.48 * kwf + 0.46 * kwf * levels(i32::from(r.align_max));
    let alm = (m.fix_add.alm as f64 * adder / full).ceil().max(0.0) as u64;
    UnitCost { alm: mul.alm + alm, dsp: mul.dsp, m10k: mul.m10k }
}

/// The logic of design `d` by the family's Yosys-flow figures `l`, in the family's units
/// ([`crate::target::DesignLogic`]: each write port by its multiplexer inputs, each PE by its
/// buffer words, at the design's word bits), at least half its flip-flops ([`Design::flip_flops`]:
/// the packing bound of a design too small for its logic to fill the ALMs its registers need);
/// without the per-word terms.
pub fn design_logic_alm(d: &Design, l: &crate::target::DesignLogic) -> f64 {
    // each write port by its inputs (the shared output included), and each shared multiplexer
    let ports = (0..d.n_pe()).flat_map(|slot| {
        let shared = d.shared_inputs(slot) as u64;
        (0..2).map(move |port| d.port_inputs(slot, port) as u64).chain((shared > 0).then_some(shared))
    });
    let luts = l.alm(d.word_bits, ports, d.pes.iter().map(|p| p.buffer_words));
    // a small design's ALMs are set by its registers, two a half ALM (the packing bound's)
    luts.max(d.flip_flops().div_ceil(2) as f64)
}

/// The estimate for `d` under `m`, with Yosys' cells when it ran: its logic in place of the
/// analytic model's, and its fixed-point units' cells in place of [`fixed_unit`]'s fit.
pub fn estimate(d: &Design, m: &CostModel, yosys: Option<YosysDesign>) -> Resources {
    // each PE's unit: binary32 ones the target's, fixed-point ones by their word and intermediate
    let unit = |p: &crate::design::PeImages| match (d.pe_kind, p.is_mul) {
        (crate::design::PeKind::Binary32, false) => m.fp_add,
        (crate::design::PeKind::Binary32, true) => m.fp_mul,
        (crate::design::PeKind::Fixed, true) if p.mac => {
            fixed_mac_unit(m, d.word_bits, d.intermediate_bits(p.slot), p.shift_ranges.unwrap_or(ShiftRanges::FULL))
        }
        (crate::design::PeKind::Fixed, is_mul) => {
            fixed_unit(m, d.word_bits, is_mul, d.intermediate_bits(p.slot), p.shift_ranges.unwrap_or(ShiftRanges::FULL))
        }
    };
    let measured = yosys.as_ref().and_then(|y| y.units.as_ref());
    let units: Vec<UnitCost> = match measured {
        Some(cells) => cells.iter().map(|c| UnitCost { alm: c.alm(), dsp: c.dsp, m10k: 0 }).collect(),
        None => d.pes.iter().map(unit).collect(),
    };
    let fp = units.into_iter().fold(UnitCost { alm: 0, dsp: 0, m10k: 0 }, |a, u| UnitCost {
        alm: a.alm + u.alm,
        dsp: a.dsp + u.dsp,
        m10k: a.m10k + u.m10k,
    });
    let units_from = if measured.is_some() { "yosys" } else { "estimate" };
    let yosys = yosys.map(|y| y.logic);
    let memories = memory_costs(d, m.family);
    let mem_m10k: u64 = memories.iter().map(|c| c.m10k).sum();
    let (logic_from, logic_alm, logic_dsp) = match &yosys {
        Some(y) => ("yosys", y.alm(), y.dsp),
        None => {
            let n = d.n_pe() as f64;
            // The multiplexers and output words are costed for 32-bit words: a narrower word
            // (fixed-point PEs, `word_bits`) takes its share.
            let word = f64::from(d.word_bits) / 32.0;
            // the memories in LUT RAM (Yosys counts their cells when it runs)
            let lutram: u64 = memories.iter().filter(|c| c.lutram).map(|c| lutram_alm(c.words, c.width)).sum();
            let words = m.pe_word_alm * d.pes.iter().map(|p| p.data.words.len().max(1) as f64).sum::<f64>()
                + m.output_word_alm * output_words(d) as f64 * word
                + lutram as f64;
            let a = match m.design_logic {
                // the family's Yosys flow, port by port and PE by PE
                Some(l) => design_logic_alm(d, &l) + words,
                // a design has two write ports per PE memory (`codegen<fpga>` refuses other targets)
                None => m.crossbar_alm * d.mux_inputs() as f64 * word + m.pe_memory_alm * n + m.control_alm + words,
            };
            ("estimate", a.ceil() as u64, 0)
        }
    };
    let alm = logic_alm + fp.alm;
    let m10k = mem_m10k + fp.m10k;
    let dsp = logic_dsp + fp.dsp;
    Resources {
        alm,
        m10k,
        dsp,
        units: m.family.units(),
        fits: alm <= m.capacity.alm && m10k <= m.capacity.m10k && dsp <= m.capacity.dsp,
        cycles: d.cycles,
        clock_mhz: m.clock_mhz,
        us: f64::from(d.cycles) / m.clock_mhz,
        fmax_mhz: None,
        capacity: m.capacity,
        logic_from,
        logic_alm,
        units_from,
        yosys,
        pnr: None,
        fp_units: fp,
        memories,
    }
}

/// The estimate `r` with place and route's figures in place of its counts (`resources=pnr`):
/// logic, block RAM and multipliers as nextpnr counted them (the whole design: `logic_alm` is
/// all of it and `fp_units` zero), fit as placed and within the device, and the time at the
/// measured Fmax (the declared clock when the design was not placed). `memories` stays the
/// analytic count of each memory's blocks.
pub fn with_pnr(r: Resources, m: &CostModel, p: PnrFigures) -> Resources {
    let clock_mhz = p.fmax_mhz.unwrap_or(m.clock_mhz);
    Resources {
        alm: p.lut4,
        m10k: p.ebr,
        dsp: p.mult18,
        fits: p.placed && p.lut4 <= m.capacity.alm && p.ebr <= m.capacity.m10k && p.mult18 <= m.capacity.dsp,
        clock_mhz,
        us: f64::from(r.cycles) / clock_mhz,
        fmax_mhz: p.fmax_mhz,
        logic_from: "pnr",
        logic_alm: p.lut4,
        units_from: "pnr",
        fp_units: UnitCost { alm: 0, dsp: 0, m10k: 0 },
        pnr: Some(p),
        ..r
    }
}

/// A folder under the system's temporary folder, removed on drop.
pub(crate) struct TempDir(pub(crate) PathBuf);

impl TempDir {
    pub(crate) fn new() -> Option<TempDir> {
        use std::sync::atomic::{AtomicU32, Ordering};
        static N: AtomicU32 = AtomicU32::new(0);
        let base = std::env::temp_dir();
        for _ in 0..16 {
            let p = base.join(format!("robovec-yosys-{}-{}", std::process::id(), N.fetch_add(1, Ordering::Relaxed)));
            if std::fs::create_dir(&p).is_ok() {
                return Some(TempDir(p));
            }
        }
        None
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// True when `yosys` can be started.
pub fn yosys_available() -> bool {
    Command::new("yosys").arg("-V").output().map(|o| o.status.success()).unwrap_or(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alm_packing_bound() {
        let y = YosysCells { lut6: 10, lut_small: 5, arith: 2, ff: 20, dsp: 0, mlab: 0 };
        // 10 + ⌈7/2⌉ = 14 vs ⌈20/2⌉ = 10
        assert_eq!(y.alm(), 14);
        let y = YosysCells { ff: 41, ..y };
        assert_eq!(y.alm(), 21);
        // 3 MLAB slices of 32 bits: ⌈3/2⌉ = 2 ALMs
        let y = YosysCells { mlab: 3, ..y };
        assert_eq!(y.alm(), 23);
    }

    #[test]
    fn stat_json_cells() {
        let s = r#"{"design": {"num_cells_by_type": {"MISTRAL_ALUT6": 3, "MISTRAL_ALUT2": 1, "MISTRAL_ALUT5": 2,
            "MISTRAL_FF": 7, "MISTRAL_MUL27X27": 1, "fp_mul": 4}}}"#;
        let y = parse_stat(s).unwrap();
        assert_eq!(y, YosysCells { lut6: 3, lut_small: 3, arith: 0, ff: 7, dsp: 1, mlab: 0 });
        assert!(parse_stat("{}").is_err());
    }
}
