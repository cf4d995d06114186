//! Body frames chosen so that a chain of URDF joints with dense constant rotations costs one
//! sparse rotation per joint, the rotational half of Denavit–Hartenberg frames (Denavit &
//! Hartenberg, "A kinematic notation for lower-pair mechanisms based on matrices", J. Appl.
//! Mech. 22, 1955; Craig, *Introduction to Robotics*, 3rd ed., §3.4): [`reframe`], which
//! [`crate::generate`] applies when it lowers the model's op count.
//!
//! # The problem
//! A URDF joint moves its child by `x_parent = xyz + ro·R_a(q)·x_child`: a constant rotation
//! `ro` (the `rpy`) and a rotation about the axis `a`. When `rpy` is neither a quarter turn nor
//! about one axis (TIAGo Pro's arms: `rpy="-1.5707963267949 3.14 0"`), `ro` is dense and every
//! vector carried across the joint costs its 15 ops on top of the joint rotation's 6, in the
//! RNEA and in each of the CRBA's column forces.
//!
//! # The frames
//! Link `L` gets the frame `Q_L` (its URDF frame times a constant rotation): `Q_L = G_L·Rz(φ_L)`
//! where `G_L` turns `z` onto the joint axis (`G_L e_z = a`) and `φ_L` is free. In these frames
//! the joint is `x'_P = Q_Pᵀ xyz + Rz(γ − φ_P)·Rx(β)·Rz(q + φ_L + δ)·x'_L`, with
//! `Rz(γ) Rx(β) Rz(δ)` the z-x-z Euler angles of `B_Pᵀ·ro·G_L` (`Q_P = B_P·Rz(φ_P)`). Choosing
//! `φ_P = γ` (the parent's free angle spent on this child) leaves the constant rotation
//! `Rx(β)` — 4 products per vector — and the rest is a joint **offset** `θ₀ = φ_L + δ`:
//! the child turns by `Rz(q + θ₀)`, whose `cos`, `sin` are two products of `C`, `S` each
//! ([`crate::robot::Joint::offset`]).
//!
//! # Which links
//! A revolute link whose joint has a revolute child with a dense constant rotation is a
//! *host*: it spends `φ` on that child (the one with the most moving joints below it, the
//! *preferred* child). Hosts and preferred children are reframed; a preferred child that is no
//! host spends its `φ` on its own offset (`φ = −δ`, `θ₀ = 0`). A fixed link below a moved one
//! takes `Q = roᵀ·Q_P` (its joint rotation becomes the identity). Every other link keeps its
//! URDF frame (`Q = I`), so a robot without such a chain — every topology family — comes back
//! unchanged. Prismatic links keep `Q = I`: a rotation about their axis does not commute into
//! an offset.
//!
//! The rotated `xyz`, centres of mass and inertia tensors lose their structural zeros, so the
//! frames do not always pay (UR5's `dirdyna`: 915 → 1084 ops); the generator keeps them only
//! when both functions together have fewer ops (TIAGo Pro: 41 853 → 40 231; figures measured
//! when introduced).
//!
//! The joint coordinates keep their meaning (`q` is the same angle about the same physical
//! axis), so `Qq`, `M` and `c` are unchanged: only the parameters of reframed links (`dpt`,
//! `l`, `In`) are in these frames instead of the URDF's (rounding-level differences; entries
//! within 10⁻¹⁵ of 0 or ±1 are snapped as [`Origin::from_xyz_rpy`] does).

use super::robot::{rotate_tensor, snap, Inertial, JointKind, Origin, Robot};

type Mat = [[f64; 3]; 3];
type Vec3 = [f64; 3];

const IDENTITY: Mat = Origin::IDENTITY.rot;

