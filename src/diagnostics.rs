//! codespan-reporting glue: render diagnostics against one source file as plain text.
//!
//! # Long lines
//! A source line longer than [`MAX_LINE`] characters (a generated statement of a megabyte on one
//! line) is not quoted whole: the snippet shows a window of about [`MAX_LINE`] characters
//! around the labels on that line, with `…` where text was cut. The locus `file:line:col` and
//! the line numbers in the gutter stay those of the original file. Messages, labels and notes
//! longer than [`MAX_MESSAGE`] characters (a huge token quoted in a message) are shortened in the
//! middle the same way. A diagnostic thus takes a few hundred bytes per label at most.

use std::ops::Range;

use codespan_reporting::diagnostic::Diagnostic;
use codespan_reporting::files::{Error as FilesError, Files, Location, SimpleFile};
use codespan_reporting::term::{emit_into_string, Config};

/// Longest source line quoted whole in a diagnostic, characters; longer lines are windowed.
pub const MAX_LINE: usize = 240;
/// Longest message, label or note kept whole, characters; longer ones are cut in the middle.
pub const MAX_MESSAGE: usize = 300;

/// The cut marker.
const ELLIPSIS: &str = "…";

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
        SourceFile { name: name.into(), text: robovec_front::source_text(bytes) }
    }

    /// Renders diagnostics (no colour), each ending in a blank line; long lines and messages
    /// are shortened (see the module doc). At most [`MAX_SHOWN`] are shown, then one line
    /// `error: … and N more errors not shown (fix the first ones: later ones often follow
    /// from them)` (issue 29: one swapped line of a Python file gave 49 KB of cascading errors).
    pub fn render(&self, diags: &[Diagnostic<()>]) -> String {
        let config = Config::default();
        // Line starts are computed once for all the diagnostics.
        let file = SimpleFile::new(self.name.as_str(), self.text.as_str());
        let more = diags.len().saturating_sub(MAX_SHOWN);
        let tail = (more > 0).then(|| {
            format!(
                "error: … and {more} more errors not shown (fix the first ones: later ones often follow from them)\n"
            )
        });
        diags
            .iter()
            .take(MAX_SHOWN)
            .map(|d| {
                let d = shorten_messages(d);
                let rendered = match Windowed::new(&file, &d) {
                    Some((view, d)) => emit_into_string(&config, &view, &d),
                    None => emit_into_string(&config, &file, &d),
                };
                rendered.unwrap_or_else(|e| format!("error: {}\n(could not render: {e})\n", d.message))
            })
            .chain(tail)
            .collect()
    }
}

/// Diagnostics [`SourceFile::render`] shows at most.
pub const MAX_SHOWN: usize = 20;

/// `s` cut in the middle to at most about `max` characters.
fn shorten(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let keep = max / 2;
    let head: String = s.chars().take(keep).collect();
    let tail: String = s.chars().skip(n - keep).collect();
    format!("{head}{ELLIPSIS}{tail}")
}

fn shorten_messages(d: &Diagnostic<()>) -> Diagnostic<()> {
    let mut d = d.clone();
    d.message = shorten(&d.message, MAX_MESSAGE);
    for l in &mut d.labels {
        l.message = shorten(&l.message, MAX_MESSAGE);
    }
    for n in &mut d.notes {
        *n = shorten(n, MAX_MESSAGE);
    }
    d
}

/// One line of a [`Windowed`] view.
struct ViewLine {
    /// 0-based line index in the original text (`None`: a blank separator line).
    orig: Option<usize>,
    /// Byte range of the line's text in the view.
    view: Range<usize>,
    /// Byte range of the original shown (`orig_window.start` ↔ `view.start + prefix`).
    orig_window: Range<usize>,
    /// Bytes of the `…` prefix (0 when the line is shown from its start).
    prefix: usize,
}

