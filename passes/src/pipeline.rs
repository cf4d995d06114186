//! The pipeline text: `a,b<k=v;k2=v2>,c` (LLVM `opt -passes=` syntax, one nesting level).
//! Commas inside `<…>` belong to the parameter (`dce<outputs=Qq[1],Qq[2]>`).
//!
//! Named pipelines ([`NAMED`], LLVM's `default<O2>`): `default<depth>` and `default<ops>` stand
//! for a list of passes and may appear anywhere in a pipeline (`atomise,default<depth>,place`);
//! [`parse_pipeline`] expands them, so reports and `-time-passes` name the passes that ran.

use crate::PassError;

/// One element of a pipeline: a pass name and its raw parameters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PassSpec {
    /// Pass name.
    pub name: String,
    /// `(key, value)`; `value` is `None` for a bare flag.
    pub params: Vec<(String, Option<String>)>,
}

impl std::fmt::Display for PassSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.name)?;
        if !self.params.is_empty() {
            let ps: Vec<String> = self
                .params
                .iter()
                .map(|(k, v)| match v {
                    Some(v) => format!("{k}={v}"),
                    None => k.clone(),
                })
                .collect();
            write!(f, "<{}>", ps.join(";"))?;
        }
        Ok(())
    }
}

/// A named pipeline: what `-passes=` accepts in place of a pass, and the passes it stands for.
pub struct NamedPipeline {
    /// As written in a pipeline: `default<depth>`.
    pub name: &'static str,
    /// The passes it expands to (a pipeline text).
    pub expansion: &'static str,
    /// What it is for, with the measurements that chose it.
    pub doc: &'static str,
}

/// The named pipelines (issue 31 item 3), chosen by measurement on the public corpus's
/// `dirdyna` and `invdyna` files (`-stats`; coman, Frank_segway, Jeep, m454): `balance` after
/// `zero-removal` shortens every sum (coman 2057 → 744 cycles, Jeep 897 → 467, Segway 720 →
/// 350) at no op cost, and a `cse` after it merges the sums that balanced trees share (Jeep
/// 8 183 → 8 168 ops, m454 608 → 592); `recurrence` then restructures the chains through the
/// bodies (coman 744 → 475, Jeep 467 → 327, Segway 350 → 246, WALK-MAN 831 → 508: 0.23–0.54×
/// `atomise`'s critical path on every file, 0.83–1.32× its ops; `scripts/depth_corpus.sh`).
/// Without reassociation, `cse` before `zero-removal` gives fewer ops than after (Jeep 8 181
/// against 8 289), and `schedule-cpu` last makes the one-state C faster on every model and
/// flag set the codegen bench times (`cargo bench --bench codegen_c -- m454 frank_segway jeep
/// --flags=all --core`, docs/benchmarks.md): it changes the order only, so the outputs stay
/// bit for bit those of `atomise,cse,zero-removal,cse`.
pub const NAMED: &[NamedPipeline] = &[
    NamedPipeline {
        name: "default<depth>",
        expansion: "atomise,cse,zero-removal,balance,cse,recurrence,cse",
        doc: "the shortest critical path within 1.5x the ops (for place and codegen<fpga>): tree-height \
              reduction of every sum and product, then of the chains through the bodies",
    },
    NamedPipeline {
        name: "default<ops>",
        expansion: "atomise,cse,zero-removal,cse,schedule-cpu",
        doc: "the fewest ops without reassociation, in the order that needs the fewest registers (for one-state \
              C): shared terms merged, 0 − x folded into signs, the body reordered for a CPU (bit-exact)",
    },
];

/// Parses a pipeline text into its elements (names and parameters are not checked here),
/// named pipelines ([`NAMED`]) expanded in place.
///
/// # Errors
/// [`PassError::BadPipeline`] on empty elements, unbalanced `<>`, a malformed name, or
/// `default<…>` naming no pipeline of [`NAMED`].
pub fn parse_pipeline(text: &str) -> Result<Vec<PassSpec>, PassError> {
    let mut out = Vec::new();
    for spec in parse_elements(text)? {
        if spec.name != "default" {
            out.push(spec);
            continue;
        }
        let written = spec.to_string();
        let named = NAMED.iter().find(|n| n.name == written).ok_or_else(|| PassError::BadPipeline {
            pipeline: text.to_string(),
            message: format!(
                "`{written}` is no named pipeline; expected {}",
                NAMED.iter().map(|n| format!("`{}`", n.name)).collect::<Vec<_>>().join(" or ")
            ),
        })?;
        out.extend(parse_elements(named.expansion).expect("named pipelines parse"));
    }
    Ok(out)
}

