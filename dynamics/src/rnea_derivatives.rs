//! The analytical derivatives of the inverse dynamics, ∂τ/∂q and ∂τ/∂v (issue 50 item 2: the
//! recursions of Carpentier & Mansard, "Analytical derivatives of rigid body dynamics
//! algorithms", RSS 2018, written by the generator), in one inertial frame; and the world-frame
//! `M` and `c` that `aba_derivatives` solves with ([`world_parts`]).
//!
//! # Formulation
//! Plücker coordinates of the inertial frame that coincides, at this instant, with the frame of
//! the *moving root* (the lowest body above every moving joint; the world's own frame when there
//! is none): τ and its derivatives are the same in any inertial frame, and in this one the
//! root's pose is the identity, so its rotation enters only gravity, `g' = R_rootᵀ g`, and the
//! free flyer's columns are unit twists. Below, "world" means this frame. A motion `(v; ω)` (the
//! velocity of the point at the origin, the angular velocity), a force `(F; N)` (the moment
//! about the origin), their pairing `v·F + ω·N`. Joint column `S_j`: `(o × z; z)` for a revolute
//! joint of world axis `z` through `o`, `(z; 0)` prismatic, the base frame's unit twists for a
//! free flyer (Pinocchio's tangent space: the derivatives come out along it, with no map). Per
//! body `k` (parent `λ`): `V_k = V_λ + Σ S_j q̇_j`, `A_k = A_λ + Σ S_j q̈_j + Σ (V_k × S_j) q̇_j`
//! with `A_0 = (−g'; 0)`, the spatial inertia `I_k` about the origin (mass `m`, first moment `h = m c`,
//! second moment `J`), `f_k = I_k A_k + V_k ×* I_k V_k`. Per subtree: its inertia `Ic`, force
//! `F`, momentum `Hc = Σ I_k V_k` and the rate of its inertia `İc = Σ ([V_k×*] I_k − I_k [V_k×])`
//! (a spatial inertia with zero mass: `ḣ = m v + ω × h`, `J̇ = [ω]×J − J[ω]× − (h vᵀ + v hᵀ) +
//! 2 (v·h) 1`).
//!
//! Moving `q_j` moves the subtree of `j` rigidly (`S_j ×`) and, beyond that, changes its bodies'
//! velocities by `w_j = V_λ(j) × S_j` and accelerations by `p_j + w_j × V_k`, `p_j = A_λ(j) × S_j
//! − w_j × V_λ(j)`; the rigid part cancels in `τ_i = S_i·F_i` when `S_i` moves with it. So, with
//! `B x = İc x + x ×* Hc` (the rate of `Σ I_k (x × V_k) + x ×* I_k V_k + V_k ×* I_k x`):
//! - `j` an ancestor-or-self of `i`: `∂τ_i/∂q_j = r1_i·p_j + r2_i·w_j` and
//!   `∂τ_i/∂q̇_j = r1_i·(w_j + Ṡ_j) + r2_i·S_j`, with `r1_i = Ic_i S_i`, `r2_i = İc_i S_i −
//!   S_i ×* Hc_i` (subtree of `i`) and `Ṡ_j = V_k × S_j` (`k` the body of `j`);
//! - `i` a strict ancestor of `j`: `∂τ_i/∂q_j = S_i·(S_j ×* F_j + Ic_j p_j + B_j w_j)` and
//!   `∂τ_i/∂q̇_j = S_i·(Ic_j (w_j + Ṡ_j) + B_j S_j)` (subtree of `j`);
//! - 0 otherwise.
//!
//! Per pair two 6-vector pairings (one where `i` is above `j`), after a pass over the bodies.

use crate::depth::composite::{origin_inertia, OriginInertia};
use crate::depth::kinematics::{bind_v3, vdot, vscale, Frames};
use crate::rnea::{cross, matvec, motions, vadd, Drive, Motion, M3, V3};
use crate::robot::JointKind;
use crate::sym::{add, mul, neg, sub, Builder, Term, ZERO};
use rustc_hash::FxHashMap;

