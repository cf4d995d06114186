//! File tests, in the way of Cranelift's `filetests`: each `tests/ir/<pass>/*.rvir` (a back end's
//! under `tests/ir/codegen/<back end>/`) is a small module whose `;` comment lines say what to
//! run and what to look at:
//!
//! - `; passes: PIPELINE` (the first line): the pipeline run on the module;
//! - a comment saying what the case shows, with the expected figures derived by hand;
//! - `; output: WHAT, …` (default `ir`): what the snapshot holds, in this order: `ir` the IR
//!   after the pipeline; `code` a back end's generated code (the main file, its companions such
//!   as C's header, further units); `files` the files the artifacts write (their paths, and the
//!   contents of those a `; show: PATTERN` line names, `*` matching any characters); `report`
//!   the artifacts' JSON report entries per function (SPEC §7); `stats` the lines `-stats`
//!   prints on stderr (the rewriting passes' notes, the final IR's figures, the artifacts'
//!   lines). Wall times are masked (`<wall>`), so snapshots do not change from run to run;
//! - `; check: TEXT` and `; not: TEXT`: TEXT must (must not) appear in the snapshot — the
//!   pass's defining effect in words a reader verifies without reading the whole snapshot. The
//!   `check:` lines match in their order (each after the previous one's match, as FileCheck's
//!   `CHECK:` in Cranelift's filetests); a `not:` text must appear nowhere.
//!
//! With the default output the snapshot is exactly the IR after the pipeline. Also: every
//! registered pass, and every back end of the `codegen` family, has a folder of file tests;
//! and the seed's own example (eq. 2.1 → eq. 2.2) from a tiny Robotran C file.

use std::path::Path;

use robovec_backends::REGISTRY as PASSES;
use robovec_ir::text::parse;
use robovec_ir::{Def, Function, Module, Operand};
use robovec_passes::artifact::report_entries;
use robovec_passes::{parse_pipeline, summary, Instrumentation, Params, PassContext, PassManager, Session};

/// What a pipeline produced, as plain data.
struct Produced {
    /// The IR after the pipeline.
    ir: String,
    /// Generated code: (what it is, text), main file first.
    code: Vec<(String, String)>,
    /// Files the artifacts write: (path, bytes, executable).
    files: Vec<(String, Vec<u8>, bool)>,
    /// Per function in module order: its name and the artifacts' report entries as one object.
    reports: Vec<(String, serde_json::Value)>,
    /// What `-stats` prints on stderr (early-stop notes first, as the driver does).
    stats: String,
}

/// Runs `pipeline` on `m` (left as the pipeline leaves it) and collects what the run produced.
/// The one function of these tests that runs a pipeline: a [`Session`] of the complete
/// registry (passes and back ends), its module and artifacts read back as plain data.
fn run_pipeline(pipeline: &str, m: &mut Module) -> Produced {
    let pm = PassManager::with_registry(PASSES, pipeline, Instrumentation::default())
        .unwrap_or_else(|e| panic!("{pipeline}: {e}"));
    let mut session = Session::new(pm, std::mem::take(m), PassContext::default());
    session.run_quiet().unwrap_or_else(|e| panic!("{pipeline}: {e}"));
    let (module, cx, _) = session.into_parts();
    *m = module;
    let mut code = Vec::new();
    for c in cx.artifacts().filter_map(|a| a.code()) {
        code.push((format!("main ({})", c.language), c.main.clone()));
        code.extend(c.companions.iter().map(|(ext, text)| (format!("companion .{ext}"), text.clone())));
        code.extend(c.units.iter().enumerate().map(|(k, text)| (format!("unit {}", k + 1), text.clone())));
    }
    let several = m.functions.len() > 1;
    let files = cx
        .artifacts()
        .flat_map(|a| a.files(several))
        .map(|f| (f.path.display().to_string(), f.bytes, f.executable))
        .collect();
    let reports = m
        .functions
        .iter()
        .map(|f| {
            let entries = report_entries(cx.artifacts(), &f.name).into_iter().map(|(k, v)| (k.to_string(), v));
            (f.name.clone(), serde_json::Value::Object(entries.collect()))
        })
        .collect();
    let mut stats: String = cx.stopped().iter().map(|s| format!("note: {s}\n")).collect();
    stats += &summary::stats_text(&summary::figures(m, &cx, None), &cx, None);
    for a in cx.artifacts() {
        stats += &a.log_text(true);
    }
    Produced { ir: m.to_string(), code, files, reports, stats }
}

/// One kind of output a file test snapshots (`; output:`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Output {
    Ir,
    Code,
    Files,
    Report,
    Stats,
}

impl Output {
    const WORDS: &'static [(&'static str, Output)] = &[
        ("ir", Output::Ir),
        ("code", Output::Code),
        ("files", Output::Files),
        ("report", Output::Report),
        ("stats", Output::Stats),
    ];
}

