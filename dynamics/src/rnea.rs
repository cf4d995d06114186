//! Inverse dynamics `Qq` of a fixed-base tree by the recursive Newton–Euler algorithm, in body
//! frames, symbolic in `q`, `qd`, `qdd`, `g` and the model parameters.
//!
//! Conventions (Robotran's, see the double pendulum example's README):
//! - every quantity of body `b` is in body `b`'s frame; the joint frame of joint `b` is its
//!   URDF `<origin>` in the parent link frame, the child frame is the joint frame moved by the
//!   joint (`R_axis(q)` about the unit axis, or `axis·q` along it);
//! - `OM`, `OMp`: angular velocity and acceleration; `ALPHA`: acceleration of the body origin
//!   **minus gravity** (the base starts at `ALPHA = −g`, so gravity needs no extra force);
//! - forward: `ALPHA_b = Rᵀ(ALPHA_p + OMp_p × d + OM_p × (OM_p × d))` (+ the prismatic terms
//!   `axis·qdd + 2 OM × axis·qd`), `OM_b = Rᵀ OM_p + axis·qd`,
//!   `OMp_b = Rᵀ OMp_p + axis·qdd + (Rᵀ OM_p) × axis·qd`;
//! - backward: `Fs = m (ALPHA + OMp × l + OM × (OM × l))` (force of the body at its centre of
//!   mass), `Cs = In·OMp + OM × (In·OM) + l × Fs` (its moment about the body origin),
//!   `Fq`, `Cq` add the children's `R Fq`, `R Cq + d × R Fq`; `Qq = axis · Cq` (revolute) or
//!   `axis · Fq` (prismatic).
//!
//! One-axis rotations are written `R = k kᵀ + C (I − k kᵀ) + S [k]×` with `C = cos(q)`,
//! `S = sin(q)` trig variables and the numeric unit axis `k`: for an axis along ±x, ±y or ±z
//! this folds to Robotran's C/S products. Constant rotations (URDF `rpy`) are numbers.

use robovec_ir::TrigFn;

use super::robot::{snap, JointKind};
use super::sym::{add, mul, neg, sub, sum, Builder, Term, ZERO};
use super::{Layout, Model, Stopped};

/// A 3-vector of terms.
pub type V3 = [Term; 3];
/// A 3×3 matrix of terms (row-major).
pub type M3 = [[Term; 3]; 3];

pub(crate) fn cross(a: &V3, b: &V3) -> V3 {
    [
        sub(mul(a[1].clone(), b[2].clone()), mul(a[2].clone(), b[1].clone())),
        sub(mul(a[2].clone(), b[0].clone()), mul(a[0].clone(), b[2].clone())),
        sub(mul(a[0].clone(), b[1].clone()), mul(a[1].clone(), b[0].clone())),
    ]
}

pub(crate) fn vadd(a: &V3, b: &V3) -> V3 {
    [add(a[0].clone(), b[0].clone()), add(a[1].clone(), b[1].clone()), add(a[2].clone(), b[2].clone())]
}

fn scale(a: &[f64; 3], s: &Term) -> V3 {
    [mul(Term::C(a[0]), s.clone()), mul(Term::C(a[1]), s.clone()), mul(Term::C(a[2]), s.clone())]
}

pub(super) fn dot(a: &[f64; 3], b: &V3) -> Term {
    sum((0..3).map(|i| mul(Term::C(a[i]), b[i].clone())))
}

/// `m·v` (or `mᵀ·v` when `transpose`).
pub(crate) fn matvec(m: &M3, v: &V3, transpose: bool) -> V3 {
    let e = |i: usize, j: usize| if transpose { m[j][i].clone() } else { m[i][j].clone() };
    [0, 1, 2].map(|i| sum((0..3).map(|j| mul(e(i, j), v[j].clone()))))
}

pub(super) fn numeric(r: &[[f64; 3]; 3]) -> M3 {
    r.map(|row| row.map(Term::C))
}

/// `R = k kᵀ + C (I − k kᵀ) + S [k]×`.
fn axis_rotation(k: &[f64; 3], c: &Term, s: &Term) -> M3 {
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let mut r: M3 = Default::default();
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            let kk = k[i] * k[j];
            let delta = if i == j { 1.0 } else { 0.0 };
            *x = sum([Term::C(kk), mul(Term::C(delta - kk), c.clone()), mul(Term::C(kx[i][j]), s.clone())]);
        }
    }
    r
}

