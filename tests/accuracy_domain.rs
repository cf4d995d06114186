//! `accuracy` in an input domain (issue 48): with `-ranges=FILE` or `accuracy<ranges=FILE>`
//! every input the domain covers is drawn inside its range — sampled, hard and after hill
//! climbing — on a corpus file; the report says where the inputs were drawn (`drawn_in`) and
//! gives each output's largest absolute errors (`max_abs_f32`, `max_abs_f64`), which bound the
//! errors recomputed by an independent route; a bad ranges file is a located error.

use std::collections::BTreeMap;

use robovec_ir::interp;
use robovec_ir::numerics::reference::eval_big;
use robovec_ir::numerics::Tape;

use crate::common::{corpus_dir, opt, stderr, tmp};

/// Every input family of the Segway's `invdyna`, with ends that are not binary32 numbers and
/// a few points (one not binary32: −9.81).
const SEGWAY_RANGES: &str = r#"{
  "q[*]": [-0.4, 1.9], "qd[*]": [-3.3, 3.1], "qdd[*]": [-5, 5],
  "In[*][*]": [0.01, 0.3], "dpt[*][*]": [-0.7, 0.7], "l[*][*]": [-0.3, 0.3],
  "m[*]": [0.5, 12.1], "frc[*][*]": [-20, 20], "trq[*][*]": [-2.5, 2.5],
  "g[*]": [0, 0], "g[3]": [-9.81, -9.81]
}"#;

fn segway() -> String {
    corpus_dir().join("c/frank_segway__mbs_invdyna_Frank_segway.c").display().to_string()
}

/// The range `SEGWAY_RANGES` gives `name` (exact key first, then the glob of its family).
fn expected_range(name: &str) -> (f64, f64) {
    let ranges: BTreeMap<String, (f64, f64)> = serde_json::from_str(SEGWAY_RANGES).unwrap();
    if let Some(&r) = ranges.get(name) {
        return r;
    }
    let base = &name[..name.find('[').unwrap()];
    let glob = if name.matches('[').count() == 2 { format!("{base}[*][*]") } else { format!("{base}[*]") };
    ranges[&glob]
}

