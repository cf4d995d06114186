//! File scanner for Robotran Python (numpy 6.6 and MBsysTran 8.1): `#` comments (also trailing
//! ones), `import`/`from … import` lines, `def name(params):`, `\` continuations, one statement
//! per line; indentation is not significant for straight-line bodies and is ignored.

use robovec_ir::Span;

use super::ast::FuncAst;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::lines::LineScanner;
use super::scan;
use super::Language;

/// Parameters that are never outputs.
const NOT_OUTPUTS: &[&str] = &["s", "tsim", "usrfun", "self", "isens", "sens"];

/// The Python file scanner, fed one logical line at a time ([`crate::lines`]: comments and
/// `\` continuations already removed).
#[derive(Default)]
pub struct Scanner {
    funcs: Vec<FuncAst>,
    outside_reported: bool,
    dropped: bool,
    mark: usize,
}

impl LineScanner for Scanner {
    const LANG: Language = Language::Python;

    fn line(&mut self, src: &str, line: &[Spanned<'_>], errors: &mut Vec<FrontError>) {
        let first = line[0];
        let word = if let Tok::Ident(w) = first.1 { Some(w) } else { None };
        match word {
            Some("import" | "from") => return,
            Some("def") => {
                self.dropped = false;
                self.mark = errors.len();
                if let Some(f) = signature(line, errors) {
                    self.funcs.push(f);
                }
                return;
            }
            Some("pass") if line.len() == 1 => return,
            Some("return") if line.len() == 1 => return,
            Some(w) if scan::control_kind(w).is_some() || w == "return" => {
                let what = scan::control_kind(w).unwrap_or("`return` with a value");
                if !self.dropped {
                    // The loop diagnostic alone tells why the file is rejected.
                    errors.truncate(self.mark);
                    errors.push(scan::control_error(src, what, Span::new(first.0, first.2)));
                    self.funcs.pop();
                }
                self.dropped = true;
                return;
            }
            _ => {}
        }
        if self.dropped {
            return;
        }
        let Some(f) = self.funcs.last_mut() else {
            if !self.outside_reported {
                errors.push(scan::unexpected(&first, "`def name(M, c, s, tsim):` before statements"));
                self.outside_reported = true;
            }
            return;
        };
        let stmt = match line {
            [rest @ .., (_, Tok::Semi, _)] => rest,
            _ => line,
        };
        scan::file_statement(stmt, f, errors);
        f.span = f.span.to(Span::new(line[0].0, line[line.len() - 1].2));
    }

    fn funcs(&mut self) -> &mut Vec<FuncAst> {
        &mut self.funcs
    }
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
