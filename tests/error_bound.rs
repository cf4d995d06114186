//! `error-bound` (issue 48 item 3): the certified bound is sound — no error measured at a
//! point of the domain against the certified reference ever exceeds it — on random functions
//! with every op the IR has, on Robotran-like DAGs and on the corpus, in binary64, binary32 and
//! mixed formats; hand-computed bounds of small functions; the pass's report and refusals.

use std::collections::BTreeMap;

use proptest::prelude::*;
use robovec_ir::domain::Domain;
use robovec_ir::format::Format;
use robovec_ir::numerics::{RefValue, Reference, Tape};
use robovec_ir::rng::SplitMix64;
use robovec_ir::{Function, Operand};
use robovec_passes::error_bound::bound::{bound_with_adjoints, OutputAdjoints};
use robovec_passes::error_bound::{bound, BoundError, Formats, TrigImpl};
use robovec_passes::range::{enclose_with, EncloseError};

use crate::common::{opt, stderr};
use crate::range::{generous_domain, random_function, range};

/// The largest error measured over the outputs, as a multiple of their bounds (≤ 1 when
/// sound), with the output.
#[derive(Debug, Default)]
struct Worst {
    ratio: f64,
    output: String,
    /// (output, point) pairs compared.
    compared: u64,
}

/// A lower bound of |computed − exact| from the certified reference `r` (the exact value
/// correctly rounded to binary64: within half an ulp of it).
fn error_at_least(computed: f64, r: &RefValue) -> f64 {
    let ulp = (r.f64.abs().next_up() - r.f64.abs()).max(f64::from_bits(1));
    ((computed - r.f64).abs() - ulp / 2.0).max(0.0)
}

/// A point of `dom` for `f`'s tape inputs: corners first (all lo, all hi), then each input at
/// an end (a third of the time) or uniform inside.
fn point(tape: &Tape, dom: &Domain, k: usize, rng: &mut SplitMix64) -> Vec<f64> {
    let ranges: Vec<robovec_ir::Interval> = tape.inputs.iter().map(|n| dom.get(n).unwrap().interval).collect();
    robovec_passes::error_bound::domain_point(&ranges, k as u64, rng)
}

/// What the bound of `f` over a domain reads in every format: its values' enclosures (as the
/// pass computes them: 16 affine atoms) and its outputs' adjoints over them (which depend on
/// the ops and the enclosures, not on the formats: `bound` is
/// `bound_with_adjoints(OutputAdjoints::new(f, x))`, and `precision` shares them the same way).
struct Enclosed {
    x: Vec<robovec_ir::Interval>,
    adjoints: Option<OutputAdjoints>,
}

impl Enclosed {
    fn of(f: &Function, x: Vec<robovec_ir::Interval>) -> Enclosed {
        let adjoints = OutputAdjoints::new(f, &x);
        Enclosed { x, adjoints }
    }

    /// [`bound`] of `f` in `formats`.
    fn bound(&self, f: &Function, formats: Formats) -> Result<Vec<f64>, BoundError> {
        bound_with_adjoints(f, &self.x, formats, 0, self.adjoints.as_ref(), TrigImpl::Libm, || false)
    }
}

/// [`Enclosed`] over `dom` (panics when `f` cannot be enclosed there).
fn enclosure(what: &str, f: &Function, dom: &Domain) -> Enclosed {
    Enclosed::of(f, enclose_with(f, dom, Some(16), || false).unwrap_or_else(|e| panic!("{what}: {e:?}")))
}

/// Bounds `f` over `dom` (enclosed as `x`) in `formats` and compares with the error
/// at `n` points of the domain (computed as `formats` says, against the certified exact
/// value); panics on any error above its bound.
fn check_sound(what: &str, f: &Function, dom: &Domain, x: &Enclosed, formats: Formats, n: usize, seed: u64) -> Worst {
    let e = x.bound(f, formats).unwrap_or_else(|e| panic!("{what}: {e:?}"));
    check_bounds(what, f, dom, &e, formats, n, seed)
}

/// [`check_sound`] of the bounds `e` (by value index) already computed.
fn check_bounds(what: &str, f: &Function, dom: &Domain, e: &[f64], formats: Formats, n: usize, seed: u64) -> Worst {
    let tape = Tape::new(f);
    let mut reference = Reference::new();
    let mut refs = Vec::new();
    let mut rng = SplitMix64::new(seed);
    let mut worst = Worst::default();
    for k in 0..n {
        let xs = point(&tape, dom, k, &mut rng);
        let computed: Vec<f64> = match formats {
            Formats::F64 => tape.eval::<f64>(&xs),
            Formats::F32 => tape.eval::<f32>(&xs).into_iter().map(f64::from).collect(),
            Formats::Mixed => {
                let at: BTreeMap<&str, f64> = tape.inputs.iter().map(String::as_str).zip(xs.iter().copied()).collect();
                let vals = robovec_ir::format::eval_values(f, |n| at[n]).unwrap_or_else(|e| panic!("{what}: {e:?}"));
                tape.outputs
                    .iter()
                    .map(|(name, _)| {
                        let o = f.outputs.iter().find(|o| &o.name == name).unwrap();
                        match o.value {
                            Operand::Value(v) => vals[v.index()],
                            Operand::Const(c) => c,
                        }
                    })
                    .collect()
            }
        };
        reference.eval(&tape, &xs, &mut refs);
        for (((name, _), &y), r) in tape.outputs.iter().zip(&computed).zip(&refs) {
            let o = f.outputs.iter().find(|o| &o.name == name).unwrap();
            let b = match o.value {
                Operand::Value(v) => e[v.index()],
                Operand::Const(_) => continue,
            };
            if !b.is_finite() || !r.certified || r.f64.is_nan() {
                continue;
            }
            let err = if y.is_finite() { error_at_least(y, r) } else { f64::INFINITY };
            assert!(
                err <= b,
                "{what}: output {name} in {formats:?} at point {k} ({xs:?}) is {y:e}, {err:e} from the exact \
                 {:e}: above its bound {b:e}",
                r.f64
            );
            worst.compared += 1;
            let ratio = if b > 0.0 { err / b } else { 0.0 };
            if ratio > worst.ratio {
                worst.ratio = ratio;
                worst.output = name.clone();
            }
        }
    }
    worst
}

/// A copy of `f` with some values in binary32 and some in a fixed-point format wide enough
/// for its range (16 to 40 bits; the fraction chosen from the value's enclosure and error in
/// binary64, with two guard bits of integer headroom).
pub(crate) fn with_random_formats(f: &Function, dom: &Domain, seed: u64) -> Function {
    random_formats(f, dom, seed, false)
}

/// Every value of `f` whose range is finite in a random fixed-point format (16 to 40 bits, as
/// [`with_random_formats`] chooses them), the others binary64: most ops are then integer ops
/// (`robovec_ir::format::integer_op`), some past its 62 bits (two 40-bit factors).
pub(crate) fn with_fixed_point_formats(f: &Function, dom: &Domain, seed: u64) -> Function {
    random_formats(f, dom, seed, true)
}

