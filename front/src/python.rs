//! File scanner for Robotran Python (numpy 6.6 and MBsysTran 8.1): `#` comments (also trailing
//! ones), `import`/`from … import` lines, `def name(params):`, `\` continuations, one statement
//! per line; indentation is not significant for straight-line bodies and is ignored.

use robovec_ir::Span;

use super::ast::FuncAst;
use super::clock::Clock;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::scan;

/// Parameters that are never outputs.
const NOT_OUTPUTS: &[&str] = &["s", "tsim", "usrfun", "self", "isens", "sens"];

/// Scans a Python file.
/// Stops at `clock`'s deadline (one tick per line).
pub fn scan(src: &str, toks: &[Spanned<'_>], errors: &mut Vec<FrontError>, clock: &Clock) -> Vec<FuncAst> {
    let mut flat = Vec::with_capacity(toks.len());
    let mut k = 0;
    while k < toks.len() {
        match toks[k].1 {
            Tok::Hash(_) => {}
            Tok::Backslash if toks.get(k + 1).is_some_and(|t| t.1 == Tok::Newline) => k += 1,
            _ => flat.push(toks[k]),
        }
        k += 1;
    }
    let mut funcs: Vec<FuncAst> = Vec::new();
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
            Some("import" | "from") => continue,
            Some("def") => {
                dropped = false;
                mark = errors.len();
                if let Some(f) = signature(line, errors) {
                    funcs.push(f);
                }
                continue;
            }
            Some("pass") if line.len() == 1 => continue,
            Some("return") if line.len() == 1 => continue,
            Some(w) if scan::control_kind(w).is_some() || w == "return" => {
                let what = scan::control_kind(w).unwrap_or("`return` with a value");
                if !dropped {
                    // The loop diagnostic alone tells why the file is rejected.
                    errors.truncate(mark);
                    errors.push(scan::control_error(src, what, Span::new(first.0, first.2)));
                }
                if !dropped {
                    funcs.pop();
                }
                dropped = true;
                continue;
            }
            _ => {}
        }
        if dropped {
            continue;
        }
        let Some(f) = funcs.last_mut() else {
            if !outside_reported {
                errors.push(scan::unexpected(&first, "`def name(M, c, s, tsim):` before statements"));
                outside_reported = true;
            }
            continue;
        };
        let stmt = match line {
            [rest @ .., (_, Tok::Semi, _)] => rest,
            _ => line,
        };
        scan::file_statement(stmt, f, errors);
        f.span = f.span.to(Span::new(line[0].0, line[line.len() - 1].2));
    }
    funcs
}

/// `def name(a, b, s, tsim):`
fn signature(line: &[Spanned<'_>], errors: &mut Vec<FrontError>) -> Option<FuncAst> {
    let span = scan::span_of(line, line[0].0);
    match line {
        [_, (_, Tok::Ident(name), _), (_, Tok::LParen, _), inner @ .., (_, Tok::RParen, _), (_, Tok::Colon, _)] => {
            let mut f = FuncAst::new(name, span);
            for (p, _, _) in scan::params(inner) {
                f.params.push(p.to_string());
                if !NOT_OUTPUTS.contains(&p) {
                    f.outputs.push(p.to_string());
                }
            }
            Some(f)
        }
        _ => {
            errors.push(
                FrontError::new(span, "malformed function signature", "this line")
                    .note("expected `def dirdyna(M, c, s, tsim):`"),
            );
            None
        }
    }
}
