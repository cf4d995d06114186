//! The study behind `robovec-gen --study` (issue 14): the thesis's study of seed §3.2, Table
//! 3.1, on robovec's topology families — 23, 50, 70, 100, 130 dof × serial, semi-serial,
//! parallel, direct dynamics (`dirdyna`) — run in process through the pass manager.
//!
//! Per case ([`run::run_case`]): ops, ASAP − ASAPCycle and number Y as generated (`atomise`),
//! after `atomise,zero-removal,balance` and after the best rewrite pipeline; placed cycles of
//! `place<pe=N>` at N = 8, 16, 32, 64 after the best pipeline; binary32 bits of error
//! (`accuracy<samples=K>`, mean and max over outputs and samples). Every figure comes from the
//! code behind `robovec-opt`'s `-stats` and report (`robovec_passes::summary::Figures`, the
//! placement's figures, the `accuracy` artifact's report entry), so it is what
//! `robovec-opt FILE.urdf -function=dirdyna -passes=PIPELINE -stats` prints for the URDF
//! `robovec-gen --topology T --dof N --seed S` writes (the tests check it through the binaries).
//!
//! # The best rewrite pipeline
//! [`DEFAULT_BEST`] = `atomise,zero-removal,cse,distribute,balance`. Rule: fewest placed
//! cycles summed over N = 8, 16, 32, 64, at binary32 error no worse than
//! `zero-removal,balance`'s. Measured on the 23-, 70- and 130-dof cases (9 cases, 100
//! samples; sums over the cases; the generator before `crate::origins`):
//!
//! | best pipeline candidate | ops | ASAPCycle | cycles N = 8 / 16 / 32 / 64 (sum) | f32 bits mean / max |
//! |---|---:|---:|---:|---:|
//! | `atomise,zero-removal,balance` (the thesis's rewrites, for reference) | 369 234 | 17 487 | 29 016 / 18 635 / 17 577 / 17 487 (82 715) | 0.88 / 22.2 |
//! | `atomise,cse,zero-removal,balance` | 335 205 | 17 487 | 26 192 / 18 024 / 17 502 / 17 487 (79 205) | 0.88 / 22.0 |
//! | `atomise,zero-removal,cse,distribute,balance` | 361 590 | 13 457 | 27 087 / 15 604 / 13 499 / 13 457 (69 647) | 0.88 / 22.0 |
//! | `atomise,zero-removal,cse,inline<max-uses=3>,balance` | 346 060 | 14 305 | 26 252 / 15 700 / 14 360 / 14 305 (70 617) | 0.88 / 21.4 |
//! | `atomise,zero-removal,cse,distribute,inline<max-uses=3>,balance` | 419 073 | 12 556 | 31 141 / 16 389 / 12 642 / 12 556 (72 728) | 0.88 / 21.4 |
//!
//! `cse` merges the repeated products of the generator's CRBA/RNEA (bit-exact); `distribute`
//! multiplies critical products of sums out (ops budget 1.5×; `max-growth=2` gives the same
//! IR) so that `balance` can reorder the terms: the critical path is 23% shorter than with
//! `cse,zero-removal,balance` for 8% more ops. Only at N = 8, where placement is bound by
//! ops / N, does the smaller IR of `cse,zero-removal,balance` place in fewer cycles (3%).
//! Adding `inline` shortens the critical path further but costs 16% more ops and 15% more
//! cycles at N = 8. `eqsat` windows were not measured on these sizes. `--best PIPELINE` runs
//! another pipeline.
//!
//! The cases are [`cases`], one case run through a pipeline session is [`run::run_case`], the
//! table [`table`]; this module runs every case in parallel with a progress bar and writes the
//! folder and its figures ([`figures`]). The robots and their equations come from
//! `robovec-dynamics` (the study's topology families and the generator); the study sits on the
//! driver's side, above the passes it runs.
//!
//! # Outputs
//! Without `--report-dir`, the markdown table ([`table::markdown`]) on stdout. With
//! `--report-dir DIR`, the folder written whole through [`crate::output::OutputSet`]
//! (temporary folder, one rename; refused when `DIR` is a file, a symbolic link or a folder
//! robovec did not write): `study.md` (the table, the thesis's rows beside it, the shape
//! comparison, the figures), `study.json`, `study.csv`, the study's SVG figures each with its
//! CSV ([`figures`]), and per case `cases/<dof>-<topology>/` with `-report-dir`'s content
//! (`report.json`, `report.md`, the seven SVGs; [`crate::report_dir::files`]) of the run
//! `BEST,accuracy<samples=K>,sweep<pe=8,16,32,64>,place<pe=8>` with `-pareto` of the three
//! pipelines. `--no-case-reports` leaves the per-case folders out (and their runs: the table
//! alone takes under a minute), and `study.md` then links to none; `docs/study/` is written so.
//!
//! Cases run in parallel (rayon); progress goes through [`crate::progress_bars`] (an
//! `indicatif` bar on a terminal without `-q`).

pub mod cases;
pub mod figures;
pub mod run;
pub mod table;

use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use robovec_dynamics::topology::Topology;

use crate::options::{output_failure, Failure};
use crate::output::OutputSet;
use run::{CaseResult, Plan};

/// The default best rewrite pipeline (see the module doc for the choice).
pub const DEFAULT_BEST: &str = "atomise,zero-removal,cse,distribute,balance";

