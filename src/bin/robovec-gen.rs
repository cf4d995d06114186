//! `robovec-gen`: robots robovec builds itself, written as URDF or as Robotran C (issue 14).
//!
//! `robovec-gen --topology serial|semi-serial|parallel|star --dof N [--seed S] [-o FILE.urdf]` writes
//! one model of the study's topology families (`robovec_dynamics::topology`, seed §3.2 Table 3.1)
//! as a URDF (`robovec_dynamics::urdf_out`: numbers round-trip exact), to stdout without `-o`.
//! `robovec-opt FILE.urdf -function=dirdyna -passes=…` then runs any pipeline on its equations
//! (the URDF front end reads it back to the same IR the generator writes directly: tested in
//! `tests/pinocchio.rs`, which also checks every family against Pinocchio).
//!
//! `robovec-gen (--topology T --dof N | --urdf FILE.urdf) --format c --function invdyna|dirdyna
//! [--floating-base] [--fold-params] [--params-out P.json] -o mbs_invdyna_X.c` writes one
//! function as a Robotran 6.6 C file and its header `mbs_invdyna_X.h` beside it
//! (`robovec_dynamics::robotran_c`), which robovec's C front end reads back to the same IR
//! (`tests/robotran_c.rs`); see `robovec::export`.
//!
//! `robovec-gen --study [--dof 23,50,…] [--topology serial,…] [--seed S] [--samples K]
//! [--best PIPELINE] [--report-dir DIR] [-q]` runs the thesis's study (seed §3.2, Table 3.1) on
//! the families instead: see `robovec::study` (the command, the cases, what is measured, the
//! table).
//!
//! Exit status: 0 on success, 1 for a bad URDF or when the output cannot be written, 2 on bad
//! usage.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use robovec::export::{Export, Format, Source};
use robovec_dynamics::topology::Topology;

/// Command line of `robovec-gen`.
#[derive(Parser, Debug)]
#[command(
    name = "robovec-gen",
    version,
    about = "Write a robot (a topology family or a URDF) as URDF or as Robotran C, or run the study"
)]
struct Args {
    /// Topology family: serial (one chain), semi-serial (a few medium chains), parallel (many
    /// short chains from the base) or star (one joint per branch, not a study family). With
    /// --study: a comma-separated list (default serial, semi-serial, parallel).
    #[arg(long, value_delimiter = ',', required_unless_present_any = ["study", "urdf"], conflicts_with = "urdf")]
    topology: Vec<Topology>,
    /// Degrees of freedom (revolute joints), at least 1. With --study: a comma-separated list
    /// (default 23,50,70,100,130).
    #[arg(long, value_delimiter = ',', required_unless_present_any = ["study", "urdf"], conflicts_with = "urdf", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    dof: Vec<u32>,
    /// Seed of the random parameters (the same seed gives the same robot on every machine).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output file (written whole or not at all); stdout when absent. With --format c: the .c
    /// file, its header goes beside it with the extension .h.
    #[arg(short = 'o', long = "output", conflicts_with = "study")]
    output: Option<PathBuf>,
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    study: StudyArgs,
}

/// What is written for one robot (`robovec::export`).
#[derive(clap::Args, Debug)]
struct ModelArgs {
    /// Read the robot from this URDF instead of building a topology family.
    #[arg(long, conflicts_with = "study")]
    urdf: Option<PathBuf>,
    /// urdf: the robot as URDF; c: one function (--function) as a Robotran 6.6 C file and header.
    #[arg(long, value_enum, default_value = "urdf", conflicts_with = "study")]
    format: Format,
    /// With --format c (required there): the function, invdyna (Qq) or dirdyna (M, c).
    #[arg(long, value_parser = ["invdyna", "dirdyna"], conflicts_with = "study")]
    function: Option<String>,
    /// Put the robot on Robotran's floating base (T1 T2 T3 R1 R2 R3 as q[1..6]).
    #[arg(long, conflicts_with = "study")]
    floating_base: bool,
    /// With --format c: fold the model parameters into the equations.
    #[arg(long, conflicts_with = "study")]
    fold_params: bool,
    /// With --format c: write the values of the parameters left as inputs to this JSON file.
    #[arg(long, conflicts_with = "study")]
    params_out: Option<PathBuf>,
}