/// [`with_random_formats`], or with `fix_only` [`with_fixed_point_formats`].
fn random_formats(f: &Function, dom: &Domain, seed: u64, fix_only: bool) -> Function {
    let x = enclose_with(f, dom, Some(16), || false).unwrap();
    let mut g = f.clone();
    let mut rng = SplitMix64::new(seed);
    let values: Vec<robovec_ir::Value> = f.inputs.iter().chain(&f.body).copied().collect();
    for v in values {
        let m = x[v.index()].mag();
        if !m.is_finite() {
            continue;
        }
        match if fix_only { 1 } else { rng.below(3) } {
            0 => g.set_format(v, Format::Binary32),
            1 => {
                let width = 16 + rng.below(25) as u32;
                // Integer bits: enough for 4·m (the value, its error, headroom), sign included.
                let int_bits = (4.0 * m.max(1e-6)).log2().ceil() as i32 + 1;
                let fraction = (width as i32 - int_bits).clamp(-64, 126);
                if let Some(fmt) = Format::fix(width, fraction) {
                    g.set_format(v, fmt);
                }
            }
            _ => {}
        }
    }
    g
}

/// [`check_sound`] of `g` (in formats) in mode mixed, at 32 points; a fixed-point format the
/// bound cannot prove wide enough is refused (`FixOverflow`), never bounded, and not checked.
fn check_sound_formatted(what: &str, g: &Function, dom: &Domain, seed: u64) {
    let x = enclosure(what, g, dom);
    match x.bound(g, Formats::Mixed) {
        Ok(e) => {
            check_bounds(what, g, dom, &e, Formats::Mixed, 32, seed);
        }
        Err(robovec_passes::error_bound::BoundError::FixOverflow { .. }) => {}
        Err(e) => panic!("{e:?}"),
    }
}

/// The domain a `-report` says its run used (`domain`: each input's `range`).
fn report_domain(r: &serde_json::Value) -> Domain {
    let mut dom = Domain::default();
    for (name, d) in r["domain"].as_object().expect("the report has a domain") {
        dom.ranges.insert(name.clone(), range(d["range"][0].as_f64().unwrap(), d["range"][1].as_f64().unwrap()));
    }
    dom
}

proptest! {
    // 64 cases (PROPTEST_CASES=N for a longer campaign: the issue's 10⁴ random DAGs).
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(64),
        ..ProptestConfig::default()
    })]

    /// Every op the IR has, in binary64 and binary32: no error measured at a point of the
    /// domain exceeds the bound.
    #[test]
    fn bounds_hold_on_random_functions(seed in any::<u64>(), ops in 1usize..60) {
        let (f, dom) = random_function(seed, ops);
        let x = enclosure(&format!("seed {seed}"), &f, &dom);
        for formats in [Formats::F64, Formats::F32] {
            check_sound(&format!("seed {seed}"), &f, &dom, &x, formats, 32, seed);
        }
    }

    /// Mixed formats: random values in binary32 and fixed point, the rest binary64.
    #[test]
    fn bounds_hold_on_random_functions_in_mixed_formats(seed in any::<u64>(), ops in 1usize..40) {
        let (f, dom) = random_function(seed, ops);
        check_sound_formatted(&format!("mixed seed {seed}"), &with_random_formats(&f, &dom, seed), &dom, seed);
    }

    /// Fixed point everywhere it fits: mostly integer ops, whose constants read as 32-bit
    /// words (their distance counted), exact before their one rounding.
    #[test]
    fn bounds_hold_on_random_functions_in_fixed_point(seed in any::<u64>(), ops in 1usize..40) {
        let (f, dom) = random_function(seed, ops);
        check_sound_formatted(&format!("fixed seed {seed}"), &with_fixed_point_formats(&f, &dom, seed), &dom, seed);
    }

    /// The bound holds against the rounding model's own adversarial executions (every op,
    /// binary64, binary32, mixed and fixed-point formats).
    #[test]
    fn bounds_hold_against_the_models_worst_executions(seed in any::<u64>(), ops in 1usize..50) {
        let (f, dom) = random_function(seed, ops);
        let x = enclosure(&format!("seed {seed}"), &f, &dom);
        for formats in [Formats::F64, Formats::F32] {
            check_witness(&format!("seed {seed}"), &f, &dom, &x, formats, 16, seed);
        }
        for (what, g) in [("mixed", with_random_formats(&f, &dom, seed)), ("fixed", with_fixed_point_formats(&f, &dom, seed))] {
            let what = format!("{what} seed {seed}");
            check_witness(&what, &g, &dom, &enclosure(&what, &g, &dom), Formats::Mixed, 16, seed);
        }
    }

    /// The same on the synthetic Robotran-like DAGs.
    #[test]
    fn bounds_hold_against_the_models_worst_executions_on_dags(seed in any::<u64>(), ops in 50usize..400) {
        let f = robovec_testkit::dag_gen::generate(ops, seed);
        let dom = crate::range::random_domain(&f, seed);
        let x = enclosure(&format!("dag {seed}"), &f, &dom);
        for formats in [Formats::F64, Formats::F32] {
            check_witness(&format!("dag {seed}"), &f, &dom, &x, formats, 8, seed);
        }
    }

    /// The adjoints `error-bound` weighs roundings with enclose the true derivatives: random
    /// functions with every op, half their inputs over more than a whole turn (where `sin` and
    /// `cos` ride on harmonics), and the Robotran-like DAGs over whole turns.
    #[test]
    fn adjoint_enclosures_hold(seed in any::<u64>(), ops in 1usize..50, dag_ops in 50usize..400) {
        let (f, mut dom) = random_function(seed, ops);
        let mut rng = SplitMix64::new(seed ^ 0x51);
        for r in dom.ranges.values_mut() {
            if rng.chance(500) {
                let a = rng.unit() * 4.0 - 2.0;
                r.interval = robovec_ir::Interval::new(a, a + 7.0);
            }
        }
        check_adjoints(&format!("seed {seed}"), &f, &dom, 16, seed);
        let g = robovec_testkit::dag_gen::generate(dag_ops, seed);
        let mut dom = crate::range::random_domain(&g, seed);
        for (name, r) in dom.ranges.iter_mut() {
            if name.starts_with('q') {
                r.interval = robovec_ir::Interval::new(-3.5, 3.5);
            }
        }
        check_adjoints(&format!("dag {seed}"), &g, &dom, 8, seed);
    }

    /// The synthetic Robotran-like DAGs (deep sums of products, trig of joint angles).
    #[test]
    fn bounds_hold_on_robotran_like_dags(seed in any::<u64>(), ops in 50usize..600) {
        let f = robovec_testkit::dag_gen::generate(ops, seed);
        let dom = crate::range::random_domain(&f, seed);
        let x = enclosure(&format!("dag {seed}"), &f, &dom);
        for formats in [Formats::F64, Formats::F32] {
            check_sound(&format!("dag {seed}"), &f, &dom, &x, formats, 16, seed);
        }
    }
}

/// [`check_witness`] of `f` (enclosed as `x`) in `formats` at `n` points: no execution the rounding model allows
/// ([`robovec_passes::error_bound::witness`]: every rounding at its largest, aligned with the
/// output's gradient) has an error above the bound. Far stronger than sampling: the witness is
/// what sampling's random-signed roundings would take ~10⁵× more points to approach. Returns the
/// number of (output, point) pairs compared.
fn check_witness(what: &str, f: &Function, dom: &Domain, x: &Enclosed, formats: Formats, n: usize, seed: u64) -> usize {
    use robovec_passes::error_bound::witness::Witness;
    let e = match x.bound(f, formats) {
        Ok(e) => e,
        Err(robovec_passes::error_bound::BoundError::FixOverflow { .. }) => return 0,
        Err(err) => panic!("{what}: {err:?}"),
    };
    let mut w = Witness::new(f, formats);
    let tape = Tape::new(f);
    let mut rng = SplitMix64::new(seed);
    let mut compared = 0;
    for k in 0..n {
        let xs = point(&tape, dom, k, &mut rng);
        let Ok(errors) = w.errors_at(&xs) else { continue };
        for (o, err) in f.outputs.iter().zip(errors) {
            let (Operand::Value(v), Some(err)) = (o.value, err) else { continue };
            let b = e[v.index()];
            assert!(
                err <= b,
                "{what}: output {} in {formats:?} at point {k} ({xs:?}): an execution the rounding model allows is \
                 {err:e} off, above the bound {b:e}",
                o.name
            );
            compared += 1;
        }
    }
    compared
}

