//! The search of `precision` (the module doc of [`super`]): rank the cheaper formats by the
//! first-order damage they do to the outputs' bounds, then binary-search the longest prefix
//! of the ranking that the certified bound accepts. `target=fpga` first gives narrow fixed-point
//! words by its own search ([`super::fpga`]), then runs the binary32 phase on the rest.

use std::collections::BTreeMap;

use robovec_ir::format::{Format, FIX_FRACTION_RANGE};
use robovec_ir::{BinOp, Def, Function, Interval, Operand, Value};

use robovec_machine::target::Target as Device;

use super::budget::Budget;
use super::fpga;
use crate::error_bound::bound::{
    bound_with_adjoints, sensitivities, BoundError, Formats, OutputAdjoints, Rounding, TrigImpl,
};

crate::params::word_enum! {
    /// What the formats are chosen for (`target=`).
    pub enum Target {
        /// C on a CPU: binary32 where the bound allows.
        C = "c",
        /// A microcontroller without FPU: 32-bit fixed point first, then binary32.
        Mcu = "mcu",
        /// An FPGA datapath: fixed-point words as narrow as the budget allows, costed in DSP
        /// blocks and ALM from the target description ([`super::fpga`]).
        Fpga = "fpga",
    }
}

/// What `target=fpga` reports besides the common figures.
#[derive(Clone, Debug, PartialEq)]
pub struct FpgaFigures {
    /// The target description's name (`de10-nano`, a JSON file's `name`).
    pub device: String,
    /// DSP blocks with every value binary64, and with the formats ([`super::fpga::resources`]).
    pub dsp: (f64, f64),
    /// ALM, likewise.
    pub alm: (f64, f64),
    /// Fixed-point values per word width.
    pub widths: BTreeMap<u32, usize>,
}

/// The formats chosen for one function and what they give.
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    /// Every value not in binary64, with its format.
    pub formats: Vec<(Value, Format)>,
    /// The target.
    pub target: Target,
    /// The relative budget when every output has the same relative one.
    pub budget: Option<f64>,
    /// Per output with a budget: name, certified bound, budget (absolute), largest magnitude
    /// of its range.
    pub outputs: Vec<(String, f64, f64, f64)>,
    /// Cost with every value binary64, and with the formats.
    pub cost: (f64, f64),
    /// Values per format.
    pub histogram: BTreeMap<String, usize>,
    /// Bound sweeps run by the search.
    pub sweeps: usize,
    /// Outputs whose binary64 bound exceeds the budget: kept as binary64 computes them.
    pub unreachable: Vec<String>,
    /// Outputs without a finite bound (a callback, a divisor near 0): not constrained.
    pub unbounded: Vec<String>,
    /// The search was stopped (`-time-limit`) with the formats accepted so far.
    pub stopped: bool,
    /// `target=fpga`: the device's figures.
    pub fpga: Option<FpgaFigures>,
    /// Per output of [`Choice::outputs`], in order: its certified bound if every binary32 and
    /// fixed-point value had one more bit ([`crate::error_bound::bound::bound_with_more_bits`]),
    /// ∞ where none is finite.
    pub one_more_bit: Vec<f64>,
}

impl Choice {
    /// The report of this choice for function `name`.
    pub fn report(&self, name: &str) -> super::PrecisionReport {
        let worst = self.outputs.iter().map(|(n, b, _, m)| (n, b / m)).max_by(|a, b| a.1.total_cmp(&b.1));
        super::PrecisionReport {
            function: name.to_string(),
            target: self.target.as_str(),
            budget: self.budget,
            formats: self.histogram.clone(),
            max_rel_to_range: worst.map_or(0.0, |w| w.1),
            worst_output: worst.map(|w| w.0.clone()),
            cost_before: self.cost.0,
            cost_after: self.cost.1,
            sweeps: self.sweeps,
            unreachable: self.unreachable.clone(),
            unbounded: self.unbounded.clone(),
            widths: self.fpga.as_ref().map(|x| x.widths.clone()),
            dsp: self.fpga.as_ref().map(|x| x.dsp.1),
            alm: self.fpga.as_ref().map(|x| x.alm.1),
            device: self.fpga.as_ref().map(|x| x.device.clone()),
            ns_per_state: None,
            ns_batch: None,
            outputs: self
                .outputs
                .iter()
                .zip(&self.one_more_bit)
                .map(|((n, bound, budget, _), &more)| {
                    let finite = |x: f64| x.is_finite().then_some(x);
                    (
                        n.clone(),
                        super::OutputBound { bound: finite(*bound), budget: *budget, one_more_bit: finite(more) },
                    )
                })
                .collect(),
        }
    }
}

