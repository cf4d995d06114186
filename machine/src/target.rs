//! The target description: one record of the device every pass places for, sizes against and
//! converts cycles with (issue 12). Selected once on the command line (`-target=de10-nano` or
//! `-target=FILE.json`) and carried by the pass context; a pass parameter (`lat-add=…`) only
//! overrides it where given.
//!
//! Two records describe the machine, with distinct roles: [`Target`] is the *device* (latencies,
//! write ports, memory sizes, capacities, per-unit costs, clock); the *PE array* a placement is
//! made for ([`robovec_ir::placement::PeArray`]: PE counts, latencies, write ports, buffers) is
//! what the IR carries, built from the device by [`Target::pe_array`].
//!
//! # The built-in `de10-nano` (seed ch. 1, SPEC §1 and §5)
//! | field | value | source |
//! |---|---|---|
//! | `latencies.add` | 12 cycles = 10 stages + 2 | seed §1.3: ADD IP of 10 stages (Table 1.1, 178 MHz) + 2 cycles of crossbar and write; SPEC §1 |
//! | `latencies.mul` | 7 cycles = 5 stages + 2 | seed §1.3: MULTI IP of 5 stages (Table 1.2, 199 MHz) + 2; SPEC §1 |
//! | `latencies.div`, `latencies.call` | 12 cycles | on the ADD side (SPEC §1; the seed has neither) |
//! | `writes` | 2 write ports per PE memory per cycle | seed §1.1.2 (M10K: 2 ports, double-pumped) |
//! | `pe_words` | 2048 words | seed §1.3.1 ("our PE memory contains 2048 addresses", 11 address bits, 7 M10K) |
//! | `buffer_words` | 16 words | seed §1.3.1 ("we use 16 addresses to save the results") |
//! | `instr_words` | 65 536 words | the depth of the instruction memories the top may generate (a 16-bit cycle counter); the seed's 987-cycle design used 1024-word memories (48 128 bits, §1.3.1); what a deeper memory costs is counted in M10K by [`Target::estimate`] |
//! | `instr_width` | 52 bits | seed §1.3.1 (two read and two write addresses of 11 bits as 3 hex digits, enables, add/sub bit) |
//! | `clock_mhz` | 120 MHz | seed §1.3 and §1.3.2 (see below) |
//! | `alm`, `m10k`, `dsp` | 41 910 ALM, 553 M10K, 112 DSP | the DE10-Nano's Cyclone V SE 5CSEBA6U23I7 as Quartus' fitter counts it, the denominators of the seed's Table 1.4 (`4413/41910`, `120/553`, `20/112`); Intel's *Cyclone V Device Overview* (CV-51001, SE A6 row) gives the 112 variable-precision DSP blocks and the 10-Kbit M10K (its family table rounds ALM and block counts slightly differently; the fitter's usable counts are the ones a fit is judged against) |
//! | `m10k_bits` | 10 240 bits | Intel, *Cyclone V Device Overview*: M10K = 10 Kbit blocks |
//! | `fp_add` | 360 ALM, 2 DSP, 0 M10K per ADD PE | seed Table 1.4, row "PE ADD" (Quartus figures of the 8-PE design) |
//! | `fp_mul` | 100 ALM, 3 DSP, 0 M10K per MULTI PE | seed Table 1.4, row "PE MULTI" |
//! | `pe_memory_alm` | 3 ALM per PE memory | seed Table 1.4, row "PE Memory" |
//! | `crossbar_alm` | 8.125 ALM per (PE-memory write port × crossbar source) | seed Table 1.4, row "Interconnections": 2080 ALM for 8 PE memories × 2 write ports (one multiplexer each, 16 in all, §1.3.1) × 16 sources (8 results + 8 buffer reads) |
//! | `control_alm` | 469 ALM | seed Table 1.4: the total (4413) minus the rows (4·360 + 4·100 + 8·3 + 2080 = 3944): cycle counter, start/done and glue the table does not itemise |
//! | `datapath.dsp_modes` | 3 × (9×9), 2 × (18×19), 1 × (27×27) multipliers per DSP block | Intel, *Cyclone V Device Overview* (CV-51001), "Variable-Precision DSP Block": each block is "independent three 9 x 9, two 18 x 18, or one 27 x 27 multipliers"; the device handbook (vol. 1, "Variable Precision DSP Blocks") names the 18-bit mode 18 × 19 |
//! | `datapath.fix_alm_per_bit` | 0.5 ALM per bit of a fixed-point adder | Cyclone V device handbook, "Adaptive Logic Module": an ALM in arithmetic mode has two dedicated full adders, so a `w`-bit carry chain takes `w/2` ALM |
//! | `datapath.fp64_add` | 886 ALM, 0 DSP | Intel, *Floating-Point IP Cores User Guide* (UG-01058), "FP_FUNCTIONS Resource Utilization": double-precision Add on Arria V (the same 28 nm ALM and variable-precision DSP block as Cyclone V; its single-precision Add is the seed's 360 ALM) |
//! | `datapath.fp64_mul` | 250 ALM, 4 DSP | estimate: a 53 × 53 mantissa product tiles into four 27 × 27 blocks (the "54 × 54: four blocks" row of Intel's variable-precision DSP tables); ALM 2.5 × the seed's binary32 MULTI (exponent, rounding and normalisation twice as wide, plus the tiles' adder). No datasheet figure at hand |
//! | `datapath.convert_alm` | 100 ALM per conversion | estimate: a conversion between fixed and floating point (or binary32 and binary64) is a leading-zero count and a barrel shift of the word, of the order of the seed's MULTI PE logic (100 ALM) |
//! | `fix_pe.add` | latency 3 cycles = 1 stage + 2; 477 ALM, 0 DSP | issue 49: the floored sum and its rounding (`hdl/fix_units.v`, `fix_add_sub`: the finer operand floored, the coarser lifted, the sum rounded by the few bits left, [`crate::design::build::FloorShifts`]): the sum registered, its rounding computed in the next clock straight into the PE's result register (the issue's "1–2 stages"; until the units were sized to their shifts a second, empty stage delayed the rounded result by a clock for nothing: every register-to-register path is the same without it; declared for the DE10-Nano, whose clock the M10K sets; on the ECP5-85F nextpnr measures the design, docs/fpga.md); ALM from Yosys 0.23 `synth_intel_alm` of that module at `LATENCY = 2` with 32-bit words, KW = 64 and any shift (`RMAX = 62`, `AMAX = 63`, `SMIN = −64`, `SMAX = 63`: [`crate::design::build::ShiftRanges::FULL`]) by [`crate::resources`]' packing bound; a design's PEs are sized to their own shifts and widths (`resources::fixed_unit`: a typical WALK-MAN ADD PE, 26-bit words flooring by ≤ 18 and rounding by 0 … 1, 157 ALM, where the aligned form took 240) |
//! | `fix_pe.mul` | latency 4 cycles = 2 stages + 2; 299 ALM, 2 DSP | a 32 × 32 signed product as four registered 16 × 16 partial products (four 18 × 19 multipliers, two per Cyclone V variable-precision block: 2 blocks), their sum registered, and the rounding shift (any shift) into the result register; a product that is one DSP multiplier is registered and rounded: 3 cycles ([`FixPe::latencies_for`]); ALM from Yosys as above at `LATENCY = 3` (41 LUT6, 474 smaller LUTs, 41 carry bits; 4 `MISTRAL_MUL18X18`); a 27-bit MULTI PE rounding by 24 to 26 bits, as the Jeep's, is one 27 × 27 block and 36 ALM |
//! | `output_word_alm` | 0 ALM per output-memory word | not in the seed (its outputs are read from the PE memories); the FPGA back end's output memories are block RAM with a registered read port (`rv_out_mem`), counted as M10K blocks, so they take no logic a word. (Until issue 49 they were 32-bit registers read asynchronously: 16 ALM a word, the slope Yosys measured per PE, [`crate::resources`].) The key stays for a design whose output words cost logic; optional in a JSON target (default 0) |
//! | `design_logic` | 0.35 ALM per multiplexer input bit, 0.4 per write-port bit, 1.35 per PE bit, 1.2 per further buffer-word bit | not the seed's: Yosys 0.23 `synth_intel_alm` of robovec's generated designs, which the FPGA back end's analytic estimate predicts in place of the seed-form `crossbar_alm`, `pe_memory_alm` and `control_alm` (Quartus' figures of the seed's design, below Yosys' of these designs); measured and fitted as [`Family::design_logic`] says |
//!
//!
//! The `datapath` record (issue 48 item 5, `precision<target=fpga>`) costs a datapath of one
//! operator per op in each value's own format, not the PE array; its fields and their use are in
//! [`Datapath`]. It is optional in a JSON target (every field defaults to the row above).
//!
//! ## The clock
//! Seed §1.3: the M10K is limited to 240 MHz on the DE10-Nano and the PE memory runs at twice the
//! PE clock (two memory cycles per PE cycle: read, then write, §1.1.2), so the PE clock is at
//! most 120 MHz; the ADD/MULTI couple (10, 5) was chosen so that the PEs (178 / 199 MHz,
//! Table 1.3) are not the limit. §1.3.2 names the two clocks CLK120 and CLK240 ("respectively …
//! 120 and 240 MHz") and the conclusion calls 120 MHz the design's "theoretical maximal
//! frequency". The design as built reached only about 50 MHz on CLK240 (§1.3.2; the conclusion's
//! "two clock design which limited the frequency of 50 MHz"), i.e. 25 MHz of PE clock, because
//! CLK120 was derived from CLK240's edges. The built-in target takes **120 MHz**, the clock the
//! architecture is designed for and that a top with a proper PLL pair can run at; the as-built
//! 25 MHz is `examples/targets/de10-nano-as-built.json`.
//!
//! # The built-in `ecp5-85f` (issue 49 item 4)
//! The Lattice ECP5-85F (LFE5U-85F, CABGA381), the device of the open flow: Yosys `synth_ecp5`,
//! nextpnr-ecp5 and ecppack ([`crate::pnr`], `codegen<fpga;resources=pnr>`). Family
//! [`Family::Ecp5`]: `alm` counts LUT4 slots, `m10k` EBR blocks, `dsp` MULT18X18D multipliers.
//! Its clock and unit costs are Yosys' and nextpnr's measurements of robovec's own Verilog
//! (YoWASP Yosys 0.70 and nextpnr 0.11.1, docs/fpga.md), not a datasheet's; with
//! `resources=pnr` every figure of a design is measured instead.
//!
//! | field | value | source |
//! |---|---|---|
//! | `family` | `ecp5` | |
//! | `alm`, `m10k`, `dsp`, `m10k_bits` | 83 640 LUT4, 208 EBR, 156 MULT18X18D, 18 432 bits | Lattice FPGA-DS-02012, *ECP5 and ECP5-5G Family Data Sheet*, LFE5U-85 column (84K LUTs, 208 sysMEM blocks of 18 Kbit, 156 18 × 18 multipliers); 83 640 is nextpnr's count of `TRELLIS_COMB` slots on the device |
//! | `pnr` | `85k`, `CABGA381` | nextpnr-ecp5's `--85k` and the package of the ECP5 evaluation board and the ULX3S |
//! | `clock_mhz` | 80 MHz | declared, for estimates without place and route: fixed-point designs of the double pendulum placed and routed at 75–88 MHz (binary32 ones at 18.5 MHz: `fp_units.v`'s combinational cores); `resources=pnr` replaces it by the measured Fmax |
//! | `latencies`, `fix_pe.*.latency` | as the DE10-Nano's | the same Verilog units and pipeline (SPEC §1's + 2) |
//! | `pe_words` | 512 | a PE memory as four simple dual-port banks of one EBR each (512 × 36, `PDPW16KD`) and its live-value table ([`PeMemory::LiveValueTable`]) |
//! | `fp_add`, `fp_mul` | 1 675 LUT4; 1 261 LUT4 + 4 MULT18X18D | Yosys `synth_ecp5` of `fp_add_sub` (`LATENCY = 10`) and `fp_mul` (5) alone: LUT4 + 2 × CCU2C |
//! | `fix_pe.add`, `fix_pe.mul` | 1 400 LUT4; 2 129 LUT4 + 4 MULT18X18D | Yosys `synth_ecp5` (LUT4 + 2 × CCU2C): `fix_mul` of the full range at 3; `fix_add_sub` (floored form) the reference that scales ([`crate::resources`]) to the ADD PEs designs have (seven configurations of 16–32-bit words: 309 to 978 LUT4, a typical WALK-MAN ADD PE 435; the full-range unit itself is 3 177); a 27-bit MULTI PE rounding by 24 to 26 bits is 230 LUT4 |
//! | `pe_memory_alm`, `pe_word_alm` | 314 LUT4 + 4.1 LUT4 per word | Yosys of `rv_pe_mem_lvt` at 64, 512 and 1 024 words (575, 2 403, 4 445 LUT4): the bypass and bank choice, and the live-value table (a bit a word, two write and two read ports) in logic |
//! | `crossbar_alm` | 60 LUT4 per multiplexer input | Yosys of `rv_mux` with 17 sources (1 011 LUT4 + 5 CCU2C: 60 a source; 9 sources: 44) |
//! | `output_word_alm` | 0 | the DE10-Nano's: output memories are block RAM (EBR) |
//! | `control_alm` | 469 | the DE10-Nano's |
//! | `datapath` | 9 × 9 (two a block), 18 × 18; 1 LUT4 a bit of adder; binary64 units 3 500 LUT4 (add), 2 500 LUT4 + 9 MULT18X18D (mul); conversion 200 LUT4 | the multiplier modes of the sysDSP slice (FPGA-DS-02012, "sysDSP"); a CCU2C adds two bits in two LUT4 slots; the binary64 and conversion figures are estimates scaled from the binary32 units above (no measurement) |
//!
//! # The JSON format (`-target=FILE.json`)
//! One object, every key required except `family` (default `cyclone-v`), `pnr` (ECP5 only),
//! `pe_word_alm` (default 0), `output_word_alm` (default 0), `design_logic` (default: the
//! family's, [`Family::design_logic`]), `latencies.div` and
//! `latencies.call` (default: the `add` latency, as they run on ADD PEs), `datapath` (each
//! of its fields defaults to the DE10-Nano's, the table above) and `fix_pe` (the DE10-Nano's
//! when left out); an unknown key
//! anywhere is an error, as is a value that makes no sense (zero latency, ports, words, width
//! or capacity; a clock that is not a positive finite number; a negative or non-finite cost):
//!
//! ```json
//! {
//!   "name": "de10-nano",
//!   "clock_mhz": 120.0,
//!   "latencies": { "add": 12, "mul": 7, "div": 12, "call": 12 },
//!   "writes": 2,
//!   "pe_words": 2048,
//!   "buffer_words": 16,
//!   "instr_words": 65536,
//!   "instr_width": 52,
//!   "alm": 41910,
//!   "m10k": 553,
//!   "dsp": 112,
//!   "m10k_bits": 10240,
//!   "fp_add": { "alm": 360, "dsp": 2, "m10k": 0 },
//!   "fp_mul": { "alm": 100, "dsp": 3, "m10k": 0 },
//!   "pe_memory_alm": 3,
//!   "crossbar_alm": 8.125,
//!   "control_alm": 469,
//!   "output_word_alm": 0,
//!   "datapath": {
//!     "dsp_modes": [{ "a": 9, "b": 9, "per_block": 3 }, { "a": 18, "b": 19, "per_block": 2 },
//!                   { "a": 27, "b": 27, "per_block": 1 }],
//!     "fix_alm_per_bit": 0.5,
//!     "fp64_add": { "alm": 886, "dsp": 0, "m10k": 0 },
//!     "fp64_mul": { "alm": 250, "dsp": 4, "m10k": 0 },
//!     "convert_alm": 100
//!   },
//!   "fix_pe": {
//!     "add": { "latency": 3, "alm": 477, "dsp": 0, "m10k": 0 },
//!     "mul": { "latency": 4, "alm": 299, "dsp": 2, "m10k": 0 }
//!   }
//! }
//! ```
//!
//! # The analytic resource estimate ([`Target::estimate`])
//! For `n_add` ADD and `n_mul` MULTI PEs (`n_pe = n_add + n_mul`) running `cycles` cycles:
//! - ALM = `n_add·fp_add.alm + n_mul·fp_mul.alm` plus the logic around the units. In the
//!   seed's form (a target without `design_logic`): `n_pe·pe_memory_alm
//!   + crossbar_alm·n_pe·writes·(2·n_pe) + control_alm` (the crossbar: one multiplexer per
//!   PE-memory write port over the `2·n_pe` sources, each result and each buffer read). With
//!   `design_logic` (the built-ins' Cyclone V; [`Target::estimate_with`]): robovec's crossbar
//!   design as Yosys maps it, `DW·(n_pe·writes·(mux_input_bit·2·n_pe + mux_port_bit)
//!   + Σ_PEs (pe_bit + buffer_word_bit·(b − 1)))` for `DW`-bit words and each PE's `b` buffer
//!   words (`place` and `sweep` give the placement's word and buffers);
//! - DSP = `n_add·fp_add.dsp + n_mul·fp_mul.dsp`;
//! - M10K = per PE, `fp_*.m10k` plus each of its memories as ⌈bits / m10k_bits⌉ (at least 1;
//!   [`M10kFit::Bits`], see "M10K blocks" below):
//!   PE memory `pe_words × 32`, buffer memory `buffer_words × 32`, instruction memory
//!   `(cycles + 1) × instr_width`, buffer instructions `(cycles + 1) × (2·bw + 2)`, crossbar
//!   memory `(cycles + 1) × writes·sw`, with `bw = ⌈log2 buffer_words⌉` and
//!   `sw = ⌈log2(2·n_pe + 1)⌉` (the encoding of issue 12). Memories are sized by the target
//!   (the fixed 2048-word PE memory of Table 1.4), not by what a placement uses.
//!
//! On the seed's own configuration (4 + 4 PE, 987 cycles, §1.3.1) the seed's form gives 4413
//! ALM and 20 DSP (Table 1.4, by construction of `control_alm`) and 128 M10K against the
//! table's 120: the bit count puts a 988 × 52-bit instruction memory in 6 blocks where the seed
//! reports 3–4, and the crossbar memories in 8 where it reports 20. Those are Quartus' figures
//! of the seed's design; robovec's design maps to more under Yosys (a crossbar input of 32 bits
//! is 11.2 ALM, not 8.125), so the built-in target estimates with `design_logic` (5,258 ALM for
//! the same 4 + 4 PEs with one buffer word each), which does not fall below Yosys: a design
//! `place` and `sweep` say fits does. The FPGA back end replaces this estimate by its own
//! design's ([`crate::resources`]: its routes and buffers) or Yosys' figures for one N; `sweep`
//! uses it to say which N fit.
//!
//! # M10K blocks ([`m10k_blocks`])
//! One function counts the M10K blocks of a memory for both estimates, with the model as a
//! parameter ([`M10kFit`]), because the two estimates count differently and their figures are
//! kept:
//! - [`M10kFit::Bits`] (this module's analytic estimate, [`Target::estimate`], so `place`'s
//!   report and `sweep`): ⌈words·width / m10k_bits⌉, at least 1 — the bit count, a lower bound
//!   that follows the target's `m10k_bits`;
//! - [`M10kFit::Configurations`] (the FPGA back end's estimate of a generated design,
//!   [`crate::resources::memory_costs`], so `resources.json`): the fewest blocks over the
//!   Cyclone V M10K configurations (Cyclone V device handbook, "Embedded Memory Blocks": 8K×1,
//!   4K×2, 2K×5, 1K×10, 512×20, 256×40), 0 for an empty memory; a true dual-port memory (the PE
//!   memory) cannot use ×40. The configurations are the Cyclone V's whatever the target's
//!   `m10k_bits`.
//!
//! A block of a configuration holds at most 10 240 bits, so on the DE10-Nano the
//! configurations never give fewer blocks than the bit count; they give more where no
//! configuration packs the memory: shallow and wide (100 × 52: 1 by bits, 2 by
//! configurations, as 256×40 needs two blocks side by side), or widths that fill a
//! configuration badly (1500 × 6: 1 by bits, 2 by configurations). They agree on the seed's
//! memories, 2048 × 32 (7), 16 × 32 (1) and 988 × 52 (6), and on every memory 5, 10, 20 or 40
//! bits wide (2K×5, 1K×10, 512×20 and 256×40 hold exactly 10 240 bits; ×40 simple dual-port
//! and ROM only).

