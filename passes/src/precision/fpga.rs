//! `precision<target=fpga>`: narrow fixed-point words per value, costed in DSP blocks and ALM
//! from the target description ([`robovec_machine::target::Datapath`]).
//!
//! # Cost model ([`resources`])
//! A datapath of one operator per op, each in its value's format (what a fully spatial FPGA
//! pipeline of the function builds; the PE array of the seed time-shares binary32 PEs instead).
//! With `p = datapath.fix_alm_per_bit` (½ on the Cyclone V) and, for an op `z` in `fix<w_z,f_z>`
//! whose fixed-point operands have widths `w_a`, `w_b` and integer bits `i = w − f`:
//!
//! | op | DSP | ALM |
//! |---|---|---|
//! | `a ± b` | 0 | `p·(max(i_a, i_b, i_z) + f_z + 1)` (aligned adder and its rounding bit) |
//! | `a × b` | [`robovec_machine::target::Datapath::product`]`(w_a, w_b)` | its tile adders + `p·(w_z + 1)` (rounding) |
//! | `a / b` | 0 | `p·w_z·(w_b + 1)` (digit recurrence: one `w_b + 1`-bit add/sub per quotient bit) |
//! | `√a` | 0 | `p·w_z·(w_z + 2)` |
//! | `sin`, `cos` | 0 | `3·p·w_z²` (CORDIC: three `w_z`-bit adders per iteration, `w_z` iterations) |
//! | `fma` | as `×` | as `×` plus `p·(w_z + 1)` |
//!
//! A constant operand has the width of its significand (bits from the first to the last 1, plus
//! the sign; 0 for 0 and powers of two, whose product is a shift); an operand in a binary format
//! read by a fixed-point op has the result's width (after its conversion). Binary32 ops cost the
//! target's `fp_mul` (products) or `fp_add` (everything else: the ADD side of the PE array);
//! binary64 ops `datapath.fp64_mul` / `datapath.fp64_add`. Each operand read in a format of
//! another kind (fixed, binary32, binary64; fixed to fixed is a shift of wires) costs
//! `datapath.convert_alm`. Inputs cost nothing (they arrive in their formats).
//!
//! **One figure** ranks assignments: the share of the device, `100·(DSP/dsp + ALM/alm)` with
//! `dsp`, `alm` the target's capacities (112 DSP and 41,910 ALM on the DE10-Nano: a DSP block
//! weighs as much as 374 ALM). It can exceed 100: a spatial datapath of a large function does
//! not fit one device; the figure still compares assignments.
//!
//! # Search ([`fixed_phase`])
//! 1. **Fraction bits from the sensitivities.** With `λ_v` the first-order weight of value `v`'s
//!    rounding in `Σ_o E_o / budget_o` ([`crate::error_bound::bound::sensitivities`]) and `S =
//!    1 − max_o E64_o / budget_o` the room binary64 leaves, value `v` gets the share `s_v = S ·
//!    c_v / Σc` of the room (`c_v` the cost of one more bit of `v`, the optimum of `Σ c_v·f_v`
//!    under `Σ λ_v·2^-(f_v+1) ≤ S`) and the fewest fraction bits `f_v` with `λ_v · 2^-(f_v+1) ≤
//!    s_v`. A value whose word would exceed 53 bits (its integer bits estimated from its range
//!    and a first-order error `S/λ_v`), or that feeds an output already at its binary64 bound,
//!    stays binary64; so does a value with an unbounded range or error (a callback, a divisor
//!    near 0).
//! 2. **One global shift `δ`** of every `f_v`, found by the certified bound (exponential steps
//!    then bisection: about 8 sweeps): the smallest `δ` the bound accepts (negative when the
//!    first-order sum was pessimistic, as it sums over the outputs).
//! 3. **Bits removed in batches**: values ranked by first-order damage of one bit less (their
//!    sensitivity re-seeded with `1/(budget_o − E_o)`, the room each output has left) per unit of
//!    cost saved; a binary search finds the longest prefix of that ranking that can lose a bit;
//!    up to [`ROUNDS`] rounds. Before and after them, the operands of products at most
//!    [`SNAP_BITS`] bits wider than an operand size of a DSP mode (9, 18, 19, 27 on the Cyclone
//!    V) are offered that size, the same way: the DSP count of a product is a step
//!    function of the widths that the smooth per-bit cost does not see.
//! 4. **Widths from the bound**: during the search every fixed value is `fix<53,f>` (the bound of
//!    every value depends on fraction bits only; the width only decides whether the range fits);
//!    the final width of each is the smallest whose range holds the value's enclosure widened by
//!    its certified error ([`min_width`], the bound's own overflow test), so no headroom bit is
//!    spent. The final assignment is checked by the bound like every other.