/// Every corpus function that encloses over the generous domain, binary32, at 2 points (a
/// corner and a uniform draw): no execution the rounding model allows is above the bound.
#[test]
fn bounds_hold_against_the_models_worst_executions_on_the_corpus() {
    let (mut functions, mut compared) = (0, 0);
    for (name, f) in crate::tree_height::corpus_functions() {
        let dom = generous_domain(&f);
        let Ok(x) = enclose_with(&f, &dom, Some(16), || false) else { continue };
        let n = check_witness(&name, &f, &dom, &Enclosed::of(&f, x), Formats::F32, 3, 7);
        functions += usize::from(n > 0);
        compared += n;
    }
    assert!(functions >= 55 && compared >= 5_000, "{functions} functions, {compared} (output, point) pairs");
}

/// Every corpus function whose values can all be enclosed over the generous domain, binary32
/// and binary64, 24 points each: no error above its bound.
#[test]
fn bounds_hold_on_the_corpus() {
    let (mut bounded, mut compared) = (0, 0);
    for (name, f) in crate::tree_height::corpus_functions() {
        let dom = generous_domain(&f);
        let x = match enclose_with(&f, &dom, Some(16), || false) {
            Ok(x) => Enclosed::of(&f, x),
            Err(EncloseError::DivisorHoldsZero { .. } | EncloseError::SqrtOfNegative { .. }) => continue,
            Err(e) => panic!("{name}: {e:?}"),
        };
        let mut any = false;
        for formats in [Formats::F32, Formats::F64] {
            any |= check_sound(&name, &f, &dom, &x, formats, 24, 3).compared > 0;
        }
        bounded += 1;
        compared += usize::from(any);
    }
    // Functions whose outputs all call user callbacks have no finite bound to compare.
    assert!(bounded >= 60 && compared >= 55, "{bounded} corpus functions bounded, {compared} compared");
}

/// Hand-computed bounds of `y = x · 0.1` over x ∈ [1, 2]. Binary64: the input and the
/// constant are exact and the product rounds once, so the bound is u·max|y| = 2⁻⁵³·0.2 (within
/// a few ulps: outward and upward roundings). Binary32: the input rounds (E_x = 2⁻²⁴·2), the
/// constant rounds to 13421773·2⁻²⁷ (E_c its exact distance to 0.1), the product propagates
/// M_c·E_x + M_x·E_c + E_x·E_c and rounds once. Fixed point: the binary64 product, then half a
/// step; a format too narrow for [0.1, 0.2] is refused.
#[test]
fn hand_computed_bounds() {
    let m =
        robovec_ir::text::parse("func @f {\n  phase atomised\n  input %x\n  %y = mul %x, 0.1\n  output y = %y\n}\n")
            .unwrap();
    let f = &m.functions[0];
    let mut dom = Domain::default();
    dom.ranges.insert("x".into(), range(1.0, 2.0));
    let x = enclose_with(f, &dom, None, || false).unwrap();
    let y = f.lookup("y").unwrap().index();
    // Underflow's absolute terms are binary64 numbers above zero (2⁻¹⁰⁷⁵ itself is not one).
    use robovec_passes::error_bound::Rounding;
    assert!(Rounding::F64.abs >= 2f64.powi(-1074) && Rounding::F32.abs >= 2f64.powi(-150));
    let e64 = bound(f, &x, Formats::F64, || false).unwrap()[y];
    let u64_ = 2f64.powi(-53);
    let expected = u64_ * 0.2;
    assert!(e64 >= expected && e64 <= expected * (1.0 + 1e-12), "{e64:e} vs {expected:e}");
    let u = 2f64.powi(-24);
    let c32 = 13_421_773.0 / 134_217_728.0; // 0.1 rounded to binary32
    let eps = (c32 - 0.1f64).abs(); // exact in binary64: both are within 2⁻⁵⁰ of 0.1
    let propagated = 0.1 * (2.0 * u) + 2.0 * eps + (2.0 * u) * eps; // M_c·E_x + M_x·E_c + E_x·E_c
    let expected = propagated + u * (0.2 + propagated);
    let e32 = bound(f, &x, Formats::F32, || false).unwrap()[y];
    assert!(e32 >= expected && e32 <= expected * (1.0 + 1e-9), "{e32:e} vs {expected:e}");
    // A fixed-point value: y in fix<16,12> — the binary64 product then half a step, 2⁻¹³.
    let mut g = f.clone();
    g.set_format(f.lookup("y").unwrap(), Format::fix(16, 12).unwrap());
    let e = bound(&g, &x, Formats::Mixed, || false).unwrap()[y];
    let expected = u64_ * 0.2 + 2f64.powi(-13);
    assert!(e >= expected && e <= expected * (1.0 + 1e-9), "{e:e} vs {expected:e}");
    // fix<2,3> holds [-0.25, 0.125]: 0.2 overflows.
    g.set_format(f.lookup("y").unwrap(), Format::fix(2, 3).unwrap());
    let err = bound(&g, &x, Formats::Mixed, || false).unwrap_err();
    assert!(err.message("f").contains("%y in fix<2,3> may overflow"), "{}", err.message("f"));
}

