//! `robovec-opt`: argument parsing → [`robovec::driver::run`] → exit status. No logic here.
//!
//! Every write to stdout and stderr is checked: a failed one (closed pipe, full disk) ends with
//! exit status 1 and one line on stderr (nothing when stderr itself failed), never a panic.

use std::io::Write;

use clap::Parser;
use robovec::cli::{normalise_args, Cli};

/// mimalloc instead of the system allocator, with [`robovec::allocator::configure`]'s settings
/// (why and the figures: that module).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    robovec::allocator::configure();
    std::process::exit(run());
}

/// Writes `text` to stdout and flushes; on failure says so on stderr. Returns the exit status.
fn to_stdout(text: &str, ok: i32) -> i32 {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ok,
        Err(e) => {
            to_stderr(&format!("error: cannot write to stdout: {e}\n"));
            1
        }
    }
}

/// Writes `text` to stderr; if that fails there is nowhere left to say so.
fn to_stderr(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes()).and_then(|()| err.flush());
}

fn run() -> i32 {
    let cli = match Cli::try_parse_from(normalise_args(std::env::args())) {
        Ok(c) => c,
        // --help and --version (stdout), or a usage error (stderr).
        Err(e) => return robovec::cli::report_parse_error(&e),
    };
    if let Some(listing) = cli.print_passes {
        return to_stdout(&listing.render(), 0);
    }
    let opts = match cli.options() {
        Ok(o) => o,
        Err(e) => {
            to_stderr(&format!("{e}\n"));
            return 2;
        }
    };
    // A large input gets the allocator's settings for large runs (`robovec::allocator`); the
    // size of stdin or of a file that cannot be read yet counts as small.
    if let Ok(m) = std::fs::metadata(&opts.input) {
        robovec::allocator::configure_for_input(m.len());
    }
    use std::io::IsTerminal;
    let terminal =
        robovec::driver::Terminal { stdout: std::io::stdout().is_terminal(), stderr: std::io::stderr().is_terminal() };
    let mut stdout = std::io::stdout().lock();
    // Not locked for the whole run: the progress bars (issue 13) draw on stderr too.
    let mut stderr = std::io::stderr();
    match robovec::driver::run_with(&opts, terminal, &mut stdout, &mut stderr) {
        Ok(()) => 0,
        Err(f) => {
            to_stderr(f.message());
            f.exit_code()
        }
    }
}
