//! `codegen<c;abi=plain|robotran|pinocchio;precision=f64|f32;batch=1|2|4|8|16;trig=libm|input|inline;name=…>`:
//! the functions as C (issue 11, SPEC §8).
//!
//! Every IR operation becomes one C statement, in the IR's order, so that the compiled code
//! computes bit for bit what robovec's interpreter computes (`-eval`, `-eval-precision=f32`)
//! when compiled without contraction (`-ffp-contract=off`; the file also says
//! `#pragma STDC FP_CONTRACT OFF`). `batch=W` computes W independent states per call with
//! GCC/Clang vector extensions (one source for SSE, AVX2, AVX-512 and NEON), lane-contiguous:
//! element `i` of lane `l` is `in[i*W + l]`. With `trig=input` the `sin`/`cos` of the joint
//! coordinates are inputs (after the IR's inputs); with `trig=libm` they are computed (per lane).
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
mod native;
pub use callbacks::split_callee;
pub mod pinocchio;
pub mod plain;
pub mod robotran;
mod split;
pub mod trig;

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

use robovec_ir::{Callee, Def, Function, Module};

use super::names::{free_name, is_c_identifier, is_reserved_symbol, reserved_symbol_reason, sanitise};
use super::{CodegenArtifact, Interface};
use crate::params::{word_enum, ParamKind};
use crate::{GeneratedCode, Member, ParamInfo, Params, Pass, PassContext, PassError};

/// The C back end of `codegen`: `codegen<c;…>`, with its parameters.
pub const BACK_END: Member = Member {
    name: "c",
    doc: "C (SPEC §8); `-o FILE` gets the code and FILE.h its prototypes",
    params: &[ABI, PRECISION, BATCH, TRIG, NAME, CHUNK, UNITS],
    build: |p| Ok(Box::new(CodegenC::from_params(p)?)),
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
    doc: "C: arithmetic in `double` (f64) or `float` (f32)",
};
/// `batch=1|2|4|8|16`.
pub const BATCH: ParamInfo = ParamInfo {
    name: "batch",
    kind: ParamKind::U32Set { default: 1, allowed: &[1, 2, 4, 8, 16] },
    doc: "C: states per call, lanes (`in[i*W + lane]`; every array likewise with `abi=pinocchio`); not with `abi=robotran`",
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
    doc: "C: a function of more statements (ops) is written as a chain of parts of at most about this many, \
          which its entry point calls with its live values in an array on its stack (same symbol and signature; \
          GCC's time and memory per function grow faster than its size); `0`: one function",
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

/// Written at the top of every generated file: GCC 12's SLP vectoriser fuses a vector of
/// products and an alternating subtract/add into `vfmaddsub`/`vfmsubadd` even under
/// `-ffp-contract=off` (its `addsub` pattern, `tree-vect-slp-patterns.cc`, did not check the
/// contraction mode; later GCC does), so on a target with FMA (`-march=native` here) the
/// code is no longer bit-exact. Four statements suffice (`x1 = in[0]*in[2]; x2 = in[1]*in[3];
/// out[0] = x1 - in[4]; out[1] = x2 + in[5];`); split code, whose live values sit side by side
/// in `live[]`, met it on coman's `dirdyna` (23 of 682 outputs off by an ulp at `-O2
/// -march=native`). For GCC 12 with FMA only, the file turns SLP vectorisation off.
pub const SLP_GUARD: &str =
    "/* GCC 12 fuses a*b-c, d*e+f into vfmaddsub despite -ffp-contract=off (SLP addsub pattern): */\n\
    #if defined(__GNUC__) && !defined(__clang__) && __GNUC__ == 12 && defined(__FMA__)\n\
    #pragma GCC optimize (\"no-tree-slp-vectorize\")\n#endif\n";

/// C's own switch for contraction, for the compilers that honour it (Clang, and the C99 ones
/// that follow the standard): GCC ignores `#pragma STDC FP_CONTRACT` and says so under `-Wall`
/// (`-Wunknown-pragmas`), which `-Werror` builds of the user's project would turn into an error,
/// so GCC does not see it (it needs `-ffp-contract=off`, as the file's opening comment says).
pub const STDC_GUARD: &str = "#if !defined(__GNUC__) || defined(__clang__)\n#pragma STDC FP_CONTRACT OFF\n#endif\n";

/// `ROBOVEC_UNUSED`, with which [`body::vector_helpers`] and [`trig::helpers`] mark the file's
/// static helper functions (vector lanes, inline sin/cos) as possibly unused (a function uses
/// some of them only, no sqrt or no fma), so that `-Wall -Werror` builds pass with Clang
/// (`-Wunused-function` covers unused static inline functions there, not in GCC).
pub const UNUSED_HELPERS: &str =
    "#ifndef ROBOVEC_UNUSED\n#if defined(__GNUC__)\n#define ROBOVEC_UNUSED __attribute__((unused))\n\
     #else\n#define ROBOVEC_UNUSED\n#endif\n#endif\n";

/// The C back end's options.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CodegenC {
    /// `abi=`.
    pub abi: Abi,
    /// `precision=`.
    pub precision: Precision,
    /// States per call, lanes (`batch=`: 1, 2, 4, 8 or 16).
    pub batch: u32,
    /// `trig=`.
    pub trig: Trig,
    /// The symbol (or prefix, with several functions); `None`: from the function's name.
    pub name: Option<String>,
    /// Statements (ops) per part of a split function (`chunk=`; 0: never split).
    pub chunk: u32,
    /// Translation units (`units=`; 1: one file).
    pub units: u32,
}