use crate::{Layout, Model, Stopped};

/// A spatial vector: linear part, angular part (a motion `(v; ω)` or a force `(F; N)`).
type S6 = [V3; 2];

fn zero3() -> V3 {
    [ZERO, ZERO, ZERO]
}

fn zero6() -> S6 {
    [zero3(), zero3()]
}

fn add6(a: &S6, b: &S6) -> S6 {
    [vadd(&a[0], &b[0]), vadd(&a[1], &b[1])]
}

fn sub3(a: &V3, b: &V3) -> V3 {
    [0, 1, 2].map(|k| sub(a[k].clone(), b[k].clone()))
}

fn scale6(a: &S6, s: &Term) -> S6 {
    [vscale(&a[0], s), vscale(&a[1], s)]
}

/// Motion cross motion: `(ω₁ × v₂ + v₁ × ω₂; ω₁ × ω₂)`.
fn mcross(a: &S6, b: &S6) -> S6 {
    [vadd(&cross(&a[1], &b[0]), &cross(&a[0], &b[1])), cross(&a[1], &b[1])]
}

/// Motion cross force: `(ω × F; ω × N + v × F)`.
fn fcross(m: &S6, f: &S6) -> S6 {
    [cross(&m[1], &f[0]), vadd(&cross(&m[1], &f[1]), &cross(&m[0], &f[0]))]
}

/// The pairing of a motion and a force, `v·F + ω·N`.
fn pair(m: &S6, f: &S6) -> Term {
    add(vdot(&m[0], &f[0]), vdot(&m[1], &f[1]))
}

fn bind6(b: &mut Builder, name: &str, n: impl std::fmt::Display + Copy, x: S6) -> S6 {
    let [l, a] = x;
    [bind_v3(b, &format!("{name}l"), n, l), bind_v3(b, &format!("{name}a"), n, a)]
}

/// A spatial inertia about the world origin: mass, first moment `h = m c`, second moment `J`
/// (symmetric). With `mass` zero it holds a rate of change (`İ`).
#[derive(Clone)]
struct Inertia {
    mass: Term,
    h: V3,
    j: M3,
}

impl Inertia {
    fn zero() -> Inertia {
        Inertia { mass: ZERO, h: zero3(), j: Default::default() }
    }

    /// `I·(v; ω) = (m v − h × ω; h × v + J ω)`.
    fn apply(&self, x: &S6) -> S6 {
        let lin = sub3(&vscale(&x[0], &self.mass), &cross(&self.h, &x[1]));
        let ang = vadd(&cross(&self.h, &x[0]), &matvec(&self.j, &x[1], false));
        [lin, ang]
    }

    fn plus(&self, o: &Inertia) -> Inertia {
        let j = [0, 1, 2].map(|r| [0, 1, 2].map(|c| add(self.j[r][c].clone(), o.j[r][c].clone())));
        Inertia { mass: add(self.mass.clone(), o.mass.clone()), h: vadd(&self.h, &o.h), j }
    }

    /// Its entries bound (the upper triangle of `J`, mirrored).
    fn bind(self, b: &mut Builder, name: &str, n: usize) -> Inertia {
        let mass = b.bind(&format!("{name}m{n}"), self.mass);
        let h = bind_v3(b, &format!("{name}h"), n, self.h);
        let mut upper: FxHashMap<(usize, usize), Term> = FxHashMap::default();
        for (r, row) in self.j.iter().enumerate() {
            for (c, x) in row.iter().enumerate().skip(r) {
                upper.insert((r, c), b.bind(&format!("{name}J{}{}_{n}", r + 1, c + 1), x.clone()));
            }
        }
        let j: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| upper[&(r.min(c), r.max(c))].clone()));
        Inertia { mass, h, j }
    }
}

/// Whether body `a` is body `x` or one of its ancestors (`parent` by body, 0 the base).
fn ancestor_or_self(parent: &[usize], a: usize, mut x: usize) -> bool {
    while x != 0 {
        if x == a {
            return true;
        }
        x = parent[x];
    }
    false
}

