//! Progress of long work (issue 13): accuracy samples, sweep configurations, place's search
//! iterations.
//!
//! Passes never touch the terminal. A pass asks the run's [`Progress`] hook
//! ([`crate::PassContext::progress`]) for a [`Task`] with a label and a total number of steps
//! and advances it; the driver fills the hook with a display (a progress bar on stderr when
//! stderr is a terminal and `-q` is not given) or leaves it hidden, in which case every
//! [`Task`] is a no-op costing one branch. Tasks are advanced from the pass's own thread, at
//! most once per step of its loop (per chunk of samples for `accuracy`), so a display is never
//! drawn from a worker thread.

use std::fmt;
use std::sync::Arc;

/// A display of progress: what the driver plugs into [`Progress`].
pub trait ProgressSink: Send + Sync {
    /// Starts a task named `label` (`accuracy @dirdyna: samples`) of `total` steps.
    fn start(&self, label: &str, total: u64) -> Box<dyn ProgressDisplay>;
}

/// One running task of a [`ProgressSink`].
pub trait ProgressDisplay: Send + Sync {
    /// Sets the steps done so far (at most the task's total).
    fn set(&self, done: u64);
    /// Ends the task (its display is cleared or left finished, as the sink decides).
    fn finish(&self);
}

/// The run's progress hook: hidden (the default) or a [`ProgressSink`].
#[derive(Clone, Default)]
pub struct Progress(Option<Arc<dyn ProgressSink>>);

impl fmt::Debug for Progress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() { "Progress(shown)" } else { "Progress(hidden)" })
    }
}

impl Progress {
    /// No display: every task is a no-op.
    pub fn hidden() -> Progress {
        Progress(None)
    }

    /// Progress shown through `sink`.
    pub fn shown(sink: Arc<dyn ProgressSink>) -> Progress {
        Progress(Some(sink))
    }

    /// True when a display is plugged in.
    pub fn is_shown(&self) -> bool {
        self.0.is_some()
    }

    /// A task of `total` steps (a no-op one when hidden).
    pub fn task(&self, label: &str, total: u64) -> Task {
        Task(self.0.as_ref().map(|s| Arc::from(s.start(label, total))))
    }
}

/// One task's handle: advance it with [`Task::set`]; it finishes when [`Task::finish`] is
/// called or the last clone is dropped.
#[derive(Clone, Default)]
pub struct Task(Option<Arc<dyn ProgressDisplay>>);

impl fmt::Debug for Task {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() { "Task(shown)" } else { "Task(hidden)" })
    }
}

impl Task {
    /// Sets the steps done.
    pub fn set(&self, done: u64) {
        if let Some(d) = &self.0 {
            d.set(done);
        }
    }

    /// Ends the task.
    pub fn finish(&self) {
        if let Some(d) = &self.0 {
            d.finish();
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::sync::Mutex;

    /// A sink that records every call: `(label, total)` at start, then `set`/`finish` events.
    #[derive(Default)]
    pub(crate) struct Recorder(pub(crate) Arc<Mutex<Vec<String>>>);

    struct Line(Arc<Mutex<Vec<String>>>, String);

    impl ProgressSink for Recorder {
        fn start(&self, label: &str, total: u64) -> Box<dyn ProgressDisplay> {
            self.0.lock().unwrap().push(format!("start {label} {total}"));
            Box::new(Line(self.0.clone(), label.to_string()))
        }
    }

    impl ProgressDisplay for Line {
        fn set(&self, done: u64) {
            self.0.lock().unwrap().push(format!("set {} {done}", self.1));
        }
        fn finish(&self) {
            self.0.lock().unwrap().push(format!("finish {}", self.1));
        }
    }

    #[test]
    fn hidden_tasks_do_nothing_and_shown_tasks_reach_the_sink() {
        let t = Progress::hidden().task("x", 3);
        t.set(1);
        t.finish();
        assert_eq!(format!("{t:?}"), "Task(hidden)");
        let rec = Recorder::default();
        let log = rec.0.clone();
        let p = Progress::shown(Arc::new(rec));
        let t = p.task("sweep", 4);
        t.set(2);
        t.finish();
        assert_eq!(*log.lock().unwrap(), ["start sweep 4", "set sweep 2", "finish sweep"]);
    }
}
