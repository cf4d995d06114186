//! The C file's layout (SPEC §8): the opening comment, the guards ([`SLP_GUARD`],
//! [`STDC_GUARD`]), the helpers ([`UNUSED_HELPERS`], vector lanes, `trig=inline`), the callback
//! declarations, the split functions' parts spread over `units=K` translation units, the entry
//! points, and the header with its include guard. The functions themselves come from the ABIs
//! ([`super::plain`], [`super::robotran`], [`super::pinocchio`]).

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

use robovec_ir::{Function, Module};

use super::{body, callbacks, has_fused, native, pinocchio, plain, robotran, split, trig};
use super::{Abi, CodegenC, Emitted, Trig};
use crate::CodegenArtifact;
use robovec_passes::time_limit::TickerError;
use robovec_passes::{GeneratedCode, PassError};

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

/// `ROBOVEC_UNUSED`, with which the vector helpers (`body.rs`) and the `trig=inline` helpers ([`trig`]) mark the file's
/// static helper functions (vector lanes, inline sin/cos) as possibly unused (a function uses
/// some of them only, no sqrt or no fma), so that `-Wall -Werror` builds pass with Clang
/// (`-Wunused-function` covers unused static inline functions there, not in GCC).
pub const UNUSED_HELPERS: &str =
    "#ifndef ROBOVEC_UNUSED\n#if defined(__GNUC__)\n#define ROBOVEC_UNUSED __attribute__((unused))\n\
     #else\n#define ROBOVEC_UNUSED\n#endif\n#endif\n";

