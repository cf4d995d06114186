//! The pipeline text: `a,b<k=v;k2=v2>,c` (LLVM `opt -passes=` syntax, one nesting level).
//! Commas inside `<…>` belong to the parameter (`dce<outputs=Qq[1],Qq[2]>`).

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

/// Parses a pipeline text into its elements (names and parameters are not checked here).
///
/// # Errors
/// [`PassError::BadPipeline`] on empty elements, unbalanced `<>` or a malformed name.
pub fn parse_pipeline(text: &str) -> Result<Vec<PassSpec>, PassError> {
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
    fn malformed_pipelines_are_rejected() {
        for bad in ["", "atomise,", "a<b", "a>b", "a<x=1>b", "a b"] {
            assert!(parse_pipeline(bad).is_err(), "{bad:?} should be rejected");
        }
    }
}
