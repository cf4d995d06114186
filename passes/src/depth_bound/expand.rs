//! Every value of an atomised function as a polynomial in its *x-variables*, with coefficients
//! that are functions of the *θ-inputs*, sampled at [`SAMPLES`] points.
//!
//! The θ-inputs are the inputs a trig variable or a call reads (transitively): joint angles
//! under `sin`/`cos`, arguments of `sqrt` or of a user callback. Every other input is an
//! x-variable. A value is then `Σ_α c_α(θ)·x^α`: an x-monomial `x^α` (a multiset of
//! x-variables) with a coefficient `c_α` that is an analytic function of the θ-inputs (products
//! and sums of constants, θ-inputs, trig and call results, and quotients by them). A
//! coefficient is kept at its values in [`SAMPLES`] pseudo-random θ points
//! ([`robovec_ir::interp::pseudo_random_input`], seeds 1…) with the sum of the magnitudes that
//! made it; it counts as zero (an exact cancellation, such as `a·b − b·a`) when every sample is
//! within [`ZERO_RELATIVE`] of that magnitude — rounding leaves about 1e-16 of it, a nonzero
//! analytic function vanishes at three random points with probability 0.
//!
//! A fused multiply-add (`@fma(a, b, c) = a·b + c`, `@fms = a·b − c`, `@fnma = c − a·b`,
//! [`robovec_ir::Intrinsic`]; what `contract` writes) is not a call here: it is expanded as the
//! product and the sum it fuses, and its operands stay x-variables (issue 47: after `contract`
//! they were taken as θ-inputs, every product became a coefficient and the bound 0 cycles).
//!
//! A value is `None` (not expanded) when it divides by an x-variable, reads a value that is not
//! expanded, or would hold more than `max_terms` monomials (or multiply more than
//! [`PAIRS_PER_TERM`] × `max_terms` pairs of them): expansion is exponential in the depth of
//! products of sums, so large functions expand only their small values. Cost: O(Σ products of
//! the operands' term counts) ≤ O(ops · max_terms · [`PAIRS_PER_TERM`]).

use std::collections::HashMap;
use std::rc::Rc;

use robovec_ir::interp::{eval_call, pseudo_random_input};
use robovec_ir::{BinOp, Def, Function, Intrinsic, Operand, TrigFn, Value};

/// θ points each coefficient is sampled at.
pub const SAMPLES: usize = 3;

/// A coefficient whose every sample is at most this × its magnitude is an exact zero.
pub const ZERO_RELATIVE: f64 = 1e-9;

/// A product may pair at most this × `max_terms` monomials of its operands.
pub const PAIRS_PER_TERM: usize = 16;

/// An x-monomial: the indices of its x-variables (into [`Expansion::variables`]), sorted, with
/// repetition (`x₀²·x₃` is `[0, 0, 3]`). The empty monomial is the coefficient alone.
pub type Monomial = Box<[u32]>;

/// A coefficient at the [`SAMPLES`] θ points, with the sum of the magnitudes of the products
/// that made each sample (the scale its rounding error is relative to).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coef {
    /// Values at the θ points.
    pub at: [f64; SAMPLES],
    /// Sum of magnitudes at the θ points.
    pub magnitude: [f64; SAMPLES],
}

impl Coef {
    fn constant(c: f64) -> Coef {
        Coef { at: [c; SAMPLES], magnitude: [c.abs(); SAMPLES] }
    }

    fn samples(at: [f64; SAMPLES]) -> Coef {
        Coef { at, magnitude: at.map(f64::abs) }
    }

    fn times(self, o: Coef) -> Coef {
        let mut r = self;
        for k in 0..SAMPLES {
            r.at[k] = self.at[k] * o.at[k];
            r.magnitude[k] = self.magnitude[k] * o.magnitude[k];
        }
        r
    }

    fn accumulate(&mut self, o: Coef, sign: f64) {
        for k in 0..SAMPLES {
            self.at[k] += sign * o.at[k];
            self.magnitude[k] += o.magnitude[k];
        }
    }

    /// True when every sample is an exact cancellation (see the module doc).
    pub fn is_zero(&self) -> bool {
        (0..SAMPLES).all(|k| self.at[k].abs() <= ZERO_RELATIVE * self.magnitude[k])
    }

