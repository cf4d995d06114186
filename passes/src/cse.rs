//! `cse`: common-subexpression elimination by local value numbering over the one basic block.
//!
//! Robotran's equations compute the same product or sum more than once (coman_longarms'
//! `dirdyna`: 5 364 of its 33 545 atomised ops repeat an earlier op). Two ops with the same
//! operator on the same operands compute the same bits, so the later one is dropped and its users
//! (ops and outputs) read the earlier one. `a + b` and `b + a`, `a * b` and `b * a` are the same
//! op: IEEE 754 addition and multiplication are commutative exactly (IEEE 754-2019 §6.3 / §5.4.1:
//! the result is the exact result rounded, whatever the operand order), so every output keeps
//! its value bit for bit and its error against the original equations. `-` and `/` keep their
//! operand order; `sin`/`cos` of one input merge; calls are never merged (a user callback is
//! the user's code). Constants are compared by their bits (`-0.0` is not `0.0`).
//!
//! Why a pass when a C compiler does the same: the passes after it see the DAG the hardware
//! runs. `place` puts fewer ops on the PEs (fewer cycles at small N), and `schedule-cpu`
//! orders the DAG whose live ranges GCC allocates, instead of one where a merged op looks dead
//! long before GCC's copy of it is.
//!
//! Works in both phases (nested expressions of the parsed phase are not merged, only their
//! operands renamed). Clears timing attributes. Cost: O(values + operands) expected (hashing).

use std::collections::HashMap;

use robovec_ir::{BinOp, Def, Function, Module, Operand, TrigFn, Value};

use crate::{AtTimeLimit, Params, Pass, PassContext, PassError, PassInfo, Ticker};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "cse",
    doc: "common-subexpression elimination: an op equal to an earlier one (same operator, same operands; + and * commutative) is dropped, its users read the earlier one (bit-exact)",
    params: &[],
    build: |_: &Params| Ok(Box::new(Cse)),
};

/// The `cse` pass.
#[derive(Debug)]
pub struct Cse;

/// An operand as a hash key: a value's number or a constant's bits.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Key {
    Value(u32),
    Const(u64),
}

fn key(o: &Operand) -> Key {
    match o {
        Operand::Value(v) => Key::Value(v.index() as u32),
        Operand::Const(c) => Key::Const(c.to_bits()),
    }
}

/// What makes two definitions the same op.
#[derive(PartialEq, Eq, Hash)]
enum OpKey {
    Binary(BinOp, Key, Key),
    Trig(TrigFn, u32),
}

fn op_key(def: &Def) -> Option<OpKey> {
    match def {
        Def::Binary(op, a, b) => {
            let (mut x, mut y) = (key(a), key(b));
            let commutative = matches!(op, BinOp::Add | BinOp::Mul);
            if commutative && y < x {
                std::mem::swap(&mut x, &mut y);
            }
            Some(OpKey::Binary(*op, x, y))
        }
        Def::Trig(t, v) => Some(OpKey::Trig(*t, v.index() as u32)),
        Def::Input | Def::Call(..) | Def::Expr(_) => None,
    }
}

/// Merges the repeated ops of `f`; returns how many were dropped.
pub fn cse_function(f: &mut Function) -> usize {
    cse_within(f, &Ticker::default())
}

/// [`cse_function`] that stops looking for repeats when `ticker` says so (`-time-limit`; one
/// tick per value): the merges found so far are kept, the later ops only read the merged
/// values (a renaming, without hashing).
pub fn cse_within(f: &mut Function, ticker: &Ticker) -> usize {
    let mut repr: Vec<Value> = (0..f.values.len()).map(|i| Value::with_number(i as u32)).collect();
    let mut dropped = vec![false; f.values.len()];
    let mut table: HashMap<OpKey, Value> = HashMap::with_capacity(f.body.len());
    let body = f.body.clone();
    for v in body {
        // Operands first: a merged operand makes two later ops equal.
        let def = &mut f.value_mut(v).def;
        def.map_values(&|x| repr[x.index()]);
        if ticker.tick() {
            continue;
        }
        if let Some(k) = op_key(def) {
            match table.get(&k) {
                Some(&first) => {
                    repr[v.index()] = first;
                    dropped[v.index()] = true;
                }
                None => {
                    table.insert(k, v);
                }
            }
        }
    }
    let n = dropped.iter().filter(|&&d| d).count();
    if n > 0 {
        for o in &mut f.outputs {
            if let Operand::Value(v) = o.value {
                o.value = Operand::Value(repr[v.index()]);
            }
        }
        f.retain(|_, v| !dropped[v.index()]);
        f.clear_timing();
    }
    n
}