use std::collections::BTreeMap;

use robovec_ir::format::{Format, FIX_FRACTION_RANGE, FIX_MAX_WIDTH};
use robovec_ir::{BinOp, Def, Function, Interval, Intrinsic, Operand, Value};
use robovec_machine::target::Target as Device;

use crate::error_bound::bound::{bound_with_adjoints, sensitivities, BoundError, Formats, OutputAdjoints, TrigImpl};

/// Rounds of bit removal (step 3 of the module doc).
pub const ROUNDS: usize = 4;

/// DSP blocks and ALM of `f`'s ops in `g`'s formats (`g` is `f` with formats) on `device`
/// (module doc's table).
pub fn resources(f: &Function, g: &Function, device: &Device) -> (f64, f64) {
    let (mut dsp, mut alm) = (0.0, 0.0);
    for &v in &f.body {
        let (d, a) = op_cost(f, g, v, device);
        dsp += d;
        alm += a;
    }
    (dsp, alm)
}

/// The share of the device, `100·(DSP/dsp + ALM/alm)` (module doc).
pub fn share(dsp: f64, alm: f64, device: &Device) -> f64 {
    100.0 * (dsp / f64::from(device.dsp) + alm / f64::from(device.alm))
}

/// The kind of a format for conversions: fixed point (any), binary32, binary64.
fn kind(format: Format) -> u8 {
    match format {
        Format::Fix { .. } => 0,
        Format::Binary32 => 1,
        Format::Binary64 => 2,
    }
}

/// Bits of a constant's significand and its sign: 0 for 0, ±1 and powers of two (a shift).
pub fn const_bits(c: f64) -> u32 {
    if c == 0.0 || !c.is_finite() {
        return 0;
    }
    let bits = c.abs().to_bits();
    let exp = (bits >> 52) & 0x7ff;
    let mant = if exp == 0 { bits & ((1 << 52) - 1) } else { (bits & ((1 << 52) - 1)) | (1 << 52) };
    let significant = 64 - mant.leading_zeros() - mant.trailing_zeros();
    if significant <= 1 {
        0
    } else {
        significant + 1
    }
}

