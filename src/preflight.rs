//! Checks of `robovec-opt`'s options before any work (issue 10): against each other and the
//! pipeline, output paths and folders under the output policy ([`crate::output`]), files that
//! passes will read, and — once the input is read, before any pass runs — `-function`.
//!
//! Issue 47 added two: the input-specific options (`--free-flyer`, `-gravity`, …) against the
//! ones the input's front end reads ([`check_front_options`], declared in the front-end
//! registry: [`robovec_front::FrontEnd::options`]), and no output over a file the run reads
//! ([`read_files`]: the input, compared by identity, not by spelling).

use std::path::{Path, PathBuf};

use robovec_ir::Module;
use robovec_passes::{ParamKind, PassManager};

use crate::options::{output_failure, select, Failure, Options};
use crate::output::{self, ReadFile};

/// Checks every option against the pipeline and every output path and folder under the output
/// policy, before any work.
///
/// # Errors
/// [`Failure::Usage`] for options that contradict each other, the pipeline or the input's
/// front end ([`check_front_options`]), and for an output that is a file the run reads
/// ([`read_files`]; a `-report-dir` holding one); [`Failure::Output`] for a path the policy refuses; [`Failure::Input`] for a file a pass
/// parameter names that cannot be opened.
pub fn check_options(opts: &Options, pm: &PassManager) -> Result<(), Failure> {
    check_front_options(opts)?;
    if opts.sweep_csv.is_some() && !pm.makes_csv_table() {
        return Err(Failure::Usage(format!(
            "error: -sweep-csv needs a {} pass in the pipeline (a pass whose results include a CSV table)\n",
            csv_passes(pm)
        )));
    }
    let output = opts.output.as_deref().filter(|p| p.as_os_str() != "-");
    let units = pm.code_units();
    let main = code_file(opts, pm);
    if units > 1 && main.is_none() {
        return Err(Failure::Usage(format!(
            "error: the back end writes {units} translation units (`units={units}`) beside `-o FILE`: give -o a \
             file path (not stdout or a device)\n"
        )));
    }
    let mut companions: Vec<PathBuf> = match (output, pm.code_companions()) {
        (Some(o), Some(exts)) => exts.iter().filter_map(|e| companion_path(o, e)).collect(),
        _ => Vec::new(),
    };
    if let Some(m) = &main {
        companions.extend((1..units).map(|k| robovec_passes::unit_path(m, k)));
    }
    let files: Vec<(&str, &Path)> = [
        ("-o", output),
        ("-report", opts.report.as_deref()),
        ("-sweep-csv", opts.sweep_csv.as_deref()),
        ("-params-out", opts.params_out.as_deref()),
    ]
    .into_iter()
    .filter_map(|(flag, p)| p.map(|p| (flag, p)))
    .chain(companions.iter().map(|p| ("-o's companion", p.as_path())))
    .collect();
    for (i, (flag_a, a)) in files.iter().enumerate() {
        for (flag_b, b) in &files[i + 1..] {
            if let (Some(x), Some(y)) = (same_file_key(a), same_file_key(b)) {
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
    // No output over a file the run reads (issue 47: `-o` naming the input replaced it, exit 0).
    let reads = read_files(opts, pm)?;
    let dumps: Vec<PathBuf> = match &opts.instr.dump_dir {
        Some(d) => pm.dump_names().iter().map(|n| d.join(n)).collect(),
        None => Vec::new(),
    };
    for (flag, p) in files.iter().copied().chain(dumps.iter().map(|p| ("-dump-dir's dump", p.as_path()))) {
        let Some(id) = output::file_id(p) else { continue };
        if let Some(r) = reads.iter().find(|r| r.id.as_ref() == Some(&id)) {
            return Err(Failure::Usage(format!(
                "error: {flag} `{}` is {}; robovec never writes over a file the run reads: choose another path\n",
                p.display(),
                r.describe()
            )));
        }
    }
    if let Some(dir) = &opts.report_dir {
        if let Some(r) = reads.iter().find(|r| r.is_inside(dir)) {
            return Err(Failure::Usage(format!(
                "error: -report-dir `{}` holds {}, and the folder is replaced as a whole; choose another folder\n",
                dir.display(),
                r.describe()
            )));
        }
    }
    // Every folder the run writes, named for messages.
    let folders: Vec<(String, PathBuf)> = opts
        .instr
        .dump_dir
        .iter()
        .map(|d| ("-dump-dir".to_string(), d.clone()))
        .chain(
            pass_paths(pm, |k, _| matches!(k, ParamKind::OutputFolder))
                .into_iter()
                .map(|(pass, key, d)| (format!("pass `{pass}`'s {key}="), PathBuf::from(d))),
        )
        .chain(opts.report_dir.iter().map(|d| ("-report-dir".to_string(), d.clone())))
        .collect();
    for (flag, d) in &folders {
        if flag != "-report-dir" {
            output::check_folder(d).map_err(output_failure)?;
        }
    }
    // No output inside another's folder (issue 29: `-report=DIR/manifest.json` beside
    // `codegen<fpga;out=DIR>`, or `-o dd/001-atomise.after.rvir` with `-dump-dir=dd`, replaced
    // one output by another; a pass folder inside `-report-dir` failed only after the work).
    let inside_folder = |p: &Path, dir: &Path| -> bool { resolved(p).starts_with(resolved(dir)) };
    for (flag, p) in &files {
        if let Some((dflag, d)) = folders.iter().find(|(_, d)| inside_folder(p, d)) {
            return Err(Failure::Usage(format!(
                "error: {flag} `{}` is inside {dflag} `{}`; choose another path\n",
                p.display(),
                d.display()
            )));
        }
    }
    for (i, (fa, a)) in folders.iter().enumerate() {
        for (j, (fb, b)) in folders.iter().enumerate() {
            if i != j && inside_folder(a, b) && (resolved(a) != resolved(b) || i < j) {
                let what = if resolved(a) == resolved(b) { "is the same folder as" } else { "is inside" };
                return Err(Failure::Usage(format!(
                    "error: {fa} `{}` {what} {fb} `{}`; choose another path\n",
                    a.display(),
                    b.display()
                )));
            }
        }
    }
    for (flag, p) in &files {
        // A path ending in `/` names a folder (issue 29: `-o nope/` wrote a file `nope`).
        if p.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR) {
            return Err(Failure::Usage(format!(
                "error: {flag} `{}` names a folder (it ends in `/`); {flag} writes a file\n",
                p.display()
            )));
        }
        output::check_file(p).map_err(output_failure)?;
    }
    if let Some(dir) = &opts.report_dir {
        output::check_replaceable_folder(dir).map_err(output_failure)?;
    }
    check_pass_files(pm)?;
    // `-pareto`'s pipelines: every name, parameter and file they read, before any work too.
    if let Some(text) = &opts.pareto {
        let managers = robovec_passes::whole_run::pareto::managers(pm.registry(), text).map_err(Failure::from)?;
        for (_, other) in managers {
            check_pass_files(&other)?;
        }
    }
    Ok(())
}

/// Refuses, as bad usage, an input-specific option (`--free-flyer`, `-gravity`, `-params-out`,
/// …: [`robovec_front::FrontOption`]) given with an input whose front end does not read it
/// (issue 47: they were silently ignored on a `.c` file, a `.rvir` or stdin). The registry
/// says which front end reads which option ([`robovec_front::FrontEnd::options`]); an input no
/// front end claims is refused when it is loaded. Also `-params-out` with `--fold-params`: no
/// parameter is then left as an input.
///
/// # Errors
/// [`Failure::Usage`] naming the option, the input and its kind, and the inputs that take it.
pub fn check_front_options(opts: &Options) -> Result<(), Failure> {
    let Some(fe) = robovec_front::front_end_for(&opts.input) else { return Ok(()) };
    if let Some(&o) = opts.front_given.iter().find(|o| !fe.options().contains(o)) {
        let input = if opts.input == "-" { "stdin".to_string() } else { format!("`{}`", opts.input) };
        let takers: Vec<String> = o.read_by().iter().map(|n| format!("{n} input")).collect();
        let takers = if takers.is_empty() { "no input".to_string() } else { takers.join(" or ") };
        return Err(Failure::Usage(format!(
            "error: {} does not apply to {input}, a {} input: it concerns {takers} only\n",
            o.flag(),
            fe.name()
        )));
    }
    let given = |o| opts.front_given.contains(&o);
    if given(robovec_front::FrontOption::ParamsOut) && given(robovec_front::FrontOption::FoldParams) {
        return Err(Failure::Usage(
            "error: -params-out: with --fold-params no parameter is left as an input (the values are in the equations)\n"
                .into(),
        ));
    }
    Ok(())
}

/// Every file the run reads, which no output may replace: the input (stdin's file when it is
/// a regular file), the files its front end reads beside it ([`robovec_front::FrontEnd::reads_beside`]:
/// a `.c` file's `.h`), `-eval`'s inputs, a `-target` file, and the files the passes of the
/// pipeline and of `-pareto`'s pipelines read ([`ParamKind::Path`]: `specialize<params=…>`,
/// `accuracy<params=…>`, `eqsat<rules=…>`). Files that do not exist (yet) are listed without
/// identity: nothing to protect.
///
/// # Errors
/// [`Failure::Usage`] for a `-pareto` text that does not parse.
pub fn read_files(opts: &Options, pm: &PassManager) -> Result<Vec<ReadFile>, Failure> {
    let mut reads = Vec::new();
    if opts.input == "-" {
        reads.push(ReadFile::stdin());
    } else {
        reads.push(ReadFile::new("the input", &opts.input));
        if let Some(fe) = robovec_front::front_end_for(&opts.input) {
            let beside = fe.reads_beside(Path::new(&opts.input));
            let what = format!("the file the {} front end reads beside the input", fe.name());
            reads.extend(beside.into_iter().map(|p| ReadFile::new(what.clone(), p)));
        }
    }
    if let Some(e) = &opts.eval {
        reads.push(ReadFile::new("-eval's inputs file", e));
    }
    if let Some(r) = &opts.ranges {
        reads.push(ReadFile::new("the -ranges file", r));
    }
    if let Some(t) = opts.target.as_deref().filter(|t| robovec_machine::target::Target::built_in(t).is_none()) {
        reads.push(ReadFile::new("the -target file", t));
    }
    let mut managers = Vec::new();
    if let Some(text) = &opts.pareto {
        managers = robovec_passes::whole_run::pareto::managers(pm.registry(), text).map_err(Failure::from)?;
    }
    for m in std::iter::once(pm).chain(managers.iter().map(|(_, m)| m)) {
        for (pass, key, file) in pass_paths(m, reads_file) {
            reads.push(ReadFile::new(format!("pass `{pass}`'s {key}= file"), file));
        }
    }
    Ok(reads)
}

/// What tells two outputs on one file apart: the file a regular output finally goes to
/// ([`output::identity`]), or a FIFO itself (issue 29: one FIFO given to `-report` and `-o`
/// lost one of them); `None` for character devices (`/dev/null` may take any number).
fn same_file_key(p: &Path) -> Option<PathBuf> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if std::fs::metadata(p).is_ok_and(|m| m.file_type().is_fifo()) {
            return Some(resolved(p));
        }
    }
    output::identity(p)
}

