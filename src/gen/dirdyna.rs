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
//! optimisation.
//!
//! # Size (`-passes=atomise -stats`, symbolic parameters / `--fold-params`)
//! | robot | dof | `dirdyna` ops | `invdyna` ops |
//! |---|---|---|---|
//! | double pendulum (example) | 2 | 53 / 47 | 42 |
//! | three_link_arm (example) | 3 | 854 / 760 | 510 |
//! | UR5 (example-robot-data) | 6 | 1291 / 1282 | 575 |
//! | Panda with fingers (example-robot-data) | 9 | 4068 / 3966 | 1365 |
//!
//! For scale, the corpus's Robotran `mbs_dirdyna` of Frank_segway (17 joints) states 4287 flops.

use rustc_hash::FxHashMap;

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
    let mut upper: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    for j in 0..nq {
        let unit = Drive {
            qd: vec![ZERO; nq],
            qdd: (0..nq).map(|k| Term::C(if k == j { 1.0 } else { 0.0 })).collect(),
            g: [ZERO, ZERO, ZERO],
        };
        for (qi, t) in sweep(model, layout, b, &motions, &unit) {
            let i = qi - 1;
            if i <= j {
                let t = b.bind(&format!("M{qi}_{}", j + 1), t);
                upper.insert((i, j), t);
            }
        }
    }
    let mut c = vec![ZERO; nq];
    for (qi, t) in sweep(model, layout, b, &motions, &drive) {
        c[qi - 1] = t;
    }
    for i in 0..nq {
        for j in 0..nq {
            let t = upper.get(&(i.min(j), i.max(j))).cloned().unwrap_or(ZERO);
            b.output(&format!("M[{}][{}]", i + 1, j + 1), &format!("M{}_{}", i + 1, j + 1), t);
        }
    }
    for (i, t) in c.into_iter().enumerate() {
        b.output(&format!("c[{}]", i + 1), &format!("c{}", i + 1), t);
    }
}
