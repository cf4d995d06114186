//! Diagnostics of the URDF front end: each bad input names the offending element's line.

use super::*;

fn err(text: &str) -> (String, usize) {
    let e = parse(text).expect_err("bad input");
    let (line, _) = robovec_ir::span::line_col(text, e.span.start as usize);
    (e.message, line)
}

const HEAD: &str = "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial></link>\n";

#[test]
fn malformed_xml_points_at_the_break() {
    let (msg, line) = err("<robot name=\"r\">\n<link name=\"a\">\n</robot>\n");
    assert!(msg.starts_with("malformed XML"), "{msg}");
    assert_eq!(line, 3);
}

#[test]
fn unknown_parent_link_is_named() {
    let t =
        format!("{HEAD}<joint name=\"j\" type=\"revolute\">\n<parent link=\"zz\"/><child link=\"b\"/></joint></robot>");
    let (msg, line) = err(&t);
    assert_eq!(msg, "parent link `zz` is not defined");
    assert_eq!(line, 5);
}

#[test]
fn missing_child_element() {
    let t = format!("{HEAD}<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/></joint></robot>");
    assert_eq!(err(&t).0, "joint has no `<child>`");
}

#[test]
fn unsupported_joint_types() {
    for ty in ["planar", "floating"] {
        let t =
            format!("{HEAD}<joint name=\"j\" type=\"{ty}\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>");
        assert_eq!(err(&t).0, format!("unsupported joint type `{ty}`"));
    }
}

#[test]
fn two_parents_and_loops() {
    let t = format!(
        "{HEAD}<link name=\"c\"/>\n<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
         <joint name=\"k\" type=\"fixed\"><parent link=\"c\"/><child link=\"b\"/></joint></robot>"
    );
    let (msg, line) = err(&t);
    assert!(msg.starts_with("link `b` has two parents"), "{msg}");
    assert_eq!(line, 6);
    let t = format!(
        "{HEAD}<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
         <joint name=\"k\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>"
    );
    assert!(err(&t).0.contains("loop"));
}

#[test]
fn senseless_mass_and_inertia() {
    let t = "<robot name=\"r\"><link name=\"a\">\n<inertial><mass value=\"-2\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial></link></robot>";
    let (msg, line) = err(t);
    assert_eq!(msg, "negative mass -2");
    assert_eq!(line, 2);
    // ixy² > ixx·iyy: indefinite, as TIAGo's URDF has; used as written (Pinocchio's reader takes
    // it), with a warning at the tensor.
    let t = "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"2\"/>\n<inertia ixx=\"1\" ixy=\"3\" iyy=\"1\" izz=\"1\"/></inertial></link></robot>";
    let p = parse_with_limits(t).expect("used as written");
    assert_eq!(p.robot.links[0].inertial.expect("kept").inertia[0][1], 3.0);
    assert_eq!(p.warnings.len(), 1);
    assert_eq!(p.warnings[0].message, "inertia tensor is not positive semi-definite");
    assert_eq!(robovec_ir::span::line_col(t, p.warnings[0].span.start as usize).0, 2);
    // Rounding noise on massless links' zero tensors (iCub's `ixz="2.40741e-35"`,
    // `ixx="-5.42101e-20"`): warnings too, one per tensor.
    let t = "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"0\"/><inertia ixx=\"0\" ixz=\"2.4e-35\" iyy=\"0\" izz=\"0\"/></inertial></link>\n\
             <link name=\"b\"><inertial><mass value=\"0\"/><inertia ixx=\"-5.4e-20\" iyy=\"-5.4e-20\" izz=\"0\"/></inertial></link>\n\
             <joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>";
    assert_eq!(parse_with_limits(t).expect("used as written").warnings.len(), 2);
    let t = "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"2\"/></inertial></link></robot>";
    assert_eq!(err(t).0, "`<inertial>` has no `<inertia>`");
}

#[test]
fn pinocchio_joint_order_is_depth_first_by_name() {
    // Two branches from the root: joint names sort `a_j` < `b_j`, whatever the file order.
    let t = format!(
        "{HEAD}<link name=\"c\"/><link name=\"d\"/>\n\
         <joint name=\"b_j\" type=\"revolute\"><parent link=\"a\"/><child link=\"c\"/></joint>\n\
         <joint name=\"a_j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
         <joint name=\"a_k\" type=\"revolute\"><parent link=\"b\"/><child link=\"d\"/></joint></robot>"
    );
    let r = parse(&t).expect("valid");
    let names: Vec<&str> = r.dfs_joints().iter().map(|&j| r.joints[j].name.as_str()).collect();
    assert_eq!(names, ["a_j", "a_k", "b_j"]);
}