/// [`parse_pipeline`] without the expansion of named pipelines.
fn parse_elements(text: &str) -> Result<Vec<PassSpec>, PassError> {
    let bad = |m: &str| PassError::BadPipeline { pipeline: text.to_string(), message: m.to_string() };
    let mut elems = Vec::new();
    let mut depth = 0i32;
    let mut start = 0;
    for (i, ch) in text.char_indices() {
        match ch {
            '<' => depth += 1,
            '>' => {
                depth -= 1;
                if depth < 0 {
                    return Err(bad("`>` without `<`"));
                }
            }
            ',' if depth == 0 => {
                elems.push(&text[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    if depth != 0 {
        return Err(bad("`<` without `>`"));
    }
    elems.push(&text[start..]);
    let mut out = Vec::new();
    for e in elems {
        let e = e.trim();
        if e.is_empty() {
            return Err(bad("empty pass name (stray comma?)"));
        }
        let (name, params) = match e.find('<') {
            Some(open) => {
                if !e.ends_with('>') || depth_after(&e[open..]) {
                    return Err(bad(&format!("`{e}`: parameters must close the element: name<k=v;…>")));
                }
                (&e[..open], &e[open + 1..e.len() - 1])
            }
            None => (e, ""),
        };
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(bad(&format!("`{name}` is not a pass name")));
        }
        let mut ps = Vec::new();
        for p in params.split(';').map(str::trim).filter(|p| !p.is_empty()) {
            match p.split_once('=') {
                Some((k, v)) => ps.push((k.trim().to_string(), Some(v.trim().to_string()))),
                None => ps.push((p.to_string(), None)),
            }
        }
        out.push(PassSpec { name: name.to_string(), params: ps });
    }
    Ok(out)
}

/// True when `<…>` closes before the end of `s` (i.e. text follows the parameters).
fn depth_after(s: &str) -> bool {
    let mut d = 0;
    for (i, c) in s.char_indices() {
        match c {
            '<' => d += 1,
            '>' => {
                d -= 1;
                if d == 0 && i + 1 != s.len() {
                    return true;
                }
            }
            _ => {}
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_and_commas_inside_brackets() {
        let p = parse_pipeline("atomise,dce<outputs=Qq[1],Qq[2]>,asap-alap<lat-add=10;lat-mul=5>").unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!(p[1].params, vec![("outputs".into(), Some("Qq[1],Qq[2]".into()))]);
        assert_eq!(p[2].to_string(), "asap-alap<lat-add=10;lat-mul=5>");
    }

    #[test]
    fn named_pipelines_expand_in_place() {
        let names = |t: &str| parse_pipeline(t).unwrap().iter().map(ToString::to_string).collect::<Vec<_>>();
        assert_eq!(names("default<depth>"), ["atomise", "cse", "zero-removal", "balance", "cse", "recurrence", "cse"]);
        assert_eq!(
            names("atomise,default<ops>,place<pe=16>"),
            ["atomise", "atomise", "cse", "zero-removal", "cse", "schedule-cpu", "place<pe=16>"]
        );
        for bad in ["default", "default<O2>", "default<depth;ops>", "default<depth=1>"] {
            let e = parse_pipeline(bad).unwrap_err().to_string();
            assert!(e.contains("no named pipeline") && e.contains("`default<depth>`"), "{bad}: {e}");
        }
        for n in NAMED {
            assert!(parse_pipeline(n.expansion).unwrap().iter().all(|s| s.name != "default"), "{}", n.name);
            for spec in parse_pipeline(n.expansion).unwrap() {
                assert!(crate::build_pass(&spec).is_ok(), "{}: {spec} builds", n.name);
            }
        }
    }

    #[test]
    fn malformed_pipelines_are_rejected() {
        for bad in ["", "atomise,", "a<b", "a>b", "a<x=1>b", "a b"] {
            assert!(parse_pipeline(bad).is_err(), "{bad:?} should be rejected");
        }
    }
}
