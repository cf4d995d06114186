//! File scanner for Robotran Matlab (`.m`): `%` comments, `function [M,c] = dirdyna(s,tsim,usrfun)`
//! signatures, `...` continuations, `;`-terminated statements one per line, optional `end`.

use robovec_ir::Span;

use super::ast::FuncAst;
use super::clock::Clock;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::scan;

/// Scans a Matlab file.
/// Stops at `clock`'s deadline (one tick per line).
pub fn scan(src: &str, toks: &[Spanned<'_>], errors: &mut Vec<FrontError>, clock: &Clock) -> Vec<FuncAst> {
    // Drop comments and continuations (`...` with the rest of its line and the line break).
    let mut flat = Vec::with_capacity(toks.len());
    let mut k = 0;
    while k < toks.len() {
        match toks[k].1 {
            Tok::PercentComment => {}
            Tok::Ellipsis => {
                if toks.get(k + 1).is_some_and(|t| t.1 == Tok::Newline) {
                    k += 1;
                }
            }
            _ => flat.push(toks[k]),
        }
        k += 1;
    }
    let mut funcs: Vec<FuncAst> = Vec::new();
    let mut ended = false;
    let mut outside_reported = false;
    let mut dropped = false;
    let mut mark = errors.len();
    for line in scan::lines(&flat) {
        let first = line[0];
        if clock.tick(first.0) {
            break;
        }
        let word = if let Tok::Ident(w) = first.1 { Some(w) } else { None };
        match word {
            Some("function") => {
                dropped = false;
                mark = errors.len();
                if let Some(f) = signature(line, errors) {
                    funcs.push(f);
                    ended = false;
                }
                continue;
            }
            Some("end") if line.len() == 1 || (line.len() == 2 && line[1].1 == Tok::Semi) => {
                ended = true;
                continue;
            }
            Some("return") if line.len() == 1 || (line.len() == 2 && line[1].1 == Tok::Semi) => continue,
            Some(w) if scan::control_kind(w).is_some() || w == "return" => {
                let what = scan::control_kind(w).unwrap_or("`return`");
                if !dropped {
                    // The loop diagnostic alone tells why the file is rejected.
                    errors.truncate(mark);
                    errors.push(scan::control_error(src, what, Span::new(first.0, first.2)));
                }
                // Drop the function: nothing after a loop can be trusted.
                if !dropped && !ended {
                    funcs.pop();
                }
                ended = true;
                dropped = true;
                continue;
            }
            _ => {}
        }
        let Some(f) = funcs.last_mut().filter(|_| !ended) else {
            if !outside_reported && !dropped {
                errors.push(scan::unexpected(&first, "`function [outputs] = name(s,tsim,usrfun)` before statements"));
                outside_reported = true;
            }
            continue;
        };
        for stmt in line.split(|t| t.1 == Tok::Semi).filter(|s| !s.is_empty()) {
            scan::file_statement(stmt, f, errors);
        }
        f.span = f.span.to(Span::new(line[0].0, line[line.len() - 1].2));
    }
    funcs
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
