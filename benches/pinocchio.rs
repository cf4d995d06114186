//! robovec's generated C against Pinocchio's C++ (issue 14) and against Pinocchio's own code
//! generator, CppADCodeGen (issue 30), side by side in one process: the dynamics and (issue 50)
//! their derivatives.
//!
//! `cargo bench --bench pinocchio -- [ROBOT…] [--reps=N] [--runs=K] [--base=composite|free-flyer]
//! [--functions=dynamics|derivatives|all] [--compile-times=yes|no]`
//!
//! Robots (default: all): `ur5`, `panda` (fixed base), `solo12`, `talos`, `tiago_pro` (floating
//! base: `--base=free-flyer`, the default, is Pinocchio's `JointModelFreeFlyer` and robovec's
//! `--free-flyer`; `--base=composite` is Robotran's six-joint base, robovec's
//! `--floating-base`, and Pinocchio's composite root joint PX PY PZ RX RY RZ), `serial30` (the 30-dof
//! serial topology family robot, `robovec_dynamics::topology`, seed 1) — the robots of
//! `tests/pinocchio.rs`. For each robot it
//! 1. runs `benches/pinocchio/export_model.py` with the venv's Python: Pinocchio's model built as
//!    the oracle builds it (or on the free-flyer), saved with `saveToText`, and 64 random states
//!    (the oracle's distribution; a free-flyer's quaternion uniform on the sphere) shared by all;
//! 2. runs `benches/pinocchio/cg_sources.py`: CppADCodeGen's C of `rnea`, `crba` (the upper
//!    triangle of `M`) and `aba`, and of `rnea_derivatives` (`CodeGenRNEADerivatives`' tape
//!    with the outputs `dtau_dq`, `dtau_dv`: robovec's function has no `dtau_da = M`),
//!    `aba_derivatives` (`CodeGenABADerivatives`) and `minv` (`CodeGenMinv`, the upper
//!    triangle) for that model (`--functions=` picks the groups; a large function comes in
//!    parts, `cg_F_forward_zero__k.c`, each compiled on its own) (`cg_export.cpp`, compiled once and cached in
//!    `target/pinocchio_bench/cg_export-HASH`, 5–9 min; the sources rewritten only when the model
//!    changes), each compiled twice as its own object ([`CG_BUILDS`]: `-O3 -march=native` and
//!    `-Ofast -march=native`, Pinocchio's default), its function renamed per build;
//! 3. writes robovec's C with `robovec-opt URDF -function=F --fold-params -gravity=G [--floating-base |
//!    --free-flyer] -passes=PIPELINE,codegen<c;abi=plain;…>` for [`VARIANTS`] of four functions:
//!    `invdyna` (against `pinocchio::rnea`), `dirdyna` cut by `dce<outputs=…>` to the upper
//!    triangle of `M` (against `pinocchio::crba`, which fills the upper triangle only) and to that
//!    and `c` (against `crba` then `nonLinearEffects`): both sides compute and store the same
//!    entries (Robotran's `M[j][i] = M[i][j]` copies of the lower triangle are 0 ops but 1.9× the
//!    stores: 13% of `M`'s time on TIAGo Pro at `batch=8`), and `fordyna` (against
//!    `pinocchio::aba`, from the `tau` of the reference inverse dynamics of each state), and the
//!    derivative functions `rnea_derivatives` (against `computeRNEADerivatives`),
//!    `aba_derivatives` (against `computeABADerivatives`, from the same `tau`) and `minv` cut
//!    by `dce<outputs=…>` to the upper triangle (against `computeMinverse`, which fills that
//!    triangle only); the derivatives with respect to `q` are along Pinocchio's tangent space on
//!    the free flyer;
//! 4. builds one binary: `benches/pinocchio/harness.cpp` (Pinocchio header-only, instantiated
//!    for `double` and `long double`, `g++ -O3 -march=native -DNDEBUG`; compiled once and cached
//!    in `target/pinocchio_bench/` under the hash of its source and flags: 3–9 min), CG's objects,
//!    robovec's C (`cc -O3 -march=native -ffp-contract=off`) and the table of inputs and maps
//!    `table.c`;
//! 5. runs it `runs` times (default 5, `reps` default 101): each rep times every contestant of a
//!    function once, alternating, the order rotated each rep, ~0.3 ms per sample (`--sample-ms=`)
//!    cycling over the 64 states; the ratios are built from **paired** samples against two baselines (the
//!    baseline's ns over the contestant's in the same rep): Pinocchio's run-time algorithm (for
//!    `crba` and `aba` the faster of the LOCAL and WORLD conventions in that run) and CG (the
//!    faster of its two builds in that run), median per run, then median over the runs;
//! 6. measures bits of error (`robovec_ir::numerics::bits_f64`, Herbie's ordinal distance, the
//!    `accuracy` pass's metric) of every contestant's f64 values on the 64 states against
//!    Pinocchio evaluated on `long double` (64-bit significand) from the exact coordinates;
//!    for `M` only the upper triangle counts (the lower one is a copy on every side).
//!
//! 7. times `cc -O2 -c` of CG's one-state source (all its parts) and robovec's
//!    [`COMPILE_TIMED`] file of each function, alternating, 3 times each (median); skipped
//!    with `--compile-times=no` (on Talos and TIAGo Pro they take about 25 minutes of the run).
//!
//! Prints a Markdown table (per function one row against Pinocchio's run-time algorithm and,
//! where CG has the function, one against CG), the compile times, and every contestant, and
//! writes them to `target/pinocchio_bench/table.md`.
//! Needs `cc`, `g++` and the Pinocchio venv at `target/pinocchio-venv` (or
//! `ROBOVEC_PINOCCHIO_PYTHON`) with `cmeel-eigen`, `cmeel-cppad` and `cmeel-cppadcodegen`; fails
//! with the commands to create it otherwise.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::process::Command;

