//! Built-in robot families for the parallelisation study (seed §3.2, Table 3.1: 23, 50, 70, 100
//! and 130 dof, each as a serial, a semi-serial and a parallel multibody system): a seeded
//! random [`Robot`] of a given topology and number of degrees of freedom, which the generator
//! ([`crate::generate`]) turns into `invdyna` and `dirdyna` like any URDF.
//!
//! # The families
//! Every family is a fixed base (link `base`) carrying open chains of revolute joints; the
//! thesis's parallel systems have closed loops, which are cut into trees (seed §3.1) and whose
//! constraints are out of scope here, so "parallel" means many short chains. [`chains`] gives the
//! chain lengths:
//! - [`Topology::Serial`]: one chain of `dof` joints (the longest kinematic chain, the most ops);
//! - [`Topology::SemiSerial`]: `k = max(2, round(√dof / 2))` chains of medium length (23 dof →
//!   2 chains, 50 → 4, 70 → 4, 100 → 5, 130 → 6), the lengths differing by at most one;
//! - [`Topology::Parallel`]: chains of [`PARALLEL_CHAIN`] joints (a leg or a finger), the last
//!   one shorter when `dof` is not a multiple (130 dof → 33 chains).
//!
//! Beyond the study, [`Topology::Star`]: `dof` single-joint branches off the base (issue 28's
//! scale input: its mass matrix is diagonal, so the generator's cost must follow the ops it
//! writes, not `dof²`). It is not in [`Topology::ALL`] (the study's families, with the thesis's
//! rows) but is a family like them for [`build`] and `robovec-gen --topology star`.
//!
//! # Random parameters (seeded, reproducible: XorShift, `rand_xorshift`)
//! For each joint: the axis is one of x, y, z of its frame (so the rotations fold to Robotran's
//! C/S products); the joint origin `dpt` in the parent frame has each coordinate either 0 (a
//! structural zero, probability ½) or uniform in ±[0.05, 0.4] m, at least one non-zero; no
//! constant rotation (`rpy = 0`, Robotran's aligned joint frames). For each body: mass uniform
//! in [0.5, 5] kg; centre of mass with each coordinate 0 (probability ½) or uniform in
//! ±[0.01, 0.2] m; a diagonal inertia tensor with principal moments uniform in [0.01, 0.02)
//! kg·m² (so every triangle inequality `Ixx + Iyy ≥ Izz` holds). The same `(topology, dof, seed)`
//! gives the same robot on every machine.
//!
//! # Names
//! Joints `j001`, `j002`, … and their child links `b001`, … numbered chain after chain, zero
//! padded to the width of `dof` so that byte order (which fixes Pinocchio's and robovec's joint
//! numbering, see [`crate`]) is creation order: `q[i]` is joint `i`.

use std::fmt;
use std::str::FromStr;

use rand::{RngExt, SeedableRng};
use rand_xorshift::XorShiftRng;
use robovec_ir::Span;

use super::robot::{Inertial, Joint, JointKind, Link, Origin, Robot};

/// Joints per chain of a [`Topology::Parallel`] robot.
pub const PARALLEL_CHAIN: usize = 4;

/// A family of the study (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Topology {
    /// One chain.
    Serial,
    /// A few medium chains from the base.
    SemiSerial,
    /// Many short chains from the base.
    Parallel,
    /// One-joint chains from the base (not a study family: see the module doc).
    Star,
}

impl Topology {
    /// Every family, in the thesis's order.
    pub const ALL: [Topology; 3] = [Topology::Serial, Topology::SemiSerial, Topology::Parallel];

    /// Every family [`build`] makes: the study's ([`Topology::ALL`]), then [`Topology::Star`].
    pub const EVERY: [Topology; 4] = [Topology::Serial, Topology::SemiSerial, Topology::Parallel, Topology::Star];

    /// The command-line name: `serial`, `semi-serial`, `parallel`, `star`.
    pub fn name(self) -> &'static str {
        match self {
            Topology::Serial => "serial",
            Topology::SemiSerial => "semi-serial",
            Topology::Parallel => "parallel",
            Topology::Star => "star",
        }
    }
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Topology {
    type Err = String;

    /// Parses a command-line name.
    ///
    /// # Errors
    /// A message listing the names when `s` is none of them.
    fn from_str(s: &str) -> Result<Topology, String> {
        Topology::EVERY
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| format!("unknown topology `{s}`: expected serial, semi-serial, parallel or star"))
    }
}

/// The chain lengths (joints per chain, summing to `dof`) of `topology` at `dof` degrees of
/// freedom; empty when `dof` is 0.
pub fn chains(topology: Topology, dof: usize) -> Vec<usize> {
    if dof == 0 {
        return Vec::new();
    }
    match topology {
        Topology::Serial => vec![dof],
        Topology::SemiSerial => {
            let k = (((dof as f64).sqrt() / 2.0).round() as usize).clamp(2, dof.max(2)).min(dof);
            (0..k).map(|i| dof / k + usize::from(i < dof % k)).collect()
        }
        Topology::Parallel => {
            let mut c = vec![PARALLEL_CHAIN; dof / PARALLEL_CHAIN];
            if !dof.is_multiple_of(PARALLEL_CHAIN) {
                c.push(dof % PARALLEL_CHAIN);
            }
            c
        }
        Topology::Star => vec![1; dof],
    }
}

