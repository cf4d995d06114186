//! `specialize<params=FILE.json>`: folds model parameters whose values are known, then drops
//! dead code. Without `params`, only what is already constant folds.
//!
//! Phase: atomised → atomised. `FILE.json` is an object of canonical input name → number, the
//! names and format of `-eval` (SPEC §2, §7: `{"dpt[3][5]": 0, "m[2]": 1.5}`). Every input it
//! names becomes that constant, then, in body order:
//! - an op or `sqrt` on constants folds to its value (computed in f64; kept as an op when the
//!   value is not finite, e.g. a division by zero);
//! - `sin`/`cos` of a known coordinate folds;
//! - `x·0`, `0·x`, `0 / x` → 0; `x·1`, `1·x`, `x / 1` → x; `x + 0`, `0 + x`, `x − 0` → x;
//!   `0 − x` stays (a sign for `zero-removal`) unless `x` is known;
//! - user callbacks stay (they are opaque).
//!
//! Then `dce` drops what no output reads (the known inputs among it). So a model where
//! `dpt[3][5] = 0` loses every term that parameter multiplies. Numerics: folding in f64 changes
//! rounding against a binary32 evaluation of the original only by the rounding of the folded
//! constants; `x·0 → 0` assumes a finite `x` (IEEE gives NaN for ±∞ and −0 for negative `x`).
//! Names in the file that are not inputs of a function are reported on the `-stats` line.
//!
//! # Errors
//! A file that cannot be read or is not such a JSON object: [`PassError::Failed`] naming the
//! file, line and column (exit status 1). Cost: O(values + operands) plus `dce`'s.

use std::collections::BTreeMap;

use robovec_ir::{BinOp, Def, Function, Module, Operand, TrigFn};

use crate::dce::Dce;
use crate::params::ParamKind;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "specialize",
    doc: "fold model parameters of known value (JSON file, -eval format), simplify x*0, x*1, x+0, then dce",
    params: &[ParamInfo {
        name: "params",
        kind: ParamKind::Path,
        doc: "JSON file: object of canonical input name -> number, e.g. {\"dpt[3][5]\": 0}; without it only constants fold",
    }],
    build: |p: &Params| Ok(Box::new(Specialize { path: p.path("params")? })),
    props: crate::Props { requires: Some(robovec_ir::Phase::Atomised), ..crate::Props::DEFAULT },
};

/// The `specialize` pass.
#[derive(Debug)]
pub struct Specialize {
    /// Path of the JSON parameter file; `None`: no known parameter (constants still fold).
    pub path: Option<String>,
}

/// Reads a parameter file: JSON object of input name → number.
///
/// # Errors
/// [`PassError::Failed`] naming the file and what is wrong.
pub fn read_params(path: &str) -> Result<BTreeMap<String, f64>, PassError> {
    let fail = |message: String| PassError::Failed { pass: "specialize".into(), message };
    let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read `{path}`: {e}")))?;
    serde_json::from_str::<BTreeMap<String, f64>>(&text).map_err(|e| {
        fail(format!(
            "`{path}` line {}, column {}: {e}; expected a JSON object of input name -> number, e.g. {{\"dpt[3][5]\": 0}}",
            e.line(),
            e.column()
        ))
    })
}

impl Pass for Specialize {
    fn name(&self) -> &'static str {
        "specialize"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let params = match &self.path {
            Some(path) => read_params(path)?,
            None => BTreeMap::new(),
        };
        let unused: Vec<&str> = params
            .keys()
            .filter(|k| !m.functions.iter().any(|f| f.lookup(k).is_some_and(|v| matches!(f.value(v).def, Def::Input))))
            .map(String::as_str)
            .collect();
        // `-time-limit`: required (it changes what a function takes); one linear sweep per
        // function, so the clock is read between functions (and by `dce` after).
        let parts = try_each_function(
            m,
            cx,
            "specialize",
            AtTimeLimit::Required,
            Before::Clock,
            |_, _| None,
            |f, _, _| {
                let before = f.op_counts().total;
                let known = specialize_function(f, &params);
                Ok(Step::Done((f.name.clone(), before, known)))
            },
        )?;
        Dce { keep: None }.run(m, cx)?;
        let mut line = Vec::new();
        for ((name, before, known), f) in parts.into_iter().zip(&m.functions) {
            line.push(format!("@{name}: {known} inputs known, ops {before} -> {}", f.op_counts().total));
        }
        let mut note = format!("specialize<params={}>: {}", self.path.as_deref().unwrap_or("none"), line.join("; "));
        if !unused.is_empty() {
            note += &format!("; {} given names are not inputs: {}", unused.len(), unused.join(", "));
        }
        cx.remark("specialize", m, note);
        Ok(())
    }
}

