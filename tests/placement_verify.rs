//! Issue 10 items 4 and 5: a placement is verified wherever it is read (hand-broken placed
//! `.rvir` files → exit 1 with `file:line:col` and the rule broken, with an empty pipeline and
//! with `asap-alap`), `sim` and pass-order errors point at the offending line, and `sim`'s
//! `-stats` line and report object.

use std::path::{Path, PathBuf};

use crate::common::{opt, stderr, tmp};

/// A correct placement, computed by hand (cycles: %d issues at 13 on add0, +12 → 25).
const GOOD: &str = "func @f {
  phase atomised
  input %x
  input %y
  input %z
  %m1 = mul %x, %y
  %m2 = mul %y, %z
  %a = add %x, %y
  %b = sub %y, %z
  %c = add %m1, %m2
  %d = add %a, %b
  output o1 = %c
  output o2 = %d
  placement n_add=1 n_mul=1 lat_add=12 lat_mul=7 lat_div=12 lat_call=12 writes=2 buffer=1 {
    words add0=3 mul0=3
    buffers add0=0 mul0=0
    issue %m1 mul0 0
    issue %m2 mul0 1
    issue %a add0 0
    issue %b add0 1
    issue %c add0 8
    issue %d add0 13
    load add0 0 %x
    load add0 1 %y
    load add0 2 %z
    load mul0 0 %x
    load mul0 1 %y
    load mul0 2 %z
    write %m1 add0 0 7
    write %m2 add0 1 8
    write %a add0 0 12
    write %b add0 1 13
  }
}
";

/// `GOOD` with line `old` replaced by `new`; returns the file and `path:line:col` of the
/// new line (its first non-blank character).
fn broken(dir: &Path, old: &str, new: &str) -> (PathBuf, String) {
    let lines: Vec<&str> = GOOD.lines().collect();
    let i = lines.iter().position(|l| l.trim() == old).unwrap_or_else(|| panic!("no line `{old}`"));
    let mut out: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    out[i] = format!("    {new}");
    let path = dir.join("bad.rvir");
    std::fs::write(&path, out.join("\n") + "\n").unwrap();
    let at = format!("{}:{}:5", path.display(), i + 1);
    (path, at)
}

/// Runs `bad.rvir` with an empty pipeline and with `asap-alap`: both exit 1 naming the rule
/// and the line `at_line` (the changed line when `None`).
fn rejected_at(name: &str, old: &str, new: &str, rule: &str, at_line: Option<&str>) {
    let d = tmp(name);
    let (path, mut at) = broken(&d, old, new);
    if let Some(l) = at_line {
        let i = GOOD.lines().position(|x| x.trim() == l).unwrap_or_else(|| panic!("no line `{l}`"));
        at = format!("{}:{}:5", path.display(), i + 1);
    }
    for passes in ["-passes=", "-passes=asap-alap"] {
        let out = d.join("out.rvir");
        let o = opt(&[path.to_str().unwrap(), passes, "-o", out.to_str().unwrap()]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name} {passes}: {e}");
        assert!(e.contains(&at), "{name} {passes}: no `{at}` in:\n{e}");
        assert!(e.contains(rule), "{name} {passes}: no `{rule}` in:\n{e}");
        assert!(!out.exists(), "{name}: output written");
    }
}

fn rejected(name: &str, old: &str, new: &str, rule: &str) {
    rejected_at(name, old, new, rule, None)
}

#[test]
fn the_hand_computed_placement_is_accepted_and_simulates() {
    let d = tmp("good");
    let path = d.join("good.rvir");
    std::fs::write(&path, GOOD).unwrap();
    for passes in ["-passes=", "-passes=asap-alap", "-passes=sim"] {
        let o = opt(&[path.to_str().unwrap(), passes, "-o", "-"]);
        assert_eq!(o.status.code(), Some(0), "{passes}: {}", stderr(&o));
    }
}

#[test]
fn an_op_issued_twice_is_rejected() {
    rejected("twice", "issue %m2 mul0 1", "issue %m1 mul0 1", "issued twice");
}

#[test]
fn two_ops_on_one_pe_in_one_cycle_are_rejected() {
    rejected("busy", "issue %b add0 1", "issue %b add0 0", "a PE issues at most one op per cycle");
}

#[test]
fn an_op_on_the_wrong_pe_type_is_rejected() {
    rejected("wrong_type", "issue %m1 mul0 0", "issue %m1 add0 2", "a PE of the wrong type");
}

#[test]
fn an_operand_not_yet_written_is_rejected() {
    // %m2 arrives (and is written into add0) at cycle 8: %c cannot issue at 7.
    rejected(
        "not_written",
        "issue %c add0 8",
        "issue %c add0 7",
        "operand %m2 of %c is not in the memory of add0 at cycle 7 (written there only at cycle 8)",
    );
}

#[test]
fn an_operand_never_written_is_rejected() {
    // %m1 written into mul0 instead of add0: %c on add0 cannot read it.
    rejected_at(
        "never_written",
        "write %m1 add0 0 7",
        "write %m1 mul0 0 7",
        "operand %m1 of %c is not in the memory of add0 at cycle 8 (never loaded or written there)",
        Some("issue %c add0 8"),
    );
    rejected_at(
        "never_loaded",
        "load add0 2 %z",
        "load mul0 2 %x",
        "operand %z of %b is not in the memory of add0 at cycle 1",
        Some("issue %b add0 1"),
    );
}

