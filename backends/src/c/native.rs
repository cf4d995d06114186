//! `abi=robotran`: user callbacks called with Robotran's (MBsysC's) native signatures, so the
//! drop-in links against the user's own callback definitions (issue 11).
//!
//! The C front end flattens `SWr1 = user_ExtForces(PxF1,RxF1,VxF1,OMxF1,AxF1,OMPxF1,s,tsim,1);`
//! into one `call @user_ExtForces.1[k](…)` per element `k` read (`SWr1[k]`), whose operands are
//! the elements of each local array in row-major order (`PxF1[1..3]`, `RxF1[1][1]`,
//! `RxF1[1][2]`, …, `RxF1[3][3]`, `VxF1[1..3]`, `OMxF1[1..3]`, `AxF1[1..3]`, `OMPxF1[1..3]`),
//! then `tsim`; `s` is dropped and the trailing integer is appended to the name (`.1`). The
//! drop-in rebuilds the arrays (1-based, index 0 zero), makes ONE native call per distinct
//! callee and index at the position of its first element, and each element becomes
//! `x = SWr1[k];`, read right after the call: the later elements are *attached* to the first
//! ([`Native::lead`], [`super::body::Body::order`]), so the call's result is read before any
//! other call can reuse the user's result array, and a function split into parts
//! ([`super::split`]) never needs the result pointer in another part. A scalar callback (`user_LinkForces(Z1,Zd1,s,tsim,1)`, IR operands `Z1, Zd1,
//! tsim`) is one direct call per IR call, as in Robotran's source.
//!
//! The prototypes ([`prototypes`]) are MBsysC's own (`mbs_project_interface.h`); they are
//! written in the generated files inside `#ifndef ROBOVEC_NO_USER_CALLBACK_PROTOTYPES`, so a
//! project whose headers already declare them may leave them out (identical redeclarations
//! are also valid C).

use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;

use robovec_ir::{Def, Function, Module, Operand, Value};

use super::body::{Body, Native};
use super::callbacks::{callee_names, split_callee, Callback};
use super::is_intrinsic;
use robovec_passes::PassError;

/// The local arrays of a vector callback, `(name prefix, number of indices)`, in the order of
/// the native signature (and of the IR's operands).
const EXT_ARRAYS: &[(&str, usize)] = &[("PxF", 1), ("RxF", 2), ("VxF", 1), ("OMxF", 1), ("AxF", 1), ("OMPxF", 1)];

/// A native callback signature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Shape {
    /// `double *NAME(double PxF[4], double RxF[4][4], …, MbsData *s, double tsim, int ixF)`:
    /// 25 IR operands (24 array elements, then `tsim`), result `SWr[1..9]`.
    ExtForces,
    /// `double NAME(double Z, double Zd, MbsData *s, double tsim, int ilnk)`: 3 IR operands.
    LinkForces,
}

impl Shape {
    fn of(base: &str) -> Option<Shape> {
        match base {
            "user_ExtForces" | "user_call_ExtForces" => Some(Shape::ExtForces),
            "user_LinkForces" | "user_call_LinkForces" => Some(Shape::LinkForces),
            _ => None,
        }
    }

    fn operands(self) -> usize {
        match self {
            Shape::ExtForces => EXT_ARRAYS.iter().map(|&(_, d)| 3usize.pow(d as u32)).sum::<usize>() + 1,
            Shape::LinkForces => 3,
        }
    }

    fn prototype(self, base: &str) -> String {
        match self {
            Shape::ExtForces => format!(
                "double *{base}(double PxF[4], double RxF[4][4], double VxF[4], double OMxF[4], double AxF[4], \
                 double OMPxF[4], MbsData *s, double tsim, int ixF);"
            ),
            Shape::LinkForces => format!("double {base}(double Z, double Zd, MbsData *s, double tsim, int ilnk);"),
        }
    }
}

fn fail(f: &Function, message: String) -> PassError {
    PassError::Failed { pass: "codegen".into(), message: format!("@{}: {message}", f.name) }
}

/// The native prototypes of the callbacks `cbs` (`m`'s, [`super::callbacks::callbacks`]),
/// guarded (empty without callbacks).
///
/// # Errors
/// [`PassError::Failed`] for a callback with no known native signature, naming the first
/// function of `m` that calls it.
pub(crate) fn prototypes(m: &Module, cbs: &[Callback]) -> Result<String, PassError> {
    let bases: Vec<&str> = cbs.iter().map(|k| k.base.as_str()).collect();
    if let Some(&base) = bases.iter().find(|b| Shape::of(b).is_none()) {
        let caller = m.functions.iter().find(|f| callee_names(f).iter().any(|n| n == base)).unwrap_or(&m.functions[0]);
        return Err(unknown(caller, base));
    }
    if bases.is_empty() {
        return Ok(String::new());
    }
    let mut s = String::from(
        "/* User callbacks with MBsysC's own signatures (mbs_project_interface.h), defined by the user.\n \
         * Define ROBOVEC_NO_USER_CALLBACK_PROTOTYPES when another header declares them. */\n\
         #ifndef ROBOVEC_NO_USER_CALLBACK_PROTOTYPES\n",
    );
    for b in &bases {
        let _ = writeln!(s, "{}", Shape::of(b).expect("checked").prototype(b));
    }
    s += "#endif\n\n";
    Ok(s)
}

