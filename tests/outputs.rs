//! Issue 10 item 1: output files never damage what is at their path, a run leaves all of its
//! outputs or none, stdout/stderr failures are exit 1 with one line, and options are checked
//! before any work. Also item 5's empty `.rvir` (bad input, exit 1).
//!
//! The character device and FIFO tests need `mknod`/`mkfifo` and root (as in CI); when they
//! cannot be made the tests fail, they do not skip.

use std::fs;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{stderr, tmp};

const BIN: &str = env!("CARGO_BIN_EXE_robovec-opt");

fn opt(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("robovec-opt runs")
}

fn pendulum() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("examples/double_pendulum/mbs_invdyna_double_pendulum.c")
        .display()
        .to_string()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Sorted names in `d`.
fn entries(d: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

fn mode(p: &Path) -> u32 {
    fs::metadata(p).unwrap().permissions().mode() & 0o7777
}

/// Asserts exit status 1 and exactly one line on stderr, with no panic text.
fn assert_one_line_exit_1(code: Option<i32>, err: &str, what: &str) {
    assert_eq!(code, Some(1), "{what}: exit status; stderr: {err}");
    assert_eq!(err.lines().count(), 1, "{what}: one line on stderr, got: {err:?}");
    assert!(!err.contains("panicked"), "{what}: {err}");
}

#[test]
fn a_character_device_stays_a_device() {
    let d = tmp("chardev");
    let null = d.join("null");
    let made = Command::new("mknod").args([s(&null), "c", "1", "3"]).status().expect("mknod runs");
    assert!(made.success(), "mknod failed: this test needs root (as in CI)");
    let o = opt(&[&pendulum(), "-passes=atomise,asap-alap", "-o", s(&null), &format!("-report={}", null.display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    let t = fs::symlink_metadata(&null).unwrap().file_type();
    assert!(t.is_char_device(), "{} is no longer a character device: {t:?}", null.display());
    assert_eq!(entries(&d), ["null"], "no temporary or other file beside the device");
}

#[test]
fn a_symlink_is_followed_and_stays_a_link() {
    let d = tmp("symlink");
    fs::create_dir(d.join("sub")).unwrap();
    fs::write(d.join("real.rvir"), "old").unwrap();
    fs::write(d.join("sub/report.json"), "old").unwrap();
    std::os::unix::fs::symlink("real.rvir", d.join("link.rvir")).unwrap();
    // A link into another folder: the temporary file must go beside the target, not the link.
    std::os::unix::fs::symlink("sub/report.json", d.join("report-link.json")).unwrap();
    // A dangling link creates the file it names.
    std::os::unix::fs::symlink("sub/new.csv", d.join("csv-link")).unwrap();
    let o = opt(&[
        &pendulum(),
        "-passes=atomise,sweep<pe=1>",
        "-o",
        s(&d.join("link.rvir")),
        &format!("-report={}", d.join("report-link.json").display()),
        &format!("-sweep-csv={}", d.join("csv-link").display()),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for (link, to) in [("link.rvir", "real.rvir"), ("report-link.json", "sub/report.json"), ("csv-link", "sub/new.csv")]
    {
        let p = d.join(link);
        assert!(fs::symlink_metadata(&p).unwrap().file_type().is_symlink(), "{link} is no longer a link");
        assert_eq!(fs::read_link(&p).unwrap(), Path::new(to), "{link} points elsewhere");
    }
    assert!(fs::read_to_string(d.join("real.rvir")).unwrap().contains("func @invdyna"));
    let j: serde_json::Value = serde_json::from_str(&fs::read_to_string(d.join("sub/report.json")).unwrap()).unwrap();
    assert_eq!(j["function"], "invdyna");
    assert!(fs::read_to_string(d.join("sub/new.csv")).unwrap().starts_with("function,"));
    assert_eq!(entries(&d), ["csv-link", "link.rvir", "real.rvir", "report-link.json", "sub"]);
    assert_eq!(entries(&d.join("sub")), ["new.csv", "report.json"]);
}

#[test]
fn file_modes_are_kept_and_read_only_files_refused_before_any_work() {
    let d = tmp("modes");
    let private = d.join("private.rvir");
    fs::write(&private, "old").unwrap();
    fs::set_permissions(&private, fs::Permissions::from_mode(0o600)).unwrap();
    let o = opt(&[&pendulum(), "-passes=atomise", "-o", s(&private)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(fs::read_to_string(&private).unwrap().contains("func @invdyna"));
    assert_eq!(mode(&private), 0o600, "the file keeps its mode");

    let ro = d.join("ro.rvir");
    fs::write(&ro, "keep").unwrap();
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o444)).unwrap();
    let dumps = d.join("dumps");
    let o = opt(&[&pendulum(), "-passes=atomise", "-o", s(&ro), &format!("-dump-dir={}", dumps.display())]);
    assert_one_line_exit_1(o.status.code(), &stderr(&o), "read-only -o");
    assert!(stderr(&o).contains("ro.rvir") && stderr(&o).contains("read-only"), "{}", stderr(&o));
    assert_eq!(fs::read_to_string(&ro).unwrap(), "keep");
    assert_eq!(mode(&ro), 0o444);
    assert!(!dumps.exists(), "refused before any pass ran");
    assert_eq!(entries(&d), ["private.rvir", "ro.rvir"]);
}

#[test]
fn a_fifo_is_written_directly() {
    let d = tmp("fifo");
    let fifo = d.join("fifo");
    let made = Command::new("mkfifo").arg(s(&fifo)).status().expect("mkfifo runs");
    assert!(made.success(), "mkfifo failed");
    let got = d.join("got");
    let mut reader =
        Command::new("cat").arg(s(&fifo)).stdout(fs::File::create(&got).unwrap()).spawn().expect("cat runs");
    let o = opt(&[&pendulum(), "-passes=atomise", "-o", s(&fifo)]);
    // If the FIFO was replaced, `cat` still waits on the old one: stop it rather than hang.
    let t0 = Instant::now();
    while reader.try_wait().unwrap().is_none() && t0.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let finished = reader.try_wait().unwrap().is_some();
    if !finished {
        let _ = reader.kill();
        let _ = reader.wait();
    }
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(finished, "the reader of the FIFO never got an end of file");
    assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "still a FIFO");
    assert!(fs::read_to_string(&got).unwrap().contains("func @invdyna"));
    assert_eq!(entries(&d), ["fifo", "got"]);
    // One FIFO for two outputs is refused before any work (issue 29: one of them was lost).
    let o = opt(&[&pendulum(), "-passes=atomise", &format!("-report={}", s(&fifo)), "-o", s(&fifo)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("are the same file"), "{}", stderr(&o));
}

/// Runs `cmd` (a shell command using `$BIN`, `$IN`) with stdout into a pipe whose reader has
/// already exited; returns (exit status, stderr).
fn into_closed_pipe(d: &Path, cmd: &str) -> (Option<i32>, String) {
    let script = format!("{{ sleep 0.5; {cmd} 2>\"$D/err\"; echo $? > \"$D/status\"; }} | true");
    let st =
        Command::new("sh").arg("-c").arg(script).env("BIN", BIN).env("IN", pendulum()).env("D", d).status().unwrap();
    assert!(st.success());
    let code = fs::read_to_string(d.join("status")).unwrap().trim().parse().ok();
    (code, fs::read_to_string(d.join("err")).unwrap())
}

#[test]
fn a_closed_pipe_is_exit_1_with_one_line() {
    let d = tmp("pipe");
    let (code, err) = into_closed_pipe(&d, "\"$BIN\" --print-passes");
    assert_one_line_exit_1(code, &err, "--print-passes | (closed)");
    assert!(err.contains("stdout"), "{err}");
    // The report is put in place before stdout is written: the diagnostic names it.
    let (code, err) = into_closed_pipe(&d, "\"$BIN\" \"$IN\" -passes=atomise -report=\"$D/r.json\"");
    assert_one_line_exit_1(code, &err, "IR | (closed)");
    assert!(err.contains("stdout") && err.contains("already written") && err.contains("r.json"), "{err}");
}

#[test]
fn a_failure_while_putting_files_in_place_names_the_files_already_written() {
    let d = tmp("commit");
    // A full disk of our own (`/dev/full`'s numbers): devices are written after the renames.
    let full = d.join("full");
    let made = Command::new("mknod").args([s(&full), "c", "1", "7"]).status().expect("mknod runs");
    assert!(made.success(), "mknod failed: this test needs root (as in CI)");
    let r = d.join("r.json");
    let o = opt(&[&pendulum(), "-passes=atomise", &format!("-report={}", r.display()), "-o", s(&full)]);
    let err = stderr(&o);
    assert_one_line_exit_1(o.status.code(), &err, "-o full device");
    assert!(err.contains("No space left") && err.contains("already written") && err.contains("r.json"), "{err}");
    assert!(fs::read_to_string(&r).unwrap().contains("\"function\": \"invdyna\""));
    assert!(fs::symlink_metadata(&full).unwrap().file_type().is_char_device());
    assert_eq!(entries(&d), ["full", "r.json"]);
}

#[test]
fn a_full_disk_is_exit_1_with_one_line() {
    let full = || fs::OpenOptions::new().write(true).open("/dev/full").expect("/dev/full");
    for args in [vec!["--print-passes".to_string()], vec![pendulum(), "-passes=atomise".into()]] {
        let o = Command::new(BIN).args(&args).stdout(Stdio::from(full())).output().unwrap();
        assert_one_line_exit_1(o.status.code(), &stderr(&o), &format!("{args:?} > /dev/full"));
        assert!(stderr(&o).contains("No space left"), "{}", stderr(&o));
    }
    // --help and --version of both binaries too (issue 29: robovec-gen's were exit 0).
    for bin in [BIN, env!("CARGO_BIN_EXE_robovec-gen")] {
        for flag in ["--help", "--version"] {
            let o = Command::new(bin).arg(flag).stdout(Stdio::from(full())).output().unwrap();
            assert_one_line_exit_1(o.status.code(), &stderr(&o), &format!("{bin} {flag} > /dev/full"));
            assert!(stderr(&o).contains("cannot write to stdout: No space left"), "{}", stderr(&o));
        }
    }
    // stderr on a full disk: exit 1 (nothing can be said) and no output file.
    let d = tmp("full");
    let out = d.join("out.rvir");
    let o = Command::new(BIN)
        .args([&pendulum(), "-passes=atomise", "-stats", "-o", s(&out)])
        .stderr(Stdio::from(full()))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(entries(&d), Vec::<String>::new(), "a run whose stderr failed leaves no file");
}

#[test]
fn a_failing_run_leaves_none_of_its_outputs() {
    let d = tmp("failing");
    // The second pass fails (no such output) after the first one's dumps were written.
    let args = |d: &Path| {
        vec![
            pendulum(),
            "-passes=atomise,dce<outputs=nope>,sweep<pe=1>".to_string(),
            "-o".into(),
            d.join("out.rvir").display().to_string(),
            format!("-report={}", d.join("r.json").display()),
            format!("-sweep-csv={}", d.join("s.csv").display()),
            format!("-dump-dir={}", d.join("dumps/deeper").display()),
        ]
    };
    let o = Command::new(BIN).args(args(&d)).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no output matches `nope`"), "{}", stderr(&o));
    assert_eq!(entries(&d), Vec::<String>::new(), "nothing of the run is left, not even the dump folders");

    // Existing files of an earlier run are left exactly as they were.
    fs::create_dir_all(d.join("dumps/deeper")).unwrap();
    for f in ["out.rvir", "r.json", "s.csv", "dumps/deeper/001-atomise.after.rvir"] {
        fs::write(d.join(f), "old").unwrap();
    }
    let o = Command::new(BIN).args(args(&d)).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    for f in ["out.rvir", "r.json", "s.csv", "dumps/deeper/001-atomise.after.rvir"] {
        assert_eq!(fs::read_to_string(d.join(f)).unwrap(), "old", "{f}");
    }
    assert_eq!(entries(&d), ["dumps", "out.rvir", "r.json", "s.csv"]);
    assert_eq!(entries(&d.join("dumps/deeper")), ["001-atomise.after.rvir"]);

    // The same run without the failing pass writes everything.
    let mut ok = args(&d);
    ok[1] = "-passes=atomise,sweep<pe=1>".into();
    let o = Command::new(BIN).args(&ok).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        entries(&d.join("dumps/deeper")),
        ["001-atomise.after.rvir", "001-atomise.before.rvir", "002-sweep.after.rvir", "002-sweep.before.rvir"]
    );
    assert!(fs::read_to_string(d.join("dumps/deeper/001-atomise.after.rvir")).unwrap().contains("func @invdyna"));
    assert!(fs::read_to_string(d.join("s.csv")).unwrap().starts_with("function,"));
}

#[test]
fn usage_errors_come_before_any_work() {
    let d = tmp("usage");
    let dumps = d.join("dumps");
    let dump = format!("-dump-dir={}", dumps.display());
    let out = d.join("out.rvir");
    let cases: [(&[&str], i32, &str); 7] = [
        (&["-passes=atomise", &format!("-sweep-csv={}", d.join("s.csv").display())], 2, "needs a `sweep` pass"),
        (
            &["-passes=atomise", "-function=nope", &format!("-report={}", d.join("r.json").display())],
            2,
            "no function `nope`",
        ),
        (&["-passes=atomise", "-function=nope", "-stats"], 2, "no function `nope`"),
        (&["-passes=atomise", &format!("-report={}", out.display())], 2, "are the same file"),
        (&["-passes=atomise", &format!("-report={}", d.join("missing/r.json").display())], 1, "missing"),
        // A file a pass would read only when it runs must exist before any work.
        (&["-passes=atomise,specialize<params=missing.json>"], 1, "cannot read params file `missing.json`"),
        // Likewise for the pipelines of `-pareto`: checked before the first of them runs (which
        // would fail on its own, naming `nope`, if it ran first).
        (
            &["-passes=atomise", "-pareto=atomise,dce<outputs=nope>;atomise,eqsat<rules=missing.rules>"],
            1,
            "pass `eqsat`: cannot read rules file `missing.rules`",
        ),
    ];
    for (extra, code, needle) in cases {
        let mut args = vec![pendulum(), dump.clone(), "-o".into(), out.display().to_string()];
        args.extend(extra.iter().map(|s| s.to_string()));
        let o = Command::new(BIN).args(&args).output().unwrap();
        assert_eq!(o.status.code(), Some(code), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(!dumps.exists(), "{extra:?}: no pass ran, no dump was written");
        assert_eq!(entries(&d), Vec::<String>::new(), "{extra:?}: no file written");
    }
    // A path ending in `/` names a folder, never a file (issue 29: `-o nope/` wrote `nope`).
    for flag in ["-o", "-report"] {
        let nope = format!("{}/", d.join("nope").display());
        let args: Vec<String> = if flag == "-o" {
            vec![pendulum(), "-passes=atomise".into(), "-o".into(), nope.clone()]
        } else {
            vec![pendulum(), "-passes=atomise".into(), format!("-report={nope}"), "-o".into(), s(&out).into()]
        };
        let o = Command::new(BIN).args(&args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{flag}: {}", stderr(&o));
        assert!(stderr(&o).contains(&format!("{flag} `{nope}` names a folder (it ends in `/`)")), "{}", stderr(&o));
        assert_eq!(entries(&d), Vec::<String>::new(), "{flag}: no file written");
    }
    // A folder given as an output file, and a dump folder that is a file.
    fs::create_dir(d.join("adir")).unwrap();
    let o = opt(&[&pendulum(), "-passes=atomise", &dump, "-o", s(&d.join("adir"))]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("folder") && !dumps.exists(), "{}", stderr(&o));
    let o =
        opt(&[&pendulum(), "-passes=atomise", "-o", s(&out), &format!("-dump-dir={}", d.join("adir/x/y").display())]);
    assert!(o.status.success(), "{}", stderr(&o));
    fs::write(d.join("afile"), "").unwrap();
    let o =
        opt(&[&pendulum(), "-passes=atomise", "-o", s(&out), &format!("-dump-dir={}", d.join("afile/x").display())]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("is not a folder"), "{}", stderr(&o));
}

#[test]
fn an_empty_or_comment_only_rvir_is_bad_input() {
    let d = tmp("empty");
    for (name, text) in [("empty.rvir", ""), ("comments.rvir", "; only a comment\n\n; and another\n")] {
        let p = d.join(name);
        fs::write(&p, text).unwrap();
        let o = opt(&[s(&p), "-passes=atomise", &format!("-report={}", d.join("r.json").display())]);
        assert_eq!(o.status.code(), Some(1), "{name}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("expected at least one `func`") && e.contains(&format!("{name}:1:1")), "{name}: {e}");
        assert!(!d.join("r.json").exists());
    }
}

/// Every output is known before any work, and none goes inside another's folder (issue 29:
/// such runs replaced one output by another with exit 0, or failed only after all the work
/// blaming a temporary file): usage error, exit 2, nothing written, naming both.
#[test]
fn an_output_inside_another_outputs_folder_is_a_usage_error_naming_both() {
    let d = tmp("nested");
    let fpga = d.join("fpga");
    let dd = d.join("dd");
    let place = "-passes=atomise,place<pe=2>";
    let with_fpga = format!("{place},codegen<fpga;out={}>", fpga.display());
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            vec![
                with_fpga.clone(),
                format!("-report={}", fpga.join("manifest.json").display()),
                "-o".into(),
                "-".into(),
            ],
            format!(
                "-report `{}` is inside pass `codegen`'s out= `{}`",
                fpga.join("manifest.json").display(),
                fpga.display()
            ),
        ),
        (
            vec![with_fpga.clone(), "-o".into(), fpga.join("simulate").display().to_string()],
            format!("-o `{}` is inside pass `codegen`'s out= `{}`", fpga.join("simulate").display(), fpga.display()),
        ),
        (
            vec![
                place.into(),
                format!("-dump-dir={}", dd.display()),
                "-o".into(),
                dd.join("001-atomise.after.rvir").display().to_string(),
            ],
            format!("-o `{}` is inside -dump-dir `{}`", dd.join("001-atomise.after.rvir").display(), dd.display()),
        ),
        (
            vec![
                format!("{place},codegen<fpga;out={}>", d.join("rep/fpga").display()),
                format!("-report-dir={}", d.join("rep").display()),
                "-o".into(),
                "-".into(),
            ],
            format!(
                "pass `codegen`'s out= `{}` is inside -report-dir `{}`",
                d.join("rep/fpga").display(),
                d.join("rep").display()
            ),
        ),
        (
            vec![with_fpga.clone(), format!("-dump-dir={}", d.join("x/../fpga").display()), "-o".into(), "-".into()],
            format!(
                "-dump-dir `{}` is the same folder as pass `codegen`'s out= `{}`",
                d.join("x/../fpga").display(),
                fpga.display()
            ),
        ),
    ];
    for (extra, needle) in cases {
        let mut args = vec![pendulum()];
        args.extend(extra.iter().cloned());
        let o = Command::new(BIN).args(&args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(&needle), "{extra:?}: {}", stderr(&o));
        assert_eq!(entries(&d), Vec::<String>::new(), "{extra:?}: nothing written");
    }
}

/// `robovec-opt` run in `dir` (for relative spellings), with `stdin` as its standard input.
fn opt_in(dir: &Path, args: &[&str], stdin: Option<&Path>) -> Output {
    let mut c = Command::new(BIN);
    c.current_dir(dir).args(args);
    if let Some(p) = stdin {
        c.stdin(fs::File::open(p).unwrap());
    }
    c.output().expect("robovec-opt runs")
}

/// Every file under `d` (relative path → bytes), folders included as empty entries.
fn snapshot(d: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![d.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in fs::read_dir(&p).unwrap() {
            let e = e.unwrap();
            let t = e.file_type().unwrap();
            let rel = e.path().strip_prefix(d).unwrap().to_path_buf();
            if t.is_dir() {
                stack.push(e.path());
                out.insert(rel, Vec::new());
            } else if t.is_symlink() {
                out.insert(rel, fs::read_link(e.path()).unwrap().into_os_string().into_encoded_bytes());
            } else {
                out.insert(rel, fs::read(e.path()).unwrap());
            }
        }
    }
    out
}

/// Issue 47: an output naming a file the run reads — the input above all — replaced it with
/// exit 0. It is bad usage (exit 2) before any work, whatever the spelling (`./x`, `d/../x`,
/// an absolute path, a symbolic or a hard link), and nothing in the folder changes.
#[test]
fn no_output_is_written_over_the_input() {
    let d = tmp("input");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    fs::copy(root.join("examples/double_pendulum/double_pendulum.urdf"), d.join("robot.urdf")).unwrap();
    fs::copy(root.join("examples/double_pendulum/mbs_invdyna_double_pendulum.c"), d.join("m.c")).unwrap();
    fs::copy(root.join("examples/double_pendulum/mbs_invdyna_double_pendulum.h"), d.join("m.h")).unwrap();
    fs::create_dir(d.join("sub")).unwrap();
    std::os::unix::fs::symlink("robot.urdf", d.join("link.urdf")).unwrap();
    fs::hard_link(d.join("robot.urdf"), d.join("hard.urdf")).unwrap();
    let ir = opt(&[&pendulum(), "-passes=atomise", "-o", "-"]);
    assert!(ir.status.success(), "{}", stderr(&ir));
    fs::write(d.join("x.rvir"), &ir.stdout).unwrap();
    fs::write(d.join("in.json"), r#"{"q[1]": 0.5}"#).unwrap();
    let abs = d.join("robot.urdf").display().to_string();
    let before = snapshot(&d);
    let urdf_is = "is the input `robot.urdf`; robovec never writes over a file the run reads";
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["robot.urdf", "-o", "robot.urdf"], format!("-o `robot.urdf` {urdf_is}")),
        (vec!["robot.urdf", "-o", "./robot.urdf"], format!("-o `./robot.urdf` {urdf_is}")),
        (vec!["robot.urdf", "-o", "link.urdf"], format!("-o `link.urdf` {urdf_is}")),
        (vec!["robot.urdf", "-o", "sub/../robot.urdf"], format!("-o `sub/../robot.urdf` {urdf_is}")),
        (vec!["robot.urdf", "-o", &abs], format!("-o `{abs}` {urdf_is}")),
        (vec!["robot.urdf", "-o", "hard.urdf"], format!("-o `hard.urdf` {urdf_is}")),
        (vec!["./link.urdf", "-o", "robot.urdf"], "-o `robot.urdf` is the input `./link.urdf`".into()),
        (vec!["robot.urdf", "-report=robot.urdf", "-o", "/dev/null"], format!("-report `robot.urdf` {urdf_is}")),
        (
            vec!["robot.urdf", "-params-out=./robot.urdf", "-o", "/dev/null"],
            format!("-params-out `./robot.urdf` {urdf_is}"),
        ),
        (vec!["x.rvir", "-o", "./x.rvir"], "-o `./x.rvir` is the input `x.rvir`".into()),
        (vec!["m.c", "-o", "m.c"], "-o `m.c` is the input `m.c`".into()),
        // The header the C front end reads beside the input, as -o or as -o's companion.
        (vec!["m.c", "-o", "m.h"], "-o `m.h` is the file the Robotran C front end reads beside the input `m.h`".into()),
        (
            vec!["m.c", "-passes=atomise,codegen<c>", "-o", "sub/../m.rvir"],
            "-o's companion `sub/../m.h` is the file the Robotran C front end reads beside the input `m.h`".into(),
        ),
        // -eval's inputs are read too.
        (
            vec!["x.rvir", "-eval=in.json", "-report=./in.json", "-o", "/dev/null"],
            "-report `./in.json` is -eval's inputs file `in.json`".into(),
        ),
        (
            vec!["x.rvir", "-passes=atomise,sweep<pe=1>", "-sweep-csv=x.rvir", "-o", "/dev/null"],
            "-sweep-csv `x.rvir` is the input `x.rvir`".into(),
        ),
        // A file a pass reads.
        (
            vec!["x.rvir", "-passes=atomise,specialize<params=in.json>", "-o", "in.json"],
            "-o `in.json` is pass `specialize`'s params= file `in.json`".into(),
        ),
    ];
    for (args, needle) in &cases {
        let mut args = args.clone();
        if !args.iter().any(|a| a.starts_with("-passes")) {
            args.push("-passes=atomise");
        }
        let o = opt_in(&d, &args, None);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle.as_str()), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).lines().count(), 1, "{args:?}: {}", stderr(&o));
        assert!(snapshot(&d) == before, "{args:?}: a file changed");
    }
    // IR on stdin from a regular file: that file is the input too.
    let o = opt_in(&d, &["-", "-passes=atomise", "-o", "x.rvir"], Some(&d.join("x.rvir")));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("-o `x.rvir` is the input (the file on stdin)"), "{}", stderr(&o));
    // The dumps: `-dump-dir=.` over an input named like one of them.
    fs::copy(d.join("x.rvir"), d.join("001-atomise.after.rvir")).unwrap();
    let before = snapshot(&d);
    let o = opt_in(&d, &["001-atomise.after.rvir", "-passes=atomise", "-dump-dir=.", "-o", "/dev/null"], None);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("-dump-dir's dump `./001-atomise.after.rvir` is the input `001-atomise.after.rvir`"),
        "{}",
        stderr(&o)
    );
    assert!(snapshot(&d) == before, "nothing changed");
    // Other paths and outputs that are not read are written as before.
    let o = opt_in(&d, &["x.rvir", "-passes=atomise", "-o", "y.rvir", "-report=r.json"], None);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(fs::read(d.join("y.rvir")).unwrap(), ir.stdout);
}

