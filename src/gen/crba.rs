//! The joint-space mass matrix `M(q)` by the composite-rigid-body algorithm (CRBA; Walker &
//! Orin 1982, method 3; Featherstone, *Rigid Body Dynamics Algorithms*, 2008, §6.2), in body
//! frames with Robotran's parameters and the same frames, numbering and joint motions as the
//! RNEA of [`super::rnea`].
//!
//! # The recursion
//! A composite body is `(m, h, J)`: mass, first moment `h = Σ mₖ rₖ` and rotational inertia
//! `J = −Σ mₖ [rₖ]×²` about the frame origin. Body `b` alone is `(m_b, m_b l_b,
//! In_b − m_b [l_b]×²)`. Leaves to root, each composite is moved into its parent's frame by
//! `x_parent = t + R x_child` and added there:
//! `m' = m`, `h' = R h + m t`, `J' = R J Rᵀ + m (|t|² I − t tᵀ) + 2 (t·u) I − u tᵀ − t uᵀ`
//! with `u = R h` (the parallel-axis theorem for a rotated, shifted body; symmetric, so only
//! the upper triangle is formed). The joint motion (`R = R_axis(q)`, or a shift `axis·q`) and
//! the constant joint origin (`dpt`, URDF `rpy`) are applied as two such moves.
//!
//! Column `j` of `M`: the spatial force that the composite below joint `j` needs for a unit
//! joint acceleration, `n = J a`, `f = a × h` (revolute axis `a`) or `n = h × a`, `f = m a`
//! (prismatic), gives `M[j][j] = a·n` (or `a·f`); carried up the path to the root (`f ← R f`,
//! `n ← R n + t × (R f)`), it gives `M[i][j]` for every ancestor joint `i`. Only the upper
//! triangle `i ≤ j` is written (joints are numbered depth first, so an ancestor has the smaller
//! index).
//!
//! # Turns about the joint axis
//! A revolute joint about `±x`, `±y` or `±z` turns the composite's `J` in one coordinate plane.
//! `Composite::moved` writes those three entries with `c² + s² = 1` (`turned`: `J'pp = Jpp − B`,
//! `J'qq = Jqq + B`, `J'pq = Jpq + s·c·d − 2Jpq·s²`, `d = Jpp − Jqq`, `B = d·s² + 2Jpq·s·c`)
//! instead of the rows-times-columns product `R J Rᵀ`; a constant rotation about one axis (a
//! URDF `rpy` about one axis, not a quarter turn) takes the same path with numbers for `c`,
//! `s`. Upper triangle of `M`, `--fold-params`, after `atomise,cse`: serial30 7 805 → 7 639
//! ops, UR5 175 → 153, Panda (9 coordinates) 547 → 515, Solo-12 984 → 906, Talos 4 235 →
//! 3 993, TIAGo Pro 8 466 → 8 271.
//!
//! # Constant rotations
//! A joint whose URDF `rpy` is neither a quarter turn nor about one axis has a dense constant
//! rotation `ro` (TIAGo Pro's and UR5's arms). Where it saves ops (`merged_rotation`), the
//! CRBA moves composites and column forces across such a joint by one rotation
//! `P = ro·R_axis(q)`, bound once per joint as `RP{r}{c}{body}`, instead of `R_axis(q)` then
//! `ro`: 15 ops per vector instead of up to 6 + 15. `M` of TIAGo Pro (floating base, 39
//! coordinates, `--fold-params`, after `atomise,cse`): 11 195 → 10 428 ops; UR5: 303 → 228
//! (measured when introduced, before the slid origins, `sym`'s gathered constants and the
//! turns above). The composite still crosses such a joint by `P` (turning it about the joint
//! axis, then by `ro`, cost more on UR5's `M`: 153 → 185 ops).
//!
//! # Robotran's floating base
//! The joints `T1 T2 T3 R1 R2 R3` have no offset and no constant rotation, so their axes meet
//! at the base's origin: a column force that reaches the base (or any body of that root
//! segment) gives all six entries by projection on the axes expressed in the base frame
//! (`WM`, formed once per body), `projection`, instead of being carried through five more
//! frames. `M` of TIAGo Pro: 10 032 → 9 908 ops; Talos 4 971 → 4 856; Solo-12 1 230 → 1 192
//! (measured when introduced).
//!
//! # Why CRBA
//! The unit-acceleration RNEA (Walker & Orin's method 1) re-runs the forward and backward
//! recursion of joint `j`'s whole subtree for every column; CRBA forms each subtree's inertia
//! once and then only carries one force per column to the root. Counts in the
//! [`super::dirdyna`] module doc.

