//! Source-to-source differentiation of the SSA IR ([`differentiate`]; issue 50 item 1; what
//! Enzyme does for LLVM IR, on robovec's straight-line functions). The pass `diff<wrt=…;mode=…>`
//! of `robovec-passes` wraps it; the URDF generator's derivative functions call it.
//!
//! For every output `o` of a function and every input `x` named by `wrt`, a new output holds
//! `∂o/∂x`, computed by new ops appended to the body (the original values and outputs are kept
//! bit for bit). `wrt` is a comma-separated list; an entry names one input (`q[4]`) or a family
//! (`q` takes `q[1]`, `q[2]`, …, as `dce<outputs=…>` names outputs); without `wrt`, every input
//! (the full Jacobian, as `dce` keeps every output without `outputs`). An entry that matches no
//! input of any function is an error.
//!
//! **Names.** `∂o/∂x` is the output `d<O>_d<X><o's indices><x's indices>`, where `O` and `X`
//! are the names before their first `[`: `∂Qq[4]/∂q[2]` is `dQq_dq[4][2]`, `∂M[1][2]/∂q[3]` is
//! `dM_dq[1][2][3]`, a scalar output `T` gives `dT_dq[3]`. In an interleaved function (states
//! `#k`, `interleave`) an output of state `k` is differentiated with respect to state `k`'s
//! inputs and its derivative carries `#k`. The outputs come after the original ones, grouped
//! by output, each group in `wrt` order (an entry's inputs by index). A name already taken is an
//! error naming it.
//!
//! **Rules.** `+ − × /` by the chain rule; a trig variable `%S4 = sin %q[4]` has derivative
//! `%C4` (the function's own `cos %q[4]` when it has one, else a new trig variable), `cos` has
//! `−sin`; `@sqrt(a)` has `da / (2·√a)` (one `2·√a` per square root); `@fma(a, b, c) = a·b + c`,
//! `@fms` (`a·b − c`) and `@fnma` (`c − a·b`) are differentiated as their products and sums.
//! An opaque user callback whose operands depend on a `wrt` input is an error naming it (its
//! derivative is unknown); one that does not has derivative zero.
//!
//! **Structural zeros are never materialised.** A derivative is an operand that is absent when
//! it is zero by structure (the value does not depend on the input), a constant when it is one
//! (`∂(3·x)/∂x = 3`), and a value otherwise; signs are carried beside it, so `d(a − b)` with
//! `da = 0` costs no negation until an output needs one (`sub 0.0, …`). Products by a constant
//! 1 are not written. A derivative output that is zero by structure is the constant `0.0` (no op).
//!
//! **Modes.** `forward` sweeps the body once, carrying each value's derivatives with respect to
//! every `wrt` input that reaches it: ops in O(ops × inputs). `reverse` sweeps the body backwards
//! once per output, accumulating adjoints: O(ops × outputs). `auto` (the default) takes the
//! mode that carries fewer derivative terms: forward's are, over the values, the `wrt` inputs
//! that reach each one, reverse's the outputs each one reaches (bit sets, one linear sweep
//! each way; see `sweep_terms`).
//! Both give the same derivatives in exact arithmetic (and the same ops up to order when an
//! output has one input); the rounding differs.
//!
//! Phase: atomised → atomised, any front end's function, without numeric formats (the pass is
//! declared without `Props::formats`, so the manager refuses a formatted function). Existing outputs keep their value bit for bit; timing attributes
//! and any placement are dropped. Required at `-time-limit`: it changes the outputs.

use std::collections::HashMap;

use crate::time_limit::Ticker;
use crate::{split_state, state_name, BinOp, Def, Function, Intrinsic, Operand, Span, TrigFn, Value};

/// How the derivatives are accumulated (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Tangents carried along the body, all `wrt` inputs at once.
    Forward,
    /// Adjoints swept back from each output.
    Reverse,
}

/// True when `entry` names `input`: the same name, or its family (`q` for `q[4]`), state
/// suffixes aside.
pub fn matches(entry: &str, input: &str) -> bool {
    let base = split_state(input).0;
    base == entry || (base.starts_with(entry) && base[entry.len()..].starts_with('['))
}