use robovec_ir::analysis::Latencies;
use robovec_ir::placement::PeArray;

/// The FPGA family of a target: what its `alm`, `m10k` and `dsp` capacities and costs count
/// ([`Family::units`]), the block-RAM configurations a memory maps onto
/// ([`M10kFit::Configurations`]) and how the design builds its PE memories
/// ([`Family::pe_memory`]). JSON: `"family": "cyclone-v"` (the default) or `"ecp5"`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Family {
    /// Intel Cyclone V (the DE10-Nano): ALM, M10K (10 Kbit), variable-precision DSP blocks.
    #[default]
    CycloneV,
    /// Lattice ECP5: LUT4 slots (nextpnr's `TRELLIS_COMB`, a `CCU2C` carry cell taking two),
    /// EBR (DP16KD, 18 Kbit), MULT18X18D multipliers.
    Ecp5,
}

/// The names of a family's three resources, as reports print them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Units {
    /// Logic: `ALM` or `LUT4`.
    pub logic: &'static str,
    /// Block RAM: `M10K` or `EBR`.
    pub bram: &'static str,
    /// Multipliers: `DSP` (a variable-precision block) or `MULT18X18D`.
    pub dsp: &'static str,
}

/// The logic of a generated design (`codegen<fpga>`) as the family's Yosys flow maps it, in
/// the family's logic units per bit of the design's word (`word_bits`: 32 for binary32 PEs,
/// the fixed-point PEs' word): what the FPGA back end's analytic estimate
/// ([`crate::resources::estimate`] without Yosys) and [`Target::estimate_with`] (`place`,
/// `sweep`) charge instead of the seed's per-PE figures (`crossbar_alm`, `pe_memory_alm`,
/// `control_alm`), which a target without it keeps. For a word of `DW` bits:
/// `Σ_ports DW·(mux_input_bit·k + mux_port_bit) + Σ_PEs DW·(pe_bit + buffer_word_bit·(b − 1))`
/// over each write port's `k` multiplexer inputs and each PE's `b` buffer words, plus the
/// target's `pe_word_alm` per PE-memory word and `output_word_alm` per output word.
/// JSON: `design_logic` (optional; a target without it takes its family's,
/// [`Family::design_logic`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignLogic {
    /// Per multiplexer input of a write port, per bit (`rv_mux`).
    pub mux_input_bit: f64,
    /// Per write port, per bit (the tree's rounding up to whole LUTs).
    pub mux_port_bit: f64,
    /// Per PE, per bit: its logic outside the unit, the multiplexer and the memories (the
    /// buffer's first word, the result and operand registers, the control decoding) and its
    /// share of the top's output read multiplexer.
    pub pe_bit: f64,
    /// Per buffer word beyond the first, per bit (the buffer's registers or MLAB and its read
    /// multiplexer).
    pub buffer_word_bit: f64,
}

