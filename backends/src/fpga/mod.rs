//! `codegen<fpga;out=DIR;format=mif|hex|both;resources=auto|yosys|estimate;interconnect=crossbar|specialised>`: the seed's
//! architecture (ch. 1, §2.3; SPEC §5) for a placed function, as files an FPGA engineer loads,
//! simulates and sizes (issue 12).
//!
//! `DIR` receives (with several functions, `DIR/FUNCTION/` per function):
//! - `hex/NAME.hex` (`$readmemh`) and/or `mif/NAME.mif` (Intel MIF), per PE slot `S`:
//!   `peS_instr` (instruction memory, one word per cycle `0..=cycles`), `peS_xbar` (crossbar
//!   memory: the two write selects of PE memory `S`), `peS_bufi` (buffer instructions),
//!   `peS_capt` (output capture), `peS_data` (initial PE memory: constants, input words 0),
//!   `peS_out` (initial output memory), `peS_fix` (fixed-point PEs: shift words); and
//!   `ctrl0`, `ctrl1`, … (the control memory the HDL reads, which all PEs share: per cycle
//!   every PE's instruction, crossbar, buffer, capture and shift words, PE after PE, in lanes
//!   of the family's widest block-RAM word; the manifest's `control_lanes` and each PE's
//!   `control`). Word layouts: [`robovec_machine::encode`]'s
//!   module doc and the manifest's `widths` and `layout`.
//! - `manifest.json`: sizes, widths, the load map (input / trig value / constant → PE slot,
//!   address), the output map (output → PE slot, output-memory address), target, cycles.
//! - `hdl/`: `fp_units.v` (the FP unit boundary `fp_add_sub`, `fp_mul` with bit-exact binary32
//!   models: see that file's header for how to bind Intel's IP), `rv_mem.v` (inferred RAM/ROM
//!   initialised with `$readmemh`), `rv_lib.v` (PE, control), `robovec_top.v` (generated top:
//!   N ADD + N MULTI PEs, crossbar bus, cycle counter, start/done, output read port) and
//!   `testbench.v`.
//! - `simulate` (executable, Python 3 standard library + Icarus Verilog): `DIR/simulate
//!   INPUTS.json` runs the design and prints `{"cycles", "clocks", "outputs", "bits"}`.
//! - `resources.json`: ALM / M10K / DSP, fit, cycles, clock, µs ([`robovec_machine::resources`]).
//!
//! ## Issue 49: the interconnect and the PEs
//! - `interconnect=crossbar` (default) writes the seed's crossbar: any program of the same PEs
//!   loads; `interconnect=specialised` gives each write port a multiplexer over the sources its
//!   program routes ([`robovec_machine::design::routes`], which also says which programs such a
//!   design accepts).
//! - The PEs follow the function's formats ([`robovec_machine::program::fixed`]): binary32 PEs
//!   for a function without numeric formats, fixed-point PEs (`hdl/fix_units.v`, a shift memory
//!   per PE) when every value is `fix<w ≤ 32, f>`; anything else is refused naming a value.
//!
//! ## Design choices (where the issue is silent)
//! - The images are written from the machine program's encoding; the design's RTL
//!   (`hdl/rv_lib.v`) executes cycle `k` of the program in clock `k` after `start` and keeps
//!   `ir/src/placement.rs`'s timing exactly: the FP unit is a combinational binary32 core plus
//!   a delay line of `latency − 2` stages (the "+2" are the PE memory's read register and the
//!   crossbar register), so a result issued at `t` is written at `t + latency`.
//! - Inputs are not ports: they are words of the initial PE memory images at the load map's
//!   addresses (as the seed loads "initial data"); `simulate` writes them before running.
//! - The resource estimate runs Yosys inside the pass when `yosys` is on `PATH` and the design
//!   has at most [`AUTO_YOSYS_MAX_PES`] PEs (`resources=auto`, the default; larger designs get
//!   the analytic estimate and a `-stats` note);
//!   `resources=yosys` requires it at any size, `resources=estimate` skips it (analytic crossbar
//!   cost; deterministic and fast for tests).
//! - Trig initial values (`S4 = sin q[4]`) are loaded words computed by the host in binary32
//!   (`simulate` calls the C library's `sinf`/`cosf`, as robovec's interpreter does).
//! - Rejected with a diagnostic and nothing written: a function without placement, `div` or
//!   `call` ops (the PEs have only `fp_add_sub` and `fp_mul`), targets with `writes` ≠ 2 (the
//!   instruction word has two write ports), memories beyond the target (PE memory words, buffer
//!   depth, instruction memory depth) and latencies below 2.
//! - `-time-limit`: the pass is required (the output), so a limit reached before a function
//!   starts or while its placement is lowered (the lowering and its verifier tick once per
//!   value, write and cycle) ends the run with a time-limit error, nothing written. The
//!   encoding, the design, Yosys and the estimate of a lowered function are not interrupted
//!   (linear in the program's steps; Yosys only for designs of at most
//!   [`AUTO_YOSYS_MAX_PES`] PEs unless `resources=yosys`).
//!
//! This file is the pass (its parameters, its report and artifact); the work — lowering,
//! encoding, design, Verilog, estimate, files — is the machine crate's ([`robovec_machine::emit`]).

