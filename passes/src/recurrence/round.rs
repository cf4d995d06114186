//! One round of [`super::Recurrence`]: the critical values of a balanced function written as
//! linear forms ([`super::forms`]), each value made from its op or its form, whichever is ready
//! first, in a new function built on demand from the outputs.

use robovec_ir::{BinOp, Def, Function, Operand, Timing, Value};

use super::forms::{Builder, Form, Signed};
use super::Recurrence;
use crate::Ticker;

/// How a critical value is made when something needs it as a value.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Make {
    /// Its own op on its operands' values.
    Op,
    /// Its form.
    Form,
}

/// One restructuring of `f` (balanced, `timing` its timing): the values with at most `slack`
/// cycles of slack that are ready at `from` or later.
pub(super) fn round(
    f: &Function,
    timing: &[Option<Timing>],
    (slack, from): (u32, u32),
    opts: &Recurrence,
    ticker: &Ticker,
) -> Option<Function> {
    let lat = opts.lat;
    let n = f.values.len();
    let critical = |v: Value| -> bool {
        matches!(f.value(v).def, Def::Binary(BinOp::Add | BinOp::Sub | BinOp::Mul, _, _))
            && timing[v.index()].is_some_and(|t| t.alap_cycle - t.asap_cycle <= slack && t.asap_cycle >= from)
    };
    let mut b = Builder::new(&f.name, lat);
    b.out.equations = f.equations;
    b.out.states = f.states;
    b.out.span = f.span;
    let mut r = Round {
        f,
        b,
        made: vec![None; n],
        forms: vec![None; n],
        make: vec![Make::Op; n],
        est: vec![0; n],
        max_terms: opts.max_terms as usize,
    };
    for &v in &f.inputs {
        let d = f.value(v);
        let x = r.b.input(&d.name, d.span);
        r.made[v.index()] = Some(Signed::plus(Operand::Value(x)));
    }
    for &v in &f.body {
        if ticker.tick() {
            return None;
        }
        if critical(v) {
            r.restructure(v);
        } else {
            let s = r.value_of(v);
            r.est[v.index()] = r.b.t(s.op);
        }
    }
    let mut outs = Vec::with_capacity(f.outputs.len());
    for o in &f.outputs {
        let op = match o.value {
            Operand::Value(v) => {
                let s = r.value_of(v);
                r.b.plain(s, &o.name, o.span)
            }
            c => c,
        };
        outs.push((o.name.clone(), op, o.span));
    }
    let mut out = r.b.out;
    for (name, op, span) in outs {
        out.set_output(name, op, span);
    }
    let live = out.live_values(&[]);
    out.retain(|g, v| live[v.index()] || matches!(g.value(v).def, Def::Input));
    Some(out)
}

struct Round<'a> {
    f: &'a Function,
    b: Builder,
    /// The value of each original value in the new function, once made.
    made: Vec<Option<Signed>>,
    /// The form of each critical value.
    forms: Vec<Option<Form>>,
    make: Vec<Make>,
    /// Ready time of each original value as it will be made (cycles).
    est: Vec<u32>,
    max_terms: usize,
}

