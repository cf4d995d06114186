//! The wall-clock limit of a run (`-time-limit=SECONDS`): its [`Deadline`] and the [`Ticker`]
//! every long loop counts its steps on, for whatever works on the IR: the front ends and the
//! generator while loading, the passes after. The policy of the passes (which may be skipped,
//! which get the grace) lives with the pass manager (`robovec_passes::time_limit`); the
//! policy of a load with the front ends (`robovec_front::clock`).
//!
//! Every loop over ops, values, cycles or samples ticks a [`Ticker`] (the clock is read every
//! [`Ticker::EVERY`] ticks), so a run ends at the limit (or its grace) plus one step of some
//! loop. Tests make the stops deterministic with a tick budget ([`Ticker::new`]'s `budget`:
//! every ticker stops at that tick whatever the machine's speed) or a deadline already passed.

use std::cell::Cell;

/// A wall-clock limit on a pipeline run (`-time-limit=SECONDS`), or its grace (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deadline {
    /// When the limit is reached.
    pub at: std::time::Instant,
    /// The limit as given, seconds.
    pub seconds: f64,
    /// True for [`Deadline::grace`]: the limit plus the grace the passes the output needs get.
    pub grace: bool,
    /// The time kept back before the limit ([`Deadline::keeping`]): the work that may be cut
    /// short stops this long before `at`, so that what the output cannot do without and what is
    /// never interrupted still end by the limit. Zero for a grace.
    pub kept: std::time::Duration,
}

impl Deadline {
    /// A limit of `seconds` from now.
    pub fn after_seconds(seconds: f64) -> Deadline {
        let d = std::time::Duration::try_from_secs_f64(seconds.max(0.0)).unwrap_or(std::time::Duration::MAX);
        Deadline { at: later(std::time::Instant::now(), d), seconds, grace: false, kept: std::time::Duration::ZERO }
    }

    /// This limit with `kept` kept back before it ([`Deadline::kept`]; the pass manager keeps
    /// the estimated time of the output's tail, `robovec_passes::time_limit`); a grace is
    /// returned as it is.
    pub fn keeping(&self, kept: std::time::Duration) -> Deadline {
        if self.grace {
            return *self;
        }
        Deadline { kept, ..*self }
    }

    /// When the work this deadline bounds must stop: the limit less what is kept back.
    pub fn end(&self) -> std::time::Instant {
        self.at.checked_sub(self.kept).unwrap_or(self.at)
    }

    /// The grace of a limit of `seconds`: 5 % of it plus 0.5 s, so that a run whose searches
    /// stopped at the limit still ends within the 10 % + 1 s of it after the required
    /// passes, the verifier and the output.
    pub fn grace_seconds(seconds: f64) -> f64 {
        0.05 * seconds + 0.5
    }

    /// The deadline of the passes the output needs (`AtTimeLimit::Required` in `robovec-passes`): this limit
    /// plus [`Deadline::grace_seconds`].
    pub fn grace(&self) -> Deadline {
        if self.grace {
            return *self;
        }
        let extra = std::time::Duration::try_from_secs_f64(Self::grace_seconds(self.seconds)).unwrap_or_default();
        Deadline { at: later(self.at, extra), grace: true, kept: std::time::Duration::ZERO, ..*self }
    }

    /// Time left before [`Deadline::end`] (zero once reached).
    pub fn time_left(&self) -> std::time::Duration {
        self.end().saturating_duration_since(std::time::Instant::now())
    }

    /// True once [`Deadline::end`] is reached: the limit, less what is kept back.
    pub fn reached(&self) -> bool {
        std::time::Instant::now() >= self.end()
    }

    /// Why a pass stopped: `time limit of 5 s reached` (a grace: `time limit of 5 s and its
    /// grace of 0.75 s reached`).
    pub fn reason(&self) -> String {
        if self.grace {
            format!("time limit of {} s and its grace of {} s reached", self.seconds, Self::grace_seconds(self.seconds))
        } else {
            format!("time limit of {} s reached", self.seconds)
        }
    }
}

/// `t + d`, or about a century from now beyond what the clock represents ("no limit").
fn later(t: std::time::Instant, d: std::time::Duration) -> std::time::Instant {
    t.checked_add(d).unwrap_or_else(|| std::time::Instant::now() + std::time::Duration::from_secs(100 * 365 * 86_400))
}

/// Counts the steps of a long loop and says when to stop for `-time-limit` (module doc).
///
/// Not `Sync` (a [`Cell`]): a loop spread over threads keeps one per thread or checks the
/// [`Deadline`] itself.
#[derive(Debug, Default)]
pub struct Ticker {
    deadline: Option<Deadline>,
    /// Tests: stop at this tick instead of reading the clock.
    budget: Option<u64>,
    ticks: Cell<u64>,
    stopped: Cell<bool>,
}

