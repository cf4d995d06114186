//! robovec's passes and the pass manager.
//!
//! Every pass is registered once in [`PASSES`] (name, parameters, doc, constructor); that
//! table feeds `-passes=` parsing, `--print-passes` and the error that lists valid names (as
//! rustc's `declare_passes!` and Cranelift's `timing.rs` do). A pass only transforms; the
//! [`manager`] does printing, dumping, verifying and timing.
#![deny(missing_docs)]

pub mod accuracy;
pub mod artifact;
pub mod asap_alap;
pub mod atomise;
pub mod contract;
pub mod cse;
pub mod dce;
pub mod depth_bound;
pub mod diff;
pub mod each;
pub mod eqsat;
pub mod error_bound;
pub mod inline;
pub mod interleave;
pub mod manager;
pub mod params;
pub mod pipeline;
pub mod place;
pub mod precision;
pub mod progress;
pub mod range;
pub mod recurrence;
pub mod reference;
pub mod report;
pub mod rotate_3m;
pub mod schedule_cpu;
pub mod session;
pub mod sim;
pub mod specialize;
pub mod summary;
pub mod sweep;
pub mod time_limit;
#[cfg(test)]
mod time_limit_tests;
pub mod tree_height;
pub mod whole_run;

use robovec_ir::analysis::Latencies;
use robovec_ir::verifier::VerifierError;
use robovec_ir::{Module, Phase, Span};
use robovec_machine::target::Target;

pub use artifact::{unit_path, Artifact, ArtifactFile, GeneratedCode, Merge, Produced, ReportEntry};
pub use each::{each_function, try_each_function, Before, Step};
pub use manager::{DumpSink, Element, Instrumentation, PassManager, PassRecord, PrintSelector};
pub use params::{LatencyOverride, Member, ParamInfo, ParamKind, Params};
pub use pipeline::{parse_pipeline, PassSpec};
pub use session::Session;
pub use time_limit::{AtTimeLimit, Deadline, Ticker};

/// What a pass may fail with.
#[derive(Debug, thiserror::Error)]
pub enum PassError {
    /// The pipeline text names an unknown pass; lists the valid names.
    #[error("unknown pass `{name}`; valid passes: {valid}")]
    UnknownPass {
        /// The unknown name.
        name: String,
        /// Comma-separated valid names.
        valid: String,
    },
    /// A parameter is unknown, repeated or malformed.
    #[error("pass `{pass}`: {message}")]
    BadParameter {
        /// Pass name.
        pass: String,
        /// What is wrong, with the valid parameters.
        message: String,
    },
    /// The pipeline text does not parse.
    #[error("bad pipeline `{pipeline}`: {message}")]
    BadPipeline {
        /// The pipeline text.
        pipeline: String,
        /// What is wrong.
        message: String,
    },
    /// The module is in the wrong phase for the pass.
    #[error("pass `{pass}` needs phase {needs:?} but function @{function} is {found:?} (run `atomise` first)")]
    WrongPhase {
        /// Pass name.
        pass: String,
        /// Function name.
        function: String,
        /// Phase required.
        needs: Phase,
        /// Phase found.
        found: Phase,
        /// The function's source span (`Span::DUMMY` when a front end or pass made it).
        span: Span,
    },
    /// Any other failure of a pass on the given input.
    #[error("pass `{pass}`: {message}")]
    Failed {
        /// Pass name.
        pass: String,
        /// What went wrong.
        message: String,
    },
    /// The verifier rejected the module after a pass (names the pass).
    #[error("verifier failed after pass `{pass}`:\n{errors}")]
    Verify {
        /// The pass after which the module no longer verifies (`input` before any pass).
        pass: String,
        /// The errors, one per line.
        errors: String,
        /// The same errors with their source spans, for rendering against the input.
        list: Vec<VerifierError>,
    },
    /// An error located at a line of the input (a `.rvir` placement line, a definition…).
    #[error("{error}")]
    At {
        /// The offending source text.
        span: Span,
        /// The error.
        error: Box<PassError>,
    },
    /// `-time-limit` was reached before or while a pass the output needs ran (see
    /// [`time_limit`]): nothing is written.
    #[error("pass `{pass}`: {message}")]
    TimeLimit {
        /// Pass name.
        pass: String,
        /// The limit and where the pass stopped.
        message: String,
    },
    /// Writing a dump failed.
    #[error("cannot write dump {path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The [`DumpSink`] refused a dump (the message names the file).
    #[error("{message}")]
    Output {
        /// One line, ready for stderr.
        message: String,
    },
    /// Writing IR prints or the timing table to the log (stderr) failed.
    #[error("cannot write to the log: {0}")]
    Log(std::io::Error),
}

