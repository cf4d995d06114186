//! The command line of `robovec-opt` (SPEC §7), LLVM `opt` style.
//!
//! clap parses `--flag=value`; LLVM's single-dash spellings (`-passes=…`, `-print-after-all`)
//! are mapped onto them first, so both `-flag` and `--flag` work. `-o` and `-p` stay short.

use std::path::PathBuf;

use clap::{ArgAction, Parser};
use robovec_front::FrontOption;
use robovec_passes::{Instrumentation, PrintSelector};

use crate::options::Options;

/// `robovec-opt INPUT -passes=PIPELINE [options]`
#[derive(Parser, Debug)]
#[command(
    name = "robovec-opt",
    version,
    about = "Run a pipeline of passes over Robotran equations (C, Matlab, Python), a URDF robot's generated equations or robovec IR (.rvir)",
    after_help = "Single-dash spellings (-passes=…, -print-after-all) are accepted as in LLVM's opt.\n\
                  Exit status: 0 success, 1 bad input, 2 bad usage."
)]
pub struct Cli {
    /// Input: a Robotran file (.c, .m, .py), a URDF robot (.urdf) or robovec IR (.rvir); `-` reads IR from stdin.
    pub input: Option<String>,
    /// Pipeline, LLVM syntax: `atomise,dce<outputs=c>,asap-alap<lat-add=12>`.
    #[arg(long = "passes", short = 'p', value_name = "PIPELINE", default_value = "")]
    pub passes: String,
    /// Write the final IR to FILE (default: stdout, unless -eval prints there).
    #[arg(short = 'o', value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Print the IR (stderr) after every pass.
    #[arg(long)]
    pub print_after_all: bool,
    /// Print the IR (stderr) before every pass.
    #[arg(long)]
    pub print_before_all: bool,
    /// Print the IR (stderr) after the named passes (comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "PASS")]
    pub print_after: Vec<String>,
    /// Print the IR (stderr) before the named passes (comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "PASS")]
    pub print_before: Vec<String>,
    /// Write `NNN-<pass>.before.rvir` / `.after.rvir` for every pass into DIR.
    #[arg(long, value_name = "DIR")]
    pub dump_dir: Option<PathBuf>,
    /// Print a pass timing table to stderr.
    #[arg(long)]
    pub time_passes: bool,
    /// Verify the IR after each pass (default true; `-verify-each=false` turns it off).
    #[arg(long, action = ArgAction::Set, num_args = 0..=1, default_value_t = true, default_missing_value = "true")]
    pub verify_each: bool,
    /// Write the JSON report (SPEC §7) to FILE.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Write the report as a folder: report.json (as -report), report.md and SVG figures with
    /// the CSV of the numbers each draws (cycles, µs, parallelisation rate and memory against
    /// N from `sweep`; occupation and timeline from `place`; the -pareto front). DIR must be
    /// missing, empty or a report folder written before; it is replaced as a whole.
    #[arg(long, value_name = "DIR")]
    pub report_dir: Option<PathBuf>,
    /// Quiet: no progress bars on stderr (they are shown only when stderr is a terminal).
    #[arg(short = 'q', long)]
    pub quiet: bool,
    /// Evaluate the final IR (in f64, or f32 with -eval-precision=f32) on the inputs in FILE
    /// (JSON object name → number); print inputs and outputs as JSON on stdout.
    #[arg(long, value_name = "FILE")]
    pub eval: Option<PathBuf>,
    /// The function that -report and -eval describe (e.g. `sensor_2`).
    #[arg(long, value_name = "NAME")]
    pub function: Option<String>,
    /// Print the stats of the final IR (ops, critical path, Y) to stderr.
    #[arg(long)]
    pub stats: bool,
    /// Write the rows of `sweep` passes to FILE as CSV.
    #[arg(long, value_name = "FILE")]
    pub sweep_csv: Option<PathBuf>,
    /// Speed against error: run each `;`-separated pipeline on the input and print one table
    /// (ops, critical path, placed cycles, bits of error in f32/f64 against the input with the
    /// 95% confidence interval; Pareto-optimal rows marked, rows outside the error budget of
    /// the input flagged); with -report, also its `pareto` array.
    #[arg(long, value_name = "PIPELINE;PIPELINE;…")]
    pub pareto: Option<String>,
    /// Samples of -pareto's accuracy measurement (same for every pipeline).
    #[arg(long, value_name = "N", default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    pub pareto_samples: u32,
    /// Seed of -pareto's accuracy measurement.
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    pub pareto_seed: u64,
    /// Evaluation precision of -eval: `f64` (default) or `f32` (inputs rounded to binary32,
    /// every operation in binary32 in the IR's order, as the FPGA computes).
    #[arg(long, value_name = "f32|f64", default_value = "f64", value_parser = ["f32", "f64"])]
    pub eval_precision: String,
    /// After the pipeline, check that every output stays within the rigorous error budget of
    /// the input's exact value (bit for bit for bit-exact pipelines); exit 1 naming the first
    /// output that does not.
    #[arg(long)]
    pub check: bool,
    /// Points of -check.
    #[arg(long, value_name = "N", default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    pub check_samples: u32,
    /// Seed of -check's points (point i is `accuracy<seed=S>`'s point i).
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    pub check_seed: u64,
    /// List the registered passes with their parameters and exit: as text, or
    /// (`--print-passes=markdown`) as the manual's page docs/passes.md.
    #[arg(long, value_name = "FORMAT", num_args = 0..=1, require_equals = true, default_missing_value = "text")]
    pub print_passes: Option<PassListing>,
    /// The machine every pass targets: `de10-nano` (built in, seed ch. 1) or a JSON target
    /// file (latencies, write ports, memory words, clock, device capacities, unit costs; see
    /// docs/targets.md). A pass's `lat-*`/`writes` parameter overrides it only where
    /// given.
    #[arg(long, value_name = "de10-nano|FILE.json")]
    pub target: Option<String>,
    /// The input domain: a JSON object of input name or glob → [lo, hi] (`{"q[3]": [-1.2,
    /// 2.5], "qd[*]": [-10, 10]}`), over the input's defaults (a URDF's limits and parameters);
    /// what `range` encloses every value over (docs/accuracy.md, "Certified ranges").
    #[arg(long, value_name = "FILE")]
    pub ranges: Option<PathBuf>,
    /// URDF input: fold the model's numeric parameters (masses, inertias, lengths) into the
    /// equations instead of keeping them as inputs `dpt`, `l`, `m`, `In`.
    #[arg(long)]
    pub fold_params: bool,
    /// URDF input: put the robot on Robotran's floating base (`T1`–`T3` translations along x,
    /// y, z, then `R1`–`R3` rotations about x, y, z: `q[1..6]`; the URDF's joints follow).
    #[arg(long, conflicts_with = "free_flyer")]
    pub floating_base: bool,
    /// URDF input: put the robot on Pinocchio's free-flyer base (`JointModelFreeFlyer`): `q[1..3]`
    /// the base position in the world, `q[4..7]` its unit quaternion (x, y, z, w), `qd[1..6]`,
    /// `qdd[1..6]`, `Qq[1..6]` its velocity, acceleration and force in the base frame (linear,
    /// then angular); the URDF's joints follow (`q[8]`, `qd[7]`). The quaternion is not
    /// normalised by the equations (as in Pinocchio).
    #[arg(long)]
    pub free_flyer: bool,
    /// URDF input: a continuous joint's configuration, one angle `q[i]` (`angle`, Robotran's)
    /// or Pinocchio's pair `q[i] = cos θ`, `q[i+1] = sin θ` (`cos-sin`, what
    /// `codegen<c;abi=pinocchio>` callers pass; not normalised by the equations).
    /// Default `angle`.
    #[arg(long, value_name = "angle|cos-sin")]
    pub continuous: Option<ContinuousJoint>,
    /// URDF input: the gravity vector `x,y,z` (m/s², world frame), written into the equations
    /// as numbers instead of the inputs `g[1..3]` (Pinocchio's default is `0,0,-9.81`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_gravity, allow_hyphen_values = true)]
    pub gravity: Option<[f64; 3]>,
    /// URDF input: the generator's formulation. `ops` (the default): the fewest ops, body-frame
    /// recursive Newton–Euler, CRBA, LᵀDL or ABA. `depth`: the shortest critical path, every
    /// recursion of `invdyna` and of `dirdyna` (`M` by world-frame composite inertias, `c`)
    /// written in the world frame as a parallel prefix along the tree's chains; `fordyna` solves
    /// with those `M` and `c` by the sparse LᵀDL (the ABA on long chains).
    /// See docs/rewrites.md.
    #[arg(long, value_name = "ops|depth")]
    pub formulation: Option<FormulationArg>,
    /// URDF input: write the values of the parameters kept as inputs to FILE, the JSON object
    /// (`{"m[1]": 2.5, …}`) that `specialize<params=FILE>` and `-eval` read.
    #[arg(long, value_name = "FILE")]
    pub params_out: Option<PathBuf>,
    /// Wall-clock limit of the whole run, loading included, seconds (any positive finite
    /// number): every pass honours it (`robovec_passes::time_limit`): the passes the output
    /// can do without stop or are skipped with a valid result and say so on stderr (`note: …`)
    /// and in the report (`stopped_early`); those it needs get a short grace, then exit 1.
    #[arg(long, value_name = "SECONDS", value_parser = parse_time_limit)]
    pub time_limit: Option<f64>,
}

