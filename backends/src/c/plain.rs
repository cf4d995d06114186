//! `abi=plain`: `void SYMBOL(const REAL *restrict in, REAL *restrict out)` (SPEC §8).
//!
//! Input `i` (canonical names in [`crate::Interface::inputs`]) is `in[i]`, output `j`
//! is `out[j]`; with `batch=W`, lane `l` of them is `in[i*W + l]` and `out[j*W + l]`, loaded
//! and stored with `memcpy` (no alignment is assumed); with `layout=rows` they are
//! `in[l*NI + i]` and `out[l*NO + j]` (`NI` inputs, `NO` outputs a state), read and written
//! lane by lane.
//!
//! Order: each input is read just before the first statement that uses it and each output is
//! written right after the statement that computes it (`in` and `out` are `restrict`, so
//! nothing aliases and the results are the same in any order). Reading every input first and
//! writing every output last, as the first version did, kept ~1400 values live across the whole
//! body: on coman_longarms' `dirdyna` at `batch=8` (`-O3 -march=native`, GCC 12) the stack frame
//! was 97 KB — three times the 32 KB L1 data cache — with 17.9k stack operands; now it is
//! 26 KB with 5.6k, 15 % fewer instructions, and the file compiles in 12 s instead of 144 s
//! (issue 11's measurements). `abi=robotran` keeps reads first and writes last: its output
//! arrays may alias `MbsData` fields.
//!
//! Split into parts (`chunk=OPS`, `split.rs`), each part is `static void
//! SYMBOL_partK(const REAL *restrict in, REAL *restrict out, T *restrict live)` with the same
//! order inside (each part reads the inputs it uses at their first use in it, and the live
//! values of earlier parts likewise), and the entry point, with the same signature, calls them
//! in order; with `batch=W` the entry point runs the loop over the vector chunks and hands each
//! part `in` and `out` already offset to the chunk.

use std::collections::HashSet;
use std::fmt::Write as _;

use robovec_ir::{Function, Operand, Value};

use super::body::Body;
use super::split::{part_name, part_prefix, Part, Plan};
use super::{interface, CodegenC, Emitted};
use crate::input_values;
use crate::literal;
use crate::names::c_names;

/// The parameter and helper names of the plain ABI (never given to a value).
pub const RESERVED: &[&str] = &["in", "out", "live"];

/// `f` as `symbol`: its definition (split into parts of at most `o.chunk` statements when it
/// has `2·o.chunk` or more, `split.rs`; part names avoid `taken`, the file's other global names), its prototype (with the
/// documented input and output order, for the header) and its interface.
pub(crate) fn function(
    o: &CodegenC,
    f: &Function,
    symbol: &str,
    taken: &HashSet<String>,
    ticker: &robovec_passes::Ticker,
    io_f32: bool,
) -> Emitted {
    let mut iface = interface(o, f, symbol);
    if io_f32 {
        iface.precision = super::Precision::F32;
    }
    let layout = Layout {
        params: vec![("in", false), ("out", true)],
        inputs: (0..iface.inputs.len()).map(|i| Source::Elem(0, i)).collect(),
        outputs: (0..f.outputs.len()).map(|j| vec![(1, j)]).collect(),
        float_arrays: io_f32,
        row_len: vec![iface.inputs.len(), f.outputs.len()],
    };
    let comment =
        format!("@{}: {} inputs, {} outputs (order: see the header)", f.name, iface.inputs.len(), iface.outputs.len());
    let (s, parts) = arrays(o, f, symbol, taken, ticker, &layout, &comment);
    let real = if io_f32 { "float" } else { o.real() };
    let w = o.batch as usize;
    let sig = format!("void {symbol}(const {real} *restrict in, {real} *restrict out)");
    let mut proto = format!("/* @{} as {symbol}", f.name);
    if w > 1 && o.layout == super::BatchLayout::Rows {
        let _ = write!(
            proto,
            ", {w} states per call as rows (element i of state l at in[l*{} + i], out[l*{} + i])",
            iface.inputs.len(),
            f.outputs.len()
        );
    } else if w > 1 {
        let _ = write!(proto, ", {w} states per call (lane l of element i at [i*{w} + l])");
    }
    proto += ".\n * Inputs:";
    for (i, n) in iface.inputs.iter().enumerate() {
        let _ = write!(proto, "{}in[{i}] {n}", if i % 8 == 0 { "\n *   " } else { ", " });
    }
    proto += "\n * Outputs:";
    for (j, n) in iface.outputs.iter().enumerate() {
        let _ = write!(proto, "{}out[{j}] {n}", if j % 8 == 0 { "\n *   " } else { ", " });
    }
    let _ = writeln!(
        proto,
        " */\n{sig};\n#define {symbol}_INPUTS {}\n#define {symbol}_OUTPUTS {}\n",
        iface.inputs.len(),
        iface.outputs.len()
    );
    Emitted { entry: s, parts, proto, iface }
}

