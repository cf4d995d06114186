//! An interpreter for any function, in either phase, in `f64` or `f32`, in exactly the IR's
//! operation order (each `+ - * /` rounded once in the chosen precision, left operand first).
//!
//! Semantics:
//! - an input takes the value given by name, converted to the precision (`f64 as f32`);
//! - `sin`/`cos` trig variables are computed in the precision from their input;
//! - a unary minus in a parsed expression is IEEE negation (what the Robotran C code does);
//!   `atomise` turns it into `0 - x`, which differs only in the sign of a zero result;
//! - `call @sqrt(x)` is the square root; any other callee is a user callback, which robovec
//!   cannot see: it is evaluated by a documented stand-in, [`callback_standin`], so that every
//!   phase of the same function computes the same numbers.

pub use crate::float::Float;
use crate::function::Function;
use crate::syntax::{BinOp, Callee, Def, Expr, Operand, TrigFn};

/// The stand-in for an opaque user callback: `Σ_k w_k · a_k` summed left to right, with
/// weights `w_k ∈ {-1, -7/8, …, 1}` (exact in binary32) derived from the callee name, element
/// and argument position by FNV-1a. With no argument it is the constant `w_0`.
pub fn callback_standin<T: Float>(callee: &Callee, args: &[T]) -> T {
    let weight = |k: usize| {
        let mut h: u64 = 0xcbf29ce484222325;
        let mut eat = |b: u8| {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        };
        callee.name.bytes().for_each(&mut eat);
        callee.elem.unwrap_or(0).to_le_bytes().into_iter().for_each(&mut eat);
        (k as u64).to_le_bytes().into_iter().for_each(&mut eat);
        T::from_f64(((h % 17) as f64 - 8.0) / 8.0)
    };
    if args.is_empty() {
        return weight(0);
    }
    let mut acc = weight(0) * args[0];
    for (k, a) in args.iter().enumerate().skip(1) {
        acc = acc + weight(k) * *a;
    }
    acc
}

/// Evaluates a call in precision `T`.
pub fn eval_call<T: Float>(callee: &Callee, args: &[T]) -> T {
    match crate::intrinsic::Intrinsic::of(callee, args.len()) {
        Some(i) => i.eval(args),
        None => callback_standin(callee, args),
    }
}

/// Applies a binary operator in precision `T`.
pub fn eval_binop<T: Float>(op: BinOp, a: T, b: T) -> T {
    match op {
        BinOp::Add => a + b,
        BinOp::Sub => a - b,
        BinOp::Mul => a * b,
        BinOp::Div => a / b,
    }
}

/// Values of every value of `f` (indexed by `Value::index()`), computed in precision `T`.
///
/// `input(name)` gives each input's value in `f64`. Panics only if `f` does not verify (a value
/// read before its definition).
pub fn eval_values<T: Float>(f: &Function, mut input: impl FnMut(&str) -> f64) -> Vec<T> {
    let mut vals: Vec<Option<T>> = vec![None; f.values.len()];
    for &v in &f.inputs {
        vals[v.index()] = Some(T::from_f64(input(f.name_of(v))));
    }
    for &v in &f.body {
        let get = |o: &Operand| match o {
            Operand::Value(x) => vals[x.index()].expect("value read before definition"),
            Operand::Const(c) => T::from_f64(*c),
        };
        vals[v.index()] = Some(eval_def(&f.value(v).def, get));
    }
    vals.into_iter().map(|x| x.unwrap_or(T::from_f64(f64::NAN))).collect()
}

/// One body value's definition computed in precision `T` from its operands (`get`; a trig
/// argument is read as `Operand::Value`). Panics on [`Def::Input`], which has no definition.
pub fn eval_def<T: Float>(def: &Def, get: impl Fn(&Operand) -> T) -> T {
    match def {
        Def::Input => unreachable!("inputs are not in the body"),
        Def::Trig(t, a) => {
            let x = get(&Operand::Value(*a));
            match t {
                TrigFn::Sin => x.sin(),
                TrigFn::Cos => x.cos(),
            }
        }
        Def::Binary(op, a, b) => eval_binop(*op, get(a), get(b)),
        Def::Call(c, args) => {
            let a: Vec<T> = args.iter().map(&get).collect();
            eval_call(c, &a)
        }
        Def::Expr(e) => eval_expr(e, &get),
    }
}

fn eval_expr<T: Float>(e: &Expr, get: &impl Fn(&Operand) -> T) -> T {
    match e {
        Expr::Operand(o) => get(o),
        Expr::Neg(x) => -eval_expr(x, get),
        Expr::Binary(op, a, b) => {
            let a = eval_expr(a, get);
            eval_binop(*op, a, eval_expr(b, get))
        }
        Expr::Call(c, args) => {
            let a: Vec<T> = args.iter().map(|x| eval_expr(x, get)).collect();
            eval_call(c, &a)
        }
    }
}

/// Outputs of `f` in precision `T`, in output order: `(name, value)`.
pub fn eval<T: Float>(f: &Function, input: impl FnMut(&str) -> f64) -> Vec<(String, T)> {
    let vals = eval_values::<T>(f, input);
    f.outputs
        .iter()
        .map(|o| {
            let x = match o.value {
                Operand::Value(v) => vals[v.index()],
                Operand::Const(c) => T::from_f64(c),
            };
            (o.name.clone(), x)
        })
        .collect()
}

/// Deterministic pseudo-random value in [-1, 1) for input `name` under `seed` (the first draw of
/// [`crate::rng::SplitMix64`] seeded with an FNV-1a hash); used for inputs a user does not give
/// (SPEC §7 `-eval`).
pub fn pseudo_random_input(name: &str, seed: u64) -> f64 {
    let mut h: u64 = 0xcbf29ce484222325 ^ seed;
    for b in name.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x100000001b3);
    }
    crate::rng::SplitMix64::new(h).unit() * 2.0 - 1.0
}
