//! `codegen<c;abi=plain|robotran|pinocchio;precision=f64|f32;batch=1|2|4|8|16;layout=lanes|rows;trig=libm|input|inline;name=…>`:
//! the functions as C (issue 11, SPEC §8).
//!
//! Every IR operation becomes one C statement, in the IR's order, so that the compiled code
//! computes bit for bit what robovec's interpreter computes (`-eval`, `-eval-precision=f32`)
//! when compiled without contraction (`-ffp-contract=off`; the file also says
//! `#pragma STDC FP_CONTRACT OFF`). `batch=W` computes W independent states per call with
//! GCC/Clang vector extensions (one source for SSE, AVX2, AVX-512 and NEON), lane-contiguous:
//! element `i` of lane `l` is `in[i*W + l]`; with `layout=rows`, `W` rows of a row-major `(B, n)`
//! array: `in[l*n + i]`, `n` the array's elements per state (read and written lane by lane).
//! With `trig=input` the `sin`/`cos` of the joint coordinates are inputs (after the IR's
//! inputs); with `trig=libm` they are computed (per lane).
//! With `trig=inline` they are computed by robovec's own branch-free sin/cos, written into the
//! file ([`trig`]: vectorised over the lanes, one reduction for the sin and cos of one
//! coordinate, within 1 ulp; one state's input coordinates in one block, a loop the C compiler
//! vectorises, `body::TrigBlock`): that code is **not** bit-exact with the interpreter, whose
//! sin/cos are libm's.
//!
//! ABIs: `plain` ([`plain`]) is `void NAME(const REAL *restrict in, REAL *restrict out)`;
//! `robotran` ([`robotran`]) has the signature and `MbsData` field access of the Robotran
//! function the IR came from, a drop-in replacement of its file; `pinocchio` ([`pinocchio`])
//! has the signatures of Pinocchio's algorithms for the URDF generator's functions
//! (`NAME_rnea(q, v, a, tau)`, `NAME_crba(q, M)`, `NAME_nle(q, v, nle)`, `NAME_aba(q, v, tau, qdd)`).

mod body;
mod callbacks;
mod file;
mod native;
mod slp;
pub use callbacks::split_callee;
pub mod pinocchio;
pub mod plain;
pub mod robotran;
mod split;
pub mod trig;

pub use file::{SLP_GUARD, STDC_GUARD, UNUSED_HELPERS};

use std::collections::HashSet;
use std::path::Path;

use robovec_ir::{Callee, Def, Function, Module};

use super::names::{free_name, is_c_identifier, is_reserved_symbol, reserved_symbol_reason, sanitise};
use super::{CodegenArtifact, Interface};
use robovec_passes::params::{word_enum, ParamKind};
use robovec_passes::{Member, ParamInfo, Params, Pass, PassContext, PassError};

/// The C back end of `codegen`: `codegen<c;…>`, with its parameters.
pub const BACK_END: Member = Member {
    name: "c",
    doc: "C (SPEC §8); `-o FILE` gets the code and FILE.h its prototypes",
    params: &[ABI, PRECISION, BATCH, LAYOUT, TRIG, NAME, CHUNK, UNITS, SLP],
    build: |p| Ok(Box::new(CodegenC::from_params(p)?)),
    props: robovec_passes::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        preserves_timing: true,
        back_end: true,
        formats: true,
        ..robovec_passes::Props::DEFAULT
    },
};

