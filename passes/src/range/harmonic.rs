//! Affine forms on the harmonics of the joint angles: the rotation-aware layer of
//! `range<method=affine>` (issue 48 item 2).
//!
//! **Why.** Plain affine arithmetic gives `sin q` and `cos q` of a joint that turns fully two
//! independent noise symbols, so a rotation `c·x − s·y` is enclosed by `|x| + |y|` where the
//! truth is `√(x² + y²)`, and a chain of rotations compounds it: on the UR5's RNEA the median
//! enclosure is 3.2× the sampled range, 17× at the 90th percentile (docs/accuracy.md). The
//! functions robovec encloses reach the angles only through `sin`/`cos` of inputs (SPEC §1's
//! trig variables), and a product of those is again a sum of sines and cosines of integer
//! combinations of the angles: `cos a · cos b = ½cos(a − b) + ½cos(a + b)`. Kept in that form,
//! a rotation is exact.
//!
//! **The form.** A value is `Σ_h (A_h·cos θ_h + B_h·sin θ_h)`, where each **harmonic**
//! `θ_h = Σᵢ nᵢ·qᵢ` is an integer combination of the angles (the inputs read by `sin`/`cos`,
//! of nonzero width; `θ = 0` holds the constant part, `cos 0 = 1`), and `A_h`, `B_h` are affine
//! forms over noise symbols as in [`super::affine`] (inputs' and values' own symbols; an angle
//! read elsewhere keeps its own linear symbol there). It is stored as **atoms** `(h, cos|sin,
//! symbol or centre, coefficient)`. Sums merge atoms; a product multiplies each atom of one
//! operand's centre part with every atom of the other (product-to-sum, exact up to rounding),
//! and bounds the product of the two symbol parts (`rx·ry`) on the value's own symbol, as affine
//! arithmetic does; `1/y` and `√x` are the min-range linear approximations of
//! [`super::affine`] applied to the form.
//!
//! **The range.** For each harmonic `h ≠ 0` and each symbol, `|a·cos θ + b·sin θ| ≤ √(a² + b²)`
//! (and the interval `a·cos Θ_h + b·sin Θ_h` over the harmonic's range `Θ_h`, when narrower);
//! the constant part adds its centre. Summing these bounds treats every harmonic and symbol as
//! free, a superset of the true set of points: sound whatever the correlations.
//!
//! **Soundness.** As in [`super::affine`]: every coefficient is computed in round-to-nearest
//! and its rounding bounded (`u = 2⁻⁵²` relative plus 10⁻³⁰⁰) on the value's own symbol, with
//! the rounding of the binary64 operation itself and [`LIBM_ULPS`] for `sin`/`cos`; the
//! product-to-sum halvings are exact. The pass intersects this range with the interval and the
//! affine enclosures (all three sound).
//!
//! **Cap.** A form keeps at most `cap` atoms: the pairs `(h, symbol)` of smallest bound beyond
//! it go to the own symbol (their bound, rounded up). A product costs O(cap²) (the centre part of
//! one operand times the other), the sweep O(ops · cap²) in time and O(live values · cap) in
//! memory; the harmonics are interned once per sweep. The cap scales with the function's size
//! ([`range_atoms`], [`adjoint_atoms`]): within [48, 1,024], many atoms where a function is
//! small enough to afford them, 48 for the largest, so the work stays linear in ops.

use robovec_ir::domain::Domain;
use robovec_ir::interval::LIBM_ULPS;
use robovec_ir::{BinOp, Def, Function, Interval, Intrinsic, Operand, TrigFn, Value};
use rustc_hash::FxHashMap;

use super::affine::{reciprocal_line, sqrt_line};
use super::enclose::of;

/// Fewest atoms a form keeps: the cap of the largest functions (WALK-MAN's 33k ops and beyond).
pub const MIN_ATOMS: usize = 48;
/// Most atoms a form keeps: the cap of the smallest functions (an arm's RNEA).
pub const MAX_ATOMS: usize = 1024;
/// `ops × cap` the enclosing sweep ([`HarmonicSweep::new`]) may spend: the cap is
/// `2²⁰ / ops` within [[`MIN_ATOMS`], [`MAX_ATOMS`]] ([`range_atoms`]).
pub const RANGE_ATOM_WORK: usize = 1 << 20;
/// `(outputs × ops)² × cap` the adjoint sweeps ([`HarmonicSweep::adjoints`], one per output)
/// may spend: the cap is `2³⁷ / (outputs × ops)²` within [[`MIN_ATOMS`], [`MAX_ATOMS`]]
/// ([`adjoint_atoms`]).
pub const ADJOINT_ATOM_WORK: u64 = 1 << 37;