impl PassError {
    /// Attaches the source span of the offending input line; a `Span::DUMMY` leaves `self`
    /// unchanged.
    pub fn at(self, span: Span) -> PassError {
        if span == Span::DUMMY {
            self
        } else {
            PassError::At { span, error: Box::new(self) }
        }
    }

    /// The source span the error points at, if any (`WrongPhase`: the function).
    pub fn span(&self) -> Option<Span> {
        match self {
            PassError::At { span, .. } | PassError::WrongPhase { span, .. } => {
                Some(*span).filter(|s| *s != Span::DUMMY)
            }
            _ => None,
        }
    }
}

/// How a pass's [`Diagnostic`] is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Severity {
    /// What a rewriting pass changed or an analysis found, one line per run: printed under
    /// `-stats`.
    Remark,
    /// The pass stopped early or was skipped (`-time-limit`, a work budget), with a valid
    /// result: always printed as a `note:` line, listed in the report's `stopped_early`.
    Stop,
}

/// What a pass says beside its artifacts (typed, as the artifacts are): its severity, the pass,
/// where (the functions it is about; none: the module or the pipeline), and the line.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Diagnostic {
    /// How it is shown.
    pub severity: Severity,
    /// The pass that said it, as written in the pipeline or registered (`balance`,
    /// `inline<max-uses=3;max-size=64>`).
    pub pass: String,
    /// The functions it is about, in module order (empty: the module, or the pipeline).
    pub functions: Vec<String>,
    /// The line as printed (`balance: @dirdyna: ops 4261 -> 4095, …`).
    pub message: String,
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// State that passes share across one pipeline run.
///
/// Results a pass makes for the user (tables, figures, files, generated code) are not fields
/// here: the pass hands them over as [`Artifact`]s with [`PassContext::emit`].
#[derive(Debug, Default)]
pub struct PassContext {
    /// The machine the run targets (`-target=de10-nano|FILE.json`, selected once; default
    /// `de10-nano`): latencies, write ports, memory sizes, clock and device capacities for
    /// every pass (see [`robovec_machine::target`]). Set it with [`PassContext::with_target`].
    pub target: Target,
    /// The pipeline's latencies now, cycles: the target's, until a pass gives `lat-*`
    /// explicitly; from that pass on the given ones replace them (the others stay), for every
    /// later pass and for the final figures (`-stats`, the report's `stats`). Passes read them
    /// with [`PassContext::latencies_for`].
    pub latencies: Latencies,
    /// Which pass last overrode [`PassContext::latencies`] and how (`asap-alap<lat-add=6;lat-mul=4>`);
    /// `None`: they are the target's.
    pub latencies_from: Option<String>,
    /// What the passes said beside their artifacts, in order ([`Diagnostic`]: severity, the
    /// pass, the functions it is about, the line): one remark per run of a rewriting pass saying
    /// what it changed (ops added or removed, critical path before and after; the driver prints
    /// them with `-stats`), one stop per pass that stopped early or was skipped (the driver
    /// prints each as a `note:` line, with or without `-stats`, and the report lists them in
    /// `stopped_early`).
    pub diagnostics: Vec<Diagnostic>,
    /// `-time-limit=SECONDS`: the instant by which the pipeline should end, with the limit it
    /// came from. Passes with long loops (eqsat's windows, place's restarts and search, sweep's
    /// configurations) check [`PassContext::out_of_time`] between steps, stop early with a valid
    /// result, and say so (see [`PassContext::note_stop`]).
    pub deadline: Option<Deadline>,
    /// Tests: every [`Ticker`] of the run ([`PassContext::ticker`]) stops at this tick, so a
    /// test stops any pass's loop at a chosen step whatever the machine's speed. `None` in
    /// real runs.
    pub tick_budget: Option<u64>,
    /// What `-time-limit` does to the pass running now (set by the manager from
    /// [`Props::at_time_limit`]; [`AtTimeLimit::Skip`] outside a pipeline): the tickers of a
    /// required pass ([`PassContext::ticker`]) run to the limit's grace ([`Deadline::grace`]).
    pub running: AtTimeLimit,
    /// The module as it entered the pipeline: the reference `accuracy` measures errors
    /// against (issue 10). The manager sets it when a pass asks for it
    /// ([`Props::needs_original`]) and it is not set yet (`-pareto` presets it).
    pub original: Option<robovec_ir::Module>,
    /// What the passes produced, in the order they produced it (see [`crate::artifact`]).
    pub artifacts: Vec<Produced>,
    /// The file `-o` writes a back end's code to (set by the driver; `None` for stdout or
    /// outside `robovec-opt`): a back end that writes several files names them after it in
    /// the code and the report (`codegen<c;units=K>`).
    pub code_file: Option<std::path::PathBuf>,
    /// Index in the pipeline of the pass running now (set by the manager; `None` outside a
    /// pipeline), recorded with every artifact.
    pub pass_index: Option<usize>,
    /// Ops of each function (by name) when the pipeline first had it atomised: after the
    /// pass that atomised it, or at the start when the input was atomised already (set by the
    /// manager). The baseline of ops budgets stated against the atomised equations (issue 31:
    /// `default<depth>` within 1.5× `atomise`'s ops; `recurrence<budget-of=atomised>`).
    pub atomised_ops: std::collections::HashMap<String, u64>,
    /// Where long loops report progress (samples, sweep configurations, search iterations):
    /// hidden by default; the driver plugs a display in when stderr is a terminal (see
    /// [`progress`]). Passes never write to the terminal themselves.
    pub progress: progress::Progress,
    /// The input domain (issue 48): each input's range of values, from the input's defaults
    /// (a URDF's joint limits and parameter values) and `-ranges=FILE`, set by the driver
    /// (`None` outside `robovec-opt`: a pass that needs it then reads its own `ranges=FILE`).
    pub domain: Option<robovec_ir::domain::Domain>,
    /// The first pass of the run that may have changed the exact real-number function of the
    /// module (one without [`Props::exact_in_reals`] or [`Props::bit_exact`]; set by the
    /// manager): from there on no error bound against the pipeline's input holds.
    pub reals_changed_by: Option<String>,
}

