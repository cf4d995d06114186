//! Issue 10 §3, resources stay bounded: building the IR is linear in the number of outputs,
//! an over-long statement's diagnostic stays short, and `-time-limit` / eqsat's work budget
//! stop heavy but valid runs with a valid result and a note.

use std::path::PathBuf;

use robovec_front::synth::{straight_line_c, Shape};
use robovec_front::{parse_str, Language};

use crate::common::{corpus_dir, opt, tmp};

/// Outputs compared by name while building the parsed and the atomised function of a
/// generated file with about `outputs` outputs; also the outputs counted by the generator.
fn output_work(outputs: u64) -> (u64, u64, u64) {
    // ~48 bytes per temporary + output with one op per temporary.
    let shape = Shape { bytes: outputs as usize * 48, joints: 8, temps_per_output: 1, ops_per_temp: 1 };
    let g = straight_line_c(shape);
    let m = parse_str(Language::C, g.text.as_bytes(), None).unwrap_or_else(|e| panic!("{:?}", &e[..1]));
    let f = &m.functions[0];
    assert_eq!(f.outputs.len() as u64, g.outputs, "one output per generated output");
    let a = robovec_passes::atomise::atomise_function(f);
    assert_eq!(a.outputs.len() as u64, g.outputs);
    (f.output_probes(), a.output_probes(), g.outputs)
}

/// Today's main located each new output by scanning all the earlier ones (`set_output`):
/// 20k outputs cost 2·10⁸ name comparisons, 40k four times as many. Now each `set_output`
/// compares one name, so doubling the outputs doubles the work.
#[test]
fn building_n_outputs_compares_o_n_names_in_the_front_end_and_atomise() {
    let (p1, a1, n1) = output_work(20_000);
    let (p2, a2, n2) = output_work(40_000);
    assert!(n1 >= 18_000 && n2 as f64 >= 1.9 * n1 as f64, "generator: {n1}, {n2} outputs");
    for (what, w1, w2) in [("front end", p1, p2), ("atomise", a1, a2)] {
        assert!(w1 <= 2 * n1 && w2 <= 2 * n2, "{what}: {w1} comparisons for {n1} outputs, {w2} for {n2}");
        assert!(w2 as f64 <= 2.5 * w1 as f64, "{what}: {w1} → {w2} comparisons when the outputs double");
    }
}

