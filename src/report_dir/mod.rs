//! `-report-dir=DIR` (issue 13): the report of a run as a folder a researcher can read —
//! `report.json` (SPEC §7, the same text `-report` writes), `report.md` (a readable summary
//! with the tables and the figures embedded) and SVG figures of seed ch. 2–3, each with a CSV
//! of the numbers it draws (`cycles.svg` + `cycles.csv`, …).
//!
//! **Design.** The figures are drawn from the report JSON itself, read back by key
//! ([`data::ReportData`]: `sweep` rows, `placement`, `pareto` rows, each as the row type the
//! pass that writes it declares), never from the passes' artifacts: the driver stays ignorant
//! of passes, a figure can only show numbers the report holds (what the tests check through the
//! CSVs), and a new report key gets a figure by
//! adding one function to [`figures`]. Figures whose numbers the report lacks are not drawn
//! (no `sweep` → no cycles-vs-N figures; an unplaced final IR → no occupation or timeline; no
//! `-pareto` → no Pareto figure); `report.md` says which are missing and why.
//!
//! The folder is written as a whole ([`crate::output::OutputSet::stage_folder`]: temporary
//! folder beside `DIR`, then one rename), with the run's other outputs.

pub mod data;
pub mod figures;
mod markdown;

pub use markdown::markdown;

/// The files of the report folder for `report` (the report JSON's text): `(file name, bytes)`,
/// `report.json` first.
///
/// # Errors
/// A message when the report cannot be read back or a figure cannot be drawn (internal errors).
pub fn files(report_text: &str) -> Result<Vec<(String, Vec<u8>)>, String> {
    let value: serde_json::Value = serde_json::from_str(report_text).map_err(|e| format!("report.json: {e}"))?;
    let d = data::ReportData::read(&value)?;
    let figs = figures::all(&d)?;
    let mut out = vec![("report.json".to_string(), report_text.as_bytes().to_vec())];
    out.push(("report.md".to_string(), markdown(&value, &d, &figs).into_bytes()));
    for f in figs {
        out.push((format!("{}.svg", f.name), f.svg.into_bytes()));
        out.push((format!("{}.csv", f.name), f.csv.into_bytes()));
    }
    Ok(out)
}