use std::path::{Path, PathBuf};

use serde::Serialize;

use robovec_machine::design::build::{DesignError, Limits};
use robovec_machine::design::routes::Interconnect;
use robovec_machine::design::Design;
use robovec_machine::emit::{emit_until, DesignFile, EmitOptions};
use robovec_machine::resources::{cost_model, CostModel, Logic, Resources, AUTO_YOSYS_MAX_PES};

use robovec_passes::params::{word_enum, ParamKind};
use robovec_passes::{try_each_function, AtTimeLimit, Before, Step};
use robovec_passes::{
    Artifact, ArtifactFile, Member, Merge, ParamInfo, Params, Pass, PassContext, PassError, ReportEntry, Ticker,
};

/// The FPGA back end of `codegen`: `codegen<fpga;…>`, with its parameters.
pub const BACK_END: Member = Member {
    name: "fpga",
    doc: "the placed design's images, manifest, Verilog, simulate script and resources (issue 12), in `out=DIR`",
    params: &[OUT, FORMAT, RESOURCES, INTERCONNECT],
    build: |p| Ok(Box::new(CodegenFpga::from_params(p)?)),
    props: robovec_passes::Props { back_end: true, formats: true, ..robovec_passes::Props::DEFAULT },
};

/// `out=DIR`.
pub const OUT: ParamInfo = ParamInfo {
    name: "out",
    kind: ParamKind::OutputFolder,
    doc: "FPGA: folder for images, manifest, Verilog, simulate script and resources.json (default `fpga`)",
};
/// `format=mif|hex|both`.
pub const FORMAT: ParamInfo = ParamInfo {
    name: "format",
    kind: ParamKind::Choice { choices: Format::WORDS, default: Format::Both.as_str() },
    doc: "FPGA: memory images as Intel MIF, $readmemh hex, or both",
};
/// `resources=auto|yosys|estimate`.
pub const RESOURCES: ParamInfo = ParamInfo {
    name: "resources",
    kind: ParamKind::Choice { choices: Logic::WORDS, default: Logic::Auto.as_str() },
    doc: "FPGA: logic from Yosys (auto: when on PATH and at most 32 + 32 PEs), the analytic estimate, or (pnr, ECP5 targets) the whole design synthesized, placed and routed with Yosys and nextpnr-ecp5: measured LUT4, EBR, MULT18X18D, Fmax and a bitstream (issue 49)",
};

/// `interconnect=crossbar|specialised`.
pub const INTERCONNECT: ParamInfo = ParamInfo {
    name: "interconnect",
    kind: ParamKind::Choice { choices: Interconnect::WORDS, default: Interconnect::Crossbar.as_str() },
    doc: "FPGA: the write ports' multiplexers: over every PE's result and buffer (crossbar: any program of the same PEs loads) or over the sources this program routes (specialised; issue 49)",
};