#[path = "pinocchio/side.rs"]
mod side;

use side::{read_states, robovec_inputs, run, Env, States};

/// States both sides evaluate (a multiple of every batch width).
const NSETS: usize = 64;

/// robovec's variants of each function: label, pipeline before `codegen`, lanes, `trig`. One
/// state with `trig=libm` as the plain baseline, and with `trig=inline`, `contract` and
/// `schedule-cpu` (its greedy order cuts the register spills of one long function: Solo-12's
/// `rnea` 1.43 → 1.59× CG, docs/benchmarks.md "Timed against CppADCodeGen", run 3); batches of 4 (one AVX2 vector of doubles) and 8 (one AVX-512 vector: the fastest width per
/// state where the machine has AVX-512, 4 where it has AVX2 only: 8 and 16 lanes were 5–45 %
/// slower per state on TIAGo Pro and serial30 on a Zen 3). `trig=libm` and `trig=inline`
/// compute sin/cos, like for like with Pinocchio; `trig=input` takes them as inputs (the
/// ceiling: what computing them costs is the difference). `fma`: the `contract` pass fuses
/// multiplies into additions (C99 `fma`, one rounding, bit-exact with robovec's interpreter),
/// like for like with Pinocchio, whose `-O3 -march=native` build contracts; `batch=8,
/// trig=inline` without it shows what the fusion gives. `zero-removal` before it (exact: it
/// only moves signs) turns `0 − a·b` into a product with a negated constant where it can,
/// instead of a fused `0 − a·b` (serial30's `M` −27 ops, TIAGo Pro's −52: 2.5 % and 3.5 %
/// faster at `batch=8` on a Zen 3). `slp=4`: the one-state code with four isomorphic ops as one
/// vector op (`codegen<c;slp=4>`, packs seeded by four columns of a derivative matrix).
const VARIANTS: [(&str, &str, u32, &str); 7] = [
    ("1 state, trig=libm", "atomise,cse", 1, "libm"),
    ("1 state, trig=inline, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 1, "inline"),
    ("1 state, trig=inline, fma, slp=4", "atomise,cse,zero-removal,contract,schedule-cpu", 1, "inline;slp=4"),
    ("batch=4, trig=inline, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 4, "inline"),
    ("batch=8, trig=inline", "atomise,cse,zero-removal,schedule-cpu", 8, "inline"),
    ("batch=8, trig=inline, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 8, "inline"),
    ("batch=8, trig=input, fma", "atomise,cse,zero-removal,contract,schedule-cpu", 8, "input"),
];

/// The variants whose bits of error the summary shows: without and with fused multiply-adds.
const BITS_OF: [&str; 2] = ["1 state, trig=libm", "batch=8, trig=inline, fma"];

/// The comparisons (the harness's groups, in its order): label, robovec function, outputs kept
/// (`dce`), Pinocchio's side, CppADCodeGen's function (`cg_export.cpp`; none computes `M` and `c`
/// together). The first four are the dynamics (issues 14, 30), the last three the derivatives
/// (issue 50: the derivatives with respect to `q` along Pinocchio's tangent space).
const GROUPS: [(&str, &str, Keep, &str, Option<&str>); 7] = [
    ("inverse dynamics", "invdyna", Keep::All, "rnea", Some("rnea")),
    ("mass matrix", "dirdyna", Keep::UpperM, "crba", Some("crba")),
    ("M and c", "dirdyna", Keep::UpperMAndC, "crba + nonLinearEffects", None),
    ("forward dynamics", "fordyna", Keep::All, "aba", Some("aba")),
    ("∇ inverse dynamics", "rnea_derivatives", Keep::All, "computeRNEADerivatives", Some("rnea_derivatives")),
    ("∇ forward dynamics", "aba_derivatives", Keep::All, "computeABADerivatives", Some("aba_derivatives")),
    ("inverse mass matrix", "minv", Keep::UpperMinv, "computeMinverse", Some("minv")),
];

/// The groups `--functions=` selects: `dynamics` (0–3), `derivatives` (4–6) or `all`.
fn parse_functions(s: &str) -> Vec<usize> {
    match s {
        "dynamics" => (0..4).collect(),
        "derivatives" => (4..7).collect(),
        "all" => (0..GROUPS.len()).collect(),
        _ => panic!("--functions={s}: dynamics, derivatives or all"),
    }
}

/// CppADCodeGen's builds of each of its functions: label, `cc` flags. `-Ofast` is Pinocchio's
/// default (`CodeGenBase::compileLib`), here with `-march=native` as every contestant; `-O3
/// -march=native` is robovec's optimisation level (GCC contracts multiply-adds in both, as in
/// Pinocchio's C++; `-Ofast` also reassociates). The objects are linked without `-Ofast`, so no
/// flush-to-zero start-up code enters the process.
const CG_BUILDS: [(&str, &[&str]); 2] = [("O3", &["-O3", "-march=native"]), ("Ofast", &["-Ofast", "-march=native"])];

/// The root joint of the floating robots: one switch for both sides.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Base {
    /// Robotran's six-joint base, robovec's `--floating-base`; Pinocchio's root joint
    /// `JointModelComposite(PX PY PZ RX RY RZ)`.
    Composite,
    /// Pinocchio's `JointModelFreeFlyer` (position, unit quaternion x y z w; the base's velocity in
    /// its own frame), robovec's `--free-flyer` (`q[1..nv+1]`, `qd[1..nv]`).
    FreeFlyer,
}

impl Base {
    fn parse(s: &str) -> Base {
        match s {
            "composite" => Base::Composite,
            "free-flyer" => Base::FreeFlyer,
            _ => panic!("--base={s}: composite or free-flyer"),
        }
    }

    /// `export_model.py`'s base argument.
    fn export_arg(self) -> &'static str {
        match self {
            Base::Composite => "floating",
            Base::FreeFlyer => "free-flyer",
        }
    }

    /// robovec-opt's flag.
    fn robovec_flag(self) -> &'static str {
        match self {
            Base::Composite => "--floating-base",
            Base::FreeFlyer => "--free-flyer",
        }
    }
}

