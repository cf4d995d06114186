//! Input domains (issue 48 item 1): for each input of a function, the closed interval of real
//! values it may take — what the `range` pass encloses every value over, and what later
//! precision analyses bound errors over.
//!
//! A run's [`Domain`] is the input's **defaults** (a URDF's joint limits and model parameters,
//! `robovec_front::Loaded::domain_defaults`) overridden by a **ranges file** (`-ranges=FILE`,
//! or `range<ranges=FILE>`), read by [`parse_ranges`]: a JSON object of input name → `[lo, hi]`:
//!
//! ```json
//! {"q[3]": [-1.2, 2.5], "qd[*]": [-10, 10], "dpt[*][2]": [0.1, 0.1]}
//! ```
//!
//! A key is an exact canonical input name (SPEC §2) or a **glob** where each `*` stands for
//! one bracketed index or any run of characters without `[` or `]` (`qd[*]` matches `qd[4]`,
//! not `qdd[4]` nor `qd[1][2]`; `In[*][*]` matches every `In`). An exact key beats a glob;
//! of several globs matching one input the one with fewer `*` wins, then the later in the file.
//! A state copy of an input made by `interleave` (`q[3]#2`: state 2's `q[3]`) has its base
//! input's range: keys and defaults are matched against base names, and [`Domain::get`] maps
//! a suffixed name to its base (every state ranges over the same domain).
//! Units are the input's (rad, m, rad/s, N·m, kg …). Bounds are binary64 numbers, finite,
//! `lo ≤ hi` (`[x, x]` fixes an input at `x`). A glob that matches no input is allowed (one
//! file serves a family of models: `qdd[*]` for `dirdyna` and `invdyna`); an exact name that
//! names no input is an error (a typo would otherwise leave an input at its default).
//!
//! Errors are [`SourceError`]s located in the file's text: not JSON, not an object, a value
//! that is not a pair of finite numbers `lo ≤ hi`, a key given twice ([`parse_ranges`]); a key
//! that is an exact name of no input of the functions the run describes ([`resolve`]).

use std::collections::BTreeMap;

use crate::diagnostic::SourceError;
use crate::interval::Interval;
use crate::span::Span;
use crate::Function;

/// One input's range and where it came from.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Range {
    /// The closed interval of the input's values, in its units; finite ends, `lo ≤ hi`.
    pub interval: Interval,
    /// Where it came from, for reports and messages: `ranges.json: qd[*]`, `URDF <limit> of
    /// joint `yaw``, `URDF parameter value`.
    pub source: String,
}

/// The ranges of a run's inputs: exact canonical input name → [`Range`] (a name's range is the
/// same in every function of the module that has the input).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Domain {
    /// Input name → its range.
    pub ranges: BTreeMap<String, Range>,
}

impl Domain {
    /// The range of input `name`, if the domain gives one. A state copy of an input
    /// (`q[4]#2`, made by `interleave`; [`crate::function::split_state`]) has its base name's
    /// range unless the domain names the copy itself: every state ranges over the same domain.
    /// The one place a domain is looked up by name.
    pub fn get(&self, name: &str) -> Option<&Range> {
        self.ranges.get(name).or_else(|| match crate::function::split_state(name) {
            (base, k) if k > 0 => self.ranges.get(base),
            _ => None,
        })
    }

    /// The inputs of `f` the domain gives no range for, in input order.
    pub fn missing<'f>(&self, f: &'f Function) -> Vec<&'f str> {
        f.inputs.iter().map(|&v| f.name_of(v)).filter(|n| self.get(n).is_none()).collect()
    }

    /// `f`'s inputs with their ranges, in input order (those without a range left out).
    pub fn of_function<'d>(&'d self, f: &Function) -> Vec<(String, &'d Range)> {
        f.inputs.iter().filter_map(|&v| self.get(f.name_of(v)).map(|r| (f.name_of(v).to_string(), r))).collect()
    }
}

/// One key of a ranges file, as read.
#[derive(Clone, Debug, PartialEq)]
pub struct RangeKey {
    /// The key: an exact input name or a glob with `*`.
    pub key: String,
    /// Its interval.
    pub interval: Interval,
    /// The key's text in the file (byte offsets), for diagnostics.
    pub span: Span,
}

