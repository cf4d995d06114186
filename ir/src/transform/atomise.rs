//! The phase transition parsed → atomised (SPEC §3; seed §2.1, eq. 2.2): equations →
//! binary operations. The `atomise` pass of `robovec-passes` runs it on a module; the front ends'
//! contract (`robovec_front::verify_accepted`) and the generator's op counts call it directly.
//!
//! Phase: parsed → atomised. Every nested expression becomes a sequence of single operations:
//! - sums and products cascade left to right in source order, as the tree is written:
//!   `a+b-c` → `(a+b)-c`, `a*b*c` → `(a*b)*c`;
//! - a unary minus becomes `0 - t` **after** its term `t` is computed (`-g3*S4` →
//!   `t = g3*S4; r = 0 - t`), except on a literal or on a product whose first factor is a
//!   literal, where the literal is negated instead (`-(2.0)*x*y` → `((-2.0)*x)*y`,
//!   `-(1.0)` → the constant −1.0);
//! - a plain copy (`M[1][1] = FM41_15;`) or a lone constant is 0 ops: uses are rewritten to the
//!   copied operand and the value disappears;
//! - calls stay calls, on atomised arguments.
//!
//! The root operation of an equation keeps the equation's name; intermediate operations are
//! named `NAME.1`, `NAME.2`, … in emission order (left operand first). Already-atomic
//! definitions are copied. Numerics: identical to the parsed form in every precision except the
//! sign of a zero produced by `0 - t` where C computes `-t` (see [`crate::interp`]).
//!
//! Contract: idempotent (an atomised function is copied unchanged); never changes an output's
//! value; the op counts equal [`crate::count::count_expr`] of the source expressions.
//! Cost: O(expression nodes).

use std::borrow::Cow;

use crate::count::{count_expr, neg_folds, OpCounts};
use crate::time_limit::Ticker;
use crate::{BinOp, Def, Expr, Function, Operand, Phase, Span, Value, ValueData};

/// Returns the atomised form of `f` (which must verify).
pub fn atomise_function(f: &Function) -> Function {
    atomise_within(Cow::Borrowed(f), &Ticker::default()).expect("a ticker without a limit never stops")
}

/// [`atomise_function`] consuming `f`: each equation's expression is dropped as soon as it is
/// atomised and names move instead of being copied, so the parsed and the atomised function
/// are never both whole in memory (issue 10 §3). Same result as [`atomise_function`].
pub fn atomise_owned(f: Function) -> Function {
    atomise_within(Cow::Owned(f), &Ticker::default()).expect("a ticker without a limit never stops")
}

/// [`atomise_function`] that stops when `ticker` says so (one tick per equation; `None`
/// then): the URDF generator's op counts under `-time-limit` (issue 47).
pub fn atomise_until(f: &Function, ticker: &Ticker) -> Option<Function> {
    atomise_within(Cow::Borrowed(f), ticker)
}

/// The name, definition and span of `v`: borrowed, or taken out of an owned function.
fn take<'a>(src: &mut Cow<'a, Function>, v: Value) -> (Cow<'a, str>, Cow<'a, Def>, Span) {
    match src {
        Cow::Borrowed(f) => {
            let d: &'a ValueData = &f.values[v.index()];
            (Cow::Borrowed(d.name.as_str()), Cow::Borrowed(&d.def), d.span)
        }
        Cow::Owned(f) => {
            let d = &mut f.values[v.index()];
            (Cow::Owned(std::mem::take(&mut d.name)), Cow::Owned(std::mem::replace(&mut d.def, Def::Input)), d.span)
        }
    }
}

