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
        SourceFile { name: name.into(), text: lossless_len_text(bytes) }
    }

    /// Renders diagnostics (no colour), each ending in a blank line.
    pub fn render(&self, diags: &[Diagnostic<()>]) -> String {
        let file = SimpleFile::new(self.name.as_str(), self.text.as_str());
        let config = Config::default();
        diags
            .iter()
            .map(|d| emit_into_string(&config, &file, d).unwrap_or_else(|e| format!("error: {}\n(could not render: {e})\n", d.message)))
            .collect()
    }
}

/// UTF-8 text of the same byte length as `bytes`: every byte of an invalid sequence becomes `?`.
pub fn lossless_len_text(bytes: &[u8]) -> String {
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
                out.push_str(std::str::from_utf8(good).expect("valid prefix"));
                let n = e.error_len().unwrap_or(bad.len());
                out.extend(std::iter::repeat_n('?', n));
                rest = &bad[n..];
            }
        }
    }
}
