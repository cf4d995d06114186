//! Operation counts of parsed expressions, following SPEC §3 without atomising.
//!
//! This is the reference the `atomise` pass is tested against: it walks the expression tree and
//! counts what the convention says the atomised form holds.

use crate::function::OpCounts;
use crate::syntax::{BinOp, Expr, OpKind, Operand};

/// True when a unary minus on `e` folds into a literal (SPEC §3): `e` is a literal, or a
/// product/quotient chain whose first factor is a literal.
pub fn neg_folds(e: &Expr) -> bool {
    match e {
        Expr::Operand(Operand::Const(_)) => true,
        Expr::Binary(BinOp::Mul | BinOp::Div, a, _) => neg_folds(a),
        _ => false,
    }
}

/// Adds to `c` the ops that expression `e` atomises into.
pub fn count_expr(e: &Expr, c: &mut OpCounts) {
    match e {
        Expr::Operand(_) => {}
        Expr::Neg(x) => {
            count_expr(x, c);
            if !neg_folds(x) {
                c.bump(OpKind::Sub);
            }
        }
        Expr::Binary(op, a, b) => {
            count_expr(a, c);
            count_expr(b, c);
            c.bump(op.kind());
        }
        Expr::Call(_, args) => {
            args.iter().for_each(|a| count_expr(a, c));
            c.bump(OpKind::Call);
        }
    }
}