/// Runs `passes` on the Segway's `invdyna` with `extra` options: the report and stderr.
fn run(d: &std::path::Path, passes: &str, extra: &[&str]) -> (serde_json::Value, String) {
    let r = d.join("r.json");
    let seg = segway();
    let mut args = vec![seg.as_str(), "-stats"];
    let p = format!("-passes={passes}");
    let rep = format!("-report={}", r.display());
    args.extend([p.as_str(), rep.as_str(), "-o", "/dev/null"]);
    args.extend(extra);
    let o = opt(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    (serde_json::from_str(&std::fs::read_to_string(r).unwrap()).unwrap(), stderr(&o))
}

/// Every input of every listed point lies in its range, exactly.
fn assert_inside(acc: &serde_json::Value, want_points: usize) {
    let worst = acc["worst"].as_array().unwrap();
    assert_eq!(worst.len(), want_points);
    let mut inputs = 0;
    for w in worst {
        for (name, x) in w["inputs"].as_object().unwrap() {
            let (lo, hi) = expected_range(name);
            let x = x.as_f64().unwrap();
            assert!(lo <= x && x <= hi, "{name} = {x:e} outside [{lo}, {hi}]");
            inputs += 1;
        }
    }
    assert!(inputs > 150 * want_points, "{inputs} inputs checked");
}

#[test]
fn a_domain_run_on_the_corpus_draws_every_input_inside_it() {
    let d = tmp("acc_domain");
    let ranges = d.join("segway.json");
    std::fs::write(&ranges, SEGWAY_RANGES).unwrap();
    let ranges = ranges.display().to_string();
    // Hard mode, every point kept (worst-count ≥ samples) and every point climbed from: the
    // listed points are every sample after its climb.
    let (r, e) = run(
        &d,
        "atomise,accuracy<mode=hard;samples=120;worst-count=1000;climb-points=120;climb=3>",
        &[&format!("-ranges={ranges}")],
    );
    let acc = &r["accuracy"];
    assert_eq!(acc["drawn_in"], "domain");
    assert_eq!(acc["evaluations"], 120 + 120 * 3 * 8);
    assert_inside(acc, 120);
    let n = acc["worst"][0]["inputs"].as_object().unwrap().len();
    assert!(e.contains(&format!("@invdyna: inputs drawn in: domain ({n} of {n} drawn inputs in the domain)")), "{e}");
    assert!(e.contains("max abs f32"), "{e}");
    // The report's `domain` (what -ranges resolved) is what the test expects.
    for (name, entry) in r["domain"].as_object().unwrap() {
        let (lo, hi) = expected_range(name);
        assert_eq!(entry["range"], serde_json::json!([lo, hi]), "{name}");
    }
    // The absolute errors bound the errors at the listed points, recomputed from the
    // interpreter and a 1024-bit reference (half an ulp of slack: `eval_big` rounds the exact
    // value to binary64).
    let (m, _) = robovec::driver::load(&segway()).map_err(|f| f.message().to_string()).unwrap();
    let f = &m.functions[0];
    let t = Tape::new(f);
    let all: Vec<usize> = (0..t.outputs.len()).collect();
    let outputs = acc["outputs"].as_object().unwrap();
    let mut seen32 = vec![0.0f64; all.len()];
    for w in acc["worst"].as_array().unwrap().iter().take(20) {
        let inputs: BTreeMap<String, f64> = serde_json::from_value(w["inputs"].clone()).unwrap();
        let x: Vec<f64> = t.inputs.iter().map(|n| inputs[n]).collect();
        let exact = eval_big(&t, &x, 1024, &all);
        let c32 = interp::eval::<f32>(f, |n| inputs[n]);
        let c64 = interp::eval::<f64>(f, |n| inputs[n]);
        for (k, (name, _)) in t.outputs.iter().enumerate() {
            let o = &outputs[name];
            let slack = exact[k].f64.abs() * f64::EPSILON;
            let d32 = (c32[k].1 as f64 - exact[k].f64).abs();
            let d64 = (c64[k].1 - exact[k].f64).abs();
            assert!(d32 <= o["max_abs_f32"].as_f64().unwrap() + slack, "{name}: {d32:e} above {}", o["max_abs_f32"]);
            assert!(d64 <= o["max_abs_f64"].as_f64().unwrap() + slack, "{name}: {d64:e} above {}", o["max_abs_f64"]);
            seen32[k] = seen32[k].max(d32);
        }
    }
    // Not vacuous: binary32's largest error is far above binary64's on some output.
    assert!(outputs.values().any(|o| o["max_abs_f32"].as_f64().unwrap() > 1e6 * o["max_abs_f64"].as_f64().unwrap()));
    assert!(seen32.iter().any(|&x| x > 0.0));

    // Sampled, with the pass's own `ranges=FILE` (no -ranges): the same domain.
    let (r, _) = run(&d, &format!("atomise,accuracy<samples=150;worst-count=1000;ranges={ranges}>"), &[]);
    assert_eq!(r["accuracy"]["drawn_in"], "domain");
    assert_inside(&r["accuracy"], 150);
    assert!(r.get("domain").is_none(), "the pass's file is not the run's domain");
}

#[test]
fn without_a_domain_the_physical_table_is_used_and_said() {
    let d = tmp("acc_table");
    let (r, e) = run(&d, "atomise,accuracy<samples=50>", &[]);
    assert_eq!(r["accuracy"]["drawn_in"], "physical table");
    assert!(!e.contains("inputs drawn in"), "{e}");
    for o in r["accuracy"]["outputs"].as_object().unwrap().values() {
        assert!(o["max_abs_f32"].as_f64().unwrap() >= o["max_abs_f64"].as_f64().unwrap());
    }
    // A domain that covers some inputs only: those inside, the others from the table.
    let ranges = d.join("q.json");
    std::fs::write(&ranges, r#"{"q[*]": [0.25, 0.5]}"#).unwrap();
    let (r, e) = run(&d, "atomise,accuracy<samples=50;worst-count=50>", &[&format!("-ranges={}", ranges.display())]);
    let acc = &r["accuracy"];
    assert_eq!(acc["drawn_in"], "domain and physical table");
    assert!(e.contains("inputs drawn in: domain and physical table ("), "{e}");
    let mut outside = 0;
    for w in acc["worst"].as_array().unwrap() {
        for (name, x) in w["inputs"].as_object().unwrap() {
            let x = x.as_f64().unwrap();
            if name.starts_with("q[") {
                assert!((0.25..=0.5).contains(&x), "{name} = {x}");
            } else {
                outside += !(0.25..=0.5).contains(&x) as u32;
            }
        }
    }
    assert!(outside > 100, "the table's inputs are not confined: {outside}");
}

#[test]
fn a_bad_ranges_file_of_the_pass_is_a_located_error() {
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        "-passes=accuracy<ranges=tests/inputs/ranges/reversed.json>",
        "-o",
        "/dev/null",
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("accuracy"), "{e}");
    assert!(e.contains("bad range for `b`: lo = 3 is greater than hi = -1"), "{e}");
    assert!(e.contains("reversed.json:2:2"), "{e}");
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        "-passes=accuracy<ranges=tests/inputs/ranges/unknown.json>",
        "-o",
        "/dev/null",
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("`c`: no input is named so") && e.contains("unknown.json:2:2"), "{e}");
}