#[test]
fn every_prefix_and_byte_flip_of_the_example_is_an_error_or_a_valid_module() {
    // Truncations and one-byte corruptions of a real URDF: the front end never panics, every
    // error span lies inside the text, and an accepted module verifies and atomises.
    let text = include_str!("../../../examples/three_link_arm/three_link_arm.urdf");
    let opts = FrontOptions::default();
    let check = |t: &str| match Urdf.load(Path::new("x.urdf"), t, &opts) {
        Err(errs) => {
            assert!(!errs.is_empty());
            assert!(errs.iter().all(|e| e.span.end as usize <= t.len()), "span outside the text");
        }
        Ok(l) => crate::verify_accepted(&l.module).expect("accepted module verifies"),
    };
    let cuts: Vec<usize> = (0..=text.len()).filter(|&i| text.is_char_boundary(i)).step_by(7).collect();
    for i in cuts {
        check(&text[..i]);
    }
    let mut rng = robovec_ir::rng::SplitMix64::new(3);
    let subs = ['-', '0', '<', '"', ' ', 'x', '9', '.'];
    for _ in 0..400 {
        let mut b: Vec<char> = text.chars().collect();
        let at = rng.below(b.len() as u64) as usize;
        b[at] = subs[rng.below(subs.len() as u64) as usize];
        check(&b.into_iter().collect::<String>());
    }
}

/// Issue 47: an axis whose squared length is not a normal binary64 number cannot be normalised
/// (`1e308 0 0` became `0 0 0` and the joint dropped out of the equations); refused at the
/// `xyz` value, as a non-finite number is. A fixed joint's axis is never read.
#[test]
fn an_axis_that_cannot_be_normalised_is_refused_at_its_xyz() {
    let joint = |ty: &str, xyz: &str| {
        format!(
            "{HEAD}<joint name=\"j\" type=\"{ty}\"><parent link=\"a\"/><child link=\"b\"/>\n  <axis xyz=\"{xyz}\"/></joint></robot>"
        )
    };
    for (xyz, what) in [
        ("1e308 0 0", "joint axis cannot be normalised: its squared length overflows in binary64"),
        ("0 -1e200 1e200", "joint axis cannot be normalised: its squared length overflows in binary64"),
        ("1e-200 0 0", "joint axis cannot be normalised: its squared length underflows in binary64"),
        // 1e-160² = 1e-320 is subnormal: its square root is off by far more than an ulp.
        ("0 1e-160 0", "joint axis cannot be normalised: its squared length underflows in binary64"),
        ("0 0 0", "joint axis has length 0"),
        ("-0 0 0", "joint axis has length 0"),
        ("inf 0 0", "attribute `xyz` must hold 3 finite numbers"),
        ("0 nan 1", "attribute `xyz` must hold 3 finite numbers"),
        ("0 0 -1e999", "attribute `xyz` must hold 3 finite numbers"),
    ] {
        for ty in ["revolute", "continuous", "prismatic"] {
            let t = joint(ty, xyz);
            let e = parse(&t).expect_err(xyz);
            assert_eq!(e.message, what, "{ty} {xyz}");
            // The span is the attribute's value: line 5, the column of its first character.
            let at = t.find(&format!("\"{xyz}\"")).unwrap() + 1;
            assert_eq!((e.span.start as usize, e.span.end as usize), (at, at + xyz.len()), "{ty} {xyz}");
        }
        // A fixed joint's axis is not read (a non-finite number is still refused).
        assert_eq!(parse(&joint("fixed", xyz)).is_ok(), !what.starts_with("attribute"), "fixed {xyz}");
    }
    // Large and small axes whose squared length is normal are normalised exactly enough.
    for (xyz, unit) in [
        ("1e154 0 0", [1.0, 0.0, 0.0]),
        ("0 3e-150 4e-150", [0.0, 0.6, 0.8]),
        ("0 0 -2", [0.0, 0.0, -1.0]),
        ("3 4 0", [0.6, 0.8, 0.0]),
    ] {
        let r = parse(&joint("revolute", xyz)).expect(xyz);
        let a = r.joints[0].axis;
        assert!(a.iter().zip(unit).all(|(x, y)| (x - y).abs() <= 4.0 * f64::EPSILON), "{xyz}: {a:?}");
    }
}

/// A single rigid body (a quadrotor's URDF: one link, no joint) has nothing to move on a fixed
/// base: refused at its root link. On a free flyer or a floating base it moves, as in
/// Pinocchio (`buildModelFromUrdf(path, JointModelFreeFlyer())`): its six velocity coordinates.
#[test]
fn a_single_body_moves_only_on_a_moving_base() {
    let t = "<robot name=\"r\">\n<link name=\"a\"><inertial><mass value=\"1.5\"/><inertia ixx=\"1\" iyy=\"2\" izz=\"3\"/></inertial></link></robot>";
    let fixed = FrontOptions::default();
    let errs = Urdf.load(Path::new("x.urdf"), t, &fixed).err().expect("nothing moves");
    assert_eq!(errs[0].message, "robot `r` has no moving joint");
    assert_eq!(robovec_ir::span::line_col(t, errs[0].span.start as usize).0, 2);
    for opts in [
        FrontOptions { free_flyer: true, ..FrontOptions::default() },
        FrontOptions { floating_base: true, ..FrontOptions::default() },
    ] {
        let loaded = Urdf.load(Path::new("x.urdf"), t, &opts).expect("a moving base");
        crate::verify_accepted(&loaded.module).expect("verifies");
        let invdyna = loaded.module.functions.iter().find(|f| f.name == "invdyna").expect("invdyna");
        let torques = invdyna.outputs.iter().filter(|o| o.name.starts_with("Qq[")).count();
        assert_eq!(torques, 6, "six velocity coordinates");
    }
}