/// `abi=plain|robotran|pinocchio`.
pub const ABI: ParamInfo = ParamInfo {
    name: "abi",
    kind: ParamKind::Choice { choices: Abi::WORDS, default: Abi::Plain.as_str() },
    doc: "C: `plain` (in/out arrays), `robotran` (drop-in, Robotran's signature and MbsData) or `pinocchio` \
          (URDF dynamics as `NAME_rnea(q, v, a, tau)`, `NAME_crba(q, M)`, `NAME_nle(q, v, nle)`, \
          `NAME_aba(q, v, tau, qdd)` over Pinocchio's vectors, gravity (0, 0, -9.81) folded; parameters folded first)",
};
/// `precision=f64|f32`.
pub const PRECISION: ParamInfo = ParamInfo {
    name: "precision",
    kind: ParamKind::Choice { choices: Precision::WORDS, default: Precision::F64.as_str() },
    doc: "C: arithmetic and arrays in `double` (f64) or `float` (f32); with numeric formats the values compute in theirs and f32 makes the arrays `float` (binary32 outputs only)",
};
/// `batch=1|2|4|8|16`.
pub const BATCH: ParamInfo = ParamInfo {
    name: "batch",
    kind: ParamKind::U32Set { default: 1, allowed: &[1, 2, 4, 8, 16] },
    doc: "C: states per call, lanes (`in[i*W + lane]`; every array likewise with `abi=pinocchio`); not with `abi=robotran`",
};
/// `slp=0|4`.
pub const SLP: ParamInfo = ParamInfo {
    name: "slp",
    kind: ParamKind::U32Set { default: 0, allowed: &[0, 4] },
    doc: "C: one state's isomorphic ops four at a time as one vector op (`4`; packs seeded by four consecutive \
          columns of an output matrix, bit for bit the scalar code's values), or none (`0`); `batch=1` and \
          `precision=f64` only",
};
/// `layout=lanes|rows`.
pub const LAYOUT: ParamInfo = ParamInfo {
    name: "layout",
    kind: ParamKind::Choice { choices: BatchLayout::WORDS, default: BatchLayout::Lanes.as_str() },
    doc: "C: where a batch's states are in every array: `lanes` (element i of state l at `[i*W + l]`, one vector \
          load each) or `rows` (at `[l*n + i]`, n the array's elements per state: W rows of a row-major (B, n) \
          array, as numpy and Pinocchio's batches hold them; lane by lane); no effect with `batch=1`",
};
/// `trig=libm|input|inline`.
pub const TRIG: ParamInfo = ParamInfo {
    name: "trig",
    kind: ParamKind::Choice { choices: Trig::WORDS, default: Trig::Libm.as_str() },
    doc: "C: sin/cos of joint coordinates computed by libm (`libm`), taken as inputs (`input`), or computed \
          by robovec's own vectorised code in the file (`inline`: within 1 ulp, not bit-exact with `-eval`)",
};
/// `name=SYMBOL`.
pub const NAME: ParamInfo = ParamInfo {
    name: "name",
    kind: ParamKind::Names,
    doc: "C: symbol of the function (a prefix `NAME_function` with several functions; with `abi=pinocchio` \
          always the prefix of `NAME_rnea`…, default `model`)",
};

/// The default of `chunk=`: statements per part (see the module doc for the measurements).
pub const DEFAULT_CHUNK: u32 = 4000;

/// `chunk=OPS`.
pub const CHUNK: ParamInfo = ParamInfo {
    name: "chunk",
    kind: ParamKind::U32 { default: DEFAULT_CHUNK, min: 0, max: u32::MAX },
    doc: "C: a function of at least twice this many statements (ops) is written as a chain of parts of at most \
          about this many, which its entry point calls with its live values in an array on its stack (same symbol \
          and signature; GCC's time and memory per function grow faster than its size); `0`: one function",
};

/// `units=K`.
pub const UNITS: ParamInfo = ParamInfo {
    name: "units",
    kind: ParamKind::U32 { default: 1, min: 1, max: 1024 },
    doc: "C: translation units: `-o model.c` also writes `model_1.c` … `model_{K-1}.c` (parts of about equal size, \
          listed in the header and the report's `codegen.sources`) to compile in parallel and link together; \
          needs `-o FILE` and `chunk` > 0",
};

