//! A function flattened into a straight-line tape of single operations, in exactly the order
//! the interpreter ([`crate::interp`]) evaluates it: every phase (a parsed expression is
//! flattened left operand first, a unary minus is a `neg` step), only what the outputs need.
//!
//! Evaluating the tape in a [`Float`] gives bit for bit the outputs of
//! [`crate::interp::eval`] in that precision (checked on the corpus by the integration tests),
//! without allocating per evaluation or looking inputs up by name: it is what the accuracy
//! measurement runs thousands of times.

use crate::function::Function;
use crate::interp::{eval_call, Float};
use crate::intrinsic::Intrinsic;
use crate::syntax::{BinOp, Callee, Def, Expr, Operand, TrigFn};

/// One step of a tape; operands are slot numbers (inputs, then constants, then steps).
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// `a op b`, rounded once.
    Bin(BinOp, u32, u32),
    /// IEEE negation (exact), from a parsed expression's unary minus.
    Neg(u32),
    /// A trig initial variable.
    Trig(TrigFn, u32),
    /// A call: callee index into [`Tape::callees`], arguments `args[start..start + len]`.
    Call(u32, u32, u32),
}

/// A flattened function (see the module doc).
#[derive(Clone, Debug)]
pub struct Tape {
    /// Input names, in the function's input order (slots `0..inputs.len()`).
    pub inputs: Vec<String>,
    /// Constants (slots after the inputs), as written in the IR.
    pub consts: Vec<f64>,
    /// Steps; step `i` writes slot `inputs.len() + consts.len() + i`.
    pub steps: Vec<Step>,
    /// Callees of `Step::Call`.
    pub callees: Vec<Callee>,
    /// Argument slots of calls.
    pub args: Vec<u32>,
    /// Outputs: name and slot, in output order.
    pub outputs: Vec<(String, u32)>,
}

struct Builder<'a> {
    f: &'a Function,
    tape: Tape,
    slot_of: Vec<Option<u32>>,
    const_slot: std::collections::HashMap<u64, u32>,
}

impl Builder<'_> {
    fn first_step(&self) -> u32 {
        (self.tape.inputs.len() + self.tape.consts.len()) as u32
    }

    fn constant(&mut self, c: f64) -> u32 {
        if let Some(&s) = self.const_slot.get(&c.to_bits()) {
            return s;
        }
        let s = self.tape.consts.len() as u32;
        self.tape.consts.push(c);
        self.const_slot.insert(c.to_bits(), s);
        s
    }

    fn operand(&mut self, o: &Operand) -> Operand2 {
        match o {
            Operand::Value(v) => Operand2::Slot(self.slot_of[v.index()].expect("operand defined before use")),
            Operand::Const(c) => Operand2::Const(self.constant(*c)),
        }
    }

    fn push(&mut self, s: Step) -> Operand2 {
        self.tape.steps.push(s);
        Operand2::Step(self.tape.steps.len() as u32 - 1)
    }

    fn expr(&mut self, e: &Expr) -> Operand2 {
        match e {
            Expr::Operand(o) => self.operand(o),
            Expr::Neg(x) => {
                let a = self.expr(x);
                self.push(Step::Neg(a.raw()))
            }
            Expr::Binary(op, a, b) => {
                let a = self.expr(a);
                let b = self.expr(b);
                self.push(Step::Bin(*op, a.raw(), b.raw()))
            }
            Expr::Call(c, xs) => {
                let a: Vec<Operand2> = xs.iter().map(|x| self.expr(x)).collect();
                self.call(c, a)
            }
        }
    }

    fn call(&mut self, c: &Callee, a: Vec<Operand2>) -> Operand2 {
        let start = self.tape.args.len() as u32;
        self.tape.args.extend(a.iter().map(|x| x.raw()));
        self.tape.callees.push(c.clone());
        self.push(Step::Call(self.tape.callees.len() as u32 - 1, start, a.len() as u32))
    }
}

/// Slot references while building: constants and steps are renumbered at the end, when the
/// number of constants is known. Encoded in one `u32` by [`Operand2::raw`].
#[derive(Clone, Copy)]
enum Operand2 {
    Slot(u32),
    Const(u32),
    Step(u32),
}

const CONST_TAG: u32 = 1 << 30;
const STEP_TAG: u32 = 2 << 30;

