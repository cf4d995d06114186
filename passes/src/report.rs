//! The report JSON of SPEC §7 (`-report`, `-report-dir`'s `report.json`, each case of
//! `robovec-gen --study`): one function's figures after a run, the records of the passes and
//! what each artifact reports for it, in one document.

use crate::summary::Figures;
use crate::{PassContext, PassRecord};

/// The report JSON text (SPEC §7) of one function after a run: `input` (as given), `function`,
/// `pipeline` (normalised text), `passes` (the records), the function's own figures (`stats`,
/// `placement`), each artifact's entry for it (merged by key), then `stopped_early` when a pass
/// stopped early. What `robovec-opt -report` writes; `robovec-gen --study` calls it for each
/// case's report folder.
pub fn report_text(input: &str, pipeline: &str, records: &[PassRecord], cx: &PassContext, own: &Figures) -> String {
    let mut r = serde_json::Map::new();
    r.insert("input".into(), input.into());
    r.insert("function".into(), own.function.clone().into());
    r.insert("pipeline".into(), pipeline.into());
    r.insert("passes".into(), serde_json::to_value(records).expect("records serialise"));
    let entries =
        own.report_entries().into_iter().chain(crate::artifact::report_entries(cx.artifacts(), &own.function));
    for (key, value) in entries {
        r.insert(key.into(), value);
    }
    let stopped = cx.stopped();
    if !stopped.is_empty() {
        r.insert("stopped_early".into(), stopped.into());
    }
    serde_json::to_string_pretty(&serde_json::Value::Object(r)).expect("report serialises") + "\n"
}
