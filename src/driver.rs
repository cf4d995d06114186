//! `robovec-opt`'s work: read the input, run the pipeline, write IR, report and evaluation.
//!
//! Order of work: every option is checked before any work ([`crate::preflight`]: pipeline,
//! `-sweep-csv` against it, every output path and folder under the output policy of
//! [`crate::output`], files passes will read; then the `-eval` inputs);
//! the input is read (at most [`INPUT_BOUND`] bytes, under the deadline: [`load_with`]) and
//! `-function` checked against it before any pass runs; the passes run
//! with their dumps staged; the other outputs are staged; then [`OutputSet::commit`] puts every
//! file in place at once, and stdout is written last. A failure before the commit leaves
//! nothing of this run behind (see [`crate::output`] for the policy and its limits).
//!
//! Every write to stdout and stderr is checked: a failed write (closed pipe, full disk) ends the
//! run with [`Failure::Output`] (exit status 1, one line on stderr unless stderr is what failed).

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use robovec_front::{FrontOptions, Loaded};
use robovec_ir::{verifier, Module};
use robovec_passes::report::report_text;
use robovec_passes::summary::{self, Figures};
use robovec_passes::{
    whole_run, DumpSink, GeneratedCode, Instrumentation, PassContext, PassError, PassManager, Session,
};

use crate::diagnostics::SourceFile;
use crate::options::{output_failure, select};
pub use crate::options::{Failure, Options};
use crate::output::OutputSet;

/// Reads and lowers `input` to an IR module (parsed phase for Robotran files) and verifies it.
///
/// # Errors
/// [`Failure::Input`] with codespan diagnostics naming file, line and column.
pub fn load(input: &str) -> Result<(Module, SourceFile), Failure> {
    load_with(input, &FrontOptions::default()).map(|(l, src)| (l.module, src))
}

/// [`load`] with the front-end options of the command line; also returns the parameter values
/// the front end knows ([`Loaded::params`]). The front end is the registered one for the
/// input's extension ([`robovec_front::front_end_for`]); the driver names none. A front end
/// that builds its functions (URDF) builds only `opts.functions` and stops at `opts.deadline`.
/// At most [`INPUT_BOUND`] bytes are read (stdin, pipes and devices under the deadline too), and
/// the module's verification stops at the deadline as well (issue 47). The front end's
/// warnings ([`Loaded::warnings`]: a URDF's inertia tensor that is not positive semi-definite)
/// are printed to stderr as codespan warnings, and returned with the rest.
///
/// # Errors
/// [`Failure::Usage`] for an extension no front end claims, or a requested function a front
/// end that builds its functions cannot build (`no function `foo` in the input; functions:
/// invdyna, dirdyna, fordyna`, as `-function` against a loaded module); [`Failure::Input`] with codespan
/// diagnostics naming file, line and column (the time limit reached while loading among them),
/// or for an input larger than [`INPUT_BOUND`], or the time limit reached while reading or
/// verifying it.
pub fn load_with(input: &str, opts: &FrontOptions) -> Result<(Loaded, SourceFile), Failure> {
    let name = if input == "-" { "<stdin>".to_string() } else { input.to_string() };
    let bytes = read_input(input, opts.deadline.as_ref())?;
    let Some(fe) = robovec_front::front_end_for(input) else {
        return Err(Failure::Usage(format!(
            "error: cannot tell the language of `{input}`: expected a {} file (or - for IR on stdin)\n",
            robovec_front::extension_list()
        )));
    };
    if let (Some(names), Some(wanted)) = (fe.function_names(), &opts.functions) {
        if let Some(bad) = wanted.iter().find(|w| !names.contains(&w.as_str())) {
            return Err(Failure::Usage(format!(
                "error: no function `{bad}` in the input; functions: {}\n",
                names.join(", ")
            )));
        }
    }
    let src = SourceFile::from_bytes(name, &bytes);
    if let (true, Err(e)) = (fe.requires_utf8(), std::str::from_utf8(&bytes)) {
        let at = e.valid_up_to();
        let d = codespan_reporting::diagnostic::Diagnostic::error()
            .with_message(format!("invalid UTF-8 (byte 0x{:02x}): a {} file is read as UTF-8", bytes[at], fe.name()))
            .with_labels(
                vec![codespan_reporting::diagnostic::Label::primary((), at..at + 1).with_message("not UTF-8")],
            );
        return Err(Failure::Input(src.render(&[d])));
    }
    // The text is the one copy of the input kept (for diagnostics and the parse).
    drop(bytes);
    let loaded = fe
        .load(Path::new(input), &src.text, opts)
        .map_err(|errs| Failure::Input(src.render(&errs.iter().map(|e| e.to_diagnostic(())).collect::<Vec<_>>())))?;
    if !loaded.warnings.is_empty() {
        let diags: Vec<_> = loaded
            .warnings
            .iter()
            .map(|w| {
                let mut d = w.to_diagnostic(());
                d.severity = codespan_reporting::diagnostic::Severity::Warning;
                d
            })
            .collect();
        eprint!("{}", src.render(&diags));
    }
    let module = &loaded.module;
    if module.functions.is_empty() {
        // An empty or comment-only file is bad input, not a module to describe (issue 10).
        let d = codespan_reporting::diagnostic::Diagnostic::error()
            .with_message(format!("{}: the input has no function", fe.no_function_message()))
            .with_labels(vec![
                codespan_reporting::diagnostic::Label::primary((), 0..0).with_message("no function in this input")
            ]);
        return Err(Failure::Input(src.render(&[d])));
    }
    // Under `-time-limit` the verification of what a front end built (a URDF's generated
    // functions) stops at the limit too: it may have millions of outputs (issue 47: 25 million
    // for a 5,000-branch star's `dirdyna` from a 2.5 MB file, 2.7 s to verify). A module read
    // from its text is verified in time linear in that text, as it was read.
    let generated = fe.function_names().is_some();
    let ticker = robovec_passes::Ticker::new(opts.deadline.filter(|_| generated), None);
    match verifier::verify_until(module, &mut || ticker.tick()) {
        Some(Ok(())) => {}
        Some(Err(errs)) => {
            let diags: Vec<_> = errs.iter().map(|e| e.to_diagnostic((), "on input")).collect();
            return Err(Failure::Input(src.render(&diags)));
        }
        None => {
            leave_past_deadline(loaded, opts.deadline.as_ref());
            return Err(Failure::Input(format!(
                "error: {} while verifying the input\n  = note: {LOADING_NOTE}\n",
                ticker.reason()
            )));
        }
    }
    Ok((loaded, src))
}

