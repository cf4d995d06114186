//! robovec's back ends: the layer after the passes (ARCHITECTURE.md), and the complete
//! registry ([`REGISTRY`]: every pass of `robovec-passes`, then the back ends).
//!
//! `codegen<…>`: the back ends (SPEC §8). `codegen<c;…>` writes C ([`c`]); `codegen<fpga;…>`
//! writes a placed design's files ([`fpga`]). Each back end is a [`Member`] of the family
//! ([`BACK_ENDS`]) that declares its own parameters: `codegen<c;format=hex>` is refused,
//! `format` belonging to the FPGA back end.
//!
//! The first, bare word of the parameters selects the back end (`codegen<c;abi=plain>` is
//! `codegen<back-end=c;abi=plain>`). Pieces the C emitter shares with its callers live here:
//! C-identifier naming that keeps Robotran's value names ([`names`]), the input/output maps in
//! canonical SPEC §2 names ([`Interface`]) and literals that round-trip exactly ([`literal`]).
//!
//! A third back end is a folder here with its [`Member`] (selector word, doc, its own typed
//! parameters, its [`robovec_passes::Props`], constructor) and one line in [`BACK_ENDS`]; a
//! back end whose code `-o` writes implements [`robovec_passes::BackEnd`] (companion files,
//! translation units). Machine-specific work stays in the crate of its machine, as
//! `codegen<fpga>` calls `robovec-machine`.
#![deny(missing_docs)]

pub mod c;
pub mod fpga;
pub mod literal;
pub mod names;
#[cfg(test)]
mod params_tests;
#[cfg(test)]
mod time_limit_tests;

use robovec_ir::{Def, Function, Module, Phase};

use c::{Abi, Precision, Trig};
use robovec_passes::params::ParamKind;
use robovec_passes::{
    Artifact, GeneratedCode, Member, Merge, ParamInfo, Params, PassContext, PassError, PassInfo, Registry, ReportEntry,
    PASSES,
};

/// The back ends, selected by the first word of `codegen<…>`, each with its parameters.
pub const BACK_ENDS: &[Member] = &[c::BACK_END, fpga::BACK_END];

/// The complete registry: every pass of `robovec-passes` ([`robovec_passes::PASSES`]) in its
/// order, then `codegen` ([`INFO`]); what `-passes=`, `-pareto`, `--print-passes`,
/// docs/passes.md, the study and the test kit read.
pub const REGISTRY: Registry = Registry { passes: &ALL };

const ALL: [&PassInfo; PASSES.passes.len() + 1] = {
    let mut all = [&INFO; PASSES.passes.len() + 1];
    let mut i = 0;
    while i < PASSES.passes.len() {
        all[i] = PASSES.passes[i];
        i += 1;
    }
    all
};

/// Registry entry: the back-end selector; each back end declares its own parameters.
pub const INFO: PassInfo = PassInfo {
    name: "codegen",
    doc: "write the functions as code, by the back end the first bare word selects (`codegen<c;…>`, `codegen<fpga;out=DIR;…>`)",
    params: &[ParamInfo {
        name: "back-end",
        kind: ParamKind::Selector { members: BACK_ENDS, default: "c" },
        doc: "back end, given as the first bare word (`codegen<c;…>`)",
    }],
    build: Params::build_member,
    // A family: each back end (a `Member`) declares its own properties.
    props: robovec_passes::Props { back_end: true, ..robovec_passes::Props::DEFAULT },
};

