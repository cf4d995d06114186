//! `-time-limit` in every pass (issue 28 item 3): what the manager does with a pass not
//! started at the limit, and where each pass stops inside with [`PassContext::tick_budget`]
//! (deterministic: the k-th tick stops whatever the machine's speed).

use robovec_ir::interp::{eval, pseudo_random_input};
use robovec_ir::text::parse;
use robovec_ir::{verifier, Module};

use crate::{AtTimeLimit, Deadline, Instrumentation, PassContext, PassError, PassManager};

/// A parsed module of `n` equations with unary minus (zero-removal's `0 − x`), repeated
/// products (cse), sums to reassociate (balance) and multiply-adds (contract).
fn parsed(n: usize) -> Module {
    let mut t = String::from("func @f { input %q[1] input %q[2] input %qd[1] input %qd[2]\n");
    t += "%t1 = %q[1]*%q[2] + %qd[1]\n%t2 = %q[2]*%qd[1] - %qd[2]\n";
    for k in 3..=n {
        t += &format!("%t{k} = -%t{}*%q[1] + %q[2]*%qd[1] + %t{}*%qd[2] - %qd[1]\n", k - 1, k - 2);
    }
    t += &format!("output c[1] = %t{n}\noutput c[2] = %t{}\n}}\n", n - 1);
    parse(&t).expect("the test module parses")
}

fn atomised(n: usize) -> Module {
    let mut m = parsed(n);
    crate::Pass::run(&crate::atomise::Atomise, &mut m, &mut PassContext::default()).expect("atomise runs");
    m
}

/// A limit of 0 s reached 1 s ago: its grace (0.5 s) is over too.
fn passed() -> Deadline {
    let at = std::time::Instant::now().checked_sub(std::time::Duration::from_secs(1)).expect("clock");
    Deadline { at, seconds: 0.0, grace: false, kept: std::time::Duration::ZERO }
}

/// A limit of 1000 s reached now: its grace (50.5 s) is far away.
fn reached_with_grace_left() -> Deadline {
    Deadline { at: std::time::Instant::now(), seconds: 1000.0, grace: false, kept: std::time::Duration::ZERO }
}

fn outputs(m: &Module) -> Vec<(String, f64)> {
    eval::<f64>(&m.functions[0], |n| pseudo_random_input(n, 7))
}

/// Every registered pass with a pipeline element that builds it and what a limit reached
/// before it starts does (issue 28: "the README's list of passes that honour it becomes all").
const EVERY_PASS: &[(&str, AtTimeLimit)] = &[
    ("atomise", AtTimeLimit::Required),
    ("dce", AtTimeLimit::Required),
    ("asap-alap", AtTimeLimit::Skip),
    ("place<pe=2>", AtTimeLimit::Required),
    ("sim", AtTimeLimit::Skip),
    ("sweep", AtTimeLimit::Skip),
    ("accuracy", AtTimeLimit::Skip),
    ("zero-removal", AtTimeLimit::Skip),
    ("swap", AtTimeLimit::Skip),
    ("balance", AtTimeLimit::Skip),
    ("inline", AtTimeLimit::Skip),
    ("interleave", AtTimeLimit::Required),
    ("diff<wrt=q>", AtTimeLimit::Required),
    ("distribute", AtTimeLimit::Skip),
    ("recurrence", AtTimeLimit::Skip),
    ("rotate-3m", AtTimeLimit::Skip),
    ("depth-bound", AtTimeLimit::Skip),
    ("range", AtTimeLimit::Skip),
    ("error-bound", AtTimeLimit::Skip),
    ("precision", AtTimeLimit::Skip),
    ("specialize", AtTimeLimit::Required),
    ("eqsat", AtTimeLimit::Skip),
    ("cse", AtTimeLimit::Skip),
    ("contract", AtTimeLimit::Skip),
    ("schedule-cpu", AtTimeLimit::Skip),
];

