//! The worst-case error of every value of an atomised function over a domain: one sweep over
//! the body in order, O(1) per op, from the values' enclosures ([`crate::range::enclose_with`]).
//!
//! # The bound
//! Write `z` for a value's exact real value at an input point and `ẑ` for the value the
//! function computes there (in the formats [`Formats`] gives). With `X_z` the enclosure of `z`
//! over the domain, `M_z = max |X_z|` its magnitude and `E_a` the bounds of the operands
//! already computed, `|ẑ − z| ≤ E_z` where, before the result's own rounding,
//!
//! | op | propagated error `P_z` |
//! |---|---|
//! | `a ± b` | `E_a + E_b` (0 for `a − a`) |
//! | `a × b` | `M_a·E_b + M_b·E_a + E_a·E_b` |
//! | `a / b` | `(E_a + M_z·E_b) / (mig_b − E_b)`, `mig_b = min |X_b|` (unbounded when `E_b ≥ mig_b`) |
//! | `√a` | `E_a / (√(lo_a − E_a) + √lo_a)` when `E_a < lo_a`, else `√E_a` (unbounded when the computed operand may be negative) |
//! | `sin a`, `cos a` | `min(E_a, 2)` (both are 1-Lipschitz) |
//! | `fma(a, b, c)` (and `fms`, `fnma`) | `M_a·E_b + M_b·E_a + E_a·E_b + E_c` |
//!
//! (exact identities: `âb̂ − ab = a·e_b + b·e_a + e_a·e_b`, `â/b̂ − a/b = (e_a − z·e_b)/b̂`,
//! `√â − √a = e_a/(√â + √a)` and `|√x − √y| ≤ √|x − y|`), and the result's rounding adds
//! `rel·(M_z + P_z) + abs` (`|fl(y) − y| ≤ rel·|y| + abs` for the format, [`Rounding`]), so
//! `E_z = P_z + rel·(M_z + P_z) + abs`. Nothing is first-order: the products of errors are
//! kept, so the bound holds for any size of error, and every sum and product of the bound is
//! rounded upward. A value whose bound is not finite (a callback, a divisor or a square root's
//! operand that the error may carry through 0, an overflow of the enclosure) makes every value
//! computed from it unbounded; the pass reports them, never a finite number it cannot prove.
//!
//! # The adjoint bound
//! The table is exact up to its remainders: each op's error is linear in its operands' errors
//! at the exact values (`∂z/∂a`: `b` for `a·b`, `1/b` and `−z/b` for `a/b`, `1/(2√a)`, `cos a`,
//! ±1) plus a remainder bounded with the `E`s above (`E_a·E_b` for a product, `E_a²/2` for
//! `sin`/`cos`, `(E_a + M_z·E_b)·E_b/(mig_b·(mig_b − E_b))` for a quotient,
//! `E_a²/(2√lo_a·(√(lo_a − E_a) + √lo_a)²)` for a root), then the result's rounding. Unrolled,
//! `e_o = Σ_z (∂o/∂z)·s_z` exactly, `s_z` what `z` adds (rounding and remainder, `|s_z| ≤ S_z`;
//! each conversion of an operand it reads; an input's store), so `E_o ≤ Σ_z max|∂o/∂z|·S_z`
//! over the domain. [`OutputAdjoints`] encloses `max|∂o/∂z|` by a reverse sweep whose adjoints
//! are the harmonic forms of [`crate::range::harmonic`] (a chain of rotations multiplies out
//! to one rotation there, where the table adds magnitudes at each joint). Each output's bound
//! is the smaller of the two; the adjoints are computed when `outputs × ops ≤`
//! [`ADJOINT_WORK`].
//!
//! # How each format rounds ([`Formats`])
//! - **`f64`** (every value binary64, as `-eval` and the C back end's `double` compute):
//!   inputs and constants exact; each op `rel = 2⁻⁵³` (`u`), `abs = 2⁻¹⁰⁷⁴` (the smallest subnormal,
//!   above what underflow may lose); `sin`, `cos` `rel = `[`LIBM_ULPS`]`·2⁻⁵²`, `abs =
//!   `[`LIBM_ULPS`]`·2⁻¹⁰⁷³` (the C library's error, as the enclosures assume).
//! - **`f32`** (every value binary32, as `accuracy`'s binary32 evaluation and the C back end's
//!   `float` compute): inputs and constants rounded to binary32 (a constant's error, and that
//!   of an input whose range is a point, is its exact distance to its binary32 value); each op `rel = 2⁻²⁴`, `abs = 2⁻¹⁵⁰`; `sin`, `cos` of
//!   binary32 `rel = `[`LIBM_ULPS`]`·2⁻²³` — or `2⁻²³` (1 ulp, [`INLINE32_ULPS`]) with
//!   [`TrigImpl::Inline`] when the computed argument is within [`INLINE32_LIMIT`]: robovec's own
//!   binary32 kernel, as `codegen<c;trig=inline>` writes it, checked on every such argument.
//! - **`mixed`** (each value in its own format, [`robovec_ir::format`]: an op computes in its
//!   value's format): binary64 as above; a binary32 op reads its operands rounded to binary32
//!   (a constant's error is its exact distance to binary32, a binary64 or fixed-point operand
//!   adds `2⁻²⁴` of its computed magnitude, beyond binary32's largest number it is unbounded)
//!   and rounds once as in `f32`; `fix<w,f>` rounds once, `abs = 2^-(f+1)` (round to nearest),
//!   after the exact integer op ([`robovec_ir::format::integer_op`], whose constants read as
//!   32-bit words add their exact distance, [`robovec_ir::format::fix_constant`]) or after the
//!   binary64 op and its rounding (any other op), and the computed value's whole range must fit the
//!   format: `[lo_z − E_z, hi_z + E_z]` within the values that store without overflow, or the
//!   sweep stops with [`BoundError::FixOverflow`]. Inputs in fixed point or binary32 are
//!   rounded on the way in; a binary64 op, or a fixed-point op that is not an integer op, reads
//!   constants exactly.
//!
//! Exact steps the bound knows: `a − a` is 0 (while `a`'s bound is finite); a product by a constant power of two, or by
//! ±1, 0, only loses bits to underflow (`rel = 0`); a sum with the constant 0 is exact.

