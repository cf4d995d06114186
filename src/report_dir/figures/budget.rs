//! Cost against error budget (`precision`, issue 48 item 6): the budget ladder's points
//! ([`robovec_passes::precision::ladder`]).

use plotters::prelude::*;

use robovec_ir::format::Format;
use robovec_passes::precision::PrecisionReport;

use super::{err, legend, legend_at, line_key, svg_area, titled, Figure, Result, PALETTE};
use crate::report_dir::data::ReportData;

/// Size of the two-panel figure, pixels.
const SIZE2: (u32, u32) = (900, 820);

/// Values of a point per kind of format: (binary64, binary32, fixed point), from the report's
/// `formats` histogram (its keys are [`Format`]'s spellings).
pub(crate) fn per_kind(p: &PrecisionReport) -> (usize, usize, usize) {
    let (mut f64s, mut f32s, mut fixed) = (0, 0, 0);
    for (k, &n) in &p.formats {
        match k.parse::<Format>() {
            Ok(Format::Binary64) => f64s += n,
            Ok(Format::Binary32) => f32s += n,
            Ok(Format::Fix { .. }) => fixed += n,
            Err(_) => {}
        }
    }
    (f64s, f32s, fixed)
}

/// Model cost after over before (1 with no cost before: nothing to lower).
pub(crate) fn ratio(p: &PrecisionReport) -> f64 {
    if p.cost_before > 0.0 {
        p.cost_after / p.cost_before
    } else {
        1.0
    }
}

/// Tick text of a log₁₀ axis: `1e-k` at integer exponents, nothing between.
fn pow_tick(x: &f64) -> String {
    if (x - x.round()).abs() < 1e-6 {
        format!("1e{}", x.round() as i32)
    } else {
        String::new()
    }
}

/// log₁₀ of a positive value (the floor `lo` for 0).
fn l10(v: f64, lo: f64) -> f64 {
    v.max(lo).log10()
}

