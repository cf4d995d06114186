//! Forward dynamics by the articulated-body algorithm (ABA; Featherstone, *Rigid Body Dynamics
//! Algorithms*, 2008, §7.3, Table 7.1), in the body frames and with the classical
//! accelerations of [`super::rnea`]: one of the two formulations of `fordyna`
//! ([`super::fordyna`] measures both and keeps the one with fewer ops).
//!
//! # Quantities (body `b`'s frame, about its origin)
//! - accelerations `A = (OMp, ALPHA)`: angular acceleration and the classical acceleration of
//!   the origin minus gravity (the base starts at `(0, −g)`, as in the RNEA);
//! - forces `F = (C, F)`: moment about the origin, force;
//! - a rigid body: `F = I A + p` with `I = [[J, H], [Hᵀ, M]]`, `J = In − m[l]×²`, `H = m[l]×`,
//!   `M = m·1`, and the velocity terms `p = (OM × In·OM + l × f, f)`, `f = m OM × (OM × l)`
//!   (the RNEA's `Cs`, `Fs` split into their parts linear in `A` and the rest);
//! - a joint maps the parent's accelerations to the child's by `A_b = X A_p + c_b + S qdd`:
//!   `X (w, a) = (Pᵀ w, Pᵀ (a − d × w))` with `P = ro·R_axis(q)` (child → parent rotation) and
//!   `d` the child origin in the parent frame (`dpt`, plus `ro·axis·q` for a prismatic joint),
//!   `S = (axis, 0)` (revolute) or `(0, axis)` (prismatic), `c_b` the velocity terms of the
//!   RNEA's forward recursion; forces go back by `Xᵀ (n, f) = (P n + d × P f, P f)`.
//!
//! # The algorithm
//! 1. Root to leaves: `OM` and `c_b`; each body's `I` and `p`.
//! 2. Leaves to root: `U = I^A S`, `D = Sᵀ U`, `u = Qq − Sᵀ p^A`; the parent gets
//!    `Xᵀ (I^A − U Uᵀ / D) X` and `Xᵀ (p^A + I^a c + U u / D)` (a fixed joint passes `I^A`,
//!    `p^A + I^A c` unprojected).
//! 3. Root to leaves: `A' = X A_p + c`, `qdd = (u − Uᵀ A') / D`, `A = A' + S qdd`.
//!
//! `Xᵀ I X` is formed in blocks: `J' = P J Pᵀ`, `H' = P H Pᵀ`, `M' = P M Pᵀ`, then
//! `M_p = M'`, `H_p = H' + [d]× M'`, `J_p = J' − H'[d]× + [d]× H'ᵀ − [d]× M' [d]×` (only the upper
//! triangles of the symmetric `J`, `M` are formed).

use super::rnea::{cross, matvec, motions, numeric, vadd, Drive, Motion, M3, SUM_CHUNK, V3};
use super::sym::{add, mul, neg, reciprocal, sub, sum, Builder, Term, ZERO};
use super::{robot::JointKind, Layout, Model, Stopped};

fn vsub(a: &V3, b: &V3) -> V3 {
    [0, 1, 2].map(|i| sub(a[i].clone(), b[i].clone()))
}

fn vscale(a: &V3, s: &Term) -> V3 {
    [0, 1, 2].map(|i| mul(a[i].clone(), s.clone()))
}

fn vdot(a: &V3, b: &V3) -> Term {
    sum((0..3).map(|i| mul(a[i].clone(), b[i].clone())))
}

/// `[v]×`.
fn skew(v: &V3) -> M3 {
    [
        [ZERO, neg(v[2].clone()), v[1].clone()],
        [v[2].clone(), ZERO, neg(v[0].clone())],
        [neg(v[1].clone()), v[0].clone(), ZERO],
    ]
}

/// The entries below the diagonal.
const LOWER: [(usize, usize); 3] = [(1, 0), (2, 0), (2, 1)];