/// The directives of a file test's `;` lines.
#[derive(Debug, Default, PartialEq, Eq)]
struct Header {
    pipeline: String,
    outputs: Vec<Output>,
    show: Vec<String>,
    checks: Vec<String>,
    nots: Vec<String>,
}

/// Reads the directives of `src` (module doc).
///
/// # Errors
/// A first line that is not `; passes: …`, an unknown `; output:` word, an empty directive.
fn parse_header(src: &str) -> Result<Header, String> {
    let pipeline = src
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("; passes:"))
        .ok_or("the first line must be `; passes: PIPELINE`")?
        .trim()
        .to_string();
    let mut h = Header { pipeline, ..Header::default() };
    for (n, line) in src.lines().enumerate().skip(1) {
        let Some(comment) = line.trim_start().strip_prefix(';') else { continue };
        let comment = comment.trim();
        let Some((word, text)) = comment.split_once(':') else { continue };
        let text = text.trim();
        let list = match word {
            "output" => {
                for w in text.split(',').map(str::trim) {
                    let Some(&(_, o)) = Output::WORDS.iter().find(|(x, _)| *x == w) else {
                        let words: Vec<&str> = Output::WORDS.iter().map(|(x, _)| *x).collect();
                        return Err(format!("line {}: unknown output `{w}` (expected {})", n + 1, words.join(", ")));
                    };
                    h.outputs.push(o);
                }
                continue;
            }
            "show" => &mut h.show,
            "check" => &mut h.checks,
            "not" => &mut h.nots,
            _ => continue,
        };
        if text.is_empty() {
            return Err(format!("line {}: `; {word}:` needs a text", n + 1));
        }
        list.push(text.to_string());
    }
    if h.outputs.is_empty() {
        h.outputs.push(Output::Ir);
    }
    Ok(h)
}

/// True when `text` matches `pattern`, where `*` stands for any characters (none included).
fn glob_match(pattern: &str, text: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == text,
        Some((head, tail)) => {
            text.starts_with(head)
                && (head.len()..=text.len()).any(|k| text.is_char_boundary(k) && glob_match(tail, &text[k..]))
        }
    }
}

/// `text` with every wall time masked: a decimal number followed by the unit ` ms` becomes
/// `<wall> ms` (eqsat's window times; nothing else is printed in milliseconds).
fn mask_wall_times(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(k) = rest.find(" ms") {
        let after = &rest[k + 3..];
        let number = rest[..k].trim_end_matches(|c: char| c.is_ascii_digit() || c == '.').len();
        let unit = !after.starts_with(|c: char| c.is_alphanumeric() || c == '_');
        if unit && rest[number..k].contains(|c: char| c.is_ascii_digit()) {
            out += &rest[..number];
            out += "<wall>";
        } else {
            out += &rest[..k];
        }
        out += " ms";
        rest = after;
    }
    out + rest
}

/// `v` with the values of wall-time keys (`wall_ms`, eqsat's `total_ms`, `mean_ms`, `max_ms`)
/// replaced by `"<wall>"`, at any depth.
fn mask_wall_keys(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            for (k, x) in map.iter_mut() {
                if ["wall_ms", "total_ms", "mean_ms", "max_ms"].contains(&k.as_str()) {
                    *x = serde_json::Value::String("<wall>".into());
                } else {
                    mask_wall_keys(x);
                }
            }
        }
        serde_json::Value::Array(xs) => xs.iter_mut().for_each(mask_wall_keys),
        _ => {}
    }
}

/// The snapshot text of `p` for the outputs and `show` patterns of `h`: the IR alone for the
/// default output, otherwise each part under a `;; ` heading.
fn render(h: &Header, p: &Produced) -> String {
    if h.outputs == [Output::Ir] {
        return p.ir.clone();
    }
    let mut s = String::new();
    let mut part = |title: &str, text: &str| {
        s += &format!(";; {title}\n{text}");
        if !text.is_empty() && !text.ends_with('\n') {
            s.push('\n');
        }
    };
    for o in &h.outputs {
        match o {
            Output::Ir => part("ir", &p.ir),
            Output::Code if p.code.is_empty() => part("code: none", ""),
            Output::Code => p.code.iter().for_each(|(what, text)| part(&format!("code: {what}"), text)),
            Output::Files => {
                let list: String = p
                    .files
                    .iter()
                    .map(|(path, _, x)| format!("{path}{}\n", if *x { " (executable)" } else { "" }))
                    .collect();
                part("files", &list);
                for (path, bytes, _) in p.files.iter().filter(|(path, ..)| h.show.iter().any(|g| glob_match(g, path))) {
                    part(&format!("file: {path}"), &String::from_utf8_lossy(bytes));
                }
            }
            Output::Report => {
                for (function, entries) in &p.reports {
                    let mut v = entries.clone();
                    mask_wall_keys(&mut v);
                    part(&format!("report @{function}"), &(serde_json::to_string_pretty(&v).unwrap() + "\n"));
                }
            }
            Output::Stats => part("stats", &mask_wall_times(&p.stats)),
        }
    }
    s
}

