//! The pass manager: runs a pipeline and owns the cross-cutting work — IR printing before and
//! after passes, dump files, verification after each pass, timing (LLVM's pass
//! instrumentation; rustc's `run_passes_inner`). Passes never print or verify by themselves.
//!
//! Dump files (`-dump-dir`) are handed to a [`DumpSink`] as the passes run: the manager decides
//! what to dump and names each file, the sink (`robovec-opt`'s output policy) decides how files
//! are written, so a failed run leaves none of them.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use robovec_ir::{verifier, Module};

use crate::{parse_pipeline, AtTimeLimit, BackEnd, Pass, PassContext, PassError, PassSpec, Props, Registry};

/// Which passes to print the IR before/after.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum PrintSelector {
    /// None.
    #[default]
    None,
    /// Every pass (`-print-after-all`).
    All,
    /// Passes with these names (`-print-after=atomise`).
    Passes(Vec<String>),
}

impl PrintSelector {
    fn selects(&self, name: &str) -> bool {
        match self {
            PrintSelector::None => false,
            PrintSelector::All => true,
            PrintSelector::Passes(p) => p.iter().any(|x| x == name),
        }
    }
}

/// Instrumentation settings (command-line flags of SPEC §7).
#[derive(Clone, Debug)]
pub struct Instrumentation {
    /// `-print-before[-all]`.
    pub print_before: PrintSelector,
    /// `-print-after[-all]`.
    pub print_after: PrintSelector,
    /// `-dump-dir=DIR`: dumps `NNN-<pass>.before.rvir` and `.after.rvir` (NNN from 001) for every
    /// pass; the files go through the [`DumpSink`] given to [`PassManager::run_with_dumps`].
    pub dump_dir: Option<PathBuf>,
    /// `-verify-each` (default on): verify the input and the IR after every pass.
    pub verify_each: bool,
    /// `-time-passes`: print a timing table after the run.
    pub time_passes: bool,
    /// The caller verified the module before handing it over (the driver's `load` always does),
    /// so the manager skips its own check of the input; the IR after each pass is still
    /// verified under `verify_each`.
    pub input_verified: bool,
}

impl Default for Instrumentation {
    fn default() -> Self {
        Instrumentation {
            print_before: PrintSelector::None,
            print_after: PrintSelector::None,
            dump_dir: None,
            verify_each: true,
            time_passes: false,
            input_verified: false,
        }
    }
}

/// What one pass did (the report's `passes` entries, SPEC §7).
#[derive(Clone, Debug, serde::Serialize)]
pub struct PassRecord {
    /// Pass name as written in the pipeline (parameters included).
    pub name: String,
    /// Wall time of the pass alone, milliseconds (printing and verifying excluded).
    pub wall_ms: f64,
    /// Ops of the module before (SPEC §1; expressions counted as atomised).
    pub ops_before: u64,
    /// Ops after.
    pub ops_after: u64,
}

/// Receives the dumps of `-dump-dir` while the pipeline runs.
pub trait DumpSink {
    /// Takes one dump: its file name inside the dump folder (`001-atomise.before.rvir`) and its
    /// text.
    ///
    /// # Errors
    /// A one-line message naming the file; the manager stops the pipeline with
    /// [`PassError::Output`].
    fn dump(&mut self, name: &str, text: &str) -> Result<(), String>;
}

/// The sink of [`PassManager::run`]: dumps need a real sink, so this one refuses them.
pub(crate) struct NoDumps;

impl DumpSink for NoDumps {
    fn dump(&mut self, name: &str, _: &str) -> Result<(), String> {
        Err(format!("cannot write dump {name}: dumps need PassManager::run_with_dumps and a DumpSink"))
    }
}

/// One element of a pipeline: as written, its declared properties and the built pass.
pub struct Element {
    /// The element as written (name and raw parameters).
    pub spec: PassSpec,
    /// Its properties, as the registry declares them ([`crate::PassInfo::props`], or its
    /// family member's).
    pub props: Props,
    /// The built pass.
    pub pass: Box<dyn Pass>,
}

/// A parsed and checked pipeline with its instrumentation: what a [`crate::Session`] runs,
/// and what the checks before any work ask about (its back end, whether it is bit-exact, …).
pub struct PassManager {
    passes: Vec<Element>,
    instr: Instrumentation,
    registry: Registry,
}

/// Total ops of a module.
pub fn module_ops(m: &Module) -> u64 {
    m.functions.iter().map(|f| f.op_counts().total).sum()
}