/// One velocity coordinate: its index (1-based), its body, its column `S`.
struct Column {
    index: usize,
    body: usize,
    s: S6,
}

/// The world-frame quantities that the analytical `∂τ` ([`rnea_derivatives`]) and the
/// world-frame `M` and `c` ([`world_parts`]) both read. Both write them alike, so that a function
/// built from both (`aba_derivatives`, `crate::implicit`) shares them after `cse`.
struct World {
    frames: Frames,
    /// The columns, by velocity coordinate (0-based).
    columns: Vec<Column>,
    /// Each body's columns (indices into `columns`; index = body, 0 the base).
    of_body: Vec<Vec<usize>>,
    /// Per column `w_j = V_λ(j) × S_j`, the change of its subtree's velocities per unit `q_j`
    /// beyond the rigid motion (zero when `λ(j)` does not move).
    w: Vec<S6>,
    /// Each body's velocity and acceleration (index = body, 0 the base).
    vel: Vec<S6>,
    acc: Vec<S6>,
    /// Each moving body's inertia about the origin, momentum `I V` and force `I A + V ×* I V`.
    inertia: Vec<Inertia>,
    momentum: Vec<S6>,
    force: Vec<S6>,
}

impl World {
    /// Writes the frames, the columns, the velocities and accelerations (with `drive.qdd`, zero
    /// for `c`) and each moving body's inertia, momentum and force. Coordinates are those of
    /// the inertial frame that coincides with the moving root's frame at this instant (the
    /// lowest body above every moving joint): its pose leaves every body's, and its rotation is
    /// left only in gravity, `g' = R_rootᵀ g`.
    ///
    /// # Errors
    /// [`Stopped`] at the builder's deadline (checked per body).
    fn of(
        model: &Model,
        layout: &Layout,
        b: &mut Builder,
        motions: &[Motion],
        drive: &Drive,
    ) -> Result<World, Stopped> {
        let robot = &model.robot;
        let nv = layout.nv;
        let order = robot.dfs_joints();
        let parents = robot.body_parents(&order);
        let moving: Vec<usize> = (1..=order.len()).filter(|&k| layout.v_index[k - 1].is_some()).collect();
        let root = moving.first().copied().filter(|&r| moving.iter().all(|&k| ancestor_or_self(&parents, r, k)));
        let (frames, r_root) = Frames::relative_to(model, layout, b, motions, root)?;
        let gravity = match root {
            Some(root) => bind_v3(b, "GB", root, matvec(&r_root, &drive.g, true)),
            None => drive.g.clone(),
        };
        let Frames { order, parent, moves, rw, z, o, .. } = &frames;
        let nb = order.len();
        let mut columns: Vec<Column> = Vec::with_capacity(nv);
        for (i, &jn) in order.iter().enumerate() {
            let body = i + 1;
            let Some(qi) = layout.v_index[i] else { continue };
            match robot.joints[jn].kind {
                JointKind::Revolute => {
                    let s = [bind_v3(b, "SL", body, cross(&o[body], &z[body])), z[body].clone()];
                    columns.push(Column { index: qi, body, s });
                }
                JointKind::Prismatic => columns.push(Column { index: qi, body, s: [z[body].clone(), zero3()] }),
                JointKind::FreeFlyer => {
                    // The base frame's axes: the columns of its rotation.
                    let axes: [V3; 3] = [0, 1, 2].map(|k| [0, 1, 2].map(|r| rw[body][r][k].clone()));
                    for (k, e) in axes.iter().enumerate() {
                        columns.push(Column { index: qi + k, body, s: [e.clone(), zero3()] });
                    }
                    for (k, e) in axes.into_iter().enumerate() {
                        let l = bind_v3(b, "SL", format_args!("{body}_{k}"), cross(&o[body], &e));
                        columns.push(Column { index: qi + 3 + k, body, s: [l, e] });
                    }
                }
                JointKind::Fixed => {}
            }
        }
        columns.sort_by_key(|c| c.index);
        assert_eq!(columns.len(), nv, "one column per velocity coordinate");
        let mut of_body: Vec<Vec<usize>> = vec![Vec::new(); nb + 1];
        for (k, c) in columns.iter().enumerate() {
            of_body[c.body].push(k);
        }
        // Forward: velocities and accelerations.
        // The bias acceleration of a body is `Σ (V_k × S_j) q̇_j = V_λ × Σ S_j q̇_j` (as `V_k × V_k
        // = 0`), so `Σ w_j q̇_j` with `w_j = V_λ × S_j`, which the partials read too: zero on a
        // body whose parent does not move (the free flyer's base).
        let mut vel: Vec<S6> = vec![zero6(); nb + 1];
        let mut acc: Vec<S6> = vec![zero6(); nb + 1];
        let mut w: Vec<S6> = vec![zero6(); nv];
        acc[0] = [gravity.map(neg), zero3()];
        for body in 1..=nb {
            b.check(body, nb)?;
            let p = parent[body];
            let mut v = vel[p].clone();
            for &k in &of_body[body] {
                v = add6(&v, &scale6(&columns[k].s, &drive.qd[columns[k].index - 1]));
            }
            let v = bind6(b, "V", body, v);
            let mut a = acc[p].clone();
            for &k in &of_body[body] {
                let c = &columns[k];
                w[k] = bind6(b, "WJ", k + 1, mcross(&vel[p], &c.s));
                a = add6(&a, &scale6(&c.s, &drive.qdd[c.index - 1]));
                a = add6(&a, &scale6(&w[k], &drive.qd[c.index - 1]));
            }
            acc[body] = bind6(b, "A", body, a);
            vel[body] = v;
        }
        // Per body: inertia about the origin, momentum, force.
        let mut inertia: Vec<Inertia> = vec![Inertia::zero(); nb + 1];
        let mut force: Vec<S6> = vec![zero6(); nb + 1];
        let mut momentum: Vec<S6> = vec![zero6(); nb + 1];
        for body in (1..=nb).filter(|&x| moves[x]) {
            b.check(body, nb)?;
            let OriginInertia { mass, h, j } = origin_inertia(layout, b, &rw[body], &o[body], body, "W");
            let [j11, j12, j13, j22, j23, j33] = j;
            let j: M3 = [[j11.clone(), j12.clone(), j13.clone()], [j12, j22.clone(), j23.clone()], [j13, j23, j33]];
            let io = Inertia { mass, h, j }.bind(b, "IO", body);
            let v = &vel[body];
            let hk = bind6(b, "HK", body, io.apply(v));
            force[body] = add6(&io.apply(&acc[body]), &fcross(v, &hk));
            momentum[body] = hk;
            inertia[body] = io;
        }
        Ok(World { frames, columns, of_body, w, vel, acc, inertia, momentum, force })
    }

