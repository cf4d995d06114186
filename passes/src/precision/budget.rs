//! `precision<budget=FILE>`: a budget per output (issue 48 item 5), absolute or relative.
//!
//! ```json
//! {"Qq[*]": {"abs": 1e-4}, "M[*][*]": {"rel": 1e-6}, "c[3]": 1e-5}
//! ```
//!
//! A key is an output's name or a glob (`*` for one bracketed index or a run of characters
//! without brackets, as in `-ranges` files: [`robovec_ir::domain::glob_matches`]); an exact name
//! beats a glob, fewer `*` beat more, a later key an earlier one. A value is `{"abs": x}`
//! (the output's units: N·m, m/s²…), `{"rel": x}` (relative to the largest magnitude of the
//! output's range over the domain) or a bare number (relative). Every budget is positive and
//! finite. Every output of the function must have a budget (those without are named), and an
//! exact key must name an output (a glob may match none: one file serves `invdyna` and
//! `dirdyna`).

use robovec_ir::domain::glob_matches;

/// One output's budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Budget {
    /// Absolute, in the output's units.
    Abs(f64),
    /// Relative to the largest magnitude of the output's range over the domain.
    Rel(f64),
}

impl Budget {
    /// The absolute budget of an output whose range has largest magnitude `mag`.
    pub fn absolute(self, mag: f64) -> f64 {
        match self {
            Budget::Abs(x) => x,
            Budget::Rel(r) => r * mag,
        }
    }
}

/// What `budget=` gives: one budget for every output, or a file's per output.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// The same budget for every output (`budget=1e-6`: relative).
    Every(Budget),
    /// A budget file.
    File(BudgetFile),
}

/// The keys of a budget file, in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct BudgetFile {
    /// Key and budget.
    pub keys: Vec<(String, Budget)>,
}

/// Reads a budget file's text (module doc).
///
/// # Errors
/// A message with the JSON error's line and column, or naming the key whose value is not a
/// budget.
pub fn parse(text: &str) -> Result<BudgetFile, String> {
    let v: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("line {}, column {}: {e}", e.line(), e.column()))?;
    let serde_json::Value::Object(map) = v else {
        return Err("not a budget file: expected a JSON object of output name → budget".into());
    };
    let mut keys = Vec::new();
    for (k, v) in map {
        let bad =
            || format!("bad budget for `{k}`: expected a positive number, {{\"abs\": x}} or {{\"rel\": x}}, found {v}");
        let b = match &v {
            serde_json::Value::Number(n) => Budget::Rel(n.as_f64().ok_or_else(bad)?),
            serde_json::Value::Object(o) if o.len() == 1 => match (o.get("abs"), o.get("rel")) {
                (Some(x), None) => Budget::Abs(x.as_f64().ok_or_else(bad)?),
                (None, Some(x)) => Budget::Rel(x.as_f64().ok_or_else(bad)?),
                _ => return Err(bad()),
            },
            _ => return Err(bad()),
        };
        let x = match b {
            Budget::Abs(x) | Budget::Rel(x) => x,
        };
        if !(x > 0.0 && x.is_finite()) {
            return Err(bad());
        }
        keys.push((k, b));
    }
    Ok(BudgetFile { keys })
}

impl BudgetFile {
    /// The budget of each of `outputs` (in order).
    ///
    /// # Errors
    /// A message naming the outputs without a budget, or an exact key that names no output.
    pub fn resolve(&self, outputs: &[&str]) -> Result<Vec<Budget>, String> {
        let stars = |k: &str| k.matches('*').count();
        let matches = |k: &str, n: &str| if stars(k) == 0 { k == n } else { glob_matches(k, n) };
        if let Some((k, _)) = self.keys.iter().find(|(k, _)| stars(k) == 0 && !outputs.contains(&k.as_str())) {
            return Err(format!("`{k}`: no output is named so"));
        }
        let mut out = Vec::with_capacity(outputs.len());
        let mut missing = Vec::new();
        for &n in outputs {
            let best = self
                .keys
                .iter()
                .enumerate()
                .filter(|(_, (k, _))| matches(k, n))
                .min_by_key(|(i, (k, _))| (stars(k), usize::MAX - i));
            match best {
                Some((_, (_, b))) => out.push(*b),
                None => missing.push(n),
            }
        }
        if !missing.is_empty() {
            let more = if missing.len() > 8 { format!(" and {} more", missing.len() - 8) } else { String::new() };
            missing.truncate(8);
            return Err(format!(
                "no budget for output{} {}{more}",
                if missing.len() == 1 { "" } else { "s" },
                missing.join(", ")
            ));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_resolve_exact_over_glob_and_values_read() {
        let f = parse(r#"{"Qq[*]": {"abs": 1e-4}, "Qq[2]": {"rel": 1e-6}, "M[*][*]": 2e-5}"#).unwrap();
        let b = f.resolve(&["Qq[1]", "Qq[2]", "M[3][1]"]).unwrap();
        assert_eq!(b, vec![Budget::Abs(1e-4), Budget::Rel(1e-6), Budget::Rel(2e-5)]);
        assert_eq!(Budget::Rel(0.5).absolute(200.0), 100.0);
        assert_eq!(Budget::Abs(1e-4).absolute(200.0), 1e-4);
        assert!(f.resolve(&["Qq[1]", "Qq[2]", "c[1]"]).unwrap_err().contains("no budget for output c[1]"));
        let f = parse(r#"{"Qq[9]": 1e-3, "Qq[*]": 1e-3}"#).unwrap();
        assert!(f.resolve(&["Qq[1]"]).unwrap_err().contains("`Qq[9]`: no output"));
        for bad in [r#"{"a": -1}"#, r#"{"a": {"abs": 0}}"#, r#"{"a": {"abs": 1, "rel": 2}}"#, r#"{"a": "x"}"#, "[1]"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
        assert!(parse("{\"a\": 1,\n}").unwrap_err().starts_with("line 2"));
    }
}
