//! `robovec-opt`'s work: read the input, run the pipeline, write IR, report and evaluation.
//!
//! Order of work: every option is checked before any work ([`crate::preflight`]: pipeline,
//! `-sweep-csv` against it, every output path and folder under the output policy of
//! [`crate::output`], files passes will read; then the `-eval` inputs);
//! the input is read and `-function` checked against it before any pass runs; the passes run
//! with their dumps staged; the other outputs are staged; then [`OutputSet::commit`] puts every
//! file in place at once, and stdout is written last. A failure before the commit leaves
//! nothing of this run behind (see [`crate::output`] for the policy and its limits).
//!
//! Every write to stdout and stderr is checked: a failed write (closed pipe, full disk) ends the
//! run with [`Failure::Output`] (exit status 1, one line on stderr unless stderr is what failed).

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use robovec_ir::{text, verifier, Function, Module};
use robovec_passes::{DumpSink, Instrumentation, PassContext, PassError, PassManager};

use crate::diagnostics::SourceFile;
use crate::front;
use crate::output::OutputSet;
use crate::report::{evaluate, placement_report, stats, Report};

/// What the command line asked for.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Input path (`.c`, `.m`, `.py`, `.rvir`), or `-` for IR on stdin.
    pub input: String,
    /// Pipeline text (`atomise,asap-alap`).
    pub passes: String,
    /// `-o FILE`: final IR; stdout when absent (and no `-eval`).
    pub output: Option<PathBuf>,
    /// Printing, dumping, verifying, timing.
    pub instr: Instrumentation,
    /// `-report=FILE`.
    pub report: Option<PathBuf>,
    /// `-eval=FILE`.
    pub eval: Option<PathBuf>,
    /// `-function=NAME`.
    pub function: Option<String>,
    /// `-stats`: print the stats of the final IR to stderr.
    pub stats: bool,
    /// `-sweep-csv=FILE`: the rows of `sweep` runs as CSV.
    pub sweep_csv: Option<PathBuf>,
    /// `-pareto=A;B;…`: pipelines to compare (speed against error, [`crate::pareto`]).
    pub pareto: Option<String>,
    /// `-pareto-samples=N`: samples of each pipeline's accuracy measurement.
    pub pareto_samples: u32,
    /// `-pareto-seed=S`: seed of those measurements.
    pub pareto_seed: u64,
    /// `-eval-precision=f32`: evaluate in binary32.
    pub eval_f32: bool,
    /// `-check` with its samples and seed.
    pub check: Option<(u32, u64)>,
    /// `-time-limit=SECONDS`: wall-clock limit of the run (see `PassContext::deadline`).
    pub time_limit: Option<f64>,
}

/// Why a run failed; the text is ready for stderr.
#[derive(Debug)]
pub enum Failure {
    /// Bad input (exit status 1): a rendered diagnostic.
    Input(String),
    /// Bad usage (exit status 2).
    Usage(String),
    /// An output could not be written — a file under the output policy ([`crate::output`]),
    /// stdout or stderr (exit status 1). The message is one line, empty when stderr itself
    /// failed (nothing more can be said).
    Output(String),
}

impl Failure {
    /// Exit status: 1 for bad input or an output that cannot be written, 2 for bad usage
    /// (SPEC §7).
    pub fn exit_code(&self) -> i32 {
        match self {
            Failure::Input(_) | Failure::Output(_) => 1,
            Failure::Usage(_) => 2,
        }
    }

    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Failure::Input(s) | Failure::Usage(s) | Failure::Output(s) => s,
        }
    }
}