pub(super) fn mat_mul(a: &Mat, b: &Mat) -> Mat {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &Mat) -> Mat {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

pub(super) fn mat_vec(a: &Mat, v: &Vec3) -> Vec3 {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn rot_z(t: f64) -> Mat {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_x(t: f64) -> Mat {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

pub(super) fn snapped(m: &Mat) -> Mat {
    m.map(|row| row.map(snap))
}

/// `x` with magnitudes below 10⁻¹⁵ set to 0 (a zero turned into rounding noise by a rotation).
pub(super) fn tidy(x: f64) -> f64 {
    if x.abs() < 1e-15 {
        0.0
    } else {
        x
    }
}

/// Every entry 0 or ±1 (a signed permutation: free to apply).
fn is_signed_permutation(m: &Mat) -> bool {
    m.iter().flatten().all(|&x| x == 0.0 || x.abs() == 1.0)
}

/// A rotation `G` with `G e_z = a` (unit `a`); exact (entries 0, ±1) for an axis along ±x, ±y,
/// ±z.
fn align_z(a: &Vec3) -> Mat {
    // x: a unit vector orthogonal to a, from the coordinate axis least aligned with it.
    let k = (0..3).min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs())).expect("3 axes");
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let c = [e[1] * a[2] - e[2] * a[1], e[2] * a[0] - e[0] * a[2], e[0] * a[1] - e[1] * a[0]];
    let n = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let x = if n == 1.0 { c } else { c.map(|v| v / n) };
    let y = [a[1] * x[2] - a[2] * x[1], a[2] * x[0] - a[0] * x[2], a[0] * x[1] - a[1] * x[0]];
    [[x[0], y[0], a[0]], [x[1], y[1], a[1]], [x[2], y[2], a[2]]]
}

/// z-x-z Euler angles `(γ, β, δ)` of a rotation: `k = Rz(γ)·Rx(β)·Rz(δ)` to within a few ulps
/// of `k`'s entries.
///
/// Near β = 0 or π (`sin β` small) only `γ ± δ` is well conditioned: `γ` read from `k`'s third
/// column carries an error of about (error of `k`'s entries) / `sin β`, so `δ` is not read
/// from the third row but from the rest `Rx(β)ᵀ·Rz(γ)ᵀ·k`, which takes up `γ`'s error
/// (SO-101's `shoulder_pan`, `rpy="3.14159 4.18253e-17 -3.14159"`: `sin β` = 2.7·10⁻⁶, and the
/// pitch snapped out of one entry of `k` but not out of another put a 1.6·10⁻¹¹ rad turn between
/// the link frames when `δ` was read from the third row). When the tilt is below 10⁻¹⁵, `γ` is
/// the whole turn about `z` and `δ` what is left of it (0 up to rounding).
fn zxz(k: &Mat) -> (f64, f64, f64) {
    let sb = k[2][0].hypot(k[2][1]);
    let beta = sb.atan2(k[2][2]);
    let gamma = if sb < 1e-15 { k[1][0].atan2(k[0][0]) } else { k[0][2].atan2(-k[1][2]) };
    let rest = mat_mul(&mat_mul(&transpose(&rot_x(beta)), &transpose(&rot_z(gamma))), k);
    (gamma, beta, rest[1][0].atan2(rest[0][0]))
}

/// The robot in the frames of the module doc: joint origins, axes (`z` for reframed links) and
/// offsets, and links' inertials, re-expressed; `None` when no link would move (no dense
/// constant rotation on a revolute joint below a revolute joint).
pub fn reframe(robot: &Robot) -> Option<Robot> {
    let order = robot.dfs_joints();
    let nl = robot.links.len();
    let mut joint_of = vec![None; nl];
    for (j, joint) in robot.joints.iter().enumerate() {
        joint_of[joint.child] = Some(j);
    }
    let revolute = |l: usize| joint_of[l].is_some_and(|j: usize| robot.joints[j].kind == JointKind::Revolute);
    let g: Vec<Mat> = (0..nl)
        .map(|l| match joint_of[l] {
            Some(j) if revolute(l) => align_z(&robot.joints[j].axis),
            _ => IDENTITY,
        })
        .collect();
    // Moving joints in each link's subtree (children after parents in `order`).
    let mut below = vec![0usize; nl];
    for &j in order.iter().rev() {
        let joint = &robot.joints[j];
        below[joint.parent] += below[joint.child] + usize::from(joint.kind != JointKind::Fixed);
    }
    // Hosts and their preferred children (see the module doc).
    let mut preferred: Vec<Option<usize>> = vec![None; nl];
    for &j in &order {
        let joint = &robot.joints[j];
        let (p, l) = (joint.parent, joint.child);
        if !(revolute(p) && revolute(l)) {
            continue;
        }
        let k0 = mat_mul(&mat_mul(&transpose(&g[p]), &joint.origin.rot), &g[l]);
        if is_signed_permutation(&snapped(&k0)) {
            continue;
        }
        if preferred[p].is_none_or(|c| below[l] > below[c]) {
            preferred[p] = Some(l);
        }
    }
    let mut is_preferred = vec![false; nl];
    for c in preferred.iter().flatten() {
        is_preferred[*c] = true;
    }
    let reframed = |l: usize| preferred[l].is_some() || is_preferred[l];
    if !(0..nl).any(reframed) {
        return None;
    }
    // Top down: Q_L = B_L·Rz(φ_L).
    let mut base = vec![IDENTITY; nl];
    let mut phi = vec![0.0; nl];
    let frame = |base: &[Mat], phi: &[f64], l: usize| mat_mul(&base[l], &rot_z(phi[l]));
    let mut out = robot.clone();
    for &j in &order {
        let joint = &robot.joints[j];
        let (p, l) = (joint.parent, joint.child);
        let qp = frame(&base, &phi, p);
        if qp == IDENTITY && !reframed(l) {
            continue;
        }
        let o = &mut out.joints[j];
        o.origin.xyz = mat_vec(&transpose(&qp), &joint.origin.xyz).map(tidy);
        if reframed(l) {
            let k0 = mat_mul(&mat_mul(&transpose(&base[p]), &joint.origin.rot), &g[l]);
            let (gamma, beta, delta) = zxz(&k0);
            base[l] = g[l];
            phi[l] = match preferred[l] {
                Some(c) => {
                    let jc = joint_of[c].expect("a child link has a joint");
                    zxz(&mat_mul(&mat_mul(&transpose(&g[l]), &robot.joints[jc].origin.rot), &g[c])).0
                }
                None => -delta,
            };
            // φ_P is this γ when l is p's preferred child: exactly Rx(β).
            let gamma = if preferred[p] == Some(l) { 0.0 } else { gamma - phi[p] };
            o.origin.rot = snapped(&mat_mul(&rot_z(gamma), &rot_x(beta)));
            o.axis = [0.0, 0.0, 1.0];
            o.offset = phi[l] + delta;
        } else if joint.kind == JointKind::Fixed {
            // Q_L = roᵀ·Q_P: the joint's rotation becomes the identity.
            base[l] = mat_mul(&transpose(&joint.origin.rot), &qp);
            o.origin.rot = IDENTITY;
        } else {
            o.origin.rot = snapped(&mat_mul(&transpose(&qp), &joint.origin.rot));
        }
        let ql = frame(&base, &phi, l);
        if let Some(i) = robot.links[l].inertial {
            let qt = transpose(&ql);
            out.links[l].inertial = Some(Inertial {
                mass: i.mass,
                com: mat_vec(&qt, &i.com).map(tidy),
                inertia: rotate_tensor(&qt, &i.inertia).map(|row| row.map(tidy)),
            });
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat, b: &Mat) -> bool {
        a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| (x - y).abs() < 1e-14)
    }

    #[test]
    fn zxz_recomposes_and_align_z_turns_z_onto_the_axis() {
        for (r, p, y) in [(0.3, -1.1, 2.0), (-2.0679, 0.0, -1.2217), (1.52, 0.83776, -1.61), (0.0, 0.0, 0.7)] {
            let k = Origin::from_xyz_rpy([0.0; 3], [r, p, y]).rot;
            let (g, b, d) = zxz(&k);
            assert!(close(&mat_mul(&mat_mul(&rot_z(g), &rot_x(b)), &rot_z(d)), &k), "rpy {r} {p} {y}");
        }
        for a in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.6, 0.0, 0.8]] {
            let g = align_z(&a);
            assert_eq!(mat_vec(&g, &[0.0, 0.0, 1.0]), a);
            assert!(close(&mat_mul(&g, &transpose(&g)), &IDENTITY));
            let det = g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1])
                - g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0])
                + g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]);
            assert!((det - 1.0).abs() < 1e-15, "a rotation, not a reflection: {a:?}");
            if a.iter().all(|x| *x == 0.0 || x.abs() == 1.0) {
                assert!(is_signed_permutation(&g), "exact for a coordinate axis: {a:?}");
            }
        }
    }

    #[test]
    fn a_robot_without_a_dense_chain_is_left_alone() {
        let r = crate::topology::build(crate::topology::Topology::Serial, 12, 3);
        assert!(reframe(&r).is_none());
    }
}
