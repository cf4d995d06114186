//! The `accuracy` pass and `-pareto` end to end: report shape (SPEC §7), determinism, worst
//! points re-checked by an independent route (interpreter + 1024-bit reference) and replayed
//! with `-eval`, `params` files, diagnostics, and the speed-against-error table.

use robovec_ir::interp;
use robovec_ir::numerics::reference::eval_big;
use robovec_ir::numerics::{bits_f32, bits_f64, Tape};

use crate::common::{corpus_dir, opt, stderr, tmp};

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

fn report(d: &std::path::Path, input: &str, passes: &str, extra: &[&str]) -> serde_json::Value {
    let r = d.join("r.json");
    let mut args = vec![input.to_string(), format!("-passes={passes}"), format!("-report={}", r.display())];
    args.extend(extra.iter().map(|s| s.to_string()));
    args.extend(["-o".to_string(), d.join("out.rvir").display().to_string()]);
    let o = opt(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(r).unwrap()).unwrap()
}

#[test]
fn report_has_the_spec_accuracy_object_and_is_deterministic() {
    let d = tmp("shape");
    let a = report(&d, PENDULUM, "atomise,accuracy<samples=300;seed=7>", &[]);
    let acc = &a["accuracy"];
    assert_eq!(acc["samples"], 300);
    for p in ["f32", "f64"] {
        for k in ["mean_bits", "p95_bits", "max_bits"] {
            assert!(acc[p][k].is_number(), "accuracy.{p}.{k} missing: {acc}");
        }
        let s = &acc[p];
        assert!(s["mean_bits"].as_f64() <= s["p95_bits"].as_f64().map(|x| x.max(s["mean_bits"].as_f64().unwrap())));
        assert!(s["p95_bits"].as_f64() <= s["max_bits"].as_f64());
    }
    let outs = acc["outputs"].as_object().unwrap();
    assert_eq!(outs.keys().collect::<Vec<_>>(), ["Qq[1]", "Qq[2]"]);
    assert!(outs["Qq[1]"]["f32"]["max_bits"].as_f64().unwrap() <= acc["f32"]["max_bits"].as_f64().unwrap());
    // binary32 loses ~29 bits more than binary64 on each value, but bits of error count floats
    // of each format: both stay small on this well-conditioned model.
    assert!(acc["f32"]["mean_bits"].as_f64().unwrap() < 4.0 && acc["f64"]["mean_bits"].as_f64().unwrap() < 4.0);
    let b = report(&d, PENDULUM, "atomise,accuracy<samples=300;seed=7>", &[]);
    assert_eq!(a["accuracy"], b["accuracy"], "same seed, same figures");
    let c = report(&d, PENDULUM, "atomise,accuracy<samples=300;seed=8>", &[]);
    assert_ne!(a["accuracy"]["worst"], c["accuracy"]["worst"], "another seed draws other points");
}

#[test]
fn worst_points_are_recomputed_by_an_independent_route() {
    let d = tmp("worst");
    // The inputs go through JSON: this also checks that they read back exactly.
    let r = report(&d, PENDULUM, "accuracy<samples=200;worst-count=4>", &[]);
    let (m, _) = robovec::driver::load(PENDULUM).map_err(|f| f.message().to_string()).unwrap();
    let f = &m.functions[0];
    let t = Tape::new(f);
    let all: Vec<usize> = (0..t.outputs.len()).collect();
    let worst = r["accuracy"]["worst"].as_array().unwrap();
    assert_eq!(worst.len(), 4);
    for w in worst {
        let inputs: std::collections::BTreeMap<String, f64> = serde_json::from_value(w["inputs"].clone()).unwrap();
        let by_name = |n: &str| inputs[n];
        let c32 = interp::eval::<f32>(f, by_name);
        let c64 = interp::eval::<f64>(f, by_name);
        let x: Vec<f64> = t.inputs.iter().map(|n| inputs[n]).collect();
        let exact = eval_big(&t, &x, 1024, &all);
        let max32 = c32.iter().zip(&exact).map(|(c, e)| bits_f32(c.1, e.f32)).fold(0.0, f64::max);
        let max64 = c64.iter().zip(&exact).map(|(c, e)| bits_f64(c.1, e.f64)).fold(0.0, f64::max);
        assert_eq!(w["max_f32_bits"].as_f64().unwrap(), max32);
        assert_eq!(w["max_f64_bits"].as_f64().unwrap(), max64);
    }
    let firsts: Vec<f64> = worst.iter().map(|w| w["max_f32_bits"].as_f64().unwrap()).collect();
    assert!(firsts.windows(2).all(|p| p[0] >= p[1]), "worst first: {firsts:?}");
}

