//! From a placed function to the [`Design`]'s images: the machine program
//! ([`crate::program::lower`], the one lowering `sim` executes) encoded with [`crate::encode`]
//! (the layout of its module doc, LSB first), checked against the target's memories first so
//! that every problem is reported with the figures needed and available.

use robovec_ir::machine::{FixShifts, MachineOp, MachineProgram, Word};
use robovec_ir::placement::{PeArray, Placement};
use robovec_ir::syntax::TrigFn;
use robovec_ir::Function;
use robovec_ir::Span;

use super::images::Image;
use super::{addr_bits, Design, LoadWord, OutputWord, PeImages, PeKind, Source, Widths};
use crate::encode::{self, Layout};
#[cfg(doc)]
use crate::target::Family;
use crate::target::{PeMemory, Target};

/// The target's limits the design must fit (from [`Target`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Words per PE memory (2048 on the DE10-Nano: one M10K-based memory, seed §1.3.1).
    pub pe_words: u32,
    /// Words per buffer memory.
    pub buffer_words: u32,
    /// Instruction memory depth, cycles.
    pub instr_words: u32,
    /// Instruction word bits (52 on the DE10-Nano, seed §1.3.1).
    pub instr_width: u32,
    /// Write ports per PE memory per cycle.
    pub writes: u32,
    /// How the design builds its PE memories (the target family's, [`Family::pe_memory`]).
    pub pe_memory: PeMemory,
    /// Bits of a control-memory lane: the family's widest block-RAM word ([`Family::bram_word`]).
    pub control_lane_bits: u32,
    /// The widest word whose product is one of the family's DSP multipliers
    /// ([`Family::one_multiplier_word`]: 27 on the Cyclone V, 18 on the ECP5): a fixed-point
    /// MULTI PE of a wider word registers its partial products (`hdl/fix_units.v`).
    pub multiplier_word: u32,
    /// The deepest output memory built in LUT RAM ([`Family::lutram_words`]; 0: none).
    pub out_lutram_words: u32,
}

impl Limits {
    /// The limits of target `t`.
    pub fn of(t: &Target) -> Limits {
        Limits {
            pe_words: t.pe_words,
            buffer_words: t.buffer_words,
            instr_words: t.instr_words,
            instr_width: t.instr_width,
            writes: t.writes,
            pe_memory: t.family.pe_memory(),
            control_lane_bits: t.family.bram_word(),
            multiplier_word: t.family.one_multiplier_word(),
            out_lutram_words: t.family.lutram_words(),
        }
    }
}

/// binary32 bits of an `f64` literal rounded to nearest (what `-eval-precision=f32` does).
pub fn f32_bits(x: f64) -> u32 {
    (x as f32).to_bits()
}

fn source(w: &Word, fixed: Option<&robovec_ir::machine::FixedProgram>) -> Source {
    match w {
        Word::Input(n) => Source::Input { input: n.clone() },
        Word::Trig(t, n) => {
            let trig = match t {
                TrigFn::Sin => "sin",
                TrigFn::Cos => "cos",
            };
            Source::Trig { name: format!("{trig}({n})"), trig, of: n.clone() }
        }
        Word::Const(c) => Source::Const { value: *c, bits: format!("0x{:08x}", constant_bits(*c, fixed)) },
    }
}

/// The word of constant `c`: its binary32 bits, or on fixed-point PEs its 32-bit integer
/// ([`crate::program::fixed::constant_word`], two's complement).
fn constant_bits(c: f64, fixed: Option<&robovec_ir::machine::FixedProgram>) -> u32 {
    match fixed {
        None => f32_bits(c),
        Some(_) => crate::program::fixed::constant_word(c).map_or(0, |k| k as u32),
    }
}

fn initial_word(w: &Option<Word>, fixed: Option<&robovec_ir::machine::FixedProgram>) -> u64 {
    match w {
        Some(Word::Const(c)) => u64::from(constant_bits(*c, fixed)) & word_mask(word_bits_of(fixed)),
        _ => 0,
    }
}

/// Bits of the data word: the fixed-point program's `word_bits`, 32 for binary32 PEs.
fn word_bits_of(fixed: Option<&robovec_ir::machine::FixedProgram>) -> u32 {
    fixed.map_or(32, |x| x.word_bits)
}

/// The low `bits` bits set.
fn word_mask(bits: u32) -> u64 {
    if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    }
}

