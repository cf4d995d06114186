//! Front-end diagnostics: a byte span into the original source, a message, a label and notes.

use codespan_reporting::diagnostic::{Diagnostic, Label};
use robovec_ir::Span;

/// One problem found in a Robotran file.
///
/// `span` is a byte range into the **original** bytes handed to [`super::parse_str`]; since
/// [`super::source_text`] keeps every byte offset, it also indexes the text the driver renders.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrontError {
    /// Offending text (byte offsets into the source).
    pub span: Span,
    /// What is wrong, lower case (`unknown function `tan``).
    pub message: String,
    /// Label on the offending text.
    pub label: String,
    /// What was expected, or where a related thing is.
    pub notes: Vec<String>,
}

impl FrontError {
    /// An error at `span`.
    pub fn new(span: Span, message: impl Into<String>, label: impl Into<String>) -> FrontError {
        FrontError { span, message: message.into(), label: label.into(), notes: Vec::new() }
    }

    /// Adds a note.
    pub fn note(mut self, note: impl Into<String>) -> FrontError {
        self.notes.push(note.into());
        self
    }

    /// A codespan diagnostic for this error in `file`.
    pub fn to_diagnostic<F: Copy>(&self, file: F) -> Diagnostic<F> {
        Diagnostic::error()
            .with_message(self.message.clone())
            .with_labels(vec![Label::primary(file, self.span.range()).with_message(self.label.clone())])
            .with_notes(self.notes.clone())
    }
}

impl std::fmt::Display for FrontError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (bytes {}..{}: {})", self.message, self.span.start, self.span.end, self.label)?;
        for n in &self.notes {
            write!(f, "; note: {n}")?;
        }
        Ok(())
    }
}

impl std::error::Error for FrontError {}
