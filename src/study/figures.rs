//! The study's own SVG figures, drawn with `plotters` like `-report-dir`'s, each with the CSV
//! of exactly the numbers it draws: `ops` (ops against dof per topology, the three pipelines),
//! `critical_path` (ASAPCycle against dof), `y` (number Y against dof), `cycles` (placed
//! cycles against N per case) and `f32_error` (binary32 bits of error against dof).

use plotters::prelude::*;

use crate::study::run::{CaseResult, Shape};
use robovec_dynamics::topology::Topology;

use crate::report_dir::figures::{Figure, PALETTE, SIZE};

type Result<T> = std::result::Result<T, String>;

fn err(e: impl std::fmt::Display) -> String {
    format!("drawing a study figure failed: {e}")
}

/// How a line is drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stroke {
    /// Solid, 2 px.
    Solid,
    /// Dashed, 2 px.
    Dashed,
    /// Solid, 1 px.
    Thin,
}

/// One line: label, colour index, stroke, points.
struct Line {
    label: String,
    colour: usize,
    stroke: Stroke,
    points: Vec<(f64, f64)>,
}

/// Axis numbers without needless decimals.
fn tick(v: &f64) -> String {
    if v.abs() >= 10.0 || v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

/// Draws `lines` on one chart; `log2_x` puts x on a log₂ axis labelled with powers of two.
fn chart(title: &str, x_desc: &str, y_desc: &str, lines: &[Line], log2_x: bool) -> Result<String> {
    let xs = lines.iter().flat_map(|l| l.points.iter().map(|p| p.0));
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.05).max(0.3);
    let y_max = lines.iter().flat_map(|l| l.points.iter().map(|p| p.1)).fold(0.0f64, f64::max).max(1e-9) * 1.45;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let mut c = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d((lo - pad)..(hi + pad), 0f64..y_max)
            .map_err(err)?;
        let pow2 = |x: &f64| {
            if (x - x.round()).abs() < 1e-6 && *x >= 0.0 {
                format!("{}", 1u64 << (x.round() as u32).min(40))
            } else {
                String::new()
            }
        };
        let mut mesh = c.configure_mesh();
        mesh.x_desc(x_desc).y_desc(y_desc).y_label_formatter(&tick).light_line_style(RGBColor(242, 242, 242));
        if log2_x {
            mesh.x_labels(((hi - lo).ceil() as usize + 3).max(2)).x_label_formatter(&pow2);
        } else {
            mesh.x_label_formatter(&tick);
        }
        mesh.draw().map_err(err)?;
        for l in lines {
            let col = PALETTE[l.colour % PALETTE.len()];
            let w = if l.stroke == Stroke::Thin { 1 } else { 2 };
            let style = col.stroke_width(w);
            let s = if l.stroke == Stroke::Dashed {
                c.draw_series(DashedLineSeries::new(l.points.iter().copied(), 6, 4, style)).map_err(err)?
            } else {
                c.draw_series(LineSeries::new(l.points.iter().copied(), style)).map_err(err)?
            };
            let stroke = l.stroke;
            s.label(l.label.as_str()).legend(move |(x, y)| {
                if stroke == Stroke::Dashed {
                    PathElement::new(vec![(x, y), (x + 6, y)], col.stroke_width(w))
                } else {
                    PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(w))
                }
            });
            c.draw_series(l.points.iter().map(|&p| Circle::new(p, 3, col.filled()))).map_err(err)?;
        }
        // Lines rise to the right against dof and fall to the right against N: the legend
        // goes to the emptier upper corner.
        let corner = if log2_x { SeriesLabelPosition::UpperRight } else { SeriesLabelPosition::UpperLeft };
        c.configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(svg)
}

/// The topologies present in `results`, in the thesis's order, with their colour index.
fn topologies(results: &[CaseResult]) -> Vec<(usize, Topology)> {
    Topology::ALL.into_iter().enumerate().filter(|(_, t)| results.iter().any(|r| r.case.topology == *t)).collect()
}

