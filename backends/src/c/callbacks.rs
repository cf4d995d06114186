//! User callbacks: the calls of a function that are neither intrinsics nor trig, named as
//! Robotran names them (`user_ExtForces.1` is `user_ExtForces` with one integer argument), and
//! their declarations in the generated files.

use std::fmt::Write as _;

use robovec_ir::{Callee, Def, Module};

use super::is_intrinsic;
use robovec_passes::PassError;

/// A user callback the generated code calls: Robotran's name without the integer arguments
/// the IR appends (`user_ExtForces.1` → `user_ExtForces`, one index).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Callback {
    /// The C name (`user_ExtForces`).
    pub base: String,
    /// How many integer arguments of the source call the IR appended to the name (`.1`).
    pub indices: usize,
}

/// The C names of the callbacks `f` calls (one per call op, in body order): names the emitter
/// must not give to a value.
pub fn callee_names(f: &robovec_ir::Function) -> Vec<String> {
    f.body
        .iter()
        .filter_map(|&v| match &f.value(v).def {
            robovec_ir::Def::Call(c, _) => split_callee(c).ok().map(|(b, _)| b),
            _ => None,
        })
        .collect()
}

/// The C name and integer arguments of a callback: `user_ExtForces.1` → (`user_ExtForces`,
/// `[1]`); Matlab's `usrfun.flink.1` → (`usrfun_flink`, `[1]`) (the trailing integer segments
/// are the source call's integer arguments, the others part of the name).
///
/// # Errors
/// [`PassError::Failed`] when what is left is not a C identifier.
pub fn split_callee(c: &Callee) -> Result<(String, Vec<i64>), PassError> {
    let parts: Vec<&str> = c.name.split('.').collect();
    let n_idx = parts.iter().rev().take_while(|p| p.parse::<i64>().is_ok()).count().min(parts.len() - 1);
    let base = parts[..parts.len() - n_idx].join("_");
    let idx: Vec<i64> = parts[parts.len() - n_idx..].iter().map(|p| p.parse().expect("checked")).collect();
    if crate::names::is_c_identifier(&base) {
        Ok((base, idx))
    } else {
        Err(PassError::Failed {
            pass: "codegen".into(),
            message: format!("callee `@{}` is not a C name followed by integer arguments (`user_X.1`)", c.name),
        })
    }
}

/// Every user callback of `m`, in order of first use.
///
/// # Errors
/// [`PassError::Failed`] when a callee is not a C name, or one name is called with two
/// different numbers of integer arguments (C has one signature per name).
pub(crate) fn callbacks(m: &Module) -> Result<Vec<Callback>, PassError> {
    let mut out: Vec<Callback> = Vec::new();
    for f in &m.functions {
        for &v in &f.body {
            if let Def::Call(c, args) = &f.value(v).def {
                if is_intrinsic(c, args.len()) {
                    continue;
                }
                let (base, idx) = split_callee(c)?;
                match out.iter().find(|k| k.base == base) {
                    Some(k) if k.indices != idx.len() => {
                        return Err(PassError::Failed {
                            pass: "codegen".into(),
                            message: format!(
                                "callback `{base}` is called with {} and with {} integer arguments",
                                k.indices,
                                idx.len()
                            ),
                        })
                    }
                    Some(_) => {}
                    None => out.push(Callback { base, indices: idx.len() }),
                }
            }
        }
    }
    Ok(out)
}

/// The extern declarations of the callbacks (also in the header).
pub(crate) fn callback_decls(cbs: &[Callback], real: &str) -> String {
    if cbs.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "/* User callbacks, defined by the user (Robotran's names). A call `user_X(i1, …, elem, n, args)`\n \
         * returns element `elem` (1-based; 0 for a scalar result) of Robotran's `user_X(…, i1, …)` for the\n \
         * n {real} arguments args[0..n] (the numbers the Robotran call reads, in robovec's IR order). */\n"
    );
    for k in cbs {
        let idx: String = (1..=k.indices).map(|i| format!("int index{i}, ")).collect();
        let _ = writeln!(s, "extern {real} {}({idx}int elem, int nargs, const {real} *args);", k.base);
    }
    s.push('\n');
    s
}
