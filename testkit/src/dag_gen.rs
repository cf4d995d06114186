//! Synthetic Robotran-like DAGs for tests and benchmarks: [`generate`]`(n_ops, seed)` returns
//! an atomised function with exactly `n_ops` operations.
//!
//! # Shape (what is imitated and from where)
//! The body is a sequence of *equations*, each atomised as SPEC §3 does a Robotran equation:
//! a sum of 1–5 terms (`add`/`sub` cascaded left to right), each term a product of 1–3 factors
//! (`mul` cascaded left to right), sometimes negated (`0 - t`). The root op of an equation is
//! named like a Robotran temporary (`OM17`, `AlF42`, `FA355`), intermediate ops `NAME.1`,
//! `NAME.2`, … as `atomise` names them. With these proportions the mix is ≈ 55 % `mul`,
//! 25 % `add`, 20 % `sub` (the corpus file `walkman__mbs_dirdyna_walkman_robotran.m` has 55 % /
//! 26 % / 19 %).
//!
//! A factor is
//! - an input (17 %): `q[b]`, `qd[b]`, `dpt[k][b]`, `l[k][b]`, `m[b]`, `In[k][b]`, `g[k]`,
//!   `frc[k][b]`, `trq[k][b]`, with `b` the body the equation is about (bodies advance with the
//!   equations, so inputs are local too);
//! - a trig initial variable (12 %): `C4 = cos %q[4]`, `S4 = sin %q[4]`;
//! - a constant (1 %);
//! - otherwise the result of an earlier equation: 80 % of the time a *recent* one — between
//!   `gap` and `2·gap` equations back — and 20 % of the time any equation at least `gap` back
//!   (long-range reuse). The walkman corpus file reads 16 % inputs, 12 % trig, 1 % constants.
//!
//! # Critical path
//! Every reference to another equation jumps back at least `gap` equations, so a path crosses
//! at most `equations / gap` equations, each adding a few ops of its cascade. With
//! `gap = 0.75·√n_ops` equations (≈ 3.4·√n ops back: ≈ 650 values at 37k ops, ≈ 2 600 at 600k)
//! the critical path grows like `√n_ops`, as in seed Table 3.1 (serial systems: 20k ops → ASAP
//! 342, 94k → 757, 367k → 1517, 620k → 1965; the walkman corpus file: 37.6k ops → ASAP 179,
//! ASAPCycle 2013). Measured here with seed 1, ASAP / ASAPCycle (default latencies): 10k ops →
//! 104 / 1093, 37.6k → 202 / 2160, 100k → 335 / 3590, 600k → 814 / 8669.

//! # Outputs
//! Every op whose result no op reads becomes an output `Qq[i]` (1-based, in body order).
//!
//! Deterministic for a seed ([`SplitMix64`], the workspace's one generator). Cost: O(n_ops) time
//! and memory; 600k ops take ≈ 0.4 s in release builds (0.4–0.6 s measured on a loaded 2-core
//! machine), of which ≈ 0.05 s is the DAG itself and the rest the value names and the function's
//! name index.

use robovec_ir::rng::SplitMix64;
use robovec_ir::{BinOp, Def, Function, Operand, Output, Phase, Span, TrigFn, Value, ValueData};

/// An operand while generating: a leaf slot, an op (index into the op list) or a constant.
#[derive(Clone, Copy, Debug)]
enum Src {
    Input(u32),
    Trig(u32),
    Op(u32),
    Const(f64),
}

/// One generated op: operator, operands, equation number and position (0 = the equation's root).
struct RawOp {
    op: BinOp,
    a: Src,
    b: Src,
    eq: u32,
    k: u32,
}

/// Input families: (name, range of the leading index `k` (0 = none), weight per mille). All but
/// `g` also carry a body index.
const FAMILIES: &[(&str, u32, u32)] = &[
    ("q", 0, 60),
    ("qd", 0, 200),
    ("dpt", 3, 200),
    ("l", 3, 100),
    ("m", 0, 100),
    ("In", 9, 150),
    ("g", 3, 50),
    ("frc", 3, 70),
    ("trq", 3, 70),
];