#[test]
fn every_registered_pass_is_skipped_or_ends_the_run_when_the_limit_is_reached_before_it() {
    for info in crate::PASSES.iter() {
        assert!(
            EVERY_PASS.iter().any(|(p, _)| p.split('<').next() == Some(info.name)),
            "pass `{}` is missing from EVERY_PASS: say what a reached limit does to it (the back ends: \
             robovec-backends' time_limit_tests)",
            info.name
        );
    }
    for &(text, policy) in EVERY_PASS {
        let pm = PassManager::new(text, Instrumentation::default()).expect("builds");
        assert_eq!(pm.elements().next().map(|e| e.props.at_time_limit), Some(policy), "{text}");
        let mut m = if text == "atomise" { parsed(20) } else { atomised(20) };
        let before = m.to_string();
        let mut cx = PassContext { deadline: Some(passed()), ..PassContext::default() };
        let ran = pm.run(&mut m, &mut cx, &mut Vec::new());
        match policy {
            AtTimeLimit::Skip => {
                let records = ran.unwrap_or_else(|e| panic!("{text}: {e}"));
                assert_eq!(cx.stopped(), [format!("{text} skipped: time limit of 0 s reached before it started")]);
                assert_eq!(m.to_string(), before, "{text}: a skipped pass leaves the module as it was");
                assert_eq!((records.len(), records[0].wall_ms), (1, 0.0), "{text}: listed with no time");
            }
            AtTimeLimit::Required => match ran {
                Err(PassError::TimeLimit { pass, message }) => {
                    assert_eq!(pass, text);
                    assert_eq!(
                        message,
                        "time limit of 0 s and its grace of 0.5 s reached before it started (pass 1 of 1); \
                         the output needs it, so nothing is written"
                    );
                }
                other => panic!("{text}: {other:?}"),
            },
        }
    }
}