/// A small text made of the lines a diagnostic's labels touch, long ones windowed, with the
/// original line and column numbers (a [`Files`] for codespan).
struct Windowed<'a> {
    /// The whole original file (its line index finds original lines).
    file: &'a SimpleFile<&'a str, &'a str>,
    text: String,
    lines: Vec<ViewLine>,
}

/// The original line (0-based) holding byte `at`, and its byte range (without the line end).
fn orig_line(file: &SimpleFile<&str, &str>, at: usize) -> (usize, Range<usize>) {
    let text = *file.source();
    let at = at.min(text.len());
    let index = file.line_index((), at).unwrap_or(0);
    let mut r = file.line_range((), index).unwrap_or(at..at);
    while r.end > r.start && matches!(text.as_bytes()[r.end - 1], b'\n' | b'\r') {
        r.end -= 1;
    }
    (index, r)
}

fn floor_char(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil_char(s: &str, mut i: usize) -> usize {
    while i < s.len() && !s.is_char_boundary(i) {
        i += 1;
    }
    i
}

impl<'a> Windowed<'a> {
    /// A view of the lines of `d`'s labels and `d` with its labels moved into the view; `None`
    /// when every such line is short (the plain file renders as it always did).
    fn new(file: &'a SimpleFile<&'a str, &'a str>, d: &Diagnostic<()>) -> Option<(Windowed<'a>, Diagnostic<()>)> {
        let text: &str = file.source();
        // Lines touched by a label (start and end), with the label offsets on each.
        let mut touched: Vec<(usize, Range<usize>, Vec<usize>)> = Vec::new();
        for l in &d.labels {
            for at in [l.range.start, l.range.end] {
                let (i, r) = orig_line(file, at);
                match touched.iter_mut().find(|t| t.0 == i) {
                    Some(t) => t.2.push(at.min(text.len())),
                    None => touched.push((i, r, vec![at.min(text.len())])),
                }
            }
        }
        if touched.iter().all(|t| text[t.1.clone()].chars().count() <= MAX_LINE) {
            return None;
        }
        touched.sort_by_key(|t| t.0);
        let mut w = Windowed { file, text: String::new(), lines: Vec::new() };
        let mut prev: Option<usize> = None;
        for (i, range, offsets) in &touched {
            if let Some(p) = prev {
                if *i > p + 1 {
                    // Two blank lines: codespan shows a break (`·`) between distant lines.
                    for _ in 0..2 {
                        let at = w.text.len();
                        w.lines.push(ViewLine { orig: None, view: at..at, orig_window: 0..0, prefix: 0 });
                        w.text.push('\n');
                    }
                }
            }
            prev = Some(*i);
            let line = &text[range.clone()];
            let (win, prefix, suffix) = if line.chars().count() <= MAX_LINE {
                (range.clone(), false, false)
            } else {
                // Centre on the first label offset of this line.
                let centre = offsets.iter().copied().min().unwrap_or(range.start);
                let half = MAX_LINE / 2;
                let lo = floor_char(text, centre.saturating_sub(half).max(range.start));
                let hi = ceil_char(text, (lo + MAX_LINE).min(range.end));
                let lo = floor_char(text, hi.saturating_sub(MAX_LINE).max(range.start).min(lo));
                (lo..hi, lo > range.start, hi < range.end)
            };
            let at = w.text.len();
            let prefix_len = if prefix { ELLIPSIS.len() } else { 0 };
            if prefix {
                w.text.push_str(ELLIPSIS);
            }
            w.text.push_str(&text[win.clone()]);
            if suffix {
                w.text.push_str(ELLIPSIS);
            }
            let end = w.text.len();
            w.text.push('\n');
            w.lines.push(ViewLine { orig: Some(*i), view: at..end, orig_window: win, prefix: prefix_len });
        }
        let mut d = d.clone();
        for l in &mut d.labels {
            l.range = w.to_view(l.range.start)..w.to_view(l.range.end);
            if l.range.end < l.range.start {
                l.range.end = l.range.start;
            }
        }
        Some((w, d))
    }

    /// The view offset of original byte `at` (clamped into its line's window).
    fn to_view(&self, at: usize) -> usize {
        let (i, _) = orig_line(self.file, at);
        let l = self.lines.iter().find(|l| l.orig == Some(i)).expect("every label line is in the view");
        let at = at.clamp(l.orig_window.start, l.orig_window.end);
        l.view.start + l.prefix + (at - l.orig_window.start)
    }

    fn view_line(&self, byte: usize) -> usize {
        self.lines.iter().rposition(|l| l.view.start <= byte).unwrap_or(0)
    }
}

impl<'a> Files<'a> for Windowed<'_> {
    type FileId = ();
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, (): ()) -> Result<&'a str, FilesError> {
        Ok(self.file.name())
    }

    fn source(&'a self, (): ()) -> Result<&'a str, FilesError> {
        Ok(&self.text)
    }

    fn line_index(&'a self, (): (), byte_index: usize) -> Result<usize, FilesError> {
        Ok(self.view_line(byte_index))
    }

    fn line_number(&'a self, (): (), line_index: usize) -> Result<usize, FilesError> {
        let l =
            self.lines.get(line_index).ok_or(FilesError::LineTooLarge { given: line_index, max: self.lines.len() })?;
        Ok(l.orig.map_or(0, |i| i + 1))
    }

    fn location(&'a self, (): (), byte_index: usize) -> Result<Location, FilesError> {
        let l = &self.lines[self.view_line(byte_index)];
        let Some(i) = l.orig else { return Ok(Location { line_number: 0, column_number: 0 }) };
        // The original offset, then the original column (characters from the line start, 1-based).
        let off = byte_index.saturating_sub(l.view.start + l.prefix).min(l.orig_window.len());
        let orig = l.orig_window.start + off;
        let (_, line) = orig_line(self.file, orig);
        let column = self.file.source()[line.start..orig].chars().count() + 1;
        Ok(Location { line_number: i + 1, column_number: column })
    }

    fn line_range(&'a self, (): (), line_index: usize) -> Result<Range<usize>, FilesError> {
        let l =
            self.lines.get(line_index).ok_or(FilesError::LineTooLarge { given: line_index, max: self.lines.len() })?;
        Ok(l.view.start..(l.view.end + 1).min(self.text.len()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use codespan_reporting::diagnostic::Label;

    #[test]
    fn a_long_line_is_windowed_with_the_original_line_and_column() {
        let long = format!("x = {};", "ab+".repeat(50_000));
        let text = format!("first line\n{long}\nlast\n");
        let src = SourceFile { name: "f.c".into(), text: text.clone() };
        let at = 11 + 4 + 3 * 49_000; // line 2, column 4 + 3·49000 + 1
        let d = Diagnostic::error()
            .with_message("bad")
            .with_labels(vec![Label::primary((), at..at + 2).with_message("here")]);
        let out = src.render(&[d]);
        assert!(out.len() < 1000, "{} bytes:\n{out}", out.len());
        assert!(out.contains(&format!("f.c:2:{}", 4 + 3 * 49_000 + 1)), "{out}");
        assert!(out.contains('…') && out.contains("ab+ab"), "{out}");
        assert!(out.contains("2 │"), "{out}");
    }

    #[test]
    fn short_lines_render_as_before() {
        let src = SourceFile { name: "f.c".into(), text: "a\nb = 1 $;\n".into() };
        let d =
            Diagnostic::error().with_message("bad").with_labels(vec![Label::primary((), 8..9).with_message("here")]);
        let out = src.render(std::slice::from_ref(&d));
        let plain = emit_into_string(&Config::default(), &SimpleFile::new("f.c", src.text.as_str()), &d).unwrap();
        assert_eq!(out, plain);
        assert!(out.contains("f.c:2:7"), "{out}");
    }
}
