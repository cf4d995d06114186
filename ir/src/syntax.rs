//! Data declarations of the IR: no code here (rustc's `mir/syntax.rs` rule).
//!
//! Semantics are documented in the crate root; units are stated on each field.

use crate::entities::Value;
use crate::span::Span;

/// The phase of a function: which definition forms are allowed (checked by the verifier).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum Phase {
    /// Straight from a front end: a value may be defined by a nested expression (one equation).
    Parsed,
    /// After `atomise`: every value is one operation on inputs, constants or earlier values.
    Atomised,
}

/// A binary arithmetic operation (IEEE 754, round to nearest even, in the evaluation's precision).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BinOp {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
}

/// The kind of an operation, as counted in reports (SPEC §1 "operation", §7 `stats.ops`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum OpKind {
    /// `add`
    Add,
    /// `sub`
    Sub,
    /// `mul`
    Mul,
    /// `div`
    Div,
    /// `call` (`sqrt` and user callbacks)
    Call,
}

/// `sin` or `cos` of a joint coordinate: a trig initial variable (SPEC §1), not an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TrigFn {
    /// `sin`
    Sin,
    /// `cos`
    Cos,
}

/// An operand: an SSA value or a numeric constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operand {
    /// A value of the same function.
    Value(Value),
    /// A finite numeric constant (in a parsed expression: non-negative, see [`Expr::Operand`]).
    Const(f64),
}

/// The function a `call` invokes: `@sqrt`, or an opaque user callback such as
/// `@user_ExtForces.1[3]` (callee `user_ExtForces.1`, element 3 of the returned vector).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Callee {
    /// Callee name; integer literal arguments of the source call are appended as `.N`.
    pub name: String,
    /// 1-based element of a vector result (`SWr1[3]`), or `None` for a scalar result.
    pub elem: Option<u32>,
}

/// A nested expression: the right-hand side of one equation (parsed phase only).
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A leaf. Constants in expressions are non-negative; a minus is an explicit [`Expr::Neg`].
    Operand(Operand),
    /// Unary minus, as written in the source (SPEC §3 atomises it to `0 - x` or folds it).
    Neg(Box<Expr>),
    /// A binary operation.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// A call with its numeric arguments (both boxed: an expression node is 24 bytes, not 56 —
    /// the parsed form of a large file is mostly expression nodes; issue 10 §3).
    Call(Box<Callee>, Box<Vec<Expr>>),
}

/// How a value is defined.
#[derive(Clone, Debug, PartialEq)]
pub enum Def {
    /// A function input (joint coordinate, model parameter…): known before the equations run.
    Input,
    /// A trig initial variable: `sin`/`cos` of an input (SPEC §1); not an operation.
    Trig(TrigFn, Value),
    /// One binary operation (both phases).
    Binary(BinOp, Operand, Operand),
    /// One call on operands (both phases). The callee is boxed: a definition is 40 bytes, not
    /// 64 (calls are rare; every value holds a definition).
    Call(Box<Callee>, Vec<Operand>),
    /// A nested expression (parsed phase only).
    Expr(Expr),
}

/// Schedule attributes of one operation (seed §2.2, SPEC §4), written by `asap-alap`.
///
/// `asap`/`alap` are in unit steps, `asap_cycle`/`alap_cycle` in cycles (the op's result is
/// usable at `asap_cycle`), `mobility = alap - asap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Timing {
    /// ASAP level (unit weights; an op on inputs only has ASAP 1).
    pub asap: u32,
    /// ALAP level (unit weights).
    pub alap: u32,
    /// ASAPCycle: cycle in which the result is ready (latency weights).
    pub asap_cycle: u32,
    /// ALAPCycle: latest ready cycle that keeps the critical path.
    pub alap_cycle: u32,
    /// Mobility = ALAP − ASAP (unit steps).
    pub mobility: u32,
}

/// One value of a function: its name, definition and where it came from (72 bytes; its
/// schedule attributes are beside the values, [`crate::Function::timing`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ValueData {
    /// Name in the text form without `%` (`AlF15`, `q[4]`, `frc[2][11].1`); unique in its function.
    pub name: String,
    /// The definition.
    pub def: Def,
    /// Source span (Robotran or `.rvir` text), `Span::DUMMY` when a pass made it.
    pub span: Span,
}

/// One output of a function (`M[1][2]`, `Qq[4]`, `sens.P[1]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// Canonical output name (SPEC §2), unique in its function. When a source writes the same
    /// location twice (read-modify-write of `frc`), the output holds the last version.
    pub name: String,
    /// The value handed back.
    pub value: Operand,
    /// Source span.
    pub span: Span,
}
