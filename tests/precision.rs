//! `precision` (issue 48 item 5): the formats it chooses keep every output within its budget,
//! proved by `error-bound` over the same domain and checked against `-eval` at sampled points
//! (against the certified exact value); cheaper formats where the budget allows, none where it
//! does not; an unreachable budget is a diagnostic (exit 1).

use robovec_ir::domain::Domain;
use robovec_ir::numerics::{Reference, Tape};
use robovec_ir::rng::SplitMix64;
use robovec_ir::{Function, Operand};
use robovec_passes::error_bound::{bound, Formats};
use robovec_passes::precision::{choose, Target};
use robovec_passes::range::enclose_with;

use crate::common::{opt, stderr};
use crate::range::{random_function, range};

/// Applies `choose`'s formats to a copy of `f`.
fn with_choice(f: &Function, dom: &Domain, budget: f64, target: Target) -> Option<(Function, Vec<(String, f64)>)> {
    let x = enclose_with(f, dom, Some(64), || false).unwrap();
    let budgets = vec![robovec_passes::precision::budget::Budget::Rel(budget); f.outputs.len()];
    let c = choose(f, &x, &budgets, target, || false).ok()?;
    let mut g = f.clone();
    for &(v, fmt) in &c.formats {
        g.set_format(v, fmt);
    }
    Some((g, c.outputs.iter().map(|(n, _, b, _)| (n.clone(), *b)).collect()))
}

/// Every output of `g` (formatted) within its budget: by `error-bound`'s certified bound, and
/// at 32 points of the domain by `-eval`'s formats against the certified exact value.
fn assert_within(what: &str, g: &Function, dom: &Domain, budgets: &[(String, f64)], seed: u64) {
    let x = enclose_with(g, dom, Some(64), || false).unwrap();
    let e = bound(g, &x, Formats::Mixed, || false).unwrap_or_else(|e| panic!("{what}: {e:?}"));
    let tape = Tape::new(g);
    let mut reference = Reference::new();
    let mut refs = Vec::new();
    let mut rng = SplitMix64::new(seed);
    for (name, b) in budgets {
        let o = g.outputs.iter().find(|o| &o.name == name).unwrap();
        let Operand::Value(v) = o.value else { continue };
        assert!(e[v.index()] <= *b, "{what}: {name}: bound {:e} above its budget {b:e}", e[v.index()]);
    }
    for _ in 0..32 {
        let xs = crate::range::uniform_point(&tape.inputs, dom, &mut rng);
        let at = |n: &str| xs[tape.inputs.iter().position(|m| m == n).unwrap()];
        let vals = robovec_ir::format::eval_values(g, at).unwrap_or_else(|e| panic!("{what}: {e:?}"));
        reference.eval(&tape, &xs, &mut refs);
        for ((name, _), r) in tape.outputs.iter().zip(&refs) {
            let Some((_, b)) = budgets.iter().find(|(n, _)| n == name) else { continue };
            let o = g.outputs.iter().find(|o| &o.name == name).unwrap();
            let Operand::Value(v) = o.value else { continue };
            if r.certified {
                let err = (vals[v.index()] - r.f64).abs();
                assert!(err <= *b * (1.0 + 1e-12), "{what}: {name} off by {err:e}, budget {b:e}");
            }
        }
    }
}

/// Random functions with every op, the three targets, budgets from 10⁻¹² to 10⁻²: the formats chosen
/// always meet the budget; loose budgets give cheaper formats.
#[test]
fn chosen_formats_meet_the_budget_on_random_functions() {
    let mut cheaper = 0;
    for seed in 0..60u64 {
        let (f, dom) = random_function(seed * 31 + 5, 5 + seed as usize % 50);
        for (budget, target) in [
            (1e-2, Target::C),
            (1e-6, Target::Mcu),
            (1e-12, Target::C),
            (1e-4, Target::Mcu),
            (1e-3, Target::Fpga),
            (1e-9, Target::Fpga),
        ] {
            let Some((g, budgets)) = with_choice(&f, &dom, budget, target) else { continue };
            assert_within(&format!("seed {seed} {budget:e} {target:?}"), &g, &dom, &budgets, seed);
            cheaper += usize::from(g.has_formats());
        }
    }
    assert!(cheaper > 60, "only {cheaper} choices used a cheaper format");
}

