//! Scalar terms with Robotran's structural simplification, and the builder that names them.
//!
//! A [`Term`] is a small expression over IR values and constants. Its constructors fold what
//! is structurally known, as Robotran's generator does: `0·x = 0`, `1·x = x`, `x ± 0 = x`,
//! constants combined, a minus pulled out of products (`(−a)·b = −(a·b)`) and turned into a
//! subtraction in sums (`a + (−b) = a − b`). [`Builder::bind`] gives a non-trivial term a named
//! temporary (one equation of the parsed IR); atoms (a value, a constant, a negated atom) stay
//! inline, so structural zeros and ones never reach the equations.
//!
//! Beyond Robotran's rules, four rewritings that only change rounding:
//! - the numbers of a sum are gathered into one at its top (`(x + 0.4) + 0.1 = x + 0.5`), and a
//!   number times such a sum is distributed (`k·(x + c) = k·x + k·c`), so that with
//!   `--fold-params` the constants of a composite inertia cost one addition, not one each;
//! - the numeric factors of a product are multiplied into one, written first (`k·(x·y)`), so
//!   that a minus in front folds into it when atomised (SPEC §3), and `x + x` is `2·x`;
//! - a minus is never bound: `−a − b` is `−(a + b)`, and [`Builder::bind`] of `−x` binds `x`
//!   and hands back `−name`, so the readers' sums and products absorb the sign instead of a
//!   `0 − x` op (serial30's `M`, `--fold-params`, after `atomise,cse`: 59 such ops → 1);
//! - what two products share is taken out of their sum or difference (`x·y ± x·z = x·(y ± z)`,
//!   `k₁·x ± k₂·x = (k₁ ± k₂)·x`, `k·y ± k·z = k·(y ± z)`): the RNEA's `ω × (In·ω)` with a
//!   diagonal `In` becomes `(Iyy − Izz)·ωy·ωz`, `m·a + m·b` one product.
//!
//! The first three, on the upper triangle of `M` (`--fold-params`, `atomise,cse`): serial30
//! 8 017 → 7 805 ops, UR5 190 → 175, Panda (9 × 9) 599 → 547, Solo-12 1 061 → 984, Talos
//! 4 511 → 4 235, TIAGo Pro 9 044 → 8 466. The factoring, after [`super::crba`]'s turns:
//! `invdyna` (`atomise,cse`, folded / symbolic parameters) serial30 3 352 → 3 145 / 3 392 →
//! 3 266, UR5 473 → 419 / 486 → 451, TIAGo Pro 7 666 → 7 600 / 7 955 → 7 928; `M` of Panda
//! 515 → 512, Talos 3 993 → 3 989, TIAGo Pro 8 271 → 8 269 (the others unchanged).

use robovec_ir::time_limit::{Deadline, Ticker};
use robovec_ir::{BinOp, Def, Expr, Function, OpCounts, Operand, Output, Phase, Span, TrigFn, Value};
use rustc_hash::FxHashMap;

use super::{Reached, Stopped};

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

/// `t` split as `rest + c`, `c` the number at the top of a sum (0 when none). [`add`] and
/// [`sub`] keep every number of a sum gathered there, so one level is all there is to look at.
fn split_const(t: Term) -> (Term, f64) {
    match t {
        Term::C(x) => (ZERO, x),
        Term::Add(a, b) => match (*a, *b) {
            (x, Term::C(c)) | (Term::C(c), x) => (x, c),
            (a, b) => (Term::Add(Box::new(a), Box::new(b)), 0.0),
        },
        Term::Sub(a, b) => match (*a, *b) {
            (x, Term::C(c)) => (x, -c),
            (Term::C(c), x) => (neg(x), c),
            (a, b) => (Term::Sub(Box::new(a), Box::new(b)), 0.0),
        },
        Term::Neg(a) => {
            let (r, c) = split_const(*a);
            (neg(r), -c)
        }
        t => (t, 0.0),
    }
}

