//! The per-function loop of a pass, written once: every function of the module in order, the
//! pass's `-time-limit` ticker read before each one, its work on the function, and the stop
//! note when the limit stops it (before a function, or inside one) — what each pass wrote by
//! hand with a ticker and [`PassContext::note_stop`] before. [`each_function`] is the loop of a
//! pass the limit may skip; [`try_each_function`] that of any pass (a required one, whose stop
//! is its error, or one whose work may fail). Every pass that loops over the functions uses
//! them; the C back end writes one file for the module (its statements tick one ticker).

use robovec_ir::{Function, Module};

use crate::time_limit::TickerError;
use crate::{AtTimeLimit, PassContext, PassError, Ticker};

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
    /// ends; in a required pass ([`AtTimeLimit::Required`]) this is the pass's
    /// [`PassError::TimeLimit`] and `kept` is dropped.
    Stopped {
        /// Where it stopped and what was kept.
        what: String,
        /// The result of the part done.
        kept: Option<T>,
    },
    /// Cut short, its `result` kept, and the loop goes on: the function's own budget was
    /// reached (`eqsat`'s e-nodes per function), or the limit reached the part of a required
    /// pass's work the output can do without (`place`'s improvement after its first
    /// schedule). `note` is the whole stop line after the pass's name, its reason included
    /// (`stopped searching @f early (best schedule so far kept): time limit of 1 s reached`).
    Cut {
        /// The stop note, reason included.
        note: String,
        /// The function's result.
        result: T,
    },
}

/// Runs `work` on every function of `m` in order (with its index `k` and the pass's ticker,
/// [`PassContext::ticker`]) and returns the results of the functions done, in order: the loop
/// of a pass the limit may skip ([`AtTimeLimit::Skip`]) whose work cannot fail otherwise. Before
/// each function the limit is read as `before` says; when it is reached the loop ends with the
/// note `{pass} stopped {skipped(f, k)}: {reason}` (`skipped` names the function not started and
/// the `k` done: `before @g (1 functions done)`; `None`: the loop ends without a note, the stop
/// inside the previous function having said it); a [`Step::Stopped`] ends it with
/// `{pass} stopped {what}: {reason}`; a [`Step::Cut`] adds its note and goes on.
pub fn each_function<T>(
    m: &mut Module,
    cx: &mut PassContext,
    pass: &str,
    before: Before,
    skipped: impl Fn(&Function, usize) -> Option<String>,
    mut work: impl FnMut(&mut Function, usize, &Ticker) -> Step<T>,
) -> Vec<T> {
    match try_each_function(m, cx, pass, AtTimeLimit::Skip, before, skipped, |f, k, t| Ok(work(f, k, t))) {
        Ok(done) => done,
        Err(e) => unreachable!("a skippable loop whose work cannot fail does not fail: {e}"),
    }
}

