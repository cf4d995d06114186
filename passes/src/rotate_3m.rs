//! `rotate-3m`: planar rotations by a joint's cosine and sine in three multiplies instead of
//! four (the 3M method, Gauss's trick for a complex product), where a placement's multiplies
//! outnumber its additions.
//!
//! Robotran rotates every vector of a body about the joint's axis: two of its components
//! become `u = c·x − s·y` and `v = s·x + c·y`, with `c = cos q` and `s = sin q` — four products
//! and two additions, run on the MULTI PEs and the ADD PEs (seed §1.1). On the dynamics
//! files the products outnumber the additions (WALK-MAN `dirdyna` after `balance`: 18 274 `mul`
//! against 14 923 `add`/`sub`), so from the N at which a placement is resource-bound the MULTI
//! PEs decide its length while the ADD PEs wait. With `t = c·(x + y)`,
//!
//! `u = t − y·(s + c)` and `v = t + x·(s − c)`,
//!
//! three products and three additions, where `s + c` and `s − c` are computed once per joint
//! (beside the trig values, at cycle 12): one `mul` becomes one `add` per rotated pair. Every
//! sign pattern Robotran writes (`u = ±c·x ± s·y`, `v = ±s·x ± c·y`, one `add` or `sub` each:
//! rotations by `q` and by `−q`, and reflections) takes the same form, `u = α·t + y·K_u`,
//! `v = δ·t + x·K_v` with `K_u = β·s − α·c` and `K_v = γ·s − δ·c` for `u = α·c·x + β·s·y` and
//! `v = γ·s·x + δ·c·y` (one of `±(s + c)`, `±(s − c)`; the sign goes into the final `add` or
//! `sub`). It is exact in real arithmetic and reads `c` and `s` as they are, so it does not
//! rely on `c² + s² = 1`; its rounding differs (N. J. Higham, "Stability of a method for
//! multiplying complex matrices with three real matrix multiplications", SIAM J. Matrix
//! Anal. Appl. 13(3), 1992: the 3M product's error is bounded like the 4M's, with a larger
//! constant in one component), and the `accuracy` pass measures it.
//!
//! # Which pairs
//! A pair is two `add`/`sub` values `u` and `v`, each reading two products of one joint's
//! `cos` and `sin` (one each) that nothing else reads, `u` those of `(cos, x)` and `(sin, y)`,
//! `v` those of `(sin, x)` and `(cos, y)`, with `x ≠ y` values. The new form is longer by one
//! addition (`x + y` before the product: `max(x, y) + add + mul + add` against
//! `+ mul + add`), so a pair is rewritten only where that keeps the critical path: in body
//! order, with the ready cycles updated as pairs are rewritten, a pair is taken when its new
//! ready cycles stay within the ALAPCycles of `u` and `v` (latency-weighted, SPEC §4), so the
//! ASAPCycle of the function does not change. With `pe=N` (the array `place<pe=N>` will use)
//! the pass rewrites only while the multiplies bound the placement, `⌈muls / N⌉ > max(critical
//! path, ⌈ADD-side ops / N⌉)` (SPEC §4's resource bound; ADD side: `add`, `sub`, `div`,
//! `call`, what the ADD PEs run), so a placement the critical path bounds pays no rounding for
//! nothing. Without it (`pe=0`, `until=balanced`) the pass stops when the `mul` ops no longer
//! outnumber the ADD-side ops, the point past which a further pair would load the ADD PEs
//! more than it relieves the MULTI PEs; `until=all` rewrites every pair it can.
//!
//! Measured on the corpus's 18 `dirdyna`/`invdyna` files after `cse,zero-removal,balance,cse`
//! (`scripts/rotate_3m.sh`, docs/rewrites.md): the three placements the multiplies bound at
//! N = 16 (coman, WALK-MAN and MX-5 `dirdyna`) take 2.7–4.3 % fewer cycles, for 0.15–0.18
//! more mean bits of error in `f32`.
//!
//! Runs on the atomised phase and keeps it; clears timing attributes; the dead products are
//! removed. For CPUs it gains nothing (a `mul` and an `add` cost the same there). Cost:
//! O(values + operands).

use std::collections::{HashMap, HashSet};

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{BinOp, Def, Function, Module, Operand, Phase, Span, TrigFn, Value};