#[test]
fn an_over_long_statement_is_quoted_in_a_few_hundred_bytes_with_line_and_column() {
    let d = tmp("long");
    let names: Vec<String> =
        (0..1500).map(|i| format!("LongTemporaryName_{i:05}_abcdefghijklmnopqrstuvwxyz_0123456789")).collect();
    let stmt = format!("  T1 = {} $ q[1];", names.join("+"));
    assert!(stmt.len() > 90_000);
    let src = format!("void mbs_f(double *c, MbsData *s, double tsim)\n{{\n  x = q[2];\n{stmt}\n  c[1] = T1;\n}}\n");
    let path = d.join("long.c");
    std::fs::write(&path, &src).unwrap();
    let o = opt(&[path.to_str().unwrap(), "-passes=atomise"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    // The `$` is on line 4, column (its byte offset in the line) + 1.
    let col = stmt.find('$').unwrap() + 1;
    assert!(err.contains(&format!("long.c:4:{col}")), "{err}");
    assert!(err.len() < 1000, "{} bytes of diagnostic:\n{err}", err.len());
    assert!(err.contains("unexpected character") && err.contains("4 │ …") && err.contains("$ q[1];"), "{err}");
}

/// `-time-limit=1` stops eqsat between windows: exit 0, a valid IR, a note on stderr and in
/// the report. (Without the limit this run takes about 10 s in release, longer in debug.)
#[test]
fn time_limit_stops_a_heavy_eqsat_with_a_valid_ir_and_a_note() {
    let d = tmp("time_limit");
    let input = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c");
    let (out, report) = (d.join("out.rvir"), d.join("report.json"));
    let o = opt(&[
        input.to_str().unwrap(),
        "-passes=atomise,eqsat<window=64;nodes=1000000>",
        "-time-limit=1",
        "-o",
        out.to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let note = err.lines().find(|l| l.starts_with("note: eqsat stopped after ")).unwrap_or_else(|| panic!("{err}"));
    assert!(note.ends_with("windows of @dirdyna: time limit of 1 s reached"), "{note}");
    let ir = std::fs::read_to_string(&out).unwrap();
    let m = robovec_ir::text::parse(&ir).unwrap_or_else(|e| panic!("{e:?}"));
    robovec_ir::verifier::verify(&m).unwrap_or_else(|e| panic!("{e:?}"));
    assert_eq!(m.functions[0].outputs.len(), 192, "every output kept (the issue counts 192)");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["stopped_early"][0].as_str(), Some(note.trim_start_matches("note: ")));
    let e = &r["eqsat"][0];
    assert_eq!(e["stopped_early"].as_str(), Some("time limit of 1 s reached"));
    assert!(e["windows_tried"].as_u64().unwrap() < e["windows_total"].as_u64().unwrap(), "{e}");
}

#[test]
fn a_bad_time_limit_is_a_usage_error() {
    let input = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c");
    for bad in ["0", "-1", "abc", "inf", "NaN", ""] {
        let o = opt(&[input.to_str().unwrap(), "-passes=atomise", &format!("-time-limit={bad}")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "-time-limit={bad}: {err}");
        assert!(err.contains("time-limit"), "{err}");
    }
    // Any positive number (issue 29: 1e20 was refused): one beyond the clock is no limit.
    for good in ["30", "1e20", "1.7e308"] {
        let o = opt(&[input.to_str().unwrap(), "-passes=atomise,balance", &format!("-time-limit={good}"), "-o", "-"]);
        assert!(o.status.success() && String::from_utf8_lossy(&o.stderr).is_empty(), "-time-limit={good}");
    }
}

/// A limit already reached when `place` and `sweep` start: `place`, which the output needs,
/// makes its first schedule in the limit's grace and searches no further, `sweep` is skipped,
/// each with a note; the placed IR is valid.
#[test]
fn time_limit_stops_place_search_and_sweep_with_notes() {
    let d = tmp("time_limit_place");
    // The limit covers loading too, and reading a Robotran file reads the clock: the passes
    // start from the atomised IR, whose reader does not.
    let input = d.join("atomised.rvir");
    let c = corpus_dir().join("c/tricycle__mbs_cons_hJ_tricycle.c");
    let o = opt(&[c.to_str().unwrap(), "-passes=atomise", "-o", input.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = d.join("out.rvir");
    // Tricycle `cons_hJ` on 2 + 2 PEs is far enough above its bounds that place searches.
    let o = opt(&[
        input.to_str().unwrap(),
        "-passes=place<add=2;mul=2>",
        "-time-limit=0.000001",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("note: place stopped searching @cons_hJ early (best schedule so far kept): time limit of 0.000001 s reached"),
        "{err}"
    );
    let m = robovec_ir::text::parse(&std::fs::read_to_string(&out).unwrap()).unwrap_or_else(|e| panic!("{e:?}"));
    robovec_ir::verifier::verify(&m).unwrap_or_else(|e| panic!("{e:?}"));
    assert!(m.functions[0].placement.is_some());
    let o =
        opt(&[input.to_str().unwrap(), "-passes=sweep<pe=1,2>", "-time-limit=0.000001", "-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("note: sweep<pe=1,2> skipped: time limit of 0.000001 s reached before it started"), "{err}");
}

/// `accuracy` reads `-time-limit` too (once per chunk of samples): ten million samples of the
/// double pendulum (far more than a second's work) stop with the figures of the samples
/// measured, and say so in the report and on stderr.
#[test]
fn time_limit_stops_accuracy_with_its_figures_and_a_note() {
    let d = tmp("accuracy");
    let report = d.join("r.json");
    let example =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/double_pendulum/mbs_invdyna_double_pendulum.c");
    let o = opt(&[
        example.to_str().unwrap(),
        "-passes=atomise,accuracy<samples=10000000>",
        "-time-limit=1",
        &format!("-report={}", report.display()),
        "-o",
        d.join("out.rvir").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("@invdyna: accuracy stopped early: time limit"), "{err}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let why = r["accuracy"]["stopped_early"].as_str().expect("stopped_early set");
    assert!(why.starts_with("time limit"), "{why}");
    let samples = r["accuracy"]["samples"].as_u64().unwrap();
    assert!((1..10_000_000).contains(&samples), "{samples} samples measured");
    assert!(r["accuracy"]["f32"]["mean_bits"].as_f64().unwrap().is_finite());
}

/// `accuracy<mode=hard>`'s hill climbing reads `-time-limit` once per round (issue 28: Jeep
/// `dirdyna` with `climb=100;climb-points=1000` ran over 300 s under `-time-limit=5`): 64
/// climbs of 100 rounds of Jeep (far more than two seconds' work) stop, and say how far they got.
#[test]
fn time_limit_stops_accuracy_hill_climbing_with_a_note() {
    let d = tmp("accuracy_climb");
    let report = d.join("r.json");
    let jeep = corpus_dir().join("c/jeep__mbs_dirdyna_Jeep.c");
    let o = opt(&[
        jeep.to_str().unwrap(),
        "-passes=atomise,accuracy<samples=64;mode=hard;climb=100;climb-points=64>",
        "-time-limit=2",
        &format!("-report={}", report.display()),
        "-o",
        d.join("out.rvir").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let why = r["accuracy"]["stopped_early"].as_str().unwrap_or_else(|| panic!("no stopped_early: {err}"));
    let cut = why.split("; ").find(|w| w.starts_with("time limit: ")).unwrap_or_else(|| panic!("{why}"));
    // `time limit: R of 6400 hill-climbing rounds (64 climbs of 100)`.
    let done: u64 = cut["time limit: ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!(cut.ends_with(" of 6400 hill-climbing rounds (64 climbs of 100)") && done < 6400, "{cut}");
    assert!(err.contains(&format!("@dirdyna: accuracy stopped early: {why}")), "{err}");
    assert!(r["accuracy"]["f32"]["max_bits"].as_f64().unwrap().is_finite());
}

/// `sim` reads `-time-limit` between seeds (issue 28: `sim<seeds=10000>` ran 18 s under
/// `-time-limit=5`): the seeds simulated are checked, the stats say how many, and a note says
/// where it stopped. (Stops in the lowering and the first seed: `sim`'s unit tests.)
#[test]
fn time_limit_stops_sim_between_seeds_with_a_note() {
    let d = tmp("sim_limit");
    let placed = d.join("placed.rvir");
    let segway = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c");
    let o = opt(&[segway.to_str().unwrap(), "-passes=atomise,place<pe=4>", "-o", placed.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report = d.join("r.json");
    let o = opt(&[
        placed.to_str().unwrap(),
        "-passes=sim<seeds=10000>",
        "-time-limit=0.5",
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let note = err.lines().find(|l| l.starts_with("note: sim stopped after ")).unwrap_or_else(|| panic!("{err}"));
    assert!(note.ends_with(" of 10000 seeds of @dirdyna: time limit of 0.5 s reached"), "{note}");
    let done: u32 = note["note: sim stopped after ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!((1..10_000).contains(&done), "{note}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["stopped_early"][0].as_str(), Some(note.trim_start_matches("note: ")));
    assert_eq!(r["sim"]["seeds"].as_u64(), Some(u64::from(done)), "{}", r["sim"]);
    // A limit reached before `sim` starts: skipped (a check the output does not need), one note.
    let o = opt(&[placed.to_str().unwrap(), "-passes=sim", "-time-limit=0.000001", "-o", "/dev/null"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("note: sim skipped: time limit of 0.000001 s reached before it started"), "{err}");
}

#[test]
fn time_limit_stops_pareto_measurements_with_a_note_per_pipeline() {
    let d = tmp("pareto_limit");
    let report = d.join("r.json");
    let example =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/double_pendulum/mbs_invdyna_double_pendulum.c");
    let o = opt(&[
        example.to_str().unwrap(),
        "-passes=atomise",
        "-pareto=atomise;atomise,balance",
        "-pareto-samples=10000000",
        "-time-limit=1",
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    for p in ["atomise", "atomise,balance"] {
        assert!(err.contains(&format!("note: -pareto pipeline {p}: accuracy stopped early: time limit")), "{err}");
    }
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for row in r["pareto"].as_array().unwrap() {
        let samples = row["samples"].as_u64().unwrap();
        assert!((1..10_000_000).contains(&samples), "{samples} samples measured");
        assert!(row["stopped_early"][0].as_str().unwrap().starts_with("accuracy stopped early: time limit"));
    }
}

/// `-check` reads `-time-limit` between chunks of points (issue 28: "any run"): ten million
/// points of the double pendulum (far more than a second's work) stop with a note saying how
/// many were checked; the run still succeeds and writes its output.
#[test]
fn time_limit_stops_check_with_a_note() {
    let d = tmp("check_limit");
    let example =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/double_pendulum/mbs_invdyna_double_pendulum.c");
    let out = d.join("out.rvir");
    let o = opt(&[
        example.to_str().unwrap(),
        "-passes=atomise,balance",
        "-check",
        "-check-samples=10000000",
        "-time-limit=1",
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let note = err.lines().find(|l| l.starts_with("note: -check stopped after ")).unwrap_or_else(|| panic!("{err}"));
    assert!(note.ends_with(" of 10000000 samples of @invdyna: time limit of 1 s reached"), "{note}");
    let done: u64 = note["note: -check stopped after ".len()..].split(' ').next().unwrap().parse().unwrap();
    assert!((256..10_000_000).contains(&done) && done.is_multiple_of(256), "{note}");
    assert!(out.exists(), "the output is written");
}

/// Cascading parse errors are capped (issue 29: one swapped line of a `.py` file gave 49 KB of
/// errors): the first 20 are shown, then how many more there are.
#[test]
fn parse_errors_are_capped_with_a_count_of_the_rest() {
    let d = tmp("error_cap");
    let py = d.join("bad.py");
    let mut t = String::from("import numpy as np\n\ndef dirdyna(M, c, s, tsim):\n  q = s.q\n");
    for k in 1..=60 {
        t += &format!("  T{k} = q[1] +* q[2]\n");
    }
    std::fs::write(&py, t).unwrap();
    let o = opt(&[py.to_str().unwrap(), "-passes=atomise"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    let shown = e.lines().filter(|l| l.starts_with("error")).count();
    assert_eq!(shown, 21, "20 diagnostics and the count: {e}");
    assert!(
        e.trim_end()
            .ends_with("error: … and 40 more errors not shown (fix the first ones: later ones often follow from them)"),
        "{e}"
    );
    assert!(e.contains("bad.py:5:") && !e.contains("bad.py:25:"), "the first ones, located: {e}");
}
