//! The enclosure of every value of an atomised function over a domain by outward-rounded
//! interval arithmetic ([`robovec_ir::interval`]): one sweep over the body in order, O(1) per
//! op. [`enclose`] is public so that later analyses (`error-bound`) read the same enclosures.

use robovec_ir::domain::Domain;
use robovec_ir::{BinOp, Def, Function, Interval, Intrinsic, Operand, Span, TrigFn, Value};

/// Why a function's values cannot all be enclosed.
#[derive(Clone, Debug, PartialEq)]
pub enum EncloseError {
    /// Inputs the domain gives no range for (names, in input order).
    Missing(Vec<String>),
    /// A division whose divisor's enclosure contains 0.
    DivisorHoldsZero {
        /// The quotient's name.
        value: String,
        /// Its definition's source span (`Span::DUMMY` when a pass made it).
        span: Span,
        /// The divisor as written (`%x` or a constant).
        divisor: String,
        /// The divisor's enclosure.
        range: Interval,
    },
    /// A square root of a value whose enclosure holds negative numbers.
    SqrtOfNegative {
        /// The root's name.
        value: String,
        /// Its definition's source span.
        span: Span,
        /// The operand's enclosure.
        range: Interval,
    },
    /// The ticker stopped the sweep after this many values of the body.
    Stopped(usize),
}

impl EncloseError {
    /// The source span the error points at, if any.
    pub fn span(&self) -> Option<Span> {
        match self {
            EncloseError::DivisorHoldsZero { span, .. } | EncloseError::SqrtOfNegative { span, .. } => {
                Some(*span).filter(|s| *s != Span::DUMMY)
            }
            _ => None,
        }
    }

    /// The message (`@f: …`) for function `f`.
    pub fn message(&self, f: &str) -> String {
        match self {
            EncloseError::Missing(names) => {
                let shown: Vec<&str> = names.iter().take(12).map(String::as_str).collect();
                let more = match names.len() - shown.len() {
                    0 => String::new(),
                    k => format!(" and {k} more"),
                };
                format!(
                    "@{f}: no range for {} input{}: {}{more}; give them with -ranges=FILE (or range<ranges=FILE>), \
                     a JSON object such as {{\"q[*]\": [-3.1416, 3.1416]}} (docs/accuracy.md, \"Certified ranges\")",
                    names.len(),
                    if names.len() == 1 { "" } else { "s" },
                    shown.join(", ")
                )
            }
            EncloseError::DivisorHoldsZero { value, divisor, range, .. } => format!(
                "@{f}: the divisor {divisor} of %{value} may be 0 over the domain: its range is {range}; narrow the \
                 inputs' ranges (-ranges=FILE) so that it excludes 0"
            ),
            EncloseError::SqrtOfNegative { value, range, .. } => format!(
                "@{f}: %{value} is the square root of a value that may be negative over the domain: its range is \
                 {range}; narrow the inputs' ranges (-ranges=FILE)"
            ),
            EncloseError::Stopped(k) => format!("in @{f} after {k} values"),
        }
    }
}

/// The interval of an operand.
pub(super) fn of(x: &[Interval], o: &Operand) -> Interval {
    match o {
        Operand::Value(v) => x[v.index()],
        Operand::Const(c) => Interval::point(*c),
    }
}

/// The enclosure of every value of `f` (atomised) over `domain`, indexed by
/// [`Value::index`]: inputs get their domain range; `sin`/`cos`, `+ − × /`, `@sqrt` and the
/// fused `@fma`, `@fms`, `@fnma` their outward-rounded enclosures; a user callback every real
/// ([`Interval::ENTIRE`]: robovec cannot see it). `x · x` and `x − x` of one value are the
/// square and 0 (the dependency of the two operands is exact). `tick` is called once per value
/// of the body and stops the sweep when it returns true.
///
/// # Errors
/// [`EncloseError`]: inputs without a range (all named), the first division by an enclosure
/// holding 0 or square root of one holding negatives, or the stop.
pub fn enclose(f: &Function, domain: &Domain, tick: impl FnMut() -> bool) -> Result<Vec<Interval>, EncloseError> {
    enclose_with(f, domain, None, tick)
}