impl Default for CodegenC {
    fn default() -> CodegenC {
        CodegenC {
            abi: Abi::Plain,
            precision: Precision::F64,
            batch: 1,
            trig: Trig::Libm,
            name: None,
            chunk: DEFAULT_CHUNK,
            units: 1,
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
            trig: p.word("trig")?,
            name: p.names("name")?.map(|n| n.join(",")),
            chunk: p.u32("chunk")?,
            units: p.u32("units")?,
        };
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
    /// file; it names the units (`model.c` → `model_1.c`, [`crate::unit_path`]) in the header
    /// and in each interface's `sources` and `header` (the report's `codegen`); `None` (the
    /// code goes to stdout, or a caller of the library) leaves them out.
    ///
    /// # Errors
    /// [`PassError::Failed`] when a function cannot be written in this ABI (an unknown
    /// Robotran function kind for `abi=robotran`; for `abi=pinocchio` a function other than the
    /// URDF generator's or an input or output with no place in Pinocchio's signatures,
    /// [`pinocchio`]; a callback used with two arities).
    pub fn emit_as(&self, m: &Module, main: Option<&Path>) -> Result<CodegenArtifact, PassError> {
        self.emit_within(m, main, &crate::Ticker::default())
    }

    /// [`CodegenC::emit_as`] that stops when `ticker` says so (`-time-limit`; one tick per
    /// statement written).
    ///
    /// # Errors
    /// As [`CodegenC::emit_as`], and [`PassError::TimeLimit`] when stopped (the code is the
    /// run's output: no part of it is returned).
    pub fn emit_within(
        &self,
        m: &Module,
        main: Option<&Path>,
        ticker: &crate::Ticker,
    ) -> Result<CodegenArtifact, PassError> {
        let fused = m.functions.iter().any(has_fused);
        let callbacks = callbacks::callbacks(m)?;
        let decls = if self.abi == Abi::Robotran {
            native::prototypes(m, &callbacks)?
        } else {
            callbacks::callback_decls(&callbacks, self.real())
        };
        let (symbols, emitted, preface) = if self.abi == Abi::Pinocchio {
            pinocchio::emit(self, m, ticker)?
        } else {
            let symbols = self.symbols(m)?;
            // The file's global names, which no part may take.
            let taken: HashSet<String> =
                symbols.iter().cloned().chain(callbacks.iter().map(|k| k.base.clone())).collect();
            let mut emitted = Vec::with_capacity(m.functions.len());
            for (f, symbol) in m.functions.iter().zip(&symbols) {
                emitted.push(if self.abi == Abi::Robotran {
                    robotran::function(self, f, symbol, &taken, ticker)?
                } else {
                    plain::function(self, f, symbol, &taken, ticker)
                });
                if ticker.stopped() {
                    return Err(ticker.error("codegen", &format!("writing @{}", f.name)));
                }
            }
            (symbols, emitted, String::new())
        };
        let units = self.units as usize;
        let unit_of = unit_assignment(&emitted, units);
        let file_names: Vec<String> = match main {
            Some(p) => (0..units).map(|k| crate::unit_path(p, k).display().to_string()).collect(),
            None => Vec::new(),
        };
        let header_name = main.map(|p| p.with_extension("h").display().to_string());
        let base_name = |k: usize| -> String {
            file_names.get(k).map_or(format!("unit {}", k + 1), |n| {
                Path::new(n).file_name().map_or(n.clone(), |x| x.to_string_lossy().into_owned())
            })
        };
        let split = emitted.iter().any(|e| !e.parts.is_empty());
        let mut files: Vec<String> = (0..units)
            .map(|k| {
                let mut c = self.preamble(fused, split);
                if units > 1 {
                    let list: Vec<String> = (0..units).map(base_name).collect();
                    let _ = write!(
                        c,
                        "/* Translation unit {} of {units} ({}): compile each, link all. */\n\n",
                        k + 1,
                        list.join(", ")
                    );
                }
                if self.abi == Abi::Robotran {
                    c += "#include \"mbs_data.h\"\n\n";
                }
                c += &decls;
                c
            })
            .collect();
        // The parts in other units are declared in the main file (it calls them) and in
        // their own unit (before their definitions).
        let mut externs = String::new();
        for (e, units_of) in emitted.iter().zip(&unit_of) {
            for (p, &u) in e.parts.iter().zip(units_of) {
                if u > 0 {
                    let _ = writeln!(externs, "{};", p.signature);
                    let _ = writeln!(files[u], "{};", p.signature);
                }
            }
        }
        if !externs.is_empty() {
            files[0] += "/* Parts defined in the other translation units. */\n";
            files[0] += &externs;
            files[0].push('\n');
            for f in &mut files[1..] {
                f.push('\n');
            }
        }
        let mut h = preface;
        let mut interfaces = Vec::new();
        for (e, units_of) in emitted.into_iter().zip(&unit_of) {
            for (p, &u) in e.parts.iter().zip(units_of) {
                let storage = if u == 0 { "static " } else { "" };
                // The parameters a part may not read are cast to void.
                let voids = split::void_params(&p.signature);
                let _ = write!(files[u], "{storage}{}\n{{\n{voids}{}}}\n\n", p.signature, p.body);
            }
            files[0] += &e.entry;
            h += &e.proto;
            let mut iface = e.iface;
            iface.parts = e.parts.len().max(1);
            iface.sources.clone_from(&file_names);
            iface.header.clone_from(&header_name);
            interfaces.push(iface);
        }
        if self.abi == Abi::Robotran {
            let symbol_of = |f: &Function| {
                let i = m.functions.iter().position(|g| std::ptr::eq(g, f)).expect("a function of m");
                symbols[i].clone()
            };
            let (code, proto) = robotran::sensor_dispatch(m, symbol_of);
            files[0] += &code;
            h += &proto;
        }
        // The first symbol as it is (case kept: `AB` and `ab` are two files' symbols, one guard each).
        let guard = symbols.first().map_or("ROBOVEC_GENERATED_H".to_string(), |s| format!("ROBOVEC_{s}_H"));
        let units_note = if units > 1 {
            let list: Vec<String> = (0..units).map(base_name).collect();
            format!(
                "/* The code is in {units} translation units: {}. Compile each (in parallel if you wish) and link \
                 them all. */\n\n",
                list.join(", ")
            )
        } else {
            String::new()
        };
        let header = self.header(&guard, &units_note, &h, &decls);
        let main_text = files.remove(0);
        Ok(CodegenArtifact {
            code: GeneratedCode { language: "C", main: main_text, companions: vec![("h", header)], units: files },
            interfaces,
        })
    }

    fn options_text(&self) -> String {
        format!(
            "codegen<c;abi={};precision={};batch={};trig={}>",
            self.abi.as_str(),
            self.precision.as_str(),
            self.batch,
            self.trig.as_str()
        )
    }

    /// The file's opening comment, [`SLP_GUARD`] and includes; `fused`: some function has fused
    /// multiply-adds (`contract`); `split`: some function is split into parts
    /// (`ROBOVEC_NOINLINE`).
    fn preamble(&self, fused: bool, split: bool) -> String {
        let mut s = format!(
            "/* Generated by robovec {}.\n * Every operation of robovec's IR is one statement, in the IR's order: compiled without\n \
             * floating-point contraction it computes bit for bit what robovec's interpreter computes{}.\n \
             {}* Compile with -ffp-contract=off (GCC contracts a*b+c into an FMA under -march=native),\n \
             * e.g. cc -O2 -ffp-contract=off -c model.c; link with -lm. */\n\
             {STDC_GUARD}{SLP_GUARD}#include <math.h>\n#include <string.h>\n\n",
            self.options_text(),
            if self.trig == Trig::Inline {
                ",\n * except sin/cos: with trig=inline they are robovec's own (below), within 1 ulp but not libm's bits;\n \
                 * never compile with -ffast-math (it would fold their rounding trick)"
            } else {
                ""
            },
            if fused {
                "* Fused multiply-adds (the contract pass) are C99 fma, one rounding as in the interpreter: one\n \
                 * instruction where the target has FMA (-mfma, -march=haswell or later), a slow libm call otherwise.\n "
            } else {
                ""
            }
        );
        if split {
            let _ = write!(
                s,
                "/* Functions of more than {} statements are split into parts (chunk={}): the entry point keeps\n \
                 * its symbol and signature and calls its parts in order, passing the values one part computes\n \
                 * and a later one reads in an array on its own stack (nothing static: re-entrant). The parts\n \
                 * are never inlined into it, which would make one large function again. */\n\
                 #if defined(__GNUC__)\n#define ROBOVEC_NOINLINE __attribute__((noinline))\n#else\n#define ROBOVEC_NOINLINE\n#endif\n\n",
                self.chunk, self.chunk
            );
        }
        if self.batch > 1 || self.trig == Trig::Inline {
            // The helpers below are `ROBOVEC_UNUSED`: a function uses some of them only.
            s += UNUSED_HELPERS;
        }
        if self.batch > 1 {
            s += &body::vector_helpers(self.real(), self.batch, self.f32());
        }
        if self.trig == Trig::Inline {
            s += &trig::helpers(self.f32(), self.batch > 1);
        }
        s
    }

    /// The header: `guard` its include guard (from the first symbol, so that the headers of
    /// two models can be included together), `units_note` the list of translation units.
    fn header(&self, guard: &str, units_note: &str, prototypes: &str, callback_decls: &str) -> String {
        let mut s = format!(
            "/* Generated by robovec {}: prototypes of the C file beside this one. */\n\
             #ifndef {guard}\n#define {guard}\n\n{units_note}",
            self.options_text()
        );
        if self.abi == Abi::Robotran {
            s += "#include \"mbs_data.h\"\n\n";
        }
        // Pinocchio's callers are C++.
        let cpp = self.abi == Abi::Pinocchio;
        if cpp {
            s += "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n";
        }
        s += prototypes;
        s += callback_decls;
        if cpp {
            s += "#ifdef __cplusplus\n}\n#endif\n\n";
        }
        s += "#endif\n";
        s
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

    fn requires(&self) -> Option<robovec_ir::Phase> {
        Some(robovec_ir::Phase::Atomised)
    }

    fn preserves_timing(&self) -> bool {
        true
    }

    fn code_companions(&self) -> Option<&'static [&'static str]> {
        Some(&["h"])
    }

    fn code_units(&self) -> usize {
        self.units as usize
    }
}

/// Unit of each part of each function (`units` translation units, 0 the main file):
/// contiguous runs of about equal statements, in call order (part starting after `s` of the
/// `total` statements of all parts goes to unit `⌊s·units/total⌋`).
fn unit_assignment(emitted: &[Emitted], units: usize) -> Vec<Vec<usize>> {
    let total: usize = emitted.iter().flat_map(|e| &e.parts).map(|p| p.ops).sum();
    let mut before = 0usize;
    emitted
        .iter()
        .map(|e| {
            e.parts
                .iter()
                .map(|p| {
                    let u = (before * units).checked_div(total).unwrap_or(0);
                    before += p.ops;
                    u.min(units - 1)
                })
                .collect()
        })
        .collect()
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
        trig: o.trig,
        inputs: super::input_values(f, o.trig == Trig::Input).iter().map(|&v| f.name_of(v).to_string()).collect(),
        outputs: f.outputs.iter().map(|x| x.name.clone()).collect(),
        parts: 1,
        sources: Vec::new(),
        header: None,
    }
}