impl CodegenC {
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
        ticker: &robovec_passes::Ticker,
    ) -> Result<CodegenArtifact, PassError> {
        let formats = self.check_formats(m)?;
        if formats && self.f32() {
            // Formats with float arrays: the values computed as their formats say (the body of
            // precision=f64), the plain ABI's arrays `float` (`plain::function`'s `io_f32`).
            let inner = CodegenC { precision: super::Precision::F64, ..self.clone() };
            return inner.emit_files(m, main, ticker, true);
        }
        self.emit_files(m, main, ticker, false)
    }

    /// [`CodegenC::emit_within`] once formats are checked: `io_f32`, the plain ABI's arrays are
    /// `float` (formats with `precision=f32`), the interface says `f32`.
    fn emit_files(
        &self,
        m: &Module,
        main: Option<&Path>,
        ticker: &robovec_passes::Ticker,
        io_f32: bool,
    ) -> Result<CodegenArtifact, PassError> {
        let fused = m.functions.iter().any(has_fused);
        let formats = m.functions.iter().any(|f| f.has_formats());
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
                    plain::function(self, f, symbol, &taken, ticker, io_f32)
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
            Some(p) => (0..units).map(|k| robovec_passes::unit_path(p, k).display().to_string()).collect(),
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
                let mut c = self.preamble(fused, split, formats);
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
        // The first symbol as it is (case kept: `AB` and `ab` are two files' symbols, one guard each),
        // then a hash of what the files hold: two models written under the same names (`model_rnea`)
        // get two guards (issue 47).
        let named = symbols.first().map_or("ROBOVEC_GENERATED_H".to_string(), |s| format!("ROBOVEC_{s}_H"));
        let guard = format!(
            "{named}_{:016X}",
            content_hash(files.iter().map(String::as_str).chain([h.as_str(), decls.as_str()]))
        );
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
            "codegen<c;abi={};precision={};batch={};trig={}{}>",
            self.abi.as_str(),
            self.precision.as_str(),
            self.batch,
            self.trig.as_str(),
            if self.slp > 0 { format!(";slp={}", self.slp) } else { String::new() }
        )
    }

    /// The file's opening comment, [`SLP_GUARD`] and includes; `fused`: some function has fused
    /// multiply-adds (`contract`); `split`: some function is split into parts
    /// (`ROBOVEC_NOINLINE`).
    fn preamble(&self, fused: bool, split: bool, formats: bool) -> String {
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
                "/* Functions of {} statements or more are split into parts of at most {} (chunk={}): the entry point keeps\n \
                 * its symbol and signature and calls its parts in order, passing the values one part computes\n \
                 * and a later one reads in an array on its own stack (nothing static: re-entrant). The parts\n \
                 * are never inlined into it, which would make one large function again. */\n\
                 #if defined(__GNUC__)\n#define ROBOVEC_NOINLINE __attribute__((noinline))\n#else\n#define ROBOVEC_NOINLINE\n#endif\n\n",
                2 * u64::from(self.chunk),
                self.chunk,
                self.chunk
            );
        }
        if self.batch > 1 || self.trig == Trig::Inline || self.slp > 0 {
            // The helpers below are `ROBOVEC_UNUSED`: a function uses some of them only.
            s += UNUSED_HELPERS;
        }
        if formats {
            // Before the vector helpers: robovec_fix_from_v calls robovec_fix_from.
            s += FORMAT_HELPERS;
        }
        let mut helpers = String::new();
        if self.batch > 1 && formats {
            helpers += &body::format_vector_helpers(self.batch);
        } else if self.batch > 1 {
            helpers += &body::vector_helpers(self.real(), self.batch, self.f32());
        }
        if self.slp > 0 {
            helpers += &body::slp_helpers();
        }
        if self.trig == Trig::Inline && formats && self.batch > 1 {
            helpers += &trig::helpers_halves();
            helpers += &trig::helpers_vec32();
        } else if self.trig == Trig::Inline {
            helpers += &trig::helpers(self.f32(), self.batch > 1);
        }
        s += &shared_helpers(&helpers);
        s
    }

    /// True when a function of `m` has values in numeric formats (issue 48,
    /// [`robovec_ir::format`]), which the C then computes each in its format (`Body::read`,
    /// `Body::stored`): binary32 values as `float` (`robovec_vec32` vectors in a batch, twice the
    /// lanes of `double`), the others as `double` (fixed point through [`FORMAT_HELPERS`]), bit
    /// for bit what `-eval` computes (but for `trig=inline`'s sin/cos, never bit-exact).
    ///
    /// With `precision=f32` (`abi=plain` only) the arrays are `float` — data already in binary32,
    /// an RL simulator's or a GPU pipeline's — and every output must be a binary32 value (or a
    /// constant exact in binary32): an output in another format would be rounded on the way out,
    /// a rounding the certified bound does not count. An input of any format reads its `float`
    /// exactly (widened, or stored in its fixed-point format).
    ///
    /// # Errors
    /// [`PassError::Failed`] when formats meet options that cannot honour them: `abi=robotran`
    /// (its `MbsData` is `double`), or `precision=f32` with an output not in binary32 (named).
    fn check_formats(&self, m: &Module) -> Result<bool, PassError> {
        let Some(f) = m.functions.iter().find(|f| f.has_formats()) else { return Ok(false) };
        // (`abi=pinocchio` with `precision=f32` is bad usage already: its vectors are double.)
        let clash = (self.abi == Abi::Robotran).then(|| format!("abi={}", self.abi.as_str()));
        if clash.is_none() && self.f32() {
            for f in &m.functions {
                for o in &f.outputs {
                    let in_float = match o.value {
                        robovec_ir::Operand::Value(v) => f.format(v) == robovec_ir::format::Format::Binary32,
                        robovec_ir::Operand::Const(c) => c as f32 as f64 == c,
                    };
                    if !in_float {
                        return Err(PassError::Failed {
                            pass: "codegen".into(),
                            message: format!(
                                "@{}: precision=f32 writes float arrays, but output `{}` is not a binary32 value: its \
                                 value would be rounded on the way out, which no certified bound counts (give it the \
                                 format f32, or write double arrays with precision=f64)",
                                f.name, o.name
                            ),
                        });
                    }
                }
            }
        }
        match clash {
            Some(c) => Err(PassError::Failed {
                pass: "codegen".into(),
                message: format!(
                    "@{} has values in numeric formats, which codegen<c> writes with abi=plain (double or float \
                     arrays) or abi=pinocchio (double), not with {c}",
                    f.name
                ),
            }),
            None => Ok(true),
        }
    }

    /// The header: `guard` its include guard (from the first symbol and a hash of the files'
    /// text, so that the headers of two models can be included together), `units_note` the list
    /// of translation units.
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