/// The Segway `dirdyna` over a narrow domain: at 10⁻³ every value is binary32 (C) and the cost
/// halves; at 10⁻⁹ most stay binary64; for the microcontroller 32-bit fixed point; every
/// choice meets its budget.
#[test]
fn the_segway_gets_binary32_at_a_loose_budget() {
    let (f, dom) = segway();
    let (g, budgets) = with_choice(&f, &dom, 1e-3, Target::C).unwrap();
    let values = f.inputs.len() + f.body.len();
    let f32s = f.inputs.iter().chain(&f.body).filter(|&&v| g.format(v) == robovec_ir::format::Format::Binary32).count();
    assert_eq!(f32s, values, "every value binary32 at 1e-3");
    assert_within("segway 1e-3", &g, &dom, &budgets, 1);
    let (g, budgets) = with_choice(&f, &dom, 1e-9, Target::C).unwrap();
    let f32s = f.inputs.iter().chain(&f.body).filter(|&&v| g.format(v) == robovec_ir::format::Format::Binary32).count();
    assert!(f32s < values / 10, "{f32s} of {values} binary32 at 1e-9");
    assert_within("segway 1e-9", &g, &dom, &budgets, 2);
    let (g, budgets) = with_choice(&f, &dom, 1e-5, Target::Mcu).unwrap();
    let fixed = f
        .inputs
        .iter()
        .chain(&f.body)
        .filter(|&&v| matches!(g.format(v), robovec_ir::format::Format::Fix { width: 32, .. }))
        .count();
    assert!(fixed > values * 9 / 10, "{fixed} of {values} in fix<32,*>");
    assert_within("segway mcu 1e-5", &g, &dom, &budgets, 3);
}

/// An unreachable budget (below binary64's own error) keeps the outputs as binary64 computes
/// them and names them; the pass's line and report, and the formats in the output IR.
#[test]
fn the_pass_reports_and_keeps_binary64_where_the_budget_is_unreachable() {
    let dir = crate::common::tmp("precision");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"a": [1, 2], "b": [0.5, 1]}"#).unwrap();
    let run = |budget: &str| {
        opt(&[
            "tests/inputs/ranges/div.rvir",
            &format!("-ranges={}", ranges.display()),
            &format!("-passes=precision<budget={budget}>,error-bound"),
            &format!("-report={}", report.display()),
            "-o",
            dir.join("out.rvir").to_str().unwrap(),
        ])
    };
    let o = run("1e-16");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot meet the budget even in binary64"), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(!r["precision"]["unreachable"].as_array().unwrap().is_empty(), "{}", r["precision"]);
    assert!(r["precision"]["formats"].get("f32").is_none(), "{}", r["precision"]);
    let o = run("1e-3");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("precision @"), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["precision"]["target"], "c");
    assert!(r["precision"]["formats"]["f32"].as_u64().unwrap() > 0, "{}", r["precision"]);
    assert!(r["precision"]["max_rel_to_range"].as_f64().unwrap() <= 1e-3);
    // The output IR carries the formats and reads back.
    let text = std::fs::read_to_string(dir.join("out.rvir")).unwrap();
    assert!(text.contains(": f32"), "{text}");
    robovec_ir::text::parse(&text).unwrap();
}