impl Round<'_> {
    fn est_of(&self, o: Operand) -> u32 {
        match o {
            Operand::Value(v) => self.est[v.index()],
            Operand::Const(_) => 0,
        }
    }

    fn form_of(&mut self, o: Operand) -> Form {
        match o {
            Operand::Value(v) => match &self.forms[v.index()] {
                Some(fm) => fm.clone(),
                None => Form::scalar(self.value_of(v)),
            },
            c => Form::scalar(Signed::plus(c)),
        }
    }

    fn operand(&mut self, o: Operand) -> Signed {
        match o {
            Operand::Value(v) => self.value_of(v),
            c => Signed::plus(c),
        }
    }

    /// Writes the critical value `v`'s form and chooses how `v` is made.
    fn restructure(&mut self, v: Value) {
        let d = self.f.value(v);
        let Def::Binary(op, a, c) = d.def else { unreachable!("critical values are add, sub, mul") };
        let (name, span) = (d.name.as_str(), d.span);
        let form = match op {
            BinOp::Add | BinOp::Sub => {
                let (fa, fc) = (self.form_of(a), self.form_of(c));
                self.b.add_forms(fa, &fc, op == BinOp::Sub, name, span)
            }
            _ => {
                // Scale the later operand's form by the earlier operand's value.
                let (early, late) = if self.est_of(a) <= self.est_of(c) { (a, c) } else { (c, a) };
                let s = self.operand(early);
                let fl = self.form_of(late);
                self.b.scale(&fl, s, name, span)
            }
        };
        let form = self.b.tidy(form, self.max_terms, name, span);
        let by_form = self.b.form_time(&form);
        let by_op = self.est_of(a).max(self.est_of(c)) + self.b.lat.of(op.kind());
        let i = v.index();
        (self.make[i], self.est[i]) = if by_form < by_op { (Make::Form, by_form) } else { (Make::Op, by_op) };
        // A plain sum of values that its form does not make earlier is a pivot itself: its
        // consumers would only have more terms to scale.
        let plain = form.terms.iter().all(|t| t.coef == Operand::Const(1.0));
        self.forms[i] = if plain && form.terms.len() > 1 && by_form >= by_op { None } else { Some(form) };
    }

    /// The value of original value `v` in the new function, made on first use (iteratively:
    /// chains of critical values made by their ops are as long as the function).
    fn value_of(&mut self, v: Value) -> Signed {
        let mut stack = vec![v];
        while let Some(&x) = stack.last() {
            if self.made[x.index()].is_some() {
                stack.pop();
                continue;
            }
            let d = self.f.value(x);
            if self.forms[x.index()].is_some() && self.make[x.index()] == Make::Form {
                let fm = self.forms[x.index()].take().expect("checked");
                let s = self.b.materialise(&fm, &d.name, d.span);
                self.forms[x.index()] = Some(fm);
                self.made[x.index()] = Some(s);
                stack.pop();
                continue;
            }
            let mut pending = false;
            d.def.for_each_value(|a| {
                if self.made[a.index()].is_none() {
                    stack.push(a);
                    pending = true;
                }
            });
            if !pending {
                let s = self.op_of(x);
                self.made[x.index()] = Some(s);
            }
        }
        self.made[v.index()].expect("made above")
    }

    /// `v`'s own op on its operands' values (which are made).
    fn op_of(&mut self, v: Value) -> Signed {
        let d = self.f.value(v);
        let (name, span) = (d.name.as_str(), d.span);
        match &d.def {
            Def::Binary(op, a, c) => {
                let (x, y) = (self.operand_made(*a), self.operand_made(*c));
                match op {
                    BinOp::Add => self.b.add(x, y, name, span),
                    BinOp::Sub => self.b.add(x, y.negated(), name, span),
                    BinOp::Mul => self.b.mul(x, y, name, span),
                    BinOp::Div => Signed { neg: x.neg ^ y.neg, op: self.b.bin(BinOp::Div, x.op, y.op, name, span) },
                }
            }
            Def::Trig(t, a) => {
                let Some(Signed { op: Operand::Value(x), neg: false }) = self.made[a.index()] else {
                    unreachable!("trig reads an input")
                };
                let ready = 0;
                Signed::plus(Operand::Value(self.b.define(name, Def::Trig(*t, x), span, ready)))
            }
            Def::Call(c, args) => {
                let mut ops = Vec::with_capacity(args.len());
                for &o in args {
                    let s = self.operand_made(o);
                    ops.push(self.b.plain(s, name, span));
                }
                let ready = ops.iter().map(|&o| self.b.t(o)).max().unwrap_or(0) + self.b.lat.call;
                Signed::plus(Operand::Value(self.b.define(name, Def::Call(c.clone(), ops), span, ready)))
            }
            Def::Input | Def::Expr(_) => unreachable!("atomised bodies hold ops and trig variables"),
        }
    }

    fn operand_made(&self, o: Operand) -> Signed {
        match o {
            Operand::Value(x) => self.made[x.index()].expect("operands are made first"),
            c => Signed::plus(c),
        }
    }
}
