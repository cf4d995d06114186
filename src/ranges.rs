//! The run's input domain (issue 48): the input's defaults ([`robovec_front::Loaded::domain_defaults`],
//! a URDF's limits and parameters) overridden by `-ranges=FILE` ([`robovec_ir::domain`]),
//! resolved once after loading for the inputs of the module's functions (those a URDF's `-function`
//! built; every function of a Robotran file, as the passes see them), and
//! handed to the passes as [`robovec_passes::PassContext::domain`].

use std::collections::BTreeMap;
use std::path::Path;

use robovec_ir::domain::{self, Domain, Range};
use robovec_ir::Module;

use crate::diagnostics::SourceFile;
use crate::options::{Failure, Options};

/// The domain of the run: `defaults` overridden by `-ranges=FILE` over the inputs of the
/// module's functions (a key must match an input of one of them); when `required` names a pass
/// (the first of the pipeline that needs the domain, `robovec_passes::Props::needs_domain`),
/// every one of their inputs must have a range.
///
/// # Errors
/// [`Failure::Input`] (exit 1): the ranges file cannot be read or is refused (a codespan
/// diagnostic at the key: not JSON, a bad `[lo, hi]`, a key given twice, a key matching no
/// input), or, when `required`, inputs without a range (all named, with the hint `-ranges=FILE`).
pub fn domain(
    opts: &Options,
    module: &Module,
    defaults: &BTreeMap<String, Range>,
    required: Option<&str>,
) -> Result<Domain, Failure> {
    // Every function of the module: passes run on all of them (`-function` selects what the
    // report and `-eval` describe, not what the passes see).
    let functions: Vec<&robovec_ir::Function> = module.functions.iter().collect();
    let mut inputs: Vec<&str> = functions.iter().flat_map(|f| f.inputs.iter().map(|&v| f.name_of(v))).collect();
    inputs.sort_unstable();
    inputs.dedup();
    let dom = match &opts.ranges {
        None => domain::resolve(defaults, None, inputs.iter().copied())
            .map_err(|e| Failure::Input(format!("error: {e}\n")))?,
        Some(path) => {
            let text = std::fs::read(path)
                .map_err(|e| Failure::Input(format!("error: cannot read -ranges file `{}`: {e}\n", path.display())))?;
            let src = SourceFile::from_bytes(path.display().to_string(), &text);
            let render = |e: robovec_ir::SourceError| {
                Failure::Input(src.render(&[e.to_diagnostic(()).with_message(format!("-ranges: {}", e.message))]))
            };
            let keys = domain::parse_ranges(&src.text).map_err(render)?;
            let name = display_name(path);
            domain::resolve(defaults, Some((&name, &keys)), inputs.iter().copied()).map_err(render)?
        }
    };
    if let Some(pass) = required {
        let mut missing: Vec<String> = Vec::new();
        for f in &functions {
            for n in dom.missing(f) {
                if !missing.iter().any(|m| m == n) {
                    missing.push(n.to_string());
                }
            }
        }
        if !missing.is_empty() {
            let shown: Vec<&str> = missing.iter().take(16).map(String::as_str).collect();
            let more = match missing.len() - shown.len() {
                0 => String::new(),
                k => format!(" and {k} more"),
            };
            let fs: Vec<&str> = functions.iter().map(|f| f.name.as_str()).collect();
            return Err(Failure::Input(format!(
                "error: no range for {} input{} of @{}: {}{more}\n  = help: give them with -ranges=FILE, a JSON \
                 object of input name (or glob) → [lo, hi], such as {{\"q[*]\": [-3.1416, 3.1416], \"qd[*]\": [-10, \
                 10]}}\n  = note: the domain is needed by the pipeline's `{pass}` pass; defaults cover a URDF's \
                 limits and parameters only (docs/accuracy.md, \"Certified ranges\")\n",
                missing.len(),
                if missing.len() == 1 { "" } else { "s" },
                fs.join(", @"),
                shown.join(", "),
            )));
        }
    }
    Ok(dom)
}

/// The file's name as sources show it (`ranges.json`).
fn display_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned())
}
