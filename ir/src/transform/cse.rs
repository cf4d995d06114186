//! Common-subexpression elimination by local value numbering over the one basic block (what
//! the `cse` pass of `robovec-passes` runs on a module; the generator counts its ops with it).
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

use crate::time_limit::Ticker;
use crate::{BinOp, Def, Function, Operand, TrigFn, Value};

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