/// One candidate: value, the format it would take, its first-order damage.
struct Candidate {
    value: Value,
    format: Format,
    damage: f64,
    /// A fixed-point format given one more integer bit after the bound found it may overflow.
    widened: bool,
}

/// Chooses formats for `f` (atomised; its own formats are ignored) whose certified bound keeps
/// every output `o` within its budget (`budgets`, one per output in order: absolute, or
/// relative to `max|o|` over the domain) over the domain whose enclosures are `x`
/// ([`crate::range::enclose_with`]).
///
/// Outputs whose binary64 bound already exceeds the budget keep their binary64 bound as
/// theirs ([`Choice::unreachable`]); outputs with no finite bound are not constrained
/// ([`Choice::unbounded`]).
///
/// `stop` is read before each sweep of the search: once it says stop, the search keeps the
/// formats accepted so far ([`Choice::stopped`]; the final check still runs).
///
/// `target=fpga` is costed on the built-in DE10-Nano ([`choose_on`] takes a target description).
///
/// # Errors
/// A message (`@f: …`) when the enclosures cannot be bounded at all (never for a function the
/// enclosures accept) or, as an internal error, when the final formats fail the bound.
pub fn choose(
    f: &Function,
    x: &[Interval],
    budgets: &[Budget],
    target: Target,
    stop: impl FnMut() -> bool,
) -> Result<Choice, String> {
    choose_on(f, x, budgets, target, &Device::de10_nano(), TrigImpl::Libm, MCU_WORD, stop)
}

