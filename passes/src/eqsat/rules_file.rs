//! `rules=FILE`: extra rewrite rules for `eqsat`, read from a text file (format in
//! `docs/eqsat-rules.md`).
//!
//! ```text
//! # a comment
//! double: (* 2 ?x) => (+ ?x ?x)
//! drop-one: (* ?a ?b) => ?a if is-one ?b
//! ```
//!
//! One rule per line: `name: lhs => rhs [if COND [and COND]…]`. Patterns are s-expressions
//! over `+ - *` (two operands) and `neg` (one), pattern variables `?name` and decimal numbers.
//! Conditions are `const ?x`, `not-const ?x`, `nonzero ?x` and `is-one ?x`
//! ([`super::rules::CondKind`]). A bad file yields codespan diagnostics naming file, line, column
//! and what was expected; it never panics.

use std::path::Path;

use codespan_reporting::diagnostic::Diagnostic;
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term::{emit_into_string, Config};
use robovec_ir::{SourceError, Span};

use super::lang::{Const, Rewrite};
use super::rules::{make_rule, CondKind, Conds};

/// One rule as read from a file: texts of its patterns (egg syntax) and its conditions.
#[derive(Clone, Debug, PartialEq)]
pub struct RuleText {
    /// Rule name (kebab-case by convention).
    pub name: String,
    /// Left pattern, egg s-expression text.
    pub lhs: String,
    /// Right pattern.
    pub rhs: String,
    /// Conditions: (kind, variable with its `?`).
    pub conds: Vec<(CondKind, String)>,
}

/// A token of a line: its text and byte range in the file.
#[derive(Clone, Copy, Debug)]
struct Tok<'a> {
    text: &'a str,
    start: usize,
}

impl Tok<'_> {
    fn span(&self) -> Span {
        Span::new(self.start, self.start + self.text.len())
    }
}

fn tokens(line: &str, base: usize) -> Vec<Tok<'_>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices() {
        let delim = c.is_whitespace() || c == '(' || c == ')';
        if delim {
            if let Some(s) = start.take() {
                out.push(Tok { text: &line[s..i], start: base + s });
            }
            if c != ' ' && !c.is_whitespace() {
                out.push(Tok { text: &line[i..i + 1], start: base + i });
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push(Tok { text: &line[s..], start: base + s });
    }
    out
}

struct LineParser<'a> {
    toks: Vec<Tok<'a>>,
    pos: usize,
    end: usize,
    vars: Vec<String>,
}

type PResult<T> = Result<T, SourceError>;

impl<'a> LineParser<'a> {
    fn peek(&self) -> Option<Tok<'a>> {
        self.toks.get(self.pos).copied()
    }

    fn err_here(&self, what: &str, expected: &str) -> SourceError {
        let (span, found) = match self.peek() {
            Some(t) => (t.span(), format!("`{}`", t.text)),
            None => (Span::new(self.end, self.end), "end of line".to_string()),
        };
        SourceError::new(span, format!("{what}: expected {expected}, found {found}"), format!("expected {expected}"))
    }

    /// A pattern; `bind` records its variables (left side) or checks them (right side).
    fn pattern(&mut self, bind: bool) -> PResult<String> {
        let Some(t) = self.peek() else {
            return Err(self.err_here("incomplete pattern", "`(`, a `?variable` or a number"));
        };
        self.pos += 1;
        if t.text == "(" {
            let Some(op) = self.peek() else { return Err(self.err_here("incomplete pattern", "an operator")) };
            let arity = match op.text {
                "+" | "-" | "*" => 2,
                "neg" => 1,
                _ => return Err(self.err_here("unknown operator", "one of `+`, `-`, `*`, `neg`")),
            };
            self.pos += 1;
            let mut parts = vec![op.text.to_string()];
            for _ in 0..arity {
                if self.peek().is_some_and(|t| t.text == ")") {
                    return Err(self.err_here(&format!("`{}` takes {arity} operand(s)", op.text), "an operand"));
                }
                parts.push(self.pattern(bind)?);
            }
            if self.peek().is_none_or(|t| t.text != ")") {
                return Err(self.err_here(&format!("`{}` takes {arity} operand(s)", op.text), "`)`"));
            }
            self.pos += 1;
            return Ok(format!("({})", parts.join(" ")));
        }
        if let Some(name) = t.text.strip_prefix('?') {
            let ok = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ok {
                self.pos -= 1;
                return Err(self.err_here("bad pattern variable", "`?` followed by a letter and letters or digits"));
            }
            if bind {
                if !self.vars.iter().any(|v| v == t.text) {
                    self.vars.push(t.text.to_string());
                }
            } else if !self.vars.iter().any(|v| v == t.text) {
                return Err(SourceError::new(
                    t.span(),
                    format!("variable `{}` is not bound by the left-hand side", t.text),
                    "unbound variable",
                )
                .note(format!("the left-hand side binds: {}", self.vars.join(", "))));
            }
            return Ok(t.text.to_string());
        }
        match t.text.parse::<Const>() {
            Ok(c) => Ok(c.to_string()),
            Err(_) => {
                self.pos -= 1;
                Err(self.err_here("bad pattern", "`(`, a `?variable` or a finite number"))
            }
        }
    }

    fn expect(&mut self, text: &str, what: &str) -> PResult<()> {
        if self.peek().is_some_and(|t| t.text == text) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.err_here(what, &format!("`{text}`")))
        }
    }
}