    /// Whether body `a` is `x` or one of its ancestors.
    fn ancestor_or_self(&self, a: usize, x: usize) -> bool {
        ancestor_or_self(&self.frames.parent, a, x)
    }

    /// The subtree sums of per-body inertias, bound under `name`, leaves to root (a body's
    /// index is above its parent's).
    fn subtree_inertias(&self, b: &mut Builder, mut per_body: Vec<Inertia>, name: &str) -> Vec<Inertia> {
        let Frames { parent, moves, .. } = &self.frames;
        for body in (1..per_body.len()).rev().filter(|&x| moves[x]) {
            per_body[body] = per_body[body].clone().bind(b, name, body);
            let p = parent[body];
            if p != 0 && moves[p] {
                per_body[p] = per_body[p].plus(&per_body[body]);
            }
        }
        per_body
    }

    /// The subtree sums of per-body spatial vectors, bound under `name` (as
    /// [`World::subtree_inertias`]).
    fn subtree_sums(&self, b: &mut Builder, mut per_body: Vec<S6>, name: &str) -> Vec<S6> {
        let Frames { parent, moves, .. } = &self.frames;
        for body in (1..per_body.len()).rev().filter(|&x| moves[x]) {
            per_body[body] = bind6(b, name, body, per_body[body].clone());
            let p = parent[body];
            if p != 0 && moves[p] {
                per_body[p] = add6(&per_body[p], &per_body[body]);
            }
        }
        per_body
    }

