//! URDF text → [`Robot`]: the kinematic tree with every number the dynamics needs, checked.
//!
//! XML is read by [`roxmltree`], which keeps the byte range of every element and attribute, so
//! that each diagnostic points at `file:line:col` of the offending element or attribute value.
//! (`urdf-rs` was the other candidate: it deserialises through serde into plain structs and
//! keeps no positions, so its errors could not name a line; its data model is also what this
//! module needs in 200 lines.) Only what the dynamics reads is parsed: `<link>` with
//! `<inertial>` (`origin`, `mass`, `inertia`), `<joint>` with `type`, `parent`, `child`,
//! `origin` and `axis`; `<limit>` is read by [`parse_with_limits`] for the input domain's defaults (issue 48); visuals,
//! collisions, transmissions and gazebo tags are ignored.

use robovec_ir::Span;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::FrontError;
use robovec_dynamics::robot::{rotate_tensor, Inertial, Joint, JointKind, Link, Origin, Robot};

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

fn inertial(node: roxmltree::Node, warnings: &mut Vec<FrontError>) -> Result<Option<Inertial>, FrontError> {
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
    // Not physical, but Pinocchio's reader takes it as written, and example-robot-data's robots
    // have such tensors (TIAGo's `ixy² > ixx·iyy`, iCub's `ixx="-5.42101e-20"`, rounding noise
    // on massless links): used as written, with a warning.
    if !psd {
        warnings.push(
            FrontError::new(span_of(in_el.range()), "inertia tensor is not positive semi-definite", "this tensor")
                .note("a principal minor is negative: no rigid body has this tensor")
                .note("used as written, as Pinocchio's URDF reader does"),
        );
    }
    // The tensor in the link frame: R I Rᵀ with the inertial origin's rotation.
    Ok(Some(Inertial { mass, com: o.xyz, inertia: rotate_tensor(&o.rot, &m) }))
}

/// The unit vector of a joint's `<axis xyz="…">` (`v`, finite numbers), normalised as
/// Pinocchio does (exact for axes along ±x/±y/±z). A fixed joint's axis is never read: it is
/// kept as given when it cannot be normalised.
///
/// # Errors
/// For a moving joint, spanning the `xyz` value: an axis of length 0, and an axis whose
/// squared length `x² + y² + z²` is not a normal finite number — it overflows (`1e308 0 0`:
/// the division by an infinite length made the axis `0 0 0`, and the joint dropped out of
/// the equations, issue 47) or underflows to a subnormal number or 0 (`1e-200 0 0`), so the
/// length and the normalised components would be wrong or not finite.
fn unit_axis(v: [f64; 3], kind: JointKind, el: roxmltree::Node) -> Result<[f64; 3], FrontError> {
    let squared = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let n = squared.sqrt();
    let unit = [v[0] / n, v[1] / n, v[2] / n];
    let normal = squared.is_normal() && unit.iter().all(|x| x.is_finite());
    if kind == JointKind::Fixed {
        return Ok(if normal && n != 1.0 { unit } else { v });
    }
    if normal {
        return Ok(if n == 1.0 { v } else { unit });
    }
    let span = el.attribute_node("xyz").map_or(el.range(), |a| a.range_value());
    let e = if v == [0.0; 3] {
        FrontError::new(span_of(span), "joint axis has length 0", "this axis")
    } else {
        let why = if squared.is_infinite() { "overflows" } else { "underflows" };
        FrontError::new(
            span_of(span),
            format!("joint axis cannot be normalised: its squared length {why} in binary64"),
            "this axis",
        )
        .note(format!(
            "found `{}`; expected a direction whose squared length x² + y² + z² is a normal number \
             (between {:e} and {:e}), such as `0 0 1`",
            el.attribute("xyz").unwrap_or_default(),
            f64::MIN_POSITIVE,
            f64::MAX
        ))
    };
    Err(e)
}

/// A joint's `<limit>` (issue 48): the ranges its coordinate, velocity and effort default to
/// (radians or metres; rad/s or m/s; N·m or N). A bound is `None` when the element does not
/// state it — or states a placeholder: `velocity="0"` or `effort="0"` (a joint that cannot
/// move or act would be fixed; writers put 0 where they know no limit), `lower` = `upper`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Limit {
    /// `[lower, upper]`, when both are given and `lower < upper`.
    pub position: Option<(f64, f64)>,
    /// `velocity`, when positive.
    pub velocity: Option<f64>,
    /// `effort`, when positive.
    pub effort: Option<f64>,
}

/// Reads a joint's `<limit>`, if it has one.
///
/// # Errors
/// A bound that is not a finite number, a negative `velocity` or `effort`, `lower > upper`;
/// at the attribute.
fn limit(j: roxmltree::Node) -> Result<Option<Limit>, FrontError> {
    let Some(l) = child_elem(j, "limit") else { return Ok(None) };
    let one = |name: &str| numbers::<1>(l, name).map(|x| x.map(|[x]| x));
    let at = |name: &str| span_of(l.attribute_node(name).map_or(l.range(), |a| a.range_value()));
    let (lower, upper) = (one("lower")?, one("upper")?);
    let (velocity, effort) = (one("velocity")?, one("effort")?);
    for (name, x) in [("velocity", velocity), ("effort", effort)] {
        if x.is_some_and(|x| x < 0.0) {
            return Err(FrontError::new(at(name), format!("negative {name} limit"), "here")
                .note(format!("expected a {name} limit >= 0 (the joint's range is [-{name}, {name}])")));
        }
    }
    if let (Some(lo), Some(hi)) = (lower, upper) {
        if lo > hi {
            return Err(FrontError::new(
                at("lower"),
                format!("joint limit lower = {lo} is above upper = {hi}"),
                "here",
            )
            .note("expected lower <= upper"));
        }
    }
    Ok(Some(Limit {
        position: lower.zip(upper).filter(|(lo, hi)| lo < hi),
        velocity: velocity.filter(|&v| v > 0.0),
        effort: effort.filter(|&e| e > 0.0),
    }))
}