/// Bits of the intermediate K (`hdl/fix_units.v`) that a fixed-point PE of `dw`-bit words
/// needs for the ops whose shifts are `shifts`:
/// - a MULTI PE's product: `2·dw` bits and one more, at least `s + 2` for a rounding by `s` bits
///   (its constant `2^(s−1)` positive);
/// - an ADD PE's floored sum ([`FloorShifts`]): `dw + max(D, 1)` bits for its largest rounding
///   `D` — the sum is computed modulo `2^KW`, which is exact for the bits the rounding keeps, since
///   the range proof puts every result within `dw` bits (`round_D(Z)`'s low `dw` bits are those of
///   `Z + 2^(D−1)`'s bits `D … dw + D − 1`; a left shift, `D ≤ 0`, keeps bits below `dw`).
///
/// At most 64 (robovec's `INTEGER_BITS` bound of 62 bits on every exact intermediate, with the
/// range proof, `robovec_ir::format`).
pub fn intermediate_bits(dw: u32, is_mul: bool, shifts: impl IntoIterator<Item = FixShifts>) -> u32 {
    if !is_mul {
        let d = shifts.into_iter().map(|sh| i32::from(FloorShifts::of(sh).round)).fold(1, i32::max);
        return (dw + d as u32).min(64);
    }
    shifts
        .into_iter()
        .map(|sh| (2 * dw + 1).max(u32::try_from(sh.shift).unwrap_or(0) + 2))
        .fold(2 * dw + 1, u32::max)
        .min(64)
}

/// An ADD op's shifts as the ADD unit applies them (`fix_add_sub` in `hdl/fix_units.v`): the
/// finer operand floored by `floor` bits, the coarser lifted by `lift` bits, their sum rounded
/// by `round` bits (a left shift when `round ≤ 0`).
///
/// The op's exact sum is `K = x_f ± (x_c << A)` (`A` = [`FixShifts::align`], `x_f` the operand
/// not aligned), rounded by `S` = [`FixShifts::shift`]. With `r = min(A, S − 1)` for `S ≥ 1`
/// (else 0), `(x_c << A) + 2^(S−1)` is a multiple of `2^r`, so
/// `round_S(K) = round_(S−r)(⌊±x_f / 2^r⌋ ± (x_c << (A − r)))`: the floor drops only bits
/// below the grid the rounding keeps. The unit then adds words of about the result's width,
/// not the aligned sum's `dw + A + 2` bits, and its rounding shifts by `S − r`, which is 0 or 1
/// for nearly every op (a sum rounds to the coarser operand's grid or one bit coarser):
/// WALK-MAN's 20,475 ADD ops at 26-bit words need `D ∈ {−3, −1, 0, 1}` where `S` took 0 … 24.
/// (The same reformulation as the smaller multiply-add, docs/fpga.md.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FloorShifts {
    /// Bits the finer operand is floored (`r`, 0 ≤ r ≤ A).
    pub floor: u8,
    /// Bits the coarser operand is shifted left (`A − r`).
    pub lift: u8,
    /// Bits the sum is rounded (`S − r`; negative: a left shift).
    pub round: i8,
}

impl FloorShifts {
    /// The floored form of an ADD op's shifts `sh` (see the type).
    pub fn of(sh: FixShifts) -> FloorShifts {
        let (a, s) = (i32::from(sh.align & 63), i32::from(sh.shift));
        let r = if s >= 1 { a.min(s - 1) } else { 0 };
        FloorShifts { floor: r as u8, lift: (a - r) as u8, round: (s - r) as i8 }
    }

    /// `K`'s rounding computed the unit's way, the identity's right-hand side (the property
    /// test of this module compares it with [`FixShifts::apply`]): `⌊±x_f / 2^r⌋ ± (x_c << l)`
    /// rounded by `D` (ties toward +∞), for `a ± b` with `sh`'s operand order and alignment
    /// (`None` when the result leaves 64 bits).
    pub fn apply(sh: FixShifts, sub: bool, a: i64, b: i64) -> Option<i64> {
        let f = FloorShifts::of(sh);
        let (xf, xc) = FloorShifts::terms(sh, sub, a, b);
        i64::try_from(f.round_sum((xf >> f.floor) + (xc << f.lift))).ok()
    }

    /// The finer operand and the coarser of `a ± b` under `sh`, each with its sign in the op.
    fn terms(sh: FixShifts, sub: bool, a: i64, b: i64) -> (i128, i128) {
        let (a, b) = (i128::from(a), i128::from(b));
        let b = if sub { -b } else { b };
        if sh.align_b {
            (a, b)
        } else {
            (b, a)
        }
    }

