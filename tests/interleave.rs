//! `interleave<states=K>` (issue 49 item 3, throughput): K independent states in one function,
//! evaluated, placed, simulated and reported per state. The Icarus check of an interleaved
//! design is in `fpga.rs`.

use std::collections::BTreeMap;

use crate::common::{opt, opt_to_ir, stderr, tmp};

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

/// The outputs of `-eval` (binary64) of `src` after `pipeline` on the inputs `given`.
fn eval(pipeline: &str, given: &BTreeMap<String, f64>, dir: &std::path::Path, name: &str) -> BTreeMap<String, f64> {
    let file = dir.join(format!("{name}.json"));
    std::fs::write(&file, serde_json::to_string(given).unwrap()).unwrap();
    let o = opt(&[PENDULUM, &format!("-passes={pipeline}"), &format!("-eval={}", file.display()), "-o", "/dev/null"]);
    assert!(o.status.success(), "{pipeline}: {}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("eval JSON");
    v["outputs"].as_object().unwrap().iter().map(|(k, x)| (k.clone(), x.as_f64().unwrap())).collect()
}

/// The pendulum's inputs (as `-eval` lists them after `atomise`).
fn pendulum_inputs(dir: &std::path::Path) -> Vec<String> {
    let o = opt(&[PENDULUM, "-passes=atomise", &format!("-eval={}", write(dir, "none.json", "{}").display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    v["inputs"].as_object().unwrap().keys().cloned().collect()
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn three_interleaved_states_evaluate_as_three_separate_evaluations() {
    let d = tmp("eval");
    let names = pendulum_inputs(&d);
    assert!(names.iter().any(|n| n == "q[1]") && names.len() > 10, "{names:?}");
    // Distinct inputs per state: state s's input i is a different number for every (s, i).
    let value = |s: usize, i: usize| 0.1 + 0.37 * s as f64 - 0.053 * i as f64 + 0.011 * (s * i) as f64;
    let mut all = BTreeMap::new();
    let mut per_state = Vec::new();
    for s in 0..3 {
        let mut one = BTreeMap::new();
        for (i, n) in names.iter().enumerate() {
            one.insert(n.clone(), value(s, i));
            all.insert(if s == 0 { n.clone() } else { format!("{n}#{s}") }, value(s, i));
        }
        per_state.push(one);
    }
    let together = eval("atomise,cse,interleave<states=3>", &all, &d, "all");
    let mut expected = 0;
    for (s, given) in per_state.iter().enumerate() {
        let alone = eval("atomise,cse", given, &d, &format!("state{s}"));
        for (name, y) in &alone {
            let key = if s == 0 { name.clone() } else { format!("{name}#{s}") };
            let z = together.get(&key).unwrap_or_else(|| panic!("no output {key}"));
            assert_eq!(y.to_bits(), z.to_bits(), "state {s} output {name}: alone {y}, interleaved {z}");
            expected += 1;
        }
    }
    assert_eq!(together.len(), expected, "no other outputs");
    // The states differ (distinct inputs), so the check compared different numbers.
    assert_ne!(together["Qq[1]"], together["Qq[1]#1"]);
}

#[test]
fn states_print_and_read_back_and_zero_states_are_refused() {
    let d = tmp("text");
    let src = "func @f {\n  phase atomised\n  equations 1\n  states 3\n  input %a\n  input %a#1\n  input %a#2\n  \
               %x = mul %a, %a\n  %x#1 = mul %a#1, %a#1\n  %x#2 = mul %a#2, %a#2\n  output y = %x\n  \
               output y#1 = %x#1\n  output y#2 = %x#2\n}\n";
    let m = robovec_ir::text::parse(src).expect("parses");
    assert_eq!(m.functions[0].states, 3);
    assert_eq!(m.to_string(), src, "prints exactly as read");
    // Through the tool: an empty pipeline writes it back unchanged.
    let input = write(&d, "three.rvir", src);
    let (_, out) = opt_to_ir(&d, &[input.to_str().unwrap(), "-passes="]);
    assert_eq!(out.to_string(), src);
    // One state prints no `states` line.
    let one = robovec_ir::text::parse("func @f { phase atomised input %a output y = %a }").unwrap();
    assert!(!one.to_string().contains("states"), "{one}");
    assert_eq!(one.functions[0].states, 1);
    // `states 0` is bad input (exit 1) from the verifier.
    let zero = write(&d, "zero.rvir", &src.replace("states 3", "states 0"));
    let o = opt(&[zero.to_str().unwrap(), "-passes=", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("`states 0`: a function computes at least one state"), "{}", stderr(&o));
    let errs = robovec_ir::verifier::verify(&robovec_ir::text::parse(&src.replace("states 3", "states 0")).unwrap())
        .unwrap_err();
    assert_eq!(errs.len(), 1, "{errs:?}");
}

#[test]
fn bad_states_parameters_are_usage_errors() {
    for bad in ["0", "1025", "-1", "two"] {
        let o = opt(&[PENDULUM, &format!("-passes=atomise,interleave<states={bad}>"), "-o", "/dev/null"]);
        assert_eq!(o.status.code(), Some(2), "states={bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("states"), "states={bad}: {}", stderr(&o));
    }
    // A Robotran signature takes one state: refused, naming the way out; abi=plain takes them all.
    let o = opt(&[PENDULUM, "-passes=atomise,interleave<states=2>,codegen<c;abi=robotran>", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("evaluates 2 states") && stderr(&o).contains("abi=plain"), "{}", stderr(&o));
    let o = opt(&[PENDULUM, "-passes=atomise,interleave<states=2>,codegen<c;abi=plain>", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // K = 1 is the identity.
    let d = tmp("identity");
    let (_, a) = opt_to_ir(&d, &[PENDULUM, "-passes=atomise,cse"]);
    let (_, b) = opt_to_ir(&d, &[PENDULUM, "-passes=atomise,cse,interleave<states=1>"]);
    assert_eq!(a.to_string(), b.to_string());
}

#[test]
fn the_report_gives_latency_and_time_per_state() {
    let d = tmp("report");
    for k in [1u32, 2, 4] {
        let (r, m) = opt_to_ir(
            &d,
            &[
                PENDULUM,
                &format!("-passes=atomise,cse,interleave<states={k}>,place<pe=2;restarts=0;search=0>"),
                "-stats",
            ],
        );
        assert_eq!(m.functions[0].states, k);
        let p = &r["placement"];
        let (cycles, clock) = (p["cycles"].as_f64().unwrap(), p["clock_mhz"].as_f64().unwrap());
        assert_eq!(p["states"], k);
        let want = cycles / clock * 1000.0 / f64::from(k);
        let got = p["ns_per_state"].as_f64().unwrap();
        assert!((got - want).abs() <= 1e-9 * want, "K={k}: ns_per_state {got}, cycles/clock·1000/K = {want}");
        // The latency stays the whole evaluation's.
        assert!((p["us"].as_f64().unwrap() - cycles / clock).abs() < 1e-12);
        // SPEC §7's keys are all still there.
        for key in ["n_add", "n_mul", "lat_add", "lat_mul", "cycles", "lower_bound", "parallelisation_rate"] {
            assert!(!p[key].is_null(), "{key}");
        }
    }
    // -stats says it beside the latency when there are several states.
    let o = opt(&[
        PENDULUM,
        "-passes=atomise,cse,interleave<states=4>,place<pe=2;restarts=0;search=0>",
        "-stats",
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = stderr(&o).lines().find(|l| l.contains("placed on")).unwrap().to_string();
    assert!(line.contains(" MHz (4 states: ") && line.contains(" ns per state)"), "{line}");
    // `sweep`'s rows too.
    let (r, _) = opt_to_ir(&d, &[PENDULUM, "-passes=atomise,interleave<states=3>,sweep<pe=1,2>"]);
    let rows = r["sweep"].as_array().expect("sweep rows");
    assert!(!rows.is_empty());
    for row in rows {
        assert_eq!(row["states"], 3);
        let want = row["us"].as_f64().unwrap() * 1000.0 / 3.0;
        assert!((row["ns_per_state"].as_f64().unwrap() - want).abs() <= 1e-9 * want, "{row}");
    }
}

const PENDULUM_RANGES: &str = r#"{"q[*]": [-3.2, 3.2], "qd[*]": [-10, 10], "qdd[*]": [-10, 10], "g[3]": [-9.81, -9.81],
  "dpt[*][*]": [0.5, 0.5], "m[*]": [1, 1], "l[*][*]": [0.25, 0.25], "In[*][*]": [0.1, 0.1]}"#;

/// A fixed-point function interleaved: the state copies' inputs range as their base inputs, so
/// `sim` (which draws its points in the domain) and `error-bound` run after `interleave`.
#[test]
fn fixed_point_states_are_simulated_in_the_domain_of_their_base_inputs() {
    let d = tmp("fixed");
    let ranges = write(&d, "ranges.json", PENDULUM_RANGES);
    let (r, m) = opt_to_ir(
        &d,
        &[
            PENDULUM,
            &format!("-ranges={}", ranges.display()),
            "-passes=atomise,cse,precision<budget=1e-4;target=mcu>,interleave<states=2>,place<pe=2;restarts=0;search=0>,sim,error-bound<format=mixed>",
        ],
    );
    let f = &m.functions[0];
    assert_eq!(f.states, 2);
    assert!(f.lookup("q[1]#1").is_some());
    // Formats are copied: each copy has its original's.
    for &v in &f.inputs {
        let (base, _) = robovec_ir::split_state(f.name_of(v));
        assert_eq!(f.format(v), f.format(f.lookup(base).unwrap()), "{}", f.name_of(v));
    }
    assert_eq!(r["sim"]["precisions"], serde_json::json!(["fixed point"]));
    // Both states have the same certified bound (the same ops over the same domain).
    let outs = r["error_bound"]["outputs"].as_object().expect("error-bound outputs");
    assert_eq!(outs.len(), 4);
    assert_eq!(outs["Qq[1]"]["abs"], outs["Qq[1]#1"]["abs"]);
    assert!(outs["Qq[1]"]["abs"].as_f64().unwrap() > 0.0);
}

/// The formats `precision` certified for one state verify after `interleave`: the verifier's
/// fixed-point range check encloses each state as tightly as one alone (the harmonic forms'
/// atom cap is one state's, `range::harmonic::range_atoms`). On the Jeep `dirdyna` (8k ops)
/// over the generous domain the cap of the doubled function, 64 atoms against one state's 128,
/// enclosed a value of state 0 beyond the format precision had given it.
#[test]
fn formats_certified_for_one_state_verify_after_interleaving() {
    let d = tmp("formats_per_state");
    let jeep = crate::common::corpus_dir().join("c/jeep__mbs_dirdyna_Jeep.c").display().to_string();
    let (m, _) = robovec::driver::load(&jeep).unwrap_or_else(|f| panic!("{}", f.message()));
    let dom = crate::range::generous_domain(&m.functions[0]);
    let ranges: serde_json::Map<String, serde_json::Value> =
        dom.ranges.iter().map(|(name, r)| (name.clone(), serde_json::json!([r.interval.lo, r.interval.hi]))).collect();
    let file = write(&d, "ranges.json", &serde_json::Value::Object(ranges).to_string());
    let o = opt(&[
        &jeep,
        &format!("-ranges={}", file.display()),
        "-passes=atomise,cse,precision<budget=1e-2;target=mcu>,interleave<states=2>",
        "-stats",
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("fix<32,*>"), "precision gave fixed-point formats: {}", stderr(&o));
}
