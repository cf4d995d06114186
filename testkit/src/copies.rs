//! Independent copies of one Robotran Matlab function in one file: the scale benchmark's input
//! (issue 28: "WALK-MAN × 16", 588k ops).
//!
//! [`matlab_copies`] repeats the function's body `copies` times. In copy `k` (0-based) every
//! temporary (a name the body assigns, other than the state and output names) gets the suffix
//! `_xK` (`C4` → `C4_x3`; copy 0 keeps its names), and the indices of the state vectors `q`,
//! `qd`, `qdd` and of the outputs `c` (one index) and `M` (both indices) are shifted by
//! `k · n_joints`; the output arrays' `zeros(…)` sizes are scaled to match. Model constants
//! (`s.dpt`, `s.l`, `s.m`, `s.In`, `s.frc`, `s.trq`, `s.g`) are shared by every copy. Copy `k`'s
//! outputs are therefore copy 0's for the `k`-th block of the state: the copies are independent
//! DAGs of equal size (`copies` × the ops of one).

use std::collections::HashSet;

/// Names the copies share or shift instead of renaming.
const STATE: [&str; 3] = ["q", "qd", "qdd"];
const OUTPUTS: [&str; 2] = ["M", "c"];

/// `copies` independent copies of Robotran Matlab function `text` with `n_joints` joints (its
/// state vectors' length; 55 for the corpus's WALK-MAN): see the module doc. The header (up to
/// the first statement that reads the state) and the `end` trailer are written once.
///
/// Panics when `copies` is 0 or when a renamed temporary would collide with a name of the file
/// (test support: the inputs are known files).
pub fn matlab_copies(text: &str, copies: usize, n_joints: usize) -> String {
    assert!(copies > 0, "at least one copy");
    let lines: Vec<&str> = text.lines().collect();
    // The body: from the first `% ===== BEGIN task` line (or the first assignment to a temporary)
    // to the last line before a trailing `end`.
    let start = lines.iter().position(|l| l.contains("BEGIN task")).unwrap_or(0);
    let mut end = lines.len();
    while end > start && matches!(lines[end - 1].trim(), "" | "end" | "end;") {
        end -= 1;
    }
    let (head, body, tail) = (&lines[..start], &lines[start..end], &lines[end..]);
    let temporaries = assigned_names(body);
    let all_names: HashSet<String> = identifiers(text).into_iter().map(|(_, s)| s.to_string()).collect();
    let mut out = String::with_capacity(text.len() * copies + 64);
    for l in head {
        out.push_str(&scale_zeros(l, copies, n_joints));
        out.push('\n');
    }
    for k in 0..copies {
        let suffix = format!("_x{k}");
        if k > 0 {
            for t in &temporaries {
                assert!(!all_names.contains(&format!("{t}{suffix}")), "{t}{suffix} is already a name");
            }
        }
        for l in body {
            out.push_str(&rewrite_line(l, k, &suffix, n_joints, &temporaries));
            out.push('\n');
        }
    }
    for l in tail {
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// Names assigned by `NAME = …` statements, other than the state and output names.
fn assigned_names(body: &[&str]) -> HashSet<String> {
    let mut names = HashSet::new();
    for l in body {
        let t = l.trim_start();
        if t.starts_with('%') {
            continue;
        }
        let ident: String = t.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        if ident.is_empty() || ident.starts_with(|c: char| c.is_ascii_digit()) {
            continue;
        }
        let rest = t[ident.len()..].trim_start();
        if rest.starts_with('=') && !rest.starts_with("==") && !STATE.contains(&&*ident) && !OUTPUTS.contains(&&*ident)
        {
            names.insert(ident);
        }
    }
    names
}

/// Identifier tokens of `line` with their byte offsets (a `%` comment ends the line).
fn identifiers(line: &str) -> Vec<(usize, &str)> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i].is_ascii_alphabetic() || b[i] == b'_' {
            let s = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((s, &line[s..i]));
        } else if b[i].is_ascii_digit() {
            // A number (possibly with an exponent such as `1e5`): not an identifier.
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.') {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    out
}

/// One body line of copy `k`.
fn rewrite_line(line: &str, k: usize, suffix: &str, n: usize, temporaries: &HashSet<String>) -> String {
    if line.trim_start().starts_with('%') {
        return line.to_string();
    }
    let shift = k * n;
    let mut out = String::with_capacity(line.len() + 16);
    let mut last = 0;
    for (at, name) in identifiers(line) {
        let after = at + name.len();
        out.push_str(&line[last..at]);
        last = after;
        let member = at > 0 && line.as_bytes()[at - 1] == b'.';
        if member {
            out.push_str(name);
        } else if k > 0 && temporaries.contains(name) {
            out.push_str(name);
            out.push_str(suffix);
        } else if STATE.contains(&name) || OUTPUTS.contains(&name) {
            out.push_str(name);
            if let Some((indices, len)) = parse_indices(&line[after..]) {
                let shifted: Vec<String> = indices.iter().map(|i| (i + shift).to_string()).collect();
                out.push('(');
                out.push_str(&shifted.join(","));
                out.push(')');
                last = after + len;
            }
        } else {
            out.push_str(name);
        }
    }
    out.push_str(&line[last..]);
    out
}

/// `(i)` or `(i,j)` with integer literals at the start of `s`: the indices and the length.
fn parse_indices(s: &str) -> Option<(Vec<usize>, usize)> {
    let rest = s.strip_prefix('(')?;
    let close = rest.find(')')?;
    let indices: Option<Vec<usize>> = rest[..close].split(',').map(|p| p.trim().parse().ok()).collect();
    Some((indices?, close + 2))
}

/// `zeros(n,…)` in a header line scaled by `copies` where a dimension equals `n` (the outputs'
/// allocation: `M = zeros(55,55)`, `c = zeros(55,1)`).
fn scale_zeros(line: &str, copies: usize, n: usize) -> String {
    let Some(at) = line.find("zeros(") else { return line.to_string() };
    let Some((dims, len)) = parse_indices(&line[at + 5..]) else { return line.to_string() };
    let dims: Vec<String> = dims.iter().map(|&d| if d == n { d * copies } else { d }.to_string()).collect();
    format!("{}zeros({}){}", &line[..at], dims.join(","), &line[at + 5 + len..])
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "function [M,c] = f(s)\n M = zeros(2,2);\n c = zeros(2,1);\nq = s.q;\n% ===== BEGIN task 0 =====\n  C1 = cos(q(1));\n  M(1,2) = C1*s.m(2);\n  c(2) = C1+qd(2)+S1e; % S1e\n% ====== END Task 0 ======\nend\n";

    #[test]
    fn copies_rename_temporaries_and_shift_state_and_outputs() {
        let got = matlab_copies(SMALL, 3, 2);
        assert!(got.contains(" M = zeros(6,6);"), "{got}");
        assert!(got.contains(" c = zeros(6,1);"), "{got}");
        assert!(got.contains("  C1 = cos(q(1));"), "{got}");
        assert!(got.contains("  C1_x2 = cos(q(5));"), "{got}");
        assert!(got.contains("  M(5,6) = C1_x2*s.m(2);"), "{got}");
        // `S1e` is not assigned in the body: a shared name, unchanged; the comment too.
        assert!(got.contains("  c(4) = C1_x1+qd(4)+S1e; % S1e"), "{got}");
        assert_eq!(got.matches("BEGIN task").count(), 3);
        assert!(got.ends_with("end\n"));
    }
}