/// Parses and checks a URDF document.
///
/// # Errors
/// The first problem, spanning the offending element or attribute: malformed XML, a root
/// element other than `<robot>`, a joint without `parent`/`child` or naming an unknown link, a
/// link that is the child of two joints, no root link or a loop, a `planar` or `floating` joint
/// (unsupported below the root; a floating base is modelled by the generator, not by a joint),
/// a negative mass, a non-finite number, an
/// axis of length 0 or whose squared length overflows or underflows.
///
/// Cost: linear in the text (names are found through hash maps, issue 28: a 20,000-link
/// star spent 2 s comparing names).
pub fn parse(text: &str) -> Result<Robot, FrontError> {
    parse_with_limits(text).map(|p| p.robot)
}

/// What [`parse_with_limits`] reads from a URDF.
pub struct Parsed {
    /// The tree.
    pub robot: Robot,
    /// The `<limit>` of each joint that has one, by joint name.
    pub limits: FxHashMap<String, Limit>,
    /// What is read but suspect, in file order: an inertia tensor that is not positive
    /// semi-definite (kept as written).
    pub warnings: Vec<FrontError>,
}

/// [`parse`], with the `<limit>` of each joint that has one, by joint name (issue 48: the
/// defaults of the input domain), and the warnings. A `<limit>` is checked ([`Limit`])
/// whatever the joint's type.
///
/// # Errors
/// As [`parse`], and a `<limit>` bound that is not a finite number, a negative velocity or
/// effort, a lower bound above the upper one.
pub fn parse_with_limits(text: &str) -> Result<Parsed, FrontError> {
    let mut limits = FxHashMap::default();
    let mut warnings = Vec::new();
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
    let mut link_of: FxHashMap<&str, usize> = FxHashMap::default();
    for l in root_el.children().filter(|c| c.has_tag_name("link")) {
        let n = required(l, "name", "`<link>`")?;
        if link_of.insert(n, links.len()).is_some() {
            return Err(FrontError::new(
                span_of(l.range()),
                format!("link `{n}` is defined twice"),
                "second definition",
            ));
        }
        links.push(Link { name: n.to_string(), inertial: inertial(l, &mut warnings)?, span: span_of(l.range()) });
    }
    let link_index = |node: roxmltree::Node, tag: &str| -> Result<usize, FrontError> {
        let el = child_elem(node, tag).ok_or_else(|| {
            FrontError::new(span_of(node.range()), format!("joint has no `<{tag}>`"), "this joint")
                .note(format!("expected <{tag} link=\"…\"/>"))
        })?;
        let a = el.attribute_node("link").ok_or_else(|| {
            FrontError::new(span_of(el.range()), format!("`<{tag}>` has no `link` attribute"), "here")
        })?;
        link_of.get(a.value()).copied().ok_or_else(|| {
            FrontError::new(
                span_of(a.range_value()),
                format!("{tag} link `{}` is not defined", a.value()),
                "unknown link",
            )
        })
    };
    let mut joints: Vec<Joint> = Vec::new();
    let mut joint_names: FxHashSet<&str> = FxHashSet::default();
    // The first joint whose child each link is.
    let mut parent_joint: Vec<Option<usize>> = vec![None; links.len()];
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
        if !joint_names.insert(jname) {
            return Err(FrontError::new(
                span_of(j.range()),
                format!("joint `{jname}` is defined twice"),
                "second definition",
            ));
        }
        if let Some(other) = parent_joint[child].map(|k| &joints[k]) {
            return Err(FrontError::new(
                span_of(j.range()),
                format!("link `{}` has two parents (joints `{}` and `{jname}`)", links[child].name, other.name),
                "second parent joint",
            )
            .note("a URDF is a tree: closed loops must be cut"));
        }
        parent_joint[child] = Some(joints.len());
        if let Some(l) = limit(j)? {
            limits.insert(jname.to_string(), l);
        }
        let mut axis = [1.0, 0.0, 0.0];
        if let Some(a) = child_elem(j, "axis") {
            if let Some(v) = numbers::<3>(a, "xyz")? {
                axis = unit_axis(v, kind, a)?;
            }
        }
        joints.push(Joint {
            name: jname.to_string(),
            kind,
            parent,
            child,
            origin: origin(j)?,
            axis,
            offset: 0.0,
            rank: 0,
            continuous: ty.value() == "continuous",
            span: span_of(j.range()),
        });
    }
    let roots: Vec<usize> = (0..links.len()).filter(|&l| parent_joint[l].is_none()).collect();
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
    let robot = Robot { name, links, joints, root, cos_sin: false };
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
    Ok(Parsed { robot, limits, warnings })
}
