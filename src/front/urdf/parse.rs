//! URDF text → [`Robot`]: the kinematic tree with every number the dynamics needs, checked.
//!
//! XML is read by [`roxmltree`], which keeps the byte range of every element and attribute, so
//! that each diagnostic points at `file:line:col` of the offending element or attribute value.
//! (`urdf-rs` was the other candidate: it deserialises through serde into plain structs and
//! keeps no positions, so its errors could not name a line; its data model is also what this
//! module needs in 200 lines.) Only what the dynamics reads is parsed: `<link>` with
//! `<inertial>` (`origin`, `mass`, `inertia`), `<joint>` with `type`, `parent`, `child`,
//! `origin` and `axis`; visuals, collisions, limits, transmissions and gazebo tags are ignored.

use robovec_ir::Span;

use crate::front::FrontError;

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
fn snap(x: f64) -> f64 {
    if x.abs() < 1e-15 {
        0.0
    } else if (x.abs() - 1.0).abs() < 1e-15 {
        x.signum()
    } else {
        x
    }
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
}

impl Robot {
    /// The joints leaving link `l`, ordered by joint name (byte order): the order urdfdom (and
    /// so `pinocchio.buildModelFromUrdf`) visits them, since it keeps joints in a sorted map.
    pub fn children(&self, l: usize) -> Vec<usize> {
        let mut c: Vec<usize> = (0..self.joints.len()).filter(|&j| self.joints[j].parent == l).collect();
        c.sort_by(|&a, &b| self.joints[a].name.as_bytes().cmp(self.joints[b].name.as_bytes()));
        c
    }

    /// Every joint in depth-first pre-order from the root, children by [`Robot::children`]:
    /// Pinocchio's joint order once the fixed joints are left out. Cost: O(joints · log joints).
    pub fn dfs_joints(&self) -> Vec<usize> {
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); self.links.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            children[joint.parent].push(j);
        }
        for c in &mut children {
            c.sort_by(|&a, &b| self.joints[a].name.as_bytes().cmp(self.joints[b].name.as_bytes()));
        }
        let mut out = Vec::with_capacity(self.joints.len());
        let mut stack: Vec<usize> = children[self.root].iter().rev().copied().collect();
        while let Some(j) = stack.pop() {
            out.push(j);
            stack.extend(children[self.joints[j].child].iter().rev());
        }
        out
    }
}

fn span_of(r: std::ops::Range<usize>) -> Span {
    Span::new(r.start, r.end)
}

/// The byte offset of roxmltree's 1-based row/column (columns count characters).
fn offset_of(text: &str, pos: roxmltree::TextPos) -> usize {
    let mut off = 0;
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if i + 1 == pos.row as usize {
            return off + line.char_indices().nth(pos.col.saturating_sub(1) as usize).map_or(line.len(), |(b, _)| b);
        }
        off += line.len();
    }
    text.len()
}

/// Reads the attribute `name` of `node` as `n` numbers separated by blanks.
fn numbers<const N: usize>(node: roxmltree::Node, name: &str) -> Result<Option<[f64; N]>, FrontError> {
    let Some(a) = node.attribute_node(name) else { return Ok(None) };
    let span = span_of(a.range_value());
    let parts: Vec<&str> = a.value().split_whitespace().collect();
    let bad = || {
        FrontError::new(span, format!("attribute `{name}` must hold {N} finite numbers"), "here")
            .note(format!("found `{}`", a.value()))
    };
    if parts.len() != N {
        return Err(bad());
    }
    let mut out = [0.0; N];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p.parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(bad)?;
    }
    Ok(Some(out))
}

fn origin(node: roxmltree::Node) -> Result<Origin, FrontError> {
    match node.children().find(|c| c.has_tag_name("origin")) {
        None => Ok(Origin::IDENTITY),
        Some(o) => Ok(Origin::from_xyz_rpy(
            numbers::<3>(o, "xyz")?.unwrap_or([0.0; 3]),
            numbers::<3>(o, "rpy")?.unwrap_or([0.0; 3]),
        )),
    }
}

fn required<'a>(node: roxmltree::Node<'a, '_>, name: &str, what: &str) -> Result<&'a str, FrontError> {
    node.attribute(name).ok_or_else(|| {
        FrontError::new(span_of(node.range()), format!("{what} has no `{name}` attribute"), "this element")
    })
}

fn child_elem<'a, 'i>(node: roxmltree::Node<'a, 'i>, tag: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children().find(|c| c.has_tag_name(tag))
}

