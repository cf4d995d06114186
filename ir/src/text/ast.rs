//! The parse tree of `.rvir` text: names unresolved, spans kept. [`super::parser`] resolves
//! names into a [`crate::Module`].

use crate::span::Span;
use crate::syntax::{BinOp, Callee, Phase, Timing, TrigFn};

/// One `func @name { … }`.
#[derive(Debug)]
pub struct FuncAst<'a> {
    /// Function name.
    pub name: &'a str,
    /// `phase …` line, default [`Phase::Parsed`].
    pub phase: Option<Phase>,
    /// `equations N` line.
    pub equations: Option<u32>,
    /// `states K` line (1 when absent).
    pub states: Option<u32>,
    /// Body lines in order.
    pub items: Vec<ItemAst<'a>>,
    /// The placement block, if any.
    pub placement: Option<PlacementAst<'a>>,
    /// The whole function.
    pub span: Span,
}

/// A `placement key=value… { words … buffers … lines }` block.
#[derive(Debug)]
pub struct PlacementAst<'a> {
    /// Architecture keys (`n_add`, `n_mul`, `lat_add`, `lat_mul`, `lat_div`, `lat_call`,
    /// `writes`, `buffer`).
    pub arch: Vec<(&'a str, u32, Span)>,
    /// Words per PE memory (`add0=5`).
    pub words: Vec<(&'a str, u32, Span)>,
    /// Words per buffer.
    pub buffers: Vec<(&'a str, u32, Span)>,
    /// Issue, load and write lines.
    pub lines: Vec<PlacementLineAst<'a>>,
    /// The whole block.
    pub span: Span,
}

/// One line of a placement block.
#[derive(Debug)]
pub enum PlacementLineAst<'a> {
    /// `issue %v PE CYCLE`
    Issue {
        /// Op name.
        value: &'a str,
        /// PE name (`add0`).
        pe: &'a str,
        /// Issue cycle.
        cycle: u32,
        /// Line span.
        span: Span,
    },
    /// `load PE ADDR OPERAND`
    Load {
        /// PE name.
        pe: &'a str,
        /// Address.
        addr: u32,
        /// Input, trig value or constant.
        operand: OperandAst<'a>,
        /// Line span.
        span: Span,
    },
    /// `write %v PE ADDR CYCLE [buffer BADDR]`
    Write {
        /// Op name.
        value: &'a str,
        /// Target PE memory.
        pe: &'a str,
        /// Address.
        addr: u32,
        /// Write cycle.
        cycle: u32,
        /// `buffer BADDR` for an indirect write.
        via: Option<(&'a str, u32)>,
        /// Line span.
        span: Span,
    },
}

/// One line of a function body.
#[derive(Debug)]
pub enum ItemAst<'a> {
    /// `input %name : format`
    Input(&'a str, Span, Option<crate::format::Format>),
    /// `%name = rhs : format {timing}`
    Def {
        /// Defined name.
        name: &'a str,
        /// Span of `%name`.
        name_span: Span,
        /// Right-hand side.
        rhs: RhsAst<'a>,
        /// Numeric format, when not binary64.
        format: Option<crate::format::Format>,
        /// Schedule attributes.
        timing: Option<Timing>,
    },
    /// `output NAME = operand`
    Output(&'a str, OperandAst<'a>, Span),
}

/// A right-hand side.
#[derive(Debug)]
pub enum RhsAst<'a> {
    /// `add a, b` …
    Bin(BinOp, OperandAst<'a>, OperandAst<'a>),
    /// `cos %q[4]`
    Trig(TrigFn, OperandAst<'a>),
    /// `call @f(a, b)`
    Call(Callee, Vec<OperandAst<'a>>),
    /// An infix expression.
    Expr(ExprAst<'a>),
}

/// An operand: `%name` or a constant.
#[derive(Debug)]
pub enum OperandAst<'a> {
    /// A value name and its span.
    Value(&'a str, Span),
    /// A constant (may be negative in operation form).
    Const(f64, Span),
}

/// An infix expression.
#[derive(Debug)]
pub enum ExprAst<'a> {
    /// Leaf.
    Operand(OperandAst<'a>),
    /// `-x`
    Neg(Box<ExprAst<'a>>),
    /// `a op b`
    Bin(BinOp, Box<ExprAst<'a>>, Box<ExprAst<'a>>),
    /// `@f(args)`
    Call(Callee, Vec<ExprAst<'a>>),
}

/// Splits `user_ExtForces.1[3]` into callee name and element.
pub fn callee(text: &str) -> Callee {
    if let Some(open) = text.rfind('[') {
        if text.ends_with(']') {
            if let Ok(e) = text[open + 1..text.len() - 1].parse::<u32>() {
                return Callee { name: text[..open].to_string(), elem: Some(e) };
            }
        }
    }
    Callee { name: text.to_string(), elem: None }
}

/// Builds [`Timing`] from `{asap=…, alap=…, asap_cycle=…, alap_cycle=…, mobility=…}`.
///
/// # Errors
/// A missing, repeated or unknown key, or a mobility that is not `alap - asap`.
pub fn timing<'a>(
    kv: Vec<(&'a str, u32)>,
    start: usize,
    end: usize,
) -> Result<Timing, lalrpop_util::ParseError<usize, super::lexer::Tok<'a>, super::error::GrammarError>> {
    let err = |msg: String| lalrpop_util::ParseError::User {
        error: super::error::GrammarError::BadTiming { start, end, message: msg },
    };
    const KEYS: [&str; 5] = ["asap", "alap", "asap_cycle", "alap_cycle", "mobility"];
    let mut got: [Option<u32>; 5] = [None; 5];
    for (k, v) in kv {
        let Some(i) = KEYS.iter().position(|x| *x == k) else {
            return Err(err(format!("unknown timing key `{k}`; expected one of {}", KEYS.join(", "))));
        };
        if got[i].replace(v).is_some() {
            return Err(err(format!("timing key `{k}` given twice")));
        }
    }
    let mut vals = [0u32; 5];
    for (i, g) in got.iter().enumerate() {
        vals[i] = g.ok_or_else(|| err(format!("timing key `{}` missing", KEYS[i])))?;
    }
    let [asap, alap, asap_cycle, alap_cycle, mobility] = vals;
    if alap < asap || mobility != alap - asap {
        return Err(err(format!("mobility must equal alap - asap ({alap} - {asap}), found {mobility}")));
    }
    Ok(Timing { asap, alap, asap_cycle, alap_cycle, mobility })
}