/// The three pipelines' shapes of a case, with their names.
fn pipelines(r: &CaseResult) -> [(&'static str, &Shape); 3] {
    [("generated", &r.generated), ("zero-removal,balance", &r.zero_balance), ("best", &r.best)]
}

/// A shape figure against dof: colour per topology; as generated dashed, after
/// `zero-removal,balance` thin, after the best pipeline solid.
fn per_dof(
    results: &[CaseResult],
    (name, caption, title, y_desc): (&'static str, &str, &str, &str),
    column: &str,
    value: fn(&Shape) -> f64,
) -> Result<Figure> {
    let mut lines = Vec::new();
    let mut csv = format!("topology,pipeline,dof,{column}\n");
    for (ci, t) in topologies(results) {
        let rows: Vec<&CaseResult> = results.iter().filter(|r| r.case.topology == t).collect();
        for (pi, p) in ["generated", "zero-removal,balance", "best"].into_iter().enumerate() {
            let mut points = Vec::new();
            for r in &rows {
                let s = pipelines(r)[pi].1;
                points.push((r.case.dof as f64, value(s)));
                csv += &format!("{t},{p},{},{}\n", r.case.dof, value(s));
            }
            let stroke = [Stroke::Dashed, Stroke::Thin, Stroke::Solid][pi];
            lines.push(Line { label: format!("{t}, {p}"), colour: ci, stroke, points });
        }
    }
    let svg = chart(title, "degrees of freedom", y_desc, &lines, false)?;
    Ok(Figure { name, caption: caption.to_string(), svg, csv })
}

/// Every study figure, in `study.md` order.
///
/// # Errors
/// A message when plotting fails (an internal error).
pub fn all(results: &[CaseResult]) -> Result<Vec<Figure>> {
    let mut out = vec![
        per_dof(
            results,
            ("ops", "Ops of dirdyna against dof per topology: as generated (dashed), after zero-removal,balance (thin) and after the best pipeline (solid); colour per topology", "Ops vs dof", "ops"),
            "ops",
            |s| s.ops as f64,
        )?,
        per_dof(
            results,
            ("critical_path", "Critical path in cycles (largest ASAPCycle, add 12 / mul 7) against dof, the three pipelines (as in the ops figure)", "Critical path vs dof", "ASAPCycle (cycles)"),
            "asap_cycle",
            |s| s.asap_cycle as f64,
        )?,
        per_dof(
            results,
            ("y", "Number Y = ops / ASAPCycle (seed §3.2) against dof, the three pipelines (as in the ops figure)", "Y vs dof", "Y = ops / ASAPCycle"),
            "y",
            |s| s.y,
        )?,
    ];
    // Cycles against N per case: colour by dof, one line per case.
    let mut dofs: Vec<usize> = results.iter().map(|r| r.case.dof).collect();
    dofs.dedup();
    let mut lines = Vec::new();
    let mut csv = String::from("dof,topology,n,cycles\n");
    for r in results {
        let colour = dofs.iter().position(|&d| d == r.case.dof).unwrap_or(0);
        let stroke = match r.case.topology {
            Topology::Serial => Stroke::Solid,
            Topology::SemiSerial => Stroke::Dashed,
            Topology::Parallel | Topology::Star => Stroke::Thin,
        };
        let points = r.placed.iter().map(|p| ((p.n.max(1) as f64).log2(), p.cycles as f64)).collect();
        for p in &r.placed {
            csv += &format!("{},{},{},{}\n", r.case.dof, r.case.topology, p.n, p.cycles);
        }
        lines.push(Line { label: r.case.label(), colour, stroke, points });
    }
    out.push(Figure {
        name: "cycles",
        caption: "Placed cycles (place<pe=N> after the best pipeline) against N per case; colour per dof, serial solid, semi-serial dashed, parallel thin".into(),
        svg: chart("Placed cycles vs N", "N (ADD PEs = MULTI PEs), log scale", "cycles", &lines, true)?,
        csv,
    });
    let mut lines = Vec::new();
    let mut csv = String::from("topology,statistic,dof,f32_bits\n");
    for (ci, t) in topologies(results) {
        let rows: Vec<&CaseResult> = results.iter().filter(|r| r.case.topology == t).collect();
        for (k, stat) in ["mean", "max"].into_iter().enumerate() {
            let mut points = Vec::new();
            for r in &rows {
                let v = if k == 0 { r.f32_bits.mean } else { r.f32_bits.max };
                points.push((r.case.dof as f64, v));
                csv += &format!("{t},{stat},{},{v}\n", r.case.dof);
            }
            let stroke = if k == 0 { Stroke::Solid } else { Stroke::Dashed };
            lines.push(Line { label: format!("{t}, {stat}"), colour: ci, stroke, points });
        }
    }
    out.push(Figure {
        name: "f32_error",
        caption: "binary32 bits of error (accuracy after the best pipeline) against dof: mean (solid) and max (dashed) over outputs and samples".into(),
        svg: chart("f32 bits of error vs dof", "degrees of freedom", "bits of error", &lines, false)?,
        csv,
    });
    Ok(out)
}
