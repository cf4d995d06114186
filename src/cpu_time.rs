//! The time of a function's generated C on the machine that runs robovec: what `-report-dir`
//! draws beside a model's cost (issue 48 item 6, "cost (ns/state …) against the budget"; the
//! CPU beside the FPGA of issue 49 is the same measurement).
//!
//! One measurement ([`ns_per_state`]): the function's C (`codegen<c;abi=plain;trig=inline>`,
//! `batch=W`) and a driver are compiled by the system compiler (`$CC`, else `cc`) with
//! `-O3 -march=native -ffp-contract=off` in a temporary folder; the driver calls the function on
//! [`STATES`] states drawn uniformly from the domain (a point where an input's range is one),
//! cycling through them, in [`REPEATS`] timed repeats of about 2 ms each, and prints the median
//! ns per state. One process, one function: the numbers of a figure are side by side in time
//! but not interleaved, so they are a picture of the machine, not a benchmark claim
//! (`scripts/precision_speed.sh` alternates its contestants). Under `-time-limit` the compiler
//! and the program are stopped (killed) at the deadline given, and the measurement fails.

use std::fmt::Write as _;
use std::path::Path;

use robovec_backends::c::{CodegenC, Trig};
use robovec_ir::domain::Domain;
use robovec_ir::rng::SplitMix64;
use robovec_ir::time_limit::Deadline;
use robovec_ir::{Function, Module};

/// The compiler's flags (the generated file asks for `-ffp-contract=off`).
pub const FLAGS: [&str; 4] = ["-O3", "-march=native", "-ffp-contract=off", "-std=c99"];

/// The system C compiler: `$CC`, else `cc`.
pub fn compiler() -> String {
    std::env::var("CC").unwrap_or_else(|_| "cc".into())
}

/// States the driver cycles through (drawn once, lane-contiguous per call).
pub const STATES: usize = 16;
/// Timed repeats; the median is reported.
pub const REPEATS: usize = 31;

