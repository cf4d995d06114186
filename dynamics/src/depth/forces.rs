//! One Newton–Euler sweep in the world frame, every recursion of the body-frame RNEA
//! ([`crate::rnea::sweep`]) written as a parallel prefix along the tree's heavy chains
//! ([`super::scan`]). The formulas are in the module doc of [`super`].

use super::kinematics::{bind_v3, vdot, vector_prefix, vscale, Frames, SUMS};
use super::scan::suffix;
use crate::rnea::{acceleration_matrix, cross, matvec, vadd, Drive, Motion, M3, V3};
use crate::robot::JointKind;
use crate::sym::{mul, neg, sub, Builder, Term, ZERO};
use crate::{Layout, Model, Stopped};

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
    let frames = Frames::of(model, layout, b, motions)?;
    sweep_in(model, layout, b, &frames, drive)
}

/// [`sweep`] in kinematics already written ([`Frames::of`]; `dirdyna` shares them with `M`).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body, forward and backward).
pub fn sweep_in(
    model: &Model,
    layout: &Layout,
    b: &mut Builder,
    frames: &Frames,
    drive: &Drive,
) -> Result<Vec<(usize, Term)>, Stopped> {
    let robot = &model.robot;
    let Frames { order, parent, moves, chains, rw, z, r: t, o, .. } = frames;
    let nb = order.len();
    let zero3 = || [ZERO, ZERO, ZERO];
    // Per body (index 0: the base), in the world frame: ω, ω̇, the origin's acceleration minus
    // gravity, U = [ω̇]× + [ω]×².
    let mut om: Vec<V3> = vec![zero3(); nb + 1];
    let mut omp: Vec<V3> = vec![zero3(); nb + 1];
    let mut alpha: Vec<V3> = vec![zero3(); nb + 1];
    let mut u: Vec<M3> = vec![Default::default(); nb + 1];
    alpha[0] = drive.g.clone().map(neg);
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
    for chain in chains {
        let p = parent[chain[0]];
        let late = p != 0;
        let mut w_terms = Vec::with_capacity(chain.len());
        for &body in chain {
            b.check(body, nb)?;
            let i = body - 1;
            let (qd, _) = rates(i);
            w_terms.push(match robot.joints[order[i]].kind {
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
        for (&body, a) in chain.iter().zip(alphas) {
            alpha[body] = a;
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
                torque.push((qi, sub(vdot(&z[body], &ms[body]), vdot(&frames.zo[body], &fs[body]))));
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