/// Folds the inputs of `f` named in `params` and simplifies (see the module doc); dead values
/// stay for `dce`. Returns how many inputs were known.
pub fn specialize_function(f: &mut Function, params: &BTreeMap<String, f64>) -> usize {
    let mut map: Vec<Operand> =
        (0..f.values.len() as u32).map(|i| Operand::Value(robovec_ir::Value::with_number(i))).collect();
    let mut known = 0;
    for &v in &f.inputs {
        if let Some(&x) = params.get(f.name_of(v)) {
            if x.is_finite() {
                map[v.index()] = Operand::Const(x);
                known += 1;
            }
        }
    }
    let m = |o: Operand, map: &[Operand]| match o {
        Operand::Value(x) => map[x.index()],
        c => c,
    };
    for i in 0..f.body.len() {
        let v = f.body[i];
        let def = f.value(v).def.clone();
        let (def, to) = match def {
            Def::Trig(t, a) => match map[a.index()] {
                Operand::Const(x) => (None, Some(Operand::Const(if t == TrigFn::Sin { x.sin() } else { x.cos() }))),
                _ => (None, None),
            },
            Def::Binary(op, a, b) => {
                let (a, b) = (m(a, &map), m(b, &map));
                (Some(Def::Binary(op, a, b)), simplify(op, a, b))
            }
            Def::Call(c, args) => {
                let args: Vec<Operand> = args.into_iter().map(|o| m(o, &map)).collect();
                // An intrinsic of constants folds (a non-finite result, e.g. `sqrt` of a
                // negative constant, stays a call: see below).
                let consts: Option<Vec<f64>> =
                    args.iter().map(|a| if let Operand::Const(x) = a { Some(*x) } else { None }).collect();
                let to = match (robovec_ir::Intrinsic::of(&c, args.len()), consts) {
                    (Some(i), Some(xs)) => Some(Operand::Const(i.eval(&xs))),
                    _ => None,
                };
                (Some(Def::Call(c, args)), to)
            }
            _ => (None, None),
        };
        match to {
            Some(o) if !matches!(o, Operand::Const(c) if !c.is_finite()) => map[v.index()] = o,
            _ => {
                if let Some(def) = def {
                    f.value_mut(v).def = def;
                }
            }
        }
    }
    for o in &mut f.outputs {
        o.value = m(o.value, &map);
    }
    f.clear_timing();
    known
}

/// The operand `a op b` simplifies to, if any.
fn simplify(op: BinOp, a: Operand, b: Operand) -> Option<Operand> {
    let is = |o: Operand, k: f64| matches!(o, Operand::Const(c) if c == k);
    match (op, a, b) {
        (_, Operand::Const(x), Operand::Const(y)) => Some(Operand::Const(robovec_ir::interp::eval_binop(op, x, y))),
        (BinOp::Mul, _, _) if is(a, 0.0) || is(b, 0.0) => Some(Operand::Const(0.0)),
        (BinOp::Mul, _, _) if is(a, 1.0) => Some(b),
        (BinOp::Mul | BinOp::Div, _, _) if is(b, 1.0) => Some(a),
        (BinOp::Div, _, _) if is(a, 0.0) => Some(Operand::Const(0.0)),
        (BinOp::Add, _, _) if is(a, 0.0) => Some(b),
        (BinOp::Add | BinOp::Sub, _, _) if is(b, 0.0) => Some(a),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    #[test]
    fn hand_computed_folding() {
        // x = a*b + c*d - e, y = 0 - d*a, z = sqrt(c*c + a); a = 2, c = 0, e = 1.5:
        // x = 2*b - 1.5 (c*d vanishes), y = 0 - d*2, z = sqrt(2) folds.
        let mut m = parse(
            "func @f { phase atomised input %a input %b input %c input %d input %e
              %x.1 = mul %a, %b %x.2 = mul %c, %d %x.3 = add %x.1, %x.2 %x = sub %x.3, %e
              %y.1 = mul %d, %a %y = sub 0.0, %y.1
              %z.1 = mul %c, %c %z.2 = add %z.1, %a %z = call @sqrt(%z.2)
              output o1 = %x output o2 = %y output o3 = %z }",
        )
        .unwrap();
        let params: BTreeMap<String, f64> =
            [("a", 2.0), ("c", 0.0), ("e", 1.5)].iter().map(|(k, v)| (k.to_string(), *v)).collect();
        let f = &mut m.functions[0];
        assert_eq!(specialize_function(f, &params), 3);
        Dce { keep: None }.run(&mut m, &mut PassContext::default()).unwrap();
        let f = &m.functions[0];
        let text = f.to_string();
        let body: Vec<&str> =
            text.lines().map(str::trim).filter(|l| l.starts_with('%') || l.starts_with("output")).collect();
        assert_eq!(
            body,
            [
                "%x.1 = mul 2.0, %b",
                "%x = sub %x.1, 1.5",
                "%y.1 = mul %d, 2.0",
                "%y = sub 0.0, %y.1",
                "output o1 = %x",
                "output o2 = %y",
                &format!("output o3 = {:?}", 2f64.sqrt()),
            ]
        );
        assert_eq!(f.inputs.len(), 2, "only b and d remain inputs");
    }
}
