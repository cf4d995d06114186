//! Issue 27: the passes reference of the manual, `docs/passes.md`, is generated from the pass
//! registry (`robovec_passes::reference::markdown`, what `robovec-opt --print-passes=markdown`
//! prints) and fails here when the committed page drifts from the code.

use std::path::Path;

use robovec_backends::REGISTRY as PASSES;
use robovec_passes::ParamInfo;

use crate::common::{opt, stderr};

/// The committed page.
fn committed() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/passes.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_committed_passes_page_is_the_registrys() {
    let (page, generated) = (committed(), robovec_passes::reference::markdown(robovec_backends::REGISTRY));
    if page != generated {
        let first = page.lines().zip(generated.lines()).position(|(a, b)| a != b);
        let line = first.unwrap_or_else(|| page.lines().count().min(generated.lines().count()));
        panic!(
            "docs/passes.md differs from the pass registry from line {}:\n  committed: {:?}\n  registry:  {:?}\n\
             regenerate it with `cargo run -- --print-passes=markdown > docs/passes.md` and review the diff",
            line + 1,
            page.lines().nth(line).unwrap_or("(end of file)"),
            generated.lines().nth(line).unwrap_or("(end of file)"),
        );
    }
}

#[test]
fn print_passes_markdown_prints_the_page() {
    let o = opt(&["--print-passes=markdown"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(String::from_utf8(o.stdout).unwrap(), robovec_passes::reference::markdown(robovec_backends::REGISTRY));
    // The text listing is the default format, `--print-passes` bare.
    let bare = opt(&["--print-passes"]);
    let text = opt(&["--print-passes=text"]);
    assert!(bare.status.success() && text.status.success());
    assert_eq!(bare.stdout, text.stdout);
    assert_eq!(String::from_utf8(bare.stdout).unwrap(), robovec_passes::reference::text(robovec_backends::REGISTRY));
    let bad = opt(&["--print-passes=html"]);
    assert_eq!(bad.status.code(), Some(2), "{}", stderr(&bad));
}

/// The rows of the table that follows `heading` on `page`, up to the next heading.
fn rows_under<'a>(page: &'a str, heading: &str) -> Vec<&'a str> {
    let start = page.find(&format!("\n{heading}\n")).unwrap_or_else(|| panic!("no heading `{heading}`"));
    page[start + heading.len() + 2..]
        .lines()
        .take_while(|l| !l.starts_with('#'))
        .filter(|l| l.starts_with("| `"))
        .collect()
}

/// Checks a table against the declarations, read here from the registry's fields rather than
/// through the page's writer: one row per parameter, in order, with its default and range.
fn assert_rows(rows: &[&str], params: &[ParamInfo], what: &str) {
    assert_eq!(rows.len(), params.len(), "{what}: {rows:#?}");
    for (row, q) in rows.iter().zip(params) {
        assert!(row.starts_with(&format!("| `{}` |", q.name)), "{what}: {row}");
        let range = q.range_text().replace('|', "\\|");
        assert!(row.contains(&range), "{what}: `{}` lacks its range {range}: {row}", q.name);
        assert!(row.contains(&q.default_text().replace('|', "\\|")), "{what}: `{}` lacks its default: {row}", q.name);
    }
}

#[test]
fn the_page_has_every_pass_member_and_parameter() {
    let page = robovec_passes::reference::markdown(robovec_backends::REGISTRY);
    for p in PASSES {
        let own = rows_under(&page, &format!("## `{}`", p.name));
        assert_rows(&own, p.params, p.name);
        for q in p.params {
            for m in q.members() {
                let heading = format!("### `{}<{}>`: {} `{}`", p.name, m.name, q.name.replace('-', " "), m.name);
                assert_rows(&rows_under(&page, &heading), m.params, &heading);
            }
        }
    }
    // The back ends' parameters each appear under their own back end only.
    let c = rows_under(&page, "### `codegen<c>`: back end `c`");
    let fpga = rows_under(&page, "### `codegen<fpga>`: back end `fpga`");
    assert!(c.iter().any(|r| r.starts_with("| `abi` |")) && !c.iter().any(|r| r.starts_with("| `format` |")));
    assert!(fpga.iter().any(|r| r.starts_with("| `format` |")) && !fpga.iter().any(|r| r.starts_with("| `abi` |")));
}
