//! `zero-removal<lat-add;lat-mul;lat-div;lat-call>`: removes the `0 − x` ops that `atomise`
//! inserts for a unary minus (SPEC §3) by moving signs (seed §2.4.1; SPEC §6).
//!
//! Phase: atomised → atomised. Every cluster keeps its tree ([`Shape::Keep`]) minus its
//! additive zero terms (and ±1 factors); the sign a removed `0 − x` leaves is carried as
//! [`super::rebuild`] describes: a `−` term next to a `+` one turns the parent's `add` into a
//! `sub` (or swaps its operands: the positive term comes forward), two `−` terms are added and
//! carry the sign up, a product carries it to its consumers (`(0 − x)·y` → `−(x·y)`), a
//! constant factor takes it. Where a sign reaches an output or a call argument and nothing on
//! the way can take it, one `0 − x` stays (documented choice: an output keeps its true sign;
//! robovec has no negated outputs): on the output's value itself, or on one negative term of
//! its cluster when that makes the output ready earlier (`−a − b·c` → `(0 − a) − b·c`, ready at
//! 24 cycles, rather than `0 − (a + b·c)` at 31).
//!
//! Contract: never adds an op, never lengthens the critical path (`asap_cycle` under the given
//! latencies; enforced, see [`super::rewrite`]), and the outputs are bit for bit those of the
//! input (negation and exchanging `a + (−b)` for `a − b` are exact in IEEE 754) except the
//! sign of an exact zero. Idempotent. Cost: O(values + operands) plus O(k log k) per cluster
//! with negative terms.
//!
//! Under other latencies the critical path can grow, but only through the negations made:
//! every tree keeps its shape, so a path of the result is a path of the input without its
//! zeros and with the negations made on it. Where signs carried from two zeros meet, the one
//! negation left goes in that cluster, on a term or the result, and can sit on a path that had
//! no zero: `(0 − s)·u + (0 − h)·w` becomes `(0 − h·w) − s·u`, shorter under the given
//! latencies but one add longer where `w` is late; every other place in that cluster is too
//! (test `zero_removal_is_longer_under_other_latencies_only_through_its_negations`). Keeping one
//! zero where it was, `(0 − h)·w − s·u`, would not be, but the rebuild never moves a sign back
//! to a zero it has removed. The corpus files are no longer under the tests' four latency sets.

use robovec_ir::Module;

use super::{rewrite_within, summary, Shape};
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// The latency parameters the cluster rewrites take (cycles; SPEC §1 defaults).
pub const LATENCY_PARAMS: &[ParamInfo] = crate::params::LATENCY_PARAMS;

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "zero-removal",
    doc: "remove the `0 - x` ops of atomise by moving signs into parents and consumers (seed §2.4.1)",
    params: LATENCY_PARAMS,
    build: |p: &Params| {
        Ok(Box::new(ClusterRewrite { name: "zero-removal", shape: Shape::Keep, lat: p.latency_override()? }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// A pass that rebuilds every cluster with one [`Shape`] (`zero-removal`, `swap`, `balance`).
#[derive(Debug)]
pub struct ClusterRewrite {
    /// Registered name.
    pub name: &'static str,
    /// Tree of each cluster.
    pub shape: Shape,
    /// Latencies given on the pass for the ready times (and the critical-path check), cycles;
    /// the others are the pipeline's ([`PassContext::latencies_for`]).
    pub lat: crate::LatencyOverride,
}

impl Pass for ClusterRewrite {
    fn name(&self) -> &'static str {
        self.name
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let lat = cx.latencies_for(self.name, &self.lat);
        let n = m.functions.len();
        // The rewrite ticks per op: a limit reached before a function is found inside it (its
        // first tick says stop), so that function is named as kept.
        let kept = move |f: &robovec_ir::Function, k| {
            format!("in @{} ({k} of {n} functions rewritten; @{} kept as it was)", f.name, f.name)
        };
        let outcomes = each_function(
            m,
            cx,
            self.name,
            Before::Ticked,
            |f, k| Some(kept(f, k)),
            |f, k, ticker| {
                let Some((g, o)) = rewrite_within(f, self.shape, &lat, ticker) else {
                    return Step::Stopped { what: kept(f, k), kept: None };
                };
                *f = g;
                Step::Done((f.name.clone(), o))
            },
        );
        cx.remark(self.name, m, summary(self.name, &outcomes));
        Ok(())
    }
}
