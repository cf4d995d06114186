//! `sweep<pe=1,2,4,8,16,32,64>`: places every function at each N with the seed's algorithm —
//! classical and mobility priority (preferential selection), naive selection (classical) — and
//! with robovec's forward-backward improvement (`classical+fbi`), and records
//! the seed's study figures per run: cycles against the lower-bound curves and Y (seed §3.3,
//! Table 2.2), parallelisation rate (§3.4) and PE memory / buffer words per PE type (Fig.
//! 2.4–2.7). The function is unchanged; the rows go to the report (`sweep`), the `-stats`
//! table and `-sweep-csv`.
//!
//! Every placement of a sweep is executed by the simulator (`sim`) in f32 and f64 and must
//! reproduce the interpreter bit for bit; a failure stops the pipeline.
//!
//! Placements use the pipeline's latencies (the target's, or those a pass before gave
//! explicitly, `PassContext::latencies_for`) and the target's write ports. Each row also gives
//! `us` (cycles at the target's clock), `states` and `ns_per_state` (the time per state of a
//! function of several states, `interleave`), and the analytic resource estimate
//! (`robovec_machine::target::Target::estimate`; `fits` also needs the placement's memories within
//! the target's). A second artifact, [`SweepFit`] (report `sweep_fit`, lines after the table),
//! names per function the smallest N whose placement reaches the critical path (cycles =
//! largest ASAPCycle, in any configuration) and the smallest and largest N of the sweep that
//! fit the device (in any configuration); `null` when none does.

use robovec_ir::analysis::compute_timing;
use robovec_ir::Module;

use crate::params::ParamKind;
use crate::place::{
    cycles, lower_bound, ops_per_side, tight_lower_bound, try_place_function_within, PlaceError, PlaceOptions,
    Priority, Select,
};
use crate::sim::{SimError, SimErrorKind};
use crate::{
    try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker,
};

/// min / mean / max of words over the PEs of one type.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct WordStats {
    /// Smallest memory, words.
    pub min: u32,
    /// Mean, words.
    pub mean: f64,
    /// Largest memory, words.
    pub max: u32,
}

fn word_stats(w: &[u32]) -> WordStats {
    if w.is_empty() {
        return WordStats::default();
    }
    WordStats {
        min: *w.iter().min().expect("non-empty"),
        mean: w.iter().map(|&x| x as f64).sum::<f64>() / w.len() as f64,
        max: *w.iter().max().expect("non-empty"),
    }
}

/// One placement of a sweep: a row of the report's `sweep` (written, and read back for
/// `-report-dir`'s figures), the `-stats` table and `-sweep-csv`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SweepRow {
    /// Function name.
    pub function: String,
    /// N: ADD PEs = MULTI PEs.
    pub n: u32,
    /// `classical`, `mobility` (the seed's list scheduling alone) or `classical+fbi` (with
    /// forward-backward improvement).
    pub priority: String,
    /// `naive` or `preferential`.
    pub select: String,
    /// Cycles of the placement.
    pub cycles: u32,
    /// `cycles` in µs at the target's clock (the latency of one evaluation).
    pub us: f64,
    /// States one evaluation computes (`Function::states`: K after `interleave<states=K>`).
    #[serde(default = "one_state")]
    pub states: u32,
    /// ns per state: `cycles / clock_mhz · 1000 / states` (issue 49 item 3).
    #[serde(default)]
    pub ns_per_state: f64,
    /// SPEC §4 lower bound, cycles.
    pub lower_bound: u32,
    /// The tighter bound of [`crate::place::tight_lower_bound`] (no placement beats it either),
    /// cycles.
    pub tight_lower_bound: u32,
    /// First lower-bound curve of seed §3.3 (100% parallelisation): max over the PE types of
    /// ⌈ops of the type / N⌉ − 1 + latency, cycles.
    pub resource_bound: u32,
    /// Second curve: the critical path (largest ASAPCycle), cycles.
    pub critical_path: u32,
    /// Number Y = ops / critical path (seed §3.2).
    pub y: f64,
    /// ops / (cycles × 2N).
    pub parallelisation_rate: f64,
    /// PE memory words over the ADD PEs.
    pub pe_words_add: WordStats,
    /// PE memory words over the MULTI PEs.
    pub pe_words_mul: WordStats,
    /// Buffer words over the ADD PEs.
    pub buffer_words_add: WordStats,
    /// Buffer words over the MULTI PEs.
    pub buffer_words_mul: WordStats,
    /// Direct writes.
    pub writes_direct: u64,
    /// Indirect writes.
    pub writes_indirect: u64,
    /// add/sub latency of the placement, cycles.
    pub lat_add: u32,
    /// mul latency of the placement, cycles.
    pub lat_mul: u32,
    /// Estimated ALM ([`robovec_machine::target::Target::estimate`]).
    pub alm: u32,
    /// Estimated M10K blocks.
    pub m10k: u32,
    /// Estimated DSP blocks.
    pub dsp: u32,
    /// True when the estimate is within the device's capacity and the placement's memories
    /// within the target's (`place::report::fits_memories`).
    pub fits: bool,
}