word_enum! {
    /// The signature of the generated functions (`abi=`).
    pub enum Abi {
        /// `plain` ([`plain`]): `void NAME(const REAL *restrict in, REAL *restrict out)`.
        Plain = "plain",
        /// `robotran` ([`robotran`]): the signature and `MbsData` field access of the Robotran
        /// function the IR came from, a drop-in replacement of its file.
        Robotran = "robotran",
        /// `pinocchio` ([`pinocchio`]): the URDF generator's functions with the signatures of
        /// Pinocchio's `rnea`, `crba`, `nonLinearEffects` and `aba` over its vectors.
        Pinocchio = "pinocchio",
    }
}

word_enum! {
    /// Where a batch's states are in the arrays (`layout=`).
    pub enum BatchLayout {
        /// `lanes`: element `i` of state `l` at `p[i*W + l]`.
        Lanes = "lanes",
        /// `rows`: element `i` of state `l` at `p[l*n + i]`, `n` the array's elements per state.
        Rows = "rows",
    }
}

impl BatchLayout {
    /// True for `lanes`, the layout SPEC §8 describes (the report leaves it out).
    pub fn is_lanes(&self) -> bool {
        *self == BatchLayout::Lanes
    }
}

word_enum! {
    /// The arithmetic of the generated code (`precision=`).
    pub enum Precision {
        /// `f64`: `double`.
        F64 = "f64",
        /// `f32`: `float`.
        F32 = "f32",
    }
}

word_enum! {
    /// How the generated C gets the sin/cos of the joint coordinates (`trig=`).
    pub enum Trig {
        /// `libm`: `sin`/`cos` (`sinf`/`cosf`), lane by lane in a batch; bit-exact with `-eval`.
        Libm = "libm",
        /// `input`: the values are inputs after the IR's own.
        Input = "input",
        /// `inline`: robovec's own branch-free code ([`trig`]), vectorised over the lanes.
        Inline = "inline",
    }
}

/// The C back end's options.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CodegenC {
    /// `abi=`.
    pub abi: Abi,
    /// `precision=`.
    pub precision: Precision,
    /// States per call, lanes (`batch=`: 1, 2, 4, 8 or 16).
    pub batch: u32,
    /// Where a batch's states are in the arrays (`layout=`).
    pub layout: BatchLayout,
    /// `trig=`.
    pub trig: Trig,
    /// The symbol (or prefix, with several functions); `None`: from the function's name.
    pub name: Option<String>,
    /// Statements (ops) per part of a split function (`chunk=`; 0: never split).
    pub chunk: u32,
    /// Translation units (`units=`; 1: one file).
    pub units: u32,
    /// Lanes of the packs of one state's isomorphic ops (`slp=`: 0, none, or 4; `backends/src/c/slp.rs`).
    pub slp: u32,
}

impl Default for CodegenC {
    fn default() -> CodegenC {
        CodegenC {
            abi: Abi::Plain,
            precision: Precision::F64,
            batch: 1,
            layout: BatchLayout::Lanes,
            trig: Trig::Libm,
            name: None,
            chunk: DEFAULT_CHUNK,
            units: 1,
            slp: 0,
        }
    }
}

/// One function as C ([`plain::function`], [`robotran::function`]).
pub(crate) struct Emitted {
    /// The definition under the function's symbol with its opening comment: the whole body, or
    /// (split) the entry point that calls the parts.
    pub entry: String,
    /// The parts, in call order; empty when the function is not split.
    pub parts: Vec<split::Part>,
    /// Its declarations for the header.
    pub proto: String,
    /// Its interface (SPEC §8).
    pub iface: Interface,
}

fn bad(message: String) -> PassError {
    PassError::BadParameter { pass: "codegen".into(), message }
}