#[test]
fn hard_mode_writes_worst_points_that_eval_replays() {
    let d = tmp("hard");
    let dir = d.join("worst");
    let passes = format!("atomise,accuracy<mode=hard;samples=300;worst={};worst-count=3>", dir.display());
    let r = report(&d, PENDULUM, &passes, &[]);
    let acc = &r["accuracy"];
    assert_eq!(acc["mode"], "hard");
    assert!(acc["evaluations"].as_u64().unwrap() > 300, "hill climbing evaluated more points");
    for k in 1..=3 {
        let file = dir.join(format!("worst-{k}.json"));
        let o = opt(&[PENDULUM, "-passes=atomise", &format!("-eval={}", file.display())]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
        let e: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let written: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        assert_eq!(e["inputs"], written, "-eval used exactly the worst point");
        assert_eq!(written, acc["worst"][k - 1]["inputs"]);
    }
    assert!(!dir.join("worst-4.json").exists());
    // Joint angles sit near 0, ±π/2, ±π unless the search moved them.
    let q: f64 = serde_json::from_value(acc["worst"][0]["inputs"]["q[1]"].clone()).unwrap();
    assert!(q.abs() <= 4.0, "{q}");
}

#[test]
fn params_files_fix_inputs_and_bad_ones_are_input_errors() {
    let d = tmp("params");
    let p = d.join("p.json");
    std::fs::write(&p, r#"{"m[1]": 2.5, "g[3]": -9.81}"#).unwrap();
    let r = report(&d, PENDULUM, &format!("accuracy<samples=50;params={}>", p.display()), &[]);
    for w in r["accuracy"]["worst"].as_array().unwrap() {
        assert_eq!(w["inputs"]["m[1]"], 2.5);
        assert_eq!(w["inputs"]["g[3]"], -9.81);
    }
    let rep = d.join("bad.json");
    std::fs::write(&p, "{\"m[1]\": 2.5,\n oops}").unwrap();
    let o =
        opt(&[PENDULUM, &format!("-passes=accuracy<params={}>", p.display()), &format!("-report={}", rep.display())]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("line 2, column 2") && stderr(&o).contains("p.json"), "{}", stderr(&o));
    assert!(!rep.exists(), "no report after a failure");
    std::fs::write(&p, r#"{"m[99]": 1.0}"#).unwrap();
    let o = opt(&[PENDULUM, &format!("-passes=accuracy<params={}>", p.display())]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("`m[99]` is not an input"), "{}", stderr(&o));
    let o = opt(&[PENDULUM, "-passes=accuracy<mode=fuzzy>"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("`mode` must be `sampled` or `hard`"), "{}", stderr(&o));
}

#[test]
fn accuracy_keeps_the_ir_and_its_placement() {
    let d = tmp("keep");
    let seg = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c").display().to_string();
    let a = d.join("a.rvir");
    let b = d.join("b.rvir");
    let o = opt(&[&seg, "-passes=atomise,place<pe=4>", "-o", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = opt(&[&seg, "-passes=atomise,place<pe=4>,accuracy<samples=20>,sim", "-stats", "-o", b.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap());
    let e = stderr(&o);
    assert!(e.contains("@dirdyna: accuracy (sampled inputs, 20 samples") && e.contains("placed on 4 ADD"), "{e}");
    assert!(e.contains("f32 mean/p95/max") && e.contains("M[1][1]"), "-stats lists outputs: {e}");
}

#[test]
fn print_passes_shows_accuracy_parameters() {
    let o = opt(&["--print-passes"]);
    let s = String::from_utf8_lossy(&o.stdout);
    for p in ["accuracy", "samples", "seed", "mode", "params", "worst", "worst-count", "climb"] {
        assert!(s.contains(p), "{p} missing:\n{s}");
    }
}

#[test]
fn pareto_table_and_report() {
    let d = tmp("pareto");
    let seg = corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c").display().to_string();
    let pipelines = "atomise;atomise,place<pe=1;improve=0>;atomise,place<pe=4>";
    for flag in ["-pareto", "--pareto"] {
        let r = d.join("r.json");
        let o = opt(&[
            &seg,
            &format!("{flag}={pipelines}"),
            "-pareto-samples=20",
            &format!("-report={}", r.display()),
            "-o",
            d.join("o.rvir").to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("@dirdyna: speed against error (20 samples"), "{e}");
        let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
        let rows = j["pareto"].as_array().unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0]["pipeline"], "atomise");
        assert!(rows[0]["placed_cycles"].is_null() && rows[0]["time_cycles"] == rows[0]["asap_cycle"]);
        assert_eq!(rows[1]["n"], 1);
        // Placement never changes the numbers: same errors, and N = 1 is slower than N = 4.
        assert_eq!(rows[1]["f32"], rows[2]["f32"]);
        assert!(rows[1]["placed_cycles"].as_u64() > rows[2]["placed_cycles"].as_u64());
        assert_eq!(rows[1]["pareto_optimal"], false);
        // The placed N = 4 run cannot beat the critical path: both are on the front only if equal.
        let front: Vec<bool> = rows.iter().map(|r| r["pareto_optimal"].as_bool().unwrap()).collect();
        assert!(front[0]);
        assert_eq!(front[2], rows[2]["time_cycles"] == rows[0]["time_cycles"]);
    }
    let o = opt(&[PENDULUM, "-pareto=atomise;frobnicate"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("-pareto pipeline `frobnicate`: unknown pass"), "{}", stderr(&o));
    let o = opt(&[PENDULUM, "-pareto=atomise;;dce"]);
    assert_eq!(o.status.code(), Some(2));
    let o = opt(&[PENDULUM, "-pareto=place"]);
    assert_eq!(o.status.code(), Some(1), "place on parsed input fails: {}", stderr(&o));
}

#[test]
fn modules_of_several_functions_get_one_worst_file_per_function() {
    let d = tmp("sensors");
    let dir = d.join("w");
    let sensor = corpus_dir().join("c/m454__mbs_sensor_m454_project.c").display().to_string();
    let passes = format!("-passes=accuracy<samples=20;worst={};worst-count=1>", dir.display());
    let o = opt(&[&sensor, &passes, "-o", d.join("o.rvir").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(
        names,
        ["sensor_1-worst-1.json", "sensor_2-worst-1.json", "sensor_3-worst-1.json", "sensor_4-worst-1.json"]
    );
    let o = opt(&[&sensor, "-passes=", "-function=sensor_3", &format!("-eval={}", dir.join(&names[2]).display())]);
    assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
}