pub(super) fn bind3(b: &mut Builder, name: &str, body: impl std::fmt::Display, v: V3) -> V3 {
    let [x, y, z] = v;
    [b.bind(&format!("{name}1{body}"), x), b.bind(&format!("{name}2{body}"), y), b.bind(&format!("{name}3{body}"), z)]
}

/// The joint's rotation (child → joint frame) and translation (child origin in the joint
/// frame) as terms of its coordinate.
#[derive(Clone)]
pub struct Motion {
    /// `R_axis(q)` of a revolute joint.
    pub(super) rot: Option<M3>,
    /// `axis·q` of a prismatic joint.
    pub(super) shift: Option<V3>,
    /// A free flyer's rotation `R(quat)` (base → world; [`quaternion_rotation`]). Its
    /// translation enters no dynamics; `rot` and `shift` are `None`.
    pub(super) free: Option<M3>,
}

/// The rotation (child → parent) of the unit quaternion `(x, y, z, w)`, as Eigen's
/// `Quaternion::toRotationMatrix` (what Pinocchio's free flyer uses) writes it, with
/// `t = 2·(x, y, z)`: `R = [[1 − (tyy + tzz), txy − twz, txz + twy], [txy + twz, 1 − (txx + tzz),
/// tyz − twx], [txz − twy, tyz + twx, 1 − (txx + tyy)]]` (`tyy = ty·y`, `twz = tz·w`, …).
/// For a quaternion that is not of unit norm this is not a rotation, as in Pinocchio:
/// normalising is the caller's job. Every entry bound once as `RQ{r}{c}{body}`.
fn quaternion_rotation(b: &mut Builder, body: usize, quat: [Term; 4]) -> M3 {
    let [x, y, z, w] = quat;
    let t = [x.clone(), y.clone(), z.clone()].map(|c| mul(Term::C(2.0), c));
    let t: [Term; 3] = [0, 1, 2].map(|k| b.bind(&format!("TQ{}{body}", k + 1), t[k].clone()));
    let p = |a: &Term, c: &Term| mul(a.clone(), c.clone());
    let (txx, tyy, tzz) = (p(&t[0], &x), p(&t[1], &y), p(&t[2], &z));
    let (txy, txz, tyz) = (p(&t[1], &x), p(&t[2], &x), p(&t[2], &y));
    let (twx, twy, twz) = (p(&t[0], &w), p(&t[1], &w), p(&t[2], &w));
    let one = || Term::C(1.0);
    let r = [
        [sub(one(), add(tyy.clone(), tzz.clone())), sub(txy.clone(), twz.clone()), add(txz.clone(), twy.clone())],
        [add(txy, twz), sub(one(), add(txx.clone(), tzz)), sub(tyz.clone(), twx.clone())],
        [sub(txz, twy), add(tyz, twx), sub(one(), add(txx, tyy))],
    ];
    let mut out: M3 = Default::default();
    for (i, row) in r.into_iter().enumerate() {
        for (j, e) in row.into_iter().enumerate() {
            out[i][j] = b.bind(&format!("RQ{}{}{body}", i + 1, j + 1), e);
        }
    }
    out
}

/// `U = [ω̇]× + [ω]×[ω]×` of a body (Khalil & Kleinfinger's customised Newton–Euler: W. Khalil,
/// E. Dombre, *Modeling, Identification and Control of Robots*, 2002, §9.5): `U·v = ω̇ × v + ω ×
/// (ω × v)`, the acceleration of a point at `v` relative to the origin's, for every child's
/// joint origin and the centre of mass (or first moment) alike. `[ω]×² = ω ωᵀ − |ω|² I`: the six
/// products `ωᵢωⱼ` (bound as `WW{i}{j}{body}`), three sums on the diagonal, six off it — 15 ops
/// once per body where each `ω̇ × v + ω × (ω × v)` costs 33; entries bound as `U{r}{c}{body}`.
pub(super) fn acceleration_matrix(b: &mut Builder, body: usize, w: &V3, wp: &V3) -> M3 {
    let mut ww: M3 = Default::default();
    for i in 0..3 {
        for j in i..3 {
            ww[i][j] = b.bind(&format!("WW{}{}{body}", i + 1, j + 1), mul(w[i].clone(), w[j].clone()));
            ww[j][i] = ww[i][j].clone();
        }
    }
    let wpx = [
        [ZERO, neg(wp[2].clone()), wp[1].clone()],
        [wp[2].clone(), ZERO, neg(wp[0].clone())],
        [neg(wp[1].clone()), wp[0].clone(), ZERO],
    ];
    let mut out: M3 = Default::default();
    for r in 0..3 {
        for c in 0..3 {
            let t = if r == c {
                let (x, y) = ((r + 1) % 3, (r + 2) % 3);
                neg(add(ww[x][x].clone(), ww[y][y].clone()))
            } else {
                add(ww[r][c].clone(), wpx[r][c].clone())
            };
            out[r][c] = b.bind(&format!("U{}{}{body}", r + 1, c + 1), t);
        }
    }
    out
}

