//! `range` and the input domain (issue 48 items 1–2): the enclosures are sound — every value
//! computed at a point of the domain lies in its enclosure — on random functions with every op
//! the IR has, on the corpus and on a URDF; the domain's defaults come from a URDF's `<limit>`s;
//! bad ranges files, missing ranges and divisors that may be 0 are located diagnostics (exit 1).

use std::collections::BTreeMap;

use proptest::prelude::*;
use robovec_ir::domain::{Domain, Range};
use robovec_ir::interp::eval_values;
use robovec_ir::numerics::{Tape, DD};
use robovec_ir::rng::SplitMix64;
use robovec_ir::{Function, Interval};
use robovec_passes::range::{enclose_with, EncloseError};

use crate::common::{opt, stderr};

pub(crate) fn range(lo: f64, hi: f64) -> Range {
    Range { interval: Interval::new(lo, hi), source: "test".into() }
}

/// A uniform point of `dom` for the inputs `names`, in that order.
pub(crate) fn uniform_point(names: &[String], dom: &Domain, rng: &mut SplitMix64) -> Vec<f64> {
    names
        .iter()
        .map(|n| {
            let i = dom.get(n).unwrap().interval;
            (i.lo + rng.unit() * (i.hi - i.lo)).clamp(i.lo, i.hi)
        })
        .collect()
}

/// A random domain for `f`'s inputs: each `[a, a + w]` with `a` in [−2, 2] and `w` in [0, 1]
/// (a point 30 % of the time).
pub(crate) fn random_domain(f: &Function, seed: u64) -> Domain {
    let mut rng = SplitMix64::new(seed ^ 7);
    let mut dom = Domain::default();
    for &v in &f.inputs {
        let a = rng.unit() * 4.0 - 2.0;
        let w = if rng.chance(300) { 0.0 } else { rng.unit() };
        dom.ranges.insert(f.name_of(v).to_string(), range(a, a + w));
    }
    dom
}

/// Evaluates `f` at `n` points of `dom` (the corners, then uniform draws) and asserts every
/// value computed in binary64, and every output's exact value, lies in its enclosure `x`.
fn assert_sound(what: &str, f: &Function, dom: &Domain, x: &[Interval], n: usize, seed: u64) {
    let mut rng = SplitMix64::new(seed);
    let inputs: Vec<(&str, Interval)> =
        f.inputs.iter().map(|&v| (f.name_of(v), dom.get(f.name_of(v)).unwrap().interval)).collect();
    let tape = Tape::new(f);
    for k in 0..n {
        let point: BTreeMap<&str, f64> = inputs
            .iter()
            .map(|&(name, i)| {
                let t = match k {
                    0 => 0.0,
                    1 => 1.0,
                    _ => rng.unit(),
                };
                (name, (i.lo + t * (i.hi - i.lo)).clamp(i.lo, i.hi))
            })
            .collect();
        let vals = eval_values::<f64>(f, |name| point[name]);
        for (i, (&y, e)) in vals.iter().zip(x).enumerate() {
            let v = robovec_ir::Value::with_number(i as u32);
            assert!(
                y.is_nan() || e.contains(y),
                "{what}: %{} = {y:e} at point {k} is outside its enclosure {e}",
                f.name_of(v)
            );
        }
        // The exact value too (double-double, ≈ 2⁻¹⁰⁰ relative: a tolerance of 10⁻²⁰ relative
        // tells an enclosure of the binary64 value alone, ~10⁻¹⁶ off, from one of both).
        let xs: Vec<f64> = tape.inputs.iter().map(|n| point[n.as_str()]).collect();
        for ((name, _), exact) in tape.outputs.iter().zip(tape.eval::<DD>(&xs)) {
            let o = f.outputs.iter().find(|o| &o.name == name).unwrap();
            let e = match o.value {
                robovec_ir::Operand::Value(v) => x[v.index()],
                robovec_ir::Operand::Const(c) => Interval::point(c),
            };
            let r = exact.hi + exact.lo;
            let tol = 1e-20 * r.abs().max(1.0);
            assert!(
                !r.is_finite() || (e.lo - tol <= r && r <= e.hi + tol),
                "{what}: the exact value of {name}, {r:e}, at point {k} is outside its enclosure {e}"
            );
        }
    }
}

