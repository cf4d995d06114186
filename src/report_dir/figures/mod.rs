//! The SVG figures of `-report-dir` (seed ch. 2–3), drawn with `plotters`' SVG backend, each
//! with the CSV of exactly the numbers it draws (written with Rust's shortest round-trip
//! formatting, so they read back equal to the report's).
//!
//! Text is laid out with plotters' built-in size estimate (no font files: the SVG backend
//! writes `<text>` elements and the viewer renders them with its own sans-serif font).
//!
//! This file has what every figure shares (the heading, ticks, colours); `sweep.rs` the figures
//! over N (cycles, µs, parallelisation, memory), `placement.rs` the placed function's
//! occupation and timeline, `pareto.rs` speed against error, `budget.rs` the cost of
//! `precision`'s formats against the error budget.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::data::ReportData;

pub(crate) mod budget;
mod pareto;
mod placement;
mod sweep;

use budget::budget;
use pareto::pareto;
use placement::{occupation, timeline};
use sweep::{cycles, memory, microseconds, parallelisation};

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

pub(crate) type Result<T> = std::result::Result<T, String>;

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

/// Draws the legend of `chart`'s labelled series in the upper right corner, on a white box.
fn legend<'a, CT: plotters::coord::CoordTranslate>(chart: &mut ChartContext<'a, SVGBackend<'a>, CT>) -> Result<()> {
    legend_at(chart, SeriesLabelPosition::UpperRight)
}

/// [`legend`] at `position`.
fn legend_at<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// The legend key of a line series: a 20-pixel line of colour `c`, `width` pixels wide.
fn line_key<C: Color + 'static>(c: C, width: u32) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(width))
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
    if d.precision_ladder.as_ref().is_some_and(|l| !l.points.is_empty()) {
        out.push(budget(d)?);
    }
    Ok(out)
}

fn max_of(xs: impl Iterator<Item = f64>) -> f64 {
    xs.fold(0.0f64, f64::max)
}

fn svg_area(buf: &mut String, size: (u32, u32)) -> DrawingArea<SVGBackend<'_>, Shift> {
    let root = SVGBackend::with_string(buf, size).into_drawing_area();
    let _ = root.fill(&WHITE);
    root
}