/// The default of [`SweepRow::states`] (a report written before it).
fn one_state() -> u32 {
    1
}

impl SweepRow {
    /// The configuration's label: `classical`, `mobility`, `classical/naive`, `classical+fbi`
    /// (the priority, with the selection when it is not the preferential one).
    pub fn config(&self) -> String {
        if self.select == "preferential" {
            self.priority.clone()
        } else {
            format!("{}/{}", self.priority, self.select)
        }
    }
}

/// What a sweep says of one function on the target: see the module doc.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FitRow {
    /// Function name.
    pub function: String,
    /// The target's name.
    pub target: String,
    /// Critical path (largest ASAPCycle), cycles.
    pub critical_path: u32,
    /// Smallest N of the sweep whose placement reaches the critical path (any configuration).
    pub n_critical_path: Option<u32>,
    /// Smallest N of the sweep that fits the device (any configuration).
    pub n_fits_min: Option<u32>,
    /// Largest N of the sweep that fits the device (any configuration).
    pub n_fits_max: Option<u32>,
    /// Fewest cycles of the sweep and its N (smallest N on ties).
    pub best_cycles: Option<u32>,
    /// N of `best_cycles`.
    pub n_best: Option<u32>,
    /// `best_cycles` in µs at the target's clock.
    pub best_us: Option<f64>,
}

/// The [`FitRow`]s of one `sweep` run: report `sweep_fit`, lines on stderr after the table.
#[derive(Clone, Debug)]
pub struct SweepFit {
    /// One per function swept.
    pub rows: Vec<FitRow>,
}

impl crate::Artifact for SweepFit {
    fn pass(&self) -> &'static str {
        "sweep"
    }

    fn log_text(&self, _detail: bool) -> String {
        let n = |x: Option<u32>| x.map_or("none".to_string(), |n| format!("N = {n}"));
        self.rows
            .iter()
            .map(|r| {
                format!(
                    "sweep @{} on {}: critical path {} cycles reached from {}; fits the device from {} to {}; \
                     fewest cycles {} ({}, {})\n",
                    r.function,
                    r.target,
                    r.critical_path,
                    n(r.n_critical_path),
                    n(r.n_fits_min),
                    n(r.n_fits_max),
                    r.best_cycles.map_or("-".to_string(), |c| c.to_string()),
                    n(r.n_best),
                    r.best_us.map_or("-".to_string(), |u| format!("{u:.3} µs"))
                )
            })
            .collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let rows: Vec<&FitRow> = self.rows.iter().filter(|r| r.function == function).collect();
        Some(crate::ReportEntry::new("sweep_fit", &rows, crate::Merge::Append))
    }
}