    /// `r1_j = Ic S_j` over the subtree of column `j`'s body, bound, by column.
    fn r1(&self, b: &mut Builder, ic: &[Inertia]) -> Vec<S6> {
        self.columns.iter().enumerate().map(|(k, c)| bind6(b, "R1", k + 1, ic[c.body].apply(&c.s))).collect()
    }
}

/// Writes `rnea_derivatives` (outputs `dtau_dq[i][j]`, `dtau_dv[i][j]`, `i, j = 1..=nv`, row
/// by row, along Pinocchio's tangent space) by the formulation of the module doc: inputs `q`,
/// `qd`, `qdd`, `g` (and the parameters).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body and per row).
pub fn rnea_derivatives(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let nv = layout.nv;
    let drive = Drive::inputs(b, nv, true);
    let motions = motions(model, layout, b);
    let world = World::of(model, layout, b, &motions, &drive)?;
    let World { frames, columns, of_body, w, vel, acc, inertia, .. } = &world;
    let Frames { order, parent, moves, .. } = frames;
    let nb = order.len();
    // Per body: the rate of its inertia.
    let mut idot: Vec<Inertia> = vec![Inertia::zero(); nb + 1];
    for body in (1..=nb).filter(|&x| moves[x]) {
        b.check(body, nb)?;
        let (v, io) = (&vel[body], &inertia[body]);
        // İ: ḣ = m v + ω × h, J̇ = [ω]×J − J[ω]× − (h vᵀ + v hᵀ) + 2 (v·h) 1.
        let (lin, om) = (&v[0], &v[1]);
        let hdot = vadd(&vscale(lin, &io.mass), &cross(om, &io.h));
        let wj: M3 = [0, 1, 2].map(|k| cross(om, &[0, 1, 2].map(|r| io.j[r][k].clone())));
        // `wj[k]` is column k of [ω]×J; (J[ω]×)[r][k] = −([ω]×J)[k][r] (J symmetric).
        let vh = b.bind(&format!("VH{body}"), vdot(lin, &io.h));
        let jdot: M3 = [0, 1, 2].map(|r| {
            [0, 1, 2].map(|k| {
                let rot_part = add(wj[k][r].clone(), wj[r][k].clone());
                let outer = add(mul(io.h[r].clone(), lin[k].clone()), mul(lin[r].clone(), io.h[k].clone()));
                let diag = if r == k { mul(Term::C(2.0), vh.clone()) } else { ZERO };
                add(sub(rot_part, outer), diag)
            })
        });
        idot[body] = Inertia { mass: ZERO, h: hdot, j: jdot }.bind(b, "ID", body);
    }
    // Subtree sums, leaves to root.
    let ic = world.subtree_inertias(b, inertia.clone(), "IC");
    let idot = world.subtree_inertias(b, idot, "IDC");
    let force = world.subtree_sums(b, world.force.clone(), "FC");
    let momentum = world.subtree_sums(b, world.momentum.clone(), "HC");
    let r1 = world.r1(b, &ic);
    // Per column: `w + Ṡ`, p; r2 (over its body's subtree); and the terms for its ancestors.
    let mut w_sdot: Vec<S6> = Vec::with_capacity(nv);
    let mut pj: Vec<S6> = Vec::with_capacity(nv);
    let mut r2: Vec<S6> = Vec::with_capacity(nv);
    let mut g_q: Vec<S6> = Vec::with_capacity(nv);
    let mut g_v: Vec<S6> = Vec::with_capacity(nv);
    for (k, c) in columns.iter().enumerate() {
        b.check_at(crate::Reached::Row { row: k + 1, rows: nv })?;
        let (body, s) = (c.body, &c.s);
        let p = parent[body];
        let wk = &w[k];
        // `Ṡ_j = V_k × S_j`; on a body of one column `V_k = V_λ + S_j q̇_j`, so `Ṡ_j = w_j`.
        let ws = if of_body[body].len() == 1 { scale6(wk, &Term::C(2.0)) } else { add6(wk, &mcross(&vel[body], s)) };
        let ws = bind6(b, "WS", k + 1, ws);
        let pk = bind6(b, "PJ", k + 1, sub6(&mcross(&acc[p], s), &mcross(wk, &vel[p])));
        let (icb, idb, hc) = (&ic[body], &idot[body], &momentum[body]);
        let r2k = bind6(b, "R2", k + 1, sub6(&idb.apply(s), &fcross(s, hc)));
        let bop = |x: &S6| add6(&idb.apply(x), &fcross(x, hc));
        let gq = add6(&add6(&fcross(s, &force[body]), &icb.apply(&pk)), &bop(wk));
        let gv = add6(&icb.apply(&ws), &bop(s));
        g_q.push(bind6(b, "GQ", k + 1, gq));
        g_v.push(bind6(b, "GV", k + 1, gv));
        w_sdot.push(ws);
        pj.push(pk);
        r2.push(r2k);
    }
    let mut rows: Vec<Vec<(Term, Term)>> = Vec::with_capacity(nv);
    for i in 0..nv {
        b.check_at(crate::Reached::Row { row: i + 1, rows: nv })?;
        let bi = columns[i].body;
        let mut row = Vec::with_capacity(nv);
        for j in 0..nv {
            let bj = columns[j].body;
            let entry = if world.ancestor_or_self(bj, bi) {
                let dq = add(pair(&pj[j], &r1[i]), pair(&w[j], &r2[i]));
                let dv = add(pair(&w_sdot[j], &r1[i]), pair(&columns[j].s, &r2[i]));
                (dq, dv)
            } else if world.ancestor_or_self(bi, bj) {
                (pair(&columns[i].s, &g_q[j]), pair(&columns[i].s, &g_v[j]))
            } else {
                (ZERO, ZERO)
            };
            row.push(entry);
        }
        rows.push(row);
    }
    for (i, row) in rows.iter().enumerate() {
        for (j, (dq, _)) in row.iter().enumerate() {
            b.output(&format!("dtau_dq[{}][{}]", i + 1, j + 1), &format!("dtau_dq{}_{}", i + 1, j + 1), dq.clone());
        }
        for (j, (_, dv)) in row.iter().enumerate() {
            b.output(&format!("dtau_dv[{}][{}]", i + 1, j + 1), &format!("dtau_dv{}_{}", i + 1, j + 1), dv.clone());
        }
    }
    Ok(())
}

