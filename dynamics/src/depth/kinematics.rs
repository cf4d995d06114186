//! The world-frame kinematics both depth-optimised writers read ([`super::forces`] and
//! [`super::composite`]): each body's orientation, joint axis and origin as parallel prefixes
//! along the tree's heavy chains ([`super::scan`]), and the helpers that write them.

use super::scan::{heavy_chains, prefix, Network};
use crate::rnea::{cross, matvec, numeric, vadd, Motion, M3, V3};
use crate::robot::JointKind;
use crate::sym::{mul, sum, Builder, Term, ZERO};
use crate::{Layout, Model, Stopped};

/// The network of the rotation prefixes (3 × 3 products, 45 ops each when dense):
/// Ladner–Fischer's `P₁`, one level of pairing around Sklansky. Measured on the study robots
/// (`scripts/depth_formulation.sh`): as short as Sklansky (a 130-joint chain's `invdyna` 715
/// cycles after `atomise`, Brent–Kung's 796) for fewer products (41 596 ops against Sklansky's
/// 46 886 and Brent–Kung's 38 410); `P₂` is 746 cycles again (docs/rewrites.md).
pub(super) const ROTATIONS: Network = Network::LadnerFischer(1);
/// The network of the vector prefixes and suffixes (3 adds each): the shallower.
pub(super) const SUMS: Network = Network::Sklansky;

/// `a·c` of two 3 × 3 matrices (entries summed left to right).
pub(crate) fn matmul(a: &M3, c: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| sum((0..3).map(|k| mul(a[i][k].clone(), c[k][j].clone())))))
}

/// `m·k` for a numeric vector `k` (a joint axis).
pub(super) fn matvec_num(m: &M3, k: &[f64; 3]) -> V3 {
    [0, 1, 2].map(|r| sum((0..3).map(|c| mul(m[r][c].clone(), Term::C(k[c])))))
}

/// `v·s`, entry by entry.
pub(crate) fn vscale(v: &V3, s: &Term) -> V3 {
    v.clone().map(|x| mul(x, s.clone()))
}

/// `a·c` for two vectors of terms.
pub(crate) fn vdot(a: &V3, c: &V3) -> Term {
    sum((0..3).map(|k| mul(a[k].clone(), c[k].clone())))
}

/// Binds the entries of `m` as `{name}{r}{c}_{n}`.
pub(super) fn bind_m3(b: &mut Builder, name: &str, n: impl std::fmt::Display, m: M3) -> M3 {
    let mut out: M3 = Default::default();
    for (r, row) in m.into_iter().enumerate() {
        for (c, e) in row.into_iter().enumerate() {
            out[r][c] = b.bind(&format!("{name}{}{}_{n}", r + 1, c + 1), e);
        }
    }
    out
}

/// Binds the entries of `v` as `{name}{k}_{n}`.
pub(crate) fn bind_v3(b: &mut Builder, name: &str, n: impl std::fmt::Display, v: V3) -> V3 {
    let [x, y, z] = v;
    [b.bind(&format!("{name}1_{n}"), x), b.bind(&format!("{name}2_{n}"), y), b.bind(&format!("{name}3_{n}"), z)]
}

/// Prefix sums along one chain: `start + t₁ + ⋯ + t_i` for every `i`, bound as
/// `{name}{k}_{body}`. An early `start` (the base's value, an input or 0) joins the first term;
/// a late one (the chain head's parent's) is added to every prefix, one add after the network.
pub(super) fn vector_prefix(
    b: &mut Builder,
    name: &str,
    bodies: &[usize],
    start: &V3,
    late: bool,
    mut terms: Vec<V3>,
) -> Vec<V3> {
    if !late {
        terms[0] = vadd(start, &terms[0]);
    }
    let mut n = 0usize;
    let inner = format!("{name}s");
    let mut op = |x: &V3, y: &V3| {
        n += 1;
        bind_v3(b, &inner, format_args!("{}_{n}", bodies[0]), vadd(x, y))
    };
    let sums = prefix(&terms, SUMS, &mut op);
    sums.into_iter()
        .zip(bodies)
        .map(|(s, &body)| {
            let s = if late { vadd(start, &s) } else { s };
            bind_v3(b, name, body, s)
        })
        .collect()
}

/// The world-frame kinematics of a tree (index = body in the depth-first walk, 0 the base).
pub struct Frames {
    /// The depth-first walk of joints ([`crate::robot::Robot::dfs_joints`]).
    pub order: Vec<usize>,
    /// Parent body of each body (0: the base).
    pub parent: Vec<usize>,
    /// Whether a moving joint lies on the body's path from the root.
    pub moves: Vec<bool>,
    /// The heavy chains ([`super::scan::heavy_chains`]), by head.
    pub chains: Vec<Vec<usize>>,
    /// Orientation body → world `R_b` (3 × 3).
    pub rw: Vec<M3>,
    /// Joint axis in the world `z_b = R_b·axis` (unit; 0 for a fixed joint's axis when unset).
    pub z: Vec<V3>,
    /// The step from the parent's origin to the body's, in the world: `r_b = R_p·t_b`, m.
    pub r: Vec<V3>,
    /// The body's origin in the world `o_b = o_p + r_b` (the base's at 0), m.
    pub o: Vec<V3>,
    /// `z_b × o_b` of a revolute joint (minus the moment part of its Plücker axis), m; 0 else.
    pub zo: Vec<V3>,
}

