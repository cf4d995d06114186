//! C identifiers for the values of a function: Robotran's names where they are valid C
//! (`AlF15`, `S4`), otherwise sanitised (`q[4]` → `q_4`, `frc[2][11].1` → `frc_2_11_1`) and
//! made unique with a numeric suffix; never a C keyword or a name the generated file uses.

use robovec_ir::Function;
use std::collections::HashSet;

/// C keywords and names the emitters' files use themselves (libm, `memcpy`, macros of
/// `<math.h>`); a value named like one of them is renamed.
const RESERVED: &[&str] = &[
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    "_Bool",
    "_Complex",
    "_Imaginary",
    "sin",
    "cos",
    "sqrt",
    "sinf",
    "cosf",
    "sqrtf",
    "memcpy",
    "NAN",
    "INFINITY",
    "HUGE_VAL",
    "HUGE_VALF",
    "M_PI",
    "M_E",
    "errno",
    "EDOM",
    "ERANGE",
    "NULL",
    "lane",
];

/// True when `s` is a C identifier (letters, digits, `_`, not starting with a digit).
pub fn is_c_identifier(s: &str) -> bool {
    let mut ch = s.chars();
    ch.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_') && ch.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `q[4]` → `q_4`, `frc[2][11].1` → `frc_2_11_1`, `a-b` → `a_b`; a leading digit gets `v_`.
pub fn sanitise(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        match c {
            ']' => {}
            c if c.is_ascii_alphanumeric() || c == '_' => s.push(c),
            _ => s.push('_'),
        }
    }
    while s.ends_with('_') && s.len() > 1 {
        s.pop();
    }
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "v_");
    }
    s
}

/// One C identifier per value of `f` (indexed by `Value::index()`), distinct from each other,
/// from [`RESERVED`], from `extra_reserved` (the ABI's parameter names, the symbol, callback
/// names) and from names starting with `robovec_` (the emitters' helpers). Valid names are
/// kept first, so a sanitised name never takes a Robotran name.
pub fn c_names(f: &Function, extra_reserved: &[&str]) -> Vec<String> {
    let mut taken: HashSet<String> = RESERVED.iter().chain(extra_reserved).map(|s| s.to_string()).collect();
    let free = |s: &str, taken: &HashSet<String>| !taken.contains(s) && !s.starts_with("robovec_");
    let mut out: Vec<Option<String>> = vec![None; f.values.len()];
    for (i, d) in f.values.iter().enumerate() {
        if is_c_identifier(&d.name) && free(&d.name, &taken) {
            taken.insert(d.name.clone());
            out[i] = Some(d.name.clone());
        }
    }
    for (i, d) in f.values.iter().enumerate() {
        if out[i].is_none() {
            let mut base = sanitise(&d.name);
            if base.starts_with("robovec_") {
                base.insert_str(0, "v_");
            }
            let name = if free(&base, &taken) {
                base
            } else {
                (2..).map(|k| format!("{base}_{k}")).find(|n| free(n, &taken)).expect("unbounded counter")
            };
            taken.insert(name.clone());
            out[i] = Some(name);
        }
    }
    out.into_iter().map(|n| n.expect("every value named")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn robotran_names_stay_and_others_become_unique_identifiers() {
        let m = parse(
            "func @f { input %q[4] input %q_4 input %in input %double input %robovec_x \
             %AlF15 = %q[4] * %q_4  %frc[2][11].1 = %AlF15 + %in  %x = %double - %robovec_x \
             output c[1] = %frc[2][11].1 output c[2] = %x }",
        )
        .unwrap();
        let f = &m.functions[0];
        let n = c_names(f, &["in", "out"]);
        let by = |s: &str| n[f.lookup(s).unwrap().index()].clone();
        assert_eq!(by("AlF15"), "AlF15");
        assert_eq!(by("q_4"), "q_4", "a valid name keeps its name");
        assert_eq!(by("q[4]"), "q_4_2", "the sanitised name does not take it");
        assert_eq!(by("frc[2][11].1"), "frc_2_11_1");
        assert_eq!(by("in"), "in_2");
        assert_eq!(by("double"), "double_2");
        assert_eq!(by("robovec_x"), "v_robovec_x");
        let set: HashSet<&String> = n.iter().collect();
        assert_eq!(set.len(), n.len());
        assert!(n.iter().all(|s| is_c_identifier(s)));
    }
}
