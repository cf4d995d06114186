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
//! # Formulation: CRBA for `M`, RNEA for `c`
//! - `c = RNEA(q, qd, qdd = 0, g)`: one sweep of [`super::rnea::sweep`].
//! - `M` by the composite-rigid-body algorithm ([`super::crba`]; Walker & Orin 1982, method 3):
//!   each subtree's inertia is formed once, then one force per column is carried to the root.
//!   Only the entries `i ≤ j` are formed (symmetry).
//!
//! Robotran itself uses a semi-explicit Newton–Euler formulation; the unit-acceleration RNEA
//! (method 1: column `j` is `RNEA(q, qd = 0, qdd = e_j, g = 0)`, which reuses the RNEA checked
//! against Pinocchio) was this generator's first formulation and stays as
//! [`MassMatrix::UnitAcceleration`], an independent recursion that the tests compare CRBA with.
//! It re-runs the recursion over joint `j`'s whole subtree for every column, so it grows as
//! O(dof³) on a chain where CRBA grows as O(dof²):
//!
//! | model (symbolic parameters, own frames) | dof | `dirdyna` ops, CRBA | unit-acceleration RNEA |
//! |---|---|---|---|
//! | `--topology parallel --dof 23 --seed 1` | 23 | 2 676 | 3 128 |
//! | `--topology semi-serial --dof 23 --seed 1` | 23 | 5 954 | 11 189 |
//! | `--topology serial --dof 23 --seed 1` | 23 | 8 931 | 22 766 |
//! | `--topology serial --dof 50 --seed 1` | 50 | 32 962 | 105 363 |
//! | `--topology serial --dof 130 --seed 1` | 130 | 183 883 | 691 775 |
//!
//! The critical path is the same for both (it runs through `c`'s velocity recursion).
//! The thesis's Robotran models have 19 970, 93 525 and 620 257 ops for the serial 23, 50
//! and 130 dof (seed Table 3.1; different models).
//!
//! # Size (`-passes=atomise -stats`, symbolic parameters / `--fold-params`)
//! | robot | dof | `dirdyna` ops | `invdyna` ops |
//! |---|---|---|---|
//! | double pendulum (example) | 2 | 47 / 35 | 41 / 41 |
//! | three_link_arm (example) | 3 | 657 / 507 | 475 / 469 |
//! | UR5 (example-robot-data) | 6 | 774 / 664 | 529 / 499 |
//! | Panda with fingers (example-robot-data) | 9 | 2184 / 1886 | 1282 / 1267 |
//!
//! For scale, the corpus's Robotran `mbs_dirdyna` of Frank_segway (17 joints) states 4287 flops.

use rustc_hash::FxHashMap;

use super::crba::{self, bind_entry};
use super::rnea::{motions, sweep, Drive, Motion};
use super::sym::{Builder, Term, ZERO};
use super::{Layout, Model, Reached, Stopped};

/// How `M` is formed: [`crate::crba`] (the default) or the unit-acceleration RNEA (kept as
/// an independent cross-check of the CRBA in tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MassMatrix {
    /// Composite-rigid-body algorithm.
    Crba,
    /// One RNEA sweep per column with `qdd = e_j`, `qd = 0`, `g = 0`.
    UnitAcceleration,
}

/// Writes `dirdyna` (outputs `M[i][j]`, then `c[i]`) into `b`, `M` by CRBA.
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn dirdyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    dirdyna_with(model, layout, b, MassMatrix::Crba)
}

/// Writes `dirdyna` with `M` formed by `how`. Cost: the ops of `M` and `c` plus one output per
/// entry of `M` (`nq²`, Robotran's layout); an entry that folds to 0 or copies the upper one
/// costs its output and nothing else (no name of a temporary, no table entry).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body and per row of `M`).
pub fn dirdyna_with(model: &Model, layout: &Layout, b: &mut Builder, how: MassMatrix) -> Result<(), Stopped> {
    let nq = layout.nv;
    let mut parts = |b: &mut Builder, motions: &[Motion], drive: &Drive| {
        let entries = match how {
            MassMatrix::Crba => crba::mass_matrix(model, layout, b, motions)?,
            MassMatrix::UnitAcceleration => unit_acceleration(model, layout, b, motions, nq)?,
        };
        Ok((entries, sweep(model, layout, b, motions, drive)?))
    };
    dirdyna_by(model, layout, b, &mut parts)
}

/// What writes `M` and `c` of [`dirdyna_by`]: given the builder, the joint motions and `c`'s
/// drive (`qdd = 0`), the upper triangle of `M` ([`crba::Entries`]) and the joint forces
/// `(i, c_i)`, sorted by `i`.
pub type Parts<'a> = dyn FnMut(&mut Builder, &[Motion], &Drive) -> Parted + 'a;