use robovec_ir::format::Format;
use robovec_ir::interval::LIBM_ULPS;
use robovec_ir::{BinOp, Def, Function, Interval, Intrinsic, Operand, Span, Value};

use crate::range::harmonic::{adjoint_atoms, Adjoints, HarmonicSweep};

/// Which format each value is computed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Formats {
    /// Every value binary64.
    F64,
    /// Every value binary32 (inputs and constants rounded to it).
    F32,
    /// Each value in its own format ([`Function::format`]).
    Mixed,
}

crate::params::word_enum! {
    /// Which `sin`/`cos` the computed function calls: the error each is allowed.
    pub enum TrigImpl {
        /// The C library's (and `-eval`'s): [`LIBM_ULPS`] ulps of the result's format.
        Libm = "libm",
        /// robovec's own, as `codegen<c;trig=inline>` writes it: a binary32 `sin`/`cos` whose
        /// argument is within [`INLINE32_LIMIT`] is within [`INLINE32_ULPS`] ulp of the exact
        /// value (every such binary32 argument checked); beyond it, and in binary64 (tested on
        /// hard arguments, not on all of them), [`LIBM_ULPS`].
        Inline = "inline",
    }
}

/// The largest `|x|` (rad) whose binary32 `sin`/`cos` `codegen<c;trig=inline>` computes with its
/// own kernel (2¹¹; beyond it the C library's `sinf`/`cosf`): `backends/src/c/trig`.
pub const INLINE32_LIMIT: f64 = 2048.0;

/// The error allowed to the binary32 `sin`/`cos` of `codegen<c;trig=inline>` on
/// `|x| ≤` [`INLINE32_LIMIT`], in ulps of the exact value's binade: 1. Every binary32 argument
/// of that range, both signs, through the three kernels the back end writes (one state, a
/// `float` batch, binary32 values in a `double` file), compiled with and without FMA, was
/// compared with the C library's binary64 `sin`/`cos` (`scripts/trig_ulps.sh`; the largest
/// error and where are in docs/accuracy.md).
pub const INLINE32_ULPS: f64 = 1.0;

/// The rounding of a stored result: `|fl(y) − y| ≤ rel·|y| + abs`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rounding {
    /// Relative part (unit roundoff).
    pub rel: f64,
    /// Absolute part (underflow, or half a fixed-point step).
    pub abs: f64,
}

/// 2⁻⁵³, binary64's unit roundoff.
const U64: f64 = f64::EPSILON / 2.0;
/// 2⁻²⁴, binary32's unit roundoff.
const U32: f64 = f32::EPSILON as f64 / 2.0;

impl Rounding {
    /// No rounding.
    pub const EXACT: Rounding = Rounding { rel: 0.0, abs: 0.0 };
    /// One binary64 rounding of an op (underflow included: 2⁻¹⁰⁷⁴, the subnormal step, as
    /// half of it is not a binary64 number).
    pub const F64: Rounding = Rounding { rel: U64, abs: f64::from_bits(1) };
    /// One binary32 rounding of an op (underflow included: half of 2⁻¹⁴⁹).
    pub const F32: Rounding = Rounding { rel: U32, abs: 7.006_492_321_624_085e-46 };

    /// The rounding of storing a binary64 result in `format` (after the binary64 op's own).
    pub fn store(format: Format) -> Rounding {
        match format {
            Format::Binary64 => Rounding::EXACT,
            Format::Binary32 => Rounding::F32,
            Format::Fix { fraction, .. } => Rounding { rel: 0.0, abs: 2f64.powi(-fraction - 1) },
        }
    }

    /// This rounding followed by `then` (`(1 + r₁)(1 + r₂) − 1` and the absolute parts
    /// carried through), rounded upward.
    pub fn then(self, then: Rounding) -> Rounding {
        let rel = up(up(self.rel + then.rel) + up(self.rel * then.rel));
        let abs = up(up(self.abs * (1.0 + then.rel).next_up()) + then.abs);
        Rounding { rel, abs }
    }

    /// This rounding with both parts times `scale` (`2^-bits`: `bits` more bits of precision).
    pub fn scaled(self, scale: f64) -> Rounding {
        Rounding { rel: self.rel * scale, abs: self.abs * scale }
    }

    /// The error of rounding a value of magnitude at most `m` (0 for no rounding).
    fn of(self, m: f64) -> f64 {
        if self == Rounding::EXACT {
            return 0.0;
        }
        up(up(self.rel * m) + self.abs)
    }
}