/// The outputs of robovec's function a comparison keeps.
#[derive(Clone, Copy)]
enum Keep {
    All,
    /// `M[i][j]`, `i ≤ j`: what `crba` fills.
    UpperM,
    /// That and `c`.
    UpperMAndC,
    /// `Minv[i][j]`, `i ≤ j`: what `computeMinverse` fills.
    UpperMinv,
}

impl Keep {
    /// The pipeline's `dce<outputs=…>,` (empty for [`Keep::All`]) for `nv` coordinates, and
    /// its short label.
    fn dce(self, nv: usize) -> (String, &'static str) {
        let upper = |m: &str| -> String {
            let entries: Vec<String> = (1..=nv).flat_map(|i| (i..=nv).map(move |j| format!("{m}[{i}][{j}]"))).collect();
            entries.join(",")
        };
        match self {
            Keep::All => (String::new(), ""),
            Keep::UpperM => (format!("dce<outputs={}>,", upper("M")), "dce<outputs=M upper>,"),
            Keep::UpperMAndC => (format!("dce<outputs={},c>,", upper("M")), "dce<outputs=M upper,c>,"),
            Keep::UpperMinv => (format!("dce<outputs={}>,", upper("Minv")), "dce<outputs=Minv upper>,"),
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
    /// Median over runs of the median paired ratio baseline / this, per [`Baseline`] (1 for the
    /// baseline's best; `None`: the function has no such baseline).
    ratio: [Option<f64>; 2],
    errors: side::Errors,
}

/// What robovec is compared with: Pinocchio's run-time C++ algorithms, or its CppADCodeGen C.
/// A function's baseline in a run is the faster of that side's contestants (`crba`'s LOCAL and
/// WORLD conventions, CG's two builds).
#[derive(Clone, Copy)]
enum Baseline {
    Pinocchio,
    Cg,
}

impl Baseline {
    const ALL: [Baseline; 2] = [Baseline::Pinocchio, Baseline::Cg];

    /// The contestant-name prefix of this side.
    fn prefix(self) -> &'static str {
        match self {
            Baseline::Pinocchio => "pinocchio ",
            Baseline::Cg => "cg ",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Baseline::Pinocchio => "Pinocchio",
            Baseline::Cg => "CG",
        }
    }
}

/// One contestant's median ns in one run and its median paired ratio against each [`Baseline`].
type RunFigures = (f64, [Option<f64>; 2]);

/// gcc -O2 compile time of one generated C file of each side: `cc -O2 -c`, the two sides
/// alternating, 3 times each; median seconds per side, (CG, robovec).
type CompileTimes = (f64, f64);

fn compile_seconds(cg: &[std::path::PathBuf], robovec: &std::path::Path, dir: &std::path::Path) -> CompileTimes {
    let obj = dir.join("compile-time.o");
    let time = |srcs: &[&std::path::Path]| {
        let t0 = std::time::Instant::now();
        for src in srcs {
            run(Command::new("cc").args(["-O2", "-c"]).arg(src).arg("-o").arg(&obj));
        }
        t0.elapsed().as_secs_f64()
    };
    let cg: Vec<&std::path::Path> = cg.iter().map(|p| p.as_path()).collect();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        a.push(time(&cg));
        b.push(time(&[robovec]));
    }
    (side::median(&a), side::median(&b))
}