impl Operand2 {
    fn raw(self) -> u32 {
        match self {
            Operand2::Slot(s) => s,
            Operand2::Const(c) => CONST_TAG | c,
            Operand2::Step(s) => STEP_TAG | s,
        }
    }
}

impl Tape {
    /// Flattens `f` (which must verify). Values no output needs are left out.
    ///
    /// # Panics
    /// If `f` does not verify (a value read before its definition) or has 2³⁰ slots or more.
    pub fn new(f: &Function) -> Tape {
        let live = f.live_values(&[]);
        let tape = Tape {
            inputs: f.inputs.iter().map(|&v| f.name_of(v).to_string()).collect(),
            consts: Vec::new(),
            steps: Vec::new(),
            callees: Vec::new(),
            args: Vec::new(),
            outputs: Vec::new(),
        };
        let mut b = Builder { f, tape, slot_of: vec![None; f.values.len()], const_slot: Default::default() };
        for (i, &v) in f.inputs.iter().enumerate() {
            b.slot_of[v.index()] = Some(i as u32);
        }
        for &v in &b.f.body {
            if !live[v.index()] {
                continue;
            }
            let r = match &b.f.value(v).def {
                Def::Input => unreachable!("inputs are not in the body"),
                Def::Trig(t, a) => {
                    let a = b.operand(&Operand::Value(*a));
                    b.push(Step::Trig(*t, a.raw()))
                }
                Def::Binary(op, x, y) => {
                    let (x, y) = (b.operand(x), b.operand(y));
                    b.push(Step::Bin(*op, x.raw(), y.raw()))
                }
                Def::Call(c, xs) => {
                    let a: Vec<Operand2> = xs.iter().map(|x| b.operand(x)).collect();
                    b.call(c, a)
                }
                Def::Expr(e) => b.expr(e),
            };
            b.slot_of[v.index()] = Some(r.raw());
        }
        for o in &b.f.outputs {
            let s = b.operand(&o.value).raw();
            b.tape.outputs.push((o.name.clone(), s));
        }
        // Resolve tagged references now that the number of constants is known.
        let n_in = b.tape.inputs.len() as u32;
        let first = b.first_step();
        let fix = |x: &mut u32| {
            *x = match *x & (3 << 30) {
                0 => *x,
                CONST_TAG => n_in + (*x & !CONST_TAG),
                _ => first + (*x & !STEP_TAG),
            }
        };
        let mut tape = b.tape;
        for s in &mut tape.steps {
            match s {
                Step::Bin(_, a, c) => {
                    fix(a);
                    fix(c)
                }
                Step::Neg(a) | Step::Trig(_, a) => fix(a),
                Step::Call(..) => {}
            }
        }
        tape.args.iter_mut().for_each(fix);
        tape.outputs.iter_mut().for_each(|(_, s)| fix(s));
        tape
    }

    /// Number of slots an evaluation fills.
    pub fn slots(&self) -> usize {
        self.inputs.len() + self.consts.len() + self.steps.len()
    }

    /// Evaluates in precision `T`: `inputs[i]` is the value of input `self.inputs[i]` (in
    /// `f64`, converted by `T::from_f64` as the interpreter does). `slots` is scratch space
    /// (reused across calls: no allocation once it is large enough); the outputs are
    /// `slots[s]` for each `(_, s)` of [`Tape::outputs`].
    pub fn eval_into<T: Float>(&self, inputs: &[f64], slots: &mut Vec<T>, scratch: &mut Vec<T>) {
        assert_eq!(inputs.len(), self.inputs.len(), "one value per input");
        slots.clear();
        slots.extend(inputs.iter().map(|&x| T::from_f64(x)));
        slots.extend(self.consts.iter().map(|&x| T::from_f64(x)));
        for s in &self.steps {
            let r = match *s {
                Step::Bin(op, a, b) => {
                    // What `interp::eval_binop` does, inlined: this loop is the hot path.
                    let (a, b) = (slots[a as usize], slots[b as usize]);
                    match op {
                        BinOp::Add => a + b,
                        BinOp::Sub => a - b,
                        BinOp::Mul => a * b,
                        BinOp::Div => a / b,
                    }
                }
                Step::Neg(a) => -slots[a as usize],
                Step::Trig(TrigFn::Sin, a) => slots[a as usize].sin(),
                Step::Trig(TrigFn::Cos, a) => slots[a as usize].cos(),
                Step::Call(c, start, len) => {
                    scratch.clear();
                    let args = &self.args[start as usize..(start + len) as usize];
                    scratch.extend(args.iter().map(|&x| slots[x as usize]));
                    eval_call(&self.callees[c as usize], scratch)
                }
            };
            slots.push(r);
        }
    }