/// What a [`Parts`] returns: the upper triangle of `M` and the joint forces `(i, c_i)`.
pub type Parted = Result<(crba::Entries, Vec<(usize, Term)>), Stopped>;

/// `dirdyna`'s inputs, statements and outputs in Robotran's layout, with `M` and `c` written by
/// `parts` (the CRBA and the RNEA, or the depth-optimised formulation's, [`super::depth`]).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body and per row of `M`).
pub fn dirdyna_by(model: &Model, layout: &Layout, b: &mut Builder, parts: &mut Parts<'_>) -> Result<(), Stopped> {
    let nq = layout.nv;
    // `c`'s inputs first (gravity, rates), then the trig variables.
    let drive = Drive::inputs(b, nq, false);
    let motions = motions(model, layout, b);
    let mut upper: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    let (entries, forces) = parts(b, &motions, &drive)?;
    for ((i, j), t) in entries {
        upper.insert((i - 1, j - 1), t);
    }
    let mut c = vec![ZERO; nq];
    for (qi, t) in forces {
        c[qi - 1] = t;
    }
    // `nq²` names: each made of its row's `M[i]` and its column's `[j]`, formatted once.
    let columns: Vec<String> = (1..=nq).map(|j| format!("[{j}]")).collect();
    b.f.outputs.reserve(nq * nq + nq);
    for i in 0..nq {
        b.check_at(Reached::Row { row: i + 1, rows: nq })?;
        let row = format!("M[{}]", i + 1);
        for (j, column) in columns.iter().enumerate() {
            let t = upper.get(&(i.min(j), i.max(j))).cloned().unwrap_or(ZERO);
            let mut name = String::with_capacity(row.len() + column.len());
            name.push_str(&row);
            name.push_str(column);
            b.output_with(name, || format!("M{}_{}", i + 1, j + 1), t);
        }
    }
    for (i, t) in c.into_iter().enumerate() {
        b.output(&format!("c[{}]", i + 1), &format!("c{}", i + 1), t);
    }
    Ok(())
}

