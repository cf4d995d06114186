//! The robot the symbolic generator reads: a kinematic tree of links and joints with every
//! number the dynamics needs (issue 14). Front ends build it — the URDF front end
//! (`robovec_front::urdf`, a crate above this one) and the study's topology families
//! ([`crate::topology`]) — and the generator ([`crate::generate`]) writes its equations; the
//! generator depends on no input format.

use robovec_ir::Span;

/// A rigid transform given as URDF's `<origin xyz="…" rpy="…"/>`: translation (m) and the
/// rotation `R = Rz(yaw)·Ry(pitch)·Rx(roll)` (URDF's fixed-axis roll-pitch-yaw), as a row-major
/// 3×3 matrix mapping child coordinates to parent coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    /// Translation `xyz`, metres.
    pub xyz: [f64; 3],
    /// Rotation matrix `R` (row-major), child → parent.
    pub rot: [[f64; 3]; 3],
}

impl Origin {
    /// The identity transform (an absent `<origin>`).
    pub const IDENTITY: Origin = Origin { xyz: [0.0; 3], rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] };

    /// From `xyz` and `rpy` (radians). Angles of exactly 0 give exact 0/1 entries; entries
    /// within 1e-15 of 0 or ±1 (the rounding noise of `cos(π/2)` = 6·10⁻¹⁷ for a quarter turn
    /// written as `1.5707963267948966`) are snapped to it, so that quarter turns fold as
    /// structural zeros and ones, as Robotran's exact rotations do. The change is below 10⁻¹⁵
    /// of the entry, far under the 10⁻¹⁰ agreement with Pinocchio the tests ask.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Origin {
        let (sr, cr) = rpy[0].sin_cos();
        let (sp, cp) = rpy[1].sin_cos();
        let (sy, cy) = rpy[2].sin_cos();
        let rot = [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
        .map(|row| row.map(snap));
        Origin { xyz, rot }
    }
}

/// `x` snapped to 0 or ±1 when within 1e-15 of it (see [`Origin::from_xyz_rpy`]).
pub(super) fn snap(x: f64) -> f64 {
    if x.abs() < 1e-15 {
        0.0
    } else if (x.abs() - 1.0).abs() < 1e-15 {
        x.signum()
    } else {
        x
    }
}

/// `R·T·Rᵀ`: a tensor `T` (an inertia) given in a frame turned by `R` into the frame `R` maps
/// to (both 3×3, row-major).
pub fn rotate_tensor(r: &[[f64; 3]; 3], t: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for (a, row) in out.iter_mut().enumerate() {
        for (b, x) in row.iter_mut().enumerate() {
            *x = (0..3).flat_map(|k| (0..3).map(move |l| (k, l))).map(|(k, l)| r[a][k] * t[k][l] * r[b][l]).sum();
        }
    }
    out
}

/// The mass properties of a link (URDF `<inertial>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertial {
    /// Mass, kg (≥ 0).
    pub mass: f64,
    /// Centre of mass in the link frame, m.
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass **in the link frame** (the `<inertial>` origin's
    /// rotation applied), kg·m², row-major, symmetric positive (semi-)definite.
    pub inertia: [[f64; 3]; 3],
}

/// A joint type robovec's generator handles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// `revolute` (limits ignored) or `continuous`: rotation about `axis` by `q`.
    Revolute,
    /// `prismatic`: translation along `axis` by `q`.
    Prismatic,
    /// `fixed`: no degree of freedom.
    Fixed,
    /// Pinocchio's `JointModelFreeFlyer` (the root joint of `--free-flyer`,
    /// [`Robot::with_free_flyer`]): the child's pose in the parent (the world) as 7 configuration
    /// coordinates — position (m), then the unit quaternion `(x, y, z, w)` — and its velocity as 6
    /// — linear (m/s), then angular (rad/s), both in the child's frame. Only as the root joint,
    /// from a fixed world; `axis` and `origin` are unused (identity).
    FreeFlyer,
}

impl JointKind {
    /// Velocity coordinates (`qd`, `qdd`, `Qq`, rows of `M`) of the joint: 0, 1 or 6.
    pub fn nv(self) -> usize {
        match self {
            JointKind::Fixed => 0,
            JointKind::Revolute | JointKind::Prismatic => 1,
            JointKind::FreeFlyer => 6,
        }
    }

    /// Configuration coordinates (`q`) of the joint: 0, 1 or 7.
    pub fn nq(self) -> usize {
        match self {
            JointKind::FreeFlyer => 7,
            k => k.nv(),
        }
    }
}

