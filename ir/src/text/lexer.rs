//! Lexer of the `.rvir` text form (logos), adapted to lalrpop's external-lexer interface.

use logos::Logos;

/// A token of the `.rvir` text form. Whitespace and `;` comments are skipped.
#[derive(Logos, Clone, Copy, Debug, PartialEq)]
#[logos(skip r"[ \t\r\n\f]+")]
#[logos(skip(r";[^\n]*", allow_greedy = true))]
pub enum Tok<'a> {
    /// `func`
    #[token("func")]
    Func,
    /// `phase`
    #[token("phase")]
    Phase,
    /// `parsed`
    #[token("parsed")]
    Parsed,
    /// `atomised`
    #[token("atomised")]
    Atomised,
    /// `equations`
    #[token("equations")]
    Equations,
    /// `states`
    #[token("states")]
    States,
    /// `input`
    #[token("input")]
    Input,
    /// `output`
    #[token("output")]
    Output,
    /// `add`
    #[token("add")]
    Add,
    /// `sub`
    #[token("sub")]
    Sub,
    /// `mul`
    #[token("mul")]
    Mul,
    /// `div`
    #[token("div")]
    Div,
    /// `call`
    #[token("call")]
    Call,
    /// `sin`
    #[token("sin")]
    Sin,
    /// `cos`
    #[token("cos")]
    Cos,
    /// `placement`
    #[token("placement")]
    Placement,
    /// `issue`
    #[token("issue")]
    Issue,
    /// `load`
    #[token("load")]
    Load,
    /// `write`
    #[token("write")]
    Write,
    /// `words`
    #[token("words")]
    Words,
    /// `buffers`
    #[token("buffers")]
    Buffers,
    /// `{`
    #[token("{")]
    LBrace,
    /// `}`
    #[token("}")]
    RBrace,
    /// `(`
    #[token("(")]
    LParen,
    /// `)`
    #[token(")")]
    RParen,
    /// `,`
    #[token(",")]
    Comma,
    /// `=`
    #[token("=")]
    Eq,
    /// `+`
    #[token("+")]
    Plus,
    /// `-`
    #[token("-")]
    Minus,
    /// `*`
    #[token("*")]
    Star,
    /// `/`
    #[token("/")]
    Slash,
    /// A value's numeric format after `:` (`: f32`, `:fix<32,20>` → `f32`, `fix<32,20>`);
    /// checked by the grammar ([`crate::format::Format`]).
    #[regex(r":[ \t]*[A-Za-z0-9_]*(<[^>\n]*>)?", |lex| lex.slice()[1..].trim_start())]
    Format(&'a str),
    /// A value name after `%` (`%AlF15` → `AlF15`, `%frc[2][11].1`), with its state suffix
    /// `#k` when it belongs to state `k ≥ 1` of an interleaved function (`%q[4]#2`).
    #[regex(r"%[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+|\[[0-9]+\])*(#[0-9]+)?", |lex| &lex.slice()[1..])]
    Local(&'a str),
    /// A function or callee name after `@` (`@dirdyna`, `@user_ExtForces.1[3]`).
    #[regex(r"@[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+|\[[0-9]+\])*", |lex| &lex.slice()[1..])]
    Global(&'a str),
    /// A bare name: output names (`M[1][2]`, `sens.P[1]`, `Qq[1]#2` for state 2 of an
    /// interleaved function) and attribute keys.
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+|\[[0-9]+\])*(#[0-9]+)?")]
    Name(&'a str),
    /// An unsigned number as written (`2.0`, `12`, `1e-7`); parsed by the grammar.
    #[regex(r"[0-9]+(\.[0-9]*)?([eE][+-]?[0-9]+)?")]
    Number(&'a str),
}

impl std::fmt::Display for Tok<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Tok::Local(s) => write!(f, "%{s}"),
            Tok::Global(s) => write!(f, "@{s}"),
            Tok::Name(s) | Tok::Number(s) => write!(f, "{s}"),
            Tok::Format(s) => write!(f, ": {s}"),
            Tok::LBrace => f.write_str("{"),
            Tok::RBrace => f.write_str("}"),
            Tok::LParen => f.write_str("("),
            Tok::RParen => f.write_str(")"),
            Tok::Comma => f.write_str(","),
            Tok::Eq => f.write_str("="),
            Tok::Plus => f.write_str("+"),
            Tok::Minus => f.write_str("-"),
            Tok::Star => f.write_str("*"),
            Tok::Slash => f.write_str("/"),
            other => write!(f, "{}", format!("{other:?}").to_lowercase()),
        }
    }
}

/// A character sequence that starts no token, at byte offsets `start..end`.
#[derive(Clone, Debug, PartialEq)]
pub struct LexError {
    /// First byte of the bad text.
    pub start: usize,
    /// One past its last byte.
    pub end: usize,
}

/// Spanned tokens of `src` in the form lalrpop's generated parser consumes.
pub fn tokens(src: &str) -> impl Iterator<Item = Result<(usize, Tok<'_>, usize), LexError>> {
    Tok::lexer(src).spanned().map(|(t, r)| match t {
        Ok(t) => Ok((r.start, t, r.end)),
        Err(()) => Err(LexError { start: r.start, end: r.end }),
    })
}
