//! A session: one pipeline run on one module — the module, the pipeline ([`PassManager`]:
//! its elements with their declared properties), the context the passes share
//! ([`PassContext`]), and what the run made (the artifacts, the pass records).
//!
//! Every caller that runs a whole pipeline goes through it: `robovec-opt`'s driver, the study
//! of `robovec-gen --study`, `-pareto` (one session per pipeline), `-check` (it asks the
//! session whether its pipeline is bit-exact) and the test kit's numeric property. Questions
//! about the pipeline (is it bit-exact, does it end in a back end, does it make a CSV table)
//! are answered from the registry's declarations ([`crate::Props`]), never from pass names;
//! results are read as the artifacts' own types ([`Session::artifacts_of`]).

use std::io::Write;

use robovec_ir::Module;

use crate::manager::NoDumps;
use crate::{Artifact, DumpSink, GeneratedCode, PassContext, PassError, PassManager, PassRecord};

/// One pipeline run on one module (module doc).
pub struct Session {
    pipeline: PassManager,
    /// The module: the input until [`Session::run`], the final IR after.
    pub module: Module,
    /// The context the passes share: target, latencies, deadline, artifacts, notes.
    pub cx: PassContext,
    records: Vec<PassRecord>,
}

impl Session {
    /// A session that will run `pipeline` on `module` with `cx` (its target, deadline and
    /// progress display set by the caller).
    pub fn new(pipeline: PassManager, module: Module, cx: PassContext) -> Session {
        Session { pipeline, module, cx, records: Vec::new() }
    }

    /// Runs the pipeline; IR prints and the timing table go to `log`, dumps to `dumps`
    /// ([`PassManager::run_with_dumps`]).
    ///
    /// # Errors
    /// As [`PassManager::run_with_dumps`].
    pub fn run(&mut self, log: &mut dyn Write, dumps: &mut dyn DumpSink) -> Result<(), PassError> {
        self.records = self.pipeline.run_with_dumps(&mut self.module, &mut self.cx, log, dumps)?;
        Ok(())
    }

    /// Runs a further pipeline on the session's module and context, as if its passes followed
    /// the session's in one `-passes` list (the study's measurements after its best pipeline):
    /// its records are appended and its elements join the session's pipeline.
    ///
    /// # Errors
    /// As [`Session::run`].
    pub fn run_more(&mut self, more: PassManager) -> Result<(), PassError> {
        let records = more.run(&mut self.module, &mut self.cx, &mut std::io::sink())?;
        self.records.extend(records);
        self.pipeline.append(more);
        Ok(())
    }

    /// Runs the pipeline with no log and no dumps (the studies, the test kit).
    ///
    /// # Errors
    /// As [`Session::run`].
    pub fn run_quiet(&mut self) -> Result<(), PassError> {
        self.run(&mut std::io::sink(), &mut NoDumps)
    }

    /// The pipeline, with its questions ([`PassManager::is_bit_exact`],
    /// [`PassManager::back_end`], …).
    pub fn pipeline(&self) -> &PassManager {
        &self.pipeline
    }

    /// What each pass did (the report's `passes`), after [`Session::run`].
    pub fn records(&self) -> &[PassRecord] {
        &self.records
    }

    /// The artifacts produced, in order.
    pub fn artifacts(&self) -> impl Iterator<Item = &dyn Artifact> {
        self.cx.artifacts()
    }

    /// The artifacts of type `T`, in order: results read as the type the pass made them, not
    /// through their report JSON.
    pub fn artifacts_of<T: Artifact>(&self) -> impl Iterator<Item = &T> {
        self.cx.artifacts_of::<T>()
    }

    /// The code the back end the pipeline ends in generated (`None` when it ends in no back
    /// end: `-o` then writes the IR).
    ///
    /// # Errors
    /// [`PassError::Failed`] when it ends in a back end that generated no code (before the
    /// run, or a back end that failed to say).
    pub fn generated_code(&self) -> Result<Option<&GeneratedCode>, PassError> {
        if self.pipeline.back_end().is_none() {
            return Ok(None);
        }
        let last = self.pipeline.last_index();
        let code = self.cx.artifacts.iter().filter(|p| p.pass_index == last).find_map(|p| p.artifact.code());
        code.map(Some).ok_or_else(|| PassError::Failed {
            pass: self.pipeline.elements().last().map_or_else(String::new, |e| e.spec.to_string()),
            message: "the pipeline's last pass is a back end but generated no code".into(),
        })
    }

    /// The module, the context and the records, taking the session apart.
    pub fn into_parts(self) -> (Module, PassContext, Vec<PassRecord>) {
        (self.module, self.cx, self.records)
    }
}