/// The latencies function `f` runs with on `target`'s PE array (issue 49): `pipeline` (the
/// pass's, [`PassContext::latencies_for`]) for binary32 PEs; for a function on fixed-point PEs
/// ([`robovec_machine::program::fixed::pe_kind`]) the target's `fix_pe` latencies for its word
/// ([`robovec_machine::target::FixPe::latencies_for`]: a MULTI PE one stage shorter when a
/// product is one DSP multiplier and the function has no fused multiply-add) with those `given`
/// on the pass applied. `asap-alap` and
/// `place` time each function with it.
pub fn function_latencies(
    target: &Target,
    f: &robovec_ir::Function,
    pipeline: Latencies,
    given: &LatencyOverride,
) -> Latencies {
    use robovec_machine::program::fixed::{pe_kind, word_bits, PeKind};
    match pe_kind(f) {
        Ok(PeKind::Fixed) => {
            let mac = f.body.iter().any(|&v| f.is_fixed_mac(v));
            given.apply(&target.fix_pe.latencies_for(target.family, word_bits(f), mac))
        }
        _ => pipeline,
    }
}

impl PassContext {
    /// A context for `target`, its latencies the pipeline's.
    pub fn with_target(target: Target) -> PassContext {
        PassContext { latencies: target.latencies, target, ..PassContext::default() }
    }

