//! Speed against error (`-pareto`): each pipeline's cycles against its bits of error, with its
//! certified bound beside them when the run has a domain.

use plotters::prelude::*;

use robovec_passes::whole_run::pareto::{Certified, ParetoRow};

use super::{err, legend, line_key, max_of, svg_area, tick, titled, Figure, Result, PALETTE, SIZE};
use crate::report_dir::data::ReportData;

/// The speed-against-error plane of `-pareto`: time (placed cycles, else critical path)
/// against mean bits of error in binary32 and binary64; Pareto-optimal rows joined; with a
/// domain, each row's certified binary32 bound (relative to the output's range) written beside
/// its point and both bounds in the CSV's last two columns.
pub(super) fn pareto(d: &ReportData) -> Result<Figure> {
    let rows = &d.pareto;
    // The certified columns come last (other tools read the first seven by position); empty
    // without a domain or where the row has no finite bound.
    let mut csv = String::from(
        "index,pipeline,time_cycles,f32_mean_bits,f64_mean_bits,pareto_optimal,sound,f32_certified_max_rel,f64_certified_max_rel\n",
    );
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
    for (i, r) in rows.iter().enumerate() {
        let (c32, c64) = r.certified.map_or((None, None), |c| (c.f32_max_rel, c.f64_max_rel));
        csv += &format!(
            "{},\"{}\",{},{},{},{},{},{},{}\n",
            i + 1,
            r.pipeline.replace('"', "\"\""),
            r.time_cycles,
            r.f32.mean_bits,
            r.f64.mean_bits,
            r.pareto_optimal,
            r.sound,
            opt(c32),
            opt(c64)
        );
    }
    let x_max = max_of(rows.iter().flat_map(|r| [r.f32.mean_bits, r.f64.mean_bits])).max(0.5) * 1.15;
    let y_max = max_of(rows.iter().map(|r| f64::from(r.time_cycles))).max(1.0) * 1.4;
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE);
        let area = titled(&root, d)?;
        let mut chart = ChartBuilder::on(&area)
            .caption("Speed vs error (-pareto)", ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(0f64..x_max, 0f64..y_max)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("mean bits of error (Herbie), over outputs and samples")
            .y_desc("time: placed cycles, else critical path (cycles)")
            .y_label_formatter(&tick)
            .light_line_style(RGBColor(242, 242, 242))
            .draw()
            .map_err(err)?;
        let (c32, c64) = (PALETTE[0], PALETTE[1]);
        let mut front: Vec<&ParetoRow> = rows.iter().filter(|r| r.pareto_optimal).collect();
        front.sort_by(|a, b| a.f32.mean_bits.total_cmp(&b.f32.mean_bits));
        chart
            .draw_series(LineSeries::new(
                front.iter().map(|r| (r.f32.mean_bits, f64::from(r.time_cycles))),
                c32.stroke_width(1),
            ))
            .map_err(err)?
            .label("Pareto front (binary32)")
            .legend(line_key(c32, 1));
        chart
            .draw_series(rows.iter().map(|r| Circle::new((r.f32.mean_bits, f64::from(r.time_cycles)), 5, c32.filled())))
            .map_err(err)?
            .label("binary32")
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, c32.filled()));
        chart
            .draw_series(
                rows.iter().map(|r| TriangleMarker::new((r.f64.mean_bits, f64::from(r.time_cycles)), 6, c64.filled())),
            )
            .map_err(err)?
            .label("binary64")
            .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, c64.filled()));
        // Each binary32 point is labelled with its row number and, with a domain, its certified
        // bound beside the sampled bits (`≤ 3.1e-6`: largest binary32 bound / output range).
        chart
            .draw_series(rows.iter().enumerate().map(|(i, r)| {
                let mark = if r.sound { "" } else { " (unsound)" };
                let cert = match r.certified {
                    Some(Certified { f32_max_rel: Some(b), .. }) => format!(" certified ≤ {b:.1e}"),
                    Some(_) => " certified: -".to_string(),
                    None => String::new(),
                };
                Text::new(
                    format!("{}{mark}{cert}", i + 1),
                    (r.f32.mean_bits, f64::from(r.time_cycles)),
                    ("sans-serif", 13),
                )
            }))
            .map_err(err)?;
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "pareto",
        caption: if rows.iter().any(|r| r.certified.is_some()) {
            "Speed against error of the -pareto pipelines (numbers: the rows of the table above); the line joins the Pareto-optimal rows; beside each binary32 point its certified bound over the domain (error-bound: largest bound / output range; the sampled bits are Herbie's mean over the samples)".into()
        } else {
            "Speed against error of the -pareto pipelines (numbers: the rows of the table above); the line joins the Pareto-optimal rows".into()
        },
        svg,
        csv,
    })
}