/// What is wrong with `output` against the `check:` and `not:` lines of `h` (one line each):
/// the `check:` texts must appear in their order (each after the previous one's match, as
/// FileCheck's `CHECK:`), the `not:` texts nowhere.
fn check_output(h: &Header, output: &str) -> Vec<String> {
    let mut wrong = Vec::new();
    let mut at = 0;
    for c in &h.checks {
        match output[at..].find(c.as_str()) {
            Some(k) => at += k + c.len(),
            None if output.contains(c.as_str()) => {
                wrong.push(format!("check: `{c}` found, but before the previous check"))
            }
            None => wrong.push(format!("check: `{c}` not found")),
        }
    }
    wrong.extend(h.nots.iter().filter(|c| output.contains(c.as_str())).map(|c| format!("not: `{c}` found")));
    wrong
}

#[test]
fn ir_file_tests() {
    let mut failures = Vec::new();
    insta::glob!("ir/**/*.rvir", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let h = parse_header(&src).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut m = parse(&src).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
        let output = render(&h, &run_pipeline(&h.pipeline, &mut m));
        let name = path.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap_or(path).display().to_string();
        for e in check_output(&h, &output) {
            // Printed at once too: a snapshot failure ends the glob before the assert below.
            eprintln!("{name}: {e}");
            failures.push(format!("{name}: {e}"));
        }
        insta::assert_snapshot!(output);
    });
    assert!(failures.is_empty(), "file tests whose checks fail:\n{}", failures.join("\n"));
}

#[test]
fn directives_are_read_and_checks_can_fail() {
    let src = "; passes: atomise,cse\n; The duplicate goes.\n; output: ir, stats\n; check: %p = mul\n\
               ;   check:   ops 3  \n; not: %q = mul\nfunc @f {\n  ; show: *.hex\n}\n";
    let h = parse_header(src).unwrap();
    assert_eq!(
        h,
        Header {
            pipeline: "atomise,cse".into(),
            outputs: vec![Output::Ir, Output::Stats],
            show: vec!["*.hex".into()],
            checks: vec!["%p = mul".into(), "ops 3".into()],
            nots: vec!["%q = mul".into()],
        }
    );
    assert!(check_output(&h, "%p = mul %a, %b ops 3").is_empty());
    assert_eq!(check_output(&h, "%p = add ops 3 %q = mul"), ["check: `%p = mul` not found", "not: `%q = mul` found"]);
    assert_eq!(check_output(&h, "ops 3, %p = mul"), ["check: `ops 3` found, but before the previous check"]);
    assert_eq!(parse_header("; passes: cse\nfunc @f {}").unwrap().outputs, [Output::Ir], "the IR by default");
    assert!(parse_header("func @f {}").unwrap_err().contains("first line"));
    assert!(parse_header("; passes: cse\n; output: ir, asm\n").unwrap_err().contains("unknown output `asm`"));
    assert!(parse_header("; passes: cse\n; check:\n").unwrap_err().contains("line 2"));
}

#[test]
fn wall_times_are_masked_and_show_patterns_match() {
    let line = "@f: eqsat: time 1.5 ms total, 0.375 ms mean / 0.900 ms max per window; 12 msgs, x ms, 3 s";
    assert_eq!(
        mask_wall_times(line),
        "@f: eqsat: time <wall> ms total, <wall> ms mean / <wall> ms max per window; 12 msgs, x ms, 3 s"
    );
    let mut v = serde_json::json!({"passes": [{"name": "cse", "wall_ms": 0.25}], "eqsat": {"total_ms": 3.0, "ops": 7}});
    mask_wall_keys(&mut v);
    assert_eq!(
        v,
        serde_json::json!({"passes": [{"name": "cse", "wall_ms": "<wall>"}], "eqsat": {"total_ms": "<wall>", "ops": 7}})
    );
    assert!(glob_match("fpga/hex/*.hex", "fpga/hex/pe0_instr.hex"));
    assert!(glob_match("*manifest.json", "fpga/manifest.json"));
    assert!(glob_match("fpga/hdl/robovec_top.v", "fpga/hdl/robovec_top.v"));
    assert!(!glob_match("fpga/hex/*.hex", "fpga/mif/pe0_instr.mif"));
    assert!(!glob_match("*.hex", "fpga/hex/pe0.hex.txt"));
}