/// A folder replaced as a whole never holds a file the run reads; files a pass names only
/// when it writes them (`accuracy<worst=DIR>`) are checked when they are known: exit 2,
/// nothing written.
#[test]
fn no_output_folder_replaces_a_file_the_run_reads() {
    let d = tmp("input_folder");
    let rep = d.join("rep");
    fs::create_dir(&rep).unwrap();
    fs::write(rep.join("report.json"), "{}").unwrap();
    fs::write(rep.join("in.json"), r#"{"q[1]": 0.5}"#).unwrap();
    let before = snapshot(&d);
    let o = opt(&[
        &pendulum(),
        "-passes=atomise",
        &format!("-eval={}", rep.join("in.json").display()),
        &format!("-report-dir={}", rep.display()),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let needle =
        format!("-report-dir `{}` holds -eval's inputs file `{}`", rep.display(), rep.join("in.json").display());
    assert!(stderr(&o).contains(&needle), "{}", stderr(&o));
    assert!(snapshot(&d) == before, "nothing changed");
    // `accuracy<worst=W>` writes W/worst-1.json, here the -eval inputs of the same run.
    let w = d.join("w");
    let acc = format!("-passes=atomise,accuracy<samples=20;worst={};worst-count=1>", w.display());
    let o = opt(&[&pendulum(), &acc, "-o", "/dev/null"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let worst = w.join("worst-1.json");
    let before = snapshot(&d);
    let o = opt(&[&pendulum(), &acc, &format!("-eval={}", worst.display()), "-o", s(&d.join("out.rvir"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let needle = format!("cannot write `{}`: it is -eval's inputs file `{}`", worst.display(), worst.display());
    assert!(stderr(&o).contains(&needle), "{}", stderr(&o));
    assert!(snapshot(&d) == before, "nothing changed, no temporary file left");
}

/// `robovec-gen --urdf X -o X` replaced the robot it read (issue 47).
#[test]
fn robovec_gen_does_not_write_over_its_urdf() {
    let d = tmp("gen_input");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    fs::copy(root.join("examples/double_pendulum/double_pendulum.urdf"), d.join("robot.urdf")).unwrap();
    let before = snapshot(&d);
    let gen = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_robovec-gen")).current_dir(&d).args(args).output().expect("robovec-gen runs")
    };
    for (args, needle) in [
        (&["--urdf", "robot.urdf", "-o", "./robot.urdf"][..], "-o `./robot.urdf` is the input `robot.urdf`"),
        (
            &[
                "--urdf",
                "robot.urdf",
                "--format",
                "c",
                "--function",
                "invdyna",
                "-o",
                "m.c",
                "--params-out",
                "robot.urdf",
            ],
            "--params-out `robot.urdf` is the input `robot.urdf`",
        ),
    ] {
        let o = gen(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(snapshot(&d) == before, "{args:?}: a file changed");
    }
    let o = gen(&["--urdf", "robot.urdf", "-o", "copy.urdf"]);
    assert!(o.status.success(), "{}", stderr(&o));
}
