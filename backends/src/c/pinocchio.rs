//! `abi=pinocchio`: the URDF generator's functions with the signatures of Pinocchio's
//! algorithms, so that a program written against Pinocchio's vectors calls robovec's C
//! without reshuffling them (issue 30):
//!
//! | IR function | C function | Pinocchio |
//! |---|---|---|
//! | `invdyna` | `void NAME_rnea(const double *q, const double *v, const double *a, double *tau)` | `rnea(model, data, q, v, a)` |
//! | `dirdyna`'s `M` | `void NAME_crba(const double *q, double *M)` | `crba(model, data, q)`, both triangles |
//! | `dirdyna`'s `c` | `void NAME_nle(const double *q, const double *v, double *nle)` | `nonLinearEffects(model, data, q, v)` |
//! | `fordyna` | `void NAME_aba(const double *q, const double *v, const double *tau, double *qdd)` | `aba(model, data, q, v, tau)` |
//! | `rnea_derivatives` | `void NAME_rnea_derivatives(const double *q, const double *v, const double *a, double *dtau_dq, double *dtau_dv)` | `computeRNEADerivatives(model, data, q, v, a)` |
//! | `aba_derivatives` | `void NAME_aba_derivatives(const double *q, const double *v, const double *tau, double *ddq_dq, double *ddq_dv, double *Minv)` | `computeABADerivatives(model, data, q, v, tau)`, `Minv` both triangles |
//! | `minv` | `void NAME_minv(const double *q, double *Minv)` | `computeMinverse(model, data, q)`, both triangles |
//!
//! The last three are the generator's derivative functions (`-function=rnea_derivatives`, …;
//! issue 50): each matrix row-major `nv × nv`, derivatives with respect to `q` (`…_dq`) too:
//! the generator writes them along Pinocchio's tangent space (a free flyer's `nq = nv + 1`
//! coordinates, a `(cos, sin)` pair's two, have `nv` directions), as Pinocchio returns them.
//!
//! `dirdyna` gives two functions, each the backward slice of its outputs (the mass matrix
//! depends on `q` only, so `NAME_crba` takes no velocity). `fordyna` exists when the URDF is
//! loaded with `-function=fordyna`.
//!
//! # Index convention
//! Arrays are 0-based and map by name and index, never by position in the IR's input list:
//! input `q[i]` is `q[i-1]`, `qd[i]` is `v[i-1]`, `qdd[i]` is `a[i-1]`, `Qq[i]` (an input of
//! `fordyna`) is `tau[i-1]`; outputs `Qq[i]` are `tau[i-1]`, `c[i]` are `nle[i-1]`, `qdd[i]` are
//! `qdd[i-1]`, and `M[i][j]` is `M[(i-1)*nv + (j-1)]`: row-major with both triangles (the same
//! array as Pinocchio's column-major `data.M` once symmetrised, since `M` is symmetric). When
//! the IR has one triangle only, each entry is written to its mirror too; an entry missing in
//! both is an error. `nv` is the largest velocity index of the module (`qd`, `qdd`, `Qq`, `c`,
//! `M`) and `nq` the largest `q` index, at least `nv` (Pinocchio's free-flyer has `nq = nv + 1`):
//! the header defines `NAME_NQ` and `NAME_NV`. A joint Pinocchio holds as `(cos θ, sin θ)` (a
//! URDF `continuous` joint, `nq = 2` for it) takes that pair when the URDF is loaded with
//! `--continuous=cos-sin`; without it, it is one angle `q[i]` and the model's `q` is not
//! Pinocchio's.
//!
//! # Gravity and parameters
//! Inputs `g[1..3]` (the generator's gravity) are folded into the code as Pinocchio's default
//! `model.gravity`, (0, 0, −9.81) m/s²: constants the function reads, so the C computes bit for
//! bit what `-eval` computes with those values of `g`. A model written with its gravity as
//! constants has no `g` input, and nothing is folded. Model parameters (`m`, `l`, `In`, `dpt`)
//! must be folded before: `--fold-params` on the URDF, or `specialize<params=FILE>`; an input
//! that is not `q`, `qd`, `qdd`, `Qq` or `g` is an error naming it.
//!
//! # Options
//! `name=NAME` is the prefix of the symbols (default `model`, Pinocchio's name for the model
//! argument: `model_rnea`); `batch=W` takes W states per call, lane-contiguous as in the plain
//! ABI: element `k` of lane `l` of every array is `p[k*W + l]` (`M`'s element `(i-1)*nv + (j-1)`
//! likewise); with `layout=rows`, `W` rows of a row-major `(B, n)` array, as numpy's and
//! Pinocchio's batches hold them: element `k` of state `l` is `p[l*n + k]`, `n` the array's
//! elements per state (`nq` for `q`, `nv` for `v`, `nv·nv` for a matrix). `trig=libm` and
//! `trig=inline` as for the other ABIs; `chunk=` and `units=` too.
//! `precision=f32` and `trig=input` are refused ([`super::CodegenC::from_params`]): Pinocchio's
//! vectors are doubles and its signatures take no sin/cos.
//!
//! The header declares the functions without `restrict` (the definitions have it: an output
//! array may not overlap an input) inside `extern "C"` for C++ callers, with the include guard
//! `ROBOVEC_NAME_<first function>_H`.