    /// The latencies `pass` runs with: the pipeline's ([`PassContext::latencies`]) with those
    /// given on the pass (`given`) replacing theirs. When some are given, they become the
    /// pipeline's from now on and [`PassContext::latencies_from`] names the pass.
    pub fn latencies_for(&mut self, pass: &str, given: &LatencyOverride) -> Latencies {
        let lat = given.apply(&self.latencies);
        if !given.is_empty() {
            self.latencies = lat;
            self.latencies_from = Some(format!("{pass}<{}>", given.text()));
        }
        lat
    }

    /// Where the pipeline's latencies come from, for reports: `target de10-nano` or the pass
    /// that last gave them (`asap-alap<lat-add=6;lat-mul=4>`).
    pub fn latencies_source(&self) -> String {
        match &self.latencies_from {
            Some(p) => p.clone(),
            None => format!("target {}", self.target.name),
        }
    }

    /// Time left before `-time-limit` is reached (`None`: no limit).
    pub fn time_left(&self) -> Option<std::time::Duration> {
        self.deadline.map(|d| d.time_left())
    }

    /// True when `-time-limit` is given and reached: a pass stops starting new work.
    pub fn out_of_time(&self) -> bool {
        self.deadline.is_some_and(|d| d.reached())
    }

    /// A [`Ticker`] for a pass's long loop: the run's deadline, or its grace for a required
    /// pass ([`PassContext::running`]), and the test budget [`PassContext::tick_budget`].
    pub fn ticker(&self) -> Ticker {
        let deadline = match self.running {
            AtTimeLimit::Skip => self.deadline,
            AtTimeLimit::Required => self.deadline.map(|d| d.grace()),
        };
        Ticker::new(deadline, self.tick_budget)
    }

    /// Records that `pass` stopped early: `what` says where and why (`after 12 of 345 windows
    /// of @dirdyna: time limit of 1 s reached`); a [`Severity::Stop`] diagnostic
    /// (`eqsat stopped after …`).
    pub fn note_stop(&mut self, pass: &str, what: &str) {
        self.diagnostics.push(Diagnostic {
            severity: Severity::Stop,
            pass: pass.to_string(),
            functions: Vec::new(),
            message: format!("{pass} stopped {what}"),
        });
    }

    /// Records that the manager skipped `pass` (`-time-limit` reached before it started;
    /// `reason`: `time limit of 1 s reached`): a [`Severity::Stop`] diagnostic
    /// (`balance skipped: time limit of 1 s reached before it started`).
    pub fn note_skip(&mut self, pass: &str, reason: &str) {
        self.diagnostics.push(Diagnostic {
            severity: Severity::Stop,
            pass: pass.to_string(),
            functions: Vec::new(),
            message: format!("{pass} skipped: {reason} before it started"),
        });
    }

    /// Records what `pass` did to the functions of `m` ([`Severity::Remark`]; `message` is the
    /// whole line `-stats` prints, `balance: @dirdyna: ops 4261 -> 4095, …`).
    pub fn remark(&mut self, pass: &str, m: &Module, message: String) {
        let functions = m.functions.iter().map(|f| f.name.clone()).collect();
        self.remark_in(pass, functions, message);
    }

    /// [`PassContext::remark`] about the named `functions` only (`codegen<fpga>`'s estimate of
    /// one function's resources).
    pub fn remark_in(&mut self, pass: &str, functions: Vec<String>, message: String) {
        self.diagnostics.push(Diagnostic { severity: Severity::Remark, pass: pass.to_string(), functions, message });
    }

    /// The lines of the diagnostics of `severity`, in order.
    pub fn lines(&self, severity: Severity) -> impl Iterator<Item = &str> {
        self.diagnostics.iter().filter(move |d| d.severity == severity).map(|d| d.message.as_str())
    }

    /// The early stops so far (the [`Severity::Stop`] lines), in order: what the report lists
    /// in `stopped_early`.
    pub fn stopped(&self) -> Vec<String> {
        self.lines(Severity::Stop).map(str::to_string).collect()
    }

