//! Link frames slid along their joint axes so that joint offsets `dpt` have more structural
//! zeros: the translational half of Denavit–Hartenberg frames (Denavit & Hartenberg, "A
//! kinematic notation for lower-pair mechanisms based on matrices", J. Appl. Mech. 22, 1955;
//! Craig, *Introduction to Robotics*, 3rd ed., §3.4, which puts each origin where the common
//! normal meets the joint axis): [`slide`], which [`crate::generate`] applies when it
//! lowers the model's op count. [`crate::frames`] chooses the rotations; this module the
//! origins.
//!
//! # The freedom
//! A revolute joint turns its child link about a line: the axis `a` through the child frame's
//! origin. Moving that origin along the line by `s` (the child frame becomes
//! `x'_L = x_L − s·a`) changes nothing physical, and `R_a(q)·a = a` keeps the joint a rotation
//! about `a` by the same `q`: the joint origin becomes `xyz + s·(ro·a)` (`ro` its constant
//! rotation), every child joint's origin `xyz_C − s·a` and the centre of mass `l − s·a`; the
//! inertia about the centre of mass, the rotations and the offsets stay. `q`, `Qq`, `M` and `c`
//! keep their meaning (tested against the unslid robot in [`crate::dirdyna`]'s tests).
//!
//! # What it saves
//! Each non-zero `dpt` component costs ops wherever a vector crosses the joint: about 4 per
//! column of `M` carried across it (the CRBA's `d × f`, for every moving joint below), a few
//! in the RNEA. With an axis along a coordinate axis, `s` can zero the joint origin's
//! component along the axis, or a child's component along it (and the centre of mass's); a
//! tree dynamic program over a few such candidates per link (at most [`MAX_CANDIDATES`])
//! minimises `Σ w·nnz(dpt) + Σ nnz(l)`, with `w` = 2 + the moving joints at and below the joint
//! (the columns carried across it). The upper triangle of `M` after `atomise,cse`, parameters
//! folded: serial30 8 573 → 8 017 ops, UR5 228 → 190, Panda 506 → 461, Solo-12 1 192 → 1 061,
//! Talos 4 856 → 4 511, TIAGo Pro 9 908 → 9 044 (measured when introduced; after
//! [`crate::sym`]'s folding and [`crate::crba`]'s turns the slid figures are 7 639,
//! 153, Panda's 7 × 7 arm 388, 906, 3 989 and 8 269). The generator keeps the slid frames only
//! when both functions together get fewer ops.
//!
//! # What stays
//! Prismatic joints (a slide along their axis is a change of `q`), fixed joints, and the
//! links of the root segment (joints at the parent's origin without constant rotation from the
//! root down: Robotran's floating base `T1…R3`, whose meeting axes the CRBA's projection uses)
//! are not slid. Values that a slide brings within 10⁻¹⁵ of 0 are set to 0.

use super::frames::{mat_vec, tidy};
use super::robot::{JointKind, Robot};

type Vec3 = [f64; 3];

/// Candidate slides kept per link (0 first): enough for the zeros an axis-aligned joint can
/// make, and a bound on the dynamic program's work (`O(links · MAX_CANDIDATES²)`).
pub const MAX_CANDIDATES: usize = 8;

fn nnz(v: &Vec3) -> usize {
    v.iter().filter(|x| tidy(**x) != 0.0).count()
}

/// `v + s·u − t·w`, tidied.
fn moved(v: &Vec3, s: f64, u: &Vec3, t: f64, w: &Vec3) -> Vec3 {
    [0, 1, 2].map(|k| tidy(v[k] + s * u[k] - t * w[k]))
}