/// DSP and ALM of one op `v` in `g`'s formats (module doc's table).
fn op_cost(f: &Function, g: &Function, v: Value, device: &Device) -> (f64, f64) {
    let d = &device.datapath;
    let p = d.fix_alm_per_bit;
    let fz = g.format(v);
    let def = &f.value(v).def;
    let operands: Vec<Operand> = match def {
        Def::Binary(_, a, b) => vec![*a, *b],
        Def::Call(_, args) => args.clone(),
        Def::Trig(_, a) => vec![Operand::Value(*a)],
        Def::Input | Def::Expr(_) => return (0.0, 0.0),
    };
    let conversions =
        operands.iter().filter(|o| matches!(o, Operand::Value(a) if kind(g.format(*a)) != kind(fz))).count() as f64;
    let mut alm = conversions * d.convert_alm;
    let intrinsic = match def {
        Def::Call(callee, args) => Intrinsic::of(callee, args.len()),
        _ => None,
    };
    let is_mul = matches!(def, Def::Binary(BinOp::Mul, ..));
    let is_fused = matches!(intrinsic, Some(Intrinsic::Fma | Intrinsic::Fms | Intrinsic::Fnma));
    let Format::Fix { width: wz, fraction: frz } = fz else {
        let (add, mul) = match fz {
            Format::Binary32 => (device.fp_add, device.fp_mul),
            _ => (d.fp64_add, d.fp64_mul),
        };
        let units: &[robovec_machine::target::UnitCost] = if is_fused {
            &[mul, add]
        } else if is_mul {
            &[mul]
        } else {
            &[add]
        };
        let dsp = units.iter().map(|u| f64::from(u.dsp)).sum::<f64>();
        alm += units.iter().map(|u| u.alm).sum::<f64>();
        return (dsp, alm);
    };
    let iz = wz as i32 - frz;
    // Width and integer bits of an operand in the op's fixed-point arithmetic.
    let width = |o: &Operand| match *o {
        Operand::Value(a) => match g.format(a) {
            Format::Fix { width, .. } => width,
            _ => wz,
        },
        Operand::Const(c) => const_bits(c),
    };
    let int_bits = |o: &Operand| match *o {
        Operand::Value(a) => match g.format(a) {
            Format::Fix { width, fraction } => width as i32 - fraction,
            _ => iz,
        },
        Operand::Const(_) => iz,
    };
    let wzf = f64::from(wz);
    let round = p * (wzf + 1.0);
    let (dsp, more) = match def {
        Def::Binary(op, a, b) => match op {
            BinOp::Add | BinOp::Sub => {
                let span = int_bits(a).max(int_bits(b)).max(iz) + frz + 1;
                (0.0, p * f64::from(span.max(1)))
            }
            BinOp::Mul => {
                let (dsp, tiles) = d.product(width(a), width(b));
                (dsp, tiles + round)
            }
            BinOp::Div => (0.0, p * wzf * f64::from(width(b) + 1)),
        },
        Def::Trig(..) => (0.0, 3.0 * p * wzf * wzf),
        Def::Call(..) => match intrinsic {
            Some(Intrinsic::Sqrt) => (0.0, p * wzf * (wzf + 2.0)),
            Some(_) => {
                let (dsp, tiles) = d.product(width(&operands[0]), width(&operands[1]));
                (dsp, tiles + 2.0 * round)
            }
            None => (f64::from(d.fp64_add.dsp), d.fp64_add.alm),
        },
        Def::Input | Def::Expr(_) => (0.0, 0.0),
    };
    (dsp, alm + more)
}

/// The cost, in the device share, of one more fraction bit of each value (smoothed: a DSP
/// block per `a` bits of the widest mode for each product it is an operand of, the adder or
/// the quotient's bits of its own op): the `c_v` of the module doc, never 0.
fn bit_costs(f: &Function, device: &Device) -> Vec<f64> {
    let d = &device.datapath;
    let pa = 100.0 / f64::from(device.alm) * d.fix_alm_per_bit;
    let widest = d.dsp_modes.iter().map(|m| m.a.max(m.b)).max().unwrap_or(27).max(1);
    let pd = 100.0 / f64::from(device.dsp) / f64::from(widest);
    // Typical word of a value, for the ops whose logic grows with the product of two widths.
    let typical = 24.0;
    let mut c = vec![0.0f64; f.values.len()];
    for &v in &f.body {
        let def = &f.value(v).def;
        let mut user = |o: &Operand, w: f64| {
            if let Operand::Value(a) = *o {
                c[a.index()] += w;
            }
        };
        let own = match def {
            Def::Binary(op, a, b) => match op {
                BinOp::Add | BinOp::Sub => pa,
                BinOp::Mul => {
                    user(a, pd);
                    user(b, pd);
                    pa
                }
                BinOp::Div => {
                    user(b, pa * typical);
                    pa * typical
                }
            },
            Def::Trig(..) => 6.0 * pa * typical,
            Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
                Some(Intrinsic::Sqrt) => 2.0 * pa * typical,
                Some(_) => {
                    user(&args[0], pd);
                    user(&args[1], pd);
                    2.0 * pa
                }
                None => 0.0,
            },
            Def::Input | Def::Expr(_) => 0.0,
        };
        c[v.index()] += own;
    }
    for x in &mut c {
        *x = x.max(pa * 0.25);
    }
    c
}

/// Integer bits, the sign included, of a word holding magnitudes up to `t` (at least 2⁻⁶⁰).
fn int_bits(t: f64) -> i32 {
    let t = if t.is_finite() { t.max(2f64.powi(-60)) } else { f64::MAX };
    t.log2().ceil() as i32 + 1
}