    /// Hands over a result of the running pass (see [`crate::artifact`]).
    pub fn emit(&mut self, artifact: impl Artifact + 'static) {
        self.artifacts.push(Produced { pass_index: self.pass_index, artifact: Box::new(artifact) });
    }

    /// The artifacts produced so far, in order.
    pub fn artifacts(&self) -> impl Iterator<Item = &dyn Artifact> {
        self.artifacts.iter().map(|p| p.artifact.as_ref())
    }

    /// The artifacts of type `T` produced so far, in order (results read as their own type).
    pub fn artifacts_of<T: Artifact>(&self) -> impl Iterator<Item = &T> {
        self.artifacts().filter_map(|a| (a as &dyn std::any::Any).downcast_ref::<T>())
    }
}

/// A transformation or analysis over a whole module (`Debug` shows its options). What the
/// manager needs to know of a pass besides running it is declared in the registry
/// ([`PassInfo::props`], [`Props`]), not asked of the pass.
pub trait Pass: std::fmt::Debug {
    /// The registered (kebab-case) name.
    fn name(&self) -> &'static str;
    /// Runs the pass on every function of `m`.
    ///
    /// # Errors
    /// [`PassError`] when the input is not what the pass accepts.
    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError>;
    /// For a back end whose code `-o` writes (`codegen<c>`; `codegen<fpga>` writes a folder and
    /// leaves `-o` the IR): what `-o` and the output policy need to know of that code before
    /// it runs.
    fn as_back_end(&self) -> Option<&dyn BackEnd> {
        None
    }
}

/// What a back end's code is written as (SPEC §8): the files beside `-o FILE`. A back end whose
/// code `-o` writes implements it and returns itself from [`Pass::as_back_end`].
pub trait BackEnd {
    /// The extensions of the companion files of the code (`["h"]` for C's header). A pipeline
    /// whose last pass is a back end writes that pass's code with `-o FILE` instead of the IR,
    /// and the companions beside `FILE`.
    fn companions(&self) -> &'static [&'static str] {
        &[]
    }

    /// The translation units the code is written as (`codegen<c;units=K>`; 1: the main file
    /// only). With more than one, `-o FILE` is required and unit `k` goes to
    /// [`unit_path`]`(FILE, k)` ([`GeneratedCode::units`]).
    fn units(&self) -> usize {
        1
    }
}

/// The properties of a pass, declared with it in the registry ([`PassInfo::props`], or a
/// family member's [`Member::props`]) and read from there by the manager, the session's
/// questions ([`PassManager::is_bit_exact`], …), the driver's checks and the test kit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Props {
    /// The phase every function must be in, if any; the manager checks it before the pass runs.
    pub requires: Option<Phase>,
    /// What the manager does when `-time-limit` is reached before the pass starts
    /// ([`time_limit`]): the run ends ([`AtTimeLimit::Required`], the default), or the pass is
    /// skipped ([`AtTimeLimit::Skip`]: the module is valid and complete without it).
    pub at_time_limit: AtTimeLimit,
    /// The pass keeps existing timing attributes valid (analyses that only read, or write
    /// timing themselves); otherwise the manager clears them after the pass.
    pub preserves_timing: bool,
    /// The pass reads [`PassContext::original`] (the manager then keeps a copy of the module as
    /// it entered the pipeline).
    pub needs_original: bool,
    /// Every output keeps its value bit for bit in binary32 and binary64 (the sign of an exact
    /// zero aside): a pipeline of such passes must reproduce its input exactly (`-check`,
    /// `-pareto`, the test kit's numeric property; docs/accuracy.md).
    pub bit_exact: bool,
    /// The pass that must run right before this one (`sim` executes the placement `place`
    /// attaches; any pass in between may drop it).
    pub needs_before: Option<&'static str>,
    /// Its artifact has a CSV table (what `-sweep-csv=FILE` writes).
    pub csv_table: bool,
    /// A back end: it writes the module as code or design files (the `codegen` family's
    /// members); one whose code `-o` writes implements [`BackEnd`].
    pub back_end: bool,
    /// The pass understands numeric formats (`robovec_ir::format`: binary32 and fixed-point
    /// values, issue 48): it keeps them or computes with them. The manager refuses to run a pass
    /// without it on a function that has any (never a silent reinterpretation as binary64).
    pub formats: bool,
    /// The pass reads the input domain ([`PassContext::domain`]: `range`): the driver then
    /// resolves it before any work and refuses a run where an input has no range.
    pub needs_domain: bool,
    /// The pass keeps the exact real-number value of every output as a function of the inputs
    /// (identities only: reassociation, distribution, common subexpressions, fused
    /// multiply-adds, reordering; every analysis). `error-bound` proves its bound against the
    /// pipeline's input only after such passes; a pass without it (constant folding in
    /// binary64, user rules) sets [`PassContext::reals_changed_by`]. `bit_exact` implies it.
    pub exact_in_reals: bool,
}