word_enum! {
    /// The memory images written (`format=`).
    pub enum Format {
        /// `both`: `hex/` and `mif/`.
        Both = "both",
        /// `mif`: Intel MIF only.
        Mif = "mif",
        /// `hex`: `$readmemh` hex only.
        Hex = "hex",
    }
}

/// The `codegen<fpga;…>` pass.
#[derive(Debug, Clone)]
pub struct CodegenFpga {
    /// Output folder.
    pub out: PathBuf,
    /// `format=`.
    pub format: Format,
    /// `resources=`.
    pub resources: Logic,
    /// `interconnect=`.
    pub interconnect: Interconnect,
}

/// The pass's name in its time-limit errors.
const PASS: &str = "codegen<fpga>";

fn failed(message: String) -> PassError {
    PassError::Failed { pass: "codegen".into(), message }
}

impl CodegenFpga {
    /// The options from checked parameters. Without `out`, the folder is `fpga` (in the
    /// working folder).
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for an empty `out`.
    pub fn from_params(p: &Params) -> Result<CodegenFpga, PassError> {
        let out = p.path("out")?.unwrap_or_else(|| "fpga".into());
        Ok(CodegenFpga {
            out: out.into(),
            format: p.word("format")?,
            resources: p.word("resources")?,
            interconnect: p.word("interconnect")?,
        })
    }
}

/// The report's `fpga` entry for one function.
#[derive(Clone, Debug, Serialize)]
pub struct FpgaReport {
    /// The folder written.
    pub out: String,
    /// Image formats.
    pub format: &'static str,
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// Cycles per evaluation.
    pub cycles: u32,
    /// `crossbar` or `specialised` (`interconnect=`).
    pub interconnect: &'static str,
    /// `binary32` or `fixed`: the PEs the function runs on (issue 49).
    pub pe_kind: &'static str,
    /// 32-bit multiplexer inputs of all write ports (crossbar: `2·n_pe` per port).
    pub mux_inputs: u64,
    /// Clock, MHz: the target's declared clock, or with `resources=pnr` the measured Fmax.
    pub clock_mhz: f64,
    /// `resources=pnr`: the Fmax nextpnr measured, MHz (then `clock_mhz` and `us` are at it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fmax_mhz: Option<f64>,
    /// µs per evaluation (the latency).
    pub us: f64,
    /// States one evaluation computes (`Function::states`, issue 49 item 3).
    pub states: u32,
    /// ns per state: `cycles / clock_mhz · 1000 / states` (the throughput figure).
    pub ns_per_state: f64,
    /// ALM / M10K / DSP (in the target family's units, `resources.units`), fit.
    pub resources: Resources,
}

/// What `codegen<fpga>` produced: per function, its design, files and figures.
#[derive(Debug)]
pub struct FpgaArtifact {
    /// Per function: name, report, files relative to the function's folder.
    pub functions: Vec<(String, FpgaReport, Vec<DesignFile>)>,
    /// `out=DIR`.
    pub out: PathBuf,
}

impl Artifact for FpgaArtifact {
    fn pass(&self) -> &'static str {
        "codegen"
    }

    fn report(&self, function: &str) -> Option<ReportEntry> {
        let (_, r, _) = self.functions.iter().find(|(f, _, _)| f == function)?;
        Some(ReportEntry::new("fpga", r, Merge::Last))
    }

    fn stats_text(&self, function: Option<&str>) -> String {
        let mut s = String::new();
        for (f, r, _) in self.functions.iter().filter(|(f, _, _)| function.is_none_or(|x| x == f)) {
            let x = &r.resources;
            let u = x.units;
            let clock = match r.fmax_mhz {
                Some(fmax) => format!("{fmax} MHz (Fmax, nextpnr)"),
                None => format!("{} MHz", r.clock_mhz),
            };
            s += &format!(
                "fpga @{f}: {} ADD + {} MULTI {} PEs, {} interconnect, {} cycles, {:.3} us at {clock}{}; {} {}, {} {}, {} {} ({}; {})\n",
                r.n_add,
                r.n_mul,
                r.pe_kind,
                r.interconnect,
                r.cycles,
                r.us,
                robovec_passes::summary::per_state(r.states, r.ns_per_state),
                x.alm,
                u.logic,
                x.m10k,
                u.bram,
                x.dsp,
                u.dsp,
                if x.fits { "fits" } else { "does not fit" },
                x.logic_from
            );
        }
        s
    }

    fn files(&self, several_functions: bool) -> Vec<ArtifactFile> {
        let mut v = Vec::new();
        for (f, _, files) in &self.functions {
            let base = if several_functions { self.out.join(f) } else { self.out.clone() };
            for x in files {
                v.push(ArtifactFile { path: base.join(&x.path), bytes: x.bytes.clone(), executable: x.executable });
            }
        }
        v
    }
}