/// The smallest width of `fix<w,fraction>` that holds the computed value of a value whose
/// enclosure is `r` and certified error `err`: the bound's own overflow test (its computed range
/// `[lo − err, hi + err]`, widened by one float each way, stores without overflow). `None` past
/// [`FIX_MAX_WIDTH`].
pub fn min_width(r: Interval, err: f64, fraction: i32) -> Option<u32> {
    if !err.is_finite() {
        return None;
    }
    let (lo, hi) = ((r.lo - err).next_down(), (r.hi + err).next_up());
    (1..=FIX_MAX_WIDTH).find(|&w| {
        let Some(fmt) = Format::fix(w, fraction) else { return false };
        let (Some((flo, fhi)), Some(step)) = (fmt.fix_range(), fmt.fix_step()) else { return false };
        lo >= flo - step / 2.0 && hi < fhi + step / 2.0
    })
}

/// What the search needs of [`super::choose()`]: the enclosures, the outputs with a budget (value,
/// absolute budget), and its sweep counter and stop.
pub struct Search<'a, S: FnMut() -> bool> {
    /// Enclosures of every value.
    pub x: &'a [Interval],
    /// Output value and absolute budget.
    pub outs: Vec<(Value, f64)>,
    /// Outputs already at their binary64 bound.
    pub unreachable: Vec<Value>,
    /// Sweeps run.
    pub sweeps: usize,
    /// Read before each sweep.
    pub stop: S,
    /// Set once `stop` said so.
    pub stopped: bool,
    /// Values that stay binary64 (by index; empty: none).
    pub keep: Vec<bool>,
    /// The outputs' adjoints, shared by every probe ([`OutputAdjoints`]).
    pub adjoints: Option<&'a OutputAdjoints>,
}

/// Why a probe failed.
enum Refused {
    /// The bound does not meet a budget.
    Budget,
    /// This value's range does not fit its word.
    Overflow(String),
    /// Stopped before the sweep.
    Stopped,
}

impl<'a, S: FnMut() -> bool> Search<'a, S> {
    /// A search over enclosures `x` for the outputs `outs` (value, absolute budget), those in
    /// `unreachable` at their binary64 bound, reading `stop` before each sweep.
    pub fn new(x: &'a [Interval], outs: Vec<(Value, f64)>, unreachable: Vec<Value>, stop: S) -> Self {
        Search { x, outs, unreachable, sweeps: 0, stop, stopped: false, keep: Vec::new(), adjoints: None }
    }

    /// The bounds when `h`'s formats meet every budget.
    /// The longest non-empty prefix of `offers` (rank, value, fraction bits: each value's
    /// fewer bits, best first) whose formats `fix<53, f>` on `h` the bound accepts, with its
    /// bounds: a binary search, one [`Search::probe`] per step. `None` when no prefix is
    /// accepted, or the search stops before one is.
    fn longest_prefix(&mut self, h: &Function, offers: &[(f64, Value, i32)]) -> Option<(Function, Vec<f64>)> {
        let with = |k: usize| {
            let mut t = h.clone();
            for &(_, v, fr) in &offers[..k] {
                if let Some(fmt) = Format::fix(FIX_MAX_WIDTH, fr) {
                    t.set_format(v, fmt);
                }
            }
            t
        };
        let (mut lo, mut hi) = (0usize, offers.len());
        let mut got = None;
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            let t = with(mid);
            match self.probe(&t) {
                Ok(et) => {
                    lo = mid;
                    got = Some((t, et));
                }
                Err(Refused::Stopped) => break,
                Err(_) => hi = mid - 1,
            }
        }
        got
    }

    fn probe(&mut self, h: &Function) -> Result<Vec<f64>, Refused> {
        if self.stopped || (self.stop)() {
            self.stopped = true;
            return Err(Refused::Stopped);
        }
        self.sweeps += 1;
        let e = bound_with_adjoints(h, self.x, Formats::Mixed, 0, self.adjoints, TrigImpl::Libm, || false).map_err(
            |err| match err {
                BoundError::FixOverflow { value, .. } => Refused::Overflow(value),
                BoundError::Stopped(_) => Refused::Stopped,
            },
        )?;
        if self.outs.iter().all(|&(v, b)| e[v.index()] <= b) {
            Ok(e)
        } else {
            Err(Refused::Budget)
        }
    }
}

