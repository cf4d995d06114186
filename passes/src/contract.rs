//! `contract`: fuses a multiply into the additions that read it, `a·b ± c` → one fused
//! multiply-add with one rounding ([`robovec_ir::Intrinsic`]: `@fma`, `@fms`, `@fnma`), for
//! CPUs with FMA units.
//!
//! This is C's `-ffp-contract=fast` (ISO C §6.5 ¶8, `FP_CONTRACT`) done in the IR, so that the
//! contraction is part of the program instead of the C compiler's choice: the interpreter
//! (`-eval`, `accuracy`, `sim`) evaluates the fused ops with `mul_add`, and `codegen<c>` writes
//! them as C99 `fma`, so generated C compiled with `-ffp-contract=off` still equals robovec's
//! evaluation bit for bit (SPEC §8) — with contraction, not without. Each fused op rounds once
//! where the pair rounded twice: outputs change at the rounding level (usually towards the
//! exact value); the `accuracy` pass measures it against the original equations.
//!
//! # Which multiplies
//! A `mul` is fused when it is not an output and **every** use of it is an `add` or `sub`
//! with it as one operand (GCC's rule in its `widening_mul` pass): then every such addition
//! becomes a fused op and the `mul` disappears, one instruction fewer per `mul` and none more.
//! `m + y`, `y + m` → `fma(a, b, y)`; `m − y` → `fms(a, b, y)`; `y − m` → `fnma(a, b, y)`, for
//! `m = a·b`. An addition of two such multiplies absorbs the one with fewer uses, then the
//! earlier one (GCC converts multiplies in statement order; absorbing the later one instead was
//! no faster on serial30's `M`), and keeps the other as its addend; a multiply some of whose
//! additions absorbed their other operand is left unfused, and those additions choose again,
//! until no choice changes.
//!
//! Runs on the atomised phase and keeps it; clears timing attributes. A fused op is a `call`
//! (SPEC §3 counts it as one op of kind `call`), which `place` runs as a call and
//! `codegen<fpga>` rejects: this pass is for CPU back ends. Cost: O(values + operands) per
//! round; rounds are few (each one drops a multiply for good).

use robovec_ir::{BinOp, Def, Function, Intrinsic, Module, Operand, Value};

use crate::{Params, Pass, PassContext, PassError, PassInfo};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "contract",
    doc: "fuse a*b +/- c into one fused multiply-add (@fma, @fms, @fnma; one rounding) where every use of the multiply is an add/sub: C's -ffp-contract in the IR, for CPUs with FMA",
    params: &[],
    build: |_: &Params| Ok(Box::new(Contract)),
};

/// The `contract` pass.
#[derive(Debug)]
pub struct Contract;

/// What [`contract_function`] did to one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Contracted {
    /// Additions that became `@fma`.
    pub fma: usize,
    /// Subtractions `m − y` that became `@fms`.
    pub fms: usize,
    /// Subtractions `y − m` that became `@fnma`.
    pub fnma: usize,
    /// Multiplies removed (every use fused).
    pub muls_removed: usize,
}

/// The multiply `a·b` defining `o`, if `o` is one.
fn mul_of(f: &Function, o: &Operand) -> Option<(Value, Operand, Operand)> {
    let Operand::Value(v) = *o else { return None };
    match f.value(v).def {
        Def::Binary(BinOp::Mul, a, b) => Some((v, a, b)),
        _ => None,
    }
}