/// Parses the text of a rules file.
///
/// # Errors
/// Every malformed line, as [`SourceError`]s with byte spans into `text`.
pub fn parse_rules(text: &str, taken: &[String]) -> Result<Vec<RuleText>, Vec<SourceError>> {
    let mut rules: Vec<RuleText> = Vec::new();
    let mut errors = Vec::new();
    let mut base = 0;
    for raw in text.split_inclusive('\n') {
        let line_start = base;
        base += raw.len();
        let line = raw.split('#').next().unwrap_or("").trim_end_matches(['\n', '\r']);
        if line.trim().is_empty() {
            continue;
        }
        match parse_line(line, line_start, taken, &rules) {
            Ok(r) => rules.push(r),
            Err(e) => errors.push(e),
        }
    }
    if errors.is_empty() {
        Ok(rules)
    } else {
        Err(errors)
    }
}

fn parse_line(line: &str, start: usize, taken: &[String], earlier: &[RuleText]) -> PResult<RuleText> {
    let lead = line.len() - line.trim_start().len();
    let Some(colon) = line.find(':') else {
        let end = start + line.trim_end().len();
        return Err(SourceError::new(
            Span::new(start + lead, end),
            "expected `name: lhs => rhs`, found no `:`",
            "expected a rule name followed by `:`",
        ));
    };
    let name = line[..colon].trim();
    let name_span = Span::new(start + lead, (start + lead + name.len()).max(start + colon));
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
        return Err(SourceError::new(
            name_span,
            format!("bad rule name `{name}`: expected letters, digits, `-` or `_`"),
            "expected a rule name",
        ));
    }
    if taken.iter().any(|t| t == name) || earlier.iter().any(|r| r.name == name) {
        return Err(SourceError::new(name_span, format!("rule `{name}` is defined twice"), "duplicate rule name")
            .note("names must differ from the built-in rules and from earlier rules of the file"));
    }
    let mut p = LineParser {
        toks: tokens(&line[colon + 1..], start + colon + 1),
        pos: 0,
        end: start + line.len(),
        vars: Vec::new(),
    };
    let lhs_at = p.peek();
    let lhs = p.pattern(true)?;
    if lhs.starts_with('?') {
        let t = lhs_at.expect("a pattern was read");
        return Err(SourceError::new(t.span(), "the left-hand side is a bare variable", "expected `(`")
            .note("a left-hand side must be an operator pattern or a number, or it would match everything"));
    }
    p.expect("=>", "after the left-hand side")?;
    let rhs = p.pattern(false)?;
    let mut conds = Vec::new();
    if p.peek().is_some() {
        p.expect("if", "after the right-hand side")?;
        loop {
            let kws: Vec<String> = CondKind::ALL.iter().map(|(k, _)| format!("`{k}`")).collect();
            let Some(kind) = p.peek().and_then(|t| CondKind::ALL.iter().find(|(k, _)| *k == t.text)) else {
                return Err(p.err_here("unknown condition", &format!("one of {}", kws.join(", "))));
            };
            p.pos += 1;
            let Some(v) = p.peek().filter(|t| t.text.starts_with('?')) else {
                return Err(p.err_here(&format!("condition `{}`", kind.0), "a `?variable`"));
            };
            if !p.vars.iter().any(|x| x == v.text) {
                return Err(SourceError::new(
                    v.span(),
                    format!("variable `{}` is not bound by the left-hand side", v.text),
                    "unbound variable",
                ));
            }
            p.pos += 1;
            conds.push((kind.1, v.text.to_string()));
            if p.peek().is_none() {
                break;
            }
            p.expect("and", "after a condition")?;
        }
    }
    Ok(RuleText { name: name.to_string(), lhs, rhs, conds })
}

/// Builds egg rewrites from parsed rules.
///
/// # Errors
/// egg's message for a rule it rejects (should not happen after [`parse_rules`]).
pub fn to_rewrites(rules: &[RuleText]) -> Result<Vec<Rewrite>, String> {
    rules
        .iter()
        .map(|r| {
            let conds = Conds(r.conds.iter().map(|(k, v)| (*k, v.parse().expect("checked variable"))).collect());
            make_rule(&r.name, &r.lhs, &r.rhs, conds).map_err(|e| format!("rule `{}`: {e}", r.name))
        })
        .collect()
}

/// Renders `errors` against `text` (no colour), one codespan diagnostic each.
pub fn render(name: &str, text: &str, errors: &[SourceError]) -> String {
    let file = SimpleFile::new(name, text);
    let config = Config::default();
    errors
        .iter()
        .map(|e| {
            let d: Diagnostic<()> = e.to_diagnostic(());
            emit_into_string(&config, &file, &d).unwrap_or_else(|_| format!("error: {}\n", e.message))
        })
        .collect()
}

/// Reads, checks and builds the rules of `path`; `existing` are the rules already in use
/// (their names are taken).
///
/// # Errors
/// A message ready for stderr: the file cannot be read, or rendered diagnostics.
pub fn load(path: &Path, existing: &[Rewrite]) -> Result<Vec<Rewrite>, String> {
    let shown = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read rules file `{shown}`: {e}"))?;
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let taken: Vec<String> = existing.iter().map(|r| r.name.to_string()).collect();
    let rules = parse_rules(&text, &taken)
        .map_err(|errs| format!("bad rules file `{shown}`\n{}", render(&shown, &text, &errs)))?;
    to_rewrites(&rules).map_err(|e| format!("bad rules file `{shown}`: {e}"))
}