/// `g` (every value binary64, accepted with bounds `e64`) with fixed-point words where the
/// search of the module doc puts them, every fixed value `fix<53,f>` (widths are set by
/// [`tighten`]). Returns `g` unchanged when no assignment is accepted.
pub fn fixed_phase<S: FnMut() -> bool>(
    f: &Function,
    g: &Function,
    e64: &[f64],
    device: &Device,
    s: &mut Search<'_, S>,
) -> Function {
    let x = s.x;
    let values: Vec<Value> = f.inputs.iter().chain(&f.body).copied().collect();
    let seeds: Vec<(Value, f64)> = s.outs.iter().map(|&(v, b)| (v, 1.0 / b)).collect();
    let lam = sensitivities(g, x, e64, &seeds);
    let cost = bit_costs(f, device);
    // Values an output at its binary64 bound depends on stay binary64.
    let mut frozen = vec![false; f.values.len()];
    for &v in &s.unreachable {
        frozen[v.index()] = true;
    }
    let keep = |v: Value| s.keep.get(v.index()).copied().unwrap_or(false);
    for &v in f.body.iter().rev() {
        if !frozen[v.index()] {
            continue;
        }
        let mut mark = |o: &Operand| {
            if let Operand::Value(a) = *o {
                frozen[a.index()] = true;
            }
        };
        match &f.value(v).def {
            Def::Binary(_, a, b) => {
                mark(a);
                mark(b);
            }
            Def::Call(_, args) => args.iter().for_each(&mut mark),
            Def::Trig(_, a) => mark(&Operand::Value(*a)),
            Def::Input | Def::Expr(_) => {}
        }
    }
    // The room binary64 leaves, over the outputs that have some.
    let worst = s
        .outs
        .iter()
        .filter(|(v, _)| !s.unreachable.contains(v))
        .map(|&(v, b)| e64[v.index()] / b)
        .fold(0.0f64, f64::max);
    let room = (1.0 - worst).max(1e-9);
    // Candidates: value, fraction bits at δ = 0, the first-order error its inputs add at δ = 0.
    let mut cands: Vec<(Value, i32, f64)> = Vec::new();
    let total: f64 =
        values.iter().filter(|v| lam[v.index()] > 0.0 && lam[v.index()].is_finite()).map(|v| cost[v.index()]).sum();
    for &v in &values {
        let (m, err, l) = (x[v.index()].mag(), e64[v.index()], lam[v.index()]);
        let callback = matches!(&f.value(v).def, Def::Call(c, args) if Intrinsic::of(c, args.len()).is_none());
        if !m.is_finite() || !err.is_finite() || frozen[v.index()] || keep(v) || callback || !l.is_finite() {
            continue;
        }
        if l <= 0.0 {
            // No constrained output depends on it: a two-bit word of its range.
            let fr = (2 - int_bits(m + err)).clamp(*FIX_FRACTION_RANGE.start(), *FIX_FRACTION_RANGE.end());
            cands.push((v, fr, 0.0));
            continue;
        }
        let sv = room * cost[v.index()] / total;
        let fr = (l / (2.0 * sv)).log2().ceil();
        if !fr.is_finite() {
            continue;
        }
        cands.push((v, fr.clamp(-1000.0, 1000.0) as i32, room / l));
    }
    // The assignment at shift δ (probe widths), values out of reach of 53 bits left binary64.
    let mut demoted = vec![false; f.values.len()];
    let assign = |delta: i32, demoted: &[bool]| {
        let mut h = g.clone();
        for &(v, fr, fwd) in &cands {
            if demoted[v.index()] {
                continue;
            }
            let fr = if fwd == 0.0 { fr } else { fr + delta };
            let fr = fr.max(*FIX_FRACTION_RANGE.start());
            let top = 2.0 * (x[v.index()].mag() + e64[v.index()] + fwd * 2f64.powi(-delta));
            if !FIX_FRACTION_RANGE.contains(&fr) || int_bits(top) + fr > FIX_MAX_WIDTH as i32 {
                continue;
            }
            if let Some(fmt) = Format::fix(FIX_MAX_WIDTH, fr) {
                h.set_format(v, fmt);
            }
        }
        h
    };
    // Accepted at δ? A value that overflows its 53 bits leaves the candidates (at most 32).
    let mut overflows = 0;
    let mut accepted = |delta: i32, demoted: &mut Vec<bool>, s: &mut Search<'_, S>| -> Option<(Function, Vec<f64>)> {
        loop {
            let h = assign(delta, demoted);
            match s.probe(&h) {
                Ok(e) => return Some((h, e)),
                Err(Refused::Overflow(name)) if overflows < 32 => {
                    overflows += 1;
                    let &(v, ..) = cands.iter().find(|c| f.name_of(c.0) == name)?;
                    demoted[v.index()] = true;
                }
                Err(_) => return None,
            }
        }
    };
    if cands.is_empty() {
        return g.clone();
    }
    // Step 2: the smallest accepted δ in [-24, 40].
    let (mut best, mut lo_fail, mut hi_ok);
    match accepted(0, &mut demoted, s) {
        Some(ok) => {
            best = ok;
            hi_ok = 0;
            lo_fail = None;
            let mut step = 1;
            while step <= 24 {
                match accepted(-step, &mut demoted, s) {
                    Some(ok) => {
                        best = ok;
                        hi_ok = -step;
                        step *= 2;
                    }
                    None => {
                        lo_fail = Some(-step);
                        break;
                    }
                }
            }
        }
        None => {
            let mut step = 1;
            let mut found = None;
            let mut last_fail = 0;
            while step <= 40 && !s.stopped {
                match accepted(step, &mut demoted, s) {
                    Some(ok) => {
                        found = Some((step, ok));
                        break;
                    }
                    None => {
                        last_fail = step;
                        step *= 2;
                    }
                }
            }
            let Some((d, ok)) = found else { return g.clone() };
            best = ok;
            hi_ok = d;
            lo_fail = Some(last_fail);
        }
    }
    if let Some(mut lo) = lo_fail {
        while hi_ok - lo > 1 && !s.stopped {
            let mid = lo + (hi_ok - lo) / 2;
            match accepted(mid, &mut demoted, s) {
                Some(ok) => {
                    best = ok;
                    hi_ok = mid;
                }
                None => lo = mid,
            }
        }
    }
    // Step 3: products down to a DSP mode's operand size, rounds of one bit less on the longest
    // accepted prefix of the ranking, products again.
    let (mut h, mut e) = best;
    let factors = product_operands(f);
    (h, e) = snap(f, h, e, &factors, device, s);
    for _ in 0..ROUNDS {
        if s.stopped {
            break;
        }
        let seeds: Vec<(Value, f64)> =
            s.outs.iter().map(|&(v, b)| (v, 1.0 / (b - e[v.index()]).max(b * 1e-12))).collect();
        let lam = sensitivities(&h, x, &e, &seeds);
        let mut ranked: Vec<(f64, Value, i32)> = values
            .iter()
            .filter_map(|&v| match h.format(v) {
                Format::Fix { fraction, .. } if fraction > *FIX_FRACTION_RANGE.start() => {
                    let damage = lam[v.index()] * 2f64.powi(-fraction - 1);
                    Some((damage / cost[v.index()], v, fraction - 1))
                }
                _ => None,
            })
            .collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
        match s.longest_prefix(&h, &ranked) {
            Some((t, et)) => {
                h = t;
                e = et;
            }
            None => break,
        }
    }
    (h, _) = snap(f, h, e, &factors, device, s);
    h
}

