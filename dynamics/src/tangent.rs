//! Derivatives with respect to `q` along Pinocchio's tangent space (issue 50:
//! `computeRNEADerivatives` and `computeABADerivatives` differentiate along
//! `pinocchio.integrate(model, q, dq)`, `dq ∈ R^nv`, at `dq = 0`), where a joint's
//! configuration is not its velocity coordinate ([`Coordinate`]): the free flyer, and a
//! continuous joint as Pinocchio's `(cos θ, sin θ)` pair (`--continuous=cos-sin`), whose
//! column is `∂/∂θ = −sin θ·∂/∂(cos θ) + cos θ·∂/∂(sin θ)` (2 multiplies and an add a row).
//!
//! The free flyer's configuration is `q[1..7]`: the position `p`, then the unit quaternion
//! `(x, y, z, w)`; its velocity `qd[1..6]` is linear then angular, in the base frame.
//! `integrate` moves the base by `exp(dq)` in its own frame, so to first order at `dq = 0`:
//! - `∂p/∂dq_k = R e_k` for the linear `k = 1..3` (`R` the quaternion's rotation), and `p` does
//!   not move with the angular ones (the coupling of SE(3)'s exponential is second order);
//! - `∂quat/∂dq_{3+a} = quat ⊗ (e_a / 2, 0)` for the angular `a = 1..3`: vector part
//!   `(w e_a + u × e_a) / 2`, scalar `−u_a / 2` (`u = (x, y, z)`);
//! - every other joint's coordinate `q[j + 1]` is its velocity coordinate `j ≥ 7` (or its
//!   `(cos, sin)` pair's column, above).
//!
//! So a derivative row `∂o/∂q[1..nq]` (along robovec's coordinates, as `diff` writes it)
//! becomes `∂o/∂dq[1..nv] = ∂o/∂q · J(q)` with that `nq × nv` Jacobian `J`. Zero entries are
//! skipped, so the map costs about 30 ops a row.

use std::collections::BTreeMap;

use robovec_ir::{BinOp, Def, Function, Operand, Output, Span};

use crate::robot::{JointKind, Robot};
use crate::Layout;

/// How one joint's velocity coordinates follow from its configuration coordinates, in
/// velocity order ([`coordinates`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinate {
    /// One velocity coordinate, the configuration coordinate `q[q]` itself (revolute,
    /// prismatic, a continuous joint as its angle).
    Plain {
        /// The configuration coordinate (1-based).
        q: usize,
    },
    /// A continuous joint as Pinocchio's `(cos θ, sin θ) = (q[q], q[q + 1])`.
    CosSin {
        /// The first of the pair (1-based).
        q: usize,
    },
    /// Pinocchio's free flyer at `q[q..q + 7]`: position, then unit quaternion `(x, y, z, w)`;
    /// six velocity coordinates (module doc).
    FreeFlyer {
        /// Its first configuration coordinate (1-based).
        q: usize,
    },
}

/// The [`Coordinate`] of each moving joint of `robot` (numbered by `layout`), in velocity
/// order; `None` when every one is [`Coordinate::Plain`]: the derivatives along robovec's
/// coordinates are then already along the tangent space.
pub fn coordinates(robot: &Robot, layout: &Layout) -> Option<Vec<Coordinate>> {
    let mut out = Vec::new();
    for (i, &j) in robot.dfs_joints().iter().enumerate() {
        let (Some(_), Some(q)) = (layout.v_index[i], layout.q_index[i]) else { continue };
        let joint = &robot.joints[j];
        out.push(if joint.kind == JointKind::FreeFlyer {
            Coordinate::FreeFlyer { q }
        } else if robot.cos_sin && joint.continuous {
            Coordinate::CosSin { q }
        } else {
            Coordinate::Plain { q }
        });
    }
    out.iter().any(|c| !matches!(c, Coordinate::Plain { .. })).then_some(out)
}

/// Writes ops into a function under one name prefix (`ff_tangent`, `ff_tangent.1`, …; linear in
/// the ops, [`Function::define_counted`]), folding structural zeros and ones.
pub(crate) struct Ops<'f> {
    pub(crate) f: &'f mut Function,
    prefix: &'static str,
    count: u32,
}

