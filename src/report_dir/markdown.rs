//! `report.md`: the report as a readable page — the run, the final IR's figures, the tables of
//! the report (sweep, Pareto, accuracy) and the figures embedded as images.

use std::fmt::Write;

use serde_json::Value;

use super::data::ReportData;
use super::figures::Figure;

fn num(v: Option<&Value>) -> String {
    match v {
        Some(Value::Number(n)) => match n.as_f64() {
            Some(x) if x.fract() != 0.0 => format!("{x:.3}"),
            _ => n.to_string(),
        },
        Some(Value::Null) | None => "-".into(),
        Some(v) => v.to_string(),
    }
}

/// Markdown table cell text (`|` escaped).
fn cell(s: &str) -> String {
    s.replace('|', "\\|")
}

/// The page (see the module doc).
pub fn markdown(report: &Value, d: &ReportData, figures: &[Figure]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {} @{}\n", d.model, d.function);
    let _ = writeln!(s, "- input: `{}`", report.get("input").and_then(Value::as_str).unwrap_or("?"));
    let _ = writeln!(s, "- pipeline: `{}`", d.pipeline);
    if let Some(st) = report.get("stats") {
        let ops = st.get("ops").and_then(|o| o.get("total"));
        let _ = writeln!(
            s,
            "- final IR: {} ops, critical path {} ops / {} cycles, Y = {} (latencies add {}, mul {}: {})",
            num(ops),
            num(st.get("asap")),
            num(st.get("asap_cycle")),
            num(st.get("y")),
            num(st.get("latencies").and_then(|l| l.get("add"))),
            num(st.get("latencies").and_then(|l| l.get("mul"))),
            st.get("latencies_from").and_then(Value::as_str).unwrap_or("given"),
        );
    }
    if let Some(p) = report.get("placement") {
        let _ = writeln!(
            s,
            "- placement: {} ADD + {} MULTI PEs, {} cycles ({} µs at {} MHz), lower bound {}, tight lower bound {}, parallelisation rate {}",
            num(p.get("n_add")),
            num(p.get("n_mul")),
            num(p.get("cycles")),
            num(p.get("us")),
            num(p.get("clock_mhz")),
            num(p.get("lower_bound")),
            num(p.get("tight_lower_bound")),
            num(p.get("parallelisation_rate")),
        );
    }
    if let Some(a) = report.get("accuracy") {
        let b = |k: &str, f: &str| num(a.get(k).and_then(|x| x.get(f)));
        let _ = writeln!(
            s,
            "- accuracy ({} samples): binary32 mean / p95 / max {} / {} / {} bits, binary64 {} / {} / {} bits",
            num(a.get("samples")),
            b("f32", "mean_bits"),
            b("f32", "p95_bits"),
            b("f32", "max_bits"),
            b("f64", "mean_bits"),
            b("f64", "p95_bits"),
            b("f64", "max_bits"),
        );
    }
    if let Some(Value::Array(stops)) = report.get("stopped_early") {
        for x in stops {
            let _ = writeln!(s, "- stopped early: {}", x.as_str().unwrap_or_default());
        }
    }
    if let Some(Value::Array(rows)) = report.get("sweep") {
        let _ = writeln!(s, "\n## Sweep\n");
        let _ = writeln!(
            s,
            "| N | priority | select | cycles | µs | LB | tight LB | bound 1 | critical path | par. rate | PE words ADD min/mean/max | PE words MUL | buffer ADD | buffer MUL | fits |"
        );
        let _ = writeln!(s, "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|---|---|---|");
        let w = |r: &Value, k: &str| {
            let g = |f: &str| num(r.get(k).and_then(|x| x.get(f)));
            format!("{}/{}/{}", g("min"), g("mean"), g("max"))
        };
        for r in rows {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                num(r.get("n")),
                r.get("priority").and_then(Value::as_str).unwrap_or(""),
                r.get("select").and_then(Value::as_str).unwrap_or(""),
                num(r.get("cycles")),
                num(r.get("us")),
                num(r.get("lower_bound")),
                num(r.get("tight_lower_bound")),
                num(r.get("resource_bound")),
                num(r.get("critical_path")),
                num(r.get("parallelisation_rate")),
                w(r, "pe_words_add"),
                w(r, "pe_words_mul"),
                w(r, "buffer_words_add"),
                w(r, "buffer_words_mul"),
                num(r.get("fits")),
            );
        }
    }
    if !d.pareto.is_empty() {
        let _ = writeln!(s, "\n## Speed against error (`-pareto`)\n");
        let _ =
            writeln!(s, "| # | pipeline | time (cycles) | f32 mean bits | f64 mean bits | Pareto-optimal | sound |");
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---|---|");
        for (i, r) in d.pareto.iter().enumerate() {
            let _ = writeln!(
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
    if !missing.is_empty() {
        let _ = writeln!(s, "Not drawn: {}.", missing.join("; "));
    }
    s
}
