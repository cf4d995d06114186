//! Parse + IR scaling (issue 10 §3): time and peak memory of
//! `robovec-opt FILE -passes=atomise,asap-alap -o OUT` on generated straight-line Robotran C
//! files ([`robovec_front::synth`], one output per temporary: ~1.4·10⁶ outputs per 100 MB) of
//! 1, 10 and 100 MB.
//!
//! Each size runs the release binary in a child process; the peak resident memory is the
//! child's `VmHWM` (`/proc/PID/status`, sampled every 2 ms until it exits), so the figures are
//! those of a user's run, output file included. Prints one row per size: input MB, outputs,
//! ops, wall seconds, peak RSS MB and peak RSS / input size.
//!
//! Run: `cargo bench --bench parse_scale` (about a minute; sizes as arguments in MB:
//! `cargo bench --bench parse_scale -- 1 10`). `--bin PATH` measures another build of
//! `robovec-opt` (e.g. an older one, for a before/after comparison); `--keep` leaves the
//! generated files in the temporary folder.

use std::path::PathBuf;
use std::process::Command;

use robovec_front::synth::{straight_line_c, Shape};

#[path = "common.rs"]
mod common;

fn main() {
    let mut sizes: Vec<f64> = Vec::new();
    let mut bin = PathBuf::from(env!("CARGO_BIN_EXE_robovec-opt"));
    let mut keep = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--bin" => bin = PathBuf::from(args.next().expect("--bin PATH")),
            "--keep" => keep = true,
            "--bench" => {} // added by `cargo bench`
            _ => match a.parse::<f64>() {
                Ok(mb) if mb > 0.0 => sizes.push(mb),
                _ => eprintln!("parse_scale: ignoring argument `{a}`"),
            },
        }
    }
    if sizes.is_empty() {
        sizes = vec![1.0, 10.0, 100.0];
    }
    let dir = std::env::temp_dir().join(format!("robovec-parse-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    println!("binary: {}", bin.display());
    println!(
        "{:>8} {:>10} {:>11} {:>9} {:>10} {:>9}  pipeline atomise,asap-alap",
        "input MB", "outputs", "ops", "time s", "peak MB", "peak/in"
    );
    for mb in sizes {
        let g = straight_line_c(Shape::many_outputs((mb * 1e6) as usize));
        let input = dir.join(format!("scale_{mb}MB.c"));
        let output = dir.join(format!("scale_{mb}MB.rvir"));
        std::fs::write(&input, &g.text).expect("write the generated file");
        let len = g.text.len() as f64;
        let (outputs, ops) = (g.outputs, g.ops);
        drop(g);
        let (ok, secs, peak, err) = common::run_measured(
            Command::new(&bin).arg(&input).arg("-passes=atomise,asap-alap").arg("-o").arg(&output),
        );
        if !ok {
            println!("{:>8.1} robovec-opt failed: {}", len / 1e6, err.lines().next().unwrap_or(""));
            continue;
        }
        println!(
            "{:>8.1} {:>10} {:>11} {:>9.2} {:>10.0} {:>9.1}",
            len / 1e6,
            outputs,
            ops,
            secs,
            peak as f64 / 1e6,
            peak as f64 / len
        );
        if !keep {
            let _ = std::fs::remove_file(&input);
            let _ = std::fs::remove_file(&output);
        }
    }
    if !keep {
        let _ = std::fs::remove_dir(&dir);
    }
}