/// The cap on a form's atoms when enclosing a function of `ops` ops: `2²⁰ / ops` within
/// [48, 1,024] atoms.
///
/// More atoms keep more (harmonic, symbol) pairs apart, fewer go to the value's own symbol:
/// the enclosures tighten (Panda's RNEA: the binary32 bound 3.2·10⁻¹ → 2.5·10⁻¹ N·m at 48 →
/// 1,024 atoms) for O(ops · cap²) time, which is why the cap falls as the function grows:
/// 1,024 atoms up to 1,024 ops (an arm: +0.02 s), 264 at Talos's 3,969, 48 from 21,845 ops on
/// (a humanoid's `dirdyna`, where the sweep already takes a fifth of a second). docs/accuracy.md.
/// `ops` is one state's (`Function::states`): interleaved states are independent copies, each
/// enclosed as one alone.
pub fn range_atoms(ops: usize) -> usize {
    (RANGE_ATOM_WORK / ops.max(1)).clamp(MIN_ATOMS, MAX_ATOMS)
}

/// The cap on a form's atoms in the adjoint sweeps of a function with `outputs` outputs and
/// `ops` ops: `2³⁷ / (outputs × ops)²` within [48, 1,024] atoms.
///
/// The sweeps cost O(outputs × ops × atoms²) when the forms fill their cap, which a long chain's
/// do (30 revolute joints in series: 30 × 2,971 at 94 atoms took 15 s and 2 GB), and much less
/// when they do not (an arm's): so the cap falls with the square of the work and reaches 48 at
/// 53,000 `outputs × ops`. Measured (release, binary32 bound, the largest over the outputs and
/// the median bound / witness): UR5 RNEA (1,024 atoms) 8.0·10⁻³ → 4.7·10⁻³ N·m (median 19.6 →
/// 14.1) in 0.14 s; Panda (1,024) 3.2·10⁻¹ → 1.2·10⁻¹ N·m (117 → 59) in 1.6 s.
/// docs/accuracy.md.
pub fn adjoint_atoms(outputs: usize, ops: usize) -> usize {
    let work = (outputs.max(1) as u64).saturating_mul(ops.max(1) as u64);
    let cap = ADJOINT_ATOM_WORK / work.saturating_mul(work);
    usize::try_from(cap).unwrap_or(usize::MAX).clamp(MIN_ATOMS, MAX_ATOMS)
}

/// `2⁻⁵²`, as [`super::affine`]'s bound for one rounding (relative).
const U: f64 = f64::EPSILON;
/// Absolute slack per rounding (underflow).
const TINY: f64 = 1e-300;
/// The symbol of an atom of the centre part (no noise symbol).
const CENTRE: u32 = u32::MAX;

/// One term `c · trig(θ_h) · ε_sym` of a form (`trig` = cos, or sin when `sin`; `ε = 1` for
/// [`CENTRE`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Atom {
    h: u32,
    sym: u32,
    sin: bool,
    c: f64,
}

impl Atom {
    /// The order of a form's atoms, `(h, sym, sin)` lexicographically, packed in one word for
    /// the sorts (harmonic ids stay far below 2³¹: each is a combination the sweep interned).
    fn key(&self) -> u64 {
        debug_assert!(self.h < 1 << 31);
        (u64::from(self.h) << 33) | (u64::from(self.sym) << 1) | u64::from(self.sin)
    }
}

/// A form: atoms sorted by `(h, sym, sin)`, no zero coefficient, no `sin` atom on `θ = 0`.
#[derive(Clone, Debug, Default)]
struct HForm {
    atoms: Vec<Atom>,
}

/// `√(a² + b²)` rounded up: `m·√(1 + t²)` with `m = max(|a|, |b|)` and `t = min/m ≤ 1`
/// (no overflow, no underflow but of `t²`, which leaves `1 + t²` within `2⁻¹⁰²²` of its exact
/// value), a handful of roundings of relative error ≤ `u` each, covered by `(1 + 8·2⁻⁵²)`.
fn hypot_up(a: f64, b: f64) -> f64 {
    let (a, b) = (a.abs(), b.abs());
    let (m, n) = if a >= b { (a, b) } else { (b, a) };
    if n == 0.0 {
        return m;
    }
    let t = n / m;
    m * (1.0 + t * t).sqrt() * (1.0 + 8.0 * U) + TINY
}

/// Sums `n` nonnegative numbers: `Σ·(1 + n·2⁻⁵²)` bounds the round-to-nearest sum's error
/// (`(n − 1)·u·Σ`) from above.
#[derive(Clone, Copy)]
struct FastUp {
    sum: f64,
    n: u32,
}

impl FastUp {
    fn zero() -> FastUp {
        FastUp { sum: 0.0, n: 0 }
    }
    fn add(&mut self, e: f64) {
        self.sum += e.abs();
        self.n += 1;
    }
    fn total(self) -> f64 {
        self.sum * (1.0 + f64::from(self.n + 1) * U) + TINY
    }
}

/// The harmonics `θ = Σ nᵢ·qᵢ` met in one sweep, interned: id 0 is `θ = 0`.
struct Harmonics {
    /// Each harmonic's combination `(angle, n)`, sorted by angle, first `n` positive.
    combos: Vec<Vec<(u32, i32)>>,
    /// Each harmonic's range `Θ_h` (from the angles' domain ranges, outward-rounded).
    ranges: Vec<Interval>,
    /// `cos Θ_h` and `sin Θ_h`, enclosed.
    trig: Vec<(Interval, Interval)>,
    /// Whether `Θ_h` spans a whole turn (both enclosures `[−1, 1]`: the bound is `√(a² + b²)`).
    full: Vec<bool>,
    ids: FxHashMap<Vec<(u32, i32)>, u32>,
    /// `(h, k)` → `(h + k, its sign, h − k, its sign)`, the sign the normalisation flipped.
    pairs: FxHashMap<(u32, u32), [(u32, f64); 2]>,
    /// Each angle's domain range, by angle number.
    angle_ranges: Vec<Interval>,
    /// The sweep's cap on a form's atoms.
    cap: usize,
    /// [`Harmonics::mul`]'s buffer.
    scratch: Vec<Atom>,
}

