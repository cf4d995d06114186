//! Execution of a [`MachineProgram`] on numbers of precision `T` (what `sim` runs), cycle by
//! cycle in the order of [`robovec_ir::machine`]'s timing contract: arrivals (buffer stores, output capture),
//! buffer reads, PE-memory writes, issues. The executor knows nothing of values: it reads
//! addresses, routes the crossbar and computes with the PE's unit — what the hardware does.
//! [`execute_until`] takes a `stop` hook called once per cycle (a caller's time limit).

use std::collections::HashMap;

use robovec_ir::interp::{eval_binop, eval_call, Float};
use robovec_ir::intrinsic::Intrinsic;
use robovec_ir::machine::{Instr, MachineOp, MachineProgram, Source, Word};
use robovec_ir::syntax::{BinOp, TrigFn};

use crate::error::{MachineError, MachineErrorKind as K, When};

/// What one execution computed.
#[derive(Clone, Debug, PartialEq)]
pub struct Executed<T> {
    /// Outputs in the program's output-map order (`Function::outputs` order).
    pub outputs: Vec<(String, T)>,
    /// Cycles run (the program's `cycles`).
    pub cycles: u32,
}

/// Runs `p` in precision `T`; `input(name)` gives each input's value (called once per name,
/// on first use). Inputs and constants are `T::from_f64(x)`, trig words `sin`/`cos` in `T` of
/// the input, ops [`eval_binop`] / [`eval_call`] in `T` (as `interp` computes).
///
/// # Errors
/// [`K::Unverified`] when the program is inconsistent (a word read before it was written, a
/// crossbar source carrying nothing, an address beyond its memory, a result after the last
/// cycle) — never for a program [`crate::program::lower`] returned.
pub fn execute<T: Float>(p: &MachineProgram, input: impl FnMut(&str) -> f64) -> Result<Executed<T>, MachineError> {
    execute_until(p, input, &|| false)
}

/// [`execute`] that calls `stop` once per cycle, before running it, and gives up when it
/// returns true (the caller's time limit, `-time-limit`).
///
/// # Errors
/// [`K::Stopped`] at the cycle not run when `stop` returned true (nothing else returns it),
/// else as [`execute`].
pub fn execute_until<T: Float>(
    p: &MachineProgram,
    mut input: impl FnMut(&str) -> f64,
    stop: &dyn Fn() -> bool,
) -> Result<Executed<T>, MachineError> {
    let mut inputs: HashMap<String, T> = HashMap::new();
    let load = |w: &Word| -> Result<T, String> {
        let mut get = |n: &str| *inputs.entry(n.to_string()).or_insert_with(|| T::from_f64(input(n)));
        Ok(match w {
            Word::Input(n) => get(n),
            Word::Trig(TrigFn::Sin, n) => get(n).sin(),
            Word::Trig(TrigFn::Cos, n) => get(n).cos(),
            Word::Const(c) => T::from_f64(*c),
        })
    };
    let op = |i: &Instr, _slot: usize, _cycle: usize, args: &[T]| -> Result<T, String> {
        let binary = |op: BinOp| match args {
            [a, b] => Ok(eval_binop(op, *a, *b)),
            _ => Err(format!("{op:?} reads {} words", args.len())),
        };
        match &i.op {
            MachineOp::Add => binary(BinOp::Add),
            MachineOp::Sub => binary(BinOp::Sub),
            MachineOp::Mul => binary(BinOp::Mul),
            MachineOp::Div => binary(BinOp::Div),
            MachineOp::Call(callee) | MachineOp::Mac(callee) => Ok(eval_call(callee, args)),
        }
    };
    run(p, load, op, stop)
}

