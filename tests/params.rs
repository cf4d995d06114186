//! Issue 10 item 5: each parameter's default and range are declared once; `--print-passes`
//! prints them from the declaration.

use std::process::Command;

use robovec_passes::PASSES;

#[test]
fn print_passes_shows_every_declared_default_and_range() {
    let o = Command::new(env!("CARGO_BIN_EXE_robovec-opt")).arg("--print-passes").output().unwrap();
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8(o.stdout).unwrap();
    for info in PASSES {
        for p in info.params {
            let line = format!("      {:<12} (default {}; {}) {}", p.name, p.default_text(), p.range_text(), p.doc);
            assert!(text.lines().any(|l| l == line), "no line `{line}` in:\n{text}");
        }
    }
    // The default eqsat really uses (`--print-passes` said 8 while the code used 6).
    let window = robovec_passes::eqsat::EqsatOptions::default().window;
    assert!(text.contains(&format!("      window       (default {window}; 2..=64)")), "{text}");
}