/// [`each_function`] for any pass: `at` is the pass's `-time-limit` policy and `work` may fail
/// (its error ends the loop and is returned as it is).
///
/// - [`AtTimeLimit::Skip`]: as [`each_function`].
/// - [`AtTimeLimit::Required`] (the output needs every function's result; the ticker reads the
///   limit's grace): a limit reached before a function, or a [`Step::Stopped`], is the pass's
///   [`PassError::TimeLimit`] (`pass \`dce\`: … stopped before @g (1 functions done); the
///   output needs it, so nothing is written`; `skipped` gives the place, `None` the default
///   `before @g (K functions done)`); a [`Step::Cut`] adds its note and goes on.
///
/// # Errors
/// The work's own error, or the [`PassError::TimeLimit`] of a required pass.
pub fn try_each_function<T>(
    m: &mut Module,
    cx: &mut PassContext,
    pass: &str,
    at: AtTimeLimit,
    before: Before,
    skipped: impl Fn(&Function, usize) -> Option<String>,
    mut work: impl FnMut(&mut Function, usize, &Ticker) -> Result<Step<T>, PassError>,
) -> Result<Vec<T>, PassError> {
    let ticker = cx.ticker();
    let mut done = Vec::new();
    for (k, f) in m.functions.iter_mut().enumerate() {
        let reached = match before {
            Before::Ticked => ticker.stopped(),
            Before::Clock => ticker.check(),
        };
        if reached {
            let what = skipped(f, k);
            if at == AtTimeLimit::Required {
                let what = what.unwrap_or_else(|| format!("before @{} ({k} functions done)", f.name));
                return Err(ticker.error(pass, &what));
            }
            if let Some(what) = what {
                cx.note_stop(pass, &format!("{what}: {}", ticker.reason()));
            }
            break;
        }
        match work(f, k, &ticker)? {
            Step::Done(t) => done.push(t),
            Step::Cut { note, result } => {
                done.push(result);
                cx.note_stop(pass, &note);
            }
            Step::Stopped { what, .. } if at == AtTimeLimit::Required => return Err(ticker.error(pass, &what)),
            Step::Stopped { what, kept } => {
                done.extend(kept);
                cx.note_stop(pass, &format!("{what}: {}", ticker.reason()));
                break;
            }
        }
    }
    Ok(done)
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

    #[test]
    fn a_required_pass_stopped_before_or_inside_a_function_fails_with_nothing_kept() {
        let required = |budget, inside: bool| {
            let mut cx = PassContext { tick_budget: Some(budget), ..PassContext::default() };
            let r = try_each_function(
                &mut module(),
                &mut cx,
                "p",
                AtTimeLimit::Required,
                Before::Clock,
                |_, _| None,
                |f, _, t| {
                    Ok(match inside && t.tick() {
                        true => Step::Stopped { what: format!("in @{}", f.name), kept: Some(f.name.clone()) },
                        false => Step::Done(f.name.clone()),
                    })
                },
            );
            (r.map_err(|e| e.to_string()), cx.stopped())
        };
        // The clock read before @g reaches the budget of 2: the default place names it.
        let (r, notes) = required(2, false);
        assert_eq!(
            r.unwrap_err(),
            "pass `p`: tick budget of 2 steps reached: stopped before @g (1 functions done); the output needs it, \
             so nothing is written"
        );
        assert!(notes.is_empty(), "a required pass's stop is its error, not a note: {notes:?}");
        // A stop inside @f (the check before it is tick 1, the work's tick 2): its error.
        let (r, _) = required(2, true);
        assert!(r.unwrap_err().contains("stopped in @f; the output needs it"));
        // Without a limit: every function's result.
        assert_eq!(required(u64::MAX, true).0.unwrap(), ["f", "g"]);
    }

    #[test]
    fn a_cut_function_keeps_its_result_and_the_loop_goes_on() {
        for at in [AtTimeLimit::Skip, AtTimeLimit::Required] {
            let mut cx = PassContext::default();
            let done = try_each_function(
                &mut module(),
                &mut cx,
                "p",
                at,
                Before::Ticked,
                |_, _| None,
                |f, k, _| {
                    Ok(match k {
                        0 => Step::Cut { note: format!("searching @{} early: own budget", f.name), result: k },
                        _ => Step::Done(k),
                    })
                },
            )
            .unwrap();
            assert_eq!(done, [0, 1], "{at:?}");
            assert_eq!(cx.stopped(), ["p stopped searching @f early: own budget"], "{at:?}");
        }
    }

    #[test]
    fn the_works_own_error_ends_the_loop_as_it_is() {
        let mut cx = PassContext::default();
        let mut seen = Vec::new();
        let r: Result<Vec<()>, _> = try_each_function(
            &mut module(),
            &mut cx,
            "p",
            AtTimeLimit::Skip,
            Before::Clock,
            |_, _| None,
            |f, _, _| {
                seen.push(f.name.clone());
                Err(PassError::Failed { pass: "p".into(), message: format!("@{} is wrong", f.name) })
            },
        );
        assert_eq!(r.unwrap_err().to_string(), "pass `p`: @f is wrong");
        assert_eq!(seen, ["f"]);
    }
}
