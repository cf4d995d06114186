//! Affine arithmetic with a capped number of noise symbols (Comba & Stolfi 1993; de Figueiredo
//! & Stolfi 2004): the correlation-aware layer of `range<method=affine>`.
//!
//! Each value is an **affine form** `x = c + Σ xᵢ·εᵢ` over **noise symbols** `εᵢ ∈ [−1, 1]`:
//! one per input of nonzero width (its range is `mid + rad·ε`), and one **own symbol** per
//! value that holds what the value adds — the nonlinear part of a product, the error of the
//! linear approximation of `1/t`, `√t`, `sin`, `cos`, the rounding of the form's coefficients
//! and of the binary64 operation itself. Forms share symbols, so `x − x`, `x·y − y·x` and the
//! sums of a recursion that re-read the same inputs cancel where interval arithmetic adds
//! widths.
//!
//! **Cap.** A form keeps at most `cap` symbols (the parameter `terms`, default
//! [`DEFAULT_TERMS`], 64): when an operation gives more, the smallest coefficients are summed
//! (rounded up) into the value's own symbol. Each operation thus costs O(cap) (merges of sorted
//! lists; the cap's selection is a partial sort), and the sweep is O(ops · cap) in time; forms
//! are dropped after their value's last use, so memory is O(live values · cap).
//!
//! **Soundness.** Every coefficient is computed in round-to-nearest and its rounding error
//! bounded (`|fl(t) − t| ≤ u·|fl(t)|` with `u = 2⁻⁵²`, twice the unit roundoff, plus 10⁻³⁰⁰ for
//! underflow) and added to the own symbol; the form's range `c ± Σ|xᵢ|` is summed with
//! outward rounding. Each operation's own symbol also covers the rounding of the binary64
//! operation on the computed operands (`u`·magnitude of its interval enclosure), so a form
//! encloses both the exact value and the interpreter's binary64 value (the same argument as
//! for intervals: the computed value is a point of the form with the inputs' symbols at the
//! input and other values of the own symbols). The pass intersects each form's range with the
//! value's interval enclosure (both sound), and uses that intersection to bound the nonlinear
//! part of a product (`|Σxᵢεᵢ| ≤ min(Σ|xᵢ|, max(|lo − c|, |hi − c|))`).

use robovec_ir::domain::Domain;
use robovec_ir::{BinOp, Def, Function, Interval, Intrinsic, Operand, TrigFn};

use super::enclose::EncloseError;

/// Default cap on the noise symbols of one affine form.
pub const DEFAULT_TERMS: usize = 64;

/// `2⁻⁵²`: twice the unit roundoff of binary64, the bound used for one rounding of a
/// coefficient (relative), generous on purpose.
const U: f64 = f64::EPSILON;

/// Absolute slack per rounding for underflow (10⁻³⁰⁰, far above the largest gradual-underflow
/// error 2⁻¹⁰⁷⁴).
const TINY: f64 = 1e-300;

/// An affine form: centre, terms `(symbol, coefficient)` sorted by symbol, no zero coefficient.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Form {
    /// The centre `c`.
    pub centre: f64,
    /// `(symbol, coefficient)`, sorted by symbol.
    pub terms: Vec<(u32, f64)>,
}

/// Sums nonnegative numbers rounded up.
fn sum_up(xs: impl IntoIterator<Item = f64>) -> f64 {
    xs.into_iter().fold(Interval::point(0.0), |acc, x| acc + Interval::point(x)).hi
}

impl Form {
    /// The point `x`.
    pub fn point(x: f64) -> Form {
        Form { centre: x, terms: Vec::new() }
    }

    /// `Σ|xᵢ|` rounded up: the radius around the centre.
    pub fn radius(&self) -> f64 {
        sum_up(self.terms.iter().map(|t| t.1.abs()))
    }

    /// The range `c ± Σ|xᵢ|`, rounded outward.
    pub fn range(&self) -> Interval {
        let r = self.radius();
        Interval::point(self.centre) + Interval::new(-r, r)
    }
}