/// Where the generated code reads one input of a function written by [`arrays`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Source {
    /// Element `.1` of parameter `.0` (an input array of [`Layout::params`]).
    Elem(usize, usize),
    /// A constant written into the code (`abi=pinocchio`'s gravity).
    Const(f64),
}

/// The array parameters of a function written by [`arrays`] and where each input and output
/// lives in them: the plain ABI's `in`/`out`, or Pinocchio's `q`, `v`, `a`, `tau`, `M`, ….
pub(crate) struct Layout<'a> {
    /// The parameters in order: C name, true for an output array (`REAL *restrict`; an input
    /// array is `const REAL *restrict`).
    pub params: Vec<(&'a str, bool)>,
    /// Per input of the function ([`input_values`] order): where it is read.
    pub inputs: Vec<Source>,
    /// Per output of the function: the `(parameter, element)` it is written to, one or more (a
    /// mass matrix's mirrored triangle).
    pub outputs: Vec<Vec<(usize, usize)>>,
    /// The arrays are `float` while the values compute in their formats (formats with
    /// `precision=f32`; the body's options are then `precision=f64`).
    pub float_arrays: bool,
    /// Per parameter, its elements per state: with `batch=W;layout=rows` element `e` of state
    /// `l` is `p[l*n + e]`.
    pub row_len: Vec<usize>,
}

