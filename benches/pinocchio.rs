//! robovec's generated C against Pinocchio's C++ (issue 14), side by side in one process.
//!
//! `cargo bench --bench pinocchio -- [ROBOT…] [--reps=N] [--runs=K]`
//!
//! Robots (default: all): `ur5`, `panda` (fixed base), `solo12`, `talos`, `tiago_pro` (Robotran's
//! floating base, Pinocchio's composite root joint PX PY PZ RX RY RZ), `serial30` (the 30-dof
//! serial topology family robot, `robovec_dynamics::topology`, seed 1) — the robots of
//! `tests/pinocchio.rs`. For each robot it
//! 1. runs `benches/pinocchio/export_model.py` with the venv's Python: Pinocchio's model built as
//!    the oracle builds it, saved with `saveToText`, and 64 random states (the oracle's
//!    distribution) shared by both sides;
//! 2. writes robovec's C with `robovec-opt URDF -function=F --fold-params [--floating-base]
//!    -passes=PIPELINE,codegen<c;abi=plain;…>` for [`VARIANTS`] of three functions: `invdyna`
//!    (against `pinocchio::rnea`), `dirdyna` cut by `dce<outputs=…>` to the upper triangle of
//!    `M` (against `pinocchio::crba`, which fills the upper triangle only) and to that and `c`
//!    (against `crba` then `nonLinearEffects`): both sides compute and store the same entries
//!    (Robotran's `M[j][i] = M[i][j]` copies of the lower triangle are 0 ops but 1.9× the
//!    stores: 13% of `M`'s time on TIAGo Pro at `batch=8`);
//! 3. builds one binary: `benches/pinocchio/harness.cpp` (Pinocchio header-only, instantiated
//!    for `double` and `long double`, `g++ -O3 -march=native -DNDEBUG`; compiled once and cached
//!    in `target/pinocchio_bench/` under the hash of its source and flags: ~3 min), robovec's C
//!    (`cc -O3 -march=native -ffp-contract=off`) and the table of inputs and maps `table.c`;
//! 4. runs it `runs` times (default 5, `reps` default 101): each rep times every contestant of a function once,
//!    alternating, the order rotated each rep, ~0.3 ms per sample cycling over the 64 states; the
//!    ratio is built from **paired** samples (Pinocchio's ns over robovec's in the same rep; for
//!    `crba` the faster of Pinocchio's LOCAL and WORLD conventions in that run), median per run,
//!    then median over the runs;
//! 5. measures bits of error (`robovec_ir::numerics::bits_f64`, Herbie's ordinal distance, the
//!    `accuracy` pass's metric) of every contestant's f64 values on the 64 states against
//!    Pinocchio evaluated on `long double` (64-bit significand) from the exact coordinates;
//!    for `M` only the upper triangle counts (the lower one is a copy on both sides).
//!
//! Prints a Markdown table and writes it to `target/pinocchio_bench/table.md`. Needs `cc`, `g++`
//! and the Pinocchio venv at `target/pinocchio-venv` (or `ROBOVEC_PINOCCHIO_PYTHON`) with
//! `cmeel-eigen` for Eigen's headers; fails with the commands to create it otherwise.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::process::Command;

#[path = "pinocchio/side.rs"]
mod side;

use side::{read_states, robovec_inputs, run, Env, States};

/// States both sides evaluate (a multiple of every batch width).
const NSETS: usize = 64;