/// Accumulates the rounding errors and approximation errors of one operation (each a bound,
/// nonnegative), rounded up.
struct Slack(Interval);

impl Slack {
    fn new() -> Slack {
        Slack(Interval::point(0.0))
    }
    fn add(&mut self, e: f64) {
        self.0 = self.0 + Interval::point(e.abs());
    }
    /// The bound for a result `z` computed in one rounding.
    fn round(&mut self, z: f64) {
        self.add(z.abs() * U + TINY);
    }
    fn total(&self) -> f64 {
        self.0.hi
    }
}

/// The form `a·x + b·y + d` (one linear combination), with the roundings in `slack`.
fn combine(x: &Form, a: f64, y: &Form, b: f64, d: f64, slack: &mut Slack) -> (f64, Vec<(u32, f64)>) {
    let c = a * x.centre + b * y.centre + d;
    // Two products, two sums: four roundings bounded by 4u of the magnitudes.
    slack.add(4.0 * U * ((a * x.centre).abs() + (b * y.centre).abs() + d.abs() + c.abs()) + 4.0 * TINY);
    let mut terms = Vec::with_capacity(x.terms.len() + y.terms.len());
    let (mut i, mut j) = (0, 0);
    while i < x.terms.len() || j < y.terms.len() {
        let (s, z, mag) = match (x.terms.get(i), y.terms.get(j)) {
            (Some(&(s, p)), Some(&(t, _))) if s < t => {
                i += 1;
                (s, a * p, (a * p).abs())
            }
            (Some(&(s, _)), Some(&(t, q))) if t < s => {
                j += 1;
                (t, b * q, (b * q).abs())
            }
            (Some(&(s, p)), Some(&(_, q))) => {
                i += 1;
                j += 1;
                (s, a * p + b * q, (a * p).abs() + (b * q).abs())
            }
            (Some(&(s, p)), None) => {
                i += 1;
                (s, a * p, (a * p).abs())
            }
            (None, Some(&(t, q))) => {
                j += 1;
                (t, b * q, (b * q).abs())
            }
            (None, None) => unreachable!(),
        };
        // A product and a sum: at most 3u of the magnitudes (u = 2⁻⁵² is twice the roundoff).
        slack.add(2.0 * U * mag + 2.0 * TINY);
        if z != 0.0 {
            terms.push((s, z));
        }
    }
    (c, terms)
}

/// The forms of a function's values, swept in body order.
pub struct AffineSweep<'f> {
    f: &'f Function,
    cap: usize,
    forms: Vec<Option<Form>>,
    /// Remaining uses of each value (forms are dropped at 0).
    uses: Vec<u32>,
}