/// A random atomised function with every op the IR has: `+ − × /`, `sqrt`, `fma`, `fms`,
/// `fnma`, `sin`/`cos` of inputs; divisors and square roots read `v·v + c` (c ≥ 0.25) so that
/// their enclosures are positive. Its inputs' domain: random intervals (some points).
pub(crate) fn random_function(seed: u64, ops: usize) -> (Function, Domain) {
    let mut rng = SplitMix64::new(seed);
    let n_in = 2 + rng.below(5) as usize;
    let mut text = String::from("func @f {\n  phase atomised\n");
    let mut names: Vec<String> = Vec::new();
    let mut dom = Domain::default();
    for k in 0..n_in {
        let n = format!("x{k}");
        text += &format!("  input %{n}\n");
        let a = rng.unit() * 8.0 - 4.0;
        let w = if rng.chance(200) { 0.0 } else { rng.unit() * 3.0 };
        dom.ranges.insert(n.clone(), range(a, a + w));
        names.push(n);
    }
    let mut t = 0;
    let mut fresh = |text: &mut String, def: String, names: &mut Vec<String>| {
        t += 1;
        let n = format!("t{t}");
        *text += &format!("  %{n} = {def}\n");
        names.push(n.clone());
        n
    };
    for _ in 0..ops {
        let pick = |rng: &mut SplitMix64, names: &[String]| {
            if rng.chance(80) {
                format!("{:?}", (rng.unit() * 4.0 - 2.0))
            } else {
                format!("%{}", names[rng.below(names.len() as u64) as usize])
            }
        };
        let (a, b, c) = (pick(&mut rng, &names), pick(&mut rng, &names), pick(&mut rng, &names));
        let def = match rng.below(10) {
            0..=1 => format!("add {a}, {b}"),
            2 => format!("sub {a}, {b}"),
            3..=4 => format!("mul {a}, {b}"),
            5 => format!("mul {a}, {a}"),
            6 | 7 => {
                let sq = fresh(&mut text, format!("mul {b}, {b}"), &mut names);
                let pos = fresh(&mut text, format!("add %{sq}, {:?}", 0.25 + rng.unit()), &mut names);
                if rng.chance(500) {
                    format!("div {a}, %{pos}")
                } else {
                    format!("call @sqrt(%{pos})")
                }
            }
            8 => {
                let f = ["fma", "fms", "fnma"][rng.below(3) as usize];
                format!("call @{f}({a}, {b}, {c})")
            }
            _ => {
                let x = &names[rng.below(n_in as u64) as usize];
                format!("{} %{x}", if rng.chance(500) { "sin" } else { "cos" })
            }
        };
        fresh(&mut text, def, &mut names);
    }
    text += &format!("  output y = %{}\n  output z = %{}\n}}\n", names[names.len() - 1], names[names.len() / 2]);
    let m = robovec_ir::text::parse(&text).unwrap_or_else(|e| panic!("{e:?}\n{text}"));
    (m.functions.into_iter().next().unwrap(), dom)
}

proptest! {
    // 64 cases (PROPTEST_CASES=N for a longer campaign).
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64),
        ..ProptestConfig::default()
    })]

    /// Every op the IR has, both methods: no value computed at a point of the domain leaves
    /// its enclosure.
    #[test]
    fn enclosures_hold_every_value_of_random_functions(seed in any::<u64>(), ops in 1usize..60, cap in 2usize..20) {
        let (f, dom) = random_function(seed, ops);
        for affine in [None, Some(cap)] {
            let x = enclose_with(&f, &dom, affine, || false).unwrap_or_else(|e| panic!("{e:?}"));
            assert_sound(&format!("seed {seed} {affine:?}"), &f, &dom, &x, 24, seed);
        }
    }

    /// The synthetic Robotran-like DAGs (deep sums of products, trig of joint angles), with a
    /// random domain over every input.
    #[test]
    fn enclosures_hold_every_value_of_robotran_like_dags(seed in any::<u64>(), ops in 50usize..800) {
        let f = robovec_testkit::dag_gen::generate(ops, seed);
        let dom = random_domain(&f, seed);
        for affine in [None, Some(8)] {
            let x = enclose_with(&f, &dom, affine, || false).unwrap();
            assert_sound(&format!("dag {seed} {affine:?}"), &f, &dom, &x, 16, seed);
        }
    }
}