use crate::params::ParamKind;
use crate::{AtTimeLimit, ParamInfo, Params, Pass, PassContext, PassError, PassInfo};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "rotate-3m",
    doc: "planar rotations by a joint's (cos, sin) in three multiplies and three adds instead of four and two \
          (the 3M method: u = t - y(s+c), v = t + x(s-c), t = c(x+y)), off the critical path, while the muls \
          outnumber the ADD-side ops: for placements whose MULTI PEs bound them",
    params: &[
        ParamInfo {
            name: "pe",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "N of the PE array to place on (N ADD + N MULTI): rewrite only while ⌈muls / N⌉ exceeds the critical \
                  path and ⌈ADD-side ops / N⌉; 0: see `until`",
        },
        ParamInfo {
            name: "until",
            kind: ParamKind::Choice { choices: &["balanced", "all"], default: "balanced" },
            doc: "with pe=0: stop when the muls no longer outnumber the ADD-side ops (`balanced`), or rewrite every \
                  pair that keeps the critical path (`all`)",
        },
        crate::params::LAT_ADD,
        crate::params::LAT_MUL,
        crate::params::LAT_DIV,
        crate::params::LAT_CALL,
    ],
    build: |p: &Params| {
        let stop = match (p.u32("pe")?, p.choice("until")?) {
            (0, "all") => Stop::All,
            (0, _) => Stop::Balanced,
            (n, _) => Stop::Placed(n),
        };
        Ok(Box::new(Rotate3m { stop, lat: p.latencies()?, given: p.latency_override()? }))
    },
};

/// Where [`rotate_function`] stops rewriting (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Every pair that keeps the critical path (`until=all`).
    All,
    /// When the `mul` ops no longer outnumber the ADD-side ops (`until=balanced`).
    Balanced,
    /// When `⌈muls / N⌉` no longer exceeds the critical path and `⌈ADD-side ops / N⌉`
    /// (`pe=N`).
    Placed(u32),
}

/// The `rotate-3m` pass.
#[derive(Clone, Debug)]
pub struct Rotate3m {
    /// Where to stop.
    pub stop: Stop,
    /// Latencies, cycles (replaced at run time by the pipeline's with `given` applied).
    pub lat: Latencies,
    /// Latencies given on the pass.
    pub given: crate::LatencyOverride,
}

/// What [`rotate_function`] did to one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rotated {
    /// Rotated pairs found (candidates).
    pub pairs: usize,
    /// Pairs rewritten (each: one `mul` fewer, one `add` more).
    pub rewritten: usize,
    /// `s + c` and `s − c` values added (at most two per joint).
    pub joint_sums: usize,
}

/// One side of a pair: `±(trig·other)` read by the `add`/`sub` value.
#[derive(Clone, Copy, Debug)]
struct Product {
    /// The product's value.
    value: Value,
    /// The joint coordinate the trig value is of.
    angle: Value,
    trig: TrigFn,
    /// The trig value.
    tv: Value,
    /// The other factor.
    other: Value,
    /// +1 or −1: the sign under which the `add`/`sub` reads it.
    sign: i8,
}

/// A candidate `u` (or `v`): the value and its two products.
#[derive(Clone, Copy, Debug)]
struct Half {
    value: Value,
    cos: Product,
    sin: Product,
}

impl Half {
    /// Which of `s ± c` this side reads (`K = b·s − a·c` for `a·c·(cos factor) + b·s·(sin
    /// factor)`: `s − c` when both signs are +, `±(s + c)` otherwise), and the sign `σ` of `K`
    /// against it.
    fn joint_sum(&self) -> (bool, i8) {
        match (self.sin.sign, self.cos.sign) {
            (1, 1) => (false, 1),
            (1, _) => (true, 1),
            _ => (true, -1),
        }
    }
}

/// The product `m`, read once (`uses`), as `trig(q)·other` with `other` a value.
fn product(f: &Function, uses: &[u32], m: Operand, sign: i8) -> Option<Product> {
    let Operand::Value(m) = m else { return None };
    if uses[m.index()] != 1 {
        return None;
    }
    let Def::Binary(BinOp::Mul, Operand::Value(a), Operand::Value(b)) = f.value(m).def else { return None };
    [(a, b), (b, a)].into_iter().find_map(|(t, other)| match f.value(t).def {
        Def::Trig(trig, angle) if t != other => Some(Product { value: m, angle, trig, tv: t, other, sign }),
        _ => None,
    })
}