/// `x` rounded upward by one float (bounds are sums and products rounded to nearest: the next
/// float up is at least the exact result).
fn up(x: f64) -> f64 {
    if x.is_nan() {
        f64::INFINITY
    } else {
        x.next_up()
    }
}

/// Why the sweep cannot bound a function.
#[derive(Clone, Debug, PartialEq)]
pub enum BoundError {
    /// A fixed-point value whose computed range does not fit its format.
    FixOverflow {
        /// The value's name.
        value: String,
        /// Its definition's source span.
        span: Span,
        /// Its format.
        format: Format,
        /// The range the computed value may take (enclosure widened by its error bound).
        range: Interval,
        /// The format's range.
        fits: (f64, f64),
    },
    /// The ticker stopped the sweep after this many values of the body.
    Stopped(usize),
}

impl BoundError {
    /// The message (`@f: …`) for function `f`.
    pub fn message(&self, f: &str) -> String {
        match self {
            BoundError::FixOverflow { value, format, range, fits, .. } => format!(
                "@{f}: %{value} in {format} may overflow over the domain: its computed value may reach {range}, \
                 beyond the format's [{:e}, {:e}]; give it more integer bits (fewer fractional bits) or narrow the \
                 inputs' ranges",
                fits.0, fits.1
            ),
            BoundError::Stopped(k) => format!("in @{f} after {k} values"),
        }
    }

    /// The source span the error points at, if any.
    pub fn span(&self) -> Option<Span> {
        match self {
            BoundError::FixOverflow { span, .. } => Some(*span).filter(|s| *s != Span::DUMMY),
            BoundError::Stopped(_) => None,
        }
    }
}

/// The error bound of every value of `f` (atomised), indexed by [`Value::index`], from the
/// enclosures `x` of its exact values over the domain ([`crate::range::enclose_with`], same
/// indexing): `f64::INFINITY` where no finite bound is proved (module doc). `tick` is called
/// once per value of the body and stops the sweep when it returns true.
///
/// # Errors
/// [`BoundError::FixOverflow`] (mode [`Formats::Mixed`] only), or the stop.
pub fn bound(f: &Function, x: &[Interval], mode: Formats, tick: impl FnMut() -> bool) -> Result<Vec<f64>, BoundError> {
    bound_with_more_bits(f, x, mode, 0, tick)
}

/// [`bound`] as if every binary32 and fixed-point format had `bits` more bits of precision
/// (`bits = 1`: binary32 rounding to half its unit, `fix<w,f>` as `fix<w+1,f+1>`; binary64, the
/// reference, as it is): their roundings, conversions and input stores scaled by `2^-bits`, the
/// values' ranges and the overflow limits as they are. `precision` reports with it what one
/// more bit would give each output. For fixed point it is exactly [`bound`] of the function
/// with the wider formats while each op that is an integer op ([`robovec_ir::format::integer_op`],
/// decided on `f`'s formats) stays one in the wider function (its intermediate two bits longer
/// at most, within [`robovec_ir::format::INTEGER_BITS`]); for binary32 a bound for a hypothetical format of 24 + `bits`
/// significant bits (`bits = 0` is [`bound`]).
///
/// # Errors
/// As [`bound`].
pub fn bound_with_more_bits(
    f: &Function,
    x: &[Interval],
    mode: Formats,
    bits: i32,
    tick: impl FnMut() -> bool,
) -> Result<Vec<f64>, BoundError> {
    let adjoints = OutputAdjoints::new(f, x);
    bound_with_adjoints(f, x, mode, bits, adjoints.as_ref(), TrigImpl::Libm, tick)
}

/// [`bound_with_more_bits`] with each output's adjoints computed already ([`OutputAdjoints`]:
/// they depend on the ops and the enclosures, not on the formats, so `precision` computes them
/// once for all its candidates; `None`: the forward bound alone), for the `sin`/`cos` `trig`
/// (the others take [`TrigImpl::Libm`]).
///
/// # Errors
/// As [`bound`].
pub fn bound_with_adjoints(
    f: &Function,
    x: &[Interval],
    mode: Formats,
    bits: i32,
    adjoints: Option<&OutputAdjoints>,
    trig: TrigImpl,
    tick: impl FnMut() -> bool,
) -> Result<Vec<f64>, BoundError> {
    sweep(f, x, mode, bits, adjoints, trig, tick)
}

/// The adjoints of each output of a function ([`HarmonicSweep::adjoints`]): `max|∂o/∂z|` for
/// every value `z`, with which [`bound`] weighs each value's rounding and remainder
/// (`Σ_z max|∂o/∂z| · S_z`, the module doc's "adjoint bound").
#[derive(Clone, Debug)]
pub struct OutputAdjoints {
    outputs: Vec<(Value, Option<Adjoints>)>,
}

impl OutputAdjoints {
    /// The adjoints of `f`'s outputs over the enclosures `x`; `None` when `outputs × ops`
    /// exceeds [`ADJOINT_WORK`].
    pub fn new(f: &Function, x: &[Interval]) -> Option<OutputAdjoints> {
        if f.outputs.len().saturating_mul(f.body.len()) > ADJOINT_WORK {
            return None;
        }
        Some(Self::with_atoms(f, x, adjoint_atoms(f.outputs.len(), f.body.len())))
    }