/// The affine forms never widen an enclosure and, on sums of correlated terms, tighten it:
/// `(x + y) − (x − y)` is `2y` exactly, where intervals add the widths.
#[test]
fn affine_forms_keep_correlations_that_intervals_lose() {
    let f = robovec_ir::text::parse(
        "func @f { phase atomised input %x input %y %s = add %x, %y %d = sub %x, %y %r = sub %s, %d output r = %r }",
    )
    .unwrap()
    .functions
    .remove(0);
    let mut dom = Domain::default();
    dom.ranges.insert("x".into(), range(-1.0, 1.0));
    dom.ranges.insert("y".into(), range(0.0, 1.0));
    let r = f.lookup("r").unwrap().index();
    let iv = enclose_with(&f, &dom, None, || false).unwrap()[r];
    let af = enclose_with(&f, &dom, Some(16), || false).unwrap()[r];
    // By hand: s ∈ [−1, 2], d ∈ [−2, 1], so intervals give s − d ∈ [−2, 4]; the exact range
    // of 2y is [0, 2].
    assert_eq!(iv, Interval::new(-2.0, 4.0));
    assert!(af.lo >= -1e-12 && af.lo <= 0.0 && af.hi >= 2.0 && af.hi <= 2.0 + 1e-12, "{af}");
}

/// Harmonic forms keep `sin² + cos² = 1` through rotations: a planar chain of `k` joints over
/// whole turns rotating the vector (1, 0), `(x', y') = (c·x − s·y, s·x + c·y)` at each joint,
/// keeps its length 1, so each component's exact range is [−1, 1]; and `c·c + s·s` of one angle
/// is exactly 1. Affine forms alone give `|x| + |y|` per joint (the width doubles every two
/// joints: 2^(k/2) by hand), intervals the same.
#[test]
fn harmonic_forms_keep_rotations_exact() {
    let k = 8;
    let mut text = String::from("func @chain {\n  phase atomised\n");
    for j in 1..=k {
        text += &format!("  input %q{j}\n");
    }
    text += "  %x0 = add 1.0, 0.0\n  %y0 = sub 0.0, 0.0\n";
    for j in 1..=k {
        let (p, n) = (j - 1, j);
        text += &format!(
            "  %c{j} = cos %q{j}\n  %s{j} = sin %q{j}\n  %a{j} = mul %c{j}, %x{p}\n  %b{j} = mul %s{j}, %y{p}\n  \
             %x{n} = sub %a{j}, %b{j}\n  %d{j} = mul %s{j}, %x{p}\n  %e{j} = mul %c{j}, %y{p}\n  %y{n} = add %d{j}, %e{j}\n"
        );
    }
    text += "  %cc = mul %c1, %c1\n  %ss = mul %s1, %s1\n  %one = add %cc, %ss\n";
    text += &format!("  output x = %x{k}\n  output y = %y{k}\n  output one = %one\n}}\n");
    let f = robovec_ir::text::parse(&text).unwrap().functions.remove(0);
    let mut dom = Domain::default();
    for j in 1..=k {
        dom.ranges.insert(format!("q{j}"), range(-3.5, 3.5));
    }
    let x = enclose_with(&f, &dom, Some(64), || false).unwrap();
    let iv = enclose_with(&f, &dom, None, || false).unwrap();
    for name in [format!("x{k}"), format!("y{k}")] {
        let e = x[f.lookup(&name).unwrap().index()];
        assert!(e.lo >= -1.0 - 1e-9 && e.hi <= 1.0 + 1e-9 && e.lo <= -1.0 + 0.05 && e.hi >= 1.0 - 0.05, "{name}: {e}");
        // Intervals: the width doubles every two joints (both components reach 2^(k/2) = 16).
        let i = iv[f.lookup(&name).unwrap().index()];
        assert!(i.hi >= 8.0, "intervals give {i} for {name}");
    }
    let one = x[f.lookup("one").unwrap().index()];
    assert!((one.lo - 1.0).abs() <= 1e-12 && (one.hi - 1.0).abs() <= 1e-12, "cos² + sin² enclosed by {one}");
    assert_sound("rotation chain", &f, &dom, &x, 256, 9);
}