impl<'f> AffineSweep<'f> {
    /// A sweep over `f` with forms of at most `cap` symbols (≥ 2), the inputs' forms from
    /// `domain` (each input of nonzero width gets its own symbol, its value's index).
    pub fn new(f: &'f Function, domain: &Domain, cap: usize) -> AffineSweep<'f> {
        let mut uses = vec![0u32; f.values.len()];
        let count = |o: &Operand, uses: &mut Vec<u32>| {
            if let Operand::Value(v) = o {
                uses[v.index()] += 1;
            }
        };
        for &v in &f.body {
            match &f.value(v).def {
                Def::Trig(_, a) => uses[a.index()] += 1,
                Def::Binary(_, a, b) => {
                    count(a, &mut uses);
                    count(b, &mut uses);
                }
                Def::Call(_, args) => args.iter().for_each(|a| count(a, &mut uses)),
                Def::Input | Def::Expr(_) => {}
            }
        }
        let mut forms = vec![None; f.values.len()];
        for &v in &f.inputs {
            let Some(r) = domain.get(f.name_of(v)) else { continue };
            let i = r.interval;
            // mid ± rad with mid, rad rounded: rad taken up so that [lo, hi] ⊂ mid ± rad.
            let mid = i.lo / 2.0 + i.hi / 2.0;
            let rad = (Interval::point(i.hi) - Interval::point(mid))
                .hi
                .max((Interval::point(mid) - Interval::point(i.lo)).hi);
            let terms = if rad > 0.0 { vec![(v.index() as u32, rad)] } else { Vec::new() };
            forms[v.index()] = Some(Form { centre: mid, terms });
        }
        AffineSweep { f, cap: cap.max(2), forms, uses }
    }

    fn form(&self, o: &Operand) -> Form {
        match o {
            Operand::Const(c) => Form::point(*c),
            Operand::Value(v) => self.forms[v.index()].clone().unwrap_or_default(),
        }
    }

    fn release(&mut self, o: &Operand) {
        if let Operand::Value(v) = o {
            let u = &mut self.uses[v.index()];
            *u = u.saturating_sub(1);
            if *u == 0 {
                self.forms[v.index()] = None;
            }
        }
    }

    /// The part `Σxᵢεᵢ` of `x` bounded with its interval enclosure `ix` too.
    fn spread(x: &Form, ix: Interval) -> f64 {
        let r = x.radius();
        let from_interval = (ix.hi - x.centre).abs().max((x.centre - ix.lo).abs()) * (1.0 + 2.0 * U);
        if from_interval.is_finite() {
            r.min(from_interval)
        } else {
            r
        }
    }

    /// The form of body value `v`, given every value's interval enclosure so far in `x`
    /// (`x[v]` already holds `v`'s own): returns the enclosure, the form's range intersected
    /// with `x[v]`. An unbounded value (a callback's, an overflow) keeps its interval and has
    /// no form; a value that reads one gets a form of its own from its interval
    /// (`mid ± rad` on its own symbol), as does a value when that is narrower.
    pub fn step(&mut self, v: robovec_ir::Value, x: &[Interval]) -> Result<Interval, EncloseError> {
        let f = self.f;
        let data = f.value(v);
        let own = v.index() as u32;
        let iv = x[v.index()];
        let mut slack = Slack::new();
        // The rounding of the binary64 operation itself on the computed operands.
        let op_rounding = |slack: &mut Slack| slack.add(iv.mag() * U + TINY);
        let interval_of = |o: &Operand| super::enclose::of(x, o);
        let formless = |o: &Operand| matches!(o, Operand::Value(p) if self.forms[p.index()].is_none());
        let reads_formless = match &data.def {
            Def::Trig(_, a) => formless(&Operand::Value(*a)),
            Def::Binary(_, a, b) => formless(a) || formless(b),
            Def::Call(_, args) => args.iter().any(formless),
            Def::Input | Def::Expr(_) => false,
        };
        let (centre, mut terms) = match &data.def {
            Def::Input | Def::Expr(_) => (0.0, Vec::new()),
            _ if iv.is_bounded() && reads_formless => {
                self.finish_operands(&data.def);
                if self.uses[v.index()] > 0 {
                    self.forms[v.index()] = Some(own_interval(iv, own));
                }
                return Ok(iv);
            }
            _ if !iv.is_bounded() => {
                self.finish_operands(&data.def);
                self.forms[v.index()] = None;
                return Ok(iv);
            }
            Def::Trig(t, a) => {
                let q = self.form(&Operand::Value(*a));
                let ia = x[a.index()];
                let r = Self::spread(&q, ia);
                // First order about the centre: sin(c + h) = sin c + cos c·h + R, |R| ≤ h²/2
                // (|sin''|, |cos''| ≤ 1), with the libm's error on sin c, cos c. Taken only when
                // it is narrower than the interval: otherwise the value is mid ± rad of its own.
                let (s, c) = (q.centre.sin(), q.centre.cos());
                let (v0, d) = match t {
                    TrigFn::Sin => (s, c),
                    TrigFn::Cos => (c, -s),
                };
                let libm = 4.0 * U + TINY;
                let taylor = d.abs() * r + r * r / 2.0 + 2.0 * libm;
                if r.is_finite() && taylor < iv.width() / 2.0 && q.centre.abs() < 1e6 {
                    slack.add(r * r / 2.0 * (1.0 + 4.0 * U));
                    // sin c and cos c each within `libm`; the interpreter's own sin at the point too.
                    slack.add(libm * (2.0 + r));
                    // The constant v0 − d·c is itself rounded twice.
                    let k = v0 - d * q.centre;
                    slack.add(2.0 * U * (v0.abs() + (d * q.centre).abs() + k.abs()) + TINY);
                    let (c0, t) = combine(&q, d, &Form::point(0.0), 0.0, k, &mut slack);
                    self.finish_operands(&data.def);
                    (c0, t)
                } else {
                    self.finish_operands(&data.def);
                    self.forms[v.index()] = Some(own_interval(iv, own));
                    return Ok(iv);
                }
            }
            Def::Binary(op, a, b) => {
                let same = super::enclose::same_pair(a, b);
                let (fa, fb) = (self.form(a), self.form(b));
                let r = match op {
                    BinOp::Add => combine(&fa, 1.0, &fb, 1.0, 0.0, &mut slack),
                    BinOp::Sub if same => (0.0, Vec::new()),
                    BinOp::Sub => combine(&fa, 1.0, &fb, -1.0, 0.0, &mut slack),
                    BinOp::Mul => {
                        let (ra, rb) = (Self::spread(&fa, interval_of(a)), Self::spread(&fb, interval_of(b)));
                        mul(&fa, &fb, ra, rb, same, &mut slack)
                    }
                    BinOp::Div => {
                        // a · (1/b), 1/b by its min-range linear approximation over b's enclosure.
                        let ib = interval_of(b);
                        let recip = reciprocal(&fb, ib, own, &mut slack);
                        let ra = Self::spread(&fa, interval_of(a));
                        let rr = recip.radius();
                        mul(&fa, &recip, ra, rr, false, &mut slack)
                    }
                };
                if !same || *op != BinOp::Sub {
                    op_rounding(&mut slack);
                }
                self.finish_operands(&data.def);
                r
            }
            Def::Call(callee, args) => {
                let forms: Vec<Form> = args.iter().map(|o| self.form(o)).collect();
                let spreads: Vec<f64> =
                    args.iter().zip(&forms).map(|(o, fo)| Self::spread(fo, interval_of(o))).collect();
                let r = match Intrinsic::of(callee, args.len()) {
                    Some(Intrinsic::Sqrt) => sqrt(&forms[0], interval_of(&args[0]), &mut slack),
                    Some(i) => {
                        // a square (`fma(x, x, c)`) as `x · x`: its product is the square
                        let same = super::enclose::same_pair(&args[0], &args[1]);
                        let (c0, t) = mul(&forms[0], &forms[1], spreads[0], spreads[1], same, &mut slack);
                        let p = Form { centre: c0, terms: t };
                        let p = if i == Intrinsic::Fnma { negate(&p) } else { p };
                        let sign = if i == Intrinsic::Fms { -1.0 } else { 1.0 };
                        combine(&p, 1.0, &forms[2], sign, 0.0, &mut slack)
                    }
                    None => unreachable!("a callback's enclosure is unbounded"),
                };
                op_rounding(&mut slack);
                self.finish_operands(&data.def);
                r
            }
        };
        // Cap: the smallest coefficients beyond cap − 1 go to the own symbol.
        if terms.len() >= self.cap {
            // Largest first (keeping the inputs' symbols first measured worse: 30-dof chain, 64
            // symbols, median ratio 3279 against 2040).
            terms.sort_unstable_by(|p, q| q.1.abs().total_cmp(&p.1.abs()));
            for t in terms.drain(self.cap - 1..) {
                slack.add(t.1);
            }
            terms.sort_unstable_by_key(|t| t.0);
        }
        put_own(&mut terms, own, slack.total());
        let form = Form { centre, terms };
        let r = form.range();
        let enclosure = Interval::new(r.lo.max(iv.lo), r.hi.min(iv.hi));
        if self.uses[v.index()] > 0 {
            self.forms[v.index()] = Some(form);
        }
        Ok(enclosure)
    }

    fn finish_operands(&mut self, def: &Def) {
        match def {
            Def::Trig(_, a) => self.release(&Operand::Value(*a)),
            Def::Binary(_, a, b) => {
                self.release(a);
                self.release(b);
            }
            Def::Call(_, args) => args.iter().for_each(|a| self.release(a)),
            Def::Input | Def::Expr(_) => {}
        }
    }
}

/// `−x` (exact).
fn negate(x: &Form) -> Form {
    Form { centre: -x.centre, terms: x.terms.iter().map(|&(s, c)| (s, -c)).collect() }
}

/// A value of its own: `mid ± rad` of interval `i` on symbol `own`.
fn own_interval(i: Interval, own: u32) -> Form {
    let mid = i.lo / 2.0 + i.hi / 2.0;
    let rad = (Interval::point(i.hi) - Interval::point(mid)).hi.max((Interval::point(mid) - Interval::point(i.lo)).hi);
    Form { centre: mid, terms: if rad > 0.0 { vec![(own, rad)] } else { Vec::new() } }
}

/// `x · y` (or `x²` when `same`): `cx·cy + cx·Σyᵢεᵢ + cy·Σxᵢεᵢ` and the nonlinear part
/// `(Σxᵢεᵢ)(Σyᵢεᵢ)`, bounded by `rx·ry` (for a square, in `[0, rx²]`: centred at `rx²/2`).
fn mul(x: &Form, y: &Form, rx: f64, ry: f64, same: bool, slack: &mut Slack) -> (f64, Vec<(u32, f64)>) {
    let (cx, cy) = (x.centre, y.centre);
    let mut lin_x = x.clone();
    lin_x.centre = 0.0;
    let mut lin_y = y.clone();
    lin_y.centre = 0.0;
    let (_, terms) = combine(&lin_y, cx, &lin_x, cy, 0.0, slack);
    let mut centre = cx * cy;
    slack.round(centre);
    let nonlinear = rx * ry * (1.0 + 2.0 * U);
    if same {
        // (Σxᵢεᵢ)² ∈ [0, rx²]: centre + rx²/2 ± rx²/2.
        let half = nonlinear / 2.0;
        let c2 = centre + half;
        slack.round(c2);
        centre = c2;
        slack.add(half);
    } else {
        slack.add(nonlinear);
    }
    (centre, terms)
}

/// `1/y` over `y`'s enclosure `iy` (not holding 0): the min-range linear approximation
/// `α·y + ζ ± δ` ([`reciprocal_line`]).
fn reciprocal(y: &Form, iy: Interval, own: u32, slack: &mut Slack) -> Form {
    let Some((alpha, zeta, delta)) = reciprocal_line(iy) else { return own_unknown(iy, own, slack) };
    // The approximation's error δ and the combination's roundings on the own symbol, kept in
    // the form: the quotient multiplies them by the dividend.
    let mut own_slack = Slack::new();
    own_slack.add(delta);
    let (c, mut terms) = combine(y, alpha, &Form::point(0.0), 0.0, zeta, &mut own_slack);
    put_own(&mut terms, own, own_slack.total());
    Form { centre: c, terms }
}

/// The min-range linear approximation of `1/t` over `iy` (not holding 0): `(α, ζ, δ)` with
/// `|1/t − (α·t + ζ)| ≤ δ` for every `t` of `iy`, `α = −1/b²` at the end `b` of largest magnitude
/// (`1/t − αt` is monotone on the enclosure), all computed with intervals; `None` when a
/// coefficient is not finite.
pub(super) fn reciprocal_line(iy: Interval) -> Option<(f64, f64, f64)> {
    let neg = iy.hi < 0.0;
    let (a, b) = if neg { (-iy.hi, -iy.lo) } else { (iy.lo, iy.hi) };
    // On [a, b] (0 < a ≤ b): g(t) = 1/t + t/b² decreases, so g ∈ [g(b), g(a)] = [2/b, 1/a + a/b²].
    let one = Interval::point(1.0);
    let (ia, ib) = (Interval::point(a), Interval::point(b));
    let b2 = one.checked_div(ib * ib)?;
    // |α| ≤ 1/b² keeps g monotone: g'(t) = −1/t² − α ≤ −1/t² + 1/b² ≤ 0.
    let alpha = -b2.lo;
    let g = |t: Interval| one.checked_div(t).map(|r| r - Interval::point(alpha) * t);
    let (ga, gb) = (g(ia)?, g(ib)?);
    let lo = ga.lo.min(gb.lo);
    let hi = ga.hi.max(gb.hi);
    let zeta = lo / 2.0 + hi / 2.0;
    let delta = (Interval::point(hi) - Interval::point(zeta)).hi.max((Interval::point(zeta) - Interval::point(lo)).hi);
    if !(alpha.is_finite() && zeta.is_finite() && delta.is_finite()) {
        return None;
    }
    // For y < 0: 1/y = −1/(−y) = −(α·(−y) + ζ) = α·y − ζ.
    Some((alpha, if neg { -zeta } else { zeta }, delta))
}

/// Adds `e ≥ 0` to the coefficient of symbol `own` in `terms` (sorted), as a magnitude: a
/// value's own symbol appears in no other value's definition, so its sign is free.
fn put_own(terms: &mut Vec<(u32, f64)>, own: u32, e: f64) {
    if e <= 0.0 {
        return;
    }
    match terms.binary_search_by_key(&own, |t| t.0) {
        Ok(k) => terms[k].1 = (Interval::point(terms[k].1.abs()) + Interval::point(e)).hi,
        Err(k) => terms.insert(k, (own, e)),
    }
}

/// The form of `1/y` when the approximation fails: the interval of `1/y` on the own symbol.
fn own_unknown(iy: Interval, own: u32, slack: &mut Slack) -> Form {
    let _ = slack;
    let r = Interval::point(1.0).checked_div(iy).unwrap_or(Interval::ENTIRE);
    own_interval(r, own)
}

/// `√x` over `x`'s enclosure `ix` (nonnegative): the min-range approximation
/// [`sqrt_line`], or the interval of `√x` when it fails.
fn sqrt(x: &Form, ix: Interval, slack: &mut Slack) -> (f64, Vec<(u32, f64)>) {
    let Some((alpha, zeta, delta)) = sqrt_line(ix) else {
        // The interval of √x: its centre, its radius on the own symbol (through the slack).
        let r = ix.sqrt().unwrap_or(Interval::ENTIRE);
        let f = own_interval(r, 0);
        slack.add(f.radius());
        return (f.centre, Vec::new());
    };
    slack.add(delta);
    combine(x, alpha, &Form::point(0.0), 0.0, zeta, slack)
}

/// The min-range linear approximation of `√t` over `ix` (nonnegative): `(α, ζ, δ)` with
/// `|√t − (α·t + ζ)| ≤ δ` on `ix`, the slope at the upper end, `α = 1/(2√b)`
/// (`g(t) = √t − αt` increases on `[a, b]`); `None` when `b ≤ 0` or a coefficient is not finite.
pub(super) fn sqrt_line(ix: Interval) -> Option<(f64, f64, f64)> {
    let (a, b) = (ix.lo, ix.hi);
    let sb = Interval::point(b).sqrt().unwrap_or(Interval::ENTIRE);
    if b <= 0.0 || !sb.is_bounded() || sb.lo <= 0.0 {
        return None;
    }
    // α ≤ 1/(2√b) keeps g increasing: g'(t) = 1/(2√t) − α ≥ 0.
    let alpha = Interval::point(0.5).checked_div(sb).map(|q| q.lo)?;
    let g = |t: f64| {
        let s = Interval::point(t).sqrt().unwrap_or(Interval::ENTIRE);
        s - Interval::point(alpha) * Interval::point(t)
    };
    let (ga, gb) = (g(a), g(b));
    let (lo, hi) = (ga.lo.min(gb.lo), ga.hi.max(gb.hi));
    let zeta = lo / 2.0 + hi / 2.0;
    let delta = (Interval::point(hi) - Interval::point(zeta)).hi.max((Interval::point(zeta) - Interval::point(lo)).hi);
    (alpha.is_finite() && delta.is_finite()).then_some((alpha, zeta, delta))
}