/// `M` and `c` ([`crate::dirdyna::Parts`]) in the world frame of [`rnea_derivatives`], written
/// as it writes its shared quantities, so that `aba_derivatives` built from this `fordyna` and
/// those partials (`implicit.rs`) computes them once: `M[i][j] = S_i·(Ic S_j)` (`Ic`
/// over the subtree of `j`'s body, `i`'s an ancestor or the same, the CRBA's pairing) and
/// `c_i = S_i·F_i` with the subtree force at `q̈ = 0` (the RNEA's), `i, j` velocity coordinates.
/// The closure returns [`Stopped`] at the builder's deadline (checked per body).
pub fn world_parts<'a>(
    model: &'a Model,
    layout: &'a Layout,
) -> impl FnMut(&mut Builder, &[Motion], &Drive) -> crate::dirdyna::Parted + 'a {
    move |b: &mut Builder, motions: &[Motion], drive: &Drive| {
        let world = World::of(model, layout, b, motions, drive)?;
        let ic = world.subtree_inertias(b, world.inertia.clone(), "IC");
        let force = world.subtree_sums(b, world.force.clone(), "FC");
        let r1 = world.r1(b, &ic);
        let columns = &world.columns;
        let mut entries = Vec::new();
        for (j, cj) in columns.iter().enumerate() {
            for ci in columns.iter().take(j + 1) {
                if world.ancestor_or_self(ci.body, cj.body) {
                    let t = pair(&ci.s, &r1[j]);
                    if t != ZERO {
                        entries.push(((ci.index, cj.index), t));
                    }
                }
            }
        }
        let c = columns.iter().map(|ci| (ci.index, pair(&ci.s, &force[ci.body]))).collect();
        Ok((entries, c))
    }
}

