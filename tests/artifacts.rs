//! What passes hand to the run (artifacts) reaches the user whatever the pass: the report keeps
//! its keys in order, merges rows of several runs and keeps the last measurement, and
//! `-sweep-csv` writes one table with one header.

use crate::common::{opt, stderr, tmp};

const PENDULUM: &str = "examples/double_pendulum/mbs_invdyna_double_pendulum.c";

fn report(args: &[&str], name: &str) -> serde_json::Value {
    let d = tmp(name);
    let r = d.join("r.json");
    let mut all = vec![PENDULUM];
    all.extend_from_slice(args);
    let flag = format!("-report={}", r.display());
    all.extend_from_slice(&[&flag, "-o", "/dev/null"]);
    let o = opt(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(&std::fs::read_to_string(r).unwrap()).unwrap()
}

#[test]
fn report_keys_come_in_order_and_artifacts_merge_by_key() {
    let r = report(
        &["-passes=atomise,sweep<pe=1>,accuracy<samples=20;seed=1>,sweep<pe=2,4>,accuracy<samples=30;seed=2>"],
        "artifacts_report",
    );
    let keys: Vec<&str> = r.as_object().unwrap().keys().map(String::as_str).collect();
    assert_eq!(keys, ["input", "function", "pipeline", "passes", "stats", "sweep", "sweep_fit", "accuracy"]);
    // 4 configurations per N: 1 N in the first sweep, 2 in the second, rows appended in order.
    let ns: Vec<u64> = r["sweep"].as_array().unwrap().iter().map(|row| row["n"].as_u64().unwrap()).collect();
    assert_eq!(ns, [1, 1, 1, 1, 2, 2, 2, 2, 4, 4, 4, 4]);
    // The last accuracy run describes the final IR.
    assert_eq!(r["accuracy"]["samples"], 30);
    assert_eq!(r["accuracy"]["seed"], 2);
}

#[test]
fn sweep_csv_of_two_runs_has_one_header() {
    let d = tmp("artifacts_csv");
    let csv = d.join("s.csv");
    let o = opt(&[
        PENDULUM,
        "-passes=atomise,sweep<pe=1>,sweep<pe=2>",
        &format!("-sweep-csv={}", csv.display()),
        "-o",
        "/dev/null",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with("function,n,"), "{}", lines[0]);
    assert_eq!(lines.iter().filter(|l| l.starts_with("function,")).count(), 1, "{text}");
    assert_eq!(lines.len(), 1 + 8, "{text}");
    // Both runs' tables are printed on stderr.
    assert_eq!(stderr(&o).matches("function      N priority").count(), 2, "{}", stderr(&o));
}
