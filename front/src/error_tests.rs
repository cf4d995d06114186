//! Diagnostics: every bad input gives an error with a useful span, message, label and note,
//! and no input makes the front end panic.

use super::{parse_str, FrontError, Language};

fn errs(lang: Language, src: &[u8]) -> Vec<FrontError> {
    match parse_str(lang, src, None) {
        Ok(m) => panic!("expected an error, got\n{m}"),
        Err(e) => e,
    }
}

/// The first error, checked to carry a label and at least one note.
fn first(lang: Language, src: &str) -> FrontError {
    let e = errs(lang, src.as_bytes()).remove(0);
    assert!(!e.label.is_empty() && !e.notes.is_empty(), "error without label or note: {e:?}");
    assert!(e.message.starts_with(|c: char| c.is_lowercase() || c == '`'), "message starts lower case: {}", e.message);
    e
}

fn at(src: &str, e: &FrontError) -> String {
    src[e.span.range()].to_string()
}

fn c_fn(body: &str) -> String {
    format!("void mbs_dirdyna(double **M,double *c,\nMbsData *s, double tsim)\n{{\n#define q s->q\n{body}}}\n")
}

#[test]
fn unknown_function() {
    let src = c_fn("  X = tan(q[1]);\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "unknown function `tan`");
    assert_eq!(at(&src, &e), "tan");
    assert!(e.notes[0].contains("sqrt"), "lists the accepted functions");
    let e = first(Language::Matlab, "function [M] = dirdyna(s,tsim,usrfun)\n  X = pow(q(1),2);\n");
    assert_eq!(e.message, "unknown function `pow`");
    let e = first(Language::Python, "def dirdyna(M, c, s, tsim):\n  X = 2*atan2(q[1], q[2])\n");
    assert_eq!(e.message, "unknown function `atan2`");
}

#[test]
fn use_before_definition_and_redefinition() {
    let src = c_fn("  X = q[1];\n  Z = X+Y*(2.0);\n  Y = q[2];\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "use of `Y` before its definition");
    assert_eq!(at(&src, &e), "Y");
    let src = c_fn("  X = q[1];\n  M[1][1] = X;\n  X = q[2];\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "value `X` defined twice");
    assert!(e.notes[0].contains("line 5"), "{:?}", e.notes);
    // An element of an output array that was never written.
    let e = first(Language::C, &c_fn("  X = M[1][1];\n"));
    assert_eq!(e.message, "use of `M[1][1]` before its definition");
    // A failed statement does not cascade into more errors.
    let all = errs(Language::C, c_fn("  X = tan(q[1]);\n  Y = X*X;\n  M[1][1] = Y;\n").as_bytes());
    assert_eq!(all.len(), 1, "{all:?}");
    let all = errs(Language::Python, b"def invdyna(phi,s,tsim):\n  Qq = phi\n  A = q[1]*(2.0.1)\n  Qq[1] = A\n");
    assert_eq!(all.len(), 1, "a statement that does not parse poisons its name: {all:?}");
}

#[test]
fn loops_and_branches_are_rejected_with_their_line() {
    let src = c_fn("  X = q[1];\n  while (X > 1)\n  {\n  X = q[2];\n  }\n");
    let e = first(Language::C, &src);
    assert!(e.message.starts_with("`while` loop at line 6: robovec handles straight-line"), "{}", e.message);
    assert_eq!(at(&src, &e), "while");
    for (kw, what) in [
        ("for(i=1;i<=3;i++)", "`for` loop"),
        ("if (X)", "`if` branch"),
        ("goto end;", "`goto`"),
        ("do { X = q[2]; } while (X);", "`do` loop"),
    ] {
        let e = first(Language::C, &c_fn(&format!("  X = q[1];\n  {kw}\n")));
        assert!(e.message.starts_with(&format!("{what} at line 6")), "{}", e.message);
    }
    let e = first(Language::C, &c_fn("  X = q[1];\n  return X;\n"));
    assert!(e.message.starts_with("`return` with a value at line 6"), "{}", e.message);
    // A helper with a loop rejects the file even when the main function is straight-line.
    let src = format!("void reset_frctrq(MBSdataStruct *s) \n{{ \n\tint i,j; \n\tfor(i=1;i<=s->nbody;i++) \n\t{{\n\t\ts->frc[1][i]=0; \n\t}}\n}}\n{}", c_fn("  c[1] = q[1];\n"));
    assert!(first(Language::C, &src).message.starts_with("`for` loop at line 4"));
    let e = first(
        Language::Matlab,
        "function [c] = dirdyna(s,tsim,usrfun)\n  X = q(1);\n  for i = 1:3\n  X = q(2);\n  end\n",
    );
    assert!(e.message.starts_with("`for` loop at line 3"), "{}", e.message);
    let e = first(Language::Python, "def dirdyna(M, c, s, tsim):\n    X = q[1]\n    while X:\n        X = q[2]\n");
    assert!(e.message.starts_with("`while` loop at line 3"), "{}", e.message);
}

#[test]
fn bad_indices_and_numbers() {
    let src = c_fn("  X = q[x];\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "index must be a positive integer literal");
    assert_eq!(at(&src, &e), "x");
    let src = c_fn("  X = q[];\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "empty index");
    assert_eq!(at(&src, &e), "[]");
    assert_eq!(first(Language::C, &c_fn("  X = q[0];\n")).message, "index `0` is out of range");
    assert_eq!(first(Language::C, &c_fn("  X = q[1.5];\n")).message, "index must be a positive integer literal");
    let src = c_fn("  X = q[1]*(2.0.1);\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "number `2.0.1` does not parse");
    assert_eq!(at(&src, &e), "2.0.1");
    assert_eq!(first(Language::C, &c_fn("  X = (1e5)*q[1];\n")).message, "number `1e5` does not parse");
}

#[test]
fn syntax_errors_and_unterminated_statements() {
    let src = c_fn("  X = q[1]*-q[2];\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "unexpected `-`");
    let src = c_fn("  X = q[1]+q[2]\n");
    let e = first(Language::C, &src);
    assert_eq!(e.message, "statement is not terminated by `;`");
    assert_eq!(at(&src, &e), "X = q[1]+q[2]");
    let e = first(Language::C, "void mbs_invdyna(double *Qq, MbsData *s, double tsim)\n{\n  Qq[1] = q[1];\n");
    assert_eq!(e.message, "unclosed `{`");
    let all = errs(Language::C, b"void mbs_invdyna(double *Qq, MbsData *s, double tsim)\n{\n  Qq[1] = q[1]");
    let msgs: Vec<&str> = all.iter().map(|e| e.message.as_str()).collect();
    assert_eq!(msgs, ["unclosed `{`", "statement is not terminated by `;`"]);
    let e = first(Language::Matlab, "function [c] = dirdyna(s,tsim,usrfun)\n  c(1) = q(1)+...\n");
    assert_eq!(e.message, "unexpected end of statement");
    let e = first(Language::Python, "def dirdyna(M, c, s, tsim):\n    c[1] = q[1]* \\\n");
    assert_eq!(e.message, "unexpected end of statement");
    let e = first(Language::C, &c_fn("  user_DrivenJoints(s,tsim);\n"));
    assert_eq!(e.message, "call statement `user_DrivenJoints(…)` is not supported");
    let e = first(Language::C, &c_fn("  X = cos(q[1])*q[2];\n"));
    assert_eq!(e.message, "`cos` is accepted only as a whole right-hand side");
    let e = first(Language::C, &c_fn("  X = cos(X1);\n"));
    assert!(e.message.contains("use of `X1`") || e.message.contains("joint coordinate"), "{}", e.message);
}

#[test]
fn empty_and_garbage_files() {
    for lang in [Language::C, Language::Matlab, Language::Python] {
        let e = errs(lang, b"");
        assert_eq!(e[0].message, "no Robotran function found");
        assert!(e[0].notes[0].starts_with("expected"));
        let e = errs(lang, b"// just a comment\n% another\n# and one\n");
        assert!(!e.is_empty());
        let e = errs(Language::C, b"double    C4;\r\ndouble    S4;\r\n");
        assert_eq!(e.len(), 1);
        assert_eq!(e[0].message, "no Robotran function found");
        let e = errs(lang, b"\n\n   \n");
        assert!(!e.is_empty());
        let e = errs(lang, b"\x00\x01\xff\xfe garbage \x80 @@ \xc3");
        assert!(!e.is_empty());
        for err in &e {
            assert!(err.span.end as usize <= 18);
        }
    }
}

#[test]
fn absurd_nesting_and_length_are_diagnosed() {
    let deep = format!("  X = {}q[1]{};\n", "(".repeat(300), ")".repeat(300));
    let e = first(Language::C, &c_fn(&deep));
    assert_eq!(e.message, "expression nests deeper than 256 parentheses");
    let deeper = format!("  X = {}q[1];\n", "(".repeat(200_000));
    assert_eq!(first(Language::C, &c_fn(&deeper)).message, "expression nests deeper than 256 parentheses");
    let long = format!("  X = q[1]{};\n", "+q[1]".repeat(100_000));
    assert!(first(Language::C, &c_fn(&long)).message.starts_with("statement has more than"));
    // The largest accepted statement goes through lowering, counting, printing and verifying.
    let big = format!(
        "  X = -(q[1]{})*{}q[2]{};\n  M[1][1] = X;\n",
        "+q[1]*q[2]/q[3]".repeat(600),
        "(".repeat(250),
        ")".repeat(250)
    );
    let m = std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(move || {
            let m = super::snippet_tests::parse(Language::C, &c_fn(&big));
            let f = &m.functions[0];
            assert_eq!(f.op_counts().total, 1800 + 1 + 1);
            robovec_ir::verifier::verify(&m).expect("verifies");
            m.to_string().len()
        })
        .expect("thread")
        .join()
        .expect("no stack overflow on a 1800-operator statement");
    assert!(m > 0);
    let py = format!("def dirdyna(M, c, s, tsim):\n    X = {}1\n", "(".repeat(1000));
    assert!(first(Language::Python, &py).message.contains("256"));
}

#[test]
fn diagnostics_render_with_codespan() {
    use codespan_reporting::files::SimpleFile;
    use codespan_reporting::term::{emit_into_string, Config};
    let src = c_fn("  X = tan(q[1]);\n");
    let e = first(Language::C, &src);
    let file = SimpleFile::new("x.c", src.as_str());
    let out = emit_into_string(&Config::default(), &file, &e.to_diagnostic(())).expect("renders");
    assert!(out.contains("x.c:5:7"), "{out}");
    assert!(out.contains("unknown function `tan`"), "{out}");
}

/// The workspace's deterministic generator (`robovec_ir::rng`) mutates corpus-like text and throws
/// random bytes at every front end; none may panic.
#[test]
fn no_panic_on_mutated_or_random_input() {
    let seeds: [&[u8]; 3] = [
        super::snippet_tests::C_SAMPLE.as_bytes(),
        b"function [M,c] = dirdyna(s,tsim,usrfun)\n M = zeros(2,2);\nq = s.q;\n  C2 = cos(q(2));\n  A = -(s.dpt(2,4)*C2+...\n s.m(3));\n  M(1,1) = A;\n",
        b"def invdyna(phi,s,tsim):\n  Qq = phi\n  C4 = np.cos(q[4])\n  A = C4*(-s.m[2]+ \\\n  q[1])\n  Qq[1] = A\n",
    ];
    let mut rng = robovec_ir::rng::SplitMix64::new(0x9E37_79B9_7F4A_7C15);
    let mut next = move || rng.next_u64();
    let alphabet = b"()[];=+-*/,.\n\\%#{}sq1 0.2xX_-> \r\xe9";
    for round in 0..3000 {
        let seed = seeds[round % 3];
        let mut buf = seed.to_vec();
        for _ in 0..(1 + next() % 6) {
            let pos = (next() as usize) % (buf.len() + 1);
            match next() % 3 {
                0 if pos < buf.len() => {
                    buf.remove(pos);
                }
                1 => buf.insert(pos, alphabet[(next() as usize) % alphabet.len()]),
                _ if pos < buf.len() => buf[pos] = (next() & 0xff) as u8,
                _ => {}
            }
        }
        for lang in [Language::C, Language::Matlab, Language::Python] {
            if let Err(errs) = parse_str(lang, &buf, None) {
                for e in errs {
                    assert!(
                        e.span.end as usize <= buf.len().max(1),
                        "span out of range for {:?}",
                        String::from_utf8_lossy(&buf)
                    );
                }
            }
        }
    }
}
