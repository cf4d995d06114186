//! `-report-dir` (issue 13): every figure is written, parses as SVG, and its CSV holds the
//! report's numbers; the folder is written as a whole; progress reaches the hook; the IR is held
//! back from a terminal.

use std::path::Path;
use std::sync::{Arc, Mutex};

use serde_json::Value;

use crate::common::{opt, stderr, tmp};

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

/// Rows of a CSV file (header dropped), split at commas (the tested files quote no comma but
/// `pareto.csv`'s pipeline column, which the test reads from the end).
fn csv_rows(dir: &Path, name: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    text.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect()
}

fn f(s: &str) -> f64 {
    s.parse().unwrap_or_else(|e| panic!("`{s}`: {e}"))
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The figures a run with `place`, `sweep` and `-pareto` draws.
const ALL: [&str; 7] = ["cycles", "microseconds", "parallelisation", "memory", "occupation", "timeline", "pareto"];

#[test]
fn every_figure_is_svg_and_draws_the_reports_numbers() {
    let d = tmp("full");
    let dir = d.join("rep");
    let report = d.join("report.json");
    let o = opt(&[
        PENDULUM,
        "-passes=atomise,place<pe=2>,sweep<pe=1,2,4>",
        "-pareto=atomise,place<pe=2>;atomise,balance,place<pe=2>",
        "-pareto-samples=40",
        &format!("-report-dir={}", dir.display()),
        &format!("-report={}", report.display()),
        "-o",
        d.join("out.rvir").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains('\x1b'), "no progress drawing on a pipe");
    // Issue 49 item 5: the swept function's C timed on this machine, on the µs figure.
    let r0: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let cpu = &r0["cpu"];
    let (one, batched) = (num(&cpu["one_state_us"]), num(&cpu["batched_us"]));
    assert!(one > 0.0 && batched > 0.0 && num(&cpu["batch"]) == 4.0, "{cpu}");
    let us = std::fs::read_to_string(dir.join("microseconds.csv")).unwrap();
    assert!(
        us.contains(&format!("cpu_one_state,,{one}\n")) && us.contains(&format!("cpu_batch4,,{batched}\n")),
        "{us}"
    );
    assert!(std::fs::read_to_string(dir.join("microseconds.svg"))
        .unwrap()
        .contains("one state per call (this machine)"));
    // report.json is -report's text.
    assert_eq!(std::fs::read(dir.join("report.json")).unwrap(), std::fs::read(&report).unwrap());
    let r: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for name in ALL {
        let svg = std::fs::read_to_string(dir.join(format!("{name}.svg"))).unwrap_or_else(|e| panic!("{name}: {e}"));
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}.svg is not XML: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg", "{name}");
        let texts: String = doc.descendants().filter_map(|n| n.text()).collect::<Vec<_>>().join(" ");
        assert!(texts.contains("mbs_invdyna_double_pendulum @invdyna"), "{name}: title names the model: {texts}");
        assert!(dir.join(format!("{name}.csv")).is_file(), "{name}.csv");
        assert!(md.contains(&format!("]({name}.svg)")), "report.md embeds {name}.svg");
    }
    let names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    assert_eq!(names.len(), 2 + 2 * ALL.len(), "{names:?}");

    // The rows are read back as the types their passes write (serde both ways): each
    // re-serialises to the report's own JSON.
    fn round_trip<T: serde::Serialize + serde::de::DeserializeOwned>(v: &Value) {
        let x: T = serde_json::from_value(v.clone()).unwrap_or_else(|e| panic!("{e}: {v}"));
        assert_eq!(&serde_json::to_value(&x).unwrap(), v);
    }
    round_trip::<Vec<robovec_passes::sweep::SweepRow>>(&r["sweep"]);
    round_trip::<robovec_passes::place::report::PlacementReport>(&r["placement"]);
    round_trip::<Vec<robovec_passes::whole_run::pareto::ParetoRow>>(&r["pareto"]);

    // Sweep figures: one CSV row per (configuration, N) of the report, same numbers.
    let sweep = r["sweep"].as_array().unwrap();
    assert_eq!(sweep.len(), 3 * 4);
    let config = |row: &Value| {
        let (p, s) = (row["priority"].as_str().unwrap(), row["select"].as_str().unwrap());
        if s == "preferential" {
            p.to_string()
        } else {
            format!("{p}/{s}")
        }
    };
    for (file, key) in
        [("cycles.csv", "cycles"), ("microseconds.csv", "us"), ("parallelisation.csv", "parallelisation_rate")]
    {
        let rows: Vec<_> = csv_rows(&dir, file)
            .into_iter()
            .filter(|c| !c[0].contains("bound") && c[0] != "critical_path" && c[0] != "y" && !c[0].starts_with("cpu_"))
            .collect();
        assert_eq!(rows.len(), sweep.len(), "{file}");
        for row in sweep {
            let hit = rows
                .iter()
                .find(|c| c[0] == config(row) && f(&c[1]) == num(&row["n"]))
                .unwrap_or_else(|| panic!("{file}: {row}"));
            assert_eq!(f(&hit[2]), num(&row[key]), "{file} {}", config(row));
        }
    }
    let cycles = csv_rows(&dir, "cycles.csv");
    for row in sweep {
        for bound in ["resource_bound", "critical_path"] {
            let hit = cycles.iter().find(|c| c[0] == bound && f(&c[1]) == num(&row["n"])).unwrap();
            assert_eq!(f(&hit[2]), num(&row[bound]));
        }
    }
    assert_eq!(f(&cycles.iter().find(|c| c[0] == "y").unwrap()[1]), num(&r["stats"]["y"]), "Y is the final IR's");
    // Memory: naive = classical/naive, preferential = classical/preferential (seed alone).
    let memory = csv_rows(&dir, "memory.csv");
    assert_eq!(memory.len(), 4 * 2 * 3, "4 memories, 2 selections, 3 N");
    for row in sweep.iter().filter(|x| x["priority"] == "classical") {
        let sel = row["select"].as_str().unwrap();
        for (what, key) in [
            ("PE memory ADD PEs", "pe_words_add"),
            ("PE memory MULTI PEs", "pe_words_mul"),
            ("buffer ADD PEs", "buffer_words_add"),
            ("buffer MULTI PEs", "buffer_words_mul"),
        ] {
            // The memory name holds a comma ("PE memory, ADD PEs"): columns shift by one.
            let hit = memory
                .iter()
                .find(|c| format!("{}{}", c[0], c[1]) == what && c[2] == sel && f(&c[3]) == num(&row["n"]))
                .unwrap_or_else(|| panic!("memory.csv: {what} {sel} {}", row["n"]));
            assert_eq!(
                [f(&hit[4]), f(&hit[5]), f(&hit[6])],
                [num(&row[key]["min"]), num(&row[key]["mean"]), num(&row[key]["max"])]
            );
        }
    }
    // Occupation: every cycle of both PE types.
    let occ = csv_rows(&dir, "occupation.csv");
    let p = &r["placement"];
    let cycles_placed = num(&p["cycles"]);
    for (ty, key) in [("add", "add"), ("mul", "mul")] {
        let want: Vec<f64> = p["occupation"][key].as_array().unwrap().iter().map(num).collect();
        let got: Vec<f64> = occ.iter().filter(|c| c[0] == ty).map(|c| f(&c[3])).collect();
        assert_eq!(got, want, "occupation {ty}");
        for c in occ.iter().filter(|c| c[0] == ty) {
            assert_eq!(f(&c[2]), f(&c[1]) / cycles_placed, "normalised time");
        }
    }
    // Timeline: every op of the 48-op model issues within its 131 cycles (< 256: all shown).
    let tl = csv_rows(&dir, "timeline.csv");
    let issues = p["timeline"]["issues"].as_array().unwrap();
    assert_eq!(issues.len() as f64, num(&r["stats"]["ops"]["total"]));
    assert_eq!(tl.len(), issues.len());
    for (c, i) in tl.iter().zip(issues) {
        assert_eq!(c[0], i["pe_type"].as_str().unwrap());
        assert_eq!([f(&c[1]), f(&c[2]), f(&c[3])], [num(&i["pe"]), num(&i["cycle"]), num(&i["latency"])]);
        assert_eq!(c[5], i["value"].as_str().unwrap());
        let n = if c[0] == "add" { num(&p["n_add"]) } else { num(&p["n_mul"]) };
        assert!(f(&c[1]) < n && f(&c[2]) < cycles_placed);
    }
    // Pareto: time and mean bits of each row (columns from the end: the pipeline is quoted);
    // no domain, so the two certified columns at the end are empty.
    let par = csv_rows(&dir, "pareto.csv");
    let rows = r["pareto"].as_array().unwrap();
    assert_eq!(par.len(), rows.len());
    for (c, row) in par.iter().zip(rows) {
        let k = c.len();
        assert_eq!(
            [f(&c[k - 7]), f(&c[k - 6]), f(&c[k - 5])],
            [num(&row["time_cycles"]), num(&row["f32"]["mean_bits"]), num(&row["f64"]["mean_bits"])]
        );
        assert_eq!(c[k - 4], row["pareto_optimal"].to_string());
        assert_eq!([c[k - 2].as_str(), c[k - 1].as_str()], ["", ""]);
    }
    assert!(md.contains("cost-against-budget figure needs `precision`"), "{md}");
}

#[test]
fn the_folder_is_replaced_whole_and_foreign_content_is_refused() {
    let d = tmp("replace");
    let dir = d.join("rep");
    let run = |passes: &str| opt(&[PENDULUM, passes, &format!("-report-dir={}", dir.display()), "-o", "/dev/null"]);
    // Placed, no sweep: occupation and timeline only; report.md says what is missing.
    let o = run("-passes=atomise,place<pe=2>");
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["occupation.csv", "occupation.svg", "report.json", "report.md", "timeline.csv", "timeline.svg"]);
    assert!(std::fs::read_to_string(dir.join("report.md")).unwrap().contains("need a `sweep` pass"));
    // A second run replaces the folder: nothing of the first stays.
    std::fs::write(dir.join("stale.svg"), "<svg/>").unwrap();
    let o = run("-passes=atomise");
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["report.json", "report.md"]);
    // Nothing left beside it.
    let beside: Vec<String> =
        std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    assert_eq!(beside, ["rep"]);
    // A folder holding something robovec did not write is refused before any work, untouched.
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let o = run("-passes=atomise");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("notes.txt"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(dir.join("notes.txt")).unwrap(), "mine");
    // A failing run leaves no folder.
    let fresh = d.join("fresh");
    let o = opt(&[
        PENDULUM,
        "-passes=atomise,place<pe=2>,sim,dce<outputs=nope>",
        &format!("-report-dir={}", fresh.display()),
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(!fresh.exists());
    #[cfg(unix)]
    {
        let link = d.join("link");
        std::os::unix::fs::symlink(&dir, &link).unwrap();
        let o = opt(&[PENDULUM, "-passes=atomise", &format!("-report-dir={}", link.display())]);
        assert_eq!(o.status.code(), Some(1));
        assert!(stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    }
}

/// Every task started: label, total, and the positions set, in order.
type Log = Arc<Mutex<Vec<(String, u64, Vec<u64>)>>>;

/// A progress sink recording every task into its [`Log`].
#[derive(Default, Clone)]
struct Recorder(Log);

struct Line(Log, usize);

impl robovec_passes::progress::ProgressSink for Recorder {
    fn start(&self, label: &str, total: u64) -> Box<dyn robovec_passes::progress::ProgressDisplay> {
        let mut v = self.0.lock().unwrap();
        v.push((label.to_string(), total, Vec::new()));
        Box::new(Line(self.0.clone(), v.len() - 1))
    }
}

impl robovec_passes::progress::ProgressDisplay for Line {
    fn set(&self, done: u64) {
        self.0.lock().unwrap()[self.1].2.push(done);
    }
    fn finish(&self) {}
}

#[test]
fn long_loops_report_progress_through_the_hook() {
    let (mut m, _) = robovec::driver::load(PENDULUM).unwrap();
    let rec = Recorder::default();
    let mut cx = robovec_passes::PassContext {
        progress: robovec_passes::progress::Progress::shown(Arc::new(rec.clone())),
        ..robovec_passes::PassContext::default()
    };
    let pm = robovec_passes::PassManager::with_registry(
        robovec_backends::REGISTRY,
        "atomise,sweep<pe=1,2>,accuracy<samples=300>",
        Default::default(),
    )
    .unwrap();
    pm.run(&mut m, &mut cx, &mut std::io::sink()).unwrap();
    let log = rec.0.lock().unwrap().clone();
    let sweep = log.iter().find(|x| x.0 == "sweep: placements").expect("sweep task");
    // 1 function × 2 N × 4 configurations, each reported once, in order.
    assert_eq!((sweep.1, sweep.2.clone()), (8, (1..=8).collect::<Vec<u64>>()));
    let acc = log.iter().find(|x| x.0 == "accuracy @invdyna: samples").expect("accuracy task");
    assert_eq!(acc.1, 300);
    assert_eq!(acc.2.last(), Some(&300), "all samples measured");

    // -pareto: one step per pipeline.
    let (m, _) = robovec::driver::load(PENDULUM).unwrap();
    let rec = Recorder::default();
    let progress = robovec_passes::progress::Progress::shown(Arc::new(rec.clone()));
    let target = robovec_machine::target::Target::de10_nano();
    robovec_passes::whole_run::pareto::measure(
        robovec_backends::REGISTRY,
        &m,
        "invdyna",
        "atomise;atomise,balance",
        20,
        1,
        None,
        &target,
        &progress,
        None,
    )
    .unwrap();
    let log = rec.0.lock().unwrap().clone();
    assert_eq!(log, [("-pareto: pipelines".to_string(), 2, vec![1, 2])]);
}

#[test]
fn the_ir_is_held_back_from_a_terminal_unless_asked_for() {
    use robovec::driver::{stdout_choice, StdoutChoice};
    let dash = Path::new("-");
    let file = Path::new("out.rvir");
    // (output, eval, stdout terminal, tables shown) → choice
    assert_eq!(stdout_choice(None, false, false, false), StdoutChoice::Main, "a pipe gets the IR");
    assert_eq!(
        stdout_choice(None, false, false, true),
        StdoutChoice::Main,
        "tables go to stderr; the pipe still gets the IR"
    );
    assert_eq!(stdout_choice(None, false, true, false), StdoutChoice::HeldBack { note: true });
    assert_eq!(
        stdout_choice(None, false, true, true),
        StdoutChoice::HeldBack { note: false },
        "the table is the answer"
    );
    assert_eq!(stdout_choice(Some(dash), false, true, true), StdoutChoice::Main, "-o - forces it");
    assert_eq!(stdout_choice(Some(file), false, true, false), StdoutChoice::Nothing);
    assert_eq!(stdout_choice(None, true, true, false), StdoutChoice::Eval);

    // Through the driver, with stdout said to be a terminal.
    let run = |args: &[&str]| {
        let mut argv = vec!["robovec-opt".to_string(), PENDULUM.to_string()];
        argv.extend(args.iter().map(|s| s.to_string()));
        let cli = <robovec::cli::Cli as clap::Parser>::try_parse_from(robovec::cli::normalise_args(argv)).unwrap();
        let opts = cli.options().unwrap();
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let terminal = robovec::driver::Terminal { stdout: true, stderr: false };
        robovec::driver::run_with(&opts, terminal, &mut out, &mut err).unwrap();
        (String::from_utf8(out).unwrap(), String::from_utf8(err).unwrap())
    };
    let (out, err) = run(&["-passes=atomise"]);
    assert_eq!(out, "");
    assert!(err.contains("note: the final IR is not printed on a terminal") && err.contains("-o -"), "{err}");
    let (out, err) = run(&["-passes=atomise", "-stats"]);
    assert_eq!(out, "");
    assert!(err.contains("@invdyna: equations") && !err.contains("note:"), "{err}");
    let (out, _) = run(&["-passes=atomise", "-o", "-"]);
    assert!(out.starts_with("func @invdyna") || out.contains("func @invdyna"), "{out}");
}

#[test]
fn no_other_output_may_go_inside_the_report_folder() {
    let d = tmp("inside");
    let dir = d.join("rep");
    std::fs::create_dir(&dir).unwrap();
    let o = opt(&[
        PENDULUM,
        "-passes=atomise",
        &format!("-report-dir={}", dir.display()),
        "-o",
        d.join("rep/out.rvir").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("inside -report-dir"), "{}", stderr(&o));
    let o = opt(&[
        PENDULUM,
        "-passes=atomise",
        "-q",
        &format!("-report-dir={}", dir.display()),
        &format!("-dump-dir={}", dir.display()),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
}

const ARM: &str = "examples/three_link_arm/three_link_arm.urdf";

/// `-ranges` for `ARM`: its continuous joint's velocity (the URDF's limits give the rest).
fn arm_ranges(d: &Path) -> String {
    let path = d.join("ranges.json");
    std::fs::write(&path, r#"{"qd[2]": [-3, 3]}"#).unwrap();
    format!("-ranges={}", path.display())
}

/// The report of `ARM @invdyna` over [`arm_ranges`] after `passes`, read as JSON.
fn arm_report(d: &Path, passes: &str) -> Value {
    let report = d.join("direct.json");
    let o = opt(&[
        ARM,
        "-function=invdyna",
        &arm_ranges(d),
        passes,
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{passes}: {}", stderr(&o));
    serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap()
}

/// Issue 48 item 6: with `precision` in the pipeline, the cost-against-budget figure has one
/// CSV row per budget of the ladder, each the report `precision` itself writes at that budget
/// (the pass run directly), certified within its budget; with a domain (the URDF's limits and
/// `-ranges`), `-pareto`'s CSV and
/// table carry each row's certified bounds, as `error-bound` and `range` compute them directly.
#[test]
fn precision_draws_cost_against_budget_and_pareto_its_certified_bounds() {
    use robovec_passes::precision::ladder::BUDGETS;
    let d = tmp("budget");
    let dir = d.join("rep");
    let o = opt(&[
        ARM,
        "-function=invdyna",
        &arm_ranges(&d),
        "-passes=atomise,precision<budget=1e-5;target=mcu>",
        "-pareto=atomise;atomise,balance",
        "-pareto-samples=20",
        &format!("-report-dir={}", dir.display()),
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: Value = serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let svg = std::fs::read_to_string(dir.join("budget.svg")).unwrap();
    roxmltree::Document::parse(&svg).unwrap();
    assert!(md.contains("](budget.svg)") && md.contains("not measured"), "{md}");
    assert!(!md.contains("cost-against-budget figure needs"), "{md}");

    // One row per budget, in the ladder's order; each the pass's own report at that budget.
    let text = std::fs::read_to_string(dir.join("budget.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows = csv_rows(&dir, "budget.csv");
    assert_eq!(rows.len(), BUDGETS.len());
    assert_eq!(r["precision_ladder"]["points"].as_array().unwrap().len(), BUDGETS.len());
    assert_eq!(r["precision_ladder"]["target"], "mcu");
    let mut pass_costs = Vec::new();
    for (row, &b) in rows.iter().zip(&BUDGETS) {
        assert_eq!(f(&row[col("budget")]), b);
        let p = &arm_report(&d, &format!("-passes=atomise,precision<budget={b:e};target=mcu>"))["precision"];
        for key in ["cost_before", "cost_after", "max_rel_to_range"] {
            assert_eq!(f(&row[col(key)]), num(&p[key]), "{key} at {b:e}");
        }
        let count = |pick: &dyn Fn(&str) -> bool| -> f64 {
            p["formats"].as_object().unwrap().iter().filter(|(k, _)| pick(k)).map(|(_, n)| num(n)).sum()
        };
        assert_eq!(f(&row[col("fixed_values")]), count(&|k| k.starts_with("fix<")));
        assert_eq!(f(&row[col("f32_values")]), count(&|k| k == "f32"));
        assert_eq!(f(&row[col("f64_values")]), count(&|k| k == "f64"));
        assert_eq!(f(&row[col("unreachable")]), p["unreachable"].as_array().unwrap().len() as f64);
        assert!(f(&row[col("cost_after")]) <= f(&row[col("cost_before")]));
        if p["unreachable"].as_array().unwrap().is_empty() {
            assert!(f(&row[col("max_rel_to_range")]) <= b, "certified within {b:e}");
        }
        pass_costs.push(num(&p["cost_after"]));
    }
    // The pipeline's own point (1e-5) is on the ladder.
    let k = BUDGETS.iter().position(|&b| b == 1e-5).unwrap();
    assert_eq!(pass_costs[k], num(&r["precision"]["cost_after"]));
    // Looser budgets never cost more here (the chooser does not promise it in general).
    assert!(pass_costs.windows(2).all(|w| w[0] <= w[1]), "{pass_costs:?}");

    // -pareto: the certified columns (appended last), equal to the report's and to error-bound's
    // bound over range's enclosure of each output, computed directly.
    let text = std::fs::read_to_string(dir.join("pareto.csv")).unwrap();
    assert!(text.starts_with(
        "index,pipeline,time_cycles,f32_mean_bits,f64_mean_bits,pareto_optimal,sound,f32_certified_max_rel,f64_certified_max_rel\n"
    ));
    let par = csv_rows(&dir, "pareto.csv");
    let rows = r["pareto"].as_array().unwrap();
    assert_eq!(par.len(), 2);
    for (c, row) in par.iter().zip(rows) {
        let k = c.len();
        assert_eq!(
            [f(&c[k - 2]), f(&c[k - 1])],
            [num(&row["certified"]["f32_max_rel"]), num(&row["certified"]["f64_max_rel"])]
        );
    }
    for (fmt, k) in [("f32", 2), ("f64", 1)] {
        let direct = arm_report(&d, &format!("-passes=atomise,range,error-bound<format={fmt}>"));
        let mut worst = 0.0f64;
        for (name, enclosure) in direct["range"]["outputs"].as_object().unwrap() {
            let mag = enclosure.as_array().unwrap().iter().map(|v| num(v).abs()).fold(0.0, f64::max);
            let abs = num(&direct["error_bound"]["outputs"][name]["abs"]);
            if mag > 0.0 {
                worst = worst.max(abs / mag);
            }
        }
        let got = f(&par[0][par[0].len() - k]);
        assert!((got - worst).abs() <= 1e-12 * worst, "{fmt}: pareto {got:e}, direct {worst:e}");
    }
    assert!(md.contains("f32 certified max rel"), "{md}");
}

/// With `precision<target=c>`, `-report-dir` times each point of the budget ladder on this
/// machine (`src/report_dir/ladder_time.rs`): every row has a positive `ns_per_state` at batch 8
/// or 16, the binary64 baseline at batch 4 or 8, their ratio in `measured_ratio`; points with
/// the same formats share one measurement. (No speed is claimed: a timed test cannot.)
#[test]
fn the_budget_ladder_of_target_c_is_timed() {
    let d = tmp("budget-time");
    let dir = d.join("rep");
    let o = opt(&[
        ARM,
        "-function=invdyna",
        &arm_ranges(&d),
        "-passes=atomise,precision<budget=1e-5>",
        &format!("-report-dir={}", dir.display()),
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(dir.join("budget.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let rows = csv_rows(&dir, "budget.csv");
    let r: Value = serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    let base = num(&r["precision_ladder"]["binary64_ns_per_state"]);
    assert!(base > 0.0);
    assert!([4.0, 8.0].contains(&num(&r["precision_ladder"]["binary64_batch"])));
    let mut by_formats: Vec<(String, f64)> = Vec::new();
    for (row, p) in rows.iter().zip(r["precision_ladder"]["points"].as_array().unwrap()) {
        let ns = f(&row[col("ns_per_state")]);
        assert!(ns > 0.0 && ns == num(&p["ns_per_state"]));
        assert!([8.0, 16.0].contains(&f(&row[col("ns_batch")])));
        assert_eq!(f(&row[col("binary64_ns_per_state")]), base);
        assert!((f(&row[col("measured_ratio")]) - ns / base).abs() <= 1e-12 * ns / base);
        let formats = p["formats"].to_string();
        match by_formats.iter().find(|(k, _)| *k == formats) {
            Some((_, t)) => assert_eq!(*t, ns, "one measurement per assignment"),
            None => by_formats.push((formats, ns)),
        }
    }
    assert!(by_formats.len() >= 2, "the ladder has binary32 and binary64 points");
    let svg = std::fs::read_to_string(dir.join("budget.svg")).unwrap();
    assert!(svg.contains("measured ns/state after / before"), "the figure draws the measured line");
}
