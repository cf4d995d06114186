//! [`Module`] → `.rvir` text. Deterministic; `parse(print(m)) == m` (spans aside).

use std::fmt::{self, Write};

use super::write_const;
use crate::function::{Function, Module};
use crate::syntax::{BinOp, Callee, Def, Expr, Operand, Phase, TrigFn};

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

/// How the leaves of an infix expression are spelled: the `.rvir` text writes `%name`, `1.5`
/// and `@callee`; another printer of the same grammar (sum → product → factor, the grammar of
/// Robotran's C, Matlab and Python expressions too) spells them its own way and keeps the tree.
pub trait Leaves {
    /// Writes an operand (a value or a non-negative constant).
    fn operand<W: Write>(&self, out: &mut W, o: &Operand) -> fmt::Result;
    /// Writes a callee's name (what precedes the parenthesised arguments).
    fn callee<W: Write>(&self, out: &mut W, c: &Callee) -> fmt::Result;
    /// Whether `+` and `-` between terms are spaced (` + `, the `.rvir` text) or not (`+`,
    /// Robotran's C).
    fn spaced_sums(&self) -> bool {
        true
    }
}

/// The `.rvir` spelling of the leaves of a function's expressions.
struct IrLeaves<'a>(&'a Function);

impl Leaves for IrLeaves<'_> {
    fn operand<W: Write>(&self, out: &mut W, o: &Operand) -> fmt::Result {
        write_operand(out, self.0, o)
    }
    fn callee<W: Write>(&self, out: &mut W, c: &Callee) -> fmt::Result {
        write_callee(out, c)
    }
}

// Expression printing mirrors the grammar (sum → product → factor) so that the tree reads back
// unchanged: a negation or sum in factor position is parenthesised.
fn write_sum(out: &mut impl Write, l: &impl Leaves, e: &Expr) -> fmt::Result {
    match e {
        Expr::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) => {
            write_sum(out, l, a)?;
            if l.spaced_sums() {
                write!(out, " {} ", op.symbol())?;
            } else {
                out.write_char(op.symbol())?;
            }
            write_product(out, l, b)
        }
        Expr::Neg(x) => {
            out.write_char('-')?;
            write_product(out, l, x)
        }
        _ => write_product(out, l, e),
    }
}

fn write_product(out: &mut impl Write, l: &impl Leaves, e: &Expr) -> fmt::Result {
    match e {
        Expr::Binary(op @ (BinOp::Mul | BinOp::Div), a, b) => {
            write_product(out, l, a)?;
            write!(out, "{}", op.symbol())?;
            write_factor(out, l, b)
        }
        _ => write_factor(out, l, e),
    }
}

fn write_factor(out: &mut impl Write, l: &impl Leaves, e: &Expr) -> fmt::Result {
    match e {
        Expr::Operand(o) => l.operand(out, o),
        Expr::Call(c, args) => {
            l.callee(out, c)?;
            out.write_char('(')?;
            for (i, a) in args.iter().enumerate() {
                if i > 0 {
                    out.write_str(", ")?;
                }
                write_sum(out, l, a)?;
            }
            out.write_char(')')
        }
        _ => {
            out.write_char('(')?;
            write_sum(out, l, e)?;
            out.write_char(')')
        }
    }
}

/// Writes an infix expression of `f`.
pub fn write_expr(out: &mut impl Write, f: &Function, e: &Expr) -> fmt::Result {
    write_sum(out, &IrLeaves(f), e)
}

/// Writes an infix expression with the leaves spelled by `leaves`, with the parentheses the
/// `.rvir` text uses (only where the grammar needs them, so the text parses back to the same
/// tree; `*` and `/` unspaced, `+` and `-` as [`Leaves::spaced_sums`] says).
pub fn write_expr_with(out: &mut impl Write, leaves: &impl Leaves, e: &Expr) -> fmt::Result {
    write_sum(out, leaves, e)
}

/// ` : FORMAT` after a value's definition, when its format is not binary64.
fn write_format(out: &mut impl Write, f: &Function, v: crate::entities::Value) -> fmt::Result {
    let format = f.format(v);
    if format.is_default() {
        return Ok(());
    }
    write!(out, " : {format}")
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
    if f.states != 1 {
        writeln!(out, "  states {}", f.states)?;
    }
    for &v in &f.inputs {
        write!(out, "  input %{}", f.name_of(v))?;
        write_format(out, f, v)?;
        out.write_char('\n')?;
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
        write_format(out, f, v)?;
        if let Some(t) = &f.timing(v) {
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