/// What drives one RNEA sweep: joint rates and accelerations per coordinate (index `i − 1` for
/// `q[i]`) and the gravity vector `g`, as terms (inputs, or constants such as 0 and 1).
pub struct Drive {
    /// `qd[i]` terms.
    pub qd: Vec<Term>,
    /// `qdd[i]` terms.
    pub qdd: Vec<Term>,
    /// The gravity vector (`g[1..3]`), m/s².
    pub g: V3,
}

impl Drive {
    /// The symbolic drive: `qd[i]`, `qdd[i]` and `g[k]` inputs (`qdd` zero when `with_qdd` is
    /// false, which gives Robotran's `c`).
    pub fn inputs(b: &mut Builder, nq: usize, with_qdd: bool) -> Drive {
        let g = [1, 2, 3].map(|k| b.input(&format!("g[{k}]")));
        let (mut qd, mut qdd) = (Vec::with_capacity(nq), Vec::with_capacity(nq));
        for i in 1..=nq {
            qd.push(b.input(&format!("qd[{i}]")));
            qdd.push(if with_qdd { b.input(&format!("qdd[{i}]")) } else { ZERO });
        }
        Drive { qd, qdd, g }
    }
}

/// The trig variables (`C1 = cos(q[1])`, `S1`…, Robotran's "Trigonometric Variables" block, in
/// joint order) and each body's joint motion (index = body, 0 = the base).
pub fn motions(model: &Model, layout: &Layout, b: &mut Builder) -> Vec<Motion> {
    let robot = &model.robot;
    let order = robot.dfs_joints();
    let mut motions: Vec<Motion> = Vec::with_capacity(order.len() + 1);
    motions.push(Motion { rot: None, shift: None, free: None });
    for (i, &j) in order.iter().enumerate() {
        let joint = &robot.joints[j];
        let motion = match (joint.kind, layout.q_index[i]) {
            (JointKind::Revolute, Some(qi)) => {
                let (mut c, mut s) = if robot.cos_sin && joint.continuous {
                    // Pinocchio's (cos, sin) pair of a continuous joint: the trig variables.
                    (b.input(&format!("q[{qi}]")), b.input(&format!("q[{}]", qi + 1)))
                } else {
                    let q = b.input(&format!("q[{qi}]"));
                    (b.trig(&format!("C{qi}"), TrigFn::Cos, q.clone()), b.trig(&format!("S{qi}"), TrigFn::Sin, q))
                };
                if joint.offset != 0.0 {
                    // cos and sin of q + offset (`crate::frames`), bound as CQ, SQ.
                    let (so, co) = joint.offset.sin_cos();
                    let (so, co) = (Term::C(snap(so)), Term::C(snap(co)));
                    let c2 = sub(mul(c.clone(), co.clone()), mul(s.clone(), so.clone()));
                    let s2 = add(mul(s, co), mul(c, so));
                    c = b.bind(&format!("CQ{qi}"), c2);
                    s = b.bind(&format!("SQ{qi}"), s2);
                }
                Motion { rot: Some(axis_rotation(&joint.axis, &c, &s)), shift: None, free: None }
            }
            (JointKind::Prismatic, Some(qi)) => {
                let q = b.input(&format!("q[{qi}]"));
                Motion { rot: None, shift: Some(scale(&joint.axis, &q)), free: None }
            }
            (JointKind::FreeFlyer, Some(qi)) => {
                // q[qi..qi + 2]: the position, which no dynamics reads; then x, y, z, w.
                let quat = [3, 4, 5, 6].map(|k| b.input(&format!("q[{}]", qi + k)));
                Motion { rot: None, shift: None, free: Some(quaternion_rotation(b, i + 1, quat)) }
            }
            _ => Motion { rot: None, shift: None, free: None },
        };
        motions.push(motion);
    }
    motions
}

/// Writes `invdyna` (outputs `Qq[1..nq]`) into `b`.
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn invdyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let nq = layout.nv;
    let drive = Drive::inputs(b, nq, true);
    let motions = motions(model, layout, b);
    for (qi, t) in sweep(model, layout, b, &motions, &drive)? {
        b.output(&format!("Qq[{qi}]"), &format!("Qq{qi}"), t);
    }
    Ok(())
}

