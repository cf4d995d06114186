//! Speed of the generated C against Robotran's own C (issue 11, "Fast, measured side by side").
//!
//! `cargo bench --bench codegen_c -- [MODEL…] [--flags=o2|native|native-contract|both|all] [--reps=N] [--runs=K] [--quick] [--core]
//! [--split[=OPS,OPS…]]`
//!
//! `--quick`: no `trig=libm` batches, 20 accuracy samples; `--core`: only the variants of the
//! issue's goals (`atomise`, `atomise[,cse],schedule-cpu`, 8 × f64 and 16 × f32 with `trig=input`).
//! `--split`: split code against unsplit instead (issue 28, item 5): `atomise` and `atomise,cse`
//! one state and `atomise,cse,schedule-cpu` 8 × f64 `trig=input`, each with `chunk=0` (one
//! function) and with `chunk=OPS` for each OPS given (default: the back end's default), and
//! the paired ratio of each split variant against its `chunk=0` twin (unsplit ns / split ns in
//! the same rep: > 1 means the split code is faster).
//!
//! For each model (a corpus `dirdyna`/`invdyna` C file, named by its prefix: `m454` (default),
//! `coman_longarms`, `jeep`, `walkman`, `tricycle`, `frank_segway`, `coman_longarms:invdyna`), it
//! 1. writes robovec's C with `robovec-opt FILE -passes=PIPELINE,codegen<c;abi=plain;…>` for
//!    every variant of [`variants`] (pipelines `atomise`, `atomise[,cse],schedule-cpu`,
//!    `atomise,zero-removal,balance[,schedule-cpu]`, `specialize` with the model parameters
//!    fixed, `dce<outputs=c>`; `batch=4,8` f64 and `batch=8,16` f32 with `trig=input|libm`);
//! 2. builds ONE binary per flag set (`-O2`, and `-O3 -march=native -ffp-contract=off`; with
//!    `--flags=native-contract` or `all` also `-O3 -march=native` with GCC's default contraction,
//!    the way Robotran's users compile its C, every side so) with
//!    Robotran's original C (its `MbsData` from the stub headers in `benches/codegen_c/`, arrays
//!    filled with pseudo-random values), every variant, and the timing driver
//!    `benches/codegen_c/driver.c`, which checks each variant against Robotran's outputs on one
//!    state and then times them all, alternating, rotating who goes first: median ns per state
//!    over `reps` samples of ~0.5 ms, inputs cycling over the same 64 states between calls
//!    for every variant (a batch of W lanes holds W of them); the binary runs `runs` times
//!    (default 5) as separate processes;
//! 3. measures each pipeline's error with `accuracy` (bits of error against the original
//!    equations, SPEC §6; Robotran's C evaluates each equation left to right, which is the
//!    `atomise` pipeline's order, so its error is `atomise`'s);
//! 4. prints one table: model, variant, flags, ns/state (median, min–max), ratio vs Robotran at
//!    the same flags (> 1: faster) from **paired** ratios (both functions' ns/state from the
//!    same rep, a few ms apart: on a shared machine whose speed drifts by 2× between runs, the
//!    ratio of neighbouring samples is stable where the ratio of medians is not): each run's
//!    median paired ratio, then the median over the runs and their min–max (one process's
//!    median is tight but moves by ±20 % between processes on this VM), error bits (f64 or f32
//!    mean / max), and the check.
//!
//! Needs `cc` (GCC or Clang) and the corpus at `../shared`. Work files go to
//! `target/codegen_c_bench/`. CI never runs it (`cargo bench --no-run` only builds this file).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Number of input states the driver cycles through.
const NSETS: usize = 64;

/// One robovec variant: a pipeline before codegen and the codegen options.
#[derive(Clone, Debug)]
struct Variant {
    /// Short label in the table.
    label: String,
    /// Pipeline before `codegen`.
    pipeline: String,
    /// `f64` or `f32`.
    precision: &'static str,
    /// States per call.
    batch: u32,
    /// `input` or `libm`.
    trig: &'static str,
    /// `chunk=` (`None`: the back end's default).
    chunk: Option<u32>,
    /// The variant (index) this one is paired against: its `chunk=0` twin.
    base: Option<usize>,
}

