//! Operation counts: [`OpCounts`] (SPEC §7 `stats.ops`), and the counts of parsed expressions,
//! following SPEC §3 without atomising ([`count_expr`]).
//!
//! [`count_expr`] is the reference the `atomise` pass is tested against: it walks the expression
//! tree and counts what the convention says the atomised form holds.

use crate::syntax::{BinOp, Expr, OpKind, Operand};

/// Counts of operations by kind (SPEC §7 `stats.ops`), units: ops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct OpCounts {
    /// `add` ops.
    pub add: u64,
    /// `sub` ops.
    pub sub: u64,
    /// `mul` ops.
    pub mul: u64,
    /// `div` ops.
    pub div: u64,
    /// `call` ops.
    pub call: u64,
    /// Sum of the above.
    pub total: u64,
}

impl OpCounts {
    /// Counts one op of `kind`.
    pub fn bump(&mut self, kind: OpKind) {
        match kind {
            OpKind::Add => self.add += 1,
            OpKind::Sub => self.sub += 1,
            OpKind::Mul => self.mul += 1,
            OpKind::Div => self.div += 1,
            OpKind::Call => self.call += 1,
        }
        self.total += 1;
    }
}

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
