//! Checks of `robovec-opt`'s options before any work (issue 10): against each other and the
//! pipeline, output paths and folders under the output policy ([`crate::output`]), files that
//! passes will read, and — once the input is read, before any pass runs — `-function`.

use std::path::{Path, PathBuf};

use robovec_ir::Module;
use robovec_passes::PassManager;

use crate::driver::{output_failure, select, Failure, Options};
use crate::output;

/// Checks every option against the pipeline and every output path and folder under the output
/// policy, before any work.
///
/// # Errors
/// [`Failure::Usage`] for options that contradict each other or the pipeline;
/// [`Failure::Output`] for a path the policy refuses; [`Failure::Input`] for a file a pass
/// parameter names that cannot be opened.
pub fn check_options(opts: &Options, pm: &PassManager) -> Result<(), Failure> {
    if opts.sweep_csv.is_some() && !pm.specs().any(|s| s.name == "sweep") {
        return Err(Failure::Usage("error: -sweep-csv needs a `sweep` pass in the pipeline\n".into()));
    }
    let files: Vec<(&str, &Path)> = [
        ("-o", opts.output.as_deref().filter(|p| p.as_os_str() != "-")),
        ("-report", opts.report.as_deref()),
        ("-sweep-csv", opts.sweep_csv.as_deref()),
    ]
    .into_iter()
    .filter_map(|(flag, p)| p.map(|p| (flag, p)))
    .collect();
    for (_, p) in &files {
        output::check_file(p).map_err(output_failure)?;
    }
    for (i, (flag_a, a)) in files.iter().enumerate() {
        for (flag_b, b) in &files[i + 1..] {
            if let (Some(x), Some(y)) = (output::identity(a), output::identity(b)) {
                if x == y {
                    return Err(Failure::Usage(format!(
                        "error: {flag_a} `{}` and {flag_b} `{}` are the same file\n",
                        a.display(),
                        b.display()
                    )));
                }
            }
        }
    }
    let worst_dirs = pm
        .specs()
        .filter(|s| s.name == "accuracy")
        .filter_map(|s| s.params.iter().find(|(k, _)| k == "worst").and_then(|(_, v)| v.clone()))
        .filter(|v| !v.is_empty());
    for d in opts.instr.dump_dir.iter().cloned().chain(worst_dirs.map(PathBuf::from)) {
        output::check_folder(&d).map_err(output_failure)?;
    }
    check_pass_files(pm)?;
    // `-pareto`'s pipelines: every name, parameter and file they read, before any work too.
    if let Some(text) = &opts.pareto {
        for (_, other) in crate::pareto::managers(text)? {
            check_pass_files(&other)?;
        }
    }
    Ok(())
}

/// Files a pass reads when it runs (`accuracy<params=…>`, `specialize<params=…>`,
/// `eqsat<rules=…>`) must be readable before any work, so a typo fails at once; the pass
/// checks their content when it runs.
///
/// # Errors
/// [`Failure::Input`] naming the pass, the parameter and the file.
fn check_pass_files(pm: &PassManager) -> Result<(), Failure> {
    const READ_BY_PASSES: [(&str, &str); 3] = [("accuracy", "params"), ("specialize", "params"), ("eqsat", "rules")];
    for spec in pm.specs() {
        for (key, file) in &spec.params {
            let Some(file) = file.as_deref().filter(|f| !f.is_empty()) else { continue };
            if READ_BY_PASSES.contains(&(spec.name.as_str(), key.as_str())) {
                std::fs::File::open(file).map_err(|e| {
                    Failure::Input(format!("error: pass `{}`: cannot read {key} file `{file}`: {e}\n", spec.name))
                })?;
            }
        }
    }
    Ok(())
}

/// Checks `-function` and the one-function needs of `-report`, `-eval` and `-pareto` against
/// the input, before any pass runs.
///
/// # Errors
/// [`Failure::Usage`] naming the functions of the input.
pub fn check_functions(opts: &Options, module: &Module) -> Result<(), Failure> {
    if opts.function.is_some() {
        select(module, &opts.function, "-function")?;
    }
    for (given, what) in
        [(opts.report.is_some(), "-report"), (opts.eval.is_some(), "-eval"), (opts.pareto.is_some(), "-pareto")]
    {
        if given {
            select(module, &opts.function, what)?;
        }
    }
    Ok(())
}