    fn is_finite(&self) -> bool {
        self.at.iter().chain(&self.magnitude).all(|x| x.is_finite())
    }
}

/// A polynomial: its nonzero terms, sorted by monomial.
pub type Poly = Vec<(Monomial, Coef)>;

/// The expansion of every value of a function.
#[derive(Debug)]
pub struct Expansion {
    /// The x-variables, by index: input values.
    pub variables: Vec<Value>,
    /// By value index: its polynomial, or `None` (not expanded; see the module doc). Only the
    /// outputs' are kept: the others are dropped after their last read.
    pub polys: Vec<Option<Rc<Poly>>>,
}

impl Expansion {
    /// The polynomial of an operand (a constant is a polynomial of at most one term).
    pub fn of(&self, o: Operand) -> Option<Rc<Poly>> {
        match o {
            Operand::Value(v) => self.polys[v.index()].clone(),
            Operand::Const(c) => Some(Rc::new(constant(c))),
        }
    }
}

fn constant(c: f64) -> Poly {
    constant_or_empty(Coef::constant(c))
}

/// The fused multiply-add a call is (`@fma`, `@fms`, `@fnma`), if it is one.
pub fn fused(def: &Def) -> Option<Intrinsic> {
    match def {
        Def::Call(callee, args) => Intrinsic::of(callee, args.len()).filter(|i| i.is_fused()),
        _ => None,
    }
}

/// The inputs read, through any chain of values, by a trig variable or a call other than a
/// fused multiply-add ([`fused`]): by value index.
pub fn theta_inputs(f: &Function) -> Vec<bool> {
    let mut read = vec![false; f.values.len()];
    for &v in f.body.iter().rev() {
        let def = &f.value(v).def;
        let under = read[v.index()] || (matches!(def, Def::Trig(..) | Def::Call(..)) && fused(def).is_none());
        if under {
            def.for_each_value(|x| read[x.index()] = true);
        }
    }
    read
}

/// Expands every value of `f` (atomised) into at most `max_terms` monomials; `stop` is asked
/// before each value and ends the expansion early (the values left are `None`).
pub fn expand(f: &Function, max_terms: usize, mut stop: impl FnMut() -> bool) -> Expansion {
    let theta = theta_inputs(f);
    let mut polys: Vec<Option<Rc<Poly>>> = vec![None; f.values.len()];
    let mut variables = Vec::new();
    for &v in &f.inputs {
        let p = if theta[v.index()] {
            let name = f.name_of(v);
            let at = std::array::from_fn(|k| pseudo_random_input(name, k as u64 + 1));
            vec![(Box::default(), Coef::samples(at))]
        } else {
            variables.push(v);
            vec![(vec![variables.len() as u32 - 1].into_boxed_slice(), Coef::constant(1.0))]
        };
        polys[v.index()] = Some(Rc::new(p));
    }
    // Reads left of each value: its polynomial is dropped after the last. An output's read is
    // never done, so outputs keep theirs.
    let mut reads = f.use_counts();
    let mut ex = Expansion { variables, polys };
    for &v in &f.body {
        if stop() {
            break;
        }
        let p = match &f.value(v).def {
            Def::Input | Def::Expr(_) => None,
            Def::Trig(t, a) => ex.polys[a.index()].as_deref().and_then(scalar).map(|c| {
                let at = c.at.map(|x| match t {
                    TrigFn::Sin => x.sin(),
                    TrigFn::Cos => x.cos(),
                });
                vec![(Box::default(), Coef::samples(at))]
            }),
            Def::Call(_, args) if fused(&f.value(v).def).is_some() => {
                let ops: Option<Vec<Rc<Poly>>> = args.iter().map(|o| ex.of(*o)).collect();
                ops.and_then(|ops| {
                    let ab = product(&ops[0], &ops[1], max_terms)?;
                    match fused(&f.value(v).def)? {
                        Intrinsic::Fma => Some(sum(&ab, &ops[2], 1.0)),
                        Intrinsic::Fms => Some(sum(&ab, &ops[2], -1.0)),
                        Intrinsic::Fnma => Some(sum(&ops[2], &ab, -1.0)),
                        Intrinsic::Sqrt => None,
                    }
                })
            }
            Def::Call(callee, args) => {
                let args: Option<Vec<Coef>> = args.iter().map(|o| ex.of(*o).as_deref().and_then(scalar)).collect();
                args.map(|args| {
                    let at =
                        std::array::from_fn(|k| eval_call(callee, &args.iter().map(|c| c.at[k]).collect::<Vec<_>>()));
                    constant_or_empty(Coef::samples(at))
                })
            }
            Def::Binary(op, a, b) => match (ex.of(*a), ex.of(*b)) {
                (Some(a), Some(b)) => match op {
                    BinOp::Add => Some(sum(&a, &b, 1.0)),
                    BinOp::Sub => Some(sum(&a, &b, -1.0)),
                    BinOp::Mul => product(&a, &b, max_terms),
                    BinOp::Div => scalar(&b).and_then(|d| quotient(&a, d)),
                },
                _ => None,
            },
        };
        ex.polys[v.index()] = p.filter(|p| p.len() <= max_terms && p.iter().all(|(_, c)| c.is_finite())).map(Rc::new);
        f.value(v).def.for_each_value(|x| {
            reads[x.index()] -= 1;
            if reads[x.index()] == 0 {
                ex.polys[x.index()] = None;
            }
        });
    }
    ex
}