/// Robotran temporary prefixes for equation roots (none is `C`/`S` + digits, so no clash with
/// trig names).
const PREFIXES: &[&str] = &["OM", "AlF", "FA", "FM", "OpF", "CF", "AlM", "OpM", "BS", "RLlink", "Dz", "Fq"];

/// Leaf slots: inputs are numbered `family * stride + k * (dof + 1) + b`, trig `b * 2 + (sin)`.
struct Leaves {
    dof: u32,
}

impl Leaves {
    fn stride(&self) -> u32 {
        10 * (self.dof + 1)
    }

    /// An input of the equation about body `body` (1-based).
    fn input(&self, rng: &mut SplitMix64, body: u32) -> u32 {
        let mut r = rng.below(1000) as u32;
        let mut fam = 0;
        for (i, &(_, _, w)) in FAMILIES.iter().enumerate() {
            if r < w {
                fam = i;
                break;
            }
            r -= w;
        }
        let (_, nk, _) = FAMILIES[fam];
        let k = if nk == 0 { 0 } else { 1 + rng.below(nk as u64) as u32 };
        // `g[k]` has no body index; everything else is about this body or a neighbour.
        let b = if FAMILIES[fam].0 == "g" { 0 } else { self.near(rng, body) };
        fam as u32 * self.stride() + k * (self.dof + 1) + b
    }

    /// A trig variable of the equation about body `body`.
    fn trig(&self, rng: &mut SplitMix64, body: u32) -> u32 {
        self.near(rng, body) * 2 + rng.below(2) as u32
    }

    /// `body` most of the time, else the previous body (the parent in a chain).
    fn near(&self, rng: &mut SplitMix64, body: u32) -> u32 {
        if body > 1 && rng.chance(300) {
            body - 1
        } else {
            body
        }
    }

    fn input_name(&self, slot: u32) -> String {
        let (fam, rest) = (slot / self.stride(), slot % self.stride());
        let (k, b) = (rest / (self.dof + 1), rest % (self.dof + 1));
        let name = FAMILIES[fam as usize].0;
        match (k, b) {
            (0, b) => format!("{name}[{b}]"),
            (k, 0) => format!("{name}[{k}]"),
            (k, b) => format!("{name}[{k}][{b}]"),
        }
    }

    fn trig_input(&self, slot: u32) -> u32 {
        slot / 2 // `q` is family 0 with no k: slot = b
    }
}

struct Gen {
    rng: SplitMix64,
    leaves: Leaves,
    ops: Vec<RawOp>,
    /// Op index of each equation's root.
    roots: Vec<u32>,
    /// Minimum distance, in equations, of a reference to another equation.
    gap: usize,
    /// Equations per body (bodies advance with the equations).
    eqs_per_body: usize,
}

impl Gen {
    fn factor(&mut self, eq: usize) -> Src {
        let body = 1 + ((eq / self.eqs_per_body) as u32 % self.leaves.dof);
        let r = self.rng.below(1000);
        if r < 170 || (r >= 300 && eq < self.gap) {
            return Src::Input(self.leaves.input(&mut self.rng, body));
        }
        if r < 290 {
            return Src::Trig(self.leaves.trig(&mut self.rng, body));
        }
        if r < 300 {
            const CONSTS: [f64; 5] = [0.5, 2.0, 9.81, 0.25, 3.0];
            return Src::Const(CONSTS[self.rng.below(5) as usize]);
        }
        let last = eq.min(self.roots.len()) - self.gap; // newest eligible equation
        let j = if self.rng.chance(800) {
            last.saturating_sub(self.rng.below(self.gap as u64) as usize)
        } else {
            self.rng.below(last as u64 + 1) as usize
        };
        Src::Op(self.roots[j])
    }

    fn emit(&mut self, op: BinOp, a: Src, mut b: Src, eq: usize, budget: &mut usize) -> Src {
        if let (Src::Const(_), Src::Const(_)) = (a, b) {
            b = Src::Trig(2); // `C1`
        }
        *budget -= 1;
        let k = self.ops.iter().rev().take_while(|o| o.eq == eq as u32).count() as u32 + 1;
        self.ops.push(RawOp { op, a, b, eq: eq as u32, k });
        Src::Op(self.ops.len() as u32 - 1)
    }