/// Drops `x`, or, once `deadline` has passed, leaves it to the process's exit (issue 47): a run
/// that fails past its time limit ends at once, and freeing a large module block by block
/// took about a second per gigabyte (a 5,000-branch star's `dirdyna` stopped while verifying
/// at a 10 s limit: 4.5 GB), where the system reclaims a process's memory at once.
fn leave_past_deadline<T>(x: T, deadline: Option<&robovec_passes::Deadline>) {
    if deadline.is_some_and(|d| d.reached()) {
        std::mem::forget(x);
    }
}

/// The most bytes read from one input, stdin included (1 GiB): far above any real input (the
/// largest Robotran file of the corpus is a few MB, the scale benchmarks write 100 MB), and
/// what a run can hold (memory is about 11× the input), so that `robovec-opt - < /dev/zero`
/// ends with an error instead of reading without end (issue 47).
pub const INPUT_BOUND: u64 = 1 << 30;

/// The note of a run stopped by `-time-limit` while loading.
const LOADING_NOTE: &str = "-time-limit covers loading too: nothing is written without a complete module";

/// Why [`read_bounded`] gave up.
enum ReadStop {
    /// The input holds more than [`INPUT_BOUND`] bytes (or its size says so).
    TooLarge,
    /// The reader was told to stop (its caller's time limit was reached).
    Abandoned,
    /// The system's error.
    Io(std::io::Error),
}