impl CodegenC {
    /// The options from checked parameters.
    ///
    /// # Errors
    /// [`PassError::BadParameter`] for options that cannot go together (`abi=robotran` with
    /// `batch>1`, `precision=f32`, `trig=input` or `trig=inline`: Robotran's signature is one state of
    /// `double`s that computes its own trig; `abi=pinocchio` with `precision=f32` or `trig=input`:
    /// Pinocchio's vectors are doubles and its signatures take no sin/cos; `units>1` with
    /// `chunk=0`) and for a `name` that is not one C identifier.
    pub fn from_params(p: &Params) -> Result<CodegenC, PassError> {
        let o = CodegenC {
            abi: p.word("abi")?,
            precision: p.word("precision")?,
            batch: p.u32("batch")?,
            layout: p.word("layout")?,
            trig: p.word("trig")?,
            name: p.names("name")?.map(|n| n.join(",")),
            chunk: p.u32("chunk")?,
            units: p.u32("units")?,
            slp: p.u32("slp")?,
        };
        if o.slp > 0 && (o.batch > 1 || o.f32()) {
            let clash = if o.batch > 1 { format!("batch={}", o.batch) } else { "precision=f32".into() };
            return Err(bad(format!(
                "`slp={}` packs the ops of one state of doubles into vectors; it cannot go with `{clash}`",
                o.slp
            )));
        }
        if o.units > 1 && o.chunk == 0 {
            return Err(bad(format!(
                "`units={}` spreads the parts of split functions over files; `chunk=0` makes no parts",
                o.units
            )));
        }
        if let Some(n) = &o.name {
            if !is_c_identifier(n) {
                return Err(bad(format!("parameter `name` must be one C identifier, found `{n}`")));
            }
            if let Some(why) = reserved_symbol_reason(n) {
                return Err(bad(format!("parameter `name`: `{n}` cannot name generated C: it is {why}")));
            }
        }
        if o.abi == Abi::Robotran {
            let clash = if o.batch > 1 {
                Some(format!("batch={}", o.batch))
            } else if o.f32() {
                Some("precision=f32".into())
            } else if o.trig == Trig::Input {
                Some("trig=input".into())
            } else {
                None
            };
            if let Some(c) = clash {
                return Err(bad(format!(
                    "`abi=robotran` cannot go with `{c}`: Robotran's signature takes one state of doubles \
                     and no sin/cos (use `abi=plain`)"
                )));
            }
        }
        if o.abi == Abi::Pinocchio {
            let clash = if o.f32() {
                Some(("precision=f32", "Pinocchio's vectors are doubles"))
            } else if o.trig == Trig::Input {
                Some(("trig=input", "Pinocchio's signatures take no sin/cos"))
            } else {
                None
            };
            if let Some((c, why)) = clash {
                return Err(bad(format!("`abi=pinocchio` cannot go with `{c}`: {why} (use `abi=plain`)")));
            }
        }
        Ok(o)
    }

    /// True for `precision=f32`.
    pub fn f32(&self) -> bool {
        self.precision == Precision::F32
    }

