//! `robovec-opt`'s work: read the input, run the pipeline, write IR, report and evaluation.
//!
//! Nothing is written before everything succeeded: outputs are built in memory and files are
//! written through a temporary file and a rename, so a failure never leaves a half-written file.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use robovec_ir::{text, verifier, Function, Module};
use robovec_passes::{Instrumentation, PassContext, PassManager};

use crate::diagnostics::SourceFile;
use crate::front;
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
}

impl Failure {
    /// Exit status: 1 for bad input, 2 for bad usage (SPEC §7).
    pub fn exit_code(&self) -> i32 {
        match self {
            Failure::Input(_) => 1,
            Failure::Usage(_) => 2,
        }
    }

    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Failure::Input(s) | Failure::Usage(s) => s,
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
    let path = Path::new(input);
    let module = match front::language_of(path) {
        Some(lang) if input != "-" => {
            let header = if path.extension().is_some_and(|e| e == "c") {
                std::fs::read(path.with_extension("h")).ok()
            } else {
                None
            };
            front::parse_str(lang, &bytes, header.as_deref()).map_err(|errs| {
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
    if let Err(errs) = verifier::verify(&module) {
        let diags: Vec<_> = errs.iter().map(|e| e.to_diagnostic((), "on input")).collect();
        return Err(Failure::Input(src.render(&diags)));
    }
    Ok((module, src))
}

fn select<'m>(m: &'m Module, want: &Option<String>, what: &str) -> Result<&'m Function, Failure> {
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

/// Writes `data` to `path` through a temporary file in the same folder and a rename.
///
/// # Errors
/// [`Failure::Input`] naming the file.
pub fn write_atomically(path: &Path, data: &[u8]) -> Result<(), Failure> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let fname = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{fname}.{}.tmp", std::process::id()));
    let fail = |e: std::io::Error| Failure::Input(format!("error: cannot write `{}`: {e}\n", path.display()));
    std::fs::write(&tmp, data).map_err(fail)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail(e)
    })
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

/// Writes the `worst-K.json` files of every `accuracy<worst=DIR>` measurement.
fn write_worst_points(reports: &[robovec_passes::accuracy::AccuracyReport], prefix: bool) -> Result<(), Failure> {
    for r in reports {
        let Some(dir) = &r.worst_dir else { continue };
        std::fs::create_dir_all(dir).map_err(|e| Failure::Input(format!("error: cannot create `{dir}`: {e}\n")))?;
        for (name, json) in robovec_passes::accuracy::report::worst_files(r, prefix) {
            write_atomically(&Path::new(dir).join(name), json.as_bytes())?;
        }
    }
    Ok(())
}

/// Runs one `robovec-opt` invocation. `stdout` receives the IR (or `-eval` JSON); `stderr`
/// receives dumps, timing and stats.
///
/// # Errors
/// [`Failure`] with its exit status.
pub fn run(opts: &Options, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), Failure> {
    let deadline = opts.time_limit.map(robovec_passes::Deadline::after_seconds);
    let pm = PassManager::new(&opts.passes, opts.instr.clone()).map_err(|e| Failure::Usage(format!("error: {e}\n")))?;
    let eval_inputs = opts.eval.as_deref().map(read_eval_inputs).transpose()?;
    let (mut module, _src) = load(&opts.input)?;
    let pareto = match &opts.pareto {
        Some(text) => {
            let name = select(&module, &opts.function, "-pareto")?.name.clone();
            let rows = crate::pareto::run(&module, &name, text, opts.pareto_samples, opts.pareto_seed)?;
            let _ = write!(stderr, "{}", crate::pareto::to_table(&name, &rows));
            rows
        }
        None => Vec::new(),
    };
    let mut cx = PassContext { deadline, ..PassContext::default() };
    let records = pm.run(&mut module, &mut cx, stderr).map_err(|e| Failure::Input(format!("error: {e}\n")))?;
    for s in &cx.stopped {
        let _ = writeln!(stderr, "note: {s}");
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
                    let _ = writeln!(stderr, "warning: `{name}` is not an input of @{}; ignored", f.name);
                }
            }
            Some(serde_json::to_string_pretty(&evaluate(f, given)).expect("eval serialises") + "\n")
        }
        None => None,
    };
    if opts.stats {
        for note in &cx.notes {
            let _ = writeln!(stderr, "{note}");
        }
        for f in &module.functions {
            if opts.function.as_ref().is_some_and(|n| n != &f.name) {
                continue;
            }
            let s = stats(f, &cx.latencies);
            let _ = writeln!(
                stderr,
                "@{}: equations {}, ops {} (add {}, sub {}, mul {}, div {}, call {}), inputs {}, outputs {}, \
                 critical path {} ops / {} cycles, Y = {:.2}",
                f.name,
                s.equations.map_or("?".to_string(), |e| e.to_string()),
                s.ops.total,
                s.ops.add,
                s.ops.sub,
                s.ops.mul,
                s.ops.div,
                s.ops.call,
                s.inputs,
                s.outputs,
                s.asap,
                s.asap_cycle,
                s.y
            );
            if let Some(p) = placement_report(f) {
                let max = |v: &[u32]| v.iter().copied().max().unwrap_or(0);
                let _ = writeln!(
                    stderr,
                    "@{}: placed on {} ADD + {} MULTI PEs: {} cycles, lower bound {} (x{:.3}), parallelisation rate {:.3}, \
                     PE memory up to {} words, buffer up to {} words, writes {} direct / {} indirect",
                    f.name,
                    p.n_add,
                    p.n_mul,
                    p.cycles,
                    p.lower_bound,
                    p.cycles_over_lower_bound,
                    p.parallelisation_rate,
                    max(&p.pe_memory_words),
                    max(&p.buffer_words),
                    p.writes_direct,
                    p.writes_indirect
                );
            }
        }
    }
    if opts.stats {
        for e in cx.eqsat.iter().filter(|e| opts.function.as_ref().is_none_or(|n| n == &e.function)) {
            let _ = writeln!(stderr, "{e}");
        }
    }
    if !cx.sweep.is_empty() {
        let _ = write!(stderr, "{}", robovec_passes::sweep::to_table(&cx.sweep));
    }
    if !cx.accuracy.is_empty() {
        let _ = write!(stderr, "{}", robovec_passes::accuracy::report::to_text(&cx.accuracy, opts.stats));
    }
    let ir = module.to_string();

    // Then write.
    write_worst_points(&cx.accuracy, module.functions.len() > 1)?;
    if let Some(path) = &opts.sweep_csv {
        if cx.sweep.is_empty() {
            return Err(Failure::Usage("error: -sweep-csv needs a `sweep` pass in the pipeline\n".into()));
        }
        write_atomically(path, robovec_passes::sweep::to_csv(&cx.sweep).as_bytes())?;
    }
    if let (Some(path), Some(r)) = (&opts.report, &report) {
        write_atomically(path, r.as_bytes())?;
    }
    match &opts.output {
        Some(p) if p.as_os_str() == "-" => {
            let _ = stdout.write_all(ir.as_bytes());
        }
        Some(p) => write_atomically(p, ir.as_bytes())?,
        None if eval.is_none() => {
            let _ = stdout.write_all(ir.as_bytes());
        }
        None => {}
    }
    if let Some(e) = eval {
        let _ = stdout.write_all(e.as_bytes());
    }
    Ok(())
}