    /// The floored sum `z` rounded by `round` bits ([`FixShifts::round`]).
    fn round_sum(&self, z: i128) -> i128 {
        FixShifts { align: 0, align_b: false, shift: self.round }.round(z)
    }
}

/// Bits of the exact intermediate K of a MULTI PE with the multiply-add unit (`fix_mac` in
/// `hdl/fix_units.v`) for `dw`-bit words and the shifts `shifts` of its program (fused ops and
/// products): the aligned sum `±(a·b << lp) ± (c << lc)` takes `max(2·dw + lp, dw + lc) + 1`
/// bits and one more for the rounding constant, at least `s + 2` for a rounding by `s` bits and
/// the product's `2·dw + 1`; at most 64 (robovec's `INTEGER_BITS` bound of 62 bits on every
/// exact intermediate, `robovec_ir::format`, so the sum is exact modulo 2^64 and fits).
pub fn mac_intermediate_bits(dw: u32, shifts: impl IntoIterator<Item = FixShifts>) -> u32 {
    shifts
        .into_iter()
        .map(|sh| {
            let align = u32::from(sh.align & 63);
            let (lp, lc) = if sh.align_b { (0, align) } else { (align, 0) };
            ((2 * dw + lp).max(dw + lc) + 2).max(u32::try_from(sh.shift).unwrap_or(0) + 2)
        })
        .fold(2 * dw + 1, u32::max)
        .min(64)
}

/// The shifts a fixed-point PE's program uses: the largest alignment and the range of the
/// rounding shifts (`hdl/fix_units.v`'s `AMAX`, `SMIN`, `SMAX`). The unit's shifters cover only
/// these, so their levels are ⌈log₂(AMAX + 1)⌉ and ⌈log₂(SMAX − SMIN + 1)⌉ instead of 6 and 7
/// (on the Jeep's `dirdyna` at 16 + 16 PEs, a MULTI PE rounds by 24 to 26 bits, an ADD PE aligns
/// by at most 11 to 32 bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShiftRanges {
    /// The largest alignment (bits, 0..=63).
    pub align_max: u8,
    /// The smallest rounding shift (bits; negative: a left shift).
    pub shift_min: i8,
    /// The largest rounding shift (bits).
    pub shift_max: i8,
    /// The largest floor of the finer operand (bits; ADD PEs, whose ranges are those of the
    /// ops' [`FloorShifts`]: `align_max` their largest lift, `shift_min … shift_max` their
    /// roundings; 0 on MULTI PEs).
    pub floor_max: u8,
}

impl ShiftRanges {
    /// Any shift a shift word holds: alignments up to 63 bits (6 levels), any 7-bit rounding
    /// shift, floors up to 62 bits. The unit the target's `fix_pe` costs describe, and the
    /// HDL's defaults.
    pub const FULL: ShiftRanges = ShiftRanges { align_max: 63, shift_min: -64, shift_max: 63, floor_max: 62 };
}

/// The [`ShiftRanges`] of the ops whose shifts are `shifts` (the issued ops of one PE; none:
/// `AMAX = 0`, `SMIN = SMAX = 0`) on a MULTI PE (`floor_max` 0).
pub fn shift_ranges(shifts: impl IntoIterator<Item = FixShifts>) -> ShiftRanges {
    ranges_of(shifts.into_iter().map(|sh| (sh.align & 63, sh.shift, 0)))
}

/// The [`ShiftRanges`] of an ADD PE whose ops' shifts are `shifts`: those of their
/// [`FloorShifts`] (the largest lift as `align_max`, the roundings, the largest floor).
pub fn floored_shift_ranges(shifts: impl IntoIterator<Item = FixShifts>) -> ShiftRanges {
    ranges_of(shifts.into_iter().map(FloorShifts::of).map(|f| (f.lift, f.round, f.floor)))
}

/// The [`ShiftRanges`] of ops' `(alignment, rounding, floor)` shifts (none: all 0).
fn ranges_of(ops: impl Iterator<Item = (u8, i8, u8)>) -> ShiftRanges {
    let mut r: Option<ShiftRanges> = None;
    for (align, shift, floor) in ops {
        let x = r.get_or_insert(ShiftRanges { align_max: 0, shift_min: shift, shift_max: shift, floor_max: 0 });
        x.align_max = x.align_max.max(align);
        x.shift_min = x.shift_min.min(shift);
        x.shift_max = x.shift_max.max(shift);
        x.floor_max = x.floor_max.max(floor);
    }
    r.unwrap_or(ShiftRanges { align_max: 0, shift_min: 0, shift_max: 0, floor_max: 0 })
}

