//! `abi=plain`: `void SYMBOL(const REAL *restrict in, REAL *restrict out)` (SPEC §8).
//!
//! Input `i` (canonical names in [`crate::codegen::Interface::inputs`]) is `in[i]`, output `j`
//! is `out[j]`; with `batch=W`, lane `l` of them is `in[i*W + l]` and `out[j*W + l]`, loaded
//! and stored with `memcpy` (no alignment is assumed).
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

use std::fmt::Write as _;

use robovec_ir::{Function, Operand, Value};

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
    // Inputs are read just before their first use and outputs written right after their value
    // is computed (`in` and `out` are `restrict`: nothing aliases), which keeps the compiler's
    // live ranges short (see the module doc). Outputs that are inputs or constants come last.
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
    let mut loaded = vec![false; inputs.len()];
    let mut load = |s: &mut String, v: Value| {
        if let Some(i) = input_at[v.index()] {
            if !std::mem::replace(&mut loaded[i], true) {
                let n = &names[v.index()];
                if w > 1 {
                    let _ = writeln!(s, "  {ty} {n};\n  memcpy(&{n}, in + {} + {at}, sizeof {n});", i * w);
                } else {
                    let _ = writeln!(s, "  const {ty} {n} = in[{i}];");
                }
            }
        }
    };
    let store = |s: &mut String, j: usize, x: &Operand| {
        let e = b.operand_value(x);
        if w > 1 {
            match x {
                Operand::Value(_) => {
                    let _ = writeln!(s, "  memcpy(out + {} + {at}, &{e}, sizeof {e});", j * w);
                }
                Operand::Const(_) => {
                    let _ = writeln!(s, "  {{ const {ty} k = {e}; memcpy(out + {} + {at}, &k, sizeof k); }}", j * w);
                }
            }
        } else {
            let _ = writeln!(s, "  out[{j}] = {e};");
        }
    };
    b.statements_with(&mut s, &mut |s, v| f.value(v).def.for_each_value(|a| load(s, a)), &mut |s, v| {
        for &j in &outputs_of[v.index()] {
            store(s, j, &f.outputs[j].value);
        }
    });
    for (j, out) in f.outputs.iter().enumerate() {
        match out.value {
            Operand::Value(v) if input_at[v.index()].is_none() => {}
            Operand::Value(v) => {
                load(&mut s, v);
                store(&mut s, j, &out.value);
            }
            Operand::Const(_) => store(&mut s, j, &out.value),
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
