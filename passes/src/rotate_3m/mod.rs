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
//! (beside the trig values, at cycle 12): one `mul` becomes one `add` per rotated pair. It is
//! exact in real arithmetic and reads `c` and `s` as they are, so it does not rely on
//! `c² + s² = 1`; its rounding differs (N. J. Higham, "Stability of a method for multiplying
//! complex matrices with three real matrix multiplications", SIAM J. Matrix Anal. Appl. 13(3),
//! 1992: the 3M product's error is bounded like the 4M's, with a larger constant in one
//! component), and the `accuracy` pass measures it.
//!
//! # Which pairs
//! The four products `c·x`, `s·y`, `s·x`, `c·y` of one joint's trig values (`x ≠ y` values),
//! each read once, as terms of sums: a sum is a cluster of `add`/`sub` ops whose inner ops are
//! read once (after `balance` a rotation's two products are often two terms of a larger sum,
//! a body's velocity or force). `u` is the sum with `α·c·x` and `β·s·y`, `v` the one with
//! `γ·s·x` and `δ·c·y` (signs ±1 from the path to the sum's root; `u` and `v` may be one sum),
//! found by `pairs::find`. Since `α·c·x + β·s·y = α·t + β·y·(s − αβ·c)` and
//! `γ·s·x + δ·c·y = δ·t + γ·x·(s − γδ·c)`, `t` takes the place of the two `cos` products and
//! `y·(s ∓ c)`, `x·(s ∓ c)` those of the `sin` products, each term keeping its sign: every sign
//! pattern (rotations by `q` and `−q`, reflections, either operand order) is the same rewrite.
//!
//! # Where
//! The replacements are ready one addition later (`t` at `max(x, y) + add + mul` against
//! `+ mul`), so a pair is rewritten only where that keeps the critical path: in body order,
//! with the ready cycles updated as pairs are rewritten, a pair is taken when each replacement
//! is ready by the ALAPCycle of the product it replaces (latency-weighted, SPEC §4); every op
//! then stays within its ALAPCycle and the ASAPCycle of the function does not change. With
//! `pe=N` (the array `place<pe=N>` will use) the pass rewrites only while the multiplies bound
//! the placement, `⌈muls / N⌉ > max(critical path, ⌈ADD-side ops / N⌉)` (SPEC §4's resource
//! bound; ADD side: `add`, `sub`, `div`, `call`, what the ADD PEs run), so a placement the
//! critical path bounds pays no rounding for nothing. Without it (`pe=0`, `until=balanced`) the
//! pass stops when the `mul` ops no longer outnumber the ADD-side ops, past which a further pair
//! would load the ADD PEs more than it relieves the MULTI PEs; `until=all` rewrites every pair
//! that keeps the critical path. (Letting the path grow towards the resource bound rewrites more
//! pairs but places no faster: WALK-MAN `dirdyna` at N = 16, 1102 cycles on an 831-cycle path,
//! 1107–1112 with the path let grow to 882–1035.)
//!
//! Measured on the corpus's 18 `dirdyna`/`invdyna` files after `cse,zero-removal,balance,cse`
//! (`scripts/rotate_3m.sh`, docs/rewrites.md): the three placements the multiplies bound at
//! N = 16 (coman, WALK-MAN and MX-5 `dirdyna`) take 2.7–6.2 % fewer cycles, for 0.17–0.20
//! more mean bits of error in `f32`; the others are unchanged.
//!
//! Runs on the atomised phase and keeps it; clears timing attributes; the dead products are
//! removed. For CPUs it gains nothing (a `mul` and an `add` cost the same there). Cost:
//! O(values + operands).

use std::collections::{HashMap, HashSet};

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{BinOp, Def, Function, Module, Operand, Span, Value};

mod pairs;

use crate::params::ParamKind;
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

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
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
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

