//! `-time-limit` in the back ends (issue 28 item 3; the passes' own are in `robovec-passes`'
//! `time_limit_tests`): a back end is required (the output is its code), runs in the limit's
//! grace, and one stopped inside ends the run saying where.

use robovec_ir::text::parse;
use robovec_ir::Module;
use robovec_passes::{AtTimeLimit, Deadline, Instrumentation, PassContext, PassError, PassManager};

use crate::REGISTRY;

/// An atomised module of `n` equations (sums of products of the inputs and earlier values).
fn atomised(n: usize) -> Module {
    let mut t = String::from("func @f { input %q[1] input %q[2] input %qd[1] input %qd[2]\n");
    t += "%t1 = %q[1]*%q[2] + %qd[1]\n%t2 = %q[2]*%qd[1] - %qd[2]\n";
    for k in 3..=n {
        t += &format!("%t{k} = -%t{}*%q[1] + %q[2]*%qd[1] + %t{}*%qd[2] - %qd[1]\n", k - 1, k - 2);
    }
    t += &format!("output c[1] = %t{n}\noutput c[2] = %t{}\n}}\n", n - 1);
    let mut m = parse(&t).expect("the test module parses");
    run(&pipeline("atomise"), &mut m, PassContext::default()).expect("atomise runs");
    m
}

fn pipeline(text: &str) -> PassManager {
    PassManager::with_registry(REGISTRY, text, Instrumentation::default()).expect("builds")
}

fn run(pm: &PassManager, m: &mut Module, mut cx: PassContext) -> Result<PassContext, PassError> {
    pm.run(m, &mut cx, &mut Vec::new()).map(|_| cx)
}

#[test]
fn every_back_end_is_required_when_the_limit_is_reached_before_it() {
    for member in crate::BACK_ENDS {
        assert!(member.props.back_end, "{}", member.name);
        assert_eq!(member.props.at_time_limit, AtTimeLimit::Required, "{}", member.name);
    }
    for text in ["codegen<c>", "codegen<fpga;out=unused>"] {
        let pm = pipeline(text);
        assert_eq!(pm.elements().next().map(|e| e.props.at_time_limit), Some(AtTimeLimit::Required), "{text}");
        let at = std::time::Instant::now().checked_sub(std::time::Duration::from_secs(1)).expect("clock");
        let cx = PassContext {
            deadline: Some(Deadline { at, seconds: 0.0, grace: false, kept: std::time::Duration::ZERO }),
            ..PassContext::default()
        };
        match run(&pm, &mut atomised(20), cx) {
            Err(PassError::TimeLimit { pass, message }) => {
                assert_eq!(pass, text);
                assert!(
                    message.ends_with("before it started (pass 1 of 1); the output needs it, so nothing is written")
                );
            }
            other => panic!("{text}: {:?}", other.map(|_| ())),
        }
    }
}

#[test]
fn after_the_limit_a_back_end_runs_in_its_grace() {
    let pm = pipeline("atomise,balance,cse,codegen<c>");
    let mut m = parse("func @f { input %a input %b %x = %a*%b + %a*%b - %b output y = %x }\n").unwrap();
    let reached =
        Deadline { at: std::time::Instant::now(), seconds: 1000.0, grace: false, kept: std::time::Duration::ZERO };
    let cx = run(&pm, &mut m, PassContext { deadline: Some(reached), ..PassContext::default() }).expect("grace");
    assert_eq!(
        cx.stopped(),
        [
            "balance skipped: time limit of 1000 s reached before it started",
            "cse skipped: time limit of 1000 s reached before it started"
        ]
    );
    assert_eq!(cx.artifacts().filter(|a| a.code().is_some()).count(), 1, "the code");
}

#[test]
fn a_back_end_stopped_inside_ends_the_run_saying_where() {
    for (text, budget, expect) in
        [("codegen<c>", 5, "stopped writing @f"), ("codegen<c;abi=robotran>", 5, "stopped writing @dirdyna")]
    {
        let mut m = atomised(60);
        if text.contains("robotran") {
            m.functions[0].name = "dirdyna".into();
        }
        match run(&pipeline(text), &mut m, PassContext { tick_budget: Some(budget), ..PassContext::default() }) {
            Err(e @ PassError::TimeLimit { .. }) => {
                let e = e.to_string();
                assert!(e.contains(&format!("tick budget of {budget} steps reached: {expect};")), "{text}: {e}");
                assert!(e.ends_with("the output needs it, so nothing is written"), "{e}");
            }
            other => panic!("{text}: {:?}", other.map(|_| ())),
        }
    }
}