fn sub6(a: &S6, b: &S6) -> S6 {
    [sub3(&a[0], &b[0]), sub3(&a[1], &b[1])]
}

#[cfg(test)]
mod tests {
    use robovec_ir::time_limit::Ticker;

    use crate::depth::tests::{cos_sin, worst_relative};
    use crate::robot::{JointKind, Robot};
    use crate::sym::Builder;
    use crate::topology::{build, Topology};
    use crate::{Layout, Model};

    /// The worst `|analytical − diff| / (1 + max |diff|)` over three states: the analytical
    /// ∂τ/∂q, ∂τ/∂v against `diff` on the body-frame RNEA (`invdyna`, checked against Pinocchio
    /// and finite differences in `tests/diff.rs`) mapped to the tangent space, parameters as
    /// inputs at their values.
    fn worst(robot: Robot) -> f64 {
        let model = Model { robot };
        let layout = Layout::of(&model.robot);
        let mut b = Builder::new("rnea_derivatives", Default::default());
        super::rnea_derivatives(&model, &layout, &mut b).expect("no deadline");
        let analytical = b.finish();
        let mut b = Builder::new("invdyna", Default::default());
        crate::rnea::invdyna(&model, &layout, &mut b).expect("no deadline");
        let coords = crate::tangent::coordinates(&model.robot, &layout);
        let by_diff =
            crate::derive(&b.finish(), &crate::DERIVED[0], &layout, coords.as_deref(), &Ticker::new(None, None))
                .expect("no deadline");
        assert_eq!(analytical.outputs.len(), 2 * layout.nv * layout.nv);
        assert_eq!(by_diff.outputs.len(), 2 * layout.nv * layout.nv, "diff's matrices whole");
        worst_relative(&model.robot, &analytical, &by_diff, false)
    }

    /// Every joint kind and base: revolute chains and trees, prismatic joints, Pinocchio's
    /// free flyer, continuous joints as `(cos, sin)` pairs; in the moving root's coordinates
    /// (a revolute or prismatic first joint, the free flyer) and in the world's (branches off
    /// the fixed base).
    #[test]
    fn analytical_derivatives_equal_diff_on_the_rnea() {
        let mut prismatic = build(Topology::Serial, 7, 2);
        for (k, j) in prismatic.joints.iter_mut().enumerate() {
            if k % 3 == 1 && j.kind == JointKind::Revolute {
                j.kind = JointKind::Prismatic;
                j.continuous = false;
            }
        }
        // The last link massless: no equation reads the last velocity, whose column of `diff`'s
        // `dtau_dv` (zeros) was once missing.
        let mut light_tip = build(Topology::Serial, 5, 6);
        let tip = light_tip.joints.iter().map(|j| j.child).max().expect("joints");
        light_tip.links[tip].inertial = None;
        let cases = [
            ("serial 7", build(Topology::Serial, 7, 1)),
            ("serial 5, massless tip", light_tip),
            ("semi-serial 9", build(Topology::SemiSerial, 9, 1)),
            ("prismatic", prismatic),
            // Several chains off the fixed base: no moving root, the world's own coordinates.
            ("parallel 9", build(Topology::Parallel, 9, 2)),
            ("parallel 9, free flyer", build(Topology::Parallel, 9, 3).with_free_flyer().expect("free names")),
            ("semi-serial 9, cos-sin", cos_sin(build(Topology::SemiSerial, 9, 4))),
            (
                "serial 6, free flyer, cos-sin",
                cos_sin(build(Topology::Serial, 6, 5)).with_free_flyer().expect("free names"),
            ),
        ];
        for (label, robot) in cases {
            let e = worst(robot);
            assert!(e <= 1e-10, "{label}: {e:e}");
        }
    }
}
