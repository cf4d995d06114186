//! File scanner for Robotran C (ROBOTRAN 6.6 and MBsysTran 8.1): finds function definitions
//! and their parameters, skips comments, `#include`, declarations and the pointer prologue,
//! records `#define X s->X` aliases and `double *X;` pointers, splits `;`-terminated
//! statements (which may span lines) and the sensor `switch (isens) { case N: … break; }`.

use robovec_ir::Span;

use super::ast::{Case, FuncAst, Stmt};
use super::clock::Clock;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::lower::Lower;
use super::scan::{self, Parsed};
use super::Language;

mod stream;

pub use stream::scan_and_lower;
use stream::{Stream, Streamed};

const TYPES: &[&str] =
    &["void", "int", "double", "float", "long", "unsigned", "static", "const", "MbsData", "MBSdataStruct", "MbsSensor"];

/// Scans a C file. `header` is the companion `.h` text: its declarations are only used for
/// `double *X;` pointers.
/// Stops at `clock`'s deadline (one tick per statement).
pub fn scan(
    src: &str,
    toks: &[Spanned<'_>],
    header: Option<&str>,
    errors: &mut Vec<FrontError>,
    clock: &Clock,
) -> Vec<FuncAst> {
    scan_impl(src, toks, header, errors, None, clock)
}

fn scan_impl(
    src: &str,
    toks: &[Spanned<'_>],
    header: Option<&str>,
    errors: &mut Vec<FrontError>,
    mut streamed: Option<&mut Streamed>,
    clock: &Clock,
) -> Vec<FuncAst> {
    // Without comments and newlines (already so when lexed by `parse_str`: no copy then).
    let filtered: Vec<Spanned<'_>>;
    let toks = if toks.iter().any(|t| ignored(&t.1)) {
        filtered = toks.iter().copied().filter(|t| !ignored(&t.1)).collect();
        &filtered[..]
    } else {
        toks
    };
    let mut header_pointers = Vec::new();
    if let Some(h) = header {
        let htoks: Vec<_> = super::lexer::lex(h).into_iter().filter(|t| t.1 != Tok::Newline).collect();
        for decl in htoks.split(|t| t.1 == Tok::Semi) {
            declaration(decl, &mut header_pointers, &mut Vec::new());
        }
    }
    let mut funcs = Vec::new();
    let mut defines = Vec::new();
    let mut i = 0;
    let mut junk_reported = false;
    while i < toks.len() && !clock.stopped() {
        match toks[i].1 {
            Tok::Hash(text) => {
                directive(text, Span::new(toks[i].0, toks[i].2), &mut defines, errors);
                i += 1;
            }
            Tok::Semi => i += 1,
            Tok::Ident(w) if TYPES.contains(&w) => {
                let start = i;
                // The function name is the last identifier before `(`.
                let Some(open) = (i..toks.len()).find(|&k| !matches!(toks[k].1, Tok::Ident(_) | Tok::Star)) else {
                    errors.push(scan::unexpected(&toks[toks.len() - 1], "a function definition"));
                    break;
                };
                if matches!(toks[open].1, Tok::Semi | Tok::LBracket | Tok::Comma) {
                    // A file-level declaration (`double    C4;` in a companion header): ignored.
                    i = skip_item(toks, open);
                    continue;
                }
                let name = match (toks[open].1, open.checked_sub(1).map(|k| toks[k].1)) {
                    (Tok::LParen, Some(Tok::Ident(n))) if open - 1 > start => n,
                    _ => {
                        errors.push(scan::unexpected(&toks[open], "a function definition `void NAME(…) { … }`"));
                        i = skip_item(toks, open);
                        continue;
                    }
                };
                let Some(close) = matching(toks, open) else {
                    errors.push(
                        FrontError::new(Span::new(toks[open].0, toks[open].2), "unclosed `(`", "opened here")
                            .note("expected `)` closing the parameter list"),
                    );
                    break;
                };
                let body_open = close + 1;
                match toks.get(body_open).map(|t| t.1) {
                    Some(Tok::Semi) => i = body_open + 1, // a prototype
                    Some(Tok::LBrace) => {
                        let body_close = matching(toks, body_open).unwrap_or_else(|| {
                            errors.push(
                                FrontError::new(
                                    Span::new(toks[body_open].0, toks[body_open].2),
                                    "unclosed `{`",
                                    "function body opened here",
                                )
                                .note("expected `}` closing the function body"),
                            );
                            toks.len()
                        });
                        let end = toks.get(body_close).map_or(src.len(), |t| t.0);
                        let mut f = FuncAst::new(
                            name,
                            Span::new(toks[start].0, toks.get(body_close).map_or(src.len(), |t| t.2)),
                        );
                        for (p, stars, ty) in scan::params(&toks[open + 1..close]) {
                            f.params.push(p.to_string());
                            if stars > 0 && ty == "double" {
                                f.outputs.push(p.to_string());
                            }
                        }
                        f.defines = defines.clone();
                        f.pointers = header_pointers.clone();
                        let mark = errors.len();
                        let mut stream = streamed.as_ref().map(|_| Stream { lower: None, at: (0, 0) });
                        let scanned = match stream.as_mut() {
                            // The outline left the body out: it is lexed again, a window at a time.
                            Some(stream) => {
                                stream::body_in_windows(src, toks[body_open].2, end, &mut f, errors, stream, clock)
                            }
                            None => {
                                body(src, &toks[body_open + 1..body_close], end, &mut f, errors, None, &mut None, clock)
                            }
                        };
                        if scanned {
                            if let (Some(st), Some(stream)) = (streamed.as_deref_mut(), stream) {
                                st.broken |= f.cases.is_some()
                                    || !f.poisoned.is_empty()
                                    || (stream.lower.is_some() && stream.at != (f.defines.len(), f.pointers.len()));
                                let lower = stream.lower.unwrap_or_else(|| Lower::new(src, Language::C, &f));
                                st.functions.push(lower.finish(f.name.clone(), errors));
                            }
                            funcs.push(f);
                        } else if let Some(fatal) = errors.pop() {
                            // Control flow: the loop diagnostic alone tells why the file is rejected.
                            errors.truncate(mark);
                            errors.push(fatal);
                        }
                        i = body_close + 1;
                    }
                    _ => {
                        let t = toks.get(body_open).copied().unwrap_or((toks[close].2, Tok::Semi, toks[close].2));
                        errors.push(scan::unexpected(&t, "`{` opening the function body"));
                        i = skip_item(toks, body_open);
                    }
                }
            }
            _ => {
                if !junk_reported {
                    errors.push(scan::unexpected(&toks[i], "a function definition, `#include` or a comment"));
                    junk_reported = true;
                }
                i += 1;
            }
        }
    }
    funcs
}

/// Tokens the C scanner skips: comments and newlines.
pub fn ignored(t: &Tok<'_>) -> bool {
    matches!(t, Tok::SlashComment | Tok::BlockComment | Tok::Newline)
}

/// Index of the bracket closing the one at `open`.
fn matching(toks: &[Spanned<'_>], open: usize) -> Option<usize> {
    let (o, c) = match toks[open].1 {
        Tok::LParen => (Tok::LParen, Tok::RParen),
        _ => (Tok::LBrace, Tok::RBrace),
    };
    let mut depth = 0usize;
    for (k, t) in toks.iter().enumerate().skip(open) {
        if t.1 == o {
            depth += 1;
        } else if t.1 == c {
            depth -= 1;
            if depth == 0 {
                return Some(k);
            }
        }
    }
    None
}

/// After an error at top level: the index after the next `;` or balanced `{…}`.
fn skip_item(toks: &[Spanned<'_>], from: usize) -> usize {
    let mut k = from;
    while k < toks.len() {
        match toks[k].1 {
            Tok::Semi => return k + 1,
            Tok::LBrace => return matching(toks, k).map_or(toks.len(), |c| c + 1),
            _ => k += 1,
        }
    }
    k
}

/// `#include …` is ignored; `#define X s->X` makes `X` an alias of the input array `X`.
fn directive(text: &str, span: Span, defines: &mut Vec<String>, errors: &mut Vec<FrontError>) {
    let words: Vec<&str> = text[1..].split_whitespace().collect();
    match words.as_slice() {
        ["include", ..] => {}
        ["define", name, repl] if *repl == format!("s->{name}") => defines.push(name.to_string()),
        ["define", ..] => errors.push(
            FrontError::new(span, "unsupported macro", "this `#define`")
                .note("expected only `#define X s->X` aliases such as `#define q s->q`"),
        ),
        _ => errors.push(
            FrontError::new(span, "unsupported preprocessor line", "this line")
                .note("expected `#include` or `#define X s->X`"),
        ),
    }
}

/// A declaration `double a, *b, c[4];`: records pointer names; an initialiser is an error.
fn declaration(toks: &[Spanned<'_>], pointers: &mut Vec<String>, errors: &mut Vec<FrontError>) {
    if let Some(t) = toks.iter().find(|t| t.1 == Tok::Eq) {
        errors.push(
            FrontError::new(scan::span_of(toks, t.0), "declaration with an initialiser", "initialised here")
                .note("expected a plain declaration such as `double PxF1[4];` (initialised arrays occur only in accelred/invdynared files)"),
        );
        return;
    }
    for d in toks.split(|t| t.1 == Tok::Comma) {
        let head = &d[..d.iter().position(|t| t.1 == Tok::LBracket).unwrap_or(d.len())];
        let stars = head.iter().filter(|t| t.1 == Tok::Star).count();
        let name = head.iter().rev().find_map(|t| if let Tok::Ident(s) = t.1 { Some(s) } else { None });
        if let (Some(n), true) = (name, stars == 1) {
            pointers.push(n.to_string());
        }
    }
}

/// Where statements go while scanning a body.
enum Target {
    Prefix,
    Case,
    /// After `break;` or `default:` inside the switch: nothing may follow until `case`.
    Dead,
    Suffix,
}

/// Scans a function body (or a part of one ending after a `;`) into `f`; false after a fatal
/// (control-flow or structure) error, which is then the last error pushed. `returned` is the
/// `return;` seen so far in the body (statements after it are unreachable). Stops at `clock`'s
/// deadline (one tick per token position visited), returning true: the caller asks the clock.
#[allow(clippy::too_many_arguments)]
fn body<'s>(
    src: &'s str,
    toks: &[Spanned<'_>],
    end: usize,
    f: &mut FuncAst,
    errors: &mut Vec<FrontError>,
    mut stream: Option<&mut Stream<'s>>,
    returned: &mut Option<Span>,
    clock: &Clock,
) -> bool {
    let mut i = 0;
    let mut target = Target::Prefix;
    let mut cases: Option<Vec<Case>> = None;
    let mut switch_close: Option<usize> = None;
    let mut push =
        |s: Stmt, target: &Target, f: &mut FuncAst, cases: &mut Option<Vec<Case>>, errors: &mut Vec<FrontError>| {
            match target {
                // Without a `switch` (else the batch path decides), the statements lower in
                // source order: prefix then suffix.
                Target::Prefix | Target::Suffix if stream.is_some() => {
                    if let Some(st) = stream.as_deref_mut() {
                        if st.lower.is_none() {
                            st.at = (f.defines.len(), f.pointers.len());
                            st.lower = Some(Lower::new(src, Language::C, f));
                        }
                        if let Some(lower) = st.lower.as_mut() {
                            lower.stmt(&s);
                        }
                    }
                }
                Target::Prefix => f.prefix.push(s),
                Target::Suffix => f.suffix.push(s),
                Target::Case => {
                    if let Some(c) = cases.as_mut().and_then(|c| c.last_mut()) {
                        c.body.push(s)
                    }
                }
                Target::Dead => errors.push(
                    FrontError::new(s.span, "unreachable statement in a `switch`", "after `break;` or `default:`")
                        .note("expected `case N:` before statements"),
                ),
            }
        };
    while i < toks.len() {
        let t = toks[i];
        if clock.tick(t.0) {
            return true;
        }
        if Some(i) == switch_close {
            target = Target::Suffix;
            switch_close = None;
            i += 1;
            continue;
        }
        let word = if let Tok::Ident(w) = t.1 { Some(w) } else { None };
        let next = toks.get(i + 1).map(|t| t.1);
        match (t.1, word) {
            (Tok::Hash(text), _) => {
                directive(text, Span::new(t.0, t.2), &mut f.defines, errors);
                i += 1;
            }
            (Tok::Semi, _) => i += 1,
            (_, Some(w)) if TYPES.contains(&w) && !matches!(next, Some(Tok::Eq)) => {
                let semi = (i..toks.len()).find(|&k| toks[k].1 == Tok::Semi).unwrap_or(toks.len());
                declaration(&toks[i + 1..semi], &mut f.pointers, errors);
                i = semi + 1;
            }
            (_, Some("switch")) if cases.is_none() && matches!(next, Some(Tok::LParen)) => {
                let close = matching(toks, i + 1);
                match close.map(|c| (c, toks.get(c + 1).map(|t| t.1))) {
                    Some((c, Some(Tok::LBrace))) => {
                        switch_close = matching(toks, c + 1);
                        if switch_close.is_none() {
                            errors.push(
                                FrontError::new(Span::new(t.0, t.2), "unclosed `switch`", "this switch")
                                    .note("expected `}` closing the switch"),
                            );
                            return false;
                        }
                        cases = Some(Vec::new());
                        target = Target::Dead;
                        i = c + 2;
                    }
                    _ => {
                        errors.push(
                            FrontError::new(Span::new(t.0, t.2), "malformed `switch`", "this switch")
                                .note("expected `switch (isens) { case 1: … }`"),
                        );
                        return false;
                    }
                }
            }
            (_, Some("case")) if cases.is_some() && switch_close.is_some() => {
                let label = match (toks.get(i + 1), toks.get(i + 2).map(|t| t.1)) {
                    (Some(&(_, Tok::Number(n), _)), Some(Tok::Colon)) => n.parse::<u32>().ok(),
                    _ => None,
                };
                let Some(label) = label else {
                    errors.push(
                        FrontError::new(Span::new(t.0, t.2), "malformed `case` label", "this case")
                            .note("expected `case N:` with an integer N"),
                    );
                    return false;
                };
                let span = Span::new(t.0, toks[i + 2].2);
                let cs = cases.get_or_insert_with(Vec::new);
                if let Some(prev) = cs.iter().find(|c| c.label == label) {
                    let line = robovec_ir::span::line_of(src, prev.span.start as usize);
                    errors.push(
                        FrontError::new(span, format!("`case {label}` appears twice"), "second case")
                            .note(format!("first `case {label}:` at line {line}")),
                    );
                }
                cs.push(Case { label, body: Vec::new(), span });
                target = Target::Case;
                i += 3;
            }
            (_, Some("default")) if switch_close.is_some() && matches!(next, Some(Tok::Colon)) => {
                target = Target::Dead;
                i += 2;
            }
            (_, Some("break")) if switch_close.is_some() && matches!(next, Some(Tok::Semi)) => {
                target = Target::Dead;
                i += 2;
            }
            (_, Some("return")) if matches!(next, Some(Tok::Semi)) => {
                *returned = Some(Span::new(t.0, toks[i + 1].2));
                i += 2;
            }
            (_, Some("return")) => {
                errors.push(scan::control_error(src, "`return` with a value", Span::new(t.0, t.2)));
                return false;
            }
            (_, Some(w)) if scan::control_kind(w).is_some() => {
                errors.push(scan::control_error(src, scan::control_kind(w).unwrap_or(w), Span::new(t.0, t.2)));
                return false;
            }
            (Tok::LBrace | Tok::RBrace, _) => {
                errors.push(scan::unexpected(&t, "a statement; nested blocks are not supported"));
                return false;
            }
            _ => {
                // A statement: tokens up to `;`.
                let stop = (i..toks.len())
                    .find(|&k| {
                        matches!(toks[k].1, Tok::Semi | Tok::LBrace | Tok::RBrace | Tok::Hash(_))
                            || Some(k) == switch_close
                    })
                    .unwrap_or(toks.len());
                let stmt = &toks[i..stop];
                if stop >= toks.len() || toks[stop].1 != Tok::Semi {
                    let at = toks.get(stop).map_or(end, |t| t.0);
                    errors.push(
                        FrontError::new(
                            scan::span_of(stmt, at),
                            "statement is not terminated by `;`",
                            "this statement",
                        )
                        .note("expected `;` at the end of the statement"),
                    );
                    i = stop;
                    continue;
                }
                if let Some(r) = *returned {
                    let line = robovec_ir::span::line_of(src, r.start as usize);
                    errors.push(
                        FrontError::new(
                            scan::span_of(stmt, t.0),
                            "unreachable statement after `return;`",
                            "after return",
                        )
                        .note(format!("`return;` at line {line} ends the function")),
                    );
                }
                match scan::statement(stmt, errors) {
                    Parsed::Stmt(s) => push(*s, &target, f, &mut cases, errors),
                    Parsed::Failed(Some(name)) => f.poisoned.push(name),
                    Parsed::Ignored | Parsed::Failed(None) => {}
                }
                i = stop + 1;
            }
        }
    }
    f.cases = cases;
    true
}
