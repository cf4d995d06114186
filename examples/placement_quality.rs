//! Placement quality over the corpus: for every straight-line Robotran file of
//! `../shared/corpus/robotran` and every N in {1, 2, 4, 8, 16, 32, 64}, the placed cycles
//! (classical priority, preferential selection, default options) against the SPEC §4 lower
//! bound and the tight lower bound (`place::tight_lower_bound`). Prints the runs above
//! 1.02 × the tight bound and a summary.
//!
//! `cargo run --release --example placement_quality [-- FILTER]`

use robovec_passes::atomise::atomise_function;
use robovec_passes::place::{cycles, lower_bound, place_function, tight_lower_bound, PlaceOptions};

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/robotran");
    let mut files = Vec::new();
    for sub in ["c", "matlab", "python"] {
        for e in std::fs::read_dir(root.join(sub)).expect("the corpus at ../shared/corpus/robotran") {
            let p = e.expect("dir entry").path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let straight = !name.contains("accelred") && !name.contains("invdynared");
            if straight && p.extension().is_some_and(|x| x == "c" || x == "m" || x == "py") && name.contains(&filter) {
                files.push(p);
            }
        }
    }
    files.sort();
    let (mut runs, mut over_spec, mut over_tight_105, mut over_tight_102) = (0, 0, 0, 0);
    let (mut worst_spec, mut worst_tight) = ((1.0f64, String::new()), (1.0f64, String::new()));
    for p in files {
        let (m, _) = robovec::driver::load(p.to_str().unwrap()).unwrap_or_else(|f| panic!("{}", f.message()));
        for f in m.functions.iter().map(atomise_function) {
            if f.op_counts().total == 0 {
                continue;
            }
            for n in [1, 2, 4, 8, 16, 32, 64] {
                let o = PlaceOptions::with_pes(n);
                let c = cycles(&f, &place_function(&f, &o));
                let (lb, tight) = (lower_bound(&f, &o.arch), tight_lower_bound(&f, &o.arch));
                let name = format!("{} @{} N={n}", p.file_name().unwrap().to_string_lossy(), f.name);
                let (rs, rt) = (c as f64 / lb as f64, c as f64 / tight as f64);
                runs += 1;
                over_spec += usize::from(rs > 1.05);
                over_tight_105 += usize::from(rt > 1.05);
                over_tight_102 += usize::from(rt > 1.02);
                if rt > 1.02 || rs > 1.05 {
                    println!("{name}: {c} cycles, SPEC LB {lb} ({rs:.3}), tight LB {tight} ({rt:.3})");
                }
                if rs > worst_spec.0 {
                    worst_spec = (rs, name.clone());
                }
                if rt > worst_tight.0 {
                    worst_tight = (rt, name);
                }
            }
        }
    }
    println!("{runs} runs; above 1.05 x SPEC LB: {over_spec}; above 1.05 x tight LB: {over_tight_105}; above 1.02 x tight LB: {over_tight_102}");
    println!(
        "worst / SPEC LB {:.4} ({}); worst / tight LB {:.4} ({})",
        worst_spec.0, worst_spec.1, worst_tight.0, worst_tight.1
    );
}
