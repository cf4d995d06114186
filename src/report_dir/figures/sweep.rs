//! The figures over N (seed ch. 3): cycles, µs, parallelisation and memory of the sweep's
//! configurations.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use robovec_passes::sweep::{SweepRow, WordStats};

use super::{err, legend, line_key, max_of, svg_area, tick, titled, Figure, Result, PALETTE, SIZE};
use crate::report_dir::data::ReportData;

/// One drawn series: legend label, points (x, y), and whether it is a dashed (bound) or thin
/// (min/max) line rather than the main line with markers.
type Series = (String, Vec<(f64, f64)>, bool);

/// A memory panel: its title and the words it reads from a sweep row.
type Panel = (&'static str, fn(&SweepRow) -> WordStats);

/// Tick text of the log₂ N axis: `2^x` at integer x, nothing between.
fn n_tick(x: &f64) -> String {
    if (x - x.round()).abs() < 1e-6 && *x >= 0.0 {
        format!("{}", 1u64 << (x.round() as u32).min(40))
    } else {
        String::new()
    }
}

/// The configurations of the sweep in first-appearance order.
fn configs(rows: &[SweepRow]) -> Vec<String> {
    let mut c: Vec<String> = Vec::new();
    for r in rows {
        if !c.contains(&r.config()) {
            c.push(r.config());
        }
    }
    c
}

/// The N of the sweep, ascending, each once.
fn ns(rows: &[SweepRow]) -> Vec<u32> {
    let mut n: Vec<u32> = rows.iter().map(|r| r.n).collect();
    n.sort_unstable();
    n.dedup();
    n
}

/// The x coordinate of N: log₂ N (the seed's figures double N at each step).
fn lx(n: u32) -> f64 {
    (n.max(1) as f64).log2()
}

/// The x range around the sweep's N, in log₂ N.
fn n_range(ns: &[u32]) -> std::ops::Range<f64> {
    let lo = lx(ns.first().copied().unwrap_or(1));
    let hi = lx(ns.last().copied().unwrap_or(1));
    (lo - 0.3)..(hi + 0.3)
}

/// Draws `series` (label, points) as lines with markers on a log-N chart.
fn n_chart(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: &str,
    y_desc: &str,
    ns: &[u32],
    series: &[Series],
    marks: &[(String, f64)],
) -> Result<()> {
    // Head room above the data for the legend.
    let y_max = max_of(series.iter().flat_map(|s| s.1.iter().map(|p| p.1))).max(1e-9) * 1.45;
    let range = n_range(ns);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(range.clone(), 0f64..y_max)
        .map_err(err)?;
    n_mesh(&mut chart, "N (ADD PEs = MULTI PEs), log scale", y_desc, &range)?;
    for (i, (label, pts, dashed)) in series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        if *dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.iter().copied(), 6, 4, c.stroke_width(2)))
                .map_err(err)?
                .label(label.as_str())
                .legend(line_key(c, 2));
        } else {
            marked_line(&mut chart, label, pts, c)?;
        }
    }
    for (label, y) in marks {
        let x = &y.max(1e-9).log2();
        if *x > range.start && *x < range.end {
            let grey = RGBColor(120, 120, 120);
            chart
                .draw_series(DashedLineSeries::new(vec![(*x, 0.0), (*x, y_max)], 4, 4, grey.stroke_width(1)))
                .map_err(err)?
                .label(label.as_str())
                .legend(line_key(grey, 1));
        }
    }
    legend(&mut chart)?;
    Ok(())
}

/// Rows of one configuration, by N.
fn of_config<'a>(rows: &'a [SweepRow], config: &str) -> Vec<&'a SweepRow> {
    let mut v: Vec<&SweepRow> = rows.iter().filter(|r| r.config() == config).collect();
    v.sort_by_key(|r| r.n);
    v
}

/// One row per N: the first sweep row at that N (the bounds do not depend on the configuration).
fn per_n(rows: &[SweepRow]) -> Vec<&SweepRow> {
    ns(rows).into_iter().filter_map(|n| rows.iter().find(|r| r.n == n)).collect()
}

