//! `report.md`: the report as a readable page — the run, the final IR's figures, the tables of
//! the report (sweep, Pareto, accuracy, the budget ladder) and the figures embedded as images — written from the
//! run's typed results ([`ReportData`]), the same values `report.json` holds, printed as its
//! numbers read: integers as they are, fractions to 3 decimals, a missing value as `-`.

use std::fmt::Write;

use super::data::ReportData;
use super::figures::Figure;

/// A number of the page, as the report's JSON gives it (see the module doc).
trait Num {
    fn num(&self) -> String;
}

macro_rules! integer_num {
    ($($t:ty),*) => {$(impl Num for $t {
        fn num(&self) -> String {
            self.to_string()
        }
    })*};
}
integer_num!(u32, u64);

impl Num for f64 {
    /// A fraction to 3 decimals; an integral value as JSON writes it (`12.0`); a value JSON
    /// cannot hold (not finite: `null`) as `-`.
    fn num(&self) -> String {
        match serde_json::Number::from_f64(*self) {
            Some(_) if self.fract() != 0.0 => format!("{self:.3}"),
            Some(n) => n.to_string(),
            None => "-".into(),
        }
    }
}

impl Num for bool {
    fn num(&self) -> String {
        self.to_string()
    }
}

/// Markdown table cell text (`|` escaped).
fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The page (see the module doc).
pub fn markdown(d: &ReportData, figures: &[Figure]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {} @{}\n", d.model, d.function);
    let _ = writeln!(s, "- input: `{}`", d.input);
    let _ = writeln!(s, "- pipeline: `{}`", d.pipeline);
    let st = &d.stats;
    let _ = writeln!(
        s,
        "- final IR: {} ops, critical path {} ops / {} cycles, Y = {} (latencies add {}, mul {}: {})",
        st.ops.total.num(),
        st.asap.num(),
        st.asap_cycle.num(),
        st.y.num(),
        st.latencies.add.num(),
        st.latencies.mul.num(),
        st.latencies_from.as_deref().unwrap_or("given"),
    );
    if let Some(p) = &d.placement {
        let _ = writeln!(
            s,
            "- placement: {} ADD + {} MULTI PEs, {} cycles ({} µs at {} MHz), lower bound {}, tight lower bound {}, parallelisation rate {}",
            p.n_add.num(),
            p.n_mul.num(),
            p.cycles.num(),
            p.us.num(),
            p.clock_mhz.num(),
            p.lower_bound.num(),
            p.tight_lower_bound.num(),
            p.parallelisation_rate.num(),
        );
    }
    if let Some(a) = &d.accuracy {
        let _ = writeln!(
            s,
            "- accuracy ({} samples): binary32 mean / p95 / max {} / {} / {} bits, binary64 {} / {} / {} bits",
            a.samples.num(),
            a.f32.mean_bits.num(),
            a.f32.p95_bits.num(),
            a.f32.max_bits.num(),
            a.f64.mean_bits.num(),
            a.f64.p95_bits.num(),
            a.f64.max_bits.num(),
        );
    }
    for x in &d.stopped_early {
        let _ = writeln!(s, "- stopped early: {x}");
    }
    if d.swept {
        let _ = writeln!(s, "\n## Sweep\n");
        let _ = writeln!(
            s,
            "| N | priority | select | cycles | µs | LB | tight LB | bound 1 | critical path | par. rate | PE words ADD min/mean/max | PE words MUL | buffer ADD | buffer MUL | fits |"
        );
        let _ = writeln!(s, "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|---|---|---|");
        let w = |w: &robovec_passes::sweep::WordStats| format!("{}/{}/{}", w.min.num(), w.mean.num(), w.max.num());
        for r in &d.sweep {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r.n.num(),
                r.priority,
                r.select,
                r.cycles.num(),
                r.us.num(),
                r.lower_bound.num(),
                r.tight_lower_bound.num(),
                r.resource_bound.num(),
                r.critical_path.num(),
                r.parallelisation_rate.num(),
                w(&r.pe_words_add),
                w(&r.pe_words_mul),
                w(&r.buffer_words_add),
                w(&r.buffer_words_mul),
                r.fits.num(),
            );
        }
    }
    if !d.pareto.is_empty() {
        let _ = writeln!(s, "\n## Speed against error (`-pareto`)\n");
        // With a domain, the certified bounds (`error-bound`'s, largest bound / output range)
        // beside the sampled bits, as the last two columns.
        let certified = d.pareto.iter().any(|r| r.certified.is_some());
        let _ = write!(s, "| # | pipeline | time (cycles) | f32 mean bits | f64 mean bits | Pareto-optimal | sound |");
        let _ = writeln!(s, "{}", if certified { " f32 certified max rel | f64 certified max rel |" } else { "" });
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---|---|{}", if certified { "---:|---:|" } else { "" });
        let sci = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3e}"));
        for (i, r) in d.pareto.iter().enumerate() {
            let _ = write!(
                s,
                "| {} | `{}` | {} | {:.3} | {:.3} | {} | {} |",
                i + 1,
                cell(&r.pipeline),
                r.time_cycles,
                r.f32.mean_bits,
                r.f64.mean_bits,
                if r.pareto_optimal { "yes" } else { "" },
                if r.sound { "yes" } else { "no" }
            );
            if certified {
                let (a, b) = r.certified.map_or((None, None), |c| (c.f32_max_rel, c.f64_max_rel));
                let _ = write!(s, " {} | {} |", sci(a), sci(b));
            }
            let _ = writeln!(s);
        }
    }
    if let Some(l) = d.precision_ladder.as_ref().filter(|l| !l.points.is_empty()) {
        let _ = writeln!(s, "\n## Cost against error budget (`precision`, target {})\n", l.target);
        let _ = writeln!(
            s,
            "The chooser of `precision` run again at each budget with the pipeline's target and domain; cost is the \
             target's cost model (the pass's documentation), not a measurement.\n"
        );
        let _ = writeln!(
            s,
            "| budget | cost before | cost after | after / before | values f64 / f32 / fixed | certified max bound / range | worst output | unreachable outputs |"
        );
        let _ = writeln!(s, "|---:|---:|---:|---:|---|---:|---|---:|");
        for p in &l.points {
            let (a, b, c) = super::figures::budget::per_kind(p);
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.3} | {a} / {b} / {c} | {:.3e} | {} | {} |",
                p.budget.map_or("-".to_string(), |b| format!("{b:e}")),
                p.cost_before.num(),
                p.cost_after.num(),
                super::figures::budget::ratio(p),
                p.max_rel_to_range,
                cell(p.worst_output.as_deref().unwrap_or("-")),
                p.unreachable.len()
            );
        }
    }
    let _ = writeln!(s, "\n## Figures\n");
    for f in figures {
        let _ = writeln!(
            s,
            "### {}\n\n{}. Numbers: [`{n}.csv`]({n}.csv).\n\n![{n}]({n}.svg)\n",
            f.name,
            f.caption,
            n = f.name
        );
    }
    let mut missing = Vec::new();
    if d.sweep.is_empty() {
        missing.push("cycles, µs, parallelisation rate and memory against N need a `sweep` pass in the pipeline");
    }
    if d.placement.is_none() {
        missing.push("occupation and the placement timeline need a placed final IR (`place` in the pipeline)");
    }
    if d.pareto.is_empty() {
        missing.push("the speed-against-error figure needs `-pareto=A;B;…`");
    }
    if d.precision_ladder.as_ref().is_none_or(|l| l.points.is_empty()) {
        missing.push(if d.precision_ladder.is_some() {
            "the cost-against-budget figure's ladder stopped before its first budget (see the early stops above)"
        } else {
            "the cost-against-budget figure needs `precision` in the pipeline"
        });
    }
    if !missing.is_empty() {
        let _ = writeln!(s, "Not drawn: {}.", missing.join("; "));
    }
    s
}
