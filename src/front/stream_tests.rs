//! The streaming path of the C front end ([`super::c::scan_and_lower`]) gives the module of the
//! batch path ([`super::c::scan`] then [`super::lower::lower_module`]), and leaves the files it
//! does not cover (errors, `switch`, late declarations) to the batch path.

use super::synth::{straight_line_c, Shape};
use super::{c, lexer, lower, Language};

fn batch(src: &str) -> (robovec_ir::Module, usize) {
    let toks = lexer::lex_where(src, |t| !c::ignored(t));
    let mut errors = Vec::new();
    let funcs = c::scan(src, &toks, None, &mut errors);
    let m = lower::lower_module(src, Language::C, &funcs, &mut errors);
    (m, errors.len())
}

fn streamed(src: &str) -> Option<robovec_ir::Module> {
    let toks = lexer::lex_where(src, |t| !c::ignored(t));
    c::scan_and_lower(src, &toks, None)
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
