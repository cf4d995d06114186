//! One Newton–Euler sweep in the world frame, every recursion of the body-frame RNEA
//! ([`crate::rnea::sweep`]) written as a parallel prefix along the tree's heavy chains
//! ([`super::scan`]). The formulas are in the module doc of [`super`].

use super::scan::{heavy_chains, prefix, suffix, Network};
use crate::rnea::{acceleration_matrix, cross, matvec, numeric, vadd, Drive, Motion, M3, V3};
use crate::robot::JointKind;
use crate::sym::{mul, neg, sub, sum, Builder, Term, ZERO};
use crate::{Layout, Model, Stopped};

/// The network of the rotation prefixes (3 × 3 products, 45 ops each when dense): the fewer
/// products.
const ROTATIONS: Network = Network::BrentKung;
/// The network of the vector prefixes and suffixes (3 adds each): the shallower.
const SUMS: Network = Network::Sklansky;

/// `a·c` of two 3 × 3 matrices (entries summed left to right).
fn matmul(a: &M3, c: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| sum((0..3).map(|k| mul(a[i][k].clone(), c[k][j].clone())))))
}

/// `m·k` for a numeric vector `k` (a joint axis).
fn matvec_num(m: &M3, k: &[f64; 3]) -> V3 {
    [0, 1, 2].map(|r| sum((0..3).map(|c| mul(m[r][c].clone(), Term::C(k[c])))))
}

/// `v·s`, entry by entry.
fn vscale(v: &V3, s: &Term) -> V3 {
    v.clone().map(|x| mul(x, s.clone()))
}

/// `a·c` for two vectors of terms.
fn vdot(a: &V3, c: &V3) -> Term {
    sum((0..3).map(|k| mul(a[k].clone(), c[k].clone())))
}

/// Binds the entries of `m` as `{name}{r}{c}_{n}`.
fn bind_m3(b: &mut Builder, name: &str, n: impl std::fmt::Display, m: M3) -> M3 {
    let mut out: M3 = Default::default();
    for (r, row) in m.into_iter().enumerate() {
        for (c, e) in row.into_iter().enumerate() {
            out[r][c] = b.bind(&format!("{name}{}{}_{n}", r + 1, c + 1), e);
        }
    }
    out
}

/// Binds the entries of `v` as `{name}{k}_{n}`.
fn bind_v3(b: &mut Builder, name: &str, n: impl std::fmt::Display, v: V3) -> V3 {
    let [x, y, z] = v;
    [b.bind(&format!("{name}1_{n}"), x), b.bind(&format!("{name}2_{n}"), y), b.bind(&format!("{name}3_{n}"), z)]
}

