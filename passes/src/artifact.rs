//! Artifacts: what a pass produces besides the IR — figures, tables, files, generated code —
//! as typed values the pass owns and knows how to render.
//!
//! A pass hands its artifacts to the run with [`crate::PassContext::emit`]; the manager tags
//! each with the pipeline element that made it. After the pipeline the driver renders them
//! without knowing which pass made which: their lines on stderr ([`Artifact::log_text`], and
//! [`Artifact::stats_text`] under `-stats`), their entries in the JSON report
//! ([`Artifact::report`], SPEC §7), their CSV table (`-sweep-csv`), the files their parameters
//! name ([`Artifact::files`]) and, for a back end, the generated code that `-o` writes instead
//! of the IR ([`Artifact::code`], SPEC §8). This is naga's and Cranelift's split between a
//! pass and its output, and what LLVM's `opt` does with analysis printers.

use std::fmt::Debug;
use std::path::{Path, PathBuf};

/// How report entries with the same key, from several artifacts, combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Merge {
    /// The entries are JSON arrays; the report holds their concatenation, in pipeline order
    /// (`sweep` rows, `eqsat` runs).
    Append,
    /// The last entry wins (`accuracy`, `sim`, `codegen`: the last run describes the final IR).
    Last,
}

/// One entry of the JSON report (SPEC §7) for one function.
#[derive(Clone, Debug)]
pub struct ReportEntry {
    /// The report's key (`sweep`, `accuracy`, `codegen`…).
    pub key: &'static str,
    /// Its value (an array when `merge` is [`Merge::Append`]).
    pub value: serde_json::Value,
    /// How it combines with entries of the same key.
    pub merge: Merge,
}

impl ReportEntry {
    /// An entry from anything serialisable.
    ///
    /// # Panics
    /// When `value` does not serialise to JSON (report types are plain data: they always do).
    pub fn new(key: &'static str, value: &impl serde::Serialize, merge: Merge) -> ReportEntry {
        ReportEntry { key, value: serde_json::to_value(value).expect("report values serialise"), merge }
    }
}

/// A file an artifact writes at a path its pass's parameters name (`accuracy<worst=DIR>`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArtifactFile {
    /// Where it goes.
    pub path: PathBuf,
    /// Its content.
    pub bytes: Vec<u8>,
    /// True for a program (`codegen<fpga>`'s `simulate`): written with the execute bits set
    /// (`rwxr-xr-x` for a new file; an existing file's mode plus execute where it can read).
    pub executable: bool,
}

/// Generated code: a back end's main output. When the pipeline's last pass produced it, `-o
/// FILE` (or stdout) receives [`GeneratedCode::main`] instead of the IR (SPEC §8), and each
/// companion goes beside `FILE` with its own extension.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeneratedCode {
    /// Language of `main`, for messages (`C`).
    pub language: &'static str,
    /// The main file's text.
    pub main: String,
    /// Companion files: `(extension, text)`; with `-o model.c`, `("h", …)` goes to `model.h`.
    /// Not written when the code goes to stdout.
    pub companions: Vec<(&'static str, String)>,
    /// Further translation units (`codegen<c;units=K>`, issue 28): unit `k` (1-based) goes to
    /// [`unit_path`]`(FILE, k)`. Empty for one file; a back end with several units needs
    /// `-o FILE` ([`crate::BackEnd::units`]).
    pub units: Vec<String>,
}

/// Where translation unit `k` of generated code whose main file is `main` goes: `main` for 0,
/// else `_k` before the extension (`model.c`, 2 → `model_2.c`; `dir/model` → `dir/model_2`).
pub fn unit_path(main: &Path, k: usize) -> PathBuf {
    if k == 0 {
        return main.to_path_buf();
    }
    let stem = main.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let name = match main.extension() {
        Some(e) => format!("{stem}_{k}.{}", e.to_string_lossy()),
        None => format!("{stem}_{k}"),
    };
    main.with_file_name(name)
}