impl Props {
    /// A required pass that needs no phase, clears timing and is not bit-exact: the
    /// properties a declaration starts from (`Props { bit_exact: true, ..Props::DEFAULT }`).
    pub const DEFAULT: Props = Props {
        requires: None,
        at_time_limit: AtTimeLimit::Required,
        preserves_timing: false,
        needs_original: false,
        bit_exact: false,
        needs_before: None,
        csv_table: false,
        back_end: false,
        formats: false,
        needs_domain: false,
        exact_in_reals: false,
    };
}

impl Default for Props {
    fn default() -> Props {
        Props::DEFAULT
    }
}

/// One entry of the pass registry.
pub struct PassInfo {
    /// Name used in `-passes=`.
    pub name: &'static str,
    /// One-line description.
    pub doc: &'static str,
    /// Accepted parameters. A pass family (`codegen`) declares a [`ParamKind::Selector`] here,
    /// and each of its [`Member`]s its own parameters.
    pub params: &'static [ParamInfo],
    /// Builds the pass from checked parameters (a family: [`Params::build_member`]).
    pub build: fn(&Params) -> Result<Box<dyn Pass>, PassError>,
    /// Its properties (a family's members declare their own: [`Member::props`]).
    pub props: Props,
}

impl PassInfo {
    /// Every parameter declaration of the pass: its own, then (for a pass family) each
    /// member's, in `--print-passes` order.
    pub fn every_param(&'static self) -> impl Iterator<Item = &'static ParamInfo> {
        self.params.iter().chain(self.params.iter().flat_map(ParamInfo::members).flat_map(|m| m.params))
    }

    /// The declaration of parameter `key`: the pass's own, or a member's (for a pass family).
    pub fn param(&'static self, key: &str) -> Option<&'static ParamInfo> {
        self.every_param().find(|p| p.name == key)
    }
}

/// A registry of passes: the table `-passes=` names are looked up in, `--print-passes` and
/// docs/passes.md are written from, and the manager reads each pass's [`Props`] from. This
/// crate's own is [`PASSES`] (the transforms and analyses); the complete one, with the back
/// ends, is `robovec_backends::REGISTRY`.
#[derive(Clone, Copy, Debug)]
pub struct Registry {
    /// Every pass, in `--print-passes` order.
    pub passes: &'static [&'static PassInfo],
}

impl std::fmt::Debug for PassInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PassInfo({})", self.name)
    }
}

impl Registry {
    /// Looks up a registered pass.
    pub fn get(&self, name: &str) -> Option<&'static PassInfo> {
        self.passes.iter().copied().find(|p| p.name == name)
    }

    /// Comma-separated names of all registered passes.
    pub fn names(&self) -> String {
        self.passes.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
    }

    /// Every registered pass, in order.
    pub fn iter(&self) -> impl Iterator<Item = &'static PassInfo> {
        self.passes.iter().copied()
    }

    /// Builds the pass of a parsed pipeline element, checking its parameters; with the
    /// properties it was declared with (a family member's, for a family).
    ///
    /// # Errors
    /// [`PassError::UnknownPass`] or [`PassError::BadParameter`].
    pub fn build(&self, spec: &PassSpec) -> Result<(Props, Box<dyn Pass>), PassError> {
        let info = self
            .get(&spec.name)
            .ok_or_else(|| PassError::UnknownPass { name: spec.name.clone(), valid: self.names() })?;
        let params = Params::check(info, &spec.params)?;
        (info.build)(&params).map(|p| (params.props(info), p))
    }

    /// The properties of a registered pass built with default parameters (a family: its
    /// default member's), `None` for an unknown name.
    pub fn props_of(&self, name: &str) -> Option<Props> {
        let info = self.get(name)?;
        Some(Params::defaults(info).props(info))
    }
}