impl DesignLogic {
    /// The logic of a design of `word_bits`-bit words whose write ports have `ports`
    /// multiplexer inputs each and whose PEs' buffers hold `buffers` words each (a buffer of 0
    /// words costs as one), in the family's units.
    pub fn alm(
        &self,
        word_bits: u32,
        ports: impl IntoIterator<Item = u64>,
        buffers: impl IntoIterator<Item = u32>,
    ) -> f64 {
        let ports: f64 = ports.into_iter().map(|k| self.mux_input_bit * k as f64 + self.mux_port_bit).sum();
        let pes: f64 = buffers.into_iter().map(|b| self.pe_bit + self.buffer_word_bit * f64::from(b.max(1) - 1)).sum();
        f64::from(word_bits) * (ports + pes)
    }
}

/// How a design builds each PE memory (two reads and two writes per cycle, `hdl/rv_mem.v`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeMemory {
    /// One block RAM at twice the PE clock (seed §1.1.2 and §1.3: the M10K double-pumped, at
    /// most 240 MHz, so the PE clock at most 120 MHz; `rv_pe_mem`), in simple dual-port mode: a
    /// write and a read each half cycle give the two writes and two reads of a PE cycle (the
    /// same-cycle bypass is `rv_pe_mem`'s logic), so the ×40 configuration serves words of up
    /// to 40 bits 256 deep in one block. (Until issue 49's clusters it was counted in true
    /// dual-port mode, ×20 at most: a 26-bit PE memory took two blocks for the same accesses.)
    DoublePumped,
    /// Four simple dual-port banks (one per write port × read port) and a live-value table
    /// (LaForest & Steffan, FPGA 2010; `rv_pe_mem_lvt`): for block RAMs that cannot run at twice
    /// the clock, the ECP5's.
    LiveValueTable,
}

impl Family {
    /// The logic of a generated design in this family's Yosys flow ([`DesignLogic`]), where it
    /// was measured: the Cyclone V's (Yosys 0.23 `synth_intel_alm`, the ALM packing bound of
    /// [`crate::resources`]). `rv_mux` alone at 16-bit words and 2 to 64 inputs is at most
    /// 0.35 ALM per input bit and 0.05 per port bit (0.34 and −0.19 by least squares; 0.4 a port
    /// bit before its selects became 0-based and ungated, issue 49); the rest,
    /// fitted on the Jeep's fixed-point designs at 4 + 4 to 36 + 42 PEs and its binary32 ones at
    /// 8 + 8 (crossbar and specialised), 1.35 ALM per PE bit and 1.2 per further buffer word
    /// bit. The model is above Yosys on all of them: by 1–7 % from 8 + 8 PEs up, by 18 % at
    /// 4 + 4 (docs/fpga.md, "The estimate against Yosys"). The ECP5: `None` (the seed-form
    /// model with its LUT4 figures, above what nextpnr places; `resources=pnr` measures it).
    pub const fn design_logic(self) -> Option<DesignLogic> {
        match self {
            Family::CycloneV => {
                Some(DesignLogic { mux_input_bit: 0.35, mux_port_bit: 0.05, pe_bit: 1.35, buffer_word_bit: 1.2 })
            }
            Family::Ecp5 => None,
        }
    }

    /// The resource names of the family.
    pub const fn units(self) -> Units {
        match self {
            Family::CycloneV => Units { logic: "ALM", bram: "M10K", dsp: "DSP" },
            Family::Ecp5 => Units { logic: "LUT4", bram: "EBR", dsp: "MULT18X18D" },
        }
    }