/// The pass on a ranges file: the report's `error_bound` has every output with `abs` and
/// `rel`, the maxima and the format; a pass that folds constants in binary64 before it is
/// refused (exit 1) naming it.
#[test]
fn the_pass_reports_and_refuses() {
    let dir = crate::common::tmp("error-bound");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"a": [1, 2], "b": [0.5, 1]}"#).unwrap();
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        &format!("-ranges={}", ranges.display()),
        "-passes=error-bound<format=f32>",
        &format!("-report={}", report.display()),
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("error-bound @"), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let eb = &r["error_bound"];
    assert_eq!(eb["format"], "f32");
    let outs = eb["outputs"].as_object().unwrap();
    assert!(!outs.is_empty());
    let mut max_abs: f64 = 0.0;
    for (name, b) in outs {
        let abs = b["abs"].as_f64().unwrap_or_else(|| panic!("{name}: {b}"));
        assert!(abs > 0.0 && abs < 1e-3, "{name}: {abs}");
        max_abs = max_abs.max(abs);
    }
    assert_eq!(eb["max_abs"].as_f64().unwrap(), max_abs);
    // specialize folds in binary64: the bound against the input would not hold.
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        &format!("-ranges={}", ranges.display()),
        "-passes=specialize,error-bound",
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("`specialize` ran before it"), "{}", stderr(&o));
    // Identities keep it: cse, contract.
    let o = opt(&[
        "tests/inputs/ranges/div.rvir",
        &format!("-ranges={}", ranges.display()),
        "-passes=cse,contract,error-bound",
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// Tightness on the corpus (a measurement, not a check: `cargo test --release --test root
/// error_bound::tightness -- --ignored --nocapture`): per `dirdyna`/`invdyna` function, the
/// binary32 bound over the generous domain divided by the largest error found at `N` points
/// (env `TIGHTNESS_POINTS`, default 2000) of the domain and by `accuracy<mode=hard>` with `N`
/// samples in it, its median and the share of outputs within 100×.
#[test]
#[ignore]
fn tightness() {
    let n: usize = std::env::var("TIGHTNESS_POINTS").ok().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let mut pooled: Vec<f64> = Vec::new();
    for (name, f) in crate::tree_height::corpus_functions() {
        if !(name.contains("dirdyna") || name.contains("invdyna") || name.contains("accelred")) {
            continue;
        }
        let mut dom = generous_domain(&f);
        // TIGHTNESS_HALF_WIDTH=w: joint coordinates in [q₀ − w, q₀ + w] around a pose, rates in ±10·w.
        if let Some(w) = std::env::var("TIGHTNESS_HALF_WIDTH").ok().and_then(|s| s.parse::<f64>().ok()) {
            for (n, r) in dom.ranges.iter_mut() {
                let c = robovec_ir::interp::pseudo_random_input(n, 5);
                if n.starts_with("q[") {
                    *r = range(c - w, c + w);
                } else if n.starts_with("qd[") || n.starts_with("qdd[") {
                    *r = range(-10.0 * w, 10.0 * w);
                }
            }
        }
        let Ok(x) = enclose_with(
            &f,
            &dom,
            Some(std::env::var("TERMS").ok().and_then(|s| s.parse().ok()).unwrap_or(64)),
            || false,
        ) else {
            println!("{name}: not enclosed");
            continue;
        };
        let e = bound(&f, &x, Formats::F32, || false).unwrap();
        let tape = Tape::new(&f);
        let mut reference = Reference::new();
        let mut refs = Vec::new();
        let mut rng = SplitMix64::new(11);
        let mut worst = vec![0f64; tape.outputs.len()];
        let mut hull = vec![(f64::INFINITY, f64::NEG_INFINITY); tape.outputs.len()];
        for k in 0..n {
            let xs = point(&tape, &dom, k, &mut rng);
            let y = tape.eval::<f32>(&xs);
            reference.eval(&tape, &xs, &mut refs);
            for (((w, &y), r), h) in worst.iter_mut().zip(&y).zip(&refs).zip(hull.iter_mut()) {
                *h = (h.0.min(r.f64), h.1.max(r.f64));
                if r.certified {
                    *w = w.max((y as f64 - r.f64).abs());
                }
            }
        }
        // The largest error accuracy<mode=hard> finds in the same domain counts too.
        let hard = robovec_passes::accuracy::max_abs_errors(&f, None, &dom, n as u64, 1, true).unwrap();
        for ((o, _), w) in tape.outputs.iter().zip(worst.iter_mut()) {
            if let Some((_, m32, _)) = hard.iter().find(|h| &h.0 == o) {
                if m32.is_finite() {
                    *w = w.max(*m32);
                }
            }
        }
        let mut ratios: Vec<(f64, &str)> = tape
            .outputs
            .iter()
            .zip(&worst)
            .filter_map(|((o, _), &w)| {
                let out = f.outputs.iter().find(|x| &x.name == o).unwrap();
                let Operand::Value(v) = out.value else { return None };
                let b = e[v.index()];
                (b.is_finite() && w > 0.0).then(|| (b / w, o.as_str()))
            })
            .collect();
        ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
        if ratios.is_empty() {
            continue;
        }
        let mut widths: Vec<f64> = tape
            .outputs
            .iter()
            .zip(&hull)
            .filter_map(|((o, _), h)| {
                let out = f.outputs.iter().find(|x| &x.name == o).unwrap();
                let Operand::Value(v) = out.value else { return None };
                (h.1 > h.0).then(|| x[v.index()].width() / (h.1 - h.0))
            })
            .collect();
        widths.sort_by(f64::total_cmp);
        if !widths.is_empty() {
            println!(
                "  enclosure/sampled width: median {:.1}, p90 {:.1}",
                widths[widths.len() / 2],
                widths[widths.len() * 9 / 10]
            );
        }
        pooled.extend(ratios.iter().map(|r| r.0));
        let within = ratios.iter().filter(|r| r.0 <= 100.0).count();
        println!(
            "{name}: {} outputs; bound/sampled median {:.1}, p90 {:.1}, worst {:.1} ({}); within 100x: {:.0}%",
            ratios.len(),
            ratios[ratios.len() / 2].0,
            ratios[ratios.len() * 9 / 10].0,
            ratios.last().unwrap().0,
            ratios.last().unwrap().1,
            100.0 * within as f64 / ratios.len() as f64
        );
    }
    pooled.sort_by(f64::total_cmp);
    if !pooled.is_empty() {
        let within = pooled.iter().filter(|&&r| r <= 100.0).count();
        println!(
            "all: {} outputs; median {:.1}, p90 {:.1}, worst {:.3e}; within 100x: {:.0}%",
            pooled.len(),
            pooled[pooled.len() / 2],
            pooled[pooled.len() * 9 / 10],
            pooled.last().unwrap(),
            100.0 * within as f64 / pooled.len() as f64
        );
    }
}

/// The verifier's range check of fixed-point formats: `y = x · 0.1` in fix<8,4> holds
/// [−8, 7.9375]; over x ∈ [0, 10] y fits, over x ∈ [0, 100] it may reach 10: the run stops
/// with exit 1 naming the value, its range and the format's, before any pass output.
#[test]
fn the_verifier_checks_fixed_point_ranges_over_the_domain() {
    let dir = crate::common::tmp("fix-range");
    let run = |hi: f64| {
        let ranges = dir.join(format!("r{hi}.json"));
        std::fs::write(&ranges, format!(r#"{{"x": [0, {hi}]}}"#)).unwrap();
        opt(&[
            "tests/inputs/formats/fix_range.rvir",
            &format!("-ranges={}", ranges.display()),
            "-passes=dce",
            "-o",
            "/dev/null",
        ])
    };
    let o = run(10.0);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = run(100.0);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("%y in fix<8,4> may overflow") && e.contains("[-8e0, 7.9375e0]"), "{e}");
}

/// The issue's soundness check against `accuracy<mode=hard>` drawn in the same domain
/// ([`robovec_passes::accuracy::max_abs_errors`]: singular poses, ends, hill climbing, every
/// point inside the domain): on every corpus function that encloses over the generous domain,
/// no output's largest measured absolute error, binary32 or binary64, exceeds its bound.
#[test]
fn bounds_hold_against_accuracy_hard_on_the_corpus() {
    let samples: u64 = std::env::var("HARD_SAMPLES").ok().and_then(|s| s.parse().ok()).unwrap_or(48);
    let mut compared = 0;
    for (name, f) in crate::tree_height::corpus_functions() {
        let dom = generous_domain(&f);
        let Ok(x) = enclose_with(&f, &dom, Some(64), || false) else { continue };
        let e32 = bound(&f, &x, Formats::F32, || false).unwrap();
        let e64 = bound(&f, &x, Formats::F64, || false).unwrap();
        let measured = robovec_passes::accuracy::max_abs_errors(&f, None, &dom, samples, 1, true)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        for ((out, m32, m64), o) in measured.iter().zip(&f.outputs) {
            assert_eq!(out, &o.name);
            let Operand::Value(v) = o.value else { continue };
            for (format, m, b) in [("f32", m32, e32[v.index()]), ("f64", m64, e64[v.index()])] {
                if b.is_finite() && m.is_finite() {
                    assert!(
                        m <= &b,
                        "{name}: output {out} in {format}: accuracy<mode=hard> measured {m:e}, above the bound {b:e}"
                    );
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 5000, "{compared} (output, format) pairs compared");
}

/// `-pareto` with an input domain adds each row's certified bounds (binary32 above binary64,
/// both positive), none for a pipeline that changes the exact function (`specialize`), and
/// none at all without a domain.
#[test]
fn pareto_rows_carry_the_certified_bound_over_the_domain() {
    let dir = crate::common::tmp("pareto-certified");
    let (ranges, report) = (dir.join("r.json"), dir.join("report.json"));
    std::fs::write(&ranges, r#"{"qd[2]": [-3, 3]}"#).unwrap();
    let run = |with_ranges: bool| {
        let mut args = vec![
            "examples/three_link_arm/three_link_arm.urdf".to_string(),
            "-function=invdyna".into(),
            "-pareto=atomise;atomise,contract;atomise,specialize".into(),
            "-pareto-samples=50".into(),
            "-passes=atomise".into(),
            format!("-report={}", report.display()),
            "-o".into(),
            "/dev/null".into(),
        ];
        if with_ranges {
            args.push(format!("-ranges={}", ranges.display()));
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = opt(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
        (r["pareto"].as_array().unwrap().clone(), stderr(&o))
    };
    let (rows, err) = run(true);
    assert!(err.contains("certified over the domain"), "{err}");
    for row in &rows[..2] {
        let c = &row["certified"];
        let (a, b) = (c["f32_max_rel"].as_f64().unwrap(), c["f64_max_rel"].as_f64().unwrap());
        assert!(a > b && b > 0.0 && a < 1e-3, "{row}");
    }
    assert!(rows[2].get("certified").is_none(), "specialize folds in binary64: {}", rows[2]);
    let (rows, err) = run(false);
    assert!(!err.contains("certified over the domain"), "{err}");
    assert!(rows.iter().all(|r| r.get("certified").is_none()));
}

/// "One more bit" (`bound_with_more_bits`, precision's report): for fixed-point formats it is
/// the bound of the same function with every `fix<w,f>` widened to `fix<w+1,f+1>`, computed
/// here by the ordinary bound on that function. (It is not always below the bound as it is:
/// that one rounds a binary32 constant by its exact distance, one more bit by half an ulp.)
#[test]
fn one_more_bit_is_the_bound_of_the_wider_formats() {
    use robovec_passes::error_bound::bound::bound_with_more_bits;
    let mut compared = 0;
    for seed in 0..60u64 {
        let (f, dom) = random_function(seed * 31 + 5, 6 + (seed as usize % 30));
        let mixed = crate::error_bound::with_random_formats(&f, &dom, seed);
        let x = enclose_with(&f, &dom, Some(16), || false).unwrap();
        // Fixed point only: binary32 values back to binary64, then every fix<w,f> one bit wider.
        let mut fixed = mixed.clone();
        let mut wider = mixed.clone();
        for &v in f.inputs.iter().chain(&f.body) {
            match mixed.format(v) {
                Format::Binary32 => {
                    fixed.set_format(v, Format::Binary64);
                    wider.set_format(v, Format::Binary64);
                }
                Format::Fix { width, fraction } if width < 53 && fraction < 126 => {
                    wider.set_format(v, Format::fix(width + 1, fraction + 1).unwrap());
                }
                Format::Fix { .. } => {
                    fixed.set_format(v, Format::Binary64);
                    wider.set_format(v, Format::Binary64);
                }
                Format::Binary64 => {}
            }
        }
        // Point inputs round by their exact distance in the ordinary bound: none here.
        if f.inputs.iter().any(|&v| x[v.index()].lo == x[v.index()].hi) {
            continue;
        }
        let (Ok(more), Ok(wide)) = (
            bound_with_more_bits(&fixed, &x, Formats::Mixed, 1, || false),
            bound(&wider, &x, Formats::Mixed, || false),
        ) else {
            continue;
        };
        for o in &f.outputs {
            if let Operand::Value(v) = o.value {
                assert_eq!(more[v.index()].to_bits(), wide[v.index()].to_bits(), "seed {seed} {}", o.name);
                compared += 1;
            }
        }
    }
    assert!(compared >= 40, "only {compared} outputs compared");
}

/// `∂out/∂z` at a point for every value `z` (by value index), by reverse-mode differentiation
/// in binary64 from the values `vals`, and the same sweep on magnitudes (`Σ` over paths of
/// `|∂|` products: what the binary64 rounding of the first can be off by, times a few ulps).
fn jacobian_row(f: &Function, vals: &[f64], out: robovec_ir::Value) -> (Vec<f64>, Vec<f64>) {
    let n = f.values.len();
    let (mut adj, mut mag) = (vec![0.0; n], vec![0.0; n]);
    adj[out.index()] = 1.0;
    mag[out.index()] = 1.0;
    for &z in f.body.iter().rev() {
        let (a, m) = (adj[z.index()], mag[z.index()]);
        if m == 0.0 {
            continue;
        }
        robovec_passes::error_bound::witness::local_partials(&f.value(z).def, vals, |v, d| {
            adj[v.index()] += a * d;
            mag[v.index()] += m * d.abs();
        });
    }
    (adj, mag)
}

/// The adjoints' enclosures hold: at `n` points of `dom` (corners, ends, uniform), every
/// `|∂out/∂z|` is within `max|∂out/∂z|` of [`robovec_passes::error_bound::bound::adjoint_sups`]
/// (up to binary64's own rounding of the point's derivative). Returns the number of
/// (output, value, point) comparisons with a nonzero derivative.
fn check_adjoints(what: &str, f: &Function, dom: &Domain, n: usize, seed: u64) -> usize {
    use robovec_passes::error_bound::bound::adjoint_sups;
    let x = match enclose_with(f, dom, Some(16), || false) {
        Ok(x) => x,
        Err(EncloseError::DivisorHoldsZero { .. } | EncloseError::SqrtOfNegative { .. }) => return 0,
        Err(e) => panic!("{what}: {e:?}"),
    };
    let tape = Tape::new(f);
    let mut rng = SplitMix64::new(seed);
    let mut compared = 0;
    let outs: Vec<robovec_ir::Value> = f
        .outputs
        .iter()
        .filter_map(|o| match o.value {
            Operand::Value(v) => Some(v),
            Operand::Const(_) => None,
        })
        .collect();
    let sups: Vec<Option<Vec<f64>>> = outs.iter().map(|&o| adjoint_sups(f, &x, o)).collect();
    for k in 0..n {
        let xs = point(&tape, dom, k, &mut rng);
        let at: BTreeMap<&str, f64> = tape.inputs.iter().map(String::as_str).zip(xs.iter().copied()).collect();
        let vals = robovec_ir::interp::eval_values::<f64>(f, |name| at[name]);
        if vals.iter().any(|v| !v.is_finite()) {
            continue;
        }
        for (&o, sup) in outs.iter().zip(&sups) {
            let Some(sup) = sup else { continue };
            let (j, m) = jacobian_row(f, &vals, o);
            for (i, (&jz, &mz)) in j.iter().zip(&m).enumerate() {
                let v = robovec_ir::Value::with_number(i as u32);
                assert!(
                    jz.abs() <= sup[i] + 1e-10 * mz + 1e-300,
                    "{what}: |∂{}/∂{}| = {:e} at point {k} exceeds its enclosure's {:e}",
                    f.name_of(o),
                    f.name_of(v),
                    jz.abs(),
                    sup[i]
                );
                compared += usize::from(jz != 0.0);
            }
        }
    }
    compared
}

/// The adjoints of the UR5's RNEA (`robovec-gen`'s `invdyna`, every joint over its URDF limits,
/// a whole turn or two) enclose its derivatives at 200 points, and the adjoint bound is what
/// certifies its 32-bit fixed point (issue 48's "Beyond RoboPrec" goal, 10⁻⁴ N·m): the forward
/// bound alone is above it.
#[test]
fn adjoints_of_the_ur5_rnea_and_its_fixed_point_bound() {
    let dir = crate::common::tmp("adjoint-ur5");
    let Some(urdf) = crate::common::robot_urdf("ur_description/urdf/ur5_robot.urdf") else { return };
    let budget = dir.join("b.json");
    std::fs::write(&budget, r#"{"Qq[*]": {"abs": 1e-4}}"#).unwrap();
    let (r, m) = crate::common::opt_to_ir(
        &dir,
        &[
            urdf.to_str().unwrap(),
            "-function=invdyna",
            "--fold-params",
            &format!("-passes=default<ops>,precision<budget={};target=mcu>,error-bound", budget.display()),
        ],
    );
    let g = &m.functions[0];
    assert!(
        g.inputs.iter().chain(&g.body).all(|&v| matches!(g.format(v), Format::Fix { width: 32, .. })),
        "every value in 32-bit fixed point: {}",
        r["precision"]
    );
    let max_abs = r["error_bound"]["max_abs"].as_f64().unwrap();
    assert!(max_abs <= 1e-4, "certified {max_abs:e} N·m");
    // The domain the report used, for the adjoints' check and the forward bound alone.
    let dom = report_domain(&r);
    let mut plain = g.clone();
    plain.clear_formats();
    assert!(check_adjoints("UR5", &plain, &dom, 200, 5) > 10_000);
    let x = enclose_with(g, &dom, Some(64), || false).unwrap();
    let adjoint = bound(g, &x, Formats::Mixed, || false).unwrap();
    let forward = robovec_passes::error_bound::bound::forward_bound(g, &x, Formats::Mixed).unwrap();
    let worst = |e: &[f64]| {
        g.outputs
            .iter()
            .map(|o| match o.value {
                Operand::Value(v) => e[v.index()],
                _ => 0.0,
            })
            .fold(0.0, f64::max)
    };
    assert!((worst(&adjoint) - max_abs).abs() <= 1e-12 * max_abs);
    assert!(worst(&forward) > 1e-4, "the forward bound alone, {:e}, already meets the goal", worst(&forward));
}

/// A point of `dom` with every coordinate a binary32 number inside its range (as `accuracy`
/// draws them), from [`point`].
fn point_f32(tape: &Tape, dom: &Domain, k: usize, rng: &mut SplitMix64) -> Vec<f64> {
    let xs = point(tape, dom, k, rng);
    tape.inputs
        .iter()
        .zip(xs)
        .map(|(n, x)| {
            let i = dom.get(n).unwrap().interval;
            let mut y = x as f32;
            if (y as f64) > i.hi {
                y = y.next_down();
            }
            if (y as f64) < i.lo {
                y = y.next_up();
            }
            if (y as f64) < i.lo || (y as f64) > i.hi {
                x
            } else {
                y as f64
            }
        })
        .collect()
}

/// Per output (in `f.outputs` order), the largest witness error ([`Witness`]) over `n` points
/// of `dom` in `mode`.
fn witness_errors(f: &Function, dom: &Domain, mode: Formats, n: usize, seed: u64) -> Vec<f64> {
    use robovec_passes::error_bound::witness::Witness;
    let mut w = Witness::new(f, mode);
    let mut plain = f.clone();
    plain.clear_formats();
    let tape = Tape::new(&plain);
    assert_eq!(tape.inputs, w.inputs());
    let mut rng = SplitMix64::new(seed);
    let mut worst = vec![0f64; f.outputs.len()];
    for k in 0..n {
        let xs = point_f32(&tape, dom, k, &mut rng);
        let Ok(e) = w.errors_at(&xs) else { continue };
        for (m, e) in worst.iter_mut().zip(e) {
            *m = m.max(e.unwrap_or(0.0));
        }
    }
    worst
}

/// The first-order size of the model's worst execution at `xs`: `Σ_z |∂o/∂z|·½ ulp₃₂(z)`.
fn first_order_witness(f: &Function, names: &[String], xs: &[f64], o: robovec_ir::Value) -> f64 {
    let vals = robovec_ir::interp::eval_values::<f64>(f, |n| xs[names.iter().position(|t| t == n).unwrap()]);
    let g = robovec_passes::error_bound::witness::gradient(f, &vals, o);
    f.body
        .iter()
        .map(|z| {
            let v = vals[z.index()];
            if v == 0.0 || !v.is_finite() {
                0.0
            } else {
                g[z.index()].abs() * 2f64.powi(v.abs().log2().floor() as i32 - 24)
            }
        })
        .sum()
}

/// Per output (in `f.outputs` order), the witness error at a point found by coordinate ascent
/// on [`first_order_witness`]: the best of 50 uniform points, then 3 rounds over the inputs
/// trying each at its ends, middle and quarters.
fn climbed_witnesses(f: &Function, dom: &Domain) -> Vec<f64> {
    use robovec_passes::error_bound::witness::Witness;
    let mut w = Witness::new(f, Formats::F32);
    let names: Vec<String> = w.inputs().to_vec();
    let ranges: Vec<(f64, f64)> = names
        .iter()
        .map(|n| {
            let i = dom.get(n).unwrap().interval;
            (i.lo, i.hi)
        })
        .collect();
    let mut rng = SplitMix64::new(1);
    let mut out = vec![0.0; f.outputs.len()];
    for (k, o) in f.outputs.iter().enumerate() {
        let Operand::Value(v) = o.value else { continue };
        let (mut best, mut top) = (Vec::new(), -1.0);
        for _ in 0..50 {
            let xs: Vec<f64> = ranges.iter().map(|&(lo, hi)| lo + rng.unit() * (hi - lo)).collect();
            let p = first_order_witness(f, &names, &xs, v);
            if p > top {
                (best, top) = (xs, p);
            }
        }
        for _ in 0..3 {
            for (i, &(lo, hi)) in ranges.iter().enumerate() {
                for t in [0.0, 1.0, 0.5, 0.25, 0.75] {
                    let old = best[i];
                    best[i] = lo + t * (hi - lo);
                    let p = first_order_witness(f, &names, &best, v);
                    if p > top {
                        top = p;
                    } else {
                        best[i] = old;
                    }
                }
            }
        }
        // Binary32 inputs inside their ranges, as accuracy draws them.
        let xs: Vec<f64> = best.iter().zip(&ranges).map(|(&x, &(lo, hi))| (x as f32 as f64).clamp(lo, hi)).collect();
        out[k] = w.errors_at(&xs).ok().and_then(|e| e[k]).unwrap_or(0.0);
    }
    out
}

/// How much of the tightness gap no certification can close (a measurement: `cargo test
/// --release --test root error_bound::witness_tightness -- --ignored --nocapture`; env
/// `WITNESS_POINTS`, default 200, `HARD_SAMPLES`, default 10⁴): for UR5, Panda and Talos RNEA
/// over their URDF limits (binary32), per output the bound `B`, the largest error
/// `accuracy<mode=hard>` finds `S`, and the witness `W` (the error of an execution the
/// rounding model allows: a lower bound of every sound bound). Prints the medians of `B/S`,
/// `W/S`, `B/W` and the shares of outputs with `W/S > 100` (beyond any certified bound's
/// reach) and `B/W ≤ 100`. Asserts `W ≤ B` (soundness against the model's own worst case).
#[test]
#[ignore]
fn witness_tightness() {
    let n: usize = std::env::var("WITNESS_POINTS").ok().and_then(|s| s.parse().ok()).unwrap_or(200);
    let samples: u64 = std::env::var("HARD_SAMPLES").ok().and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let dir = crate::common::tmp("witness-tightness");
    let mut cases: Vec<(String, Function, Domain)> = Vec::new();
    for (name, rel) in [
        ("UR5", "ur_description/urdf/ur5_robot.urdf"),
        ("Panda", "panda_description/urdf/panda.urdf"),
        ("Talos", "talos_data/robots/talos_reduced.urdf"),
    ] {
        let urdf = crate::common::robot_urdf(rel).unwrap_or_else(|| panic!("{rel}"));
        let (r, m) = crate::common::opt_to_ir(
            &dir,
            &[
                urdf.to_str().unwrap(),
                "-function=invdyna",
                "--fold-params",
                "-passes=default<ops>,error-bound<format=f32>",
            ],
        );
        cases.push((name.to_string(), m.functions[0].clone(), report_domain(&r)));
    }
    if let Ok(only) = std::env::var("WITNESS_CORPUS") {
        for (name, f) in crate::tree_height::corpus_functions() {
            if name.contains(&only) {
                let dom = generous_domain(&f);
                cases.push((name, f, dom));
            }
        }
    }
    for (name, f, dom) in cases {
        let x = enclose_with(&f, &dom, Some(64), || false).unwrap();
        let e = bound(&f, &x, Formats::F32, || false).unwrap();
        let t = std::time::Instant::now();
        let mut w = witness_errors(&f, &dom, Formats::F32, n, 3);
        for (k, c) in climbed_witnesses(&f, &dom).into_iter().enumerate() {
            w[k] = w[k].max(c);
        }
        let secs = t.elapsed().as_secs_f64();
        let hard = robovec_passes::accuracy::max_abs_errors(&f, None, &dom, samples, 1, true).unwrap();
        let (mut bs, mut ws, mut bw) = (Vec::new(), Vec::new(), Vec::new());
        for ((o, w), (_, s, _)) in f.outputs.iter().zip(&w).zip(&hard) {
            let Operand::Value(v) = o.value else { continue };
            let b = e[v.index()];
            assert!(*w <= b, "{name}: {}: witness {w:e} above the bound {b:e}", o.name);
            if b.is_finite() && *s > 0.0 && *w > 0.0 && s.is_finite() {
                bs.push(b / s);
                ws.push(w / s);
                bw.push(b / w);
            }
        }
        let med = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        };
        let share = |v: &[f64], p: &dyn Fn(f64) -> bool| {
            100.0 * v.iter().filter(|&&r| p(r)).count() as f64 / v.len().max(1) as f64
        };
        let (over, within_b_s, within_b_w) =
            (share(&ws, &|r| r > 100.0), share(&bs, &|r| r <= 100.0), share(&bw, &|r| r <= 100.0));
        println!(
            "{name}: {} outputs; B/S median {:.1}, W/S median {:.1} (max {:.1}), B/W median {:.1} (max {:.1}); \
             W/S > 100: {over:.0}%; B/S <= 100: {within_b_s:.0}%; B/W <= 100: {within_b_w:.0}%; witness {secs:.2} s",
            bs.len(),
            med(&mut bs),
            med(&mut ws),
            ws.last().copied().unwrap_or(f64::NAN),
            med(&mut bw),
            bw.last().copied().unwrap_or(f64::NAN),
        );
    }
}

/// The witness of `y = x · 0.1` in binary32 at x = 1.5, by hand. The exact function's constant
/// is the binary64 number `0.1` parses to (`c64`); the computation reads it as the binary32
/// c = 13421773·2⁻²⁷. The product 1.5·c is not a binary32 number, so it rounds, and the worst
/// execution adds just under half an ulp (2⁻²⁷ in [0.125, 0.25)) on the side of the constant's
/// error: W = 1.5·(c − c64) + (1 − 2⁻²⁰)·2⁻²⁷, less half an ulp of the reference in binary64
/// (2⁻⁵⁶), within the reference's own rounding (2⁻⁵⁶). At x = 2 the product is exact (a power
/// of 2 times a binary32 number): only the constant's error, 2·(c − c64) − 2⁻⁵⁶ (0.2 is in [0.125, 0.25) too).
#[test]
fn the_witness_of_a_product_by_hand() {
    use robovec_passes::error_bound::witness::Witness;
    let m =
        robovec_ir::text::parse("func @f {\n  phase atomised\n  input %x\n  %y = mul %x, 0.1\n  output y = %y\n}\n")
            .unwrap();
    let f = &m.functions[0];
    let mut w = Witness::new(f, Formats::F32);
    let (c, c64) = (13_421_773.0 / 134_217_728.0, 0.1f64);
    let got = w.errors_at(&[1.5]).unwrap()[0].unwrap();
    // c − c64 is exact in binary64 (both within 2⁻²⁷ of each other, 53-bit aligned).
    let expected = 1.5 * (c - c64) + (1.0 - 2f64.powi(-20)) * 2f64.powi(-27) - 2f64.powi(-56);
    assert!((got - expected).abs() <= 2f64.powi(-55), "{got:e} vs {expected:e}");
    let got = w.errors_at(&[2.0]).unwrap()[0].unwrap();
    let expected = 2.0 * (c - c64) - 2f64.powi(-56);
    assert!((got - expected).abs() <= 1e-24, "{got:e} vs {expected:e}");
    // Binary64: 1.5·c64 rounds; the worst execution is half an ulp of 0.15 away, less the
    // reference's own half ulp: at most 2⁻⁵⁶ (+ the reference's rounding, 2⁻⁵⁶).
    let mut w64 = Witness::new(f, Formats::F64);
    let got = w64.errors_at(&[1.5]).unwrap()[0].unwrap();
    assert!(got <= 2f64.powi(-55), "{got:e}");
}

/// `error-bound<witness=N>` on the UR5's RNEA over its URDF limits in binary32: every output
/// has a witness, positive and below its bound (the model's worst execution cannot beat a
/// sound bound), and the log prints the pessimism; without `witness` the key is absent.
#[test]
fn the_pass_reports_witnesses_below_the_bound() {
    let dir = crate::common::tmp("witness-pass");
    let urdf = crate::common::robot_urdf("ur_description/urdf/ur5_robot.urdf").expect("UR5 from example-robot-data");
    let (r, _) = crate::common::opt_to_ir(
        &dir,
        &[
            urdf.to_str().unwrap(),
            "-function=invdyna",
            "--fold-params",
            "-passes=default<ops>,error-bound<format=f32;witness=8>",
        ],
    );
    let outs = r["error_bound"]["outputs"].as_object().unwrap();
    assert_eq!(outs.len(), 6);
    for (name, b) in outs {
        let (abs, w) = (b["abs"].as_f64().unwrap(), b["witness"].as_f64().unwrap_or_else(|| panic!("{name}: {b}")));
        assert!(w > 0.0 && w <= abs, "{name}: witness {w:e}, bound {abs:e}");
        // The bound is not absurdly far from what the model allows (UR5: ~15× at the median).
        assert!(abs / w < 1e3, "{name}: bound / witness {}", abs / w);
    }
    let (r, _) = crate::common::opt_to_ir(
        &dir,
        &[urdf.to_str().unwrap(), "-function=invdyna", "--fold-params", "-passes=default<ops>,error-bound<format=f32>"],
    );
    assert!(r["error_bound"]["outputs"].as_object().unwrap().values().all(|b| b.get("witness").is_none()));
}

/// The atom cap scales with the function's size (`harmonic::adjoint_atoms`): an arm's RNEA
/// gets 1,024 atoms where a humanoid's `dirdyna` keeps 48. On the UR5 (6 outputs × ~400 ops)
/// the pass's bound with them is at least a quarter tighter than with 48 atoms on the largest
/// output (measured 8.0·10⁻³ → 4.7·10⁻³ N·m), and both stay above the rounding model's worst
/// execution at 16 points of the domain (so the tighter bound is still sound where it is
/// checked hardest).
#[test]
fn the_atom_cap_scales_with_the_function() {
    use robovec_passes::error_bound::bound::{bound_with_adjoints, OutputAdjoints, TrigImpl};
    use robovec_passes::error_bound::witness::Witness;
    use robovec_passes::range::harmonic::{adjoint_atoms, range_atoms, MAX_ATOMS, MIN_ATOMS};
    // The rule at the sizes the docs quote.
    assert_eq!((adjoint_atoms(6, 399), range_atoms(399)), (MAX_ATOMS, MAX_ATOMS));
    assert_eq!((adjoint_atoms(1306, 33_233), range_atoms(33_233)), (MIN_ATOMS, MIN_ATOMS));
    assert!(adjoint_atoms(32, 3969) < range_atoms(3969) && range_atoms(3969) < MAX_ATOMS);

    let dir = crate::common::tmp("atom-cap");
    let urdf = crate::common::robot_urdf("ur_description/urdf/ur5_robot.urdf").expect("UR5 from example-robot-data");
    let (r, m) = crate::common::opt_to_ir(
        &dir,
        &[urdf.to_str().unwrap(), "-function=invdyna", "--fold-params", "-passes=default<ops>,error-bound<format=f32>"],
    );
    let f = &m.functions[0];
    let dom = report_domain(&r);
    let x = enclose_with(f, &dom, Some(64), || false).unwrap();
    let outs: Vec<_> = f
        .outputs
        .iter()
        .map(|o| match o.value {
            Operand::Value(v) => v,
            _ => panic!("{} is a constant", o.name),
        })
        .collect();
    let at = |atoms: usize| {
        let adj = OutputAdjoints::with_atoms(f, &x, atoms);
        let e = bound_with_adjoints(f, &x, Formats::F32, 0, Some(&adj), TrigImpl::Libm, || false).unwrap();
        outs.iter().map(|v| e[v.index()]).collect::<Vec<f64>>()
    };
    let (few, many) = (at(MIN_ATOMS), at(adjoint_atoms(f.outputs.len(), f.body.len())));
    // The pass's own figure is the scaled cap's.
    let reported = r["error_bound"]["max_abs"].as_f64().unwrap();
    let max = |e: &[f64]| e.iter().copied().fold(0.0, f64::max);
    assert!((reported - max(&many)).abs() <= 1e-12 * reported, "{reported:e} vs {:e}", max(&many));
    assert!(max(&many) <= 0.75 * max(&few), "{:e} against {:e} at 48 atoms", max(&many), max(&few));
    let mut w = Witness::new(f, Formats::F32);
    let ranges: Vec<robovec_ir::Interval> = w.inputs().iter().map(|n| dom.get(n).unwrap().interval).collect();
    let mut rng = SplitMix64::new(7);
    for k in 0..16 {
        let p = robovec_passes::error_bound::domain_point(&ranges, k, &mut rng);
        for (o, e) in w.errors_at(&p).unwrap().into_iter().enumerate() {
            let e = e.unwrap();
            assert!(
                e <= many[o] && e <= few[o],
                "{}: witness {e:e} above {:e} / {:e}",
                f.outputs[o].name,
                many[o],
                few[o]
            );
        }
    }
}

/// `trig=inline`: robovec's binary32 `sin`/`cos` (`codegen<c;trig=inline>`) is allowed 1 ulp
/// where the C library is allowed 4 (`bound::INLINE32_ULPS`, checked on every binary32 argument
/// by `scripts/trig_ulps.sh`). For `y = sin x` in binary32 with `x` in [0.5, 1] the two bounds
/// differ by the rounding term alone: 3 ulps more for the library, `3·2⁻²³·(sin 1 + P)` with `P`
/// the propagated error (~6·10⁻⁸, negligible here); beyond `|x| = 2¹¹` the kernel hands over to
/// the library and the bounds are equal.
#[test]
fn the_inline_trig_allowance_by_hand() {
    use robovec_passes::error_bound::bound::{bound_with_adjoints, TrigImpl};
    let m = robovec_ir::text::parse("func @f {\n  phase atomised\n  input %x\n  %y = sin %x\n  output y = %y\n}\n")
        .unwrap();
    let f = &m.functions[0];
    let y = f.outputs[0].value;
    let Operand::Value(y) = y else { panic!() };
    let at = |lo: f64, hi: f64, trig| {
        let mut dom = Domain::default();
        dom.ranges.insert("x".into(), range(lo, hi));
        let x = enclose_with(f, &dom, Some(16), || false).unwrap();
        bound_with_adjoints(f, &x, Formats::F32, 0, None, trig, || false).unwrap()[y.index()]
    };
    let (libm, inline) = (at(0.5, 1.0, TrigImpl::Libm), at(0.5, 1.0, TrigImpl::Inline));
    let expected = 3.0 * 2f64.powi(-23) * 1f64.sin();
    assert!(inline < libm, "{inline:e} vs {libm:e}");
    assert!(
        ((libm - inline) - expected).abs() <= 1e-6 * expected,
        "difference {:e}, expected {expected:e}",
        libm - inline
    );
    let (libm, inline) = (at(3000.0, 3001.0, TrigImpl::Libm), at(3000.0, 3001.0, TrigImpl::Inline));
    assert_eq!(libm, inline);
}

/// `trig=inline` through the command line: the report's `error_bound` says `"trig": "inline"`
/// (and has no `trig` key by default), the log names it, the UR5's binary32 bound falls (its
/// sines and cosines are allowed 1 ulp, not 4); `precision<trig=inline>` with a target other
/// than `c` is bad usage (exit 2) naming both.
#[test]
fn trig_inline_on_the_command_line() {
    let dir = crate::common::tmp("trig-inline");
    let urdf = crate::common::robot_urdf("ur_description/urdf/ur5_robot.urdf").expect("UR5 from example-robot-data");
    let run = |trig: &str| {
        let (r, _) = crate::common::opt_to_ir(
            &dir,
            &[
                urdf.to_str().unwrap(),
                "-function=invdyna",
                "--fold-params",
                &format!("-passes=default<ops>,error-bound<format=f32{trig}>"),
            ],
        );
        r["error_bound"].clone()
    };
    let (libm, inline) = (run(""), run(";trig=inline"));
    assert!(libm.get("trig").is_none(), "{libm}");
    assert_eq!(inline["trig"], "inline");
    let (a, b) = (libm["max_abs"].as_f64().unwrap(), inline["max_abs"].as_f64().unwrap());
    assert!(b < a, "trig=inline {b:e} against libm {a:e}");
    let o = opt(&[
        urdf.to_str().unwrap(),
        "-function=invdyna",
        "--fold-params",
        "-passes=default<ops>,precision<target=mcu;trig=inline>",
        "-o",
        "/dev/null",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("trig=inline") && stderr(&o).contains("target=mcu"), "{}", stderr(&o));
}
