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
//! # In fixed point (issue 49)
//! After `precision<target=mcu>` (a function with formats) the fused op takes the addition's
//! format, and a multiply is fused only when each fused op stays an integer op
//! ([`robovec_ir::format::integer_op`]: the exact `±a·b ± c`, then one rounding, within 62
//! bits). The product's own rounding is gone. With the run's domain the verifier's range check
//! must still hold: a value it says may overflow gets one integer bit more at its width
//! (`contract_in_range`; the remark counts them), else nothing is fused. `error-bound` after
//! this pass certifies the result (on the pendulum every output's bound falls or stays; on
//! the corpus models of issue 49 the largest bound over binary32's is unchanged). Such a fused
//! op runs on a MULTI PE as a multiply-accumulate ([`robovec_ir::Function::op_kind`]: a `mul`
//! for the PE array); `sim` runs it bit for bit and `codegen<fpga>` builds that unit (`fix_mac`).
//!
//! Runs on the atomised phase and keeps it; clears timing attributes. A fused op is a `call`
//! (SPEC §3 counts it as one op of kind `call`); a binary one is run by `place` as a call on
//! an ADD PE, which `codegen<fpga>` rejects: for binary formats this pass is for CPU back
//! ends. Cost: O(values + operands); in fixed point with a domain, plus the enclosures and up
//! to 512 sweeps of the bound.

use std::collections::HashSet;

use robovec_ir::{BinOp, Def, Function, Intrinsic, Module, Operand, Value};

