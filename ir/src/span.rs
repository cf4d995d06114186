//! Source spans: byte offsets into one source text.

/// A half-open byte range `start..end` into a source text (UTF-8 bytes, 0-based).
///
/// `Span::DUMMY` (0..0) marks entities made by passes rather than read from text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Span {
    /// First byte (inclusive).
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl Span {
    /// The span of entities that have no source text.
    pub const DUMMY: Span = Span { start: 0, end: 0 };

    /// A span from byte offsets; panics never, saturates offsets above `u32::MAX`.
    pub fn new(start: usize, end: usize) -> Span {
        let c = |x: usize| u32::try_from(x).unwrap_or(u32::MAX);
        Span { start: c(start), end: c(end.max(start)) }
    }

    /// The byte range, for codespan labels.
    pub fn range(self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span { start: self.start.min(other.start), end: self.end.max(other.end) }
    }
}

/// 1-based line of byte `offset` in `src` (offsets past the end count as the end). Cost: one
/// pass over the bytes before `offset`.
pub fn line_of(src: &str, offset: usize) -> usize {
    let offset = offset.min(src.len());
    1 + src.as_bytes()[..offset].iter().filter(|&&b| b == b'\n').count()
}

/// 1-based line and column of a byte offset in `src` (column counts chars).
pub fn line_col(src: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(src.len());
    let mut line = 1;
    let mut col = 1;
    for (i, ch) in src.char_indices() {
        if i >= offset {
            break;
        }
        if ch == '\n' {
            line += 1;
            col = 1;
        } else {
            col += 1;
        }
    }
    (line, col)
}

/// The byte offset of 1-based `line` and `column` (chars; serde_json's error positions) in
/// `src`: the start of the character there, clamped to the line's end and to `src`'s end
/// (column 0 is the line's start).
pub fn offset_of_line_col(src: &str, line: usize, column: usize) -> usize {
    let mut off = 0;
    for (i, text) in src.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            let col = column.saturating_sub(1);
            return off + text.char_indices().nth(col).map_or(text.len(), |(b, _)| b);
        }
        off += text.len();
    }
    src.len()
}