/// Runs `p` on fixed-point PEs (`p.fixed`, issue 49): words are the values' integers, each
/// op exact on them then rounded by its [`robovec_ir::machine::FixShifts`] (what the HDL's
/// `fix_add_sub`/`fix_mul` and `-eval` compute); inputs are stored in their formats (rounded to
/// nearest, ties up), trig words are `sin`/`cos` in binary64 of the stored input, then stored;
/// outputs are `k · 2^-f` in their formats.
///
/// # Errors
/// As [`execute`]; [`K::Formats`] for a program without a fixed-point side or a loaded word no
/// 32-bit word holds; [`K::Unverified`] for a result beyond 32 bits (an overflow the range
/// proof excludes, which the hardware would wrap).
pub fn execute_fixed_until(
    p: &MachineProgram,
    mut input: impl FnMut(&str) -> f64,
    stop: &dyn Fn() -> bool,
) -> Result<Executed<f64>, MachineError> {
    use crate::program::fixed::{constant_word, value_of, word_of};
    let fx = p.fixed.as_ref().ok_or_else(|| MachineError::new(K::Formats, "the program is not for fixed-point PEs"))?;
    let mut inputs: HashMap<String, f64> = HashMap::new();
    let load = |w: &Word| -> Result<i64, String> {
        let frac = fx.fraction(w).ok_or_else(|| format!("no fixed-point format for the word {w:?}"))?;
        let mut stored = |n: &str| -> Result<f64, String> {
            let x = *inputs.entry(n.to_string()).or_insert_with(|| input(n));
            let f = fx.inputs.get(n).copied().ok_or_else(|| format!("input `{n}` has no fixed-point format"))?;
            word_of(x, f).map(|k| value_of(k, f)).ok_or_else(|| format!("input `{n}` = {x} overflows its format"))
        };
        let k = match w {
            Word::Input(n) => word_of(stored(n)?, frac),
            Word::Trig(TrigFn::Sin, n) => word_of(stored(n)?.sin(), frac),
            Word::Trig(TrigFn::Cos, n) => word_of(stored(n)?.cos(), frac),
            Word::Const(c) => constant_word(*c),
        };
        k.ok_or_else(|| format!("the word {w:?} does not fit 32 bits at {frac} fractional bits"))
    };
    let op = |i: &Instr, slot: usize, cycle: usize, args: &[i64]| -> Result<i64, String> {
        let sh = fx.shifts.get(slot).and_then(|c| c.get(cycle)).copied().flatten().ok_or("an op without shifts")?;
        let r = match (&i.op, args) {
            (MachineOp::Mac(callee), [a, b, c]) => {
                let (negate_product, negate_addend) = match Intrinsic::of(callee, 3) {
                    Some(Intrinsic::Fma) => (false, false),
                    Some(Intrinsic::Fms) => (false, true),
                    Some(Intrinsic::Fnma) => (true, false),
                    _ => return Err(format!("{:?} has no fixed-point unit", i.op)),
                };
                sh.apply_fused(negate_product, negate_addend, *a, *b, *c)
            }
            (_, [a, b]) => sh.apply(&i.op, *a, *b).ok_or_else(|| format!("{:?} has no fixed-point unit", i.op))?,
            _ => return Err(format!("{:?} reads {} words", i.op, args.len())),
        };
        i32::try_from(r).map(i64::from).map_err(|_| format!("the result {r} overflows the 32-bit word"))
    };
    let x = run(p, load, op, stop)?;
    let outputs = x.outputs.into_iter().zip(&fx.outputs).map(|((n, k), &f)| (n, value_of(k, f))).collect();
    Ok(Executed { outputs, cycles: x.cycles })
}