    /// The steps the outputs `outputs` (indices into [`Tape::outputs`]) depend on: `mask[i]` for
    /// step `i`.
    pub fn cone(&self, outputs: &[usize]) -> Vec<bool> {
        let first = self.inputs.len() + self.consts.len();
        let mut mask = vec![false; self.steps.len()];
        let mark = |slot: u32, mask: &mut Vec<bool>| {
            if let Some(i) = (slot as usize).checked_sub(first) {
                mask[i] = true;
            }
        };
        for &k in outputs {
            mark(self.outputs[k].1, &mut mask);
        }
        for i in (0..self.steps.len()).rev() {
            if !mask[i] {
                continue;
            }
            match self.steps[i] {
                Step::Bin(_, a, b) => {
                    mark(a, &mut mask);
                    mark(b, &mut mask)
                }
                Step::Neg(a) | Step::Trig(_, a) => mark(a, &mut mask),
                Step::Call(_, start, len) => {
                    for &a in &self.args[start as usize..(start + len) as usize] {
                        mark(a, &mut mask)
                    }
                }
            }
        }
        mask
    }

    /// The user callbacks the outputs depend on (every callee but the intrinsics, see
    /// [`crate::intrinsic::Intrinsic`]): robovec cannot see them and evaluates them with the interpreter's
    /// stand-in ([`crate::interp::callback_standin`]). Distinct names (`name` or `name[elem]`),
    /// sorted.
    pub fn standin_callees(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .steps
            .iter()
            .filter_map(|s| match *s {
                Step::Call(c, _, len) if Intrinsic::of(&self.callees[c as usize], len as usize).is_none() => {
                    let c = &self.callees[c as usize];
                    Some(match c.elem {
                        Some(e) => format!("{}[{e}]", c.name),
                        None => c.name.clone(),
                    })
                }
                _ => None,
            })
            .collect();
        out.sort();
        out.dedup();
        out
    }

    /// Outputs in precision `T`, in output order (allocates; see [`Tape::eval_into`]).
    pub fn eval<T: Float>(&self, inputs: &[f64]) -> Vec<T> {
        let (mut slots, mut scratch) = (Vec::new(), Vec::new());
        self.eval_into(inputs, &mut slots, &mut scratch);
        self.outputs.iter().map(|&(_, s)| slots[s as usize]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text;

    const SRC: &str = "func @f {\n  phase parsed\n  input %a\n  input %b\n  %S = sin %a\n  \
                       %x = -%a*%b + (%S - 2.0)\n  %dead = %a*%a\n  %y = @sqrt(%x*%x)\n  \
                       %z = @user_F.1[2](%a, %y)\n  output Qq[1] = %y\n  output Qq[2] = %z\n  output c = 2.0\n}\n";

    #[test]
    fn tape_reproduces_the_interpreter_and_skips_dead_values() {
        let m = text::parse(SRC).unwrap();
        let f = &m.functions[0];
        let t = Tape::new(f);
        // dead value %a*%a is not on the tape: sin, mul, neg, sub, add, mul, sqrt, call.
        assert_eq!(t.steps.len(), 8);
        for (a, b) in [(0.3, -1.7), (2.0, 0.125), (-0.0, 5.0)] {
            let get = |n: &str| if n == "a" { a } else { b };
            let i64: Vec<f64> = crate::interp::eval::<f64>(f, get).into_iter().map(|x| x.1).collect();
            let i32: Vec<f32> = crate::interp::eval::<f32>(f, get).into_iter().map(|x| x.1).collect();
            let t64 = t.eval::<f64>(&[a, b]);
            let t32 = t.eval::<f32>(&[a, b]);
            assert_eq!(
                i64.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                t64.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
            assert_eq!(
                i32.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                t32.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
            );
        }
        assert_eq!(t.outputs.iter().map(|o| o.0.as_str()).collect::<Vec<_>>(), ["Qq[1]", "Qq[2]", "c"]);
        assert_eq!(t.standin_callees(), ["user_F.1[2]"], "sqrt is not a stand-in");
    }
}