/// The [`FitRow`] of `function` from its rows.
fn fit_row(function: &str, target: &robovec_machine::target::Target, critical_path: u32, rows: &[SweepRow]) -> FitRow {
    let mine = || rows.iter().filter(|r| r.function == function);
    let n_critical_path = mine().filter(|r| r.cycles <= critical_path).map(|r| r.n).min();
    let n_fits_min = mine().filter(|r| r.fits).map(|r| r.n).min();
    let n_fits_max = mine().filter(|r| r.fits).map(|r| r.n).max();
    let best = mine().min_by_key(|r| (r.cycles, r.n));
    FitRow {
        function: function.to_string(),
        target: target.name.clone(),
        critical_path,
        n_critical_path,
        n_fits_min,
        n_fits_max,
        best_cycles: best.map(|r| r.cycles),
        n_best: best.map(|r| r.n),
        best_us: best.map(|r| target.us(r.cycles)),
    }
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "sweep",
    doc: "place at several N (classical/mobility, naive/preferential), simulate each, tabulate the seed's study",
    params: &[ParamInfo {
        name: "pe",
        kind: ParamKind::U32List { default: "1,2,4,8,16,32,64", min: 1, max: 4096 },
        doc: "values of N, comma-separated",
    }],
    build: |p: &Params| Ok(Box::new(Sweep { ns: p.u32_list("pe")? })),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        formats: true,
        csv_table: true,
        ..crate::Props::DEFAULT
    },
};

/// The `sweep` pass.
#[derive(Debug)]
pub struct Sweep {
    /// Values of N.
    pub ns: Vec<u32>,
}

