//! The token set shared by the three front ends (logos), lexed once over the whole file.
//!
//! Comments of every language are tokens, not skipped: each file scanner keeps the ones of
//! its language as comments and rejects the others (`%` in a C file is an error, `#` is a
//! preprocessor line in C and a comment in Python). Newlines are tokens too (they end Matlab
//! and Python statements; C ignores them). Blanks, CRs and a byte-order mark are skipped. A character that starts no token becomes
//! [`Tok::Error`] so that a scanner can report it in context instead of aborting.

use logos::Logos;

use super::clock::Clock;

/// A token of a Robotran file.
#[derive(Logos, Clone, Copy, Debug, PartialEq, Eq)]
#[logos(skip r"[ \t\f\r\x0b\u{FEFF}]+")]
pub enum Tok<'a> {
    /// `// …` to the end of the line (C comment).
    #[regex(r"//[^\n]*", allow_greedy = true)]
    SlashComment,
    /// `/* … */` (C block comment; not in the corpus but harmless).
    #[regex(r"/\*([^*]|\*+[^*/])*\*+/")]
    BlockComment,
    /// `% …` to the end of the line (Matlab comment).
    #[regex(r"%[^\n]*", allow_greedy = true)]
    PercentComment,
    /// `# …` to the end of the line: a C preprocessor line or a Python comment.
    #[regex(r"#[^\n]*", allow_greedy = true)]
    Hash(&'a str),
    /// `...` and the rest of its line (Matlab continuation).
    #[regex(r"\.\.\.[^\n]*", allow_greedy = true)]
    Ellipsis,
    /// `\` (Python continuation when it ends a line).
    #[token("\\")]
    Backslash,
    /// A line feed (a CR before it is skipped as blank).
    #[token("\n")]
    Newline,
    /// An identifier (keywords are identifiers too; scanners compare the text).
    #[regex(r"[A-Za-z_][A-Za-z0-9_]*")]
    Ident(&'a str),
    /// A number as written; trailing letters and extra dots are kept in the token so that
    /// `2.0.1` or `1e5` is reported as one bad number.
    #[regex(r"[0-9]+(\.[0-9]+)*[A-Za-z0-9_]*")]
    Number(&'a str),
    /// A string literal (`mbs_msg("…")`).
    #[regex(r#""([^"\\\n]|\\[^\n])*""#)]
    Str(&'a str),
    /// `(`
    #[token("(")]
    LParen,
    /// `)`
    #[token(")")]
    RParen,
    /// `[`
    #[token("[")]
    LBracket,
    /// `]`
    #[token("]")]
    RBracket,
    /// `{`
    #[token("{")]
    LBrace,
    /// `}`
    #[token("}")]
    RBrace,
    /// `,`
    #[token(",")]
    Comma,
    /// `;`
    #[token(";")]
    Semi,
    /// `:`
    #[token(":")]
    Colon,
    /// `=`
    #[token("=")]
    Eq,
    /// `+`
    #[token("+")]
    Plus,
    /// `-`
    #[token("-")]
    Minus,
    /// `*`
    #[token("*")]
    Star,
    /// `/`
    #[token("/")]
    Slash,
    /// `->`
    #[token("->")]
    Arrow,
    /// `.`
    #[token(".")]
    Dot,
    /// Any other punctuation (`<`, `&`, `!`, …): only in loop headers; reported by the scanner.
    #[regex(r"[<>!&|?~^@$'`]")]
    Punct,
    /// A character that starts no token (never produced by logos; see [`lex`]).
    Error,
}

impl std::fmt::Display for Tok<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            Tok::SlashComment => "//",
            Tok::BlockComment => "/*",
            Tok::PercentComment => "%",
            Tok::Hash(s) | Tok::Ident(s) | Tok::Number(s) | Tok::Str(s) => s,
            Tok::Ellipsis => "...",
            Tok::Backslash => "\\",
            Tok::Newline => "end of line",
            Tok::LParen => "(",
            Tok::RParen => ")",
            Tok::LBracket => "[",
            Tok::RBracket => "]",
            Tok::LBrace => "{",
            Tok::RBrace => "}",
            Tok::Comma => ",",
            Tok::Semi => ";",
            Tok::Colon => ":",
            Tok::Eq => "=",
            Tok::Plus => "+",
            Tok::Minus => "-",
            Tok::Star => "*",
            Tok::Slash => "/",
            Tok::Arrow => "->",
            Tok::Dot => ".",
            Tok::Punct => "punctuation",
            Tok::Error => "invalid character",
        };
        f.write_str(s)
    }
}

/// A token with its byte range `start..end` in the source.
pub type Spanned<'a> = (usize, Tok<'a>, usize);

/// Every token of `src`, including comments and newlines; unlexable text becomes [`Tok::Error`].
pub fn lex(src: &str) -> Vec<Spanned<'_>> {
    lex_where(src, |_| true)
}

/// The tokens of `src` for which `keep` holds (the C scanner drops comments and newlines while
/// lexing: the token vector is the largest structure of a batch parse, 40 bytes per token;
/// the streaming path, `super::c::scan_and_lower`, never builds it).
pub fn lex_where(src: &str, keep: impl Fn(&Tok<'_>) -> bool) -> Vec<Spanned<'_>> {
    lex_until(src, keep, &Clock::default())
}

/// [`lex_where`] that stops at `clock`'s deadline (one tick per token; the tokens so far are
/// returned and the clock says it stopped).
pub fn lex_until<'s>(src: &'s str, keep: impl Fn(&Tok<'_>) -> bool, clock: &Clock) -> Vec<Spanned<'s>> {
    Tok::lexer(src)
        .spanned()
        .take_while(|(_, r)| !clock.tick(r.start))
        .map(|(t, r)| (r.start, t.unwrap_or(Tok::Error), r.end))
        .filter(|t| keep(&t.1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(s: &str) -> Vec<Tok<'_>> {
        lex(s).into_iter().map(|t| t.1).collect()
    }

    #[test]
    fn lexes_accesses_and_numbers() {
        assert_eq!(
            kinds("x = s->dpt[2][4]*(2.0);"),
            vec![
                Tok::Ident("x"),
                Tok::Eq,
                Tok::Ident("s"),
                Tok::Arrow,
                Tok::Ident("dpt"),
                Tok::LBracket,
                Tok::Number("2"),
                Tok::RBracket,
                Tok::LBracket,
                Tok::Number("4"),
                Tok::RBracket,
                Tok::Star,
                Tok::LParen,
                Tok::Number("2.0"),
                Tok::RParen,
                Tok::Semi
            ]
        );
        assert_eq!(kinds("2.0.1"), vec![Tok::Number("2.0.1")]);
        assert_eq!(
            kinds("a*...\r\n b"),
            vec![Tok::Ident("a"), Tok::Star, Tok::Ellipsis, Tok::Newline, Tok::Ident("b")]
        );
        assert_eq!(kinds("a \\\n"), vec![Tok::Ident("a"), Tok::Backslash, Tok::Newline]);
        assert_eq!(kinds("\u{1}"), vec![Tok::Error]);
    }
}