    /// Emits one equation (or as much of it as `budget` allows).
    fn equation(&mut self, budget: &mut usize) {
        let eq = self.roots.len();
        let first = self.ops.len();
        let terms = 1 + self.rng.below(5);
        let mut acc: Option<Src> = None;
        'eq: for _ in 0..terms {
            let r = self.rng.below(100);
            let mut factors = if r < 35 {
                1
            } else if r < 83 {
                2
            } else {
                3
            };
            if terms == 1 && factors == 1 {
                factors = 2;
            }
            let mut prod = self.factor(eq);
            for _ in 1..factors {
                if *budget == 0 {
                    break 'eq;
                }
                let x = self.factor(eq);
                prod = self.emit(BinOp::Mul, prod, x, eq, budget);
            }
            acc = Some(match acc {
                None => prod,
                Some(a) => {
                    if *budget == 0 {
                        break 'eq;
                    }
                    let op = if self.rng.chance(410) { BinOp::Sub } else { BinOp::Add };
                    self.emit(op, a, prod, eq, budget)
                }
            });
        }
        if *budget > 0 && self.ops.len() > first && self.rng.chance(80) {
            let a = acc.expect("an op was emitted");
            self.emit(BinOp::Sub, Src::Const(0.0), a, eq, budget);
        }
        if self.ops.len() > first {
            // The last op emitted is the root (when the budget cut the equation short, the
            // partial term is the root and the partial sum before it one more sink).
            let root = self.ops.len() - 1;
            self.ops[root].k = 0;
            self.roots.push(root as u32);
        }
    }
}

/// A synthetic atomised function with exactly `n_ops` operations (see the module doc for the
/// shape); verifies, and is the same for the same `(n_ops, seed)`.
pub fn generate(n_ops: usize, seed: u64) -> Function {
    let dof = ((n_ops as f64).sqrt() / 4.0).round().clamp(3.0, 400.0) as u32;
    let gap = ((n_ops as f64).sqrt() * 0.75).round().max(1.0) as usize;
    let eqs_per_body = (n_ops / 5 / dof as usize).max(1);
    let mut g = Gen {
        rng: SplitMix64::new(seed ^ 0x005E_ED0F_D0F5),
        leaves: Leaves { dof },
        ops: Vec::with_capacity(n_ops),
        roots: Vec::with_capacity(n_ops / 3 + 1),
        gap,
        eqs_per_body,
    };
    let mut budget = n_ops;
    while budget > 0 {
        g.equation(&mut budget);
    }
    build(&g, n_ops, seed)
}

