//! The mass matrix `M` of the depth-optimised formulation: the composite-rigid-body algorithm
//! (Walker & Orin 1982, method 3; R. Featherstone, *Rigid Body Dynamics Algorithms*, 2008,
//! §6.2) in the world frame about the world origin, where a subtree's composite inertia is a
//! plain sum over its bodies — a suffix sum along each heavy chain ([`super::scan`]) instead
//! of the body-frame recurrence `I^C_p += X I^C_k Xᵀ` of [`crate::crba`].
//!
//! Per body `j` (world frame, about the origin): mass `m_j`, first moment `h_j = m_j c_j`
//! (`c_j = o_j + R_j l_j`), rotational inertia `J_j = R_j In_j R_jᵀ + m_j (|c_j|² 1 − c_j c_jᵀ)`
//! (6 entries, symmetric). A subtree's composite `(m, h, J)` is the sum of its bodies'. A
//! coordinate's Plücker axis is `s = (s_ω, s_v)` = `(z, o × z)` (revolute about `z` through
//! `o`), `(0, z)` (prismatic), the base frame's columns `(R e_k, o × R e_k)` and `(0, R e_k)`
//! (free flyer). The force of a unit motion `s` of column `j`'s composite is `n = J s_ω + h ×
//! s_v`, `F = m s_v − h × s_ω`, and `M_ij = s_ω(i)·n + s_v(i)·F` for every coordinate `i` of a
//! body on the path from the root to `j` (`i ≤ j`).

use super::kinematics::{bind_v3, vdot, Frames, SUMS};
use super::scan::suffix;
use crate::crba::{bind_entry, Entries};
use crate::rnea::{cross, matvec, vadd, M3, V3};
use crate::robot::JointKind;
use crate::sym::{add, mul, neg, sub, sum, Builder, Term, ZERO};
use crate::{Layout, Model, Stopped};

/// A composite inertia about the world origin: `[m, h₁, h₂, h₃, J₁₁, J₁₂, J₁₃, J₂₂, J₂₃, J₃₃]`.
type Inertia = [Term; 10];

/// `J·v` for the 6 entries of a symmetric `J` (`[J₁₁, J₁₂, J₁₃, J₂₂, J₂₃, J₃₃]`).
fn symvec(j: &[Term], v: &V3) -> V3 {
    let at = |r: usize, c: usize| {
        let (r, c) = (r.min(c), r.max(c));
        j[[[0, 1, 2], [1, 3, 4], [2, 4, 5]][r][c]].clone()
    };
    [0, 1, 2].map(|r| sum((0..3).map(|c| mul(at(r, c), v[c].clone()))))
}

/// One body's spatial inertia about the world origin, in world axes.
pub(crate) struct OriginInertia {
    /// Mass `m` (the parameter `m[body]`).
    pub mass: Term,
    /// First moment `h = m c` (`c = o + R l` the centre of mass, bound as `C{tag}{k}_{body}`),
    /// bound as `H{tag}{k}_{body}`.
    pub h: V3,
    /// Second moment about the origin `J = R In Rᵀ + m (|c|² 1 − c cᵀ)`, upper triangle
    /// `[J₁₁, J₁₂, J₁₃, J₂₂, J₂₃, J₃₃]`, not bound.
    pub j: [Term; 6],
}

/// Body `body`'s inertia about the world origin from its pose (`rot` its rotation to the world
/// frame, `origin` its frame's origin) and its parameters (`m[body]`, `l[k][body]`, the inertia
/// tensor about its centre of mass in its own axes), `tag` naming what it binds: the one
/// formula the depth formulation's `M` and the analytical `∂τ` (`crate::rnea_derivatives`)
/// both write. `R In` is bound row by row as `RI{tag}{r}_{body}`; the shift
/// `m (|c|² 1 − c cᵀ)` is written per entry, `h_x c_x + h_y c_y` on the diagonal (the other two
/// axes) and `−h_r c_c` off it: 3 ops an entry, no `|c|²`.
pub(crate) fn origin_inertia(
    layout: &Layout,
    b: &mut Builder,
    rot: &M3,
    origin: &V3,
    body: usize,
    tag: &str,
) -> OriginInertia {
    let mass = layout.param(b, &format!("m[{body}]"));
    let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
    let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
    let c = bind_v3(b, &format!("C{tag}"), body, vadd(origin, &matvec(rot, &l, false)));
    let h = bind_v3(b, &format!("H{tag}"), body, c.clone().map(|x| mul(mass.clone(), x)));
    // R·In, then (R·In)·Rᵀ on the upper triangle.
    let ri: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|k| sum((0..3).map(|m| mul(rot[r][m].clone(), inn[m][k].clone())))));
    let ri = [0, 1, 2].map(|r| bind_v3(b, &format!("RI{tag}{}", r + 1), body, ri[r].clone()));
    let mut j: [Term; 6] = Default::default();
    let mut e = 0;
    for r in 0..3 {
        for cc in r..3 {
            let rot_part = sum((0..3).map(|k| mul(ri[r][k].clone(), rot[cc][k].clone())));
            let shift = if r == cc {
                let (x, y) = ((r + 1) % 3, (r + 2) % 3);
                add(mul(h[x].clone(), c[x].clone()), mul(h[y].clone(), c[y].clone()))
            } else {
                neg(mul(h[r].clone(), c[cc].clone()))
            };
            j[e] = add(rot_part, shift);
            e += 1;
        }
    }
    OriginInertia { mass, h, j }
}

