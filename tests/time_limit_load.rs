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

/// `robovec-opt` with `args`, stdin from `stdin`; its output and wall time.
fn timed(args: &[&str], stdin: std::process::Stdio) -> (std::process::Output, f64) {
    let t = std::time::Instant::now();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .stdin(stdin)
        .output()
        .expect("robovec-opt runs");
    (o, t.elapsed().as_secs_f64())
}

/// The grace of a limit (`robovec_passes::Deadline::grace_seconds`) plus a margin for a loaded
/// machine running a debug build.
fn within_grace(limit: f64, elapsed: f64) -> bool {
    elapsed <= limit + robovec_passes::Deadline::grace_seconds(limit) + 2.0
}

/// Issue 47: stdin that gives nothing (a pipe whose writer never writes) or never ends
/// (`/dev/zero`) is read under the deadline: the run ends at the limit with exit 1, where it
/// waited or read without end (`/dev/zero`: 4.2 GB at 8 s).
#[cfg(unix)]
#[test]
fn stdin_is_read_under_the_deadline() {
    // A pipe held open and never written.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
        .args(["-", "-time-limit=0.5", "-o", "/dev/null"])
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("robovec-opt runs");
    let held = child.stdin.take();
    let t = std::time::Instant::now();
    let o = child.wait_with_output().expect("it ends");
    let elapsed = t.elapsed().as_secs_f64();
    drop(held);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.starts_with("error: time limit of 0.5 s reached while reading <stdin>\n"), "{e}");
    assert!(within_grace(0.5, elapsed), "{elapsed} s");
    // `/dev/zero`: stopped at the limit, or at the input bound if it reads faster than 1 GiB/s.
    let zero = std::fs::File::open("/dev/zero").expect("/dev/zero");
    let (o, elapsed) = timed(&["-", "-time-limit=1", "-o", "/dev/null"], zero.into());
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.starts_with("error: time limit of 1 s reached while reading <stdin>")
            || e.starts_with("error: <stdin> is larger than 1 GiB (1073741824 bytes)"),
        "{e}"
    );
    assert!(within_grace(1.0, elapsed), "{elapsed} s");
}

/// Issue 47: an input larger than the bound (1 GiB) is refused at once, before it is read (a
/// sparse file: no disk space used).
#[test]
fn an_input_over_the_bound_is_refused_before_it_is_read() {
    let d = tmp("bound");
    let big = d.join("big.rvir");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(robovec::driver::INPUT_BOUND + 1).unwrap();
    drop(f);
    let (o, elapsed) = timed(&[big.to_str().unwrap(), "-o", "/dev/null"], std::process::Stdio::null());
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.starts_with(&format!(
            "error: `{}` is larger than 1 GiB (1073741824 bytes), the most robovec reads from one input\n",
            big.display()
        )),
        "{e}"
    );
    assert!(elapsed < 5.0, "refused without reading: {elapsed} s");
    std::fs::remove_file(&big).unwrap();
}

/// Issue 47, against the clock (the tick-budget tests of `robovec-dynamics` stop every step at
/// a chosen tick): a 3,000-branch star's `dirdyna` (9 million outputs of `M`, compacted and
/// verified after they are written) and a 2,000-joint chain's `fordyna` end within the grace
/// of a 1 s limit, with the time-limit error, wherever the limit falls.
#[test]
fn generated_functions_end_within_the_grace() {
    let d = tmp("grace");
    for (t, dof, function) in
        [(Topology::Star, 3000, "-function=dirdyna"), (Topology::Serial, 2000, "-function=fordyna")]
    {
        let file = d.join(format!("{t}{dof}.urdf"));
        std::fs::write(&file, robovec_dynamics::urdf_out::write_urdf(&build(t, dof, 1))).unwrap();
        let (o, elapsed) =
            timed(&[file.to_str().unwrap(), function, "-time-limit=1", "-o", "/dev/null"], std::process::Stdio::null());
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{t} {dof}: {e}");
        assert!(e.contains("error: time limit of 1 s reached while "), "{t} {dof}: {e}");
        assert!(within_grace(1.0, elapsed), "{t} {dof}: {elapsed} s");
    }
}