/// Why [`differentiate`] failed.
#[derive(Debug)]
pub enum Failure {
    /// The time limit stopped it (the function is then incomplete and must not be used).
    Stopped,
    /// The function cannot be differentiated: the message names the value and why.
    Message(String),
}

/// A derivative: an operand (a value, or a non-negative constant) and its sign. `None` where it
/// is zero by structure.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tan {
    op: Operand,
    neg: bool,
}

impl Tan {
    fn konst(c: f64) -> Option<Tan> {
        (c != 0.0).then_some(Tan { op: Operand::Const(c.abs()), neg: c < 0.0 })
    }
    fn negated(self) -> Tan {
        Tan { neg: !self.neg, ..self }
    }
    fn constant(self) -> Option<f64> {
        match self.op {
            Operand::Const(c) => Some(if self.neg { -c } else { c }),
            Operand::Value(_) => None,
        }
    }
}

/// Writes the derivative ops into the function, folding constants and signs.
struct Builder<'f> {
    f: &'f mut Function,
    /// The base of the new values' names (`d_<output or value>`), then `.1`, `.2`, …
    base: String,
    /// Names tried so far under `base` (a counter, not a search from 1 each time: linear).
    count: u32,
}

impl<'f> Builder<'f> {
    fn new(f: &'f mut Function, base: String) -> Builder<'f> {
        Builder { f, base, count: 0 }
    }

    fn emit(&mut self, op: BinOp, a: Operand, b: Operand) -> Operand {
        Operand::Value(self.f.define_counted(&self.base, &mut self.count, Def::Binary(op, a, b), Span::DUMMY))
    }

    /// `t · x` for an operand `x` of the function.
    fn scale(&mut self, t: Option<Tan>, x: Operand) -> Option<Tan> {
        let t = t?;
        match (t.constant(), x) {
            (Some(c), Operand::Const(k)) => Tan::konst(c * k),
            (_, Operand::Const(0.0)) => None,
            (_, Operand::Const(k)) if k.abs() == 1.0 => Some(if k < 0.0 { t.negated() } else { t }),
            (_, Operand::Const(k)) => {
                Some(Tan { op: self.emit(BinOp::Mul, t.op, Operand::Const(k.abs())), neg: t.neg ^ (k < 0.0) })
            }
            (Some(c), x) if c.abs() == 1.0 => Some(Tan { op: x, neg: c < 0.0 }),
            (_, x) => Some(Tan { op: self.emit(BinOp::Mul, t.op, x), neg: t.neg }),
        }
    }

    /// `t / x`.
    fn divide(&mut self, t: Option<Tan>, x: Operand) -> Option<Tan> {
        let t = t?;
        match (t.constant(), x) {
            (Some(c), Operand::Const(k)) => Tan::konst(c / k),
            (_, Operand::Const(k)) if k.abs() == 1.0 => Some(if k < 0.0 { t.negated() } else { t }),
            (_, x) => {
                let neg = t.neg ^ matches!(x, Operand::Const(k) if k < 0.0);
                let x = match x {
                    Operand::Const(k) => Operand::Const(k.abs()),
                    v => v,
                };
                Some(Tan { op: self.emit(BinOp::Div, t.op, x), neg })
            }
        }
    }

    /// `a + b`.
    fn add(&mut self, a: Option<Tan>, b: Option<Tan>) -> Option<Tan> {
        let (a, b) = match (a, b) {
            (None, t) | (t, None) => return t,
            (Some(a), Some(b)) => (a, b),
        };
        if let (Some(x), Some(y)) = (a.constant(), b.constant()) {
            return Tan::konst(x + y);
        }
        Some(match (a.neg, b.neg) {
            (false, false) => Tan { op: self.emit(BinOp::Add, a.op, b.op), neg: false },
            (true, true) => Tan { op: self.emit(BinOp::Add, a.op, b.op), neg: true },
            (false, true) => Tan { op: self.emit(BinOp::Sub, a.op, b.op), neg: false },
            (true, false) => Tan { op: self.emit(BinOp::Sub, b.op, a.op), neg: false },
        })
    }

    /// The operand that holds `t` with its sign (`sub 0.0, …` when negative); `0.0` for zero.
    fn materialise(&mut self, t: Option<Tan>) -> Operand {
        match t {
            None => Operand::Const(0.0),
            Some(t) if !t.neg => t.op,
            Some(t) => match t.op {
                Operand::Const(c) => Operand::Const(-c),
                v => self.emit(BinOp::Sub, Operand::Const(0.0), v),
            },
        }
    }
}

/// A name made of identifier characters only (`frc[2][11].1` → `frc_2_11_1`), for new values.
fn plain(name: &str) -> String {
    let base = split_state(name).0;
    base.chars().filter(|&c| c != ']').map(|c| if c == '[' || c == '.' { '_' } else { c }).collect()
}

/// A name's family (before its first `[`) and the rest (`("Qq", "[4]")`), state suffix aside.
fn family(name: &str) -> (&str, &str) {
    let base = split_state(name).0;
    base.find('[').map_or((base, ""), |i| base.split_at(i))
}

/// The derivative output's name `∂o/∂x` (see the module doc).
pub fn derivative_name(output: &str, input: &str) -> String {
    let (of, oi) = family(output);
    let (xf, xi) = family(input);
    state_name(&format!("d{of}_d{xf}{oi}{xi}"), split_state(output).1)
}

/// The numeric indices of a name (`[2][11]` → `[2, 11]`), for ordering a family's inputs.
fn indices(name: &str) -> Vec<u64> {
    family(name).1.split(['[', ']']).filter_map(|s| s.parse().ok()).collect()
}

/// One partial derivative `∂v/∂a` of a definition `v` with respect to one of its operands `a`,
/// for the chain rule ([`partials`] lists them, [`chain`] applies one).
enum Partial {
    /// `∂v/∂a = 1` (sign aside).
    One(bool),
    /// `∂v/∂a = factor` (an operand, sign).
    By(Operand, bool),
    /// `∂v/∂a = 1 / d` (sign).
    Over(Operand, bool),
    /// `∂v/∂a = −(v / d)`: the divisor's partial of `v = a / d`.
    QuotOver(Operand, Operand),
}

/// The partials of value `v` (see [`Partial`]), creating `cos`/`sin` trig variables and `2·√a`
/// values when needed. An opaque call is an error only when a partial is asked for.
fn partials(
    f: &mut Function,
    v: Value,
    trig_of: &mut HashMap<(Value, bool), Value>,
    twice: &mut HashMap<Value, Operand>,
) -> Result<Vec<(Operand, Partial)>, String> {
    let def = f.value(v).def.clone();
    Ok(match def {
        Def::Input | Def::Expr(_) => vec![],
        Def::Trig(fun, x) => {
            let want_sin = fun == TrigFn::Cos;
            let other = match trig_of.get(&(x, want_sin)) {
                Some(&t) => t,
                None => {
                    let (tf, prefix) = if want_sin { (TrigFn::Sin, "S") } else { (TrigFn::Cos, "C") };
                    let t = f.define_fresh(&format!("{prefix}_{}", plain(f.name_of(x))), Def::Trig(tf, x), Span::DUMMY);
                    trig_of.insert((x, want_sin), t);
                    t
                }
            };
            vec![(Operand::Value(x), Partial::By(Operand::Value(other), want_sin))]
        }
        Def::Binary(op, a, b) => match op {
            BinOp::Add => vec![(a, Partial::One(false)), (b, Partial::One(false))],
            BinOp::Sub => vec![(a, Partial::One(false)), (b, Partial::One(true))],
            BinOp::Mul => vec![(a, Partial::By(b, false)), (b, Partial::By(a, false))],
            BinOp::Div => vec![(a, Partial::Over(b, false)), (b, Partial::QuotOver(Operand::Value(v), b))],
        },
        Def::Call(callee, args) => match Intrinsic::of(&callee, args.len()) {
            Some(Intrinsic::Sqrt) => {
                let a = args[0];
                let two = match twice.get(&v) {
                    Some(&t) => t,
                    None => {
                        let t = Operand::Value(f.define_fresh(
                            &format!("d_{}_2sqrt", plain(f.name_of(v))),
                            Def::Binary(BinOp::Add, Operand::Value(v), Operand::Value(v)),
                            Span::DUMMY,
                        ));
                        twice.insert(v, t);
                        t
                    }
                };
                vec![(a, Partial::Over(two, false))]
            }
            Some(i) => {
                let (x, y, z) = (args[0], args[1], args[2]);
                let (pn, sn) = match i {
                    Intrinsic::Fma => (false, false),
                    Intrinsic::Fms => (false, true),
                    _ => (true, false),
                };
                vec![(x, Partial::By(y, pn)), (y, Partial::By(x, pn)), (z, Partial::One(sn))]
            }
            None => {
                if args.iter().any(|a| matches!(a, Operand::Value(_))) {
                    return Err(format!(
                        "`%{}` calls the user callback `@{}`, whose derivative is unknown",
                        f.name_of(v),
                        callee.name
                    ));
                }
                vec![]
            }
        },
    })
}

/// Each value's partials, made once when first needed (a reverse sweep per output meets a value
/// once for every output that reaches it), with the trig variables and `2·√a` values they made.
struct Partials {
    of: Vec<Option<Vec<(Operand, Partial)>>>,
    trig_of: HashMap<(Value, bool), Value>,
    twice: HashMap<Value, Operand>,
}

impl Partials {
    /// The partials of `v` ([`partials`]); the error names the function.
    fn get(&mut self, f: &mut Function, v: Value) -> Result<&[(Operand, Partial)], Failure> {
        if self.of[v.index()].is_none() {
            let ps = partials(f, v, &mut self.trig_of, &mut self.twice)
                .map_err(|m| Failure::Message(format!("@{}: {m}", f.name)))?;
            self.of[v.index()] = Some(ps);
        }
        Ok(self.of[v.index()].as_deref().expect("made above"))
    }
}

/// `t · ∂` for one partial.
fn chain(b: &mut Builder, t: Option<Tan>, p: &Partial) -> Option<Tan> {
    match *p {
        Partial::One(neg) => t.map(|t| if neg { t.negated() } else { t }),
        Partial::By(x, neg) => b.scale(t, x).map(|t| if neg { t.negated() } else { t }),
        Partial::Over(d, neg) => b.divide(t, d).map(|t| if neg { t.negated() } else { t }),
        Partial::QuotOver(q, d) => {
            let s = b.scale(t, q);
            b.divide(s, d).map(Tan::negated)
        }
    }
}

/// What `auto` compares: the derivative terms each mode carries, `(Σ over values of the wrt
/// inputs that reach it, Σ over values of the outputs it reaches)`, the first the forward
/// sweep's tangents, the second the reverse sweeps' adjoints. Bit sets of inputs (outputs) per
/// value: O(values × ⌈inputs / 64⌉ + values × ⌈outputs / 64⌉) words and time.
fn sweep_terms(f: &Function, xs: &[Value], depends: &[bool]) -> (u64, u64) {
    let n = depends.len();
    let words = xs.len().div_ceil(64).max(1);
    let mut reach = vec![0u64; n * words];
    for (j, x) in xs.iter().enumerate() {
        reach[x.index() * words + j / 64] |= 1 << (j % 64);
    }
    let mut forward = 0u64;
    for &v in &f.body {
        if !depends[v.index()] {
            continue;
        }
        f.value(v).def.for_each_value(|a| {
            for w in 0..words {
                reach[v.index() * words + w] |= reach[a.index() * words + w];
            }
        });
        forward +=
            reach[v.index() * words..(v.index() + 1) * words].iter().map(|w| u64::from(w.count_ones())).sum::<u64>();
    }
    let outs: Vec<Value> = f
        .outputs
        .iter()
        .filter_map(|o| match o.value {
            Operand::Value(v) if depends[v.index()] => Some(v),
            _ => None,
        })
        .collect();
    let words = outs.len().div_ceil(64).max(1);
    let mut reached = vec![0u64; n * words];
    for (k, v) in outs.iter().enumerate() {
        reached[v.index() * words + k / 64] |= 1 << (k % 64);
    }
    let mut reverse = 0u64;
    for &v in f.body.iter().rev() {
        if !depends[v.index()] {
            continue;
        }
        reverse +=
            reached[v.index() * words..(v.index() + 1) * words].iter().map(|w| u64::from(w.count_ones())).sum::<u64>();
        f.value(v).def.for_each_value(|a| {
            for w in 0..words {
                reached[a.index() * words + w] |= reached[v.index() * words + w];
            }
        });
    }
    (forward, reverse)
}

/// Differentiates `f` (atomised, verified) in place: the derivative outputs of the module doc
/// for the inputs `wrt` names (every input when `wrt` is empty, by family then index), in
/// `mode` (`None`: by shape). Returns the mode used.
///
/// # Errors
/// A user callback on a path from a `wrt` input, a derivative output name already taken
/// ([`Failure::Message`]), or the time limit ([`Failure::Stopped`]).
pub fn differentiate(f: &mut Function, wrt: &[String], mode: Option<Mode>, ticker: &Ticker) -> Result<Mode, Failure> {
    f.placement = None;
    f.clear_timing();
    // The wrt inputs, in entry order, each entry's by index.
    let mut xs: Vec<(usize, Vec<u64>, Value)> = f
        .inputs
        .iter()
        .filter_map(|&v| {
            let k = if wrt.is_empty() { Some(0) } else { wrt.iter().position(|e| matches(e, f.name_of(v))) };
            k.map(|k| (k, indices(f.name_of(v)), v))
        })
        .collect();
    xs.sort_by(|a, b| (a.0, &a.1, f.name_of(a.2)).cmp(&(b.0, &b.1, f.name_of(b.2))));
    let xs: Vec<Value> = xs.into_iter().map(|x| x.2).collect();
    let mut slot = vec![u32::MAX; f.values.len()];
    for (j, &x) in xs.iter().enumerate() {
        slot[x.index()] = j as u32;
    }
    // Which values depend on a wrt input (one forward sweep), and the trig variables by angle.
    let mut depends = vec![false; f.values.len()];
    let mut trig_of: HashMap<(Value, bool), Value> = HashMap::new();
    for &x in &xs {
        depends[x.index()] = true;
    }
    for &v in &f.body {
        let d = &f.value(v).def;
        if let Def::Trig(fun, x) = d {
            trig_of.entry((*x, *fun == TrigFn::Sin)).or_insert(v);
        }
        let mut any = false;
        d.for_each_value(|a| any |= depends[a.index()]);
        depends[v.index()] = any;
    }
    let outputs: Vec<(String, Operand)> = f.outputs.iter().map(|o| (o.name.clone(), o.value)).collect();
    // Per output, the `xs` it is differentiated with respect to: its own state's.
    let columns: Vec<Vec<usize>> = outputs
        .iter()
        .map(|(o, _)| (0..xs.len()).filter(|&j| split_state(o).1 == split_state(f.name_of(xs[j])).1).collect())
        .collect();
    let mode = mode.unwrap_or_else(|| {
        let (forward, reverse) = sweep_terms(f, &xs, &depends);
        if forward <= reverse {
            Mode::Forward
        } else {
            Mode::Reverse
        }
    });
    for ((o, _), cols) in outputs.iter().zip(&columns) {
        for &j in cols {
            let name = derivative_name(o, f.name_of(xs[j]));
            if f.output_position(&name).is_some() || f.lookup(&name).is_some_and(|v| f.value(v).def == Def::Input) {
                return Err(Failure::Message(format!(
                    "@{}: `{name}`, the derivative of `{o}` with respect to `{}`, is already a name of the function",
                    f.name,
                    f.name_of(xs[j])
                )));
            }
        }
    }
    let twice = HashMap::new();
    let body: Vec<Value> = f.body.clone();
    let n = f.values.len();
    let mut partial_of = Partials { of: (0..n).map(|_| None).collect(), trig_of, twice };
    // The derivative of each output with respect to each of its columns, written at the end.
    let mut results: Vec<Vec<Option<Tan>>> = Vec::with_capacity(outputs.len());
    match mode {
        Mode::Forward => {
            // tangents[v]: (slot, ∂v/∂x_slot), sorted by slot, for every value v.
            let mut tangents: Vec<Vec<(u32, Tan)>> = vec![Vec::new(); n];
            for &x in &xs {
                tangents[x.index()] = vec![(slot[x.index()], Tan { op: Operand::Const(1.0), neg: false })];
            }
            for &v in &body {
                if ticker.tick() {
                    return Err(Failure::Stopped);
                }
                if !depends[v.index()] {
                    continue;
                }
                let ps = partial_of.get(f, v)?;
                let mut b = Builder::new(f, format!("d_{}", plain(f.name_of(v))));
                let mut acc: Vec<(u32, Option<Tan>)> = Vec::new();
                for (a, p) in ps {
                    let Operand::Value(a) = *a else { continue };
                    for &(j, t) in &tangents[a.index()] {
                        let term = chain(&mut b, Some(t), p);
                        match acc.binary_search_by_key(&j, |e| e.0) {
                            Ok(i) => acc[i].1 = b.add(acc[i].1, term),
                            Err(i) => acc.insert(i, (j, term)),
                        }
                    }
                }
                tangents[v.index()] = acc.into_iter().filter_map(|(j, t)| t.map(|t| (j, t))).collect();
            }
            for ((_, ov), cols) in outputs.iter().zip(&columns) {
                let ts: &[(u32, Tan)] = match ov {
                    Operand::Value(v) => &tangents[v.index()],
                    Operand::Const(_) => &[],
                };
                let at = |j: usize| ts.binary_search_by_key(&(j as u32), |e| e.0).ok().map(|i| ts[i].1);
                results.push(cols.iter().map(|&j| at(j)).collect());
            }
        }
        Mode::Reverse => {
            // Each value's position in the body, for a backward sweep from an output.
            let mut pos = vec![usize::MAX; n];
            for (i, &v) in body.iter().enumerate() {
                pos[v.index()] = i;
            }
            let mut adjoint: Vec<Option<Tan>> = vec![None; n];
            for ((o, ov), cols) in outputs.iter().zip(&columns) {
                let mut found: Vec<Option<Tan>> = vec![None; xs.len()];
                if let Operand::Value(ov) = *ov {
                    if depends[ov.index()] {
                        let mut touched = vec![ov];
                        adjoint[ov.index()] = Some(Tan { op: Operand::Const(1.0), neg: false });
                        if slot[ov.index()] != u32::MAX {
                            found[slot[ov.index()] as usize] = adjoint[ov.index()];
                        }
                        let start = pos[ov.index()];
                        if start != usize::MAX {
                            for k in (0..=start).rev() {
                                if ticker.tick() {
                                    return Err(Failure::Stopped);
                                }
                                let v = body[k];
                                let Some(t) = adjoint[v.index()] else { continue };
                                let ps = partial_of.get(f, v)?;
                                let mut b = Builder::new(f, format!("d_{}_d_{}", plain(o), plain(f.name_of(v))));
                                for (a, p) in ps {
                                    let Operand::Value(a) = *a else { continue };
                                    if !depends[a.index()] {
                                        continue;
                                    }
                                    let term = chain(&mut b, Some(t), p);
                                    let sum = b.add(adjoint[a.index()], term);
                                    if adjoint[a.index()].is_none() {
                                        touched.push(a);
                                    }
                                    adjoint[a.index()] = sum;
                                    if slot[a.index()] != u32::MAX {
                                        found[slot[a.index()] as usize] = sum;
                                    }
                                }
                            }
                        }
                        for v in touched {
                            adjoint[v.index()] = None;
                        }
                    }
                }
                results.push(cols.iter().map(|&j| found[j]).collect());
            }
        }
    }
    let mut b = Builder::new(f, "d_out".into());
    for (((o, _), cols), ds) in outputs.iter().zip(&columns).zip(results) {
        for (&j, t) in cols.iter().zip(ds) {
            let name = derivative_name(o, b.f.name_of(xs[j]));
            let value = b.materialise(t);
            b.f.set_output(name, value, Span::DUMMY);
        }
    }
    Ok(mode)
}
