//! `-time-limit=SECONDS` in the passes (issue 28 item 3): the run's [`Deadline`], the
//! [`Ticker`] that every pass's long loops count their steps on, and the manager's policy for
//! a pass the limit reaches ([`AtTimeLimit`]).
//!
//! # Policy
//! The deadline starts with the run, before loading (the front ends read it too, and a load it
//! stops ends the run). The limit is for the work a run may cut short; what the output cannot
//! do without gets a short **grace** after it ([`Deadline::grace`]: 5 % of the limit plus
//! 0.5 s), so that a search that used the time to the limit (`eqsat`, `place`'s improvement,
//! `accuracy`) still leaves a result:
//!
//! - **A skippable pass** ([`AtTimeLimit::Skip`]: the rewrites that only improve, the
//!   analyses, the checks and measurements) not started at the limit is skipped with a note
//!   (`balance skipped: time limit of 1 s reached before it started`); one the limit reaches
//!   while it runs stops at its next step with a valid module and a note (a rebuilding rewrite
//!   keeps the function it was rebuilding as it was; the searches keep the best found so far;
//!   the measurements report what they measured).
//! - **A required pass** ([`AtTimeLimit::Required`]: `atomise`, whose phase every later pass
//!   needs, `place`'s first schedule, the back ends, and the passes that change what a
//!   function computes or takes, `specialize` and `dce`) runs, its tickers reading the grace;
//!   at the grace's end it stops with [`PassError::TimeLimit`] (exit 1, nothing written, as a
//!   limit reached while loading), and so does the manager for one not started by then.
//!
//! Every loop over ops, values, cycles or samples ticks a [`Ticker`] (the clock is read every
//! [`Ticker::EVERY`] ticks), so a run ends at the limit (or its grace) plus one step of some
//! loop. What follows the passes is required too and reads the grace's clock: the verifier
//! after each pass (`PassManager`), building `place`'s memories for the schedule kept, and
//! writing the main output (the driver); past the grace each ends the run as a required pass
//! does. So that a run which can finish does, the manager keeps time back before the limit
//! for that tail ([`kept_for`]: 2.5 µs per op of the module, [`Deadline::keeping`]): the
//! searches and the check before a skippable pass stop that much earlier.
//!
//! [`Deadline`] and [`Ticker`] live in `robovec-ir` (the front ends and the generator read them
//! too); they are re-exported here.
//!
//! Tests make the stops deterministic with [`crate::PassContext::tick_budget`] (every ticker
//! of the run stops at that tick whatever the machine's speed) or a deadline already passed.

use crate::PassError;
pub use robovec_ir::time_limit::{Deadline, Ticker};

/// What the manager does with a pass that has not started when `-time-limit` is reached
/// (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AtTimeLimit {
    /// Skip it with a note: the module is valid and complete without it. Its tickers stop at
    /// the limit.
    #[default]
    Skip,
    /// Run it within the grace ([`Deadline::grace`]), whose end stops it with
    /// [`PassError::TimeLimit`]: the output needs it.
    Required,
}

/// The time kept back before the limit per op of the module, ns ([`kept_for`]).
pub const KEPT_NS_PER_OP: u64 = 2_500;

/// The time the pass manager keeps back before the limit for a module of `ops` ops
/// ([`Deadline::keeping`]): what runs after the searches stop and is not cut short grows with
/// the module — a placement's memories built for the best schedule found, the verifier after
/// each pass, writing the output — at about 2.1 µs per op together on a 2-core VM (a
/// 1,000,824-op `invdyna` of a 10,000-joint chain placed on 8 + 8 PEs: memories 0.69 s,
/// verifier 0.56 s, the `.rvir` 0.64 s); [`KEPT_NS_PER_OP`] rounds that up. The searches (and
/// the manager's check before a skippable pass) then stop that long before the limit, so
/// that a run that can finish by the limit and its grace does; a 30,000-op model keeps 75 ms.
pub fn kept_for(ops: u64) -> std::time::Duration {
    std::time::Duration::from_nanos(ops.saturating_mul(KEPT_NS_PER_OP))
}

/// The error of a required pass whose [`Ticker`] stopped.
pub trait TickerError {
    /// `pass` stopped `where_` (`in @dirdyna after 41 of 600 000 values`), nothing is written:
    /// [`PassError::TimeLimit`] with [`Ticker::stop_message`].
    fn error(&self, pass: &str, where_: &str) -> PassError;
}

impl TickerError for Ticker {
    fn error(&self, pass: &str, where_: &str) -> PassError {
        PassError::TimeLimit { pass: pass.to_string(), message: self.stop_message(where_) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stopped_required_pass_fails_with_the_tickers_message() {
        let t = Ticker::new(None, Some(1));
        assert!(t.tick());
        let e = t.error("atomise", "in @f after 0 of 9 values");
        assert_eq!(
            e.to_string(),
            "pass `atomise`: tick budget of 1 steps reached: stopped in @f after 0 of 9 values; \
             the output needs it, so nothing is written"
        );
    }
}
