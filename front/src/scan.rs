//! Helpers shared by the file scanners: statement dispatch, control-flow diagnostics and
//! logical lines for the line-oriented languages (Matlab, Python).

use robovec_ir::Span;

use super::ast::{FuncAst, Stmt};
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::stmt::parse_stmt;
use super::Language;

use robovec_ir::span::line_of;

/// Words that start control flow in any of the three languages.
pub fn control_kind(word: &str) -> Option<&'static str> {
    Some(match word {
        "while" => "`while` loop",
        "for" => "`for` loop",
        "do" => "`do` loop",
        "if" => "`if` branch",
        "else" => "`else` branch",
        "elif" => "`elif` branch",
        "elseif" => "`elseif` branch",
        "switch" => "`switch`",
        "goto" => "`goto`",
        "try" => "`try` block",
        "with" => "`with` block",
        "continue" => "`continue`",
        _ => return None,
    })
}

/// The diagnostic for control flow in a function body (loops, branches, `goto`, valued `return`).
pub fn control_error(src: &str, what: &str, span: Span) -> FrontError {
    let line = line_of(src, span.start as usize);
    FrontError::new(
        span,
        format!(
            "{what} at line {line}: robovec handles straight-line Robotran functions only; \
             accelred/invdynared files are not supported"
        ),
        "control flow",
    )
    .note("expected only assignments `name = expression` in a function body (sensor files: one `switch (isens)`)")
}

/// The diagnostic for a file without any function.
pub fn no_function(lang: Language, len: usize) -> FrontError {
    let expected = match lang {
        Language::C => {
            "expected a C function such as `void mbs_dirdyna(double **M,double *c, MbsData *s, double tsim) { … }`"
        }
        Language::Matlab => "expected a Matlab function such as `function [M,c] = dirdyna(s,tsim,usrfun)`",
        Language::Python => "expected a Python function such as `def dirdyna(M, c, s, tsim):`",
    };
    FrontError::new(Span::new(0, len.min(1)), "no Robotran function found", "in this file").note(expected)
}

/// Span covering a token slice (empty span at `at` when the slice is empty).
pub fn span_of(toks: &[Spanned<'_>], at: usize) -> Span {
    match (toks.first(), toks.last()) {
        (Some(a), Some(b)) => Span::new(a.0, b.2),
        _ => Span::new(at, at),
    }
}

/// What one statement's tokens turned out to be.
pub enum Parsed {
    /// An assignment.
    Stmt(Box<Stmt>),
    /// `mbs_msg("…")`: a runtime message, ignored (it computes nothing).
    Ignored,
    /// An error was pushed; the name assigned, when it can be told, is poisoned so that its
    /// later uses do not cascade into more errors.
    Failed(Option<String>),
}

/// Parses the tokens of one statement (terminator excluded) and files it in `f`.
/// Statement-position calls are rejected, except `mbs_msg(…)` which is ignored.
pub fn file_statement(toks: &[Spanned<'_>], f: &mut FuncAst, errors: &mut Vec<FrontError>) {
    match statement(toks, errors) {
        Parsed::Stmt(s) => f.prefix.push(*s),
        Parsed::Failed(Some(name)) => f.poisoned.push(name),
        Parsed::Failed(None) | Parsed::Ignored => {}
    }
}

/// Parses the tokens of one statement (terminator excluded). Statement-position calls are
/// rejected, except `mbs_msg(…)` which is ignored.
pub fn statement(toks: &[Spanned<'_>], errors: &mut Vec<FrontError>) -> Parsed {
    let span = span_of(toks, 0);
    let has_eq = toks.iter().any(|t| t.1 == Tok::Eq);
    if !has_eq {
        if let [(_, Tok::Ident(name), _), (_, Tok::LParen, _), ..] = toks {
            if *name == "mbs_msg" {
                return Parsed::Ignored;
            }
            errors.push(
                FrontError::new(span, format!("call statement `{name}(…)` is not supported"), "call without a result")
                    .note("expected an assignment `name = expression`; robovec cannot see what a call without a result changes (only `mbs_msg(…)` is ignored)"),
            );
            return Parsed::Failed(None);
        }
        errors.push(
            FrontError::new(span, "expected an assignment", "not an assignment").note("expected `name = expression`"),
        );
        return Parsed::Failed(None);
    }
    match parse_stmt(toks, span.end as usize) {
        Ok(s) => Parsed::Stmt(Box::new(s)),
        Err(e) => {
            errors.push(e);
            let lhs = match toks {
                [(_, Tok::Ident(obj), _), (_, Tok::Arrow | Tok::Dot, _), (_, Tok::Ident(name), _), ..] => {
                    format!("{obj}.{name}")
                }
                [(_, Tok::Ident(name), _), ..] => name.to_string(),
                _ => return Parsed::Failed(None),
            };
            Parsed::Failed(Some(lhs))
        }
    }
}

/// Splits tokens into logical lines at newlines (continuations must already be removed),
/// dropping empty lines.
pub fn lines<'t, 'a>(toks: &'t [Spanned<'a>]) -> Vec<&'t [Spanned<'a>]> {
    toks.split(|t| t.1 == Tok::Newline).filter(|l| !l.is_empty()).collect()
}

/// Parameter names of a parenthesised list `a, b, c` (tokens between the parentheses); each
/// entry is (name, number of `*`, first word).
pub fn params<'a>(toks: &[Spanned<'a>]) -> Vec<(&'a str, usize, &'a str)> {
    toks.split(|t| t.1 == Tok::Comma)
        .filter_map(|p| {
            let name = p.iter().rev().find_map(|t| if let Tok::Ident(s) = t.1 { Some(s) } else { None })?;
            let first = p.iter().find_map(|t| if let Tok::Ident(s) = t.1 { Some(s) } else { None }).unwrap_or(name);
            let stars = p.iter().filter(|t| t.1 == Tok::Star).count();
            Some((name, stars, first))
        })
        .collect()
}

/// Reports a token that has no place where it is.
pub fn unexpected(t: &Spanned<'_>, expected: &str) -> FrontError {
    let what = match t.1 {
        Tok::Error => "invalid character".to_string(),
        Tok::Punct => "unexpected character".to_string(),
        other => format!("unexpected `{other}`"),
    };
    FrontError::new(Span::new(t.0, t.2), what, "not expected here").note(format!("expected {expected}"))
}