/// The cost-against-budget figure: above, the cost model's cost after / before and the share of
/// values in binary32 and in fixed point at each budget of the ladder; below, the certified
/// bound reached against the budget (log–log, the budget's diagonal dashed: every point at or
/// below it but for outputs binary64 cannot keep within it).
pub(super) fn budget(d: &ReportData) -> Result<Figure> {
    let Some(l) = &d.precision_ladder else { return Err("no budget ladder".into()) };
    let pts: Vec<&PrecisionReport> = l.points.iter().filter(|p| p.budget.is_some_and(|b| b > 0.0)).collect();
    let mut csv = String::from(
        "budget,cost_before,cost_after,cost_ratio,max_rel_to_range,values,f64_values,f32_values,fixed_values,sweeps,unreachable,worst_output,\
         ns_per_state,ns_batch,binary64_ns_per_state,binary64_batch,measured_ratio\n",
    );
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
    for p in &pts {
        let (a, b, c) = per_kind(p);
        csv += &format!(
            "{},{},{},{},{},{},{a},{b},{c},{},{},{},{},{},{},{},{}\n",
            p.budget.unwrap_or(0.0),
            p.cost_before,
            p.cost_after,
            ratio(p),
            p.max_rel_to_range,
            a + b + c,
            p.sweeps,
            p.unreachable.len(),
            p.worst_output.as_deref().unwrap_or(""),
            opt(p.ns_per_state),
            p.ns_batch.map_or(String::new(), |b| b.to_string()),
            opt(l.binary64_ns_per_state),
            l.binary64_batch.map_or(String::new(), |b| b.to_string()),
            opt(measured(p, l.binary64_ns_per_state))
        );
    }
    let bx = |p: &PrecisionReport| p.budget.unwrap_or(1.0).log10();
    let (x_lo, x_hi) =
        pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(bx(p)), hi.max(bx(p))));
    let (x_lo, x_hi) = if x_lo.is_finite() { (x_lo - 0.4, x_hi + 0.4) } else { (-10.4, -1.6) };
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE2);
        let area = titled(&root, d)?;
        let (top, bottom) = area.split_vertically(SIZE2.1 * 11 / 20);
        let mut chart = ChartBuilder::on(&top)
            .caption(format!("Cost against error budget (precision, target {})", l.target), ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(x_lo..x_hi, 0f64..1.45)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("error budget, relative to each output's largest magnitude over the domain (log scale)")
            .y_desc("fraction")
            .x_labels(((x_hi - x_lo).ceil() as usize + 1).max(2))
            .x_label_formatter(&pow_tick)
            .y_label_formatter(&|v: &f64| if *v <= 1.0 + 1e-9 { format!("{v:.1}") } else { String::new() })
            .light_line_style(RGBColor(242, 242, 242))
            .draw()
            .map_err(err)?;
        let share = |p: &PrecisionReport, k: usize| {
            let (a, b, c) = per_kind(p);
            let n = (a + b + c).max(1) as f64;
            [a, b, c][k] as f64 / n
        };
        let c0 = PALETTE[0];
        chart
            .draw_series(LineSeries::new(pts.iter().map(|p| (bx(p), ratio(p))), c0.stroke_width(2)))
            .map_err(err)?
            .label(format!("model cost after / before ({})", unit(l.target)))
            .legend(line_key(c0, 2));
        chart.draw_series(pts.iter().map(|p| Circle::new((bx(p), ratio(p)), 4, c0.filled()))).map_err(err)?;
        // The measured time of each point's C against binary64's, where measured (target c).
        let timed: Vec<(f64, f64)> =
            pts.iter().filter_map(|p| measured(p, l.binary64_ns_per_state).map(|r| (bx(p), r.min(1.45)))).collect();
        if !timed.is_empty() {
            let c = PALETTE[3];
            chart
                .draw_series(LineSeries::new(timed.iter().copied(), c.stroke_width(2)))
                .map_err(err)?
                .label(format!(
                    "measured ns/state after / before (best batch of 8, 16 / binary64's best, batch={}; this machine)",
                    l.binary64_batch.unwrap_or(0)
                ))
                .legend(line_key(c, 2));
            chart.draw_series(timed.iter().map(|&p| Cross::new(p, 5, c.stroke_width(2)))).map_err(err)?;
        }
        let mut kinds = vec![(1usize, "share of values in binary32")];
        if pts.iter().any(|p| per_kind(p).2 > 0) {
            kinds.push((2, "share of values in 32-bit fixed point"));
        }
        for (i, (k, label)) in kinds.into_iter().enumerate() {
            let c = PALETTE[i + 1];
            chart
                .draw_series(DashedLineSeries::new(pts.iter().map(|p| (bx(p), share(p, k))), 6, 4, c.stroke_width(2)))
                .map_err(err)?
                .label(label)
                .legend(line_key(c, 2));
            chart
                .draw_series(pts.iter().map(|p| TriangleMarker::new((bx(p), share(p, k)), 5, c.filled())))
                .map_err(err)?;
        }
        legend(&mut chart)?;

        // Below: the certified bound reached against the budget.
        let floor = 1e-18;
        let ys: Vec<f64> = pts.iter().flat_map(|p| [l10(p.max_rel_to_range, floor), bx(p)]).collect();
        let y_lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let y_hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (y_lo, y_hi) = if y_lo.is_finite() { (y_lo.floor() - 0.5, y_hi.ceil() + 1.5) } else { (-12.0, 0.0) };
        let mut chart = ChartBuilder::on(&bottom)
            .caption("Certified bound reached (error-bound over the domain)", ("sans-serif", 14))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("error budget (log scale)")
            .y_desc("largest bound / output range (log)")
            .x_labels(((x_hi - x_lo).ceil() as usize + 1).max(2))
            .y_labels(((y_hi - y_lo).ceil() as usize + 1).clamp(2, 12))
            .x_label_formatter(&pow_tick)
            .y_label_formatter(&pow_tick)
            .light_line_style(RGBColor(242, 242, 242))
            .draw()
            .map_err(err)?;
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(DashedLineSeries::new(vec![(x_lo, x_lo), (x_hi, x_hi)], 6, 4, grey.stroke_width(1)))
            .map_err(err)?
            .label("bound = budget")
            .legend(line_key(grey, 1));
        let c = PALETTE[2];
        chart
            .draw_series(LineSeries::new(
                pts.iter().map(|p| (bx(p), l10(p.max_rel_to_range, floor))),
                c.stroke_width(2),
            ))
            .map_err(err)?
            .label("certified max bound / range, chosen formats")
            .legend(line_key(c, 2));
        chart
            .draw_series(pts.iter().map(|p| Circle::new((bx(p), l10(p.max_rel_to_range, floor)), 4, c.filled())))
            .map_err(err)?;
        legend_at(&mut chart, SeriesLabelPosition::UpperLeft)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "budget",
        caption: format!(
            "Cost against error budget: `precision`'s chooser run again at each budget (relative to each output's \
             largest magnitude over the domain) with the pipeline's target ({}) and domain; the cost is the target's \
             cost model ({}), not measured ns or µs; below, the certified bound the chosen formats reach (the rows of \
             the table above){}",
            l.target,
            unit(l.target),
            if l.binary64_ns_per_state.is_some() {
                "; with target c, each point's C is also timed on the machine that made the report \
                 (`ns_per_state`, the faster of batch=8 and batch=16, against the faster binary64 C of batch=4 \
                 and batch=8, `measured_ratio`: one process each, medians)"
            } else {
                ""
            }
        ),
        svg,
        csv,
    })
}

/// A point's measured ns per state over the binary64 baseline's, when both were measured.
fn measured(p: &PrecisionReport, baseline: Option<f64>) -> Option<f64> {
    match (p.ns_per_state, baseline) {
        (Some(ns), Some(b)) if b > 0.0 => Some(ns / b),
        _ => None,
    }
}

/// What the target's cost model counts.
fn unit(target: &str) -> &'static str {
    match target {
        "mcu" => "estimated cycles of a microcontroller without FPU",
        _ => "ops, binary32 op ½",
    }
}