    /// The adjoints of `f`'s outputs over the enclosures `x`, their forms capped at `atoms`
    /// atoms (≥ 4) whatever the function's size: [`OutputAdjoints::new`] takes
    /// [`adjoint_atoms`]; this is for comparisons. O(outputs · ops · atoms²) time.
    pub fn with_atoms(f: &Function, x: &[Interval], atoms: usize) -> OutputAdjoints {
        let mut exact = HarmonicSweep::over_enclosures(f, x, atoms);
        for &v in &f.body {
            exact.step(v, x);
        }
        let mut outputs: Vec<(Value, Option<Adjoints>)> = Vec::new();
        for o in &f.outputs {
            let Operand::Value(v) = o.value else { continue };
            if outputs.iter().any(|p| p.0 == v) {
                continue;
            }
            outputs.push((v, exact.adjoints(v, x)));
        }
        OutputAdjoints { outputs }
    }
}

/// [`bound`] by the forward sweep alone (the module doc's table: magnitudes, no adjoints), as
/// it is for functions beyond [`ADJOINT_WORK`]; for comparisons.
///
/// # Errors
/// As [`bound`].
pub fn forward_bound(f: &Function, x: &[Interval], mode: Formats) -> Result<Vec<f64>, BoundError> {
    sweep(f, x, mode, 0, None, TrigImpl::Libm, || false)
}

/// The forward sweep, then (with `adjoint`) each output's adjoint bound where smaller.
fn sweep(
    f: &Function,
    x: &[Interval],
    mode: Formats,
    bits: i32,
    adjoints: Option<&OutputAdjoints>,
    trig: TrigImpl,
    mut tick: impl FnMut() -> bool,
) -> Result<Vec<f64>, BoundError> {
    let scale = 2f64.powi(-bits);
    let mut e = vec![f64::INFINITY; f.values.len()];
    let mut nonneg = vec![false; f.values.len()];
    let mut sources = adjoints
        .map(|_| Sources { local: vec![f64::INFINITY; f.values.len()], conversions: vec![[0.0; 3]; f.values.len()] });
    for &v in &f.inputs {
        let r = x[v.index()];
        let m = r.mag();
        let format = format_in(f, v, mode);
        e[v.index()] = match format.store(r.lo) {
            _ if m > largest(f, v, mode) => f64::INFINITY,
            // A point (a fixed parameter): its rounding is known exactly.
            Ok(stored) if r.lo == r.hi && bits == 0 => up((stored - r.lo).abs()),
            _ => Rounding::store(format).scaled(scale).of(m),
        };
        nonneg[v.index()] = x[v.index()].lo >= 0.0;
        if let Some(s) = &mut sources {
            s.local[v.index()] = e[v.index()];
        }
        check_fits(f, v, x, &e, mode)?;
    }
    for (k, &v) in f.body.iter().enumerate() {
        if tick() {
            return Err(BoundError::Stopped(k));
        }
        let (bound, local, conversions) = match propagate(f, v, x, &e, &nonneg, mode, trig, scale) {
            Step::Known(b) => (b, b, [0.0; 3]),
            Step::Propagated { propagated, rounding, reads, remainder } => {
                let b = round(f, v, x, mode, scale, propagated, rounding);
                let own =
                    if b.is_finite() { (Interval::point(b) - Interval::point(propagated)).hi.max(0.0) } else { b };
                let mut conversions = [0.0; 3];
                for (k, (o, &read)) in f.value(v).def.operands().iter().zip(&reads).enumerate().take(3) {
                    let base = match o {
                        Operand::Value(p) => e[p.index()],
                        Operand::Const(_) => 0.0,
                    };
                    conversions[k] = if read.is_finite() {
                        (Interval::point(read) - Interval::point(base)).hi.max(0.0)
                    } else {
                        read
                    };
                }
                (b, up(own + remainder), conversions)
            }
        };
        e[v.index()] = bound;
        if let Some(s) = &mut sources {
            s.local[v.index()] = local;
            s.conversions[v.index()] = conversions;
        }
        nonneg[v.index()] = computed_nonneg(f, v, x, &e, &nonneg);
        check_fits(f, v, x, &e, mode)?;
    }
    if let (Some(s), Some(adjoints)) = (&sources, adjoints) {
        // Each output's bound by its adjoints, where smaller (both are sound).
        for (v, adj) in &adjoints.outputs {
            let Some(adj) = adj else { continue };
            if !e[v.index()].is_finite() || e[v.index()] == 0.0 {
                continue;
            }
            let b = adjoint_sum(adj, s);
            if b < e[v.index()] {
                e[v.index()] = b;
            }
        }
    }
    Ok(e)
}

/// What each value adds to the outputs' errors, for the adjoint bound
/// (the forward sweep fills it, by value index).
#[derive(Clone, Debug, Default)]
struct Sources {
    /// `S_z`: the value's own rounding plus the remainder of its op's linearisation (for an
    /// input, its store's error); `∞` when unbounded.
    local: Vec<f64>,
    /// The conversion each operand's read adds (binary32 narrowing, a constant's distance),
    /// by operand position.
    conversions: Vec<[f64; 3]>,
}

/// `Σ_z max|∂o/∂z| · S_z + Σ_(z, k) max|∂o/∂z|·max|∂z/∂operand_k| · conversion_(z, k)`, rounded
/// up (`∞` when a reached value has no bound).
fn adjoint_sum(adj: &Adjoints, s: &Sources) -> f64 {
    let mut total = Interval::point(0.0);
    for (i, &sup) in adj.sup.iter().enumerate() {
        if sup > 0.0 {
            total = total + Interval::point(sup) * Interval::point(s.local[i]);
            for (w, c) in adj.conversion_weight[i].iter().zip(&s.conversions[i]) {
                if *w > 0.0 && *c > 0.0 {
                    total = total + Interval::point(*w) * Interval::point(*c);
                }
            }
        }
    }
    if total.hi.is_nan() {
        f64::INFINITY
    } else {
        total.hi
    }
}

