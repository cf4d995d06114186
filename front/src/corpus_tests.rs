//! The public corpus: every straight-line file parses, every loop file is rejected with the
//! loop diagnostic, and the Frank segway figures of SPEC §3 hold.

use std::path::{Path, PathBuf};

use super::{language_of, parse_str, FrontError};

/// The Robotran corpus in `../shared` beside the workspace root (this crate sits one level below it).
const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/corpus/robotran");

/// Every `.c`, `.m`, `.py` file of the corpus (fails, never skips, when it is missing).
fn corpus_files() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in ["c", "matlab", "python"] {
        let d = Path::new(CORPUS).join(dir);
        let entries = std::fs::read_dir(&d).unwrap_or_else(|e| panic!("corpus folder {} missing: {e}", d.display()));
        for e in entries {
            let p = e.expect("readable corpus entry").path();
            if matches!(p.extension().and_then(|e| e.to_str()), Some("c" | "m" | "py")) {
                out.push(p);
            }
        }
    }
    out.sort();
    assert!(out.len() >= 30, "corpus looks incomplete: {} files", out.len());
    out
}

fn is_loop_file(p: &Path) -> bool {
    let n = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
    n.contains("accelred") || n.contains("invdynared")
}

fn parse_file(p: &Path) -> Result<robovec_ir::Module, Vec<FrontError>> {
    let src = std::fs::read(p).expect("readable corpus file");
    let header = std::fs::read(p.with_extension("h")).ok();
    let lang = language_of(p).expect("known extension");
    parse_str(lang, &src, if lang == super::Language::C { header.as_deref() } else { None })
}

#[test]
fn straight_line_files_parse_and_loop_files_are_rejected() {
    let mut failures = Vec::new();
    for p in corpus_files() {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string();
        match (parse_file(&p), is_loop_file(&p)) {
            (Ok(m), false) => {
                assert!(!m.functions.is_empty(), "{name}: no function");
                if let Err(errs) = robovec_ir::verifier::verify(&m) {
                    failures.push(format!(
                        "{name}: verifier: {:?}",
                        errs.iter().take(3).map(|e| e.message.clone()).collect::<Vec<_>>()
                    ));
                }
                let text = m.to_string();
                match robovec_ir::text::parse(&text) {
                    Ok(back) => {
                        for (a, b) in m.functions.iter().zip(&back.functions) {
                            assert_eq!(a.op_counts(), b.op_counts(), "{name}: .rvir round trip changes {}", a.name);
                            assert_eq!(a.outputs.len(), b.outputs.len(), "{name}: .rvir round trip changes {}", a.name);
                        }
                    }
                    Err(errs) => failures.push(format!("{name}: printed IR does not parse back: {:?}", errs.first())),
                }
                for f in &m.functions {
                    let stats = f.op_counts();
                    println!(
                        "{name}: {} equations={} ops={} (add {} sub {} mul {} div {} call {}) inputs={} outputs={}",
                        f.name,
                        f.equations.unwrap_or(0),
                        stats.total,
                        stats.add,
                        stats.sub,
                        stats.mul,
                        stats.div,
                        stats.call,
                        f.inputs.len(),
                        f.outputs.len()
                    );
                }
            }
            (Err(errs), false) => failures.push(format!(
                "{name}: {}",
                errs.iter().take(5).map(|e| e.to_string()).collect::<Vec<_>>().join("\n    ")
            )),
            (Ok(_), true) => failures.push(format!("{name}: loop file accepted")),
            (Err(errs), true) => {
                if !errs.iter().any(|e| e.message.contains("loop at line") && e.message.contains("straight-line")) {
                    failures.push(format!(
                        "{name}: no loop diagnostic: {:?}",
                        errs.iter().map(|e| &e.message).collect::<Vec<_>>()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn frank_segway_dirdyna_matches_spec() {
    let m = parse_file(&Path::new(CORPUS).join("c/frank_segway__mbs_dirdyna_Frank_segway.c")).expect("parses");
    assert_eq!(m.functions.len(), 1);
    let f = &m.functions[0];
    assert_eq!(f.name, "dirdyna");
    assert_eq!(f.equations, Some(924));
    let c = f.op_counts();
    assert_eq!((c.add, c.sub, c.mul, c.div, c.call, c.total), (954, 923, 2384, 0, 0, 4261));
}

/// Long mutation run over the corpus (`cargo test -p robovec --lib front -- --ignored`):
/// slices of real files with random edits; nothing may panic.
#[test]
#[ignore = "long fuzz run; run on demand"]
fn corpus_mutations_never_panic() {
    let files = corpus_files();
    let mut rng = robovec_ir::rng::SplitMix64::new(0x2545_F491_4F6C_DD1D);
    let mut next = move || rng.next_u64();
    let rounds: usize = std::env::var("FRONT_FUZZ_ROUNDS").ok().and_then(|s| s.parse().ok()).unwrap_or(20_000);
    for _ in 0..rounds {
        let p = &files[(next() as usize) % files.len()];
        let src = std::fs::read(p).expect("readable");
        let start = (next() as usize) % src.len();
        let len = 1 + (next() as usize) % 4000;
        let mut buf = src[start..(start + len).min(src.len())].to_vec();
        if next() % 2 == 0 {
            // keep the signature so that bodies get exercised
            buf = [&src[..src.len().min(2000)], &buf[..]].concat();
        }
        for _ in 0..(next() % 8) {
            let pos = (next() as usize) % (buf.len() + 1);
            let alphabet = b"()[];=+-*/,.\n\\%#{}-> \r0123456789swhileforcase:";
            let byte = alphabet[(next() as usize) % alphabet.len()];
            match next() % 3 {
                0 if pos < buf.len() => {
                    buf.remove(pos);
                }
                1 => buf.insert(pos, byte),
                _ if pos < buf.len() => buf[pos] = (next() & 0xff) as u8,
                _ => {}
            }
        }
        let lang = language_of(p).expect("known");
        match parse_str(lang, &buf, None) {
            Err(errs) => assert!(errs.iter().all(|e| e.span.end as usize <= buf.len().max(1))),
            Ok(m) => {
                if let Err(e) = robovec_ir::verifier::verify(&m) {
                    panic!(
                        "front output does not verify: {:?}\n{}",
                        e.first().map(|e| &e.message),
                        String::from_utf8_lossy(&buf)
                    );
                }
            }
        }
    }
}