/// `f` as `symbol` over the arrays of `layout`: the definition of the entry point, opening with
/// `/* {comment}. */` (split into parts of at most `o.chunk` statements when it has `2·o.chunk`
/// or more, `split.rs`; part names avoid `taken`, the file's other global names), and its parts. Element `e` of a
/// parameter is `p[e]`, with `batch=W` lane `l` of it is `p[e*W + l]` (`memcpy`, no alignment
/// assumed), with `layout=rows` `p[l*n + e]` (`n` = [`Layout::row_len`], lane by lane). Inputs
/// are read just before their first use and outputs written right after the statement that
/// computes them (the module doc); outputs that are inputs or constants come last.
pub(crate) fn arrays(
    o: &CodegenC,
    f: &Function,
    symbol: &str,
    taken: &HashSet<String>,
    ticker: &robovec_passes::Ticker,
    layout: &Layout,
    comment: &str,
) -> (String, Vec<Part>) {
    let io_f32 = layout.float_arrays;
    let mut reserved: Vec<&str> = layout.params.iter().map(|p| p.0).collect();
    reserved.extend(RESERVED);
    reserved.push(symbol);
    let callee_names = super::callbacks::callee_names(f);
    reserved.extend(callee_names.iter().map(String::as_str));
    let names = c_names(f, &reserved);
    let b = Body::new(o, f, &names, None, ticker);
    let (order, attached) = b.order();
    let plan = Plan::new(f, &order, &attached, o.chunk as usize, &[], &[]);
    // The arrays' type: `float` with formats and precision=f32 (`io_f32`), else the values'.
    let real = if io_f32 { "float" } else { o.real() };
    let w = o.batch as usize;
    let params: Vec<String> = layout
        .params
        .iter()
        .map(|&(p, out)| if out { format!("{real} *restrict {p}") } else { format!("const {real} *restrict {p}") })
        .collect();
    let params = params.join(", ");
    let sig = format!("void {symbol}({params})");
    let ty = b.value_type();
    let inputs = input_values(f, o.trig == super::Trig::Input);
    let mut input_at: Vec<Option<usize>> = vec![None; f.values.len()];
    for (i, &v) in inputs.iter().enumerate() {
        input_at[v.index()] = Some(i);
    }
    let mut outputs_of: Vec<Vec<usize>> = vec![Vec::new(); f.values.len()];
    for (j, out) in f.outputs.iter().enumerate() {
        if let Operand::Value(v) = out.value {
            if input_at[v.index()].is_none() {
                outputs_of[v.index()].push(j);
            }
        }
    }
    let split = plan.parts() > 1;
    let rows = w > 1 && o.layout == super::BatchLayout::Rows;
    // A batch: one pass of the body per chunk of ROBOVEC_VL lanes. `chunk(p)`: where the chunk
    // starts in parameter `p`; `at(p)`: the body's offset (none in a part, whose entry point
    // passes its arrays at the chunk already).
    let chunk = |p: usize| -> String {
        if rows {
            format!(" + robovec_chunk * ROBOVEC_VL * {}", layout.row_len[p])
        } else {
            " + robovec_chunk * ROBOVEC_VL".into()
        }
    };
    let at = |p: usize| -> String {
        if split {
            String::new()
        } else {
            chunk(p)
        }
    };
    // Element `e` of parameter `p`, lanes into the vector `var`, or out of the vector `x`:
    // `memcpy` of `w` adjacent lanes, or lane by lane from rows of `row_len[p]` elements.
    let fill = |p: usize, e: usize, var: &str| -> String {
        let name = layout.params[p].0;
        if rows {
            let n = layout.row_len[p];
            format!(
                "for (int robovec_lane = 0; robovec_lane < ROBOVEC_VL; robovec_lane++) {var}[robovec_lane] = \
                 {name}[robovec_lane * {n} + {e}{}];",
                at(p)
            )
        } else {
            format!("memcpy(&{var}, {name} + {}{}, sizeof {var});", e * w, at(p))
        }
    };
    let spill = |p: usize, e: usize, x: &str| -> String {
        let name = layout.params[p].0;
        if rows {
            let n = layout.row_len[p];
            format!(
                "for (int robovec_lane = 0; robovec_lane < ROBOVEC_VL; robovec_lane++) \
                 {name}[robovec_lane * {n} + {e}{}] = {x}[robovec_lane];",
                at(p)
            )
        } else {
            format!("memcpy({name} + {}{}, &{x}, sizeof {x});", e * w, at(p))
        }
    };
    // Part k has read value v when read[v] == k + 1.
    let mut read = vec![0u32; f.values.len()];
    let mut load = |s: &mut String, v: Value, k: usize| {
        if read[v.index()] == k as u32 + 1 {
            return;
        }
        let n = &names[v.index()];
        if let Some(i) = input_at[v.index()] {
            read[v.index()] = k as u32 + 1;
            let vty = b.type_of(v);
            match layout.inputs[i] {
                Source::Elem(p, e) if w > 1 && io_f32 => {
                    // A float array: the lanes as a robovec_vec32, then in the value's format.
                    let expr = if b.narrow(v) {
                        "robovec_in32".to_string()
                    } else {
                        b.stored(v, "__builtin_convertvector(robovec_in32, robovec_vec)".into())
                    };
                    let _ = writeln!(
                        s,
                        "  {vty} {n};\n  {{\n    robovec_vec32 robovec_in32;\n    {}\n    {n} = {expr};\n  }}",
                        fill(p, e, "robovec_in32")
                    );
                }
                Source::Elem(p, e) if w > 1 && f.format(v).is_default() => {
                    let _ = writeln!(s, "  {ty} {n};\n  {}", fill(p, e, n));
                }
                Source::Elem(p, e) if w > 1 && b.narrow(v) && !rows => {
                    let _ =
                        writeln!(s, "  const {vty} {n} = robovec_load32({} + {}{});", layout.params[p].0, e * w, at(p));
                }
                Source::Elem(p, e) if w > 1 => {
                    // The arrays are of the file's real type: load, then store in the format.
                    let _ = writeln!(
                        s,
                        "  {vty} {n};\n  {{\n    {ty} robovec_in;\n    {}\n    {n} = {};\n  }}",
                        fill(p, e, "robovec_in"),
                        b.stored(v, "robovec_in".into())
                    );
                }
                Source::Elem(p, e) => {
                    let _ = writeln!(s, "  const {vty} {n} = {};", b.stored(v, format!("{}[{e}]", layout.params[p].0)));
                }
                Source::Const(c) => {
                    let _ = writeln!(s, "  const {vty} {n} = {};", b.stored(v, b.operand_value(&Operand::Const(c))));
                }
            }
        } else if plan.reads_live(v, k) {
            read[v.index()] = k as u32 + 1;
            let slot = format!("live[{}]", plan.slot(v).expect("read from live"));
            // A live slot is of the file's real type: a value in another format converts back
            // (exactly: it was written from that format).
            let back = if f.format(v).is_default() { slot } else { b.stored(v, slot) };
            let _ = writeln!(s, "  const {} {n} = {back};", b.type_of(v));
        }
    };
    let store = |s: &mut String, j: usize, x: &Operand| {
        let e = b.operand_value(x);
        for &(p, el) in &layout.outputs[j] {
            if w > 1 && io_f32 {
                // Every output is binary32 or a constant exact in it (`check_formats`).
                match x {
                    Operand::Value(v) => {
                        let _ = writeln!(s, "  {}", spill(p, el, &names[v.index()]));
                    }
                    Operand::Const(c) => {
                        let k = literal::operand(*c, true);
                        let _ =
                            writeln!(s, "  {{ const robovec_vec32 k = robovec_splat32({k}); {} }}", spill(p, el, "k"));
                    }
                }
            } else if w > 1 {
                match x {
                    Operand::Value(v) if b.narrow(*v) && rows => {
                        let k = "__builtin_convertvector(k32, robovec_vec)";
                        let _ = writeln!(
                            s,
                            "  {{ const robovec_vec32 k32 = {}; const {ty} k = {k}; {} }}",
                            names[v.index()],
                            spill(p, el, "k")
                        );
                    }
                    Operand::Value(v) if b.narrow(*v) => {
                        let _ = writeln!(
                            s,
                            "  robovec_store32({} + {}{}, {});",
                            layout.params[p].0,
                            el * w,
                            at(p),
                            names[v.index()]
                        );
                    }
                    Operand::Value(v) if f.format(*v).is_default() => {
                        let _ = writeln!(s, "  {}", spill(p, el, &e));
                    }
                    // A constant, or a fixed-point value's integers scaled.
                    _ => {
                        let _ = writeln!(s, "  {{ const {ty} k = {e}; {} }}", spill(p, el, "k"));
                    }
                }
            } else {
                let _ = writeln!(s, "  {}[{el}] = {e};", layout.params[p].0);
            }
        }
    };
    // The statements of part k (all of them when not split), then in the last part the
    // outputs that are inputs or constants.
    let mut statements = |s: &mut String, k: usize| {
        let range = plan.bounds[k]..plan.bounds[k + 1];
        b.statements_with(
            &order[range],
            s,
            &mut |s, v| f.value(v).def.for_each_value(|a| load(s, a, k)),
            &mut |s, v| {
                for &j in &outputs_of[v.index()] {
                    store(s, j, &f.outputs[j].value);
                }
                if let Some(slot) = plan.slot(v) {
                    let _ = writeln!(s, "  live[{slot}] = {};", b.operand(&Operand::Value(v)));
                }
            },
        );
        if k + 1 == plan.parts() {
            for (j, out) in f.outputs.iter().enumerate() {
                match out.value {
                    Operand::Value(v) if input_at[v.index()].is_none() => {}
                    Operand::Value(v) => {
                        load(s, v, k);
                        store(s, j, &out.value);
                    }
                    Operand::Const(_) => store(s, j, &out.value),
                }
            }
        }
    };
    let mut s =
        format!("/* {comment}{}. */\n", if split { format!("; {} parts", plan.parts()) } else { String::new() });
    let mut parts = Vec::new();
    if split {
        let prefix = part_prefix(symbol, plan.parts(), taken);
        let live_ty = if w > 1 { "robovec_vec" } else { o.real() };
        for k in 0..plan.parts() {
            let mut body = String::new();
            statements(&mut body, k);
            parts.push(Part {
                signature: format!(
                    "ROBOVEC_NOINLINE void {}({params}, {live_ty} *restrict live)",
                    part_name(&prefix, k)
                ),
                body,
                ops: plan.bounds[k + 1] - plan.bounds[k],
            });
        }
        let _ = write!(
            s,
            "{sig}\n{{\n  /* Values computed in one part and read in a later one. */\n  {live_ty} live[{}];\n",
            plan.slots.max(1)
        );
        let (indent, args) = if w > 1 {
            s += super::body::CHUNK_LOOP;
            let a: Vec<String> =
                layout.params.iter().enumerate().map(|(k, p)| format!("{}{}", p.0, chunk(k))).collect();
            ("    ", a.join(", ") + ", live")
        } else {
            let a: Vec<&str> = layout.params.iter().map(|p| p.0).collect();
            ("  ", a.join(", ") + ", live")
        };
        for k in 0..plan.parts() {
            let _ = writeln!(s, "{indent}{}({args});", part_name(&prefix, k));
        }
        if w > 1 {
            s += "  }\n";
        }
        s += "}\n\n";
    } else {
        // `in` goes unread in a function of constants (as car43's `link3D`).
        let _ = write!(s, "{sig}\n{{\n{}", super::split::void_params(&sig));
        if w > 1 {
            s += super::body::CHUNK_LOOP;
        }
        statements(&mut s, 0);
        if w > 1 {
            s += "  }\n";
        }
        s += "}\n\n";
    }
    (s, parts)
}
