//! `abi=robotran`: a drop-in replacement of the Robotran function the IR came from, with its
//! signature and `MbsData` field access (1-based arrays as Robotran uses them), so the file
//! replaces Robotran's own in an MBsysC project (GRAMMAR-NOTES §1.3, §2.3 list the signatures).
//!
//! Inputs are read into locals first (`const double q_4 = s->q[4];`), outputs written last
//! (`M[1][2] = CM12;`), so an output array that aliases an `MbsData` field (`mbs_link(s->frc,
//! …)`) is never read after being written. Sensors (`@sensor_3`, `@gensensor_3`) become one
//! static function each and one `mbs_sensor(MbsSensor *sens, MbsData *s, int isens)` (or
//! `mbs_gensensor`) that switches on `isens`, as Robotran's does.

use std::collections::HashSet;
use std::fmt::Write as _;

use robovec_ir::{Function, Module, Operand, Value};

use super::body::Body;
use super::split::{part_name, part_prefix, Part, Plan};
use super::{interface, CodegenC, Emitted};
use crate::names::c_names;
use robovec_passes::PassError;

/// A Robotran function kind: the IR function name, Robotran's symbol and its output arrays.
struct Kind {
    ir: &'static str,
    symbol: &'static str,
    /// Output parameters `(C type, name)` before `MbsData *s, double tsim`.
    outputs: &'static [(&'static str, &'static str)],
}

const KINDS: &[Kind] = &[
    Kind { ir: "dirdyna", symbol: "mbs_dirdyna", outputs: &[("double **", "M"), ("double *", "c")] },
    Kind { ir: "invdyna", symbol: "mbs_invdyna", outputs: &[("double *", "Qq")] },
    Kind { ir: "cons_hJ", symbol: "mbs_cons_hJ", outputs: &[("double *", "h"), ("double **", "Jac")] },
    Kind { ir: "cons_jdqd", symbol: "mbs_cons_jdqd", outputs: &[("double *", "Jdqd")] },
    Kind {
        ir: "link",
        symbol: "mbs_link",
        outputs: &[
            ("double **", "frc"),
            ("double **", "trq"),
            ("double *", "Flnk"),
            ("double *", "Z"),
            ("double *", "Zd"),
        ],
    },
    Kind { ir: "link3D", symbol: "mbs_link3D", outputs: &[("double **", "frc"), ("double **", "trq")] },
    Kind { ir: "extforces", symbol: "mbs_extforces", outputs: &[("double **", "frc"), ("double **", "trq")] },
];

/// `MbsData` fields robovec's functions read (SPEC §2 names): `(name, number of indices)`.
pub const MBS_FIELDS: &[(&str, usize)] = &[
    ("q", 1),
    ("qd", 1),
    ("qdd", 1),
    ("m", 1),
    ("g", 1),
    ("lrod", 1),
    ("Qq", 1),
    ("dpt", 2),
    ("l", 2),
    ("In", 2),
    ("frc", 2),
    ("trq", 2),
];

/// `MbsSensor` fields (`sens.P[1]`…): `(name, number of indices)`.
pub const SENSOR_FIELDS: &[(&str, usize)] = &[("P", 1), ("V", 1), ("OM", 1), ("A", 1), ("OMP", 1), ("R", 2), ("J", 2)];

/// A minimal `mbs_data.h`: `MbsData` and `MbsSensor` with the fields of [`MBS_FIELDS`] and
/// [`SENSOR_FIELDS`] as Robotran's `mbs_data.h` declares them (`double *q; double **dpt;`,
/// 1-based: the caller allocates one more element per dimension), `double tsim` and
/// `int flag_stop` (set by `mbs_link3D`). Enough to
/// compile and call the `abi=robotran` code outside MBsysC (tests, benchmarks).
pub fn mbs_data_header() -> String {
    let field = |(n, dims): &(&str, usize)| format!("    double {}{n};\n", "*".repeat(*dims));
    let mut s = String::from(
        "/* Minimal MbsData and MbsSensor for robovec's abi=robotran code (fields as in Robotran's\n \
         * mbs_data.h: 1-based arrays, one extra element per dimension). */\n\
         #ifndef MBS_DATA_H\n#define MBS_DATA_H\n\ntypedef struct MbsData {\n    double tsim;\n    int flag_stop;\n",
    );
    MBS_FIELDS.iter().for_each(|f| s += &field(f));
    s += "} MbsData;\n\ntypedef struct MbsSensor {\n";
    SENSOR_FIELDS.iter().for_each(|f| s += &field(f));
    s += "} MbsSensor;\n\n#endif\n";
    s
}

/// `sensor_3` → (`mbs_sensor`, 3); `gensensor_3` → (`mbs_gensensor`, 3).
fn sensor(f: &Function) -> Option<(&'static str, u32)> {
    for (prefix, symbol) in [("sensor_", "mbs_sensor"), ("gensensor_", "mbs_gensensor")] {
        if let Some(k) = f.name.strip_prefix(prefix).and_then(|k| k.parse().ok()) {
            return Some((symbol, k));
        }
    }
    None
}