/// One joint of the tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The URDF name.
    pub name: String,
    /// Its type.
    pub kind: JointKind,
    /// Index of the parent link in [`Robot::links`].
    pub parent: usize,
    /// Index of the child link in [`Robot::links`].
    pub child: usize,
    /// Child joint frame in the parent link frame.
    pub origin: Origin,
    /// Unit axis in the joint (= child link) frame (URDF default `1 0 0`).
    pub axis: [f64; 3],
    /// A revolute joint turns its child by `q + offset` (radians): 0 as read from a URDF; set
    /// by the generator's choice of body frames ([`crate::frames`]).
    pub offset: f64,
    /// Where the joint goes among its parent link's children: by `(rank, name)`. 0 as read from
    /// a URDF (urdfdom's name order); [`crate::lump::contract_fixed`] sets every joint's to its
    /// place in the original walk, so that joints moved up past a removed fixed joint keep it.
    pub rank: usize,
    /// A URDF `continuous` joint (a [`JointKind::Revolute`] without limits): with
    /// [`Robot::cos_sin`], its configuration is Pinocchio's `(cos q, sin q)` pair.
    pub continuous: bool,
    /// The `<joint>` element.
    pub span: Span,
}

/// One link.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    /// The URDF name.
    pub name: String,
    /// Mass properties; `None` when the link has no `<inertial>` (massless).
    pub inertial: Option<Inertial>,
    /// The `<link>` element.
    pub span: Span,
}

/// A checked URDF tree: one root link, every other link the child of exactly one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Robot {
    /// `<robot name>`.
    pub name: String,
    /// Links in file order.
    pub links: Vec<Link>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// The root link (child of no joint).
    pub root: usize,
    /// `--continuous=cos-sin`: every [`Joint::continuous`] joint takes two configuration
    /// coordinates, `q[i] = cos θ` and `q[i + 1] = sin θ`, as Pinocchio's
    /// `JointModelRevoluteUnbounded` (`nq = 2`, `nv = 1`), instead of the angle `θ`; the
    /// equations read them as the trig variables (no `sin`/`cos` call). Not normalised: the
    /// caller's job, as in Pinocchio.
    pub cos_sin: bool,
}

impl Robot {
    /// The joints leaving link `l`, ordered by joint name (byte order): the order urdfdom (and
    /// so `pinocchio.buildModelFromUrdf`) visits them, since it keeps joints in a sorted map.
    pub fn children(&self, l: usize) -> Vec<usize> {
        let mut c: Vec<usize> = (0..self.joints.len()).filter(|&j| self.joints[j].parent == l).collect();
        c.sort_by(|&a, &b| self.joint_order(a, b));
        c
    }

    /// The root segment, per link: the root and every link whose joints up to the root all have
    /// no offset and no constant rotation, with no prismatic joint below a revolute one
    /// (Robotran's floating base `T1 T2 T3 R1 R2 R3`). Their joints all act at one point: the
    /// CRBA projects column forces there ([`crate::crba`]) and [`crate::origins`]
    /// leaves them in place. Cost: O(joints · log joints).
    pub fn root_segment(&self) -> Vec<bool> {
        let mut in_segment = vec![false; self.links.len()];
        let mut revolute_above = vec![false; self.links.len()];
        in_segment[self.root] = true;
        for j in self.dfs_joints() {
            let jo = &self.joints[j];
            // A free flyer's child is no part of it: the base's velocity is in its own frame,
            // whose six coordinates the CRBA writes as one block, not by projection.
            let plain =
                jo.origin.xyz == [0.0; 3] && jo.origin.rot == Origin::IDENTITY.rot && jo.kind != JointKind::FreeFlyer;
            in_segment[jo.child] =
                in_segment[jo.parent] && plain && !(jo.kind == JointKind::Prismatic && revolute_above[jo.parent]);
            revolute_above[jo.child] = revolute_above[jo.parent] || jo.kind == JointKind::Revolute;
        }
        in_segment
    }

    /// The order of two sibling joints: by [`Joint::rank`], then by name (byte order).
    fn joint_order(&self, a: usize, b: usize) -> std::cmp::Ordering {
        let (a, b) = (&self.joints[a], &self.joints[b]);
        a.rank.cmp(&b.rank).then_with(|| a.name.as_bytes().cmp(b.name.as_bytes()))
    }

    /// Every joint in depth-first pre-order from the root, children by [`Robot::children`]:
    /// Pinocchio's joint order once the fixed joints are left out. Cost: O(joints · log joints).
    pub fn dfs_joints(&self) -> Vec<usize> {
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); self.links.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            children[joint.parent].push(j);
        }
        for c in &mut children {
            c.sort_by(|&a, &b| self.joint_order(a, b));
        }
        let mut out = Vec::with_capacity(self.joints.len());
        let mut stack: Vec<usize> = children[self.root].iter().rev().copied().collect();
        while let Some(j) = stack.pop() {
            out.push(j);
            stack.extend(children[self.joints[j].child].iter().rev());
        }
        out
    }

    /// The body of every link (length: the links) for the depth-first joint order `order`
    /// ([`Robot::dfs_joints`]): body `i + 1` is the child link of `order[i]`, body 0 the root
    /// link (the base).
    pub fn link_bodies(&self, order: &[usize]) -> Vec<usize> {
        let mut link_body = vec![0; self.links.len()];
        for (i, &j) in order.iter().enumerate() {
            link_body[self.joints[j].child] = i + 1;
        }
        link_body
    }

    /// The parent body of every body of `order` ([`Robot::link_bodies`]'s numbering; length
    /// `order.len() + 1`, entry 0 the base's, 0).
    pub fn body_parents(&self, order: &[usize]) -> Vec<usize> {
        let link_body = self.link_bodies(order);
        std::iter::once(0).chain(order.iter().map(|&j| link_body[self.joints[j].parent])).collect()
    }
}

