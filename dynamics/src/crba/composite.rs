//! Composite rigid bodies (mass, first moment, rotational inertia about the frame origin) and
//! their moves into the parent's frame, with the turn about a coordinate axis written by
//! `c² + s² = 1` (see the parent module's doc).

use crate::rnea::{bind3, matvec, vadd, M3, V3};
use crate::sym::{add, mul, neg, sub, sum, Builder, Term, ZERO};

/// The upper triangle of a symmetric 3×3 matrix, row by row.
const UPPER: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// A composite rigid body in one frame: mass, first moment and rotational inertia about the
/// frame origin (see the module doc).
#[derive(Clone, Default)]
pub(super) struct Composite {
    pub(super) m: Term,
    pub(super) h: V3,
    pub(super) j: M3,
}

impl Composite {
    pub(super) fn zero() -> Composite {
        Composite { m: ZERO, h: [ZERO, ZERO, ZERO], j: Default::default() }
    }

    /// One body: mass `m`, centre of mass `l`, inertia `inn` about the centre of mass:
    /// `(m, m l, In + m (|l|² I − l lᵀ))`.
    pub(super) fn body(m: Term, l: V3, inn: M3) -> Composite {
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

    /// `self + o`, taking both: no copy of `self`, which as a link's composite grows by one
    /// child at a time (a copy per child would cost the square of its children).
    pub(super) fn add(self, o: Composite) -> Composite {
        let Composite { m, h, j } = self;
        let [h0, h1, h2] = h;
        let [o0, o1, o2] = o.h;
        let mut j = j;
        for (row, orow) in j.iter_mut().zip(o.j) {
            for (x, y) in row.iter_mut().zip(orow) {
                *x = add(std::mem::take(x), y);
            }
        }
        Composite { m: add(m, o.m), h: [add(h0, o0), add(h1, o1), add(h2, o2)], j }
    }

    /// Rotated by `r` (child → parent), then shifted by `t` (the child origin in the parent).
    /// A rotation about a coordinate axis ([`axis_turn`]) turns `J` by [`turned`], its
    /// temporaries named after `tag` (`"2"` for body 2's joint, `"O2"` for its origin).
    pub(super) fn moved(&self, b: &mut Builder, tag: &str, r: Option<&M3>, t: Option<&V3>) -> Composite {
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

    /// Every entry bound as a temporary: `MC{body}`, `HC{k}{body}`, `JC{r}{c}{body}` (`body`
    /// is any tag: `12`, or `12_3` for the third partial sum of body 12's children).
    pub(super) fn bind(&self, b: &mut Builder, body: impl std::fmt::Display) -> Composite {
        let m = b.bind(&format!("MC{body}"), self.m.clone());
        let h = bind3(b, "HC", &body, self.h.clone());
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
