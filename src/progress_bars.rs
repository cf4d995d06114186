//! The progress display of `robovec-opt` (issue 13): `indicatif` bars on stderr, plugged into
//! the passes' [`robovec_passes::progress::Progress`] hook only when stderr is a terminal and
//! `-q` is not given ([`progress_for`]); piped or quiet runs get the hidden hook, so their
//! stderr is byte for byte what it was.
//!
//! Each task is one bar (`label [bar] done/total, elapsed, ETA`) cleared when the task ends, so
//! the tables and notes printed after the pipeline are all that stays on screen.

use std::sync::Arc;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use robovec_passes::progress::{Progress, ProgressDisplay, ProgressSink};

/// Bars on stderr.
struct Bars {
    multi: MultiProgress,
}

/// One bar; cleared when finished or dropped.
struct Bar(ProgressBar);

impl ProgressSink for Bars {
    fn start(&self, label: &str, total: u64) -> Box<dyn ProgressDisplay> {
        let style = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} ({elapsed}, ETA {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        let bar = self.multi.add(ProgressBar::new(total).with_style(style).with_message(label.to_string()));
        Box::new(Bar(bar))
    }
}

impl ProgressDisplay for Bar {
    fn set(&self, done: u64) {
        self.0.set_position(done);
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

/// Whether progress is shown: only on a terminal, and never under `-q`.
pub fn shows_progress(stderr_is_terminal: bool, quiet: bool) -> bool {
    stderr_is_terminal && !quiet
}

/// The hook for a run: bars on stderr when [`shows_progress`], else hidden.
pub fn progress_for(stderr_is_terminal: bool, quiet: bool) -> Progress {
    if shows_progress(stderr_is_terminal, quiet) {
        Progress::shown(Arc::new(Bars { multi: MultiProgress::with_draw_target(ProgressDrawTarget::stderr()) }))
    } else {
        Progress::hidden()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_only_on_a_terminal_and_not_quiet() {
        assert!(shows_progress(true, false));
        assert!(!shows_progress(true, true));
        assert!(!shows_progress(false, false));
        assert!(!progress_for(false, false).is_shown());
        assert!(!progress_for(true, true).is_shown());
        assert!(progress_for(true, false).is_shown());
    }
}