/// The default N of the placements (N ADD + N MULTI PEs).
pub const DEFAULT_NS: [u32; 4] = [8, 16, 32, 64];

/// What `robovec-gen --study` was asked.
#[derive(Clone, Debug)]
pub struct Options {
    /// Degrees of freedom (default [`cases::THESIS_DOFS`]).
    pub dofs: Vec<usize>,
    /// Topology families (default all three).
    pub topologies: Vec<Topology>,
    /// Seed of the robots' parameters.
    pub seed: u64,
    /// `accuracy` samples per case.
    pub samples: u32,
    /// The best rewrite pipeline (from the parsed equations).
    pub best: String,
    /// N of the placements.
    pub ns: Vec<u32>,
    /// The report folder; the table goes to stdout without it.
    pub report_dir: Option<PathBuf>,
    /// With [`Options::report_dir`]: also write each case's full report under
    /// `cases/<dof>-<topology>/` (53 MB and 5–9 min for the 15 cases; `false`: the study-level
    /// files only, what `docs/study/` holds).
    pub case_reports: bool,
    /// No progress bar, no summary line on stderr.
    pub quiet: bool,
    /// The command line, for `study.md`.
    pub command: String,
}

/// Runs the study: every case, then the table on `stdout` or the folder.
///
/// # Errors
/// [`Failure::Usage`] for a best pipeline that does not parse or an empty case list;
/// [`Failure::Output`] when the folder is refused (checked before any work) or cannot be
/// written, or stdout fails; [`Failure::Input`] when a pass fails on a case.
pub fn run(
    opts: &Options,
    stderr_is_terminal: bool,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let best = run::manager(&opts.best)?.pipeline_text();
    if opts.dofs.is_empty() || opts.topologies.is_empty() || opts.ns.is_empty() {
        return Err(Failure::Usage("error: --study needs at least one dof, topology and N\n".into()));
    }
    if let Some(dir) = &opts.report_dir {
        crate::output::check_replaceable_folder(dir).map_err(output_failure)?;
    }
    let plan = Plan {
        seed: opts.seed,
        samples: opts.samples,
        best: best.clone(),
        ns: opts.ns.clone(),
        report: opts.report_dir.is_some() && opts.case_reports,
    };
    let list = cases::cases(&opts.dofs, &opts.topologies);
    let task =
        crate::progress_bars::progress_for(stderr_is_terminal, opts.quiet).task("study cases", list.len() as u64);
    let finished = AtomicU64::new(0);
    let t0 = Instant::now();
    // Largest cases first, so the parallel run does not end on one big case alone.
    let mut order: Vec<usize> = (0..list.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((list[i].dof, list[i].topology == Topology::Serial)));
    let mut done: Vec<(usize, Result<CaseResult, robovec_passes::whole_run::Failure>)> = order
        .par_iter()
        .map(|&i| {
            let r = run::run_case(&list[i], &plan);
            task.set(finished.fetch_add(1, Ordering::Relaxed) + 1);
            (i, r)
        })
        .collect();
    task.finish();
    done.sort_by_key(|(i, _)| *i);
    let results = done.into_iter().map(|(_, r)| r).collect::<Result<Vec<_>, _>>()?;
    let secs = t0.elapsed().as_secs_f64();
    match &opts.report_dir {
        None => {
            stdout
                .write_all(table::markdown(&results, &best).as_bytes())
                .and_then(|()| stdout.flush())
                .map_err(|e| Failure::Output(format!("error: cannot write to stdout: {e}\n")))?;
        }
        Some(dir) => {
            let files = folder_files(&results, opts, &best)?;
            let mut out = OutputSet::new();
            out.stage_folder(dir, &files).map_err(output_failure)?;
            out.commit().map_err(output_failure)?;
        }
    }
    if !opts.quiet {
        writeln!(stderr, "study: {} cases in {secs:.1} s", results.len())
            .map_err(|_| Failure::Output(String::new()))?;
    }
    Ok(())
}

/// The files of the study folder: `study.md`, `study.json`, `study.csv`, the figures and
/// their CSVs, then each case's report folder under `cases/<dof>-<topology>/`.
fn folder_files(results: &[CaseResult], opts: &Options, best: &str) -> Result<Vec<(String, Vec<u8>)>, Failure> {
    let figs = figures::all(results).map_err(|e| Failure::Output(format!("error: --study: {e}\n")))?;
    let captions: Vec<(&str, String)> = figs.iter().map(|f| (f.name, f.caption.clone())).collect();
    let mut files = vec![
        ("study.md".to_string(), table::study_md(results, best, &opts.command, &captions).into_bytes()),
        ("study.json".to_string(), table::json(results, opts.seed, opts.samples, best).into_bytes()),
        ("study.csv".to_string(), table::csv(results).into_bytes()),
    ];
    for f in figs {
        files.push((format!("{}.svg", f.name), f.svg.into_bytes()));
        files.push((format!("{}.csv", f.name), f.csv.into_bytes()));
    }
    for r in results {
        let Some((report, data)) = &r.report else { continue };
        let case = crate::report_dir::files(report, data)
            .map_err(|e| Failure::Output(format!("error: --study: {}: {e}\n", r.case.label())))?;
        for (name, bytes) in case {
            files.push((format!("cases/{}/{name}", r.case.slug()), bytes));
        }
    }
    Ok(files)
}
