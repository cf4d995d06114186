//! `abi=plain`: `void SYMBOL(const REAL *restrict in, REAL *restrict out)` (SPEC §8).
//!
//! Input `i` (canonical names in [`crate::codegen::Interface::inputs`]) is `in[i]`, output `j`
//! is `out[j]`; with `batch=W`, lane `l` of them is `in[i*W + l]` and `out[j*W + l]`, loaded
//! and stored with `memcpy` (no alignment is assumed).

use std::fmt::Write as _;

use robovec_ir::{Function, Operand};

use super::body::Body;
use super::{interface, CodegenC};
use crate::codegen::names::c_names;
use crate::codegen::{input_values, Interface};

/// The parameter and helper names of the plain ABI (never given to a value).
pub const RESERVED: &[&str] = &["in", "out"];

/// The C definition of `f` as `symbol`, its prototype (with the documented input and output
/// order, for the header) and its interface.
pub fn function(o: &CodegenC, f: &Function, symbol: &str) -> (String, String, Interface) {
    let iface = interface(o, f, symbol);
    let mut reserved: Vec<&str> = RESERVED.to_vec();
    reserved.push(symbol);
    let callee_names = super::body::callee_names(f);
    reserved.extend(callee_names.iter().map(String::as_str));
    let names = c_names(f, &reserved);
    let b = Body { o, f, names: &names, native: None };
    let real = o.real();
    let w = o.batch as usize;
    let sig = format!("void {symbol}(const {real} *restrict in, {real} *restrict out)");
    let mut s = format!(
        "/* @{}: {} inputs, {} outputs (order: see the header). */\n{sig}\n{{\n",
        f.name,
        iface.inputs.len(),
        iface.outputs.len()
    );
    let ty = b.value_type();
    // A batch: one pass of the body per chunk of ROBOVEC_VL lanes, at offset `at` in a block.
    let at = "robovec_chunk * ROBOVEC_VL";
    if w > 1 {
        s += super::body::CHUNK_LOOP;
    }
    for (i, &v) in input_values(f, o.trig_input).iter().enumerate() {
        let n = &names[v.index()];
        if w > 1 {
            let _ = writeln!(s, "  {ty} {n};\n  memcpy(&{n}, in + {} + {at}, sizeof {n});", i * w);
        } else {
            let _ = writeln!(s, "  const {ty} {n} = in[{i}];");
        }
    }
    b.statements(&mut s);
    for (j, out) in f.outputs.iter().enumerate() {
        let x = b.operand_value(&out.value);
        if w > 1 {
            match out.value {
                Operand::Value(_) => {
                    let _ = writeln!(s, "  memcpy(out + {} + {at}, &{x}, sizeof {x});", j * w);
                }
                Operand::Const(_) => {
                    let _ = writeln!(s, "  {{ const {ty} k = {x}; memcpy(out + {} + {at}, &k, sizeof k); }}", j * w);
                }
            }
        } else {
            let _ = writeln!(s, "  out[{j}] = {x};");
        }
    }
    if w > 1 {
        s += "  }\n";
    }
    s += "}\n\n";
    let mut proto = format!("/* @{} as {symbol}", f.name);
    if w > 1 {
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
        " */\n{sig};\n#define {}_INPUTS {}\n#define {}_OUTPUTS {}\n",
        symbol.to_uppercase(),
        iface.inputs.len(),
        symbol.to_uppercase(),
        iface.outputs.len()
    );
    (s, proto, iface)
}