impl Harmonics {
    fn new(angle_ranges: Vec<Interval>, cap: usize) -> Harmonics {
        let mut h = Harmonics {
            combos: Vec::new(),
            ranges: Vec::new(),
            trig: Vec::new(),
            full: Vec::new(),
            ids: FxHashMap::default(),
            pairs: FxHashMap::default(),
            angle_ranges,
            cap,
            scratch: Vec::new(),
        };
        h.intern(Vec::new());
        h
    }

    /// The id of the normalised combination `combo` (sorted, no zero, first positive).
    fn intern(&mut self, combo: Vec<(u32, i32)>) -> u32 {
        if let Some(&id) = self.ids.get(&combo) {
            return id;
        }
        let id = self.combos.len() as u32;
        let mut range = Interval::point(0.0);
        for &(a, n) in &combo {
            range = range + Interval::point(f64::from(n)) * self.angle_ranges[a as usize];
        }
        let (c, s) = (range.cos(), range.sin());
        self.full.push(c.lo <= -1.0 && c.hi >= 1.0 && s.lo <= -1.0 && s.hi >= 1.0);
        self.trig.push((c, s));
        self.ranges.push(range);
        self.combos.push(combo.clone());
        self.ids.insert(combo, id);
        id
    }

    /// The harmonic of angle `a` alone.
    fn angle(&mut self, a: u32) -> u32 {
        self.intern(vec![(a, 1)])
    }

    /// `h + s·k` normalised: its id and the sign `±1` by which `θ` was multiplied.
    fn combine(&mut self, h: u32, k: u32, s: i32) -> (u32, f64) {
        let (x, y) = (&self.combos[h as usize], &self.combos[k as usize]);
        let mut out: Vec<(u32, i32)> = Vec::with_capacity(x.len() + y.len());
        let (mut i, mut j) = (0, 0);
        while i < x.len() || j < y.len() {
            let (a, n) = match (x.get(i), y.get(j)) {
                (Some(&(a, n)), Some(&(b, _))) if a < b => {
                    i += 1;
                    (a, n)
                }
                (Some(&(a, _)), Some(&(b, m))) if b < a => {
                    j += 1;
                    (b, s * m)
                }
                (Some(&(a, n)), Some(&(_, m))) => {
                    i += 1;
                    j += 1;
                    (a, n + s * m)
                }
                (Some(&(a, n)), None) => {
                    i += 1;
                    (a, n)
                }
                (None, Some(&(b, m))) => {
                    j += 1;
                    (b, s * m)
                }
                (None, None) => unreachable!(),
            };
            if n != 0 {
                out.push((a, n));
            }
        }
        let sign = match out.first() {
            Some(&(_, n)) if n < 0 => {
                out.iter_mut().for_each(|t| t.1 = -t.1);
                -1.0
            }
            _ => 1.0,
        };
        (self.intern(out), sign)
    }

    /// `(h + k, sign)` and `(h − k, sign)`.
    fn pair(&mut self, h: u32, k: u32) -> [(u32, f64); 2] {
        if let Some(&p) = self.pairs.get(&(h, k)) {
            return p;
        }
        let p = [self.combine(h, k, 1), self.combine(h, k, -1)];
        self.pairs.insert((h, k), p);
        p
    }
    /// `x · y` (`x²` when `same`): every atom of `x`'s centre part times every atom of `y`, every
    /// symbol atom of `x` times `y`'s centre part, and the product of the symbol parts bounded by
    /// `rx·ry` on the own symbol (for a square, in `[0, rx²]`).
    fn mul(&mut self, x: &HForm, y: &HForm, same: bool, slack: &mut FastUp) -> Vec<Atom> {
        // The products go to a buffer kept between calls (thousands of atoms at a time: a fresh
        // vector each time cost a third of the sweep in the kernel's page clearing).
        let mut out = std::mem::take(&mut self.scratch);
        out.clear();
        let mut mag = FastUp::zero();
        for p in x.atoms.iter().filter(|a| a.sym == CENTRE) {
            for q in &y.atoms {
                let c = p.c * q.c;
                mag.add(c);
                product_atoms(self, *p, *q, c, q.sym, &mut out);
            }
        }
        for p in x.atoms.iter().filter(|a| a.sym != CENTRE) {
            for q in y.atoms.iter().filter(|a| a.sym == CENTRE) {
                let c = p.c * q.c;
                mag.add(c);
                product_atoms(self, *p, *q, c, p.sym, &mut out);
            }
        }
        // Each product rounded once (the halvings are exact).
        slack.add(U * mag.total() + TINY * out.len() as f64);
        // Many more products than a form keeps: all but the largest 4·cap go to the slack
        // before the sort (each bounded by its |c|: |trig · ε| ≤ 1).
        let keep = 4 * self.cap;
        if out.len() > 2 * keep {
            out.select_nth_unstable_by(keep, |p, q| q.c.abs().total_cmp(&p.c.abs()));
            for a in out.drain(keep..) {
                slack.add(a.c);
            }
        }
        merge_in_place(&mut out, slack);
        let mut result = out.clone();
        self.scratch = out;
        let mut out = std::mem::take(&mut result);
        let (rx, ry) = (self.symbol_radius(x), self.symbol_radius(y));
        let nonlinear = Interval::point(rx) * Interval::point(ry);
        if same {
            // (Σ)² ∈ [0, rx²]: centre + rx²/2 ± rx²/2.
            let half = nonlinear.hi / 2.0;
            out.push(Atom { h: 0, sym: CENTRE, sin: false, c: half });
            out = normalise(out, slack);
            slack.add(half);
        } else {
            slack.add(nonlinear.hi);
        }
        out
    }