use crate::{each_function, Before, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "contract",
    doc: "fuse a*b +/- c into one fused multiply-add (@fma, @fms, @fnma; one rounding) where every use of the multiply is an add/sub: C's -ffp-contract in the IR, for CPUs with FMA",
    params: &[],
    build: |_: &Params| Ok(Box::new(Contract)),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        formats: true,
        ..crate::Props::DEFAULT
    },
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
        let fused_of = |op: BinOp, x: Operand, y: Operand| {
            let first = x == Operand::Value(m);
            let addend = if first { y } else { x };
            let fused = match (op, first) {
                (BinOp::Add, _) => Intrinsic::Fma,
                (_, true) => Intrinsic::Fms,
                _ => Intrinsic::Fnma,
            };
            (fused, Def::Call(Box::new(fused.callee()), vec![a, b, addend]))
        };
        // In fixed point a fused op must stay an integer op (exact, then rounded once): tried
        // on every use first, the multiply is kept when one would not be.
        if f.has_formats() && !uses.iter().all(|&u| fixed_fusion_exact(f, u, &fused_of)) {
            continue;
        }
        for &u in uses {
            let Def::Binary(op, x, y) = f.value(u).def else { unreachable!("an addition") };
            let (fused, def) = fused_of(op, x, y);
            *match fused {
                Intrinsic::Fma => &mut out.fma,
                Intrinsic::Fms => &mut out.fms,
                _ => &mut out.fnma,
            } += 1;
            f.value_mut(u).def = def;
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

/// True when addition `u` of a function with formats, fused by `fused_of`, is an integer op
/// ([`robovec_ir::format::integer_op`]) or keeps a non-fixed format (computed in its format
/// as before). Tried in place and undone.
fn fixed_fusion_exact(
    f: &mut Function,
    u: Value,
    fused_of: &dyn Fn(BinOp, Operand, Operand) -> (Intrinsic, Def),
) -> bool {
    if !matches!(f.format(u), robovec_ir::format::Format::Fix { .. }) {
        return true;
    }
    let Def::Binary(op, x, y) = f.value(u).def else { return false };
    let before = std::mem::replace(&mut f.value_mut(u).def, fused_of(op, x, y).1);
    let exact = robovec_ir::format::integer_op(f, u).is_some();
    f.value_mut(u).def = before;
    exact
}

/// Most rounds of [`contract_in_range`]: each gives one value one integer bit more.
const RANGE_ROUNDS: usize = 512;

/// [`contract_within`] on a function with fixed-point formats over `domain`, and the formats
/// refitted where the verifier's range check ([`crate::error_bound::bound::check_fixed_formats`])
/// would fail: the fused function computes the same reals, but its enclosures are not the
/// unfused one's (the harmonic forms of a rotation `C·x + S·y` whose `x`, `y` are fused ops
/// fold more of their atoms into slack: WALK-MAN's `%AlF238` 2.23e6 against 2.02e6), and
/// `precision` leaves no headroom bit. Each round finds the first value that may overflow and
/// gives it one integer bit more at the same width (one fraction bit fewer); the enclosures are
/// computed once (they do not depend on the formats). When a round would leave an op that is
/// not an integer op, or after [`RANGE_ROUNDS`] rounds, or when the ticker stops, nothing is
/// fused. Returns what was fused and the values refitted. `error-bound` after this pass
/// certifies the result (the refitted values round to a coarser step). Cost:
/// O(ops + the enclosures + rounds · the bound's sweep).
fn contract_in_range(f: &mut Function, domain: &robovec_ir::domain::Domain, ticker: &Ticker) -> (Contracted, usize) {
    use crate::error_bound::bound::{bound, BoundError, Formats};
    use robovec_ir::format::{integer_op, Format, FIX_FRACTION_RANGE};
    let mut g = f.clone();
    let c = contract_within(&mut g, ticker);
    if ticker.stopped() {
        return (Contracted::default(), 0);
    }
    let Ok(x) = crate::range::enclose_with(&g, domain, Some(crate::range::affine::DEFAULT_TERMS), || ticker.tick())
    else {
        return (Contracted::default(), 0);
    };
    let mut refitted = HashSet::new();
    for _ in 0..RANGE_ROUNDS {
        match bound(&g, &x, Formats::Mixed, || ticker.tick()) {
            Ok(_) => {
                *f = g;
                return (c, refitted.len());
            }
            Err(BoundError::FixOverflow { value, .. }) => {
                let Some(v) = g.lookup(&value) else { break };
                let Format::Fix { width, fraction } = g.format(v) else { break };
                let Some(coarser) = Format::fix(width, fraction - 1).filter(|_| fraction > *FIX_FRACTION_RANGE.start())
                else {
                    break;
                };
                g.set_format(v, coarser);
                // the value and the ops that read it must stay integer ops
                let mut exact = g.op_kind(v).is_none() || integer_op(&g, v).is_some();
                for &u in &g.body {
                    if exact && g.value(u).def.operands().contains(&Operand::Value(v)) {
                        exact = integer_op(&g, u).is_some() || !matches!(g.format(u), Format::Fix { .. });
                    }
                }
                if !exact {
                    break;
                }
                refitted.insert(v);
            }
            Err(_) => break,
        }
    }
    (Contracted::default(), 0)
}

impl Pass for Contract {
    fn name(&self) -> &'static str {
        "contract"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let skipped = |f: &robovec_ir::Function, _| Some(format!("before @{}", f.name));
        let domain = cx.domain.clone();
        let parts = each_function(m, cx, "contract", Before::Ticked, skipped, |f, _, ticker| {
            let fixed = f.has_formats()
                && f.body.iter().any(|&v| matches!(f.format(v), robovec_ir::format::Format::Fix { .. }));
            let (c, kept) = match &domain {
                Some(d) if fixed && d.missing(f).is_empty() => contract_in_range(f, d, ticker),
                _ => (contract_within(f, ticker), 0),
            };
            let mut part = format!(
                "@{} {} fused (fma {}, fms {}, fnma {}), {} mul removed",
                f.name,
                c.fma + c.fms + c.fnma,
                c.fma,
                c.fms,
                c.fnma,
                c.muls_removed
            );
            if kept > 0 {
                part += &format!(", {kept} value(s) given an integer bit more for the fixed-point range check");
            }
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
