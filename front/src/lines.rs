//! The line-oriented front ends (Matlab, Python): logical lines lexed one at a time
//! ([`Lines`]), and the streaming path that lowers each statement as soon as its line is
//! scanned ([`scan_and_lower`]; issue 28 item 4, "memory ≤ 20× the input").
//!
//! # Why
//! The batch path held the whole file's tokens (40 bytes each), a copy without comments and
//! continuations, and every statement tree at once: WALK-MAN × 16 as Matlab (9.3 MB, 588k
//! ops) peaked at 445 MB through `atomise,asap-alap`, 48× the input. [`Lines`] keeps one
//! logical line's tokens (both paths read the file through it), and [`scan_and_lower`] hands
//! each statement to the lowering (`Lower`) and drops its tree, so what grows with the file
//! is the IR being built, as in the C front end's streaming path ([`crate::c::scan_and_lower`]).
//!
//! # Contract
//! [`scan_and_lower`] returns the module of the batch path ([`scan`] then
//! [`crate::lower::lower_module`]) or `None`: at the first error or poisoned statement, for a
//! file without functions, and for two functions of one name, the batch path runs from the
//! start and gives the diagnostics, which are the reference (`lines_tests.rs` checks both
//! paths on every corpus Matlab and Python file).

use logos::Logos;
use robovec_ir::{Function, Module};

use super::ast::FuncAst;
use super::clock::Clock;
use super::error::FrontError;
use super::lexer::{Spanned, Tok};
use super::lower::Lower;
use super::Language;

/// A line-oriented file scanner (Matlab's, Python's): fed each logical line, it groups the
/// statements into functions.
pub trait LineScanner: Default {
    /// The language it scans.
    const LANG: Language;
    /// Files one logical line (never empty; comments and continuations removed); problems go
    /// to `errors`.
    fn line(&mut self, src: &str, line: &[Spanned<'_>], errors: &mut Vec<FrontError>);
    /// The functions so far, the last one still open (statements are added to its `prefix`).
    fn funcs(&mut self) -> &mut Vec<FuncAst>;
}

/// The logical lines of a Matlab or Python file, lexed one at a time: comments dropped (`%`,
/// `#`), a continuation (`...` and the rest of its line; `\` at the end of a line) joins the
/// next line, empty lines skipped. Holds one line's tokens whatever the file's size.
pub struct Lines<'s, 'c> {
    lexer: logos::SpannedIter<'s, Tok<'s>>,
    lang: Language,
    clock: &'c Clock<'c>,
    /// A token read ahead (after `...` or `\`) that is not a newline.
    pending: Option<Spanned<'s>>,
    line: Vec<Spanned<'s>>,
}

impl<'s, 'c> Lines<'s, 'c> {
    /// The lines of `src` in `lang` (Matlab or Python); lexing stops at `clock`'s deadline
    /// (one tick per token).
    pub fn new(src: &'s str, lang: Language, clock: &'c Clock<'c>) -> Lines<'s, 'c> {
        Lines { lexer: Tok::lexer(src).spanned(), lang, clock, pending: None, line: Vec::new() }
    }

    fn token(&mut self) -> Option<Spanned<'s>> {
        if let Some(t) = self.pending.take() {
            return Some(t);
        }
        let (t, r) = self.lexer.next()?;
        if self.clock.tick(r.start) {
            return None;
        }
        Some((r.start, t.unwrap_or(Tok::Error), r.end))
    }

    /// The next logical line; `None` at the end of the file or once the deadline is reached.
    pub fn next_line(&mut self) -> Option<&[Spanned<'s>]> {
        let matlab = self.lang == Language::Matlab;
        self.line.clear();
        while let Some(t) = self.token() {
            match t.1 {
                Tok::Newline if self.line.is_empty() => {}
                Tok::Newline => return Some(&self.line),
                Tok::PercentComment if matlab => {}
                Tok::Hash(_) if !matlab => {}
                Tok::Ellipsis if matlab => match self.token() {
                    Some((_, Tok::Newline, _)) | None => {}
                    next => self.pending = next,
                },
                Tok::Backslash if !matlab => match self.token() {
                    Some((_, Tok::Newline, _)) => {}
                    next => {
                        self.line.push(t);
                        self.pending = next;
                    }
                },
                _ => self.line.push(t),
            }
        }
        (!self.line.is_empty()).then_some(&self.line)
    }
}

/// The batch path: every line of `src` through `S`; the functions with their statement trees.
/// Stops at `clock`'s deadline (one tick per token and per line).
pub fn scan<S: LineScanner>(src: &str, errors: &mut Vec<FrontError>, clock: &Clock) -> Vec<FuncAst> {
    let mut scanner = S::default();
    let mut lines = Lines::new(src, S::LANG, clock);
    while let Some(line) = lines.next_line() {
        if clock.tick(line[0].0) {
            break;
        }
        scanner.line(src, line, errors);
    }
    std::mem::take(scanner.funcs())
}

/// The streaming path: every line of `src` through `S`, each statement lowered as soon as its
/// line is filed; `None` where the batch path must decide (module doc) or at the deadline
/// (the caller asks the clock).
pub fn scan_and_lower<S: LineScanner>(src: &str, clock: &Clock) -> Option<Module> {
    let mut scanner = S::default();
    let mut lines = Lines::new(src, S::LANG, clock);
    let mut errors = Vec::new();
    let mut m = Module::default();
    // The function being lowered: its index in the scanner's list.
    let mut open: Option<(usize, Lower<'_>)> = None;
    let add = |m: &mut Module, f: Function| {
        let unique = m.function(&f.name).is_none();
        m.functions.push(f);
        unique
    };
    while let Some(line) = lines.next_line() {
        if clock.tick(line[0].0) {
            return None;
        }
        scanner.line(src, line, &mut errors);
        let funcs = scanner.funcs();
        if !errors.is_empty() || funcs.last().is_some_and(|f| !f.poisoned.is_empty() || f.cases.is_some()) {
            return None;
        }
        let Some(last) = funcs.len().checked_sub(1) else { continue };
        if open.as_ref().is_none_or(|(i, _)| *i != last) {
            if let Some((i, lower)) = open.take() {
                if !add(&mut m, finish(lower, &funcs[i], &mut errors)) {
                    return None;
                }
            }
            open = Some((last, Lower::new(src, S::LANG, &funcs[last])));
        }
        if let Some((_, lower)) = open.as_mut() {
            for s in funcs[last].prefix.drain(..) {
                lower.stmt(&s);
            }
        }
    }
    let funcs = scanner.funcs();
    if let Some((i, lower)) = open.take() {
        if !add(&mut m, finish(lower, &funcs[i], &mut errors)) {
            return None;
        }
    }
    (errors.is_empty() && !clock.stopped() && !m.functions.is_empty()).then_some(m)
}

/// The lowered function of `fa` (its span now covers its last line).
fn finish(mut lower: Lower<'_>, fa: &FuncAst, errors: &mut Vec<FrontError>) -> Function {
    lower.set_span(fa.span);
    lower.finish(fa.name.clone(), errors)
}