impl PassManager {
    /// Parses `pipeline` and builds every pass of [`crate::PASSES`] (all names and parameters
    /// checked up front).
    ///
    /// # Errors
    /// [`PassError::BadPipeline`], [`PassError::UnknownPass`], [`PassError::BadParameter`].
    pub fn new(pipeline: &str, instr: Instrumentation) -> Result<PassManager, PassError> {
        PassManager::with_registry(crate::PASSES, pipeline, instr)
    }

    /// Parses `pipeline` and builds every pass from `registry` (all names and parameters
    /// checked up front).
    ///
    /// # Errors
    /// [`PassError::BadPipeline`], [`PassError::UnknownPass`], [`PassError::BadParameter`].
    pub fn with_registry(registry: Registry, pipeline: &str, instr: Instrumentation) -> Result<PassManager, PassError> {
        let specs = if pipeline.trim().is_empty() { Vec::new() } else { parse_pipeline(pipeline)? };
        let passes = specs
            .into_iter()
            .map(|spec| registry.build(&spec).map(|(props, pass)| Element { spec, props, pass }))
            .collect::<Result<Vec<_>, _>>()?;
        for selector in [&instr.print_before, &instr.print_after] {
            if let PrintSelector::Passes(names) = selector {
                for n in names {
                    if registry.get(n).is_none() {
                        return Err(PassError::UnknownPass { name: n.clone(), valid: registry.names() });
                    }
                }
            }
        }
        Ok(PassManager { passes, instr, registry })
    }

    /// Appends `more`'s elements (a session that ran it after this pipeline:
    /// [`crate::Session::run_more`]).
    pub fn append(&mut self, more: PassManager) {
        self.passes.extend(more.passes);
    }

    /// The registry the pipeline was built from.
    pub fn registry(&self) -> Registry {
        self.registry
    }

    /// The normalised pipeline text (round-trips through [`PassManager::new`]).
    pub fn pipeline_text(&self) -> String {
        self.passes.iter().map(|e| e.spec.to_string()).collect::<Vec<_>>().join(",")
    }

    /// The elements of the pipeline, in order (names and raw parameters), for checking
    /// options against it before any work.
    pub fn specs(&self) -> impl Iterator<Item = &PassSpec> {
        self.passes.iter().map(|e| &e.spec)
    }

    /// The elements of the pipeline, in order: each as written, its declared properties and
    /// the built pass.
    pub fn elements(&self) -> impl Iterator<Item = &Element> {
        self.passes.iter()
    }

    /// The built passes, in order.
    pub fn passes(&self) -> impl Iterator<Item = &dyn Pass> {
        self.passes.iter().map(|e| e.pass.as_ref())
    }

    /// True when every pass of the pipeline is declared bit-exact ([`Props::bit_exact`]; an
    /// empty pipeline is): its result must reproduce its input bit for bit.
    pub fn is_bit_exact(&self) -> bool {
        self.passes.iter().all(|e| e.props.bit_exact)
    }

    /// True when some pass's artifact has a CSV table ([`Props::csv_table`]).
    pub fn makes_csv_table(&self) -> bool {
        self.passes.iter().any(|e| e.props.csv_table)
    }

    /// The back end the pipeline ends in, when `-o` writes its code ([`Props::back_end`] and
    /// [`Pass::as_back_end`]): `-o FILE` then receives its code, not the IR, with its companion
    /// files beside it.
    pub fn back_end(&self) -> Option<&dyn BackEnd> {
        self.passes.last().filter(|e| e.props.back_end).and_then(|e| e.pass.as_back_end())
    }