/// Seed Fig. 3.4–3.8: cycles against N for each configuration, the two lower-bound curves and
/// N = Y marked.
pub(super) fn cycles(d: &ReportData) -> Result<Figure> {
    let rows = &d.sweep;
    let ns = ns(rows);
    let mut series: Vec<Series> = Vec::new();
    let mut csv = String::from("configuration,n,cycles\n");
    for c in configs(rows) {
        let pts: Vec<(f64, f64)> = of_config(rows, &c).iter().map(|r| (lx(r.n), f64::from(r.cycles))).collect();
        for r in of_config(rows, &c) {
            csv += &format!("{c},{},{}\n", r.n, r.cycles);
        }
        series.push((c, pts, false));
    }
    let bounds = per_n(rows);
    series.push((
        "lower bound 1: ops / N + latency".into(),
        bounds.iter().map(|r| (lx(r.n), f64::from(r.resource_bound))).collect(),
        true,
    ));
    series.push((
        "lower bound 2: critical path".into(),
        bounds.iter().map(|r| (lx(r.n), f64::from(r.critical_path))).collect(),
        true,
    ));
    for r in &bounds {
        csv += &format!("resource_bound,{},{}\n", r.n, r.resource_bound);
        csv += &format!("critical_path,{},{}\n", r.n, r.critical_path);
    }
    let y = rows[0].y;
    csv += &format!("y,{y},\n");
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE);
        let area = titled(&root, d)?;
        n_chart(&area, "Cycles vs N", "cycles", &ns, &series, &[(format!("N = Y = {y:.2}"), y)])?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "cycles",
        caption: "Cycles against N per configuration, with the two lower-bound curves of seed §3.3 and N = Y marked (seed Fig. 3.4–3.8)".into(),
        svg,
        csv,
    })
}

/// One line per sweep configuration of `value` against N: the figure `name`, its CSV column
/// `column`, chart title `what` and y label `y_label`; then the dashed lines `flat` (label,
/// CSV row name, y: a value that does not depend on N).
fn per_config(
    d: &ReportData,
    (name, caption): (&'static str, String),
    (what, y_label): (&str, &str),
    column: &str,
    value: fn(&SweepRow) -> f64,
    flat: &[(String, String, f64)],
) -> Result<Figure> {
    let rows = &d.sweep;
    let ns = ns(rows);
    let mut series = Vec::new();
    let mut csv = format!("configuration,n,{column}\n");
    for c in configs(rows) {
        let of = of_config(rows, &c);
        for r in &of {
            csv += &format!("{c},{},{}\n", r.n, value(r));
        }
        series.push((c, of.iter().map(|r| (lx(r.n), value(r))).collect(), false));
    }
    for (label, row, y) in flat {
        csv += &format!("{row},,{y}\n");
        series.push((label.clone(), ns.iter().map(|&n| (lx(n), *y)).collect(), true));
    }
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE);
        let area = titled(&root, d)?;
        n_chart(&area, what, y_label, &ns, &series, &[])?;
        root.present().map_err(err)?;
    }
    Ok(Figure { name, caption, svg, csv })
}

/// µs against N at the target's clock, with the function's C on this machine (one state, and
/// per state in a batch) as horizontal dashed lines when `-report-dir` timed it.
pub(super) fn microseconds(d: &ReportData) -> Result<Figure> {
    let clock = d.sweep.iter().find(|r| r.us > 0.0).map(|r| f64::from(r.cycles) / r.us);
    let what = match clock {
        Some(mhz) => format!("µs vs N at {mhz:.0} MHz"),
        None => "µs vs N".into(),
    };
    let mut caption = "Time of one evaluation (µs) against N at the target's clock".to_string();
    let mut flat = Vec::new();
    if let Some(cpu) = &d.cpu {
        caption += &format!(
            "; dashed, the function's C on the machine that made the report ({}): one state per call and per state at batch={}",
            cpu.build, cpu.batch
        );
        flat.push(("robovec's C, one state per call (this machine)".into(), "cpu_one_state".into(), cpu.one_state_us));
        flat.push((
            format!("robovec's C, batch={}, per state (this machine)", cpu.batch),
            format!("cpu_batch{}", cpu.batch),
            cpu.batched_us,
        ));
    }
    per_config(d, ("microseconds", caption), (&what, "time (µs)"), "us", |r| r.us, &flat)
}

/// Parallelisation rate against N (seed Fig. 3.9–3.13).
pub(super) fn parallelisation(d: &ReportData) -> Result<Figure> {
    per_config(
        d,
        ("parallelisation", "Parallelisation rate ops / (cycles × 2N) against N (seed Fig. 3.9–3.13)".into()),
        ("Parallelisation rate vs N", "parallelisation rate (ops / (cycles x 2N))"),
        "parallelisation_rate",
        |r| r.parallelisation_rate,
        &[],
    )
}

