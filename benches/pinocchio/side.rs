//! Helpers of `benches/pinocchio.rs`: the Pinocchio environment and the harness build, the shared
//! states, input and output maps, bits of error from the harness's values.

use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Flags of the C++ harness (Pinocchio header-only: its `double` and `long double` instances are
/// compiled here, for this CPU): optimisation, then the flags shared with `cg_ops.py`
/// (`pinocchio_cxx_flags.txt`).
fn cxx_flags() -> Vec<&'static str> {
    let shared = include_str!("pinocchio_cxx_flags.txt").lines().map(str::trim);
    ["-O3", "-march=native"].into_iter().chain(shared.filter(|l| !l.is_empty() && !l.starts_with('#'))).collect()
}

/// Flags of robovec's generated C (the `native` set of `cargo bench --bench codegen_c`; no
/// contraction, so the values are `-eval`'s).
pub const C_FLAGS: &[&str] = &["-O3", "-march=native", "-ffp-contract=off", "-Wno-psabi"];

/// How to create the environment (the commands of `scripts/test.sh`: Pinocchio, its robots,
/// Eigen's, CppAD's and CppADCodeGen's headers).
const HOW: &str = "python3 -m venv target/pinocchio-venv && \
    target/pinocchio-venv/bin/pip install pin example-robot-data cmeel-eigen cmeel-cppad cmeel-cppadcodegen";

/// The Pinocchio environment and the bench's work folder.
pub struct Env {
    /// The repository.
    pub root: PathBuf,
    /// The venv's Python.
    pub python: PathBuf,
    /// `cmeel.prefix` (include/, lib/ of Pinocchio, Boost, Eigen).
    pub prefix: PathBuf,
    /// `target/pinocchio_bench`.
    pub work: PathBuf,
    /// The compiled harness object.
    harness: PathBuf,
}

