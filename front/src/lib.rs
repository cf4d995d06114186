//! robovec-front: the front ends. Robotran C, Matlab and Python outputs, URDF robot
//! descriptions ([`urdf`], through the symbolic generator of [`robovec_dynamics`]) and robovec's
//! own IR text → IR modules (parsed phase). The driver reaches them through one table,
//! [`registry::FRONT_ENDS`] ([`FrontEnd`], [`FrontOptions`], [`Loaded`]).
//!
//! # Dependencies
//! This crate may import `robovec-ir` (the IR it produces, its spans and source errors),
//! `robovec-passes` (only [`verify_accepted`]'s atomisation) and `robovec-dynamics` (the robot
//! model a URDF is parsed into and the generator that writes its equations); never the driver
//! (`robovec`), which depends on it.
//!
//! # Main modules
//! [`registry`] (the front-end table), [`c`], [`matlab`], [`python`] (the file scanners),
//! [`lines`] (the line-oriented languages' lines and streaming path),
//! [`lexer`], [`stmt`] and [`ast`] (the shared lexer, statement grammar and AST), [`lower`] (AST
//! → IR), [`urdf`] (URDF → robot → equations), [`sensor`], [`synth`] (synthetic files for the
//! scale tests and benches), [`error`] (diagnostics), [`clock`] (`-time-limit` while loading).
//!
//! # Pipeline
//! Naga style: the bytes are made text by [`source_text`] (every byte offset kept),
//! lexed once by the shared logos lexer ([`lexer`]), grouped into functions and logical
//! statements by the file scanner of the language ([`c`], [`matlab`], [`python`]), each
//! statement parsed by the shared lalrpop grammar (`expr.lalrpop`, glue in [`stmt`]) into the
//! language-agnostic [`ast`], and lowered to IR by [`lower`] (whose module doc states the
//! lowering rules). A C file without errors takes the streaming path ([`c::scan_and_lower`]):
//! its function bodies are lexed again a window at a time and each statement lowered as soon
//! as it is parsed, so memory does not grow with the tokens of a body; Matlab and Python files
//! are read a logical line at a time and take the same kind of path ([`lines`]).
//!
//! # Encoding
//! Input is bytes. Valid UTF-8 is kept; each byte of an invalid UTF-8 sequence (a Latin-1
//! `é` in a banner) becomes one `?`, so every span is a byte offset into the original bytes
//! *and* into the text. Render diagnostics over [`source_text`] of the same bytes (or any
//! conversion with the same property), not over `String::from_utf8_lossy`, whose U+FFFD
//! replacement is 3 bytes long. CRLF line ends are accepted everywhere (a CR is a blank).
#![deny(missing_docs)]

pub mod ast;
pub mod c;
pub mod clock;
pub mod error;
pub mod lexer;
pub mod lines;
pub mod lower;
pub mod matlab;
pub mod python;
pub mod registry;
pub mod scan;
pub mod sensor;
pub mod stmt;
pub mod synth;
pub mod urdf;

pub use error::FrontError;
pub use registry::{extension_list, front_end_for, FrontEnd, FrontOption, FrontOptions, Loaded, FRONT_ENDS};

/// A Robotran output language (the Robotran front ends' own parameter; the driver goes
/// through [`registry`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Language {
    /// C (`.c`, companion `.h`).
    C,
    /// Matlab (`.m`).
    Matlab,
    /// Python (`.py`).
    Python,
}

/// The Robotran language of a file from its extension: `.c`/`.h` → C, `.m` → Matlab, `.py` →
/// Python (the Robotran front ends' own map; the driver goes through [`registry`]).
pub fn language_of(path: &std::path::Path) -> Option<Language> {
    match path.extension()?.to_str()? {
        "c" | "h" => Some(Language::C),
        "m" => Some(Language::Matlab),
        "py" => Some(Language::Python),
        _ => None,
    }
}

/// The bytes as text with every byte offset kept: each byte of an invalid UTF-8 sequence
/// becomes `?` (see the module doc).
pub fn source_text(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len());
    let mut rest = bytes;
    loop {
        match std::str::from_utf8(rest) {
            Ok(s) => {
                out.push_str(s);
                return out;
            }
            Err(e) => {
                let (good, bad) = rest.split_at(e.valid_up_to());
                out.push_str(std::str::from_utf8(good).unwrap_or_default());
                let n = e.error_len().unwrap_or(bad.len()).max(1).min(bad.len());
                out.extend(std::iter::repeat_n('?', n));
                rest = &bad[n..];
            }
        }
    }
}

/// Most errors reported for one file (the rest are dropped: the first ones tell the story).
pub const MAX_ERRORS: usize = 100;

