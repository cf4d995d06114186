//! The study's table as markdown (`study.md`, stdout), CSV (`study.csv`) and JSON
//! (`study.json`): one row per case, the thesis's Table 3.1 row beside it.

use std::fmt::Write;

use serde::Serialize;

use super::cases::{thesis_row, ThesisRow};
use super::run::{CaseResult, Shape, GENERATED, ZERO_BALANCE};

/// `ops, ASAP − ASAPCycle, Y` of a shape, as the thesis prints them.
fn shape_cell(s: &Shape) -> String {
    format!("{} | {} − {} | {:.2}", s.ops, s.asap, s.asap_cycle, s.y)
}

fn thesis_cell(t: Option<&ThesisRow>) -> String {
    t.map_or_else(|| "–".to_string(), |t| format!("{}, {} − {}, Y {:.2}", t.ops, t.asap, t.asap_cycle, t.y))
}

/// The markdown table (header, one row per case) of `results`; `best` names the best pipeline.
pub fn markdown(results: &[CaseResult], best: &str) -> String {
    let ns: Vec<String> = results.first().map_or_else(Vec::new, |r| r.placed.iter().map(|p| p.n.to_string()).collect());
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| case | ops | ASAP − ASAPCycle | Y | ops (z,b) | ASAP − ASAPCycle (z,b) | Y (z,b) | ops (best) | \
         ASAP − ASAPCycle (best) | Y (best) | cycles N = {} | f32 bits mean / max | thesis: ops, ASAP − ASAPCycle, Y |",
        ns.join(" / ")
    );
    let _ = writeln!(out, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
    for r in results {
        let cycles: Vec<String> = r.placed.iter().map(|p| p.cycles.to_string()).collect();
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {:.2} / {:.2} | {} |",
            r.case.label(),
            shape_cell(&r.generated),
            shape_cell(&r.zero_balance),
            shape_cell(&r.best),
            cycles.join(" / "),
            r.f32_bits.mean,
            r.f32_bits.max,
            thesis_cell(thesis_row(&r.case))
        );
    }
    let _ = writeln!(
        out,
        "\nPipelines: as generated `{GENERATED}`; (z,b) `{ZERO_BALANCE}`; best `{best}`. Cycles: `place<pe=N>` \
         (N ADD + N MULTI PEs) after the best pipeline; f32 bits: `accuracy` after the best pipeline. \
         Latencies add 12, mul 7 cycles (de10-nano). Thesis: seed Table 3.1 (its Robotran models, not these robots)."
    );
    out
}

/// `study.md`: a heading, how the study was run, the table, and the shape comparison with the
/// thesis's rows ([`shape_notes`]).
pub fn study_md(results: &[CaseResult], best: &str, command: &str, figures: &[(&str, String)]) -> String {
    let mut out = String::from("# The study (seed §3.2, Table 3.1) on robovec's topology families\n\n");
    let _ = writeln!(out, "Command: `{command}`\n");
    out += &markdown(results, best);
    out += "\n## Shapes against the thesis's rows\n\n";
    for n in shape_notes(results) {
        let _ = writeln!(out, "- {n}");
    }
    if !figures.is_empty() {
        out += "\n## Figures\n\n";
        for (name, caption) in figures {
            let _ = writeln!(out, "![{name}]({name}.svg)\n\n{caption} (numbers: `{name}.csv`)\n");
        }
    }
    if results.iter().any(|r| r.report.is_some()) {
        out += "\n## Per-case reports\n\n";
        for r in results {
            let _ = writeln!(out, "- [{}](cases/{}/report.md)", r.case.label(), r.case.slug());
        }
    }
    out
}