/// The `--study` flag group (`robovec::study`).
#[derive(clap::Args, Debug)]
struct StudyArgs {
    /// Run the study of seed §3.2 Table 3.1 (dirdyna of every dof × topology) and print its table.
    #[arg(long)]
    study: bool,
    /// --study: accuracy samples per case.
    #[arg(long, default_value_t = 200, requires = "study", value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples: u32,
    /// --study: the best rewrite pipeline (from the parsed equations).
    #[arg(long, default_value = robovec::study::DEFAULT_BEST, requires = "study")]
    best: String,
    /// --study: write the study folder (study.md/json/csv, figures, per-case reports) here.
    #[arg(long, requires = "study")]
    report_dir: Option<PathBuf>,
    /// --study --report-dir: write the study-level files only, without each case's report
    /// folder under cases/ (minutes faster, 53 MB smaller).
    #[arg(long, requires = "report_dir")]
    no_case_reports: bool,
    /// --study: no progress bar and no summary line.
    #[arg(short = 'q', long, requires = "study")]
    quiet: bool,
}

/// `--study`: runs `robovec::study::run`.
fn study(args: &Args) -> ExitCode {
    use std::io::IsTerminal;
    let dofs = if args.dof.is_empty() {
        robovec::study::cases::THESIS_DOFS.to_vec()
    } else {
        args.dof.iter().map(|&d| d as usize).collect()
    };
    let topologies = if args.topology.is_empty() { Topology::ALL.to_vec() } else { args.topology.clone() };
    let opts = robovec::study::Options {
        dofs,
        topologies,
        seed: args.seed,
        samples: args.study.samples,
        best: args.study.best.clone(),
        ns: robovec::study::DEFAULT_NS.to_vec(),
        report_dir: args.study.report_dir.clone(),
        case_reports: !args.study.no_case_reports,
        quiet: args.study.quiet,
        command: std::iter::once("robovec-gen".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" "),
    };
    let terminal = std::io::stderr().is_terminal();
    match robovec::study::run(&opts, terminal, &mut std::io::stdout().lock(), &mut std::io::stderr()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprint!("{}", f.message());
            ExitCode::from(f.exit_code() as u8)
        }
    }
}

/// mimalloc, as in `robovec-opt` ([`robovec::allocator`]): the study runs every case's passes in
/// this process.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    robovec::allocator::configure();
    let args = match Args::try_parse() {
        Ok(a) => a,
        // --help and --version (stdout: a failed write is exit 1), or a usage error.
        Err(e) => return ExitCode::from(robovec::cli::report_parse_error(&e) as u8),
    };
    if args.study.study {
        return study(&args);
    }
    let source = match &args.model.urdf {
        Some(path) => Source::Urdf(path.clone()),
        None => {
            let (&[topology], &[dof]) = (args.topology.as_slice(), args.dof.as_slice()) else {
                use clap::CommandFactory;
                Args::command()
                    .error(
                        clap::error::ErrorKind::ArgumentConflict,
                        "--topology and --dof take one value each without --study",
                    )
                    .exit();
            };
            Source::Topology { topology, dof: dof as usize, seed: args.seed }
        }
    };
    let function = match (args.model.format, &args.model.function) {
        (Format::C, Some(f)) => f.clone(),
        (Format::Urdf, None) => String::new(),
        (Format::C, None) => usage("--format c writes one function: add --function invdyna or --function dirdyna"),
        (Format::Urdf, Some(_)) => usage("--function selects the equations of --format c; a URDF holds the robot"),
    };
    let export = Export {
        source,
        format: args.model.format,
        function,
        floating_base: args.model.floating_base,
        fold_params: args.model.fold_params,
        params_out: args.model.params_out.clone(),
        output: args.output.clone(),
    };
    match robovec::export::run(&export, &mut std::io::stdout().lock()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprint!("{}", f.message());
            ExitCode::from(f.exit_code() as u8)
        }
    }
}

/// Exits with clap's usage error (status 2) saying `msg`.
fn usage(msg: &str) -> ! {
    use clap::CommandFactory;
    Args::command().error(clap::error::ErrorKind::ArgumentConflict, msg).exit()
}
