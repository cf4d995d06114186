//! Errors of the `.rvir` reader, rendered with codespan-reporting.

use crate::span::Span;

/// Errors raised inside grammar actions and by the lexer adapter (byte offsets).
#[derive(Clone, Debug, PartialEq)]
pub enum GrammarError {
    /// Text that starts no token.
    Lex {
        /// First byte.
        start: usize,
        /// One past the last byte.
        end: usize,
    },
    /// A number that does not parse as what the position needs.
    BadNumber {
        /// First byte.
        start: usize,
        /// One past the last byte.
        end: usize,
        /// What was expected ("a finite number").
        what: &'static str,
    },
    /// A numeric format that is not one (`: f16`, `: fix<64,3>`).
    BadFormat {
        /// First byte.
        start: usize,
        /// One past the last byte.
        end: usize,
        /// What was expected.
        message: String,
    },
    /// A malformed `{…}` timing attribute.
    BadTiming {
        /// First byte.
        start: usize,
        /// One past the last byte.
        end: usize,
        /// The rule broken.
        message: String,
    },
}

/// An error reading `.rvir` text: where, what, and what was expected.
pub use crate::diagnostic::SourceError as ParseError;

fn expected_note(expected: &[String]) -> String {
    let shown: Vec<&str> = expected.iter().map(|s| s.trim_matches('"')).collect();
    format!("expected one of: {}", shown.join(", "))
}

impl ParseError {
    /// Converts lalrpop's error.
    pub fn from_lalrpop(
        e: lalrpop_util::ParseError<usize, super::lexer::Tok<'_>, GrammarError>,
        src_len: usize,
    ) -> ParseError {
        use lalrpop_util::ParseError as P;
        match e {
            P::InvalidToken { location } => {
                ParseError::new(Span::new(location, location + 1), "invalid token", "no token starts here")
            }
            P::UnrecognizedEof { location, expected } => {
                let at = location.min(src_len);
                ParseError::new(Span::new(at, at), "unexpected end of input", "input ends here")
                    .note(expected_note(&expected))
            }
            P::UnrecognizedToken { token: (l, t, r), expected } => {
                ParseError::new(Span::new(l, r), format!("unexpected `{t}`"), "not expected here")
                    .note(expected_note(&expected))
            }
            P::ExtraToken { token: (l, t, r) } => {
                ParseError::new(Span::new(l, r), format!("extra token `{t}`"), "not expected here")
            }
            P::User { error } => match error {
                GrammarError::Lex { start, end } => {
                    ParseError::new(Span::new(start, end), "invalid character", "no token starts here")
                }
                GrammarError::BadNumber { start, end, what } => {
                    ParseError::new(Span::new(start, end), "number does not parse", format!("expected {what}"))
                }
                GrammarError::BadFormat { start, end, message } => {
                    ParseError::new(Span::new(start, end), message, "not a numeric format")
                }
                GrammarError::BadTiming { start, end, message } => {
                    ParseError::new(Span::new(start, end), message, "in this timing attribute")
                }
            },
        }
    }
}