/// [`choose`] for the target description `device` (what `target=fpga` costs against: its DSP
/// blocks, ALM and [`robovec_machine::target::Datapath`]; the other targets ignore it) and the
/// `sin`/`cos` the code will call (`trig`: [`TrigImpl::Inline`] for `codegen<c;trig=inline>`,
/// whose binary32 kernel is allowed 1 ulp where the C library is allowed 4) and, for
/// `target=mcu`, the fixed-point word (`word`, bits: `fix<word,f>`; [`MCU_WORD`] = 32 is a
/// microcontroller's register, narrower words are for fixed-point PEs whose products fit one
/// DSP multiplier, docs/fpga.md; the other targets ignore it).
///
/// # Errors
/// As [`choose`].
pub fn choose_on(
    f: &Function,
    x: &[Interval],
    budgets: &[Budget],
    target: Target,
    device: &Device,
    trig: TrigImpl,
    word: u32,
    mut stop: impl FnMut() -> bool,
) -> Result<Choice, String> {
    assert!(MCU_WORDS.contains(&word), "word {word} outside {MCU_WORDS:?}");
    assert_eq!(budgets.len(), f.outputs.len(), "one budget per output");
    let mut g = f_with_default(f);
    let values: Vec<Value> = f.inputs.iter().chain(&f.body).copied().collect();
    // The outputs' adjoints depend on the ops and the enclosures only: once for every sweep.
    let adjoints = OutputAdjoints::new(f, x);
    let adjoints = adjoints.as_ref();
    let bound = |h: &Function, x: &[Interval], mode| bound_with_adjoints(h, x, mode, 0, adjoints, trig, || false);
    let e64 = bound(&g, x, Formats::Mixed).map_err(|e| e.message(&f.name))?;
    // Outputs with a budget: those whose range is not 0. One whose binary64 bound already
    // exceeds it keeps that bound as its budget (it stays as binary64 computes it); one with
    // no finite bound is left out (nothing about it can be proved).
    let mut outs: Vec<(String, Value, f64)> = Vec::new();
    let (mut unreachable, mut unbounded) = (Vec::new(), Vec::new());
    for (o, budget) in f.outputs.iter().zip(budgets) {
        let Operand::Value(v) = o.value else { continue };
        let m = x[v.index()].mag();
        if !m.is_finite() || !e64[v.index()].is_finite() {
            unbounded.push(o.name.clone());
            continue;
        }
        let mut b = budget.absolute(m);
        if b <= 0.0 {
            continue;
        }
        if e64[v.index()] > b {
            unreachable.push(o.name.clone());
            b = e64[v.index()];
        }
        outs.push((o.name.clone(), v, b));
    }
    // The bound takes `a − a` as exactly 0, but it is NaN when the computed `a` is infinite or
    // NaN, which only an infinite bound of `a` allows: so the operand of each keeps a finite
    // bound (a guard: at most its magnitude or twice its binary64 bound, checked with the
    // outputs' budgets), and the values computed from one whose binary64 bound is already
    // infinite are marked (`target=fpga` leaves them binary64).
    let mut guards: Vec<(Value, f64)> = Vec::new();
    let mut poisoned = vec![false; f.values.len()];
    for &v in &f.body {
        let def = &f.value(v).def;
        if let Def::Binary(BinOp::Sub, Operand::Value(a), Operand::Value(b)) = def {
            let ea = e64[a.index()];
            if a == b && ea.is_finite() {
                guards.push((*a, (2.0 * ea).max(x[a.index()].mag()).max(f64::MIN_POSITIVE)));
            } else if a == b {
                poisoned[v.index()] = true;
            }
        }
        if def.operands().iter().any(|o| matches!(o, Operand::Value(a) if poisoned[a.index()])) {
            poisoned[v.index()] = true;
        }
    }
    let seeds: Vec<(Value, f64)> =
        outs.iter().map(|&(_, v, b)| (v, 1.0 / b)).chain(guards.iter().map(|&(v, b)| (v, 1.0 / b))).collect();
    let lam = sensitivities(&g, x, &e64, &seeds);
    let mut sweeps = 0;
    // The bounds when `h`'s formats meet every budget; otherwise `Err` with the fixed-point
    // value that may overflow, if that is why.
    let check = |h: &Function, sweeps: &mut usize| -> Result<Vec<f64>, Option<String>> {
        *sweeps += 1;
        let e = bound(h, x, Formats::Mixed).map_err(|err| match err {
            BoundError::FixOverflow { value, .. } => Some(value),
            BoundError::Stopped(_) => None,
        })?;
        if outs.iter().all(|&(_, v, b)| e[v.index()] <= b) && guards.iter().all(|&(v, b)| e[v.index()] <= b) {
            Ok(e)
        } else {
            Err(None)
        }
    };
    let accepts = |h: &Function, sweeps: &mut usize| check(h, sweeps).ok();
    let fix_word = move |m: f64, err: f64| fix_in(word, m, err);
    let phases: &[&dyn Fn(f64, f64) -> Option<Format>] = match target {
        Target::C | Target::Fpga => &[&binary32],
        Target::Mcu => &[&fix_word, &binary32],
    };
    let mut stopped = false;
    let reached: Vec<Value> = outs.iter().filter(|(n, ..)| unreachable.contains(n)).map(|o| o.1).collect();
    let budgeted: Vec<(Value, f64)> = outs.iter().map(|&(_, v, b)| (v, b)).chain(guards.iter().copied()).collect();
    let search = |stop| {
        let mut s = fpga::Search::new(x, budgeted.clone(), reached.clone(), stop);
        s.keep = poisoned.clone();
        s.adjoints = adjoints;
        s
    };
    if target == Target::Fpga {
        // Narrow fixed-point words first (in probe widths of 53 bits until `tighten`).
        let mut s = search(&mut stop);
        g = fpga::fixed_phase(f, &g, &e64, device, &mut s);
        sweeps += s.sweeps;
        stopped = s.stopped;
    }
    for phase in phases {
        if stopped {
            break;
        }
        let mut candidates: Vec<Candidate> = values
            .iter()
            .filter_map(|&v| {
                let (m, err) = (x[v.index()].mag(), e64[v.index()]);
                if !m.is_finite() || !err.is_finite() || !g.format(v).is_default() {
                    return None;
                }
                let format = phase(m, err)?;
                let r = Rounding::store(format);
                let added = r.rel * (m + err) + r.abs;
                Some(Candidate { value: v, format, damage: lam[v.index()] * added, widened: false })
            })
            .collect();
        candidates.sort_by(|a, b| a.damage.total_cmp(&b.damage));
        // The longest accepted prefix (k = 0 is the current assignment, accepted).
        let with = |candidates: &[Candidate], k: usize| {
            let mut h = g.clone();
            for c in &candidates[..k] {
                h.set_format(c.value, c.format);
            }
            h
        };
        // A fixed-point candidate whose range the others' added error pushes out of its format
        // stops the prefix there: it leaves the ranking and the search goes on (at most 64
        // times per phase, each a binary search).
        let mut lo = 0usize;
        for _ in 0..64 {
            let mut hi = candidates.len();
            let mut overflow = None;
            while lo < hi {
                if stop() {
                    stopped = true;
                    break;
                }
                let mid = (lo + hi).div_ceil(2);
                match check(&with(&candidates, mid), &mut sweeps) {
                    Ok(_) => lo = mid,
                    Err(o) => {
                        overflow = overflow.or(o);
                        hi = mid - 1;
                    }
                }
            }
            if stopped {
                break;
            }
            let Some(name) = overflow else { break };
            let Some(j) = candidates.iter().position(|c| f.name_of(c.value) == name) else { break };
            if j < lo {
                break;
            }
            // A fixed-point candidate gets one more integer bit; one that has it already (or
            // another format) leaves the ranking.
            match candidates[j].format {
                Format::Fix { width, fraction } if fraction > *FIX_FRACTION_RANGE.start() && !candidates[j].widened => {
                    candidates[j].format = Format::fix(width, fraction - 1).expect("a narrower fraction is a format");
                    candidates[j].widened = true;
                }
                _ => {
                    candidates.remove(j);
                }
            }
        }
        // Cost is not monotone in the prefix (conversions between formats cost too): the
        // cheapest of 17 accepted prefixes, 0 and `lo` included, if the bound accepts it.
        let mut best = (cost(f, &g, target, device), 0usize);
        for i in 1..=16 {
            let k = lo * i / 16;
            let c = cost(f, &with(&candidates, k), target, device);
            if c < best.0 {
                best = (c, k);
            }
        }
        // (After a stop only `lo`, accepted, is kept: no further sweep.)
        let k = if !stopped && best.1 != lo && accepts(&with(&candidates, best.1), &mut sweeps).is_some() {
            best.1
        } else {
            lo
        };
        g = with(&candidates, k);
    }
    if target == Target::Fpga {
        let mut s = fpga::Search::new(x, budgeted.clone(), reached.clone(), || false);
        s.adjoints = adjoints;
        g = fpga::tighten(f, &g, &mut s);
        sweeps += s.sweeps;
    }
    let e = accepts(&g, &mut sweeps)
        .ok_or_else(|| format!("@{}: internal error: the chosen formats fail (please report)", f.name))?;
    let mut histogram = BTreeMap::new();
    let mut formats = Vec::new();
    for &v in &values {
        let fmt = g.format(v);
        *histogram.entry(fmt.to_string()).or_insert(0) += 1;
        if !fmt.is_default() {
            formats.push((v, fmt));
        }
    }
    let budget = match budgets.first() {
        Some(&Budget::Rel(r)) if budgets.iter().all(|b| *b == Budget::Rel(r)) => Some(r),
        _ => None,
    };
    let more = bound_with_adjoints(&g, x, Formats::Mixed, 1, adjoints, trig, || false).ok();
    let one_more_bit = outs.iter().map(|(_, v, _)| more.as_ref().map_or(f64::INFINITY, |m| m[v.index()])).collect();
    Ok(Choice {
        one_more_bit,
        formats,
        target,
        budget,
        outputs: outs.iter().map(|(n, v, b)| (n.clone(), e[v.index()], *b, x[v.index()].mag())).collect(),
        cost: (cost(f, &f_with_default(f), target, device), cost(f, &g, target, device)),
        histogram,
        sweeps,
        unreachable,
        unbounded,
        stopped,
        fpga: (target == Target::Fpga).then(|| {
            let before = fpga::resources(f, &f_with_default(f), device);
            let after = fpga::resources(f, &g, device);
            FpgaFigures {
                device: device.name.clone(),
                dsp: (before.0, after.0),
                alm: (before.1, after.1),
                widths: fpga::widths(f, &g),
            }
        }),
    })
}

