//! `robovec-opt`: argument parsing → [`robovec::driver::run`] → exit status. No logic here.

use clap::Parser;
use robovec::cli::{normalise_args, print_passes, Cli};

fn main() {
    let cli = Cli::parse_from(normalise_args(std::env::args()));
    if cli.print_passes {
        print!("{}", print_passes());
        return;
    }
    let opts = match cli.options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut stdout = std::io::stdout().lock();
    let mut stderr = std::io::stderr().lock();
    if let Err(f) = robovec::driver::run(&opts, &mut stdout, &mut stderr) {
        eprint!("{}", f.message());
        std::process::exit(f.exit_code());
    }
}