use super::rnea::{bind3, cross, dot, matvec, numeric, vadd, Motion, M3, V3};
use super::robot::JointKind;
use super::sym::{add, mul, neg, sub, sum, Builder, Term, ZERO};
use rustc_hash::FxHashMap;

use super::{Layout, Model};

/// The upper triangle of a symmetric 3×3 matrix, row by row.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// A composite rigid body in one frame: mass, first moment and rotational inertia about the
/// frame origin (see the module doc).
#[derive(Clone)]
struct Composite {
    m: Term,
    h: V3,
    j: M3,
}

impl Composite {
    fn zero() -> Composite {
        Composite { m: ZERO, h: [ZERO, ZERO, ZERO], j: Default::default() }
    }

    /// One body: mass `m`, centre of mass `l`, inertia `inn` about the centre of mass:
    /// `(m, m l, In + m (|l|² I − l lᵀ))`.
    fn body(m: Term, l: V3, inn: M3) -> Composite {
        let mut j: M3 = Default::default();
        for a in 0..3 {
            for c in a..3 {
                let shift = if a == c {
                    let (x, y) = ((a + 1) % 3, (a + 2) % 3);
                    mul(m.clone(), add(mul(l[x].clone(), l[x].clone()), mul(l[y].clone(), l[y].clone())))
                } else {
                    neg(mul(m.clone(), mul(l[a].clone(), l[c].clone())))
                };
                j[a][c] = add(inn[a][c].clone(), shift);
                j[c][a] = j[a][c].clone();
            }
        }
        Composite { h: l.map(|x| mul(m.clone(), x)), m, j }
    }

    fn add(&self, o: &Composite) -> Composite {
        let j: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| add(self.j[r][c].clone(), o.j[r][c].clone())));
        Composite { m: add(self.m.clone(), o.m.clone()), h: vadd(&self.h, &o.h), j }
    }

    /// Rotated by `r` (child → parent), then shifted by `t` (the child origin in the parent).
    /// A rotation about a coordinate axis ([`axis_turn`]) turns `J` by [`turned`], its
    /// temporaries named after `tag` (`"2"` for body 2's joint, `"O2"` for its origin).
    fn moved(&self, b: &mut Builder, tag: &str, r: Option<&M3>, t: Option<&V3>) -> Composite {
        let (h, j) = match (r, r.and_then(axis_turn)) {
            (Some(r), Some(turn)) => (matvec(r, &self.h, false), turned(b, tag, &self.j, &turn)),
            (Some(r), None) => {
                let rj: M3 = [0, 1, 2]
                    .map(|i| [0, 1, 2].map(|k| sum((0..3).map(|l| mul(r[i][l].clone(), self.j[l][k].clone())))));
                // Upper triangle of (R J) Rᵀ, mirrored.
                let mut j: M3 = Default::default();
                for a in 0..3 {
                    for c in a..3 {
                        j[a][c] = sum((0..3).map(|k| mul(rj[a][k].clone(), r[c][k].clone())));
                        j[c][a] = j[a][c].clone();
                    }
                }
                (matvec(r, &self.h, false), j)
            }
            (None, _) => (self.h.clone(), self.j.clone()),
        };
        let Some(t) = t else {
            return Composite { m: self.m.clone(), h, j };
        };
        // m (|t|² I − t tᵀ) + 2 (t·u) I − u tᵀ − t uᵀ, with u = R h.
        let tt = |a: usize, c: usize| mul(t[a].clone(), t[c].clone());
        let tu = |a: usize, c: usize| add(mul(h[a].clone(), t[c].clone()), mul(t[a].clone(), h[c].clone()));
        let mut out: M3 = Default::default();
        for a in 0..3 {
            for c in a..3 {
                let shift = if a == c {
                    let (x, y) = ((a + 1) % 3, (a + 2) % 3);
                    // m (t_x² + t_y²) + 2 (t_x u_x + t_y u_y): the other two axes.
                    add(mul(self.m.clone(), add(tt(x, x), tt(y, y))), add(tu(x, x), tu(y, y)))
                } else {
                    neg(add(mul(self.m.clone(), tt(a, c)), tu(a, c)))
                };
                out[a][c] = add(j[a][c].clone(), shift);
                out[c][a] = out[a][c].clone();
            }
        }
        let h = vadd(&h, &t.clone().map(|x| mul(self.m.clone(), x)));
        Composite { m: self.m.clone(), h, j: out }
    }

    fn bind(&self, b: &mut Builder, body: usize) -> Composite {
        let m = b.bind(&format!("MC{body}"), self.m.clone());
        let h = bind3(b, "HC", body, self.h.clone());
        let mut j: M3 = Default::default();
        for (a, c) in UPPER {
            j[a][c] = b.bind(&format!("JC{}{}{body}", a + 1, c + 1), self.j[a][c].clone());
            j[c][a] = j[a][c].clone();
        }
        Composite { m, h, j }
    }
}

