//! The budget ladder (issue 48 item 6): the cost of `precision`'s formats against the error
//! budget, for `-report-dir`'s cost-against-budget figure.
//!
//! The chooser ([`super::choose()`]) runs again on one function at each relative budget of
//! [`BUDGETS`] (10⁻² … 10⁻¹⁰ of each output's largest magnitude over the domain, the same for
//! every output), with the target and the domain of the pipeline's last `precision` run on it
//! ([`PrecisionRun::target`], [`PrecisionRun::domain`]). Each point is the report `precision`
//! would write at that budget ([`PrecisionReport`]): the cost model's cost before and after
//! (the module doc of [`super`]: `c` counts ops, ½ per binary32 op; `mcu` estimates cycles — a
//! model, not a measurement), the values per format and the certified bound reached
//! (`max_rel_to_range`, never above the budget but for the outputs binary64 cannot keep within
//! it, named in `unreachable`).
//!
//! The function is the final IR's (its formats are ignored: the chooser starts from binary64),
//! enclosed once; each point is one search, about log₂(values) O(ops) sweeps, so the ladder
//! costs O(ops × log₂ values × [`BUDGETS`]). Under `-time-limit` it stops at the limit with
//! the points finished so far (a search the limit cuts is dropped: its cost is not the
//! search's) and a note ([`study`]).

use robovec_ir::domain::Domain;
use robovec_ir::{Function, Module};
use serde::Serialize;

use super::budget::Budget;
use super::{choose, PrecisionReport, PrecisionRun, Target};
use crate::range::{affine::DEFAULT_TERMS, enclose_with, EncloseError};
use crate::{PassContext, Ticker};

/// The relative budgets of the ladder, loosest first.
pub const BUDGETS: [f64; 9] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10];

/// The ladder of one function: the report's `precision_ladder`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BudgetLadder {
    /// The function.
    #[serde(skip)]
    pub function: String,
    /// `c` or `mcu`: the pipeline's `precision` target.
    pub target: &'static str,
    /// One point per budget of [`BUDGETS`] reached, in that order (`budget` is the point's
    /// relative budget).
    pub points: Vec<PrecisionReport>,
    /// Why the ladder has fewer points than [`BUDGETS`] (`-time-limit`), if it has.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// The formats chosen at each point (value, format; binary64 values not listed), for
    /// `-report-dir`'s measured time of each point's C.
    #[serde(skip)]
    pub assignments: Vec<Vec<(robovec_ir::Value, robovec_ir::format::Format)>>,
    /// `-report-dir`, target `c`: the median ns per state of the function's best binary64 C
    /// (every value binary64, the faster of `batch=4` and `batch=8`: the baseline each point's
    /// [`PrecisionReport::ns_per_state`] is measured against), when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub binary64_ns_per_state: Option<f64>,
    /// The `batch` of [`BudgetLadder::binary64_ns_per_state`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub binary64_batch: Option<u32>,
}

/// The ladder of `f` over `domain` for `target` at `budgets` (relative, one per point). The
/// ticker is read during the enclosure and before each sweep of each search: once it says stop,
/// the points finished are kept and [`BudgetLadder::stopped`] says where.
///
/// # Errors
/// A message (`@f: …`) when `f`'s values cannot be enclosed over `domain` (an input without a
/// range, a division by an interval holding 0) or bounded.
pub fn ladder(
    f: &Function,
    domain: &Domain,
    target: Target,
    budgets: &[f64],
    ticker: &Ticker,
) -> Result<BudgetLadder, String> {
    let mut out = BudgetLadder {
        function: f.name.clone(),
        target: target.as_str(),
        points: Vec::new(),
        stopped: None,
        assignments: Vec::new(),
        binary64_ns_per_state: None,
        binary64_batch: None,
    };
    let x = match enclose_with(f, domain, Some(DEFAULT_TERMS), || ticker.tick()) {
        Ok(x) => x,
        Err(e @ EncloseError::Stopped(_)) => {
            out.stopped = Some(format!("enclosing {}: {}", e.message(&f.name), ticker.reason()));
            return Ok(out);
        }
        Err(e) => return Err(e.message(&f.name)),
    };
    for (k, &b) in budgets.iter().enumerate() {
        let stop = || format!("after {k} of {} budgets of @{}: {}", budgets.len(), f.name, ticker.reason());
        if ticker.check() {
            out.stopped = Some(stop());
            break;
        }
        let c = choose(f, &x, &vec![Budget::Rel(b); f.outputs.len()], target, || ticker.tick())?;
        if c.stopped {
            out.stopped = Some(stop());
            break;
        }
        out.points.push(c.report(&f.name));
        out.assignments.push(c.formats.clone());
    }
    Ok(out)
}

/// The ladder of function `function` of `module` when the run's `precision` gave it formats
/// (its last [`PrecisionRun`] with a report of it: that run's target and domain), emitted into
/// `cx` as an artifact; nothing when no `precision` ran on it. `-time-limit` (`cx.deadline`,
/// and `cx.tick_budget` in tests) stops it as the module doc says, with a note in
/// `cx`'s early stops (`-report-dir: budget ladder stopped …`), keeping back the time of the
/// output's tail ([`crate::time_limit::kept_for`]); a function that cannot be
/// enclosed gets a note and no ladder (the figure is then not drawn).
pub fn study(module: &Module, cx: &mut PassContext, function: &str) {
    let Some(run) =
        cx.artifacts_of::<PrecisionRun>().filter(|r| r.functions.iter().any(|p| p.function == function)).last()
    else {
        return;
    };
    let Some(f) = module.function(function) else { return };
    let (target, domain) = (run.target, run.domain.clone());
    // Skippable work: it stops early enough for the output's tail, as the passes do.
    let kept = crate::time_limit::kept_for(crate::manager::module_ops(module));
    let ticker = Ticker::new(cx.deadline.map(|d| d.keeping(kept)), cx.tick_budget);
    match ladder(f, &domain, target, &BUDGETS, &ticker) {
        Ok(l) => {
            if let Some(why) = &l.stopped {
                cx.note_stop("-report-dir: budget ladder", why);
            }
            cx.emit(l);
        }
        Err(e) => cx.note_stop("-report-dir: budget ladder", &format!("before its first budget (not drawn): {e}")),
    }
}

impl crate::Artifact for BudgetLadder {
    fn pass(&self) -> &'static str {
        "-report-dir"
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        (function == self.function).then(|| crate::ReportEntry::new("precision_ladder", self, crate::Merge::Last))
    }
}
