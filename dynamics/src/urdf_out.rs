//! A URDF writer for [`Robot`] (issue 14): lets Pinocchio load a robot robovec built itself
//! (the topology families), so the oracle checks them as it checks the shipped URDFs.
//!
//! Numbers are printed with Rust's `{:?}` for `f64`, the shortest text that parses back to the
//! same `f64` (round-trip exact). The rotation of an origin is written as URDF `rpy`
//! (`R = Rz(y)·Ry(p)·Rx(r)`): `p = asin(−R₃₁)`, `r = atan2(R₃₂, R₃₃)`, `y = atan2(R₂₁, R₁₁)`
//! (away from gimbal lock; at `|R₃₁| = 1`, `r = 0` and `y = atan2(−R₁₂, R₂₂)`). The rotation
//! read back may thus differ from `rot` by a few ulp; the identity and quarter turns whose
//! entries are exact 0/±1 come back exact after [`Origin::from_xyz_rpy`]'s snapping.
//! Inertia is written in the link frame (identity `<inertial>` rotation).

use super::robot::{JointKind, Origin, Robot};
use std::fmt::Write;

/// The URDF text of `robot`: one `<link>` per link (with `<inertial>` when it has one), one
/// `<joint>` per joint (`revolute` with no limits is written as `continuous`).
pub fn write_urdf(robot: &Robot) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>\n<robot name=\"{}\">", xml_escape(&robot.name));
    for link in &robot.links {
        match &link.inertial {
            None => {
                let _ = writeln!(s, "  <link name=\"{}\"/>", xml_escape(&link.name));
            }
            Some(i) => {
                let _ = writeln!(s, "  <link name=\"{}\">\n    <inertial>", xml_escape(&link.name));
                let _ = writeln!(s, "      <origin xyz=\"{}\" rpy=\"0 0 0\"/>", triple(i.com));
                let _ = writeln!(s, "      <mass value=\"{:?}\"/>", i.mass);
                let t = &i.inertia;
                let _ = writeln!(
                    s,
                    "      <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>",
                    t[0][0], t[0][1], t[0][2], t[1][1], t[1][2], t[2][2]
                );
                let _ = writeln!(s, "    </inertial>\n  </link>");
            }
        }
    }
    for j in &robot.joints {
        let kind = match j.kind {
            JointKind::Revolute => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
            // URDF's spelling of a six-degree-of-freedom joint (robovec reads the URDF back
            // without it and adds it with `--free-flyer`).
            JointKind::FreeFlyer => "floating",
        };
        let _ = writeln!(s, "  <joint name=\"{}\" type=\"{kind}\">", xml_escape(&j.name));
        let _ = writeln!(s, "    <parent link=\"{}\"/>", xml_escape(&robot.links[j.parent].name));
        let _ = writeln!(s, "    <child link=\"{}\"/>", xml_escape(&robot.links[j.child].name));
        let _ = writeln!(s, "    <origin xyz=\"{}\" rpy=\"{}\"/>", triple(j.origin.xyz), triple(rpy(&j.origin)));
        if matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) {
            let _ = writeln!(s, "    <axis xyz=\"{}\"/>", triple(j.axis));
        }
        if j.kind == JointKind::Prismatic {
            let _ = writeln!(s, "    <limit lower=\"-1e9\" upper=\"1e9\" effort=\"0\" velocity=\"0\"/>");
        }
        let _ = writeln!(s, "  </joint>");
    }
    s.push_str("</robot>\n");
    s
}

/// URDF roll-pitch-yaw (radians) of `o.rot` (see the module doc).
pub fn rpy(o: &Origin) -> [f64; 3] {
    let r = &o.rot;
    if r[2][0].abs() >= 1.0 {
        let p = -r[2][0].signum() * std::f64::consts::FRAC_PI_2;
        [0.0, p, (-r[0][1]).atan2(r[1][1])]
    } else {
        [r[2][1].atan2(r[2][2]), (-r[2][0]).asin(), r[1][0].atan2(r[0][0])]
    }
}

fn triple(v: [f64; 3]) -> String {
    format!("{:?} {:?} {:?}", v[0], v[1], v[2])
}

/// `s` as an XML attribute value: markup characters escaped, and tab, newline and carriage
/// return as character references, which XML keeps in attribute values (written as they are,
/// a reader normalises them to spaces; issue 29: a name with a newline came back changed).
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' | '\n' | '\r' => out.push_str(&format!("&#{};", c as u32)),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_round_trips_through_from_xyz_rpy() {
        for rpy0 in [[0.0, 0.0, 0.0], [0.3, -0.7, 1.1], [std::f64::consts::FRAC_PI_2, 0.0, 0.0], [0.2, 0.0, -2.5]] {
            let o = Origin::from_xyz_rpy([0.0; 3], rpy0);
            let back = Origin::from_xyz_rpy([0.0; 3], rpy(&o));
            for i in 0..3 {
                for k in 0..3 {
                    assert!((o.rot[i][k] - back.rot[i][k]).abs() < 1e-14, "{rpy0:?}");
                }
            }
        }
    }

    #[test]
    fn attribute_values_keep_markup_and_line_breaks() {
        assert_eq!(xml_escape("a<b>&\"c\"\nd\te\r"), "a&lt;b&gt;&amp;&quot;c&quot;&#10;d&#9;e&#13;");
    }

    #[test]
    fn numbers_are_written_round_trip_exact() {
        assert_eq!(triple([0.1, 1.0 / 3.0, -0.0]), "0.1 0.3333333333333333 -0.0");
    }
}