/// Reads `input` (`-`: stdin) whole, at most `bound` bytes ([`INPUT_BOUND`]), in chunks of
/// 1 MiB, and gives up between two chunks once `abandoned` is set.
fn read_bounded(input: &str, bound: u64, abandoned: &std::sync::atomic::AtomicBool) -> Result<Vec<u8>, ReadStop> {
    let (mut reader, size): (Box<dyn Read>, u64) = if input == "-" {
        (Box::new(std::io::stdin()), 0)
    } else {
        let file = std::fs::File::open(input).map_err(ReadStop::Io)?;
        // A regular file's length (0 for devices and pipes, which may hold anything).
        let size = file.metadata().map_or(0, |m| if m.is_file() { m.len() } else { 0 });
        (Box::new(file), size)
    };
    if size > bound {
        return Err(ReadStop::TooLarge);
    }
    let mut bytes = Vec::with_capacity(size as usize);
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        if abandoned.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(ReadStop::Abandoned);
        }
        let n = match reader.read(&mut chunk) {
            Ok(0) => return Ok(bytes),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(ReadStop::Io(e)),
        };
        if (bytes.len() + n) as u64 > bound {
            return Err(ReadStop::TooLarge);
        }
        bytes.extend_from_slice(&chunk[..n]);
    }
}

/// The bytes of `input` (`-`: stdin), at most [`INPUT_BOUND`] of them (issue 47:
/// `robovec-opt - -time-limit=1 < /dev/zero` read 4.2 GB in 8 s and went on). A regular file
/// larger than the bound is refused before it is read; a smaller one is read whole (a
/// fraction of a second for the largest: the front end's clock then takes over). Stdin,
/// pipes, FIFOs and devices, which may give anything or block, are read up to the bound and,
/// under a deadline, on a thread of their own, which the run leaves behind (told to stop at
/// its next chunk) once `deadline` is reached.
///
/// # Errors
/// [`Failure::Input`] (exit 1): the file cannot be read, it is larger than the bound
/// (`error: <stdin> is larger than 1 GiB, the most robovec reads from one input`), or the
/// deadline was reached first (`error: time limit of 1 s reached while reading <stdin>`).
fn read_input(input: &str, deadline: Option<&robovec_passes::Deadline>) -> Result<Vec<u8>, Failure> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{mpsc, Arc};
    let shown = if input == "-" { "<stdin>".to_string() } else { format!("`{input}`") };
    let failure = |stop: ReadStop| match stop {
        ReadStop::TooLarge => Failure::Input(format!(
            "error: {shown} is larger than 1 GiB ({INPUT_BOUND} bytes), the most robovec reads from one input\n  \
             = note: the largest Robotran and URDF inputs are tens of megabytes\n"
        )),
        ReadStop::Abandoned => unreachable!("only a run past its deadline abandons its reader"),
        ReadStop::Io(e) if input == "-" => Failure::Input(format!("error: cannot read stdin: {e}\n")),
        ReadStop::Io(e) => Failure::Input(format!("error: cannot read `{input}`: {e}\n")),
    };
    let regular = input != "-" && std::fs::metadata(input).is_ok_and(|m| m.is_file());
    let Some(deadline) = deadline.copied().filter(|_| !regular) else {
        return read_bounded(input, INPUT_BOUND, &AtomicBool::new(false)).map_err(failure);
    };
    let abandoned = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let (path, flag) = (input.to_string(), Arc::clone(&abandoned));
    let reader = std::thread::Builder::new().name("robovec-read".into()).spawn(move || {
        let _ = tx.send(read_bounded(&path, INPUT_BOUND, &flag));
    });
    if reader.is_err() {
        return read_bounded(input, INPUT_BOUND, &abandoned).map_err(failure);
    }
    match rx.recv_timeout(deadline.time_left()) {
        Ok(read) => read.map_err(failure),
        Err(_) => {
            abandoned.store(true, Ordering::Relaxed);
            Err(Failure::Input(format!(
                "error: {} while reading {shown}\n  = note: {LOADING_NOTE}\n",
                deadline.reason()
            )))
        }
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

/// A failed write to stderr: exit 1 with nothing more to say.
fn stderr_failure(_: std::io::Error) -> Failure {
    Failure::Output(String::new())
}

/// A writer that stops at a `-time-limit`'s grace: every write reads the clock
/// ([`robovec_passes::Ticker::check`]; at most 64 KiB is written per call, and the caller
/// buffers the small writes before it), and once it stopped writes fail with the ticker's
/// message (`… reached: stopped while writing it; the output needs it, so nothing is
/// written`): the staged file is then removed with the run's others.
struct GraceWriter<'a> {
    inner: &'a mut dyn Write,
    ticker: &'a robovec_passes::Ticker,
}

impl Write for GraceWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        const CHUNK: usize = 1 << 16;
        if self.ticker.check() {
            return Err(std::io::Error::other(self.ticker.stop_message("while writing it")));
        }
        self.inner.write(&buf[..buf.len().min(CHUNK)])
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
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

