//! `robovec-gen --study` (issue 14): the table's figures are those `robovec-opt -stats` prints
//! for the same case and pipeline (an independent path: the URDF `robovec-gen` writes, read
//! back by the URDF front end, run by `robovec-opt`); the report folder holds the study's
//! files, figures with their CSVs and each case's `-report-dir` content; refusals and usage
//! errors.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{opt, stderr, tmp};

fn gen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robovec-gen")).args(args).output().expect("robovec-gen runs")
}

const BEST: &str = robovec::study::DEFAULT_BEST;

/// The table rows of the markdown on stdout, by case label: the cells after the label.
fn rows(md: &str) -> Vec<(String, Vec<String>)> {
    md.lines()
        .filter(|l| l.starts_with("| ") && l.contains("-dof "))
        .map(|l| {
            let cells: Vec<String> = l.trim_matches('|').split(" | ").map(|c| c.trim().to_string()).collect();
            (cells[0].clone(), cells[1..].to_vec())
        })
        .collect()
}

/// `robovec-opt URDF -function=dirdyna -passes=P -stats`'s stderr.
fn stats(urdf: &Path, pipeline: &str) -> String {
    let o = opt(&[
        urdf.to_str().unwrap(),
        "-function=dirdyna",
        &format!("-passes={pipeline}"),
        "-stats",
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{pipeline}: {}", stderr(&o));
    stderr(&o)
}

/// `ops | ASAP − ASAPCycle | Y` from the `@dirdyna: equations …` line.
fn shape_cells(stats: &str) -> [String; 3] {
    let l = stats.lines().find(|l| l.starts_with("@dirdyna: equations")).expect("figures line");
    let after = |key: &str| l.split(key).nth(1).expect(key).to_string();
    let ops = after(", ops ").split(' ').next().unwrap().to_string();
    let cp = after("critical path ");
    let mut w = cp.split(' ');
    let asap = w.next().unwrap().to_string();
    let cycles = w.nth(2).unwrap().to_string();
    let y = after("Y = ").split(' ').next().unwrap().to_string();
    [ops, format!("{asap} − {cycles}"), y]
}

#[test]
fn table_figures_equal_robovec_opt_stats_for_the_same_case_and_pipeline() {
    let o = gen(&["--study", "--dof", "4,9", "--topology", "serial,parallel", "--samples", "40", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "-q prints nothing on stderr: {}", stderr(&o));
    let md = String::from_utf8(o.stdout).unwrap();
    let table = rows(&md);
    let labels: Vec<&str> = table.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["4-dof serial", "4-dof parallel", "9-dof serial", "9-dof parallel"], "{md}");
    assert!(md.contains(&format!("best `{BEST}`")), "{md}");
    let d = tmp("table_vs_opt");
    for (label, cells) in &table {
        let (dof, topology) = label.split_once("-dof ").unwrap();
        let urdf = d.join(format!("{topology}{dof}.urdf"));
        let w = gen(&["--topology", topology, "--dof", dof, "--seed", "1", "-o", urdf.to_str().unwrap()]);
        assert!(w.status.success(), "{}", stderr(&w));
        for (k, pipeline) in ["atomise", "atomise,zero-removal,balance", BEST].into_iter().enumerate() {
            assert_eq!(cells[3 * k..3 * k + 3], shape_cells(&stats(&urdf, pipeline)), "{label}: {pipeline}");
        }
        let cycles: Vec<String> = [8, 16, 32, 64]
            .iter()
            .map(|n| {
                let s = stats(&urdf, &format!("{BEST},place<pe={n}>"));
                let l = s.lines().find(|l| l.starts_with("@dirdyna: placed")).expect("placed line");
                l.split("PEs: ").nth(1).unwrap().split(' ').next().unwrap().to_string()
            })
            .collect();
        assert_eq!(cells[9], cycles.join(" / "), "{label}: cycles");
        let s = stats(&urdf, &format!("{BEST},accuracy<samples=40>"));
        let l = s.lines().find(|l| l.starts_with("@dirdyna: accuracy")).expect("accuracy line");
        let f32 = l.split("mean/p95/max f32 ").nth(1).unwrap().split(' ').next().unwrap();
        let v: Vec<&str> = f32.split('/').collect();
        assert_eq!(cells[10], format!("{} / {}", v[0], v[2]), "{label}: f32 bits");
        assert_eq!(cells[11], "–", "no thesis row at {dof} dof");
    }
}

#[test]
fn report_dir_holds_the_study_its_figures_and_every_cases_report() {
    let d = tmp("report_dir");
    let dir = d.join("study");
    let args = ["--study", "--dof", "4", "--topology", "serial,semi-serial", "--samples", "20", "-q", "--report-dir"];
    let mut a = args.to_vec();
    a.push(dir.to_str().unwrap());
    let o = gen(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "the table goes to the folder");
    let read = |p: &str| std::fs::read_to_string(dir.join(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
    let md = read("study.md");
    assert_eq!(rows(&md).len(), 2, "{md}");
    let json: serde_json::Value = serde_json::from_str(&read("study.json")).unwrap();
    let cases = json["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 2);
    // Each figure with its CSV, drawing exactly the study's numbers.
    for f in ["ops", "critical_path", "y", "cycles", "f32_error"] {
        assert!(read(&format!("{f}.svg")).starts_with("<svg"), "{f}.svg");
        assert!(md.contains(&format!("({f}.svg)")), "study.md embeds {f}");
    }
    let ops_csv = read("ops.csv");
    let csv = read("study.csv");
    for c in cases {
        let (dof, topo) = (c["dof"].as_u64().unwrap(), c["topology"].as_str().unwrap());
        for (key, name) in [("generated", "generated"), ("zero_balance", "zero-removal,balance"), ("best", "best")] {
            let ops = c[key]["ops"].as_u64().unwrap();
            assert!(ops_csv.lines().any(|l| l == format!("{topo},{name},{dof},{ops}")), "{topo} {name}: {ops_csv}");
            let s = &c[key];
            let line = format!("{dof},{topo},{key},{ops},{},{},{}", s["asap"], s["asap_cycle"], s["y"]);
            assert!(csv.lines().any(|l| l == line), "{line} in {csv}");
        }
        for p in c["placed"].as_array().unwrap() {
            let line = format!("{dof},{topo},{},{}", p["n"], p["cycles"]);
            assert!(read("cycles.csv").lines().any(|l| l == line), "{line}");
        }
        // The case's report folder: -report-dir's files, its placement at N = 8 the table's.
        let case = format!("cases/{dof}-{topo}");
        let report: serde_json::Value = serde_json::from_str(&read(&format!("{case}/report.json"))).unwrap();
        assert_eq!(report["function"], "dirdyna");
        assert_eq!(report["pipeline"], format!("{BEST},accuracy<samples=20>,sweep<pe=8,16,32,64>,place<pe=8>"));
        assert_eq!(report["placement"]["cycles"], c["placed"][0]["cycles"]);
        assert_eq!(report["stats"]["ops"]["total"], c["best"]["ops"]);
        assert_eq!(report["accuracy"]["f32"]["mean_bits"], c["f32_bits"]["mean"]);
        for f in ["cycles", "microseconds", "parallelisation", "memory", "occupation", "timeline", "pareto"] {
            assert!(read(&format!("{case}/{f}.svg")).starts_with("<svg"), "{case}/{f}.svg");
            assert!(dir.join(format!("{case}/{f}.csv")).is_file(), "{case}/{f}.csv");
        }
        assert!(read(&format!("{case}/report.md")).contains("dirdyna"));
        assert!(md.contains(&format!("({case}/report.md)")), "study.md links {case}");
    }
    // Run again over the folder it wrote: replaced whole.
    let o = gen(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("cases/4-serial/report.json").is_file());
    // --no-case-reports: the same study-level table, no cases/ folder and no link to one.
    let csv = read("study.csv");
    let mut short = a.to_vec();
    short.push("--no-case-reports");
    let o = gen(&short);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(read("study.csv"), csv, "the table does not depend on the per-case reports");
    assert!(!dir.join("cases").exists(), "no per-case folders");
    assert!(!read("study.md").contains("](cases/"), "study.md links no case folder");
    assert!(dir.join("ops.svg").is_file());
}

#[test]
fn refused_report_dir_and_usage_errors() {
    let d = tmp("refusals");
    let real = d.join("real");
    std::fs::create_dir(&real).unwrap();
    let link = d.join("link");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let file = d.join("file");
    std::fs::write(&file, "keep").unwrap();
    let foreign = d.join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    for (what, dir) in [("symlink", &link), ("file", &file), ("foreign folder", &foreign)] {
        let o = gen(&["--study", "--dof", "2", "--topology", "serial", "--report-dir", dir.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{what}: {}", stderr(&o));
        assert!(stderr(&o).contains("cannot write folder"), "{what}: {}", stderr(&o));
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
    assert_eq!(std::fs::read_to_string(foreign.join("notes.txt")).unwrap(), "mine");
    assert_eq!(std::fs::read_dir(&real).unwrap().count(), 0, "nothing written through the link");
    let out = d.join("x.urdf");
    for bad in [
        &["--study", "--best", "atomise,no-such-pass"][..],
        &["--study", "--best", "atomise,place<pe=0>"],
        &["--study", "--samples", "0"],
        &["--study", "--dof", "0"],
        &["--study", "--topology", "tree"],
        &["--study", "-o", out.to_str().unwrap()],
        &["--samples", "5", "--topology", "serial", "--dof", "3"],
        &["--report-dir", "x", "--topology", "serial", "--dof", "3"],
        &["--topology", "serial,parallel", "--dof", "3"],
    ] {
        let o = gen(bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", stderr(&o));
        assert!(!out.exists());
    }
}

/// The thesis's rows the study prints beside its own are Table 3.1's, as the seed states them.
#[test]
fn thesis_rows_are_table_3_1_of_the_seed() {
    let seed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/seed");
    let text: String = std::fs::read_dir(&seed)
        .unwrap_or_else(|e| panic!("the seed thesis is missing at {}: {e}", seed.display()))
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap_or_default())
        .find(|t| t.contains("Table 3.1: Study Cases Characteristics"))
        .expect("the seed holds Table 3.1");
    for r in robovec::study::cases::THESIS_ROWS {
        let line = format!(
            "{}-dof {}\t{}\t{} - {}\t{}",
            r.dof,
            r.topology,
            r.ops,
            r.asap,
            r.asap_cycle,
            format!("{:.2}", r.y).trim_end_matches('0').trim_end_matches('.')
        );
        assert!(text.lines().any(|l| l.trim_end() == line), "{line:?} not in Table 3.1");
    }
}