/// What one generated function takes and gives, in argument order (SPEC §8 `codegen`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Interface {
    /// Function name in the IR (`dirdyna`).
    #[serde(skip)]
    pub function: String,
    /// The C symbol (`dirdyna`, `mbs_dirdyna`, `model_crba`).
    pub symbol: String,
    /// `plain`, `robotran` or `pinocchio` (the report writes the word).
    pub abi: Abi,
    /// `f64` or `f32`.
    pub precision: Precision,
    /// States per call (lanes).
    pub batch: u32,
    /// Where a batch's states are: `lanes` (SPEC §8's `in[i*W + lane]`; left out of the report)
    /// or `rows` (`in[lane*n + i]`, `n` the array's elements per state).
    #[serde(skip_serializing_if = "c::BatchLayout::is_lanes")]
    pub layout: c::BatchLayout,
    /// `libm`, `input` or `inline`.
    pub trig: Trig,
    /// Canonical input names (SPEC §2), in argument order: `in[i]` (or `in[i*W + lane]`) is
    /// input `i`. With `trig=input` the trig values (`S4`, `C4`) follow the IR's inputs. With
    /// `abi=pinocchio`, the elements of the input arrays in order (`q[1]`…`q[nq]`, `qd[1]`…),
    /// outputs likewise (`M[1][1]`, `M[1][2]`, …).
    pub inputs: Vec<String>,
    /// Canonical output names, in result order.
    pub outputs: Vec<String>,
    /// Functions the body is written as (`chunk=`, issue 28): 1, or the number of parts the
    /// entry point calls.
    pub parts: usize,
    /// The C files to compile, main file first (`-o FILE` and, with `units=K`, its K − 1
    /// further units); empty (and left out of the report) when the code goes to stdout.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<String>,
    /// The header written beside the main file; absent when the code goes to stdout.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub header: Option<String>,
}

/// The inputs of `f` in argument order: the IR's inputs, then (with `trig_as_input`) every trig
/// value in body order.
pub fn input_values(f: &Function, trig_as_input: bool) -> Vec<robovec_ir::Value> {
    let mut v = f.inputs.clone();
    if trig_as_input {
        v.extend(f.body.iter().copied().filter(|&x| matches!(f.value(x).def, Def::Trig(..))));
    }
    v
}

/// The artifact of a back end: the generated code and one [`Interface`] per function.
#[derive(Debug)]
pub struct CodegenArtifact {
    /// The code (`-o` writes it).
    pub code: GeneratedCode,
    /// Per function, what its generated symbol takes and gives.
    pub interfaces: Vec<Interface>,
}

impl Artifact for CodegenArtifact {
    fn pass(&self) -> &'static str {
        "codegen"
    }

    fn report(&self, function: &str) -> Option<ReportEntry> {
        let i = self.interfaces.iter().find(|i| i.function == function)?;
        Some(ReportEntry::new("codegen", i, Merge::Last))
    }

    fn code(&self) -> Option<&GeneratedCode> {
        Some(&self.code)
    }
}

/// Runs a back end's emitter over the module and hands its code to the run.
pub(crate) fn run_emitter(
    m: &Module,
    cx: &mut PassContext,
    emit: impl Fn(&Module) -> Result<CodegenArtifact, PassError>,
) -> Result<(), PassError> {
    robovec_passes::require_phase("codegen", m, Phase::Atomised)?;
    let a = emit(m)?;
    cx.emit(a);
    Ok(())
}

#[cfg(test)]
mod tests {
    use robovec_passes::{parse_pipeline, PassError};

    fn build_pass(spec: &robovec_passes::PassSpec) -> Result<Box<dyn robovec_passes::Pass>, PassError> {
        crate::REGISTRY.build(spec).map(|(_, p)| p)
    }

    fn build(text: &str) -> Result<String, PassError> {
        let spec = parse_pipeline(text).unwrap().remove(0);
        build_pass(&spec).map(|p| format!("{p:?}"))
    }