    /// The bound of the symbol part of `x`: `Σ_(h, ε) |a·cos θ_h + b·sin θ_h|` bounded by
    /// [`Self::pair_bound`].
    fn symbol_radius(&self, x: &HForm) -> f64 {
        let mut r = FastUp::zero();
        for_pairs(&x.atoms, |_, h, sym, a, b| {
            if sym != CENTRE {
                r.add(self.pair_bound(h, a, b));
            }
        });
        r.total()
    }

    /// A bound of `|a·cos θ + b·sin θ|` over harmonic `h`'s range.
    fn pair_bound(&self, h: u32, a: f64, b: f64) -> f64 {
        if h == 0 {
            return a.abs();
        }
        let m = hypot_up(a, b);
        if self.full[h as usize] {
            return m;
        }
        let (c, s) = self.trig[h as usize];
        let i = Interval::point(a) * c + Interval::point(b) * s;
        m.min(i.mag())
    }

    /// The form's range: the centre part's enclosure plus the symbol part's bound.
    fn range(&self, x: &HForm) -> Interval {
        let mut r = Interval::point(0.0);
        let mut spread = FastUp::zero();
        for_pairs(&x.atoms, |_, h, sym, a, b| {
            if sym != CENTRE {
                spread.add(self.pair_bound(h, a, b));
            } else if h == 0 {
                r = r + Interval::point(a);
            } else if self.full[h as usize] {
                spread.add(hypot_up(a, b));
            } else {
                let (c, s) = self.trig[h as usize];
                let m = hypot_up(a, b);
                let i = Interval::point(a) * c + Interval::point(b) * s;
                r = r + Interval::new(i.lo.max(-m), i.hi.min(m));
            }
        });
        let s = spread.total();
        r + Interval::new(-s, s)
    }

    /// Keeps at most `cap` atoms: the pairs `(h, symbol)` of smallest bound beyond go to the slack.
    fn cap_atoms(&self, cap: usize, atoms: &mut Vec<Atom>, slack: &mut FastUp) {
        if atoms.len() < cap {
            return;
        }
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for_pairs(atoms, |run, h, _, a, b| pairs.push((self.pair_bound(h, a, b), run.start, run.end)));
        pairs.sort_unstable_by(|p, q| q.0.total_cmp(&p.0));
        let mut keep = vec![false; atoms.len()];
        let mut kept = 0;
        for &(bound, k, e) in &pairs {
            if kept + (e - k) < cap {
                kept += e - k;
                keep[k..e].iter_mut().for_each(|x| *x = true);
            } else {
                slack.add(bound);
            }
        }
        let mut i = 0;
        atoms.retain(|_| {
            i += 1;
            keep[i - 1]
        });
    }
}

/// The atoms of `trig_p(θ_h) · trig_q(θ_k)` scaled by `c`, pushed onto `out` with symbol `sym`
/// (product-to-sum; the halvings exact).
fn product_atoms(hs: &mut Harmonics, p: Atom, q: Atom, c: f64, sym: u32, out: &mut Vec<Atom>) {
    let mut push = |h: u32, sin: bool, c: f64| {
        if c != 0.0 && !(h == 0 && sin) {
            out.push(Atom { h, sym, sin, c });
        }
    };
    if p.h == 0 {
        push(q.h, q.sin, c);
        return;
    }
    if q.h == 0 {
        push(p.h, p.sin, c);
        return;
    }
    let [(sum, ss), (diff, sd)] = hs.pair(p.h, q.h);
    let half = c / 2.0;
    match (p.sin, q.sin) {
        // cos a cos b = ½cos(a − b) + ½cos(a + b)
        (false, false) => {
            push(diff, false, half);
            push(sum, false, half);
        }
        // sin a sin b = ½cos(a − b) − ½cos(a + b)
        (true, true) => {
            push(diff, false, half);
            push(sum, false, -half);
        }
        // sin a cos b = ½sin(a + b) + ½sin(a − b)
        (true, false) => {
            push(sum, true, half * ss);
            push(diff, true, half * sd);
        }
        // cos a sin b = ½sin(a + b) − ½sin(a − b)
        (false, true) => {
            push(sum, true, half * ss);
            push(diff, true, -half * sd);
        }
    }
}