    /// `double` or `float`.
    pub fn real(&self) -> &'static str {
        if self.f32() {
            "float"
        } else {
            "double"
        }
    }

    /// The symbol of each function of `m`, in order: Robotran's names for `abi=robotran`
    /// (prefixed `NAME_` with `name=` and several functions), else `name=` or the function's
    /// name sanitised; injective, and for `abi=plain` never [`is_reserved_symbol`] (a derived
    /// symbol that would be is renamed, [`free_name`]), nor the size macro of another.
    ///
    /// # Errors
    /// [`PassError::Failed`] for a function with no Robotran signature (`abi=robotran`).
    fn symbols(&self, m: &Module) -> Result<Vec<String>, PassError> {
        let several = m.functions.len() > 1;
        let mut taken: HashSet<String> = HashSet::new();
        let mut out = Vec::with_capacity(m.functions.len());
        for f in &m.functions {
            let wanted = match (&self.name, self.abi) {
                (Some(n), Abi::Robotran) if several => format!("{n}_{}", robotran::symbol(f)?),
                (Some(n), _) if several => format!("{n}_{}", sanitise(&f.name)),
                (Some(n), _) => n.clone(),
                (None, Abi::Robotran) => robotran::symbol(f)?,
                (None, _) => sanitise(&f.name),
            };
            let symbol = match self.abi {
                // Robotran's names are the drop-in's contract: kept as they are (the sensors share
                // `mbs_sensor`, which dispatches on the sensor's number).
                Abi::Robotran => wanted,
                Abi::Plain | Abi::Pinocchio => free_name(&wanted, &taken, is_reserved_symbol),
            };
            taken.extend([format!("{symbol}_INPUTS"), format!("{symbol}_OUTPUTS"), symbol.clone()]);
            out.push(symbol);
        }
        Ok(out)
    }

    /// The C file, its header and the interfaces, for every function of `m` (atomised), as
    /// [`CodegenC::emit_as`] without a file name.
    ///
    /// # Errors
    /// As [`CodegenC::emit_as`].
    pub fn emit(&self, m: &Module) -> Result<CodegenArtifact, PassError> {
        self.emit_as(m, None)
    }

    /// The C file, its header, the further translation units (`units=K`: K − 1 of them) and
    /// the interfaces, for every function of `m` (atomised). `main`: where `-o` writes the C
    /// file; it names the units (`model.c` → `model_1.c`, [`robovec_passes::unit_path`]) in the header
    /// and in each interface's `sources` and `header` (the report's `codegen`); `None` (the
    /// code goes to stdout, or a caller of the library) leaves them out.
    ///
    /// # Errors
    /// [`PassError::Failed`] when a function cannot be written in this ABI (an unknown
    /// Robotran function kind for `abi=robotran`; for `abi=pinocchio` a function other than the
    /// URDF generator's or an input or output with no place in Pinocchio's signatures,
    /// [`pinocchio`]; a callback used with two arities).
    pub fn emit_as(&self, m: &Module, main: Option<&Path>) -> Result<CodegenArtifact, PassError> {
        self.emit_within(m, main, &robovec_passes::Ticker::default())
    }
}

impl Pass for CodegenC {
    fn name(&self) -> &'static str {
        "codegen"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let main = cx.code_file.clone();
        let ticker = cx.ticker();
        super::run_emitter(m, cx, |m| self.emit_within(m, main.as_deref(), &ticker))
    }

    fn as_back_end(&self) -> Option<&dyn robovec_passes::BackEnd> {
        Some(self)
    }
}

impl robovec_passes::BackEnd for CodegenC {
    fn companions(&self) -> &'static [&'static str] {
        &["h"]
    }

    fn units(&self) -> usize {
        self.units as usize
    }
}

/// True when a `call` is an intrinsic ([`robovec_ir::Intrinsic`]: `sqrt`, and the fused
/// multiply-adds written as C99 `fma`), as opposed to a user callback.
pub fn is_intrinsic(c: &Callee, args: usize) -> bool {
    robovec_ir::Intrinsic::of(c, args).is_some()
}

/// True when `f` has a fused multiply-add (`@fma`, `@fms`, `@fnma`: the `contract` pass).
pub fn has_fused(f: &Function) -> bool {
    f.body.iter().any(|&v| match &f.value(v).def {
        Def::Call(c, args) => robovec_ir::Intrinsic::of(c, args.len()).is_some_and(|i| i.is_fused()),
        _ => false,
    })
}

/// True when `f` has a trig value (`sin`/`cos` of a joint coordinate).
pub fn has_trig(f: &Function) -> bool {
    f.body.iter().any(|&v| matches!(f.value(v).def, Def::Trig(..)))
}

/// The interface (SPEC §8) of `f` written as `symbol` under options `o`.
pub(crate) fn interface(o: &CodegenC, f: &Function, symbol: &str) -> Interface {
    Interface {
        function: f.name.clone(),
        symbol: symbol.to_string(),
        abi: o.abi,
        precision: o.precision,
        batch: o.batch,
        layout: if o.batch > 1 { o.layout } else { BatchLayout::Lanes },
        trig: o.trig,
        inputs: super::input_values(f, o.trig == Trig::Input).iter().map(|&v| f.name_of(v).to_string()).collect(),
        outputs: f.outputs.iter().map(|x| x.name.clone()).collect(),
        parts: 1,
        sources: Vec::new(),
        header: None,
    }
}