/// Rewrites the rotated pairs of `f` in three multiplies (module doc), until `stop`. `f` must
/// be atomised and verify; the result verifies, computes the same outputs in real arithmetic
/// and has the same ASAPCycle under `lat`. Cost: O(values + operands).
pub fn rotate_function(f: &mut Function, lat: &Latencies, stop: Stop) -> Rotated {
    let position = pairs::body_positions(f);
    let found = pairs::find(f, &position);
    let mut out = Rotated { pairs: found.len(), ..Rotated::default() };
    if found.is_empty() {
        return out;
    }
    // The pairs whose products each `add`/`sub` reads.
    let mut pair_of: HashMap<Value, Vec<usize>> = HashMap::with_capacity(4 * found.len());
    for (k, p) in found.iter().enumerate() {
        for r in p.readers() {
            pair_of.entry(r).or_default().push(k);
        }
    }
    let (timing, summary) = compute_timing(f, lat);
    let alap = |v: Value| timing[v.index()].map_or(0, |t| t.alap_cycle);
    let (mut add_side, mut muls) = crate::place::ops_per_side(f);
    let path = u64::from(summary.asap_cycle);
    // Ready cycles with the rewrites chosen so far (inputs and trig values at 0). A rewritten
    // pair's products stand for what replaces them in their sums (`t`, `y·K_u`, `x·K_v`),
    // decided when the first of their readers is reached: `x` and `y` are ready by then
    // (`pairs::find` takes only such pairs).
    let mut ready = vec![0u32; f.values.len()];
    let mut set = vec![false; f.values.len()];
    let mut decided = vec![false; found.len()];
    let mut chosen = vec![false; found.len()];
    let mut sums: HashSet<(Value, Value, bool)> = HashSet::new();
    for k in 0..f.body.len() {
        let v = f.body[k];
        for &p in pair_of.get(&v).map_or(&[][..], Vec::as_slice) {
            if !decided[p] {
                decided[p] = true;
                let go_on = match stop {
                    Stop::All => true,
                    Stop::Balanced => muls > add_side,
                    Stop::Placed(n) => {
                        let n = u64::from(n);
                        muls.div_ceil(n) > path.max(add_side.div_ceil(n))
                    }
                };
                let q = &found[p];
                let (rx, ry) = (ready[q.cx.other.index()], ready[q.sy.other.index()]);
                // t = c·(x + y); the joint sums are ready one addition after the trig values.
                let t = rx.max(ry) + lat.add + lat.mul;
                let (ku, kv) = (ry.max(lat.add) + lat.mul, rx.max(lat.add) + lat.mul);
                let fits =
                    t <= alap(q.cx.value) && t <= alap(q.cy.value) && ku <= alap(q.sy.value) && kv <= alap(q.sx.value);
                if go_on && fits {
                    chosen[p] = true;
                    for (m, r) in [(q.cx, t), (q.cy, t), (q.sy, ku), (q.sx, kv)] {
                        ready[m.value.index()] = r;
                        set[m.value.index()] = true;
                    }
                    let new_sums = q.joint_sums().into_iter().filter(|&k| sums.insert(k)).count() as u64;
                    muls -= 1;
                    add_side += 1 + new_sums;
                }
            }
        }
        if set[v.index()] {
            continue;
        }
        let def = &f.value(v).def;
        let Some(kind) = def.op_kind() else { continue };
        let mut r = 0;
        def.for_each_value(|p| r = r.max(ready[p.index()]));
        ready[v.index()] = r + lat.of(kind);
    }
    // Write the new values (appended to the body, then moved before the pair's first reader)
    // and put them in the products' places in their sums.
    let old_body = f.body.clone();
    let mut before: HashMap<Value, Vec<Value>> = HashMap::new();
    let mut after: HashMap<Value, Vec<Value>> = HashMap::new();
    let mut joint: HashMap<(Value, Value, bool), Value> = HashMap::new();
    let mut replace: HashMap<Value, Value> = HashMap::new();
    let bin = |op, a: Value, b: Value| Def::Binary(op, Operand::Value(a), Operand::Value(b));
    for q in found.iter().zip(&chosen).filter(|(_, &c)| c).map(|(q, _)| q) {
        let mut new = Vec::new();
        let (c, s, x, y) = (q.cx.trig, q.sy.trig, q.cx.other, q.sy.other);
        let base = f.name_of(q.cx.value).to_string();
        let xy = f.define_fresh(&format!("{base}.xy"), bin(BinOp::Add, x, y), Span::DUMMY);
        let t = f.define_fresh(&format!("{base}.t"), bin(BinOp::Mul, c, xy), Span::DUMMY);
        new.extend([xy, t]);
        // In u, α·c·x + β·s·y = α·t + β·y·(s − αβ·c); in v, γ·s·x + δ·c·y = δ·t + γ·x·(s − γδ·c):
        // `t` takes the cos product's place, `y·K` or `x·K` the sin product's, with its sign.
        for ((cos, sin, factor), key) in [(q.cx, q.sy, y), (q.cy, q.sx, x)].into_iter().zip(q.joint_sums()) {
            let plus = key.2;
            let k = match joint.get(&key) {
                Some(&k) => k,
                None => {
                    let name = format!("{}.{}", f.name_of(s), if plus { "pc" } else { "mc" });
                    let k = f.define_fresh(&name, bin(if plus { BinOp::Add } else { BinOp::Sub }, s, c), Span::DUMMY);
                    joint.insert(key, k);
                    // Shared by the joint's pairs: right after the later of `s` and `c`.
                    // (Trig values are body values, defined before the products that read them.)
                    let at = if position[s.index()] > position[c.index()] { s } else { c };
                    after.entry(at).or_default().push(k);
                    out.joint_sums += 1;
                    k
                }
            };
            let p = f.define_fresh(&format!("{}.k", f.name_of(sin.value)), bin(BinOp::Mul, factor, k), Span::DUMMY);
            new.push(p);
            replace.insert(cos.value, t);
            replace.insert(sin.value, p);
        }
        let first = q.readers().into_iter().min_by_key(|m| position[m.index()]).expect("four readers");
        before.entry(first).or_default().extend(new);
        out.rewritten += 1;
    }
    if out.rewritten == 0 {
        return out;
    }
    for &v in &old_body {
        if let Def::Binary(BinOp::Add | BinOp::Sub, a, b) = &mut f.value_mut(v).def {
            for x in [a, b] {
                if let Operand::Value(m) = x {
                    if let Some(&r) = replace.get(m) {
                        *x = Operand::Value(r);
                    }
                }
            }
        }
    }
    let mut body = Vec::with_capacity(f.body.len());
    for v in old_body {
        if let Some(new) = before.remove(&v) {
            body.extend(new);
        }
        body.push(v);
        if let Some(new) = after.remove(&v) {
            body.extend(new);
        }
    }
    f.body = body;
    f.retain(|_, v| !replace.contains_key(&v));
    f.clear_timing();
    out
}

impl Pass for Rotate3m {
    fn name(&self) -> &'static str {
        "rotate-3m"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let lat = cx.latencies_for("rotate-3m", &self.given);
        // `-time-limit`: one linear sweep per function, so the clock is read between them.
        let skipped = |f: &Function, k| Some(format!("before @{} ({k} functions done)", f.name));
        let parts = each_function(m, cx, "rotate-3m", Before::Clock, skipped, |f, _, _| {
            let r = rotate_function(f, &lat, self.stop);
            Step::Done(format!(
                "@{} {} of {} rotated pairs in three multiplies ({} joint sums added)",
                f.name, r.rewritten, r.pairs, r.joint_sums
            ))
        });
        cx.remark("rotate-3m", m, format!("rotate-3m: {}", parts.join("; ")));
        Ok(())
    }
}

#[cfg(test)]
mod tests;