/// The fixed-point helpers (a fixed-point value is held as its integer `k`, the value `k · 2^-f`):
/// `robovec_fix_from(x, 2^f)`, a `double` stored in `fix<w,f>` (`robovec_ir::format::Format::store`:
/// round to nearest, ties toward +∞, exact for the values the range proof admits), and
/// `robovec_fix_shr(x, n)` = `floor(x / 2^n)` (`robovec_fix_shr32` on `int32_t`) without the
/// implementation-defined right shift of a negative integer (C99 6.5.7; GCC and Clang compile
/// it to one arithmetic shift), for integer ops' rounding. Under their own guard, so that files
/// with and without formats can be `#include`d into one translation unit. binary32 values need
/// no helper: they are `float`.
pub const FORMAT_HELPERS: &str = "#ifndef ROBOVEC_FIX_HELPERS\n#define ROBOVEC_FIX_HELPERS\n#include <stdint.h>\n\
     /* Fixed-point values are integers k, the value k * 2^-f of their format fix<w,f>.\n \
     * robovec_fix_from: a double x stored in fix<w,f> (s = 2^f), to nearest, ties toward +inf (what -eval computes);\n \
     * robovec_fix_shr: floor(x / 2^n), 0 <= n < 63, without the implementation-defined shift of a negative integer. */\n\
     static inline int64_t robovec_fix_from(double x, double s) { double y = x * s, k = floor(y); return (int64_t)k + (y - k >= 0.5); }\n\
     static inline int64_t robovec_fix_shr(int64_t x, int n) { return x >= 0 ? x >> n : ~(~x >> n); }\n\
     static inline int32_t robovec_fix_shr32(int32_t x, int n) { return x >= 0 ? x >> n : ~(~x >> n); }\n\
     #endif\n\n";

/// `helpers` (the file's static helpers, its vector type and their macros: the same text for
/// the same `batch=`, `precision=` and `trig=`) under a guard, so that a translation unit that
/// `#include`s several generated files holds them once (issue 47): `ROBOVEC_HELPERS` is the
/// hash of their text, and a second file whose helpers differ stops the compilation with an
/// `#error` that says so (a `robovec_vec` of another width or type cannot be shared). Empty
/// without helpers.
fn shared_helpers(helpers: &str) -> String {
    if helpers.is_empty() {
        return String::new();
    }
    // 32 bits: a preprocessor number in every dialect (`#if` computes in `intmax_t`).
    let h = content_hash([helpers]) & 0xFFFF_FFFF;
    format!(
        "/* The helpers below are shared by the files robovec writes with the same batch=, precision=, trig= and slp=:\n \
         * a translation unit that #includes several holds them once. */\n\
         #if !defined(ROBOVEC_HELPERS)\n#define ROBOVEC_HELPERS 0x{h:08X}\n{helpers}\
         #elif ROBOVEC_HELPERS != 0x{h:08X}\n\
         #error \"robovec: generated C files #included into one translation unit must share batch=, precision=, \
         trig= and slp= (their helpers differ): compile them separately\"\n#endif\n\n"
    )
}

/// FNV-1a (64 bits) of the concatenation of `parts`: the same on every machine and run, for the
/// names of the header's guard and of the helpers' guard.
fn content_hash<'a>(parts: impl IntoIterator<Item = &'a str>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in parts.into_iter().flat_map(str::bytes) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