/// `p` made absolute with `..` and symlinks resolved as far as the path exists, and `.` and
/// `..` of the part that does not exist resolved as written, so that two spellings of one
/// place compare equal.
pub(crate) fn resolved(p: &Path) -> PathBuf {
    use std::path::Component;
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let mut acc = PathBuf::new();
    let mut exists = true;
    for c in abs.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if !exists => {
                acc.pop();
            }
            _ => {
                acc.push(c);
                if exists {
                    // Symlinks and `..` resolved as the file system has them.
                    match std::fs::canonicalize(&acc) {
                        Ok(real) => acc = real,
                        Err(_) => exists = false,
                    }
                }
            }
        }
    }
    acc
}

/// The file `-o` writes a back end's code to, when the pipeline ends in one and `-o` names a
/// regular file or a path that does not exist yet (what names its companions and further
/// translation units); `None` otherwise.
pub fn code_file(opts: &Options, pm: &PassManager) -> Option<PathBuf> {
    let o = opts.output.as_deref().filter(|p| p.as_os_str() != "-")?;
    pm.code_companions()?;
    companion_path(o, "h").map(|_| o.to_path_buf())
}

/// Where a back end's companion file with extension `ext` goes when the code goes to `output`
/// (`model.c` → `model.h`): beside it, for a regular file or a path that does not exist yet.
/// `None` for a device, a FIFO or anything else that is not a regular file (`-o /dev/null`
/// writes no `/dev/null.h`).
pub fn companion_path(output: &Path, ext: &str) -> Option<PathBuf> {
    match std::fs::metadata(output) {
        Ok(m) if !m.is_file() => None,
        _ => Some(output.with_extension(ext)),
    }
}