/// robovec's variants of each function: label, pipeline before `codegen`, lanes, `trig`. One
/// state without `schedule-cpu` (it does not help one state: docs/codegen-c.md "Speed of the generated C");
/// batches of 4 (one AVX2 vector of doubles) and 8 (one AVX-512 vector: the fastest width per
/// state where the machine has AVX-512, 4 where it has AVX2 only: 8 and 16 lanes were 5–45 %
/// slower per state on TIAGo Pro and serial30 on a Zen 3). `trig=libm` and `trig=inline`
/// compute sin/cos, like for like with Pinocchio; `trig=input` takes them as inputs (the
/// ceiling: what computing them costs is the difference). `fma`: the `contract` pass fuses
/// multiplies into additions (C99 `fma`, one rounding, bit-exact with robovec's interpreter),
/// like for like with Pinocchio, whose `-O3 -march=native` build contracts; `batch=8,
/// trig=inline` without it shows what the fusion gives. `zero-removal` before it (exact: it
/// only moves signs) turns `0 − a·b` into a product with a negated constant where it can,
/// instead of a fused `0 − a·b` (serial30's `M` −27 ops, TIAGo Pro's −52: 2.5 % and 3.5 %
/// faster at `batch=8` on a Zen 3).
const VARIANTS: [(&str, &str, u32, &str); 6] = [
    ("1 state, trig=libm", "atomise,cse", 1, "libm"),
    ("1 state, trig=inline, fma", "atomise,cse,zero-removal,contract", 1, "inline"),
    ("batch=4, trig=inline, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 4, "inline"),
    ("batch=8, trig=inline", "atomise,cse,zero-removal,schedule-cpu", 8, "inline"),
    ("batch=8, trig=inline, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 8, "inline"),
    ("batch=8, trig=input, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 8, "input"),
];

/// The variants whose bits of error the summary shows: without and with fused multiply-adds.
const BITS_OF: [&str; 2] = ["1 state, trig=libm", "batch=8, trig=inline, fma"];

/// The three comparisons: label, robovec function, outputs kept (`dce`), Pinocchio's side.
const GROUPS: [(&str, &str, Keep, &str); 3] = [
    ("inverse dynamics", "invdyna", Keep::All, "rnea"),
    ("mass matrix", "dirdyna", Keep::UpperM, "crba"),
    ("M and c", "dirdyna", Keep::UpperMAndC, "crba + nonLinearEffects"),
];

/// The outputs of robovec's function a comparison keeps.
#[derive(Clone, Copy)]
enum Keep {
    All,
    /// `M[i][j]`, `i ≤ j`: what `crba` fills.
    UpperM,
    /// That and `c`.
    UpperMAndC,
}

impl Keep {
    /// The pipeline's `dce<outputs=…>,` (empty for [`Keep::All`]) for `nv` coordinates, and
    /// its short label.
    fn dce(self, nv: usize) -> (String, &'static str) {
        let upper: Vec<String> = (1..=nv).flat_map(|i| (i..=nv).map(move |j| format!("M[{i}][{j}]"))).collect();
        match self {
            Keep::All => (String::new(), ""),
            Keep::UpperM => (format!("dce<outputs={}>,", upper.join(",")), "dce<outputs=M upper>,"),
            Keep::UpperMAndC => (format!("dce<outputs={},c>,", upper.join(",")), "dce<outputs=M upper,c>,"),
        }
    }
}

/// A robot of the comparison.
struct Robot {
    name: &'static str,
    /// `erd:REL` (example-robot-data) or `gen:serial30`.
    urdf: &'static str,
    floating: bool,
}

const ROBOTS: [Robot; 6] = [
    Robot { name: "ur5", urdf: "erd:ur_description/urdf/ur5_robot.urdf", floating: false },
    Robot { name: "panda", urdf: "erd:panda_description/urdf/panda.urdf", floating: false },
    Robot { name: "solo12", urdf: "erd:solo_description/robots/solo12.urdf", floating: true },
    Robot { name: "talos", urdf: "erd:talos_data/robots/talos_reduced.urdf", floating: true },
    Robot { name: "tiago_pro", urdf: "erd:tiago_pro_description/robots/tiago_pro.urdf", floating: true },
    Robot { name: "serial30", urdf: "gen:serial30", floating: false },
];

/// One contestant's figures on one robot and function.
struct Figures {
    name: String,
    group: usize,
    /// Median ns per state over the runs (each run's median), and its min–max.
    ns: (f64, f64, f64),
    /// Median over runs of the median paired ratio Pinocchio / this (1 for Pinocchio's best).
    ratio: f64,
    errors: side::Errors,
}

fn bench_robot(env: &Env, robot: &Robot, (reps, runs): (u32, u32)) -> (usize, Vec<Figures>) {
    let work = env.work.join(robot.name);
    std::fs::create_dir_all(&work).unwrap();
    eprintln!("== {}", robot.name);
    let urdf_spec = if let Some(g) = robot.urdf.strip_prefix("gen:") {
        assert_eq!(g, "serial30");
        let r = robovec_dynamics::topology::build(robovec_dynamics::topology::Topology::Serial, 30, 1);
        let p = work.join("serial30.urdf");
        side::write_if_changed(&p, robovec_dynamics::urdf_out::write_urdf(&r).as_bytes());
        p.to_string_lossy().into_owned()
    } else {
        robot.urdf.to_string()
    };
    let mut export = Command::new(&env.python);
    export.arg(env.root.join("benches/pinocchio/export_model.py")).arg(&urdf_spec).arg(&work);
    export.args([NSETS.to_string(), "1".into()]);
    if robot.floating {
        export.arg("floating");
    }
    let info: serde_json::Value = serde_json::from_str(&run(&mut export)).expect("export_model.py's JSON");
    let urdf = info["path"].as_str().unwrap().to_string();
    let states: States = read_states(&work.join("states.txt"));
    assert_eq!(states.x.len(), NSETS);
    let nv = states.nv;

    // robovec's C, one file per (function, variant).
    let mut columns: Vec<String> = Vec::new();
    let mut entries = Vec::new();
    let mut decls = String::new();
    let mut sources = Vec::new();
    for (g, (_, function, keep, _)) in GROUPS.iter().enumerate() {
        let (prefix, short) = keep.dce(nv);
        for (v, (label, pipeline, batch, trig)) in VARIANTS.iter().enumerate() {
            let i = g * VARIANTS.len() + v;
            let report = work.join(format!("rv{i}.json"));
            let fresh = work.join(format!("rv{i}.new.c"));
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_robovec-opt"));
            cmd.arg(&urdf).arg(format!("-function={function}")).arg("--fold-params");
            if robot.floating {
                cmd.arg("--floating-base");
            }
            let full = pipeline.replacen("atomise,", &format!("atomise,{prefix}"), 1);
            cmd.arg(format!("-passes={full},codegen<c;abi=plain;batch={batch};trig={trig};name=rv{i}>"));
            let pipeline = pipeline.replacen("atomise,", &format!("atomise,{short}"), 1);
            run(cmd.arg("-o").arg(&fresh).arg(format!("-report={}", report.display())));
            let src = work.join(format!("rv{i}.c"));
            side::write_if_changed(&src, &std::fs::read(&fresh).unwrap());
            sources.push(src);
            let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
            let list = |k: &str| -> Vec<String> {
                j["codegen"][k].as_array().unwrap().iter().map(|x| x.as_str().unwrap().to_string()).collect()
            };
            let (ins, outs) = (list("inputs"), list("outputs"));
            let symbol = j["codegen"]["symbol"].as_str().unwrap().to_string();
            let in_map: Vec<String> = ins
                .iter()
                .map(|n| {
                    if !columns.contains(n) {
                        columns.push(n.clone());
                    }
                    columns.iter().position(|c| c == n).unwrap().to_string()
                })
                .collect();
            let out_map: Vec<String> = outs.iter().map(|o| side::output_slot(o, g, nv).to_string()).collect();
            let _ = writeln!(decls, "void {symbol}(const double *restrict in, double *restrict out);");
            let _ = writeln!(decls, "static const int in_map{i}[] = {{{},0}};", in_map.join(","));
            let _ = writeln!(decls, "static const int out_map{i}[] = {{{},0}};", out_map.join(","));
            entries.push(format!(
                "  {{\"{pipeline} {label}\", {symbol}, {g}, {batch}, {}, {}, in_map{i}, out_map{i}}},",
                ins.len(),
                outs.len()
            ));
        }
    }
    let mut table = String::from("#include <stddef.h>\n");
    table += "typedef void (*rv_fn)(const double *in, double *out);\n";
    table += "typedef struct { const char *label; rv_fn fn; int group, batch, n_in, n_out; const int *in_map, *out_map; } RvVariant;\n";
    let _ = writeln!(
        table,
        "const int RV_NSETS = {NSETS}, RV_NCOLS = {}, RV_NVARIANTS = {};",
        columns.len(),
        entries.len()
    );
    table += "const double RV_SETS[] = {\n";
    for s in 0..NSETS {
        let row: Vec<String> = columns.iter().map(|c| format!("{:e}", robovec_inputs(c, &states, s))).collect();
        let _ = writeln!(table, "  {},", row.join(","));
    }
    table += "};\n";
    table += &decls;
    let _ = writeln!(table, "const RvVariant RV_VARIANTS[] = {{\n{}\n}};", entries.join("\n"));
    let table_c = work.join("table.c");
    side::write_if_changed(&table_c, table.as_bytes());
    sources.push(table_c);

    let exe = env.link(&work, &sources);
    let mut names: BTreeMap<usize, (usize, String)> = BTreeMap::new();
    // Per contestant, per run: median ns and median paired ratio.
    let mut per_run: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
    for r in 0..runs {
        let values = work.join("values.bin");
        let out = run(Command::new(&exe)
            .arg(work.join("model.txt"))
            .arg(work.join("states.txt"))
            .arg(&values)
            .arg(reps.to_string()));
        let mut times: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
        for line in out.lines() {
            let f: Vec<&str> = line.split('\t').collect();
            match f.as_slice() {
                ["contestant", c, g, name] => {
                    names.insert(c.parse().unwrap(), (g.parse().unwrap(), name.to_string()));
                }
                ["time", c, _rep, ns] => times.entry(c.parse().unwrap()).or_default().push(ns.parse().unwrap()),
                _ => {}
            }
        }
        for (g, ..) in GROUPS.iter().enumerate() {
            let members: Vec<usize> = names.iter().filter(|(_, (gg, _))| *gg == g).map(|(c, _)| *c).collect();
            // Pinocchio's baseline in this run: its fastest algorithm (median) for the group.
            let base = *members
                .iter()
                .filter(|c| names[c].1.starts_with("pinocchio"))
                .min_by(|a, b| side::median(&times[a]).total_cmp(&side::median(&times[b])))
                .unwrap();
            for &c in &members {
                let paired: Vec<f64> = times[&base].iter().zip(&times[&c]).map(|(b, x)| b / x).collect();
                per_run.entry(c).or_default().push((side::median(&times[&c]), side::median(&paired)));
            }
        }
        eprintln!("   run {} of {runs} done", r + 1);
    }
    let errors = side::errors(&work.join("values.bin"), &names, nv, NSETS);
    let figures: Vec<Figures> = names
        .iter()
        .map(|(c, (g, name))| {
            let runs = &per_run[c];
            let ns: Vec<f64> = runs.iter().map(|r| r.0).collect();
            let ratios: Vec<f64> = runs.iter().map(|r| r.1).collect();
            Figures {
                name: name.clone(),
                group: *g,
                ns: (
                    side::median(&ns),
                    ns.iter().copied().fold(f64::INFINITY, f64::min),
                    ns.iter().copied().fold(0.0, f64::max),
                ),
                ratio: side::median(&ratios),
                errors: errors[c],
            }
        })
        .collect();
    // Both sides must compute the same function: a wrong map or a broken variant fails loudly.
    for f in &figures {
        assert!(
            f.errors.relative <= 1e-9,
            "{} {}: relative error {:e} against the long double reference",
            robot.name,
            f.name,
            f.errors.relative
        );
    }
    (nv, figures)
}

/// One row of the summary: Pinocchio's fastest algorithm against each robovec variant.
fn summary_row(robot: &str, nv: usize, g: usize, figs: &[Figures], mhz: f64) -> String {
    let mine: Vec<&Figures> = figs.iter().filter(|f| f.group == g).collect();
    let pin = mine
        .iter()
        .filter(|f| f.name.starts_with("pinocchio"))
        .min_by(|a, b| a.ns.0.total_cmp(&b.ns.0))
        .expect("a Pinocchio contestant");
    let mut row = format!(
        "| {robot} | {nv} | {} (`{}`) | {:.0} ({:.0} cycles) |",
        GROUPS[g].0,
        pin.name.trim_start_matches("pinocchio "),
        pin.ns.0,
        pin.ns.0 * mhz / 1e3
    );
    let variant = |label: &str| {
        mine.iter().find(|f| f.name.starts_with("robovec") && f.name.ends_with(label)).expect("each variant")
    };
    for (label, ..) in VARIANTS {
        let f = variant(label);
        let _ = write!(row, " {:.0} ({:.1}×) |", f.ns.0, f.ratio);
    }
    let _ = write!(row, " {:.2} / {:.0} |", pin.errors.mean_bits, pin.errors.max_bits);
    for label in BITS_OF {
        let e = &variant(label).errors;
        let _ = write!(row, " {:.2} / {:.0} |", e.mean_bits, e.max_bits);
    }
    row
}

fn main() {
    let mut wanted = Vec::new();
    let (mut reps, mut runs) = (101, 5);
    for a in std::env::args().skip(1) {
        if let Some(r) = a.strip_prefix("--reps=") {
            reps = r.parse().expect("--reps=N");
        } else if let Some(r) = a.strip_prefix("--runs=") {
            runs = r.parse().expect("--runs=N");
        } else if a.starts_with('-') {
            // cargo bench passes `--bench`.
        } else {
            assert!(
                ROBOTS.iter().any(|r| r.name == a),
                "unknown robot {a}: one of ur5 panda solo12 talos tiago_pro serial30"
            );
            wanted.push(a);
        }
    }
    let env = Env::new();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let (cpu, mhz) = side::clock();
    let mut summary = format!(
        "{cpu} at {mhz} MHz (cycles = ns × that clock); load average before: {}; {runs} runs × {reps} reps, medians; \
         (×) = Pinocchio's ns ÷ robovec's, paired per rep\n\n",
        load.trim()
    );
    summary += "| robot | dof | function (Pinocchio's fastest) | Pinocchio ns/state |";
    for (label, ..) in VARIANTS {
        let _ = write!(summary, " robovec {label} |");
    }
    summary += " bits of error mean / max: Pinocchio |";
    for label in BITS_OF {
        let _ = write!(summary, " robovec {label} |");
    }
    summary += "\n|---|---:|---|---:|";
    summary += &"---:|".repeat(VARIANTS.len());
    summary += &"---|".repeat(1 + BITS_OF.len());
    summary += "\n";
    let mut detail = format!(
        "| robot | dof | function | contestant | ns/state median over {runs} runs (min–max) | Pinocchio ÷ this (paired) | bits of error mean / max | worst relative error |\n|---|---:|---|---|---:|---:|---|---:|\n"
    );
    for robot in ROBOTS.iter().filter(|r| wanted.is_empty() || wanted.iter().any(|w| w == r.name)) {
        let (nv, figs) = bench_robot(&env, robot, (reps, runs));
        for f in &figs {
            let _ = writeln!(
                detail,
                "| {} | {nv} | {} | {} | {:.1} ({:.1}–{:.1}) | {:.2}× | {:.2} / {:.0} | {:.1e} |",
                robot.name,
                GROUPS[f.group].0,
                f.name,
                f.ns.0,
                f.ns.1,
                f.ns.2,
                f.ratio,
                f.errors.mean_bits,
                f.errors.max_bits,
                f.errors.relative
            );
        }
        for g in 0..GROUPS.len() {
            summary += &summary_row(robot.name, nv, g, &figs, mhz);
            summary.push('\n');
        }
    }
    let out = format!("{summary}\nEvery contestant:\n\n{detail}");
    print!("{out}");
    let path = env.work.join("table.md");
    std::fs::write(&path, &out).unwrap();
    eprintln!("table written to {}", path.display());
}
