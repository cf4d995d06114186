//! What a `robovec-opt` run is asked for ([`Options`], from the command line) and how it fails
//! ([`Failure`], with its exit status), shared by the checks before any work
//! ([`crate::preflight`]) and the run itself ([`crate::driver`]).

use std::path::PathBuf;

use robovec_ir::{Function, Module};
use robovec_passes::Instrumentation;

/// What the command line asked for.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Input path (`.c`, `.m`, `.py`, `.urdf`, `.rvir`), or `-` for IR on stdin.
    pub input: String,
    /// Pipeline text (`atomise,asap-alap`).
    pub passes: String,
    /// `-o FILE`: final IR; stdout when absent (and no `-eval`).
    pub output: Option<PathBuf>,
    /// Printing, dumping, verifying, timing.
    pub instr: Instrumentation,
    /// `-report=FILE`.
    pub report: Option<PathBuf>,
    /// `-report-dir=DIR`: report.json, report.md, SVG figures and their CSVs
    /// ([`crate::report_dir`]), written as one folder.
    pub report_dir: Option<PathBuf>,
    /// `-q`: no progress display on stderr.
    pub quiet: bool,
    /// `-eval=FILE`.
    pub eval: Option<PathBuf>,
    /// `-function=NAME`.
    pub function: Option<String>,
    /// `-stats`: print the stats of the final IR to stderr.
    pub stats: bool,
    /// `-sweep-csv=FILE`: the rows of `sweep` runs as CSV.
    pub sweep_csv: Option<PathBuf>,
    /// `-pareto=A;B;…`: pipelines to compare (speed against error, [`robovec_passes::whole_run::pareto`]).
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
    /// Front-end options (`--fold-params`).
    pub front: robovec_front::FrontOptions,
    /// The input-specific options the command line gave, even at their default value
    /// (`--formulation=ops`): checked against the options the input's front end reads
    /// ([`robovec_front::FrontEnd::options`]) before any work ([`crate::preflight`]).
    pub front_given: Vec<robovec_front::FrontOption>,
    /// `-params-out=FILE`: the values of the model parameters the input states (a URDF's),
    /// as the JSON object `specialize<params=…>` and `-eval` read.
    pub params_out: Option<PathBuf>,
    /// `-target=de10-nano|FILE.json` as given (`None`: `de10-nano`); read by
    /// [`target`] before any work.
    pub target: Option<String>,
    /// `-ranges=FILE`: input ranges over the input's defaults ([`crate::ranges`]).
    pub ranges: Option<PathBuf>,
}

/// The target `-target` selects (`de10-nano` when absent).
///
/// # Errors
/// [`Failure::Input`] (exit 1): a file that cannot be read, is not JSON of the target format
/// (`FILE:LINE:COLUMN: unknown field …`) or holds a senseless value (the field and why).
pub fn target(opts: &Options) -> Result<robovec_machine::target::Target, Failure> {
    use robovec_machine::target::{Target, TargetError};
    let Some(spec) = &opts.target else { return Ok(Target::de10_nano()) };
    Target::resolve(spec).map_err(|e| {
        let hint = match &e {
            TargetError::Io { .. } => {
                format!("\n  = -target takes a built-in target ({}) or a JSON target file", Target::BUILT_IN.join(", "))
            }
            TargetError::Syntax { .. } | TargetError::Value { .. } => {
                "\n  = the target format is described in docs/targets.md and `robovec_machine::target`".to_string()
            }
        };
        Failure::Input(format!("error: -target: {e}{hint}\n"))
    })
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

/// `-pareto`, `-check` and the study's cases fail with the same two kinds: usage (exit 2) and
/// input (exit 1), their text kept.
impl From<robovec_passes::whole_run::Failure> for Failure {
    fn from(f: robovec_passes::whole_run::Failure) -> Failure {
        match f {
            robovec_passes::whole_run::Failure::Usage(s) => Failure::Usage(s),
            robovec_passes::whole_run::Failure::Input(s) => Failure::Input(s),
        }
    }
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