/// The registered passes declared with a CSV table ([`robovec_passes::Props::csv_table`]),
/// for messages (`` `sweep` ``).
fn csv_passes(pm: &PassManager) -> String {
    let registry = pm.registry();
    registry
        .iter()
        .filter(|i| registry.props_of(i.name).is_some_and(|p| p.csv_table))
        .map(|i| format!("`{}`", i.name))
        .collect::<Vec<_>>()
        .join(" or ")
}

/// Every path parameter of the pipeline whose declared kind satisfies `want`: `(pass, key, path)`.
fn pass_paths(pm: &PassManager, want: impl Fn(&ParamKind, &str) -> bool) -> Vec<(&str, &str, &str)> {
    let mut out = Vec::new();
    for spec in pm.specs() {
        let Some(info) = pm.registry().get(&spec.name) else { continue };
        for (key, value) in &spec.params {
            let Some(decl) = info.param(key) else { continue };
            if let Some(value) = value.as_deref().filter(|v| !v.is_empty() && want(&decl.kind, v)) {
                out.push((spec.name.as_str(), key.as_str(), value));
            }
        }
    }
    out
}

/// True when a parameter of kind `k` with value `v` names a file the pass reads: a
/// [`ParamKind::Path`], or a [`ParamKind::F64OrPath`] whose value is not a number.
fn reads_file(k: &ParamKind, v: &str) -> bool {
    matches!(k, ParamKind::Path) || (matches!(k, ParamKind::F64OrPath { .. }) && v.parse::<f64>().is_err())
}