impl Ticker {
    /// Steps between two reads of the clock (a power of two: one clock read, tens of ns, per
    /// thousand steps of tens to hundreds of ns each).
    pub const EVERY: u64 = 1024;

    /// A ticker for `deadline` (`None`: never stops) that, with `budget`, also stops at its
    /// `budget`-th tick (tests; see `PassContext::tick_budget` of `robovec-passes`).
    pub fn new(deadline: Option<Deadline>, budget: Option<u64>) -> Ticker {
        Ticker { deadline, budget, ..Ticker::default() }
    }

    /// Counts one step; true once the limit is reached (the clock is read every
    /// [`Ticker::EVERY`] steps, and every tick after a stop says stop): the loop must stop.
    pub fn tick(&self) -> bool {
        if self.stopped.get() {
            return true;
        }
        let n = self.ticks.get() + 1;
        self.ticks.set(n);
        let reached = self.budget.is_some_and(|b| n >= b)
            || (n.is_multiple_of(Self::EVERY) && self.deadline.is_some_and(|d| d.reached()));
        self.stopped.set(reached);
        reached
    }

    /// Counts one step and reads the clock now (between phases of a pass, or per function
    /// of a pass too fast to tick per op); true once the limit is reached.
    pub fn check(&self) -> bool {
        if !self.tick() && self.deadline.is_some_and(|d| d.reached()) {
            self.stopped.set(true);
        }
        self.stopped.get()
    }

    /// True once a tick or a check found the limit reached.
    pub fn stopped(&self) -> bool {
        self.stopped.get()
    }

    /// Steps counted so far.
    pub fn ticks(&self) -> u64 {
        self.ticks.get()
    }

    /// Why it stopped: `time limit of 5 s reached` (a test budget: `tick budget of K steps
    /// reached`).
    pub fn reason(&self) -> String {
        match (self.deadline, self.budget) {
            (Some(d), None) => d.reason(),
            (Some(d), Some(b)) if d.reached() || self.ticks.get() < b => d.reason(),
            (_, Some(b)) => format!("tick budget of {b} steps reached"),
            (None, None) => "no time limit".into(),
        }
    }

    /// The message of a required step that stopped: it stopped `where_` (`in @dirdyna after
    /// 41 of 600 000 values`), nothing is written (`robovec-passes`' `TickerError::error`
    /// wraps it in the pass's error).
    pub fn stop_message(&self, where_: &str) -> String {
        format!("{}: stopped {where_}; the output needs it, so nothing is written", self.reason())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reached_deadline_stops_at_the_every_th_tick_and_for_good() {
        let never = Ticker::new(None, None);
        assert!((0..10 * Ticker::EVERY).all(|_| !never.tick()) && !never.check() && !never.stopped());
        let past = Ticker::new(Some(Deadline::after_seconds(0.0)), None);
        let first = (1..=2 * Ticker::EVERY).find(|_| past.tick()).expect("stops");
        assert_eq!(first, Ticker::EVERY, "the clock is read at the EVERY-th tick");
        assert!(past.tick() && past.stopped() && past.check(), "every later tick says stop");
        assert_eq!(past.reason(), "time limit of 0 s reached");
        let far = Ticker::new(Some(Deadline::after_seconds(3600.0)), None);
        assert!((0..10 * Ticker::EVERY).all(|_| !far.tick()) && !far.check());
        let past = Ticker::new(Some(Deadline::after_seconds(0.0)), None);
        assert!(past.check() && past.tick(), "check reads the clock at once");
    }

    #[test]
    fn time_kept_back_ends_the_work_earlier_but_not_the_grace() {
        let d = Deadline::after_seconds(3600.0);
        let kept = d.keeping(std::time::Duration::from_secs(3601));
        assert!(!d.reached() && kept.reached(), "an hour's limit keeping more than an hour is reached now");
        assert_eq!(kept.time_left(), std::time::Duration::ZERO);
        assert!(d.time_left() > std::time::Duration::from_secs(3599));
        assert_eq!(kept.grace(), d.grace(), "the grace counts from the limit itself");
        assert!(!kept.grace().reached());
        assert_eq!(kept.grace().keeping(std::time::Duration::from_secs(1)), d.grace(), "a grace keeps nothing");
        assert_eq!(kept.reason(), d.reason());
        // Keeping replaces what was kept (the manager sets it before each pass).
        assert!(!kept.keeping(std::time::Duration::ZERO).reached());
    }

    #[test]
    fn a_tick_budget_stops_at_that_tick() {
        let t = Ticker::new(Some(Deadline::after_seconds(3600.0)), Some(3));
        assert!(!t.tick() && !t.tick() && t.tick() && t.tick());
        assert_eq!(t.ticks(), 3);
        assert_eq!(t.reason(), "tick budget of 3 steps reached");
        assert_eq!(
            t.stop_message("in @f after 2 of 9 values"),
            "tick budget of 3 steps reached: stopped in @f after 2 of 9 values; \
             the output needs it, so nothing is written"
        );
    }
}
