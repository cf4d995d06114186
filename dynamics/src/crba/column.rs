//! The columns of `M`: the spatial force of a unit joint acceleration, carried from its joint
//! up to the root (or to the root segment, then projected), one entry per moving ancestor
//! joint (see the parent module's doc).

use rustc_hash::FxHashMap;

use super::composite::Composite;
use super::tree::Tree;
use crate::rnea::{cross, dot, matvec, vadd, M3, V3};
use crate::robot::JointKind;
use crate::sym::{mul, sum, Builder, Term};
use crate::Stopped;

/// `M[i][j]` (1-based) bound as the temporary `M{i}_{j}` where it is formed: both ways of
/// forming `M` bind each entry as soon as it is known, so nothing it reads stays live until
/// the outputs are written.
pub(crate) fn bind_entry(b: &mut Builder, i: usize, j: usize, t: Term) -> Term {
    b.bind(&format!("M{i}_{j}"), t)
}

/// Binds a column force carried to body `body` for column `col`: `FM{k}{body}_{col}`
/// (Robotran's `FM31_24` style).
fn column_bind(b: &mut Builder, name: &str, body: usize, col: usize, v: V3) -> V3 {
    let [x, y, z] = v;
    [
        b.bind(&format!("{name}1{body}_{col}"), x),
        b.bind(&format!("{name}2{body}_{col}"), y),
        b.bind(&format!("{name}3{body}_{col}"), z),
    ]
}

/// `r·v` for a rotation that may be absent (identity).
fn rotate(r: Option<&M3>, v: &V3) -> V3 {
    r.map_or_else(|| v.clone(), |r| matvec(r, v, false))
}

/// Ops of `m·v` for a dense vector `v`: per row, a product per entry that is neither 0 nor ±1
/// and an addition per further non-zero entry.
fn matvec_ops(m: &M3) -> usize {
    m.iter()
        .map(|row| {
            let nonzero = row.iter().filter(|x| !matches!(x, Term::C(c) if *c == 0.0)).count();
            let products = row.iter().filter(|x| !matches!(x, Term::C(c) if *c == 0.0 || c.abs() == 1.0)).count();
            products + nonzero.saturating_sub(1)
        })
        .sum()
}

/// The rotation child → parent of a revolute joint whose constant origin rotation `ro` is dense
/// (a URDF `rpy` that is neither a quarter turn nor about one axis): `P = ro·R_axis(q)`, its
/// entries bound once as `RP{r}{c}{body}`, when moving a vector by `P` costs fewer ops than by
/// `R_axis(q)` then `ro` (15 against up to 6 + 15 per vector). Every column force and the
/// composite then cross that joint in one rotation. `None`: the two rotations stay apart.
pub(super) fn merged_rotation(b: &mut Builder, body: usize, ro: &M3, joint: Option<&M3>) -> Option<M3> {
    let r = joint?;
    let p: M3 = [0, 1, 2].map(|i| [0, 1, 2].map(|j| sum((0..3).map(|k| mul(ro[i][k].clone(), r[k][j].clone())))));
    if matvec_ops(&p) >= matvec_ops(ro) + matvec_ops(r) {
        return None;
    }
    Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| b.bind(&format!("RP{}{}{body}", i + 1, j + 1), p[i][j].clone()))))
}

/// A column on its way up: coordinate `qj` (1-based), the force `(n, f)` (moment about the
/// origin of body `at`, force, both in its frame).
pub(super) struct Carry {
    qj: usize,
    at: usize,
    n: V3,
    f: V3,
}

impl Carry {
    /// The body the force is at.
    pub(super) fn at(&self) -> usize {
        self.at
    }
}

