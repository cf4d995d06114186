//! Scale (issue 14): the 130-dof serial topology family (`robovec_dynamics::topology`, seed 1),
//! written as a URDF, through
//! `robovec-opt serial130.urdf -passes=atomise,zero-removal,balance,asap-alap,place<pe=32>,sim,codegen<c> -o serial130.c -time-passes -stats`
//! (both functions: `invdyna` and the ~189 000-op `dirdyna`; generation included).
//!
//! Runs the release `robovec-opt` in a child process, `--runs=K` times (default 3), and prints
//! each run's wall time and peak resident memory (`VmHWM`, sampled every 2 ms), their medians,
//! and the `-time-passes` lines of the last run (where the time goes, per pass). Goal from the
//! issue: under 10 s and 2 GB. `--dof=N` and `--topology=T` pick another case; `--bin PATH`
//! measures another build.
//!
//! Run: `cargo bench --bench scale` (`-- --runs=5 --dof=100`).

#[path = "common.rs"]
mod common;

use std::path::PathBuf;
use std::process::Command;

use robovec_dynamics::topology::{build, Topology};

fn main() {
    let mut bin = PathBuf::from(env!("CARGO_BIN_EXE_robovec-opt"));
    let (mut runs, mut dof, mut topology) = (3usize, 130usize, Topology::Serial);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if let Some(v) = a.strip_prefix("--runs=") {
            runs = v.parse().expect("--runs=K");
        } else if let Some(v) = a.strip_prefix("--dof=") {
            dof = v.parse().expect("--dof=N");
        } else if let Some(v) = a.strip_prefix("--topology=") {
            topology = v.parse().expect("--topology=serial|semi-serial|parallel");
        } else if a == "--bin" {
            bin = PathBuf::from(args.next().expect("--bin PATH"));
        } else if a != "--bench" {
            eprintln!("scale: ignoring argument `{a}`");
        }
    }
    let dir = std::env::temp_dir().join(format!("robovec-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let urdf = dir.join(format!("{topology}_{dof}.urdf"));
    std::fs::write(&urdf, robovec_dynamics::urdf_out::write_urdf(&build(topology, dof, 1))).expect("write the URDF");
    let out = dir.join("model.c");
    let pipeline = "-passes=atomise,zero-removal,balance,asap-alap,place<pe=32>,sim,codegen<c>";
    println!("binary: {}\ncase: {topology} {dof} dof, seed 1; {pipeline}", bin.display());
    let (mut secs, mut peaks, mut last_err) = (Vec::new(), Vec::new(), String::new());
    for run in 1..=runs {
        let (ok, s, peak, err) = common::run_measured(
            Command::new(&bin).arg(&urdf).arg(pipeline).arg("-time-passes").arg("-stats").arg("-o").arg(&out),
        );
        assert!(ok, "robovec-opt failed: {}", err.lines().next().unwrap_or(""));
        println!("run {run}: {s:.2} s, peak {:.0} MB", peak as f64 / 1e6);
        secs.push(s);
        peaks.push(peak as f64 / 1e6);
        last_err = err;
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!("median: {:.2} s, peak {:.0} MB (goal: < 10 s, < 2000 MB)", median(&mut secs), median(&mut peaks));
    println!("last run, -time-passes and -stats:");
    for l in last_err.lines().filter(|l| !l.trim().is_empty()) {
        println!("  {l}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