    /// The family's word (`cyclone-v`, `ecp5`).
    pub const fn as_str(self) -> &'static str {
        match self {
            Family::CycloneV => "cyclone-v",
            Family::Ecp5 => "ecp5",
        }
    }

    /// The widest fixed-point word whose product is one DSP multiplier of the family, bits:
    /// the Cyclone V's variable-precision block in 27 × 27 mode (Intel, *Cyclone V Device
    /// Overview*; Yosys maps it to one `MISTRAL_MUL27X27`), the ECP5's MULT18X18D (FPGA-DS-02012,
    /// "sysDSP"). Wider words take the target's `fix_pe.mul` (partial products).
    pub const fn one_multiplier_word(self) -> u32 {
        match self {
            Family::CycloneV => 27,
            Family::Ecp5 => 18,
        }
    }

    /// The deepest memory a design builds in the family's LUT RAM rather than in a block RAM,
    /// words: the Cyclone V's MLAB, a LAB of 10 ALMs used as 32 words × 20 bits (Cyclone V device
    /// handbook, "Embedded Memory Blocks"; Yosys `synth_intel_alm` maps such a memory to
    /// `MISTRAL_MLAB` cells of 32 words × 1 bit, two an ALM). The PE output memories that fit
    /// it may be built there (`rv_out_lutram`, issue 49): a few ALMs each instead of an M10K each
    /// (WALK-MAN at 57 + 57 PEs: 114 of its 549 M10K), as far as the design's block RAM needs
    /// (`codegen<fpga>`: `emit`'s choice). 0 on the ECP5: its output memories stay in block RAM.
    pub const fn lutram_words(self) -> u32 {
        match self {
            Family::CycloneV => 32,
            Family::Ecp5 => 0,
        }
    }

    /// How its designs build a PE memory.
    pub const fn pe_memory(self) -> PeMemory {
        match self {
            Family::CycloneV => PeMemory::DoublePumped,
            Family::Ecp5 => PeMemory::LiveValueTable,
        }
    }

    /// The block-RAM configurations `(depth, width)` of one block, and the widest a true
    /// dual-port memory may use: Cyclone V M10K 8K×1 … 256×40 (true dual-port up to ×20; Cyclone V
    /// device handbook, "Embedded Memory Blocks"); ECP5 DP16KD 16K×1 … 1K×18 true dual-port and
    /// 512×36 as the pseudo dual-port PDPW16KD (Lattice TN1264, *ECP5 and ECP5-5G Memory Usage
    /// Guide*, tables of DP16KD and PDPW16KD).
    pub const fn bram_configurations(self) -> (&'static [(u64, u64)], u64) {
        match self {
            Family::CycloneV => (&[(8192, 1), (4096, 2), (2048, 5), (1024, 10), (512, 20), (256, 40)], 20),
            Family::Ecp5 => (&[(16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36)], 18),
        }
    }

    /// Bits of the widest word of one block RAM (40 on the Cyclone V's M10K, 256 × 40; 36 on the
    /// ECP5's 512 × 36): the lanes of a design's control memory (`crate::design::Design::control_lanes`),
    /// since every narrower configuration's width divides it.
    pub const fn bram_word(self) -> u32 {
        match self {
            Family::CycloneV => 40,
            Family::Ecp5 => 36,
        }
    }
}

/// What one floating-point unit (with its PE wrapper) costs, per PE (seed Table 1.4).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitCost {
    /// Adaptive logic modules.
    pub alm: f64,
    /// Variable-precision DSP blocks.
    pub dsp: u32,
    /// M10K blocks (outside the PE's memories).
    pub m10k: u32,
}

/// A machine description (see the module doc for every field's source on the DE10-Nano).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Target {
    /// Name (`de10-nano`, or the JSON file's `name`).
    pub name: String,
    /// The FPGA family: what `alm`, `m10k`, `dsp` and the unit costs count (ALM, M10K and DSP
    /// blocks on the Cyclone V; LUT4, EBR and MULT18X18D on the ECP5: [`Family::units`]).
    pub family: Family,
    /// PE clock, MHz (one cycle of the placement = one period).
    pub clock_mhz: f64,
    /// Latencies, cycles from issue to a result written in the target PE memory (SPEC §1).
    pub latencies: Latencies,
    /// Write ports per PE memory per cycle.
    pub writes: u32,
    /// Words (binary32) per PE memory.
    pub pe_words: u32,
    /// Words (binary32) per buffer memory.
    pub buffer_words: u32,
    /// Largest instruction-memory depth, words (one word per cycle `0..=cycles`).
    pub instr_words: u32,
    /// Bits of an instruction-memory word.
    pub instr_width: u32,
    /// Device capacity, ALM.
    pub alm: u32,
    /// Device capacity, M10K blocks.
    pub m10k: u32,
    /// Device capacity, DSP blocks.
    pub dsp: u32,
    /// Bits of one M10K block.
    pub m10k_bits: u32,
    /// Cost of one ADD PE's floating-point adder/subtractor.
    pub fp_add: UnitCost,
    /// Cost of one MULTI PE's floating-point multiplier.
    pub fp_mul: UnitCost,
    /// ALM of the logic around one PE memory.
    pub pe_memory_alm: f64,
    /// ALM per word of a PE memory (the live-value table of [`PeMemory::LiveValueTable`], one
    /// bit a word with two write and two read ports, in logic; 0 on the Cyclone V).
    pub pe_word_alm: f64,
    /// ALM per PE-memory write port per crossbar source.
    pub crossbar_alm: f64,
    /// ALM of the control (cycle counter, start/done) shared by the whole design.
    pub control_alm: f64,
    /// ALM per output-memory word (32-bit registers the outputs are captured in; the FPGA back
    /// end's analytic estimate, which knows the output words per PE).
    pub output_word_alm: f64,
    /// The logic of a generated design in the family's Yosys flow, for the FPGA back end's
    /// analytic estimate (`None`: the seed-form figures above).
    pub design_logic: Option<DesignLogic>,
    /// What the operators of a datapath in per-value formats cost (`precision<target=fpga>`).
    pub datapath: Datapath,
    /// The fixed-point PEs (issue 49): their latencies and costs, for a function whose values
    /// are all `fix<w ≤ 32, f>` ([`crate::program::fixed::pe_kind`]).
    pub fix_pe: FixPe,
    /// The part nextpnr-ecp5 places for (`codegen<fpga;resources=pnr>`, [`crate::pnr`]); ECP5
    /// targets only, `None` where the open flow does not go.
    pub pnr: Option<crate::pnr::PnrPart>,
}

/// One fixed-point PE's unit: its latency (cycles from issue to a result written, the `+ 2` of
/// the PE memory read and crossbar registers included, as [`Target::latencies`]) and cost.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixUnit {
    /// Cycles from issue to a result written in the target PE memory (≥ 3: one unit stage).
    pub latency: u32,
    /// Adaptive logic modules.
    pub alm: f64,
    /// DSP blocks.
    pub dsp: u32,
    /// M10K blocks.
    pub m10k: u32,
}

/// The fixed-point PEs of a target (module doc for the DE10-Nano's figures and their sources).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixPe {
    /// The ADD PE's aligned adder/subtractor with its rounding (`hdl/fix_units.v`, `fix_add_sub`).
    pub add: FixUnit,
    /// The MULTI PE's 32 × 32 multiplier with its rounding (`fix_mul`; narrower words:
    /// [`FixPe::latencies_for`] and `resources::fixed_unit`).
    pub mul: FixUnit,
}

impl Default for FixPe {
    /// The DE10-Nano's (module doc).
    fn default() -> Self {
        FixPe {
            add: FixUnit { latency: 3, alm: 477.0, dsp: 0, m10k: 0 },
            mul: FixUnit { latency: 4, alm: 299.0, dsp: 2, m10k: 0 },
        }
    }
}

impl FixPe {
    /// The latencies of a fixed-point PE array (`div`, `call`: the ADD PE's; they have no unit).
    pub fn latencies(&self) -> Latencies {
        Latencies { add: self.add.latency, mul: self.mul.latency, div: self.add.latency, call: self.add.latency }
    }

    /// The latencies of a fixed-point PE array of `word_bits`-bit words on `family`: a product
    /// that is one DSP multiplier ([`Family::one_multiplier_word`]) has no partial products to
    /// sum, so the MULTI PE takes one stage fewer than `mul.latency` (the product, then its
    /// rounding: the ADD PE's two stages; `hdl/fix_units.v`), and never under 3 cycles. With
    /// `mac` (the function has fused multiply-adds, which MULTI PEs compute: issue 49) the
    /// MULTI PE keeps `mul.latency`: the addend is aligned and added in the stage that sums
    /// a wide product's partial products.
    pub fn latencies_for(&self, family: Family, word_bits: u32, mac: bool) -> Latencies {
        let mut l = self.latencies();
        if word_bits <= family.one_multiplier_word() && !mac {
            l.mul = l.mul.saturating_sub(1).max(3);
        }
        l
    }
}