/// `max |∂out/∂z|` over the domain for every value `z` of `f` (atomised; by value index, 0
/// where `out` does not depend on `z`), from the enclosures `x`: the adjoints [`bound`] weighs
/// each value's rounding with ([`HarmonicSweep::adjoints`]); `None` when a value on the way
/// has no form (a callback, a divisor or root's operand whose enclosure holds 0).
pub fn adjoint_sups(f: &Function, x: &[Interval], out: Value) -> Option<Vec<f64>> {
    let mut exact = HarmonicSweep::over_enclosures(f, x, adjoint_atoms(1, f.body.len()));
    for &v in &f.body {
        exact.step(v, x);
    }
    exact.adjoints(out, x).map(|a| a.sup)
}

/// The most `outputs × ops` for which [`bound`] also bounds each output by its adjoints
/// ([`HarmonicSweep::adjoints`]: one reverse sweep of O(ops · atoms²) per output, the atoms
/// [`adjoint_atoms`]); beyond it the forward bound alone. Measured (`error-bound<format=f32>`,
/// release, the whole run), forward → with adjoints: UR5 RNEA (6 × 399, 1,024 atoms) 4.2·10⁻²
/// → 4.7·10⁻³ N·m in 0.14 s; Panda (9 × 944, 1,024 atoms) 3.2·10⁻¹ → 1.2·10⁻¹ N·m in 1.6 s;
/// Talos (32 × 3,969, 48 atoms) 3.0·10¹ → 2.6·10¹ N·m, median bound / witness 1,196 → 917, in
/// 1.4 s against 0.8 s; a 30-dof chain's `invdyna` (30 × 2,971) in 4.7 s and 0.5 GB. Beyond it:
/// the Segway's `dirdyna` over whole turns (192 × 3,633) would be 1.9× tighter at the median
/// output, up to 5.6×, in 1.5 s against 0.08 s (left out: every corpus function between 2·10⁵
/// and 10⁶ would add seconds to the test suite's corpus sweeps); a humanoid's `dirdyna`
/// (1,306 × 33k) would take minutes.
pub const ADJOINT_WORK: usize = 200_000;

/// True when the operand's computed value is never negative (or is NaN).
fn is_nonneg(o: &Operand, nonneg: &[bool]) -> bool {
    match *o {
        Operand::Value(v) => nonneg[v.index()],
        Operand::Const(c) => c >= 0.0,
    }
}

/// True when `v`'s computed value is never negative: its enclosure widened by its error is, or
/// it is a square, a root, or a sum, product or quotient of such values (rounding to nearest,
/// to binary32 and to fixed point keeps the sign of a result ≥ 0).
fn computed_nonneg(f: &Function, v: Value, x: &[Interval], e: &[f64], nonneg: &[bool]) -> bool {
    if x[v.index()].lo - e[v.index()] >= 0.0 {
        return true;
    }
    let n = |o: &Operand| is_nonneg(o, nonneg);
    match &f.value(v).def {
        Def::Binary(BinOp::Mul, a, b) => a == b || (n(a) && n(b)),
        Def::Binary(BinOp::Add | BinOp::Div, a, b) => n(a) && n(b),
        Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
            Some(Intrinsic::Sqrt) => true,
            Some(Intrinsic::Fma) => (args[0] == args[1] || (n(&args[0]) && n(&args[1]))) && n(&args[2]),
            _ => false,
        },
        _ => false,
    }
}

/// The largest finite magnitude `v` may take in `mode` before its rounding may overflow (a
/// fixed-point format's overflow is [`check_fits`]'s).
fn largest(f: &Function, v: Value, mode: Formats) -> f64 {
    let f32_max = f32::MAX as f64;
    match mode {
        Formats::F64 => f64::MAX,
        Formats::F32 => f32_max,
        Formats::Mixed => match f.format(v) {
            Format::Binary32 => f32_max,
            _ => f64::MAX,
        },
    }
}

/// [`BoundError::FixOverflow`] when `v` is fixed point (mode mixed) and its computed range may
/// store out of the format.
fn check_fits(f: &Function, v: Value, x: &[Interval], e: &[f64], mode: Formats) -> Result<(), BoundError> {
    let format = f.format(v);
    let (Formats::Mixed, Some((lo, hi)), Some(step)) = (mode, format.fix_range(), format.fix_step()) else {
        return Ok(());
    };
    let err = e[v.index()];
    let r = x[v.index()];
    let range = Interval::new((r.lo - err).next_down(), (r.hi + err).next_up());
    // Storing rounds to nearest, ties up: it overflows from hi + step/2 on, and below lo − step/2.
    let fits = range.lo >= lo - step / 2.0 && range.hi < hi + step / 2.0 && err.is_finite();
    if fits {
        return Ok(());
    }
    let data = f.value(v);
    Err(BoundError::FixOverflow { value: data.name.clone(), span: data.span, format, range, fits: (lo, hi) })
}

