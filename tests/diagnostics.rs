//! Bad input → a codespan diagnostic (file, line, column, label, what was expected), exit
//! status 1, never a panic. One snapshot per file of `tests/inputs/bad/`.

#[test]
fn bad_inputs_render_diagnostics() {
    let dir = std::path::Path::new("tests/inputs/bad");
    let mut files: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert!(files.len() >= 10, "at least ten kinds of bad input");
    for p in files {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let path = format!("tests/inputs/bad/{name}");
        let failure = match robovec::driver::load(&path) {
            Ok(_) => panic!("{path} must be rejected"),
            Err(f) => f,
        };
        assert_eq!(failure.exit_code(), 1, "{path}");
        let msg = failure.message();
        assert!(msg.starts_with("error"), "{path}: {msg}");
        if !name.starts_with("empty") && !name.starts_with("garbage") {
            assert!(msg.contains(&format!("{path}:")), "{path}: the diagnostic names file:line:col\n{msg}");
        }
        insta::assert_snapshot!(name.replace('.', "_"), msg);
    }
}