/// Runs `work` in a scratch folder (`$TMPDIR/robovec-TAG-PID`, made first, removed after) with
/// the deadline of skippable work on `module`: `cx`'s, keeping back the output's tail as the
/// passes do ([`robovec_passes::time_limit::kept_for`]).
///
/// # Errors
/// `work`'s, or a message when the folder cannot be made.
pub fn measuring<T>(
    module: &Module,
    cx: &robovec_passes::PassContext,
    tag: &str,
    work: impl FnOnce(&Path, Option<&Deadline>) -> Result<T, String>,
) -> Result<T, String> {
    let kept = robovec_passes::time_limit::kept_for(robovec_passes::manager::module_ops(module));
    let deadline = cx.deadline.map(|d| d.keeping(kept));
    let dir = std::env::temp_dir().join(format!("robovec-{tag}-{}", std::process::id()));
    let result = std::fs::create_dir_all(&dir).map_err(|e| e.to_string()).and_then(|()| work(&dir, deadline.as_ref()));
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// The median ns per state of `f`'s C at `batch` states per call, compiled and run in `dir`
/// (an existing folder the caller removes), its inputs drawn from `domain` (seed 48), stopped
/// at `deadline`.
///
/// # Errors
/// A message when an input has no range in `domain`, the C cannot be written (a pass error of
/// `codegen<c>`), the compiler or the program fails (the compiler's own message), or the
/// deadline comes first.
pub fn ns_per_state(
    f: &Function,
    domain: &Domain,
    batch: u32,
    dir: &Path,
    deadline: Option<&Deadline>,
) -> Result<f64, String> {
    ns_per_state_drawn(f, batch, dir, deadline, |name, u| {
        let r = domain.get(name).ok_or_else(|| format!("input `{name}` has no range in the domain"))?.interval;
        Ok((r.lo + u * (r.hi - r.lo)).clamp(r.lo, r.hi))
    })
}

/// [`ns_per_state`] without a domain: every input uniform in [0.1, 1] (no divisor or square
/// root's operand at 0 for a Robotran model's trig and parameters; the time of straight-line
/// code does not depend on the values otherwise, subnormals aside).
///
/// # Errors
/// As [`ns_per_state`].
pub fn ns_per_state_anywhere(f: &Function, batch: u32, dir: &Path, deadline: Option<&Deadline>) -> Result<f64, String> {
    ns_per_state_drawn(f, batch, dir, deadline, |_, u| Ok(0.1 + 0.9 * u))
}

/// [`ns_per_state`] with input `name`'s value `draw(name, u)` for `u` uniform in [0, 1).
fn ns_per_state_drawn(
    f: &Function,
    batch: u32,
    dir: &Path,
    deadline: Option<&Deadline>,
    mut draw: impl FnMut(&str, f64) -> Result<f64, String>,
) -> Result<f64, String> {
    let m = Module { functions: vec![f.clone()] };
    let codegen = CodegenC { name: Some("robovec_timed".into()), batch, trig: Trig::Inline, ..CodegenC::default() };
    let art = codegen.emit(&m).map_err(|e| e.to_string())?;
    let iface = &art.interfaces[0];
    let (ni, no, w) = (iface.inputs.len(), iface.outputs.len(), batch as usize);
    let mut rng = SplitMix64::new(48);
    let mut states = String::new();
    for _ in 0..STATES {
        let mut call = vec![0.0; ni * w];
        for lane in 0..w {
            for (i, name) in iface.inputs.iter().enumerate() {
                call[i * w + lane] = draw(name, rng.unit())?;
            }
        }
        let row: Vec<String> = call.iter().map(|x| format!("{x:e}")).collect();
        let _ = writeln!(states, "  {{{}}},", if row.is_empty() { "0".into() } else { row.join(", ") });
    }
    // About 2 ms a repeat, from the op count (≈ 1 ns an op and state at worst).
    let ops = f.op_counts().total.max(1) as usize;
    let calls = (2_000_000 / (ops * w)).clamp(1, 1_000_000);
    let symbol = &iface.symbol;
    let main = format!(
        "#define _POSIX_C_SOURCE 199309L\n#include <stdio.h>\n#include <stdlib.h>\n#include <time.h>\n\
         void {symbol}(const double *restrict in, double *restrict out);\n\
         static const double states[{STATES}][{}] = {{\n{states}}};\n\
         static double out[{}];\n\
         static int by_value(const void *a, const void *b) {{ double x = *(const double *)a, y = *(const double *)b; return (x > y) - (x < y); }}\n\
         int main(void)\n{{\n  double t[{REPEATS}];\n  volatile double sink = 0;\n  \
         for (int r = 0; r < {REPEATS}; r++) {{\n    struct timespec a, b;\n    clock_gettime(CLOCK_MONOTONIC, &a);\n    \
         for (int k = 0; k < {calls}; k++) {{ {symbol}(states[k % {STATES}], out); sink += out[0]; }}\n    \
         clock_gettime(CLOCK_MONOTONIC, &b);\n    \
         t[r] = ((double)(b.tv_sec - a.tv_sec) * 1e9 + (double)(b.tv_nsec - a.tv_nsec)) / ({calls}.0 * {w});\n  }}\n  \
         qsort(t, {REPEATS}, sizeof t[0], by_value);\n  printf(\"%.6g\\n\", t[{REPEATS} / 2]);\n  (void)sink;\n  return 0;\n}}\n",
        (ni * w).max(1),
        (no * w).max(1),
    );
    std::fs::write(dir.join("timed.c"), &art.code.main).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("main.c"), main).map_err(|e| e.to_string())?;
    let cc = compiler();
    let exe = dir.join("timed");
    let mut compile = std::process::Command::new(&cc);
    compile.current_dir(dir).args(FLAGS).arg("-o").arg(&exe).args(["main.c", "timed.c", "-lm"]);
    let o = run(compile, deadline).map_err(|e| format!("the C compiler `{cc}`: {e}"))?;
    if !o.status.success() {
        return Err(format!("`{cc}` failed: {}", String::from_utf8_lossy(&o.stderr).lines().next().unwrap_or("")));
    }
    let o = run(std::process::Command::new(&exe), deadline).map_err(|e| format!("the timed program: {e}"))?;
    if !o.status.success() {
        return Err("the timed program failed".into());
    }
    String::from_utf8_lossy(&o.stdout)
        .trim()
        .parse::<f64>()
        .map_err(|e| format!("the timed program printed no time: {e}"))
}

/// `cmd`'s output, the process killed when `deadline` comes first.
fn run(mut cmd: std::process::Command, deadline: Option<&Deadline>) -> Result<std::process::Output, String> {
    use std::io::Read as _;
    let mut child = cmd
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start: {e}"))?;
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            let (mut out, mut err) = (Vec::new(), Vec::new());
            if let Some(mut s) = child.stdout.take() {
                let _ = s.read_to_end(&mut out);
            }
            if let Some(mut s) = child.stderr.take() {
                let _ = s.read_to_end(&mut err);
            }
            return Ok(std::process::Output { status, stdout: out, stderr: err });
        }
        if deadline.is_some_and(Deadline::reached) {
            let _ = child.kill();
            let _ = child.wait();
            return Err("stopped at the time limit".into());
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f() -> Function {
        robovec_ir::text::parse(
            "func @f { phase atomised input %a input %b %x = mul %a, %b %y = add %x, %a output y = %y }",
        )
        .unwrap()
        .functions
        .remove(0)
    }

    /// A measurement gives a positive time; past its deadline it stops (the compiler killed)
    /// and says so.
    #[test]
    fn it_times_and_stops_at_the_deadline() {
        let dir = std::env::temp_dir().join(format!("robovec-cpu-time-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ns = ns_per_state_anywhere(&f(), 4, &dir, None).expect("cc (scripts/test.sh installs gcc)");
        assert!(ns > 0.0 && ns.is_finite(), "{ns}");
        let past = Deadline::after_seconds(0.0);
        let e = ns_per_state_anywhere(&f(), 1, &dir, Some(&past)).unwrap_err();
        assert!(e.contains("stopped at the time limit"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