impl Robot {
    /// The name and element of the first joint (named as `joint` accepts) or link (as `link`
    /// accepts) in the file's order: a name a base the generator adds would clash with.
    fn first_named(&self, joint: impl Fn(&str) -> bool, link: impl Fn(&str) -> bool) -> Option<(String, Span)> {
        self.joints
            .iter()
            .filter(|j| joint(&j.name))
            .map(|j| (&j.name, j.span))
            .chain(self.links.iter().filter(|l| link(&l.name)).map(|l| (&l.name, l.span)))
            .min_by_key(|(_, span)| span.start)
            .map(|(name, span)| (name.clone(), span))
    }
}

/// The names of Robotran's six floating-base joints, in chain order (`q[1..6]`).
pub const FLOATING_BASE: [&str; 6] = ["T1", "T2", "T3", "R1", "R2", "R3"];

impl Robot {
    /// `self` on a floating base as Robotran models it: six joints between a new fixed root
    /// link `world` and the old root, `T1`, `T2`, `T3` (prismatic along x, y, z) then `R1`,
    /// `R2`, `R3` (revolute about x, then the new y, then the new z), joined by massless links
    /// `T1_link` … `R2_link`; the old root is the child of `R3`. These joints are `q[1..6]`
    /// and the URDF's moving joints follow from `q[7]`. Pinocchio's model of the same
    /// coordinates is `buildModelFromUrdf(path, JointModelComposite([PX, PY, PZ, RX, RY, RZ]))`.
    ///
    /// # Errors
    /// The name and the element (`<joint>` or `<link>` span) of the first URDF joint or link, in
    /// the file's order, whose name clashes with the names above.
    pub fn with_floating_base(mut self) -> Result<Robot, (String, Span)> {
        let reserved: Vec<String> = FLOATING_BASE
            .iter()
            .flat_map(|j| [j.to_string(), format!("{j}_link")])
            .chain(["world".to_string()])
            .collect();
        if let Some(clash) = self.first_named(|n| reserved.iter().any(|r| r == n), |n| reserved.iter().any(|r| r == n))
        {
            return Err(clash);
        }
        let old_root = self.root;
        let span = self.links[old_root].span;
        self.links.push(Link { name: "world".into(), inertial: None, span });
        let mut parent = self.links.len() - 1;
        self.root = parent;
        for (k, name) in FLOATING_BASE.iter().enumerate() {
            let child = if k == 5 {
                old_root
            } else {
                self.links.push(Link { name: format!("{name}_link"), inertial: None, span });
                self.links.len() - 1
            };
            let mut axis = [0.0; 3];
            axis[k % 3] = 1.0;
            let kind = if k < 3 { JointKind::Prismatic } else { JointKind::Revolute };
            self.joints.push(Joint {
                name: (*name).into(),
                kind,
                parent,
                child,
                origin: Origin::IDENTITY,
                axis,
                offset: 0.0,
                rank: 0,
                continuous: false,
                span,
            });
            parent = child;
        }
        Ok(self)
    }
}

/// The name of the free flyer's joint (Pinocchio's `root_joint`) and of the fixed link above it
/// (Pinocchio's `universe`), [`Robot::with_free_flyer`].
pub const FREE_FLYER: [&str; 2] = ["root_joint", "universe"];

impl Robot {
    /// `self` on Pinocchio's free-flyer base (`JointModelFreeFlyer`, `--free-flyer`): a new fixed
    /// root link `universe` and the joint `root_joint` of kind [`JointKind::FreeFlyer`] from it
    /// to the old root, whose mass now counts. The joint is body 1 and takes `q[1..7]` (position,
    /// quaternion `x, y, z, w`) and `qd[1..6]`, `qdd[1..6]`, `Qq[1..6]` (linear, then angular, in
    /// the base frame); the URDF's moving joints follow from `q[8]` and `qd[7]`. Pinocchio's model
    /// is `buildModelFromUrdf(path, JointModelFreeFlyer())`, with the same numbering.
    ///
    /// # Errors
    /// The name and the element of the first URDF joint or link, in the file's order, whose name
    /// is `root_joint` (a joint) or `universe` (a link).
    pub fn with_free_flyer(mut self) -> Result<Robot, (String, Span)> {
        if let Some(clash) = self.first_named(|n| n == FREE_FLYER[0], |n| n == FREE_FLYER[1]) {
            return Err(clash);
        }
        let old_root = self.root;
        let span = self.links[old_root].span;
        self.links.push(Link { name: FREE_FLYER[1].into(), inertial: None, span });
        self.root = self.links.len() - 1;
        self.joints.push(Joint {
            name: FREE_FLYER[0].into(),
            kind: JointKind::FreeFlyer,
            parent: self.root,
            child: old_root,
            origin: Origin::IDENTITY,
            axis: [0.0; 3],
            offset: 0.0,
            rank: 0,
            continuous: false,
            span,
        });
        Ok(self)
    }
}