/// `core + c` with the number at the top (`core` holds none): `x + c`, `x − |c|`, `c − y` for
/// `core = −y`, `c > 0`, and `−(y + |c|)` for `core = −y`, `c < 0` (the minus left for the
/// enclosing sum or product to absorb).
fn with_const(core: Term, c: f64) -> Term {
    if c == 0.0 {
        return core;
    }
    match core {
        Term::C(x) => Term::C(x + c),
        Term::Neg(y) if c > 0.0 => Term::Sub(Box::new(Term::C(c)), y),
        Term::Neg(y) => Term::Neg(Box::new(Term::Add(y, Box::new(Term::C(-c))))),
        x if c > 0.0 => Term::Add(Box::new(x), Box::new(Term::C(c))),
        x => Term::Sub(Box::new(x), Box::new(Term::C(-c))),
    }
}

/// `a + b`, folded; the numbers of both sums gathered into one at the top (`(x + 0.4) + 0.1`
/// is `x + 0.5`: one op where two were written).
pub fn add(a: Term, b: Term) -> Term {
    let (a, ca) = split_const(a);
    let (b, cb) = split_const(b);
    with_const(add_core(a, b), ca + cb)
}

/// `a - b`, folded; numbers gathered as in [`add`].
pub fn sub(a: Term, b: Term) -> Term {
    let (a, ca) = split_const(a);
    let (b, cb) = split_const(b);
    with_const(sub_core(a, b), ca - cb)
}

/// `a + b` of two terms without a top number: zeros dropped, minus signs turned into
/// subtractions, `−a − b` as `−(a + b)` (the minus left for the enclosing term to absorb),
/// `x + x` as `2·x` (one op either way, none when `x` has a numeric factor).
fn add_core(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if b.is_zero() => a,
        (a, b) if a.is_zero() => b,
        (a, Term::Neg(b)) => sub_core(a, *b),
        (Term::Neg(a), b) => sub_core(b, *a),
        (a, b) if a == b => mul(Term::C(2.0), a),
        (a, b) => match factored(&a, &b, true) {
            Some(t) => t,
            None => Term::Add(Box::new(a), Box::new(b)),
        },
    }
}

/// The factors of a product: its number (1 when none) and the other factors, in order.
fn factors(t: &Term) -> (f64, Vec<Term>) {
    match t {
        Term::C(k) => (*k, Vec::new()),
        Term::Mul(a, b) => {
            let (ka, mut fa) = factors(a);
            let (kb, fb) = factors(b);
            fa.extend(fb);
            (ka * kb, fa)
        }
        t => (1.0, vec![t.clone()]),
    }
}

/// `a ± b` with what the two products share taken out: `x·y ± x·z = x·(y ± z)` (numbers
/// combined, `k₁·x ± k₂·x = (k₁ ± k₂)·x`), or a common number `k·y ± k·z = k·(y ± z)`;
/// `None` when they share nothing.
fn factored(a: &Term, b: &Term, plus: bool) -> Option<Term> {
    if !matches!(a, Term::Mul(..)) && !matches!(b, Term::Mul(..)) {
        return None;
    }
    let (ka, mut fa) = factors(a);
    let (kb, mut fb) = factors(b);
    let mut common = Vec::new();
    fa.retain(|x| match fb.iter().position(|y| y == x) {
        Some(i) => {
            common.push(fb.remove(i));
            false
        }
        None => true,
    });
    let product = |k: f64, f: Vec<Term>| f.into_iter().fold(Term::C(k), mul);
    let (k, inner) = if !common.is_empty() {
        (1.0, (product(ka, fa), product(kb, fb)))
    } else if ka == kb && ka != 1.0 {
        (ka, (product(1.0, fa), product(1.0, fb)))
    } else {
        return None;
    };
    let inner = if plus { add(inner.0, inner.1) } else { sub(inner.0, inner.1) };
    Some(mul(product(k, common), inner))
}