impl RangeKey {
    /// Number of `*` in the key (0: an exact name).
    pub fn stars(&self) -> usize {
        self.key.matches('*').count()
    }
}

/// True when glob `pattern` matches input name `name` (see the module doc: `*` matches one or
/// more characters other than `[` and `]`). Linear in the lengths for the patterns of inputs
/// (a `*` never crosses a bracket, so matching is greedy per segment with backtracking only
/// inside one bracket pair).
pub fn glob_matches(pattern: &str, name: &str) -> bool {
    fn go(p: &[u8], n: &[u8]) -> bool {
        match p.split_first() {
            None => n.is_empty(),
            Some((b'*', rest)) => {
                // One or more characters that are not brackets.
                let mut k = 0;
                while k < n.len() && n[k] != b'[' && n[k] != b']' {
                    k += 1;
                    if go(rest, &n[k..]) {
                        return true;
                    }
                }
                false
            }
            Some((&c, rest)) => n.first() == Some(&c) && go(rest, &n[1..]),
        }
    }
    go(pattern.as_bytes(), name.as_bytes())
}

/// Where the JSON key `key` (as written, with its quotes) first appears in `text` at or after
/// byte `from`: the span of the quoted key, or an empty span at `from` when it cannot be found
/// (a key written with escapes).
fn key_span(text: &str, key: &str, from: usize) -> Span {
    let quoted = format!("\"{key}\"");
    match text.get(from..).and_then(|t| t.find(&quoted)) {
        Some(at) => Span::new(from + at, from + at + quoted.len()),
        None => Span::new(from, from),
    }
}

/// An ordered JSON object with its duplicates kept (serde_json's map keeps the last).
struct Entries(Vec<(String, serde_json::Value)>);

impl<'de> serde::Deserialize<'de> for Entries {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Entries, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Entries;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON object of input name → [lo, hi]")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Entries, A::Error> {
                let mut out = Vec::new();
                while let Some(e) = map.next_entry::<String, serde_json::Value>()? {
                    out.push(e);
                }
                Ok(Entries(out))
            }
        }
        d.deserialize_map(V)
    }
}

/// What a ranges file's value must be.
const EXPECTED: &str = "expected [lo, hi]: two finite numbers with lo <= hi, such as \"q[1]\": [-3.14, 3.14]";

/// Reads a ranges file's text (see the module doc) into its keys, in file order.
///
/// # Errors
/// The first problem, located in `text`: JSON that does not parse (at serde_json's line and
/// column), a top level that is not an object, a value that is not `[lo, hi]` with finite
/// numbers and `lo ≤ hi`, an empty key, a key given twice.
pub fn parse_ranges(text: &str) -> Result<Vec<RangeKey>, SourceError> {
    let Entries(entries) = serde_json::from_str::<Entries>(text).map_err(|e| {
        let at = crate::span::offset_of_line_col(text, e.line(), e.column());
        SourceError::new(Span::new(at, at), format!("not a ranges file: {e}"), "here").note(
            "expected a JSON object of input name → [lo, hi], such as {\"q[1]\": [-3.14, 3.14], \"qd[*]\": [-10, 10]}",
        )
    })?;
    let mut keys: Vec<RangeKey> = Vec::with_capacity(entries.len());
    let mut from = 0;
    for (key, value) in entries {
        let span = key_span(text, &key, from);
        from = span.end as usize;
        if let Some(first) = keys.iter().find(|k| k.key == key) {
            let (line, _) = crate::span::line_col(text, first.span.start as usize);
            return Err(SourceError::new(span, format!("range of `{key}` given twice"), "second time")
                .note(format!("first given on line {line}")));
        }
        if key.is_empty() {
            return Err(SourceError::new(span, "empty input name", "this key").note(EXPECTED));
        }
        let pair = value.as_array().filter(|a| a.len() == 2).and_then(|a| Some((a[0].as_f64()?, a[1].as_f64()?)));
        let bad =
            |what: String| SourceError::new(span, format!("bad range for `{key}`: {what}"), "this key").note(EXPECTED);
        let Some((lo, hi)) = pair else { return Err(bad(format!("found {value}"))) };
        if !lo.is_finite() || !hi.is_finite() {
            return Err(bad(format!("[{lo}, {hi}] is not finite")));
        }
        if lo > hi {
            return Err(bad(format!("lo = {lo} is greater than hi = {hi}")));
        }
        keys.push(RangeKey { key, interval: Interval::new(lo, hi), span });
    }
    Ok(keys)
}