/// The path `codegen<fpga>` writes for `function` (for messages and tests).
pub fn function_dir(out: &Path, function: &str, several: bool) -> PathBuf {
    if several {
        out.join(function)
    } else {
        out.to_path_buf()
    }
}

impl CodegenFpga {
    /// True when `resources=auto` leaves a design of `n_pes` PEs (ADD + MULTI) to the analytic
    /// estimate instead of Yosys (see [`AUTO_YOSYS_MAX_PES`]).
    fn auto_skips_yosys(&self, n_pes: u32) -> bool {
        self.resources == Logic::Auto && self.resources.skips_yosys(n_pes)
    }

    /// The design, report and files of one placed function.
    ///
    /// # Errors
    /// A diagnostic naming the function: no placement, or what [`robovec_machine::emit::emit`]
    /// refuses (what [`robovec_machine::design::build::from_placement`] refuses, or a Yosys failure;
    /// with `resources=yosys`: Yosys missing).
    pub fn build(
        &self,
        f: &robovec_ir::Function,
        limits: &Limits,
        model: &CostModel,
    ) -> Result<(Design, FpgaReport, Vec<DesignFile>), String> {
        self.build_within(f, limits, model, &Ticker::default()).map_err(|e| e.message)
    }

    /// [`CodegenFpga::build`] whose lowering ticks `ticker` (once per value, write and cycle:
    /// [`robovec_machine::program::lower_measured_until`]) and gives up when it says stop
    /// (`-time-limit`); the encoding, Yosys and the estimate after it are not interrupted.
    ///
    /// # Errors
    /// As [`CodegenFpga::build`]; when `ticker` stopped the lowering (then
    /// [`Ticker::stopped`]), the lowering's `stopped: time limit`.
    pub fn build_within(
        &self,
        f: &robovec_ir::Function,
        limits: &Limits,
        model: &CostModel,
        ticker: &Ticker,
    ) -> Result<(Design, FpgaReport, Vec<DesignFile>), DesignError> {
        let Some(p) = &f.placement else {
            return Err(format!("function @{} has no placement; run `place` before `codegen<fpga>`", f.name).into());
        };
        let opts = EmitOptions { logic: self.resources, format: self.format.as_str(), interconnect: self.interconnect };
        let (d, r, files) = emit_until(f, p, limits, model, &opts, &|| ticker.tick())?;
        let report = FpgaReport {
            out: self.out.display().to_string(),
            format: self.format.as_str(),
            n_add: d.n_add,
            n_mul: d.n_mul,
            cycles: d.cycles,
            interconnect: d.interconnect().as_str(),
            pe_kind: d.pe_kind.as_str(),
            mux_inputs: d.mux_inputs(),
            clock_mhz: r.clock_mhz,
            fmax_mhz: r.fmax_mhz,
            us: r.us,
            states: d.states,
            ns_per_state: robovec_passes::place::report::ns_per_state(d.cycles, r.clock_mhz, d.states),
            resources: r,
        };
        Ok((d, report, files))
    }
}