fn variants(params_json: &Path, dce_outputs: &str, quick: bool, core: bool) -> Vec<Variant> {
    let v = |label: &str, pipeline: &str, precision, batch, trig| Variant {
        label: label.into(),
        pipeline: pipeline.into(),
        precision,
        batch,
        trig,
        chunk: None,
        base: None,
    };
    let sched = "atomise,schedule-cpu";
    let mut out = vec![
        v("atomise", "atomise", "f64", 1, "libm"),
        v("atomise,schedule-cpu", sched, "f64", 1, "libm"),
        v("atomise,zero-removal,balance", "atomise,zero-removal,balance", "f64", 1, "libm"),
        v("atomise,zero-removal,balance,schedule-cpu", "atomise,zero-removal,balance,schedule-cpu", "f64", 1, "libm"),
    ];
    for (prec, widths) in [("f64", [4u32, 8]), ("f32", [8, 16])] {
        for w in widths {
            for trig in ["input", "libm"] {
                if quick && trig == "libm" {
                    continue;
                }
                out.push(v(&format!("{sched} batch={w} {prec} trig={trig}"), sched, prec, w, trig));
            }
        }
    }
    // Common-subexpression elimination first: schedule-cpu then orders the DAG GCC allocates.
    let cse = "atomise,cse,schedule-cpu";
    out.push(v("atomise,cse", "atomise,cse", "f64", 1, "libm"));
    out.push(v(cse, cse, "f64", 1, "libm"));
    out.push(v(&format!("{cse} batch=8 f64 trig=input"), cse, "f64", 8, "input"));
    out.push(v(&format!("{cse} batch=16 f32 trig=input"), cse, "f32", 16, "input"));
    let spec = format!("atomise,specialize<params={}>,schedule-cpu", params_json.display());
    out.push(v("specialize(params),schedule-cpu", &spec, "f64", 1, "libm"));
    out.push(v("specialize(params),schedule-cpu batch=8 f64 trig=input", &spec, "f64", 8, "input"));
    // Issue 31: the named pipeline of fewest ops (`schedule-cpu` last), alone, with fused
    // multiply-adds and robovec's own sin/cos, and batched; and without its `schedule-cpu`.
    out.push(v("atomise,cse,zero-removal,cse", "atomise,cse,zero-removal,cse", "f64", 1, "libm"));
    out.push(v("default<ops>", "default<ops>", "f64", 1, "libm"));
    out.push(v("default<ops> trig=inline", "default<ops>", "f64", 1, "inline"));
    out.push(v("default<ops>,contract trig=inline", "default<ops>,contract", "f64", 1, "inline"));
    out.push(v("default<ops> batch=8 f64 trig=input", "default<ops>", "f64", 8, "input"));
    let dce = format!("atomise,dce<outputs={dce_outputs}>,schedule-cpu");
    out.push(v(&format!("dce<outputs={dce_outputs}>,schedule-cpu"), &dce, "f64", 1, "libm"));
    if core {
        // The goals' variants only (big models compile for minutes per file).
        let keep = |l: &str| {
            l == "atomise"
                || l == "atomise,schedule-cpu"
                || l.starts_with("atomise,cse")
                || l.starts_with("default<ops>")
                || l.ends_with("batch=8 f64 trig=input") && !l.starts_with("spec")
                || l.ends_with("batch=16 f32 trig=input")
        };
        out.retain(|v| keep(&v.label));
    }
    out
}

/// `--split`: each pipeline unsplit (`chunk=0`) and split at each of `chunks`, paired.
fn split_variants(chunks: &[u32]) -> Vec<Variant> {
    let mut out = Vec::new();
    for (pipeline, precision, batch, trig) in [
        ("atomise", "f64", 1, "libm"),
        ("atomise,cse", "f64", 1, "libm"),
        ("atomise,cse,schedule-cpu", "f64", 8, "input"),
    ] {
        let what =
            if batch > 1 { format!("{pipeline} batch={batch} {precision} trig={trig}") } else { pipeline.into() };
        let base = out.len();
        for &chunk in std::iter::once(&0).chain(chunks) {
            out.push(Variant {
                label: format!("{what} chunk={chunk}"),
                pipeline: pipeline.into(),
                precision,
                batch,
                trig,
                chunk: Some(chunk),
                base: (chunk > 0).then_some(base),
            });
        }
    }
    out
}

/// A corpus model: its Robotran C file and companion header.
struct Model {
    label: String,
    c_file: PathBuf,
    /// `dirdyna` or `invdyna`.
    kind: &'static str,
}