/// Reads and lowers `input` to an IR module (parsed phase for Robotran files) and verifies it.
///
/// # Errors
/// [`Failure::Input`] with codespan diagnostics naming file, line and column.
pub fn load(input: &str) -> Result<(Module, SourceFile), Failure> {
    let (bytes, name) = if input == "-" {
        let mut b = Vec::new();
        std::io::stdin().read_to_end(&mut b).map_err(|e| Failure::Input(format!("error: cannot read stdin: {e}\n")))?;
        (b, "<stdin>".to_string())
    } else {
        let b = std::fs::read(input).map_err(|e| Failure::Input(format!("error: cannot read `{input}`: {e}\n")))?;
        (b, input.to_string())
    };
    let src = SourceFile::from_bytes(name, &bytes);
    // The text is the one copy of the input kept (for diagnostics and the parse).
    drop(bytes);
    let path = Path::new(input);
    let module = match front::language_of(path) {
        Some(lang) if input != "-" => {
            let header = if path.extension().is_some_and(|e| e == "c") {
                std::fs::read(path.with_extension("h")).ok()
            } else {
                None
            };
            front::parse_text(lang, &src.text, header.as_deref()).map_err(|errs| {
                Failure::Input(src.render(&errs.iter().map(|e| e.to_diagnostic(())).collect::<Vec<_>>()))
            })?
        }
        _ => {
            if input != "-" && path.extension().is_none_or(|e| e != "rvir") {
                return Err(Failure::Usage(format!(
                    "error: cannot tell the language of `{input}`: expected a .c, .m, .py or .rvir file (or - for IR on stdin)\n"
                )));
            }
            text::parse(&src.text).map_err(|errs| {
                Failure::Input(src.render(&errs.iter().map(|e| e.to_diagnostic(())).collect::<Vec<_>>()))
            })?
        }
    };
    if module.functions.is_empty() {
        // An empty or comment-only file is bad input, not a module to describe (issue 10).
        let is_ir = front::language_of(path).is_none() || input == "-";
        let message = if is_ir { "expected at least one `func`" } else { "expected at least one function" };
        let d = codespan_reporting::diagnostic::Diagnostic::error()
            .with_message(format!("{message}: the input has no function"))
            .with_labels(vec![
                codespan_reporting::diagnostic::Label::primary((), 0..0).with_message("no function in this input")
            ]);
        return Err(Failure::Input(src.render(&[d])));
    }
    if let Err(errs) = verifier::verify(&module) {
        let diags: Vec<_> = errs.iter().map(|e| e.to_diagnostic((), "on input")).collect();
        return Err(Failure::Input(src.render(&diags)));
    }
    Ok((module, src))
}

pub(crate) fn select<'m>(m: &'m Module, want: &Option<String>, what: &str) -> Result<&'m Function, Failure> {
    match want {
        Some(name) => m.function(name).ok_or_else(|| {
            let names: Vec<&str> = m.functions.iter().map(|f| f.name.as_str()).collect();
            Failure::Usage(format!("error: no function `{name}` in the input; functions: {}\n", names.join(", ")))
        }),
        None => match m.functions.as_slice() {
            [f] => Ok(f),
            fs => {
                let names: Vec<&str> = fs.iter().map(|f| f.name.as_str()).collect();
                Err(Failure::Usage(format!(
                    "error: {what} needs one function but the input has {}: {}; choose one with -function=NAME\n",
                    fs.len(),
                    names.join(", ")
                )))
            }
        },
    }
}

/// Writes one file under the output policy ([`crate::output`]) on its own. Inside a run, stage
/// files in the run's [`OutputSet`] instead, so that they are put in place together.
///
/// # Errors
/// [`Failure::Output`] naming the file.
pub fn write_atomically(path: &Path, data: &[u8]) -> Result<(), Failure> {
    let mut out = OutputSet::new();
    out.stage(path, data).map_err(output_failure)?;
    out.commit().map(|_| ()).map_err(output_failure)
}

fn read_eval_inputs(path: &Path) -> Result<BTreeMap<String, f64>, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::Input(format!("error: cannot read `{}`: {e}\n", path.display())))?;
    serde_json::from_str::<BTreeMap<String, f64>>(&text).map_err(|e| {
        Failure::Input(format!(
            "error: `{}` line {}, column {}: {e}\n  = expected a JSON object of input name → number, e.g. {{\"q[1]\": 0.5}}\n",
            path.display(),
            e.line(),
            e.column()
        ))
    })
}

/// Stages the `worst-K.json` files of every `accuracy<worst=DIR>` measurement.
fn stage_worst_points(
    out: &mut OutputSet,
    reports: &[robovec_passes::accuracy::AccuracyReport],
    prefix: bool,
) -> Result<(), Failure> {
    for r in reports {
        let Some(dir) = &r.worst_dir else { continue };
        out.ensure_folder(Path::new(dir)).map_err(output_failure)?;
        for (name, json) in robovec_passes::accuracy::report::worst_files(r, prefix) {
            out.stage(&Path::new(dir).join(name), json.as_bytes()).map_err(output_failure)?;
        }
    }
    Ok(())
}

