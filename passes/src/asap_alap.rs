//! `asap-alap<lat-add;lat-mul;lat-div;lat-call>`: annotates every operation with ASAP, ALAP,
//! ASAPCycle, ALAPCycle and mobility (seed §2.2, SPEC §4), printed in the IR as
//! `{asap=…, alap=…, asap_cycle=…, alap_cycle=…, mobility=…}` and read back by the parser.
//!
//! Phase: atomised → atomised; an analysis: the function is otherwise unchanged. Latencies are
//! the pipeline's (the target's, `-target`), a `lat-*` given here replacing them from this
//! pass on (also for the report's `stats.asap_cycle`). Cost: O(values + operands).

use robovec_ir::analysis::annotate_timing;
use robovec_ir::Module;

use crate::{each_function, Before, LatencyOverride, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "asap-alap",
    doc: "annotate ops with ASAP/ALAP (unit) and ASAPCycle/ALAPCycle (latency) and mobility",
    params: crate::params::LATENCY_PARAMS,
    build: |p: &Params| Ok(Box::new(AsapAlap { lat: p.latency_override()? })),
    props: crate::Props {
        formats: true,
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        ..crate::Props::DEFAULT
    },
};

/// The `asap-alap` pass.
#[derive(Debug)]
pub struct AsapAlap {
    /// Latencies given on the pass (the others are the pipeline's), cycles.
    pub lat: LatencyOverride,
}

impl Pass for AsapAlap {
    fn name(&self) -> &'static str {
        "asap-alap"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let lat = cx.latencies_for("asap-alap", &self.lat);
        // About 30 ns per op: the clock is read between functions only.
        let skipped = |f: &robovec_ir::Function, k| Some(format!("before @{} ({k} functions annotated)", f.name));
        let target = cx.target.clone();
        each_function(m, cx, "asap-alap", Before::Clock, skipped, |f, _, _| {
            let lat = crate::function_latencies(&target, f, lat, &self.lat);
            Step::Done(annotate_timing(f, &lat))
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn hand_computed_timing() {
        // x = a*b (mul), y = x + c (add), z = y*x (mul), w = a*c (mul, off the critical path).
        // ASAP: x 1, y 2, z 3, w 1.  ASAPCycle: x 7, y 19, z 26, w 7.  Critical path 3 / 26.
        // ALAP: z 3, y 2, x min(2-1, 3-1) = 1, w (no op user) 3.
        // ALAPCycle: z 26, y 26-7 = 19, x min(19-12, 26-7) = 7, w 26.
        let mut m = parse(
            "func @f { phase atomised input %a input %b input %c %x = mul %a, %b %y = add %x, %c %z = mul %y, %x %w = mul %a, %c output o = %z output p = %w }",
        )
        .unwrap();
        AsapAlap { lat: LatencyOverride::default() }.run(&mut m, &mut PassContext::default()).unwrap();
        let f = &m.functions[0];
        let t = |n: &str| f.timing(f.lookup(n).unwrap()).unwrap();
        let row = |n: &str| {
            let t = t(n);
            (t.asap, t.alap, t.asap_cycle, t.alap_cycle, t.mobility)
        };
        assert_eq!(row("x"), (1, 1, 7, 7, 0));
        assert_eq!(row("y"), (2, 2, 19, 19, 0));
        assert_eq!(row("z"), (3, 3, 26, 26, 0));
        assert_eq!(row("w"), (1, 3, 7, 26, 2));
        // Printed and re-read unchanged.
        let again = parse(&m.to_string()).unwrap();
        assert_eq!(again.to_string(), m.to_string());
    }

    #[test]
    fn parsed_input_is_rejected_by_the_manager() {
        let mut m = parse("func @f { input %a %x = %a*%a output o = %x }").unwrap();
        let pm = crate::PassManager::new("asap-alap", crate::Instrumentation::default()).unwrap();
        let e = pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink()).unwrap_err();
        assert!(e.to_string().contains("run `atomise` first"), "{e}");
    }
}
