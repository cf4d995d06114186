//! The SVG figures of `-report-dir` (seed ch. 2–3), drawn with `plotters`' SVG backend, each
//! with the CSV of exactly the numbers it draws (written with Rust's shortest round-trip
//! formatting, so they read back equal to the report's).
//!
//! Text is laid out with plotters' built-in size estimate (no font files: the SVG backend
//! writes `<text>` elements and the viewer renders them with its own sans-serif font).

use plotters::coord::Shift;
use plotters::prelude::*;

use robovec_passes::sweep::{SweepRow, WordStats};
use robovec_passes::whole_run::pareto::ParetoRow;

use super::data::ReportData;

/// One figure: file stem, title, SVG text and companion CSV.
#[derive(Clone, Debug)]
pub struct Figure {
    /// File stem: `NAME.svg` and `NAME.csv`.
    pub name: &'static str,
    /// What it shows (the report.md caption).
    pub caption: String,
    /// The SVG document.
    pub svg: String,
    /// The numbers drawn, CSV with a header line.
    pub csv: String,
}

/// Size of a single-panel figure, pixels.
pub(crate) const SIZE: (u32, u32) = (900, 560);

/// Series colours (colour-blind safe: Okabe–Ito).
pub(crate) const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
];

type Result<T> = std::result::Result<T, String>;

/// One drawn series: legend label, points (x, y), and whether it is a dashed (bound) or thin
/// (min/max) line rather than the main line with markers.
type Series = (String, Vec<(f64, f64)>, bool);

/// A memory panel: its title and the words it reads from a sweep row.
type Panel = (&'static str, fn(&SweepRow) -> WordStats);

fn err(e: impl std::fmt::Display) -> String {
    format!("drawing a figure failed: {e}")
}

/// The first title line: model, function and pipeline (shortened to fit `width` pixels).
fn heading(d: &ReportData, width: u32) -> String {
    let head = format!("{} @{}, pipeline ", d.model, d.function);
    // About 6.5 pixels per character at 13 px.
    let room = (width as usize * 10 / 65).saturating_sub(head.chars().count() + 4).max(12);
    let mut p = d.pipeline.clone();
    if p.chars().count() > room {
        p = p.chars().take(room - 3).collect::<String>() + "...";
    }
    head + &p
}

/// Writes the heading line at the top of `area` and returns the area below it.
fn titled<'a>(area: &DrawingArea<SVGBackend<'a>, Shift>, d: &ReportData) -> Result<DrawingArea<SVGBackend<'a>, Shift>> {
    let width = area.dim_in_pixel().0;
    area.titled(&heading(d, width), ("sans-serif", 13).into_font().color(&RGBColor(90, 90, 90))).map_err(err)
}

