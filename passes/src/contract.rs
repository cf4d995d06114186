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
//! `m = a·b`. Multiplies are taken in statement order (GCC's order): an addition of two
//! products absorbs the earlier one, which leaves the other as its addend, unfused.
//!
//! Runs on the atomised phase and keeps it; clears timing attributes. A fused op is a `call`
//! (SPEC §3 counts it as one op of kind `call`), which `place` runs as a call and
//! `codegen<fpga>` rejects: this pass is for CPU back ends. Cost: O(values + operands).

use robovec_ir::{BinOp, Def, Function, Intrinsic, Module, Operand, Value};

use crate::{each_function, Before, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "contract",
    doc: "fuse a*b +/- c into one fused multiply-add (@fma, @fms, @fnma; one rounding) where every use of the multiply is an add/sub: C's -ffp-contract in the IR, for CPUs with FMA",
    params: &[],
    build: |_: &Params| Ok(Box::new(Contract)),
    props: crate::Props { requires: Some(robovec_ir::Phase::Atomised), at_time_limit: crate::AtTimeLimit::Skip, exact_in_reals: true, ..crate::Props::DEFAULT },
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

/// Fuses the multiplies of `f` into their additions (see the module doc).
pub fn contract_function(f: &mut Function) -> Contracted {
    contract_within(f, &Ticker::default())
}

/// [`contract_function`] that stops fusing when `ticker` says so (`-time-limit`; one tick per
/// value): the multiplies fused so far stay fused, the later ones are kept as they are.
pub fn contract_within(f: &mut Function, ticker: &Ticker) -> Contracted {
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
    // GCC's order: each multiply in statement order is fused when all its uses are still
    // additions; an addition that absorbed one is a fused op, so the other product it reads
    // (now the addend of a call) is not.
    let mut converted = vec![false; n];
    let mut removed = vec![false; n];
    let mut out = Contracted::default();
    for k in 0..f.body.len() {
        if ticker.tick() {
            break;
        }
        let m = f.body[k];
        let Def::Binary(BinOp::Mul, a, b) = f.value(m).def else { continue };
        let uses = &adds_of[m.index()];
        if other_use[m.index()] || uses.is_empty() || uses.iter().any(|u| converted[u.index()]) {
            continue;
        }
        for &u in uses {
            let Def::Binary(op, x, y) = f.value(u).def else { unreachable!("an addition") };
            let first = x == Operand::Value(m);
            let addend = if first { y } else { x };
            let (fused, count) = match (op, first) {
                (BinOp::Add, _) => (Intrinsic::Fma, &mut out.fma),
                (_, true) => (Intrinsic::Fms, &mut out.fms),
                _ => (Intrinsic::Fnma, &mut out.fnma),
            };
            *count += 1;
            f.value_mut(u).def = Def::Call(Box::new(fused.callee()), vec![a, b, addend]);
            converted[u.index()] = true;
        }
        removed[m.index()] = true;
        out.muls_removed += 1;
    }
    if out.muls_removed > 0 {
        f.retain(|_, v| !removed[v.index()]);
    }
    f.clear_timing();
    out
}

impl Pass for Contract {
    fn name(&self) -> &'static str {
        "contract"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let skipped = |f: &robovec_ir::Function, _| Some(format!("before @{}", f.name));
        let parts = each_function(m, cx, "contract", Before::Ticked, skipped, |f, _, ticker| {
            let c = contract_within(f, ticker);
            let part = format!(
                "@{} {} fused (fma {}, fms {}, fnma {}), {} mul removed",
                f.name,
                c.fma + c.fms + c.fnma,
                c.fma,
                c.fms,
                c.fnma,
                c.muls_removed
            );
            if ticker.stopped() {
                let what = format!("in @{} ({} multiplies fused, the later ones kept)", f.name, c.muls_removed);
                return Step::Stopped { what, kept: Some(part) };
            }
            Step::Done(part)
        });
        cx.remark("contract", m, format!("contract: {}", parts.join("; ")));
        Ok(())
    }
}

#[cfg(test)]
mod tests;
