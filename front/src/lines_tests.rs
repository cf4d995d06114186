//! The line-oriented front ends ([`super::lines`]): the streaming path gives the batch path's
//! module, the batch path over [`super::lines::Lines`] reads the lines the whole-token scan
//! read, and files with errors go to the batch path.

use super::clock::Clock;
use super::lexer::{self, Spanned, Tok};
use super::lines::{self, LineScanner, Lines};
use super::{lower, matlab, python, Language};

fn batch<S: LineScanner>(src: &str) -> (robovec_ir::Module, usize) {
    let mut errors = Vec::new();
    let funcs = lines::scan::<S>(src, &mut errors, &Clock::default());
    let m = lower::lower_module(src, S::LANG, &funcs, &mut errors, &Clock::default());
    (m, errors.len())
}

fn streamed<S: LineScanner>(src: &str) -> Option<robovec_ir::Module> {
    lines::scan_and_lower::<S>(src, &Clock::default())
}

/// The logical lines as the scanners read them before [`Lines`]: the whole file lexed, the
/// comments and continuations filtered out of the full list, then split at newlines.
fn lines_of_whole_list(src: &str, lang: Language) -> Vec<Vec<Spanned<'_>>> {
    let toks = lexer::lex(src);
    let mut flat = Vec::new();
    let mut k = 0;
    while k < toks.len() {
        match (lang, toks[k].1) {
            (Language::Matlab, Tok::PercentComment) | (Language::Python, Tok::Hash(_)) => {}
            (Language::Matlab, Tok::Ellipsis) => {
                if toks.get(k + 1).is_some_and(|t| t.1 == Tok::Newline) {
                    k += 1;
                }
            }
            (Language::Python, Tok::Backslash) if toks.get(k + 1).is_some_and(|t| t.1 == Tok::Newline) => k += 1,
            _ => flat.push(toks[k]),
        }
        k += 1;
    }
    flat.split(|t| t.1 == Tok::Newline).filter(|l| !l.is_empty()).map(<[_]>::to_vec).collect()
}

fn lines_one_at_a_time(src: &str, lang: Language) -> Vec<Vec<Spanned<'_>>> {
    let clock = Clock::default();
    let mut lines = Lines::new(src, lang, &clock);
    let mut out = Vec::new();
    while let Some(l) = lines.next_line() {
        out.push(l.to_vec());
    }
    out
}

#[test]
fn lines_one_at_a_time_are_the_lines_of_the_whole_token_list() {
    for (lang, src) in [
        (
            Language::Matlab,
            "% c\nfunction [M] = f(s)\n  a = s.q(1) ...  rest\n    * 2; % tail\n\n\n  M(1,1) = a;b = 1;\nend ...",
        ),
        (Language::Matlab, "x = 1 ...\n...\n...\n+ 2;\n..."),
        (
            Language::Python,
            "# c\ndef f(M, s):\n    a = s.q[1] \\\n        * 2  # tail\n    b = a \\ 2\n\n    M[1,1] = a\\",
        ),
        (Language::Python, "\\\n\\\nx = 1\n\n"),
    ] {
        assert_eq!(lines_one_at_a_time(src, lang), lines_of_whole_list(src, lang), "{src}");
    }
}

#[test]
fn streaming_equals_batch_on_small_files() {
    let m = "function [M,c] = dirdyna(s,tsim,usrfun)\n% a comment\nC1 = cos(s.q(1));\nT1 = C1*s.dpt(1,2) ...\n  + s.q(2);\nM(1,1) = T1;\nc(1) = T1*T1;\nend\n\
             function [Q] = invdyna(s,tsim,usrfun)\nQ(1) = s.qdd(1)*2.0;\nend\nfunction [x] = empty(s)\n";
    let (b, errors) = batch::<matlab::Scanner>(m);
    assert_eq!(errors, 0);
    assert_eq!(b.functions.len(), 3);
    assert_eq!(streamed::<matlab::Scanner>(m), Some(b));
    let p = "import numpy as np\ndef dirdyna(M, c, s, tsim):\n    C1 = np.cos(s.q[1])  # c\n    T1 = C1 * \\\n        s.q[2]\n    M[1,1] = T1\n    c[1] = T1\ndef f(d, s):\n    pass\n";
    let (b, errors) = batch::<python::Scanner>(p);
    assert_eq!(errors, 0);
    assert_eq!(b.functions.len(), 2);
    assert_eq!(streamed::<python::Scanner>(p), Some(b));
}

#[test]
fn files_with_errors_go_to_the_batch_path() {
    for m in [
        // A syntax error, a use before definition (found by the lowering), a loop, a
        // statement outside any function, twice the same function, no function at all.
        "function [c] = f(s)\nc(1) = s.q(1)*;\nend\n",
        "function [c] = f(s)\nc(1) = T9;\nend\n",
        "function [c] = f(s)\nfor i = 1:3\nc(1) = 1;\nend\n",
        "c(1) = 1;\nfunction [c] = f(s)\nc(1) = s.q(1);\n",
        "function [c] = f(s)\nc(1) = s.q(1);\nend\nfunction [c] = f(s)\nc(1) = s.q(1);\nend\n",
        "% nothing\n",
    ] {
        assert_eq!(streamed::<matlab::Scanner>(m), None, "{m}");
        assert!(super::parse_str(Language::Matlab, m.as_bytes(), None).is_err(), "{m}");
    }
    let p = "def f(c, s):\n    c[1] = s.q[1] +\n";
    assert_eq!(streamed::<python::Scanner>(p), None);
    assert!(super::parse_str(Language::Python, p.as_bytes(), None).is_err());
}

/// Every corpus Matlab and Python file: the streaming path takes each straight-line file and
/// gives the batch path's module.
#[test]
fn streaming_equals_batch_on_every_corpus_matlab_and_python_file() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/robotran");
    let mut streamed_files = 0;
    for (sub, ext) in [("matlab", "m"), ("python", "py")] {
        let dir = root.join(sub);
        let entries =
            std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("corpus folder {} missing: {e}", dir.display()));
        let mut files: Vec<_> = entries.map(|e| e.expect("corpus entry").path()).collect();
        files.retain(|p| p.extension().is_some_and(|e| e == ext));
        files.sort();
        for p in &files {
            let text = super::source_text(&std::fs::read(p).expect("corpus file"));
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            let ((b, errors), s) = if ext == "m" {
                (batch::<matlab::Scanner>(&text), streamed::<matlab::Scanner>(&text))
            } else {
                (batch::<python::Scanner>(&text), streamed::<python::Scanner>(&text))
            };
            match s {
                Some(s) => {
                    assert_eq!(errors, 0, "{name}: streamed although the batch path reports errors");
                    assert_eq!(s, b, "{name}: the streaming path gives another module");
                    streamed_files += 1;
                }
                None => assert!(errors > 0, "{name}: a file without errors left to the batch path"),
            }
        }
    }
    assert_eq!(streamed_files, 13, "the corpus's 8 Matlab and 5 Python files, all straight-line");
}