use std::collections::HashSet;
use std::fmt::Write as _;

use robovec_ir::{Function, Module};

use super::plain::{arrays, Layout, Source};
use super::{CodegenC, Emitted};
use crate::names::reserved_symbol_reason;
use crate::Interface;
use robovec_passes::time_limit::TickerError;
use robovec_passes::PassError;

/// The prefix of the symbols without `name=`: `model_rnea`, `model_crba`, ….
pub const DEFAULT_NAME: &str = "model";

/// Pinocchio's default gravity (`model.gravity.linear()`), m/s²: what `g[1..3]` become.
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// The model parameters the URDF generator leaves as inputs without `--fold-params`.
const PARAMETERS: &[&str] = &["m", "l", "In", "dpt"];

/// One of the C functions: Pinocchio's algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Algo {
    Rnea,
    Crba,
    Nle,
    Aba,
    RneaDerivatives,
    AbaDerivatives,
    Minv,
}

/// Every algorithm, in the order of the module doc's table.
const ALGOS: [Algo; 7] =
    [Algo::Rnea, Algo::Crba, Algo::Nle, Algo::Aba, Algo::RneaDerivatives, Algo::AbaDerivatives, Algo::Minv];

/// The IR's output arrays that are matrices (`base[i][j]`), and how many columns one has: `nv`
/// (the derivatives with respect to `q` are along the tangent space: module doc).
fn matrix_columns(base: &str, _nq: usize, nv: usize) -> Option<usize> {
    match base {
        "dtau_dq" | "ddq_dq" | "M" | "dtau_dv" | "ddq_dv" | "Minv" => Some(nv),
        _ => None,
    }
}