fn unknown(f: &Function) -> PassError {
    let known: Vec<&str> = KINDS.iter().map(|k| k.ir).chain(["sensor_N", "gensensor_N"]).collect();
    PassError::Failed {
        pass: "codegen".into(),
        message: format!(
            "@{}: no Robotran signature is known for this function (abi=robotran knows @{}); use abi=plain",
            f.name,
            known.join(", @")
        ),
    }
}

/// The Robotran symbol of `f` (`dirdyna` → `mbs_dirdyna`, `sensor_3` → `mbs_sensor`).
///
/// # Errors
/// [`PassError::Failed`] for a function kind with no known Robotran signature.
pub fn symbol(f: &Function) -> Result<String, PassError> {
    if let Some((s, _)) = sensor(f) {
        return Ok(s.to_string());
    }
    KINDS.iter().find(|k| k.ir == f.name).map(|k| k.symbol.to_string()).ok_or_else(|| unknown(f))
}

fn split_base(name: &str) -> (&str, &str) {
    let i = name.find('[').unwrap_or(name.len());
    (&name[..i], &name[i..])
}

/// The drop-in definition of `f` as `symbol` (split into parts of at most `o.chunk`
/// statements when it has `2·o.chunk` or more, `split.rs`; part names avoid `taken`, the file's other global names),
/// its prototype and its interface. A sensor gives a static function `robovec_<symbol>_<k>`;
/// [`sensor_dispatch`] writes the switch.
///
/// Split, the entry point stores every input the parts read into `live[]` before the first
/// part (reads first, as unsplit) and the last part writes the outputs after its statements
/// (writes last); each part takes the entry point's parameters and `double *restrict live`.
///
/// # Errors
/// [`PassError::Failed`] for a function kind with no known Robotran signature, an input that
/// is no `MbsData` field, an output that is no output parameter of the signature, or a
/// function of several states (`interleave`).
pub(crate) fn function(
    o: &CodegenC,
    f: &Function,
    symbol: &str,
    taken: &HashSet<String>,
    ticker: &robovec_passes::Ticker,
) -> Result<Emitted, PassError> {
    let fail =
        |message: String| PassError::Failed { pass: "codegen".into(), message: format!("@{}: {message}", f.name) };
    if f.states > 1 {
        return Err(fail(format!(
            "evaluates {} states (`interleave`), and a Robotran signature takes one MbsData: use abi=plain, whose \
             inputs and outputs are the states' in order",
            f.states
        )));
    }
    let sens = sensor(f);
    let (params, outs): (String, Vec<&str>) = match sens {
        Some(_) => ("MbsSensor *sens, MbsData *s".into(), vec!["sens"]),
        None => {
            let k = KINDS.iter().find(|k| k.ir == f.name).ok_or_else(|| unknown(f))?;
            let flink = f.outputs.iter().any(|x| split_base(&x.name).0 == "Flink");
            let list: Vec<(&str, &str)> =
                k.outputs.iter().map(|&(t, n)| if n == "Flnk" && flink { (t, "Flink") } else { (t, n) }).collect();
            let p: String = list.iter().map(|(t, n)| format!("{t}{n}, ")).collect();
            (format!("{p}MbsData *s, double tsim"), list.iter().map(|x| x.1).collect())
        }
    };
    let args = match sens {
        Some(_) => "sens, s".to_string(),
        None => outs.iter().map(|n| format!("{n}, ")).collect::<String>() + "s, tsim",
    };
    let mut reserved: Vec<&str> = vec!["s", "tsim", "sens", "isens", "live", symbol];
    reserved.extend(&outs);
    let callee_names = super::callbacks::callee_names(f);
    reserved.extend(callee_names.iter().map(String::as_str));
    let names = c_names(f, &reserved);
    let native = super::native::statements(&Body::new(o, f, &names, None, ticker))?;
    let b = Body::new(o, f, &names, Some(&native), ticker);
    let (defined, sig, proto) = match sens {
        Some((_, k)) => {
            let d = format!("robovec_{symbol}_{k}");
            let sig = format!("static void {d}({params})");
            (d, sig, String::new())
        }
        None => {
            let sig = format!("void {symbol}({params})");
            (
                symbol.to_string(),
                sig.clone(),
                format!("/* @{} as Robotran's {symbol} (drop-in). */\n{sig};\n\n", f.name),
            )
        }
    };
    let mut access = Vec::with_capacity(f.inputs.len());
    for &v in &f.inputs {
        let n = f.name_of(v);
        access.push(if n == "tsim" {
            if sens.is_some() {
                "s->tsim".to_string()
            } else {
                "tsim".to_string()
            }
        } else {
            let (base, _) = split_base(n);
            if !MBS_FIELDS.iter().any(|(x, _)| *x == base) {
                return Err(fail(format!("input `{n}` is no MbsData field (abi=robotran reads s->q, s->dpt, …)")));
            }
            format!("s->{n}")
        });
    }
    let mut lvalues = Vec::with_capacity(f.outputs.len());
    for out in &f.outputs {
        lvalues.push(match out.name.strip_prefix("sens.") {
            Some(rest) if sens.is_some() => format!("sens->{rest}"),
            None if out.name == "flag_stop" => "s->flag_stop".to_string(),
            _ if sens.is_none() && outs.contains(&split_base(&out.name).0) => out.name.clone(),
            _ => return Err(fail(format!("output `{}` is no output parameter of {symbol}", out.name))),
        });
    }
    let (order, attached) = b.order();
    let end_uses: Vec<Value> =
        f.outputs.iter().filter_map(|x| if let Operand::Value(v) = x.value { Some(v) } else { None }).collect();
    let plan = Plan::new(f, &order, &attached, o.chunk as usize, &f.inputs, &end_uses);
    let iface = interface(o, f, symbol);
    if plan.parts() == 1 {
        // `tsim`, `s` or an output array may go unread (as in Robotran's own file).
        let mut s = format!("/* @{} */\n{sig}\n{{\n{}", f.name, super::split::void_params(&sig));
        for (&v, a) in f.inputs.iter().zip(&access) {
            let _ = writeln!(s, "  const double {} = {a};", names[v.index()]);
        }
        b.statements_with(&order, &mut s, &mut |_, _| {}, &mut |_, _| {});
        for (out, lvalue) in f.outputs.iter().zip(&lvalues) {
            let _ = writeln!(s, "  {lvalue} = {};", b.operand(&out.value));
        }
        s += "}\n\n";
        return Ok(Emitted { entry: s, parts: Vec::new(), proto, iface });
    }
    // Split: part k has read value v from live[] when read[v] == k + 1.
    let mut read = vec![0u32; f.values.len()];
    let mut load = |s: &mut String, v: Value, k: usize| {
        if read[v.index()] != k as u32 + 1 && plan.reads_live(v, k) {
            read[v.index()] = k as u32 + 1;
            let _ = writeln!(s, "  const double {} = live[{}];", names[v.index()], plan.slot(v).expect("live"));
        }
    };
    let prefix = part_prefix(&defined, plan.parts(), taken);
    let mut parts = Vec::with_capacity(plan.parts());
    for k in 0..plan.parts() {
        let mut body = String::new();
        b.statements_with(
            &order[plan.bounds[k]..plan.bounds[k + 1]],
            &mut body,
            &mut |s, v| f.value(v).def.for_each_value(|a| load(s, a, k)),
            &mut |s, v| {
                if let Some(slot) = plan.slot(v) {
                    let _ = writeln!(s, "  live[{slot}] = {};", names[v.index()]);
                }
            },
        );
        if k + 1 == plan.parts() {
            // Every operand is read before the first write (the outputs may alias MbsData
            // fields; the live values never do).
            for v in &end_uses {
                load(&mut body, *v, k);
            }
            for (out, lvalue) in f.outputs.iter().zip(&lvalues) {
                let _ = writeln!(body, "  {lvalue} = {};", b.operand(&out.value));
            }
        }
        parts.push(Part {
            signature: format!("ROBOVEC_NOINLINE void {}({params}, double *restrict live)", part_name(&prefix, k)),
            body,
            ops: plan.bounds[k + 1] - plan.bounds[k],
        });
    }
    let mut s = format!(
        "/* @{}: {} parts */\n{sig}\n{{\n  /* Inputs (read first) and values computed in one part and read in a later one. */\n  \
         double live[{}];\n",
        f.name,
        plan.parts(),
        plan.slots.max(1)
    );
    for (&v, a) in f.inputs.iter().zip(&access) {
        if let Some(slot) = plan.slot(v) {
            let _ = writeln!(s, "  live[{slot}] = {a};");
        }
    }
    for k in 0..plan.parts() {
        let _ = writeln!(s, "  {}({args}, live);", part_name(&prefix, k));
    }
    s += "}\n\n";
    Ok(Emitted { entry: s, parts, proto, iface })
}

/// The `mbs_sensor`/`mbs_gensensor` functions that switch on `isens` to the sensors of `m`,
/// and their prototypes (empty when `m` has no sensor).
pub fn sensor_dispatch(m: &Module, symbol_of: impl Fn(&Function) -> String) -> (String, String) {
    let mut groups: Vec<(String, Vec<u32>)> = Vec::new();
    for f in &m.functions {
        if let Some((_, k)) = sensor(f) {
            let sym = symbol_of(f);
            match groups.iter_mut().find(|(s, _)| *s == sym) {
                Some((_, ks)) => ks.push(k),
                None => groups.push((sym, vec![k])),
            }
        }
    }
    let (mut code, mut proto) = (String::new(), String::new());
    for (sym, ks) in groups {
        let sig = format!("void {sym}(MbsSensor *sens, MbsData *s, int isens)");
        let _ = write!(code, "{sig}\n{{\n  switch (isens) {{\n");
        for k in ks {
            let _ = writeln!(code, "  case {k}: robovec_{sym}_{k}(sens, s); break;");
        }
        code += "  default: break;\n  }\n}\n\n";
        let _ = write!(proto, "/* Robotran's {sym} (drop-in): sensor isens. */\n{sig};\n\n");
    }
    (code, proto)
}
