//! Scale (issue 28): is every pass linear in ops, from one robot to a fleet?
//!
//! **Input:** WALK-MAN × K, K independent copies of the corpus's WALK-MAN `dirdyna` (Robotran
//! Matlab, ~37.6k ops each; `robovec_testkit::copies::matlab_copies`), for K in `--copies`
//! (default 1, 4, 16, 64; add 160 for the 5.9M-op point, with `--pes=64` as the goal).
//!
//! **Pipeline:** `robovec-opt wmK.m -passes=atomise,zero-removal,balance,asap-alap,place<pe=N>,sim -time-passes -o /dev/null`
//! (N = `--pes`, default 32), then the C path the issue measures:
//! `-passes=atomise,cse,codegen<c;abi=plain> -o wmK.c` and `gcc -O2 -c` on every file it writes
//! (`--no-cc` skips it, `--cc=CMD` picks the compiler, `--cc-max=K`: only up to K copies,
//! default 16, the goal; WALK-MAN × 64 is four times that compile).
//!
//! **Measured** (release `robovec-opt` in a child process, `--runs=R` times per K — default 3 up
//! to K = 16, 1 above — medians): per pass ns/op (the pass's `-time-passes` wall time over its
//! ops before), the whole run's wall time and peak resident memory (`VmHWM`, sampled every
//! 2 ms), and the C compile's wall time and peak memory (the compiler processes run one after
//! the other; peak = the largest). The last table gives each pass's ns/op relative to the
//! smallest K: the goal is within 1.5× from × 1 to × 64.
//!
//! **URDF** (`--urdf=FAMILY:N[:FUNCTION],…`, default `serial:2000,serial:10000,star:4000,
//! star:10000,serial:250:dirdyna,serial:500:dirdyna`; `--no-urdf` skips them): `robovec-gen
//! --topology FAMILY --dof N` writes the robot, then `robovec-opt robot.urdf
//! -function=FUNCTION -passes=atomise -o /dev/null` (default `invdyna`): time, peak memory,
//! atomised ops, and both per op (the generator's cost must follow the ops it writes).
//!
//! Goals (issue 28): 588k ops (K = 16) < 10 s, < 2 GB; 5.9M ops (K = 160, `--pes=64`) < 120 s,
//! < 8 GB; the C of K = 16 compiles with `gcc -O2` in < 3 min and < 4 GB; URDF `invdyna`: a
//! 2,000-joint chain and a 4,000-branch star < 5 s, < 600 MB; 10,000 joints < 10 s, < 1.5 GB.
//!
//! **Before/after** (`--before=PATH`, another build of `robovec-opt`): for each K up to
//! `--before-max=K` (default 16: the quadratic `sim` of older builds takes minutes beyond), the
//! pipeline runs alternately with that build and this one, and a last table gives both wall
//! times and peaks and their ratios (medians of the runs).
//!
//! Run: `cargo bench --bench scale` (`-- --copies=1,4,16,64,160 --pes=64 --runs=1 --bin PATH
//! --before=PATH`).

#[path = "common.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// One run of the pipeline: per pass (name, ops before, wall ms, ops after), wall s, peak bytes.
struct PipelineRun {
    passes: Vec<(String, u64, f64, u64)>,
    secs: f64,
    peak: u64,
}