impl Algo {
    /// The suffix of the symbol.
    fn suffix(self) -> &'static str {
        match self {
            Algo::Rnea => "rnea",
            Algo::Crba => "crba",
            Algo::Nle => "nle",
            Algo::Aba => "aba",
            Algo::RneaDerivatives => "rnea_derivatives",
            Algo::AbaDerivatives => "aba_derivatives",
            Algo::Minv => "minv",
        }
    }

    /// Input arrays `(C name, the IR's array)`, then the output arrays `(C name, the IR's array)`.
    #[allow(clippy::type_complexity, reason = "two static tables of name pairs")]
    fn arrays(self) -> (&'static [(&'static str, &'static str)], &'static [(&'static str, &'static str)]) {
        match self {
            Algo::Rnea => (&[("q", "q"), ("v", "qd"), ("a", "qdd")], &[("tau", "Qq")]),
            Algo::Crba => (&[("q", "q")], &[("M", "M")]),
            Algo::Nle => (&[("q", "q"), ("v", "qd")], &[("nle", "c")]),
            Algo::Aba => (&[("q", "q"), ("v", "qd"), ("tau", "Qq")], &[("qdd", "qdd")]),
            Algo::RneaDerivatives => {
                (&[("q", "q"), ("v", "qd"), ("a", "qdd")], &[("dtau_dq", "dtau_dq"), ("dtau_dv", "dtau_dv")])
            }
            Algo::AbaDerivatives => (
                &[("q", "q"), ("v", "qd"), ("tau", "Qq")],
                &[("ddq_dq", "ddq_dq"), ("ddq_dv", "ddq_dv"), ("Minv", "Minv")],
            ),
            Algo::Minv => (&[("q", "q")], &[("Minv", "Minv")]),
        }
    }

    /// Pinocchio's call it replaces.
    fn pinocchio(self) -> &'static str {
        match self {
            Algo::Rnea => "tau = rnea(model, data, q, v, a)",
            Algo::Crba => "M = crba(model, data, q), both triangles, row-major",
            Algo::Nle => "nle = nonLinearEffects(model, data, q, v)",
            Algo::Aba => "qdd = aba(model, data, q, v, tau)",
            Algo::RneaDerivatives => "computeRNEADerivatives(model, data, q, v, a): dtau_dq, dtau_dv",
            Algo::AbaDerivatives => "computeABADerivatives(model, data, q, v, tau): ddq_dq, ddq_dv, Minv",
            Algo::Minv => "Minv = computeMinverse(model, data, q), both triangles",
        }
    }
}

/// The size of one dimension of an array of a C function: `nq` (`q`) or `nv`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dim {
    /// The configuration's size, `NAME_NQ`.
    Nq,
    /// The velocity's size, `NAME_NV`.
    Nv,
}