/// A generous domain for a corpus function: joint angles a full turn and a bit, velocities and
/// accelerations ±10, forces ±100, parameters at fixed points (masses and principal inertias
/// positive, as `accuracy` draws them), anything else a point in [−1, 1].
pub(crate) fn generous_domain(f: &Function) -> Domain {
    let mut dom = Domain::default();
    for &v in &f.inputs {
        let n = f.name_of(v);
        let family = n.split('[').next().unwrap_or(n);
        let x = robovec_ir::interp::pseudo_random_input(n, 3);
        let r = match family {
            "q" => range(-3.2, 3.2),
            "qd" | "qdd" => range(-10.0, 10.0),
            "frc" | "trq" | "Qq" => range(-100.0, 100.0),
            "m" | "lrod" => range(1.0 + x.abs(), 1.0 + x.abs()),
            "In" if ["In[1]", "In[5]", "In[9]"].iter().any(|p| n.starts_with(p)) => range(0.1 + x.abs(), 0.1 + x.abs()),
            "tsim" => range(0.0, 10.0),
            _ => range(x, x),
        };
        dom.ranges.insert(n.to_string(), r);
    }
    dom
}

/// Every corpus function (its divisions aside: an enclosure of a divisor holding 0 is a
/// diagnostic, checked to be one), both methods, 8 points each.
#[test]
fn enclosures_hold_every_value_of_the_corpus() {
    let mut enclosed = 0;
    let mut refused = 0;
    for (name, f) in crate::tree_height::corpus_functions() {
        let dom = generous_domain(&f);
        for affine in [None, Some(16)] {
            match enclose_with(&f, &dom, affine, || false) {
                Ok(x) => {
                    assert_sound(&format!("{name} {affine:?}"), &f, &dom, &x, 8, 1);
                    enclosed += 1;
                }
                Err(EncloseError::DivisorHoldsZero { range, .. }) => {
                    assert!(range.contains(0.0), "{name}: a refused divisor's range holds 0: {range}");
                    refused += 1;
                }
                Err(EncloseError::SqrtOfNegative { range, .. }) => {
                    assert!(range.lo < 0.0, "{name}: {range}");
                    refused += 1;
                }
                Err(e) => panic!("{name}: {e:?}"),
            }
        }
    }
    assert!(enclosed >= 130, "{enclosed} enclosed, {refused} refused");
}

/// The three-link arm's `invdyna`: its domain from the URDF (limits, a full turn for the
/// continuous joint, parameters as points) plus the pitch joint's velocity, which its URDF does
/// not limit; every value sound at 64 points.
#[test]
fn the_three_link_arm_is_enclosed_over_its_urdf_domain() {
    let front =
        robovec_front::FrontOptions { functions: Some(vec!["invdyna".into()]), domain: true, ..Default::default() };
    let (loaded, _) = robovec::driver::load_with("examples/three_link_arm/three_link_arm.urdf", &front).unwrap();
    let mut defaults = loaded.domain_defaults.clone();
    defaults.insert("qd[2]".into(), range(-3.0, 3.0));
    let f = robovec_ir::transform::atomise::atomise_function(&loaded.module.functions[0]);
    let names: Vec<&str> = f.inputs.iter().map(|&v| f.name_of(v)).collect();
    let dom = robovec_ir::domain::resolve(&defaults, None, names).unwrap();
    assert!(dom.missing(&f).is_empty(), "{:?}", dom.missing(&f));
    for affine in [None, Some(16)] {
        let x = enclose_with(&f, &dom, affine, || false).unwrap();
        assert_sound("three-link arm", &f, &dom, &x, 64, 5);
    }
}