/// Which of the run's standard streams are terminals (`robovec-opt` asks the OS; tests and
/// library callers say so). Both false by default: a piped run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Terminal {
    /// stdout is a terminal: the final IR is not printed there without `-o -`
    /// ([`stdout_choice`]).
    pub stdout: bool,
    /// stderr is a terminal: long work shows progress bars unless `-q`
    /// ([`crate::progress_bars::progress_for`]).
    pub stderr: bool,
}

/// What stdout receives at the end of a run (see [`stdout_choice`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StdoutChoice {
    /// The final IR (or generated code).
    Main,
    /// `-eval`'s JSON.
    Eval,
    /// Nothing: `-o FILE` took the IR.
    Nothing,
    /// Nothing, because stdout is a terminal: the IR would flood it. `note` is true when the
    /// run printed no table, so a note on stderr says how to get the IR.
    HeldBack {
        /// Say so on stderr.
        note: bool,
    },
}

/// Decides what stdout receives, as LLVM's `opt` refuses to print bitcode to a terminal:
/// `-o -` forces the IR; `-o FILE` takes it; `-eval` prints its JSON; otherwise the IR goes to
/// stdout only when stdout is not a terminal. On a terminal it is held back, with a note
/// unless the run printed tables on stderr (`-stats`, a `sweep` or `-pareto` table: the reader
/// came for those).
pub fn stdout_choice(output: Option<&Path>, eval: bool, stdout_is_terminal: bool, tables_shown: bool) -> StdoutChoice {
    match output {
        Some(p) if p.as_os_str() == "-" => StdoutChoice::Main,
        Some(_) if eval => StdoutChoice::Eval,
        Some(_) => StdoutChoice::Nothing,
        None if eval => StdoutChoice::Eval,
        None if stdout_is_terminal => StdoutChoice::HeldBack { note: !tables_shown },
        None => StdoutChoice::Main,
    }
}

/// Runs one `robovec-opt` invocation with stdout and stderr not terminals (see [`run_with`]).
///
/// # Errors
/// [`Failure`] with its exit status.
pub fn run(opts: &Options, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), Failure> {
    run_with(opts, Terminal::default(), stdout, stderr)
}

/// Runs one `robovec-opt` invocation: check options → load → run passes (and the studies
/// `-pareto` and `-check`) → render every output in memory → put every file in place at once →
/// stdout. `stdout` receives the IR, the generated code or the `-eval` JSON; `stderr` receives
/// dumps, timing, notes, stats and the artifacts' tables.
///
/// # Errors
/// [`Failure`] with its exit status.
pub fn run_with(
    opts: &Options,
    terminal: Terminal,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    // `-time-limit` covers the whole run: loading (parsing, generating) and the passes.
    let deadline = opts.time_limit.map(robovec_passes::Deadline::after_seconds);
    // `load` verifies the input (always, whatever `-verify-each` says): the manager need not.
    let instr = Instrumentation { input_verified: true, ..opts.instr.clone() };
    let pm = PassManager::with_registry(robovec_backends::REGISTRY, &opts.passes, instr)
        .map_err(|e| Failure::Usage(format!("error: {e}\n")))?;
    crate::preflight::check_options(opts, &pm)?;
    let reads = crate::preflight::read_files(opts, &pm)?;
    let target = crate::options::target(opts)?;
    let eval_inputs = opts.eval.as_deref().map(read_eval_inputs).transpose()?;
    // Only the functions the run uses are built (a URDF's `-function=invdyna` skips `dirdyna`).
    // The input domain, when the pipeline needs it (every input must then have a range) or
    // -ranges gives one: its defaults are computed while loading, then resolved before any pass.
    // The first pass that needs the domain, named in the diagnostic when an input has no range.
    let needs_domain = pm.elements().find(|e| e.props.needs_domain).map(|e| e.pass.name());
    let front = FrontOptions {
        functions: opts.function.clone().map(|f| vec![f]),
        deadline,
        domain: needs_domain.is_some() || opts.ranges.is_some(),
        ..opts.front.clone()
    };
    let (loaded, src) = load_with(&opts.input, &front)?;
    let eval_inputs = eval_inputs.map(|given| crate::eval::EvalInputs {
        given,
        defaults: loaded.input_defaults,
        defaults_source: loaded.defaults_source,
    });
    let module = loaded.module;
    crate::preflight::check_functions(opts, &module)?;
    let domain = (needs_domain.is_some() || opts.ranges.is_some())
        .then(|| crate::ranges::domain(opts, &module, &loaded.domain_defaults, needs_domain))
        .transpose()?;
    // Every file of this run goes through `out`; dropped uncommitted (any `?` below), it
    // removes what it staged.
    let mut out = OutputSet::new();
    out.protect(reads);
    if let Some(path) = &opts.params_out {
        // The front end reads -params-out (checked before any work); it may still keep no value.
        let Some(params) = &loaded.params else {
            return Err(Failure::Usage(format!(
                "error: -params-out: `{}` leaves no parameter value as an input\n",
                opts.input
            )));
        };
        let json =
            serde_json::to_string_pretty(params).map_err(|e| Failure::Output(format!("error: -params-out: {e}\n")))?;
        out.stage(path, format!("{json}\n").as_bytes()).map_err(output_failure)?;
    }
    let progress = crate::progress_bars::progress_for(terminal.stderr, opts.quiet);
    let session = run_passes(opts, pm, target, progress, deadline, domain, module, &src, &mut out, stderr)?;
    write_outputs(opts, &session, eval_inputs.as_ref(), &src, terminal, out, stdout, stderr)
}

