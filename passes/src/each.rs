//! The per-function loop of a pass, written once: every function of the module in order, the
//! pass's `-time-limit` ticker read before each one, its work on the function, and the stop
//! note when the limit stops it (before a function, or inside one) — what each pass wrote by
//! hand with a ticker and [`PassContext::note_stop`] before.

use robovec_ir::{Function, Module};

use crate::{PassContext, Ticker};

/// How [`each_function`] reads the limit before a function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Before {
    /// [`Ticker::stopped`]: the pass's work ticks inside a function, so a stop is already known.
    Ticked,
    /// [`Ticker::check`]: the work does not tick per op (one linear sweep per function), so
    /// the clock is read between functions.
    Clock,
}

/// What the work on one function came to.
#[derive(Clone, Debug, PartialEq)]
pub enum Step<T> {
    /// Done, with its result.
    Done(T),
    /// Stopped inside by the limit; `what` says where and what was kept (`in @f after 3 of 9
    /// values (merges found kept)`); `kept` is the result of the part done, if any. The loop
    /// ends.
    Stopped {
        /// Where it stopped and what was kept.
        what: String,
        /// The result of the part done.
        kept: Option<T>,
    },
}

/// Runs `work` on every function of `m` in order (with its index `k` and the pass's ticker,
/// [`PassContext::ticker`]) and returns the results of the functions done, in order. Before each
/// function the limit is read as `before` says; when it is reached the loop ends with the note
/// `{pass} stopped {skipped(f, k)}: {reason}` (`skipped` names the function not started and the
/// `k` done: `before @g (1 functions done)`; `None`: the loop ends without a note, the stop
/// inside the previous function having said it); a [`Step::Stopped`] ends it with
/// `{pass} stopped {what}: {reason}`.
pub fn each_function<T>(
    m: &mut Module,
    cx: &mut PassContext,
    pass: &str,
    before: Before,
    skipped: impl Fn(&Function, usize) -> Option<String>,
    mut work: impl FnMut(&mut Function, usize, &Ticker) -> Step<T>,
) -> Vec<T> {
    let ticker = cx.ticker();
    let mut done = Vec::new();
    for (k, f) in m.functions.iter_mut().enumerate() {
        let reached = match before {
            Before::Ticked => ticker.stopped(),
            Before::Clock => ticker.check(),
        };
        if reached {
            if let Some(what) = skipped(f, k) {
                cx.note_stop(pass, &format!("{what}: {}", ticker.reason()));
            }
            break;
        }
        match work(f, k, &ticker) {
            Step::Done(t) => done.push(t),
            Step::Stopped { what, kept } => {
                done.extend(kept);
                cx.note_stop(pass, &format!("{what}: {}", ticker.reason()));
                break;
            }
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    fn module() -> Module {
        parse("func @f { input %a %x = %a + 1.0 output y = %x }\nfunc @g { input %a %x = %a * 2.0 output y = %x }\n")
            .unwrap()
    }

    #[test]
    fn every_function_is_worked_on_in_order_without_a_limit() {
        let mut m = module();
        let mut cx = PassContext::default();
        let names = each_function(
            &mut m,
            &mut cx,
            "p",
            Before::Ticked,
            |_, _| unreachable!(),
            |f, _, _| Step::Done(f.name.clone()),
        );
        assert_eq!(names, ["f", "g"]);
        assert!(cx.stopped().is_empty());
    }

    #[test]
    fn a_stop_inside_keeps_the_part_done_and_ends_the_loop_with_one_note() {
        let mut m = module();
        let mut cx = PassContext { tick_budget: Some(1), ..PassContext::default() };
        let done = each_function(
            &mut m,
            &mut cx,
            "p",
            Before::Ticked,
            |f, k| Some(format!("before @{} ({k} done)", f.name)),
            |f, _, t| {
                assert!(t.tick(), "the budget of one tick stops at once");
                Step::Stopped { what: format!("in @{} (half kept)", f.name), kept: Some(1) }
            },
        );
        assert_eq!(done, [1]);
        assert_eq!(cx.stopped(), ["p stopped in @f (half kept): tick budget of 1 steps reached"]);
    }

    #[test]
    fn a_limit_reached_before_a_function_names_it_and_what_was_done() {
        let mut m = module();
        let mut cx = PassContext { tick_budget: Some(2), ..PassContext::default() };
        let done = each_function(
            &mut m,
            &mut cx,
            "p",
            Before::Clock,
            |f, k| Some(format!("before @{} ({k} done)", f.name)),
            |f, _, _| Step::Done(f.name.clone()),
        );
        // `check` counts a tick: the first passes, the second reaches the budget of 2.
        assert_eq!(done, ["f"]);
        assert_eq!(cx.stopped(), ["p stopped before @g (1 done): tick budget of 2 steps reached"]);
        // Without a note for the function not started: the stop is the last one's to say.
        let mut cx = PassContext { tick_budget: Some(2), ..PassContext::default() };
        let done = each_function(
            &mut module(),
            &mut cx,
            "p",
            Before::Clock,
            |_, _| None,
            |f, _, _| Step::Done(f.name.clone()),
        );
        assert_eq!((done, cx.stopped()), (vec!["f".to_string()], Vec::<String>::new()));
    }
}
