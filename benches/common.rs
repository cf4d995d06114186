//! Inputs shared by the benches (included with `#[path = "common.rs"] mod common;`; with
//! `autobenches = false` this file is not a bench target of its own).
#![allow(dead_code, reason = "each bench uses a different subset")]

use std::path::PathBuf;

use robovec_ir::Function;
use robovec_passes::atomise::atomise_function;

/// WALK-MAN's direct dynamics, the corpus's largest single-function Matlab file.
pub const WALKMAN: &str = "../shared/corpus/robotran/matlab/walkman__mbs_dirdyna_walkman_robotran.m";

/// The atomised WALK-MAN direct dynamics (37,579 ops); panics when `../shared` is missing.
pub fn walkman() -> Function {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(WALKMAN);
    let (m, _) = robovec::driver::load(&p.to_string_lossy())
        .unwrap_or_else(|e| panic!("cannot load {} (the corpus must sit at ../shared): {}", p.display(), e.message()));
    assert_eq!(m.functions.len(), 1, "{WALKMAN} holds one function");
    atomise_function(&m.functions[0])
}

/// `VmHWM` (peak resident memory) of process `pid` in bytes, if readable (Linux
/// `/proc/PID/status`).
pub fn vm_hwm(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The largest `VmHWM` of process `pid` and of its descendants alive now (a compiler driver's
/// `cc1`, an `as`), in bytes; `/proc/PID/task/TID/children` (Linux ≥ 3.5).
pub fn tree_hwm(pid: u32) -> u64 {
    let mut peak = vm_hwm(pid).unwrap_or(0);
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else { return peak };
    for t in tasks.flatten() {
        let children = std::fs::read_to_string(t.path().join("children")).unwrap_or_default();
        for c in children.split_whitespace().filter_map(|c| c.parse().ok()) {
            peak = peak.max(tree_hwm(c));
        }
    }
    peak
}

/// Runs `cmd` (stdout discarded, stderr captured) and samples the `VmHWM` of it and its
/// descendants ([`tree_hwm`]) every 2 ms until it exits: `(success, wall seconds, peak bytes
/// of the largest process, stderr)`.
pub fn run_measured(cmd: &mut std::process::Command) -> (bool, f64, u64, String) {
    use std::io::Read;
    let t0 = std::time::Instant::now();
    let mut child = cmd
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawn the measured process");
    // Drain stderr on a thread so a chatty child never blocks on a full pipe.
    let mut err_pipe = child.stderr.take().expect("stderr piped");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err_pipe.read_to_string(&mut s);
        s
    });
    let mut peak = 0;
    let status = loop {
        peak = peak.max(tree_hwm(child.id()));
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    };
    let secs = t0.elapsed().as_secs_f64();
    (status.success(), secs, peak, reader.join().unwrap_or_default())
}
