//! Issue 27: the crate graph of `ARCHITECTURE.md` ("Code map": crate, folder, what it may
//! import) is the one the manifests declare. Each crate's normal `[dependencies]` on robovec
//! crates must be exactly the table's row ("every crate below" for the driver), and the table's
//! order must be a layering: a crate imports only crates listed after it.

use std::collections::BTreeSet;
use std::path::Path;

/// `(crate, folder, may import)` rows of the code map table.
fn table() -> Vec<(String, String, Vec<String>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let start = text.find("| crate | folder | may import |").expect("the code map table in ARCHITECTURE.md");
    let names = |cell: &str| -> Vec<String> {
        cell.split('`').skip(1).step_by(2).filter(|w| w.starts_with("robovec")).map(str::to_string).collect()
    };
    text[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let krate = names(cells[1]).into_iter().next().expect("a crate name in the first column");
            let folder = cells[2].trim_matches('`').trim_end_matches('/').to_string();
            (krate, folder, names(cells[3]))
        })
        .collect()
}

/// The robovec crates in `[dependencies]` of the manifest in `folder` (`src` is the root's).
fn dependencies(folder: &str) -> BTreeSet<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = if folder == "src" { root.to_path_buf() } else { root.join(folder) };
    let text = std::fs::read_to_string(dir.join("Cargo.toml")).expect("Cargo.toml");
    let mut in_deps = false;
    let mut deps = BTreeSet::new();
    for line in text.lines() {
        if line.starts_with('[') {
            in_deps = line.trim() == "[dependencies]";
        } else if in_deps && line.starts_with("robovec") {
            deps.insert(line.split(['.', ' ', '=']).next().unwrap().to_string());
        }
    }
    deps
}

#[test]
fn the_code_map_is_the_crate_graph() {
    let rows = table();
    assert!(rows.len() >= 7, "{rows:?}");
    let workspace = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    for (i, (krate, folder, may)) in rows.iter().enumerate() {
        // The crates listed after this one, but the test-only kit (a dev-dependency at most).
        let below: BTreeSet<String> = rows[i + 1..].iter().filter(|r| r.1 != "testkit").map(|r| r.0.clone()).collect();
        let declared = dependencies(folder);
        let allowed: BTreeSet<String> =
            if may.is_empty() && krate == "robovec" { below.clone() } else { may.iter().cloned().collect() };
        assert_eq!(declared, allowed, "{krate} ({folder}/Cargo.toml) against ARCHITECTURE.md's code map");
        // Layering: the row names only crates listed after it (testkit, a dev-dependency, last).
        if folder != "testkit" {
            assert!(allowed.is_subset(&below), "{krate} may import a crate listed above it: {allowed:?}");
        }
        if folder != "src" {
            assert!(workspace.contains(&format!("\"{folder}\"")), "{folder} is not a workspace member");
        }
    }
}