/// `-time-limit=SECONDS`: a positive, finite number of seconds (`5`, `0.5`, `1e20`: a limit
/// beyond what the clock represents is no limit).
fn parse_time_limit(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("expected a number of seconds greater than 0 (such as `5` or `0.5`), found `{s}`")),
    }
}

/// Says what clap's parse error `e` says, for every binary: `--help` and `--version` on
/// stdout, errors on stderr. Returns the exit status: clap's, or 1 when stdout cannot be
/// written (a closed pipe, a full disk; issue 29: `robovec-gen --help > /dev/full` was exit 0).
pub fn report_parse_error(e: &clap::Error) -> i32 {
    use std::io::Write;
    let text = e.render().to_string();
    if e.use_stderr() {
        let _ = std::io::stderr().lock().write_all(text.as_bytes());
        return e.exit_code();
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => e.exit_code(),
        Err(err) => {
            let _ = writeln!(std::io::stderr().lock(), "error: cannot write to stdout: {err}");
            1
        }
    }
}

/// `-gravity=x,y,z`: three finite numbers (m/s²) separated by commas.
fn parse_gravity(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let numbers: Vec<f64> =
        parts.iter().filter_map(|p| p.trim().parse::<f64>().ok()).filter(|x| x.is_finite()).collect();
    match <[f64; 3]>::try_from(numbers) {
        Ok(g) if parts.len() == 3 => Ok(g),
        _ => Err(format!("expected three finite numbers `x,y,z` (m/s²), such as `0,0,-9.81`; got `{s}`")),
    }
}

