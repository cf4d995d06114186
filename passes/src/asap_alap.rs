//! `asap-alap<lat-add;lat-mul;lat-div;lat-call>`: annotates every operation with ASAP, ALAP,
//! ASAPCycle, ALAPCycle and mobility (seed §2.2, SPEC §4), printed in the IR as
//! `{asap=…, alap=…, asap_cycle=…, alap_cycle=…, mobility=…}` and read back by the parser.
//!
//! Phase: atomised → atomised; an analysis: the function is otherwise unchanged. The
//! latencies also become those of the report's `stats.asap_cycle`. Cost: O(values + operands).

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{Module, Phase};

use crate::{require_phase, ParamInfo, Params, Pass, PassContext, PassError, PassInfo};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "asap-alap",
    doc: "annotate ops with ASAP/ALAP (unit) and ASAPCycle/ALAPCycle (latency) and mobility",
    params: &[
        ParamInfo { name: "lat-add", default: "12", doc: "add/sub latency, cycles (10 pipeline + 2 write)" },
        ParamInfo { name: "lat-mul", default: "7", doc: "mul latency, cycles (5 pipeline + 2 write)" },
        ParamInfo { name: "lat-div", default: "12", doc: "div latency, cycles" },
        ParamInfo { name: "lat-call", default: "12", doc: "call (sqrt, callbacks) latency, cycles" },
    ],
    build: |p: &Params| {
        let d = Latencies::default();
        let lat = Latencies {
            add: p.u32_in("lat-add", d.add, 1, 10_000)?,
            mul: p.u32_in("lat-mul", d.mul, 1, 10_000)?,
            div: p.u32_in("lat-div", d.div, 1, 10_000)?,
            call: p.u32_in("lat-call", d.call, 1, 10_000)?,
        };
        Ok(Box::new(AsapAlap { lat }))
    },
};

/// The `asap-alap` pass.
pub struct AsapAlap {
    /// Latencies in cycles.
    pub lat: Latencies,
}

impl Pass for AsapAlap {
    fn name(&self) -> &'static str {
        "asap-alap"
    }

    fn requires(&self) -> Option<Phase> {
        Some(Phase::Atomised)
    }

    fn preserves_timing(&self) -> bool {
        true
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        require_phase(self.name(), m, Phase::Atomised)?;
        for f in &mut m.functions {
            let (t, _) = compute_timing(f, &self.lat);
            for (d, t) in f.values.iter_mut().zip(t) {
                d.timing = t;
            }
        }
        cx.latencies = self.lat;
        Ok(())
    }
}
