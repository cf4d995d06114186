//! Direct dynamics `M(q) qdd + c(q, qd, g) = Qq` of a fixed-base tree, in Robotran's
//! `mbs_dirdyna` layout: outputs `M[i][j]` for every `i, j = 1..nq` row by row (both
//! triangles; the lower entry is a plain copy of the upper one's value, 0 ops, as in the
//! corpus's `M[2][1] = FM31_24;`), then `c[1..nq]`.
//!
//! # Sign convention
//! Robotran's `c` is the inverse dynamics at `qdd = 0` (its corpus files compute `c` with the
//! same recursion as `invdyna`, the accelerations left out), so `M qdd + c = Qq` with `Qq` of
//! `invdyna`; this is Pinocchio's `nonLinearEffects` (Coriolis, centrifugal and gravity).
//!
//! # Formulation: unit-acceleration RNEA (Walker & Orin 1982, method 1)
//! - `c = RNEA(q, qd, qdd = 0, g)`: one sweep of [`super::rnea::sweep`].
//! - Column `j` of `M` is `RNEA(q, qd = 0, qdd = e_j, g = 0)`. With those inputs structural
//!   folding removes every velocity product, the gravity and every body that is not a
//!   descendant of joint `j`, so each column costs only the sweep over `j`'s subtree and the
//!   force path back to the root; only the entries `i ≤ j` are kept (symmetry).
//!
//! Why not CRBA (composite rigid-body inertias, method 3): it needs fewer multiplications on
//! long chains (the composite inertia of a subtree is formed once, not once per column), but
//! it brings a second recursion (rotating 3×3 inertia tensors and shifting them by the
//! parallel-axis theorem) that would have to be verified separately; the unit-acceleration
//! form reuses the RNEA that is already checked against Pinocchio, so `M` and `c` inherit its
//! conventions (frames, numbering, parameters) by construction. CRBA stays a later
//! optimisation; the op counts of this form are in the README ("URDF input").

use super::rnea::{motions, sweep, Drive};
use super::sym::{Builder, Term, ZERO};
use super::{Layout, Model};

/// Writes `dirdyna` (outputs `M[i][j]`, then `c[i]`) into `b`.
pub fn dirdyna(model: &Model, layout: &Layout, b: &mut Builder) {
    let nq = layout.q_index.iter().flatten().count();
    // `c`'s inputs first (gravity, rates), then the trig variables.
    let drive = Drive::inputs(b, nq, false);
    let motions = motions(model, layout, b);
    // Upper triangle, column by column.
    let mut upper: Vec<Vec<Term>> = vec![vec![ZERO; nq]; nq];
    for j in 0..nq {
        let unit = Drive {
            qd: vec![ZERO; nq],
            qdd: (0..nq).map(|k| Term::C(if k == j { 1.0 } else { 0.0 })).collect(),
            g: [ZERO, ZERO, ZERO],
        };
        for (qi, t) in sweep(model, layout, b, &motions, &unit) {
            let i = qi - 1;
            if i <= j {
                upper[i][j] = b.bind(&format!("M{qi}_{}", j + 1), t);
            }
        }
    }
    let mut c = vec![ZERO; nq];
    for (qi, t) in sweep(model, layout, b, &motions, &drive) {
        c[qi - 1] = t;
    }
    for i in 0..nq {
        for j in 0..nq {
            let t = upper[i.min(j)][i.max(j)].clone();
            b.output(&format!("M[{}][{}]", i + 1, j + 1), &format!("M{}_{}", i + 1, j + 1), t);
        }
    }
    for (i, t) in c.into_iter().enumerate() {
        b.output(&format!("c[{}]", i + 1), &format!("c{}", i + 1), t);
    }
}