#[test]
fn after_the_limit_required_passes_run_in_its_grace_and_the_others_are_skipped() {
    // (With a back end last: robovec-backends' time_limit_tests.)
    let pm = PassManager::new("atomise,balance,cse,dce", Instrumentation::default()).expect("builds");
    let mut m = parsed(20);
    let mut cx = PassContext { deadline: Some(reached_with_grace_left()), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("atomise and dce run in the grace");
    assert_eq!(
        cx.stopped(),
        [
            "balance skipped: time limit of 1000 s reached before it started",
            "cse skipped: time limit of 1000 s reached before it started"
        ]
    );
    assert_eq!(m.functions[0].phase, robovec_ir::Phase::Atomised, "atomise ran");
    // Once the grace is over too, the first required pass ends the run.
    let mut m = parsed(20);
    let mut cx = PassContext { deadline: Some(passed()), ..PassContext::default() };
    let e = pm.run(&mut m, &mut cx, &mut Vec::new()).expect_err("atomise cannot be skipped");
    assert!(e.to_string().contains("pass 1 of 4"), "{e}");
}

#[test]
fn a_required_pass_reads_the_grace_and_a_skippable_one_the_limit() {
    let d = reached_with_grace_left();
    let mut cx = PassContext { deadline: Some(d), ..PassContext::default() };
    assert!(cx.ticker().check(), "skippable: the limit");
    cx.running = AtTimeLimit::Required;
    assert!(!cx.ticker().check(), "required: the grace");
    assert_eq!(d.grace().reason(), "time limit of 1000 s and its grace of 50.5 s reached");
    assert_eq!(d.grace().grace(), d.grace(), "a grace has no grace");
}

/// Runs `text` on `m` with every ticker stopping at tick `budget`.
fn run_budget(text: &str, m: &mut Module, budget: u64) -> (Result<(), PassError>, Vec<String>) {
    let pm = PassManager::new(text, Instrumentation::default()).expect("builds");
    let mut cx = PassContext { tick_budget: Some(budget), ..PassContext::default() };
    let ran = pm.run(m, &mut cx, &mut Vec::new()).map(|_| ());
    (ran, cx.stopped())
}

#[test]
fn rebuilding_rewrites_stopped_inside_keep_the_function_as_it_was() {
    for text in ["zero-removal", "swap", "balance", "inline", "distribute", "recurrence"] {
        let mut m = atomised(60);
        let before = m.to_string();
        let (ran, stopped) = run_budget(text, &mut m, 5);
        ran.unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(stopped.len(), 1, "{text}: {stopped:?}");
        assert!(stopped[0].starts_with(&format!("{text} stopped in @f")), "{text}: {}", stopped[0]);
        assert!(stopped[0].ends_with("tick budget of 5 steps reached"), "{}", stopped[0]);
        assert_eq!(m.to_string(), before, "{text}: the function being rebuilt is kept");
        // Without a limit the pass does its work (the module changes), without a note.
        let mut m = atomised(60);
        let (ran, stopped) = run_budget(text, &mut m, u64::MAX);
        ran.unwrap_or_else(|e| panic!("{text}: {e}"));
        assert!(stopped.is_empty(), "{text}: {stopped:?}");
        assert!(
            text == "inline" || text == "distribute" || text == "recurrence" || m.to_string() != before,
            "{text} changed nothing"
        );
    }
}

#[test]
fn cse_and_contract_stopped_inside_keep_what_they_merged_and_a_valid_function() {
    let full = |text: &str| {
        let mut m = atomised(60);
        run_budget(text, &mut m, u64::MAX).0.expect("runs");
        m.functions[0].op_counts().total
    };
    let ops0 = atomised(60).functions[0].op_counts().total;
    for text in ["cse", "contract"] {
        let mut m = atomised(60);
        let (ran, stopped) = run_budget(text, &mut m, 150);
        ran.expect("skippable");
        assert_eq!(stopped.len(), 1, "{stopped:?}");
        assert!(stopped[0].starts_with(&format!("{text} stopped in @f")), "{}", stopped[0]);
        assert!(verifier::verify(&m).is_ok(), "{text}: {:?}", verifier::verify(&m));
        let ops = m.functions[0].op_counts().total;
        assert!(full(text) < ops && ops < ops0, "{text}: part of the work is kept: {} < {ops} < {ops0}", full(text));
    }
    // cse is exact: the outputs stay bit for bit.
    let mut m = atomised(60);
    run_budget("cse", &mut m, 150).0.expect("runs");
    let bits = |o: Vec<(String, f64)>| o.into_iter().map(|(n, x)| (n, x.to_bits())).collect::<Vec<_>>();
    assert_eq!(bits(outputs(&m)), bits(outputs(&atomised(60))));
}

#[test]
fn passes_that_check_between_functions_stop_before_the_next_one() {
    for text in ["asap-alap", "schedule-cpu"] {
        let mut m = atomised(60);
        let before = m.to_string();
        let (ran, stopped) = run_budget(text, &mut m, 1);
        ran.unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(stopped.len(), 1, "{text}: {stopped:?}");
        assert!(stopped[0].starts_with(&format!("{text} stopped before @f")), "{}", stopped[0]);
        assert_eq!(m.to_string(), before, "{text}");
    }
}

#[test]
fn range_stopped_inside_a_function_keeps_the_functions_enclosed_before_it() {
    // Every input of the test module in [-1, 1]; one tick per value of the body.
    let domain = unit_domain();
    let pm = PassManager::new("range<samples=4>", Instrumentation::default()).expect("builds");
    let mut m = atomised(60);
    let before = m.to_string();
    let mut cx = PassContext { tick_budget: Some(5), domain: Some(domain.clone()), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("skippable");
    assert_eq!(cx.stopped(), ["range stopped in @f after 4 values: tick budget of 5 steps reached"]);
    assert_eq!(m.to_string(), before);
    let run = cx.artifacts_of::<crate::range::RangeRun>().next().expect("an artifact");
    assert!(run.functions.is_empty(), "@f not enclosed");
    // Without a limit @f is enclosed.
    let mut cx = PassContext { domain: Some(domain), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("runs");
    assert!(cx.stopped().is_empty());
    assert_eq!(cx.artifacts_of::<crate::range::RangeRun>().next().expect("an artifact").functions.len(), 1);
}

/// `error-bound<witness=N>` stopped in its witnesses keeps the bounds (without witnesses), with
/// a note; without a limit every output gets a witness.
#[test]
fn error_bound_stopped_in_its_witnesses_keeps_the_bounds() {
    let pm = PassManager::new("error-bound<format=f32;witness=1000>", Instrumentation::default()).expect("builds");
    let mut m = atomised(60);
    // One tick per value to enclose, one per value to bound, then the witnesses' ticks.
    let budget = 2 * m.functions[0].body.len() as u64 + 10;
    let mut cx = PassContext { tick_budget: Some(budget), domain: Some(unit_domain()), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("skippable");
    assert_eq!(
        cx.stopped(),
        [format!(
            "error-bound stopped in @f's witnesses (its bounds kept, without witnesses): tick budget of {budget} steps \
             reached"
        )]
    );
    let run = cx.artifacts_of::<crate::error_bound::ErrorBoundRun>().next().expect("an artifact");
    let outputs = &run.functions[0].outputs;
    assert!(outputs.iter().all(|(_, b)| b.abs.is_some() && b.witness.is_none()), "{outputs:?}");
    let mut cx = PassContext { domain: Some(unit_domain()), ..PassContext::default() };
    PassManager::new("error-bound<format=f32;witness=4>", Instrumentation::default())
        .expect("builds")
        .run(&mut m, &mut cx, &mut Vec::new())
        .expect("runs");
    assert!(cx.stopped().is_empty());
    let run = cx.artifacts_of::<crate::error_bound::ErrorBoundRun>().next().expect("an artifact");
    assert!(run.functions[0].outputs.iter().all(|(_, b)| b.witness.is_some_and(|w| w <= b.abs.unwrap())));
}

/// Every input of the test module ([`atomised`]) in [−1, 1].
fn unit_domain() -> robovec_ir::domain::Domain {
    let r = robovec_ir::domain::Range { interval: robovec_ir::Interval::new(-1.0, 1.0), source: "test".into() };
    robovec_ir::domain::Domain {
        ranges: ["q[1]", "q[2]", "qd[1]", "qd[2]"].into_iter().map(|n| (n.to_string(), r.clone())).collect(),
    }
}

/// `precision` stopped inside its search keeps the formats accepted so far, with a note.
#[test]
fn precision_stopped_in_its_search_keeps_what_it_accepted() {
    let domain = unit_domain();
    let pm = PassManager::new("precision<budget=1e-3>", Instrumentation::default()).expect("builds");
    let mut m = atomised(60);
    // The enclosure ticks once per value of the body; then two sweeps of the search.
    let budget = m.functions[0].body.len() as u64 + 3;
    let mut cx = PassContext { tick_budget: Some(budget), domain: Some(domain), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("skippable");
    assert_eq!(
        cx.stopped(),
        [format!(
            "precision stopped searching @f early (the formats accepted so far kept, every budget met): tick budget \
             of {budget} steps reached"
        )]
    );
    let run = cx.artifacts_of::<crate::precision::PrecisionRun>().next().expect("an artifact");
    assert_eq!(run.functions.len(), 1, "@f keeps its formats");
    assert!(run.functions[0].max_rel_to_range <= 1e-3);
}

#[test]
fn required_passes_stopped_inside_end_the_run_saying_where() {
    for (text, budget, expect) in [
        ("atomise", 5, "stopped in @f after 4 of 60 equations"),
        ("dce", 1, "stopped before @f (0 functions done)"),
        ("specialize", 1, "stopped before @f (0 functions done)"),
    ] {
        let mut m = if text == "atomise" { parsed(60) } else { atomised(60) };
        if text.contains("robotran") {
            m.functions[0].name = "dirdyna".into();
        }
        match run_budget(text, &mut m, budget).0 {
            Err(e @ PassError::TimeLimit { .. }) => {
                let e = e.to_string();
                assert!(e.contains(&format!("tick budget of {budget} steps reached: {expect};")), "{text}: {e}");
                assert!(e.ends_with("the output needs it, so nothing is written"), "{e}");
            }
            other => panic!("{text}: {other:?}"),
        }
    }
}

#[test]
fn place_stopped_in_its_first_schedule_ends_the_run_and_after_it_keeps_the_best() {
    let text = "place<pe=2;improve=4>";
    match run_budget(text, &mut atomised(60), 5).0 {
        Err(e @ PassError::TimeLimit { .. }) => {
            let e = e.to_string();
            assert!(
                e.contains("tick budget of 5 steps reached: stopped in @f in its first list schedule or its memories;"),
                "{e}"
            );
        }
        other => panic!("{other:?}"),
    }
    // The limit reached, its grace not: the first schedule is made, no round of improvement.
    let pm = PassManager::new(text, Instrumentation::default()).expect("builds");
    let mut m = atomised(60);
    let mut cx = PassContext { deadline: Some(reached_with_grace_left()), ..PassContext::default() };
    pm.run(&mut m, &mut cx, &mut Vec::new()).expect("placed in the grace");
    assert_eq!(
        cx.stopped(),
        ["place stopped searching @f early (best schedule so far kept): time limit of 1000 s reached"]
    );
    assert!(verifier::verify(&m).is_ok() && m.functions[0].placement.is_some(), "{:?}", verifier::verify(&m));
    crate::sim::verify_placement(&m.functions[0], &[1]).expect("the placement kept simulates bit for bit");
}

#[test]
fn sweep_drops_the_configuration_the_limit_stops_inside() {
    let table = |b: u64| {
        let mut m = atomised(60);
        let mut cx = PassContext { tick_budget: Some(b), ..PassContext::default() };
        crate::Pass::run(&crate::sweep::Sweep { ns: vec![2] }, &mut m, &mut cx).expect("skippable");
        let csv = cx.artifacts().filter_map(|a| a.csv()).next().unwrap_or_default();
        (csv.lines().count().saturating_sub(1), cx.stopped())
    };
    assert_eq!(table(u64::MAX), (4, vec![]), "four configurations at N = 2");
    let (rows, stopped) = table(5);
    assert_eq!(rows, 0);
    assert_eq!(
        stopped,
        ["sweep stopped in N=2 classical/preferential of @f (0 of 4 configurations done, that one dropped): \
          tick budget of 5 steps reached"]
    );
}

/// Issue 47: the verifier after a pass reads the grace's clock (once per value, op, load and
/// write), so it is never what holds a run past its grace: past the grace it is the pass's
/// `TimeLimit` error; within it (or without a limit) it verifies as before.
#[test]
fn the_verifier_after_a_pass_stops_at_the_grace() {
    let body: String = (1..3000).map(|k| format!("%x{k} = %x{} + 1.0 ", k - 1)).collect();
    let m = parse(&format!("func @f {{ input %x0 {body} output y = %x2999 }}")).unwrap();
    let e = crate::manager::verify_within(&m, "cse", "cse", Some(passed())).expect_err("past the grace");
    assert_eq!(
        e.to_string(),
        "pass `cse`: time limit of 0 s and its grace of 0.5 s reached: stopped while verifying the module after \
         it; the output needs it, so nothing is written"
    );
    crate::manager::verify_within(&m, "cse", "cse", Some(reached_with_grace_left())).expect("within the grace");
    crate::manager::verify_within(&m, "cse", "cse", None).expect("no limit");
}
