//! The streaming path of the C front end ([`super::c::scan_and_lower`]) gives the module of the
//! batch path ([`super::c::scan`] then [`super::lower::lower_module`]), and leaves the files it
//! does not cover (errors, `switch`, late declarations) to the batch path.

use super::clock::Clock;
use super::synth::{straight_line_c, Shape};
use super::{c, lexer, lower, Language};

fn batch(src: &str) -> (robovec_ir::Module, usize) {
    let toks = lexer::lex_where(src, |t| !c::ignored(t));
    let mut errors = Vec::new();
    let funcs = c::scan(src, &toks, None, &mut errors, &Clock::default());
    let m = lower::lower_module(src, Language::C, &funcs, &mut errors, &Clock::default());
    (m, errors.len())
}

fn streamed(src: &str) -> Option<robovec_ir::Module> {
    c::scan_and_lower(src, None, &Clock::default())
}

#[test]
fn streaming_equals_batch_on_a_generated_file() {
    let g = straight_line_c(Shape { bytes: 30_000, joints: 4, temps_per_output: 3, ops_per_temp: 4 });
    let (b, errors) = batch(&g.text);
    assert_eq!(errors, 0);
    let s = streamed(&g.text).expect("a straight-line file takes the streaming path");
    assert_eq!(s, b);
    assert_eq!(s.functions[0].outputs.len() as u64, g.outputs);
}

#[test]
fn streaming_equals_batch_with_two_functions_pointers_and_defines() {
    let src = "void mbs_a(double *c, MbsData *s)\n{\n#define q s->q\n double *PxF1;\n  T1 = q[1]*2.0;\n  c[1] = T1+q[2];\n}\n\
               void mbs_b(double *d, MbsData *s)\n{\n  d[1] = s->q[1]*s->q[1];\n  return;\n}\n";
    let (b, errors) = batch(src);
    assert_eq!(errors, 0);
    assert_eq!(b.functions.len(), 2);
    assert_eq!(streamed(src), Some(b));
}

#[test]
fn files_the_streaming_path_does_not_cover_go_to_the_batch_path() {
    // A syntax error: the batch path reports it.
    assert_eq!(streamed("void f(double *c, MbsData *s)\n{\n  c[1] = s->q[1]*;\n}\n"), None);
    // A sensor `switch`: prefix statements are lowered per case.
    let sensor = "void sensor(MbsSensor *sens, MbsData *s, int isens)\n{\n  T1 = s->q[1]*2.0;\n  switch (isens) {\n  case 1:\n    sens->P[1] = T1;\n    break;\n  }\n}\n";
    assert_eq!(batch(sensor).1, 0);
    assert_eq!(streamed(sensor), None);
    // A `#define` after the first statement changes how earlier names read in the batch path.
    let late = "void f(double *c, MbsData *s)\n{\n  c[1] = q[1]*2.0;\n#define q s->q\n}\n";
    assert_eq!(streamed(late), None);
    // Twice the same function: the batch path names the second definition.
    let twice = "void f(double *c, MbsData *s)\n{\n  c[1] = s->q[1];\n}\nvoid f(double *c, MbsData *s)\n{\n  c[1] = s->q[1];\n}\n";
    assert_eq!(streamed(twice), None);
    assert!(batch(twice).1 > 0);
}

/// Every corpus C file: where the streaming path (bodies lexed a window at a time) takes a
/// file, its module is the batch path's; it takes every straight-line file but the sensors.
#[test]
fn streaming_equals_batch_on_every_corpus_c_file() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/robotran/c");
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("corpus folder {} missing: {e}", dir.display()));
    let mut files: Vec<_> = entries.map(|e| e.expect("corpus entry").path()).collect();
    files.retain(|p| p.extension().is_some_and(|e| e == "c"));
    files.sort();
    let mut streamed_files = 0;
    for p in &files {
        let text = super::source_text(&std::fs::read(p).expect("corpus file"));
        let header = std::fs::read(p.with_extension("h")).ok().map(|h| super::source_text(&h));
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        let toks = lexer::lex_where(&text, |t| !c::ignored(t));
        let mut errors = Vec::new();
        let funcs = c::scan(&text, &toks, header.as_deref(), &mut errors, &Clock::default());
        let batch = lower::lower_module(&text, Language::C, &funcs, &mut errors, &Clock::default());
        let straight = !name.contains("accelred") && !name.contains("invdynared") && !name.contains("sensor");
        match c::scan_and_lower(&text, header.as_deref(), &Clock::default()) {
            Some(s) => {
                assert!(errors.is_empty(), "{name}: streamed although the batch path reports {}", errors[0].message);
                assert_eq!(s, batch, "{name}: the streaming path gives another module");
                streamed_files += 1;
            }
            None => assert!(!straight, "{name}: a straight-line file left to the batch path"),
        }
    }
    assert_eq!(streamed_files, 18, "straight-line corpus C files (all 24 but 3 sensor and 3 loop files)");
}

/// A body of several windows (the generated file has ~12k tokens, windows of 4096): what
/// spans windows is seen as in the batch path.
#[test]
fn state_that_spans_windows_is_kept() {
    let g = straight_line_c(Shape { bytes: 30_000, joints: 4, temps_per_output: 3, ops_per_temp: 4 });
    let body_end = g.text.rfind('}').expect("closing brace");
    // `return;` early, a statement after it windows later: unreachable in both paths.
    let early = g.text.find("// = = Block").expect("first block");
    let ret = format!("{}  return;\n{}", &g.text[..early], &g.text[early..]);
    assert_eq!(streamed(&ret), None);
    let toks = lexer::lex_where(&ret, |t| !c::ignored(t));
    let mut errors = Vec::new();
    c::scan(&ret, &toks, None, &mut errors, &Clock::default());
    assert!(errors.iter().any(|e| e.message.contains("unreachable statement after `return;`")));
    // A `switch` in the last window: left to the batch path.
    let sw = format!("{}  switch (isens) {{\n  case 1:\n    c[1] = T1;\n    break;\n  }}\n}}\n", &g.text[..body_end]);
    assert_eq!(batch(&sw).1, 0);
    assert_eq!(streamed(&sw), None);
    // A `#define` windows after the first statement: left to the batch path.
    let late = format!("{}#define qd s->qd\n}}\n", &g.text[..body_end]);
    assert_eq!(batch(&late).1, 0);
    assert_eq!(streamed(&late), None);
    // A syntax error in the last window.
    let bad = format!("{}  c[1] = T1*;\n}}\n", &g.text[..body_end]);
    assert_eq!(streamed(&bad), None);
    assert!(batch(&bad).1 > 0);
}

/// Braces the outline cannot stand for: unbalanced, or inside a top-level parenthesis (where
/// bracket matching on the outline could differ from the one on every token).
#[test]
fn odd_braces_go_to_the_batch_path() {
    for src in [
        "void f(double *c, MbsData *s)\n{\n  c[1] = s->q[1];\n}\n}\n",
        "void f(double *c, MbsData *s)\n{\n  c[1] = s->q[1];\n",
        "void f(double *c, { ) } MbsData *s)\n{\n  c[1] = s->q[1];\n}\n",
    ] {
        assert_eq!(streamed(src), None, "{src}");
        assert!(batch(src).1 > 0, "{src}");
    }
}