/// Maps LLVM single-dash long flags (`-passes=x`) to clap's `--passes=x`.
pub fn normalise_args(args: impl IntoIterator<Item = String>) -> Vec<String> {
    args.into_iter()
        .enumerate()
        .map(|(i, a)| {
            let long_single_dash = i > 0
                && a.starts_with('-')
                && !a.starts_with("--")
                && a.len() > 2
                && a.as_bytes()[1].is_ascii_alphabetic()
                // `-o FILE` and `-oFILE` are the short option.
                && !a.starts_with("-o");
            if long_single_dash {
                format!("-{a}")
            } else {
                a
            }
        })
        .collect()
}

/// `--continuous=angle|cos-sin`: how a URDF continuous joint's configuration is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ContinuousJoint {
    /// One angle `q[i]` (Robotran's convention).
    Angle,
    /// Pinocchio's `(cos θ, sin θ)` pair `q[i]`, `q[i+1]`.
    CosSin,
}

/// `--formulation`: the symbolic generator's formulation (`robovec_dynamics::Formulation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FormulationArg {
    /// The fewest ops (body-frame RNEA, CRBA, LᵀDL or ABA).
    Ops,
    /// The shortest critical path (world-frame parallel prefixes, `robovec_dynamics::depth`).
    Depth,
}

