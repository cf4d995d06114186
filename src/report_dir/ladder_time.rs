//! The measured time of each point of the budget ladder (issue 48 item 6: "a figure of cost
//! (ns/state …) against the budget"): for target `c`, the C of the function with each point's
//! formats at `batch=8` or `batch=16` (8 `float` lanes are one AVX2 register, 16 one AVX-512
//! register), the faster, and the best binary64 C — every value binary64 at `batch=4` (the speed
//! table's baseline in docs/accuracy.md: one AVX2 register) or `batch=8` (one AVX-512 register,
//! or two AVX2 ones), the faster — timed on this machine ([`crate::cpu_time`]).
//! Points with the same formats are measured once. The figure `budget.svg` draws their ratio
//! beside the model's; `budget.csv` holds the numbers.

use robovec_passes::precision::ladder::BudgetLadder;
use robovec_passes::precision::PrecisionRun;
use robovec_passes::PassContext;

/// Lanes of the mixed-precision C (8 `float` lanes: one AVX2 register; 16: one AVX-512 one).
pub const BATCHES: [u32; 2] = [8, 16];
/// Lanes of the binary64 baselines (4 `double` lanes: one AVX2 register; 8).
pub const BINARY64_BATCHES: [u32; 2] = [4, 8];

/// Measures the last budget ladder of `function` (target `c` only) and emits it again with its
/// times ([`BudgetLadder::binary64_ns_per_state`], each point's `ns_per_state`); a failure (no C
/// compiler, a program that fails) is a note (`-report-dir: measured time …`) and the ladder
/// stays as it was.
pub fn measure(module: &robovec_ir::Module, cx: &mut PassContext, function: &str) {
    let Some(ladder) = cx.artifacts_of::<BudgetLadder>().filter(|l| l.function == function).last().cloned() else {
        return;
    };
    if ladder.target != "c" || ladder.points.is_empty() {
        return;
    }
    let Some(run) =
        cx.artifacts_of::<PrecisionRun>().filter(|r| r.functions.iter().any(|p| p.function == function)).last()
    else {
        return;
    };
    let domain = run.domain.clone();
    let Some(f) = module.function(function) else { return };
    let mut plain = f.clone();
    plain.clear_formats();
    let result = crate::cpu_time::measuring(module, cx, "time", |dir, deadline| {
        let mut out = ladder.clone();
        let best = fastest(&plain, &domain, &BINARY64_BATCHES, dir, deadline)?;
        out.binary64_ns_per_state = best.map(|b| b.0);
        out.binary64_batch = best.map(|b| b.1);
        let mut seen: Vec<(&Vec<_>, Option<(f64, u32)>)> = Vec::new();
        for (k, formats) in ladder.assignments.iter().enumerate() {
            let time = match seen.iter().find(|(a, _)| *a == formats) {
                Some(&(_, time)) => time,
                None => {
                    let mut g = plain.clone();
                    for &(v, fmt) in formats {
                        g.set_format(v, fmt);
                    }
                    let time = fastest(&g, &domain, &BATCHES, dir, deadline)?;
                    seen.push((formats, time));
                    time
                }
            };
            out.points[k].ns_per_state = time.map(|t| t.0);
            out.points[k].ns_batch = time.map(|t| t.1);
        }
        Ok(out)
    });
    match result {
        Ok(l) => cx.emit(l),
        Err(e) => cx.note_stop("-report-dir: measured time of the budget ladder", &format!("not measured: {e}")),
    }
}

/// The smaller median ns per state of `f`'s C over `batches`, and its batch.
fn fastest(
    f: &robovec_ir::Function,
    domain: &robovec_ir::domain::Domain,
    batches: &[u32],
    dir: &std::path::Path,
    deadline: Option<&robovec_ir::time_limit::Deadline>,
) -> Result<Option<(f64, u32)>, String> {
    let mut best: Option<(f64, u32)> = None;
    for &batch in batches {
        let ns = crate::cpu_time::ns_per_state(f, domain, batch, dir, deadline)?;
        if best.is_none_or(|(b, _)| ns < b) {
            best = Some((ns, batch));
        }
    }
    Ok(best)
}