/// Renders a pipeline failure; errors located in the input (verifier errors, placement lines
/// named by `sim`, a function in the wrong phase) show `file:line:col` and the line.
fn pass_failure(e: robovec_passes::PassError, src: &SourceFile) -> Failure {
    use codespan_reporting::diagnostic::{Diagnostic, Label};
    if let robovec_passes::PassError::Verify { pass, list, .. } = &e {
        if !list.is_empty() {
            let when = if pass == "input" { "on input".to_string() } else { format!("after pass `{pass}`") };
            let diags: Vec<_> = list.iter().map(|v| v.to_diagnostic((), &when)).collect();
            return Failure::Input(src.render(&diags));
        }
    }
    match e.span() {
        Some(span) if span.range().end <= src.text.len() => Failure::Input(
            src.render(&[Diagnostic::error().with_message(e.to_string()).with_labels(vec![Label::primary(
                (),
                span.range(),
            )
            .with_message("here")])]),
        ),
        _ => Failure::Input(format!("error: {e}\n")),
    }
}

/// A refused or failed output (one line from [`crate::output`]).
pub(crate) fn output_failure(message: String) -> Failure {
    Failure::Output(message + "\n")
}

/// A failed write to stderr: exit 1 with nothing more to say.
fn stderr_failure(_: std::io::Error) -> Failure {
    Failure::Output(String::new())
}

/// Dumps of `-dump-dir` staged into the run's [`OutputSet`] as the passes run.
struct StagedDumps<'a> {
    dir: PathBuf,
    out: &'a mut OutputSet,
    created: bool,
}

impl DumpSink for StagedDumps<'_> {
    fn dump(&mut self, name: &str, text: &str) -> Result<(), String> {
        if !self.created {
            self.out.ensure_folder(&self.dir)?;
            self.created = true;
        }
        self.out.stage(&self.dir.join(name), text.as_bytes())
    }
}

