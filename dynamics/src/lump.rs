//! Links on fixed joints merged into the link they hang from, as Pinocchio's URDF reader does
//! (`buildModelFromUrdf` appends a fixed link's inertia to its parent body): [`contract_fixed`],
//! which [`crate::generate_with`] applies before choosing body frames.
//!
//! A link fixed to its parent moves with it: its mass properties can join the parent's (a
//! rigid body's mass, centre of mass and inertia add up), and the joints below it can hang from
//! the parent with their origins composed with the fixed joint's. Every recursion then has one
//! body less per fixed joint: no velocity, acceleration, force or composite of its own, no step
//! of a CRBA column through it. `invdyna` on the free flyer, `--fold-params`, `atomise,cse`
//! (before → after): Talos (8 fixed joints with mass or moving joints below) and TIAGo Pro
//! (24) — see the module doc of [`crate::dirdyna`] for the counts.
//!
//! # What changes for the user
//! The coordinates (`q`, `qd`, `qdd`, `Qq`, `M`, `c`) keep their meaning and order: the moving
//! joints are walked in the original order ([`crate::robot::Joint::rank`]). The bodies are
//! renumbered (one per moving joint), so the parameters `m[b]`, `l[k][b]`, `In[k][b]`, `dpt[k][b]`
//! name the merged bodies: a body's mass is that of its link and every link fixed to it, its
//! centre of mass and inertia are theirs together (in its frame), and `dpt` is the composed
//! joint origin. Their values come with them (`-params-out`).

use super::frames::{mat_mul, mat_vec, snapped, tidy};
use super::robot::{rotate_tensor, Inertial, Joint, JointKind, Link, Origin, Robot};

/// `a ∘ b`: the transform `b` (child in `a`'s child frame) seen from `a`'s parent.
fn compose(a: &Origin, b: &Origin) -> Origin {
    let t = mat_vec(&a.rot, &b.xyz);
    let xyz = [0, 1, 2].map(|k| tidy(a.xyz[k] + t[k]));
    Origin { xyz, rot: snapped(&mat_mul(&a.rot, &b.rot)) }
}

/// Several rigid bodies' mass properties, each given in a frame placed by an [`Origin`] in the
/// common frame, as one (Huygens–Steiner for the inertia about the common centre of mass).
/// `None` when the total is massless with no inertia.
fn combine(parts: &[(Origin, Inertial)]) -> Option<Inertial> {
    let mass: f64 = parts.iter().map(|(_, i)| i.mass).sum();
    let placed: Vec<(f64, [f64; 3], [[f64; 3]; 3])> = parts
        .iter()
        .map(|(o, i)| {
            let c = mat_vec(&o.rot, &i.com);
            (i.mass, [0, 1, 2].map(|k| o.xyz[k] + c[k]), rotate_tensor(&o.rot, &i.inertia))
        })
        .collect();
    let com = if mass > 0.0 {
        [0, 1, 2].map(|k| placed.iter().map(|(m, c, _)| m * c[k]).sum::<f64>() / mass)
    } else {
        [0.0; 3]
    };
    let mut inertia = [[0.0; 3]; 3];
    for (m, c, t) in &placed {
        let r = [0, 1, 2].map(|k| c[k] - com[k]);
        let rr: f64 = r.iter().map(|x| x * x).sum();
        for a in 0..3 {
            for b in 0..3 {
                let delta = if a == b { rr } else { 0.0 };
                inertia[a][b] += t[a][b] + m * (delta - r[a] * r[b]);
            }
        }
    }
    let empty = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
    (!empty).then_some(Inertial { mass, com, inertia })
}

