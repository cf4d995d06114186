//! codespan-reporting glue: render diagnostics against one source file as plain text.

use codespan_reporting::diagnostic::Diagnostic;
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term::{emit_into_string, Config};

/// One source text as shown in diagnostics: its display name and its text (invalid UTF-8 bytes
/// replaced one-for-one by `?`, so byte offsets stay those of the original file).
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// Path as given on the command line (`-` → `<stdin>`).
    pub name: String,
    /// The text.
    pub text: String,
}

impl SourceFile {
    /// Wraps raw bytes, replacing each byte of an invalid UTF-8 sequence by `?`.
    pub fn from_bytes(name: impl Into<String>, bytes: &[u8]) -> SourceFile {
        SourceFile { name: name.into(), text: crate::front::source_text(bytes) }
    }

    /// Renders diagnostics (no colour), each ending in a blank line.
    pub fn render(&self, diags: &[Diagnostic<()>]) -> String {
        let file = SimpleFile::new(self.name.as_str(), self.text.as_str());
        let config = Config::default();
        diags
            .iter()
            .map(|d| {
                emit_into_string(&config, &file, d)
                    .unwrap_or_else(|e| format!("error: {}\n(could not render: {e})\n", d.message))
            })
            .collect()
    }
}