impl Tree<'_> {
    /// The column of coordinate `qj`, body `body`'s joint, whose composite is `c`: the force
    /// of a unit acceleration of that joint, at `body`.
    pub(super) fn start(&self, body: usize, qj: usize, c: &Composite) -> Carry {
        let joint = &self.robot.joints[self.order[body - 1]];
        let av = joint.axis.map(Term::C);
        let (n, f) = match joint.kind {
            JointKind::Revolute => (matvec(&c.j, &av, false), cross(&av, &c.h)),
            _ => (cross(&c.h, &av), av.clone().map(|x| mul(c.m.clone(), x))),
        };
        Carry { qj, at: body, n, f }
    }

    /// One step of column `col`: pushes `((i, qj), term)` onto `upper` for the joint `i` of
    /// body `col.at` (or, in the root segment, every entry above by projection) and carries
    /// the force into the parent's frame, bound as `FM`, `CM` (per body and column). `false`
    /// when the column is complete.
    ///
    /// # Errors
    /// [`Stopped`] at the builder's deadline (checked at every step).
    pub(super) fn step(
        &self,
        b: &mut Builder,
        projections: &mut FxHashMap<(usize, usize), V3>,
        col: &mut Carry,
        upper: &mut Vec<((usize, usize), Term)>,
    ) -> Result<bool, Stopped> {
        let Carry { qj, at, .. } = *col;
        b.check(at, self.order.len())?;
        if self.in_segment[at] && self.segment_moving[at] >= 2 {
            for (qi, t) in self.projection(b, projections, at, &col.n, &col.f) {
                upper.push(((qi, qj), bind_entry(b, qi, qj, t)));
            }
            return Ok(false);
        }
        if let Some(qi) = self.layout.v_index[at - 1] {
            let jo = &self.robot.joints[self.order[at - 1]];
            match jo.kind {
                // A free flyer's six rows: the force, then the moment, in the base frame.
                JointKind::FreeFlyer => {
                    for (k, t) in col.f.iter().chain(&col.n).enumerate() {
                        upper.push(((qi + k, qj), bind_entry(b, qi + k, qj, t.clone())));
                    }
                }
                JointKind::Revolute => upper.push(((qi, qj), bind_entry(b, qi, qj, dot(&jo.axis, &col.n)))),
                _ => upper.push(((qi, qj), bind_entry(b, qi, qj, dot(&jo.axis, &col.f)))),
            }
        }
        let p = self.parent[at];
        if !self.moves[p] {
            return Ok(false);
        }
        // Into the parent's frame: the joint motion, then the joint origin (merged into one
        // rotation where `merged_rotation` chose to).
        let (f1, n1) = match &self.merged[at] {
            Some(r) => (matvec(r, &col.f, false), matvec(r, &col.n, false)),
            None => {
                let mo = &self.motions[at];
                let f1 = rotate(mo.rot.as_ref(), &col.f);
                let mut n1 = rotate(mo.rot.as_ref(), &col.n);
                if let Some(s) = &mo.shift {
                    n1 = vadd(&n1, &cross(s, &f1));
                }
                (matvec(&self.ro[at], &f1, false), matvec(&self.ro[at], &n1, false))
            }
        };
        let d: V3 = [1, 2, 3].map(|k| self.layout.param(b, &format!("dpt[{k}][{at}]")));
        let f2 = column_bind(b, "FM", p, qj, f1);
        let n2 = vadd(&n1, &cross(&d, &f2));
        col.n = column_bind(b, "CM", p, qj, n2);
        col.f = f2;
        col.at = p;
        Ok(true)
    }

    /// Carries every column of `cols` to its end, one step of each in turn, and empties it.
    ///
    /// # Errors
    /// [`Stopped`] at the builder's deadline.
    pub(super) fn finish(
        &self,
        b: &mut Builder,
        projections: &mut FxHashMap<(usize, usize), V3>,
        cols: &mut Vec<Carry>,
        upper: &mut Vec<((usize, usize), Term)>,
    ) -> Result<(), Stopped> {
        let mut going = vec![true; cols.len()];
        while going.iter().any(|&g| g) {
            for (g, col) in going.iter_mut().zip(cols.iter_mut()) {
                if *g {
                    *g = self.step(b, projections, col, upper)?;
                }
            }
        }
        cols.clear();
        Ok(())
    }

    /// The entries `(i, t)` of a column whose force `(n, f)` (moment about the origin of body
    /// `at`, force, both in its frame) has reached `at` in the root segment: for each moving joint
    /// `i` from `at` up to the root, `t = w·n` (revolute) or `w·f` (prismatic), `w` its axis
    /// expressed in `at`'s frame (`R_kᵀ` of the joints between; no offsets, so every revolute axis
    /// there passes through `at`'s origin). The `w` are bound once per `(at, joint)` as
    /// `WM{k}{body}_{at}`. On Robotran's floating base this costs 23 ops per column where
    /// carrying the force through T1…R3 costs about 31.
    fn projection(
        &self,
        b: &mut Builder,
        cache: &mut FxHashMap<(usize, usize), V3>,
        at: usize,
        n: &V3,
        f: &V3,
    ) -> Vec<(usize, Term)> {
        let mut path = Vec::new();
        let mut k = at;
        while k != 0 {
            path.push(k);
            k = self.parent[k];
        }
        let mut out = Vec::new();
        for (idx, &bi) in path.iter().enumerate() {
            let Some(qi) = self.layout.v_index[bi - 1] else { continue };
            let jo = &self.robot.joints[self.order[bi - 1]];
            let w = cache.entry((at, bi)).or_insert_with(|| {
                let mut w: V3 = jo.axis.map(Term::C);
                for &k in path[..idx].iter().rev() {
                    if let Some(r) = &self.motions[k].rot {
                        w = matvec(r, &w, true);
                    }
                }
                column_bind(b, "WM", bi, at, w)
            });
            let v = if jo.kind == JointKind::Revolute { n } else { f };
            out.push((qi, sum((0..3).map(|k| mul(w[k].clone(), v[k].clone())))));
        }
        out
    }
}