/// Checks of the thesis's shapes on `results`, one sentence each: growth with dof, topology
/// ordering, Y, ratio to the thesis's rows.
pub fn shape_notes(results: &[CaseResult]) -> Vec<String> {
    use crate::gen::topology::Topology;
    let mut notes = Vec::new();
    let of = |dof: usize, t: Topology| results.iter().find(|r| r.case.dof == dof && r.case.topology == t);
    let mut dofs: Vec<usize> = results.iter().map(|r| r.case.dof).collect();
    dofs.dedup();
    for t in Topology::ALL {
        let rows: Vec<&CaseResult> = dofs.iter().filter_map(|&d| of(d, t)).collect();
        if rows.len() < 2 {
            continue;
        }
        let grows = |f: fn(&CaseResult) -> f64| rows.windows(2).all(|w| f(w[1]) >= f(w[0]));
        let ops: Vec<String> = rows.iter().map(|r| r.generated.ops.to_string()).collect();
        let ys: Vec<String> = rows.iter().map(|r| format!("{:.2}", r.generated.y)).collect();
        notes.push(format!(
            "{t}: ops as generated {} with dof ({}); critical path {}; Y {} ({})",
            if grows(|r| r.generated.ops as f64) { "grow" } else { "do not all grow" },
            ops.join(", "),
            if grows(|r| r.generated.asap_cycle as f64) { "grows" } else { "stays flat or falls somewhere" },
            if grows(|r| r.generated.y) { "grows" } else { "does not all grow" },
            ys.join(", ")
        ));
    }
    for &d in &dofs {
        let (Some(s), Some(m), Some(p)) =
            (of(d, Topology::Serial), of(d, Topology::SemiSerial), of(d, Topology::Parallel))
        else {
            continue;
        };
        let ordered = s.generated.ops >= m.generated.ops && m.generated.ops >= p.generated.ops;
        notes.push(format!(
            "{d} dof: ops serial {} semi-serial {} parallel ({} ≥ {} ≥ {} {}; serial / parallel {:.1}×)",
            if ordered { "≥" } else { "vs" },
            if ordered { "≥" } else { "vs" },
            s.generated.ops,
            m.generated.ops,
            p.generated.ops,
            if ordered { "as in the thesis" } else { "unlike the thesis" },
            s.generated.ops as f64 / p.generated.ops.max(1) as f64
        ));
    }
    let ratios: Vec<(f64, f64)> = results
        .iter()
        .filter_map(|r| {
            thesis_row(&r.case)
                .map(|t| (t.ops as f64 / r.generated.ops as f64, t.asap_cycle as f64 / r.generated.asap_cycle as f64))
        })
        .collect();
    if !ratios.is_empty() {
        let span = |f: fn(&(f64, f64)) -> f64| {
            let lo = ratios.iter().map(f).fold(f64::INFINITY, f64::min);
            let hi = ratios.iter().map(f).fold(0.0, f64::max);
            format!("{lo:.1}–{hi:.1}×")
        };
        notes.push(format!(
            "the thesis's models have {} robovec's ops as generated and {} its critical path in cycles (different robots: shapes compare, not sizes)",
            span(|r| r.0),
            span(|r| r.1)
        ));
    }
    notes
}

/// `study.csv`: one line per case, the figures of the table unformatted.
pub fn csv(results: &[CaseResult]) -> String {
    let mut out = String::from("dof,topology,pipeline,ops,asap,asap_cycle,y\n");
    for r in results {
        for (name, s) in [("generated", &r.generated), ("zero_balance", &r.zero_balance), ("best", &r.best)] {
            let _ = writeln!(
                out,
                "{},{},{name},{},{},{},{}",
                r.case.dof, r.case.topology, s.ops, s.asap, s.asap_cycle, s.y
            );
        }
    }
    out
}

/// `study.json`: the plan and every case's figures, with the thesis's row when there is one.
#[derive(Serialize)]
pub struct StudyJson<'a> {
    /// Seed of the robots.
    pub seed: u64,
    /// Accuracy samples.
    pub samples: u32,
    /// The three pipelines.
    pub pipelines: [&'a str; 3],
    /// The cases.
    pub cases: Vec<CaseJson<'a>>,
}

/// One case of [`StudyJson`].
#[derive(Serialize)]
pub struct CaseJson<'a> {
    /// The measured figures.
    #[serde(flatten)]
    pub result: &'a CaseResult,
    /// The thesis's row.
    pub thesis: Option<&'static ThesisRow>,
}

/// The `study.json` text.
pub fn json(results: &[CaseResult], seed: u64, samples: u32, best: &str) -> String {
    let j = StudyJson {
        seed,
        samples,
        pipelines: [GENERATED, ZERO_BALANCE, best],
        cases: results.iter().map(|r| CaseJson { result: r, thesis: thesis_row(&r.case) }).collect(),
    };
    serde_json::to_string_pretty(&j).expect("the study serialises") + "\n"
}
