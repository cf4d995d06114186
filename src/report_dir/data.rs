//! The report's numbers that `report.md` and the figures show, as the run made them: the final
//! IR's `stats` and `placement` (occupation, timeline), the `sweep` rows, the `pareto` rows,
//! the `accuracy` and `precision_ladder` of the reported function and the `stopped_early`
//! notes, taken from the run's artifacts and final figures as their own types ([`Stats`],
//! [`SweepRow`] of each [`SweepTable`], [`ParetoRow`] of the [`ParetoRun`], the final IR's
//! [`PlacementReport`], the last [`AccuracyReport`], the [`BudgetLadder`]), the same values the report JSON holds under the same keys (SPEC
//! §7; the report writes them from these types, `tests/report_dir.rs` checks the figures' CSVs
//! against the JSON). Nothing is parsed back.

use robovec_passes::accuracy::report::{AccuracyReport, AccuracyRun};
use robovec_passes::place::report::PlacementReport;
use robovec_passes::precision::ladder::BudgetLadder;
use robovec_passes::summary::{Figures, Stats};
use robovec_passes::sweep::{SweepRow, SweepTable};
use robovec_passes::whole_run::pareto::{ParetoRow, ParetoRun};
use robovec_passes::PassContext;

/// What the figures draw, read from one report.
#[derive(Clone, Debug)]
pub struct ReportData {
    /// Model name: the input file's stem.
    pub model: String,
    /// The reported function.
    pub function: String,
    /// The pipeline.
    pub pipeline: String,
    /// The input as given (the report's `input`).
    pub input: String,
    /// The final IR's `stats`.
    pub stats: Stats,
    /// A `sweep` ran (the report has a `sweep` key, its rows for the function maybe none).
    pub swept: bool,
    /// `sweep` rows (empty without a sweep).
    pub sweep: Vec<SweepRow>,
    /// `placement`, when the final IR is placed.
    pub placement: Option<PlacementReport>,
    /// `pareto` rows (empty without `-pareto`).
    pub pareto: Vec<ParetoRow>,
    /// The last `accuracy` measurement of the function, if any.
    pub accuracy: Option<AccuracyReport>,
    /// The report's `precision_ladder`: the cost of `precision`'s formats at each budget of
    /// [`robovec_passes::precision::ladder::BUDGETS`], computed for `-report-dir` when the
    /// pipeline's `precision` gave the function formats ([`robovec_passes::precision::ladder::study`]).
    pub precision_ladder: Option<BudgetLadder>,
    /// The reported function's C timed on this machine when it was swept
    /// ([`crate::report_dir::cpu_line`]).
    pub cpu: Option<crate::report_dir::cpu_line::CpuTimes>,
    /// The early stops of the run (`stopped_early`), in order.
    pub stopped_early: Vec<String>,
}

impl ReportData {
    /// What the figures of the report of `own.function` draw after a run of `pipeline` on
    /// `input` with context `cx`: every `sweep` row of the function in the order measured
    /// (the report's `sweep`, appended run after run), the last `-pareto` study of it (the
    /// report's `pareto`), its last `accuracy` measurement, the run's early stops and the final
    /// IR's stats and placement figures.
    pub fn of(input: &str, pipeline: &str, own: &Figures, cx: &PassContext) -> ReportData {
        let model = std::path::Path::new(input)
            .file_stem()
            .map_or_else(|| input.to_string(), |s| s.to_string_lossy().into_owned());
        let function = own.function.clone();
        let sweep = cx
            .artifacts_of::<SweepTable>()
            .flat_map(|t| t.rows.iter().filter(|r| r.function == function))
            .cloned()
            .collect();
        let pareto = cx
            .artifacts_of::<ParetoRun>()
            .filter(|p| p.function == function)
            .last()
            .map(|p| p.rows.clone())
            .unwrap_or_default();
        let precision_ladder = cx.artifacts_of::<BudgetLadder>().filter(|l| l.function == function).last().cloned();
        let cpu = cx
            .artifacts_of::<crate::report_dir::cpu_line::CpuTimes>()
            .filter(|c| c.function == function)
            .last()
            .cloned();
        let accuracy = cx
            .artifacts_of::<AccuracyRun>()
            .filter_map(|a| a.reports.iter().rev().find(|r| r.function == function))
            .last()
            .cloned();
        ReportData {
            model,
            pipeline: pipeline.to_string(),
            input: input.to_string(),
            stats: own.stats.clone(),
            swept: cx.artifacts_of::<SweepTable>().next().is_some(),
            sweep,
            placement: own.placement.clone(),
            pareto,
            accuracy,
            precision_ladder,
            cpu,
            stopped_early: cx.stopped(),
            function,
        }
    }
}