/// The 3 × 3 matrix of `f(r, c)`; with `upper`, `f` is called for `r ≤ c` only and the lower
/// entries mirror the upper ones (the matrix is known to be symmetric).
fn matrix(upper: bool, f: impl Fn(usize, usize) -> Term) -> M3 {
    let mut out: M3 = std::array::from_fn(|r| std::array::from_fn(|c| if upper && c < r { ZERO } else { f(r, c) }));
    if upper {
        for (r, c) in LOWER {
            out[r][c] = out[c][r].clone();
        }
    }
    out
}

/// `a·b` (or `a·bᵀ` when `b_transposed`); `upper`: the product is symmetric ([`matrix`]).
fn mm(a: &M3, b: &M3, b_transposed: bool, upper: bool) -> M3 {
    let e = |k: usize, c: usize| if b_transposed { b[c][k].clone() } else { b[k][c].clone() };
    matrix(upper, |r, c| sum((0..3).map(|k| mul(a[r][k].clone(), e(k, c)))))
}

fn madd(a: &M3, b: &M3, upper: bool) -> M3 {
    matrix(upper, |r, c| add(a[r][c].clone(), b[r][c].clone()))
}

/// A spatial inertia `[[J, H], [Hᵀ, M]]` acting on `(OMp, ALPHA)`; `J`, `M` symmetric.
#[derive(Clone, Default)]
struct Inertia {
    j: M3,
    h: M3,
    m: M3,
}

impl Inertia {
    /// `I·(w, a) = (J w + H a, Hᵀ w + M a)`.
    fn apply(&self, w: &V3, a: &V3) -> (V3, V3) {
        (
            vadd(&matvec(&self.j, w, false), &matvec(&self.h, a, false)),
            vadd(&matvec(&self.h, w, true), &matvec(&self.m, a, false)),
        )
    }

    fn add(&self, o: &Inertia) -> Inertia {
        Inertia { j: madd(&self.j, &o.j, true), h: madd(&self.h, &o.h, false), m: madd(&self.m, &o.m, true) }
    }

    /// `I − (uw, ua)(uw, ua)ᵀ·s`.
    fn minus_outer(&self, uw: &V3, ua: &V3, s: &Term) -> Inertia {
        let outer = |x: &V3, y: &V3, upper: bool| {
            let mut o: M3 = Default::default();
            for r in 0..3 {
                for c in 0..3 {
                    o[r][c] =
                        if upper && c < r { o[c][r].clone() } else { mul(mul(x[r].clone(), y[c].clone()), s.clone()) };
                }
            }
            o
        };
        let sub_m = |a: &M3, b: &M3, upper: bool| {
            let mut o: M3 = Default::default();
            for r in 0..3 {
                for c in 0..3 {
                    o[r][c] = if upper && c < r { o[c][r].clone() } else { sub(a[r][c].clone(), b[r][c].clone()) };
                }
            }
            o
        };
        Inertia {
            j: sub_m(&self.j, &outer(uw, uw, true), true),
            h: sub_m(&self.h, &outer(uw, ua, false), false),
            m: sub_m(&self.m, &outer(ua, ua, true), true),
        }
    }

    /// `Xᵀ I X` for the joint of rotation `p` (child → parent) and offset `d` (module doc).
    fn to_parent(&self, p: &M3, d: &V3) -> Inertia {
        let rot = |x: &M3, sym: bool| mm(&mm(p, x, false, false), p, true, sym);
        let (j1, h1, m1) = (rot(&self.j, true), rot(&self.h, false), rot(&self.m, true));
        let dx = skew(d);
        let dm = mm(&dx, &m1, false, false);
        let h = madd(&h1, &dm, false);
        // J' − H'[d]× + [d]× H'ᵀ − [d]× M' [d]×: the middle two are X + Xᵀ with X = [d]× H'ᵀ.
        let x = mm(&dx, &h1, true, false);
        let dmd = mm(&dm, &dx, false, true);
        let j =
            matrix(true, |r, c| sub(add(j1[r][c].clone(), add(x[r][c].clone(), x[c][r].clone())), dmd[r][c].clone()));
        Inertia { j, h, m: m1 }
    }