#[test]
fn an_address_beyond_the_reported_memory_is_rejected() {
    rejected(
        "address",
        "write %b add0 1 13",
        "write %b add0 3 13",
        "address 3 of the memory of add0, which reports 3 words",
    );
}

#[test]
fn a_direct_write_off_the_arrival_cycle_is_rejected() {
    rejected("write_cycle", "write %a add0 0 12", "write %a add0 0 11", "but it arrives at cycle 12");
}

#[test]
fn a_placement_on_a_parsed_function_is_rejected() {
    let d = tmp("phase");
    let path = d.join("bad.rvir");
    std::fs::write(&path, GOOD.replace("phase atomised", "phase parsed")).unwrap();
    let o = opt(&[path.to_str().unwrap(), "-passes=", "-o", "-"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("only an atomised function can be placed"), "{e}");
    let line = GOOD.lines().position(|l| l.trim_start().starts_with("placement ")).unwrap() + 1;
    assert!(e.contains(&format!("{}:{line}:3", path.display())), "{e}");
}

#[test]
fn a_missing_issue_points_at_the_definition() {
    let d = tmp("missing");
    let path = d.join("bad.rvir");
    std::fs::write(&path, GOOD.replace("    issue %d add0 13\n", "")).unwrap();
    let o = opt(&[path.to_str().unwrap(), "-passes=", "-o", "-"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("op %d is never issued"), "{e}");
    let line = GOOD.lines().position(|l| l.trim_start().starts_with("%d =")).unwrap() + 1;
    assert!(e.contains(&format!("{}:{line}:", path.display())), "{e}");
}

#[test]
fn sim_errors_name_the_offending_line() {
    // Two loads into one word before cycle 0: the verifier does not follow word lifetimes,
    // `sim` does, and names the second load's line.
    let d = tmp("sim_line");
    let (path, at) = broken(&d, "load add0 1 %y", "load add0 0 %y");
    let o = opt(&[path.to_str().unwrap(), "-passes=", "-o", "-"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = opt(&[path.to_str().unwrap(), "-passes=sim", "-o", "-"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains(&at), "no `{at}` in:\n{e}");
    assert!(e.contains("written twice in one cycle"), "{e}");
}

#[test]
fn a_pass_in_the_wrong_phase_names_the_function_line() {
    let d = tmp("wrong_phase");
    let path = d.join("parsed.rvir");
    std::fs::write(&path, "; a parsed function\nfunc @g {\n  input %x\n  %y = mul %x, 2.0\n  output o = %y\n}\n")
        .unwrap();
    let o = opt(&[path.to_str().unwrap(), "-passes=asap-alap", "-o", "-"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("needs phase Atomised"), "{e}");
    assert!(e.contains(&format!("{}:2:1", path.display())), "{e}");
}

#[test]
fn a_broken_double_pendulum_placement_is_rejected() {
    let d = tmp("pendulum");
    let placed = d.join("x.rvir");
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/double_pendulum/mbs_invdyna_double_pendulum.c");
    let o = opt(&[src, "-passes=atomise,place<pe=2>", "-o", placed.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&placed).unwrap();
    // Move the first `mul` op onto an ADD PE.
    let mul = text.lines().find_map(|l| l.trim().split_once(" = mul ").map(|(v, _)| v.to_string())).expect("a mul op");
    let lines: Vec<&str> = text.lines().collect();
    let i = lines.iter().position(|l| l.trim_start().starts_with(&format!("issue {mul} "))).unwrap();
    let mut out: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    let cycle = out[i].rsplit(' ').next().unwrap().to_string();
    out[i] = format!("    issue {mul} add1 {cycle}");
    let bad = d.join("bad.rvir");
    std::fs::write(&bad, out.join("\n") + "\n").unwrap();
    let o = opt(&[bad.to_str().unwrap(), "-passes="]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains(&format!("{}:{}:5", bad.display(), i + 1)), "{e}");
    assert!(e.contains("a PE of the wrong type"), "{e}");
}

#[test]
fn sim_prints_a_stats_line_and_a_report_object() {
    let d = tmp("sim_stats");
    let path = d.join("good.rvir");
    std::fs::write(&path, GOOD).unwrap();
    let report = d.join("r.json");
    let o = opt(&[
        path.to_str().unwrap(),
        "-passes=sim<seeds=2>",
        "-stats",
        "-o",
        d.join("o.rvir").to_str().unwrap(),
        &format!("-report={}", report.display()),
    ]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{e}");
    assert!(e.lines().any(|l| l == "sim: simulated 1 placement bit-exact in f32 and f64 (2 seeds)"), "{e}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let s = &r["sim"];
    assert_eq!(s["placements"], 1, "{r}");
    assert_eq!(s["seeds"], 2, "{r}");
    assert_eq!(s["bit_exact"], true, "{r}");
    assert_eq!(s["precisions"], serde_json::json!(["f32", "f64"]), "{r}");
    assert_eq!(s["functions"][0]["function"], "f", "{r}");
    assert_eq!(s["functions"][0]["cycles"], 25, "{r}");
    assert_eq!(s["functions"][0]["outputs"], 2, "{r}");
    assert_eq!(s["functions"][0]["writes_direct"], 4, "{r}");
    // Without `sim` there is no line and no object.
    let o = opt(&[path.to_str().unwrap(), "-passes=", "-stats", "-o", "-", &format!("-report={}", report.display())]);
    assert!(!stderr(&o).contains("sim: simulated"));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(r.get("sim").is_none(), "{r}");
}