fn main() {
    let mut bin = PathBuf::from(env!("CARGO_BIN_EXE_robovec-opt"));
    let (mut copies, mut pes, mut runs, mut cc) = (vec![1usize, 4, 16, 64], 32u32, None, Some("gcc".to_string()));
    let mut urdf: Vec<String> = "serial:2000,serial:10000,star:4000,star:10000,serial:250:dirdyna,serial:500:dirdyna"
        .split(',')
        .map(String::from)
        .collect();
    let (mut before, mut before_max, mut cc_max): (Option<PathBuf>, usize, usize) = (None, 16, 16);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if let Some(v) = a.strip_prefix("--copies=") {
            copies = v.split(',').map(|k| k.parse().expect("--copies=K,K,…")).collect();
        } else if let Some(v) = a.strip_prefix("--pes=") {
            pes = v.parse().expect("--pes=N");
        } else if let Some(v) = a.strip_prefix("--runs=") {
            runs = Some(v.parse::<usize>().expect("--runs=R").max(1));
        } else if let Some(v) = a.strip_prefix("--cc=") {
            cc = Some(v.to_string());
        } else if let Some(v) = a.strip_prefix("--urdf=") {
            urdf = v.split(',').map(String::from).collect();
        } else if a == "--no-urdf" {
            urdf.clear();
        } else if a == "--no-cc" {
            cc = None;
        } else if let Some(v) = a.strip_prefix("--cc-max=") {
            cc_max = v.parse().expect("--cc-max=K");
        } else if let Some(v) = a.strip_prefix("--before=") {
            before = Some(PathBuf::from(v));
        } else if let Some(v) = a.strip_prefix("--before-max=") {
            before_max = v.parse().expect("--before-max=K");
        } else if a == "--bin" {
            bin = PathBuf::from(args.next().expect("--bin PATH"));
        } else if a != "--bench" {
            eprintln!("scale: ignoring argument `{a}`");
        }
    }
    let shared = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(common::WALKMAN);
    let walkman = std::fs::read_to_string(&shared)
        .unwrap_or_else(|e| panic!("{}: {e} (the corpus must sit at ../shared)", shared.display()));
    let dir = std::env::temp_dir().join(format!("robovec-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let pipeline = format!("-passes=atomise,zero-removal,balance,asap-alap,place<pe={pes}>,sim");
    println!("binary: {}\ninput: WALK-MAN dirdyna × K; {pipeline}", bin.display());
    let mut rows = Vec::new();
    let mut compared = Vec::new();
    for &k in &copies {
        let input = dir.join(format!("walkman_x{k}.m"));
        std::fs::write(&input, robovec_testkit::copies::matlab_copies(&walkman, k, 55)).expect("write the input");
        let bytes = std::fs::metadata(&input).map(|m| m.len()).unwrap_or(0);
        let r = runs.unwrap_or(if k <= 16 { 3 } else { 1 });
        let old_bin = before.as_ref().filter(|_| k <= before_max);
        let mut all: Vec<PipelineRun> = Vec::new();
        let mut old: Vec<PipelineRun> = Vec::new();
        for _ in 0..r {
            if let Some(b) = old_bin {
                old.push(run_pipeline(b, &input, &pipeline));
            }
            all.push(run_pipeline(&bin, &input, &pipeline));
        }
        if !old.is_empty() {
            compared.push((
                k,
                median(old.iter().map(|x| x.secs).collect()),
                median(all.iter().map(|x| x.secs).collect()),
                median(old.iter().map(|x| x.peak as f64).collect()),
                median(all.iter().map(|x| x.peak as f64).collect()),
            ));
        }
        let c = cc.as_deref().filter(|_| k <= cc_max).map(|cc| compile_c(&bin, &input, &dir, k, cc));
        let secs = median(all.iter().map(|x| x.secs).collect());
        let peak = median(all.iter().map(|x| x.peak as f64).collect());
        let passes: Vec<(String, u64, f64)> = all[0]
            .passes
            .iter()
            .enumerate()
            .map(|(i, (name, ops, ..))| (name.clone(), *ops, median(all.iter().map(|x| x.passes[i].2).collect())))
            .collect();
        all.clear();
        println!(
            "× {k}: {:.1} MB input, {} ops, {secs:.2} s, peak {:.0} MB{}",
            bytes as f64 / 1e6,
            passes.first().map_or(0, |p| p.1),
            peak / 1e6,
            c.as_ref().map_or(String::new(), |c| format!(
                "; C: {} file(s), {:.1} MB, {} {:.1} s, peak {:.0} MB",
                c.files,
                c.bytes as f64 / 1e6,
                cc.as_deref().unwrap_or(""),
                c.secs,
                c.peak as f64 / 1e6
            ))
        );
        let _ = std::fs::remove_file(&input);
        rows.push((k, bytes, passes, secs, peak, c));
    }
    let Some(names) = rows.first().map(|r| r.2.iter().map(|p| p.0.clone()).collect::<Vec<_>>()) else { return };
    println!(
        "\n| copies | ops | input MB | {} | run s | peak MB | peak / input | C compile s | C peak MB |",
        names.join(" ns/op | ") + " ns/op"
    );
    println!("|---:|---:|---:|{}---:|---:|---:|---:|---:|", "---:|".repeat(names.len()));
    for (k, bytes, passes, secs, peak, c) in &rows {
        let per_op: Vec<String> =
            passes.iter().map(|(_, ops, ms)| format!("{:.0}", ms * 1e6 / (*ops).max(1) as f64)).collect();
        println!(
            "| × {k} | {} | {:.1} | {} | {secs:.2} | {:.0} | {:.1}× | {} | {} |",
            passes.first().map_or(0, |p| p.1),
            *bytes as f64 / 1e6,
            per_op.join(" | "),
            peak / 1e6,
            peak / (*bytes).max(1) as f64,
            c.as_ref().map_or("–".into(), |c| format!("{:.1}", c.secs)),
            c.as_ref().map_or("–".into(), |c| format!("{:.0}", c.peak as f64 / 1e6)),
        );
    }
    let base = &rows[0];
    println!("\nns/op relative to × {} (goal: within 1.5× up to × 64):", base.0);
    println!("| copies | {} |", names.join(" | "));
    println!("|---:|{}", "---:|".repeat(names.len()));
    for (k, _, passes, ..) in &rows {
        let rel: Vec<String> = passes
            .iter()
            .zip(&base.2)
            .map(|((_, ops, ms), (_, bops, bms))| {
                let (a, b) = (ms / (*ops).max(1) as f64, bms / (*bops).max(1) as f64);
                if b > 0.0 {
                    format!("{:.2}×", a / b)
                } else {
                    "–".into()
                }
            })
            .collect();
        println!("| × {k} | {} |", rel.join(" | "));
    }
    if let (Some(b), false) = (&before, compared.is_empty()) {
        println!(
            "\nbefore: {}\n| copies | before s | now s | before / now | before peak MB | now peak MB |",
            b.display()
        );
        println!("|---:|---:|---:|---:|---:|---:|");
        for (k, bs, s, bp, p) in &compared {
            println!("| × {k} | {bs:.2} | {s:.2} | {:.2}× | {:.0} | {:.0} |", bs / s, bp / 1e6, p / 1e6);
        }
    }
    if !urdf.is_empty() {
        urdf_rows(&bin, &dir, &urdf);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The URDF rows (module doc): one robot per `FAMILY:N[:FUNCTION]`, one run each.
fn urdf_rows(bin: &Path, dir: &Path, specs: &[String]) {
    let gen = bin.with_file_name("robovec-gen");
    println!("\n| robot | function | ops | time s | peak MB | µs/op | bytes/op |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    for spec in specs {
        let parts: Vec<&str> = spec.split(':').collect();
        let (family, n, function) = match parts.as_slice() {
            [f, n] => (*f, *n, "invdyna"),
            [f, n, fun] => (*f, *n, *fun),
            _ => panic!("--urdf=FAMILY:N[:FUNCTION], got `{spec}`"),
        };
        let robot = dir.join(format!("{family}_{n}.urdf"));
        let (ok, _, _, err) =
            common::run_measured(Command::new(&gen).args(["--topology", family, "--dof", n]).arg("-o").arg(&robot));
        assert!(ok, "robovec-gen {spec} failed: {}", err.lines().next().unwrap_or(""));
        let run = run_pipeline_with(bin, &robot, &[format!("-function={function}"), "-passes=atomise".to_string()]);
        let ops = run.passes.iter().find(|p| p.0 == "atomise").map_or(0, |p| p.3);
        let label = if family == "serial" { format!("chain, {n} joints") } else { format!("{family}, {n} branches") };
        println!(
            "| {label} | {function} | {ops} | {:.2} | {:.0} | {:.2} | {:.0} |",
            run.secs,
            run.peak as f64 / 1e6,
            run.secs * 1e6 / ops.max(1) as f64,
            run.peak as f64 / ops.max(1) as f64
        );
        let _ = std::fs::remove_file(&robot);
    }
}

/// The median of `v` (the upper one for an even length).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One measured run of `pipeline` on `input`, its `-time-passes` table parsed.
fn run_pipeline(bin: &Path, input: &Path, pipeline: &str) -> PipelineRun {
    run_pipeline_with(bin, input, &[pipeline.to_string()])
}

/// [`run_pipeline`] with these options before `-time-passes -o /dev/null`.
fn run_pipeline_with(bin: &Path, input: &Path, options: &[String]) -> PipelineRun {
    let (ok, secs, peak, err) =
        common::run_measured(Command::new(bin).arg(input).args(options).arg("-time-passes").arg("-o").arg("/dev/null"));
    assert!(ok, "robovec-opt failed: {}", err.lines().next().unwrap_or(""));
    // `     Wall (ms)       %  ops before   ops after  Name` rows: `12.3  4.5%  37579  37579  atomise`.
    let passes = err
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            match w.as_slice() {
                [ms, pct, before, after, name] if pct.ends_with('%') => {
                    Some((name.to_string(), before.parse().ok()?, ms.parse().ok()?, after.parse().ok()?))
                }
                _ => None,
            }
        })
        .collect();
    PipelineRun { passes, secs, peak }
}

/// The C compile of one size.
struct CCompile {
    files: usize,
    bytes: u64,
    secs: f64,
    peak: u64,
}

/// `atomise,cse,codegen<c;abi=plain>` on `input`, then `cc -O2 -c` on every `.c` file written.
fn compile_c(bin: &Path, input: &Path, dir: &Path, k: usize, cc: &str) -> CCompile {
    let out_dir = dir.join(format!("c_x{k}"));
    std::fs::create_dir_all(&out_dir).expect("C folder");
    let out = out_dir.join("model.c");
    let (ok, _, _, err) = common::run_measured(
        Command::new(bin).arg(input).arg("-passes=atomise,cse,codegen<c;abi=plain>").arg("-o").arg(&out),
    );
    assert!(ok, "robovec-opt (C) failed: {}", err.lines().next().unwrap_or(""));
    let mut files: Vec<PathBuf> = std::fs::read_dir(&out_dir)
        .expect("C folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "c"))
        .collect();
    files.sort();
    let bytes = files.iter().map(|f| std::fs::metadata(f).map_or(0, |m| m.len())).sum();
    let (mut secs, mut peak) = (0.0, 0);
    for f in &files {
        let (ok, s, p, err) =
            common::run_measured(Command::new(cc).arg("-O2").arg("-c").arg(f).arg("-o").arg(f.with_extension("o")));
        assert!(ok, "{cc} -O2 -c {} failed: {}", f.display(), err.lines().next().unwrap_or(""));
        secs += s;
        peak = peak.max(p);
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    CCompile { files: files.len(), bytes, secs, peak }
}
