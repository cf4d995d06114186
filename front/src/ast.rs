//! Language-agnostic statement AST produced by `expr.lalrpop`, and the file-level structure
//! produced by the per-language scanners (`c.rs`, `matlab.rs`, `python.rs`).

use robovec_ir::{BinOp, Span};

/// An identifier with its span.
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    /// The text.
    pub text: String,
    /// Where it is.
    pub span: Span,
}

/// `s->x` or `s.x`: the separator of a member access (only its presence matters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sep {
    /// C `->`
    Arrow,
    /// Matlab / Python `.`
    Dot,
}

/// A suffix after a name: `[i][j]`, `[i,j]` or `(…)` (Matlab index or call arguments).
#[derive(Clone, Debug, PartialEq)]
pub enum Suffix {
    /// `[a, b]`
    Bracket(Vec<Expr>, Span),
    /// `(a, b)`
    Paren(Vec<Expr>, Span),
}

/// A name reference: optional `obj->` / `obj.`, a name and suffixes (`s->dpt[2][4]`, `q(4)`,
/// `cos(q[4])`, `usrfun.flink(Z1,Zd1,s,tsim,1)`).
#[derive(Clone, Debug, PartialEq)]
pub struct Ref {
    /// `s` in `s->dpt`, `np` in `np.cos`.
    pub obj: Option<(Ident, Sep)>,
    /// The name.
    pub name: Ident,
    /// Indices or call arguments, in source order.
    pub suffix: Vec<Suffix>,
    /// The whole reference.
    pub span: Span,
}

/// An expression exactly as written (parentheses only group).
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A numeric literal; `int` when written without a dot (`0`, `4`).
    Num {
        /// Its value (finite, non-negative).
        value: f64,
        /// Written as digits only.
        int: bool,
        /// Where.
        span: Span,
    },
    /// A string literal (only legal as an `mbs_msg` argument).
    Str(Span),
    /// A name, index or call.
    Ref(Box<Ref>),
    /// Unary minus on the product term that follows.
    Neg(Box<Expr>, Span),
    /// `a op b`.
    Bin(BinOp, Box<Expr>, Box<Expr>),
}

impl Expr {
    /// The source span of the expression.
    pub fn span(&self) -> Span {
        match self {
            Expr::Num { span, .. } | Expr::Str(span) | Expr::Neg(_, span) => *span,
            Expr::Ref(r) => r.span,
            Expr::Bin(_, a, b) => a.span().to(b.span()),
        }
    }
}

/// One statement `lhs = rhs`.
#[derive(Clone, Debug, PartialEq)]
pub struct Stmt {
    /// Left-hand side.
    pub lhs: Ref,
    /// Right-hand side.
    pub rhs: Expr,
    /// Whole statement (terminator excluded).
    pub span: Span,
}

/// One `case N:` of a sensor `switch`.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// The label `N`.
    pub label: u32,
    /// Its statements.
    pub body: Vec<Stmt>,
    /// Span of `case N:`.
    pub span: Span,
}

/// One Robotran function as the scanners see it.
#[derive(Clone, Debug, PartialEq)]
pub struct FuncAst {
    /// Name with a leading `mbs_` stripped.
    pub name: String,
    /// Span of the whole function.
    pub span: Span,
    /// Parameter names, in order.
    pub params: Vec<String>,
    /// Parameters / results that are output arrays (`M`, `c`, `Qq`, `phi`, `frc`…).
    pub outputs: Vec<String>,
    /// Names declared as pointers (`double *SWr1;`): a callback result bound to one is a vector.
    pub pointers: Vec<String>,
    /// Names aliased by `#define X s->X`.
    pub defines: Vec<String>,
    /// Statements before a sensor `switch`, or the whole body.
    pub prefix: Vec<Stmt>,
    /// `switch (isens)` cases, if any.
    pub cases: Option<Vec<Case>>,
    /// Statements after the `switch` (run after every case).
    pub suffix: Vec<Stmt>,
    /// Names assigned by statements that failed to parse (their uses are not reported again).
    pub poisoned: Vec<String>,
}

impl FuncAst {
    /// An empty function.
    pub fn new(name: &str, span: Span) -> FuncAst {
        FuncAst {
            name: name.strip_prefix("mbs_").unwrap_or(name).to_string(),
            span,
            params: Vec::new(),
            outputs: Vec::new(),
            pointers: Vec::new(),
            defines: Vec::new(),
            prefix: Vec::new(),
            cases: None,
            suffix: Vec::new(),
            poisoned: Vec::new(),
        }
    }
}