    /// Every entry bound (`J`, `M` upper triangles) as `{name}{block}{r}{c}_{body}`.
    fn bind(self, b: &mut Builder, name: &str, body: impl std::fmt::Display) -> Inertia {
        let mut bind_m = |m: M3, block: &str, sym: bool| {
            let mut o: M3 = Default::default();
            for (r, row) in m.into_iter().enumerate() {
                for (c, t) in row.into_iter().enumerate() {
                    if !(sym && c < r) {
                        o[r][c] = b.bind(&format!("{name}{block}{}{}_{body}", r + 1, c + 1), t);
                    }
                }
            }
            if sym {
                for (r, c) in LOWER {
                    o[r][c] = o[c][r].clone();
                }
            }
            o
        };
        let j = bind_m(self.j, "J", true);
        let h = bind_m(self.h, "H", false);
        let m = bind_m(self.m, "M", true);
        Inertia { j, h, m }
    }
}

fn bind3(b: &mut Builder, name: &str, body: usize, v: V3) -> V3 {
    super::rnea::bind3(b, name, format_args!("_{body}"), v)
}

/// What the joint of a body is for the algorithm.
struct Link {
    /// Child → parent rotation `P`.
    p: M3,
    /// Child origin in the parent frame.
    d: V3,
    /// Motion subspace `(angular, linear)`; `None` for a fixed joint.
    s: Option<(V3, V3)>,
    /// The joint's coordinate.
    qi: Option<usize>,
    /// A free flyer (six coordinates from `qi`, `S` the identity; `s` is `None`).
    free: bool,
}

/// `x` with `A x = r` for a symmetric positive-definite 6 × 6 `A` (only `a[i][j]`, `i ≤ j`, is
/// read) by `LDLᵀ` and the two substitutions: `n³/6` multiply–adds, one reciprocal per pivot,
/// 6 of them. Temporaries `{name}L{i}_{j}`, `{name}D{i}`, `{name}Y{i}` (1-based). Row `i` is
/// velocity coordinate `first + i` (what a zero pivot is reported against, [`reciprocal`]).
fn solve6(b: &mut Builder, name: &str, first: usize, a: &[[Term; 6]; 6], r: [Term; 6]) -> [Term; 6] {
    // l[i][j] (j < i) of the unit lower L, and D.
    let mut l: [[Term; 6]; 6] = Default::default();
    let mut inv_d: [Term; 6] = Default::default();
    let mut dl: [[Term; 6]; 6] = Default::default(); // L[i][k]·D[k], k < i
    for i in 0..6 {
        for j in 0..i {
            // (A[j][i] − Σ_{k<j} L[i][k]·D[k]·L[j][k]) / D[j].
            let t = (0..j).fold(a[j][i].clone(), |t, k| sub(t, mul(dl[i][k].clone(), l[j][k].clone())));
            dl[i][j] = b.bind(&format!("{name}E{}_{}", i + 1, j + 1), t);
            l[i][j] = b.bind(&format!("{name}L{}_{}", i + 1, j + 1), mul(dl[i][j].clone(), inv_d[j].clone()));
        }
        let d = (0..i).fold(a[i][i].clone(), |t, k| sub(t, mul(dl[i][k].clone(), l[i][k].clone())));
        inv_d[i] = reciprocal(b, first + i, &format!("{name}D{}", i + 1), &format!("i{name}D{}", i + 1), d);
    }
    // L y = r, then Lᵀ x = D⁻¹ y.
    let mut y: [Term; 6] = Default::default();
    for i in 0..6 {
        let t = (0..i).fold(r[i].clone(), |t, k| sub(t, mul(l[i][k].clone(), y[k].clone())));
        y[i] = b.bind(&format!("{name}Y{}", i + 1), t);
    }
    let mut x: [Term; 6] = Default::default();
    for i in (0..6).rev() {
        let t = (i + 1..6).fold(mul(y[i].clone(), inv_d[i].clone()), |t, k| sub(t, mul(l[k][i].clone(), x[k].clone())));
        x[i] = b.bind(&format!("{name}X{}", i + 1), t);
    }
    x
}