/// `f` with every value binary64.
fn f_with_default(f: &Function) -> Function {
    let mut g = f.clone();
    g.clear_formats();
    g
}

/// Binary32 for a value of magnitude `m` and error `err`, unless it may overflow.
fn binary32(m: f64, err: f64) -> Option<Format> {
    (m + err < f32::MAX as f64 / 2.0).then_some(Format::Binary32)
}

/// `target=mcu`'s default word: 32 bits (a microcontroller's register).
pub const MCU_WORD: u32 = 32;

/// The words `target=mcu` takes (`precision<word=W>`), bits.
pub const MCU_WORDS: std::ops::RangeInclusive<u32> = 8..=32;

/// `fix<word,f>` for a value of magnitude `m` and error `err`: the fewest integer bits (the sign
/// included) that hold `(m + err)·(1 + 2⁻¹⁰)` and at least 2⁻¹⁶ — the margin for the error the
/// formats add; a value the bound still finds may overflow gets one more integer bit
/// ([`choose_on`]'s repair).
fn fix_in(word: u32, m: f64, err: f64) -> Option<Format> {
    // At least 2⁻¹⁶ of range: a value near 0 still holds the error its operands' roundings add.
    let top = ((m + err) * (1.0 + 2f64.powi(-10))).max(2f64.powi(-16));
    // |x| ≤ top < 2^(int_bits − 1): int_bits = ⌊log₂ top⌋ + 2.
    let int_bits = if top < f64::MIN_POSITIVE { -60 } else { top.log2().floor() as i32 + 2 };
    let fraction = word as i32 - int_bits;
    FIX_FRACTION_RANGE.contains(&fraction).then(|| Format::fix(word, fraction)).flatten()
}