/// `a + b` entry by entry, taking both (no copy of `a`: a link's sum over its children grows
/// by one child at a time, and copying it each time would cost the square of its children).
fn vadd_into(a: &mut V3, b: V3) {
    for (x, y) in a.iter_mut().zip(b) {
        *x = add(std::mem::take(x), y);
    }
}

/// Children whose terms a link's sum holds before it is bound (issue 28): a sum over a
/// link's children is one expression whose depth is their number, and every recursion over
/// expressions (this crate's, the IR's printer, verifier and `atomise`) would overflow the
/// stack on a hub of 100,000 branches. Binding the partial sum every `SUM_CHUNK` children
/// keeps every expression shallow; a link of the examples and example-robot-data has at most
/// a handful of children, whose sums stay as they were.
pub(super) const SUM_CHUNK: usize = 64;

/// Adds child term `t` to link `p`'s sum `acc` of `children` terms so far and binds the sum
/// as `{name}{k}{p}_{chunk}` after every [`SUM_CHUNK`]-th child.
fn add_child(b: &mut Builder, name: &str, p: usize, acc: &mut V3, children: usize, t: V3) {
    vadd_into(acc, t);
    if (children + 1).is_multiple_of(SUM_CHUNK) {
        *acc = bind3(b, name, format_args!("{p}_{}", (children + 1) / SUM_CHUNK), std::mem::take(acc));
    }
}

