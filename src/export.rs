//! What `robovec-gen` writes for one robot (issue 14): the robot as URDF
//! ([`robovec_dynamics::urdf_out`]), or one of its functions as a Robotran-format C file and
//! header ([`robovec_dynamics::robotran_c`]), with the parameter values as JSON.
//!
//! The robot is a built-in topology family ([`robovec_dynamics::topology`], seed §3.2 Table 3.1) or a URDF
//! file read by the registered URDF front end (the same located diagnostics, exit 1, as
//! `robovec-opt`). `--floating-base` and `--fold-params` mean what they mean to `robovec-opt`.
//! Every file of a run goes through one [`OutputSet`]: all of them are written or none.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use robovec_dynamics::robotran_c::{self, Banner};
use robovec_dynamics::topology::{build, Topology};
use robovec_front::FrontOptions;
use robovec_ir::Module;

use crate::options::Failure;
use crate::output::{OutputSet, ReadFile};

/// Where the robot comes from.
#[derive(Clone, Debug)]
pub enum Source {
    /// A built-in family: `--topology T --dof N --seed S`.
    Topology { topology: Topology, dof: usize, seed: u64 },
    /// `--urdf FILE`.
    Urdf(PathBuf),
}

/// What is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// The robot as URDF (numbers round-trip exact).
    Urdf,
    /// One function (`--function`) as Robotran 6.6 C (`X.c`) and its header (`X.h`).
    C,
}

/// One `robovec-gen` run that writes a model.
#[derive(Clone, Debug)]
pub struct Export {
    /// The robot.
    pub source: Source,
    /// What to write.
    pub format: Format,
    /// `invdyna` or `dirdyna` (C only).
    pub function: String,
    /// Put the robot on Robotran's floating base (`T1`–`T3`, `R1`–`R3` as `q[1..6]`).
    pub floating_base: bool,
    /// Fold the model parameters into the equations (C only).
    pub fold_params: bool,
    /// Write the values of the parameters left as inputs here (JSON, what `-params-out` writes).
    pub params_out: Option<PathBuf>,
    /// The output (`X.c` for C, its header goes to `X.h`); stdout when absent (URDF only).
    pub output: Option<PathBuf>,
}

/// Runs `e`: builds or reads the robot, writes what `e.format` asks, all files or none.
///
/// # Errors
/// [`Failure::Input`] (exit 1) for a URDF the front end refuses or a function the writer cannot
/// print; [`Failure::Usage`] (exit 2) for C without `-o FILE.c`, `--params-out` with folded
/// parameters or with URDF output, an output that is the `--urdf` file read;
/// [`Failure::Output`] (exit 1) when a file cannot be written.
pub fn run(e: &Export, stdout: &mut dyn Write) -> Result<(), Failure> {
    // Only the function written is generated.
    let front = FrontOptions {
        fold_params: e.fold_params,
        floating_base: e.floating_base,
        functions: Some(vec![e.function.clone()]),
        ..FrontOptions::default()
    };
    // The URDF read is never written over (issue 47: `--urdf X -o X` replaced it).
    let reads: Vec<ReadFile> = match &e.source {
        Source::Urdf(p) => vec![ReadFile::new("the input", p)],
        Source::Topology { .. } => Vec::new(),
    };
    if e.format == Format::Urdf {
        if e.fold_params || e.params_out.is_some() {
            return Err(Failure::Usage(
                "error: --fold-params and --params-out concern equations: add --format c\n".into(),
            ));
        }
        if let Some(path) = &e.output {
            not_read(&reads, "-o", path)?;
        }
        let robot = robot(&e.source, e.floating_base)?;
        let text = robovec_dynamics::urdf_out::write_urdf(&robot);
        return match &e.output {
            None => stdout.write_all(text.as_bytes()).map_err(|err| Failure::Output(format!("error: stdout: {err}\n"))),
            Some(path) => {
                let mut set = OutputSet::new();
                set.protect(reads);
                set.stage(path, text.as_bytes()).map_err(Failure::Output)?;
                set.commit().map(|_| ()).map_err(Failure::Output)
            }
        };
    }
    let Some(c_path) = e.output.as_ref().filter(|p| p.extension().is_some_and(|x| x == "c")) else {
        return Err(Failure::Usage("error: --format c writes a .c file and its .h beside it: give -o FILE.c\n".into()));
    };
    if e.fold_params && e.params_out.is_some() {
        return Err(Failure::Usage(
            "error: --params-out: with --fold-params no parameter is left as an input\n".into(),
        ));
    }
    // The outputs are distinct files, checked before any work (issue 29: `-o x.c --params-out
    // x.h` replaced the header with the JSON).
    let h_path = c_path.with_extension("h");
    let outputs: Vec<(&str, &Path)> = [("-o", Some(c_path.as_path())), ("-o's header", Some(h_path.as_path()))]
        .into_iter()
        .chain([("--params-out", e.params_out.as_deref())])
        .filter_map(|(flag, p)| p.map(|p| (flag, p)))
        .collect();
    for (i, (fa, a)) in outputs.iter().enumerate() {
        if let Some((fb, b)) =
            outputs[i + 1..].iter().find(|(_, b)| crate::preflight::resolved(a) == crate::preflight::resolved(b))
        {
            return Err(Failure::Usage(format!(
                "error: {fa} `{}` and {fb} `{}` are the same file\n",
                a.display(),
                b.display()
            )));
        }
    }
    for (flag, p) in &outputs {
        not_read(&reads, flag, p)?;
    }
    let (module, params, project) = equations(&e.source, front)?;
    let Some(f) = module.function(&e.function) else {
        return Err(Failure::Usage(format!("error: --function {}: expected invdyna or dirdyna\n", e.function)));
    };
    let header = file_name(&h_path);
    let source = match &e.source {
        Source::Topology { topology, dof, seed } => {
            format!("robovec-gen --topology {} --dof {dof} --seed {seed}", topology.name())
        }
        Source::Urdf(p) => format!("URDF {}", p.display()),
    };
    let banner = Banner { project: &project, joints: coordinates(f), source: &source, header: &header };
    let written = robotran_c::write(f, &banner).map_err(|err| Failure::Input(format!("error: {err}\n")))?;
    let mut set = OutputSet::new();
    set.protect(reads);
    set.stage(c_path, written.c.as_bytes()).map_err(Failure::Output)?;
    set.stage(&h_path, written.h.as_bytes()).map_err(Failure::Output)?;
    if let Some(p) = &e.params_out {
        let values = params.unwrap_or_default();
        let json = serde_json::to_string_pretty(&values).expect("parameter values serialise");
        set.stage(p, format!("{json}\n").as_bytes()).map_err(Failure::Output)?;
    }
    set.commit().map(|_| ()).map_err(Failure::Output)
}