/// One multiplier mode of a DSP block: `per_block` independent `a × b` signed products.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DspMode {
    /// Bits of one operand.
    pub a: u32,
    /// Bits of the other.
    pub b: u32,
    /// Products of this size one block computes.
    pub per_block: u32,
}

/// The cost of the operators of a datapath whose values each have their own format (issue 48
/// item 5, `precision<target=fpga>`): fixed-point words of any width up to 53 bits, binary32 and
/// binary64. Module doc for the DE10-Nano's figures and their sources.
///
/// - A product of `wa`- and `wb`-bit words: [`Datapath::product`] — the fewest DSP blocks over
///   the modes tiling the product (`⌈wa/a⌉·⌈wb/b⌉` products of mode `a × b`, either way round,
///   `per_block` of them a block; fractional when a mode packs several products), plus
///   `fix_alm_per_bit` ALM per bit of the adders summing the tiles when there is more than
///   one. On the Cyclone V this gives ⅓ block for 9 × 9, ½ for 18 × 19, 1 for 27 × 27, 1 for
///   19 × 36, 2 for 36 × 36 and 4 for 54 × 54, Intel's own figures for those sizes.
/// - A `w`-bit fixed-point adder: `fix_alm_per_bit · w` ALM.
/// - Binary32 operators: the target's `fp_add` / `fp_mul` (the seed's PE figures); binary64:
///   `fp64_add` / `fp64_mul`.
/// - A conversion between formats of different kinds: `convert_alm`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Datapath {
    /// Multiplier modes of one DSP block.
    pub dsp_modes: Vec<DspMode>,
    /// ALM per bit of a fixed-point adder (carry chain).
    pub fix_alm_per_bit: f64,
    /// One binary64 adder/subtractor.
    pub fp64_add: UnitCost,
    /// One binary64 multiplier.
    pub fp64_mul: UnitCost,
    /// ALM of one conversion between fixed and floating point, or binary32 and binary64.
    pub convert_alm: f64,
}

impl Default for Datapath {
    /// The DE10-Nano's Cyclone V (module doc).
    fn default() -> Self {
        Datapath {
            dsp_modes: vec![
                DspMode { a: 9, b: 9, per_block: 3 },
                DspMode { a: 18, b: 19, per_block: 2 },
                DspMode { a: 27, b: 27, per_block: 1 },
            ],
            fix_alm_per_bit: 0.5,
            fp64_add: UnitCost { alm: 886.0, dsp: 0, m10k: 0 },
            fp64_mul: UnitCost { alm: 250.0, dsp: 4, m10k: 0 },
            convert_alm: 100.0,
        }
    }
}

impl Datapath {
    /// DSP blocks and ALM of one product of a `wa`-bit and a `wb`-bit signed word (the struct
    /// doc): `(0, 0)` when either is 0 bits (a product by a power of two is a shift).
    pub fn product(&self, wa: u32, wb: u32) -> (f64, f64) {
        if wa == 0 || wb == 0 {
            return (0.0, 0.0);
        }
        let tiles = |m: &DspMode, x: u32, y: u32| u64::from(x.div_ceil(m.a)) * u64::from(y.div_ceil(m.b));
        let best = self
            .dsp_modes
            .iter()
            .filter(|m| m.a > 0 && m.b > 0 && m.per_block > 0)
            .map(|m| {
                let t = tiles(m, wa, wb).min(tiles(m, wb, wa));
                (t as f64 / f64::from(m.per_block), t)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match best {
            Some((dsp, t)) => (dsp, (t - 1) as f64 * f64::from(wa + wb) * self.fix_alm_per_bit),
            // No DSP mode: the product in logic, one adder of `wa + wb` bits per bit of `wb`.
            None => (0.0, f64::from(wb) * f64::from(wa + wb) * self.fix_alm_per_bit),
        }
    }
}

/// The resources a configuration needs, against the target's capacity ([`Target::estimate`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Resources {
    /// ALM (rounded up).
    pub alm: u32,
    /// M10K blocks.
    pub m10k: u32,
    /// DSP blocks.
    pub dsp: u32,
    /// True when all three are within the device's capacity.
    pub fits: bool,
}

/// A target file that cannot be used: unreadable, not JSON of the format, or a senseless value.
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// The file cannot be read.
    #[error("cannot read target file {path}: {source}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// JSON syntax or shape error (unknown field, missing field, wrong type), at a 1-based
    /// line and column.
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The path as given.
        path: String,
        /// Line, 1-based.
        line: usize,
        /// Column, 1-based.
        column: usize,
        /// What serde says.
        message: String,
    },
    /// A value out of its range.
    #[error("{path}: {message}")]
    Value {
        /// The path as given.
        path: String,
        /// The field and why.
        message: String,
    },
}

/// The JSON form of [`Latencies`]: `div` and `call` default to `add`.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LatenciesFile {
    add: u32,
    mul: u32,
    div: Option<u32>,
    call: Option<u32>,
}

/// The JSON form of [`Target`].
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetFile {
    name: String,
    #[serde(default)]
    family: Family,
    clock_mhz: f64,
    latencies: LatenciesFile,
    writes: u32,
    pe_words: u32,
    buffer_words: u32,
    instr_words: u32,
    instr_width: u32,
    alm: u32,
    m10k: u32,
    dsp: u32,
    m10k_bits: u32,
    fp_add: UnitCost,
    fp_mul: UnitCost,
    pe_memory_alm: f64,
    #[serde(default)]
    pe_word_alm: f64,
    crossbar_alm: f64,
    control_alm: f64,
    #[serde(default)]
    output_word_alm: f64,
    #[serde(default)]
    design_logic: Option<DesignLogic>,
    #[serde(default)]
    datapath: Datapath,
    #[serde(default)]
    fix_pe: FixPe,
    #[serde(default)]
    pnr: Option<crate::pnr::PnrPart>,
}

/// How a memory is mapped onto M10K blocks (module doc, "M10K blocks").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum M10kFit {
    /// The bit count: ⌈words·width / block_bits⌉, at least 1 (the analytic estimate,
    /// [`Target::estimate`], with the target's `m10k_bits`).
    Bits {
        /// Bits of one block (the target's `m10k_bits`; 10 240 on the DE10-Nano).
        block_bits: u32,
    },
    /// The fewest blocks over the family's block-RAM configurations
    /// ([`Family::bram_configurations`]; Cyclone V: 8K×1, 4K×2, 2K×5, 1K×10, 512×20, 256×40):
    /// ⌈words/d⌉·⌈width/w⌉ minimised over the configurations `d × w`, 0 for a memory without
    /// words or width (the FPGA back end's estimate, [`crate::resources::memory_costs`]).
    Configurations {
        /// Excludes the configurations wider than the family's true dual-port width (the
        /// Cyclone V's ×40, simple dual-port and ROM only). The generated designs' memories are
        /// all simple dual-port or ROM: the PE memory's two reads and two writes per cycle use
        /// the block's write and read port at twice the clock ([`PeMemory::DoublePumped`]);
        /// either mode gives the seed's 7 M10K for a 2048 × 32 PE memory.
        true_dual_port: bool,
        /// Whose blocks.
        family: Family,
    },
}

/// M10K blocks of a memory of `words` words of `width` bits, under `fit` (the one M10K model
/// of both estimates; module doc, "M10K blocks").
pub fn m10k_blocks(words: u64, width: u32, fit: M10kFit) -> u64 {
    match fit {
        M10kFit::Bits { block_bits } => {
            let bits = words * u64::from(width);
            bits.div_ceil(u64::from(block_bits)).max(1)
        }
        M10kFit::Configurations { true_dual_port, family } => {
            if words == 0 || width == 0 {
                return 0;
            }
            let (configs, tdp_width) = family.bram_configurations();
            configs
                .iter()
                .filter(|&&(_, w)| !(true_dual_port && w > tdp_width))
                .map(|&(d, w)| words.div_ceil(d) * u64::from(width).div_ceil(w))
                .min()
                .unwrap_or(0)
        }
    }
}

/// ⌈log2 n⌉ for n ≥ 1 (0 for n ≤ 1): the address bits of an n-word memory.
pub fn address_bits(n: u32) -> u32 {
    if n <= 1 {
        0
    } else {
        32 - (n - 1).leading_zeros()
    }
}