    /// When the pipeline ends in a back end ([`PassManager::back_end`]): the extensions of the
    /// companion files of its code.
    pub fn code_companions(&self) -> Option<&'static [&'static str]> {
        self.back_end().map(BackEnd::companions)
    }

    /// The translation units of the back end the pipeline ends in ([`BackEnd::units`]; 1
    /// otherwise).
    pub fn code_units(&self) -> usize {
        self.back_end().map_or(1, BackEnd::units)
    }

    /// The names of the files `-dump-dir` receives, in order (`001-atomise.before.rvir`,
    /// `001-atomise.after.rvir`, …): known before the run, so that none is written over a file
    /// the run reads.
    pub fn dump_names(&self) -> Vec<String> {
        let named = self.passes.iter().enumerate().map(|(i, e)| (i, e.pass.name()));
        named.flat_map(|(i, name)| ["before", "after"].map(|when| dump_name(i, name, when))).collect()
    }

    /// Index of the last pipeline element (the one whose code `-o` writes).
    pub fn last_index(&self) -> Option<usize> {
        self.passes.len().checked_sub(1)
    }

    /// Runs the pipeline on `m`; IR prints and the timing table go to `log`. With `dump_dir`
    /// set, use [`PassManager::run_with_dumps`] (this one fails at the first dump).
    ///
    /// # Errors
    /// As [`PassManager::run_with_dumps`].
    pub fn run(&self, m: &mut Module, cx: &mut PassContext, log: &mut dyn Write) -> Result<Vec<PassRecord>, PassError> {
        self.run_with_dumps(m, cx, log, &mut NoDumps)
    }

    /// Runs the pipeline on `m`; IR prints and the timing table go to `log`, dumps (when
    /// `dump_dir` is set) to `dumps`.
    ///
    /// # Errors
    /// The first pass error, a verifier failure naming the pass after which it happened, a dump
    /// the sink refuses ([`PassError::Output`]) or a failed write to `log` ([`PassError::Log`]).
    pub fn run_with_dumps(
        &self,
        m: &mut Module,
        cx: &mut PassContext,
        log: &mut dyn Write,
        dumps: &mut dyn DumpSink,
    ) -> Result<Vec<PassRecord>, PassError> {
        if self.instr.verify_each && !self.instr.input_verified {
            verify_named(m, "input")?;
        }
        check_fixed_formats(m, cx, "input")?;
        let mut dump = |name: String, m: &Module| match &self.instr.dump_dir {
            Some(_) => dumps.dump(&name, &m.to_string()).map_err(|message| PassError::Output { message }),
            None => Ok(()),
        };
        if cx.original.is_none() && self.passes.iter().any(|e| e.props.needs_original) {
            cx.original = Some(m.clone());
        }
        let mut records = Vec::new();
        note_atomised_ops(m, cx);
        for (i, Element { spec, props, pass }) in self.passes.iter().enumerate() {
            let name = pass.name();
            let ops_before = module_ops(m);
            // What may be cut short stops early enough for the output's tail (time_limit::kept_for).
            cx.deadline = cx.deadline.map(|d| d.keeping(crate::time_limit::kept_for(ops_before)));
            if let Some(d) = cx.deadline.filter(crate::Deadline::reached) {
                // `-time-limit` reached before the pass starts (crate::time_limit's policy).
                match props.at_time_limit {
                    AtTimeLimit::Skip => {
                        cx.note_skip(&spec.to_string(), &d.reason());
                        records.push(PassRecord {
                            name: spec.to_string(),
                            wall_ms: 0.0,
                            ops_before,
                            ops_after: ops_before,
                        });
                        continue;
                    }
                    AtTimeLimit::Required if d.grace().reached() => {
                        let message = format!(
                            "{} before it started (pass {} of {}); the output needs it, so nothing is written",
                            d.grace().reason(),
                            i + 1,
                            self.passes.len()
                        );
                        return Err(PassError::TimeLimit { pass: spec.to_string(), message });
                    }
                    AtTimeLimit::Required => {}
                }
            }
            if self.instr.print_before.selects(name) {
                write!(log, "*** IR Dump Before {spec} ***\n{m}").map_err(PassError::Log)?;
            }
            dump(dump_name(i, name, "before"), m)?;
            if let Some(phase) = props.requires {
                crate::require_phase(name, m, phase)?;
            }
            if !props.formats {
                refuse_formats(&spec.to_string(), m)?;
            }
            let t0 = Instant::now();
            cx.pass_index = Some(i);
            cx.running = props.at_time_limit;
            let ran = pass.run(m, cx);
            cx.pass_index = None;
            cx.running = AtTimeLimit::Skip;
            ran?;
            if !(props.exact_in_reals || props.bit_exact) && cx.reals_changed_by.is_none() {
                cx.reals_changed_by = Some(spec.to_string());
            }
            let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
            if !props.preserves_timing {
                m.functions.iter_mut().for_each(|f| f.clear_timing());
            }
            records.push(PassRecord { name: spec.to_string(), wall_ms, ops_before, ops_after: module_ops(m) });
            note_atomised_ops(m, cx);
            if self.instr.print_after.selects(name) {
                write!(log, "*** IR Dump After {spec} ***\n{m}").map_err(PassError::Log)?;
            }
            dump(dump_name(i, name, "after"), m)?;
            if self.instr.verify_each {
                verify_within(m, name, &spec.to_string(), cx.deadline)?;
            }
            if props.formats {
                check_fixed_formats(m, cx, name)?;
            }
        }
        if self.instr.time_passes {
            let total: f64 = records.iter().map(|r| r.wall_ms).sum();
            writeln!(log, "===-------------------------------------------------------------------------===")
                .map_err(PassError::Log)?;
            writeln!(log, "                          Pass execution timing report").map_err(PassError::Log)?;
            writeln!(log, "===-------------------------------------------------------------------------===")
                .map_err(PassError::Log)?;
            writeln!(log, "  {:>12}  {:>6}  {:>10}  {:>10}  Name", "Wall (ms)", "%", "ops before", "ops after")
                .map_err(PassError::Log)?;
            for r in &records {
                let pct = if total > 0.0 { 100.0 * r.wall_ms / total } else { 0.0 };
                writeln!(
                    log,
                    "  {:>12.3}  {:>5.1}%  {:>10}  {:>10}  {}",
                    r.wall_ms, pct, r.ops_before, r.ops_after, r.name
                )
                .map_err(PassError::Log)?;
            }
            writeln!(log, "  {total:>12.3}  100.0%  {:>10}  {:>10}  Total", "", "").map_err(PassError::Log)?;
        }
        Ok(records)
    }
}