/// `mcu`'s estimated cycles of one conversion between formats: a fixed-point store from
/// `double` (`robovec_fix_from`) is five software floating-point routines on a core without an
/// FPU (`__aeabi_dmul`, `floor`, `__aeabi_dsub`, `__aeabi_dcmpge`, `__aeabi_d2lz`: clang 14,
/// `thumbv7m`, `-O2`), a read into `double` two (`__aeabi_i2d`, `__aeabi_dmul`), each some tens of
/// cycles: an order of magnitude, as the model's other figures.
const MCU_CONVERSION: f64 = 150.0;

/// The cost of `f` under `g`'s formats for `target` (the module doc's model; `fpga`'s is the
/// device share of [`fpga::resources`] on `device`).
fn cost(f: &Function, g: &Function, target: Target, device: &Device) -> f64 {
    if target == Target::Fpga {
        let (dsp, alm) = fpga::resources(f, g, device);
        return fpga::share(dsp, alm, device);
    }
    let mut total = 0.0;
    for &v in &f.body {
        let fv = g.format(v);
        let operands = f.value(v).def.operands();
        let conversions =
            operands.iter().filter(|o| matches!(o, Operand::Value(a) if g.format(*a) != fv)).count() as f64;
        total += match (target, fv) {
            (Target::C, Format::Binary32) => 0.5 + 0.5 * conversions,
            (Target::C, _) => 1.0 + 0.5 * conversions,
            (Target::Mcu, Format::Fix { .. }) => match robovec_ir::format::integer_op(g, v) {
                // Integer adds and multiplies (a product 3), one shift to align or round.
                Some(op) => {
                    let terms: f64 = op.terms.iter().map(|t| if t.factors.len() == 2 { 3.0 } else { 1.0 }).sum();
                    terms + if op.shift != 0 { 1.0 } else { 0.0 }
                }
                // A binary64 op on the operands' values, then the store: each operand not in
                // binary64 converted, and the result.
                None => {
                    let wide = operands
                        .iter()
                        .filter(|o| matches!(o, Operand::Value(a) if !g.format(*a).is_default()))
                        .count();
                    100.0 + MCU_CONVERSION * (wide as f64 + 1.0)
                }
            },
            (Target::Mcu, Format::Binary32) => 50.0 + MCU_CONVERSION * conversions,
            (Target::Mcu, Format::Binary64) => 100.0 + MCU_CONVERSION * conversions,
            (Target::Fpga, _) => unreachable!("costed above"),
        };
    }
    total
}