/// Axis numbers: no decimals on large ranges, two on small ones.
fn tick(v: &f64) -> String {
    if v.abs() >= 10.0 || v.fract() == 0.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// Tick text of the log₂ N axis: `2^x` at integer x, nothing between.
fn n_tick(x: &f64) -> String {
    if (x - x.round()).abs() < 1e-6 && *x >= 0.0 {
        format!("{}", 1u64 << (x.round() as u32).min(40))
    } else {
        String::new()
    }
}

/// Every figure the report's numbers allow, in report.md order.
///
/// # Errors
/// A message when plotting fails (an internal error).
pub fn all(d: &ReportData) -> Result<Vec<Figure>> {
    let mut out = Vec::new();
    if !d.sweep.is_empty() {
        out.push(cycles(d)?);
        out.push(microseconds(d)?);
        out.push(parallelisation(d)?);
        out.push(memory(d)?);
    }
    if let Some(p) = &d.placement {
        if p.cycles > 0 {
            out.push(occupation(d)?);
            out.push(timeline(d)?);
        }
    }
    if !d.pareto.is_empty() {
        out.push(pareto(d)?);
    }
    Ok(out)
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

fn max_of(xs: impl Iterator<Item = f64>) -> f64 {
    xs.fold(0.0f64, f64::max)
}

fn svg_area(buf: &mut String, size: (u32, u32)) -> DrawingArea<SVGBackend<'_>, Shift> {
    let root = SVGBackend::with_string(buf, size).into_drawing_area();
    let _ = root.fill(&WHITE);
    root
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
    chart
        .configure_mesh()
        .x_desc("N (ADD PEs = MULTI PEs), log scale")
        .y_desc(y_desc)
        .x_labels(((range.end - range.start).ceil() as usize + 1).max(2))
        .x_label_formatter(&n_tick)
        .y_label_formatter(&tick)
        .light_line_style(RGBColor(242, 242, 242))
        .draw()
        .map_err(err)?;
    for (i, (label, pts, dashed)) in series.iter().enumerate() {
        let c = PALETTE[i % PALETTE.len()];
        if *dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.iter().copied(), 6, 4, c.stroke_width(2)))
                .map_err(err)?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        } else {
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                .map_err(err)?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(err)?;
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
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1)));
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
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
fn cycles(d: &ReportData) -> Result<Figure> {
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
/// `column`, chart title `what` and y label `y_label`.
fn per_config(
    d: &ReportData,
    (name, caption): (&'static str, String),
    (what, y_label): (&str, &str),
    column: &str,
    value: fn(&SweepRow) -> f64,
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
    let mut svg = String::new();
    {
        let root = svg_area(&mut svg, SIZE);
        let area = titled(&root, d)?;
        n_chart(&area, what, y_label, &ns, &series, &[])?;
        root.present().map_err(err)?;
    }
    Ok(Figure { name, caption, svg, csv })
}

/// µs against N at the target's clock.
fn microseconds(d: &ReportData) -> Result<Figure> {
    let clock = d.sweep.iter().find(|r| r.us > 0.0).map(|r| f64::from(r.cycles) / r.us);
    let what = match clock {
        Some(mhz) => format!("µs vs N at {mhz:.0} MHz"),
        None => "µs vs N".into(),
    };
    per_config(
        d,
        ("microseconds", "Time of one evaluation (µs) against N at the target's clock".into()),
        (&what, "time (µs)"),
        "us",
        |r| r.us,
    )
}

/// Seed Fig. 3.9–3.13: parallelisation rate against N.
fn parallelisation(d: &ReportData) -> Result<Figure> {
    per_config(
        d,
        ("parallelisation", "Parallelisation rate ops / (cycles × 2N) against N (seed Fig. 3.9–3.13)".into()),
        ("Parallelisation rate vs N", "parallelisation rate (ops / (cycles x 2N))"),
        "parallelisation_rate",
        |r| r.parallelisation_rate,
    )
}

/// Seed Fig. 2.4–2.7: PE memory and buffer words per PE (min / mean / max), naive against
/// preferential selection (classical priority, the seed's algorithm alone).
fn memory(d: &ReportData) -> Result<Figure> {
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
    chart
        .configure_mesh()
        .x_desc("N, log scale")
        .y_desc(y_desc)
        .x_labels(((range.end - range.start).ceil() as usize + 1).max(2))
        .x_label_formatter(&n_tick)
        .y_label_formatter(&tick)
        .light_line_style(RGBColor(242, 242, 242))
        .draw()
        .map_err(err)?;
    for (i, (label, pts, dashed)) in series.iter().enumerate() {
        let c = PALETTE[(i / 3) % PALETTE.len()];
        if *dashed {
            let c = c.mix(0.55);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(1)))
                .map_err(err)?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(1)));
        } else {
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                .map_err(err)?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(err)?;
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

/// Seed Fig. 3.15–3.38: occupation rate of the ADD and MULTI PEs over normalised time, at the
/// final placement's N (`placement.occupation`: rolling mean over 50 cycles).
fn occupation(d: &ReportData) -> Result<Figure> {
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
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
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
fn timeline(d: &ReportData) -> Result<Figure> {
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
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "timeline",
        caption: "Placement timeline: each op's issue slot on its PE over the first cycles of the placement".into(),
        svg,
        csv,
    })
}

/// The speed-against-error plane of `-pareto`: time (placed cycles, else critical path)
/// against mean bits of error in binary32 and binary64; Pareto-optimal rows joined.
fn pareto(d: &ReportData) -> Result<Figure> {
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
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c32.stroke_width(1)));
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
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok(Figure {
        name: "pareto",
        caption: "Speed against error of the -pareto pipelines (numbers: the rows of the table above); the line joins the Pareto-optimal rows".into(),
        svg,
        csv,
    })
}