impl IntoIterator for Registry {
    type Item = &'static PassInfo;
    type IntoIter = std::iter::Copied<std::slice::Iter<'static, &'static PassInfo>>;

    fn into_iter(self) -> Self::IntoIter {
        self.passes.iter().copied()
    }
}

/// The registry of this crate: every transform and analysis, in `--print-passes` order (the
/// back ends follow them in `robovec_backends::REGISTRY`).
pub const PASSES: Registry = Registry {
    passes: &[
        &atomise::INFO,
        &dce::INFO,
        &asap_alap::INFO,
        &place::INFO,
        &sim::INFO,
        &sweep::INFO,
        &accuracy::INFO,
        &tree_height::zero_removal::INFO,
        &tree_height::swap::INFO,
        &tree_height::balance::INFO,
        &inline::INFO,
        &interleave::INFO,
        &diff::INFO,
        &tree_height::distribute::INFO,
        &recurrence::INFO,
        &rotate_3m::INFO,
        &depth_bound::INFO,
        &range::INFO,
        &error_bound::INFO,
        &precision::INFO,
        &specialize::INFO,
        &eqsat::INFO,
        &cse::INFO,
        &contract::INFO,
        &schedule_cpu::INFO,
    ],
};

/// Builds the pass of a parsed pipeline element from [`PASSES`], checking its parameters.
///
/// # Errors
/// [`PassError::UnknownPass`] or [`PassError::BadParameter`].
pub fn build_pass(spec: &PassSpec) -> Result<Box<dyn Pass>, PassError> {
    PASSES.build(spec).map(|(_, p)| p)
}

/// Checks that every function of `m` is in `phase`.
///
/// # Errors
/// [`PassError::WrongPhase`] naming the first function that is not.
pub fn require_phase(pass: &str, m: &Module, phase: Phase) -> Result<(), PassError> {
    match m.functions.iter().find(|f| f.phase != phase) {
        Some(f) => Err(PassError::WrongPhase {
            pass: pass.to_string(),
            function: f.name.clone(),
            needs: phase,
            found: f.phase,
            span: f.span,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod target_tests {
    use super::*;

    #[test]
    fn the_default_context_is_the_built_in_target_with_its_latencies() {
        let cx = PassContext::default();
        assert_eq!(cx.target, Target::de10_nano());
        assert_eq!(cx.latencies, cx.target.latencies);
        assert_eq!(cx.latencies_source(), "target de10-nano");
    }

    #[test]
    fn given_latencies_replace_only_theirs_and_stay_for_later_passes() {
        let t = Target { latencies: Latencies { add: 5, mul: 3, div: 9, call: 11 }, ..Target::de10_nano() };
        let mut cx = PassContext::with_target(t);
        assert_eq!(
            cx.latencies_for("balance", &LatencyOverride::default()),
            Latencies { add: 5, mul: 3, div: 9, call: 11 }
        );
        assert_eq!(cx.latencies_from, None);
        let given = LatencyOverride { add: Some(6), ..LatencyOverride::default() };
        assert_eq!(cx.latencies_for("asap-alap", &given), Latencies { add: 6, mul: 3, div: 9, call: 11 });
        // A later pass without lat-* keeps them, and the source names the pass that gave them.
        assert_eq!(
            cx.latencies_for("place", &LatencyOverride::default()),
            Latencies { add: 6, mul: 3, div: 9, call: 11 }
        );
        assert_eq!(cx.latencies_source(), "asap-alap<lat-add=6>");
    }
}
