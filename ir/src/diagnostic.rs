//! One error type for everything read from a source text (`.rvir`, Robotran C/Matlab/Python):
//! a byte span, a message, a label and notes, rendered with codespan-reporting.

use codespan_reporting::diagnostic::{Diagnostic, Label};

use crate::span::Span;

/// A problem at a place in a source text.
///
/// `span` is a byte range into the text as read (front ends keep every byte offset of the
/// original bytes, see `robovec_front::source_text`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct SourceError {
    /// The offending text (byte offsets).
    pub span: Span,
    /// What is wrong, lower case, stating the broken rule (``unknown function `tan` ``).
    pub message: String,
    /// Label on the offending text.
    pub label: String,
    /// What was expected, or where a related thing is.
    pub notes: Vec<String>,
}

impl SourceError {
    /// An error at `span`.
    pub fn new(span: Span, message: impl Into<String>, label: impl Into<String>) -> SourceError {
        SourceError { span, message: message.into(), label: label.into(), notes: Vec::new() }
    }

    /// Adds a note line.
    pub fn note(mut self, note: impl Into<String>) -> SourceError {
        self.notes.push(note.into());
        self
    }

    /// The codespan diagnostic for this error in `file`.
    pub fn to_diagnostic<F: Copy>(&self, file: F) -> Diagnostic<F> {
        Diagnostic::error()
            .with_message(&self.message)
            .with_labels(vec![Label::primary(file, self.span.range()).with_message(&self.label)])
            .with_notes(self.notes.clone())
    }
}