fn corpus() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus/robotran/c")
}

fn find_model(spec: &str) -> Model {
    let (name, kind) = match spec.split_once(':') {
        Some((n, k)) => (n, k),
        None if spec == "walkman" => (spec, "invdyna"),
        None => (spec, "dirdyna"),
    };
    let kind: &'static str = if kind == "invdyna" { "invdyna" } else { "dirdyna" };
    let prefix = format!("{name}__mbs_{kind}_");
    let dir = corpus();
    let file = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus missing at {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            let n = p.file_name().unwrap().to_string_lossy();
            n.starts_with(&prefix) && n.ends_with(".c")
        })
        .unwrap_or_else(|| panic!("no corpus file {prefix}*.c in {}", dir.display()));
    Model { label: format!("{name} {kind}"), c_file: file, kind }
}

/// Deterministic value of input `name` in state `k` (joint coordinates, velocities,
/// accelerations and forces vary with `k`; model parameters are fixed).
fn input_value(name: &str, k: usize) -> f64 {
    let base = name.split('[').next().unwrap_or(name);
    let varies = matches!(base, "q" | "qd" | "qdd" | "frc" | "trq" | "tsim");
    let x = robovec_ir::interp::pseudo_random_input(name, if varies { 1 + k as u64 } else { 0 });
    match base {
        // Masses and inertias positive, like a real model's.
        "m" | "In" => 1.0 + 0.5 * x,
        _ => x,
    }
}

/// `S4` / `C4` → sin/cos of `q[4]` (Robotran's trig names); anything else as is.
fn value_of(name: &str, k: usize) -> f64 {
    let trig = |p: char| name.strip_prefix(p).filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()));
    if let Some(d) = trig('S') {
        input_value(&format!("q[{d}]"), k).sin()
    } else if let Some(d) = trig('C') {
        input_value(&format!("q[{d}]"), k).cos()
    } else {
        input_value(name, k)
    }
}

/// Writes `data` to `path` unless the file already holds it (so its time stamp stays).
fn write_if_changed(path: &Path, data: &[u8]) {
    if std::fs::read(path).ok().as_deref() != Some(data) {
        std::fs::write(path, data).unwrap();
    }
}

fn run(cmd: &mut Command) -> String {
    let o = cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    if !o.status.success() {
        panic!("{cmd:?} failed:\n{}", String::from_utf8_lossy(&o.stderr));
    }
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn opt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_robovec-opt"))
}

fn read_json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn names(j: &serde_json::Value, key: &str) -> Vec<String> {
    j["codegen"][key].as_array().unwrap().iter().map(|x| x.as_str().unwrap().to_string()).collect()
}

/// Robotran's output index (0-based, `M` row-major then `c`, or `Qq`) of an output name.
fn robotran_index(name: &str, kind: &str, ndof: usize) -> Option<usize> {
    let idx: Vec<usize> = name.split('[').skip(1).filter_map(|p| p.trim_end_matches(']').parse().ok()).collect();
    match (name.split('[').next()?, kind, idx.as_slice()) {
        ("M", "dirdyna", [i, j]) => Some((i - 1) * ndof + (j - 1)),
        ("c", "dirdyna", [i]) => Some(ndof * ndof + i - 1),
        ("Qq", "invdyna", [i]) => Some(i - 1),
        _ => None,
    }
}

/// Compiles `jobs` (argument lists for `cc`) two at a time.
fn compile_all(jobs: Vec<Vec<String>>) {
    for pair in jobs.chunks(2) {
        let children: Vec<_> =
            pair.iter().map(|a| (a.clone(), Command::new("cc").args(a).spawn().expect("cc runs"))).collect();
        for (a, c) in children {
            let o = c.wait_with_output().unwrap();
            assert!(o.status.success(), "cc {} failed", a.join(" "));
        }
    }
}

struct Row {
    model: String,
    variant: String,
    flags: String,
    median: f64,
    min: f64,
    max: f64,
    /// Median over the runs of each run's median paired ratio (Robotran's ns / this variant's
    /// ns in the same rep).
    ratio: f64,
    /// Smallest and largest of the runs' median paired ratios.
    ratio_range: (f64, f64),
    /// Against the `chunk=0` twin: median over the runs of each run's median paired ratio
    /// (twin's ns / this variant's ns), and its smallest and largest.
    vs_unsplit: Option<(f64, f64, f64)>,
    error: String,
    check: String,
}