impl Pass for Sweep {
    fn name(&self) -> &'static str {
        "sweep"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        // The seed's algorithm alone (improve = 0) for the Table 2.2 / Fig. 2.4–2.7 comparisons,
        // then robovec's default (forward-backward improvement).
        let configs = [
            (Priority::Classical, Select::Preferential, 0, "classical", "preferential"),
            (Priority::Mobility, Select::Preferential, 0, "mobility", "preferential"),
            (Priority::Classical, Select::Naive, 0, "classical", "naive"),
            (Priority::Classical, Select::Preferential, 2, "classical+fbi", "preferential"),
        ];
        let total = m.functions.len() * self.ns.len() * configs.len();
        let mut done = 0usize;
        let task = cx.progress.task("sweep: placements", total as u64);
        let (deadline, tick_budget, latencies, target) = (cx.deadline, cx.tick_budget, cx.latencies, cx.target.clone());
        let domain = cx.domain.clone();
        // A stop (before a configuration, or inside one, which is dropped) ends the sweep with the
        // rows done and the fit of the function it stopped in.
        let per_function = try_each_function(
            m,
            cx,
            "sweep",
            AtTimeLimit::Skip,
            Before::Ticked,
            |_, _| None,
            |f, _, _| {
                // a function on fixed-point PEs (issue 49): their latencies and units
                let latencies = crate::function_latencies(&target, f, latencies, &crate::LatencyOverride::default());
                let target = crate::place::report::units_of(f, &target);
                let word_bits = crate::place::report::word_bits_of(f);
                let ops = f.op_counts().total;
                let cp_now = compute_timing(f, &latencies).1.asap_cycle;
                let (n_add_side, n_mul) = ops_per_side(f);
                let mut rows = Vec::new();
                for &n in &self.ns {
                    for (priority, select, improve, pname, sname) in configs {
                        if deadline.is_some_and(|d| d.reached()) {
                            let fit = fit_row(&f.name, &target, cp_now, &rows);
                            return Ok(Step::Stopped {
                                what: format!("after {done} of {total} configurations"),
                                kept: Some((rows, fit)),
                            });
                        }
                        done += 1;
                        let mut o = PlaceOptions::with_pes(n);
                        // A configuration the limit reaches is dropped (its placement or its
                        // simulation stops inside): sweep is skippable, so no grace.
                        (o.deadline, o.grace, o.tick_budget) = (deadline, deadline, tick_budget);
                        o.arch.lat = latencies;
                        o.arch.writes = target.writes;
                        o.priority = priority;
                        o.select = select;
                        o.improve = improve;
                        if improve == 0 {
                            // The seed's algorithm alone: no restarts or search either.
                            (o.restarts, o.search) = (0, 0);
                        }
                        let ticker = Ticker::new(deadline, tick_budget);
                        let verified = match try_place_function_within(f, &o) {
                            Ok((p, _)) => crate::sim::verify_in(f, &p, &[1], domain.as_ref(), &ticker).map(|_| p),
                            Err(PlaceError::Stopped) => Err(SimError::stopped()),
                            Err(e @ (PlaceError::Stuck(_) | PlaceError::Partition(_))) => {
                                return Err(PassError::Failed { pass: "sweep".into(), message: e.to_string() })
                            }
                        };
                        let p = match verified {
                            Ok(p) => p,
                            Err(e) if e.kind == SimErrorKind::Stopped => {
                                let what = format!(
                                "in N={n} {pname}/{sname} of @{} ({} of {total} configurations done, that one dropped)",
                                f.name,
                                done - 1,
                            );
                                let fit = fit_row(&f.name, &target, cp_now, &rows);
                                return Ok(Step::Stopped { what, kept: Some((rows, fit)) });
                            }
                            Err(e) => {
                                return Err(PassError::Failed {
                                    pass: "sweep".into(),
                                    message: format!("@{} N={n} {pname}/{sname}: simulation failed: {e}", f.name),
                                })
                            }
                        };
                        let p = &p;
                        let c = cycles(f, p);
                        let (_, cp) = compute_timing(f, &o.arch.lat);
                        let side = |k: u64, lat: u32| if k == 0 { 0 } else { (k.div_ceil(n as u64) - 1) as u32 + lat };
                        let na = n as usize;
                        let indirect = p.writes.iter().filter(|w| w.buffer_addr.is_some()).count() as u64;
                        let est = crate::place::report::estimate(p, c, &target, word_bits);
                        rows.push(SweepRow {
                            function: f.name.clone(),
                            n,
                            priority: pname.to_string(),
                            select: sname.to_string(),
                            cycles: c,
                            us: target.us(c),
                            states: f.states,
                            ns_per_state: crate::place::report::ns_per_state(c, target.clock_mhz, f.states),
                            lower_bound: lower_bound(f, &o.arch),
                            tight_lower_bound: tight_lower_bound(f, &o.arch),
                            resource_bound: side(n_add_side, o.arch.lat.add).max(side(n_mul, o.arch.lat.mul)),
                            critical_path: cp.asap_cycle,
                            y: if cp.asap_cycle == 0 { 0.0 } else { ops as f64 / cp.asap_cycle as f64 },
                            parallelisation_rate: if c == 0 { 0.0 } else { ops as f64 / (c as f64 * 2.0 * n as f64) },
                            pe_words_add: word_stats(&p.pe_words[..na]),
                            pe_words_mul: word_stats(&p.pe_words[na..]),
                            buffer_words_add: word_stats(&p.buffer_words[..na]),
                            buffer_words_mul: word_stats(&p.buffer_words[na..]),
                            writes_direct: p.writes.len() as u64 - indirect,
                            writes_indirect: indirect,
                            lat_add: o.arch.lat.add,
                            lat_mul: o.arch.lat.mul,
                            alm: est.alm,
                            m10k: est.m10k,
                            dsp: est.dsp,
                            fits: est.fits,
                        });
                        task.set(done as u64);
                    }
                }
                let fit = fit_row(&f.name, &target, cp_now, &rows);
                Ok(Step::Done((rows, fit)))
            },
        )?;
        task.finish();
        let (rows, fit): (Vec<Vec<SweepRow>>, Vec<FitRow>) = per_function.into_iter().unzip();
        cx.emit(SweepTable { rows: rows.into_iter().flatten().collect() });
        cx.emit(SweepFit { rows: fit });
        Ok(())
    }
}

/// What one `sweep` run measured: its rows, printed as a table on stderr, written as CSV with
/// `-sweep-csv`, and listed in the report's `sweep` (rows of the reported function).
#[derive(Clone, Debug)]
pub struct SweepTable {
    /// One row per function, N and configuration, in the order measured.
    pub rows: Vec<SweepRow>,
}

