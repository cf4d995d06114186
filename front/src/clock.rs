//! The time limit of a load (`-time-limit`, issue 28 item 3): [`Clock`], which the Robotran
//! front ends' long loops (tokens lexed, lines scanned, statements parsed and lowered) tick.
//!
//! # Design
//! The deadline ([`robovec_ir::time_limit::Deadline`]) starts with the run, before loading, so that
//! `-time-limit=5` bounds reading a 50 MB file too. The loops call [`Clock::tick`] once per
//! token, line or statement; the clock is read every [`Clock::EVERY`] ticks (one clock read,
//! tens of ns, per thousand steps of a few hundred ns each: free), and once it is past the
//! deadline every later tick says stop, so each loop leaves at its next step and the phases
//! after it do not start. The front end then returns one error, [`Clock::error`]: nothing is
//! returned, since no pass can run on part of a module and the driver writes no output
//! without one. The clock is a shared reference with interior mutability ([`Cell`]) so that
//! the scanners and the lowering, which already share the source text, share it the same way.

use std::cell::Cell;

use robovec_ir::time_limit::{Deadline, Ticker};
use robovec_ir::Span;

use crate::FrontError;

/// The deadline of one load and where it stopped (module doc): a [`Ticker`] that also
/// remembers the byte offset of the step where it stopped.
#[derive(Debug, Default)]
pub struct Clock<'d> {
    deadline: Option<&'d Deadline>,
    ticker: Ticker,
    /// The byte offset of the step at which the deadline was found reached.
    stopped_at: Cell<Option<usize>>,
}

impl<'d> Clock<'d> {
    /// Ticks between two reads of the clock (a power of two).
    pub const EVERY: u64 = Ticker::EVERY;

    /// A clock for `deadline` (`None`: never stops).
    pub fn new(deadline: Option<&'d Deadline>) -> Clock<'d> {
        Clock { deadline, ticker: Ticker::new(deadline.copied(), None), stopped_at: Cell::new(None) }
    }

    /// A clock that stops at its `ticks`-th tick (tests: every loop's stop path, without
    /// timing).
    #[cfg(test)]
    pub(crate) fn after_ticks(ticks: u32) -> Clock<'static> {
        Clock { ticker: Ticker::new(None, Some(u64::from(ticks))), ..Clock::default() }
    }

    /// Records the first stop, at byte `at`.
    fn stop_at(&self, stopped: bool, at: usize) -> bool {
        if stopped && self.stopped_at.get().is_none() {
            self.stopped_at.set(Some(at));
        }
        stopped
    }

    /// Counts one step of a long loop, at byte `at` of the source; true once the deadline is
    /// reached (read every [`Clock::EVERY`] ticks): the loop must stop.
    pub fn tick(&self, at: usize) -> bool {
        self.stop_at(self.ticker.tick(), at)
    }

    /// Reads the clock now (between phases), at byte `at`; true once the deadline is reached.
    pub fn check(&self, at: usize) -> bool {
        self.stop_at(self.ticker.check(), at)
    }

    /// Whether a tick or check found the deadline reached.
    pub fn stopped(&self) -> bool {
        self.stopped_at.get().is_some()
    }

    /// The error of a stopped load of `src`: `time limit of 5 s reached while reading (line N
    /// of M)`, spanning the line reached; `None` when the load did not stop. Cost: one pass
    /// over `src` (the line numbers).
    pub fn error(&self, src: &str) -> Option<FrontError> {
        let at = self.stopped_at.get()?.min(src.len());
        let seconds = self.deadline.map_or(0.0, |d| d.seconds);
        let line = robovec_ir::span::line_of(src, at);
        let lines = src.bytes().filter(|&b| b == b'\n').count() + usize::from(!src.is_empty() && !src.ends_with('\n'));
        let start = src[..at].rfind('\n').map_or(0, |k| k + 1);
        let end = src[at..].find('\n').map_or(src.len(), |k| at + k);
        Some(
            FrontError::new(
                Span::new(start, end),
                format!("time limit of {seconds} s reached while reading (line {line} of {lines})"),
                "reached here",
            )
            .note("-time-limit covers loading too: nothing is written without a complete module"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reached_deadline_stops_within_every_ticks_and_says_where() {
        let never = Clock::new(None);
        assert!((0..10 * Clock::EVERY as usize).all(|k| !never.tick(k)));
        assert!(!never.check(0) && never.error("x").is_none());
        let past = Deadline::after_seconds(0.0);
        let c = Clock::new(Some(&past));
        let first = (0..2 * Clock::EVERY as usize).find(|&k| c.tick(k)).expect("stops");
        assert_eq!(first, Clock::EVERY as usize - 1, "read at the EVERY-th tick");
        assert!(c.tick(0) && c.stopped(), "every later tick says stop");
        let src = "a = 1;\nb = 2;\nc = 3;\n";
        let c = Clock::new(Some(&past));
        assert!(c.check(9));
        let e = c.error(src).expect("stopped");
        assert_eq!(e.message, "time limit of 0 s reached while reading (line 2 of 3)");
        assert_eq!((e.span.start, e.span.end), (7, 13), "the line reached");
        let far = Deadline::after_seconds(3600.0);
        let c = Clock::new(Some(&far));
        assert!((0..10 * Clock::EVERY as usize).all(|k| !c.tick(k)) && !c.check(0));
    }
}