impl Pass for CodegenFpga {
    fn name(&self) -> &'static str {
        "codegen"
    }

    /// `-time-limit` (a required pass: the output): the lowering of each function stops at
    /// the limit, and a limit reached before a function starts stops the pass too; either
    /// ends the run with [`PassError::TimeLimit`] (nothing written).
    fn run(&self, m: &mut robovec_ir::Module, cx: &mut PassContext) -> Result<(), PassError> {
        robovec_passes::require_phase("codegen", m, robovec_ir::Phase::Atomised)?;
        if self.resources == Logic::Pnr {
            robovec_machine::pnr::part_of(&cx.target.name, cx.target.pnr.as_ref())
                .map_err(|message| PassError::BadParameter { pass: "codegen<fpga>".into(), message })?;
        }
        let (limits, model) = (Limits::of(&cx.target), cost_model(&cx.target));
        let mut estimated = Vec::new();
        let functions = try_each_function(
            m,
            cx,
            PASS,
            AtTimeLimit::Required,
            Before::Clock,
            |_, _| None,
            |f, _, ticker| {
                let built = self.build_within(f, &limits, &model, ticker);
                if ticker.stopped() {
                    return Ok(Step::Stopped { what: format!("in @{} while lowering", f.name), kept: None });
                }
                // Located at the value or placement line the lowering names, as `sim` does.
                let (_, report, files) = built.map_err(|e| match e.span {
                    s if s == robovec_ir::Span::DUMMY => failed(e.message),
                    s => failed(e.message).at(s),
                })?;
                if self.auto_skips_yosys(report.n_add + report.n_mul) {
                    estimated.push((f.name.clone(), report.n_add + report.n_mul));
                }
                Ok(Step::Done((f.name.clone(), report, files)))
            },
        )?;
        for (f, pes) in estimated {
            cx.remark_in(
                PASS,
                vec![f.clone()],
                format!(
                    "codegen<fpga> @{f}: {pes} PEs: resources from the analytic estimate (resources=auto gives Yosys designs of at most {AUTO_YOSYS_MAX_PES} PEs; resources=yosys runs it anyway)"
                ),
            );
        }
        cx.emit(FpgaArtifact { functions, out: self.out.clone() });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use robovec_passes::place::{place_function, PlaceOptions};
    use robovec_passes::{Instrumentation, PassContext, PassError, PassManager};

    /// `@f`, 200 ops placed on 2 + 2 PEs.
    fn placed() -> robovec_ir::Module {
        let mut f = robovec_testkit::dag_gen::generate(200, 7);
        f.name = "f".into();
        f.placement = Some(place_function(&f, &PlaceOptions::with_pes(2)));
        robovec_ir::Module { functions: vec![f] }
    }

    fn run(budget: Option<u64>) -> (Result<(), PassError>, usize) {
        let pm = PassManager::with_registry(
            crate::REGISTRY,
            "codegen<fpga;out=unused;resources=estimate>",
            Instrumentation::default(),
        )
        .expect("builds");
        let mut m = placed();
        let mut cx = PassContext { tick_budget: budget, ..PassContext::default() };
        let ran = pm.run(&mut m, &mut cx, &mut Vec::new()).map(|_| ());
        assert!(cx.stopped().is_empty(), "a required pass notes no stop: {:?}", cx.stopped());
        (ran, cx.artifacts().count())
    }

    #[test]
    fn time_limit_in_the_lowering_ends_the_run_saying_where() {
        for (budget, expect) in [(1, "stopped before @f (0 functions done)"), (50, "stopped in @f while lowering")] {
            match run(Some(budget)) {
                (Err(PassError::TimeLimit { pass, message }), 0) => {
                    assert_eq!(pass, "codegen<fpga>");
                    assert_eq!(
                        message,
                        format!(
                            "tick budget of {budget} steps reached: {expect}; the output needs it, so nothing is \
                             written"
                        )
                    );
                }
                other => panic!("budget {budget}: {other:?}"),
            }
        }
        // Without a limit: the design.
        let (ran, artifacts) = run(None);
        ran.expect("emits");
        assert_eq!(artifacts, 1);
    }
}
