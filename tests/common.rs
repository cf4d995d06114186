//! Helpers shared by the integration tests.
#![allow(dead_code, reason = "each test module uses a different subset")]

use std::path::PathBuf;

/// `../shared/corpus/robotran`; panics (so the test fails) when it is missing.
pub fn corpus_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/robotran");
    assert!(d.is_dir(), "the Robotran corpus is missing at {} (CI needs ../shared beside the repository)", d.display());
    d
}

/// Every corpus source file (`.c`, `.m`, `.py`), sorted.
pub fn corpus_files() -> Vec<PathBuf> {
    let mut v = Vec::new();
    for sub in ["c", "matlab", "python"] {
        for e in std::fs::read_dir(corpus_dir().join(sub)).expect("corpus folder") {
            let p = e.expect("dir entry").path();
            if p.extension().is_some_and(|x| x == "c" || x == "m" || x == "py") {
                v.push(p);
            }
        }
    }
    v.sort();
    assert!(v.len() >= 30, "corpus looks incomplete: {} files", v.len());
    v
}

/// True for the files with loops (accelred/invdynared), which front ends reject.
pub fn is_loop_file(p: &std::path::Path) -> bool {
    let n = p.file_name().unwrap().to_string_lossy();
    n.contains("accelred") || n.contains("invdynared")
}