/// What the target cannot hold or the hardware cannot do, one line each with the figures
/// needed and available (empty: the program fits).
pub fn problems(m: &MachineProgram, limits: &Limits) -> Vec<String> {
    let mut out = Vec::new();
    let name = |s: usize| pe_name(&m.arch, s);
    if limits.writes != 2 {
        out.push(format!(
            "the target has {} write port(s) per PE memory; the instruction word has exactly 2 (write-0, write-1)",
            limits.writes
        ));
    }
    for (what, l) in [("ADD", m.arch.lat.add), ("MULTI", m.arch.lat.mul)] {
        if l < 2 {
            out.push(format!(
                "{what} latency is {l} cycles; the hardware needs at least 2 (PE memory read and crossbar registers)"
            ));
        }
    }
    let (mut unsupported, mut mac) = (Vec::new(), false);
    for (s, pe) in m.pes.iter().enumerate() {
        for (c, st) in pe.steps.iter().enumerate() {
            match st.issue.as_ref().map(|i| &i.op) {
                Some(MachineOp::Div) => unsupported.push(format!("div on {} at cycle {c}", name(s))),
                Some(MachineOp::Call(_)) => unsupported.push(format!("call on {} at cycle {c}", name(s))),
                Some(MachineOp::Mac(_)) => mac = true,
                _ => {}
            }
            if st.writes.len() > 2 {
                out.push(format!(
                    "PE memory of {} takes {} writes at cycle {c}; the hardware has 2 write ports",
                    name(s),
                    st.writes.len()
                ));
            }
        }
    }
    if !unsupported.is_empty() {
        out.push(format!(
            "{} op(s) need a divider or a function unit, which the PEs lack (ADD: fp_add_sub, MULTI: fp_mul): {}{}",
            unsupported.len(),
            unsupported.iter().take(4).cloned().collect::<Vec<_>>().join(", "),
            if unsupported.len() > 4 { ", …" } else { "" }
        ));
    }
    let worst = |v: &[u32]| v.iter().enumerate().max_by_key(|&(i, &w)| (w, std::cmp::Reverse(i))).map(|(i, &w)| (i, w));
    if let Some((s, w)) = worst(&m.pe_words).filter(|&(_, w)| w > limits.pe_words) {
        out.push(format!(
            "PE memory of {} needs {w} words; the target has {} words per PE memory",
            name(s),
            limits.pe_words
        ));
    }
    if let Some((s, w)) = worst(&m.buffer_words).filter(|&(_, w)| w > limits.buffer_words) {
        out.push(format!(
            "buffer of {} needs {w} words; the target's buffers have {} words",
            name(s),
            limits.buffer_words
        ));
    }
    let depth = u64::from(m.cycles) + 1;
    if depth > u64::from(limits.instr_words) {
        out.push(format!(
            "the program needs {depth} instruction words per PE (cycles 0..={}); the target's instruction memory has {}",
            m.cycles, limits.instr_words
        ));
    }
    let aw = addr_bits(u64::from(limits.pe_words));
    if 4 * aw + 4 > limits.instr_width.min(64) {
        out.push(format!(
            "the instruction word needs {} bits (4 addresses of {aw} bits + 4 flags); the target's is {} bits",
            4 * aw + 4,
            limits.instr_width
        ));
    } else if mac && 5 * aw + 6 > 64 {
        // a program with multiply-adds widens the word to 5aw + 6 bits (`crate::encode`)
        out.push(format!(
            "the instruction word of a program with fused multiply-adds needs {} bits (5 addresses of {aw} bits + 6 flags); the images hold at most 64",
            5 * aw + 6
        ));
    }
    out
}

/// Lowers placed function `f` (placement `p`) onto `limits`: the machine program, checked,
/// encoded into the design's images.
///
/// # Errors
/// A diagnostic (one line per problem) with the figures needed and available: an op the PEs do
/// not have (`div`, `call`), `writes` ≠ 2, a latency below 2, a memory beyond the target, or a
/// placement the machine model rejects.
pub fn from_placement(f: &Function, p: &Placement, limits: &Limits) -> Result<Design, String> {
    from_placement_until(f, p, limits, &|| false).map_err(|e| e.message)
}

