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

/// The section of ARCHITECTURE.md's code map for the crate in `folder`: from its heading
/// (`### \`folder/\` — …`) to the next heading.
fn section(folder: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let heading = format!("### `{folder}/`");
    let start = text.find(&heading).unwrap_or_else(|| panic!("no section {heading} in ARCHITECTURE.md"));
    let rest = &text[start + heading.len()..];
    let end = rest.find("\n#").unwrap_or(rest.len());
    rest[..end].to_string()
}

/// The main modules of a crate: the files and folders right under its `src/` but tests
/// (`*tests.rs`, `tests/`), the crate root and the binaries' folder.
fn main_modules(folder: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let src = if folder == "src" { root.join("src") } else { root.join(folder).join("src") };
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&src).expect("src folder") {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_dir = entry.file_type().unwrap().is_dir();
        if name.ends_with("tests.rs") || name == "tests" || name == "lib.rs" || name == "main.rs" || name == "bin" {
            continue;
        }
        if is_dir {
            out.push(format!("{name}/"));
        } else if name.ends_with(".rs") || name.ends_with(".lalrpop") {
            out.push(name);
        }
    }
    out.sort();
    out
}

/// Every `name.rs` or `name/` written in backticks in `text` (paths such as `c/file.rs` give
/// their last part and their folders).
fn named_paths(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for word in text.split('`').skip(1).step_by(2) {
        if word.contains(' ') || word.contains("::") {
            continue;
        }
        let parts: Vec<&str> = word.split('/').collect();
        for (i, p) in parts.iter().enumerate() {
            let last = i + 1 == parts.len();
            if last && (p.ends_with(".rs") || p.ends_with(".lalrpop")) {
                out.insert(p.to_string());
            } else if !p.is_empty() && (!last || word.ends_with('/')) {
                out.insert(format!("{p}/"));
            }
        }
    }
    out
}

/// Every file or folder with `name` (`x.rs` or `x/`) somewhere under `dir`.
fn exists_under(dir: &Path, name: &str) -> bool {
    let (want, is_dir) = match name.strip_suffix('/') {
        Some(d) => (d, true),
        None => (name, false),
    };
    let Ok(entries) = std::fs::read_dir(dir) else { return false };
    for e in entries.flatten() {
        if matches!(e.file_name().to_str(), Some("target" | ".git" | "fuzz")) {
            continue;
        }
        let path = e.path();
        let file_is_dir = path.is_dir();
        if e.file_name().to_string_lossy() == want && file_is_dir == is_dir {
            return true;
        }
        if file_is_dir && exists_under(&path, name) {
            return true;
        }
    }
    false
}

#[test]
fn the_module_lists_are_the_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (_, folder, _) in table() {
        let text = section(&folder);
        let named = named_paths(&text);
        for m in main_modules(&folder) {
            assert!(named.contains(&m), "ARCHITECTURE.md's section `{folder}/` does not name its module `{m}`");
        }
        let crate_dir = if folder == "src" { root.join("src") } else { root.join(&folder) };
        for n in &named {
            // Other crates' folders and files outside the crate (`hdl/`, `docs/`, …) are
            // named as such: only what the section presents as this crate's must exist in it.
            let elsewhere =
                ["ir/", "machine/", "passes/", "backends/", "front/", "dynamics/", "testkit/", "src/", "docs/"];
            if elsewhere.contains(&n.as_str()) {
                continue;
            }
            assert!(
                exists_under(&crate_dir, n) || exists_under(root, n),
                "ARCHITECTURE.md's section `{folder}/` names `{n}`, which is not in the repository"
            );
        }
    }
}