/// A typed result of a pass (see the module doc). Every method has a default that renders
/// nothing, so an artifact implements only what it has.
pub trait Artifact: std::any::Any + Debug + Send + Sync {
    /// The pass that made it (`sweep`, `accuracy`, `codegen`…).
    fn pass(&self) -> &'static str;

    /// Text printed on stderr after every run (tables such as `sweep`'s); `detail` is true under
    /// `-stats` (per-output lines and the like).
    fn log_text(&self, _detail: bool) -> String {
        String::new()
    }

    /// Lines printed on stderr under `-stats`, restricted to `function` when given.
    fn stats_text(&self, _function: Option<&str>) -> String {
        String::new()
    }

    /// The report entry describing `function`, if this artifact has one.
    fn report(&self, _function: &str) -> Option<ReportEntry> {
        None
    }

    /// A CSV table (header and rows), what `-sweep-csv=FILE` writes.
    fn csv(&self) -> Option<String> {
        None
    }

    /// Files at paths named by the pass's parameters; `several_functions` is true when the
    /// module has more than one function (file names then carry the function's).
    fn files(&self, _several_functions: bool) -> Vec<ArtifactFile> {
        Vec::new()
    }

    /// Generated code, for a back end.
    fn code(&self) -> Option<&GeneratedCode> {
        None
    }
}

/// An artifact with the position in the pipeline of the element that made it (0-based; `None`
/// for one made outside the pipeline, such as `-pareto`'s).
#[derive(Debug)]
pub struct Produced {
    /// Index of the pipeline element.
    pub pass_index: Option<usize>,
    /// The artifact.
    pub artifact: Box<dyn Artifact>,
}

/// Renders the report entries of `artifacts` for `function`, merged by key (see [`Merge`]),
/// in the order each key first appears.
pub fn report_entries<'a>(
    artifacts: impl IntoIterator<Item = &'a dyn Artifact>,
    function: &str,
) -> Vec<(&'static str, serde_json::Value)> {
    let mut out: Vec<(&'static str, serde_json::Value)> = Vec::new();
    for e in artifacts.into_iter().filter_map(|a| a.report(function)) {
        match out.iter_mut().find(|(k, _)| *k == e.key) {
            Some((_, v)) => match (e.merge, v, e.value) {
                (Merge::Append, serde_json::Value::Array(have), serde_json::Value::Array(more)) => have.extend(more),
                (_, v, value) => *v = value,
            },
            None => out.push((e.key, e.value)),
        }
    }
    out.retain(|(_, v)| !matches!(v, serde_json::Value::Array(a) if a.is_empty()));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Rows(&'static str, Merge, serde_json::Value);

    impl Artifact for Rows {
        fn pass(&self) -> &'static str {
            "test"
        }
        fn report(&self, function: &str) -> Option<ReportEntry> {
            (function == "f").then(|| ReportEntry { key: self.0, value: self.2.clone(), merge: self.1 })
        }
    }

    #[test]
    fn entries_append_or_replace_by_key_in_first_appearance_order() {
        let a = Rows("sweep", Merge::Append, serde_json::json!([1, 2]));
        let b = Rows("accuracy", Merge::Last, serde_json::json!({"n": 1}));
        let c = Rows("sweep", Merge::Append, serde_json::json!([3]));
        let d = Rows("accuracy", Merge::Last, serde_json::json!({"n": 2}));
        let e = Rows("eqsat", Merge::Append, serde_json::json!([]));
        let all: Vec<&dyn Artifact> = vec![&a, &b, &c, &d, &e];
        let got = report_entries(all.iter().copied(), "f");
        assert_eq!(
            got,
            vec![("sweep", serde_json::json!([1, 2, 3])), ("accuracy", serde_json::json!({"n": 2}))],
            "appended rows, the last accuracy, no empty list"
        );
        assert!(report_entries(all.iter().copied(), "g").is_empty());
    }
}