/// The format `w` is computed in under `mode`.
fn format_in(f: &Function, w: Value, mode: Formats) -> Format {
    match mode {
        Formats::F64 => Format::Binary64,
        Formats::F32 => Format::Binary32,
        Formats::Mixed => f.format(w),
    }
}

/// How an op reads its operands: `narrow` when its value is binary32, which rounds every
/// operand to binary32 first (`robovec_ir::format`'s semantics; in mode f32 every value is).
#[derive(Clone, Copy)]
struct Reader<'a> {
    f: &'a Function,
    mode: Formats,
    narrow: bool,
    /// The op is a fixed-point integer op (mode mixed): constants read as 32-bit words.
    integer: bool,
    /// `2^-bits` ([`bound_with_more_bits`]).
    scale: f64,
}

impl Reader<'_> {
    /// The reader of `v`'s op.
    fn of(f: &Function, v: Value, mode: Formats, scale: f64) -> Reader<'_> {
        let format = format_in(f, v, mode);
        let integer = matches!(format, Format::Fix { .. }) && robovec_ir::format::integer_op(f, v).is_some();
        Reader { f, mode, narrow: format == Format::Binary32, integer, scale }
    }

    /// The operand's enclosure and error bound as the op reads it: a constant's error is its
    /// exact distance to binary32 when the op narrows, else 0; a value not in binary32 read by
    /// a narrowing op adds a binary32 rounding of its computed magnitude (∞ past binary32's
    /// largest number).
    fn operand(&self, o: &Operand, x: &[Interval], e: &[f64]) -> (Interval, f64) {
        match *o {
            Operand::Value(v) => {
                let (r, err) = (x[v.index()], e[v.index()]);
                if !self.narrow || format_in(self.f, v, self.mode) == Format::Binary32 {
                    return (r, err);
                }
                let m = up(r.mag() + err);
                let conv = if m > f32::MAX as f64 {
                    f64::INFINITY
                } else if r.lo == r.hi && err == 0.0 && self.scale == 1.0 {
                    // An exact point (a fixed parameter): its rounding is known exactly.
                    up((r.lo - r.lo as f32 as f64).abs())
                } else {
                    Rounding::F32.scaled(self.scale).of(m)
                };
                (r, up(err + conv))
            }
            Operand::Const(c) if self.integer => {
                let (k, fc) = robovec_ir::format::fix_constant(c).expect("an integer op's constants are words");
                // k · 2^-fc is exact in binary64 (|k| ≤ 2^31), and so is the difference
                // (Sterbenz, or both within 32 significant bits of each other): rounded up anyway.
                let word = k as f64 * 2f64.powi(-fc);
                (Interval::point(c), up((c - word).abs()))
            }
            Operand::Const(c) => {
                let err = match (self.narrow, self.scale == 1.0) {
                    (false, _) => 0.0,
                    (true, true) => up((c - c as f32 as f64).abs()),
                    (true, false) => Rounding::F32.scaled(self.scale).of(c.abs()),
                };
                (Interval::point(c), err)
            }
        }
    }

    /// True for a constant whose product is exact but for underflow: 0, ±1, ±2^k (after the
    /// rounding to binary32 of a narrowing op).
    fn exact_factor(&self, o: &Operand) -> bool {
        let Operand::Const(c) = *o else { return false };
        let c = if self.narrow { c as f32 as f64 } else { c };
        c == 0.0
            || (c.is_finite() && {
                let (m, _) = frexp(c.abs());
                m == 0.5
            })
    }
}

/// The mantissa in [0.5, 1) and exponent of a positive finite `x`.
fn frexp(x: f64) -> (f64, i32) {
    if x == 0.0 {
        return (0.0, 0);
    }
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    if exp == 0 {
        // Subnormal: scale up first.
        let (m, e) = frexp(x * 2f64.powi(64));
        return (m, e - 64);
    }
    let m = f64::from_bits((bits & !(0x7ff << 52)) | (1022 << 52));
    (m, exp - 1022)
}

/// `a·b + c`'s propagated error: `M_a·E_b + M_b·E_a + E_a·E_b + E_c`.
fn product_error(ma: f64, ea: f64, mb: f64, eb: f64) -> f64 {
    if ea == 0.0 && eb == 0.0 {
        return 0.0;
    }
    up(up(up(ma * eb) + up(mb * ea)) + up(ea * eb))
}

/// What [`propagate`] finds for one value.
enum Step {
    /// The bound is known: `a − a` (0), or no finite bound.
    Known(f64),
    /// The propagated error `P_z`, the rounding of the result (before the store of a fixed-point
    /// value), and the error of each operand as the op reads it (`E_a` with its conversion, or a
    /// constant's distance), by operand position; and the remainder of the op's linearisation
    /// at the exact operands (`e_a·e_b` for a product, `e²/2` for `sin`/`cos`, …), `∞` when
    /// none is proved.
    Propagated { propagated: f64, rounding: Rounding, reads: Vec<f64>, remainder: f64 },
}

