//! The streaming path of the C front end: scans and lowers a file without ever holding its
//! tokens or its statement trees at once (issue 10 §3: the whole file's tokens took 17× the
//! input's size, its statement trees ~30×).
//!
//! 1. [`outline`] lexes the file once and keeps only the tokens outside braces (signatures,
//!    directives, file-level declarations) and each top-level `{` `}` pair, whose contents it
//!    leaves out: a few hundred tokens for a Robotran file of any size.
//! 2. The file scanner ([`super::scan_impl`]) runs on that outline as on the whole token list
//!    (every position it reads is the same), and at each function body calls
//!    [`body_in_windows`], which lexes the body again a window of [`WINDOW`] tokens at a time
//!    (each window ends after a `;`) and scans it with [`super::body`].
//! 3. Each statement is lowered as soon as it is parsed ([`Stream`]).
//!
//! Any error, or a form the streaming path does not cover (a `switch`, a `#define` or pointer
//! declared after the first statement, a poisoned statement, braces inside a top-level
//! parenthesis, unbalanced braces), gives `None`: the batch path then runs from the start and
//! gives the diagnostics, which are the reference.

use logos::Logos;
use robovec_ir::Span;

use super::super::ast::FuncAst;
use super::super::clock::Clock;
use super::super::error::FrontError;
use super::super::lexer::{Spanned, Tok};
use super::super::lower::Lower;
use super::{body, ignored, scan_impl};

/// Tokens per window of a body (at least; a window ends after the first `;` past this count).
/// 4096 tokens of 40 bytes: 160 KB, whatever the body's size.
const WINDOW: usize = 4096;

/// Functions lowered while their body is scanned, each statement as soon as it is parsed.
#[derive(Default)]
pub(super) struct Streamed {
    pub(super) functions: Vec<robovec_ir::Function>,
    /// A case the streaming path does not cover (a `switch`, a `#define` or pointer declared
    /// after the first statement, a poisoned statement): the batch path decides.
    pub(super) broken: bool,
}

/// One function's lowering in progress.
pub(super) struct Stream<'s> {
    pub(super) lower: Option<Lower<'s>>,
    /// `#define`s and pointers known when lowering started.
    pub(super) at: (usize, usize),
}

/// The streaming path of [`super::super::parse_str`]: scans and lowers `src` in one go, in
/// memory independent of the size of its function bodies (see the module doc). `None` when
/// the file has any error or a form the streaming path leaves to the batch path
/// ([`super::scan()`] then [`super::super::lower::lower_module`]), whose diagnostics are the
/// reference.
///
/// Stops at `clock`'s deadline (one tick per token lexed and per statement), returning `None`:
/// the caller asks the clock before taking the batch path.
pub fn scan_and_lower(src: &str, header: Option<&str>, clock: &Clock) -> Option<robovec_ir::Module> {
    let toks = outline(src, clock)?;
    let mut errors = Vec::new();
    let mut streamed = Streamed::default();
    let funcs = scan_impl(src, &toks, header, &mut errors, Some(&mut streamed), clock);
    if clock.stopped()
        || !errors.is_empty()
        || streamed.broken
        || funcs.is_empty()
        || funcs.len() != streamed.functions.len()
    {
        return None;
    }
    let mut m = robovec_ir::Module::default();
    for f in streamed.functions {
        if m.function(&f.name).is_some() {
            return None;
        }
        m.functions.push(f);
    }
    Some(m)
}

/// The tokens of `src` without comments and newlines, with the contents of every top-level
/// `{ … }` left out (the braces stay). `None` for unbalanced braces or a brace inside a
/// top-level parenthesis, where the file scanner's bracket matching on the outline could
/// differ from the one on every token.
fn outline<'s>(src: &'s str, clock: &Clock) -> Option<Vec<Spanned<'s>>> {
    let mut out = Vec::new();
    let (mut braces, mut parens) = (0usize, 0usize);
    for (t, r) in Tok::lexer(src).spanned() {
        if clock.tick(r.start) {
            return None;
        }
        let t = t.unwrap_or(Tok::Error);
        if ignored(&t) {
            continue;
        }
        let top = braces == 0;
        match t {
            Tok::LBrace if top && parens > 0 => return None,
            Tok::LBrace => braces += 1,
            Tok::RBrace => braces = braces.checked_sub(1)?,
            Tok::LParen if top => parens += 1,
            Tok::RParen if top => parens = parens.saturating_sub(1),
            _ => {}
        }
        if top || braces == 0 {
            out.push((r.start, t, r.end));
        }
    }
    (braces == 0).then_some(out)
}

/// Scans the body that starts at byte `start` (after its `{`) and ends at byte `end` (its
/// `}`) into `f`, lexing it [`WINDOW`] tokens at a time; each statement is lowered through
/// `stream`. False after a fatal error (as [`body`]). Stops early, returning true, once an
/// error is reported or a `switch` is seen: the file then goes to the batch path anyway.
pub(super) fn body_in_windows<'s>(
    src: &'s str,
    start: usize,
    end: usize,
    f: &mut FuncAst,
    errors: &mut Vec<FrontError>,
    stream: &mut Stream<'s>,
    clock: &Clock,
) -> bool {
    let text = &src[start..end];
    let mut toks = Tok::lexer(text)
        .spanned()
        .map(|(t, r)| (start + r.start, t.unwrap_or(Tok::Error), start + r.end))
        .filter(|t| !ignored(&t.1));
    let mut window: Vec<Spanned<'s>> = Vec::with_capacity(WINDOW + 64);
    let mut returned: Option<Span> = None;
    loop {
        window.clear();
        let mut last = true;
        for t in toks.by_ref() {
            window.push(t);
            if t.1 == Tok::Semi && window.len() >= WINDOW {
                last = false;
                break;
            }
        }
        // A window that is not the last ends with `;`: its end position is never read.
        if !body(src, &window, end, f, errors, Some(&mut *stream), &mut returned, clock) {
            return false;
        }
        if last || !errors.is_empty() || f.cases.is_some() || clock.stopped() {
            return true;
        }
    }
}
