//! File scanner for Robotran Matlab (`.m`): `%` comments, `function [M,c] = dirdyna(s,tsim,usrfun)`
//! signatures, `...` continuations, `;`-terminated statements one per line, optional `end`.

use robovec_ir::Span;

use super::ast::FuncAst;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::lines::LineScanner;
use super::scan;
use super::Language;

/// The Matlab file scanner, fed one logical line at a time ([`crate::lines`]: comments and
/// `...` continuations already removed).
#[derive(Default)]
pub struct Scanner {
    funcs: Vec<FuncAst>,
    ended: bool,
    outside_reported: bool,
    dropped: bool,
    mark: usize,
}

impl LineScanner for Scanner {
    const LANG: Language = Language::Matlab;

    fn line(&mut self, src: &str, line: &[Spanned<'_>], errors: &mut Vec<FrontError>) {
        let first = line[0];
        let word = if let Tok::Ident(w) = first.1 { Some(w) } else { None };
        match word {
            Some("function") => {
                self.dropped = false;
                self.mark = errors.len();
                if let Some(f) = signature(line, errors) {
                    self.funcs.push(f);
                    self.ended = false;
                }
                return;
            }
            Some("end") if line.len() == 1 || (line.len() == 2 && line[1].1 == Tok::Semi) => {
                self.ended = true;
                return;
            }
            Some("return") if line.len() == 1 || (line.len() == 2 && line[1].1 == Tok::Semi) => return,
            Some(w) if scan::control_kind(w).is_some() || w == "return" => {
                let what = scan::control_kind(w).unwrap_or("`return`");
                if !self.dropped {
                    // The loop diagnostic alone tells why the file is rejected.
                    errors.truncate(self.mark);
                    errors.push(scan::control_error(src, what, Span::new(first.0, first.2)));
                }
                // Drop the function: nothing after a loop can be trusted.
                if !self.dropped && !self.ended {
                    self.funcs.pop();
                }
                self.ended = true;
                self.dropped = true;
                return;
            }
            _ => {}
        }
        let Some(f) = self.funcs.last_mut().filter(|_| !self.ended) else {
            if !self.outside_reported && !self.dropped {
                errors.push(scan::unexpected(&first, "`function [outputs] = name(s,tsim,usrfun)` before statements"));
                self.outside_reported = true;
            }
            return;
        };
        for stmt in line.split(|t| t.1 == Tok::Semi).filter(|s| !s.is_empty()) {
            scan::file_statement(stmt, f, errors);
        }
        f.span = f.span.to(Span::new(line[0].0, line[line.len() - 1].2));
    }

    fn funcs(&mut self) -> &mut Vec<FuncAst> {
        &mut self.funcs
    }
}

/// `function [a,b] = name(p, q)`, `function a = name(…)` or `function name(…)`.
fn signature(line: &[Spanned<'_>], errors: &mut Vec<FrontError>) -> Option<FuncAst> {
    let span = scan::span_of(line, line[0].0);
    let bad = |errors: &mut Vec<FrontError>| {
        errors.push(
            FrontError::new(span, "malformed function signature", "this line")
                .note("expected `function [M,c] = dirdyna(s,tsim,usrfun)`"),
        );
        None
    };
    let rest = &line[1..];
    let (outputs, rest): (Vec<String>, &[Spanned<'_>]) = match rest.iter().position(|t| t.1 == Tok::Eq) {
        Some(eq) => {
            let outs = rest[..eq]
                .iter()
                .filter_map(|t| if let Tok::Ident(s) = t.1 { Some(s.to_string()) } else { None })
                .collect();
            (outs, &rest[eq + 1..])
        }
        None => (Vec::new(), rest),
    };
    let [(_, Tok::Ident(name), _), tail @ ..] = rest else { return bad(errors) };
    let params = match tail {
        [] => Vec::new(),
        [(_, Tok::LParen, _), inner @ .., (_, Tok::RParen, _)] => scan::params(inner),
        _ => return bad(errors),
    };
    let mut f = FuncAst::new(name, span);
    f.params = params.iter().map(|p| p.0.to_string()).collect();
    f.outputs = outputs;
    Some(f)
}