/// The error `v` propagates from its operands (module doc's table) and its rounding.
#[allow(clippy::too_many_arguments)]
fn propagate(
    f: &Function,
    v: Value,
    x: &[Interval],
    e: &[f64],
    nonneg: &[bool],
    mode: Formats,
    trig: TrigImpl,
    scale: f64,
) -> Step {
    let data = f.value(v);
    let mz = x[v.index()].mag();
    if !mz.is_finite() {
        return Step::Known(f64::INFINITY);
    }
    let rd = Reader::of(f, v, mode, scale);
    // An integer op is exact before its value's store ([`Rounding::store`], below).
    let op = if rd.narrow {
        Rounding::F32.scaled(scale)
    } else if rd.integer {
        Rounding::EXACT
    } else {
        Rounding::F64
    };
    let trig_ulps = |r: Rounding, ulps: f64| Rounding { rel: ulps * 2.0 * r.rel, abs: ulps * 2.0 * r.abs };
    let reads: Vec<f64>;
    let mut remainder = 0.0;
    let (propagated, rounding) = match &data.def {
        Def::Input | Def::Expr(_) => return Step::Known(f64::INFINITY),
        Def::Trig(_, a) => {
            let ea = rd.operand(&Operand::Value(*a), x, e).1;
            reads = vec![ea];
            // |sin(a + e) − sin a − cos a · e| ≤ e²/2 (and for cos).
            remainder = up(up(ea * ea) / 2.0);
            // The computed argument is within `|a| + e_a` of 0: robovec's binary32 kernel there.
            let own = trig == TrigImpl::Inline && rd.narrow && up(x[a.index()].mag() + ea) <= INLINE32_LIMIT;
            (ea.min(2.0), trig_ulps(op, if own { INLINE32_ULPS } else { LIBM_ULPS }))
        }
        Def::Binary(op_kind, a, b) => {
            let (ia, ea) = rd.operand(a, x, e);
            let (ib, eb) = rd.operand(b, x, e);
            let same = crate::range::enclose::same_pair(a, b);
            reads = vec![ea, eb];
            match op_kind {
                // `a − a` is 0 while the computed `a` is finite (∞ − ∞ is NaN).
                BinOp::Sub if same && ea.is_finite() => return Step::Known(0.0),
                BinOp::Sub if same => return Step::Known(f64::INFINITY),
                BinOp::Add | BinOp::Sub => {
                    let zero = |o: &Operand| matches!(o, Operand::Const(c) if *c == 0.0);
                    let r = if zero(a) || zero(b) { Rounding::EXACT } else { op };
                    (up(ea + eb), r)
                }
                BinOp::Mul => {
                    let r =
                        if rd.exact_factor(a) || rd.exact_factor(b) { Rounding { rel: 0.0, abs: op.abs } } else { op };
                    remainder = up(ea * eb);
                    (product_error(ia.mag(), ea, ib.mag(), eb), r)
                }
                BinOp::Div => {
                    let mig = ib.mig();
                    let room = (mig - eb).next_down();
                    if room.is_nan() || room <= 0.0 {
                        return Step::Known(f64::INFINITY);
                    }
                    let num = up(ea + up(mz * eb));
                    // (e_a − z·e_b)/b̂ − (e_a − z·e_b)/b = −(e_a − z·e_b)·e_b/(b·b̂).
                    remainder = up(up(num * eb) / (mig * room).next_down());
                    (if num == 0.0 { 0.0 } else { up(num / room) }, op)
                }
            }
        }
        Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
            Some(Intrinsic::Sqrt) => {
                let (ia, ea) = rd.operand(&args[0], x, e);
                reads = vec![ea];
                // e_a/(√â + √a) − e_a/(2√a) = −e_a²/(2√a·(√â + √a)²).
                remainder = if ea == 0.0 {
                    0.0
                } else if ea < ia.lo {
                    let low = (ia.lo - ea).next_down().max(0.0);
                    let s = (low.sqrt().next_down() + ia.lo.sqrt().next_down()).next_down();
                    let den = (2.0 * ia.lo.sqrt().next_down() * s * s).next_down();
                    if den > 0.0 {
                        up(up(ea * ea) / den)
                    } else {
                        f64::INFINITY
                    }
                } else {
                    f64::INFINITY
                };
                let p = if ea == 0.0 {
                    0.0
                } else if ea < ia.lo {
                    // e_a / (√â + √a) with â ≥ lo − E_a > 0; never above √E_a.
                    let low = (ia.lo - ea).next_down().max(0.0);
                    let den = (low.sqrt().next_down() + ia.lo.sqrt().next_down()).next_down();
                    let quotient = if den > 0.0 { up(ea / den) } else { f64::INFINITY };
                    quotient.min(up(ea.sqrt()))
                } else if is_nonneg(&args[0], nonneg) {
                    up(ea.sqrt())
                } else {
                    // The computed operand may be negative: its root is NaN.
                    return Step::Known(f64::INFINITY);
                };
                (p, op)
            }
            Some(Intrinsic::Fma | Intrinsic::Fms | Intrinsic::Fnma) => {
                let (ia, ea) = rd.operand(&args[0], x, e);
                let (ib, eb) = rd.operand(&args[1], x, e);
                let (_, ec) = rd.operand(&args[2], x, e);
                reads = vec![ea, eb, ec];
                remainder = up(ea * eb);
                (up(product_error(ia.mag(), ea, ib.mag(), eb) + ec), op)
            }
            None => return Step::Known(f64::INFINITY),
        },
    };
    if !propagated.is_finite() {
        return Step::Known(f64::INFINITY);
    }
    Step::Propagated { propagated, rounding, reads, remainder }
}