/// Runs `-pareto` (before the pipeline, on the input), the pipeline's session with its dumps
/// staged in `out`, `-report-dir`'s budget ladder (`precision::ladder::study`), then `-check`;
/// prints the early-stop notes. `deadline` is the run's,
/// started before loading.
#[allow(clippy::too_many_arguments)]
fn run_passes(
    opts: &Options,
    pm: PassManager,
    target: robovec_machine::target::Target,
    progress: robovec_passes::progress::Progress,
    deadline: Option<robovec_passes::Deadline>,
    domain: Option<robovec_ir::domain::Domain>,
    module: Module,
    src: &SourceFile,
    out: &mut OutputSet,
    stderr: &mut dyn Write,
) -> Result<Session, Failure> {
    let session_registry = pm.registry();
    let mut cx = PassContext {
        original: opts.check.map(|_| module.clone()),
        deadline,
        progress,
        code_file: crate::preflight::code_file(opts, &pm),
        domain,
        ..PassContext::with_target(target)
    };
    if let Some(text) = &opts.pareto {
        let name = select(&module, &opts.function, "-pareto")?.name.clone();
        let study = whole_run::pareto::measure(
            session_registry,
            &module,
            &name,
            text,
            opts.pareto_samples,
            opts.pareto_seed,
            deadline,
            &cx.target,
            &cx.progress,
            cx.domain.as_ref(),
        )
        .map_err(Failure::from)?;
        cx.emit(study);
    }
    // The domain in the report (`domain`) whether or not a pass reads it (`range` reports the
    // one it used, which replaces this).
    if let Some(dom) = &cx.domain {
        let functions = module
            .functions
            .iter()
            .map(|f| robovec_passes::range::FunctionDomain {
                function: f.name.clone(),
                inputs: dom.of_function(f).into_iter().map(|(n, r)| (n, r.clone())).collect(),
            })
            .collect();
        cx.emit(robovec_passes::range::DomainUsed { functions });
    }
    let mut session = Session::new(pm, module, cx);
    {
        let dir = opts.instr.dump_dir.clone().unwrap_or_default();
        let mut dumps = StagedDumps { dir, out, created: false };
        let ran = session.run(stderr, &mut dumps).map_err(|e| match e {
            PassError::Output { message } => output_failure(message),
            PassError::Log(e) => stderr_failure(e),
            e => pass_failure(e, src),
        });
        if let Err(f) = ran {
            // A run that fails past its limit leaves its module to the exit.
            leave_past_deadline(std::mem::take(&mut session.module), deadline.as_ref());
            return Err(f);
        }
    }
    // `-report-dir`'s cost-against-budget figure: the budget ladder of the reported function,
    // when the pipeline's `precision` gave it formats (its target and domain), and its points'
    // C timed on this machine (target `c`); a swept function's C timed for the µs figure.
    if opts.report_dir.is_some() {
        if let Ok(f) = select(&session.module, &opts.function, "-report-dir") {
            let name = f.name.clone();
            robovec_passes::precision::ladder::study(&session.module, &mut session.cx, &name);
            crate::report_dir::ladder_time::measure(&session.module, &mut session.cx, &name);
            crate::report_dir::cpu_line::measure(&session.module, &mut session.cx, &name);
        }
    }
    for s in session.cx.lines(robovec_passes::Severity::Stop) {
        writeln!(stderr, "note: {s}").map_err(stderr_failure)?;
    }
    if let (Some((samples, seed)), Some(original)) = (opts.check, &session.cx.original) {
        whole_run::check::run(
            &session.module,
            original,
            session.pipeline(),
            &opts.function,
            samples,
            seed,
            deadline,
            stderr,
        )
        .map_err(Failure::from)?;
    }
    Ok(session)
}