/// A polynomial without x-variable: the coefficient `c`, or none when it is zero.
fn constant_or_empty(c: Coef) -> Poly {
    if c.is_zero() {
        Vec::new()
    } else {
        vec![(Box::default(), c)]
    }
}

/// The coefficient of a polynomial that has no x-variable (zero for the empty polynomial).
fn scalar(p: &Poly) -> Option<Coef> {
    match p.as_slice() {
        [] => Some(Coef::constant(0.0)),
        [(m, c)] if m.is_empty() => Some(*c),
        _ => None,
    }
}

/// `a + sign·b`, cancelled terms dropped.
fn sum(a: &Poly, b: &Poly, sign: f64) -> Poly {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let order = match (a.get(i), b.get(j)) {
            (Some(x), Some(y)) => x.0.cmp(&y.0),
            (Some(_), None) => std::cmp::Ordering::Less,
            _ => std::cmp::Ordering::Greater,
        };
        match order {
            std::cmp::Ordering::Less => {
                out.push(a[i].clone());
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                let mut c = Coef::constant(0.0);
                c.accumulate(b[j].1, sign);
                out.push((b[j].0.clone(), c));
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                let mut c = a[i].1;
                c.accumulate(b[j].1, sign);
                if !c.is_zero() {
                    out.push((a[i].0.clone(), c));
                }
                i += 1;
                j += 1;
            }
        }
    }
    out
}

/// `a·b`, or `None` past the term or pair limits.
fn product(a: &Poly, b: &Poly, max_terms: usize) -> Option<Poly> {
    if a.len().saturating_mul(b.len()) > PAIRS_PER_TERM.saturating_mul(max_terms) {
        return None;
    }
    let mut terms: HashMap<Monomial, Coef> = HashMap::with_capacity(a.len() * b.len());
    for (ma, ca) in a {
        for (mb, cb) in b {
            let c = ca.times(*cb);
            match terms.entry(merge(ma, mb)) {
                std::collections::hash_map::Entry::Occupied(mut e) => e.get_mut().accumulate(c, 1.0),
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(c);
                }
            }
        }
    }
    let mut out: Poly = terms.into_iter().filter(|(_, c)| !c.is_zero()).collect();
    if out.len() > max_terms {
        return None;
    }
    out.sort_by(|x, y| x.0.cmp(&y.0));
    Some(out)
}

/// `a / d` for a coefficient `d` nonzero at every θ point.
fn quotient(a: &Poly, d: Coef) -> Option<Poly> {
    if d.at.contains(&0.0) {
        return None;
    }
    let inv = Coef { at: d.at.map(|x| 1.0 / x), magnitude: d.at.map(|x| 1.0 / x.abs()) };
    Some(a.iter().map(|(m, c)| (m.clone(), c.times(inv))).collect())
}

/// The product of two sorted monomials, sorted.
fn merge(a: &[u32], b: &[u32]) -> Monomial {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] <= b[j] {
            out.push(a[i]);
            i += 1;
        } else {
            out.push(b[j]);
            j += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out.into_boxed_slice()
}