fn inertial(node: roxmltree::Node) -> Result<Option<Inertial>, FrontError> {
    let Some(i) = child_elem(node, "inertial") else { return Ok(None) };
    let o = origin(i)?;
    let mass_el = child_elem(i, "mass").ok_or_else(|| {
        FrontError::new(span_of(i.range()), "`<inertial>` has no `<mass>`", "this element")
            .note("expected <mass value=\"…\"/>")
    })?;
    let [mass] = numbers::<1>(mass_el, "value")?
        .ok_or_else(|| FrontError::new(span_of(mass_el.range()), "`<mass>` has no `value` attribute", "here"))?;
    if mass < 0.0 {
        let a = mass_el.attribute_node("value").map_or(mass_el.range(), |a| a.range_value());
        return Err(FrontError::new(span_of(a), format!("negative mass {mass}"), "mass must be ≥ 0 kg"));
    }
    let in_el = child_elem(i, "inertia").ok_or_else(|| {
        FrontError::new(span_of(i.range()), "`<inertial>` has no `<inertia>`", "this element")
            .note("expected <inertia ixx=\"…\" ixy=\"…\" ixz=\"…\" iyy=\"…\" iyz=\"…\" izz=\"…\"/>")
    })?;
    let mut v = [0.0; 6];
    for (k, name) in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"].iter().enumerate() {
        v[k] = numbers::<1>(in_el, name)?.map_or(0.0, |[x]| x);
    }
    let [ixx, ixy, ixz, iyy, iyz, izz] = v;
    let m = [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]];
    // Positive semi-definite: Sylvester's criterion on all principal minors (a point mass, or a
    // rod with one zero moment, is accepted; a small tolerance absorbs rounding of the file).
    let tol = 1e-12 * (ixx.abs() + iyy.abs() + izz.abs()).max(f64::MIN_POSITIVE);
    let d2 = |a: usize, b: usize| m[a][a] * m[b][b] - m[a][b] * m[a][b];
    let det = ixx * (iyy * izz - iyz * iyz) - ixy * (ixy * izz - iyz * ixz) + ixz * (ixy * iyz - iyy * ixz);
    let psd = [ixx, iyy, izz].iter().all(|&x| x >= -tol)
        && [d2(0, 1), d2(0, 2), d2(1, 2)].iter().all(|&x| x >= -tol * tol.max(1.0))
        && det >= -tol * tol * tol.max(1.0);
    if !psd {
        return Err(FrontError::new(span_of(in_el.range()), "inertia tensor is not positive definite", "this tensor")
            .note(
                "expected a symmetric positive (semi-)definite tensor: ixx, iyy, izz ≥ 0 and every principal minor ≥ 0",
            ));
    }
    // The tensor in the link frame: R I Rᵀ with the inertial origin's rotation.
    let r = o.rot;
    let mut out = [[0.0; 3]; 3];
    for (a, row) in out.iter_mut().enumerate() {
        for (b, x) in row.iter_mut().enumerate() {
            *x = (0..3).flat_map(|k| (0..3).map(move |l| (k, l))).map(|(k, l)| r[a][k] * m[k][l] * r[b][l]).sum();
        }
    }
    Ok(Some(Inertial { mass, com: o.xyz, inertia: out }))
}