/// `v` as a [`Half`], when it is `±(cos q·x) ± (sin q·y)` with `x ≠ y` (never both negated:
/// one `add` or `sub`).
fn half(f: &Function, uses: &[u32], v: Value) -> Option<Half> {
    let (p, q) = match f.value(v).def {
        Def::Binary(BinOp::Add, a, b) => (product(f, uses, a, 1)?, product(f, uses, b, 1)?),
        Def::Binary(BinOp::Sub, a, b) => (product(f, uses, a, 1)?, product(f, uses, b, -1)?),
        _ => return None,
    };
    let (cos, sin) = match (p.trig, q.trig) {
        (TrigFn::Cos, TrigFn::Sin) => (p, q),
        (TrigFn::Sin, TrigFn::Cos) => (q, p),
        _ => return None,
    };
    (cos.angle == sin.angle && cos.other != sin.other).then_some(Half { value: v, cos, sin })
}

/// The rotated pairs of `f`: `u` reads `cos·x` and `sin·y`, its partner `v` reads `sin·x` and
/// `cos·y` of the same trig values; each value in one pair at most, `u` the earlier in body
/// order.
fn pairs(f: &Function) -> Vec<(Half, Half)> {
    let uses = f.use_counts();
    let halves: Vec<Half> = f.body.iter().filter_map(|&v| half(f, &uses, v)).collect();
    // Keyed by (cos value, cos's factor, sin's factor): u finds v under the swapped factors.
    let mut by_key: HashMap<(Value, Value, Value), usize> = HashMap::with_capacity(halves.len());
    for (i, h) in halves.iter().enumerate() {
        by_key.entry((h.cos.tv, h.cos.other, h.sin.other)).or_insert(i);
    }
    let mut taken = vec![false; halves.len()];
    let mut out = Vec::new();
    for (i, h) in halves.iter().enumerate() {
        if taken[i] {
            continue;
        }
        let Some(&j) = by_key.get(&(h.cos.tv, h.sin.other, h.cos.other)) else { continue };
        if j != i && !taken[j] && halves[j].sin.tv == h.sin.tv {
            taken[i] = true;
            taken[j] = true;
            // The form is symmetric in the two sides: the earlier is `u`.
            out.push((halves[i.min(j)], halves[i.max(j)]));
        }
    }
    out
}

