//! Register pressure of a body order: how many arithmetic results are live at once.
//!
//! # Model (what a C compiler sees in the generated code)
//! - Only *results* take registers: values defined by a binary op or a call. Inputs and trig
//!   initial variables are read from memory (`in[k]`, or a `sin`/`cos` computed once at the top
//!   and kept in a stack slot): x86 and AArch64 fold such loads into the consuming instruction
//!   or reload them at no spill cost, so they are not counted.
//! - A result is live from its definition to its last reader in the body. An output is stored
//!   where it is defined (`out[k] = x` right after `x`), so being an output does not extend a
//!   live range. A result nothing reads is live only at its definition.
//! - `live(t)` counts the results defined at or before step `t` still needed after step `t`,
//!   plus the result of step `t` itself.
//!
//! Figures: [`Pressure::max_live`] (the classic register-pressure measure, in values) and
//! [`Pressure::excess`] (Σₜ max(0, live(t) − R): value-steps that cannot sit in R registers, a
//! proxy for spill traffic). Cost: O(values + operands).

use robovec_ir::{Def, Function, Value};

/// Register pressure of one function's body order (see the module doc for the model).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Pressure {
    /// Largest number of results live at one step, values.
    pub max_live: usize,
    /// Σ over steps of `max(0, live − registers)`, value-steps.
    pub excess: u64,
    /// Σ over steps of `live`, value-steps (total live-range length).
    pub total: u64,
}

/// True when `v` is a result that takes a register (a binary op or a call).
pub fn is_result(f: &Function, v: Value) -> bool {
    matches!(f.value(v).def, Def::Binary(..) | Def::Call(..) | Def::Expr(_))
}

/// The register pressure of `f`'s body order with `registers` registers (16 for x86-64's
/// xmm/ymm registers without AVX-512).
pub fn pressure(f: &Function, registers: usize) -> Pressure {
    pressure_of_order(f, &f.body, registers)
}

/// The register pressure of `order` (a topological order of `f`'s body values).
pub fn pressure_of_order(f: &Function, order: &[Value], registers: usize) -> Pressure {
    let n = f.values.len();
    // Step of the last reader of each value (`usize::MAX`: never read).
    let mut last = vec![usize::MAX; n];
    for (t, &v) in order.iter().enumerate() {
        f.value(v).def.for_each_value(|a| last[a.index()] = t);
    }
    // Results that die after step t: ends[t].
    let mut ends = vec![0u32; order.len()];
    let mut live = 0usize;
    let mut p = Pressure::default();
    for (t, &v) in order.iter().enumerate() {
        if is_result(f, v) {
            live += 1;
            let end = if last[v.index()] == usize::MAX { t } else { last[v.index()] };
            ends[end] += 1;
        }
        p.max_live = p.max_live.max(live);
        p.total += live as u64;
        p.excess += live.saturating_sub(registers) as u64;
        live -= ends[t] as usize;
    }
    p
}