/// `budget=FILE`: absolute budgets per output (globs), the chosen formats meet each (the
/// report's bound, and `error-bound` after it), an output without a budget is exit 1.
#[test]
fn a_budget_file_gives_absolute_budgets_per_output() {
    let dir = crate::common::tmp("precision-file");
    let (ranges, budgets, report) = (dir.join("r.json"), dir.join("b.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"qd[2]": [-3, 3]}"#).unwrap();
    let run = |text: &str| {
        std::fs::write(&budgets, text).unwrap();
        opt(&[
            "examples/three_link_arm/three_link_arm.urdf",
            "-function=invdyna",
            &format!("-ranges={}", ranges.display()),
            &format!("-passes=atomise,precision<budget={};target=mcu>,error-bound", budgets.display()),
            &format!("-report={}", report.display()),
            "-o",
            "/dev/null",
        ])
    };
    let o = run(r#"{"Qq[*]": {"abs": 1e-4}}"#);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for (name, b) in r["error_bound"]["outputs"].as_object().unwrap() {
        assert!(b["abs"].as_f64().unwrap() <= 1e-4, "{name}: {b}");
    }
    assert!(r["precision"]["budget"].is_null());
    assert!(
        r["precision"]["formats"].as_object().unwrap().keys().any(|k| k.starts_with("fix<32,")),
        "{}",
        r["precision"]
    );
    let o = run(r#"{"Qq[1]": {"abs": 1e-4}}"#);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no budget for output"), "{}", stderr(&o));
    // A missing file is found before any work.
    let o = opt(&[
        "examples/three_link_arm/three_link_arm.urdf",
        "-function=invdyna",
        &format!("-ranges={}", ranges.display()),
        "-passes=atomise,precision<budget=nowhere.json>",
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot read budget file `nowhere.json`"), "{}", stderr(&o));
}

/// `word=W` (issue 49: fixed-point PEs whose products fit one DSP multiplier): `target=mcu`'s
/// words are then `fix<W,f>` and `error-bound` still proves the budget; a narrower word's bound is
/// no smaller than a wider one's; `word` alone selects `target=mcu`. `word` with another target,
/// or outside 8..=32, is bad usage.
#[test]
fn target_mcu_takes_the_fixed_point_word_it_is_given() {
    let dir = crate::common::tmp("precision_word");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"q[*]": [-3.2, 3.2], "qd[*]": [-10, 10], "qdd[*]": [-10, 10]}"#).unwrap();
    let run = |params: &str| {
        opt(&[
            "examples/three_link_arm/three_link_arm.urdf",
            "-function=invdyna",
            &format!("-ranges={}", ranges.display()),
            &format!("-passes=atomise,precision<budget=1e-3;{params}>,error-bound"),
            &format!("-report={}", report.display()),
            "-o",
            "/dev/null",
        ])
    };
    let mut worst = Vec::new();
    for word in [32, 24, 20] {
        let o = run(&format!("target=mcu;word={word}"));
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        let formats = r["precision"]["formats"].as_object().unwrap();
        let fix: Vec<&String> = formats.keys().filter(|k| k.starts_with("fix<")).collect();
        assert!(!fix.is_empty(), "word={word}: {formats:?}");
        assert!(fix.iter().all(|k| k.starts_with(&format!("fix<{word},"))), "word={word}: {formats:?}");
        let mut w = 0.0f64;
        for (name, o) in r["precision"]["outputs"].as_object().unwrap() {
            let budget = o["budget"].as_f64().unwrap();
            // error-bound's own proof after the pass, against the budget precision was given
            let proved = r["error_bound"]["outputs"][name]["abs"].as_f64().unwrap();
            assert!(proved <= budget, "word={word}: {name}: bound {proved}, budget {budget}");
            w = w.max(proved / budget);
        }
        worst.push(w);
    }
    assert!(worst[0] <= worst[1] && worst[1] <= worst[2], "narrower words, larger bounds: {worst:?}");
    // `word` alone selects target=mcu
    let o = run("word=24");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["precision"]["target"], "mcu");
    assert!(r["precision"]["formats"].as_object().unwrap().keys().any(|k| k.starts_with("fix<24,")));
    for bad in ["target=c;word=20", "target=fpga;word=27", "target=mcu;word=40", "target=mcu;word=7"] {
        let o = run(bad);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("word"), "{bad}: {}", stderr(&o));
    }
}

/// A stop inside the search keeps the formats accepted so far: still within every budget.
#[test]
fn a_stopped_search_keeps_accepted_formats() {
    for seed in 0..20u64 {
        let (f, dom) = random_function(seed * 13 + 2, 30);
        let x = enclose_with(&f, &dom, Some(64), || false).unwrap();
        let budgets = vec![robovec_passes::precision::budget::Budget::Rel(1e-4); f.outputs.len()];
        let mut left = (seed % 8) as i32;
        let target = if seed % 2 == 0 { Target::Mcu } else { Target::Fpga };
        let Ok(c) = choose(&f, &x, &budgets, target, || {
            left -= 1;
            left < 0
        }) else {
            continue;
        };
        let mut g = f.clone();
        for &(v, fmt) in &c.formats {
            g.set_format(v, fmt);
        }
        let named: Vec<(String, f64)> = c.outputs.iter().map(|(n, _, b, _)| (n.clone(), *b)).collect();
        assert_within(&format!("stopped seed {seed} {target:?}"), &g, &dom, &named, seed);
    }
}

/// The budget ladder of `-report-dir`'s cost-against-budget figure: each point is `choose` at
/// that budget (run here directly, on the function without formats), the certified bound within
/// the budget, the cost never above binary64's; a tick budget stops it with the points finished
/// and says where, never a panic.
#[test]
fn the_budget_ladder_is_the_chooser_at_each_budget() {
    use robovec_passes::precision::budget::Budget;
    use robovec_passes::precision::ladder::{ladder, BUDGETS};
    for seed in 0..12u64 {
        let (f, dom) = random_function(seed * 7 + 3, 20 + seed as usize);
        let x = enclose_with(&f, &dom, Some(robovec_passes::range::affine::DEFAULT_TERMS), || false).unwrap();
        for target in [Target::C, Target::Mcu] {
            // The ladder runs on the function with formats already chosen: they are ignored.
            let formatted = with_choice(&f, &dom, 1e-3, target).map_or_else(|| f.clone(), |(g, _)| g);
            let Ok(l) = ladder(&formatted, &dom, target, &BUDGETS, &robovec_passes::Ticker::new(None, None)) else {
                continue;
            };
            assert_eq!(l.stopped, None);
            assert_eq!(l.points.len(), BUDGETS.len(), "seed {seed}");
            for (p, &b) in l.points.iter().zip(&BUDGETS) {
                let direct = choose(&f, &x, &vec![Budget::Rel(b); f.outputs.len()], target, || false).unwrap();
                assert_eq!(p, &direct.report(&f.name), "seed {seed} {target:?} {b:e}");
                assert_eq!(p.budget, Some(b));
                assert!(p.cost_after <= p.cost_before, "seed {seed} {b:e}: {p:?}");
                if p.unreachable.is_empty() {
                    assert!(p.max_rel_to_range <= b, "seed {seed} {b:e}: {p:?}");
                }
            }
        }
    }
    // Stopped by a tick budget: fewer points, each still the chooser's, and the reason.
    let (f, dom) = random_function(11, 40);
    let counted = robovec_passes::Ticker::new(None, None);
    let full = ladder(&f, &dom, Target::C, &BUDGETS, &counted).unwrap();
    let total = counted.ticks();
    let mut cut = None;
    for ticks in [1, total / 4, total / 2, total * 3 / 4, total - 1] {
        let l = ladder(&f, &dom, Target::C, &BUDGETS, &robovec_passes::Ticker::new(None, Some(ticks))).unwrap();
        let why = l.stopped.as_deref().unwrap_or_else(|| panic!("{ticks} ticks: not stopped"));
        assert!(why.contains("tick budget of"), "{why}");
        assert_eq!(l.points[..], full.points[..l.points.len()], "{ticks} ticks");
        cut = cut.max(Some(l.points.len()));
    }
    assert!(cut.unwrap() > 0, "some budget stops after a point");
}

/// The Segway `dirdyna` (atomised) with `q` in [0.1, 0.3] rad and `qd`, `qdd` in ±1, the other
/// inputs over `generous_domain`'s ranges.
fn segway() -> (Function, Domain) {
    let path = crate::common::corpus_dir().join("c/frank_segway__mbs_dirdyna_Frank_segway.c");
    let (m, _) = robovec::driver::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{}", e.message()));
    let f = robovec_ir::transform::atomise::atomise_function(&m.functions[0]);
    let mut dom = crate::range::generous_domain(&f);
    for (n, r) in dom.ranges.iter_mut() {
        if n.starts_with("q[") {
            *r = range(0.1, 0.3);
        } else if n.starts_with("qd") {
            *r = range(-1.0, 1.0);
        }
    }
    (f, dom)
}

/// `target=fpga` on the Segway `dirdyna`: every choice meets its budget (bound and sampled
/// points); at 10⁻³ most values are fixed point and the words average under 32 bits (narrower
/// than `mcu`'s); the device share the cost model gives never grows as the budget loosens
/// (10⁻⁷ to 10⁻²), and it is below binary64's.
#[test]
fn the_segway_gets_narrow_fixed_point_words_on_the_fpga() {
    let (f, dom) = segway();
    let x = enclose_with(&f, &dom, Some(64), || false).unwrap();
    let device = robovec_machine::target::Target::de10_nano();
    let values = f.inputs.len() + f.body.len();
    let mut last: Option<(f64, f64)> = None;
    for (k, budget) in [1e-7, 1e-5, 1e-3, 1e-2].into_iter().enumerate() {
        let budgets = vec![robovec_passes::precision::budget::Budget::Rel(budget); f.outputs.len()];
        let c = robovec_passes::precision::choose_on(
            &f,
            &x,
            &budgets,
            Target::Fpga,
            &device,
            robovec_passes::error_bound::TrigImpl::Libm,
            32,
            || false,
        )
        .unwrap();
        let mut g = f.clone();
        for &(v, fmt) in &c.formats {
            g.set_format(v, fmt);
        }
        let named: Vec<(String, f64)> = c.outputs.iter().map(|(n, _, b, _)| (n.clone(), *b)).collect();
        assert_within(&format!("segway fpga {budget:e}"), &g, &dom, &named, 10 + k as u64);
        let fig = c.fpga.as_ref().expect("fpga figures");
        assert_eq!(fig.device, "de10-nano");
        let share = 100.0 * (fig.dsp.1 / 112.0 + fig.alm.1 / 41_910.0);
        assert!((share - c.cost.1).abs() <= 1e-9 * share, "{share} vs {}", c.cost.1);
        assert!(c.cost.1 < c.cost.0, "{budget:e}: {} not below binary64's {}", c.cost.1, c.cost.0);
        if let Some((prev_budget, prev)) = last {
            assert!(c.cost.1 <= prev, "{budget:e} costs {} > {prev} at the tighter {prev_budget:e}", c.cost.1);
        }
        last = Some((budget, c.cost.1));
        if budget == 1e-3 {
            let fixed: usize = fig.widths.values().sum();
            let bits: usize = fig.widths.iter().map(|(w, n)| *w as usize * n).sum();
            assert!(fixed > values * 9 / 10, "{fixed} of {values} fixed point");
            let mean = bits as f64 / fixed as f64;
            assert!(mean < 32.0, "mean width {mean}");
            eprintln!("segway fpga 1e-3: mean width {mean:.1}, {} DSP, {} ALM", fig.dsp.1, fig.alm.1);
        }
    }
}

/// The pass with `target=fpga` through the command line: the report's `widths`, `dsp`, `alm`
/// and `device` (absent for `c`), the formats in the output IR, and `error-bound` after it
/// within the budget.
#[test]
fn the_pass_reports_widths_and_device_resources_for_the_fpga() {
    let dir = crate::common::tmp("precision-fpga");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"qd[2]": [-3, 3]}"#).unwrap();
    let run = |target: &str| {
        let o = opt(&[
            "examples/three_link_arm/three_link_arm.urdf",
            "-function=invdyna",
            &format!("-ranges={}", ranges.display()),
            &format!("-passes=default<ops>,precision<budget=1e-4;target={target}>,error-bound"),
            &format!("-report={}", report.display()),
            "-o",
            dir.join("out.rvir").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        (stderr(&o), r)
    };
    let (err, r) = run("fpga");
    assert!(err.contains("% of de10-nano"), "{err}");
    let p = &r["precision"];
    assert_eq!(p["target"], "fpga");
    assert_eq!(p["device"], "de10-nano");
    assert!(p["dsp"].as_f64().unwrap() >= 0.0 && p["alm"].as_f64().unwrap() > 0.0, "{p}");
    let widths = p["widths"].as_object().unwrap();
    assert!(!widths.is_empty(), "{p}");
    let fixed: u64 = widths.values().map(|n| n.as_u64().unwrap()).sum();
    let in_formats: u64 = p["formats"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(k, _)| k.starts_with("fix<"))
        .map(|(_, n)| n.as_u64().unwrap())
        .sum();
    assert_eq!(fixed, in_formats, "{p}");
    assert!(p["max_rel_to_range"].as_f64().unwrap() <= 1e-4, "{p}");
    for (name, b) in r["error_bound"]["outputs"].as_object().unwrap() {
        assert!(b["abs"].as_f64().is_some_and(f64::is_finite), "{name}: {b}");
    }
    let text = std::fs::read_to_string(dir.join("out.rvir")).unwrap();
    assert!(text.contains(": fix<"), "{text}");
    robovec_ir::text::parse(&text).unwrap();
    let (_, r) = run("c");
    for key in ["widths", "dsp", "alm", "device"] {
        assert!(r["precision"].get(key).is_none(), "{key}: {}", r["precision"]);
    }
    // A target description without the 9- and 18-bit modes, named after the file's `name`:
    // every product takes whole DSP blocks.
    let mut t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("examples/targets/de10-nano.json").unwrap()).unwrap();
    t["name"] = "only-27".into();
    t["datapath"] = serde_json::json!({ "dsp_modes": [{ "a": 27, "b": 27, "per_block": 1 }] });
    let target = dir.join("only27.json");
    std::fs::write(&target, t.to_string()).unwrap();
    let o = opt(&[
        "examples/three_link_arm/three_link_arm.urdf",
        "-function=invdyna",
        &format!("-ranges={}", ranges.display()),
        &format!("-target={}", target.display()),
        "-passes=default<ops>,precision<budget=1e-4;target=fpga>",
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r27: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r27["precision"]["device"], "only-27");
    let dsp = r27["precision"]["dsp"].as_f64().unwrap();
    assert!(dsp > 0.0 && dsp.fract() == 0.0, "{}", r27["precision"]);
}

/// `target=mcu` end to end: a URDF arm's RNEA (`--fold-params`, over `q` ±1.5 rad, `qd` ±3
/// rad/s, `qdd` ±10 rad/s²) at a loose budget is 32-bit fixed point everywhere; `codegen<c>`
/// writes it as integer code — every op but sin/cos an integer op in `int32_t`/`int64_t`, the
/// only `double` arithmetic the inputs' and the four sin/cos' conversions — which compiles as
/// `-std=c99 -pedantic -Wall -Wextra -Werror` and computes bit for bit what `-eval` computes
/// at 64 points, each output within `error-bound`'s certified bound of the binary64 function.
#[test]
fn mcu_formats_are_integer_c_bit_exact_and_within_the_bound() {
    use robovec_backends::c::CodegenC;
    use std::fmt::Write as _;
    let dir = crate::common::tmp("precision-mcu-c");
    let ranges = dir.join("r.json");
    std::fs::write(
        &ranges,
        r#"{"q[*]": [-1.5, 1.5], "qd[*]": [-3, 3], "qdd[*]": [-10, 10], "g[1]": [0, 0], "g[2]": [0, 0], "g[3]": [-9.81, -9.81]}"#,
    )
    .unwrap();
    let (r, m) = crate::common::opt_to_ir(
        &dir,
        &[
            "examples/three_link_arm/three_link_arm.urdf",
            "-function=invdyna",
            "--fold-params",
            &format!("-ranges={}", ranges.display()),
            "-passes=default<ops>,precision<budget=1e-2;target=mcu>,error-bound",
        ],
    );
    let g = &m.functions[0];
    let fix = |v| matches!(g.format(v), robovec_ir::format::Format::Fix { width: 32, .. });
    assert!(g.inputs.iter().chain(&g.body).all(|&v| fix(v)), "{}", r["precision"]);
    let trig = g.body.iter().filter(|&&v| matches!(g.value(v).def, robovec_ir::Def::Trig(..))).count();
    let integer = g.body.iter().filter(|&&v| robovec_ir::format::integer_op(g, v).is_some()).count();
    assert_eq!(trig, 4, "cos and sin of q[1] and q[2]");
    assert_eq!(integer + trig, g.body.len(), "every op but sin/cos is an integer op");
    let art = CodegenC { name: Some("arm".into()), ..CodegenC::default() }.emit(&m).unwrap();
    let code = &art.code.main;
    // The body's only binary64: one conversion per input and per sin/cos (and the helper's own).
    let conversions = code.matches("robovec_fix_from(").count() - 1;
    assert_eq!(conversions, g.inputs.len() + trig, "{code}");
    std::fs::write(dir.join("arm.c"), code).unwrap();
    let iface = &art.interfaces[0];
    let (ni, no) = (iface.inputs.len(), iface.outputs.len());
    let dom = robovec_ir::domain::Domain {
        ranges: iface
            .inputs
            .iter()
            .map(|n| {
                let (lo, hi) = match n.split('[').next().unwrap() {
                    "q" => (-1.5, 1.5),
                    "qd" => (-3.0, 3.0),
                    "qdd" => (-10.0, 10.0),
                    _ if n == "g[3]" => (-9.81, -9.81),
                    _ => (0.0, 0.0),
                };
                (n.clone(), range(lo, hi))
            })
            .collect(),
    };
    let mut rng = SplitMix64::new(48);
    let mut binary64 = g.clone();
    binary64.clear_formats();
    let (mut bytes, mut want) = (Vec::new(), Vec::new());
    for _ in 0..64 {
        let xs = crate::range::uniform_point(&iface.inputs, &dom, &mut rng);
        let at = |n: &str| xs[iface.inputs.iter().position(|m| m == n).unwrap()];
        let vals = robovec_ir::format::eval_values(g, at).unwrap();
        let exact = robovec_ir::format::eval_values(&binary64, at).unwrap();
        bytes.extend(xs.iter().flat_map(|x| x.to_le_bytes()));
        for (name, out) in iface.outputs.iter().zip(&g.outputs) {
            let Operand::Value(v) = out.value else { panic!("{name} is a constant") };
            let b = r["error_bound"]["outputs"][name.as_str()]["abs"].as_f64().unwrap();
            want.push((name.clone(), vals[v.index()], exact[v.index()], b));
        }
    }
    let mut main = String::from("#include <stdio.h>\n#include <string.h>\n#include <stdint.h>\n");
    let _ = writeln!(
        main,
        "void arm(const double *restrict in, double *restrict out);\nint main(void)\n{{\n  double in[{ni}], out[{no}];\n  \
         while (fread(in, 8, {ni}, stdin) == {ni}) {{\n    arm(in, out);\n    for (int i = 0; i < {no}; i++) {{ uint64_t b; \
         memcpy(&b, &out[i], 8); printf(\"%016llx\\n\", (unsigned long long)b); }}\n  }}\n  return 0;\n}}"
    );
    std::fs::write(dir.join("main.c"), main).unwrap();
    let flags = ["-O1", "-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"];
    let exe = crate::common::compile_c(&dir, &flags, &["main.c", "arm.c"]);
    let got: Vec<f64> = crate::common::run_hex_lines(&exe, &bytes).into_iter().map(f64::from_bits).collect();
    assert_eq!(got.len(), want.len());
    for (c, (name, eval, exact, b)) in got.iter().zip(&want) {
        assert_eq!(c.to_bits(), eval.to_bits(), "{name}: C gives {c:e}, -eval {eval:e}");
        // The binary64 function's own error is far below the fixed-point bound.
        assert!((c - exact).abs() <= b * (1.0 + 1e-6), "{name}: {c:e} is {:e} from binary64, bound {b:e}", c - exact);
    }
}