impl Target {
    /// The names of the built-in targets, for diagnostics.
    pub const BUILT_IN: &'static [&'static str] = &["de10-nano", "ecp5-85f"];

    /// The DE10-Nano of the seed (module doc: every value and its source).
    pub fn de10_nano() -> Target {
        Target {
            name: "de10-nano".into(),
            family: Family::CycloneV,
            clock_mhz: 120.0,
            latencies: Latencies { add: 12, mul: 7, div: 12, call: 12 },
            writes: 2,
            pe_words: 2048,
            buffer_words: 16,
            instr_words: 65536,
            instr_width: 52,
            alm: 41_910,
            m10k: 553,
            dsp: 112,
            m10k_bits: 10_240,
            fp_add: UnitCost { alm: 360.0, dsp: 2, m10k: 0 },
            fp_mul: UnitCost { alm: 100.0, dsp: 3, m10k: 0 },
            pe_memory_alm: 3.0,
            pe_word_alm: 0.0,
            crossbar_alm: 8.125,
            control_alm: 469.0,
            output_word_alm: 0.0,
            design_logic: Family::CycloneV.design_logic(),
            datapath: Datapath::default(),
            fix_pe: FixPe::default(),
            pnr: None,
        }
    }

    /// The Lattice ECP5-85F (LFE5U-85F) of issue 49 item 4, for the open flow (Yosys
    /// `synth_ecp5`, nextpnr-ecp5, ecppack; `codegen<fpga;resources=pnr>`): the module doc,
    /// "The built-in `ecp5-85f`", gives every value and its source.
    pub fn ecp5_85f() -> Target {
        Target {
            name: "ecp5-85f".into(),
            family: Family::Ecp5,
            clock_mhz: 80.0,
            pe_words: 512,
            alm: 83_640,
            m10k: 208,
            dsp: 156,
            m10k_bits: 18_432,
            fp_add: UnitCost { alm: 1675.0, dsp: 0, m10k: 0 },
            fp_mul: UnitCost { alm: 1261.0, dsp: 4, m10k: 0 },
            pe_memory_alm: 314.0,
            pe_word_alm: 4.1,
            crossbar_alm: 60.0,
            design_logic: Family::Ecp5.design_logic(),
            datapath: Datapath {
                dsp_modes: vec![DspMode { a: 9, b: 9, per_block: 2 }, DspMode { a: 18, b: 18, per_block: 1 }],
                fix_alm_per_bit: 1.0,
                fp64_add: UnitCost { alm: 3500.0, dsp: 0, m10k: 0 },
                fp64_mul: UnitCost { alm: 2500.0, dsp: 9, m10k: 0 },
                convert_alm: 200.0,
            },
            fix_pe: FixPe {
                add: FixUnit { latency: 3, alm: 1400.0, dsp: 0, m10k: 0 },
                mul: FixUnit { latency: 4, alm: 2129.0, dsp: 4, m10k: 0 },
            },
            pnr: Some(crate::pnr::PnrPart { device: "85k".into(), package: "CABGA381".into() }),
            // The same Verilog units, pipeline, instruction word and control as the DE10-Nano's:
            // latencies, write ports, buffer and instruction depths, `control_alm`,
            // `output_word_alm` (module doc).
            ..Target::de10_nano()
        }
    }

    /// A built-in target by name (`None`: no such target).
    pub fn built_in(name: &str) -> Option<Target> {
        match name {
            "de10-nano" => Some(Target::de10_nano()),
            "ecp5-85f" => Some(Target::ecp5_85f()),
            _ => None,
        }
    }

    /// Reads a target from JSON text (`path` only names it in errors).
    ///
    /// # Errors
    /// [`TargetError::Syntax`] with line and column for bad JSON, unknown or missing fields and
    /// wrong types; [`TargetError::Value`] for senseless values.
    pub fn from_json(path: &str, text: &str) -> Result<Target, TargetError> {
        let f: TargetFile = serde_json::from_str(text).map_err(|e| TargetError::Syntax {
            path: path.to_string(),
            line: e.line(),
            column: e.column(),
            message: strip_position(&e.to_string()),
        })?;
        let t = Target {
            name: f.name,
            family: f.family,
            clock_mhz: f.clock_mhz,
            latencies: Latencies {
                add: f.latencies.add,
                mul: f.latencies.mul,
                div: f.latencies.div.unwrap_or(f.latencies.add),
                call: f.latencies.call.unwrap_or(f.latencies.add),
            },
            writes: f.writes,
            pe_words: f.pe_words,
            buffer_words: f.buffer_words,
            instr_words: f.instr_words,
            instr_width: f.instr_width,
            alm: f.alm,
            m10k: f.m10k,
            dsp: f.dsp,
            m10k_bits: f.m10k_bits,
            fp_add: f.fp_add,
            fp_mul: f.fp_mul,
            pe_memory_alm: f.pe_memory_alm,
            pe_word_alm: f.pe_word_alm,
            crossbar_alm: f.crossbar_alm,
            control_alm: f.control_alm,
            output_word_alm: f.output_word_alm,
            design_logic: f.design_logic.or(f.family.design_logic()),
            datapath: f.datapath,
            fix_pe: f.fix_pe,
            pnr: f.pnr,
        };
        t.validate().map_err(|message| TargetError::Value { path: path.to_string(), message })?;
        Ok(t)
    }

    /// Reads a target file.
    ///
    /// # Errors
    /// As [`Target::from_json`], plus [`TargetError::Io`].
    pub fn from_file(path: &std::path::Path) -> Result<Target, TargetError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| TargetError::Io { path: shown.clone(), source })?;
        Target::from_json(&shown, &text)
    }

    /// `de10-nano` or a JSON file's path.
    ///
    /// # Errors
    /// As [`Target::from_file`].
    pub fn resolve(spec: &str) -> Result<Target, TargetError> {
        match Target::built_in(spec) {
            Some(t) => Ok(t),
            None => Target::from_file(std::path::Path::new(spec)),
        }
    }

    /// Checks every value makes sense; the message names the field.
    ///
    /// # Errors
    /// `"field: why"`.
    pub fn validate(&self) -> Result<(), String> {
        if self.name.trim().is_empty() {
            return Err("`name` must not be empty".into());
        }
        if self.pnr.is_some() && self.family != Family::Ecp5 {
            return Err(format!(
                "`pnr` (nextpnr-ecp5's device and package) needs `\"family\": \"ecp5\"`, not `{}`",
                self.family.as_str()
            ));
        }
        if !(self.clock_mhz.is_finite() && self.clock_mhz > 0.0) {
            return Err(format!("`clock_mhz` must be a positive number of MHz, got {}", self.clock_mhz));
        }
        let l = &self.latencies;
        for (k, v) in [("add", l.add), ("mul", l.mul), ("div", l.div), ("call", l.call)] {
            if v == 0 {
                return Err(format!("`latencies.{k}` must be at least 1 cycle, got 0"));
            }
        }
        for (k, u) in [("add", &self.fix_pe.add), ("mul", &self.fix_pe.mul)] {
            if u.latency < 3 {
                return Err(format!(
                    "`fix_pe.{k}.latency` must be at least 3 cycles (one unit stage + the PE memory read and crossbar registers), got {}",
                    u.latency
                ));
            }
            if !(u.alm.is_finite() && u.alm >= 0.0) {
                return Err(format!("`fix_pe.{k}.alm` must be a non-negative number, got {}", u.alm));
            }
        }
        let counts = [
            ("writes", self.writes),
            ("pe_words", self.pe_words),
            ("buffer_words", self.buffer_words),
            ("instr_words", self.instr_words),
            ("instr_width", self.instr_width),
            ("alm", self.alm),
            ("m10k", self.m10k),
            ("dsp", self.dsp),
            ("m10k_bits", self.m10k_bits),
        ];
        for (k, v) in counts {
            if v == 0 {
                return Err(format!("`{k}` must be at least 1, got 0"));
            }
        }
        let costs = [
            ("fp_add.alm", self.fp_add.alm),
            ("fp_mul.alm", self.fp_mul.alm),
            ("pe_memory_alm", self.pe_memory_alm),
            ("pe_word_alm", self.pe_word_alm),
            ("crossbar_alm", self.crossbar_alm),
            ("control_alm", self.control_alm),
            ("output_word_alm", self.output_word_alm),
        ];
        let d = &self.datapath;
        let costs = costs.into_iter().chain([
            ("datapath.fix_alm_per_bit", d.fix_alm_per_bit),
            ("datapath.fp64_add.alm", d.fp64_add.alm),
            ("datapath.fp64_mul.alm", d.fp64_mul.alm),
            ("datapath.convert_alm", d.convert_alm),
        ]);
        let logic = self.design_logic.map(|l| {
            [
                ("design_logic.mux_input_bit", l.mux_input_bit),
                ("design_logic.mux_port_bit", l.mux_port_bit),
                ("design_logic.pe_bit", l.pe_bit),
                ("design_logic.buffer_word_bit", l.buffer_word_bit),
            ]
        });
        let costs = costs.chain(logic.into_iter().flatten());
        for (k, v) in costs {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("`{k}` must be a non-negative number of ALM, got {v}"));
            }
        }
        if let Some(m) = d.dsp_modes.iter().find(|m| m.a == 0 || m.b == 0 || m.per_block == 0) {
            return Err(format!(
                "`datapath.dsp_modes`: {m:?} must have operands of at least 1 bit and 1 product a block"
            ));
        }
        Ok(())
    }

    /// The PE array of `n_add` ADD and `n_mul` MULTI PEs on this target (its latencies and
    /// write ports; with buffer memories when `buffer`): what a placement for this device is
    /// made for.
    pub fn pe_array(&self, n_add: u32, n_mul: u32, buffer: bool) -> PeArray {
        PeArray { n_add, n_mul, lat: self.latencies, writes: self.writes, buffer }
    }

    /// Microseconds that `cycles` cycles take at [`Target::clock_mhz`] (`cycles / clock_mhz`).
    pub fn us(&self, cycles: u32) -> f64 {
        f64::from(cycles) / self.clock_mhz
    }

    /// Address bits of a PE memory (⌈log2 pe_words⌉; 11 on the DE10-Nano).
    pub fn pe_address_bits(&self) -> u32 {
        address_bits(self.pe_words)
    }

    /// Address bits of a buffer memory (⌈log2 buffer_words⌉; 4 on the DE10-Nano).
    pub fn buffer_address_bits(&self) -> u32 {
        address_bits(self.buffer_words)
    }

    /// This target with its PE units replaced by the fixed-point PEs' (`fix_pe`: their ALM,
    /// DSP and M10K as `fp_add`/`fp_mul`; issue 49): what [`Target::estimate`] costs a
    /// fixed-point PE array with.
    pub fn with_fixed_units(&self) -> Target {
        let unit = |u: &FixUnit| UnitCost { alm: u.alm, dsp: u.dsp, m10k: u.m10k };
        Target { fp_add: unit(&self.fix_pe.add), fp_mul: unit(&self.fix_pe.mul), ..self.clone() }
    }

    /// The analytic resource estimate of `n_add` ADD and `n_mul` MULTI PEs running `cycles`
    /// cycles with binary32 words and one buffer word a PE ([`Target::estimate_with`]).
    pub fn estimate(&self, n_add: u32, n_mul: u32, cycles: u32) -> Resources {
        self.estimate_with(n_add, n_mul, cycles, 32, &[])
    }

    /// The analytic resource estimate of `n_add` ADD and `n_mul` MULTI PEs running `cycles`
    /// cycles (module doc: the model and its figures against seed Table 1.4), for a crossbar
    /// design of `word_bits`-bit words whose PEs' buffers hold `buffer_words` words (slot
    /// order; a PE not listed, one word). The logic is the seed-form model where the target
    /// has no `design_logic`; with it (the built-ins' Cyclone V), the crossbar design as the
    /// family's Yosys flow maps it: `writes` ports per PE memory of `2·n_pe` multiplexer
    /// inputs, and each PE by its buffer (the figures of [`DesignLogic`]), plus
    /// `pe_word_alm` per PE-memory word of the target.
    pub fn estimate_with(
        &self,
        n_add: u32,
        n_mul: u32,
        cycles: u32,
        word_bits: u32,
        buffer_words: &[u32],
    ) -> Resources {
        let n_pe = u64::from(n_add) + u64::from(n_mul);
        let sources = 2 * n_pe;
        let units = f64::from(n_add) * self.fp_add.alm + f64::from(n_mul) * self.fp_mul.alm;
        let words = n_pe as f64 * self.pe_word_alm * f64::from(self.pe_words);
        let logic = match self.design_logic {
            None => {
                n_pe as f64 * self.pe_memory_alm
                    + self.crossbar_alm * (n_pe * u64::from(self.writes) * sources) as f64
                    + self.control_alm
            }
            Some(l) => {
                let ports = (0..n_pe * u64::from(self.writes)).map(|_| sources);
                let buffers = (0..n_pe).map(|s| buffer_words.get(s as usize).copied().unwrap_or(1));
                l.alm(word_bits, ports, buffers)
            }
        };
        let alm = units + words + logic;
        let dsp = u64::from(n_add) * u64::from(self.fp_add.dsp) + u64::from(n_mul) * u64::from(self.fp_mul.dsp);
        let depth = u64::from(cycles) + 1;
        let bw = self.buffer_address_bits();
        let sw = address_bits(u32::try_from(sources + 1).unwrap_or(u32::MAX));
        // Each memory's count saturates at u32::MAX before the sum (as the figures are u32).
        let fit = M10kFit::Bits { block_bits: self.m10k_bits };
        let blocks = |words: u64, width: u32| m10k_blocks(words, width, fit).min(u64::from(u32::MAX));
        let per_pe = blocks(u64::from(self.pe_words), 32)
            + blocks(u64::from(self.buffer_words), 32)
            + blocks(depth, self.instr_width)
            + blocks(depth, 2 * bw + 2)
            + blocks(depth, self.writes * sw);
        let m10k = n_pe * per_pe
            + u64::from(n_add) * u64::from(self.fp_add.m10k)
            + u64::from(n_mul) * u64::from(self.fp_mul.m10k);
        let sat = |x: u64| u32::try_from(x).unwrap_or(u32::MAX);
        let alm = if alm >= f64::from(u32::MAX) { u32::MAX } else { alm.ceil() as u32 };
        let (m10k, dsp) = (sat(m10k), sat(dsp));
        Resources { alm, m10k, dsp, fits: alm <= self.alm && m10k <= self.m10k && dsp <= self.dsp }
    }
}

