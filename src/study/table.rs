//! The study's table as markdown (`study.md`, stdout), CSV (`study.csv`) and JSON
//! (`study.json`): one row per case, the thesis's Table 3.1 row beside it.

use std::fmt::Write;

use serde::Serialize;

use super::cases::{thesis_row, ThesisRow};
use super::run::{CaseResult, Shape, GENERATED, ZERO_BALANCE};
use robovec_dynamics::topology::Topology;

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

/// How a sequence moves: `grows` (never falls, rises somewhere), `stays flat`, `falls` or
/// `is not monotone`.
fn trend(xs: &[f64]) -> &'static str {
    let up = xs.windows(2).any(|w| w[1] > w[0]);
    let down = xs.windows(2).any(|w| w[1] < w[0]);
    match (up, down) {
        (true, false) => "grows",
        (false, false) => "stays flat",
        (false, true) => "falls",
        (true, true) => "is not monotone",
    }
}

/// The order of the three topologies by `value`, largest first (`serial > semi-serial >
/// parallel`).
fn ordering(values: [(Topology, f64); 3]) -> String {
    let mut v = values;
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v.iter().map(|(t, _)| t.name()).collect::<Vec<_>>().join(" > ")
}

/// Checks of the thesis's shapes on `results`, one sentence each, robovec's against the
/// thesis's rows: growth with dof (ops, critical path, Y) per topology, the topology ordering
/// of ops and of Y per dof, and the ratio of sizes.
pub fn shape_notes(results: &[CaseResult]) -> Vec<String> {
    let mut notes = Vec::new();
    let of = |dof: usize, t: Topology| results.iter().find(|r| r.case.dof == dof && r.case.topology == t);
    let mut dofs: Vec<usize> = results.iter().map(|r| r.case.dof).collect();
    dofs.dedup();
    let fmt = |xs: &[f64], decimals: usize| xs.iter().map(|x| format!("{x:.decimals$}")).collect::<Vec<_>>().join(", ");
    for t in Topology::ALL {
        let rows: Vec<&CaseResult> = dofs.iter().filter_map(|&d| of(d, t)).collect();
        if rows.len() < 2 {
            continue;
        }
        let ops: Vec<f64> = rows.iter().map(|r| r.generated.ops as f64).collect();
        let cp: Vec<f64> = rows.iter().map(|r| r.generated.asap_cycle as f64).collect();
        let y: Vec<f64> = rows.iter().map(|r| r.generated.y).collect();
        let mut note = format!(
            "{t}, as generated: ops count {} ({}), critical path {} ({} cycles), Y {} ({})",
            trend(&ops),
            fmt(&ops, 0),
            trend(&cp),
            fmt(&cp, 0),
            trend(&y),
            fmt(&y, 2)
        );
        let th: Vec<&ThesisRow> = rows.iter().filter_map(|r| thesis_row(&r.case)).collect();
        if th.len() == rows.len() {
            let tops: Vec<f64> = th.iter().map(|r| r.ops as f64).collect();
            let tcp: Vec<f64> = th.iter().map(|r| r.asap_cycle as f64).collect();
            let ty: Vec<f64> = th.iter().map(|r| r.y).collect();
            note += &format!(
                "; thesis: ops count {}, critical path {}, Y {} ({})",
                trend(&tops),
                trend(&tcp),
                trend(&ty),
                fmt(&ty, 2)
            );
        }
        notes.push(note);
    }
    for &d in &dofs {
        let (Some(s), Some(m), Some(p)) =
            (of(d, Topology::Serial), of(d, Topology::SemiSerial), of(d, Topology::Parallel))
        else {
            continue;
        };
        let three = |f: &dyn Fn(&CaseResult) -> f64| {
            [(Topology::Serial, f(s)), (Topology::SemiSerial, f(m)), (Topology::Parallel, f(p))]
        };
        let mut note = format!(
            "{d} dof: ops {} (serial / parallel {:.1}×), Y {}",
            ordering(three(&|r| r.generated.ops as f64)),
            s.generated.ops as f64 / p.generated.ops.max(1) as f64,
            ordering(three(&|r| r.generated.y))
        );
        if let (Some(ts), Some(tm), Some(tp)) = (thesis_row(&s.case), thesis_row(&m.case), thesis_row(&p.case)) {
            let t3 = |f: fn(&ThesisRow) -> f64| {
                [(Topology::Serial, f(ts)), (Topology::SemiSerial, f(tm)), (Topology::Parallel, f(tp))]
            };
            note += &format!(
                "; thesis: ops {} ({:.1}×), Y {}",
                ordering(t3(|r| r.ops as f64)),
                ts.ops as f64 / tp.ops as f64,
                ordering(t3(|r| r.y))
            );
        }
        notes.push(note);
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
            "sizes: the thesis's models have {} robovec's ops as generated and {} its critical path in cycles \
             (different robots: the shapes compare, not the sizes)",
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trends_and_orderings_read_as_stated() {
        assert_eq!(trend(&[1.0, 2.0, 2.0, 3.0]), "grows");
        assert_eq!(trend(&[298.0, 298.0, 298.0]), "stays flat");
        assert_eq!(trend(&[3.0, 2.0]), "falls");
        assert_eq!(trend(&[5.03, 10.64, 15.61, 29.39, 27.12]), "is not monotone");
        let o = ordering([(Topology::Serial, 15.61), (Topology::SemiSerial, 12.51), (Topology::Parallel, 15.83)]);
        assert_eq!(o, "parallel > serial > semi-serial");
    }
}
