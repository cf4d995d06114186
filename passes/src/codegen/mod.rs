//! `codegen<…>`: the back ends (SPEC §8). `codegen<c;…>` writes C; other members of the family
//! (`codegen<fpga;…>`) plug in beside it through [`BACK_ENDS`].
//!
//! The first, bare word of the parameters selects the back end (`codegen<c;abi=plain>` is
//! `codegen<back-end=c;abi=plain>`). Shared pieces of every emitter live here: C-identifier
//! naming that keeps Robotran's value names ([`names`]), the input/output maps in canonical
//! SPEC §2 names ([`Interface`]) and literals that round-trip exactly ([`literal`]).

pub mod c;
pub mod fpga;
pub mod literal;
pub mod names;

use robovec_ir::{Def, Function, Module, Phase};

use crate::params::ParamKind;
use crate::{Artifact, GeneratedCode, Merge, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, ReportEntry};

/// A member of the `codegen` family: its selector word and how it builds from parameters.
pub struct BackEnd {
    /// The word that selects it (`c`).
    pub name: &'static str,
    /// Builds the pass from the family's checked parameters.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for options that cannot go together.
    pub build: fn(&Params) -> Result<Box<dyn Pass>, PassError>,
}

/// The back ends, selected by the first word of `codegen<…>`.
pub const BACK_ENDS: &[BackEnd] = &[
    BackEnd { name: "c", build: |p| Ok(Box::new(c::CodegenC::from_params(p)?)) },
    BackEnd { name: "fpga", build: |p| Ok(Box::new(fpga::CodegenFpga::from_params(p)?)) },
];

/// Registry entry: the back-end selector, then each back end's parameters.
pub const INFO: PassInfo = PassInfo {
    name: "codegen",
    doc: "write the functions as code (`codegen<c;…>`: C, SPEC §8, `-o FILE` gets the code; `codegen<fpga;out=DIR;…>`: the placed design's images, Verilog, simulate script and resources, issue 12)",
    params: &[
        ParamInfo {
            name: "back-end",
            kind: ParamKind::Selector { choices: &["c", "fpga"], default: "c" },
            doc: "back end, given as the first bare word (`codegen<c;…>`)",
        },
        c::ABI,
        c::PRECISION,
        c::BATCH,
        c::TRIG,
        c::NAME,
        fpga::OUT,
        fpga::FORMAT,
        fpga::RESOURCES,
    ],
    build: |p: &Params| {
        let which = p.choice("back-end")?;
        // every choice of the family is checked, whichever back end reads it
        for d in fpga::FPGA_CHOICES {
            p.choice(d.name)?;
        }
        let b = BACK_ENDS.iter().find(|b| b.name == which).expect("every selector choice has a back end");
        (b.build)(p)
    },
};

/// What one generated function takes and gives, in argument order (SPEC §8 `codegen`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Interface {
    /// Function name in the IR (`dirdyna`).
    #[serde(skip)]
    pub function: String,
    /// The C symbol (`dirdyna`, `mbs_dirdyna`).
    pub symbol: String,
    /// `plain` or `robotran`.
    pub abi: &'static str,
    /// `f64` or `f32`.
    pub precision: &'static str,
    /// States per call (lanes).
    pub batch: u32,
    /// `libm`, `input` or `inline`.
    pub trig: &'static str,
    /// Canonical input names (SPEC §2), in argument order: `in[i]` (or `in[i*W + lane]`) is
    /// input `i`. With `trig=input` the trig values (`S4`, `C4`) follow the IR's inputs.
    pub inputs: Vec<String>,
    /// Canonical output names, in result order.
    pub outputs: Vec<String>,
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
    crate::require_phase("codegen", m, Phase::Atomised)?;
    let a = emit(m)?;
    cx.emit(a);
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::{build_pass, parse_pipeline, PassError};

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
        assert!(robotran.contains("abi: \"robotran\""), "{robotran}");
        let fpga = build("codegen<fpga;out=x>").unwrap();
        assert!(fpga.contains("CodegenFpga") && fpga.contains("\"x\""), "{fpga}");
        assert!(matches!(build("codegen<fpga;abi=robotran>"), Err(PassError::BadParameter { .. })));
        assert!(matches!(build("codegen<c;out=x>"), Err(PassError::BadParameter { .. })));
        let twice = build("codegen<c;back-end=c>").unwrap_err().to_string();
        assert!(twice.contains("given twice"), "{twice}");
        let bad = build("codegen<c;abi=robotran;batch=8>").unwrap_err().to_string();
        assert!(bad.contains("`abi=robotran` cannot go with `batch=8`"), "{bad}");
    }
}