    #[test]
    fn the_first_bare_word_selects_the_back_end() {
        let plain = build("codegen").unwrap();
        assert_eq!(build("codegen<c>").unwrap(), plain, "`c` is the default back end");
        assert_eq!(build("codegen<back-end=c>").unwrap(), plain);
        let robotran = build("codegen<c;abi=robotran>").unwrap();
        assert!(robotran.contains("abi: Robotran"), "{robotran}");
        let fpga = build("codegen<fpga;out=x>").unwrap();
        assert!(fpga.contains("CodegenFpga") && fpga.contains("\"x\""), "{fpga}");
        let twice = build("codegen<c;back-end=c>").unwrap_err().to_string();
        assert!(twice.contains("given twice"), "{twice}");
        let bad = build("codegen<c;abi=robotran;batch=8>").unwrap_err().to_string();
        assert!(bad.contains("`abi=robotran` cannot go with `batch=8`"), "{bad}");
        let pinocchio = build("codegen<c;abi=pinocchio;batch=4;trig=inline>").unwrap();
        assert!(pinocchio.contains("abi: Pinocchio") && pinocchio.contains("batch: 4"), "{pinocchio}");
        for (bad, why) in [("precision=f32", "doubles"), ("trig=input", "no sin/cos")] {
            let e = build(&format!("codegen<c;abi=pinocchio;{bad}>")).unwrap_err().to_string();
            assert!(e.contains(&format!("`abi=pinocchio` cannot go with `{bad}`")) && e.contains(why), "{e}");
        }
        let verilog = build("codegen<back-end=verilog>").unwrap_err().to_string();
        assert_eq!(verilog, "pass `codegen`: parameter `back-end` must be `c` or `fpga`, found `verilog`");
    }

    #[test]
    fn a_parameter_of_the_other_back_end_is_refused_naming_its_back_end() {
        // Any value, the default too: each back end accepts its own parameters only.
        for (text, key, owner, selected) in [
            ("codegen<c;format=hex>", "format", "fpga", "c"),
            ("codegen<c;format=both>", "format", "fpga", "c"),
            ("codegen<c;out=x>", "out", "fpga", "c"),
            ("codegen<resources=auto>", "resources", "fpga", "c"),
            ("codegen<fpga;batch=4>", "batch", "c", "fpga"),
            ("codegen<fpga;abi=plain>", "abi", "c", "fpga"),
            ("codegen<fpga;name=f>", "name", "c", "fpga"),
        ] {
            let e = build(text).unwrap_err();
            assert!(matches!(e, PassError::BadParameter { .. }), "{text}: {e:?}");
            assert_eq!(
                e.to_string(),
                format!("pass `codegen`: parameter `{key}` belongs to back end `{owner}`, not `{selected}`"),
                "{text}"
            );
        }
        // A parameter no back end has lists the selected back end's.
        let e = build("codegen<fpga;frobnicate=1>").unwrap_err().to_string();
        assert_eq!(
            e,
            "pass `codegen`: unknown parameter `frobnicate` (valid: back-end, out, format, resources, interconnect)"
        );
        let e = build("codegen<frobnicate=1>").unwrap_err().to_string();
        assert_eq!(
            e,
            "pass `codegen`: unknown parameter `frobnicate` (valid: back-end, abi, precision, batch, layout, trig, name, chunk, units, slp)"
        );
    }

    #[test]
    fn the_registry_declares_each_parameter_once_under_its_back_end() {
        let info = crate::REGISTRY.get("codegen").unwrap();
        let names: Vec<&str> = info.every_param().map(|p| p.name).collect();
        assert_eq!(
            names,
            [
                "back-end",
                "abi",
                "precision",
                "batch",
                "layout",
                "trig",
                "name",
                "chunk",
                "units",
                "slp",
                "out",
                "format",
                "resources",
                "interconnect"
            ]
        );
        let members: Vec<(&str, Vec<&str>)> =
            super::BACK_ENDS.iter().map(|m| (m.name, m.params.iter().map(|p| p.name).collect())).collect();
        assert_eq!(
            members,
            [
                ("c", vec!["abi", "precision", "batch", "layout", "trig", "name", "chunk", "units", "slp"]),
                ("fpga", vec!["out", "format", "resources", "interconnect"])
            ]
        );
        assert_eq!(info.param("format").map(|p| p.name), Some("format"));
    }
}