/// Why a design cannot be made: the message, and where in the source it comes from when the
/// lowering located it (the value or placement line; [`Span::DUMMY`] otherwise), so that
/// `codegen<fpga>` reports `file:line:col` as `sim` does (issue 29).
#[derive(Clone, Debug, PartialEq)]
pub struct DesignError {
    /// One line per problem.
    pub message: String,
    /// The source span, [`Span::DUMMY`] when unknown.
    pub span: Span,
}

impl From<String> for DesignError {
    fn from(message: String) -> DesignError {
        DesignError { message, span: Span::DUMMY }
    }
}

impl From<&str> for DesignError {
    fn from(message: &str) -> DesignError {
        message.to_string().into()
    }
}

impl std::fmt::Display for DesignError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// [`from_placement`] whose lowering gives up when `stop` returns true
/// ([`crate::program::lower_until`]; the caller's time limit).
///
/// # Errors
/// As [`from_placement`]; when `stop` returned true, `the placement cannot be lowered:
/// stopped: time limit` (the caller knows it from its hook).
pub fn from_placement_until(
    f: &Function,
    p: &Placement,
    limits: &Limits,
    stop: &dyn Fn() -> bool,
) -> Result<Design, DesignError> {
    let m = crate::program::lower_until(f, p, stop)
        .map_err(|e| DesignError { message: format!("the placement cannot be lowered: {e}"), span: e.span })?;
    let found = problems(&m, limits);
    if !found.is_empty() {
        return Err(found.join("\n").into());
    }
    Ok(from_program(f, &m, limits)?)
}

/// The design of machine program `m` of `f`.
///
/// # Errors
/// What [`encode::encode`] rejects.
pub fn from_program(f: &Function, m: &MachineProgram, limits: &Limits) -> Result<Design, String> {
    let layout = Layout::new(m, limits.pe_words, limits.buffer_words, limits.instr_width).map_err(|e| e.to_string())?;
    let im = encode::encode(m, &layout).map_err(|e| e.to_string())?;
    let widths = Widths {
        aw: layout.aw,
        bw: layout.bw,
        sw: layout.sw,
        ow: layout.ow,
        cw: addr_bits(u64::from(m.cycles) + 2),
        instr: layout.instr_width,
    };
    let mut loads = Vec::new();
    let mut output_loads = Vec::new();
    let mut pes = Vec::new();
    let fx = m.fixed.as_ref();
    let load = |s: usize, pname: &str, a: usize, w: &Word| LoadWord {
        slot: s,
        pe: pname.to_string(),
        addr: a as u32,
        source: source(w, fx),
        fraction: fx.and_then(|x| x.fraction(w)),
    };
    for (s, pe) in m.pes.iter().enumerate() {
        let pname = pe_name(&m.arch, s);
        for (a, w) in pe.init.iter().enumerate() {
            if let Some(w) = w {
                loads.push(load(s, &pname, a, w));
            }
        }
        for (a, w) in pe.output_init.iter().enumerate() {
            if let Some(w) = w {
                output_loads.push(load(s, &pname, a, w));
            }
        }
        let img = |k: &str, width: u32, words: Vec<u64>| Image { name: format!("pe{s}_{k}"), width, words };
        let mut data: Vec<u64> = pe.init.iter().map(|w| initial_word(w, fx)).collect();
        let mut out: Vec<u64> = pe.output_init.iter().map(|w| initial_word(w, fx)).collect();
        let is_add = s < m.arch.n_add as usize;
        let shift_ranges = fx.map(|x| {
            let ops = x.shifts[s].iter().flatten().copied();
            if is_add {
                floored_shift_ranges(ops)
            } else {
                shift_ranges(ops)
            }
        });
        let fix = fx.map(|x| {
            let words = x.shifts[s].iter().map(|sh| sh.map_or(0, |sh| sh.word())).collect();
            img("fix", robovec_ir::machine::FixShifts::BITS, words)
        });
        data.resize(data.len().max(1), 0);
        out.resize(out.len().max(1), 0);
        let mac = pe.steps.iter().any(|st| matches!(st.issue.as_ref().map(|i| &i.op), Some(MachineOp::Mac(_))));
        pes.push(PeImages {
            mac,
            slot: s,
            pe: pname,
            is_mul: !is_add,
            instr: img("instr", widths.instr, im.instr[s].clone()),
            xbar: img("xbar", widths.xbar(), im.crossbar[s].clone()),
            bufi: img("bufi", widths.bufi(), im.buffer[s].clone()),
            capt: img("capt", widths.capt(), im.capture[s].clone()),
            data: img("data", word_bits_of(fx), data),
            out: img("out", word_bits_of(fx), out),
            buffer_words: m.buffer_words[s],
            fix,
            shift_ranges,
        });
    }
    Ok(Design {
        function: f.name.clone(),
        n_add: m.arch.n_add,
        n_mul: m.arch.n_mul,
        lat_add: m.arch.lat.add,
        lat_mul: m.arch.lat.mul,
        cycles: m.cycles,
        widths,
        pes,
        inputs: f.inputs.iter().map(|&v| f.name_of(v).to_string()).collect(),
        input_fractions: fx.map(|x| x.inputs.clone()).unwrap_or_default(),
        loads,
        output_loads,
        outputs: m
            .outputs
            .iter()
            .enumerate()
            .map(|(i, o)| OutputWord {
                name: o.name.clone(),
                slot: o.slot,
                pe: pe_name(&m.arch, o.slot),
                addr: o.addr,
                fraction: fx.map(|x| x.outputs[i]),
            })
            .collect(),
        routes: None,
        pe_memory: limits.pe_memory,
        control_lane_bits: limits.control_lane_bits,
        multiplier_word: limits.multiplier_word,
        out_lutram_words: limits.out_lutram_words,
        states: f.states,
        pe_kind: if fx.is_some() { PeKind::Fixed } else { PeKind::Binary32 },
        word_bits: word_bits_of(fx),
    })
}

