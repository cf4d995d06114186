//! [`Module`] → `.rvir` text. Deterministic; `parse(print(m)) == m` (spans aside).

use std::fmt::{self, Write};

use crate::function::{Function, Module};
use crate::syntax::{BinOp, Callee, Def, Expr, Operand, Phase, TrigFn};

/// Prints a constant so that it reads back to the same bits (Rust's shortest round-trip form).
pub fn write_const(out: &mut impl Write, x: f64) -> fmt::Result {
    write!(out, "{x:?}")
}

fn write_operand(out: &mut impl Write, f: &Function, o: &Operand) -> fmt::Result {
    match o {
        Operand::Value(v) => write!(out, "%{}", f.name_of(*v)),
        Operand::Const(x) => write_const(out, *x),
    }
}

fn write_callee(out: &mut impl Write, c: &Callee) -> fmt::Result {
    write!(out, "@{}", c.name)?;
    if let Some(e) = c.elem {
        write!(out, "[{e}]")?;
    }
    Ok(())
}

// Expression printing mirrors the grammar (sum → product → factor) so that the tree reads back
// unchanged: a negation or sum in factor position is parenthesised.
fn write_sum(out: &mut impl Write, f: &Function, e: &Expr) -> fmt::Result {
    match e {
        Expr::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) => {
            write_sum(out, f, a)?;
            write!(out, " {} ", op.symbol())?;
            write_product(out, f, b)
        }
        Expr::Neg(x) => {
            out.write_char('-')?;
            write_product(out, f, x)
        }
        _ => write_product(out, f, e),
    }
}

fn write_product(out: &mut impl Write, f: &Function, e: &Expr) -> fmt::Result {
    match e {
        Expr::Binary(op @ (BinOp::Mul | BinOp::Div), a, b) => {
            write_product(out, f, a)?;
            write!(out, "{}", op.symbol())?;
            write_factor(out, f, b)
        }
        _ => write_factor(out, f, e),
    }
}

fn write_factor(out: &mut impl Write, f: &Function, e: &Expr) -> fmt::Result {
    match e {
        Expr::Operand(o) => write_operand(out, f, o),
        Expr::Call(c, args) => {
            write_callee(out, c)?;
            out.write_char('(')?;
            for (i, a) in args.iter().enumerate() {
                if i > 0 {
                    out.write_str(", ")?;
                }
                write_sum(out, f, a)?;
            }
            out.write_char(')')
        }
        _ => {
            out.write_char('(')?;
            write_sum(out, f, e)?;
            out.write_char(')')
        }
    }
}

/// Writes an infix expression of `f`.
pub fn write_expr(out: &mut impl Write, f: &Function, e: &Expr) -> fmt::Result {
    write_sum(out, f, e)
}

/// Writes one function.
pub fn write_function(out: &mut impl Write, f: &Function) -> fmt::Result {
    writeln!(out, "func @{} {{", f.name)?;
    let phase = match f.phase {
        Phase::Parsed => "parsed",
        Phase::Atomised => "atomised",
    };
    writeln!(out, "  phase {phase}")?;
    if let Some(n) = f.equations {
        writeln!(out, "  equations {n}")?;
    }
    for &v in &f.inputs {
        writeln!(out, "  input %{}", f.name_of(v))?;
    }
    for &v in &f.body {
        let d = f.value(v);
        write!(out, "  %{} = ", d.name)?;
        match &d.def {
            Def::Input => unreachable!("inputs are not in the body"),
            Def::Trig(t, a) => {
                let t = match t {
                    TrigFn::Sin => "sin",
                    TrigFn::Cos => "cos",
                };
                write!(out, "{t} %{}", f.name_of(*a))?;
            }
            Def::Binary(op, a, b) => {
                write!(out, "{} ", op.mnemonic())?;
                write_operand(out, f, a)?;
                out.write_str(", ")?;
                write_operand(out, f, b)?;
            }
            Def::Call(c, args) => {
                out.write_str("call ")?;
                write_callee(out, c)?;
                out.write_char('(')?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        out.write_str(", ")?;
                    }
                    write_operand(out, f, a)?;
                }
                out.write_char(')')?;
            }
            Def::Expr(e) => write_expr(out, f, e)?,
        }
        if let Some(t) = &d.timing {
            write!(
                out,
                " {{asap={}, alap={}, asap_cycle={}, alap_cycle={}, mobility={}}}",
                t.asap, t.alap, t.asap_cycle, t.alap_cycle, t.mobility
            )?;
        }
        out.write_char('\n')?;
    }
    for o in &f.outputs {
        write!(out, "  output {} = ", o.name)?;
        write_operand(out, f, &o.value)?;
        out.write_char('\n')?;
    }
    if let Some(p) = &f.placement {
        super::placement::write(out, f, p)?;
    }
    writeln!(out, "}}")
}

impl fmt::Display for Function {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_function(f, self)
    }
}

impl fmt::Display for Module {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, func) in self.functions.iter().enumerate() {
            if i > 0 {
                f.write_char('\n')?;
            }
            write_function(f, func)?;
        }
        Ok(())
    }
}