impl<'f> Ops<'f> {
    pub(crate) fn new(f: &'f mut Function, prefix: &'static str) -> Ops<'f> {
        Ops { f, prefix, count: 0 }
    }

    /// `a op b`, folding `0·x`, `1·x`, `0 + x` and `x ± 0`.
    pub(crate) fn op(&mut self, o: BinOp, a: Operand, b: Operand) -> Operand {
        let zero = |x: Operand| x == Operand::Const(0.0);
        let one = |x: Operand| x == Operand::Const(1.0);
        match o {
            BinOp::Mul if zero(a) || zero(b) => return Operand::Const(0.0),
            BinOp::Mul if one(a) => return b,
            BinOp::Mul if one(b) => return a,
            BinOp::Add if zero(a) => return b,
            BinOp::Add | BinOp::Sub if zero(b) => return a,
            _ => {}
        }
        Operand::Value(self.f.define_counted(self.prefix, &mut self.count, Def::Binary(o, a, b), Span::DUMMY))
    }

    /// `Σ terms[i].0 · terms[i].1 · (−1 if terms[i].2)`: the sum of products, zeros skipped.
    pub(crate) fn dot(&mut self, terms: &[(Operand, Operand, bool)]) -> Operand {
        let mut acc = Operand::Const(0.0);
        for &(a, b, negative) in terms {
            let p = self.op(BinOp::Mul, a, b);
            if p == Operand::Const(0.0) {
                continue;
            }
            acc = if negative { self.op(BinOp::Sub, acc, p) } else { self.op(BinOp::Add, acc, p) };
        }
        acc
    }
}

/// Replaces every output `<family>[…][m]` (`m` the coordinate `q[m]`, `1..=nq`) of each of
/// `families` by `<family>[…][k]`, `k = 1..=nv`, along Pinocchio's tangent space (the module
/// doc), for the joints `coords` ([`coordinates`]). `f` is atomised; the configuration inputs
/// the map reads (the quaternion, a pair's cos and sin) are `f`'s, or added as inputs when no
/// value reads them.
pub fn to_tangent(f: &mut Function, families: &[&str], coords: &[Coordinate]) {
    let mut ops = Ops::new(f, "tangent");
    let input = |ops: &mut Ops, i: usize| {
        let n = format!("q[{i}]");
        Operand::Value(ops.f.lookup(&n).unwrap_or_else(|| ops.f.add_input(n, Span::DUMMY).expect("free")))
    };
    // The free flyer's quaternion (robovec's free flyer is the root: one at most).
    let ff = coords.iter().find_map(|c| match c {
        Coordinate::FreeFlyer { q } => Some(*q),
        _ => None,
    });
    let quat: Vec<Operand> =
        ff.map_or(vec![Operand::Const(0.0); 4], |q0| (3..7).map(|k| input(&mut ops, q0 + k)).collect());
    let pairs: Vec<(Operand, Operand)> = coords
        .iter()
        .map(|c| match c {
            Coordinate::CosSin { q } => (input(&mut ops, *q), input(&mut ops, q + 1)),
            _ => (Operand::Const(0.0), Operand::Const(0.0)),
        })
        .collect();
    let (x, y, z, w) = (quat[0], quat[1], quat[2], quat[3]);
    // R's entries, written when first needed: 2·(a·b ± c·d) or 1 − 2·(a² + b²).
    let mut rot: Option<[[Operand; 3]; 3]> = None;
    let outputs = std::mem::take(&mut ops.f.outputs);
    // The rows: family and row indices → (position of the row's first output, its coordinates).
    let mut rows: BTreeMap<usize, (String, BTreeMap<usize, Operand>)> = BTreeMap::new();
    let mut row_at: BTreeMap<String, usize> = BTreeMap::new();
    let mut kept: Vec<(usize, Output)> = Vec::new();
    for (pos, o) in outputs.into_iter().enumerate() {
        let row = families.iter().find(|fam| o.name.starts_with(*fam) && o.name[fam.len()..].starts_with('['));
        let split =
            row.and_then(|_| o.name.rfind('[')).map(|i| (o.name[..i].to_string(), &o.name[i + 1..o.name.len() - 1]));
        match split.and_then(|(r, m)| m.parse::<usize>().ok().map(|m| (r, m))) {
            Some((r, m)) => {
                let first = *row_at.entry(r.clone()).or_insert(pos);
                rows.entry(first).or_insert_with(|| (r, BTreeMap::new())).1.insert(m, o.value);
            }
            None => kept.push((pos, o)),
        }
    }
    let mut written: Vec<(usize, Output)> = Vec::new();
    for (pos, (row, raw)) in rows {
        let d = |m: usize| raw.get(&m).copied().unwrap_or(Operand::Const(0.0));
        let mut cols: Vec<Operand> = Vec::with_capacity(coords.len() + 5);
        for (c, &(cos, sin)) in coords.iter().zip(&pairs) {
            match *c {
                Coordinate::Plain { q } => cols.push(d(q)),
                Coordinate::CosSin { q } => cols.push(ops.dot(&[(d(q), sin, true), (d(q + 1), cos, false)])),
                Coordinate::FreeFlyer { q } => {
                    free_flyer_columns(&mut ops, &mut cols, &mut rot, [x, y, z, w], |m| d(q + m - 1))
                }
            }
        }
        for (k, value) in cols.into_iter().enumerate() {
            written.push((pos, Output { name: format!("{row}[{}]", k + 1), value, span: Span::DUMMY }));
        }
    }
    // Rows where their first output was; the other outputs in place.
    let mut all: Vec<(usize, Output)> = kept.into_iter().chain(written).collect();
    all.sort_by_key(|(p, _)| *p);
    for (_, o) in all {
        ops.f.set_output(o.name, o.value, o.span);
    }
}