fn bench_model(
    spec: &str,
    flag_sets: &[(&str, &str)],
    (reps, runs): (u32, u32),
    (quick, core): (bool, bool),
    split: Option<&[u32]>,
    rows: &mut Vec<Row>,
) {
    let model = find_model(spec);
    let work = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/codegen_c_bench").join(spec.replace(':', "_"));
    // Kept between runs: files are rewritten only when their content changes, and an object
    // newer than its source is not compiled again (coman's TUs take minutes at -O2).
    std::fs::create_dir_all(&work).unwrap();
    eprintln!("== {} ({})", model.label, model.c_file.display());

    // Robotran's side: its C, its companion header under the name it includes, stub headers.
    let src = std::fs::read_to_string(&model.c_file).unwrap();
    let inc = src
        .lines()
        .filter_map(|l| l.trim().strip_prefix("#include \"").and_then(|r| r.strip_suffix('"')))
        .find(|h| h.starts_with("mbs_") && h.contains(model.kind))
        .expect("the companion header include")
        .to_string();
    let h_file = model.c_file.with_extension("h");
    write_if_changed(&work.join(&inc), &std::fs::read(&h_file).unwrap());
    write_if_changed(&work.join("robotran.c"), src.as_bytes());
    let stubs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/codegen_c");
    for h in ["mbs_data.h", "mbs_project_interface.h", "MBSdataStructR7.h", "MBSfunR7.h", "driver.c"] {
        write_if_changed(&work.join(h), &std::fs::read(stubs.join(h)).unwrap());
    }

    // Inputs of the original function (atomise keeps them all) and the parameters file.
    let base_report = work.join("atomise.json");
    run(opt()
        .arg(&model.c_file)
        .arg("-passes=atomise,codegen<c;abi=plain;trig=input>")
        .arg("-o")
        .arg(work.join("probe.c"))
        .arg(format!("-report={}", base_report.display())));
    let j = read_json(&base_report);
    let all_inputs = names(&j, "inputs");
    let outputs = names(&j, "outputs");
    let params: BTreeMap<&str, f64> = all_inputs
        .iter()
        .filter(|n| {
            let b = n.split('[').next().unwrap();
            matches!(b, "dpt" | "l" | "m" | "In" | "g")
        })
        .map(|n| (n.as_str(), input_value(n, 0)))
        .collect();
    let params_json = work.join("params.json");
    std::fs::write(&params_json, serde_json::to_string(&params).unwrap()).unwrap();
    let dce_outputs =
        if model.kind == "dirdyna" { "c".to_string() } else { "Qq[1],Qq[2],Qq[3],Qq[4],Qq[5],Qq[6]".into() };
    let ndof = outputs.iter().filter(|o| o.starts_with("c[") || o.starts_with("Qq[")).count();
    let nout_robotran = if model.kind == "dirdyna" { ndof * ndof + ndof } else { ndof };

    // robovec's side: one C file per variant, and the error of each pipeline.
    let vs = match split {
        Some(chunks) => split_variants(chunks),
        None => variants(&params_json, &dce_outputs, quick, core),
    };
    let mut columns: Vec<String> = all_inputs.clone();
    let mut table = String::new();
    let mut errors: BTreeMap<(String, &str), String> = BTreeMap::new();
    let mut maps = Vec::new();
    for (i, v) in vs.iter().enumerate() {
        let rep = work.join(format!("rv{i}.json"));
        let chunk = v.chunk.map_or(String::new(), |c| format!(";chunk={c}"));
        let cg = format!(
            "codegen<c;abi=plain;precision={};batch={};trig={};name=rv{i}{chunk}>",
            v.precision, v.batch, v.trig
        );
        let fresh = work.join(format!("rv{i}.new.c"));
        run(opt()
            .arg(&model.c_file)
            .arg(format!("-passes={},{cg}", v.pipeline))
            .arg("-o")
            .arg(&fresh)
            .arg(format!("-report={}", rep.display())));
        write_if_changed(&work.join(format!("rv{i}.c")), &std::fs::read(&fresh).unwrap());
        let j = read_json(&rep);
        let ins = names(&j, "inputs");
        let outs = names(&j, "outputs");
        for n in &ins {
            if !columns.contains(n) {
                columns.push(n.clone());
            }
        }
        maps.push((ins, outs));
        let key = (v.pipeline.clone(), v.precision);
        if !errors.contains_key(&key) {
            let acc = work.join(format!("acc{i}.json"));
            let samples = if quick { 20 } else { 100 };
            let with = if v.pipeline.contains("specialize") {
                format!(";params={}", params_json.display())
            } else {
                String::new()
            };
            run(opt()
                .arg(&model.c_file)
                .arg(format!("-passes={},accuracy<samples={samples}{with}>", v.pipeline))
                .arg("-o")
                .arg(work.join(format!("acc{i}.rvir")))
                .arg(format!("-report={}", acc.display())));
            let a = read_json(&acc);
            for p in ["f64", "f32"] {
                let s = &a["accuracy"][p];
                let e = format!(
                    "{:.2} / {:.0}",
                    s["mean_bits"].as_f64().unwrap_or(f64::NAN),
                    s["max_bits"].as_f64().unwrap_or(f64::NAN)
                );
                errors.insert((v.pipeline.clone(), if p == "f64" { "f64" } else { "f32" }), e);
            }
        }
    }

    // model.inc: states, MbsData filling, variant table.
    let _ = writeln!(table, "#define NSETS {NSETS}\n#define NNAMES {}", columns.len());
    let _ = writeln!(table, "#define ROBOTRAN_KIND {}", if model.kind == "dirdyna" { 0 } else { 1 });
    let _ = writeln!(table, "#define NDOF {ndof}\n#define NOUT_ROBOTRAN {nout_robotran}");
    table += "static const double SETS[NSETS][NNAMES] = {\n";
    for k in 0..NSETS {
        let row: Vec<String> = columns.iter().map(|n| format!("{:e}", value_of(n, k))).collect();
        let _ = writeln!(table, "  {{{}}},", row.join(","));
    }
    table += "};\n";
    // Dimensions of every MbsData array from the input names (1-based: max index + 1).
    let mut dims: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    for n in &all_inputs {
        let mut parts = n.split('[');
        let b = parts.next().unwrap();
        let idx: Vec<usize> = parts.filter_map(|p| p.trim_end_matches(']').parse().ok()).collect();
        let e = dims.entry(b).or_insert((1, 1));
        if let Some(&a) = idx.first() {
            e.0 = e.0.max(a + 1);
        }
        if let Some(&c) = idx.get(1) {
            e.1 = e.1.max(c + 1);
        }
    }
    table += "static void fill_mbs(MbsData *s, const double *set) {\n";
    let vectors = ["q", "qd", "qdd", "m", "g", "Qq"];
    let matrices = ["l", "In", "dpt", "frc", "trq"];
    let rows_of = |b: &str| dims.get(b).map_or(4, |d| d.0).max(ndof + 2).max(4);
    for b in vectors {
        let _ = writeln!(table, "  s->{b} = calloc({}, sizeof(double));", rows_of(b) + 1);
    }
    for b in matrices {
        let (r, c) = dims.get(b).copied().unwrap_or((4, 4));
        let (r, c) = (r.max(4) + 1, c.max(ndof + 2).max(4) + 1);
        let _ = writeln!(
            table,
            "  s->{b} = calloc({r}, sizeof(double *)); for (int i = 0; i < {r}; i++) s->{b}[i] = calloc({c}, sizeof(double));"
        );
    }
    for (col, n) in columns.iter().enumerate() {
        let b = n.split('[').next().unwrap();
        if vectors.contains(&b) || matrices.contains(&b) {
            let _ = writeln!(table, "  s->{n} = set[{col}];");
        }
    }
    table += "}\n";
    let mut entries = Vec::new();
    for (i, (v, (ins, outs))) in vs.iter().zip(&maps).enumerate() {
        let real = if v.precision == "f32" { "float" } else { "double" };
        let _ = writeln!(table, "void rv{i}(const {real} *restrict in, {real} *restrict out);");
        let im: Vec<String> = ins.iter().map(|n| columns.iter().position(|c| c == n).unwrap().to_string()).collect();
        let om: Vec<String> = outs
            .iter()
            .map(|n| robotran_index(n, model.kind, ndof).map_or("-1".to_string(), |x| x.to_string()))
            .collect();
        let _ = writeln!(table, "static const int in_map{i}[] = {{{},0}};", im.join(","));
        let _ = writeln!(table, "static const int out_map{i}[] = {{{},0}};", om.join(","));
        let (f64p, f32p) = if v.precision == "f32" {
            ("0".to_string(), format!("rv{i}"))
        } else {
            (format!("rv{i}"), "0".to_string())
        };
        entries.push(format!(
            "  {{\"v{i}\", {f64p}, {f32p}, {}, {}, {}, in_map{i}, out_map{i}, {}}},",
            v.batch,
            ins.len(),
            outs.len(),
            v.base.map_or(-1, |b| b as i64)
        ));
    }
    let _ = writeln!(
        table,
        "#define NVARIANTS {}\nstatic const Variant VARIANTS[NVARIANTS] = {{\n{}\n}};",
        vs.len(),
        entries.join("\n")
    );
    write_if_changed(&work.join("model.inc"), table.as_bytes());

    let function = if src.contains("void mbs_") { format!("mbs_{}", model.kind) } else { model.kind.to_string() };
    for (flag_label, flags) in flag_sets {
        let fl: Vec<String> = flags.split_whitespace().map(String::from).collect();
        let dir = work.join(flag_label);
        std::fs::create_dir_all(&dir).unwrap();
        let obj = |n: &str| dir.join(format!("{n}.o")).to_string_lossy().into_owned();
        let mut jobs = Vec::new();
        let w = work.to_string_lossy().into_owned();
        let mut tu = |src: String, o: String, extra: Vec<String>| {
            let newer = |a: &str, b: &str| {
                let t = |p: &str| std::fs::metadata(p).and_then(|m| m.modified()).ok();
                matches!((t(a), t(b)), (Some(x), Some(y)) if x >= y)
            };
            let inc = format!("{w}/model.inc");
            if newer(&o, &src) && (!src.ends_with("driver.c") || newer(&o, &inc)) {
                return;
            }
            let mut a = fl.clone();
            a.push("-Wno-psabi".into());
            a.extend(extra);
            a.extend(["-I".into(), w.clone(), "-c".into(), src, "-o".into(), o]);
            jobs.push(a);
        };
        tu(format!("{w}/robotran.c"), obj("robotran"), vec![format!("-D{function}=robotran_fn")]);
        tu(format!("{w}/driver.c"), obj("driver"), vec![]);
        for i in 0..vs.len() {
            tu(format!("{w}/rv{i}.c"), obj(&format!("rv{i}")), vec![]);
        }
        let t0 = std::time::Instant::now();
        compile_all(jobs);
        eprintln!("   compiled {flag_label} in {:.1} s", t0.elapsed().as_secs_f64());
        let exe = dir.join("bench");
        let mut link: Vec<String> = vec!["-o".into(), exe.to_string_lossy().into_owned()];
        link.push(obj("driver"));
        link.push(obj("robotran"));
        link.extend((0..vs.len()).map(|i| obj(&format!("rv{i}"))));
        link.push("-lm".into());
        run(Command::new("cc").args(&link));
        // `runs` processes, alternating nothing but themselves: a process's paired median is
        // stable within it (tight quartiles) but moves by ±20 % between processes on a shared VM
        // (the host's load), so the table gives the median over processes.
        let mut checks = BTreeMap::new();
        let mut per_variant: BTreeMap<String, Vec<[f64; 6]>> = BTreeMap::new();
        let mut pairs: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        let mut order = Vec::new();
        for _ in 0..runs {
            let out = run(Command::new(&exe).arg(reps.to_string()));
            for line in out.lines() {
                let f: Vec<&str> = line.split('\t').collect();
                match f.as_slice() {
                    ["check", v, n, same, worst] => {
                        checks
                            .insert(v.to_string(), format!("{same}/{n} bit-identical, max diff {worst} of max |out|"));
                    }
                    ["pair", v, _base, median, _, _] => {
                        pairs.entry(v.to_string()).or_default().push(median.parse().unwrap());
                    }
                    ["time", v, rest @ ..] if rest.len() == 6 => {
                        let x: Vec<f64> = rest.iter().map(|t| t.parse().unwrap()).collect();
                        if !per_variant.contains_key(*v) {
                            order.push(v.to_string());
                        }
                        per_variant.entry(v.to_string()).or_default().push([x[0], x[1], x[2], x[3], x[4], x[5]]);
                    }
                    _ => {}
                }
            }
        }
        for v in &order {
            let xs = &per_variant[v];
            let median = |k: usize| {
                let mut c: Vec<f64> = xs.iter().map(|x| x[k]).collect();
                c.sort_by(f64::total_cmp);
                c[c.len() / 2]
            };
            let (variant, error) = if v == "robotran" {
                ("Robotran's C".to_string(), errors[&("atomise".to_string(), "f64")].clone())
            } else {
                let i: usize = v[1..].parse().unwrap();
                (vs[i].label.clone(), errors[&(vs[i].pipeline.clone(), vs[i].precision)].clone())
            };
            rows.push(Row {
                model: model.label.clone(),
                variant,
                flags: flag_label.to_string(),
                median: median(0),
                min: xs.iter().map(|x| x[1]).fold(f64::INFINITY, f64::min),
                max: xs.iter().map(|x| x[2]).fold(0.0, f64::max),
                ratio: median(3),
                ratio_range: (
                    xs.iter().map(|x| x[3]).fold(f64::INFINITY, f64::min),
                    xs.iter().map(|x| x[3]).fold(0.0, f64::max),
                ),
                vs_unsplit: pairs.get(v).map(|xs| {
                    let mut c = xs.clone();
                    c.sort_by(f64::total_cmp);
                    (c[c.len() / 2], c[0], c[c.len() - 1])
                }),
                error,
                check: checks.get(v).cloned().unwrap_or_default(),
            });
        }
    }
}