/// [`PassError::Failed`] when a function of `m` has a value in a numeric format other than
/// binary64: `pass` does not declare that it understands formats (`Props::formats`).
fn refuse_formats(pass: &str, m: &Module) -> Result<(), PassError> {
    let Some((f, v)) = m.functions.iter().find_map(|f| f.first_formatted().map(|v| (f, v))) else { return Ok(()) };
    Err(PassError::Failed {
        pass: pass.to_string(),
        message: format!(
            "@{} has values in numeric formats (`%{}` is {}), which this pass does not understand; \
             it would compute them as binary64",
            f.name,
            f.name_of(v),
            f.format(v)
        ),
    }
    .at(f.value(v).span))
}

fn verify_named(m: &Module, pass: &str) -> Result<(), PassError> {
    verify_within(m, pass, pass, None)
}

/// The verifier after `pass` (`spec`: as written in the pipeline). The output needs it, so
/// under `-time-limit` it runs within the limit's grace (the clock read once per value, op,
/// load and write) and its end is [`PassError::TimeLimit`]: the verifier is never the step
/// that holds a run past its grace (`crate::time_limit`).
pub(crate) fn verify_within(
    m: &Module,
    pass: &str,
    spec: &str,
    deadline: Option<crate::Deadline>,
) -> Result<(), PassError> {
    let ticker = crate::Ticker::new(deadline.map(|d| d.grace()), None);
    let verified = verifier::verify_until(m, &mut || ticker.tick()).ok_or_else(|| PassError::TimeLimit {
        pass: spec.to_string(),
        message: ticker.stop_message("while verifying the module after it"),
    })?;
    verified.map_err(|errs| PassError::Verify {
        pass: pass.to_string(),
        errors: errs.iter().map(|e| format!("  {e}")).collect::<Vec<_>>().join("\n"),
        list: errs,
    })
}

/// The verifier's range check of fixed-point formats after `pass` (or on the `input`), when the
/// run has a domain ([`crate::error_bound::bound::check_fixed_formats`]): a fixed-point value
/// whose computed range may not store in its format is an error.
fn check_fixed_formats(m: &Module, cx: &PassContext, pass: &str) -> Result<(), PassError> {
    let Some(domain) = &cx.domain else { return Ok(()) };
    for f in m.functions.iter().filter(|f| f.has_formats()) {
        crate::error_bound::bound::check_fixed_formats(f, domain).map_err(|message| PassError::Failed {
            pass: pass.to_string(),
            message: format!("the verifier's fixed-point range check failed: {message}"),
        })?;
    }
    Ok(())
}

/// Records in [`PassContext::atomised_ops`] the ops of every atomised function not recorded yet.
fn note_atomised_ops(m: &Module, cx: &mut PassContext) {
    for f in m.functions.iter().filter(|f| f.phase == robovec_ir::Phase::Atomised) {
        if !cx.atomised_ops.contains_key(&f.name) {
            cx.atomised_ops.insert(f.name.clone(), f.op_counts().total);
        }
    }
}

/// The dump of the pass at pipeline index `i` (from 0) `when` (`before`, `after`) it runs:
/// `001-atomise.before.rvir`.
fn dump_name(i: usize, pass: &str, when: &str) -> String {
    format!("{:03}-{pass}.{when}.rvir", i + 1)
}
