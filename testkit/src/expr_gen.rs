//! Random well-formed expression DAGs in the **parsed** phase (what a front end produces), for
//! property tests and fuzzing of pass pipelines: `atomise` and every later pass apply.
//!
//! A function has inputs `x[1] … x[n]`, equations `e1 … eN` (each one nested expression) and
//! outputs `y[1] …`. Expressions mix:
//! - sums, differences, products and unary minus (`-t`, also on literals: `-(2.0)*x`);
//! - leaves: inputs, earlier equations (shared values: one value read by many equations) and
//!   constants `0, 1, 2, 3, 0.5, 0.25, 1.5` (all exact in binary32, so a binary32 evaluation
//!   rounds only its operations);
//! - near-cancelling terms: `(A + s) − A`, `A − (A − s)`, `(s − A) + A` with `A` a subtree
//!   written twice and `s` a leaf.
//!
//! Outputs: every equation no other equation reads, plus a few random ones (sometimes an input
//! or a constant). Deterministic for a seed ([`generate`]); [`from_bytes`] drives the same
//! choices from fuzzer bytes (cargo-fuzz), and [`point`] draws binary32-exact input values.

use robovec_ir::{BinOp, Def, Expr, Function, Operand, Phase, Span, Value};

use robovec_ir::rng::SplitMix64;

/// A source of choices: a seeded generator or fuzzer bytes.
pub trait Choices {
    /// A number in `0..n` (`n > 0`).
    fn below(&mut self, n: u64) -> u64;
}

impl Choices for SplitMix64 {
    fn below(&mut self, n: u64) -> u64 {
        SplitMix64::below(self, n)
    }
}

/// Choices read from bytes (two per choice, little-endian); zeros once the bytes run out, so
/// every byte string gives a function.
pub struct ByteChoices<'a> {
    data: &'a [u8],
}

impl<'a> ByteChoices<'a> {
    /// Choices from `data`.
    pub fn new(data: &'a [u8]) -> ByteChoices<'a> {
        ByteChoices { data }
    }
}

impl Choices for ByteChoices<'_> {
    fn below(&mut self, n: u64) -> u64 {
        let take = self.data.len().min(2);
        let mut v = 0u64;
        for (i, b) in self.data[..take].iter().enumerate() {
            v |= (*b as u64) << (8 * i);
        }
        self.data = &self.data[take..];
        v % n
    }
}

/// Size limits of a generated function.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Inputs, 1 or more.
    pub inputs: u32,
    /// Equations, 1 or more.
    pub equations: u32,
    /// Nesting depth of one equation's expression (0 = a leaf).
    pub depth: u32,
}

impl Default for Shape {
    fn default() -> Shape {
        Shape { inputs: 5, equations: 12, depth: 4 }
    }
}

const CONSTS: [f64; 7] = [0.0, 1.0, 2.0, 3.0, 0.5, 0.25, 1.5];

struct Gen<'c, C: Choices> {
    ch: &'c mut C,
    inputs: Vec<Value>,
    eqs: Vec<Value>,
}

impl<C: Choices> Gen<'_, C> {
    fn leaf(&mut self) -> Expr {
        let r = self.ch.below(10);
        if r < 5 || (r < 8 && self.eqs.is_empty()) {
            let i = self.ch.below(self.inputs.len() as u64) as usize;
            Expr::Operand(Operand::Value(self.inputs[i]))
        } else if r < 8 {
            // Recent equations more often than old ones (locality, as in Robotran).
            let n = self.eqs.len() as u64;
            let back = self.ch.below(n).min(self.ch.below(n));
            Expr::Operand(Operand::Value(self.eqs[(n - 1 - back) as usize]))
        } else {
            Expr::Operand(Operand::Const(CONSTS[self.ch.below(CONSTS.len() as u64) as usize]))
        }
    }

    fn expr(&mut self, depth: u32) -> Expr {
        if depth == 0 || self.ch.below(4) == 0 {
            return self.leaf();
        }
        let bin = |op, a, b| Expr::Binary(op, Box::new(a), Box::new(b));
        match self.ch.below(10) {
            0..=2 => bin(BinOp::Add, self.expr(depth - 1), self.expr(depth - 1)),
            3..=4 => bin(BinOp::Sub, self.expr(depth - 1), self.expr(depth - 1)),
            5..=6 => bin(BinOp::Mul, self.expr(depth - 1), self.expr(depth - 1)),
            7 => Expr::Neg(Box::new(self.expr(depth - 1))),
            _ => {
                let a = self.expr(depth - 1);
                let s = self.leaf();
                match self.ch.below(3) {
                    0 => bin(BinOp::Sub, bin(BinOp::Add, a.clone(), s), a),
                    1 => bin(BinOp::Sub, a.clone(), bin(BinOp::Sub, a, s)),
                    _ => bin(BinOp::Add, bin(BinOp::Sub, s, a.clone()), a),
                }
            }
        }
    }
}