/// Sorts `atoms` and merges equal keys, the sums' roundings on `slack`.
fn normalise(mut atoms: Vec<Atom>, slack: &mut FastUp) -> Vec<Atom> {
    merge_in_place(&mut atoms, slack);
    atoms
}

/// [`normalise`] in place: sorts `atoms`, merges equal keys (the sums' roundings on `slack`) and
/// drops zeros.
fn merge_in_place(atoms: &mut Vec<Atom>, slack: &mut FastUp) {
    atoms.sort_unstable_by_key(Atom::key);
    let mut w = 0usize;
    let mut mag = 0.0;
    for r in 0..atoms.len() {
        let a = atoms[r];
        if w > 0 && atoms[w - 1].key() == a.key() {
            mag += a.c.abs();
            atoms[w - 1].c += a.c;
        } else {
            if mag > 0.0 {
                slack.add(U * mag + TINY);
            }
            mag = a.c.abs();
            atoms[w] = a;
            w += 1;
        }
    }
    if mag > 0.0 {
        slack.add(U * mag + TINY);
    }
    atoms.truncate(w);
    atoms.retain(|a| a.c != 0.0);
}

/// The forms of a function's values, swept in body order (beside [`super::affine::AffineSweep`]).
pub struct HarmonicSweep<'f> {
    f: &'f Function,
    cap: usize,
    forms: Vec<Option<HForm>>,
    uses: Vec<u32>,
    /// The angle number of each input read by `sin`/`cos` (by value index), if of nonzero width.
    angle: Vec<Option<u32>>,
    hs: Harmonics,
    /// The number of values `n`, which numbers the noise symbols: `[0, n)` the values' own
    /// (inputs' and roundings'), `[n, 2n)` the error of a division's reciprocal, `[2n, 5n)` the
    /// adjoint sweep's (a partial's approximation, a quotient's roundings, an adjoint's own);
    /// `None` when `5n` would reach [`CENTRE`] (no division gets a form, no adjoint is taken).
    n: Option<u32>,
}