/// `a - b` of two terms without a top number (see [`add_core`]).
fn sub_core(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if b.is_zero() => a,
        (a, b) if a.is_zero() => neg(b),
        (a, Term::Neg(b)) => add_core(a, *b),
        (Term::Neg(a), b) => neg(add_core(*a, b)),
        (a, b) => match factored(&a, &b, false) {
            Some(t) => t,
            None => Term::Sub(Box::new(a), Box::new(b)),
        },
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

/// `t` split as `k·rest` (`k = 1` when `t` has no numeric factor first).
fn split_factor(t: Term) -> (f64, Term) {
    match t {
        Term::Mul(a, b) => match (*a, *b) {
            (Term::C(k), x) => (k, x),
            (a, b) => (1.0, Term::Mul(Box::new(a), Box::new(b))),
        },
        t => (1.0, t),
    }
}

/// `a * b`, folded: the numeric factors of both sides multiplied into one written first
/// (`k·(x·y)`, so that a minus in front folds into it when atomised, SPEC §3), a minus pulled
/// out of the product, and a number times a sum with a top number distributed over it
/// (`k·(x + c) = k·x + k·c`, as many ops, the number free to join the enclosing sum).
pub fn mul(a: Term, b: Term) -> Term {
    match (a, b) {
        (a, b) if a.is_zero() || b.is_zero() => ZERO,
        (Term::C(x), Term::C(y)) => Term::C(x * y),
        (Term::Neg(a), b) => neg(mul(*a, b)),
        (a, Term::Neg(b)) => neg(mul(a, *b)),
        (Term::C(x), b) if x < 0.0 => neg(mul(Term::C(-x), b)),
        (a, Term::C(y)) if y < 0.0 => neg(mul(a, Term::C(-y))),
        (a, b) => {
            let (ka, a) = split_factor(a);
            let (kb, b) = split_factor(b);
            let k = ka * kb;
            let core = match (a, b) {
                (Term::C(x), y) | (y, Term::C(x)) => return scale(k * x, y),
                (a, b) => Term::Mul(Box::new(a), Box::new(b)),
            };
            scale(k, core)
        }
    }
}

/// `k·x` for a positive number `k` and a term `x` with no numeric factor first.
fn scale(k: f64, x: Term) -> Term {
    if k == 1.0 {
        return x;
    }
    match split_const(x) {
        (r, c) if c != 0.0 => add(scale(k, r), Term::C(k * c)),
        (r, _) => match r {
            Term::Neg(r) => neg(scale(k, *r)),
            r => Term::Mul(Box::new(Term::C(k)), Box::new(r)),
        },
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
    /// The time limit the writers check per body ([`Builder::check`]); `None`: no limit.
    pub deadline: Option<Deadline>,
    /// Tests: the steps over the whole function ([`Builder::ticker`]) stop at this tick whatever
    /// the clock says ([`crate::Request::tick_budget`]).
    pub tick_budget: Option<u64>,
    /// The first pivot that folded to a number that is zero or not finite (`1/d` of a number), by
    /// the writers' coordinate: a singular mass matrix (issue 47).
    pub singular: Option<Singular>,
}

/// A pivot of a factorisation of `M` that folded to a number whose reciprocal is not finite
/// (`1/0`): the mass matrix is singular at that coordinate, whatever the joint values
/// ([`Builder::singular`]; the URDF front end names the joint and link, issue 47).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Singular {
    /// The velocity coordinate (1-based, `qdd[i]`, row `i` of `M`) whose pivot it is.
    pub coordinate: usize,
    /// The pivot's value (0, or not finite).
    pub pivot: f64,
}

impl Builder {
    /// An empty function `name`. Inputs named in `consts` are folded to their value instead of
    /// becoming inputs (`--fold-params`).
    pub fn new(name: &str, consts: FxHashMap<String, f64>) -> Builder {
        Builder { f: Function::new(name, Phase::Parsed), consts, deadline: None, tick_budget: None, singular: None }
    }

    /// A [`Ticker`] on the builder's deadline (and test budget) for a step over the whole
    /// function: counting its ops, compacting it (issue 47: these took longer than writing).
    pub fn ticker(&self) -> Ticker {
        Ticker::new(self.deadline, self.tick_budget)
    }

    /// The [`Stopped`] of this function at `at`.
    pub fn stopped(&self, at: Reached) -> Stopped {
        Stopped { function: self.f.name.clone(), at, seconds: self.deadline.map_or(0.0, |d| d.seconds) }
    }

    /// Checks the time limit once a writer reached `body` of `bodies` (one clock read, tens of
    /// ns: writers call it per body, whose equations cost far more).
    ///
    /// # Errors
    /// [`Stopped`] naming this function and `body` once [`Builder::deadline`] is reached.
    pub fn check(&self, body: usize, bodies: usize) -> Result<(), Stopped> {
        self.check_at(Reached::Body { body, bodies })
    }

    /// [`Builder::check`] at any point of the writing (`dirdyna` checks per row of `M`).
    ///
    /// # Errors
    /// [`Stopped`] at `at` once [`Builder::deadline`] is reached.
    pub fn check_at(&self, at: Reached) -> Result<(), Stopped> {
        match &self.deadline {
            Some(d) if d.reached() => Err(self.stopped(at)),
            _ => Ok(()),
        }
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
    /// A negated term `−x` binds `x` as `m{name}` ("minus name": the value is the opposite of
    /// what `name` would hold) and returns `−m{name}`: the minus stays with the readers, whose
    /// sums and products absorb it (`a + (−b) = a − b`, `(−a)·b = −(a·b)`), instead of
    /// costing a `0 − x` op of its own; only an output that is itself negated pays it.
    pub fn bind(&mut self, name: &str, t: Term) -> Term {
        if t.is_atom() {
            return t;
        }
        if let Term::Neg(x) = t {
            return neg(self.bind(&format!("m{name}"), *x));
        }
        let e = to_expr(&t);
        let n = self.f.fresh_name(name);
        Term::V(self.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
    }

    /// Sets output `name` to `t` (bound first under `temp` when not an atom).
    pub fn output(&mut self, name: &str, temp: &str, t: Term) {
        self.output_with(name, || temp.to_string(), t);
    }

    /// [`Builder::output`] with the temporary's name made only when one is bound (`M`'s
    /// zeros and copies, `nq²` of them, need none).
    ///
    /// Each output name is written once (the writers' `Qq[i]`, `M[i][j]`, `c[i]` are): the
    /// output is appended without a lookup by name, and [`Builder::finish`] indexes the names
    /// once (a lookup and an insert into a growing table per output cost `dirdyna` of a
    /// 2,000-branch star, 4 million outputs, a third of its time; the verifier rejects a
    /// name written twice).
    pub fn output_with(&mut self, name: impl Into<String>, temp: impl FnOnce() -> String, t: Term) {
        let op = match t {
            Term::V(v) => Operand::Value(v),
            Term::C(x) if x >= 0.0 => Operand::Const(x),
            t => {
                let temp = temp();
                match self.bind(&temp, t) {
                    Term::V(v) => Operand::Value(v),
                    Term::C(x) if x >= 0.0 => Operand::Const(x),
                    other => match self.bind_always(&temp, other) {
                        Term::V(v) => Operand::Value(v),
                        _ => unreachable!(),
                    },
                }
            }
        };
        self.f.outputs.push(Output { name: name.into(), value: op, span: Span::DUMMY });
    }

    fn bind_always(&mut self, name: &str, t: Term) -> Term {
        let e = to_expr(&t);
        let n = self.f.fresh_name(name);
        Term::V(self.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
    }

    /// An empty builder for another function of the same name, folded constants and deadline
    /// (a writer that tries two formulations writes the second into it).
    pub fn fresh(&self) -> Builder {
        Builder {
            f: Function::new(&self.f.name, Phase::Parsed),
            consts: self.consts.clone(),
            deadline: self.deadline,
            tick_budget: self.tick_budget,
            singular: None,
        }
    }

    /// The ops of what [`Builder::finish`] would keep once atomised and its repeated ops merged
    /// (`-passes=atomise,cse`, what every pipeline of a user starts with): the count to compare
    /// two formulations by, since one may repeat more terms than the other (the ABA's articulated
    /// inertias, built entry by entry, repeat many). This builder is unchanged. Cost: linear in
    /// the ops. [`Builder::ops_after_cse_until`] without a time limit.
    pub fn ops_after_cse(&self) -> u64 {
        ops_after_cse_of(&self.f, &Ticker::default(), false).expect("a ticker without a limit never stops")
    }

    /// [`Builder::ops_after_cse`] that stops at the builder's deadline (one tick per equation,
    /// op and value; issue 47: on a 10,000-joint chain this count took 19 s, over twice the
    /// time of writing the function, and never looked at the clock).
    ///
    /// # Errors
    /// [`Stopped`] at [`Reached::Step`] once the deadline is reached.
    pub fn ops_after_cse_until(&self) -> Result<u64, Stopped> {
        let limited = self.deadline.is_some();
        ops_after_cse_of(&self.f, &self.ticker(), limited).ok_or_else(|| self.stopped(Reached::Step(COUNTING)))
    }

    /// The finished function: what no output needs is dropped (Robotran writes only the
    /// equations its outputs read), inputs included; `equations` counts what is left. The
    /// names of values and outputs are indexed again ([`Function::retain`]).
    /// [`Builder::finish_until`] without a time limit.
    pub fn finish(self) -> Function {
        let unlimited = Builder { deadline: None, tick_budget: None, ..self };
        unlimited.finish_until().expect("a ticker without a limit never stops")
    }

    /// [`Builder::finish`] that stops at the builder's deadline (one tick per value and output;
    /// issue 47: compacting the 25 million outputs of a 5,000-branch star's `dirdyna` takes
    /// seconds).
    ///
    /// # Errors
    /// [`Stopped`] at [`Reached::Step`] once the deadline is reached; a large function is then
    /// leaked, not freed (the run ends with an error; freeing a gigabyte took a second).
    pub fn finish_until(mut self) -> Result<Function, Stopped> {
        let ticker = self.ticker();
        let done = live_values_until(&self.f, &ticker)
            .is_some_and(|live| self.f.retain_until(|_, v| live[v.index()], &mut || ticker.tick()));
        if !done {
            let stop = self.stopped(Reached::Step(COMPACTING));
            crate::abandon(self.f);
            return Err(stop);
        }
        let kept = self.f.body.iter().filter(|&&v| matches!(self.f.value(v).def, Def::Expr(_))).count();
        self.f.equations = Some(kept as u32);
        Ok(self.f)
    }
}

/// [`Reached::Step`] of [`Builder::ops_after_cse_until`].
const COUNTING: &str = "counting its ops after atomise,cse";

/// [`Reached::Step`] of [`Builder::finish_until`].
const COMPACTING: &str = "compacting it";

/// [`Function::live_values`] of `f` (no extra roots), one tick per output and value; `None`
/// when `ticker` says stop.
fn live_values_until(f: &Function, ticker: &Ticker) -> Option<Vec<bool>> {
    let mut live = vec![false; f.values.len()];
    for o in &f.outputs {
        if ticker.tick() {
            return None;
        }
        if let Operand::Value(v) = o.value {
            live[v.index()] = true;
        }
    }
    for &v in f.body.iter().rev() {
        if ticker.tick() {
            return None;
        }
        if live[v.index()] {
            f.value(v).def.for_each_value(|a| live[a.index()] = true);
        }
    }
    Some(live)
}

/// [`Function::op_counts`] of `f`, one tick per value; `None` when `ticker` says stop.
pub(crate) fn op_counts_until(f: &Function, ticker: &Ticker) -> Option<OpCounts> {
    let mut c = OpCounts::default();
    for &v in &f.body {
        if ticker.tick() {
            return None;
        }
        match &f.value(v).def {
            Def::Expr(e) => robovec_ir::count::count_expr(e, &mut c),
            d => {
                if let Some(k) = d.op_kind() {
                    c.bump(k)
                }
            }
        }
    }
    Some(c)
}

/// The ops of `f` once atomised, pruned of what no output reads and its repeated ops merged
/// ([`Builder::ops_after_cse`]); `None` when `ticker` says stop. The atomised copy is pruned
/// (atomising a dead equation writes only dead ops) and its merges counted in place
/// ([`robovec_ir::transform::cse::cse_drops_until`]), then dropped, under a time limit (`limited`) on
/// a thread of its own ([`crate::drop_later`]: freeing the millions of names of a large one
/// took seconds), or abandoned on a stop ([`crate::abandon`]).
fn ops_after_cse_of(f: &Function, ticker: &Ticker, limited: bool) -> Option<u64> {
    let mut a = robovec_ir::transform::atomise::atomise_until(f, ticker)?;
    let pruned =
        live_values_until(&a, ticker).is_some_and(|live| a.retain_until(|_, v| live[v.index()], &mut || ticker.tick()));
    let ops = if pruned {
        let drops = robovec_ir::transform::cse::cse_drops_until(&a, ticker);
        drops.and_then(|d| Some(op_counts_until(&a, ticker)?.total - d))
    } else {
        None
    };
    match ops {
        Some(_) => crate::drop_later(a, limited),
        None => crate::abandon(a),
    }
    ops
}

/// `1 / d`: `d` bound as `d_name`, its reciprocal as `inv_name` (a number stays a number).
/// `d` is the pivot of velocity coordinate `coordinate` (1-based) in a factorisation of `M`: a
/// number whose reciprocal is not finite (a zero pivot) is recorded as [`Builder::singular`]
/// (the first one), so that the front end can say which joint and link make `M` singular
/// instead of the verifier rejecting the constant `inf` (issue 47).
pub(crate) fn reciprocal(b: &mut Builder, coordinate: usize, d_name: &str, inv_name: &str, d: Term) -> Term {
    let d = match d {
        Term::C(x) => {
            if !(1.0 / x).is_finite() && b.singular.is_none() {
                b.singular = Some(Singular { coordinate, pivot: x });
            }
            return Term::C(1.0 / x);
        }
        d => b.bind(d_name, d),
    };
    let e = Expr::Binary(BinOp::Div, Box::new(Expr::Operand(Operand::Const(1.0))), Box::new(to_expr(&d)));
    let n = b.f.fresh_name(inv_name);
    Term::V(b.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
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

    #[test]
    fn numbers_gather_and_minus_signs_are_left_to_the_readers() {
        let mut b = Builder::new("t", Default::default());
        let (x, y) = (b.input("x"), b.input("y"));
        let bx = || Box::new(x.clone());
        // One number per sum, at the top: (x + 0.25) + 0.5 and 0.5 − (0.25 − x).
        assert_eq!(add(add(x.clone(), Term::C(0.25)), Term::C(0.5)), Term::Add(bx(), Box::new(Term::C(0.75))));
        assert_eq!(sub(Term::C(0.5), sub(Term::C(0.25), x.clone())), Term::Add(bx(), Box::new(Term::C(0.25))));
        assert_eq!(mul(Term::C(2.0), add(x.clone(), Term::C(1.0))), add(mul(Term::C(2.0), x.clone()), Term::C(2.0)));
        // One numeric factor, first; x + x = 2·x.
        assert_eq!(mul(Term::C(2.0), mul(x.clone(), Term::C(3.0))), Term::Mul(Box::new(Term::C(6.0)), bx()));
        assert_eq!(add(x.clone(), x.clone()), Term::Mul(Box::new(Term::C(2.0)), bx()));
        // −x − y = −(x + y); binding it binds x + y and returns its negation.
        let s = sub(neg(x.clone()), y.clone());
        assert_eq!(s, neg(Term::Add(bx(), Box::new(y.clone()))));
        let t = b.bind("T", s);
        let Term::Neg(v) = t else { panic!("{t:?}") };
        let Term::V(v) = *v else { panic!("{v:?}") };
        assert!(matches!(&b.f.value(v).def, Def::Expr(Expr::Binary(BinOp::Add, _, _))));
        // What two products share comes out: x·y − y·z·3 = y·(x − 3·z); 2·x + 3·x = 5·x.
        let z = b.input("z");
        let (xy, yz3) = (mul(x.clone(), y.clone()), mul(mul(y.clone(), z.clone()), Term::C(3.0)));
        assert_eq!(sub(xy, yz3), mul(y.clone(), sub(x.clone(), mul(Term::C(3.0), z.clone()))));
        assert_eq!(add(mul(Term::C(2.0), x.clone()), mul(x.clone(), Term::C(3.0))), mul(Term::C(5.0), x.clone()));
        // A common number: 2·x + 2·z = 2·(x + z).
        assert_eq!(
            add(mul(Term::C(2.0), x.clone()), mul(Term::C(2.0), z.clone())),
            mul(Term::C(2.0), Term::Add(bx(), Box::new(z)))
        );
    }
}