/// How many fixed-point products (`×`, the product of a fused op) each value is an operand of.
fn product_operands(f: &Function) -> Vec<u32> {
    let mut n = vec![0u32; f.values.len()];
    for &v in &f.body {
        let pair = match &f.value(v).def {
            Def::Binary(BinOp::Mul, a, b) => Some((*a, *b)),
            Def::Call(callee, args) if matches!(Intrinsic::of(callee, args.len()), Some(i) if i != Intrinsic::Sqrt) => {
                Some((args[0], args[1]))
            }
            _ => None,
        };
        if let Some((a, b)) = pair {
            for o in [a, b] {
                if let Operand::Value(x) = o {
                    n[x.index()] += 1;
                }
            }
        }
    }
    n
}

/// Step 3's product pass (module doc): each fixed value that is an operand of a product and at most
/// [`SNAP_BITS`] bits wider than an operand size of a DSP mode (9, 18, 19, 27 on the Cyclone V)
/// is offered that size (its fraction bits lowered by the difference), ranked by first-order
/// damage per product; the longest accepted prefix of the ranking is kept (a binary search).
fn snap<S: FnMut() -> bool>(
    f: &Function,
    h: Function,
    e: Vec<f64>,
    factors: &[u32],
    device: &Device,
    s: &mut Search<'_, S>,
) -> (Function, Vec<f64>) {
    let mut sizes: Vec<u32> = device.datapath.dsp_modes.iter().flat_map(|m| [m.a, m.b]).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let seeds: Vec<(Value, f64)> = s.outs.iter().map(|&(v, b)| (v, 1.0 / (b - e[v.index()]).max(b * 1e-12))).collect();
    let lam = sensitivities(&h, s.x, &e, &seeds);
    let mut offers: Vec<(f64, Value, i32)> = Vec::new();
    for &v in f.inputs.iter().chain(&f.body) {
        let Format::Fix { fraction, .. } = h.format(v) else { continue };
        if factors[v.index()] == 0 {
            continue;
        }
        let Some(w) = min_width(s.x[v.index()], e[v.index()], fraction) else { continue };
        let Some(&t) = sizes.iter().rev().find(|&&t| t < w) else { continue };
        let k = (w - t) as i32;
        if k > SNAP_BITS || !FIX_FRACTION_RANGE.contains(&(fraction - k)) {
            continue;
        }
        let damage = lam[v.index()] * (2f64.powi(-fraction - 1 + k) - 2f64.powi(-fraction - 1));
        offers.push((damage / f64::from(factors[v.index()]), v, fraction - k));
    }
    offers.sort_by(|a, b| a.0.total_cmp(&b.0));
    s.longest_prefix(&h, &offers).unwrap_or((h, e))
}

