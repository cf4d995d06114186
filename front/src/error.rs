//! Front-end diagnostics: the IR's [`SourceError`](robovec_ir::SourceError) — a byte span into
//! the original source, a message, a label and notes.
//!
//! `span` is a byte range into the **original** bytes handed to [`super::parse_str`]; since
//! [`super::source_text`] keeps every byte offset, it also indexes the text the driver renders.

/// One problem found in a Robotran file.
pub use robovec_ir::SourceError as FrontError;