/// `add0`, `mul1` for slot `s`.
pub fn pe_name(arch: &PeArray, s: usize) -> String {
    if s < arch.n_add as usize {
        format!("add{s}")
    } else {
        format!("mul{}", s - arch.n_add as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 4096, max_global_rejects: 1 << 16, ..ProptestConfig::default() })]
        /// The floored form computes every ADD op's rounding exactly (the identity of
        /// [`FloorShifts`]), the HDL's ranges cover it, and the intermediate is wide enough:
        /// against [`FixShifts::apply`] on any operands, alignment and rounding (within the
        /// 62-bit exact bound) whose result fits `dw` bits, also computed modulo `2^KW`.
        #[test]
        fn floored_adds_equal_the_exact_rounding(
            dw in 8u32..=32,
            (a, ba) in (any::<i64>(), 1u32..=32),
            (b, bb) in (any::<i64>(), 1u32..=32),
            align in 0u8..=40,
            align_b in any::<bool>(),
            delta in -24i8..=22,
            sub in any::<bool>(),
        ) {
            // operands of any magnitude within dw bits; roundings around the alignment (where
            // results fit the word), from left shifts to well past it
            let (a, b) = (a >> (64 - ba.min(dw)), b >> (64 - bb.min(dw)));
            let sh = FixShifts { align, align_b, shift: (align as i8 + delta).max(-20) };
            let op = if sub { MachineOp::Sub } else { MachineOp::Add };
            let exact = FixShifts { shift: 0, ..sh }.apply(&op, a, b).unwrap();
            prop_assume!(exact.abs() < 1 << 62);
            let want = sh.apply(&op, a, b).unwrap();
            prop_assume!(want >= -(1i128 << (dw - 1)) && want < 1i128 << (dw - 1));
            prop_assert_eq!(FloorShifts::apply(sh, sub, a, b).map(i128::from), Some(want));
            let f = FloorShifts::of(sh);
            let r = floored_shift_ranges([sh]);
            prop_assert!(f.floor <= r.floor_max && f.lift <= r.align_max);
            prop_assert!(r.shift_min <= f.round && f.round <= r.shift_max);
            prop_assert_eq!(i32::from(f.floor) + i32::from(f.lift), i32::from(align));
            // modulo 2^KW, as the unit adds: the rounded result's low dw bits are the same
            let kw = intermediate_bits(dw, false, [sh]);
            let wrap = |x: i128| if kw >= 64 { x as i64 as i128 } else { (x << (128 - kw)) >> (128 - kw) };
            let (xf, xc) = FloorShifts::terms(sh, sub, a, b);
            let y = f.round_sum(wrap((xf >> f.floor) + wrap(xc << f.lift)));
            let low = |x: i128| x & ((1i128 << dw) - 1);
            prop_assert_eq!(low(y), low(want));
        }
    }
}