impl Frames {
    /// Writes the orientations (Ladner–Fischer prefixes of the joint rotations, times the chain
    /// head's parent's), axes, steps and origins (Sklansky prefix sums) of every body into `b`.
    ///
    /// # Errors
    /// [`Stopped`] at the builder's deadline (checked per body).
    pub fn of(model: &Model, layout: &Layout, b: &mut Builder, motions: &[Motion]) -> Result<Frames, Stopped> {
        Frames::relative_to(model, layout, b, motions, None).map(|(f, _)| f)
    }

    /// [`Frames::of`] in the coordinates of the inertial frame that coincides with body
    /// `reference`'s frame at this instant (`x' = R_refᵀ (x − o_ref)`; `None`: the world's):
    /// the reference's pose and its ancestors' are the identity there, so their rotations
    /// leave every body's pose. Returns the frames and `R_ref` (reference → world, 3 × 3, the
    /// identity for `None`), which maps world vectors such as gravity: `g' = R_refᵀ g`. Every
    /// moving body should lie in the reference's subtree: one outside it is posed through the
    /// reference's inverse, at a cost in ops.
    ///
    /// # Errors
    /// [`Stopped`] at the builder's deadline (checked per body).
    pub fn relative_to(
        model: &Model,
        layout: &Layout,
        b: &mut Builder,
        motions: &[Motion],
        reference: Option<usize>,
    ) -> Result<(Frames, M3), Stopped> {
        let robot = &model.robot;
        let order = robot.dfs_joints();
        let nb = order.len();
        let parent = robot.body_parents(&order);
        let moves = layout.moving_bodies(&parent);
        let (chains, _) = heavy_chains(&parent);
        let identity = numeric(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        let zero3 = || [ZERO, ZERO, ZERO];
        // The joint's rotation child → parent `E` and the child origin in the parent frame `t`.
        let mut e: Vec<M3> = vec![identity.clone(); nb + 1];
        let mut t: Vec<V3> = vec![zero3(); nb + 1];
        for (i, &j) in order.iter().enumerate() {
            let body = i + 1;
            let joint = &robot.joints[j];
            let ro = numeric(&joint.origin.rot);
            let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
            let m = &motions[body];
            e[body] = match (&m.rot, &m.free) {
                (_, Some(r)) => r.clone(),
                (Some(r), _) => matmul(&ro, r),
                _ => ro.clone(),
            };
            t[body] = match &m.shift {
                Some(s) => vadd(&d, &matvec(&ro, s, false)),
                None => d,
            };
        }
        // The reference and its ancestors: their rotation composed (root first), then the identity.
        let mut r_ref = identity.clone();
        if let Some(reference) = reference {
            let mut path = vec![reference];
            while parent[*path.last().expect("not empty")] != 0 {
                path.push(parent[*path.last().expect("not empty")]);
            }
            for &a in path.iter().rev() {
                r_ref = matmul(&r_ref, &e[a]);
                e[a] = identity.clone();
                t[a] = zero3();
            }
        }
        let mut f = Frames {
            rw: vec![identity; nb + 1],
            z: vec![zero3(); nb + 1],
            r: vec![zero3(); nb + 1],
            o: vec![zero3(); nb + 1],
            zo: vec![zero3(); nb + 1],
            order,
            parent,
            moves,
            chains,
        };
        let mut rn = 0usize;
        for chain in &f.chains {
            let p = f.parent[chain[0]];
            let es: Vec<M3> = chain.iter().map(|&c| e[c].clone()).collect();
            let mut op = |x: &M3, y: &M3| {
                rn += 1;
                bind_m3(b, "PR", rn, matmul(x, y))
            };
            let local = prefix(&es, ROTATIONS, &mut op);
            for (&body, l) in chain.iter().zip(local) {
                b.check(body, nb)?;
                let r = if p != 0 { matmul(&f.rw[p], &l) } else { l };
                f.rw[body] = bind_m3(b, "RW", body, r);
            }
            for (k, &body) in chain.iter().enumerate() {
                let pb = if k == 0 { p } else { chain[k - 1] };
                let joint = &robot.joints[f.order[body - 1]];
                f.z[body] = bind_v3(b, "Z", body, matvec_num(&f.rw[body], &joint.axis));
                let r = matvec(&f.rw[pb], &t[body], false);
                f.r[body] = bind_v3(b, "RD", body, r);
            }
            let steps: Vec<V3> = chain.iter().map(|&c| f.r[c].clone()).collect();
            let origins = vector_prefix(b, "O", chain, &f.o[p], p != 0, steps);
            for (&body, x) in chain.iter().zip(origins) {
                f.o[body] = x;
                if robot.joints[f.order[body - 1]].kind == JointKind::Revolute && layout.v_index[body - 1].is_some() {
                    f.zo[body] = bind_v3(b, "ZO", body, cross(&f.z[body], &f.o[body]));
                }
            }
        }
        Ok((f, r_ref))
    }
}