/// Parses a Robotran file into an IR module in `Phase::Parsed`.
///
/// `header` is the companion `.h` text of a C file (optional; its `double NAME;` lines are
/// declarations and only matter for `double *X;` pointers). Spans in errors are byte offsets
/// into `src`.
///
/// # Errors
/// Every problem found (up to [`MAX_ERRORS`]); no module is returned when there is one.
pub fn parse_str(lang: Language, src: &[u8], header: Option<&[u8]>) -> Result<robovec_ir::Module, Vec<FrontError>> {
    parse_text(lang, &source_text(src), header)
}

/// [`parse_str`] on text already made by [`source_text`] (the driver keeps that text for its
/// diagnostics and drops the bytes: one copy of the input, not three).
///
/// # Errors
/// As [`parse_str`].
pub fn parse_text(lang: Language, text: &str, header: Option<&[u8]>) -> Result<robovec_ir::Module, Vec<FrontError>> {
    parse_text_until(lang, text, header, None)
}

/// [`parse_text`] that stops at `deadline` (`-time-limit`): the lexer, the scanners and the
/// lowering tick a [`clock::Clock`] per token, line or statement.
///
/// # Errors
/// As [`parse_str`]; once the deadline is reached, only the error of [`clock::Clock::error`]
/// (`time limit of 5 s reached while reading (line N of M)`).
pub fn parse_text_until(
    lang: Language,
    text: &str,
    header: Option<&[u8]>,
    deadline: Option<&robovec_ir::time_limit::Deadline>,
) -> Result<robovec_ir::Module, Vec<FrontError>> {
    parse_with_clock(lang, text, header, &clock::Clock::new(deadline))
}

/// [`parse_text_until`] with the clock given.
fn parse_with_clock(
    lang: Language,
    text: &str,
    header: Option<&[u8]>,
    clock: &clock::Clock,
) -> Result<robovec_ir::Module, Vec<FrontError>> {
    let stopped = |clock: &clock::Clock| clock.error(text).map(|e| vec![e]);
    let mut errors = Vec::new();
    // The tokens live only while scanning: the statements own their text.
    let funcs = match lang {
        Language::C => {
            let header = header.map(source_text);
            // Statements lowered as soon as they are parsed, the bodies lexed a window at a
            // time; on any error (or a form it leaves out) the batch path below runs from the
            // start and gives the diagnostics.
            let streamed = c::scan_and_lower(text, header.as_deref(), clock);
            if let Some(e) = stopped(clock) {
                return Err(e);
            }
            if let Some(module) = streamed {
                return Ok(module);
            }
            let toks = lexer::lex_until(text, |t| !c::ignored(t), clock);
            c::scan(text, &toks, header.as_deref(), &mut errors, clock)
        }
        // As C: each statement lowered as soon as its line is scanned; on any error the batch
        // path below runs from the start ([`lines`]).
        Language::Matlab | Language::Python => {
            let streamed = match lang {
                Language::Matlab => lines::scan_and_lower::<matlab::Scanner>(text, clock),
                _ => lines::scan_and_lower::<python::Scanner>(text, clock),
            };
            if let Some(e) = stopped(clock) {
                return Err(e);
            }
            if let Some(module) = streamed {
                return Ok(module);
            }
            match lang {
                Language::Matlab => lines::scan::<matlab::Scanner>(text, &mut errors, clock),
                _ => lines::scan::<python::Scanner>(text, &mut errors, clock),
            }
        }
    };
    if let Some(e) = stopped(clock) {
        return Err(e);
    }
    if funcs.is_empty() && errors.is_empty() {
        errors.push(scan::no_function(lang, text.len()));
    }
    let module = lower::lower_module(text, lang, &funcs, &mut errors, clock);
    if let Some(e) = stopped(clock) {
        return Err(e);
    }
    if errors.is_empty() {
        Ok(module)
    } else {
        errors.sort_by_key(|e| (e.span.start, e.span.end));
        errors.truncate(MAX_ERRORS);
        Err(errors)
    }
}

#[cfg(test)]
mod clock_tests;
#[cfg(test)]
mod corpus_tests;
#[cfg(test)]
mod error_tests;
#[cfg(test)]
mod lines_tests;
#[cfg(test)]
mod snippet_tests;
#[cfg(test)]
mod stream_tests;

/// The contract every front end keeps, checked by the fuzz targets and property tests: a
/// module it returns verifies, atomises, and its atomised form verifies.
///
/// # Errors
/// A description of the first broken invariant.
pub fn verify_accepted(m: &robovec_ir::Module) -> Result<(), String> {
    robovec_ir::verifier::verify(m).map_err(|e| format!("front end returned a module that does not verify: {e:?}"))?;
    for f in &m.functions {
        let a = robovec_ir::transform::atomise::atomise_function(f);
        let errs = robovec_ir::verifier::verify_function(&a);
        if !errs.is_empty() {
            return Err(format!("atomised @{} does not verify: {errs:?}", f.name));
        }
    }
    Ok(())
}