/// Writes `fordyna` by the ABA into `b` (outputs `qdd[1..nq]`).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body of each of the three passes).
pub fn fordyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let robot = &model.robot;
    let nq = layout.nv;
    let drive = Drive::inputs(b, nq, false);
    let forces: Vec<Term> = (1..=nq).map(|i| b.input(&format!("Qq[{i}]"))).collect();
    let motions: Vec<Motion> = motions(model, layout, b);
    let order = robot.dfs_joints();
    let nb = order.len();
    let parent = robot.body_parents(&order);
    let moves = layout.moving_bodies(&parent);

    // Pass 1: joints, velocities and velocity terms, rigid inertias.
    let zero3 = || [ZERO, ZERO, ZERO];
    let mut om: Vec<V3> = vec![zero3(); nb + 1];
    let mut bias: Vec<(V3, V3)> = vec![(zero3(), zero3()); nb + 1];
    let mut links: Vec<Option<Link>> = (0..=nb).map(|_| None).collect();
    let mut ia: Vec<Inertia> = vec![Inertia::default(); nb + 1];
    let mut pa: Vec<(V3, V3)> = vec![(zero3(), zero3()); nb + 1];
    // Every body gets its joint (a body fixed to the base still turns gravity into its frame for
    // the moving bodies below it); what nothing reads is dropped by `Builder::finish`.
    for (i, &j) in order.iter().enumerate() {
        let body = i + 1;
        b.check(body, nb)?;
        let joint = &robot.joints[j];
        let p = parent[body];
        let ro = numeric(&joint.origin.rot);
        let d0: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
        let qd = layout.v_index[i].map_or(ZERO, |qi| drive.qd[qi - 1].clone());
        // The parent's `OM × (OM × d)` in the joint frame, then the joint's own terms.
        let om_j = matvec(&ro, &om[p], true);
        let centripetal = matvec(&ro, &cross(&om[p], &cross(&om[p], &d0)), true);
        let m = &motions[body];
        let (link, om_b, c) = match (joint.kind, &m.rot, &m.shift, layout.v_index[i]) {
            (JointKind::Revolute, Some(r), _, Some(qi)) => {
                let om_r = matvec(r, &om_j, true);
                let axis = joint.axis.map(Term::C);
                let sq = vscale(&axis, &qd);
                let c = (cross(&om_r, &sq), matvec(r, &centripetal, true));
                let link =
                    Link { p: mm(&ro, r, false, false), d: d0, s: Some((axis, zero3())), qi: Some(qi), free: false };
                (link, vadd(&om_r, &sq), c)
            }
            (JointKind::Prismatic, _, Some(shift), Some(qi)) => {
                let axis = joint.axis.map(Term::C);
                let sq = vscale(&axis, &qd);
                let cor = cross(&om_j, &sq);
                let lin = vadd(&vadd(&centripetal, &cross(&om_j, &cross(&om_j, shift))), &vadd(&cor, &cor));
                let d = vadd(&d0, &matvec(&ro, shift, false));
                let link = Link { p: ro, d, s: Some((zero3(), axis)), qi: Some(qi), free: false };
                (link, om_j, (zero3(), lin))
            }
            (JointKind::FreeFlyer, _, _, Some(qi)) => {
                // From the fixed world (`om_j`, `centripetal` are 0): the base's angular velocity
                // `w` and the `w × v` of its classical acceleration (see `crate::rnea`).
                let r = m.free.clone().expect("a free flyer's motion");
                let at = |k: usize| drive.qd[qi - 1 + k].clone();
                let (v, w) = ([0, 1, 2].map(at), [3, 4, 5].map(at));
                let c = (zero3(), vadd(&matvec(&r, &centripetal, true), &cross(&w, &v)));
                let link = Link { p: r.clone(), d: d0, s: None, qi: Some(qi), free: true };
                (link, vadd(&matvec(&r, &om_j, true), &w), c)
            }
            _ => (Link { p: ro, d: d0, s: None, qi: None, free: false }, om_j, (zero3(), centripetal)),
        };
        om[body] = bind3(b, "AOM", body, om_b);
        bias[body] = (bind3(b, "CW", body, c.0), bind3(b, "CA", body, c.1));
        links[body] = Some(link);
        // The rigid body.
        let mass = layout.param(b, &format!("m[{body}]"));
        let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
        let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
        let lx = skew(&l);
        let ml = vscale(&l, &mass);
        let h = skew(&ml);
        let j_o = madd(&inn, &mm(&lx, &h, false, true).map(|row| row.map(neg)), true);
        let mut m3: M3 = Default::default();
        for (k, row) in m3.iter_mut().enumerate() {
            row[k] = mass.clone();
        }
        let w = &om[body];
        let f = vscale(&cross(w, &cross(w, &l)), &mass);
        let n = vadd(&cross(w, &matvec(&inn, w, false)), &cross(&l, &f));
        ia[body] = ia[body].add(&Inertia { j: j_o, h, m: m3 });
        pa[body] = (vadd(&pa[body].0, &n), vadd(&pa[body].1, &f));
    }

    // Pass 2: articulated inertias, leaves to root.
    let mut u_of: Vec<Option<(V3, V3, Term, Term)>> = (0..=nb).map(|_| None).collect();
    let mut free_root: Option<(Inertia, V3, V3)> = None;
    let mut children = vec![0usize; nb + 1];
    for body in (1..=nb).rev() {
        if !moves[body] {
            continue;
        }
        b.check(body, nb)?;
        let link = links[body].as_ref().expect("every body has its link");
        let inertia = std::mem::take(&mut ia[body]).bind(b, "IA", body);
        let (pn, pf) = std::mem::take(&mut pa[body]);
        let (pn, pf) = (bind3(b, "PAN", body, pn), bind3(b, "PAF", body, pf));
        if link.free {
            // The root's articulated inertia and bias force, solved in pass 3 (the world above
            // does not move).
            free_root = Some((inertia, pn, pf));
            continue;
        }
        let (ia_a, pa_a) = match (&link.s, link.qi) {
            (Some((sw, sa)), Some(qi)) => {
                let (uw, ua) = inertia.apply(sw, sa);
                let (uw, ua) = (bind3(b, "UW", body, uw), bind3(b, "UA", body, ua));
                let d = add(vdot(sw, &uw), vdot(sa, &ua));
                let inv = reciprocal(b, qi, &format!("AD{body}"), &format!("iAD{body}"), d);
                let u = sub(forces[qi - 1].clone(), add(vdot(sw, &pn), vdot(sa, &pf)));
                let u = b.bind(&format!("AU{body}"), u);
                let ia_a = inertia.minus_outer(&uw, &ua, &inv);
                let uu = b.bind(&format!("AUD{body}"), mul(u.clone(), inv.clone()));
                u_of[body] = Some((uw.clone(), ua.clone(), u, inv));
                let (cw, ca) = &bias[body];
                let (icw, ica) = ia_a.apply(cw, ca);
                let pa_a = (vadd(&vadd(&pn, &icw), &vscale(&uw, &uu)), vadd(&vadd(&pf, &ica), &vscale(&ua, &uu)));
                (ia_a, pa_a)
            }
            _ => {
                let (cw, ca) = &bias[body];
                let (icw, ica) = inertia.apply(cw, ca);
                let pa_a = (vadd(&pn, &icw), vadd(&pf, &ica));
                (inertia, pa_a)
            }
        };
        let p = parent[body];
        if !moves[p] {
            continue;
        }
        let ia_p = ia_a.to_parent(&link.p, &link.d);
        let f_p = matvec(&link.p, &pa_a.1, false);
        let n_p = vadd(&matvec(&link.p, &pa_a.0, false), &cross(&link.d, &f_p));
        ia[p] = ia[p].add(&ia_p);
        pa[p] = (vadd(&pa[p].0, &n_p), vadd(&pa[p].1, &f_p));
        children[p] += 1;
        if children[p].is_multiple_of(SUM_CHUNK) {
            let k = children[p] / SUM_CHUNK;
            ia[p] = std::mem::take(&mut ia[p]).bind(b, &format!("IS{k}_"), p);
            let (n, f) = std::mem::take(&mut pa[p]);
            pa[p] = (bind3(b, &format!("PSN{k}_"), p, n), bind3(b, &format!("PSF{k}_"), p, f));
        }
    }

    // Pass 3: accelerations, root to leaves.
    let mut acc: Vec<(V3, V3)> = vec![(zero3(), drive.g.clone().map(neg)); nb + 1];
    let mut qdd: Vec<Term> = vec![ZERO; nq];
    for body in 1..=nb {
        b.check(body, nb)?;
        let link = links[body].as_ref().expect("every body has its link");
        let (wp, ap) = &acc[parent[body]];
        let w = vadd(&matvec(&link.p, wp, true), &bias[body].0);
        let a = vadd(&matvec(&link.p, &vsub(ap, &cross(&link.d, wp)), true), &bias[body].1);
        let (w, a) = (bind3(b, "AW", body, w), bind3(b, "AA", body, a));
        if let (true, Some(qi), Some((ia, pn, pf))) = (link.free, link.qi, free_root.take()) {
            // `I (A' + qdd) + p = τ` for the base's (linear, angular) `qdd`: the 6 × 6 system
            // `[[M, Hᵀ], [H, J]] (a, w) = τ − p − I A'`.
            let (iw, ia_) = ia.apply(&w, &a);
            let rhs: [Term; 6] = std::array::from_fn(|k| {
                let (p, i) = if k < 3 { (&pf[k], &ia_[k]) } else { (&pn[k - 3], &iw[k - 3]) };
                sub(forces[qi - 1 + k].clone(), add(p.clone(), i.clone()))
            });
            let e = |r: usize, c: usize| match (r < 3, c < 3) {
                (true, true) => ia.m[r][c].clone(),
                (true, false) => ia.h[c - 3][r].clone(),
                (false, true) => ia.h[r - 3][c].clone(),
                (false, false) => ia.j[r - 3][c - 3].clone(),
            };
            let x = solve6(b, "FB", qi, &std::array::from_fn(|r| std::array::from_fn(|c| e(r, c))), rhs);
            for (k, t) in x.iter().enumerate() {
                qdd[qi - 1 + k] = b.bind(&format!("QDD{}", qi + k), t.clone());
            }
            let (lin, ang): (V3, V3) =
                ([0, 1, 2].map(|k| qdd[qi - 1 + k].clone()), [3, 4, 5].map(|k| qdd[qi - 1 + k].clone()));
            acc[body] = (vadd(&w, &ang), vadd(&a, &lin));
            continue;
        }
        acc[body] = match (&link.s, &u_of[body], link.qi) {
            (Some((sw, sa)), Some((uw, ua, u, inv)), Some(qi)) => {
                let x = mul(sub(u.clone(), add(vdot(uw, &w), vdot(ua, &a))), inv.clone());
                let x = b.bind(&format!("QDD{qi}"), x);
                qdd[qi - 1] = x.clone();
                (vadd(&w, &vscale(sw, &x)), vadd(&a, &vscale(sa, &x)))
            }
            _ => (w, a),
        };
    }
    for (i, t) in qdd.into_iter().enumerate() {
        b.output(&format!("qdd[{}]", i + 1), &format!("qdd{}", i + 1), t);
    }
    Ok(())
}