impl crate::Artifact for SweepTable {
    fn pass(&self) -> &'static str {
        "sweep"
    }

    fn log_text(&self, _detail: bool) -> String {
        if self.rows.is_empty() {
            String::new()
        } else {
            to_table(&self.rows)
        }
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let rows: Vec<&SweepRow> = self.rows.iter().filter(|r| r.function == function).collect();
        Some(crate::ReportEntry::new("sweep", &rows, crate::Merge::Append))
    }

    fn csv(&self) -> Option<String> {
        Some(to_csv(&self.rows))
    }
}

/// The rows as CSV (header line first).
pub fn to_csv(rows: &[SweepRow]) -> String {
    let mut s = String::from(
        "function,n,priority,select,cycles,lower_bound,resource_bound,critical_path,y,parallelisation_rate,\
         pe_words_add_min,pe_words_add_mean,pe_words_add_max,pe_words_mul_min,pe_words_mul_mean,pe_words_mul_max,\
         buffer_words_add_min,buffer_words_add_mean,buffer_words_add_max,buffer_words_mul_min,buffer_words_mul_mean,\
         buffer_words_mul_max,writes_direct,writes_indirect,tight_lower_bound,us,lat_add,lat_mul,alm,m10k,dsp,fits,states,ns_per_state\n",
    );
    for r in rows {
        let w = |x: &WordStats| format!("{},{:.2},{}", x.min, x.mean, x.max);
        s += &format!(
            "{},{},{},{},{},{},{},{},{:.3},{:.4},{},{},{},{},{},{},{},{:.6},{},{},{},{},{},{},{},{:.3}\n",
            r.function,
            r.n,
            r.priority,
            r.select,
            r.cycles,
            r.lower_bound,
            r.resource_bound,
            r.critical_path,
            r.y,
            r.parallelisation_rate,
            w(&r.pe_words_add),
            w(&r.pe_words_mul),
            w(&r.buffer_words_add),
            w(&r.buffer_words_mul),
            r.writes_direct,
            r.writes_indirect,
            r.tight_lower_bound,
            r.us,
            r.lat_add,
            r.lat_mul,
            r.alm,
            r.m10k,
            r.dsp,
            r.fits,
            r.states,
            r.ns_per_state
        );
    }
    s
}

/// The rows as a text table (Table 2.2 style: one line per N and configuration).
pub fn to_table(rows: &[SweepRow]) -> String {
    let mut s = format!(
        "{:<10} {:>4} {:<13} {:<12} {:>8} {:>8} {:>7} {:>8} {:>7} {:>8} {:>8} {:>6} {:>15} {:>15} {:>13} {:>13} {:>9} {:>4}\n",
        "function",
        "N",
        "priority",
        "select",
        "cycles",
        "LB",
        "c/LB",
        "tightLB",
        "c/tLB",
        "res.bnd",
        "crit.p",
        "par.",
        "PE words ADD",
        "PE words MUL",
        "buffer ADD",
        "buffer MUL",
        "µs",
        "fits"
    );
    for r in rows {
        let w = |x: &WordStats| format!("{}/{:.0}/{}", x.min, x.mean, x.max);
        s += &format!(
            "{:<10} {:>4} {:<13} {:<12} {:>8} {:>8} {:>7.3} {:>8} {:>7.3} {:>8} {:>8} {:>6.3} {:>15} {:>15} {:>13} {:>13} {:>9.3} {:>4}\n",
            r.function,
            r.n,
            r.priority,
            r.select,
            r.cycles,
            r.lower_bound,
            r.cycles as f64 / r.lower_bound.max(1) as f64,
            r.tight_lower_bound,
            r.cycles as f64 / r.tight_lower_bound.max(1) as f64,
            r.resource_bound,
            r.critical_path,
            r.parallelisation_rate,
            w(&r.pe_words_add),
            w(&r.pe_words_mul),
            w(&r.buffer_words_add),
            w(&r.buffer_words_mul),
            r.us,
            if r.fits { "yes" } else { "no" }
        );
    }
    s
}