impl Default for Target {
    fn default() -> Self {
        Target::de10_nano()
    }
}

/// serde_json appends " at line L column C" to its messages; the diagnostic gives them first.
fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_string(),
        None => msg.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn de10_json() -> String {
        serde_json::to_string_pretty(&Target::de10_nano()).unwrap()
    }

    /// A MULTI PE whose product is one DSP multiplier (27-bit words on the Cyclone V, 18 on the
    /// ECP5) is one stage shorter, never under 3 cycles; the ADD PE and wider words keep theirs.
    #[test]
    fn one_multiplier_words_shorten_the_multi_pe_by_a_stage() {
        let de10 = Target::de10_nano();
        let lat = |t: &Target, w: u32| {
            let l = t.fix_pe.latencies_for(t.family, w, false);
            (l.add, l.mul)
        };
        assert_eq!([lat(&de10, 32), lat(&de10, 28), lat(&de10, 27), lat(&de10, 16)], [(3, 4), (3, 4), (3, 3), (3, 3)]);
        let ecp5 = Target::ecp5_85f();
        assert_eq!([lat(&ecp5, 27), lat(&ecp5, 19), lat(&ecp5, 18)], [(3, 4), (3, 4), (3, 3)]);
        let mut short = Target::de10_nano();
        short.fix_pe.mul.latency = 3;
        assert_eq!(lat(&short, 20), (3, 3), "one unit stage + 2 is the least");
        let mac = |t: &Target, w: u32| t.fix_pe.latencies_for(t.family, w, true).mul;
        assert_eq!(
            [mac(&de10, 27), mac(&de10, 32), mac(&ecp5, 18)],
            [4, 4, 4],
            "a MAC keeps the partial-product stage for its addend"
        );
    }

    #[test]
    fn built_in_round_trips_through_json() {
        let t = Target::from_json("x.json", &de10_json()).unwrap();
        assert_eq!(t, Target::de10_nano());
    }

    #[test]
    fn shipped_example_files_are_the_built_in_and_its_as_built_clock() {
        let file = include_str!("../../examples/targets/de10-nano.json");
        assert_eq!(Target::from_json("de10-nano.json", file).unwrap(), Target::de10_nano());
        let built = include_str!("../../examples/targets/de10-nano-as-built.json");
        let t = Target::from_json("de10-nano-as-built.json", built).unwrap();
        // Seed §1.3.2: CLK240 reached about 50 MHz, so the PE clock (half of it) 25 MHz.
        assert_eq!(t.clock_mhz, 25.0);
        assert_eq!(Target { name: "de10-nano".into(), clock_mhz: 120.0, ..t }, Target::de10_nano());
    }

    #[test]
    fn datapath_defaults_when_absent_and_products_tile_as_intel_counts() {
        // The shipped files have no `datapath`: they get the Cyclone V's (equal to the built-in
        // above); one field given, the others default.
        let mut v: serde_json::Value = serde_json::from_str(&de10_json()).unwrap();
        v["datapath"] = serde_json::json!({ "convert_alm": 50.0 });
        let t = Target::from_json("x.json", &v.to_string()).unwrap();
        assert_eq!(t.datapath, Datapath { convert_alm: 50.0, ..Datapath::default() });
        v["datapath"] = serde_json::json!({ "convert": 50.0 });
        assert!(Target::from_json("x.json", &v.to_string()).unwrap_err().to_string().contains("unknown field"));
        v["datapath"] = serde_json::json!({ "dsp_modes": [{ "a": 0, "b": 9, "per_block": 1 }] });
        assert!(Target::from_json("x.json", &v.to_string()).unwrap_err().to_string().contains("dsp_modes"));
        let d = Datapath::default();
        let dsp = |a, b| d.product(a, b).0;
        // Intel's table of variable-precision DSP usage: 9×9 a third of a block (three a
        // block), 18×19 half, 27×27 one, 19×36 one, 36×36 two, 54×54 four.
        assert!((dsp(9, 9) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(
            (dsp(18, 19), dsp(19, 18), dsp(27, 27), dsp(19, 36), dsp(36, 36), dsp(54, 54)),
            (0.5, 0.5, 1.0, 1.0, 2.0, 4.0)
        );
        assert_eq!(dsp(53, 53), 4.0);
        assert_eq!(d.product(0, 20), (0.0, 0.0));
        // One tile: no adder; four: three adders of 106 bits.
        assert_eq!(d.product(27, 27).1, 0.0);
        assert_eq!(d.product(53, 53).1, 3.0 * 106.0 * 0.5);
    }

    #[test]
    fn div_and_call_default_to_add() {
        let mut v: serde_json::Value = serde_json::from_str(&de10_json()).unwrap();
        let lat = v["latencies"].as_object_mut().unwrap();
        lat.remove("div");
        lat.remove("call");
        lat.insert("add".into(), 9.into());
        let t = Target::from_json("x.json", &v.to_string()).unwrap();
        assert_eq!(t.latencies, Latencies { add: 9, mul: 7, div: 9, call: 9 });
    }

    #[test]
    fn unknown_field_has_line_and_column() {
        let text = "{\n  \"name\": \"x\",\n  \"clok_mhz\": 50\n}";
        match Target::from_json("t.json", text) {
            Err(TargetError::Syntax { line, column, message, .. }) => {
                assert_eq!(line, 3);
                assert!(column >= 3, "{column}");
                assert!(message.contains("unknown field `clok_mhz`"), "{message}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn unknown_nested_field_is_rejected() {
        let text = de10_json().replace("\"mul\": 7", "\"mul\": 7, \"fma\": 3");
        let e = Target::from_json("t.json", &text).unwrap_err().to_string();
        assert!(e.contains("unknown field `fma`"), "{e}");
    }

    #[test]
    fn senseless_values_are_rejected() {
        for (from, to, field) in [
            ("\"add\": 12", "\"add\": 0", "latencies.add"),
            ("\"writes\": 2", "\"writes\": 0", "writes"),
            ("\"pe_words\": 2048", "\"pe_words\": 0", "pe_words"),
            ("\"clock_mhz\": 120.0", "\"clock_mhz\": 0.0", "clock_mhz"),
            ("\"clock_mhz\": 120.0", "\"clock_mhz\": -5.0", "clock_mhz"),
            ("\"crossbar_alm\": 8.125", "\"crossbar_alm\": -1.0", "crossbar_alm"),
        ] {
            let text = de10_json().replace(from, to);
            assert_ne!(text, de10_json(), "{from}");
            match Target::from_json("t.json", &text) {
                Err(TargetError::Value { message, .. }) => assert!(message.contains(field), "{message}"),
                other => panic!("{from}: {other:?}"),
            }
        }
    }

    #[test]
    fn microseconds_at_the_clock() {
        let t = Target::de10_nano();
        // 987 cycles (seed §1.3.1) at 120 MHz: 987 / 120 = 8.225 µs.
        assert!((t.us(987) - 8.225).abs() < 1e-12);
        assert_eq!(t.us(0), 0.0);
    }

    #[test]
    fn address_bits_of_the_seed() {
        assert_eq!(address_bits(2048), 11);
        assert_eq!(address_bits(16), 4);
        assert_eq!(address_bits(17), 5);
        assert_eq!(address_bits(1), 0);
        assert_eq!(Target::de10_nano().pe_address_bits(), 11);
    }

    #[test]
    fn m10k_fits_agree_on_the_seed_memories_and_differ_where_no_configuration_packs() {
        let bits = M10kFit::Bits { block_bits: 10_240 };
        let rom = M10kFit::Configurations { true_dual_port: false, family: Family::CycloneV };
        let tdp = M10kFit::Configurations { true_dual_port: true, family: Family::CycloneV };
        // seed §1.3.1: a 2048 × 32 PE memory takes 7 M10K (2K×5, ⌈32/5⌉ = 7; bits 65536 → 7)
        assert_eq!((m10k_blocks(2048, 32, bits), m10k_blocks(2048, 32, tdp)), (7, 7));
        // a ROM of 988 × 52: 1K×10 → 6 blocks; 256×40 → 4·2 = 8; 512×20 → 2·3 = 6; bits 51376 → 6
        assert_eq!((m10k_blocks(988, 52, bits), m10k_blocks(988, 52, rom)), (6, 6));
        // 16 × 32 buffer: one block (256×40)
        assert_eq!((m10k_blocks(16, 32, bits), m10k_blocks(16, 32, rom)), (1, 1));
        // shallow and wide, and a width no configuration fills: the bit count is lower
        assert_eq!((m10k_blocks(100, 52, bits), m10k_blocks(100, 52, rom)), (1, 2));
        assert_eq!((m10k_blocks(1500, 6, bits), m10k_blocks(1500, 6, rom)), (1, 2));
        // an empty memory: at least 1 by bits, none by configurations
        assert_eq!((m10k_blocks(0, 32, bits), m10k_blocks(0, 32, rom)), (1, 0));
        // the configurations never give fewer blocks than the bit count
        for words in (1..3000).step_by(7) {
            for width in 1..=64 {
                assert!(m10k_blocks(words, width, rom) >= m10k_blocks(words, width, bits), "{words} × {width}");
            }
        }
    }

    #[test]
    fn the_ecp5_85f_is_built_in_with_the_lfe5u_85f_capacities_and_its_ebr_configurations() {
        let t = Target::resolve("ecp5-85f").unwrap();
        assert_eq!(t.family, Family::Ecp5);
        // Lattice FPGA-DS-02012 (ECP5 family data sheet), LFE5U-85F: 84K LUTs (83 640 LUT4 in
        // nextpnr's chip database), 208 EBR of 18 Kbit, 156 18 × 18 multipliers.
        assert_eq!((t.alm, t.m10k, t.dsp, t.m10k_bits), (83_640, 208, 156, 18 * 1024));
        assert_eq!(t.family.units(), Units { logic: "LUT4", bram: "EBR", dsp: "MULT18X18D" });
        assert_eq!(t.pnr.as_ref().map(|p| (p.device.as_str(), p.package.as_str())), Some(("85k", "CABGA381")));
        assert_eq!(Target::from_json("x.json", &serde_json::to_string(&t).unwrap()).unwrap(), t);
        t.validate().unwrap();
        // DP16KD: true dual-port up to 1K × 18, so a 2048 × 32 memory takes 4 blocks (2K × 9:
        // 1 deep · 4 wide; 1K × 18: 2 deep · 2 wide); a simple dual-port one may use 512 × 36:
        // 64 × 32 in one block (true dual-port: 2, at 1K × 18).
        let ecp5 = |tdp| M10kFit::Configurations { true_dual_port: tdp, family: Family::Ecp5 };
        assert_eq!(m10k_blocks(2048, 32, ecp5(true)), 4);
        assert_eq!(m10k_blocks(64, 32, ecp5(false)), 1);
        assert_eq!(m10k_blocks(64, 32, ecp5(true)), 2);
        assert_eq!(m10k_blocks(16384, 1, ecp5(true)), 1);
        // `pnr` belongs to ECP5 targets only
        let wrong = Target { pnr: t.pnr.clone(), ..Target::de10_nano() };
        assert!(wrong.validate().unwrap_err().contains("ecp5"));
    }

    #[test]
    fn estimate_of_the_seed_design_matches_table_1_4() {
        // the seed-form logic (no `design_logic`): Quartus' figures of the seed's design
        let t = Target { design_logic: None, ..Target::de10_nano() };
        let r = t.estimate(4, 4, 987);
        // Table 1.4 totals: 4413 ALM, 20 DSP.
        assert_eq!(r.alm, 4413);
        assert_eq!(r.dsp, 20);
        // Per PE: PE memory 2048·32/10240 → 7, buffer 16·32 → 1, instructions 988·52 = 51376
        // bits → 6, buffer instructions 988·10 → 1, crossbar 988·2·5 → 1: 16 × 8 PE = 128.
        assert_eq!(r.m10k, 128);
        assert!(r.fits);
        // 23 + 23 PE need 23·2 + 23·3 = 115 DSP > 112.
        assert!(!t.estimate(23, 23, 100).fits);
        assert_eq!(t.estimate(22, 22, 100).dsp, 110);
        // The built-in's logic is robovec's crossbar design in Yosys' figures: 8 PE memories ×
        // 2 ports of 16 inputs at 0.35 ALM an input bit and 0.05 a port bit, 1.35 a PE bit, in
        // 32-bit words: 1840 + 32 · (16 · 5.65 + 8 · 1.35) = 5078.4; three buffer words on PE 0
        // add 2 · 1.2 · 32.
        let built_in = Target::de10_nano();
        assert_eq!(built_in.estimate(4, 4, 987).alm, 5079);
        assert_eq!(built_in.estimate_with(4, 4, 987, 32, &[3]).alm, (5078.4f64 + 76.8).ceil() as u32);
        // narrower words take their share of it
        assert_eq!(built_in.estimate_with(4, 4, 987, 16, &[]).alm, (1840.0 + 16.0 * 101.2f64).ceil() as u32);
        assert_eq!(built_in.estimate(4, 4, 987).m10k, 128, "the memories are counted as before");
    }
}