/// Refuses, as bad usage, the output `flag` `path` when it is one of the files read, by
/// identity ([`crate::output::file_id`]: `./x`, `d/../x` and links are the same file).
fn not_read(reads: &[ReadFile], flag: &str, path: &Path) -> Result<(), Failure> {
    let Some(id) = crate::output::file_id(path) else { return Ok(()) };
    match reads.iter().find(|r| r.id.as_ref() == Some(&id)) {
        Some(r) => Err(Failure::Usage(format!(
            "error: {flag} `{}` is {}; robovec never writes over a file it reads: choose another path\n",
            path.display(),
            r.describe()
        ))),
        None => Ok(()),
    }
}

/// The robot of `source` (a URDF through the URDF front end's parser and checks).
fn robot(source: &Source, floating_base: bool) -> Result<robovec_dynamics::robot::Robot, Failure> {
    let robot = match source {
        Source::Topology { topology, dof, seed } => build(*topology, *dof, *seed),
        Source::Urdf(path) => {
            let input = path.to_string_lossy().into_owned();
            let text = std::fs::read_to_string(path)
                .map_err(|err| Failure::Input(format!("error: cannot read `{input}`: {err}\n")))?;
            let parsed = robovec_front::urdf::parse(&text).ok();
            match parsed.map(|r| if floating_base { r.with_floating_base().ok() } else { Some(r) }) {
                Some(Some(robot)) => return Ok(robot),
                // The registered front end renders the located diagnostic (file:line:col).
                _ => {
                    let front = FrontOptions { fold_params: true, floating_base, ..FrontOptions::default() };
                    crate::driver::load_with(&input, &front)?;
                    return Err(Failure::Input(format!("error: `{input}` changed while it was read\n")));
                }
            }
        }
    };
    if floating_base {
        robot
            .with_floating_base()
            .map_err(|(name, _)| Failure::Input(format!("error: `{name}` is a name of robovec's floating base\n")))
    } else {
        Ok(robot)
    }
}

/// Equations of one robot: the module, the values of the parameters left as inputs, and the
/// project name.
type Equations = (Module, Option<BTreeMap<String, f64>>, String);

/// The equations, parameter values and project name of `source`.
fn equations(source: &Source, front: FrontOptions) -> Result<Equations, Failure> {
    match source {
        Source::Topology { topology, dof, seed } => {
            let robot = robot(source, front.floating_base)?;
            let request =
                robovec_dynamics::Request { fold: front.fold_params, functions: front.functions, ..Default::default() };
            let g = robovec_dynamics::generate_with(&robovec_dynamics::Model { robot }, &request)
                .expect("no deadline, no stop");
            Ok((g.module, g.params, format!("{}{dof}_seed{seed}", topology.name().replace('-', "_"))))
        }
        Source::Urdf(path) => {
            let (loaded, _) = crate::driver::load_with(&path.to_string_lossy(), &front)?;
            let project = path.file_stem().map_or("robot".into(), |s| s.to_string_lossy().into_owned());
            Ok((loaded.module, loaded.params, project))
        }
    }
}

/// The number of generalized coordinates `f` reads: the largest `i` of its `q[i]`, `qd[i]`,
/// `qdd[i]` inputs.
fn coordinates(f: &robovec_ir::Function) -> usize {
    f.inputs
        .iter()
        .filter_map(|&v| {
            let name = f.name_of(v);
            let rest =
                name.strip_prefix("qdd[").or_else(|| name.strip_prefix("qd[")).or_else(|| name.strip_prefix("q["))?;
            rest.strip_suffix(']')?.parse::<usize>().ok()
        })
        .max()
        .unwrap_or(0)
}

/// The last component of `p` (what the `.c` `#include`s).
fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}