impl From<FormulationArg> for robovec_dynamics::Formulation {
    fn from(f: FormulationArg) -> robovec_dynamics::Formulation {
        match f {
            FormulationArg::Ops => robovec_dynamics::Formulation::Ops,
            FormulationArg::Depth => robovec_dynamics::Formulation::Depth,
        }
    }
}

/// The formats of `--print-passes` (both read from the registry: [`robovec_passes::reference`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PassListing {
    /// One line per pass and per parameter (`name (default D; RANGE) doc`).
    Text,
    /// The manual's page `docs/passes.md`.
    Markdown,
}

impl PassListing {
    /// The listing in this format.
    pub fn render(self) -> String {
        match self {
            PassListing::Text => robovec_passes::reference::text(robovec_backends::REGISTRY),
            PassListing::Markdown => robovec_passes::reference::markdown(robovec_backends::REGISTRY),
        }
    }
}

impl Cli {
    /// The driver options.
    ///
    /// # Errors
    /// A usage message when no input is given.
    pub fn options(self) -> Result<Options, String> {
        let input = self.input.ok_or("error: no input file (use `-` for IR on stdin)")?;
        let sel = |all: bool, names: Vec<String>| {
            if all {
                PrintSelector::All
            } else if names.is_empty() {
                PrintSelector::None
            } else {
                PrintSelector::Passes(names)
            }
        };
        Ok(Options {
            input,
            passes: self.passes,
            output: self.output,
            instr: Instrumentation {
                print_before: sel(self.print_before_all, self.print_before),
                print_after: sel(self.print_after_all, self.print_after),
                dump_dir: self.dump_dir,
                verify_each: self.verify_each,
                time_passes: self.time_passes,
                ..Instrumentation::default()
            },
            report: self.report,
            report_dir: self.report_dir,
            quiet: self.quiet,
            eval: self.eval,
            function: self.function,
            stats: self.stats,
            sweep_csv: self.sweep_csv,
            pareto: self.pareto,
            pareto_samples: self.pareto_samples,
            pareto_seed: self.pareto_seed,
            eval_f32: self.eval_precision == "f32",
            check: self.check.then_some((self.check_samples, self.check_seed)),
            time_limit: self.time_limit,
            target: self.target,
            ranges: self.ranges,
            front_given: [
                (FrontOption::FoldParams, self.fold_params),
                (FrontOption::FloatingBase, self.floating_base),
                (FrontOption::FreeFlyer, self.free_flyer),
                (FrontOption::Continuous, self.continuous.is_some()),
                (FrontOption::Gravity, self.gravity.is_some()),
                (FrontOption::Formulation, self.formulation.is_some()),
                (FrontOption::ParamsOut, self.params_out.is_some()),
            ]
            .into_iter()
            .filter_map(|(o, given)| given.then_some(o))
            .collect(),
            front: robovec_front::FrontOptions {
                fold_params: self.fold_params,
                floating_base: self.floating_base,
                free_flyer: self.free_flyer,
                continuous_cos_sin: self.continuous == Some(ContinuousJoint::CosSin),
                gravity: self.gravity,
                formulation: self.formulation.unwrap_or(FormulationArg::Ops).into(),
                ..robovec_front::FrontOptions::default()
            },
            params_out: self.params_out,
        })
    }
}
