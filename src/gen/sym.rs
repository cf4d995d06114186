//! Scalar terms with Robotran's structural simplification, and the builder that names them.
//!
//! A [`Term`] is a small expression over IR values and constants. Its constructors fold what
//! is structurally known, as Robotran's generator does: `0·x = 0`, `1·x = x`, `x ± 0 = x`,
//! constants combined, a minus pulled out of products (`(−a)·b = −(a·b)`) and turned into a
//! subtraction in sums (`a + (−b) = a − b`). [`Builder::bind`] gives a non-trivial term a named
//! temporary (one equation of the parsed IR); atoms (a value, a constant, a negated atom) stay
//! inline, so structural zeros and ones never reach the equations.

use robovec_ir::{BinOp, Def, Expr, Function, Operand, Phase, Span, TrigFn, Value};
use rustc_hash::FxHashMap;

/// A symbolic scalar.
#[derive(Clone, Debug, PartialEq)]
pub enum Term {
    /// A number.
    C(f64),
    /// An IR value (input, trig variable or named temporary).
    V(Value),
    /// `a + b`.
    Add(Box<Term>, Box<Term>),
    /// `a - b`.
    Sub(Box<Term>, Box<Term>),
    /// `a * b`.
    Mul(Box<Term>, Box<Term>),
    /// `-a`.
    Neg(Box<Term>),
}

/// The constant 0.
pub const ZERO: Term = Term::C(0.0);

impl Default for Term {
    /// The constant 0.
    fn default() -> Term {
        ZERO
    }
}

impl Term {
    fn is_zero(&self) -> bool {
        matches!(self, Term::C(x) if *x == 0.0)
    }

    /// A value or constant, possibly negated: kept inline by [`Builder::bind`].
    pub fn is_atom(&self) -> bool {
        match self {
            Term::C(_) | Term::V(_) => true,
            Term::Neg(a) => matches!(**a, Term::C(_) | Term::V(_)),
            _ => false,
        }
    }
}

/// `a + b`, folded.
pub fn add(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if b.is_zero() => a,
        (a, b) if a.is_zero() => b,
        (Term::C(x), Term::C(y)) => Term::C(x + y),
        (a, Term::Neg(b)) => sub(a, *b),
        (Term::Neg(a), b) => sub(b, *a),
        (a, Term::C(y)) if y < 0.0 => sub(a, Term::C(-y)),
        (a, b) => Term::Add(Box::new(a), Box::new(b)),
    }
}

/// `a - b`, folded.
pub fn sub(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if b.is_zero() => a,
        (a, b) if a.is_zero() => neg(b),
        (Term::C(x), Term::C(y)) => Term::C(x - y),
        (a, Term::Neg(b)) => add(a, *b),
        (a, Term::C(y)) if y < 0.0 => add(a, Term::C(-y)),
        (a, b) => Term::Sub(Box::new(a), Box::new(b)),
    }
}

/// `-a`, folded.
pub fn neg(a: Term) -> Term {
    match a {
        Term::C(x) => Term::C(-x),
        Term::Neg(a) => *a,
        a => Term::Neg(Box::new(a)),
    }
}

/// `a * b`, folded.
pub fn mul(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if a.is_zero() || b.is_zero() => ZERO,
        (Term::C(x), Term::C(y)) => Term::C(x * y),
        (Term::C(1.0), b) => b,
        (a, Term::C(1.0)) => a,
        (Term::C(-1.0), b) => neg(b),
        (a, Term::C(-1.0)) => neg(a),
        (Term::C(x), b) if x < 0.0 => neg(mul(Term::C(-x), b)),
        (a, Term::C(y)) if y < 0.0 => neg(mul(a, Term::C(-y))),
        (Term::Neg(a), b) => neg(mul(*a, b)),
        (a, Term::Neg(b)) => neg(mul(a, *b)),
        (a, b) => Term::Mul(Box::new(a), Box::new(b)),
    }
}

/// The sum of `terms`, left to right, folded.
pub fn sum(terms: impl IntoIterator<Item = Term>) -> Term {
    terms.into_iter().fold(ZERO, add)
}

/// Builds one parsed-phase function: inputs on first use, trig variables, named temporaries.
pub struct Builder {
    /// The function being built.
    pub f: Function,
    consts: FxHashMap<String, f64>,
}

