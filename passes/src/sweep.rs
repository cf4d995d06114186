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

use robovec_ir::analysis::compute_timing;
use robovec_ir::{Module, Phase};

use crate::params::ParamKind;
use crate::place::{
    cycles, lower_bound, ops_per_side, tight_lower_bound, try_place_function, PlaceOptions, Priority, Select,
};
use crate::{ParamInfo, Params, Pass, PassContext, PassError, PassInfo};

/// min / mean / max of words over the PEs of one type.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
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

/// One placement of a sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepRow {
    /// Function name.
    pub function: String,
    /// N: ADD PEs = MULTI PEs.
    pub n: u32,
    /// `classical`, `mobility` (the seed's list scheduling alone) or `classical+fbi` (with
    /// forward-backward improvement).
    pub priority: &'static str,
    /// `naive` or `preferential`.
    pub select: &'static str,
    /// Cycles of the placement.
    pub cycles: u32,
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

    fn requires(&self) -> Option<Phase> {
        Some(Phase::Atomised)
    }

    fn preserves_timing(&self) -> bool {
        true
    }

    fn makes_csv_table(&self) -> bool {
        true
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
        let mut rows = Vec::new();
        for f in &m.functions {
            let ops = f.op_counts().total;
            let (n_add_side, n_mul) = ops_per_side(f);
            for &n in &self.ns {
                for (priority, select, improve, pname, sname) in configs {
                    if let Some(d) = cx.deadline.filter(|d| d.reached()) {
                        cx.note_stop("sweep", &format!("after {done} of {total} configurations: {}", d.reason()));
                        cx.emit(SweepTable { rows });
                        return Ok(());
                    }
                    done += 1;
                    let mut o = PlaceOptions::with_pes(n);
                    o.deadline = cx.deadline;
                    o.arch.lat = cx.latencies;
                    o.priority = priority;
                    o.select = select;
                    o.improve = improve;
                    if improve == 0 {
                        // The seed's algorithm alone: no restarts or search either.
                        (o.restarts, o.search) = (0, 0);
                    }
                    let p = try_place_function(f, &o)
                        .map_err(|e| PassError::Failed { pass: "sweep".into(), message: e })?;
                    let mut placed = f.clone();
                    placed.placement = Some(p);
                    crate::sim::verify_placement(&placed, &[1]).map_err(|e| PassError::Failed {
                        pass: "sweep".into(),
                        message: format!("@{} N={n} {pname}/{sname}: simulation failed: {e}", f.name),
                    })?;
                    let p = placed.placement.as_ref().expect("just set");
                    let c = cycles(f, p);
                    let (_, cp) = compute_timing(f, &o.arch.lat);
                    let side = |k: u64, lat: u32| if k == 0 { 0 } else { (k.div_ceil(n as u64) - 1) as u32 + lat };
                    let na = n as usize;
                    let indirect = p.writes.iter().filter(|w| w.buffer_addr.is_some()).count() as u64;
                    rows.push(SweepRow {
                        function: f.name.clone(),
                        n,
                        priority: pname,
                        select: sname,
                        cycles: c,
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
                    });
                }
            }
        }
        cx.emit(SweepTable { rows });
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
         buffer_words_mul_max,writes_direct,writes_indirect,tight_lower_bound\n",
    );
    for r in rows {
        let w = |x: &WordStats| format!("{},{:.2},{}", x.min, x.mean, x.max);
        s += &format!(
            "{},{},{},{},{},{},{},{},{:.3},{:.4},{},{},{},{},{},{},{}\n",
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
            r.tight_lower_bound
        );
    }
    s
}

/// The rows as a text table (Table 2.2 style: one line per N and configuration).
pub fn to_table(rows: &[SweepRow]) -> String {
    let mut s = format!(
        "{:<10} {:>4} {:<13} {:<12} {:>8} {:>8} {:>7} {:>8} {:>7} {:>8} {:>8} {:>6} {:>15} {:>15} {:>13} {:>13}\n",
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
        "buffer MUL"
    );
    for r in rows {
        let w = |x: &WordStats| format!("{}/{:.0}/{}", x.min, x.mean, x.max);
        s += &format!(
            "{:<10} {:>4} {:<13} {:<12} {:>8} {:>8} {:>7.3} {:>8} {:>7.3} {:>8} {:>8} {:>6.3} {:>15} {:>15} {:>13} {:>13}\n",
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
            w(&r.buffer_words_mul)
        );
    }
    s
}