/// Runs one `robovec-opt` invocation. `stdout` receives the IR (or `-eval` JSON); `stderr`
/// receives dumps, timing and stats.
///
/// # Errors
/// [`Failure`] with its exit status.
pub fn run(opts: &Options, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), Failure> {
    let deadline = opts.time_limit.map(robovec_passes::Deadline::after_seconds);
    // `load` verifies the input (always, whatever `-verify-each` says): the manager need not.
    let instr = Instrumentation { input_verified: true, ..opts.instr.clone() };
    let pm = PassManager::new(&opts.passes, instr).map_err(|e| Failure::Usage(format!("error: {e}\n")))?;
    crate::preflight::check_options(opts, &pm)?;
    let eval_inputs = opts.eval.as_deref().map(read_eval_inputs).transpose()?;
    let (mut module, src) = load(&opts.input)?;
    crate::preflight::check_functions(opts, &module)?;
    // Every file of this run goes through `out`; dropped uncommitted (any `?` below), it
    // removes what it staged.
    let mut out = OutputSet::new();
    let pareto = match &opts.pareto {
        Some(text) => {
            let name = select(&module, &opts.function, "-pareto")?.name.clone();
            let rows = crate::pareto::run(&module, &name, text, opts.pareto_samples, opts.pareto_seed)?;
            write!(stderr, "{}", crate::pareto::to_table(&name, &rows)).map_err(stderr_failure)?;
            rows
        }
        None => Vec::new(),
    };
    let mut cx = PassContext { original: opts.check.map(|_| module.clone()), deadline, ..PassContext::default() };
    let records = {
        let dir = opts.instr.dump_dir.clone().unwrap_or_default();
        let mut dumps = StagedDumps { dir, out: &mut out, created: false };
        pm.run_with_dumps(&mut module, &mut cx, stderr, &mut dumps).map_err(|e| match e {
            PassError::Output { message } => output_failure(message),
            PassError::Log(e) => stderr_failure(e),
            e => pass_failure(e, &src),
        })?
    };
    for s in &cx.stopped {
        writeln!(stderr, "note: {s}").map_err(stderr_failure)?;
    }
    if let (Some((samples, seed)), Some(original)) = (opts.check, &cx.original) {
        crate::check::run(&module, original, &pm.pipeline_text(), &opts.function, samples, seed, stderr)?;
    }

    // Build every output in memory first.
    let report = match &opts.report {
        Some(_) => {
            let f = select(&module, &opts.function, "-report")?;
            let r = Report {
                input: opts.input.clone(),
                function: f.name.clone(),
                pipeline: pm.pipeline_text(),
                passes: records.clone(),
                stats: stats(f, &cx.latencies),
                placement: placement_report(f),
                sweep: cx.sweep.iter().filter(|r| r.function == f.name).cloned().collect(),
                accuracy: cx.accuracy.iter().rev().find(|r| r.function == f.name).cloned(),
                pareto: pareto.clone(),
                eqsat: cx.eqsat.iter().filter(|e| e.function == f.name).cloned().collect(),
                sim: cx.sim.last().map(|s| {
                    let mut s = s.clone();
                    s.functions.retain(|x| x.function == f.name);
                    s
                }),
                stopped_early: cx.stopped.clone(),
            };
            Some(serde_json::to_string_pretty(&r).expect("report serialises") + "\n")
        }
        None => None,
    };
    let eval = match &eval_inputs {
        Some(given) => {
            let f = select(&module, &opts.function, "-eval")?;
            for name in given.keys() {
                if !f.inputs.iter().any(|&v| f.name_of(v) == name) {
                    writeln!(stderr, "warning: `{name}` is not an input of @{}; ignored", f.name)
                        .map_err(stderr_failure)?;
                }
            }
            let r = evaluate(f, given, opts.eval_f32);
            for c in &r.callback_standins {
                writeln!(
                    stderr,
                    "warning: @{} calls user callback `{c}`; evaluated with the stand-in (a linear form of its \
                     arguments, robovec_ir::interp::callback_standin)",
                    f.name
                )
                .map_err(stderr_failure)?;
            }
            Some(serde_json::to_string_pretty(&r).expect("eval serialises") + "\n")
        }
        None => None,
    };
    if opts.stats {
        write!(stderr, "{}", crate::report::stats_text(&module, &cx, opts.function.as_deref()))
            .map_err(stderr_failure)?;
    }
    if !cx.sweep.is_empty() {
        write!(stderr, "{}", robovec_passes::sweep::to_table(&cx.sweep)).map_err(stderr_failure)?;
    }
    if !cx.accuracy.is_empty() {
        write!(stderr, "{}", robovec_passes::accuracy::report::to_text(&cx.accuracy, opts.stats))
            .map_err(stderr_failure)?;
    }
    // The IR is printed straight into its file or stdout (never held as one string: at 7× the
    // size of a Robotran input it would be the largest allocation of a run).
    let mut print_ir = |w: &mut dyn Write| write!(w, "{module}");

    // Then put every file in place at once, and write stdout last.
    stage_worst_points(&mut out, &cx.accuracy, module.functions.len() > 1)?;
    if let Some(path) = &opts.sweep_csv {
        out.stage(path, robovec_passes::sweep::to_csv(&cx.sweep).as_bytes()).map_err(output_failure)?;
    }
    if let (Some(path), Some(r)) = (&opts.report, &report) {
        out.stage(path, r.as_bytes()).map_err(output_failure)?;
    }
    let ir_to_stdout = match &opts.output {
        Some(p) if p.as_os_str() == "-" => true,
        Some(p) => {
            out.stage_with(p, &mut print_ir).map_err(output_failure)?;
            false
        }
        None => eval.is_none(),
    };
    let written = out.commit().map_err(output_failure)?;
    let mut put = || -> std::io::Result<()> {
        if ir_to_stdout {
            let mut buf = std::io::BufWriter::with_capacity(1 << 16, &mut *stdout);
            print_ir(&mut buf)?;
            buf.flush()?;
        }
        if let Some(e) = &eval {
            stdout.write_all(e.as_bytes())?;
        }
        stdout.flush()
    };
    put().map_err(|e| {
        let already = if written.is_empty() {
            String::new()
        } else {
            let names: Vec<String> = written.iter().map(|p| format!("`{}`", p.display())).collect();
            format!("; files already written: {}", names.join(", "))
        };
        Failure::Output(format!(
            "error: cannot write to stdout: {e}{already}
"
        ))
    })
}