fn unknown(f: &Function, base: &str) -> PassError {
    fail(
        f,
        format!(
            "callback `{base}` has no known Robotran signature (abi=robotran knows user_ExtForces, \
             user_LinkForces, user_call_ExtForces, user_call_LinkForces); use abi=plain"
        ),
    )
}

/// The C statements of every user callback of `f` with the native signatures.
///
/// # Errors
/// [`PassError::Failed`] for a callback with no known native signature, a number of
/// operands or an element that does not fit it, or elements of one call with different
/// operands.
pub(crate) fn statements(b: &Body<'_>) -> Result<Native, PassError> {
    let f = b.f;
    let mut taken: HashSet<String> = b.names.iter().cloned().collect();
    let mut fresh = |want: String| {
        let mut n = want;
        while taken.contains(&n) {
            n.push_str("_cb");
        }
        taken.insert(n.clone());
        n
    };
    // (base, index) → (result array name, operands of the first element, the first element).
    let mut done: HashMap<(String, i64), (String, &[Operand], Value)> = HashMap::new();
    let mut out = HashMap::new();
    let mut lead = HashMap::new();
    for &v in &f.body {
        let Def::Call(c, args) = &f.value(v).def else { continue };
        if is_intrinsic(c, args.len()) {
            continue;
        }
        let (base, idx) = split_callee(c)?;
        let shape = Shape::of(&base).ok_or_else(|| unknown(f, &base))?;
        let [ix] = idx[..] else {
            return Err(fail(f, format!("callback `@{}`: Robotran's {base} takes one integer index", c.name)));
        };
        if args.len() != shape.operands() {
            return Err(fail(
                f,
                format!(
                    "callback `@{}` has {} operands; Robotran's {base} takes {} (whole arrays PxF, RxF, … then tsim)",
                    c.name,
                    args.len(),
                    shape.operands()
                ),
            ));
        }
        let name = &b.names[v.index()];
        let mut s = String::new();
        match shape {
            Shape::LinkForces => {
                if c.elem.is_some() {
                    return Err(fail(f, format!("callback `@{}` returns one number, not a vector", c.name)));
                }
                let _ = writeln!(
                    s,
                    "  const double {name} = {base}({}, {}, s, {}, {ix});",
                    b.operand(&args[0]),
                    b.operand(&args[1]),
                    b.operand(&args[2])
                );
            }
            Shape::ExtForces => {
                let elem = match c.elem {
                    Some(e @ 1..=9) => e,
                    _ => return Err(fail(f, format!("callback `@{}` reads no element 1..9 of SWr", c.name))),
                };
                let key = (base.clone(), ix);
                match done.get(&key) {
                    Some((res, first, first_value)) => {
                        if *first != &args[..] {
                            return Err(fail(
                                f,
                                format!(
                                    "the elements of callback `{base}(…, {ix})` have different operands; \
                                     one native call cannot give them (use abi=plain)"
                                ),
                            ));
                        }
                        let _ = writeln!(s, "  const double {name} = {res}[{elem}];");
                        lead.insert(v.index(), *first_value);
                    }
                    None => {
                        let mut it = args.iter();
                        let mut arrays = Vec::new();
                        for &(prefix, dims) in EXT_ARRAYS {
                            let a = fresh(format!("{prefix}{ix}"));
                            if dims == 1 {
                                let _ = writeln!(s, "  double {a}[4] = {{0}};");
                                for i in 1..=3 {
                                    let x = b.operand(it.next().expect("counted"));
                                    let _ = writeln!(s, "  {a}[{i}] = {x};");
                                }
                            } else {
                                let _ = writeln!(s, "  double {a}[4][4] = {{{{0}}}};");
                                for i in 1..=3 {
                                    for j in 1..=3 {
                                        let x = b.operand(it.next().expect("counted"));
                                        let _ = writeln!(s, "  {a}[{i}][{j}] = {x};");
                                    }
                                }
                            }
                            arrays.push(a);
                        }
                        let tsim = b.operand(it.next().expect("counted"));
                        let res = fresh(format!("SWr{ix}"));
                        let _ = writeln!(s, "  double *{res} = {base}({}, s, {tsim}, {ix});", arrays.join(", "));
                        let _ = writeln!(s, "  const double {name} = {res}[{elem}];");
                        done.insert(key, (res, &args[..], v));
                    }
                }
            }
        }
        out.insert(v.index(), s);
    }
    Ok(Native { statements: out, lead })
}
