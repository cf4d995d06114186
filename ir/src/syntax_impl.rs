//! The methods of the declarations in [`crate::syntax`], which holds data only: the op kind of
//! a definition or operator, the walks over the values a definition or expression reads, and
//! the text of an operator.

use crate::entities::Value;
use crate::syntax::{BinOp, Callee, Def, Expr, OpKind, Operand};

impl Def {
    /// The operation kind of this definition (`None` for inputs, trig and expressions).
    pub fn op_kind(&self) -> Option<OpKind> {
        match self {
            Def::Binary(op, _, _) => Some(op.kind()),
            Def::Call(..) => Some(OpKind::Call),
            Def::Input | Def::Trig(..) | Def::Expr(_) => None,
        }
    }

    /// The operands this definition reads, in order (the angle of a trig variable as a value;
    /// none for an input or a nested expression).
    pub fn operands(&self) -> Vec<Operand> {
        match self {
            Def::Trig(_, a) => vec![Operand::Value(*a)],
            Def::Binary(_, a, b) => vec![*a, *b],
            Def::Call(_, args) => args.clone(),
            Def::Input | Def::Expr(_) => Vec::new(),
        }
    }

    /// Calls `f` on every value this definition reads, in operand order.
    pub fn for_each_value(&self, mut f: impl FnMut(Value)) {
        match self {
            Def::Input => {}
            Def::Trig(_, v) => f(*v),
            Def::Binary(_, a, b) => {
                for o in [a, b] {
                    if let Operand::Value(v) = o {
                        f(*v)
                    }
                }
            }
            Def::Call(_, args) => args.iter().for_each(|o| {
                if let Operand::Value(v) = o {
                    f(*v)
                }
            }),
            Def::Expr(e) => e.for_each_value(&mut f),
        }
    }

    /// Rewrites every value this definition reads through `m`.
    pub fn map_values(&mut self, m: &impl Fn(Value) -> Value) {
        let op = |o: &mut Operand| {
            if let Operand::Value(v) = o {
                *v = m(*v)
            }
        };
        match self {
            Def::Input => {}
            Def::Trig(_, v) => *v = m(*v),
            Def::Binary(_, a, b) => {
                op(a);
                op(b)
            }
            Def::Call(_, args) => args.iter_mut().for_each(op),
            Def::Expr(e) => e.map_values(m),
        }
    }
}

impl Expr {
    /// The call of `callee` on `args` ([`Expr::Call`] boxes both).
    pub fn call(callee: Callee, args: Vec<Expr>) -> Expr {
        Expr::Call(Box::new(callee), Box::new(args))
    }

    /// Calls `f` on every value the expression reads, left to right.
    pub fn for_each_value(&self, f: &mut impl FnMut(Value)) {
        match self {
            Expr::Operand(Operand::Value(v)) => f(*v),
            Expr::Operand(Operand::Const(_)) => {}
            Expr::Neg(e) => e.for_each_value(f),
            Expr::Binary(_, a, b) => {
                a.for_each_value(f);
                b.for_each_value(f)
            }
            Expr::Call(_, args) => args.iter().for_each(|a| a.for_each_value(f)),
        }
    }

    /// Rewrites every value the expression reads through `m`.
    pub fn map_values(&mut self, m: &impl Fn(Value) -> Value) {
        match self {
            Expr::Operand(Operand::Value(v)) => *v = m(*v),
            Expr::Operand(Operand::Const(_)) => {}
            Expr::Neg(e) => e.map_values(m),
            Expr::Binary(_, a, b) => {
                a.map_values(m);
                b.map_values(m)
            }
            Expr::Call(_, args) => args.iter_mut().for_each(|a| a.map_values(m)),
        }
    }
}

impl BinOp {
    /// The op kind counted for this operator.
    pub fn kind(self) -> OpKind {
        use BinOp::*;
        match self {
            Add => OpKind::Add,
            Sub => OpKind::Sub,
            Mul => OpKind::Mul,
            Div => OpKind::Div,
        }
    }

    /// The text mnemonic (`add`, `sub`, `mul`, `div`).
    pub fn mnemonic(self) -> &'static str {
        use BinOp::*;
        match self {
            Add => "add",
            Sub => "sub",
            Mul => "mul",
            Div => "div",
        }
    }

    /// The infix symbol (`+ - * /`).
    pub fn symbol(self) -> char {
        use BinOp::*;
        match self {
            Add => '+',
            Sub => '-',
            Mul => '*',
            Div => '/',
        }
    }
}
