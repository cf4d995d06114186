//! `robovec-gen`: robots robovec builds itself, written as URDF (issue 14).
//!
//! `robovec-gen --topology serial|semi-serial|parallel --dof N [--seed S] [-o FILE.urdf]` writes
//! one model of the study's topology families (`robovec::gen::topology`, seed §3.2 Table 3.1)
//! as a URDF (`robovec::gen::urdf_out`: numbers round-trip exact), to stdout without `-o`.
//! `robovec-opt FILE.urdf -function=dirdyna -passes=…` then runs any pipeline on its equations
//! (the URDF front end reads it back to the same IR the generator writes directly: tested in
//! `tests/pinocchio.rs`, which also checks every family against Pinocchio).
//!
//! `robovec-gen --study [--dof 23,50,…] [--topology serial,…] [--seed S] [--samples K]
//! [--best PIPELINE] [--report-dir DIR] [-q]` runs the thesis's study (seed §3.2, Table 3.1) on
//! the families instead: see `robovec::study`.
//!
//! Exit status: 0 on success, 1 when the output cannot be written, 2 on bad usage (clap).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use robovec::gen::topology::{build, Topology};

/// Command line of `robovec-gen`.
#[derive(Parser, Debug)]
#[command(name = "robovec-gen", version, about = "Write a robot of the study's topology families as URDF")]
struct Args {
    /// Topology family: serial (one chain), semi-serial (a few medium chains) or parallel (many
    /// short chains from the base). With --study: a comma-separated list (default all three).
    #[arg(long, value_delimiter = ',', required_unless_present = "study")]
    topology: Vec<Topology>,
    /// Degrees of freedom (revolute joints), at least 1. With --study: a comma-separated list
    /// (default 23,50,70,100,130).
    #[arg(long, value_delimiter = ',', required_unless_present = "study", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    dof: Vec<u32>,
    /// Seed of the random parameters (the same seed gives the same robot on every machine).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output file (written whole or not at all); stdout when absent.
    #[arg(short = 'o', long = "output", conflicts_with = "study")]
    output: Option<PathBuf>,
    #[command(flatten)]
    study: StudyArgs,
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

fn main() -> ExitCode {
    let args = Args::parse();
    if args.study.study {
        return study(&args);
    }
    let (&[topology], &[dof]) = (args.topology.as_slice(), args.dof.as_slice()) else {
        use clap::CommandFactory;
        Args::command()
            .error(clap::error::ErrorKind::ArgumentConflict, "--topology and --dof take one value each without --study")
            .exit();
    };
    let robot = build(topology, dof as usize, args.seed);
    let text = robovec::gen::urdf_out::write_urdf(&robot);
    match &args.output {
        None => {
            if std::io::stdout().write_all(text.as_bytes()).is_err() {
                return ExitCode::from(1);
            }
        }
        Some(path) => {
            let mut set = robovec::output::OutputSet::new();
            if let Err(e) = set.stage(path, text.as_bytes()).and_then(|()| set.commit().map(|_| ())) {
                eprintln!("{e}");
                return ExitCode::from(1);
            }
        }
    }
    ExitCode::SUCCESS
}