/// The most bits the product pass of step 3 (module doc) takes from a value at once.
pub const SNAP_BITS: i32 = 3;

/// `g` (accepted, its fixed values in probe widths) with every fixed value's width the smallest
/// that holds it ([`min_width`] of its certified bound): one sweep to get the bounds, one to
/// check. Falls back to `g` when the check refuses (never seen: the widths are the bound's own
/// test).
pub fn tighten<S: FnMut() -> bool>(f: &Function, g: &Function, s: &mut Search<'_, S>) -> Function {
    let values: Vec<Value> = f.inputs.iter().chain(&f.body).copied().collect();
    if !values.iter().any(|&v| matches!(g.format(v), Format::Fix { .. })) {
        return g.clone();
    }
    s.sweeps += 1;
    let Ok(e) = bound_with_adjoints(g, s.x, Formats::Mixed, 0, s.adjoints, TrigImpl::Libm, || false) else {
        return g.clone();
    };
    let mut h = g.clone();
    for &v in &values {
        if let Format::Fix { fraction, .. } = g.format(v) {
            if let Some(w) = min_width(s.x[v.index()], e[v.index()], fraction) {
                if let Some(fmt) = Format::fix(w, fraction) {
                    h.set_format(v, fmt);
                }
            }
        }
    }
    s.sweeps += 1;
    match bound_with_adjoints(&h, s.x, Formats::Mixed, 0, s.adjoints, TrigImpl::Libm, || false) {
        Ok(eh) if s.outs.iter().all(|&(v, b)| eh[v.index()] <= b) => h,
        _ => g.clone(),
    }
}

/// Fixed-point values per width.
pub fn widths(f: &Function, g: &Function) -> BTreeMap<u32, usize> {
    let mut out = BTreeMap::new();
    for &v in f.inputs.iter().chain(&f.body) {
        if let Format::Fix { width, .. } = g.format(v) {
            *out.entry(width).or_insert(0) += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_widths_and_the_smallest_word() {
        assert_eq!((const_bits(0.0), const_bits(1.0), const_bits(-0.25), const_bits(8.0)), (0, 0, 0, 0));
        assert_eq!(const_bits(3.0), 3, "two significant bits and the sign");
        assert_eq!(const_bits(0.1), 53, "0x1.999999999999ap-4: 52 significant bits and the sign");
        // [−3, 3] with error 0.1 in steps of 1/4, the bound's test: [−3.1, 3.1] within
        // [−2^(w−1)/4 − 1/8, (2^(w−1) − 1)/4 + 1/8): w = 5 ([−4.125, 3.875)).
        assert_eq!(min_width(Interval::new(-3.0, 3.0), 0.1, 2), Some(5));
        assert_eq!(min_width(Interval::new(0.0, 0.5), 0.0, 2), Some(3));
        assert_eq!(min_width(Interval::new(-1.0, 1.0), 0.0, 60), None);
        assert_eq!(min_width(Interval::new(-1.0, 1.0), f64::INFINITY, 2), None);
    }
}