/// Turns the raw ops into a [`Function`]: used inputs (first-use order), trig, ops, outputs.
fn build(g: &Gen, n_ops: usize, seed: u64) -> Function {
    let mut f = Function::new(format!("synthetic_{n_ops}_{seed}"), Phase::Atomised);
    f.equations = Some(g.roots.len() as u32);
    let leaves = &g.leaves;
    let mut input_val: Vec<Option<Value>> = vec![None; FAMILIES.len() * leaves.stride() as usize];
    let mut trig_order: Vec<u32> = Vec::new();
    let mut trig_seen = vec![false; 2 * (leaves.dof as usize + 1)];
    {
        let mut touch_input = |f: &mut Function, slot: u32| {
            if input_val[slot as usize].is_none() {
                input_val[slot as usize] =
                    Some(f.add_input(leaves.input_name(slot), Span::DUMMY).expect("input names are unique"));
            }
        };
        for o in &g.ops {
            for s in [o.a, o.b] {
                match s {
                    Src::Input(slot) => touch_input(&mut f, slot),
                    Src::Trig(slot) => {
                        touch_input(&mut f, leaves.trig_input(slot));
                        if !std::mem::replace(&mut trig_seen[slot as usize], true) {
                            trig_order.push(slot);
                        }
                    }
                    _ => {}
                }
            }
        }
    }
    let mut trig_val = vec![None; trig_seen.len()];
    for &slot in &trig_order {
        let (func, letter) = if slot % 2 == 0 { (TrigFn::Cos, 'C') } else { (TrigFn::Sin, 'S') };
        let q = input_val[leaves.trig_input(slot) as usize].expect("q input made");
        let v = f.define(format!("{letter}{}", slot / 2), Def::Trig(func, q), Span::DUMMY).expect("unique trig name");
        trig_val[slot as usize] = Some(v);
    }
    let mut op_val: Vec<Value> = Vec::with_capacity(g.ops.len());
    f.values.reserve(g.ops.len());
    f.body.reserve(g.ops.len());
    let mut used = vec![false; g.ops.len()];
    for o in &g.ops {
        let mut operand = |s: Src| match s {
            Src::Input(slot) => Operand::Value(input_val[slot as usize].expect("input made")),
            Src::Trig(slot) => Operand::Value(trig_val[slot as usize].expect("trig defined")),
            Src::Op(i) => {
                used[i as usize] = true;
                Operand::Value(op_val[i as usize])
            }
            Src::Const(c) => Operand::Const(c),
        };
        let def = Def::Binary(o.op, operand(o.a), operand(o.b));
        let prefix = PREFIXES[o.eq as usize % PREFIXES.len()];
        let mut name = String::with_capacity(prefix.len() + 12);
        name.push_str(prefix);
        push_decimal(&mut name, o.eq);
        if o.k > 0 {
            name.push('.');
            push_decimal(&mut name, o.k);
        }
        // Names are unique by construction: push straight into the arena and index the names
        // once at the end (`define` would hash every name twice and grow the index 20 times).
        op_val.push(Value::with_number(f.values.len() as u32));
        f.body.push(Value::with_number(f.values.len() as u32));
        f.values.push(ValueData { name, def, span: Span::DUMMY });
    }
    f.reindex_names();
    let mut i = 0;
    for (k, &v) in op_val.iter().enumerate() {
        if !used[k] {
            i += 1;
            // Names are distinct: push directly (`set_output` searches the outputs by name).
            f.outputs.push(Output { name: format!("Qq[{i}]"), value: Operand::Value(v), span: Span::DUMMY });
        }
    }
    f
}

/// Appends `x` in decimal (faster than `format!` for the 600k names).
fn push_decimal(s: &mut String, mut x: u32) {
    let mut buf = [0u8; 10];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (x % 10) as u8;
        x /= 10;
        if x == 0 {
            break;
        }
    }
    s.push_str(std::str::from_utf8(&buf[i..]).expect("ASCII digits"));
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::analysis::{compute_timing, Latencies};
    use robovec_ir::verifier::verify_function;

    #[test]
    fn verifies_with_exact_op_count() {
        for n in [0, 1, 2, 3, 7, 10, 30, 100, 1000, 5000] {
            for seed in 0..4 {
                let f = generate(n, seed);
                let errs = verify_function(&f);
                assert!(errs.is_empty(), "n={n} seed={seed}: {errs:?}");
                assert_eq!(f.phase, Phase::Atomised);
                assert_eq!(f.op_counts().total, n as u64, "n={n} seed={seed}");
                assert_eq!(f.outputs.is_empty(), n == 0);
            }
        }
    }

    #[test]
    fn deterministic_per_seed() {
        assert_eq!(generate(2000, 7), generate(2000, 7));
        assert_ne!(generate(2000, 7), generate(2000, 8));
    }

    #[test]
    fn robotran_mix_and_names() {
        let f = generate(20_000, 1);
        let c = f.op_counts();
        let pct = |x: u64| x * 100 / c.total;
        assert!((50..=60).contains(&pct(c.mul)), "{c:?}");
        assert!((20..=30).contains(&pct(c.add)), "{c:?}");
        assert!((15..=25).contains(&pct(c.sub)), "{c:?}");
        assert!(f.inputs.iter().any(|&v| f.name_of(v).starts_with("qd[")));
        assert!(f.lookup("C1").is_some() || f.lookup("S1").is_some());
        assert!(f.outputs.iter().all(|o| o.name.starts_with("Qq[")));
    }

    #[test]
    fn critical_path_grows_slowly() {
        let lat = Latencies::default();
        let cp = |n| compute_timing(&generate(n, 3), &lat).1.asap;
        let (a, b) = (cp(2_000), cp(32_000));
        // 16× the ops: a chain would give 16× the path, √n growth 4×.
        assert!(a >= 10 && b > a && b < 8 * a, "critical paths {a} → {b}");
    }
}
