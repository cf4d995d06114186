//! `-target` and the one set of latencies every pass reads (issue 12, first part): the target
//! file reader's diagnostics, the latencies a pass gives explicitly carried to later passes and
//! to the final figures (the disagreements of the issue), µs at the target's clock and the
//! sweep's fit. Every expected figure is computed by hand in the comments.

use std::path::{Path, PathBuf};

use crate::common::{opt, stderr, tmp};

/// `X = (a*b + c)*a`, `W = b*c`: the critical path is mul → add → mul. With lat-add = A and
/// lat-mul = M it is 2M + A cycles; on 1 ADD + 1 MULTI PE the placement reaches it (a*b issues
/// at 0 and arrives at M, written straight into the ADD PE's memory; the add issues at M and
/// arrives at M + A, written into the MULTI PE's memory; the last mul issues then).
const SMALL: &str = "\
func @f {
  phase parsed
  input %a
  input %b
  input %c
  %X = (%a*%b + %c)*%a
  %W = %b*%c
  output Qq[1] = %X
  output Qq[2] = %W
}
";

/// An 8-term sum of products (`tests/ir/balance/sum_of_products.rvir`): with lat-add = A and
/// lat-mul = M the cascade is M + 7A cycles long and the balanced tree M + 3A.
const SUM: &str = "\
func @f {
  phase parsed
  input %a
  input %b
  input %c
  input %d
  input %e
  input %g
  input %h
  input %k
  %s = %a*%b - %c*%d + %e*%g + %h*%k + %a*%c - %b*%d + %e*%h + %g*%k
  output o = %s
}
";

fn write(d: &Path, name: &str, text: &str) -> PathBuf {
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The built-in target as JSON with `edits` (`from`, `to`) applied to the shipped example.
fn target_file(d: &Path, name: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/targets/de10-nano.json")).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from} not in the example target");
        text = text.replace(from, to);
    }
    write(d, name, &text)
}

/// Runs and returns (report, stderr); the run must succeed.
fn report(d: &Path, args: &[&str]) -> (serde_json::Value, String) {
    let r = d.join("r.json");
    let mut all: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    all.push(format!("-report={}", r.display()));
    all.push("-o".into());
    all.push(d.join("out.rvir").display().to_string());
    let refs: Vec<&str> = all.iter().map(String::as_str).collect();
    let o = opt(&refs);
    assert!(o.status.success(), "{}", stderr(&o));
    (serde_json::from_str(&std::fs::read_to_string(&r).unwrap()).unwrap(), stderr(&o))
}

#[test]
fn place_uses_the_latencies_asap_alap_was_given() {
    // Issue 12: `asap-alap<lat-add=6;lat-mul=4>,sweep` placed with them but `…,place` with
    // 12/7. Both now place with 6/4: 2·4 + 6 = 14 cycles (with 12/7 it would be 26).
    let d = tmp("asap_alap_then_place");
    let input = write(&d, "small.rvir", SMALL);
    let (r, _) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,asap-alap<lat-add=6;lat-mul=4>,place<pe=1>"]);
    let p = &r["placement"];
    assert_eq!((p["lat_add"].as_u64(), p["lat_mul"].as_u64()), (Some(6), Some(4)));
    assert_eq!(p["cycles"], 14);
    assert_eq!(r["stats"]["asap_cycle"], 14);
    assert_eq!(r["stats"]["latencies_from"], "asap-alap<lat-add=6;lat-mul=4>");
    let (s, _) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,asap-alap<lat-add=6;lat-mul=4>,sweep<pe=1,2>"]);
    for row in s["sweep"].as_array().unwrap() {
        assert_eq!((row["lat_add"].as_u64(), row["lat_mul"].as_u64()), (Some(6), Some(4)), "{row}");
        assert_eq!(row["critical_path"], 14);
        assert_eq!(row["cycles"], 14, "{row}");
    }
    assert_eq!(s["sweep_fit"][0]["n_critical_path"], 1);
    assert_eq!(s["sweep_fit"][0]["critical_path"], 14);
}

#[test]
fn balance_note_and_the_final_stats_line_give_one_critical_path() {
    // lat-add = 3, lat-mul = 2: cascade 2 + 7·3 = 23, balanced 2 + 3·3 = 11. The final
    // `-stats` line said 7 + 3·12 = 43 (the default latencies) before issue 12.
    let d = tmp("balance_stats");
    let input = write(&d, "sum.rvir", SUM);
    let (r, err) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,balance<lat-add=3;lat-mul=2>", "-stats"]);
    assert!(err.contains("critical path 23 -> 11 cycles"), "{err}");
    assert!(err.contains("critical path 4 ops / 11 cycles"), "{err}");
    assert!(err.contains("(latencies add 3, mul 2: balance<lat-add=3;lat-mul=2>)"), "{err}");
    assert_eq!(r["stats"]["asap_cycle"], 11);
    assert_eq!(r["stats"]["latencies"]["add"], 3);
    // Without lat-* the target's (12, 7): 7 + 3·12 = 43, and the report says so.
    let (r, err) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,balance", "-stats"]);
    assert!(err.contains("critical path 91 -> 43 cycles"), "{err}");
    assert_eq!(r["stats"]["asap_cycle"], 43);
    assert_eq!(r["stats"]["latencies_from"], "target de10-nano");
}