/// Files a pass reads when it runs (every parameter declared [`ParamKind::Path`]:
/// `accuracy<params=…>`, `specialize<params=…>`, `eqsat<rules=…>`) must be readable before
/// any work, so a typo fails at once; the pass checks their content when it runs.
///
/// # Errors
/// [`Failure::Input`] naming the pass, the parameter and the file.
fn check_pass_files(pm: &PassManager) -> Result<(), Failure> {
    for (pass, key, file) in pass_paths(pm, reads_file) {
        std::fs::File::open(file)
            .map_err(|e| Failure::Input(format!("error: pass `{pass}`: cannot read {key} file `{file}`: {e}\n")))?;
    }
    Ok(())
}

/// Checks `-function` and the one-function needs of `-report`, `-report-dir`, `-eval` and `-pareto` against
/// the input, before any pass runs.
///
/// # Errors
/// [`Failure::Usage`] naming the functions of the input.
pub fn check_functions(opts: &Options, module: &Module) -> Result<(), Failure> {
    if opts.function.is_some() {
        select(module, &opts.function, "-function")?;
    }
    for (given, what) in [
        (opts.report.is_some(), "-report"),
        (opts.report_dir.is_some(), "-report-dir"),
        (opts.eval.is_some(), "-eval"),
        (opts.pareto.is_some(), "-pareto"),
    ] {
        if given {
            select(module, &opts.function, what)?;
        }
    }
    Ok(())
}
