//! The passes reference, read from a registry (the complete one is `robovec_backends::REGISTRY`;
//! this crate's own is [`crate::PASSES`]): the `--print-passes`
//! listing ([`text`]) and the manual's page `docs/passes.md` ([`markdown`]).
//!
//! Both walk the same declarations the parser and the passes' defaults read (every pass's
//! [`ParamInfo`]s and, for a pass family such as `codegen`, each [`crate::Member`]'s own), so the
//! listing, the page and the code cannot disagree; the root test `tests/passes_reference.rs`
//! fails when the committed page differs from [`markdown`].

use crate::pipeline::NAMED;
use crate::{ParamInfo, PassInfo, Registry};

/// The `--print-passes` listing: each pass and its parameters, one line each as
/// `name (default D; RANGE) doc`, and for a pass family each member (`back end c: …`) with its
/// own parameters.
pub fn text(registry: Registry) -> String {
    let line =
        |q: &ParamInfo| format!("      {:<12} (default {}; {}) {}\n", q.name, q.default_text(), q.range_text(), q.doc);
    let mut s = String::from("Passes (use -passes=a,b<k=v;k2=v2>,c):\n");
    for p in registry.iter() {
        s += &format!("  {:<12} {}\n", p.name, p.doc);
        for q in p.params {
            s += &line(q);
        }
        for (selector, m) in members(p) {
            s += &format!("    {} {}: {}\n", selector.replace('-', " "), m.name, m.doc);
            for x in m.params {
                s += &line(x);
            }
        }
    }
    s += "Named pipelines (usable anywhere in -passes=):\n";
    for n in NAMED {
        s += &format!("  {:<15} = {}\n      {}\n", n.name, n.expansion, n.doc);
    }
    s
}

/// `docs/passes.md`: a section per pass in registry order (its doc, then a table of its
/// parameters: name, default, accepted values, meaning with unit), a subsection per member of
/// a pass family. What `robovec-opt --print-passes=markdown` prints.
pub fn markdown(registry: Registry) -> String {
    let mut s = String::from(
        "# Passes\n\n\
         <!-- Generated from the pass registry (`robovec_backends::REGISTRY`) by\n     \
         `robovec-opt --print-passes=markdown > docs/passes.md`; do not edit by hand:\n     \
         `tests/passes_reference.rs` fails when this page and the registry differ. -->\n\n\
         Every pass robovec knows, in registry order, with its parameters as the parser reads them.\n\
         A pipeline is written `-passes=a,b<k=v;k2=v2>,c` (LLVM's syntax; a flag takes `on` or `off`,\n\
         a pass family's member is its first bare word: `codegen<c;abi=plain>`); an unknown\n\
         parameter, a value out of range or a parameter of another back end is bad usage (exit 2).\n\
         What each pass does, with its measurements, is on the topic pages of the\n\
         [manual](README.md).\n\n",
    );
    s += "| pass | what it does |\n|---|---|\n";
    for p in registry.iter() {
        s += &format!("| [`{}`](#{}) | {} |\n", p.name, p.name, cell(p.doc));
    }
    s += "\nNamed pipelines stand for a list of passes anywhere in a pipeline \
          (`-passes=atomise,default<depth>,place<pe=16>`; LLVM's `default<O2>`):\n\n\
          | pipeline | passes | what it is for |\n|---|---|---|\n";
    for n in NAMED {
        s += &format!("| `{}` | `{}` | {} |\n", n.name, n.expansion, cell(n.doc));
    }
    for p in registry.iter() {
        s += &format!("\n## `{}`\n\n{}\n", p.name, p.doc);
        s += &table(p.params);
        for (selector, m) in members(p) {
            s += &format!("\n### `{}<{}>`: {} `{}`\n\n{}\n", p.name, m.name, selector.replace('-', " "), m.name, m.doc);
            s += &table(m.params);
        }
    }
    s
}

/// The members of a pass family, each with the name of the selector that picks it.
fn members(p: &'static PassInfo) -> impl Iterator<Item = (&'static str, &'static crate::Member)> {
    p.params.iter().flat_map(|q| q.members().iter().map(move |m| (q.name, m)))
}

/// A parameter table, or a line saying there is none.
fn table(params: &[ParamInfo]) -> String {
    if params.is_empty() {
        return "\nNo parameters.\n".to_string();
    }
    let mut s = String::from("\n| parameter | default | accepted | meaning |\n|---|---|---|---|\n");
    for q in params {
        s += &format!("| `{}` | {} | {} | {} |\n", q.name, code(&q.default_text()), code(&q.range_text()), cell(q.doc));
    }
    s
}

/// `text` as a table cell: `|` escaped, so choices (`on|off`) stay in their column.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// A default or range as code, unless it is words (`the target's, de10-nano 12`) or already
/// quotes a name (`` `pe` ``).
fn code(text: &str) -> String {
    if text.contains(' ') || text.contains('`') {
        cell(text)
    } else {
        format!("`{}`", cell(text))
    }
}
