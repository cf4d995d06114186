//! `-report-dir=DIR` (issue 13): the report of a run as a folder a researcher can read —
//! `report.json` (SPEC §7, the same text `-report` writes), `report.md` (a readable summary
//! with the tables and the figures embedded) and SVG figures of seed ch. 2–3, each with a CSV
//! of the numbers it draws (`cycles.svg` + `cycles.csv`, …).
//!
//! **Design.** The figures are drawn from the report's rows as the run made them
//! ([`data::ReportData`]: `sweep` rows, `placement`, `pareto` rows, each the type the pass
//! declares and the report writes under the same key), never parsed back from the JSON: a
//! figure shows only numbers the report holds (what the tests check through the CSVs), and a
//! new report key gets a figure by adding one function to [`figures`]. `report.md` renders
//! the report JSON it sits beside (its tables of `stats`, `placement`, …). Figures whose numbers the report lacks are not drawn
//! (no `sweep` → no cycles-vs-N figures; an unplaced final IR → no occupation or timeline; no
//! `-pareto` → no Pareto figure); `report.md` says which are missing and why.
//!
//! The folder is written as a whole ([`crate::output::OutputSet::stage_folder`]: temporary
//! folder beside `DIR`, then one rename), with the run's other outputs.

pub mod cpu_line;
pub mod data;
pub mod figures;
pub mod ladder_time;
mod markdown;

pub use markdown::markdown;

/// The files of the report folder for `report_text` (the report JSON's text) and `d` (the rows
/// its figures draw, [`data::ReportData::of`] of the same run): `(file name, bytes)`,
/// `report.json` first.
///
/// # Errors
/// A message when the report text is not JSON or a figure cannot be drawn (internal errors).
pub fn files(report_text: &str, d: &data::ReportData) -> Result<Vec<(String, Vec<u8>)>, String> {
    let figs = figures::all(d)?;
    let mut out = vec![("report.json".to_string(), report_text.as_bytes().to_vec())];
    out.push(("report.md".to_string(), markdown(d, &figs).into_bytes()));
    for f in figs {
        out.push((format!("{}.svg", f.name), f.svg.into_bytes()));
        out.push((format!("{}.csv", f.name), f.csv.into_bytes()));
    }
    Ok(out)
}