/// One C function of this ABI as a caller sees it: the IR function it is written from, its
/// symbol's suffix (`NAME_<suffix>`), its input arrays (name, length) and its output arrays
/// (name, rows, columns: `None` for a vector) in argument order: the module doc's table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Signature {
    /// The URDF generator's function (`invdyna`, `dirdyna`, `fordyna`, `rnea_derivatives`, …).
    pub function: &'static str,
    /// The symbol's suffix: `rnea`, `crba`, `nle`, `aba`, `rnea_derivatives`, …
    pub suffix: &'static str,
    /// Input arrays: C name and length.
    pub inputs: Vec<(&'static str, Dim)>,
    /// Output arrays: C name, rows and columns (`None`: a vector of `rows`), row-major.
    pub outputs: Vec<(&'static str, Dim, Option<Dim>)>,
}

/// The [`Signature`] of the C function `NAME_<suffix>` (Pinocchio's algorithm names: `rnea`,
/// `crba`, `nle`, `aba`, `rnea_derivatives`, `aba_derivatives`, `minv`); `None` for another
/// name. What a caller (the Python module) allocates and passes.
pub fn signature(suffix: &str) -> Option<Signature> {
    let a = ALGOS.into_iter().find(|a| a.suffix() == suffix)?;
    let function = match a {
        Algo::Rnea => "invdyna",
        Algo::Crba | Algo::Nle => "dirdyna",
        Algo::Aba => "fordyna",
        Algo::RneaDerivatives => "rnea_derivatives",
        Algo::AbaDerivatives => "aba_derivatives",
        Algo::Minv => "minv",
    };
    let (ins, outs) = a.arrays();
    let inputs = ins.iter().map(|&(c, ir)| (c, if ir == "q" { Dim::Nq } else { Dim::Nv })).collect();
    let outputs = outs.iter().map(|&(c, ir)| (c, Dim::Nv, matrix_columns(ir, 0, 0).map(|_| Dim::Nv))).collect();
    Some(Signature { function, suffix: a.suffix(), inputs, outputs })
}

/// Every suffix [`signature`] knows, in the module doc's order.
pub fn suffixes() -> [&'static str; 7] {
    ALGOS.map(Algo::suffix)
}

/// `M[2][3]` → (`M`, [2, 3]); `None` when the name is not `base[i]…` with 1-based integers.
fn indexed(name: &str) -> Option<(&str, Vec<usize>)> {
    let i = name.find('[')?;
    let mut idx = Vec::new();
    let mut rest = &name[i..];
    while let Some(r) = rest.strip_prefix('[') {
        let end = r.find(']')?;
        idx.push(r[..end].parse::<usize>().ok().filter(|&k| k >= 1)?);
        rest = &r[end + 1..];
    }
    rest.is_empty().then_some((&name[..i], idx))
}

fn failed(f: &Function, message: String) -> PassError {
    PassError::Failed { pass: "codegen".into(), message: format!("@{}: {message}", f.name) }
}

/// The C functions of `f` (each keeps the IR's output arrays of [`Algo::arrays`]), or the
/// error for a function that is not one of the generator's.
fn algorithms(f: &Function) -> Result<Vec<Algo>, PassError> {
    match f.name.as_str() {
        "invdyna" => Ok(vec![Algo::Rnea]),
        "dirdyna" => Ok(vec![Algo::Crba, Algo::Nle]),
        "fordyna" => Ok(vec![Algo::Aba]),
        "rnea_derivatives" => Ok(vec![Algo::RneaDerivatives]),
        "aba_derivatives" => Ok(vec![Algo::AbaDerivatives]),
        "minv" => Ok(vec![Algo::Minv]),
        _ => Err(failed(
            f,
            "abi=pinocchio writes the URDF generator's @invdyna (NAME_rnea), @dirdyna (NAME_crba, NAME_nle), \
             @fordyna (NAME_aba), @rnea_derivatives, @aba_derivatives and @minv (NAME_rnea_derivatives, …); this \
             function is none of them (use abi=plain)"
                .into(),
        )),
    }
}

/// Checks the inputs and outputs of `f` against its algorithms and returns its largest `q`
/// index and largest velocity index.
fn check(f: &Function) -> Result<(usize, usize), PassError> {
    let algos = algorithms(f)?;
    let allowed: Vec<&str> = algos.iter().flat_map(|a| a.arrays().0.iter().map(|x| x.1)).chain(["g"]).collect();
    let (mut nq, mut nv) = (0, 0);
    let mut params = Vec::new();
    for &v in &f.inputs {
        let n = f.name_of(v);
        match indexed(n) {
            Some((base, _)) if PARAMETERS.contains(&base) => params.push(n.to_string()),
            Some(("g", idx)) if idx.len() == 1 && idx[0] <= 3 => {}
            Some((base, idx)) if idx.len() == 1 && allowed.contains(&base) => {
                if base == "q" {
                    nq = nq.max(idx[0]);
                } else {
                    nv = nv.max(idx[0]);
                }
            }
            _ => {
                return Err(failed(
                    f,
                    format!(
                    "input `{n}` has no place in Pinocchio's signature (abi=pinocchio reads {} and gravity g[1..3])",
                    allowed[..allowed.len() - 1].join(", ")
                ),
                ))
            }
        }
    }
    if !params.is_empty() {
        let more = if params.len() > 4 { format!(", … ({} in all)", params.len()) } else { String::new() };
        params.truncate(4);
        return Err(failed(
            f,
            format!(
                "model parameters are inputs ({}{more}); Pinocchio's functions take the state only: load the URDF \
                 with --fold-params, or fold them with specialize<params=FILE>",
                params.join(", ")
            ),
        ));
    }
    let outs: Vec<&str> = algos.iter().flat_map(|a| a.arrays().1.iter().map(|x| x.1)).collect();
    for o in &f.outputs {
        match indexed(&o.name) {
            Some((base, idx)) if idx.len() == 2 && outs.contains(&base) && matrix_columns(base, 0, 0).is_some() => {
                nv = nv.max(idx[0]).max(idx[1]);
            }
            Some((base, idx)) if idx.len() == 1 && outs.contains(&base) => nv = nv.max(idx[0]),
            _ => {
                return Err(failed(
                    f,
                    format!("output `{}` has no place in Pinocchio's signature (abi=pinocchio writes {})", o.name, {
                        let list: Vec<String> = outs
                            .iter()
                            .map(|b| {
                                if matrix_columns(b, 0, 0).is_some() {
                                    format!("{b}[i][j]")
                                } else {
                                    format!("{b}[i]")
                                }
                            })
                            .collect();
                        list.join(", ")
                    }),
                ))
            }
        }
    }
    Ok((nq, nv))
}

/// `f` with only the output arrays of `a` and what they need: the backward slice, unused
/// inputs dropped.
fn slice(f: &Function, a: Algo) -> Function {
    let keep = a.arrays().1;
    let mut g = f.clone();
    g.outputs.retain(|o| indexed(&o.name).is_some_and(|(b, _)| keep.iter().any(|x| x.1 == b)));
    let live = g.live_values(&[]);
    g.retain(|_, v| live[v.index()]);
    g
}

/// The symbols' prefix: `name=` or [`DEFAULT_NAME`], checked so that every symbol is free.
fn prefix(o: &CodegenC) -> Result<String, PassError> {
    let n = o.name.clone().unwrap_or_else(|| DEFAULT_NAME.to_string());
    for s in ALGOS.map(|a| format!("{n}_{}", a.suffix())) {
        if let Some(why) = reserved_symbol_reason(&s) {
            return Err(PassError::BadParameter {
                pass: "codegen".into(),
                message: format!("parameter `name`: abi=pinocchio's symbol `{s}` cannot name generated C: it is {why}"),
            });
        }
    }
    Ok(n)
}

/// Every C function of `m` (atomised URDF dynamics) as [`Emitted`], with its symbol, and the
/// header's preamble (`NAME_NQ`, `NAME_NV`).
///
/// # Errors
/// [`PassError::Failed`] for a function that is not `invdyna`, `dirdyna` or `fordyna`, an
/// input or output with no place in Pinocchio's signature (model parameters among them: the
/// message says how to fold them), or a mass matrix entry missing in both triangles;
/// [`PassError::BadParameter`] for a `name=` whose symbols would be reserved.
pub(crate) fn emit(
    o: &CodegenC,
    m: &Module,
    ticker: &robovec_passes::Ticker,
) -> Result<(Vec<String>, Vec<Emitted>, String), PassError> {
    let name = prefix(o)?;
    let (mut nq, mut nv) = (0, 0);
    for f in &m.functions {
        let (q, v) = check(f)?;
        nq = nq.max(q);
        nv = nv.max(v);
    }
    nq = nq.max(nv);
    let mut jobs: Vec<(Algo, Function)> = Vec::new();
    for f in &m.functions {
        let algos = algorithms(f)?;
        for &a in &algos {
            // A function of one algorithm has only its own outputs: no slice.
            jobs.push((a, if algos.len() > 1 { slice(f, a) } else { f.clone() }));
        }
    }
    let mut seen = HashSet::new();
    for (a, f) in &jobs {
        if !seen.insert(*a) {
            return Err(failed(f, format!("two functions of the module would be {name}_{}", a.suffix())));
        }
    }
    let symbols: Vec<String> = jobs.iter().map(|(a, _)| format!("{name}_{}", a.suffix())).collect();
    let taken: HashSet<String> = symbols.iter().cloned().collect();
    let w = o.batch as usize;
    let mut emitted = Vec::with_capacity(jobs.len());
    for ((a, f), symbol) in jobs.iter().zip(&symbols) {
        let (ins, outs) = a.arrays();
        let mut params: Vec<(&str, bool)> = ins.iter().map(|x| (x.0, false)).collect();
        params.extend(outs.iter().map(|x| (x.0, true)));
        let mut inputs = Vec::with_capacity(f.inputs.len());
        for &v in &f.inputs {
            let n = f.name_of(v);
            let (base, idx) = indexed(n).expect("checked");
            inputs.push(if base == "g" {
                Source::Const(GRAVITY[idx[0] - 1])
            } else {
                let p = ins
                    .iter()
                    .position(|x| x.1 == base)
                    .ok_or_else(|| failed(f, format!("{symbol} takes no `{base}`, but its outputs read `{n}`")))?;
                Source::Elem(p, idx[0] - 1)
            });
        }
        // Each output array's length: rows × columns for a matrix, nv for a vector.
        let len = |base: &str| matrix_columns(base, nq, nv).map_or(nv, |c| nv * c);
        // Outputs: one element each, M mirrored where the IR has one triangle only.
        let mut outputs = Vec::with_capacity(f.outputs.len());
        let mut covered: Vec<Vec<bool>> = outs.iter().map(|x| vec![false; len(x.1)]).collect();
        let present: HashSet<&str> = f.outputs.iter().map(|x| x.name.as_str()).collect();
        for x in &f.outputs {
            let (base, idx) = indexed(&x.name).expect("checked");
            let k = outs.iter().position(|o| o.1 == base).expect("checked");
            let param = ins.len() + k;
            let mut dest = Vec::with_capacity(2);
            if let Some(cols) = matrix_columns(base, nq, nv) {
                let (i, j) = (idx[0] - 1, idx[1] - 1);
                dest.push((param, i * cols + j));
                if base == "M" && i != j && !present.contains(format!("M[{}][{}]", j + 1, i + 1).as_str()) {
                    dest.push((param, j * nv + i));
                }
            } else {
                dest.push((param, idx[0] - 1));
            }
            for &(_, e) in &dest {
                covered[k][e] = true;
            }
            outputs.push(dest);
        }
        for (k, &(out_c, out_ir)) in outs.iter().enumerate() {
            if let Some(e) = covered[k].iter().position(|c| !c) {
                let missing = match matrix_columns(out_ir, nq, nv) {
                    Some(c) => format!("{out_ir}[{}][{}]", e / c + 1, e % c + 1),
                    None => format!("{out_ir}[{}]", e + 1),
                };
                return Err(failed(
                    f,
                    format!(
                        "{symbol} writes {out_c}[0..{}) but the function has no output {missing} (nv = {nv}; was it removed by dce?)",
                        covered[k].len()
                    ),
                ));
            }
        }
        // Each array's elements per state (`layout=rows`).
        let mut row_len: Vec<usize> = ins.iter().map(|x| if x.1 == "q" { nq } else { nv }).collect();
        row_len.extend(outs.iter().map(|x| len(x.1)));
        let layout = Layout { params, inputs, outputs, float_arrays: false, row_len };
        let comment = format!("@{} as {symbol}: Pinocchio's {}", f.name, a.pinocchio());
        let (entry, parts) = arrays(o, f, symbol, &taken, ticker, &layout, &comment);
        if ticker.stopped() {
            return Err(ticker.error("codegen", &format!("writing {symbol}")));
        }
        // The interface: the arrays' elements in argument order.
        let mut in_names = Vec::new();
        for (&(_, base), &n) in ins.iter().zip(&layout.row_len) {
            in_names.extend((1..=n).map(|k| format!("{base}[{k}]")));
        }
        let mut out_names: Vec<String> = Vec::new();
        for &(_, base) in outs {
            match matrix_columns(base, nq, nv) {
                Some(c) => out_names.extend((1..=nv).flat_map(|i| (1..=c).map(move |j| format!("{base}[{i}][{j}]")))),
                None => out_names.extend((1..=nv).map(|k| format!("{base}[{k}]"))),
            }
        }
        let iface = Interface { inputs: in_names, outputs: out_names, ..super::interface(o, f, symbol) };
        let mut proto = format!("/* @{} as {symbol}: Pinocchio's {}.\n *", f.name, a.pinocchio());
        for &(c, base) in ins {
            let n = if base == "q" { "NQ" } else { "NV" };
            let _ = write!(proto, " {c}[0..{name}_{n}) = {base}[1..],");
        }
        let described: Vec<String> = outs
            .iter()
            .map(|&(out_c, out_ir)| match matrix_columns(out_ir, nq, nv) {
                Some(_) => format!(" {out_c}[0..{name}_NV*{name}_NV) = {out_ir}[i+1][j+1] at i*{name}_NV + j"),
                None => format!(" {out_c}[0..{name}_NV) = {out_ir}[1..]"),
            })
            .collect();
        proto += &described.join(",");
        if w > 1 && o.layout == super::BatchLayout::Rows {
            let _ = write!(
                proto,
                ";\n * {w} states per call as rows: element k of state l of every array at [l*n + k], n its elements per state"
            );
        } else if w > 1 {
            let _ = write!(proto, ";\n * {w} states per call: lane l of element k of every array at [k*{w} + l]");
        }
        let args: Vec<String> = layout
            .params
            .iter()
            .map(|&(p, out)| if out { format!("double *{p}") } else { format!("const double *{p}") })
            .collect();
        let _ = writeln!(proto, ". */\nvoid {symbol}({});\n", args.join(", "));
        emitted.push(Emitted { entry, parts, proto, iface });
    }
    let gravity = if m.functions.iter().any(|f| f.inputs.iter().any(|&v| f.name_of(v).starts_with("g["))) {
        "; gravity folded as Pinocchio's default (0, 0, -9.81)"
    } else {
        ""
    };
    let preface = format!(
        "/* Pinocchio's vectors (0-based): q has NQ elements, v, a, tau, nle, qdd NV, M and Minv NV*NV (row-major,\n \
         * both triangles), a derivative NV*NQ (..._dq) or NV*NV (row-major){gravity}. No output array may overlap an\n \
         * input. */\n\
         #define {name}_NQ {nq}\n#define {name}_NV {nv}\n\n"
    );
    Ok((symbols, emitted, preface))
}

#[cfg(test)]
mod tests {
    use super::{signature, suffixes, Dim};

    /// The table of the module doc, by hand: every function's IR source, argument order and
    /// shapes (vectors `nv`, `q` `nq`, every matrix `nv × nv`).
    #[test]
    fn signatures_follow_the_module_docs_table() {
        let s = signature("rnea").unwrap();
        assert_eq!((s.function, s.suffix), ("invdyna", "rnea"));
        assert_eq!(s.inputs, [("q", Dim::Nq), ("v", Dim::Nv), ("a", Dim::Nv)]);
        assert_eq!(s.outputs, [("tau", Dim::Nv, None)]);
        let s = signature("crba").unwrap();
        assert_eq!((s.function, s.inputs.len()), ("dirdyna", 1));
        assert_eq!(s.outputs, [("M", Dim::Nv, Some(Dim::Nv))]);
        assert_eq!(signature("nle").unwrap().outputs, [("nle", Dim::Nv, None)]);
        let s = signature("aba").unwrap();
        assert_eq!(s.function, "fordyna");
        assert_eq!(s.inputs, [("q", Dim::Nq), ("v", Dim::Nv), ("tau", Dim::Nv)]);
        let s = signature("aba_derivatives").unwrap();
        assert_eq!(
            s.outputs,
            [("ddq_dq", Dim::Nv, Some(Dim::Nv)), ("ddq_dv", Dim::Nv, Some(Dim::Nv)), ("Minv", Dim::Nv, Some(Dim::Nv))]
        );
        assert_eq!(signature("rnea_derivatives").unwrap().outputs.len(), 2);
        assert_eq!(signature("minv").unwrap().inputs, [("q", Dim::Nq)]);
        assert!(signature("invdyna").is_none() && signature("").is_none());
        assert_eq!(suffixes().len(), 7);
        assert!(suffixes().iter().all(|s| signature(s).is_some_and(|g| g.suffix == *s)));
    }
}