/// `robot` with every fixed joint contracted: its child link merged into the nearest link
/// above it whose joint moves (or the root), the joints below re-hung there with composed
/// origins, every joint's [`Joint::rank`] its place in the original walk. `None` when the robot
/// has no fixed joint. Also returns, per body of the result (1-based, index 0 unused), the body
/// it was in `robot` (for messages that name a body). Cost: O(links · log links).
pub fn contract_fixed(robot: &Robot) -> Option<(Robot, Vec<usize>)> {
    if robot.joints.iter().all(|j| j.kind != JointKind::Fixed) {
        return None;
    }
    let order = robot.dfs_joints();
    let n = robot.links.len();
    // Per link: the link it merges into and its frame there (the root and the children of
    // moving joints carry themselves at the identity).
    let mut carrier: Vec<usize> = (0..n).collect();
    let mut placed = vec![Origin::IDENTITY; n];
    for &j in &order {
        let jo = &robot.joints[j];
        if jo.kind == JointKind::Fixed {
            carrier[jo.child] = carrier[jo.parent];
            placed[jo.child] = compose(&placed[jo.parent], &jo.origin);
        }
    }
    // The links kept, in file order, and their merged mass properties.
    let kept: Vec<usize> = (0..n).filter(|&l| carrier[l] == l).collect();
    let mut new_index = vec![usize::MAX; n];
    for (k, &l) in kept.iter().enumerate() {
        new_index[l] = k;
    }
    let mut parts: Vec<Vec<(Origin, Inertial)>> = vec![Vec::new(); n];
    for l in 0..n {
        if let Some(i) = robot.links[l].inertial {
            parts[carrier[l]].push((placed[l], i));
        }
    }
    let links: Vec<Link> = kept
        .iter()
        .map(|&l| {
            let own = &robot.links[l];
            // One part at the identity is taken as it is: the link's own, or that of a link
            // fixed to it at its origin when it has none (a massless `world` above the base).
            let inertial = match parts[l].as_slice() {
                [(at, one)] if *at == Origin::IDENTITY => Some(*one),
                _ => combine(&parts[l]),
            };
            Link { name: own.name.clone(), inertial, span: own.span }
        })
        .collect();
    let mut joints = Vec::new();
    let mut body_of = vec![0];
    for (rank, &j) in order.iter().enumerate() {
        let jo = &robot.joints[j];
        if jo.kind == JointKind::Fixed {
            continue;
        }
        let p = carrier[jo.parent];
        joints.push(Joint {
            parent: new_index[p],
            child: new_index[jo.child],
            origin: compose(&placed[jo.parent], &jo.origin),
            rank,
            ..jo.clone()
        });
        body_of.push(rank + 1);
    }
    let contracted =
        Robot { name: robot.name.clone(), links, joints, root: new_index[robot.root], cos_sin: robot.cos_sin };
    Some((contracted, body_of))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::{build, Topology};

    /// The walk keeps the moving joints' order when fixed joints between them go, with names
    /// that would sort otherwise (a fixed `a` joint whose child holds `z`, beside `m`).
    #[test]
    fn moving_joints_keep_pinocchios_order() {
        let mut r = build(Topology::Parallel, 9, 2);
        // Rename so that sorting by name alone after re-hanging would change the order.
        let k = r.joints.len();
        for (i, j) in r.joints.iter_mut().enumerate() {
            j.name = format!("j{:02}", k - i);
        }
        let before: Vec<String> = r.dfs_joints().into_iter().map(|j| r.joints[j].name.clone()).collect();
        for j in [0, 3, 5] {
            r.joints[j].kind = JointKind::Fixed;
        }
        let moving: Vec<&String> =
            before.iter().filter(|n| r.joints.iter().any(|j| &j.name == *n && j.kind != JointKind::Fixed)).collect();
        let (c, body_of) = contract_fixed(&r).expect("fixed joints");
        let after: Vec<&String> = c.dfs_joints().into_iter().map(|j| &c.joints[j].name).collect();
        assert_eq!(after, moving);
        assert_eq!(body_of.len(), after.len() + 1);
        assert!(contract_fixed(&c).is_none(), "nothing left to contract");
    }

    /// A massless root link with one link fixed to it at its origin (xArm's `world` above
    /// `link_base`) takes that link's mass properties: on a free flyer the root is body 1 and
    /// its mass counts. (It once kept the root's own, none, and dropped the base's mass.)
    #[test]
    fn a_massless_root_takes_the_link_fixed_at_its_origin() {
        let mut r = build(Topology::Serial, 3, 1);
        let base = r.root;
        let mass = Inertial {
            mass: 0.9,
            com: [0.1, -0.2, 0.3],
            inertia: [[0.3, 0.01, 0.0], [0.01, 0.4, 0.02], [0.0, 0.02, 0.5]],
        };
        r.links[base].inertial = Some(mass);
        r.links.push(Link { name: "world".into(), inertial: None, span: r.links[base].span });
        let world = r.links.len() - 1;
        let mut fixed = r.joints[0].clone();
        (fixed.name, fixed.kind, fixed.parent, fixed.child, fixed.origin) =
            ("world_joint".into(), JointKind::Fixed, world, base, Origin::IDENTITY);
        r.joints.insert(0, fixed);
        r.root = world;
        let r = r.with_free_flyer().expect("free names");
        let (c, _) = contract_fixed(&r).expect("a fixed joint");
        let kept = c.links.iter().find(|l| l.name == "world").expect("the root is kept");
        assert_eq!(kept.inertial, Some(mass));
        assert_eq!(c.links.len(), r.links.len() - 1);
    }

    /// Mass properties add up: total mass, centre of mass, and the inertia about the common
    /// centre of mass of two point-like bodies by hand.
    #[test]
    fn combined_mass_properties() {
        let point = |m: f64| Inertial { mass: m, com: [0.0; 3], inertia: [[0.0; 3]; 3] };
        let at = |x: f64| Origin { xyz: [x, 0.0, 0.0], rot: Origin::IDENTITY.rot };
        let c = combine(&[(at(0.0), point(1.0)), (at(3.0), point(2.0))]).unwrap();
        assert_eq!(c.mass, 3.0);
        assert_eq!(c.com, [2.0, 0.0, 0.0]);
        // About x = 2: 1·2² + 2·1² = 6 about y and z, 0 about x.
        assert_eq!(c.inertia, [[0.0, 0.0, 0.0], [0.0, 6.0, 0.0], [0.0, 0.0, 6.0]]);
        assert!(combine(&[(at(1.0), point(0.0))]).is_none());
    }
}