/// A rotation about the coordinate axis `k`: in the rows and columns `p = k + 1`,
/// `q = k + 2` (mod 3) it is `[[c, −s], [s, c]]`, elsewhere the identity (`c = cos q`,
/// `s = ± sin q`, the sign that of the axis).
struct Turn {
    k: usize,
    p: usize,
    q: usize,
    c: Term,
    s: Term,
}

/// `r` as a [`Turn`], when it is one (a revolute joint about `±x`, `±y` or `±z`, as
/// `rnea::axis_rotation` writes it).
fn axis_turn(r: &M3) -> Option<Turn> {
    let one = Term::C(1.0);
    let k = (0..3).find(|&k| r[k][k] == one && (0..3).all(|i| i == k || (r[k][i] == ZERO && r[i][k] == ZERO)))?;
    let (p, q) = ((k + 1) % 3, (k + 2) % 3);
    let (c, s) = (r[p][p].clone(), r[q][p].clone());
    // A quarter or half turn (a signed permutation) is free to apply entry by entry.
    let quarter = c == ZERO || s == ZERO;
    (!quarter && r[q][q] == c && r[p][q] == neg(s.clone())).then_some(Turn { k, p, q, c, s })
}

/// `R J Rᵀ` for a [`Turn`] `R` and a symmetric `J`, with `c² + s² = 1` used to share the work
/// of the three entries in the plane of the turn:
/// `J'pp = Jpp − B`, `J'qq = Jqq + B`, `J'pq = Jpq + s·c·d − 2Jpq·s²`, with `d = Jpp − Jqq` and
/// `B = d·s² + 2Jpq·s·c` (expand `c² Jpp − 2cs Jpq + s² Jqq` and replace `c²` by `1 − s²`);
/// `J'pk = c Jpk − s Jqk`, `J'qk = s Jpk + c Jqk`, `J'kk = Jkk`. `s²`, `s·c` (`SS`, `SC`),
/// `d`, `2Jpq` and `B` (`JD`, `JE`, `JB`) are bound once per turn: 13 ops for the plane where
/// the rows-times-columns product costs up to 18 (6 more for `J'pk`, `J'qk` in both), and a
/// numeric `J` (a leaf body, `--fold-params`) folds `d` and `2Jpq` into constants. Named
/// after `tag` (see `Composite::moved`).
fn turned(b: &mut Builder, tag: &str, j: &M3, t: &Turn) -> M3 {
    let Turn { k, p, q, c, s } = t;
    let (k, p, q) = (*k, *p, *q);
    let ss = b.bind(&format!("SS{tag}"), mul(s.clone(), s.clone()));
    let sc = b.bind(&format!("SC{tag}"), mul(s.clone(), c.clone()));
    let d = b.bind(&format!("JD{tag}"), sub(j[p][p].clone(), j[q][q].clone()));
    // With a numeric turn (a constant rotation) the 2 joins the numbers `s·c`, `s²` instead.
    let e = mul(Term::C(2.0), j[p][q].clone());
    let e = if matches!(sc, Term::C(_)) { e } else { b.bind(&format!("JE{tag}"), e) };
    let bb = b.bind(&format!("JB{tag}"), add(mul(d.clone(), ss.clone()), mul(e.clone(), sc.clone())));
    let mut out: M3 = Default::default();
    out[k][k] = j[k][k].clone();
    out[p][p] = sub(j[p][p].clone(), bb.clone());
    out[q][q] = add(j[q][q].clone(), bb);
    out[p][q] = add(j[p][q].clone(), sub(mul(d, sc), mul(e, ss)));
    out[p][k] = sub(mul(c.clone(), j[p][k].clone()), mul(s.clone(), j[q][k].clone()));
    out[q][k] = add(mul(s.clone(), j[p][k].clone()), mul(c.clone(), j[q][k].clone()));
    for (a, c) in [(p, q), (p, k), (q, k)] {
        out[c][a] = out[a][c].clone();
    }
    out
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
fn merged_rotation(b: &mut Builder, body: usize, ro: &M3, joint: Option<&M3>) -> Option<M3> {
    let r = joint?;
    let p: M3 = [0, 1, 2].map(|i| [0, 1, 2].map(|j| sum((0..3).map(|k| mul(ro[i][k].clone(), r[k][j].clone())))));
    if matvec_ops(&p) >= matvec_ops(ro) + matvec_ops(r) {
        return None;
    }
    Some([0, 1, 2].map(|i| [0, 1, 2].map(|j| b.bind(&format!("RP{}{}{body}", i + 1, j + 1), p[i][j].clone()))))
}

/// The entries `(i, t)` of a column whose force `(n, f)` (moment about the origin of body
/// `at`, force, both in its frame) has reached `at` in the root segment: for each moving joint
/// `i` from `at` up to the root, `t = w·n` (revolute) or `w·f` (prismatic), `w` its axis
/// expressed in `at`'s frame (`R_kᵀ` of the joints between; no offsets, so every revolute axis
/// there passes through `at`'s origin). The `w` are bound once per `(at, joint)` as
/// `WM{k}{body}_{at}`. On Robotran's floating base this costs 23 ops per column where
/// carrying the force through T1…R3 costs about 31.
#[allow(clippy::too_many_arguments)]
fn projection(
    b: &mut Builder,
    cache: &mut FxHashMap<(usize, usize), V3>,
    robot: &super::robot::Robot,
    order: &[usize],
    motions: &[Motion],
    parent: &[usize],
    layout: &Layout,
    at: usize,
    n: &V3,
    f: &V3,
) -> Vec<(usize, Term)> {
    let mut path = Vec::new();
    let mut k = at;
    while k != 0 {
        path.push(k);
        k = parent[k];
    }
    let mut out = Vec::new();
    for (idx, &bi) in path.iter().enumerate() {
        let Some(qi) = layout.q_index[bi - 1] else { continue };
        let jo = &robot.joints[order[bi - 1]];
        let w = cache.entry((at, bi)).or_insert_with(|| {
            let mut w: V3 = jo.axis.map(Term::C);
            for &k in path[..idx].iter().rev() {
                if let Some(r) = &motions[k].rot {
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

/// The upper triangle of `M`: `(i, j) → term` for `i ≤ j` (1-based coordinates), entries that
/// fold to 0 left out. Writes the composites and column forces into `b` as temporaries `MC`,
/// `HC`, `JC` (per body) and `FM`, `CM` (per body and column).
pub fn mass_matrix(model: &Model, layout: &Layout, b: &mut Builder, motions: &[Motion]) -> Vec<((usize, usize), Term)> {
    let robot = &model.robot;
    let order = robot.dfs_joints();
    let nb = order.len();
    let mut link_body = vec![0; robot.links.len()];
    for (i, &j) in order.iter().enumerate() {
        link_body[robot.joints[j].child] = i + 1;
    }
    let parent: Vec<usize> =
        std::iter::once(0).chain(order.iter().map(|&j| link_body[robot.joints[j].parent])).collect();
    let mut moves = vec![false; nb + 1];
    for i in 0..nb {
        moves[i + 1] = moves[parent[i + 1]] || layout.q_index[i].is_some();
    }
    // Each body's constant joint rotation (`ro`, index = body), and the constant and joint
    // rotations merged where that is cheaper (see `merged_rotation`).
    let ro: Vec<M3> =
        std::iter::once(M3::default()).chain(order.iter().map(|&j| numeric(&robot.joints[j].origin.rot))).collect();
    let mut merged: Vec<Option<M3>> = vec![None; nb + 1];
    for body in 1..=nb {
        if moves[parent[body]] {
            merged[body] = merged_rotation(b, body, &ro[body], motions[body].rot.as_ref());
        }
    }
    // Each body alone, then leaves to root: the composite of its subtree.
    let mut comp: Vec<Composite> = vec![Composite::zero(); nb + 1];
    for body in (1..=nb).rev() {
        if !moves[body] {
            continue;
        }
        let m = layout.param(b, &format!("m[{body}]"));
        let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
        let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
        let own = Composite::body(m, l, inn);
        let c = own.add(&comp[body]).bind(b, body);
        let p = parent[body];
        if moves[p] {
            let mo = &motions[body];
            let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
            let in_parent = match &merged[body] {
                Some(p) => c.moved(b, &body.to_string(), Some(p), Some(&d)),
                None => {
                    let turned = c.moved(b, &body.to_string(), mo.rot.as_ref(), mo.shift.as_ref());
                    turned.moved(b, &format!("O{body}"), Some(&ro[body]), Some(&d))
                }
            };
            comp[p] = comp[p].add(&in_parent);
        }
        comp[body] = c;
    }
    // The root segment (`Robot::root_segment`, here per body): its joints all act at one point,
    // so a column force that reaches such a body gives every entry above it by projection (see
    // `projection`).
    let segment_of_link = robot.root_segment();
    let in_segment: Vec<bool> =
        std::iter::once(true).chain(order.iter().map(|&j| segment_of_link[robot.joints[j].child])).collect();
    let mut segment_moving = vec![0usize; nb + 1];
    for body in 1..=nb {
        segment_moving[body] = segment_moving[parent[body]] + usize::from(layout.q_index[body - 1].is_some());
    }
    let mut projections: FxHashMap<(usize, usize), V3> = FxHashMap::default();
    let mut upper = Vec::new();
    for (i, &jt) in order.iter().enumerate() {
        let Some(qj) = layout.q_index[i] else { continue };
        let body = i + 1;
        let joint = &robot.joints[jt];
        let a = joint.axis;
        let c = &comp[body];
        let av = a.map(Term::C);
        let (mut n, mut f) = match joint.kind {
            JointKind::Revolute => (matvec(&c.j, &av, false), cross(&av, &c.h)),
            _ => (cross(&c.h, &av), av.clone().map(|x| mul(c.m.clone(), x))),
        };
        let mut at = body;
        loop {
            if in_segment[at] && segment_moving[at] >= 2 {
                for (qi, t) in projection(b, &mut projections, robot, &order, motions, &parent, layout, at, &n, &f) {
                    upper.push(((qi, qj), t));
                }
                break;
            }
            if let Some(qi) = layout.q_index[at - 1] {
                let jo = &robot.joints[order[at - 1]];
                let t = if jo.kind == JointKind::Revolute { dot(&jo.axis, &n) } else { dot(&jo.axis, &f) };
                upper.push(((qi, qj), t));
            }
            let p = parent[at];
            if !moves[p] {
                break;
            }
            // Into the parent's frame: the joint motion, then the joint origin (merged into one
            // rotation where `merged_rotation` chose to).
            let (f1, n1) = match &merged[at] {
                Some(r) => (matvec(r, &f, false), matvec(r, &n, false)),
                None => {
                    let mo = &motions[at];
                    let f1 = rotate(mo.rot.as_ref(), &f);
                    let mut n1 = rotate(mo.rot.as_ref(), &n);
                    if let Some(s) = &mo.shift {
                        n1 = vadd(&n1, &cross(s, &f1));
                    }
                    (matvec(&ro[at], &f1, false), matvec(&ro[at], &n1, false))
                }
            };
            let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{at}]")));
            let f2 = column_bind(b, "FM", p, qj, f1);
            let n2 = vadd(&n1, &cross(&d, &f2));
            n = column_bind(b, "CM", p, qj, n2);
            f = f2;
            at = p;
        }
    }
    upper
}