/// Atomises `src`; `None` when `ticker` (one tick per equation) says stop (`-time-limit`).
pub fn atomise_within(mut src: Cow<'_, Function>, ticker: &Ticker) -> Option<Function> {
    let mut out = Function::new(src.name.clone(), Phase::Atomised);
    out.equations = src.equations;
    out.states = src.states;
    out.span = src.span;
    let mut map: Vec<Operand> = vec![Operand::Const(f64::NAN); src.values.len()];
    // The atomised function's exact size (SPEC §3's count of each equation), reserved at once.
    let defs: usize = src
        .body
        .iter()
        .map(|&v| match &src.values[v.index()].def {
            Def::Expr(e) => {
                let mut c = OpCounts::default();
                count_expr(e, &mut c);
                c.total as usize
            }
            _ => 1,
        })
        .sum();
    out.reserve(src.inputs.len() + defs, defs);
    for i in 0..src.inputs.len() {
        let v = src.inputs[i];
        let (name, _, span) = take(&mut src, v);
        let nv = out.add_input(name.into_owned(), span).expect("input names are unique");
        map[v.index()] = Operand::Value(nv);
    }
    for i in 0..src.body.len() {
        if ticker.tick() {
            return None;
        }
        let v = src.body[i];
        let (name, def, span) = take(&mut src, v);
        let m = |o: &Operand| match o {
            Operand::Value(x) => map[x.index()],
            c => *c,
        };
        let result = match def.as_ref() {
            Def::Input => unreachable!("inputs are not in the body"),
            Def::Trig(t, a) => {
                let Operand::Value(a) = map[a.index()] else { unreachable!("inputs map to inputs") };
                Operand::Value(out.define(name.into_owned(), Def::Trig(*t, a), span).expect("unique name"))
            }
            Def::Binary(op, a, b) => {
                let def = Def::Binary(*op, m(a), m(b));
                Operand::Value(out.define(name.into_owned(), def, span).expect("unique name"))
            }
            Def::Call(c, args) => {
                let def = Def::Call(c.clone(), args.iter().map(m).collect());
                Operand::Value(out.define(name.into_owned(), def, span).expect("unique name"))
            }
            Def::Expr(e) => {
                let mut em = Emitter { out: &mut out, root: name.into_owned(), span, next: 1, map: &map };
                em.emit(e, true)
            }
        };
        // An owned expression is dropped here, before the next equation grows `out`.
        drop(def);
        map[v.index()] = result;
    }
    let outputs = match &mut src {
        Cow::Borrowed(f) => Cow::Borrowed(&f.outputs[..]),
        Cow::Owned(f) => Cow::Owned(std::mem::take(&mut f.outputs)),
    };
    drop(src);
    for o in outputs.iter() {
        let value = match o.value {
            Operand::Value(x) => map[x.index()],
            c => c,
        };
        out.set_output(o.name.clone(), value, o.span);
    }
    Some(out)
}

struct Emitter<'a> {
    out: &'a mut Function,
    /// The equation's name: the root operation's (taken by it, the last one defined).
    root: String,
    span: Span,
    next: u32,
    map: &'a [Operand],
}

impl Emitter<'_> {
    fn define(&mut self, top: bool, def: Def) -> Operand {
        let name = if top {
            // The root name is free (sources and passes keep names unique per function) unless
            // an inner name `root.k` of an earlier equation took it.
            let root = std::mem::take(&mut self.root);
            if self.out.lookup(&root).is_some() {
                self.out.fresh_name(&root)
            } else {
                root
            }
        } else {
            loop {
                let n = format!("{}.{}", self.root, self.next);
                self.next += 1;
                if self.out.lookup(&n).is_none() {
                    break n;
                }
            }
        };
        Operand::Value(self.out.define(name, def, self.span).expect("name is free"))
    }

    fn emit(&mut self, e: &Expr, top: bool) -> Operand {
        match e {
            Expr::Operand(Operand::Value(x)) => self.map[x.index()],
            Expr::Operand(c) => *c,
            Expr::Neg(x) if neg_folds(x) => self.emit(&negate_first_literal(x), top),
            Expr::Neg(x) => {
                let t = self.emit(x, false);
                self.define(top, Def::Binary(BinOp::Sub, Operand::Const(0.0), t))
            }
            Expr::Binary(op, a, b) => {
                let a = self.emit(a, false);
                let b = self.emit(b, false);
                self.define(top, Def::Binary(*op, a, b))
            }
            Expr::Call(c, args) => {
                let args = args.iter().map(|a| self.emit(a, false)).collect();
                self.define(top, Def::Call(c.clone(), args))
            }
        }
    }
}

/// `x` with the literal that a unary minus folds into negated (see [`neg_folds`]).
fn negate_first_literal(x: &Expr) -> Expr {
    match x {
        Expr::Operand(Operand::Const(c)) => Expr::Operand(Operand::Const(-c)),
        Expr::Binary(op @ (BinOp::Mul | BinOp::Div), a, b) => {
            Expr::Binary(*op, Box::new(negate_first_literal(a)), b.clone())
        }
        _ => unreachable!("called only when neg_folds holds"),
    }
}