#[test]
fn urdf_limits_give_the_domain_defaults() {
    let front = robovec_front::FrontOptions {
        functions: Some(vec!["invdyna".into(), "fordyna".into()]),
        domain: true,
        ..Default::default()
    };
    let (loaded, _) = robovec::driver::load_with("tests/inputs/ranges/limits.urdf", &front).unwrap();
    let d = &loaded.domain_defaults;
    let get = |n: &str| d.get(n).map(|r| (r.interval.lo, r.interval.hi));
    // j1 revolute: its limits; j2 continuous: a full turn (rounded outward), its velocity and
    // effort; j3 prismatic: its position, no velocity or effort (placeholders 0).
    assert_eq!(get("q[1]"), Some((-1.5, 2.0)));
    assert_eq!(get("qd[1]"), Some((-3.0, 3.0)));
    assert_eq!(get("Qq[1]"), Some((-40.0, 40.0)));
    let (lo, hi) = get("q[2]").unwrap();
    let pi = std::f64::consts::PI;
    assert_eq!((lo, hi), ((-pi).next_down(), pi.next_up()), "one float beyond π on each side");
    assert!(d["q[2]"].source.contains("sin/cos"), "{}", d["q[2]"].source);
    assert_eq!(get("qd[2]"), Some((-5.0, 5.0)));
    assert_eq!(get("Qq[2]"), Some((-20.0, 20.0)));
    assert_eq!(get("q[3]"), Some((0.0, 0.25)));
    assert_eq!(get("qd[3]"), None, "velocity 0 is a placeholder");
    assert_eq!(get("Qq[3]"), None);
    assert_eq!(get("qdd[1]"), Some((-100.0, 100.0)));
    assert_eq!(get("m[1]"), Some((2.0, 2.0)));
    assert_eq!(get("g[3]"), Some((-9.81, -9.81)));
    assert!(d["q[1]"].source.contains("joint `j1`"), "{}", d["q[1]"].source);
    // A lower limit above the upper one is refused at the attribute.
    let o = opt(&["tests/inputs/ranges/bad_limit.urdf", "-passes=atomise", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("joint limit lower = 2.5 is above upper = 2"), "{}", stderr(&o));
    assert!(stderr(&o).contains("bad_limit.urdf:18:19"), "{}", stderr(&o));
}

#[test]
fn inputs_without_a_range_are_named_with_the_hint() {
    let o = opt(&["tests/inputs/ranges/limits.urdf", "-function=invdyna", "-passes=atomise,range", "-o", "/dev/null"]);
    assert_eq!(o.status.code(), Some(1));
    let e = stderr(&o);
    assert!(e.contains("error: no range for 1 input of @invdyna: qd[3]"), "{e}");
    assert!(e.contains("-ranges=FILE"), "{e}");
    // Given, the run succeeds and the report holds the domain and the enclosures.
    let dir = crate::common::tmp("given");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"qd[3]": [-0.1, 0.1]}"#).unwrap();
    let o = opt(&[
        "tests/inputs/ranges/limits.urdf",
        "-function=invdyna",
        "-passes=atomise,range",
        &format!("-ranges={}", ranges.display()),
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["domain"]["qd[3]"]["range"], serde_json::json!([-0.1, 0.1]));
    assert_eq!(r["domain"]["qd[3]"]["from"], "r.json: qd[3]");
    assert_eq!(r["domain"]["q[1]"]["range"], serde_json::json!([-1.5, 2.0]));
    assert_eq!(r["range"]["method"], "affine");
    assert!(r["range"]["outputs"]["Qq[1]"].as_array().is_some_and(|a| a.len() == 2), "{}", r["range"]);
    assert!(r["stats"].is_object(), "existing keys unchanged");
    // Without a pass that reads it, -ranges still puts the domain in the report.
    let o = opt(&[
        "tests/inputs/ranges/limits.urdf",
        "-function=invdyna",
        "-passes=atomise",
        &format!("-ranges={}", ranges.display()),
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["domain"]["qd[3]"]["range"], serde_json::json!([-0.1, 0.1]));
    assert!(r.get("range").is_none());
}

/// `pipeline` on `tests/inputs/ranges/div.rvir` with `-ranges=tests/inputs/ranges/FILE`: the
/// exit code and stderr.
fn run_on_div(pipeline: &str, file: &str) -> (Option<i32>, String) {
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        &format!("-passes={pipeline}"),
        &format!("-ranges=tests/inputs/ranges/{file}"),
        "-o",
        "/dev/null",
    ]);
    (o.status.code(), stderr(&o))
}

#[test]
fn bad_ranges_files_are_located() {
    let run = |file: &str| run_on_div("range", file);
    let (code, e) = run("reversed.json");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("bad range for `b`: lo = 3 is greater than hi = -1"), "{e}");
    assert!(e.contains("reversed.json:2:2"), "{e}");
    let (code, e) = run("unknown.json");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("`c`: no input is named so"), "{e}");
    assert!(e.contains("unknown.json:2:2"), "{e}");
    let (code, e) = run("syntax.json");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("not a ranges file") && e.contains("syntax.json:2:2"), "{e}");
    let (code, e) = run("missing.json");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("missing.json"), "{e}");
}

#[test]
fn a_divisor_whose_range_holds_zero_is_named_at_its_line() {
    let run = |file: &str| run_on_div("range<method=interval>", file);
    // b ∈ [−1, 1]: s = b + 0.5 ∈ [−0.5, 1.5] holds 0.
    let (code, e) = run("div.json");
    assert_eq!(code, Some(1), "{e}");
    assert!(e.contains("the divisor %s of %q may be 0 over the domain: its range is [-5e-1, 1.5e0]"), "{e}");
    assert!(e.contains("div.rvir:6:"), "{e}");
    // b ∈ [0, 1]: s ∈ [0.5, 1.5], q = a/s ∈ [1/1.5, 2/0.5] = [0.666…, 4].
    let (code, e) = run("div_ok.json");
    assert_eq!(code, Some(0), "{e}");
    assert!(e.contains("range @f: 1 outputs enclosed (interval)"), "{e}");
}