/// `E_z = P_z + rel·(M_z + P_z) + abs`: the bound of `v` from its propagated error and its
/// rounding (then its store when fixed point, mode mixed).
fn round(
    f: &Function,
    v: Value,
    x: &[Interval],
    mode: Formats,
    scale: f64,
    propagated: f64,
    rounding: Rounding,
) -> f64 {
    let mz = x[v.index()].mag();
    let rd = Reader::of(f, v, mode, scale);
    // A binary32 op rounds once, in binary32; a fixed-point value after its integer or binary64 op.
    let rounding = match mode {
        Formats::Mixed if !rd.narrow => rounding.then(Rounding::store(f.format(v)).scaled(scale)),
        _ => rounding,
    };
    let magnitude = up(mz + propagated);
    if magnitude > largest(f, v, mode) {
        // The result may overflow to ±∞: no rounding model holds.
        return f64::INFINITY;
    }
    let own = rounding.of(magnitude);
    if propagated == 0.0 && own == 0.0 {
        // Exact operands and an exact step (`a − a`, a sum with 0 of an exact value).
        return 0.0;
    }
    let total = up(propagated + own);
    if total.is_finite() {
        total
    } else {
        f64::INFINITY
    }
}

/// The verifier's check of fixed-point formats over a domain (issue 48 item 4: "the verifier
/// checks that a fixed-point value's range fits its integer bits"): when `f` (atomised) has a
/// fixed-point value and `domain` covers its inputs, every fixed-point value's computed range
/// (its enclosure widened by its error bound, mode [`Formats::Mixed`]) must store in its
/// format. `Ok` when there is nothing to check or the domain does not cover the inputs (the
/// interpreter still stops at an overflow).
///
/// # Errors
/// [`BoundError::FixOverflow`] for the first value that may overflow, or the enclosure's own
/// refusal (a divisor that may be 0 over the domain) as its message.
pub fn check_fixed_formats(f: &Function, domain: &robovec_ir::domain::Domain) -> Result<(), String> {
    let has_fix = f.phase == robovec_ir::Phase::Atomised
        && f.has_formats()
        && f.inputs.iter().chain(&f.body).any(|&v| matches!(f.format(v), Format::Fix { .. }));
    if !has_fix || !domain.missing(f).is_empty() {
        return Ok(());
    }
    let x = crate::range::enclose_with(f, domain, Some(crate::range::affine::DEFAULT_TERMS), || false)
        .map_err(|e| e.message(&f.name))?;
    bound(f, &x, Formats::Mixed, || false).map(|_| ()).map_err(|e| e.message(&f.name))
}

/// How much each value's own rounding weighs in the outputs' bounds, to first order: the
/// adjoint of the sweep's propagation ([`bound`]'s table linearised at the enclosures `x` and
/// bounds `e`: `±` passes 1, `a·b` passes `M_b + E_b` to `a`, `a/b` passes `1/(min|b| − E_b)`
/// to `a` and `M_z` times that to `b`, `√a` passes `1/(2√(lo_a − E_a))`, `sin`/`cos` 1, the
/// fused ops as a product and a sum), seeded with `seed` at each output value (added when
/// values are shared). A value's rounding error `r` adds at most about `λ_v · r` to
/// `Σ_o seed_o · E_o`. O(ops); used by `precision` to rank values, never as a bound.
pub fn sensitivities(f: &Function, x: &[Interval], e: &[f64], seed: &[(Value, f64)]) -> Vec<f64> {
    let mut lam = vec![0.0f64; f.values.len()];
    for &(v, s) in seed {
        lam[v.index()] += s;
    }
    let mag = |o: &Operand| match *o {
        Operand::Value(v) => x[v.index()].mag() + e[v.index()],
        Operand::Const(c) => c.abs(),
    };
    for &v in f.body.iter().rev() {
        let l = lam[v.index()];
        if l == 0.0 || !l.is_finite() {
            continue;
        }
        let pass = |o: &Operand, w: f64, lam: &mut Vec<f64>| {
            if let Operand::Value(a) = *o {
                let add = l * w;
                lam[a.index()] += if add.is_finite() { add } else { f64::MAX };
            }
        };
        match &f.value(v).def {
            Def::Trig(_, a) => pass(&Operand::Value(*a), 1.0, &mut lam),
            Def::Binary(op, a, b) => match op {
                BinOp::Sub if a == b => {}
                BinOp::Add | BinOp::Sub => {
                    pass(a, 1.0, &mut lam);
                    pass(b, 1.0, &mut lam);
                }
                BinOp::Mul => {
                    pass(a, mag(b), &mut lam);
                    pass(b, mag(a), &mut lam);
                }
                BinOp::Div => {
                    let (ib, eb) = Reader::of(f, v, Formats::Mixed, 1.0).operand(b, x, e);
                    let room = (ib.mig() - eb).max(f64::MIN_POSITIVE);
                    pass(a, 1.0 / room, &mut lam);
                    pass(b, x[v.index()].mag() / room, &mut lam);
                }
            },
            Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
                Some(Intrinsic::Sqrt) => {
                    let lo = match args[0] {
                        Operand::Value(w) => (x[w.index()].lo - e[w.index()]).max(0.0),
                        Operand::Const(c) => c.max(0.0),
                    };
                    pass(&args[0], 0.5 / lo.sqrt().max(1e-150), &mut lam);
                }
                Some(_) => {
                    pass(&args[0], mag(&args[1]), &mut lam);
                    pass(&args[1], mag(&args[0]), &mut lam);
                    pass(&args[2], 1.0, &mut lam);
                }
                None => {}
            },
            Def::Input | Def::Expr(_) => {}
        }
    }
    lam
}