/// The folder of file tests of pass `pass` (`member`: a back end of a pass family).
fn folder(pass: &str, member: Option<&str>) -> std::path::PathBuf {
    let dir = Path::new("tests/ir").join(pass);
    member.map_or(dir.clone(), |m| dir.join(m))
}

/// True when the folder holds a file test whose pipeline runs `info` (and its `member`).
fn has_file_test(info: &'static robovec_passes::PassInfo, member: Option<&str>) -> bool {
    let Ok(entries) = std::fs::read_dir(folder(info.name, member)) else { return false };
    entries.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "rvir")).any(|p| {
        let src = std::fs::read_to_string(&p).unwrap();
        let h = parse_header(&src).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let specs = parse_pipeline(&h.pipeline).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        specs.iter().filter(|s| s.name == info.name).any(|s| {
            let params = Params::check(info, &s.params).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            params.member().map(|m| m.name) == member
        })
    })
}

#[test]
fn every_registered_pass_and_back_end_has_a_file_test() {
    let mut missing = Vec::new();
    let mut folders = Vec::new();
    for info in PASSES {
        let members: Vec<&str> = info.params.iter().flat_map(|p| p.members()).map(|m| m.name).collect();
        let wanted: Vec<Option<&str>> =
            if members.is_empty() { vec![None] } else { members.iter().copied().map(Some).collect() };
        for member in wanted {
            folders.push(folder(info.name, member));
            if !has_file_test(info, member) {
                missing.push(format!("{} (a file test that runs it)", folder(info.name, member).display()));
            }
        }
    }
    assert!(missing.is_empty(), "registered passes without a file test in:\n{}", missing.join("\n"));
    // And every folder of file tests is a pass's (or a back end's): no test hides in a typo.
    for e in std::fs::read_dir("tests/ir").unwrap().flatten() {
        let dir = e.path();
        let inside: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.path()).collect();
        let tests = inside.iter().any(|p| p.extension().is_some_and(|x| x == "rvir"));
        assert!(!tests || folders.contains(&dir), "{}: no registered pass of that name", dir.display());
        for sub in inside.iter().filter(|p| p.is_dir()) {
            assert!(folders.contains(sub), "{}: no back end of that name", sub.display());
        }
    }
}

/// The expansion of an operand as a tree of ops over leaves named as in the source.
fn tree(f: &Function, o: Operand) -> String {
    match o {
        Operand::Const(c) => format!("{c:?}"),
        Operand::Value(v) => match &f.value(v).def {
            Def::Binary(op, a, b) => format!("({} {} {})", op.mnemonic(), tree(f, *a), tree(f, *b)),
            _ => f.name_of(v).to_string(),
        },
    }
}

#[test]
fn seed_example_atomises_to_the_seed_operations() {
    let (mut m, _) = robovec::driver::load("tests/inputs/seed_eq21.c").unwrap_or_else(|f| panic!("{}", f.message()));
    run_pipeline("atomise", &mut m);
    let ours = &m.functions[0];
    insta::assert_snapshot!(ours.to_string());

    // Seed eq. 2.2, transcribed with the seed's own names (g(3) = %g[3], qp = %qd).
    let seed = parse(
        "func @seed { phase atomised input %q[4] input %q[5] input %q[6] input %g[3] input %qd[4] input %qd[5]
          %C4 = cos %q[4] %S4 = sin %q[4] %C5 = cos %q[5] %S5 = sin %q[5] %C6 = cos %q[6] %S6 = sin %q[6]
          %AF24d = mul %g[3], %S4  %AF24 = sub 0.0, %AF24d
          %AF34d = mul %g[3], %C4  %AF34 = sub 0.0, %AF34d
          %OM15 = mul %qd[4], %C5  %OM35 = mul %qd[4], %S5
          %AF15d = mul %AF34, %S5  %AF15 = sub 0.0, %AF15d
          %AF35 = mul %AF34, %C5
          %OM16d = mul %OM15, %C6  %OM16g = mul %qd[5], %S6  %OM16 = add %OM16g, %OM16d
          %OM26d = mul %OM15, %S6  %OM26g = mul %qd[5], %C6  %OM26 = sub %OM26g, %OM26d
          output Qq[1] = %AF24 output Qq[2] = %AF34 output Qq[3] = %OM15 output Qq[4] = %OM35
          output Qq[5] = %AF15 output Qq[6] = %AF35 output Qq[7] = %OM16 output Qq[8] = %OM26 }",
    )
    .unwrap();
    let seed = &seed.functions[0];
    assert_eq!(ours.op_counts(), seed.op_counts(), "same count (15 ops: 10 mul, 4 sub, 1 add)");
    assert_eq!(seed.op_counts().total, 15);
    for (a, b) in ours.outputs.iter().zip(&seed.outputs) {
        assert_eq!(a.name, b.name);
        assert_eq!(tree(ours, a.value), tree(seed, b.value), "same structure for {}", a.name);
    }
}