/// The cycle-by-cycle run of `p` (module doc) with words `T`: `load` gives each initial word,
/// `op` computes an issued instruction on PE `slot` in cycle `cycle` from its operands.
fn run<T: Copy>(
    p: &MachineProgram,
    mut load: impl FnMut(&Word) -> Result<T, String>,
    op: impl Fn(&Instr, usize, usize, &[T]) -> Result<T, String>,
    stop: &dyn Fn() -> bool,
) -> Result<Executed<T>, MachineError> {
    let n_pe = p.n_pe();
    let span = p.cycles as usize + 1;
    let bad = |when: When, s: usize, message: String| {
        let e = MachineError::new(K::Unverified, message).at(when);
        match p.pes.get(s) {
            Some(q) => e.on(q.pe),
            None => e,
        }
    };
    if p.pes.iter().any(|q| q.steps.len() != span) || p.buffer_words.len() != n_pe {
        return Err(MachineError::new(K::Unverified, "program steps do not cover cycles 0..=cycles"));
    }
    let mut value =
        |w: &Word| -> Result<T, MachineError> { load(w).map_err(|m| MachineError::new(K::Formats, m).at(When::Load)) };
    let words = |ws: &[Option<Word>], value: &mut dyn FnMut(&Word) -> Result<T, MachineError>| {
        ws.iter().map(|w| w.as_ref().map(&mut *value).transpose()).collect::<Result<Vec<Option<T>>, MachineError>>()
    };
    let mut mem: Vec<Vec<Option<T>>> = p.pes.iter().map(|q| words(&q.init, &mut value)).collect::<Result<_, _>>()?;
    let mut out: Vec<Vec<Option<T>>> =
        p.pes.iter().map(|q| words(&q.output_init, &mut value)).collect::<Result<_, _>>()?;
    let mut buf: Vec<Vec<Option<T>>> = p.buffer_words.iter().map(|&w| vec![None; w as usize]).collect();
    // Results in flight by (arrival cycle mod `ring`, slot): a result arrives at most the
    // longest latency after its issue, so `ring` cycles of one word per PE hold them all (a
    // table of every cycle was n_pe × cycles words: 42 MB of fresh memory per run at WALK-MAN
    // × 64, read with a stride of a cycle per PE; issue 28). A cycle's row is cleared once the
    // cycle is done.
    let l = &p.arch.lat;
    let ring = l.add.max(l.mul).max(l.div).max(l.call) as usize + 1;
    let mut arriving: Vec<Option<T>> = vec![None; n_pe * ring];
    let mut bus: Vec<Option<T>> = vec![None; n_pe];
    let mut args: Vec<T> = Vec::new();
    for c in 0..span {
        let when = When::Cycle(c as u32);
        if stop() {
            return Err(MachineError::stopped().at(when));
        }
        for (s, q) in p.pes.iter().enumerate() {
            let st = &q.steps[c];
            let now = arriving[(c % ring) * n_pe + s];
            if let Some(a) = st.buffer.store {
                let w = buf[s]
                    .get_mut(a as usize)
                    .ok_or_else(|| bad(when, s, format!("buffer address {a} out of range")))?;
                *w = Some(now.ok_or_else(|| bad(when, s, "buffer store without an arriving result".into()))?);
            }
            if let Some(a) = st.capture {
                let w = out[s]
                    .get_mut(a as usize)
                    .ok_or_else(|| bad(when, s, format!("output address {a} out of range")))?;
                *w = Some(now.ok_or_else(|| bad(when, s, "output capture without an arriving result".into()))?);
            }
        }
        for (s, q) in p.pes.iter().enumerate() {
            bus[s] = match q.steps[c].buffer.read {
                Some(a) => Some(
                    buf[s]
                        .get(a as usize)
                        .copied()
                        .flatten()
                        .ok_or_else(|| bad(when, s, format!("buffer address {a} read empty or out of range")))?,
                ),
                None => None,
            };
        }
        for (s, q) in p.pes.iter().enumerate() {
            for w in &q.steps[c].writes {
                let data = match w.src {
                    Source::Result(t) if t < n_pe => arriving[(c % ring) * n_pe + t],
                    Source::Buffer(t) if t < n_pe => bus[t],
                    _ => None,
                }
                .ok_or_else(|| bad(when, s, format!("write source {:?} carries nothing", w.src)))?;
                *mem[s]
                    .get_mut(w.addr as usize)
                    .ok_or_else(|| bad(when, s, format!("write address {} out of range", w.addr)))? = Some(data);
            }
        }
        for (s, q) in p.pes.iter().enumerate() {
            let Some(i) = &q.steps[c].issue else { continue };
            args.clear();
            for &a in &i.reads {
                args.push(
                    mem[s]
                        .get(a as usize)
                        .copied()
                        .flatten()
                        .ok_or_else(|| bad(when, s, format!("read address {a} empty or out of range")))?,
                );
            }
            let x = op(i, s, c, &args).map_err(|m| bad(when, s, m))?;
            let at = c + p.latency(&i.op) as usize;
            if at >= span {
                return Err(bad(when, s, format!("result arrives at cycle {at}, after the last cycle")));
            }
            arriving[(at % ring) * n_pe + s] = Some(x);
        }
        arriving[(c % ring) * n_pe..(c % ring + 1) * n_pe].fill(None);
    }
    let mut outputs = Vec::with_capacity(p.outputs.len());
    for o in &p.outputs {
        let x = out.get(o.slot).and_then(|m| m.get(o.addr as usize)).copied().flatten().ok_or_else(|| {
            MachineError::new(K::Unverified, format!("output `{}` is not in its output memory", o.name)).at(When::End)
        })?;
        outputs.push((o.name.clone(), x));
    }
    Ok(Executed { outputs, cycles: p.cycles })
}