impl<'f> HarmonicSweep<'f> {
    /// A sweep over `f` with forms of at most `cap` atoms (≥ 4), the inputs' ranges from
    /// `domain`; `None` when no `sin`/`cos` reads an input of nonzero width (the forms would be
    /// [`super::affine`]'s).
    pub fn new(f: &'f Function, domain: &Domain, cap: usize) -> Option<HarmonicSweep<'f>> {
        Self::over(f, |v| domain.get(f.name_of(v)).map(|r| r.interval), cap, false)
    }

    /// [`Self::new`] with the inputs' ranges from their enclosures `x` (by value index): the
    /// sweep `error-bound`'s adjoints read ([`Self::adjoints`]).
    /// Every value's form is kept (not dropped after its last use): [`Self::adjoints`] reads
    /// them in reverse. Without angles the forms are [`super::affine`]'s (on `θ = 0` alone).
    pub fn over_enclosures(f: &'f Function, x: &[Interval], cap: usize) -> HarmonicSweep<'f> {
        let mut s = Self::over(f, |v| Some(x[v.index()]), cap, true).expect("forced");
        s.uses.iter_mut().for_each(|u| *u = u32::MAX);
        s
    }

    fn over(
        f: &'f Function,
        input: impl Fn(Value) -> Option<Interval>,
        cap: usize,
        force: bool,
    ) -> Option<HarmonicSweep<'f>> {
        let mut uses = vec![0u32; f.values.len()];
        let mut angle = vec![None; f.values.len()];
        let mut angle_ranges = Vec::new();
        for &v in &f.body {
            let def = &f.value(v).def;
            def.for_each_value(|p| uses[p.index()] += 1);
            if let Def::Trig(_, a) = def {
                let Some(r) = input(*a) else { continue };
                if r.width() > 0.0 && r.is_bounded() && angle[a.index()].is_none() {
                    angle[a.index()] = Some(angle_ranges.len() as u32);
                    angle_ranges.push(r);
                }
            }
        }
        if angle_ranges.is_empty() && !force {
            return None;
        }
        let mut forms = vec![None; f.values.len()];
        for &v in &f.inputs {
            let Some(i) = input(v) else { continue };
            if !i.is_bounded() {
                continue;
            }
            forms[v.index()] = Some(interval_form(i, v.index() as u32));
        }
        let n = u32::try_from(f.values.len()).ok().filter(|n| n.checked_mul(5).is_some_and(|m| m < CENTRE));
        Some(HarmonicSweep { f, cap: cap.max(4), forms, uses, angle, hs: Harmonics::new(angle_ranges, cap.max(4)), n })
    }

    fn form(&self, o: &Operand) -> Option<HForm> {
        match o {
            Operand::Const(c) => Some(constant(*c)),
            Operand::Value(v) => self.forms[v.index()].clone(),
        }
    }

    fn release(&mut self, def: &Def) {
        def.for_each_value(|v| {
            let u = &mut self.uses[v.index()];
            *u = u.saturating_sub(1);
            if *u == 0 {
                self.forms[v.index()] = None;
            }
        });
    }

    /// The enclosure of body value `v` from its form, intersected with `x[v]` (the enclosure so
    /// far); `x` holds every earlier value's.
    pub fn step(&mut self, v: Value, x: &[Interval]) -> Interval {
        let f = self.f;
        let data = f.value(v);
        let own = v.index() as u32;
        let iv = x[v.index()];
        let interval_of = |o: &Operand| of(x, o);
        let mut slack = FastUp::zero();
        let ops = data.def.operands();
        let forms: Option<Vec<HForm>> = ops.iter().map(|o| self.form(o)).collect();
        let atoms = match (&data.def, forms) {
            _ if !iv.is_bounded() => None,
            (Def::Trig(t, a), _) => match self.angle[a.index()] {
                Some(n) => {
                    let h = self.hs.angle(n);
                    // The C library's sin/cos within LIBM_ULPS ulps of a value of magnitude ≤ 1.
                    slack.add(LIBM_ULPS * U + TINY);
                    Some(vec![Atom { h, sym: CENTRE, sin: *t == TrigFn::Sin, c: 1.0 }])
                }
                None => None,
            },
            (Def::Binary(op, a, b), Some(fs)) => {
                let same = super::enclose::same_pair(a, b);
                let r = match op {
                    BinOp::Add => Some(lin(&fs[0], 1.0, &fs[1], 1.0, &mut slack)),
                    BinOp::Sub if same => Some(Vec::new()),
                    BinOp::Sub => Some(lin(&fs[0], 1.0, &fs[1], -1.0, &mut slack)),
                    BinOp::Mul => Some(self.hs.mul(&fs[0], &fs[1], same, &mut slack)),
                    BinOp::Div => reciprocal_line(interval_of(b)).zip(self.n).map(|((alpha, zeta, delta), n)| {
                        // The approximation's error on a symbol of its own, not on `own`: the
                        // product spreads it over every harmonic of the dividend, and `put_own`
                        // may flip the sign of `own`'s constant atom, which is sound only for a
                        // symbol with that one atom.
                        let recip = affine_of(&fs[1], alpha, zeta, delta, n + own);
                        self.hs.mul(&fs[0], &recip, false, &mut slack)
                    }),
                };
                if !(same && *op == BinOp::Sub) {
                    slack.add(iv.mag() * U + TINY);
                }
                r
            }
            (Def::Call(callee, args), Some(fs)) => {
                let r = match Intrinsic::of(callee, args.len()) {
                    Some(Intrinsic::Sqrt) => sqrt_line(interval_of(&args[0]))
                        .map(|(alpha, zeta, delta)| affine_of(&fs[0], alpha, zeta, delta, own).atoms),
                    Some(i) => {
                        // a square (`fma(x, x, c)`) as `x · x`: its product is the square
                        let same = super::enclose::same_pair(&args[0], &args[1]);
                        // capped as a separate product's form would be before the sum
                        let mut atoms = self.hs.mul(&fs[0], &fs[1], same, &mut slack);
                        self.hs.cap_atoms(self.cap, &mut atoms, &mut slack);
                        let p = HForm { atoms };
                        let p = if i == Intrinsic::Fnma { negate(&p) } else { p };
                        let sign = if i == Intrinsic::Fms { -1.0 } else { 1.0 };
                        Some(lin(&p, 1.0, &fs[2], sign, &mut slack))
                    }
                    None => None,
                };
                slack.add(iv.mag() * U + TINY);
                r
            }
            _ => None,
        };
        self.release(&data.def);
        let form = match atoms {
            Some(mut atoms) if slack.total().is_finite() && atoms.iter().all(|a| a.c.is_finite()) => {
                self.hs.cap_atoms(self.cap, &mut atoms, &mut slack);
                put_own(&mut atoms, own, slack.total());
                HForm { atoms }
            }
            // No form (an unbounded operand, a callback, a failed approximation): the value's
            // interval on its own symbol.
            _ if iv.is_bounded() => interval_form(iv, own),
            _ => return iv,
        };
        let r = self.hs.range(&form);
        let enclosure = Interval::new(r.lo.max(iv.lo), r.hi.min(iv.hi));
        if self.uses[v.index()] > 0 {
            // A form wider than the enclosure is replaced by the enclosure.
            let narrower = enclosure.width() < r.width() / 2.0 && enclosure.is_bounded();
            self.forms[v.index()] = Some(if narrower { interval_form(enclosure, own) } else { form });
        }
        enclosure
    }
}

/// The cos and sin coefficients of a run of atoms of one `(h, symbol)`.
fn split(run: &[Atom]) -> (f64, f64) {
    let mut ab = (0.0, 0.0);
    for a in run {
        if a.sin {
            ab.1 = a.c;
        } else {
            ab.0 = a.c;
        }
    }
    ab
}

/// Calls `each(run, h, symbol, a, b)` per pair `(h, symbol)` of `atoms` (sorted): `run` its
/// atoms' positions, `a` the cos coefficient and `b` the sin one.
fn for_pairs(atoms: &[Atom], mut each: impl FnMut(std::ops::Range<usize>, u32, u32, f64, f64)) {
    let mut k = 0;
    while k < atoms.len() {
        let mut e = k + 1;
        while e < atoms.len() && atoms[e].h == atoms[k].h && atoms[e].sym == atoms[k].sym {
            e += 1;
        }
        let (a, b) = split(&atoms[k..e]);
        each(k..e, atoms[k].h, atoms[k].sym, a, b);
        k = e;
    }
}

/// The constant `c`.
fn constant(c: f64) -> HForm {
    HForm { atoms: if c != 0.0 { vec![Atom { h: 0, sym: CENTRE, sin: false, c }] } else { Vec::new() } }
}

/// `mid ± rad` of interval `i` on symbol `sym`.
fn interval_form(i: Interval, sym: u32) -> HForm {
    let mid = i.lo / 2.0 + i.hi / 2.0;
    let rad = (Interval::point(i.hi) - Interval::point(mid)).hi.max((Interval::point(mid) - Interval::point(i.lo)).hi);
    let mut atoms = Vec::new();
    if mid != 0.0 {
        atoms.push(Atom { h: 0, sym, sin: false, c: rad });
        atoms.insert(0, Atom { h: 0, sym: CENTRE, sin: false, c: mid });
        atoms.sort_unstable_by_key(Atom::key);
    } else if rad > 0.0 {
        atoms.push(Atom { h: 0, sym, sin: false, c: rad });
    }
    atoms.retain(|a| a.c != 0.0);
    HForm { atoms }
}

/// `−x` (exact).
fn negate(x: &HForm) -> HForm {
    HForm { atoms: x.atoms.iter().map(|a| Atom { c: -a.c, ..*a }).collect() }
}

/// `a·x + b·y`, the roundings on `slack`.
fn lin(x: &HForm, a: f64, y: &HForm, b: f64, slack: &mut FastUp) -> Vec<Atom> {
    let mut out: Vec<Atom> = Vec::with_capacity(x.atoms.len() + y.atoms.len());
    for t in &x.atoms {
        let c = a * t.c;
        if a != 1.0 && a != -1.0 {
            slack.add(U * c.abs() + TINY);
        }
        out.push(Atom { c, ..*t });
    }
    for t in &y.atoms {
        let c = b * t.c;
        if b != 1.0 && b != -1.0 {
            slack.add(U * c.abs() + TINY);
        }
        out.push(Atom { c, ..*t });
    }
    normalise(out, slack)
}

/// `α·x + ζ ± δ`, `δ` on symbol `own` (kept in the form: a quotient multiplies it).
fn affine_of(x: &HForm, alpha: f64, zeta: f64, delta: f64, own: u32) -> HForm {
    let mut own_slack = FastUp::zero();
    own_slack.add(delta);
    let mut atoms = lin(x, alpha, &constant(zeta), 1.0, &mut own_slack);
    put_own(&mut atoms, own, own_slack.total());
    HForm { atoms }
}

/// Adds `e ≥ 0` to the constant-harmonic coefficient of symbol `own` (its sign is free: the
/// own symbol appears in no other value's definition).
fn put_own(atoms: &mut Vec<Atom>, own: u32, e: f64) {
    if e.is_nan() || e <= 0.0 {
        return;
    }
    let atom = Atom { h: 0, sym: own, sin: false, c: e };
    match atoms.binary_search_by_key(&atom.key(), Atom::key) {
        Ok(k) => atoms[k].c = (Interval::point(atoms[k].c.abs()) + Interval::point(e)).hi,
        Err(k) => atoms.insert(k, atom),
    }
}

impl HarmonicSweep<'_> {
    /// The enclosures of `∂out/∂z` for every value `z` (by value index: `sup` its magnitude,
    /// 0 where `out` does not depend on `z`) and, per operand read of each op, `sup|∂out/∂z| ·
    /// max|∂z/∂operand|` (what a conversion at that read weighs); `None` when a value on the
    /// way has no form. Exact partials at the exact values
    /// (`b` for `a·b`, `1/b` and `−z/b` for `a/b`, `1/(2√a)`, `cos a`), each an enclosure
    /// over the domain.
    pub fn adjoints(&mut self, out: Value, x: &[Interval]) -> Option<Adjoints> {
        let f = self.f;
        let n = self.n?;
        let mut lam: Vec<Option<HForm>> = vec![None; f.values.len()];
        lam[out.index()] = Some(constant(1.0));
        let mut adj = Adjoints { sup: vec![0.0; f.values.len()], conversion_weight: vec![[0.0; 3]; f.values.len()] };
        let partial_mag = |hs: &Harmonics, p: &HForm| hs.range(p).mag();
        for &z in f.body.iter().rev() {
            let Some(l) = lam[z.index()].take() else { continue };
            let sup = self.hs.range(&l).mag();
            if !sup.is_finite() {
                return None;
            }
            if sup == 0.0 {
                continue;
            }
            adj.sup[z.index()] = sup;
            let def = &f.value(z).def;
            // (operand, partial form) pairs; `None` partial: ±1.
            let mut parts: Vec<(Operand, Option<HForm>, f64)> = Vec::new();
            match def {
                Def::Trig(t, a) => {
                    let partial = match self.angle[a.index()] {
                        Some(k) => {
                            let h = self.hs.angle(k);
                            match t {
                                TrigFn::Sin => HForm { atoms: vec![Atom { h, sym: CENTRE, sin: false, c: 1.0 }] },
                                TrigFn::Cos => HForm { atoms: vec![Atom { h, sym: CENTRE, sin: true, c: -1.0 }] },
                            }
                        }
                        None => {
                            let i = match t {
                                TrigFn::Sin => x[a.index()].cos(),
                                TrigFn::Cos => -x[a.index()].sin(),
                            };
                            interval_form(i, 2 * n + z.index() as u32)
                        }
                    };
                    parts.push((Operand::Value(*a), Some(partial), 1.0));
                }
                Def::Binary(op, a, b) => {
                    let same = super::enclose::same_pair(a, b);
                    match op {
                        BinOp::Add => {
                            parts.push((*a, None, 1.0));
                            parts.push((*b, None, 1.0));
                        }
                        BinOp::Sub if same => {}
                        BinOp::Sub => {
                            parts.push((*a, None, 1.0));
                            parts.push((*b, None, -1.0));
                        }
                        BinOp::Mul => {
                            let (Some(xa), Some(xb)) = (self.form(a), self.form(b)) else { return None };
                            parts.push((*a, Some(xb), 1.0));
                            parts.push((*b, Some(xa), 1.0));
                        }
                        BinOp::Div => {
                            let (Some(xb), Some(xz)) = (self.form(b), self.form(&Operand::Value(z))) else {
                                return None;
                            };
                            let (alpha, zeta, delta) = reciprocal_line(of(x, b))?;
                            let mut slack = FastUp::zero();
                            let recip = affine_of(&xb, alpha, zeta, delta, 2 * n + z.index() as u32);
                            let mut quotient = self.hs.mul(&xz, &recip, false, &mut slack);
                            // The product's roundings on a fresh symbol: `2n + z` now has atoms
                            // on several harmonics (see `step`'s division).
                            put_own(&mut quotient, 3 * n + z.index() as u32, slack.total());
                            parts.push((*a, Some(recip), 1.0));
                            parts.push((*b, Some(HForm { atoms: quotient }), -1.0));
                        }
                    }
                }
                Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
                    Some(Intrinsic::Sqrt) => {
                        // ∂√a/∂a = 1/(2√a) = ½ · 1/z.
                        let xz = self.form(&Operand::Value(z))?;
                        let (alpha, zeta, delta) = reciprocal_line(x[z.index()])?;
                        let recip = affine_of(&xz, alpha, zeta, delta, 2 * n + z.index() as u32);
                        parts.push((args[0], Some(recip), 0.5));
                    }
                    Some(i) => {
                        let (Some(xa), Some(xb)) = (self.form(&args[0]), self.form(&args[1])) else {
                            return None;
                        };
                        let (sp, sc) = match i {
                            Intrinsic::Fma => (1.0, 1.0),
                            Intrinsic::Fms => (1.0, -1.0),
                            _ => (-1.0, 1.0),
                        };
                        parts.push((args[0], Some(xb), sp));
                        parts.push((args[1], Some(xa), sp));
                        parts.push((args[2], None, sc));
                    }
                    None => return None,
                },
                Def::Input | Def::Expr(_) => {}
            }
            for (k, (o, partial, sign)) in parts.into_iter().enumerate() {
                let mut slack = FastUp::zero();
                let (contribution, pmag) = match &partial {
                    Some(p) => (self.hs.mul(&l, p, false, &mut slack), partial_mag(&self.hs, p)),
                    None => (l.atoms.clone(), 1.0),
                };
                if k < 3 {
                    adj.conversion_weight[z.index()][k] = sup * pmag * sign.abs() * (1.0 + U);
                }
                let Operand::Value(a) = o else { continue };
                let mut atoms = match lam[a.index()].take() {
                    Some(prev) => lin(&prev, 1.0, &HForm { atoms: contribution }, sign, &mut slack),
                    None => lin(&HForm::default(), 1.0, &HForm { atoms: contribution }, sign, &mut slack),
                };
                self.hs.cap_atoms(self.cap, &mut atoms, &mut slack);
                put_own(&mut atoms, 4 * n + a.index() as u32, slack.total());
                if !atoms.iter().all(|t| t.c.is_finite()) {
                    return None;
                }
                lam[a.index()] = Some(HForm { atoms });
            }
        }
        for &v in &f.inputs {
            let Some(l) = lam[v.index()].take() else { continue };
            let sup = self.hs.range(&l).mag();
            if !sup.is_finite() {
                return None;
            }
            adj.sup[v.index()] = sup;
        }
        Some(adj)
    }
}

/// [`HarmonicSweep::adjoints`]' result, by value index.
#[derive(Clone, Debug)]
pub struct Adjoints {
    /// `max |∂out/∂z|` over the domain (an upper bound; 0: `out` does not depend on `z`).
    pub sup: Vec<f64>,
    /// Per operand position of `z`'s op: `max|∂out/∂z| · max|∂z/∂operand|`.
    pub conversion_weight: Vec<[f64; 3]>,
}