/// The figures of one robot: nv, every contestant's, and per group with a CG contestant the
/// compile times of [`compile_seconds`].
fn bench_robot(
    env: &Env,
    robot: &Robot,
    base: Base,
    groups: &[usize],
    (reps, runs, sample_ms): (u32, u32, f64),
    compile_times: bool,
) -> (usize, Vec<Figures>, BTreeMap<usize, CompileTimes>) {
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
        export.arg(base.export_arg());
    }
    let info: serde_json::Value = serde_json::from_str(&run(&mut export)).expect("export_model.py's JSON");
    let urdf = info["path"].as_str().unwrap().to_string();
    let states: States = read_states(&work.join("states.txt"));
    assert_eq!(states.x.len(), NSETS);
    assert_eq!(states.free_flyer, robot.floating && base == Base::FreeFlyer);
    let nv = states.nv;

    // CppADCodeGen's C (`cg_sources.py`: its exporter compiled once, its sources written once per
    // model), one copy per (function, build) with the function renamed and the flags in a comment.
    let cg_functions: Vec<&str> = groups.iter().filter_map(|&g| GROUPS[g].4).collect();
    let cg: serde_json::Value = serde_json::from_str(&run(Command::new(&env.python)
        .arg(env.root.join("benches/pinocchio/cg_sources.py"))
        .arg(work.join("model.txt"))
        .arg(work.join("cg"))
        .args(&cg_functions)))
    .expect("cg_sources.py's JSON");
    assert_eq!(cg["nv"].as_u64(), Some(nv as u64));
    let mut sources: Vec<(std::path::PathBuf, &[&str])> = Vec::new();
    let mut cg_decls = String::new();
    let mut cg_entries = Vec::new();
    for &g in groups {
        let Some(f) = GROUPS[g].4 else { continue };
        let parts = cg_parts(std::path::Path::new(cg[f].as_str().unwrap()));
        let stem = format!("cg_{f}_forward_zero");
        for (tag, flags) in CG_BUILDS {
            let symbol = format!("cg_{f}_{tag}");
            let mut head = format!("/* cc {} */\n", flags.join(" "));
            for k in 0..parts.len() {
                let suffix = if k == 0 { String::new() } else { format!("__{k}") };
                let _ = writeln!(head, "#define {stem}{suffix} {symbol}{suffix}");
            }
            for (k, part) in parts.iter().enumerate() {
                let src = work.join(format!("{symbol}{}.c", if k == 0 { String::new() } else { format!("__{k}") }));
                let text = std::fs::read_to_string(part).unwrap();
                side::write_if_changed(&src, (head.clone() + &text).as_bytes());
                sources.push((src, flags));
            }
            let _ = writeln!(
                cg_decls,
                "void {symbol}(double const *const *in, double *const *out, struct LangCAtomicFun atomic);"
            );
            cg_entries.push(format!("  {{\"{f} -{tag}\", {symbol}, {g}}},"));
        }
    }

    // robovec's C, one file per (function, variant).
    let mut columns: Vec<String> = Vec::new();
    let mut entries = Vec::new();
    let mut decls = String::new();
    for &g in groups {
        let (_, function, keep, ..) = GROUPS[g];
        let (prefix, short) = keep.dce(nv);
        for (v, (label, pipeline, batch, trig)) in VARIANTS.iter().enumerate() {
            let i = g * VARIANTS.len() + v;
            let report = work.join(format!("rv{i}.json"));
            let fresh = work.join(format!("rv{i}.new.c"));
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_robovec-opt"));
            cmd.arg(&urdf).arg(format!("-function={function}")).arg("--fold-params");
            // The model's gravity written into the equations as numbers, as CppADCodeGen's tape
            // holds Pinocchio's `model.gravity` (the states' `g`, Pinocchio's default).
            let [gx, gy, gz] = states.g;
            cmd.arg(format!("-gravity={gx:?},{gy:?},{gz:?}"));
            if robot.floating {
                cmd.arg(base.robovec_flag());
            }
            let full = pipeline.replacen("atomise,", &format!("atomise,{prefix}"), 1);
            cmd.arg(format!("-passes={full},codegen<c;abi=plain;batch={batch};trig={trig};name=rv{i}>"));
            let pipeline = pipeline.replacen("atomise,", &format!("atomise,{short}"), 1);
            run(cmd.arg("-o").arg(&fresh).arg(format!("-report={}", report.display())));
            let src = work.join(format!("rv{i}.c"));
            side::write_if_changed(&src, &std::fs::read(&fresh).unwrap());
            sources.push((src, side::C_FLAGS));
            let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
            let list = |k: &str| -> Vec<String> {
                j["codegen"][k].as_array().unwrap().iter().map(|x| x.as_str().unwrap().to_string()).collect()
            };
            let (ins, outs) = (list("inputs"), list("outputs"));
            let symbol = j["codegen"]["symbol"].as_str().unwrap().to_string();
            // The forward dynamics' `Qq[i]`: the harness's `tau[i − 1]`, map `−i`.
            let in_map: Vec<String> = ins
                .iter()
                .map(|n| {
                    if let Some(i) = n.strip_prefix("Qq[").and_then(|r| r.strip_suffix(']')) {
                        return format!("-{i}");
                    }
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
        "const int RV_NSETS = {NSETS}, RV_NCOLS = {}, RV_NVARIANTS = {}, RV_GROUPS = {};",
        columns.len(),
        entries.len(),
        groups.iter().map(|g| 1 << g).sum::<u32>()
    );
    table += "const double RV_SETS[] = {\n";
    for s in 0..NSETS {
        let row: Vec<String> = columns.iter().map(|c| format!("{:e}", robovec_inputs(c, &states, s))).collect();
        let _ = writeln!(table, "  {},", row.join(","));
    }
    table += "};\n";
    table += &decls;
    let _ = writeln!(table, "const RvVariant RV_VARIANTS[] = {{\n{}\n}};", entries.join("\n"));
    // CppADCodeGen's functions and their signature (its `cg_F_forward_zero.c`'s types).
    table += "typedef struct Array { void *data; unsigned long size; int sparse; const unsigned long *idx; unsigned long nnz; } Array;\n";
    table += "struct LangCAtomicFun { void *libModel;\n  int (*forward)(void *libModel, int atomicIndex, int q, int p, const Array tx[], Array *ty);\n  int (*reverse)(void *libModel, int atomicIndex, int p, const Array tx[], Array *px, const Array py[]); };\n";
    table += "typedef void (*cg_fn)(double const *const *in, double *const *out, struct LangCAtomicFun atomic);\n";
    table += "typedef struct { const char *label; cg_fn fn; int group; } CgVariant;\n";
    table += &cg_decls;
    let _ = writeln!(table, "const int CG_NVARIANTS = {};", cg_entries.len());
    let _ = writeln!(table, "const CgVariant CG_VARIANTS[] = {{\n{}\n}};", cg_entries.join("\n"));
    let table_c = work.join("table.c");
    side::write_if_changed(&table_c, table.as_bytes());
    sources.push((table_c, side::C_FLAGS));

    let exe = env.link(&work, &sources);
    let mut names: BTreeMap<usize, (usize, String)> = BTreeMap::new();
    // Per contestant, per run: median ns and median paired ratio against each baseline.
    let mut per_run: BTreeMap<usize, Vec<RunFigures>> = BTreeMap::new();
    for r in 0..runs {
        let values = work.join("values.bin");
        let out = run(Command::new(&exe)
            .arg(work.join("model.txt"))
            .arg(work.join("states.txt"))
            .arg(&values)
            .arg(reps.to_string())
            .arg(format!("{}", sample_ms * 1e6)));
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
        for &g in groups {
            let members: Vec<usize> = names.iter().filter(|(_, (gg, _))| *gg == g).map(|(c, _)| *c).collect();
            // Each side's baseline in this run: its fastest contestant (median) for the group.
            let bases = Baseline::ALL.map(|b| {
                members
                    .iter()
                    .copied()
                    .filter(|c| names[c].1.starts_with(b.prefix()))
                    .min_by(|x, y| side::median(&times[x]).total_cmp(&side::median(&times[y])))
            });
            assert!(bases[0].is_some(), "{}: no Pinocchio contestant for group {g}", robot.name);
            for &c in &members {
                let ratio = bases.map(|b| {
                    let b = b?;
                    let paired: Vec<f64> = times[&b].iter().zip(&times[&c]).map(|(b, x)| b / x).collect();
                    Some(side::median(&paired))
                });
                per_run.entry(c).or_default().push((side::median(&times[&c]), ratio));
            }
        }
        eprintln!("   run {} of {runs} done", r + 1);
    }
    let errors = side::errors(&work.join("values.bin"), &names, groups, nv, NSETS);
    let figures: Vec<Figures> = names
        .iter()
        .map(|(c, (g, name))| {
            let runs = &per_run[c];
            let ns: Vec<f64> = runs.iter().map(|r| r.0).collect();
            let ratio = [0, 1].map(|k| {
                let ratios: Option<Vec<f64>> = runs.iter().map(|r| r.1[k]).collect();
                ratios.map(|r| side::median(&r))
            });
            Figures {
                name: name.clone(),
                group: *g,
                ns: (
                    side::median(&ns),
                    ns.iter().copied().fold(f64::INFINITY, f64::min),
                    ns.iter().copied().fold(0.0, f64::max),
                ),
                ratio,
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
    // The compile time of each side's one-state file of each function CG has.
    let mut compile = BTreeMap::new();
    if compile_times {
        for &g in groups {
            let Some(f) = GROUPS[g].4 else { continue };
            let v = VARIANTS.iter().position(|v| v.0 == COMPILE_TIMED).expect("the timed variant");
            let rv = work.join(format!("rv{}.c", g * VARIANTS.len() + v));
            let parts = cg_parts(std::path::Path::new(cg[f].as_str().unwrap()));
            compile.insert(g, compile_seconds(&parts, &rv, &work));
        }
    }
    (nv, figures, compile)
}

/// A CppADCodeGen function's sources: `cg_F_forward_zero.c` and, for a large function, the parts
/// it calls (`cg_F_forward_zero__1.c`, …, in order).
fn cg_parts(main: &std::path::Path) -> Vec<std::path::PathBuf> {
    let stem = main.file_stem().unwrap().to_string_lossy().into_owned();
    let mut parts: Vec<(usize, std::path::PathBuf)> = std::fs::read_dir(main.parent().unwrap())
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            let name = p.file_name()?.to_str()?.to_string();
            let k = name.strip_prefix(&format!("{stem}__"))?.strip_suffix(".c")?.parse().ok()?;
            Some((k, p))
        })
        .collect();
    parts.sort();
    std::iter::once(main.to_path_buf()).chain(parts.into_iter().map(|p| p.1)).collect()
}

/// robovec's variant whose gcc -O2 compile time is measured against CG's file.
const COMPILE_TIMED: &str = "1 state, trig=inline, fma";

/// One row of the summary: a side's fastest contestant (Pinocchio's run-time algorithm or
/// CppADCodeGen's build) against each robovec variant; `None` when the function has no such
/// contestant.
fn summary_row(robot: &str, nv: usize, g: usize, baseline: Baseline, figs: &[Figures], mhz: f64) -> Option<String> {
    let mine: Vec<&Figures> = figs.iter().filter(|f| f.group == g).collect();
    let base =
        mine.iter().filter(|f| f.name.starts_with(baseline.prefix())).min_by(|a, b| a.ns.0.total_cmp(&b.ns.0))?;
    let k = baseline as usize;
    let mut row = format!(
        "| {robot} | {nv} | {} | {} `{}` | {:.0} ({:.0} cycles) |",
        GROUPS[g].0,
        baseline.label(),
        base.name.trim_start_matches(baseline.prefix()),
        base.ns.0,
        base.ns.0 * mhz / 1e3
    );
    let variant = |label: &str| {
        mine.iter().find(|f| f.name.starts_with("robovec") && f.name.ends_with(label)).expect("each variant")
    };
    for (label, ..) in VARIANTS {
        let f = variant(label);
        let _ = write!(row, " {:.0} ({:.1}×) |", f.ns.0, f.ratio[k].expect("a ratio against the baseline"));
    }
    let _ = write!(row, " {:.2} / {:.0} |", base.errors.mean_bits, base.errors.max_bits);
    for label in BITS_OF {
        let e = &variant(label).errors;
        let _ = write!(row, " {:.2} / {:.0} |", e.mean_bits, e.max_bits);
    }
    Some(row)
}

fn main() {
    let mut wanted = Vec::new();
    let (mut reps, mut runs) = (101, 5);
    let mut sample_ms = 0.3;
    let mut base = Base::FreeFlyer;
    let mut groups = parse_functions("all");
    let mut compile_times = true;
    for a in std::env::args().skip(1) {
        if let Some(b) = a.strip_prefix("--base=") {
            base = Base::parse(b);
        } else if let Some(f) = a.strip_prefix("--functions=") {
            groups = parse_functions(f);
        } else if let Some(c) = a.strip_prefix("--compile-times=") {
            compile_times = match c {
                "yes" => true,
                "no" => false,
                _ => panic!("--compile-times=yes|no"),
            };
        } else if let Some(r) = a.strip_prefix("--reps=") {
            reps = r.parse().expect("--reps=N");
        } else if let Some(r) = a.strip_prefix("--runs=") {
            runs = r.parse().expect("--runs=N");
        } else if let Some(r) = a.strip_prefix("--sample-ms=") {
            sample_ms = r.parse().expect("--sample-ms=MS");
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
        "{cpu} at {mhz} MHz (cycles = ns × that clock); load average before: {}; {runs} runs × {reps} reps of \
         {sample_ms} ms samples, medians; floating base: {}; (×) = the row's baseline's ns ÷ robovec's, paired per rep\n\n",
        load.trim(),
        match base {
            Base::Composite => "composite (PX PY PZ RX RY RZ)",
            Base::FreeFlyer => "free-flyer",
        }
    );
    summary += "| robot | dof | function | baseline (its fastest) | baseline ns/state |";
    for (label, ..) in VARIANTS {
        let _ = write!(summary, " robovec {label} |");
    }
    summary += " bits of error mean / max: baseline |";
    for label in BITS_OF {
        let _ = write!(summary, " robovec {label} |");
    }
    summary += "\n|---|---:|---|---:|";
    summary += &"---:|".repeat(VARIANTS.len());
    summary += &"---|".repeat(1 + BITS_OF.len());
    summary += "\n";
    let mut compile_table =
        String::from("| robot | dof | function | CG s | robovec s | CG ÷ robovec |\n|---|---:|---|---:|---:|---:|\n");
    let mut detail = format!(
        "| robot | dof | function | contestant | ns/state median over {runs} runs (min–max) | Pinocchio ÷ this (paired) | CG ÷ this (paired) | bits of error mean / max | worst relative error |\n|---|---:|---|---|---:|---:|---:|---|---:|\n"
    );
    for robot in ROBOTS.iter().filter(|r| wanted.is_empty() || wanted.iter().any(|w| w == r.name)) {
        let (nv, figs, compile) = bench_robot(&env, robot, base, &groups, (reps, runs, sample_ms), compile_times);
        for (g, (cg, rv)) in compile {
            let _ = writeln!(
                compile_table,
                "| {} | {nv} | {} | {cg:.2} | {rv:.2} | {:.2}× |",
                robot.name,
                GROUPS[g].0,
                cg / rv
            );
        }
        for f in &figs {
            let ratio = |k: usize| f.ratio[k].map_or("–".to_string(), |r| format!("{r:.2}×"));
            let _ = writeln!(
                detail,
                "| {} | {nv} | {} | {} | {:.1} ({:.1}–{:.1}) | {} | {} | {:.2} / {:.0} | {:.1e} |",
                robot.name,
                GROUPS[f.group].0,
                f.name,
                f.ns.0,
                f.ns.1,
                f.ns.2,
                ratio(0),
                ratio(1),
                f.errors.mean_bits,
                f.errors.max_bits,
                f.errors.relative
            );
        }
        for &g in &groups {
            for baseline in Baseline::ALL {
                if let Some(row) = summary_row(robot.name, nv, g, baseline, &figs, mhz) {
                    summary += &row;
                    summary.push('\n');
                }
            }
        }
    }
    let out = format!(
        "{summary}\ngcc -O2 compile time (`cc -O2 -c`, s, median of 3, alternating) of CG's file and robovec's \
         `{COMPILE_TIMED}` file:\n\n{compile_table}\nEvery contestant:\n\n{detail}"
    );
    print!("{out}");
    let path = env.work.join("table.md");
    std::fs::write(&path, &out).unwrap();
    eprintln!("table written to {}", path.display());
}