/// [`enclose`], and with `affine = Some(cap)` each interval intersected with the range of the
/// value's affine form of at most `cap` noise symbols ([`super::affine`]) and with the range of
/// its harmonic form of at most [`super::harmonic::range_atoms`]`(ops)` atoms
/// ([`super::harmonic`]): never wider than [`enclose`]'s, O(ops · cap) for the affine forms and
/// O(ops · atoms²) for the harmonic ones.
///
/// # Errors
/// As [`enclose`].
pub fn enclose_with(
    f: &Function,
    domain: &Domain,
    affine: Option<usize>,
    mut tick: impl FnMut() -> bool,
) -> Result<Vec<Interval>, EncloseError> {
    let missing = domain.missing(f);
    if !missing.is_empty() {
        return Err(EncloseError::Missing(missing.into_iter().map(str::to_string).collect()));
    }
    let mut x = vec![Interval::ENTIRE; f.values.len()];
    for &v in &f.inputs {
        x[v.index()] = domain.get(f.name_of(v)).expect("no input is missing").interval;
    }
    let mut sweep = affine.map(|cap| super::affine::AffineSweep::new(f, domain, cap));
    // The cap of one state's ops: K interleaved states are K independent copies, enclosed as
    // tightly as one (the same formats verify after `interleave`), for K times one's work.
    let ops_per_state = f.body.len().div_ceil(f.states.max(1) as usize);
    let mut harmonic = affine
        .and_then(|_| super::harmonic::HarmonicSweep::new(f, domain, super::harmonic::range_atoms(ops_per_state)));
    for (k, &v) in f.body.iter().enumerate() {
        if tick() {
            return Err(EncloseError::Stopped(k));
        }
        x[v.index()] = enclose_value(f, v, &x)?;
        if let Some(s) = &mut sweep {
            x[v.index()] = s.step(v, &x)?;
        }
        if let Some(h) = &mut harmonic {
            x[v.index()] = h.step(v, &x);
        }
    }
    Ok(x)
}

/// The enclosure of body value `v` from its operands' in `x`.
fn enclose_value(f: &Function, v: Value, x: &[Interval]) -> Result<Interval, EncloseError> {
    let data = f.value(v);
    Ok(match &data.def {
        Def::Input | Def::Expr(_) => Interval::ENTIRE,
        Def::Trig(t, a) => match t {
            TrigFn::Sin => x[a.index()].sin(),
            TrigFn::Cos => x[a.index()].cos(),
        },
        Def::Binary(op, a, b) => {
            let same = same_pair(a, b);
            let (ia, ib) = (of(x, a), of(x, b));
            match op {
                BinOp::Add => ia + ib,
                BinOp::Sub if same => Interval::point(0.0),
                BinOp::Sub => ia - ib,
                BinOp::Mul if same => ia.sqr(),
                BinOp::Mul => ia * ib,
                BinOp::Div => ia.checked_div(ib).ok_or_else(|| EncloseError::DivisorHoldsZero {
                    value: data.name.clone(),
                    span: data.span,
                    divisor: match b {
                        Operand::Value(p) => format!("%{}", f.name_of(*p)),
                        Operand::Const(c) => format!("{c:?}"),
                    },
                    range: ib,
                })?,
            }
        }
        Def::Call(callee, args) => match Intrinsic::of(callee, args.len()) {
            Some(Intrinsic::Sqrt) => {
                let a = of(x, &args[0]);
                a.sqrt().ok_or_else(|| EncloseError::SqrtOfNegative {
                    value: data.name.clone(),
                    span: data.span,
                    range: a,
                })?
            }
            // a square's product is its square (`fma(x, x, c)`: the dependency is exact, as for
            // `x · x`), then the sum, each outward-rounded
            Some(i @ (Intrinsic::Fma | Intrinsic::Fms | Intrinsic::Fnma)) if same_pair(&args[0], &args[1]) => {
                let p = of(x, &args[0]).sqr();
                let c = of(x, &args[2]);
                match i {
                    Intrinsic::Fma => p + c,
                    Intrinsic::Fms => p - c,
                    _ => c - p,
                }
            }
            Some(Intrinsic::Fma) => of(x, &args[0]).fma(of(x, &args[1]), of(x, &args[2])),
            Some(Intrinsic::Fms) => of(x, &args[0]).fma(of(x, &args[1]), -of(x, &args[2])),
            Some(Intrinsic::Fnma) => (-of(x, &args[0])).fma(of(x, &args[1]), of(x, &args[2])),
            None => Interval::ENTIRE,
        },
    })
}

/// True when `a` and `b` are the same value (`x · x`: a square).
pub(crate) fn same_pair(a: &Operand, b: &Operand) -> bool {
    matches!((a, b), (Operand::Value(p), Operand::Value(q)) if p == q)
}