/// The measurements of docs/accuracy.md ("Certified ranges"): per corpus function, the ratio of
/// each output's enclosure width to the width of its values at 256 points of the generous
/// domain, for intervals and affine forms of 16 and 64 symbols, and the time of the enclosure.
/// `cargo test --release --test root -- range::measure_tightness --ignored --nocapture`.
#[test]
#[ignore = "a measurement: prints the table of docs/accuracy.md"]
fn measure_tightness() {
    let narrow = std::env::var("RANGE_NARROW").is_ok();
    let methods: [(&str, Option<usize>); 3] = [("interval", None), ("affine16", Some(16)), ("affine64", Some(64))];
    let mut all: Vec<Vec<f64>> = vec![Vec::new(); methods.len()];
    for (name, f) in crate::tree_height::corpus_functions() {
        let mut dom = generous_domain(&f);
        if narrow {
            // Joint angles ±0.1 rad and velocities ±1 around 0.3, forces ±1.
            for (n, r) in dom.ranges.iter_mut() {
                let fam = n.split('[').next().unwrap_or(n);
                match fam {
                    "q" => r.interval = Interval::new(0.2, 0.4),
                    "qd" | "qdd" | "frc" | "trq" => r.interval = Interval::new(-1.0, 1.0),
                    _ => {}
                }
            }
        }
        // Sampled widths per output.
        let mut rng = SplitMix64::new(9);
        let inputs: Vec<(&str, Interval)> =
            f.inputs.iter().map(|&v| (f.name_of(v), dom.get(f.name_of(v)).unwrap().interval)).collect();
        let mut lo = vec![f64::INFINITY; f.outputs.len()];
        let mut hi = vec![f64::NEG_INFINITY; f.outputs.len()];
        for _ in 0..256 {
            let point: BTreeMap<&str, f64> =
                inputs.iter().map(|&(n, i)| (n, i.lo + rng.unit() * (i.hi - i.lo))).collect();
            for (k, (_, y)) in robovec_ir::interp::eval::<f64>(&f, |n| point[n]).into_iter().enumerate() {
                lo[k] = lo[k].min(y);
                hi[k] = hi[k].max(y);
            }
        }
        let mut line = format!("{name:70} {:>6} ops", f.op_counts().total);
        for (m, (label, affine)) in methods.iter().enumerate() {
            let t = std::time::Instant::now();
            let x = match enclose_with(&f, &dom, *affine, || false) {
                Ok(x) => x,
                Err(_) => {
                    line += &format!(" | {label}: refused");
                    continue;
                }
            };
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let mut r: Vec<f64> = f
                .outputs
                .iter()
                .enumerate()
                .filter_map(|(k, o)| {
                    let e = match o.value {
                        robovec_ir::Operand::Value(v) => x[v.index()],
                        robovec_ir::Operand::Const(c) => Interval::point(c),
                    };
                    let s = hi[k] - lo[k];
                    // Outputs whose sampled width is below 1e-9 of their magnitude are left out
                    // (structural zeros and constants: the ratio is rounding noise).
                    (s > 1e-9 * hi[k].abs().max(lo[k].abs()) && e.width().is_finite()).then(|| e.width() / s)
                })
                .collect();
            r.sort_by(f64::total_cmp);
            all[m].extend(&r);
            let med = r.get(r.len() / 2).copied().unwrap_or(f64::NAN);
            let worst = r.last().copied().unwrap_or(f64::NAN);
            line += &format!(" | {label}: median {med:9.3e} worst {worst:9.3e} {ms:7.1} ms");
        }
        println!("{line}");
    }
    for (m, (label, _)) in methods.iter().enumerate() {
        let r = &mut all[m];
        r.sort_by(f64::total_cmp);
        let q = |p: f64| r.get(((r.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
        println!(
            "ALL {label}: {} outputs, ratio median {:.3e}, p90 {:.3e}, worst {:.3e}",
            r.len(),
            q(0.5),
            q(0.9),
            q(1.0)
        );
    }
}
