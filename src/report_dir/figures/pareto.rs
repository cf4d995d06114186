//! Speed against error (`-pareto`): each pipeline's cycles against its bits of error.

use plotters::prelude::*;

use robovec_passes::whole_run::pareto::ParetoRow;

use super::{err, legend, line_key, max_of, svg_area, tick, titled, Figure, Result, PALETTE, SIZE};
use crate::report_dir::data::ReportData;

/// The speed-against-error plane of `-pareto`: time (placed cycles, else critical path)
/// against mean bits of error in binary32 and binary64; Pareto-optimal rows joined.
pub(super) fn pareto(d: &ReportData) -> Result<Figure> {
    let rows = &d.pareto;
    let mut csv = String::from("index,pipeline,time_cycles,f32_mean_bits,f64_mean_bits,pareto_optimal,sound\n");
    for (i, r) in rows.iter().enumerate() {
        csv += &format!(
            "{},\"{}\",{},{},{},{},{}\n",
            i + 1,
            r.pipeline.replace('"', "\"\""),
            r.time_cycles,
            r.f32.mean_bits,
            r.f64.mean_bits,
            r.pareto_optimal,
            r.sound
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
        chart
            .draw_series(rows.iter().enumerate().map(|(i, r)| {
                let mark = if r.sound { "" } else { " (unsound)" };
                Text::new(format!("{}{mark}", i + 1), (r.f32.mean_bits, f64::from(r.time_cycles)), ("sans-serif", 13))
            }))
            .map_err(err)?;
        legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "pareto",
        caption: "Speed against error of the -pareto pipelines (numbers: the rows of the table above); the line joins the Pareto-optimal rows".into(),
        svg,
        csv,
    })
}
