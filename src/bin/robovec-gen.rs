//! `robovec-gen`: robots robovec builds itself, written as URDF (issue 14).
//!
//! `robovec-gen --topology serial|semi-serial|parallel --dof N [--seed S] [-o FILE.urdf]` writes
//! one model of the study's topology families (`robovec::gen::topology`, seed §3.2 Table 3.1)
//! as a URDF (`robovec::gen::urdf_out`: numbers round-trip exact), to stdout without `-o`.
//! `robovec-opt FILE.urdf -function=dirdyna -passes=…` then runs any pipeline on its equations
//! (the URDF front end reads it back to the same IR the generator writes directly: tested in
//! `tests/pinocchio.rs`, which also checks every family against Pinocchio).
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
    /// short chains from the base).
    #[arg(long)]
    topology: Topology,
    /// Degrees of freedom (revolute joints), at least 1.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    dof: u32,
    /// Seed of the random parameters (the same seed gives the same robot on every machine).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output file (written whole or not at all); stdout when absent.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let robot = build(args.topology, args.dof as usize, args.seed);
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