/// Prefix sums along one chain: `start + t₁ + ⋯ + t_i` for every `i`, bound as
/// `{name}{k}_{body}`. An early `start` (the base's value, an input or 0) joins the first term;
/// a late one (the chain head's parent's) is added to every prefix, one add after the network.
fn vector_prefix(b: &mut Builder, name: &str, bodies: &[usize], start: &V3, late: bool, mut terms: Vec<V3>) -> Vec<V3> {
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

/// The joint forces `(i, Q_i)` of one sweep driven by `drive`, sorted by `i` (terms, not yet
/// bound): the same values as [`crate::rnea::sweep`] in exact arithmetic. Cost: linear in the
/// bodies times the log of the longest chain (the Sklansky sums), and in the ops written.
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
    let mut link_body = vec![0; robot.links.len()];
    for (i, &j) in order.iter().enumerate() {
        link_body[robot.joints[j].child] = i + 1;
    }
    let mut parent = vec![0usize; nb + 1];
    let mut moves = vec![false; nb + 1];
    for (i, &j) in order.iter().enumerate() {
        parent[i + 1] = link_body[robot.joints[j].parent];
        moves[i + 1] = moves[parent[i + 1]] || layout.v_index[i].is_some();
    }
    let (chains, _) = heavy_chains(&parent);
    let identity = numeric(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let zero3 = || [ZERO, ZERO, ZERO];
    // Per body (index 0: the base), in the world frame: rotation body → world, joint axis,
    // origin, the vector from the parent's origin, ω, ω̇, the origin's acceleration minus
    // gravity, U = [ω̇]× + [ω]×².
    let mut rw: Vec<M3> = vec![identity.clone(); nb + 1];
    let mut z: Vec<V3> = vec![zero3(); nb + 1];
    let mut o: Vec<V3> = vec![zero3(); nb + 1];
    let mut om: Vec<V3> = vec![zero3(); nb + 1];
    let mut omp: Vec<V3> = vec![zero3(); nb + 1];
    let mut alpha: Vec<V3> = vec![zero3(); nb + 1];
    let mut u: Vec<M3> = vec![Default::default(); nb + 1];
    alpha[0] = drive.g.clone().map(neg);
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
    let rates = |i: usize| match layout.v_index[i] {
        Some(qi) => (drive.qd[qi - 1].clone(), drive.qdd[qi - 1].clone()),
        None => (ZERO, ZERO),
    };
    // The free flyer's (v, w, v̇, ẇ), in its frame.
    let free = |i: usize| {
        let qi = layout.v_index[i].expect("a free flyer has coordinates");
        let at = |x: &[Term], k: usize| x[qi - 1 + k].clone();
        let part = |x: &[Term], s: usize| [s, s + 1, s + 2].map(|k| at(x, k));
        (part(&drive.qd, 0), part(&drive.qd, 3), part(&drive.qdd, 0), part(&drive.qdd, 3))
    };
    // Forward: chain by chain, each from its head's parent (an earlier chain, or the base).
    let mut rn = 0usize;
    for chain in &chains {
        let p = parent[chain[0]];
        let late = p != 0;
        let es: Vec<M3> = chain.iter().map(|&c| e[c].clone()).collect();
        let mut op = |x: &M3, y: &M3| {
            rn += 1;
            bind_m3(b, "PR", rn, matmul(x, y))
        };
        let local = prefix(&es, ROTATIONS, &mut op);
        for (&body, l) in chain.iter().zip(local) {
            b.check(body, nb)?;
            let r = if late { matmul(&rw[p], &l) } else { l };
            rw[body] = bind_m3(b, "RW", body, r);
        }
        // Axes, and the vectors from each parent's origin.
        let mut w_terms = Vec::with_capacity(chain.len());
        for (k, &body) in chain.iter().enumerate() {
            let i = body - 1;
            let pb = if k == 0 { p } else { chain[k - 1] };
            let joint = &robot.joints[order[i]];
            z[body] = bind_v3(b, "Z", body, matvec_num(&rw[body], &joint.axis));
            let r = matvec(&rw[pb], &t[body], false);
            t[body] = bind_v3(b, "RD", body, r);
            let (qd, _) = rates(i);
            w_terms.push(match joint.kind {
                JointKind::Revolute => bind_v3(b, "WZ", body, vscale(&z[body], &qd)),
                JointKind::FreeFlyer => matvec(&rw[body], &free(i).1, false),
                _ => zero3(),
            });
        }
        let oms = vector_prefix(b, "OM", chain, &om[p], late, w_terms.clone());
        for (&body, x) in chain.iter().zip(oms) {
            om[body] = x;
        }
        let mut wp_terms = Vec::with_capacity(chain.len());
        for (k, &body) in chain.iter().enumerate() {
            let i = body - 1;
            let pb = if k == 0 { p } else { chain[k - 1] };
            let (_, qdd) = rates(i);
            wp_terms.push(match robot.joints[order[i]].kind {
                JointKind::Revolute => vadd(&vscale(&z[body], &qdd), &cross(&om[pb], &w_terms[k])),
                JointKind::FreeFlyer => matvec(&rw[body], &free(i).3, false),
                _ => zero3(),
            });
        }
        let omps = vector_prefix(b, "OMp", chain, &omp[p], late, wp_terms);
        for (&body, x) in chain.iter().zip(omps) {
            omp[body] = x;
            u[body] = acceleration_matrix(b, body, &om[body], &omp[body]);
        }
        let mut a_terms = Vec::with_capacity(chain.len());
        for (k, &body) in chain.iter().enumerate() {
            let i = body - 1;
            let pb = if k == 0 { p } else { chain[k - 1] };
            let (qd, qdd) = rates(i);
            let mut a = if pb == 0 { zero3() } else { matvec(&u[pb], &t[body], false) };
            match robot.joints[order[i]].kind {
                JointKind::Prismatic => {
                    let zq = bind_v3(b, "VZ", body, vscale(&z[body], &qd));
                    let cor = bind_v3(b, "COR", body, cross(&om[pb], &zq));
                    a = vadd(&vadd(&a, &vscale(&z[body], &qdd)), &vadd(&cor, &cor));
                }
                JointKind::FreeFlyer => {
                    let (v, w, vp, _) = free(i);
                    a = vadd(&a, &matvec(&rw[body], &vadd(&vp, &cross(&w, &v)), false));
                }
                _ => {}
            }
            a_terms.push(a);
        }
        let alphas = vector_prefix(b, "ALPHA", chain, &alpha[p], late, a_terms);
        let origins = vector_prefix(b, "O", chain, &o[p], late, chain.iter().map(|&c| t[c].clone()).collect());
        for ((&body, a), x) in chain.iter().zip(alphas).zip(origins) {
            alpha[body] = a;
            o[body] = x;
        }
    }
    // Backward: each body's inertial force `F` and its moment about the world origin `Mo`,
    // then their sums over subtrees, chain by chain from the last (a light child's chain comes
    // after its parent's).
    let mut f_own: Vec<V3> = vec![zero3(); nb + 1];
    let mut m_own: Vec<V3> = vec![zero3(); nb + 1];
    for body in (1..=nb).rev().filter(|&x| moves[x]) {
        b.check(body, nb)?;
        let rot = &rw[body];
        let mass = layout.param(b, &format!("m[{body}]"));
        let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
        let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
        let rho = bind_v3(b, "RL", body, matvec(rot, &l, false));
        let acc_c = vadd(&alpha[body], &matvec(&u[body], &rho, false));
        let f = bind_v3(b, "Fs", body, acc_c.map(|x| mul(mass.clone(), x)));
        // Euler's equation in the body frame: `In ω̇ + ω × In ω`, turned into the world.
        let wb = bind_v3(b, "WB", body, matvec(rot, &om[body], true));
        let wpb = bind_v3(b, "WPB", body, matvec(rot, &omp[body], true));
        let iw = bind_v3(b, "IW", body, matvec(&inn, &wb, false));
        let euler = bind_v3(b, "NB", body, vadd(&matvec(&inn, &wpb, false), &cross(&wb, &iw)));
        let c = bind_v3(b, "CM", body, vadd(&o[body], &rho));
        f_own[body] = f.clone();
        m_own[body] = bind_v3(b, "Mo", body, vadd(&matvec(rot, &euler, false), &cross(&c, &f)));
    }
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nb + 1];
    for body in 1..=nb {
        children[parent[body]].push(body);
    }
    let mut fs: Vec<V3> = vec![zero3(); nb + 1];
    let mut ms: Vec<V3> = vec![zero3(); nb + 1];
    let mut sn = 0usize;
    for chain in chains.iter().rev() {
        let mut xf = Vec::with_capacity(chain.len());
        let mut xm = Vec::with_capacity(chain.len());
        for (k, &body) in chain.iter().enumerate() {
            let heavy = chain.get(k + 1).copied();
            let light = children[body].iter().filter(|&&c| Some(c) != heavy);
            let (mut f, mut m) = (f_own[body].clone(), m_own[body].clone());
            for &c in light {
                f = vadd(&f, &fs[c]);
                m = vadd(&m, &ms[c]);
            }
            xf.push(f);
            xm.push(m);
        }
        let mut op = |x: &V3, y: &V3| {
            sn += 1;
            bind_v3(b, "SUMs", sn, vadd(x, y))
        };
        let sf = suffix(&xf, SUMS, &mut op);
        let sm = suffix(&xm, SUMS, &mut op);
        for ((&body, f), m) in chain.iter().zip(sf).zip(sm) {
            fs[body] = bind_v3(b, "Fq", body, f);
            ms[body] = bind_v3(b, "Mq", body, m);
        }
    }
    // Joint forces: the subtree's wrench about the world origin projected on the joint's
    // Plücker axis `(z, o × z)`: `z·Mq − (z × o)·Fq` (revolute), `z·Fq` (prismatic).
    let mut torque: Vec<(usize, Term)> = Vec::new();
    for (i, &j) in order.iter().enumerate() {
        let body = i + 1;
        let Some(qi) = layout.v_index[i] else { continue };
        match robot.joints[j].kind {
            JointKind::Revolute => {
                let zo = bind_v3(b, "ZO", body, cross(&z[body], &o[body]));
                torque.push((qi, sub(vdot(&z[body], &ms[body]), vdot(&zo, &fs[body]))));
            }
            JointKind::Prismatic => torque.push((qi, vdot(&z[body], &fs[body]))),
            JointKind::FreeFlyer => {
                // The base's wrench about its origin, in its frame: force, then moment.
                let n = vadd(&ms[body], &cross(&fs[body], &o[body]));
                let f = matvec(&rw[body], &fs[body], true);
                let n = matvec(&rw[body], &n, true);
                torque.extend(f.into_iter().chain(n).enumerate().map(|(k, x)| (qi + k, x)));
            }
            JointKind::Fixed => {}
        }
    }
    torque.sort_by_key(|&(qi, _)| qi);
    Ok(torque)
}