fn main() {
    let mut models = Vec::new();
    let mut flags = "both".to_string();
    let mut reps = 61;
    let mut runs = 5;
    let mut quick = false;
    let mut core = false;
    let mut split: Option<Vec<u32>> = None;
    for a in std::env::args().skip(1) {
        if let Some(f) = a.strip_prefix("--flags=") {
            flags = f.into();
        } else if let Some(r) = a.strip_prefix("--reps=") {
            reps = r.parse().expect("--reps=N");
        } else if let Some(r) = a.strip_prefix("--runs=") {
            runs = r.parse().expect("--runs=N");
        } else if a == "--quick" {
            quick = true;
        } else if a == "--core" {
            core = true;
        } else if a == "--split" {
            split = Some(vec![robovec_backends::c::DEFAULT_CHUNK]);
        } else if let Some(list) = a.strip_prefix("--split=") {
            split = Some(list.split(',').map(|x| x.parse().expect("--split=OPS,OPS…")).collect());
        } else if a == "--bench" || a.starts_with('-') {
            // cargo bench passes `--bench`; ignore other harness flags.
        } else {
            models.push(a);
        }
    }
    if models.is_empty() {
        models.push("m454".into());
    }
    // `native-contract`: as Robotran's users compile its C (GCC's default `-ffp-contract=fast`
    // under `-march=native` fuses a*b+c), every side compiled so; the checks then compare
    // within their tolerance, not bit for bit.
    let all = [
        ("O2", "-O2"),
        ("O3-native", "-O3 -march=native -ffp-contract=off"),
        ("O3-native, GCC's default contraction", "-O3 -march=native"),
    ];
    let flag_sets: Vec<(&str, &str)> = match flags.as_str() {
        "o2" => all[..1].to_vec(),
        "native" => all[1..2].to_vec(),
        "native-contract" => all[2..].to_vec(),
        "all" => all.to_vec(),
        _ => all[..2].to_vec(),
    };
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut rows = Vec::new();
    for m in &models {
        bench_model(m, &flag_sets, (reps, runs), (quick, core), split.as_deref(), &mut rows);
    }
    println!("load average before: {}", load.trim());
    println!("| model | variant | flags | ns/state median (min–max) | vs Robotran: paired median over {runs} runs (min–max) | vs chunk=0: paired median over {runs} runs (min–max) | error bits mean / max | check vs Robotran (state 0) |");
    println!("|---|---|---|---:|---:|---:|---|---|");
    for r in &rows {
        let vs = r.vs_unsplit.map_or(String::new(), |(m, lo, hi)| format!("{m:.3}× ({lo:.3}–{hi:.3})"));
        println!(
            "| {} | {} | {} | {:.1} ({:.1}–{:.1}) | {:.2}× ({:.2}–{:.2}) | {vs} | {} | {} |",
            r.model,
            r.variant,
            r.flags,
            r.median,
            r.min,
            r.max,
            r.ratio,
            r.ratio_range.0,
            r.ratio_range.1,
            r.error,
            r.check
        );
    }
}