impl Env {
    /// Finds the venv (panics with [`HOW`] when it is missing or lacks a header) and builds the
    /// harness object unless a build of the same source and flags is cached.
    pub fn new() -> Env {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let python = std::env::var_os("ROBOVEC_PINOCCHIO_PYTHON")
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("target/pinocchio-venv/bin/python"));
        assert!(python.exists(), "Pinocchio's environment is missing at {}; create it with: {HOW}", python.display());
        let purelib =
            run(Command::new(&python).args(["-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]));
        let prefix = PathBuf::from(purelib.trim()).join("cmeel.prefix");
        for h in [
            "include/pinocchio/algorithm/rnea.hpp",
            "include/eigen3/Eigen/Core",
            "include/boost/version.hpp",
            "include/cppad/cg.hpp",
        ] {
            assert!(
                prefix.join(h).exists(),
                "{} is missing; create the environment with: {HOW}",
                prefix.join(h).display()
            );
        }
        let work = root.join("target/pinocchio_bench");
        std::fs::create_dir_all(&work).unwrap();
        let src = root.join("benches/pinocchio/harness.cpp");
        let text = std::fs::read(&src).unwrap();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (text, cxx_flags(), &prefix).hash(&mut h);
        let harness = work.join(format!("harness-{:016x}.o", h.finish()));
        if !harness.exists() {
            eprintln!("compiling {} (about 3 min; cached as {})", src.display(), harness.display());
            let tmp = harness.with_extension("tmp.o");
            let inc = |p: &str| format!("-I{}", prefix.join(p).display());
            run(Command::new("g++")
                .args(cxx_flags())
                .args([inc("include"), inc("include/eigen3")])
                .arg("-c")
                .arg(&src)
                .arg("-o")
                .arg(&tmp));
            std::fs::rename(&tmp, &harness).unwrap();
        }
        Env { root, python, prefix, work, harness }
    }

    /// Compiles `sources` (C, in `dir`, each with its flags) two at a time when newer than their
    /// objects, links them with the harness, returns the executable. A source's flags must be
    /// part of its text (a comment will do) for a change of flags to rebuild it.
    pub fn link(&self, dir: &Path, sources: &[(PathBuf, &[&str])]) -> PathBuf {
        let objs: Vec<PathBuf> = sources.iter().map(|s| s.0.with_extension("o")).collect();
        let stale: Vec<(&(PathBuf, &[&str]), &PathBuf)> =
            sources.iter().zip(&objs).filter(|((s, _), o)| !newer(o, s)).collect();
        let t0 = std::time::Instant::now();
        for pair in stale.chunks(2) {
            let children: Vec<_> = pair
                .iter()
                .map(|((s, flags), o)| {
                    let c = Command::new("cc").args(*flags).arg("-c").arg(s).arg("-o").arg(o).spawn().expect("cc runs");
                    (s, c)
                })
                .collect();
            for (s, c) in children {
                let out = c.wait_with_output().unwrap();
                assert!(out.status.success(), "cc {} failed", s.display());
            }
        }
        eprintln!("   compiled {} C files in {:.1} s", stale.len(), t0.elapsed().as_secs_f64());
        let exe = dir.join("bench");
        let lib = self.prefix.join("lib");
        run(Command::new("g++")
            .arg("-o")
            .arg(&exe)
            .arg(&self.harness)
            .args(&objs)
            .arg(format!("-L{}", lib.display()))
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .args(["-lboost_serialization", "-lm"]));
        exe
    }
}

/// Whether file `a` exists and is at least as new as `b`.
fn newer(a: &Path, b: &Path) -> bool {
    let t = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    matches!((t(a), t(b)), (Some(x), Some(y)) if x >= y)
}

/// Writes `data` to `path` unless the file already holds it (so its time stamp stays).
pub fn write_if_changed(path: &Path, data: &[u8]) {
    if std::fs::read(path).ok().as_deref() != Some(data) {
        std::fs::write(path, data).unwrap();
    }
}

/// Runs `cmd`, panics with its stderr on failure, returns its stdout.
pub fn run(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(o.status.success(), "{cmd:?} failed:\n{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Median (upper middle) of `xs`, which must not be empty.
pub fn median(xs: &[f64]) -> f64 {
    let mut c = xs.to_vec();
    c.sort_by(f64::total_cmp);
    c[c.len() / 2]
}

/// The CPU's model name and the clock `/proc/cpuinfo` reports (MHz; NaN when unknown).
pub fn clock() -> (String, f64) {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let field = |k: &str| {
        info.lines().find(|l| l.starts_with(k)).and_then(|l| l.split(':').nth(1)).map(|v| v.trim().to_string())
    };
    (
        field("model name").unwrap_or_else(|| "?".into()),
        field("cpu MHz").and_then(|m| m.parse().ok()).unwrap_or(f64::NAN),
    )
}

/// The states of `export_model.py`'s `states.txt`: per state the coordinates `x` (one per
/// velocity), Pinocchio's configuration `q`, velocities `v` and accelerations `a`; gravity `g`;
/// whether the root joint is Pinocchio's free-flyer (a layout of kind 2).
pub struct States {
    pub nv: usize,
    pub g: [f64; 3],
    pub free_flyer: bool,
    pub x: Vec<Vec<f64>>,
    pub q: Vec<Vec<f64>>,
    pub v: Vec<Vec<f64>>,
    pub a: Vec<Vec<f64>>,
}

/// Reads `states.txt` (format in `export_model.py`).
pub fn read_states(path: &Path) -> States {
    let text = std::fs::read_to_string(path).unwrap();
    let mut w = text.split_whitespace();
    let mut int = || -> usize { w.next().unwrap().parse().unwrap() };
    let (n, nq, nv) = (int(), int(), int());
    let mut w = text.split_whitespace().skip(3);
    let mut num = || -> f64 { w.next().expect("states.txt truncated").parse().unwrap() };
    let g = [num(), num(), num()];
    let mut free_flyer = false;
    for _ in 0..nv {
        num();
        free_flyer |= num() == 2.0;
    }
    let mut s = States { nv, g, free_flyer, x: vec![], q: vec![], v: vec![], a: vec![] };
    for _ in 0..n {
        let mut take = |k: usize| (0..k).map(|_| num()).collect::<Vec<f64>>();
        s.x.push(take(nv));
        s.q.push(take(nq));
        s.v.push(take(nv));
        s.a.push(take(nv));
    }
    s
}

/// Value of robovec input `name` in state `s`: `q[i]` the state's coordinate `i − 1` (on a
/// free-flyer `q[1..7]` are Pinocchio's `q[0..7]`, base position and quaternion, and `q[i]`,
/// `i > 7`, the joint coordinate `i − 2`), `qd[i]`, `qdd[i]` its velocity, acceleration `i − 1`;
/// `g[k]` gravity; `S4`/`C4` (`trig=input`) sin/cos of `q[4]`. (The generalised forces `Qq[i]`
/// of the forward dynamics are the harness's: see `harness.cpp`.)
pub fn robovec_inputs(name: &str, st: &States, s: usize) -> f64 {
    let index = |p: &str| -> Option<usize> { name.strip_prefix(p)?.strip_suffix(']')?.parse().ok() };
    let trig = |p: char| -> Option<usize> { name.strip_prefix(p)?.parse().ok() };
    let coordinate = |i: usize| match (st.free_flyer, i) {
        (true, 1..=7) => st.q[s][i - 1],
        (true, _) => st.x[s][i - 2],
        (false, _) => st.x[s][i - 1],
    };
    if let Some(i) = index("q[") {
        coordinate(i)
    } else if let Some(i) = index("qd[") {
        st.v[s][i - 1]
    } else if let Some(i) = index("qdd[") {
        st.a[s][i - 1]
    } else if let Some(k) = index("g[") {
        st.g[k - 1]
    } else if let Some(i) = trig('S') {
        coordinate(i).sin()
    } else if let Some(i) = trig('C') {
        coordinate(i).cos()
    } else {
        panic!("robovec input {name}: no value in the shared states")
    }
}

/// Slot of robovec output `name` in the harness's layout of group `g` (0: `Qq[i]` → `i − 1`;
/// 1, 2: `M[i][j]` → `(i − 1)·nv + j − 1`; 2: `c[i]` → `nv² + i − 1`; 3: `qdd[i]` → `i − 1`;
/// 4: `dtau_dq`, `dtau_dv`, 5: `ddq_dq`, `ddq_dv`, `Minv`, 6: `Minv`, each matrix's `[i][j]` →
/// `k·nv² + (i − 1)·nv + j − 1` for the `k`-th matrix of the group).
pub fn output_slot(name: &str, g: usize, nv: usize) -> usize {
    let idx: Vec<usize> = name.split('[').skip(1).filter_map(|p| p.trim_end_matches(']').parse().ok()).collect();
    let matrix = |k: usize, i: usize, j: usize| k * nv * nv + (i - 1) * nv + j - 1;
    match (name.split('[').next().unwrap(), g, idx.as_slice()) {
        ("Qq", 0, [i]) => i - 1,
        ("M", 1 | 2, [i, j]) => (i - 1) * nv + j - 1,
        ("c", 2, [i]) => nv * nv + i - 1,
        ("qdd", 3, [i]) => i - 1,
        ("dtau_dq", 4, [i, j]) | ("ddq_dq", 5, [i, j]) | ("Minv", 6, [i, j]) => matrix(0, *i, *j),
        ("dtau_dv", 4, [i, j]) | ("ddq_dv", 5, [i, j]) => matrix(1, *i, *j),
        ("Minv", 5, [i, j]) => matrix(2, *i, *j),
        _ => panic!("robovec output {name} in group {g}"),
    }
}

/// Entries per state of each group's layout in the harness (see [`output_slot`]).
fn group_size(g: usize, nv: usize) -> usize {
    [nv, nv * nv, nv * nv + nv, nv, 2 * nv * nv, 3 * nv * nv, nv * nv][g]
}

/// Error figures of one contestant on one function.
#[derive(Clone, Copy)]
pub struct Errors {
    /// Bits of error, mean and max over states and entries.
    pub mean_bits: f64,
    pub max_bits: f64,
    /// Worst over states of ‖values − reference‖∞ / ‖reference‖∞.
    pub relative: f64,
}

/// [`Errors`] of each contestant's values in the harness's `values.bin` (the blocks of `groups`,
/// in increasing order) against the `long double` reference; for `M` and `M⁻¹` of groups 1, 2
/// and 6 the upper triangle only (the lower one is a copy on every side).
pub fn errors(
    path: &Path,
    names: &BTreeMap<usize, (usize, String)>,
    groups: &[usize],
    nv: usize,
    nsets: usize,
) -> BTreeMap<usize, Errors> {
    let bytes = std::fs::read(path).unwrap();
    let vals: Vec<f64> = bytes.chunks_exact(8).map(|c| f64::from_ne_bytes(c.try_into().unwrap())).collect();
    let counted = |g: usize, k: usize| !matches!(g, 1 | 2 | 6) || k >= nv * nv || k / nv <= k % nv;
    let mut at = 0;
    let mut out = BTreeMap::new();
    let mut sorted = groups.to_vec();
    sorted.sort_unstable();
    for g in sorted {
        let size = group_size(g, nv);
        let block = nsets * size;
        let reference = &vals[at..at + block];
        at += block;
        for (&c, _) in names.iter().filter(|(_, (gg, _))| *gg == g) {
            let mine = &vals[at..at + block];
            at += block;
            let entries = || (0..block).filter(|&i| counted(g, i % size));
            let bits: Vec<f64> = entries().map(|i| robovec_ir::numerics::bits_f64(mine[i], reference[i])).collect();
            let mut relative: f64 = 0.0;
            for s in 0..nsets {
                let range = s * size..(s + 1) * size;
                let norm = range.clone().fold(0.0f64, |m, i| m.max(reference[i].abs()));
                let diff = range.fold(0.0f64, |m, i| m.max((mine[i] - reference[i]).abs()));
                // A NaN (a value never written) stays NaN and fails the caller's check.
                relative = if relative.is_nan() || diff.is_nan() { f64::NAN } else { relative.max(diff / norm) };
            }
            out.insert(
                c,
                Errors {
                    mean_bits: bits.iter().sum::<f64>() / bits.len() as f64,
                    max_bits: bits.iter().copied().fold(0.0, f64::max),
                    relative,
                },
            );
        }
    }
    assert_eq!(at, vals.len(), "{}: size", path.display());
    out
}