/// The robot with link frames slid along their joint axes (module doc); `None` when no slide
/// lowers the weighted count of non-zero offsets. Cost: `O(links · MAX_CANDIDATES²)`.
pub fn slide(robot: &Robot) -> Option<Robot> {
    let nl = robot.links.len();
    let order = robot.dfs_joints();
    let mut joint_of = vec![None; nl];
    for (j, joint) in robot.joints.iter().enumerate() {
        joint_of[joint.child] = Some(j);
    }
    // The root segment, and the moving joints at and below each link.
    let in_segment = robot.root_segment();
    let mut below = vec![0usize; nl];
    for &j in order.iter().rev() {
        let jo = &robot.joints[j];
        below[jo.child] += usize::from(jo.kind != JointKind::Fixed);
        below[jo.parent] += below[jo.child];
    }
    let weight = |l: usize| 2 + below[l];
    // Per link: its axis in its own frame (`a`) and in its parent's (`u = ro·a`); zero for a
    // link that does not slide.
    let slides =
        |l: usize| joint_of[l].is_some_and(|j: usize| robot.joints[j].kind == JointKind::Revolute) && !in_segment[l];
    let a: Vec<Vec3> =
        (0..nl).map(|l| if slides(l) { robot.joints[joint_of[l].unwrap()].axis } else { [0.0; 3] }).collect();
    let u: Vec<Vec3> = (0..nl)
        .map(|l| if slides(l) { mat_vec(&robot.joints[joint_of[l].unwrap()].origin.rot, &a[l]) } else { [0.0; 3] })
        .collect();
    let xyz = |l: usize| joint_of[l].map_or([0.0; 3], |j| robot.joints[j].origin.xyz);
    let com = |l: usize| robot.links[l].inertial.filter(|i| i.mass != 0.0).map(|i| i.com);
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nl];
    for jo in &robot.joints {
        children[jo.parent].push(jo.child);
    }

    // Candidates, top down: 0, and the slides that zero a component of the link's own offset
    // (for each candidate of its parent), of a child's offset, or of the centre of mass, along
    // a coordinate axis the joint axis is.
    let mut cand: Vec<Vec<f64>> = vec![vec![0.0]; nl];
    let unit = |v: &Vec3, k: usize| v[k].abs() == 1.0;
    for &j in &order {
        let l = robot.joints[j].child;
        if !slides(l) {
            continue;
        }
        let p = robot.joints[j].parent;
        let mut c = vec![0.0];
        let mut push = |t: f64| {
            if t.is_finite() && !c.contains(&t) && c.len() < MAX_CANDIDATES {
                c.push(t);
            }
        };
        for k in (0..3).filter(|&k| unit(&u[l], k)) {
            for &sp in &cand[p] {
                push(-(xyz(l)[k] - sp * a[p][k]) / u[l][k]);
            }
        }
        for k in (0..3).filter(|&k| unit(&a[l], k)) {
            for &ch in &children[l] {
                push(xyz(ch)[k] / a[l][k]);
            }
            if let Some(m) = com(l) {
                push(m[k] / a[l][k]);
            }
        }
        cand[l] = c;
    }
    // Bottom up: best[l][i] = the least cost of l's subtree (its centre of mass, its children's
    // offsets and below) when l slides by cand[l][i]; choice[c][i] = the child's best candidate
    // given its parent's i-th.
    let mut best: Vec<Vec<usize>> = cand.iter().map(|c| vec![0; c.len()]).collect();
    let mut choice: Vec<Vec<usize>> = vec![Vec::new(); nl];
    let mut post: Vec<usize> = order.iter().map(|&j| robot.joints[j].child).collect();
    post.reverse();
    post.push(robot.root);
    for &l in &post {
        for &ch in &children[l] {
            choice[ch] = vec![0; cand[l].len()];
        }
        for i in 0..cand[l].len() {
            let t = cand[l][i];
            let mut cost = com(l).map_or(0, |m| nnz(&moved(&m, 0.0, &[0.0; 3], t, &a[l])));
            for &ch in &children[l] {
                // The child's offset moves by its own slide along u and by l's along a.
                let total = |k: usize| weight(ch) * nnz(&moved(&xyz(ch), cand[ch][k], &u[ch], t, &a[l])) + best[ch][k];
                let k = (0..cand[ch].len()).min_by_key(|&k| (total(k), k)).expect("0 is a candidate");
                choice[ch][i] = k;
                cost += total(k);
            }
            best[l][i] = cost;
        }
    }
    // Top down: the chosen slide of each link.
    let mut pick = vec![0usize; nl];
    for &j in &order {
        let (p, l) = (robot.joints[j].parent, robot.joints[j].child);
        pick[l] = choice[l][pick[p]];
    }
    let s: Vec<f64> = (0..nl).map(|l| cand[l][pick[l]]).collect();
    if s.iter().all(|&x| x == 0.0) {
        return None;
    }
    let mut out = robot.clone();
    for (j, joint) in out.joints.iter_mut().enumerate() {
        let (p, l) = (robot.joints[j].parent, robot.joints[j].child);
        joint.origin.xyz = moved(&xyz(l), s[l], &u[l], s[p], &a[p]);
    }
    for (l, link) in out.links.iter_mut().enumerate() {
        if let Some(i) = &mut link.inertial {
            i.com = moved(&i.com, 0.0, &[0.0; 3], s[l], &a[l]);
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::{build, Topology};

    /// `Σ weight · nnz(dpt)` as the module doc defines it, counted on the output robot.
    fn weighted(robot: &Robot) -> usize {
        let order = robot.dfs_joints();
        let mut below = vec![0usize; robot.links.len()];
        for &j in order.iter().rev() {
            let jo = &robot.joints[j];
            below[jo.child] += usize::from(jo.kind != JointKind::Fixed);
            below[jo.parent] += below[jo.child];
        }
        robot.joints.iter().map(|j| (2 + below[j.child]) * nnz(&j.origin.xyz)).sum()
    }

    #[test]
    fn a_serial_chain_loses_offsets_and_every_joint_keeps_its_axis_line() {
        let r = build(Topology::Serial, 30, 1);
        let s = slide(&r).expect("the 30-dof chain has offsets along its axes");
        assert!(weighted(&s) < weighted(&r), "{} -> {}", weighted(&r), weighted(&s));
        // Each link frame moved along its own axis: the change of a joint origin is its own
        // slide along u minus the parent's along a, so the offsets' differences lie in the
        // span of the two axes.
        for (j0, j1) in r.joints.iter().zip(&s.joints) {
            let d: Vec3 = [0, 1, 2].map(|k| j1.origin.xyz[k] - j0.origin.xyz[k]);
            let pa = r.joints.iter().find(|p| p.child == j0.parent).map_or([0.0; 3], |p| p.axis);
            for k in 0..3 {
                if j0.axis[k] == 0.0 && pa[k] == 0.0 {
                    assert_eq!(d[k], 0.0, "{}: component {k} off both axes moved", j0.name);
                }
            }
            assert_eq!((j0.axis, j0.origin.rot, j0.offset), (j1.axis, j1.origin.rot, j1.offset));
        }
    }

    #[test]
    fn the_floating_base_segment_stays_at_its_origin() {
        let r = build(Topology::Serial, 8, 2).with_floating_base().unwrap();
        let s = slide(&r).unwrap_or(r.clone());
        for (j0, j1) in r.joints.iter().zip(&s.joints) {
            if crate::robot::FLOATING_BASE.contains(&j0.name.as_str()) {
                assert_eq!(j1.origin.xyz, [0.0; 3], "{}", j0.name);
            }
        }
    }
}
