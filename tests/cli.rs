//! `robovec-opt` end to end: SPEC §7 flags, report, eval, dumps, exit statuses.

use std::process::Command;

use crate::common::{corpus_dir, opt, stderr, tmp};

fn segway() -> String {
    corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c").display().to_string()
}

#[test]
fn print_passes_lists_every_pass_and_parameter() {
    let o = opt(&["--print-passes"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    for needle in ["atomise", "dce", "outputs", "asap-alap", "lat-add", "lat-mul", "lat-div", "lat-call"] {
        assert!(s.contains(needle), "missing {needle} in\n{s}");
    }
}

#[test]
fn unknown_passes_and_parameters_are_usage_errors_listing_valid_ones() {
    let o = opt(&[&segway(), "-passes=atomise,frobnicate"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown pass `frobnicate`; valid passes: atomise, dce, asap-alap"), "{}", stderr(&o));
    let o = opt(&[&segway(), "--passes=atomise,asap-alap<lat-foo=3>"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("valid: lat-add, lat-mul, lat-div, lat-call"), "{}", stderr(&o));
    let o = opt(&[&segway(), "-passes=asap-alap<lat-add=x>"]);
    assert_eq!(o.status.code(), Some(2));
}

/// `place<clusters=G>` beyond the smaller side's PEs conflicts with `add`/`mul`, which each take
/// their whole range alone: the pass refuses it when it runs (exit 1, as `codegen<fpga>` refuses
/// `resources=pnr` for a target without an ECP5 part), and the output file is left as it was.
#[test]
fn clusters_beyond_the_pes_are_refused() {
    let d = tmp("clusters_usage");
    let out = d.join("out.rvir");
    std::fs::write(&out, "kept").unwrap();
    let o = opt(&[&segway(), "-passes=atomise,place<add=4;mul=2;clusters=3>", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("clusters=3: at most the smaller side's PEs (2: add=4, mul=2)"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept");
    let o = opt(&[&segway(), "-passes=atomise,place<add=4;mul=2;clusters=2>,sim", "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Named pipelines (issue 31 item 3): `--print-passes` lists them with their expansion; inside a
/// pipeline they run the passes they stand for (`-time-passes` names each, the IR is what the
/// spelled-out pipeline writes); an unknown one is bad usage.
#[test]
fn named_pipelines_are_listed_and_expand_in_place() {
    let o = opt(&["--print-passes"]);
    let s = String::from_utf8_lossy(&o.stdout);
    assert!(s.contains("default<depth>  = atomise,cse,zero-removal,balance,cse,recurrence,cse"), "{s}");
    assert!(s.contains("default<ops>    = atomise,cse,zero-removal,cse,schedule-cpu"), "{s}");
    let d = tmp("named_pipelines");
    let (a, b) = (d.join("named.rvir"), d.join("spelled.rvir"));
    let o = opt(&[&segway(), "-passes=atomise,default<depth>,asap-alap", "-time-passes", "-o", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let log = stderr(&o);
    for pass in ["atomise", "cse", "zero-removal", "balance", "recurrence", "asap-alap"] {
        assert!(log.contains(&format!("  {pass}\n")), "{pass} in\n{log}");
    }
    let o = opt(&[
        &segway(),
        "-passes=atomise,atomise,cse,zero-removal,balance,cse,recurrence,cse,asap-alap",
        "-o",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&a).unwrap(), std::fs::read_to_string(&b).unwrap());
    let o = opt(&[&segway(), "-passes=atomise,default<O2>"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("`default<O2>` is no named pipeline; expected `default<depth>` or `default<ops>`"));
}

#[test]
fn report_has_the_spec_fields_and_the_segway_figures() {
    let d = tmp("report");
    let r = d.join("r.json");
    let o = opt(&[
        &segway(),
        "-passes=atomise,asap-alap",
        &format!("-report={}", r.display()),
        "-o",
        d.join("out.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
    assert_eq!(j["function"], "dirdyna");
    assert_eq!(j["pipeline"], "atomise,asap-alap");
    assert_eq!(j["passes"][0]["name"], "atomise");
    assert_eq!(j["passes"][0]["ops_before"], 4261);
    assert_eq!(j["passes"][0]["ops_after"], 4261);
    assert!(j["passes"][1]["wall_ms"].is_number());
    let s = &j["stats"];
    assert_eq!(s["equations"], 924);
    assert_eq!(s["ops"]["total"], 4261);
    assert_eq!(s["ops"]["add"], 954);
    assert_eq!(s["ops"]["sub"], 923);
    assert_eq!(s["ops"]["mul"], 2384);
    assert_eq!(s["asap"], 65);
    assert_eq!(s["asap_cycle"], 720);
    assert!((s["y"].as_f64().unwrap() - 4261.0 / 720.0).abs() < 1e-12);
    assert!(s["inputs"].as_u64().unwrap() > 0 && s["outputs"].as_u64().unwrap() > 0);
    // The written IR re-reads and carries the timing attributes.
    let o = opt(&[d.join("out.rvir").to_str().unwrap(), "-passes=", "-stats"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("asap_cycle="));
    assert!(stderr(&o).contains("critical path 65 ops / 720 cycles"), "{}", stderr(&o));
}

#[test]
fn dumps_and_prints_are_real_ir() {
    let d = tmp("dumps");
    let dump = d.join("dump");
    let o = opt(&[
        &segway(),
        "-passes=atomise,dce<outputs=c>,asap-alap",
        "-print-after-all",
        &format!("-dump-dir={}", dump.display()),
        "-time-passes",
        "-o",
        d.join("o.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("*** IR Dump After atomise ***") && e.contains("*** IR Dump After asap-alap ***"));
    assert!(e.contains("Pass execution timing report"));
    let mut names: Vec<String> =
        std::fs::read_dir(&dump).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "001-atomise.after.rvir",
            "001-atomise.before.rvir",
            "002-dce.after.rvir",
            "002-dce.before.rvir",
            "003-asap-alap.after.rvir",
            "003-asap-alap.before.rvir"
        ]
    );
    for n in names {
        let o = opt(&[dump.join(&n).to_str().unwrap(), "-passes=", "-o", d.join("x.rvir").to_str().unwrap()]);
        assert!(o.status.success(), "{n}: {}", stderr(&o));
    }
    // dce<outputs=c> dropped the mass matrix.
    let after = std::fs::read_to_string(dump.join("002-dce.after.rvir")).unwrap();
    assert!(!after.contains("output M[") && after.contains("output c[1]"));
}

#[test]
fn eval_uses_given_inputs_and_reports_all_outputs() {
    let d = tmp("eval");
    let inputs = d.join("in.json");
    std::fs::write(&inputs, r#"{"q[4]": 0.25, "dpt[3][2]": 3.5}"#).unwrap();
    let o = opt(&[&segway(), "-passes=atomise", &format!("-eval={}", inputs.display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["inputs"]["q[4]"], 0.25);
    assert_eq!(j["inputs"]["dpt[3][2]"], 3.5);
    // The inputs not given are named, with how many (issue 29: they were silently random).
    let e = stderr(&o);
    let w: Vec<&str> = e.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(w.len(), 1, "{e}");
    let given = j["inputs"].as_object().unwrap().len() - 2;
    let expect = format!("warning: {given} inputs of @dirdyna not in {} get pseudo-random values", inputs.display());
    assert!(w[0].starts_with(&expect) && w[0].contains(" in [-1, 1] (seed 0): q["), "{}", w[0]);
    assert!(w[0].ends_with(&format!(" and {} more", given - 6)), "{}", w[0]);
    assert!(j["outputs"]["M[1][1]"].is_number() && j["outputs"]["c[17]"].is_number());
    // Same numbers before atomise (the parsed IR is evaluated as written); JSON numbers compare
    // as f64, so a zero whose sign `0 - t` changed still compares equal.
    let o2 = opt(&[&segway(), "-passes=", &format!("-eval={}", inputs.display())]);
    let j2: serde_json::Value = serde_json::from_slice(&o2.stdout).unwrap();
    assert_eq!(j, j2);
}

/// `-eval` on a URDF: inputs not given take the model's parameters and Pinocchio's gravity
/// (issue 29: gravity was silently random), and a note says so; the others are named.
#[test]
fn eval_on_a_urdf_takes_the_models_parameters_and_pinocchios_gravity() {
    let d = tmp("eval_urdf");
    let inputs = d.join("in.json");
    std::fs::write(&inputs, r#"{"q[1]": 0.5, "q[2]": -0.25, "q[3]": 1.0}"#).unwrap();
    let arm = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/three_link_arm/three_link_arm.urdf");
    let o =
        opt(&[arm.to_str().unwrap(), "-function=invdyna", "-passes=atomise", &format!("-eval={}", inputs.display())]);
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((j["inputs"]["g[1]"].as_f64(), j["inputs"]["g[2]"].as_f64()), (Some(0.0), Some(0.0)));
    assert_eq!(j["inputs"]["g[3]"].as_f64(), Some(-9.81));
    let note = e.lines().find(|l| l.starts_with("note: ")).unwrap_or_else(|| panic!("{e}"));
    assert!(
        note.contains("take the URDF's parameters and Pinocchio's gravity (0, 0, -9.81): g[1], g[2], g[3]"),
        "{note}"
    );
    let warn = e.lines().find(|l| l.starts_with("warning: ")).unwrap_or_else(|| panic!("{e}"));
    assert!(
        warn.starts_with("warning: 6 inputs of @invdyna not in ")
            && warn.ends_with("qd[1], qdd[1], qd[2], qdd[2], qd[3], qdd[3]"),
        "{warn}"
    );
    // An unknown input name is reported, not silently used.
    std::fs::write(&inputs, r#"{"q[99]": 1.0}"#).unwrap();
    let o = opt(&[&segway(), "-passes=atomise", &format!("-eval={}", inputs.display())]);
    assert!(o.status.success() && stderr(&o).contains("`q[99]` is not an input of @dirdyna"));
}

#[test]
fn bad_input_exits_1_and_leaves_no_output_file() {
    let d = tmp("bad");
    let bad = d.join("bad.c");
    std::fs::write(&bad, "void mbs_invdyna(double *Qq,\nMbsData *s, double tsim)\n{\n  x = tan(q[1]);\n}\n").unwrap();
    let out = d.join("out.rvir");
    let o = opt(&[
        bad.to_str().unwrap(),
        "-passes=atomise",
        "-o",
        out.to_str().unwrap(),
        &format!("-report={}", d.join("r.json").display()),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad.c:4:"), "names file and line: {}", stderr(&o));
    assert!(!out.exists() && !d.join("r.json").exists());
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "no temporary file left behind");
}

#[test]
fn modules_with_several_functions_need_function_for_reports() {
    let d = tmp("sensor");
    let sensor = corpus_dir().join("c/m454__mbs_sensor_m454_project.c");
    let r = d.join("r.json");
    let o = opt(&[
        sensor.to_str().unwrap(),
        "-passes=atomise",
        &format!("-report={}", r.display()),
        "-o",
        d.join("o.rvir").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("-function=NAME"), "{}", stderr(&o));
    let o = opt(&[
        sensor.to_str().unwrap(),
        "-passes=atomise",
        &format!("-report={}", r.display()),
        "-function=sensor_1",
        "-o",
        d.join("o.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn ir_from_stdin_and_verifier_errors_on_input() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
        .args(["-", "-passes=atomise,asap-alap"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child.stdin.take().unwrap().write_all(b"func @f { input %a %x = -%a*%a output o = %x }").unwrap();
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("%x = sub 0.0, %x.1 {asap=2"));

    let d = tmp("verify");
    let p = d.join("bad.rvir");
    std::fs::write(&p, "func @f {\n  phase atomised\n  input %a\n  %x = %a*%a\n  output o = %x\n}\n").unwrap();
    let o = opt(&[p.to_str().unwrap(), "-passes=asap-alap"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("nested expression in an atomised function") && stderr(&o).contains("bad.rvir:4:"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn place_sim_and_sweep_end_to_end() {
    let d = tmp("place");
    let placed = d.join("placed.rvir");
    let r = d.join("r.json");
    let o = opt(&[
        &segway(),
        "-passes=atomise,place<pe=2>,sim",
        "-o",
        placed.to_str().unwrap(),
        &format!("-report={}", r.display()),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap();
    let p = &j["placement"];
    assert_eq!((p["n_add"].as_u64(), p["n_mul"].as_u64()), (Some(2), Some(2)));
    let (c, lb) = (p["cycles"].as_f64().unwrap(), p["lower_bound"].as_f64().unwrap());
    assert!(c >= lb && c <= 1.05 * lb, "{c} vs {lb}");
    assert!((p["parallelisation_rate"].as_f64().unwrap() - 4261.0 / (c * 4.0)).abs() < 1e-12);
    assert_eq!(p["pe_memory_words"].as_array().unwrap().len(), 4);
    assert_eq!(p["occupation"]["add"].as_array().unwrap().len() as f64, c);
    // The placed IR re-reads and simulates again without re-placing.
    let o = opt(&[placed.to_str().unwrap(), "-passes=sim<seeds=2>", "-o", d.join("again.rvir").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&placed).unwrap(), std::fs::read_to_string(d.join("again.rvir")).unwrap());
    // A corrupted placement is caught by the simulator, naming cycle, PE and value.
    let text = std::fs::read_to_string(&placed).unwrap();
    let line = text.lines().find(|l| l.trim_start().starts_with("write ")).unwrap().to_string();
    let bad = text.replacen(&line, "", 1);
    std::fs::write(d.join("bad.rvir"), bad).unwrap();
    let o = opt(&[d.join("bad.rvir").to_str().unwrap(), "-passes=sim"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cycle") && stderr(&o).contains('%'), "{}", stderr(&o));
    // Sweep: a table on stderr and CSV rows for each N and configuration.
    let csv = d.join("s.csv");
    let o = opt(&[
        &segway(),
        "-passes=atomise,sweep<pe=1,4>",
        &format!("-sweep-csv={}", csv.display()),
        "-o",
        d.join("s.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("classical+fbi"));
    let rows = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(rows.lines().count(), 1 + 2 * 4);
    assert!(rows.lines().nth(1).unwrap().starts_with("dirdyna,1,classical,preferential,"));
}

/// Issue 47: the URDF-only options were silently ignored on other inputs. The front-end
/// registry declares which input reads which option; any other is bad usage before any work
/// (exit 2), naming the option and the input's kind — on a Robotran file, a `.rvir` and stdin
/// alike — and nothing is written. The same options on a `.urdf` still run.
#[test]
fn urdf_options_are_bad_usage_on_other_inputs() {
    let d = tmp("front_options");
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let urdf = root.join("examples/double_pendulum/double_pendulum.urdf").display().to_string();
    let c = root.join("examples/double_pendulum/mbs_invdyna_double_pendulum.c").display().to_string();
    let ir = opt(&[&c, "-passes=atomise", "-o", "-"]);
    assert!(ir.status.success(), "{}", stderr(&ir));
    let rvir = d.join("x.rvir");
    std::fs::write(&rvir, &ir.stdout).unwrap();
    let params = d.join("p.json").display().to_string();
    let params_out = format!("-params-out={params}");
    let options: [(&[&str], &str); 9] = [
        (&["--free-flyer"], "--free-flyer"),
        (&["--floating-base"], "--floating-base"),
        (&["-gravity=0,0,-9.81"], "-gravity"),
        (&["--formulation=depth"], "--formulation"),
        // Given at its default value: still an option that does not apply.
        (&["--formulation=ops"], "--formulation"),
        (&["--fold-params"], "--fold-params"),
        (&["--continuous=cos-sin"], "--continuous"),
        (&["--continuous=angle"], "--continuous"),
        (&[&params_out], "-params-out"),
    ];
    let out = d.join("out.rvir");
    for (given, flag) in options {
        for (input, kind) in [
            (c.as_str(), format!("`{c}`, a Robotran C input")),
            (rvir.to_str().unwrap(), format!("`{}`, a robovec IR input", rvir.display())),
            ("-", "stdin, a robovec IR input".to_string()),
        ] {
            let mut args = vec![input, "-passes=atomise", "-o", out.to_str().unwrap()];
            args.extend(given);
            let o = Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
                .args(&args)
                .stdin(std::fs::File::open(&rvir).unwrap())
                .output()
                .unwrap();
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            let want = format!("error: {flag} does not apply to {kind}: it concerns URDF input only\n");
            assert_eq!(stderr(&o), want, "{args:?}");
            assert!(!out.exists() && !d.join("p.json").exists(), "{args:?}: nothing written");
        }
        // On a URDF the option is read (with -function=invdyna, the quickest to generate).
        let mut args = vec![urdf.as_str(), "-function=invdyna", "-passes=atomise", "-o", out.to_str().unwrap()];
        args.extend(given);
        let o = opt(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(std::fs::read_to_string(&out).unwrap().contains("func @invdyna"), "{args:?}");
        std::fs::remove_file(&out).unwrap();
        let _ = std::fs::remove_file(d.join("p.json"));
    }
    // -params-out with --fold-params on a URDF: no parameter is left to write.
    let o = opt(&[&urdf, "--fold-params", &params_out, "-passes=atomise", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("-params-out: with --fold-params no parameter is left as an input"), "{}", stderr(&o));
    assert!(!out.exists() && !d.join("p.json").exists());
}
