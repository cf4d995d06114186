//! `-time-limit` covers loading (issue 28 item 3): the deadline starts before the input is
//! read, the Robotran front ends check it in their statement loops and the URDF generator per
//! body, and a load that reaches it ends the run with one located error, exit 1 and nothing
//! written (no pass can run on part of a module). The limits are far below what the inputs
//! need, so the outcome does not depend on the machine's speed: the checks are structural
//! (where the load stopped), never times.

use robovec_dynamics::topology::{build, Topology};

use crate::common::{opt, stderr, tmp};

/// A Robotran Matlab `dirdyna` of `n` straight-line statements, each reading the previous.
fn matlab(n: usize) -> String {
    let mut t = String::from("function [M,c] = dirdyna(s,tsim,usrfun)\n\nq = s.q;\nqd = s.qd;\n\n  C1 = cos(q(1));\n");
    t += "  T1 = s.dpt(1,2)*C1+qd(1);\n";
    for k in 2..=n {
        t += &format!("  T{k} = T{}*C1+s.dpt(1,{})*(T{}-qd(2));\n", k - 1, k % 9 + 1, k - 1);
    }
    t += &format!("  c(1) = T{n};\n\nend\n");
    t
}

/// The same in Robotran Python.
fn python(n: usize) -> String {
    let mut t = String::from(
        "import numpy as np\n\ndef dirdyna(M, c, s, tsim):\n  q = s.q\n  qd = s.qd\n  C1 = np.cos(q[1])\n",
    );
    t += "  T1 = s.dpt[1,2]*C1+qd[1]\n";
    for k in 2..=n {
        t += &format!("  T{k} = T{}*C1+s.dpt[1,{}]*(T{}-qd[2])\n", k - 1, k % 9 + 1, k - 1);
    }
    t += &format!("  c[1] = T{n}\n");
    t
}

/// `(line reached, lines)` from `time limit of … reached while reading (line N of M)`.
fn stopped_at(err: &str) -> (usize, usize) {
    let rest = err.split("reached while reading (line ").nth(1).unwrap_or_else(|| panic!("no time-out: {err}"));
    let (n, rest) = rest.split_once(" of ").expect("N of M");
    let m = rest.split(')').next().expect("M)");
    (n.parse().expect("N"), m.parse().expect("M"))
}

/// Runs `robovec-opt FILE -passes=atomise -time-limit=LIMIT -o OUT` and checks the refusal:
/// exit 1, the time-out error, no output file. Returns stderr.
fn refused(file: &std::path::Path, limit: &str, extra: &[&str]) -> String {
    let out = file.with_extension("rvir");
    let mut args = vec![file.to_str().unwrap(), "-passes=atomise", limit, "-o", out.to_str().unwrap()];
    args.extend(extra);
    let o = opt(&args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("-time-limit covers loading too"), "{e}");
    assert!(!out.exists(), "nothing is written");
    e
}

#[test]
fn a_robotran_file_stops_at_the_first_check_past_the_limit() {
    let d = tmp("first_check");
    let c = robovec_front::synth::straight_line_c(robovec_front::synth::Shape::many_outputs(400_000)).text;
    for (name, text) in [("f.m", matlab(6000)), ("f.py", python(6000)), ("f.c", c)] {
        let file = d.join(name);
        std::fs::write(&file, &text).unwrap();
        let e = refused(&file, "-time-limit=0.000001", &[]);
        assert!(e.contains("error: time limit of 0.000001 s reached while reading (line "), "{name}: {e}");
        // The clock is read every 1024 tokens: the load stopped within the first ones.
        let (line, lines) = stopped_at(&e);
        assert_eq!(lines, text.lines().count(), "{name}");
        assert!(line * 10 < lines, "{name}: stopped at line {line} of {lines}");
        assert!(e.contains(&format!("{name}:{line}:")), "{name}: located: {e}");
        // Without the limit the same file loads.
        let o = opt(&[file.to_str().unwrap(), "-passes=", "-o", "/dev/null"]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
}

/// A limit reached in the middle of a long read (this Matlab file takes seconds to read in a
/// debug build, 0.2 s is a fraction of it): the load stops partway, not at the end.
#[test]
fn a_long_read_stops_partway() {
    let d = tmp("partway");
    let file = d.join("long.m");
    std::fs::write(&file, matlab(150_000)).unwrap();
    let e = refused(&file, "-time-limit=0.2", &[]);
    let (line, lines) = stopped_at(&e);
    assert!(line < lines, "stopped at line {line} of {lines}");
}

#[test]
fn a_urdf_stops_at_a_body_of_the_generator() {
    let d = tmp("urdf");
    let file = d.join("star.urdf");
    std::fs::write(&file, robovec_dynamics::urdf_out::write_urdf(&build(Topology::Star, 300, 2))).unwrap();
    // invdyna first: its forward sweep checks at body 1.
    let e = refused(&file, "-time-limit=0.000001", &[]);
    assert!(e.contains("error: time limit of 0.000001 s reached while generating @invdyna (body 1 of 300)"), "{e}");
    // dirdyna alone: its composites go leaves to root, from the last body; the error points at
    // that body's `<joint>` (the file's last element but the closing tag).
    let e = refused(&file, "-time-limit=0.000001", &["-function=dirdyna"]);
    assert!(e.contains("reached while generating @dirdyna (body 300 of 300)"), "{e}");
    let text = std::fs::read_to_string(&file).unwrap();
    let joint_line = text.lines().position(|l| l.contains("<joint name=\"j300\"")).expect("joint j300") + 1;
    assert!(e.contains(&format!("star.urdf:{joint_line}:")), "{e}");
    assert!(opt(&[file.to_str().unwrap(), "-passes=atomise", "-o", "/dev/null"]).status.success());
}
