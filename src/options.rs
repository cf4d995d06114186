//! What a `robovec-opt` run is asked for ([`Options`], from the command line) and how it fails
//! ([`Failure`], with its exit status), shared by the checks before any work
//! ([`crate::preflight`]) and the run itself ([`crate::driver`]).

use std::path::PathBuf;

use robovec_ir::{Function, Module};
use robovec_passes::Instrumentation;

/// What the command line asked for.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Input path (`.c`, `.m`, `.py`, `.rvir`), or `-` for IR on stdin.
    pub input: String,
    /// Pipeline text (`atomise,asap-alap`).
    pub passes: String,
    /// `-o FILE`: final IR; stdout when absent (and no `-eval`).
    pub output: Option<PathBuf>,
    /// Printing, dumping, verifying, timing.
    pub instr: Instrumentation,
    /// `-report=FILE`.
    pub report: Option<PathBuf>,
    /// `-eval=FILE`.
    pub eval: Option<PathBuf>,
    /// `-function=NAME`.
    pub function: Option<String>,
    /// `-stats`: print the stats of the final IR to stderr.
    pub stats: bool,
    /// `-sweep-csv=FILE`: the rows of `sweep` runs as CSV.
    pub sweep_csv: Option<PathBuf>,
    /// `-pareto=A;B;…`: pipelines to compare (speed against error, [`crate::pareto`]).
    pub pareto: Option<String>,
    /// `-pareto-samples=N`: samples of each pipeline's accuracy measurement.
    pub pareto_samples: u32,
    /// `-pareto-seed=S`: seed of those measurements.
    pub pareto_seed: u64,
    /// `-eval-precision=f32`: evaluate in binary32.
    pub eval_f32: bool,
    /// `-check` with its samples and seed.
    pub check: Option<(u32, u64)>,
    /// `-time-limit=SECONDS`: wall-clock limit of the run (see `PassContext::deadline`).
    pub time_limit: Option<f64>,
}

/// Why a run failed; the text is ready for stderr.
#[derive(Debug)]
pub enum Failure {
    /// Bad input (exit status 1): a rendered diagnostic.
    Input(String),
    /// Bad usage (exit status 2).
    Usage(String),
    /// An output could not be written — a file under the output policy ([`crate::output`]),
    /// stdout or stderr (exit status 1). The message is one line, empty when stderr itself
    /// failed (nothing more can be said).
    Output(String),
}

impl Failure {
    /// Exit status: 1 for bad input or an output that cannot be written, 2 for bad usage
    /// (SPEC §7).
    pub fn exit_code(&self) -> i32 {
        match self {
            Failure::Input(_) | Failure::Output(_) => 1,
            Failure::Usage(_) => 2,
        }
    }

    /// The message.
    pub fn message(&self) -> &str {
        match self {
            Failure::Input(s) | Failure::Usage(s) | Failure::Output(s) => s,
        }
    }
}

/// The function `-report`, `-eval`, `-pareto` (`what`) describe: the one `-function` names,
/// or the module's only function.
///
/// # Errors
/// [`Failure::Usage`] naming the functions of the module.
pub fn select<'m>(m: &'m Module, want: &Option<String>, what: &str) -> Result<&'m Function, Failure> {
    match want {
        Some(name) => m.function(name).ok_or_else(|| {
            let names: Vec<&str> = m.functions.iter().map(|f| f.name.as_str()).collect();
            Failure::Usage(format!("error: no function `{name}` in the input; functions: {}\n", names.join(", ")))
        }),
        None => match m.functions.as_slice() {
            [f] => Ok(f),
            fs => {
                let names: Vec<&str> = fs.iter().map(|f| f.name.as_str()).collect();
                Err(Failure::Usage(format!(
                    "error: {what} needs one function but the input has {}: {}; choose one with -function=NAME\n",
                    fs.len(),
                    names.join(", ")
                )))
            }
        },
    }
}

/// A refused or failed output (one line from [`crate::output`]).
pub fn output_failure(message: String) -> Failure {
    Failure::Output(message + "\n")
}