#[test]
fn a_target_file_sets_every_pass_and_a_pass_parameter_overrides_it_explicitly() {
    let d = tmp("target_file");
    let input = write(&d, "small.rvir", SMALL);
    let t = target_file(
        &d,
        "t.json",
        &[
            ("\"name\": \"de10-nano\"", "\"name\": \"slow\""),
            ("\"clock_mhz\": 120.0", "\"clock_mhz\": 50.0"),
            ("\"add\": 12, \"mul\": 7", "\"add\": 6, \"mul\": 4"),
        ],
    );
    let target = format!("-target={}", t.display());
    let (r, err) = report(&d, &[input.to_str().unwrap(), &target, "-passes=atomise,place<pe=1>", "-stats"]);
    // 2·4 + 6 = 14 cycles at 50 MHz: 14 / 50 = 0.28 µs.
    assert_eq!(r["placement"]["cycles"], 14);
    assert!((r["placement"]["us"].as_f64().unwrap() - 0.28).abs() < 1e-12);
    assert_eq!(r["placement"]["clock_mhz"], 50.0);
    assert_eq!(r["stats"]["asap_cycle"], 14);
    assert_eq!(r["stats"]["latencies_from"], "target slow");
    assert!(err.contains("14 cycles") && err.contains("0.280 µs at 50 MHz"), "{err}");
    // `lat-add=12` on place overrides the file's 6 only: 2·4 + 12 = 20 cycles, 0.4 µs.
    let (r, _) = report(&d, &[input.to_str().unwrap(), &target, "-passes=atomise,place<pe=1;lat-add=12>"]);
    assert_eq!(r["placement"]["cycles"], 20);
    assert_eq!((r["placement"]["lat_add"].as_u64(), r["placement"]["lat_mul"].as_u64()), (Some(12), Some(4)));
    assert!((r["placement"]["us"].as_f64().unwrap() - 0.4).abs() < 1e-12);
    assert_eq!(r["stats"]["latencies_from"], "place<lat-add=12>");
}

#[test]
fn microseconds_and_the_estimate_on_the_built_in_target() {
    let d = tmp("us_estimate");
    let input = write(&d, "small.rvir", SMALL);
    let (r, _) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,place<pe=1>"]);
    let p = &r["placement"];
    // 2·7 + 12 = 26 cycles at 120 MHz = 0.21666… µs.
    assert_eq!(p["cycles"], 26);
    assert!((p["us"].as_f64().unwrap() - 26.0 / 120.0).abs() < 1e-12);
    // 1 ADD + 1 MULTI: ALM 360 + 100 + the crossbar design in the Cyclone V's Yosys figures,
    // 32-bit words: 2 PE memories · 2 ports of 4 inputs (0.35 ALM an input bit, 0.05 a port
    // bit), 1.35 a PE bit, 1.2 a bit of each buffer word beyond a PE's first (as placed);
    // DSP 2 + 3 = 5; M10K per PE: PE memory 2048·32/10240 → 7, buffer 16·32 → 1,
    // instructions 27·52 → 1, buffer instructions 27·10 → 1, crossbar 27·2·3 → 1: 11, × 2 = 22.
    let buffers: f64 =
        p["buffer_words"].as_array().unwrap().iter().map(|b| b.as_u64().unwrap().max(1) as f64 - 1.0).sum();
    let alm = 460.0 + 32.0 * (4.0 * (0.35 * 4.0 + 0.05) + 2.0 * 1.35 + 1.2 * buffers);
    let e = &p["estimate"];
    assert_eq!((e["alm"].as_f64(), e["dsp"].as_u64(), e["m10k"].as_u64()), (Some(alm.ceil()), Some(5), Some(22)));
    assert_eq!(e["fits"], true);
}