/// Rewrites the rotated pairs of `f` in three multiplies (module doc), until `stop`.
/// `f` must be atomised and verify; the result verifies, computes the same outputs in real
/// arithmetic and has the same ASAPCycle under `lat`. Cost: O(values + operands).
pub fn rotate_function(f: &mut Function, lat: &Latencies, stop: Stop) -> Rotated {
    let found = pairs(f);
    let mut out = Rotated { pairs: found.len(), ..Rotated::default() };
    if found.is_empty() {
        return out;
    }
    let mut pair_of: HashMap<Value, usize> = HashMap::with_capacity(2 * found.len());
    for (k, (u, v)) in found.iter().enumerate() {
        pair_of.insert(u.value, k);
        pair_of.insert(v.value, k);
    }
    let (timing, summary) = compute_timing(f, lat);
    let path = i64::from(summary.asap_cycle);
    let alap = |v: Value| timing[v.index()].map_or(0, |t| t.alap_cycle);
    let counts = f.op_counts();
    let (mut muls, mut add_side) = (counts.mul as i64, (counts.add + counts.sub + counts.div + counts.call) as i64);
    // Ready cycles with the rewrites chosen so far (inputs and trig values at 0); a rewritten
    // pair's values get theirs when the first of them is reached.
    let mut ready = vec![0u32; f.values.len()];
    let mut set = vec![false; f.values.len()];
    let mut chosen = vec![false; found.len()];
    let mut sums: HashSet<(Value, bool)> = HashSet::new();
    for k in 0..f.body.len() {
        let v = f.body[k];
        if set[v.index()] {
            continue;
        }
        let def = &f.value(v).def;
        let Some(kind) = def.op_kind() else { continue };
        let mut r = 0;
        def.for_each_value(|p| r = r.max(ready[p.index()]));
        ready[v.index()] = r + lat.of(kind);
        let Some(&p) = pair_of.get(&v) else { continue };
        let go_on = match stop {
            Stop::All => true,
            Stop::Balanced => muls > add_side,
            Stop::Placed(n) => {
                let n = i64::from(n);
                (muls + n - 1) / n > path.max((add_side + n - 1) / n)
            }
        };
        if !go_on {
            break;
        }
        let (u, w) = &found[p];
        let (x, y) = (u.cos.other, u.sin.other);
        let (rx, ry) = (ready[x.index()], ready[y.index()]);
        let t = rx.max(ry) + lat.add + lat.mul;
        // The joint sums are ready one addition after the trig values.
        let u_ready = t.max(ry.max(lat.add) + lat.mul) + lat.add;
        let w_ready = t.max(rx.max(lat.add) + lat.mul) + lat.add;
        if u_ready > alap(u.value) || w_ready > alap(w.value) {
            continue;
        }
        let joint = [(u.cos.angle, u.joint_sum().0), (u.cos.angle, w.joint_sum().0)];
        let new_sums = joint.into_iter().filter(|&k| sums.insert(k)).count() as i64;
        chosen[p] = true;
        (ready[u.value.index()], ready[w.value.index()]) = (u_ready, w_ready);
        set[u.value.index()] = true;
        set[w.value.index()] = true;
        muls -= 1;
        add_side += 1 + new_sums;
    }
    // Write the new values (appended to the body, then moved before the pair's first value).
    let old_body = f.body.clone();
    let mut before: HashMap<Value, Vec<Value>> = HashMap::new();
    let mut joint: HashMap<(Value, Value, bool), Value> = HashMap::new();
    let mut dead: HashSet<Value> = HashSet::new();
    for (&(u, w), _) in found.iter().zip(&chosen).filter(|(_, &c)| c) {
        let mut new = Vec::new();
        let (c, s) = (u.cos.tv, u.sin.tv);
        let (x, y) = (u.cos.other, u.sin.other);
        let base = f.name_of(u.value).to_string();
        let bin = |op, a: Value, b: Value| Def::Binary(op, Operand::Value(a), Operand::Value(b));
        let xy = f.define_fresh(&format!("{base}.xy"), bin(BinOp::Add, x, y), Span::DUMMY);
        let t = f.define_fresh(&format!("{base}.t"), bin(BinOp::Mul, c, xy), Span::DUMMY);
        new.extend([xy, t]);
        // u = α·t + y·K_u, v = δ·t + x·K_v (module doc); K = σ·(s ± c).
        for (h, factor) in [(u, y), (w, x)] {
            let (plus, sigma) = h.joint_sum();
            let kv = match joint.get(&(s, c, plus)) {
                Some(&k) => k,
                None => {
                    let name = format!("{}.{}", f.name_of(s), if plus { "pc" } else { "mc" });
                    let k = f.define_fresh(&name, bin(if plus { BinOp::Add } else { BinOp::Sub }, s, c), Span::DUMMY);
                    joint.insert((s, c, plus), k);
                    new.push(k);
                    out.joint_sums += 1;
                    k
                }
            };
            let name = format!("{}.k", f.name_of(h.value));
            let p = f.define_fresh(&name, bin(BinOp::Mul, factor, kv), Span::DUMMY);
            new.push(p);
            f.value_mut(h.value).def = match (h.cos.sign, sigma) {
                (1, 1) => bin(BinOp::Add, t, p),
                (1, _) => bin(BinOp::Sub, t, p),
                _ => bin(BinOp::Sub, p, t),
            };
            dead.extend([h.cos.value, h.sin.value]);
        }
        before.insert(u.value, new);
        out.rewritten += 1;
    }
    if out.rewritten == 0 {
        return out;
    }
    let mut body = Vec::with_capacity(f.body.len());
    for v in old_body {
        if let Some(new) = before.remove(&v) {
            body.extend(new);
        }
        body.push(v);
    }
    f.body = body;
    f.retain(|_, v| !dead.contains(&v));
    f.clear_timing();
    out
}

impl Pass for Rotate3m {
    fn name(&self) -> &'static str {
        "rotate-3m"
    }

    fn requires(&self) -> Option<Phase> {
        Some(Phase::Atomised)
    }

    fn at_time_limit(&self) -> AtTimeLimit {
        AtTimeLimit::Skip
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let lat = cx.latencies_for("rotate-3m", &self.given);
        let ticker = cx.ticker();
        let mut parts = Vec::new();
        for (k, f) in m.functions.iter_mut().enumerate() {
            // `-time-limit`: one linear sweep per function, so the clock is read between them.
            if ticker.check() {
                cx.note_stop("rotate-3m", &format!("before @{} ({k} functions done): {}", f.name, ticker.reason()));
                break;
            }
            let r = rotate_function(f, &lat, self.stop);
            parts.push(format!(
                "@{} {} of {} rotated pairs in three multiplies ({} joint sums added)",
                f.name, r.rewritten, r.pairs, r.joint_sums
            ));
        }
        cx.notes.push(format!("rotate-3m: {}", parts.join("; ")));
        Ok(())
    }
}

#[cfg(test)]
mod tests;