/// The upper triangle of `M` (1-based `(i, j)`, `i ≤ j`, entries folding to 0 left out), each
/// entry bound as `M{i}_{j}`.
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body).
pub fn mass_matrix(model: &Model, layout: &Layout, b: &mut Builder, frames: &Frames) -> Result<Entries, Stopped> {
    let robot = &model.robot;
    let Frames { order, parent, moves, chains, rw, z, o, .. } = frames;
    let nb = order.len();
    let zero = || -> Inertia { Default::default() };
    // Each moving body's own inertia about the world origin.
    let mut own: Vec<Inertia> = vec![zero(); nb + 1];
    for body in (1..=nb).filter(|&x| moves[x]) {
        b.check(body, nb)?;
        let OriginInertia { mass, h, j } = origin_inertia(layout, b, &rw[body], &o[body], body, "G");
        let mut all: Inertia = zero();
        all[0] = mass;
        all[1..4].clone_from_slice(&h);
        all[4..].clone_from_slice(&j);
        for (k, x) in all.iter_mut().enumerate() {
            *x = b.bind(&format!("KB{k}_{body}"), std::mem::take(x));
        }
        own[body] = all;
    }
    // Composites: suffix sums along each chain, the light children's added to their parent.
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nb + 1];
    for body in 1..=nb {
        children[parent[body]].push(body);
    }
    let mut comp: Vec<Inertia> = vec![zero(); nb + 1];
    let mut n = 0usize;
    for chain in chains.iter().rev() {
        let xs: Vec<Inertia> = chain
            .iter()
            .enumerate()
            .map(|(k, &body)| {
                let heavy = chain.get(k + 1).copied();
                let mut x = own[body].clone();
                for &c in children[body].iter().filter(|&&c| Some(c) != heavy) {
                    x = std::array::from_fn(|e| add(x[e].clone(), comp[c][e].clone()));
                }
                x
            })
            .collect();
        let mut op = |x: &Inertia, y: &Inertia| -> Inertia {
            n += 1;
            std::array::from_fn(|e| b.bind(&format!("KS{e}_{n}"), add(x[e].clone(), y[e].clone())))
        };
        for (&body, x) in chain.iter().zip(suffix(&xs, SUMS, &mut op)) {
            comp[body] = std::array::from_fn(|e| b.bind(&format!("KC{e}_{body}"), x[e].clone()));
        }
    }
    // Plücker axes `(s_ω, s_v)` of every coordinate, per body.
    let mut axes: Vec<Vec<(usize, V3, V3)>> = vec![Vec::new(); nb + 1];
    for (i, &j) in order.iter().enumerate() {
        let body = i + 1;
        let Some(qi) = layout.v_index[i] else { continue };
        let zero3 = || [ZERO, ZERO, ZERO];
        axes[body] = match robot.joints[j].kind {
            JointKind::Revolute => vec![(qi, z[body].clone(), frames.zo[body].clone().map(neg))],
            JointKind::Prismatic => vec![(qi, zero3(), z[body].clone())],
            JointKind::FreeFlyer => {
                let col = |k: usize| [0, 1, 2].map(|r| rw[body][r][k].clone());
                let mut v: Vec<(usize, V3, V3)> = (0..3).map(|k| (qi + k, zero3(), col(k))).collect();
                v.extend((0..3).map(|k| (qi + 3 + k, col(k), cross(&o[body], &col(k)))));
                v
            }
            JointKind::Fixed => Vec::new(),
        };
    }
    let mut entries = Entries::new();
    for body in 1..=nb {
        b.check(body, nb)?;
        let k = &comp[body];
        let (m, h, jj) = (&k[0], [k[1].clone(), k[2].clone(), k[3].clone()], &k[4..]);
        for (qj, sw, sv) in axes[body].clone() {
            let n = vadd(&symvec(jj, &sw), &cross(&h, &sv));
            let f = sub_v(&sv.clone().map(|x| mul(m.clone(), x)), &cross(&h, &sw));
            let n = bind_v3(b, "FN", qj, n);
            let f = bind_v3(b, "FF", qj, f);
            // This body's coordinates up to `qj`, then every ancestor's.
            let mut a = body;
            while a != 0 {
                for (qi, aw, av) in &axes[a] {
                    if *qi <= qj {
                        let t = add(vdot(aw, &n), vdot(av, &f));
                        entries.push(((*qi, qj), bind_entry(b, *qi, qj, t)));
                    }
                }
                a = parent[a];
            }
        }
    }
    Ok(entries)
}

/// `a − b`, entry by entry.
fn sub_v(a: &V3, c: &V3) -> V3 {
    [0, 1, 2].map(|k| sub(a[k].clone(), c[k].clone()))
}