#[test]
fn sweep_names_the_ns_that_fit_the_device() {
    // A device of 10 DSP: N = 1 needs 5, N = 2 needs 10, N = 4 needs 20.
    let d = tmp("sweep_fit");
    let input = write(&d, "small.rvir", SMALL);
    let t = target_file(&d, "t.json", &[("\"dsp\": 112", "\"dsp\": 10")]);
    let target = format!("-target={}", t.display());
    let (r, err) = report(&d, &[input.to_str().unwrap(), &target, "-passes=atomise,sweep<pe=1,2,4>"]);
    let fit = &r["sweep_fit"][0];
    assert_eq!((fit["n_fits_min"].as_u64(), fit["n_fits_max"].as_u64()), (Some(1), Some(2)), "{fit}");
    // 2·7 + 12 = 26 cycles, reached at N = 1.
    assert_eq!((fit["critical_path"].as_u64(), fit["n_critical_path"].as_u64()), (Some(26), Some(1)));
    assert!((fit["best_us"].as_f64().unwrap() - 26.0 / 120.0).abs() < 1e-12);
    for row in r["sweep"].as_array().unwrap() {
        assert_eq!(row["fits"], row["n"].as_u64().unwrap() <= 2, "{row}");
        assert_eq!(row["dsp"], 5 * row["n"].as_u64().unwrap());
    }
    assert!(err.contains("fits the device from N = 1 to N = 2"), "{err}");
    // 4 DSP: nothing fits.
    let t = target_file(&d, "t4.json", &[("\"dsp\": 112", "\"dsp\": 4")]);
    let (r, _) =
        report(&d, &[input.to_str().unwrap(), &format!("-target={}", t.display()), "-passes=atomise,sweep<pe=1>"]);
    assert!(r["sweep_fit"][0]["n_fits_min"].is_null());
}

/// Runs with a bad target: exit 1, nothing written, the diagnostic returned.
fn bad_target(d: &Path, target: &str) -> String {
    let input = write(d, "small.rvir", SMALL);
    let out = d.join("never.rvir");
    let o =
        opt(&[input.to_str().unwrap(), &format!("-target={target}"), "-passes=atomise", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(!out.exists());
    stderr(&o)
}

#[test]
fn bad_target_files_are_bad_input_with_file_line_and_column() {
    let d = tmp("bad_targets");
    // An unknown key on line 3 (`"clok_mhz"`, a typo): serde names it, with file:line:column.
    let t = write(&d, "typo.json", "{\n  \"name\": \"x\",\n  \"clok_mhz\": 50\n}\n");
    let e = bad_target(&d, t.to_str().unwrap());
    assert!(e.contains(&format!("{}:3:", t.display())), "{e}");
    assert!(e.contains("unknown field `clok_mhz`"), "{e}");
    // An unknown key inside `latencies`, on line 4 of the example.
    let t = target_file(&d, "nested.json", &[("\"add\": 12,", "\"add\": 12, \"fma\": 5,")]);
    let e = bad_target(&d, t.to_str().unwrap());
    assert!(e.contains(&format!("{}:4:", t.display())) && e.contains("unknown field `fma`"), "{e}");
    // Not JSON.
    let t = write(&d, "garbage.json", "{\n  \"name\": \"x\",\n  oops\n}\n");
    let e = bad_target(&d, t.to_str().unwrap());
    assert!(e.contains(&format!("{}:3:3", t.display())), "{e}");
    // A missing key.
    let t = target_file(&d, "missing.json", &[("  \"writes\": 2,\n", "")]);
    let e = bad_target(&d, t.to_str().unwrap());
    assert!(e.contains("missing field `writes`"), "{e}");
    // Senseless values: zero latency, zero ports, zero words, a clock ≤ 0.
    for (from, to, field) in [
        ("\"mul\": 7", "\"mul\": 0", "latencies.mul"),
        ("\"writes\": 2", "\"writes\": 0", "writes"),
        ("\"pe_words\": 2048", "\"pe_words\": 0", "pe_words"),
        ("\"clock_mhz\": 120.0", "\"clock_mhz\": 0", "clock_mhz"),
        ("\"clock_mhz\": 120.0", "\"clock_mhz\": -120.0", "clock_mhz"),
    ] {
        let t = target_file(&d, "value.json", &[(from, to)]);
        let e = bad_target(&d, t.to_str().unwrap());
        assert!(e.contains(&format!("`{field}`")), "{to}: {e}");
    }
    // A name that is neither built in nor a file.
    let e = bad_target(&d, "de11-nano");
    assert!(
        e.contains("cannot read target file de11-nano") && e.contains("built-in target (de10-nano, ecp5-85f)"),
        "{e}"
    );
}

#[test]
fn the_built_in_target_by_name_and_as_a_file_give_the_same_report() {
    let d = tmp("built_in_vs_file");
    let input = write(&d, "small.rvir", SMALL);
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/targets/de10-nano.json");
    let (a, _) = report(&d, &[input.to_str().unwrap(), "-target=de10-nano", "-passes=atomise,place<pe=2>"]);
    let (b, _) =
        report(&d, &[input.to_str().unwrap(), &format!("-target={}", file.display()), "-passes=atomise,place<pe=2>"]);
    let (c, _) = report(&d, &[input.to_str().unwrap(), "-passes=atomise,place<pe=2>"]);
    assert_eq!(a["placement"]["cycles"], b["placement"]["cycles"]);
    assert_eq!(a["placement"]["estimate"], b["placement"]["estimate"]);
    assert_eq!(a["placement"]["estimate"], c["placement"]["estimate"]);
    assert_eq!(a["stats"], c["stats"]);
}
