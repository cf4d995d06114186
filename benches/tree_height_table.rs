//! The tree-height-reduction table of issue 5: for every straight-line corpus file, ops and
//! critical path (`asap_cycle`, cycles, default latencies) after each pipeline, the ratio to
//! the atomised critical path, and the cycles of `place<pe=N>` (classical priority,
//! preferential selection, forward-backward improvement — the pass defaults) at N = 8, 16, 32.
//!
//! Each pipeline runs through the pass manager exactly as `robovec-opt FILE -passes=P,place<pe=N>
//! -report=r.json` does (`r.json`'s `stats.ops.total`, `stats.asap_cycle`,
//! `placement.cycles`). A file with several functions (sensors) gets one row: ops summed,
//! critical path and cycles the largest over its functions.
//!
//! Run with `cargo bench --bench tree_height_table` (a few minutes); `-- --quick` skips the placements;
//! `-- FILTER` keeps the files whose name contains FILTER. Prints a Markdown table.

use std::path::PathBuf;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::Module;
use robovec_passes::place::{cycles, place_function, PlaceOptions};
use robovec_passes::{Instrumentation, PassContext, PassManager};

const PIPELINES: &[&str] = &[
    "atomise",
    "atomise,zero-removal",
    "atomise,zero-removal,swap",
    "atomise,zero-removal,swap,balance",
    "atomise,inline<max-uses=2>,balance",
    "atomise,inline<max-uses=3>,balance",
    "atomise,inline<max-uses=8>,balance",
    "atomise,inline<max-uses=64>,balance",
    "atomise,inline<max-uses=8>,distribute,balance",
    "atomise,inline<max-uses=64>,distribute<rounds=30>,balance",
];

fn corpus() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/robotran");
    let mut v = Vec::new();
    for sub in ["c", "matlab", "python"] {
        let d = dir.join(sub);
        for e in
            std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e} (the corpus must sit at ../shared)", d.display()))
        {
            let p = e.unwrap().path();
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            let ext = p.extension().map(|x| x.to_string_lossy().to_string()).unwrap_or_default();
            if ["c", "m", "py"].contains(&ext.as_str()) && !n.contains("accelred") && !n.contains("invdynared") {
                v.push(p);
            }
        }
    }
    v.sort();
    v
}

/// (ops, critical path, placed cycles at 8/16/32) of `m`.
fn measure(m: &Module, quick: bool) -> (u64, u32, [u32; 3]) {
    let lat = Latencies::default();
    let ops = m.functions.iter().map(|f| f.op_counts().total).sum();
    let cp = m.functions.iter().map(|f| compute_timing(f, &lat).1.asap_cycle).max().unwrap_or(0);
    let mut placed = [0; 3];
    if !quick {
        for (k, n) in [8, 16, 32].into_iter().enumerate() {
            let opts = PlaceOptions::with_pes(n);
            placed[k] = m.functions.iter().map(|f| cycles(f, &place_function(f, &opts))).max().unwrap_or(0);
        }
    }
    (ops, cp, placed)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    let quick = args.iter().any(|a| a == "--quick");
    let filter = args.iter().find(|a| !a.starts_with("--")).cloned().unwrap_or_default();
    println!("| file | pipeline | ops | ops ratio | asap_cycle | cp ratio | N=8 | N=16 | N=32 |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut totals = vec![(0u64, 0u64, 0.0f64, 0u32); PIPELINES.len()];
    for p in corpus().into_iter().filter(|p| p.to_string_lossy().contains(&filter)) {
        let (parsed, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let mut base = None;
        for (i, pipeline) in PIPELINES.iter().enumerate() {
            let mut m = parsed.clone();
            let pm = PassManager::with_registry(robovec_backends::REGISTRY, pipeline, Instrumentation::default())
                .expect("pipeline");
            pm.run(&mut m, &mut PassContext::default(), &mut std::io::sink())
                .unwrap_or_else(|e| panic!("{name} {pipeline}: {e}"));
            let (ops, cp, placed) = measure(&m, quick);
            if ops == 0 {
                break;
            }
            let (ops0, cp0) = *base.get_or_insert((ops, cp));
            let (r_ops, r_cp) = (ops as f64 / ops0 as f64, cp as f64 / cp0 as f64);
            let pl =
                if quick { "- | - | -".to_string() } else { format!("{} | {} | {}", placed[0], placed[1], placed[2]) };
            println!("| {name} | {pipeline} | {ops} | {r_ops:.2} | {cp} | {r_cp:.2} | {pl} |");
            let t = &mut totals[i];
            t.0 += ops0;
            t.1 += ops;
            t.2 += r_cp;
            t.3 += 1;
        }
    }
    println!("\nSummary over files (ops summed; critical-path ratio averaged over files):\n");
    println!("| pipeline | ops ratio | mean cp ratio | files |");
    println!("|---|---:|---:|---:|");
    for (pipeline, (o0, o, r, n)) in PIPELINES.iter().zip(totals) {
        println!("| {pipeline} | {:.3} | {:.3} | {n} |", o as f64 / o0 as f64, r / n.max(1) as f64);
    }
}