/// The upper triangle of `M` by one RNEA sweep per column (`qdd = e_j`, `qd = 0`, `g = 0`).
fn unit_acceleration(
    model: &Model,
    layout: &Layout,
    b: &mut Builder,
    motions: &[Motion],
    nq: usize,
) -> Result<crba::Entries, Stopped> {
    let mut upper = Vec::new();
    for j in 0..nq {
        let unit = Drive {
            qd: vec![ZERO; nq],
            qdd: (0..nq).map(|k| Term::C(if k == j { 1.0 } else { 0.0 })).collect(),
            g: [ZERO, ZERO, ZERO],
        };
        for (qi, t) in sweep(model, layout, b, motions, &unit)? {
            if qi <= j + 1 {
                upper.push(((qi, j + 1), bind_entry(b, qi, j + 1, t)));
            }
        }
    }
    Ok(upper)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use robovec_ir::interp;

    use super::*;
    use crate::topology::{build, Topology};
    use crate::Layout;

    /// `M` of `robot` by `how` at pseudo-random `q`, parameters given their values.
    fn mass_matrix(robot: &crate::robot::Robot, how: MassMatrix) -> BTreeMap<String, f64> {
        let model = Model { robot: robot.clone() };
        let layout = Layout::of(&model.robot);
        let mut given: BTreeMap<String, f64> = layout.nonzero();
        for i in 1..=layout.nq {
            given.insert(format!("q[{i}]"), (i as f64 * 0.7).sin() * 3.0);
        }
        let mut b = Builder::new("dirdyna", Default::default());
        dirdyna_with(&model, &layout, &mut b, how).expect("no deadline");
        let f = b.finish();
        // In binary64, inputs not given (qd, g) pseudo-random with seed 0: what `-eval` does.
        let value = |name: &str| given.get(name).copied().unwrap_or_else(|| interp::pseudo_random_input(name, 0));
        interp::eval::<f64>(&f, value).into_iter().filter(|(k, _)| k.starts_with("M[")).collect()
    }

    fn assert_close(what: &str, a: &BTreeMap<String, f64>, b: &BTreeMap<String, f64>, n: usize) {
        assert_within(what, a, b, n, 1e-12);
    }

    /// Every entry of `a` within `tol` times the largest of `b` of `b`'s (`n × n` entries each).
    fn assert_within(what: &str, a: &BTreeMap<String, f64>, b: &BTreeMap<String, f64>, n: usize, tol: f64) {
        assert_eq!(a.len(), n * n, "{what}");
        assert_eq!(b.len(), n * n, "{what}");
        let norm = b.values().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(norm > 0.1, "{what}: M is not trivially zero");
        for (k, x) in a {
            assert!((x - b[k]).abs() <= tol * norm, "{what} {k}: {x} vs {}", b[k]);
        }
    }

    /// CRBA's `M` against the unit-acceleration RNEA's (an independent recursion) on every
    /// topology family, on Robotran's floating base (the CRBA's root-segment projection), on the
    /// free flyer (its 6 × 6 block from the whole robot's composite) and on
    /// a chain of dense URDF rotations (merged rotations), that chain also in the frames of
    /// `crate::frames`, and the families with the origins of `crate::origins` (the
    /// same `M`: the coordinates keep their meaning): equal to 1e-12.
    #[test]
    fn crba_mass_matrix_equals_the_unit_acceleration_rnea() {
        for t in Topology::ALL {
            let r = build(t, 9, 3);
            let crba = mass_matrix(&r, MassMatrix::Crba);
            assert_close(&t.to_string(), &crba, &mass_matrix(&r, MassMatrix::UnitAcceleration), 9);
            let slid = crate::origins::slide(&r).expect("the families have offsets along their axes");
            assert_close(&format!("{t}, slid"), &mass_matrix(&slid, MassMatrix::Crba), &crba, 9);
        }
        let floating = build(Topology::Serial, 5, 2).with_floating_base().unwrap();
        let (crba, unit) =
            (mass_matrix(&floating, MassMatrix::Crba), mass_matrix(&floating, MassMatrix::UnitAcceleration));
        assert_close("floating base", &crba, &unit, 11);
        let slid = crate::origins::slide(&floating).expect("the chain above the base slides");
        assert_close("floating base, slid", &mass_matrix(&slid, MassMatrix::Crba), &crba, 11);
        let free = build(Topology::SemiSerial, 5, 2).with_free_flyer().unwrap();
        let (crba, unit) = (mass_matrix(&free, MassMatrix::Crba), mass_matrix(&free, MassMatrix::UnitAcceleration));
        assert_close("free flyer", &crba, &unit, 11);
        let mut dense = build(Topology::Serial, 7, 5);
        for (i, j) in dense.joints.iter_mut().enumerate() {
            let x = i as f64;
            j.origin = crate::robot::Origin::from_xyz_rpy(j.origin.xyz, [0.3 * x - 1.0, 0.2 * x - 0.7, 1.1 * x]);
        }
        let crba = mass_matrix(&dense, MassMatrix::Crba);
        assert_close("dense rpy", &crba, &mass_matrix(&dense, MassMatrix::UnitAcceleration), 7);
        let reframed = crate::frames::reframe(&dense).expect("a chain of dense rotations is reframed");
        assert!(reframed.joints.iter().any(|j| j.offset != 0.0), "offsets are used");
        assert_close("dense rpy, reframed", &mass_matrix(&reframed, MassMatrix::Crba), &crba, 7);
        assert_close("dense rpy, reframed, unit", &mass_matrix(&reframed, MassMatrix::UnitAcceleration), &crba, 7);
        let slid = crate::origins::slide(&reframed).expect("reframed joints turn about z");
        assert_close("dense rpy, reframed, slid", &mass_matrix(&slid, MassMatrix::Crba), &crba, 7);
    }

    /// Constant rotations near a half or a quarter turn (written to 6 digits, SO-101's
    /// `rpy="3.14159 4.18253e-17 -3.14159"` among them: a tilt of 2.7·10⁻⁶ from the joint axis)
    /// in the frames of `crate::frames`: the same `M` to 1e-15 of its largest entry. Reading the
    /// z-x-z angle `δ` from the third row put a 1.6·10⁻¹¹ rad turn between frames there (`M` off by
    /// 2·10⁻¹²).
    #[test]
    fn nearly_degenerate_rotations_reframe_to_rounding() {
        let mut r = build(Topology::Serial, 6, 5);
        let rpys = [
            [3.14159, 4.18253e-17, -3.14159],
            [-1.5708, -1.5708, 0.0],
            [-3.63608e-16, 8.74301e-16, 1.5708],
            [4.02456e-15, 8.67362e-16, -1.5708],
            [1.5708, 0.0486795, 3.14159],
            [1.5708, -5.24284e-08, -1.41553e-15],
        ];
        for (j, rpy) in r.joints.iter_mut().zip(rpys) {
            j.origin = crate::robot::Origin::from_xyz_rpy(j.origin.xyz, rpy);
            j.axis = [0.0, 0.0, 1.0];
        }
        let crba = mass_matrix(&r, MassMatrix::Crba);
        let reframed = crate::frames::reframe(&r).expect("dense rotations below revolute joints");
        assert_within("nearly degenerate, reframed", &mass_matrix(&reframed, MassMatrix::Crba), &crba, 6, 1e-15);
    }
}