/// The free flyer's six columns of one row (module doc), `d(m)` the row's entry along its
/// configuration coordinate `m = 1..=7`; `rot` is the quaternion's rotation, written on first
/// need and shared by the rows.
fn free_flyer_columns(
    ops: &mut Ops,
    cols: &mut Vec<Operand>,
    rot: &mut Option<[[Operand; 3]; 3]>,
    [x, y, z, w]: [Operand; 4],
    d: impl Fn(usize) -> Operand,
) {
    {
        let needs_rot = (1..=3).any(|m| d(m) != Operand::Const(0.0));
        if needs_rot && rot.is_none() {
            let two = Operand::Const(2.0);
            let one = Operand::Const(1.0);
            let mut pair = |a: Operand, b: Operand, c: Operand, e: Operand, plus: bool| {
                let s = ops.dot(&[(a, b, false), (c, e, !plus)]);
                ops.op(BinOp::Mul, two, s)
            };
            let xy_m_zw = pair(x, y, z, w, false);
            let xz_p_yw = pair(x, z, y, w, true);
            let xy_p_zw = pair(x, y, z, w, true);
            let yz_m_xw = pair(y, z, x, w, false);
            let xz_m_yw = pair(x, z, y, w, false);
            let yz_p_xw = pair(y, z, x, w, true);
            let mut diag = |a: Operand, b: Operand| {
                let s = ops.dot(&[(a, a, false), (b, b, false)]);
                let t = ops.op(BinOp::Mul, two, s);
                ops.op(BinOp::Sub, one, t)
            };
            let (r11, r22, r33) = (diag(y, z), diag(x, z), diag(x, y));
            *rot = Some([[r11, xy_m_zw, xz_p_yw], [xy_p_zw, r22, yz_m_xw], [xz_m_yw, yz_p_xw, r33]]);
        }
        for k in 0..3 {
            let terms: Vec<(Operand, Operand, bool)> = match &rot {
                Some(r) => (0..3).map(|m| (d(m + 1), r[m][k], false)).collect(),
                None => vec![],
            };
            cols.push(ops.dot(&terms));
        }
        // ∂quat/∂ω_a · 2: (w, z, −y, −x), (−z, w, x, −y), (y, −x, w, −z) for a = 1, 2, 3.
        let tables: [[(Operand, bool); 4]; 3] = [
            [(w, false), (z, false), (y, true), (x, true)],
            [(z, true), (w, false), (x, false), (y, true)],
            [(y, false), (x, true), (w, false), (z, true)],
        ];
        for t in tables {
            let terms: Vec<(Operand, Operand, bool)> = (0..4).map(|c| (d(4 + c), t[c].0, t[c].1)).collect();
            let s = ops.dot(&terms);
            cols.push(ops.op(BinOp::Mul, Operand::Const(0.5), s));
        }
    }
}