/// Parses and checks a URDF document.
///
/// # Errors
/// The first problem, spanning the offending element or attribute: malformed XML, a root
/// element other than `<robot>`, a joint without `parent`/`child` or naming an unknown link, a
/// link that is the child of two joints, no root link or a loop, a `planar` or `floating` joint
/// (unsupported below the root; a floating base is modelled by the generator, not by a joint),
/// a negative mass, an inertia tensor that is not positive definite, an axis of length 0.
pub fn parse(text: &str) -> Result<Robot, FrontError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let at = offset_of(text, e.pos());
        FrontError::new(Span::new(at, at), format!("malformed XML: {e}"), "here")
    })?;
    let root_el = doc.root_element();
    if !root_el.has_tag_name("robot") {
        return Err(FrontError::new(span_of(root_el.range()), "expected a `<robot>` root element", "this element"));
    }
    let name = root_el.attribute("name").unwrap_or("robot").to_string();
    let mut links: Vec<Link> = Vec::new();
    for l in root_el.children().filter(|c| c.has_tag_name("link")) {
        let n = required(l, "name", "`<link>`")?;
        if links.iter().any(|x| x.name == n) {
            return Err(FrontError::new(
                span_of(l.range()),
                format!("link `{n}` is defined twice"),
                "second definition",
            ));
        }
        links.push(Link { name: n.to_string(), inertial: inertial(l)?, span: span_of(l.range()) });
    }
    let link_index = |node: roxmltree::Node, tag: &str| -> Result<usize, FrontError> {
        let el = child_elem(node, tag).ok_or_else(|| {
            FrontError::new(span_of(node.range()), format!("joint has no `<{tag}>`"), "this joint")
                .note(format!("expected <{tag} link=\"…\"/>"))
        })?;
        let a = el.attribute_node("link").ok_or_else(|| {
            FrontError::new(span_of(el.range()), format!("`<{tag}>` has no `link` attribute"), "here")
        })?;
        links.iter().position(|l| l.name == a.value()).ok_or_else(|| {
            FrontError::new(
                span_of(a.range_value()),
                format!("{tag} link `{}` is not defined", a.value()),
                "unknown link",
            )
        })
    };
    let mut joints: Vec<Joint> = Vec::new();
    for j in root_el.children().filter(|c| c.has_tag_name("joint")) {
        let jname = required(j, "name", "`<joint>`")?;
        let ty = j.attribute_node("type").ok_or_else(|| {
            FrontError::new(span_of(j.range()), format!("joint `{jname}` has no `type`"), "this joint")
        })?;
        let kind = match ty.value() {
            "revolute" | "continuous" => JointKind::Revolute,
            "prismatic" => JointKind::Prismatic,
            "fixed" => JointKind::Fixed,
            other => {
                return Err(FrontError::new(
                    span_of(ty.range_value()),
                    format!("unsupported joint type `{other}`"),
                    "this type",
                )
                .note("expected revolute, continuous, prismatic or fixed (planar and floating joints below the root are not supported)"))
            }
        };
        let parent = link_index(j, "parent")?;
        let child = link_index(j, "child")?;
        if joints.iter().any(|x| x.name == jname) {
            return Err(FrontError::new(
                span_of(j.range()),
                format!("joint `{jname}` is defined twice"),
                "second definition",
            ));
        }
        if let Some(other) = joints.iter().find(|x| x.child == child) {
            return Err(FrontError::new(
                span_of(j.range()),
                format!("link `{}` has two parents (joints `{}` and `{jname}`)", links[child].name, other.name),
                "second parent joint",
            )
            .note("a URDF is a tree: closed loops must be cut"));
        }
        let mut axis = [1.0, 0.0, 0.0];
        if let Some(a) = child_elem(j, "axis") {
            if let Some(v) = numbers::<3>(a, "xyz")? {
                let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if n == 0.0 && kind != JointKind::Fixed {
                    return Err(FrontError::new(span_of(a.range()), "joint axis has length 0", "this axis"));
                }
                // Exact for axes along ±x/±y/±z; others normalised as Pinocchio does.
                axis = if n == 1.0 || n == 0.0 { v } else { [v[0] / n, v[1] / n, v[2] / n] };
            }
        }
        joints.push(Joint {
            name: jname.to_string(),
            kind,
            parent,
            child,
            origin: origin(j)?,
            axis,
            span: span_of(j.range()),
        });
    }
    let roots: Vec<usize> = (0..links.len()).filter(|&l| !joints.iter().any(|j| j.child == l)).collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] if links.is_empty() => {
            return Err(FrontError::new(span_of(root_el.range()), "the robot has no link", "this robot"))
        }
        [] => {
            return Err(FrontError::new(
                span_of(joints[0].span.range()),
                "the joints form a loop: every link is the child of a joint",
                "in this loop",
            )
            .note("a URDF is a tree with one root link: closed loops must be cut"))
        }
        [a, b, ..] => {
            return Err(FrontError::new(
                links[*b].span,
                format!("two root links: `{}` and `{}` are the child of no joint", links[*a].name, links[*b].name),
                "second root",
            )
            .note("a URDF is one tree: connect every link to the root by a joint"))
        }
    };
    let robot = Robot { name, links, joints, root };
    // A loop not through the root leaves its links unreachable from it.
    let seen = robot.dfs_joints();
    if seen.len() != robot.joints.len() {
        let mut reached = vec![false; robot.joints.len()];
        seen.iter().for_each(|&j| reached[j] = true);
        let j = reached.iter().position(|&r| !r).unwrap_or(0);
        return Err(FrontError::new(
            robot.joints[j].span,
            "the joints form a loop not connected to the root link",
            "in this loop",
        )
        .note("a URDF is a tree with one root link: closed loops must be cut"));
    }
    Ok(robot)
}
