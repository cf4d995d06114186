//! The placed function's figures (seed ch. 2): PE occupation and the timeline of the issue slots.

use plotters::prelude::*;

use super::{err, legend, line_key, svg_area, tick, titled, Figure, Result, PALETTE, SIZE};
use crate::report_dir::data::ReportData;

/// Seed Fig. 3.15–3.38: occupation rate of the ADD and MULTI PEs over normalised time, at the
/// final placement's N (`placement.occupation`: rolling mean over 50 cycles).
pub(super) fn occupation(d: &ReportData) -> Result<Figure> {
    let p = d.placement.as_ref().expect("called with a placement");
    let c = p.cycles as f64;
    let t = |i: usize| i as f64 / c;
    let mut csv = String::from("pe_type,cycle,normalised_time,occupation\n");
    for (k, xs) in [("add", &p.occupation.add), ("mul", &p.occupation.mul)] {
        for (i, x) in xs.iter().enumerate() {
            csv += &format!("{k},{i},{},{x}\n", t(i));
        }
    }
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE);
        let area = titled(&root, d)?;
        let what = format!("Occupation over time, N = {} ADD + {} MULTI, {} cycles", p.n_add, p.n_mul, p.cycles);
        let mut chart = ChartBuilder::on(&area)
            .caption(what.as_str(), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(0f64..1f64, 0f64..1.3f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("normalised time (cycle / cycles)")
            .y_desc("occupation rate (issues / N, mean over 50 cycles)")
            .light_line_style(RGBColor(242, 242, 242))
            .draw()
            .map_err(err)?;
        for (i, (label, xs)) in
            [("ADD PEs", &p.occupation.add), ("MULTI PEs", &p.occupation.mul)].into_iter().enumerate()
        {
            let col = PALETTE[i];
            chart
                .draw_series(LineSeries::new(xs.iter().enumerate().map(|(i, &x)| (t(i), x)), col.stroke_width(2)))
                .map_err(err)?
                .label(label)
                .legend(line_key(col, 2));
        }
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "occupation",
        caption:
            "Occupation rate of the ADD and MULTI PEs over normalised time at the placement's N (seed Fig. 3.15–3.38)"
                .into(),
        svg,
        csv,
    })
}

/// The placement timeline: which PE issues which op when, over the report's window.
pub(super) fn timeline(d: &ReportData) -> Result<Figure> {
    let p = d.placement.as_ref().expect("called with a placement");
    let tl = &p.timeline;
    let rows = p.n_add + p.n_mul;
    let row = |ty: &str, pe: u32| if ty == "add" { pe } else { p.n_add + pe };
    let mut csv = String::from("pe_type,pe,cycle,latency,op,value\n");
    for i in &tl.issues {
        csv += &format!("{},{},{},{},{},{}\n", i.pe_type, i.pe, i.cycle, i.latency, i.op, i.value);
    }
    let ops = ["add", "sub", "mul", "div", "call"];
    let mut svg = String::new();
    {
        let height = (120 + 22 * rows).clamp(300, 1400);
        let root = svg_area(&mut svg, (1300, height));
        let area = titled(&root, d)?;
        let what = format!("Placement timeline, cycles {}..{} of {}", tl.start, tl.end, p.cycles);
        let (n_add, n_mul) = (p.n_add, p.n_mul);
        let mut chart = ChartBuilder::on(&area)
            .caption(what.as_str(), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(72)
            .build_cartesian_2d(tl.start as f64..tl.end.max(tl.start + 1) as f64, 0f64..rows as f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("issue cycle")
            .y_desc("PE")
            .x_label_formatter(&tick)
            .y_labels((rows as usize).min(40) * 2 + 1)
            .y_label_formatter(&move |y| {
                // One label per PE row, at its middle.
                let k = (y - 0.5).round();
                if (y - 0.5 - k).abs() > 1e-6 || k < 0.0 || k >= (n_add + n_mul) as f64 {
                    return String::new();
                }
                let k = k as u32;
                if k < n_add {
                    format!("ADD {k}")
                } else if k - n_add < n_mul {
                    format!("MULTI {}", k - n_add)
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .draw()
            .map_err(err)?;
        for (j, op) in ops.iter().enumerate() {
            let col = PALETTE[j];
            let mine: Vec<_> = tl.issues.iter().filter(|i| i.op == *op).collect();
            if mine.is_empty() {
                continue;
            }
            chart
                .draw_series(mine.iter().map(|i| {
                    let y = row(&i.pe_type, i.pe) as f64;
                    Rectangle::new([(i.cycle as f64 + 0.08, y + 0.15), (i.cycle as f64 + 0.92, y + 0.85)], col.filled())
                }))
                .map_err(err)?
                .label(*op)
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], col.filled()));
        }
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "timeline",
        caption: "Placement timeline: each op's issue slot on its PE over the first cycles of the placement".into(),
        svg,
        csv,
    })
}