/// Seed Fig. 2.4–2.7: PE memory and buffer words per PE (min / mean / max), naive against
/// preferential selection (classical priority, the seed's algorithm alone).
pub(super) fn memory(d: &ReportData) -> Result<Figure> {
    let rows = &d.sweep;
    let ns = ns(rows);
    let picks: [Panel; 4] = [
        ("PE memory, ADD PEs", |r| r.pe_words_add),
        ("PE memory, MULTI PEs", |r| r.pe_words_mul),
        ("buffer, ADD PEs", |r| r.buffer_words_add),
        ("buffer, MULTI PEs", |r| r.buffer_words_mul),
    ];
    let selections = [("naive", "classical/naive"), ("preferential", "classical")];
    let mut csv = String::from("memory,selection,n,min,mean,max\n");
    let mut svg = String::new();
    {
        let top = svg_area(&mut svg, (1100, 820));
        let root = titled(&top, d)?;
        let root = root.titled("Words per PE, naive vs preferential selection", ("sans-serif", 16)).map_err(err)?;
        let panels = root.split_evenly((2, 2));
        for (panel, (what, pick)) in panels.iter().zip(picks) {
            let mut series = Vec::new();
            for (sel, config) in selections {
                let of = of_config(rows, config);
                for r in &of {
                    let w = pick(r);
                    csv += &format!("{what},{sel},{},{},{},{}\n", r.n, w.min, w.mean, w.max);
                }
                series.push((format!("{sel} mean"), of.iter().map(|r| (lx(r.n), pick(r).mean)).collect(), false));
                series.push((
                    format!("{sel} min"),
                    of.iter().map(|r| (lx(r.n), f64::from(pick(r).min))).collect(),
                    true,
                ));
                series.push((
                    format!("{sel} max"),
                    of.iter().map(|r| (lx(r.n), f64::from(pick(r).max))).collect(),
                    true,
                ));
            }
            // Same colour per selection: mean solid, min and max dashed.
            let series: Vec<_> = series.into_iter().collect();
            n_chart_grouped(panel, what, "words per PE", &ns, &series)?;
        }
        top.present().map_err(err)?;
    }
    Ok(Figure {
        name: "memory",
        caption: "PE memory and buffer words per PE (min / mean / max over the PEs of a type), naive against preferential selection (seed Fig. 2.4–2.7)".into(),
        svg,
        csv,
    })
}

/// Like [`n_chart`], with series in groups of three (mean, min, max) sharing a colour.
fn n_chart_grouped(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: &str,
    y_desc: &str,
    ns: &[u32],
    series: &[Series],
) -> Result<()> {
    let y_max = max_of(series.iter().flat_map(|s| s.1.iter().map(|p| p.1))).max(1.0) * 1.7;
    let range = n_range(ns);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(range.clone(), 0f64..y_max)
        .map_err(err)?;
    n_mesh(&mut chart, "N, log scale", y_desc, &range)?;
    for (i, (label, pts, dashed)) in series.iter().enumerate() {
        let c = PALETTE[(i / 3) % PALETTE.len()];
        if *dashed {
            let c = c.mix(0.55);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(1)))
                .map_err(err)?
                .label(label.as_str())
                .legend(line_key(c, 1));
        } else {
            marked_line(&mut chart, label, pts, c)?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 11))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A sweep's series as a line of colour `c` with a marker at each point, labelled `label`.
fn marked_line<'a>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    label: &str,
    pts: &[(f64, f64)],
    c: RGBColor,
) -> Result<()> {
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
        .map_err(err)?
        .label(label)
        .legend(line_key(c, 2));
    chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(err)?;
    Ok(())
}

/// The grid and axes of a log-N chart over `range` (log₂ N): N at the powers of two.
fn n_mesh<'a>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    x_desc: &str,
    y_desc: &str,
    range: &std::ops::Range<f64>,
) -> Result<()> {
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(((range.end - range.start).ceil() as usize + 1).max(2))
        .x_label_formatter(&n_tick)
        .y_label_formatter(&tick)
        .light_line_style(RGBColor(242, 242, 242))
        .draw()
        .map_err(err)
}