impl Builder {
    /// An empty function `name`. Inputs named in `consts` are folded to their value instead of
    /// becoming inputs (`--fold-params`).
    pub fn new(name: &str, consts: FxHashMap<String, f64>) -> Builder {
        Builder { f: Function::new(name, Phase::Parsed), consts }
    }

    /// The input `name` (canonical SPEC §2 name), created on first use; a folded constant when
    /// the builder was given its value.
    pub fn input(&mut self, name: &str) -> Term {
        if let Some(&x) = self.consts.get(name) {
            return Term::C(x);
        }
        Term::V(match self.f.lookup(name) {
            Some(v) => v,
            None => self.f.add_input(name, Span::DUMMY).expect("name is free"),
        })
    }

    /// The trig initial variable `name = fun(arg)` (`C1 = cos(q[1])`).
    pub fn trig(&mut self, name: &str, fun: TrigFn, arg: Term) -> Term {
        let Term::V(a) = arg else { unreachable!("trig of an input") };
        Term::V(self.f.define(self.f.fresh_name(name), Def::Trig(fun, a), Span::DUMMY).expect("fresh"))
    }

    /// `t` itself when it is an atom, else a temporary named `name` (made unique) holding it.
    pub fn bind(&mut self, name: &str, t: Term) -> Term {
        if t.is_atom() {
            return t;
        }
        let e = to_expr(&t);
        let n = self.f.fresh_name(name);
        Term::V(self.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
    }

    /// Sets output `name` to `t` (bound first under `temp` when not an atom).
    pub fn output(&mut self, name: &str, temp: &str, t: Term) {
        let t = self.bind(temp, t);
        let op = match t {
            Term::V(v) => Operand::Value(v),
            Term::C(x) if x >= 0.0 => Operand::Const(x),
            other => match self.bind_always(temp, other) {
                Term::V(v) => Operand::Value(v),
                _ => unreachable!(),
            },
        };
        self.f.set_output(name, op, Span::DUMMY);
    }

    fn bind_always(&mut self, name: &str, t: Term) -> Term {
        let e = to_expr(&t);
        let n = self.f.fresh_name(name);
        Term::V(self.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
    }

    /// The finished function: what no output needs is dropped (Robotran writes only the
    /// equations its outputs read), inputs included; `equations` counts what is left.
    pub fn finish(mut self) -> Function {
        let live = self.f.live_values(&[]);
        self.f.retain(|_, v| live[v.index()]);
        let kept = self.f.body.iter().filter(|&&v| matches!(self.f.value(v).def, Def::Expr(_))).count();
        self.f.equations = Some(kept as u32);
        self.f
    }
}

/// The parsed-IR expression of `t` (constants non-negative, minus as [`Expr::Neg`]).
pub fn to_expr(t: &Term) -> Expr {
    let bin = |op, a: &Term, b: &Term| Expr::Binary(op, Box::new(to_expr(a)), Box::new(to_expr(b)));
    match t {
        Term::C(x) if *x < 0.0 => Expr::Neg(Box::new(Expr::Operand(Operand::Const(-x)))),
        Term::C(x) => Expr::Operand(Operand::Const(*x)),
        Term::V(v) => Expr::Operand(Operand::Value(*v)),
        Term::Add(a, b) => bin(BinOp::Add, a, b),
        Term::Sub(a, b) => bin(BinOp::Sub, a, b),
        Term::Mul(a, b) => bin(BinOp::Mul, a, b),
        Term::Neg(a) => Expr::Neg(Box::new(to_expr(a))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structural_zeros_and_ones_fold() {
        let x = Term::V(Value::with_number(0));
        assert_eq!(mul(Term::C(0.0), x.clone()), ZERO);
        assert_eq!(mul(Term::C(1.0), x.clone()), x);
        assert_eq!(mul(Term::C(-1.0), x.clone()), Term::Neg(Box::new(x.clone())));
        assert_eq!(add(ZERO, x.clone()), x);
        assert_eq!(sub(ZERO, x.clone()), Term::Neg(Box::new(x.clone())));
        assert_eq!(add(x.clone(), neg(x.clone())), Term::Sub(Box::new(x.clone()), Box::new(x.clone())));
        assert_eq!(sum([Term::C(2.0), Term::C(3.0)]), Term::C(5.0));
        // (-x)*x = -(x*x), as Robotran's `BS51 = -qd[1]*qd[1]`.
        assert_eq!(mul(neg(x.clone()), x.clone()), Term::Neg(Box::new(Term::Mul(Box::new(x.clone()), Box::new(x)))));
    }
}