/// Fuses the multiplies of `f` into their additions (see the module doc).
pub fn contract_function(f: &mut Function) -> Contracted {
    let n = f.values.len();
    // Every use of every value: the additions that read it once, and whether anything else
    // (an output, another op, an addition reading it twice) does.
    let mut adds_of: Vec<Vec<Value>> = vec![Vec::new(); n];
    let mut other_use = vec![false; n];
    for o in &f.outputs {
        if let Operand::Value(v) = o.value {
            other_use[v.index()] = true;
        }
    }
    for &v in &f.body {
        match &f.value(v).def {
            Def::Binary(BinOp::Add | BinOp::Sub, a, b) => {
                if a == b {
                    if let Operand::Value(x) = a {
                        other_use[x.index()] = true;
                    }
                    continue;
                }
                for x in [a, b] {
                    if let Operand::Value(x) = x {
                        adds_of[x.index()].push(v);
                    }
                }
            }
            def => def.for_each_value(|x| other_use[x.index()] = true),
        }
    }
    let mut eligible: Vec<bool> = (0..n)
        .map(|i| {
            let v = Value::with_number(i as u32);
            !other_use[i] && !adds_of[i].is_empty() && mul_of(f, &Operand::Value(v)).is_some()
        })
        .collect();
    // Each addition's choice: the operand (0 or 1) whose multiply it absorbs.
    let mut choice: Vec<Option<usize>> = vec![None; n];
    let choose = |f: &Function, eligible: &[bool], v: Value| -> Option<usize> {
        let Def::Binary(_, a, b) = &f.value(v).def else { return None };
        let cand = |k: usize, o: &Operand| match o {
            Operand::Value(x) if eligible[x.index()] => {
                Some((adds_of[x.index()].len(), x.index(), k))
            }
            _ => None,
        };
        [cand(0, a), cand(1, b)].into_iter().flatten().min().map(|(_, _, k)| k)
    };
    let adds: Vec<Value> = f
        .body
        .iter()
        .copied()
        .filter(|&v| matches!(f.value(v).def, Def::Binary(BinOp::Add | BinOp::Sub, a, b) if a != b))
        .collect();
    for &v in &adds {
        choice[v.index()] = choose(f, &eligible, v);
    }
    loop {
        let chosen = |f: &Function, choice: &[Option<usize>], add: Value| -> Option<Value> {
            let Def::Binary(_, a, b) = &f.value(add).def else { return None };
            match (choice[add.index()], [a, b]) {
                (Some(k), ops) => match ops[k] {
                    Operand::Value(x) => Some(*x),
                    Operand::Const(_) => None,
                },
                (None, _) => None,
            }
        };
        let mut dropped = Vec::new();
        for i in 0..n {
            if eligible[i] && !adds_of[i].iter().all(|&a| chosen(f, &choice, a) == Some(Value::with_number(i as u32))) {
                eligible[i] = false;
                dropped.push(i);
            }
        }
        if dropped.is_empty() {
            break;
        }
        for i in dropped {
            for &a in &adds_of[i] {
                choice[a.index()] = choose(f, &eligible, a);
            }
        }
    }
    let mut out = Contracted::default();
    for &v in &adds {
        let Some(k) = choice[v.index()] else { continue };
        let Def::Binary(op, x, y) = f.value(v).def.clone() else { continue };
        let (m, other) = if k == 0 { (x, y) } else { (y, x) };
        let (_, a, b) = mul_of(f, &m).expect("an eligible operand is a multiply");
        let i = match (op, k) {
            (BinOp::Add, _) => Intrinsic::Fma,
            (_, 0) => Intrinsic::Fms,
            _ => Intrinsic::Fnma,
        };
        match i {
            Intrinsic::Fma => out.fma += 1,
            Intrinsic::Fms => out.fms += 1,
            _ => out.fnma += 1,
        }
        f.value_mut(v).def = Def::Call(Box::new(i.callee()), vec![a, b, other]);
    }
    out.muls_removed = eligible.iter().filter(|&&e| e).count();
    if out.muls_removed > 0 {
        f.retain(|_, v| !eligible[v.index()]);
    }
    f.clear_timing();
    out
}

impl Pass for Contract {
    fn name(&self) -> &'static str {
        "contract"
    }

    fn requires(&self) -> Option<robovec_ir::Phase> {
        Some(robovec_ir::Phase::Atomised)
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let mut parts = Vec::new();
        for f in &mut m.functions {
            let c = contract_function(f);
            parts.push(format!(
                "@{} {} fused (fma {}, fms {}, fnma {}), {} mul removed",
                f.name,
                c.fma + c.fms + c.fnma,
                c.fma,
                c.fms,
                c.fnma,
                c.muls_removed
            ));
        }
        cx.notes.push(format!("contract: {}", parts.join("; ")));
        Ok(())
    }
}

#[cfg(test)]
mod tests;