/// A value uniform in ±[lo, hi], or 0 with probability ½.
fn sparse(rng: &mut XorShiftRng, lo: f64, hi: f64) -> f64 {
    if rng.random_bool(0.5) {
        return 0.0;
    }
    let x = rng.random_range(lo..hi);
    if rng.random_bool(0.5) {
        -x
    } else {
        x
    }
}

/// The robot of `topology` with `dof` revolute joints, parameters drawn from `seed` (module
/// doc). Cost: O(dof).
pub fn build(topology: Topology, dof: usize, seed: u64) -> Robot {
    let mut rng = XorShiftRng::seed_from_u64(seed);
    let width = dof.to_string().len().max(3);
    let mut links = vec![Link { name: "base".into(), inertial: None, span: Span::DUMMY }];
    let mut joints = Vec::with_capacity(dof);
    for len in chains(topology, dof) {
        let mut parent = 0;
        for _ in 0..len {
            let n = joints.len() + 1;
            let mut xyz = [0.0; 3];
            while xyz == [0.0; 3] {
                xyz = [(); 3].map(|_| sparse(&mut rng, 0.05, 0.4));
            }
            let mut axis = [0.0; 3];
            axis[rng.random_range(0..3)] = 1.0;
            let mass = rng.random_range(0.5..5.0);
            let com = [(); 3].map(|_| sparse(&mut rng, 0.01, 0.2));
            let mut inertia = [[0.0; 3]; 3];
            for (k, row) in inertia.iter_mut().enumerate() {
                row[k] = rng.random_range(0.01..0.02);
            }
            links.push(Link {
                name: format!("b{n:0width$}"),
                inertial: Some(Inertial { mass, com, inertia }),
                span: Span::DUMMY,
            });
            let child = links.len() - 1;
            joints.push(Joint {
                name: format!("j{n:0width$}"),
                kind: JointKind::Revolute,
                parent,
                child,
                origin: Origin { xyz, rot: Origin::IDENTITY.rot },
                axis,
                offset: 0.0,
                rank: 0,
                continuous: false,
                span: Span::DUMMY,
            });
            parent = child;
        }
    }
    Robot { name: format!("{topology}_{dof}dof_seed{seed}"), links, joints, root: 0, cos_sin: false }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_lengths_follow_the_module_doc() {
        assert_eq!(chains(Topology::Serial, 23), [23]);
        // k = round(√dof / 2), at least 2: 23 → 2.40 → 2; 50 → 3.54 → 4; 130 → 5.70 → 6.
        assert_eq!(chains(Topology::SemiSerial, 23), [12, 11]);
        assert_eq!(chains(Topology::SemiSerial, 50), [13, 13, 12, 12]);
        assert_eq!(chains(Topology::SemiSerial, 130), [22, 22, 22, 22, 21, 21]);
        assert_eq!(chains(Topology::SemiSerial, 3), [2, 1]);
        assert_eq!(chains(Topology::SemiSerial, 1), [1]);
        assert_eq!(chains(Topology::Parallel, 23), [4, 4, 4, 4, 4, 3]);
        assert_eq!(chains(Topology::Parallel, 130).len(), 33);
        assert!(chains(Topology::Parallel, 0).is_empty());
        assert_eq!(chains(Topology::Star, 5), [1, 1, 1, 1, 1]);
        for t in Topology::EVERY {
            for dof in 1..140 {
                assert_eq!(chains(t, dof).iter().sum::<usize>(), dof, "{t} {dof}");
            }
        }
    }

    #[test]
    fn robots_are_reproducible_trees_numbered_in_creation_order() {
        let a = build(Topology::SemiSerial, 23, 7);
        assert_eq!(a, build(Topology::SemiSerial, 23, 7));
        assert_ne!(a, build(Topology::SemiSerial, 23, 8));
        assert_eq!(a.joints.len(), 23);
        assert_eq!(a.links.len(), 24);
        // Depth-first order by name is creation order: q[i] is joint i.
        assert_eq!(a.dfs_joints(), (0..23).collect::<Vec<_>>());
        // Chain starts hang from the base: joints 1 and 13 (lengths 12, 11).
        let from_base: Vec<&str> = a.joints.iter().filter(|j| j.parent == 0).map(|j| j.name.as_str()).collect();
        assert_eq!(from_base, ["j001", "j013"]);
        for j in &a.joints {
            assert_eq!(j.axis.iter().filter(|&&x| x == 1.0).count(), 1);
            assert_ne!(j.origin.xyz, [0.0; 3]);
            let i = a.links[j.child].inertial.unwrap();
            assert!((0.5..5.0).contains(&i.mass));
            let d = [i.inertia[0][0], i.inertia[1][1], i.inertia[2][2]];
            assert!(d[0] + d[1] >= d[2] && d[1] + d[2] >= d[0] && d[0] + d[2] >= d[1]);
        }
        assert_eq!(build(Topology::Serial, 1000, 1).joints[999].name, "j1000");
        assert_eq!("semi-serial".parse::<Topology>(), Ok(Topology::SemiSerial));
        assert_eq!("star".parse::<Topology>(), Ok(Topology::Star));
        // A star: every joint hangs from the base.
        let s = build(Topology::Star, 40, 2);
        assert!(s.joints.iter().all(|j| j.parent == 0));
        assert_eq!(s.links.len(), 41);
        assert!("tree".parse::<Topology>().is_err());
    }
}