/// The report (SPEC §7) of the function `-report` describes: the run's own fields, the figures
/// of the final IR, then each artifact's entry (merged by key), then the early stops.
/// `computed` are those of [`summary::figures`] for `-function` (the reported function is among
/// them; they are computed again only if it were not).
fn report_json(
    opts: &Options,
    session: &Session,
    computed: &[Figures],
) -> Result<(String, crate::report_dir::data::ReportData), Failure> {
    let f = select(&session.module, &opts.function, "-report")?;
    let fallback;
    let own = match computed.iter().find(|g| g.function == f.name) {
        Some(g) => g,
        None => {
            fallback = Figures::of(f, &session.cx);
            &fallback
        }
    };
    let pipeline = session.pipeline().pipeline_text();
    let data = crate::report_dir::data::ReportData::of(&opts.input, &pipeline, own, &session.cx);
    Ok((report_text(&opts.input, &pipeline, session.records(), &session.cx, own), data))
}

/// `-eval`'s JSON, with a warning on stderr for each input given that the function does not
/// have and each user callback replaced by the interpreter's stand-in.
fn eval_json(
    opts: &Options,
    module: &Module,
    given: &crate::eval::EvalInputs,
    src: &SourceFile,
    stderr: &mut dyn Write,
) -> Result<String, Failure> {
    let f = select(module, &opts.function, "-eval")?;
    for name in given.given.keys() {
        if !f.inputs.iter().any(|&v| f.name_of(v) == name) {
            writeln!(stderr, "warning: `{name}` is not an input of @{}; ignored", f.name).map_err(stderr_failure)?;
        }
    }
    // Inputs not given are named (issue 29: they were silently random, gravity too).
    let missing = crate::eval::not_given(f, given);
    let first = |names: &[String]| {
        let shown: Vec<&str> = names.iter().take(6).map(String::as_str).collect();
        let more = names.len().saturating_sub(shown.len());
        shown.join(", ") + &if more > 0 { format!(" and {more} more") } else { String::new() }
    };
    let file = opts.eval.as_deref().map_or(String::new(), |p| p.display().to_string());
    if !missing.defaulted.is_empty() {
        let (n, source) = (missing.defaulted.len(), given.defaults_source);
        writeln!(stderr, "note: {n} inputs of @{} not in {file} take {source}: {}", f.name, first(&missing.defaulted))
            .map_err(stderr_failure)?;
    }
    if !missing.random.is_empty() {
        writeln!(
            stderr,
            "warning: {} inputs of @{} not in {file} get pseudo-random values in [-1, 1] (seed 0): {}",
            missing.random.len(),
            f.name,
            first(&missing.random)
        )
        .map_err(stderr_failure)?;
    }
    let r = if f.has_formats() {
        if opts.eval_f32 {
            return Err(Failure::Usage(format!(
                "error: -eval-precision=f32: the values of @{} carry their own numeric formats, which say how each is computed\n",
                f.name
            )));
        }
        crate::eval::evaluate_formats(f, &given.given, &given.defaults, Some((&src.name, &src.text)))
            .map_err(Failure::Input)?
    } else {
        crate::eval::evaluate_with(f, &given.given, &given.defaults, opts.eval_f32)
    };
    // An output that is not finite prints as `null`: say where the values went wrong (issue 47:
    // a zero mass given for a link made every `qdd` null without a word).
    if let Some(n) = &r.non_finite {
        write!(stderr, "{}", n.warning(&f.name, Some((&src.name, &src.text)))).map_err(stderr_failure)?;
    }
    for c in &r.callback_standins {
        writeln!(
            stderr,
            "warning: @{} calls user callback `{c}`; evaluated with the stand-in (a linear form of its \
             arguments, robovec_ir::interp::callback_standin)",
            f.name
        )
        .map_err(stderr_failure)?;
    }
    Ok(serde_json::to_string_pretty(&r).expect("eval serialises") + "\n")
}