/// A function of `shape` from the choices `ch`.
pub fn generate_with(ch: &mut impl Choices, shape: Shape) -> Function {
    let mut f = Function::new("gen", Phase::Parsed);
    let inputs: Vec<Value> = (1..=shape.inputs.max(1))
        .map(|i| f.add_input(format!("x[{i}]"), Span::DUMMY).expect("fresh input name"))
        .collect();
    let mut g = Gen { ch, inputs, eqs: Vec::new() };
    let n_eq = shape.equations.max(1);
    for i in 1..=n_eq {
        let e = g.expr(shape.depth);
        let v = f.define(format!("e{i}"), Def::Expr(e), Span::DUMMY).expect("fresh equation name");
        g.eqs.push(v);
    }
    f.equations = Some(n_eq);
    let mut read = vec![false; f.values.len()];
    for &v in &f.body {
        f.value(v).def.for_each_value(|x| read[x.index()] = true);
    }
    let mut outs: Vec<Operand> = g.eqs.iter().filter(|v| !read[v.index()]).map(|&v| Operand::Value(v)).collect();
    for _ in 0..g.ch.below(3) {
        outs.push(match g.ch.below(8) {
            0 => Operand::Value(g.inputs[g.ch.below(g.inputs.len() as u64) as usize]),
            1 => Operand::Const(CONSTS[g.ch.below(CONSTS.len() as u64) as usize]),
            _ => Operand::Value(g.eqs[g.ch.below(g.eqs.len() as u64) as usize]),
        });
    }
    for (k, o) in outs.into_iter().enumerate() {
        f.set_output(format!("y[{}]", k + 1), o, Span::DUMMY);
    }
    f
}

/// A function from `seed` with the default [`Shape`].
pub fn generate(seed: u64) -> Function {
    generate_with(&mut SplitMix64::new(seed), Shape::default())
}

/// A function whose shape and structure come from fuzzer bytes: the first three bytes choose
/// 1–8 inputs, 1–24 equations and depth 0–5.
pub fn from_bytes(data: &[u8]) -> Function {
    let b = |i: usize| data.get(i).copied().unwrap_or(0) as u32;
    let shape = Shape { inputs: 1 + b(0) % 8, equations: 1 + b(1) % 24, depth: b(2) % 6 };
    generate_with(&mut ByteChoices::new(data.get(3..).unwrap_or(&[])), shape)
}

/// Input values for `f`, one per input in input order: binary32 values of magnitude in
/// [1/4, 4) with either sign, 1 in 8 exactly 0, 1 in 8 equal to the previous input (exact
/// cancellations).
pub fn point(f: &Function, ch: &mut impl Choices) -> Vec<f64> {
    let mut xs: Vec<f64> = Vec::with_capacity(f.inputs.len());
    for _ in &f.inputs {
        let x = match ch.below(8) {
            0 => 0.0,
            1 if !xs.is_empty() => xs[xs.len() - 1],
            _ => {
                let mant = 1.0 + ch.below(1 << 23) as f64 / (1u64 << 23) as f64;
                let sign = if ch.below(2) == 0 { 1.0 } else { -1.0 };
                sign * mant * 2f64.powi(ch.below(4) as i32 - 2)
            }
        };
        xs.push(x);
    }
    xs
}

#[cfg(test)]
mod tests {
    use super::*;
    use robovec_ir::{verifier, Module};

    #[test]
    fn generated_functions_verify_atomise_and_are_deterministic() {
        for seed in 0..200 {
            let f = generate(seed);
            assert_eq!(f, generate(seed));
            let m = Module { functions: vec![f.clone()] };
            verifier::verify(&m).unwrap_or_else(|e| panic!("seed {seed}: {e:?}\n{m}"));
            let a = Module { functions: vec![robovec_passes::atomise::atomise_function(&f)] };
            verifier::verify(&a).unwrap_or_else(|e| panic!("seed {seed} atomised: {e:?}\n{a}"));
            assert!(!f.outputs.is_empty());
            // The text form reads back to the same function.
            let back = robovec_ir::text::parse(&m.to_string()).unwrap();
            assert_eq!(back.to_string(), m.to_string());
        }
    }

    #[test]
    fn generated_functions_share_values_and_cancel() {
        let (mut shared, mut cancel, mut neg) = (0, 0, 0);
        for seed in 0..100 {
            let f = generate(seed);
            let mut reads = vec![0u32; f.values.len()];
            for &v in &f.body {
                f.value(v).def.for_each_value(|x| reads[x.index()] += 1);
            }
            shared += f.body.iter().filter(|v| reads[v.index()] >= 2).count();
            let text = Module { functions: vec![f] }.to_string();
            cancel += text.matches(") - (").count();
            neg += text.matches("= -").count() + text.matches("(-").count();
        }
        assert!(shared > 100 && cancel > 20 && neg > 20, "shared {shared}, cancel {cancel}, neg {neg}");
    }

    #[test]
    fn any_bytes_give_a_valid_function() {
        let mut rng = SplitMix64::new(3);
        for len in [0usize, 1, 2, 3, 7, 50, 400] {
            let data: Vec<u8> = (0..len).map(|_| rng.next_u64() as u8).collect();
            let m = Module { functions: vec![from_bytes(&data)] };
            verifier::verify(&m).unwrap_or_else(|e| panic!("{len} bytes: {e:?}\n{m}"));
        }
    }

    #[test]
    fn points_are_binary32_values() {
        let f = generate(5);
        let mut rng = SplitMix64::new(9);
        for _ in 0..100 {
            for x in point(&f, &mut rng) {
                assert_eq!(x, x as f32 as f64);
                assert!(x == 0.0 || (0.25..4.0).contains(&x.abs()));
            }
        }
    }
}