/// One RNEA sweep driven by `drive`: the joint forces `(i, Q_i)` of the coordinates that bear
/// one, sorted by `i` (terms, not yet bound). Cost: linear in the bodies and the ops written.
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body, forward and backward).
pub fn sweep(
    model: &Model,
    layout: &Layout,
    b: &mut Builder,
    motions: &[Motion],
    drive: &Drive,
) -> Result<Vec<(usize, Term)>, Stopped> {
    let robot = &model.robot;
    let order = robot.dfs_joints();
    let nb = order.len();
    // Per body (1-based index = position in `order` + 1): kinematics in its frame.
    let g: V3 = drive.g.clone().map(neg);
    let mut om: Vec<V3> = vec![Default::default(); nb + 1];
    // `U = [ω̇]× + [ω]×²` per body ([`acceleration_matrix`]); 0 for the fixed base.
    let mut u: Vec<M3> = vec![Default::default(); nb + 1];
    let mut omp: Vec<V3> = vec![Default::default(); nb + 1];
    let mut alpha: Vec<V3> = vec![Default::default(); nb + 1];
    om[0] = [ZERO, ZERO, ZERO];
    omp[0] = [ZERO, ZERO, ZERO];
    alpha[0] = g;
    // Body of each link (0: the root, the base).
    let link_body = robot.link_bodies(&order);
    let body_of_link = |l: usize| link_body[l];
    // Forward kinematics.
    for (i, &j) in order.iter().enumerate() {
        let body = i + 1;
        b.check(body, nb)?;
        let joint = &robot.joints[j];
        let p = body_of_link(joint.parent);
        let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
        let ro = numeric(&joint.origin.rot);
        // Parent quantities at the joint origin, in the joint frame.
        let acc = vadd(&alpha[p], &matvec(&u[p], &d, false));
        let om_j = matvec(&ro, &om[p], true);
        let omp_j = matvec(&ro, &omp[p], true);
        let mut al_j = matvec(&ro, &acc, true);
        let m = &motions[body];
        let (qd, qdd) = match layout.v_index[i] {
            Some(qi) => (drive.qd[qi - 1].clone(), drive.qdd[qi - 1].clone()),
            None => (ZERO, ZERO),
        };
        let (om_b, omp_b, al_b) = match (&m.rot, &m.shift, &m.free) {
            (_, _, Some(r)) => {
                // A free flyer from the fixed world (`om_j`, `omp_j` are 0): the base's own
                // velocity (linear `v`, angular `w`) and its derivative in its frame, so the
                // classical acceleration of its origin is `v' + w × v`.
                let qi = layout.v_index[i].expect("a free flyer has coordinates");
                let at = |x: &[Term], k: usize| x[qi - 1 + k].clone();
                let (v, w) = ([0, 1, 2].map(|k| at(&drive.qd, k)), [3, 4, 5].map(|k| at(&drive.qd, k)));
                let (vp, wp) = ([0, 1, 2].map(|k| at(&drive.qdd, k)), [3, 4, 5].map(|k| at(&drive.qdd, k)));
                let al_b = vadd(&matvec(r, &al_j, true), &vadd(&vp, &cross(&w, &v)));
                (vadd(&matvec(r, &om_j, true), &w), vadd(&matvec(r, &omp_j, true), &wp), al_b)
            }
            (Some(r), _, _) => {
                let om_j = bind3(b, "ROM", body, om_j);
                let al_j = bind3(b, "RALPHA", body, al_j);
                let om_r = matvec(r, &om_j, true);
                let omp_r = matvec(r, &omp_j, true);
                let sq = scale(&joint.axis, &qd);
                let om_b = vadd(&om_r, &sq);
                let omp_b = vadd(&vadd(&omp_r, &scale(&joint.axis, &qdd)), &cross(&om_r, &sq));
                (om_b, omp_b, matvec(r, &al_j, true))
            }
            (None, Some(shift), _) => {
                let om_j = bind3(b, "ROM", body, om_j);
                let omp_j = bind3(b, "ROMp", body, omp_j);
                al_j = vadd(&al_j, &vadd(&cross(&omp_j, shift), &cross(&om_j, &cross(&om_j, shift))));
                let sq = scale(&joint.axis, &qd);
                let cor = cross(&om_j, &sq);
                let al_b = vadd(&vadd(&al_j, &scale(&joint.axis, &qdd)), &vadd(&cor, &cor));
                (om_j, omp_j, al_b)
            }
            (None, None, None) => (om_j, omp_j, al_j),
        };
        om[body] = bind3(b, "OM", body, om_b);
        omp[body] = bind3(b, "OMp", body, omp_b);
        u[body] = acceleration_matrix(b, body, &om[body], &omp[body]);
        alpha[body] = bind3(b, "ALPHA", body, al_b);
    }
    // Which bodies move: those with a moving joint on their path from the root. The others
    // (fixed to the base) bear no joint torque.
    let moves = layout.moving_bodies(&robot.body_parents(&order));
    // Backward dynamics.
    let mut fq: Vec<V3> = vec![[ZERO, ZERO, ZERO]; nb + 1];
    let mut cq: Vec<V3> = vec![[ZERO, ZERO, ZERO]; nb + 1];
    let mut children = vec![0usize; nb + 1];
    let mut torque: Vec<(usize, Term)> = Vec::new();
    for i in (0..nb).rev() {
        let body = i + 1;
        if !moves[body] {
            continue;
        }
        b.check(body, nb)?;
        let joint = &robot.joints[order[i]];
        let p = body_of_link(joint.parent);
        let mass = layout.param(b, &format!("m[{body}]"));
        let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
        let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
        let (w, wp, a) = (&om[body], &omp[body], &alpha[body]);
        let acc_c = vadd(a, &matvec(&u[body], &l, false));
        let fs = bind3(b, "Fs", body, acc_c.map(|x| mul(mass.clone(), x)));
        let iw = matvec(&inn, w, false);
        let cs = vadd(&vadd(&matvec(&inn, wp, false), &cross(w, &iw)), &cross(&l, &fs));
        let f_tot = bind3(b, "Fq", body, vadd(&fs, &fq[body]));
        let c_tot = bind3(b, "Cq", body, vadd(&cs, &cq[body]));
        let m = &motions[body];
        match (joint.kind, layout.v_index[i]) {
            (JointKind::Prismatic, Some(qi)) => torque.push((qi, dot(&joint.axis, &f_tot))),
            (JointKind::Revolute, Some(qi)) => torque.push((qi, dot(&joint.axis, &c_tot))),
            // The base's spatial force in its frame: force, then moment about its origin.
            (JointKind::FreeFlyer, Some(qi)) => {
                torque.extend(f_tot.iter().chain(&c_tot).enumerate().map(|(k, t)| (qi + k, t.clone())))
            }
            _ => {}
        }
        // Into the parent's frame, about its origin.
        if !moves[p] {
            continue;
        }
        let (f_j, c_j) = match (&m.rot, &m.shift) {
            (Some(r), _) => (matvec(r, &f_tot, false), matvec(r, &c_tot, false)),
            (None, Some(shift)) => (f_tot.clone(), vadd(&c_tot, &cross(shift, &f_tot))),
            (None, None) => (f_tot.clone(), c_tot.clone()),
        };
        let ro = numeric(&joint.origin.rot);
        let f_p = bind3(b, "Fr", body, matvec(&ro, &f_j, false));
        let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
        let c_p = vadd(&matvec(&ro, &c_j, false), &cross(&d, &f_p));
        add_child(b, "FqS", p, &mut fq[p], children[p], f_p);
        add_child(b, "CqS", p, &mut cq[p], children[p], c_p);
        children[p] += 1;
    }
    torque.sort_by_key(|&(qi, _)| qi);
    Ok(torque)
}