/// The generated code `-o` writes when the pipeline ends in a back end.
fn generated_code(session: &Session) -> Result<Option<&GeneratedCode>, Failure> {
    session.generated_code().map_err(|e| Failure::Input(format!("error: {e}\n")))
}

/// The CSV tables of several artifacts as one file: a header line equal to the first table's is
/// written once.
fn join_csv(tables: impl Iterator<Item = String>) -> String {
    let mut out = String::new();
    let mut header: Option<String> = None;
    for t in tables {
        let (first, rest) = t.split_once('\n').unwrap_or((&t, ""));
        match &header {
            Some(h) if h == first => out += rest,
            _ => {
                header.get_or_insert_with(|| first.to_string());
                out += &t;
            }
        }
    }
    out
}

/// Renders every output in memory, stages every file in `out`, commits them at once, then
/// writes stdout.
#[allow(clippy::too_many_arguments)]
fn write_outputs(
    opts: &Options,
    session: &Session,
    eval_inputs: Option<&crate::eval::EvalInputs>,
    src: &SourceFile,
    terminal: Terminal,
    mut out: OutputSet,
    stdout: &mut dyn Write,
    stderr: &mut dyn Write,
) -> Result<(), Failure> {
    let (cx, module) = (&session.cx, &session.module);
    // The final IR's figures, once for both the report and `-stats` (the placement's include
    // the tight lower bound, and a parsed function is atomised to be measured).
    let reporting = opts.report.is_some() || opts.report_dir.is_some();
    let figs =
        if opts.stats || reporting { summary::figures(module, cx, opts.function.as_deref()) } else { Vec::new() };
    let report = reporting.then(|| report_json(opts, session, &figs)).transpose()?;
    let eval = eval_inputs.map(|given| eval_json(opts, module, given, src, stderr)).transpose()?;
    if opts.stats {
        write!(stderr, "{}", summary::stats_text(&figs, cx, opts.function.as_deref())).map_err(stderr_failure)?;
    }
    let mut tables_shown = opts.stats;
    for a in cx.artifacts() {
        let text = a.log_text(opts.stats);
        tables_shown |= !text.is_empty();
        write!(stderr, "{text}").map_err(stderr_failure)?;
    }
    let code = generated_code(session)?;
    // The IR is printed straight into its file or stdout (never held as one string: at 7× the
    // size of a Robotran input it would be the largest allocation of a run), within the
    // limit's grace: the output needs it.
    let grace = robovec_passes::Ticker::new(cx.deadline.map(|d| d.grace()), None);
    let mut print_main = |w: &mut dyn Write| {
        // Buffered before the clock: the printer's many small writes reach it 64 KiB at a time.
        let mut w = std::io::BufWriter::with_capacity(1 << 16, GraceWriter { inner: w, ticker: &grace });
        match code {
            Some(c) => w.write_all(c.main.as_bytes())?,
            None => write!(w, "{module}")?,
        }
        w.flush()
    };

    // Then put every file in place at once, and write stdout last. The files of passes'
    // folders are named only now: none may be a file the run reads (bad usage, as the
    // outputs checked before any work).
    for a in cx.artifacts() {
        let files = a.files(module.functions.len() > 1);
        for file in &files {
            out.check_not_read(&file.path).map_err(|e| Failure::Usage(e + "\n"))?;
        }
        for file in files {
            if let Some(dir) = file.path.parent().filter(|d| !d.as_os_str().is_empty()) {
                out.ensure_folder(dir).map_err(output_failure)?;
            }
            if file.executable {
                out.stage_executable(&file.path, &file.bytes).map_err(output_failure)?;
            } else {
                out.stage(&file.path, &file.bytes).map_err(output_failure)?;
            }
        }
    }
    if let Some(path) = &opts.sweep_csv {
        out.stage(path, join_csv(cx.artifacts().filter_map(|a| a.csv())).as_bytes()).map_err(output_failure)?;
    }
    if let (Some(path), Some((r, _))) = (&opts.report, &report) {
        out.stage(path, r.as_bytes()).map_err(output_failure)?;
    }
    if let (Some(dir), Some((r, data))) = (&opts.report_dir, &report) {
        let files =
            crate::report_dir::files(r, data).map_err(|e| Failure::Output(format!("error: -report-dir: {e}\n")))?;
        out.stage_folder(dir, &files).map_err(output_failure)?;
    }
    let choice = stdout_choice(opts.output.as_deref(), eval.is_some(), terminal.stdout, tables_shown);
    match &opts.output {
        Some(p) if p.as_os_str() != "-" => {
            out.stage_with(p, &mut print_main).map_err(output_failure)?;
            if let Some(code) = code {
                for (ext, text) in &code.companions {
                    if let Some(c) = crate::preflight::companion_path(p, ext) {
                        out.stage(&c, text.as_bytes()).map_err(output_failure)?;
                    }
                }
                for (k, text) in code.units.iter().enumerate() {
                    out.stage(&robovec_passes::unit_path(p, k + 1), text.as_bytes()).map_err(output_failure)?;
                }
            }
        }
        _ => {}
    }
    if choice == (StdoutChoice::HeldBack { note: true }) {
        // Before the commit: a failed write to stderr leaves no file behind.
        let what = code.map_or("final IR".to_string(), |c| format!("generated {}", c.language));
        writeln!(stderr, "note: the {what} is not printed on a terminal; write it with -o FILE, or print it with -o -")
            .map_err(stderr_failure)?;
    }
    let written = out.commit().map_err(output_failure)?;
    let mut put = || -> std::io::Result<()> {
        if choice == StdoutChoice::Main {
            let mut buf = std::io::BufWriter::with_capacity(1 << 16, &mut *stdout);
            print_main(&mut buf)?;
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
        Failure::Output(format!("error: cannot write to stdout: {e}{already}\n"))
    })
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;

    use super::{read_bounded, GraceWriter, ReadStop};
    use std::io::Write;

    /// Issue 47: writing the output reads the grace's clock, so it is never what holds a run
    /// past its grace; a stop is the write's error (the staged file is then removed).
    #[test]
    fn writing_stops_at_the_grace_and_writes_at_most_a_chunk_per_call() {
        let mut out = Vec::new();
        let ticker = robovec_passes::Ticker::new(None, Some(3));
        let mut w = GraceWriter { inner: &mut out, ticker: &ticker };
        assert_eq!(w.write(&[b'a'; 100_000]).unwrap(), 1 << 16, "one chunk of 64 KiB per call");
        w.write_all(b"bc").unwrap();
        let e = w.write_all(b"d").expect_err("the third tick stops");
        assert_eq!(
            e.to_string(),
            "tick budget of 3 steps reached: stopped while writing it; the output needs it, so nothing is written"
        );
        assert_eq!(out.len(), (1 << 16) + 2);
        let never = robovec_passes::Ticker::new(None, None);
        let mut all = Vec::new();
        write!(GraceWriter { inner: &mut all, ticker: &never }, "{}", "x".repeat(200_000)).unwrap();
        assert_eq!(all.len(), 200_000);
    }

    /// Issue 47: a device that never ends (`/dev/zero`) stops at the bound, a regular file is
    /// refused by its size before any read, an abandoned reader stops at its next chunk.
    #[cfg(unix)]
    #[test]
    fn reading_stops_at_the_bound_and_when_abandoned() {
        let go = AtomicBool::new(false);
        assert!(matches!(read_bounded("/dev/zero", 3 << 20, &go), Err(ReadStop::TooLarge)));
        let f = std::env::temp_dir().join(format!("robovec-read-bound-{}", std::process::id()));
        std::fs::write(&f, vec![b'x'; 5000]).unwrap();
        let name = f.to_str().unwrap();
        assert!(matches!(read_bounded(name, 4999, &go), Err(ReadStop::TooLarge)));
        assert_eq!(read_bounded(name, 5000, &go).ok().map(|b| b.len()), Some(5000));
        assert!(matches!(read_bounded("/dev/zero", 3 << 20, &AtomicBool::new(true)), Err(ReadStop::Abandoned)));
        std::fs::remove_file(&f).unwrap();
    }
}
