//! The CPU on the FPGA's plot (issue 49 item 5): when the run swept the reported function
//! (`sweep`), `-report-dir` times its C on the machine that runs the sweep — one state per call,
//! and `batch=4` per state — and the µs-against-N figure draws both as horizontal lines beside
//! the FPGA's configurations: where the design beats a CPU core, and by how much it must.
//!
//! The function is the final IR's (the C back end writes any atomised function: a placed one,
//! one in numeric formats), timed by [`crate::cpu_time`] over the run's domain when it covers
//! the inputs, else over inputs in [0.1, 1]. Reported under the key `cpu` of the function.

use robovec_passes::sweep::SweepTable;
use robovec_passes::{Artifact, Merge, PassContext, ReportEntry};
use serde::Serialize;

/// States per call of the batched measurement (4 `double` lanes: one AVX2 register).
pub const BATCH: u32 = 4;

/// The C times of one function on this machine, µs per state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CpuTimes {
    /// The function.
    #[serde(skip)]
    pub function: String,
    /// One state per call, µs (median of the repeats, [`crate::cpu_time`]).
    pub one_state_us: f64,
    /// `batch` states per call, µs per state.
    pub batched_us: f64,
    /// The batch of `batched_us`.
    pub batch: u32,
    /// How the C was built: `trig=inline`, the compiler and its flags.
    pub build: String,
}

impl Artifact for CpuTimes {
    fn pass(&self) -> &'static str {
        "-report-dir"
    }

    fn report(&self, function: &str) -> Option<ReportEntry> {
        (function == self.function).then(|| ReportEntry::new("cpu", self, Merge::Last))
    }
}

/// Times `function` of `module` when a `sweep` of it ran, and emits its [`CpuTimes`]; a failure
/// (no C compiler) is a note (`-report-dir: CPU time …`) and the figure has no CPU lines.
pub fn measure(module: &robovec_ir::Module, cx: &mut PassContext, function: &str) {
    if !cx.artifacts_of::<SweepTable>().any(|t| t.rows.iter().any(|r| r.function == function)) {
        return;
    }
    let Some(f) = module.function(function) else { return };
    let covered = cx.domain.as_ref().filter(|d| d.missing(f).is_empty());
    let result = crate::cpu_time::measuring(module, cx, "cpu", |dir, deadline| {
        let time = |batch: u32| match covered {
            Some(d) => crate::cpu_time::ns_per_state(f, d, batch, dir, deadline),
            None => crate::cpu_time::ns_per_state_anywhere(f, batch, dir, deadline),
        };
        Ok((time(1)?, time(BATCH)?))
    });
    match result {
        Ok((one, batched)) => cx.emit(CpuTimes {
            function: function.to_string(),
            one_state_us: one / 1e3,
            batched_us: batched / 1e3,
            batch: BATCH,
            build: format!(
                "codegen<c;trig=inline>, {} {}",
                crate::cpu_time::compiler(),
                crate::cpu_time::FLAGS.join(" ")
            ),
        }),
        Err(e) => cx.note_stop("-report-dir: CPU time of the swept function", &format!("not measured: {e}")),
    }
}