/// How many ops (binary ops; merged `sin`/`cos` are not ops) [`cse_function`] would drop from
/// `f`, without changing `f`: what the URDF generator needs to compare two formulations by
/// their ops after `atomise,cse` (issue 47: no copy to rewrite and free). `None` when `ticker`
/// (one tick per value) says stop. Cost: O(values) expected (hashing), no rebuild.
pub fn cse_drops_until(f: &Function, ticker: &Ticker) -> Option<u64> {
    let mut repr: Vec<Value> = (0..f.values.len()).map(|i| Value::with_number(i as u32)).collect();
    let mut table: HashMap<OpKey, Value> = HashMap::with_capacity(f.body.len());
    let mut drops = 0;
    for &v in &f.body {
        if ticker.tick() {
            return None;
        }
        // The definition as `cse_within` sees it: operands read through the merges so far.
        let m = |o: &Operand| match o {
            Operand::Value(x) => Operand::Value(repr[x.index()]),
            c => *c,
        };
        let def = match &f.value(v).def {
            Def::Binary(op, a, b) => Def::Binary(*op, m(a), m(b)),
            Def::Trig(t, a) => Def::Trig(*t, repr[a.index()]),
            _ => continue,
        };
        if let Some(k) = op_key(&def) {
            match table.get(&k) {
                Some(&first) => {
                    repr[v.index()] = first;
                    drops += u64::from(matches!(def, Def::Binary(..)));
                }
                None => {
                    table.insert(k, v);
                }
            }
        }
    }
    Some(drops)
}

impl Pass for Cse {
    fn name(&self) -> &'static str {
        "cse"
    }

    fn at_time_limit(&self) -> AtTimeLimit {
        AtTimeLimit::Skip
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let ticker = cx.ticker();
        for f in &mut m.functions {
            if ticker.stopped() {
                cx.note_stop("cse", &format!("before @{}: {}", f.name, ticker.reason()));
                break;
            }
            let (seen, n) = (ticker.ticks(), f.body.len() as u64);
            cse_within(f, &ticker);
            if ticker.stopped() {
                let done = ticker.ticks().saturating_sub(seen + 1);
                let what = format!("in @{} after {done} of {n} values (merges found kept)", f.name);
                cx.note_stop("cse", &format!("{what}: {}", ticker.reason()));
                break;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::text::parse;

    fn run(src: &str) -> Module {
        let mut m = parse(src).unwrap();
        Cse.run(&mut m, &mut PassContext::default()).unwrap();
        for f in &m.functions {
            assert!(
                robovec_ir::verifier::verify_function(f).is_empty(),
                "{:?}",
                robovec_ir::verifier::verify_function(f)
            );
        }
        m
    }

    #[test]
    fn commuted_sums_and_products_merge_and_their_users_follow() {
        // x*y and y*x are one product; then p1+z and z+p2 become one sum; q = s1 - z stays.
        let m = run("func @f { phase atomised input %x input %y input %z \
             %p1 = mul %x, %y  %p2 = mul %y, %x  %s1 = add %p1, %z  %s2 = add %z, %p2 \
             %q = sub %s2, %z  output a = %s1  output b = %s2  output c = %q }");
        let f = &m.functions[0];
        assert_eq!(f.body.len(), 3, "p2 and s2 merge into p1 and s1");
        let s1 = f.lookup("s1").unwrap();
        assert_eq!(f.outputs[1].value, Operand::Value(s1), "output b reads s1");
        match &f.value(f.lookup("q").unwrap()).def {
            Def::Binary(BinOp::Sub, Operand::Value(a), _) => assert_eq!(*a, s1),
            d => panic!("{d:?}"),
        }
    }

    #[test]
    fn subtraction_order_calls_and_constant_bits_are_kept_apart() {
        let m = run("func @f { phase atomised input %x input %y \
             %d1 = sub %x, %y  %d2 = sub %y, %x  %z1 = mul %x, 0.0  %z2 = mul %x, -0.0 \
             %c1 = call @sqrt(%x)  %c2 = call @sqrt(%x) \
             output a = %d1  output b = %d2  output c = %z1  output d = %z2  output e = %c1  output f = %c2 }");
        assert_eq!(m.functions[0].body.len(), 6, "nothing merges");
    }

    /// `cse_drops_until` counts what `cse_function` drops (merged trig variables are no op) and
    /// stops at a tick budget.
    #[test]
    fn the_drop_count_is_what_cse_drops() {
        let src = "func @f { phase atomised input %x input %y input %z              %c1 = cos %x  %c2 = cos %x  %p1 = mul %c1, %y  %p2 = mul %y, %c2  %s1 = add %p1, %z              %s2 = add %z, %p2  %d = sub %s1, %s2  %e = sub %s2, %s1              output a = %d  output b = %e }";
        let f = &parse(src).unwrap().functions[0];
        let drops = cse_drops_until(f, &Ticker::default()).expect("no limit");
        let mut g = f.clone();
        let dropped = cse_function(&mut g);
        // s2 merged into s1, `e` is `d`.
        assert_eq!(dropped, 4, "c2, p2, s2, e");
        assert_eq!(drops, 3, "p2, s2 and e are ops; c2 is a trig variable");
        assert_eq!(f.op_counts().total - drops, g.op_counts().total);
        assert_eq!(cse_drops_until(f, &Ticker::new(None, Some(4))), None, "the 4th of 8 values stops it");
    }
}