/// The domain of `inputs` (every input name of the functions the run describes): `defaults`
/// (name → range), overridden by the keys of a ranges file `file` (its name for sources, and
/// its keys; exact names beat globs, fewer `*` beat more, later beat earlier). Inputs neither
/// covers are left out ([`Domain::missing`] names them).
///
/// # Errors
/// A key of the file matching none of `inputs`, at the key (the inputs are named in a note).
pub fn resolve<'a>(
    defaults: &BTreeMap<String, Range>,
    file: Option<(&str, &[RangeKey])>,
    inputs: impl IntoIterator<Item = &'a str>,
) -> Result<Domain, SourceError> {
    // A state copy (`q[4]#2`) ranges as its base input: the domain holds base names only and
    // [`Domain::get`] maps a suffixed name to its base.
    let mut inputs: Vec<&str> = inputs.into_iter().map(|n| crate::function::split_state(n).0).collect();
    let mut seen = std::collections::HashSet::new();
    inputs.retain(|n| seen.insert(*n));
    let mut ranges = BTreeMap::new();
    for &name in &inputs {
        if let Some(r) = defaults.get(name) {
            ranges.insert(name.to_string(), r.clone());
        }
    }
    let Some((file_name, keys)) = file else { return Ok(Domain { ranges }) };
    let mut used = vec![false; keys.len()];
    for &name in &inputs {
        // The best key: fewest stars, then latest.
        let best = keys
            .iter()
            .enumerate()
            .filter(|(_, k)| if k.stars() == 0 { k.key == name } else { glob_matches(&k.key, name) })
            .min_by_key(|(i, k)| (k.stars(), usize::MAX - i));
        if let Some((i, k)) = best {
            used[i] = true;
            ranges.insert(name.to_string(), Range { interval: k.interval, source: format!("{file_name}: {}", k.key) });
        }
    }
    // Keys that matched an input but lost to a better key are still inputs' keys.
    for (i, k) in keys.iter().enumerate() {
        if !used[i] && inputs.iter().any(|&n| if k.stars() == 0 { k.key == n } else { glob_matches(&k.key, n) }) {
            used[i] = true;
        }
    }
    if let Some(k) = keys.iter().zip(&used).find(|(k, &u)| !u && k.stars() == 0).map(|(k, _)| k) {
        let shown: Vec<&str> = inputs.iter().take(8).copied().collect();
        let more = if inputs.len() > shown.len() {
            format!(" and {} more", inputs.len() - shown.len())
        } else {
            String::new()
        };
        return Err(SourceError::new(k.span, format!("`{}`: no input is named so", k.key), "this key")
            .note(format!("the inputs are {}{more}", shown.join(", ")))
            .note(
                "a key is an input's canonical name (`q[3]`, `dpt[1][2]`) or a glob with `*` for an index (`qd[*]`)",
            ));
    }
    Ok(Domain { ranges })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_one_index_per_star() {
        assert!(glob_matches("qd[*]", "qd[4]"));
        assert!(glob_matches("qd[*]", "qd[12]"));
        assert!(!glob_matches("qd[*]", "qdd[4]"));
        assert!(!glob_matches("qd[*]", "qd[1][2]"));
        assert!(!glob_matches("qd[*]", "qd[]"));
        assert!(glob_matches("dpt[*][2]", "dpt[3][2]"));
        assert!(!glob_matches("dpt[*][2]", "dpt[3][12]"));
        assert!(glob_matches("In[*][*]", "In[5][17]"));
        assert!(glob_matches("q[4]", "q[4]"));
    }

    #[test]
    fn exact_names_beat_globs_and_files_beat_defaults() {
        let text = r#"{"q[*]": [-1, 1], "q[2]": [0, 0.5], "m[*]": [1, 2]}"#;
        let keys = parse_ranges(text).unwrap();
        assert_eq!(keys.len(), 3);
        assert_eq!(&text[keys[1].span.range()], "\"q[2]\"");
        let mut defaults = BTreeMap::new();
        let d = |x: f64| Range { interval: Interval::point(x), source: "default".into() };
        defaults.insert("m[1]".to_string(), d(3.0));
        defaults.insert("g[3]".to_string(), d(-9.81));
        let dom = resolve(&defaults, Some(("r.json", &keys)), ["q[1]", "q[2]", "m[1]", "g[3]", "qd[1]"]).unwrap();
        assert_eq!(dom.get("q[1]").unwrap().interval, Interval::new(-1.0, 1.0));
        assert_eq!(dom.get("q[2]").unwrap().interval, Interval::new(0.0, 0.5));
        assert_eq!(dom.get("q[2]").unwrap().source, "r.json: q[2]");
        assert_eq!(dom.get("m[1]").unwrap().interval, Interval::new(1.0, 2.0), "the file overrides a default");
        assert_eq!(dom.get("g[3]").unwrap().interval, Interval::point(-9.81));
        assert!(dom.get("qd[1]").is_none());
    }

    #[test]
    fn state_copies_range_as_their_base_input() {
        let keys = parse_ranges(r#"{"q[*]": [-1, 1], "m[1]": [2, 3]}"#).unwrap();
        // The names of an interleaved function: base names and their state copies.
        let dom = resolve(&BTreeMap::new(), Some(("r.json", &keys)), ["q[1]", "q[1]#1", "m[1]#2", "m[1]"]).unwrap();
        assert_eq!(dom.ranges.len(), 2, "the domain holds base names only");
        assert_eq!(dom.get("q[1]#1").unwrap().interval, Interval::new(-1.0, 1.0));
        assert_eq!(dom.get("m[1]#2").unwrap().interval, Interval::new(2.0, 3.0));
        assert_eq!(dom.get("m[1]#2").unwrap().source, "r.json: m[1]");
        assert!(dom.get("qd[1]#1").is_none());
        // An exact key of a base name that only state copies carry still names an input.
        let keys = parse_ranges(r#"{"m[1]": [2, 3]}"#).unwrap();
        let dom = resolve(&BTreeMap::new(), Some(("r.json", &keys)), ["m[1]#1"]).unwrap();
        assert!(dom.get("m[1]#1").is_some());
    }

    #[test]
    fn bad_files_are_located() {
        let e = parse_ranges("{\"q[1]\": [2, 1]}").unwrap_err();
        assert!(e.message.contains("lo = 2 is greater than hi = 1"), "{e}");
        assert_eq!(e.span, Span::new(1, 7));
        let e = parse_ranges("{\"q[1]\": [0, 1],\n \"q[2]\": [0]}").unwrap_err();
        assert!(e.message.contains("bad range for `q[2]`: found [0]"), "{e}");
        assert_eq!(e.span, Span::new(18, 24));
        let e = parse_ranges("{\"q[1]\": [0, 1e999]}").unwrap_err();
        assert!(e.message.contains("bad range") || e.message.contains("not a ranges file"), "{e}");
        let e = parse_ranges("{\"q[1]\": [0, 1],\n\"q[1]\": [0, 2]}").unwrap_err();
        assert!(e.message.contains("given twice") && e.notes[0].contains("line 1"), "{e:?}");
        let e = parse_ranges("{\"q[1]\": [0, 1]\n\"q[2]\": 3}").unwrap_err();
        assert!(e.message.starts_with("not a ranges file"), "{e}");
        assert_eq!(e.span.start, 16, "line 2, column 1");
        let keys = parse_ranges("{\"qq[1]\": [0, 1]}").unwrap();
        let e = resolve(&BTreeMap::new(), Some(("r.json", &keys)), ["q[1]"]).unwrap_err();
        assert!(e.message.contains("`qq[1]`: no input is named so"), "{e}");
        // A glob that matches nothing is allowed (one file for a family of models).
        let keys = parse_ranges("{\"qq[*]\": [0, 1], \"q[*]\": [2, 3]}").unwrap();
        let dom = resolve(&BTreeMap::new(), Some(("r.json", &keys)), ["q[1]"]).unwrap();
        assert_eq!(dom.get("q[1]").unwrap().interval, Interval::new(2.0, 3.0));
    }
}
