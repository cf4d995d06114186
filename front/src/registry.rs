//! The front-end registry: every input language robovec reads, in one table ([`FRONT_ENDS`]).
//!
//! The driver picks the front end of an input by its file extension ([`front_end_for`]) and
//! calls [`FrontEnd::load`]; it never names a language. Adding a language is one module and
//! one line in [`FRONT_ENDS`] (the URDF front end, issue 14, is such a line). robovec IR
//! (`.rvir`, and `-` for stdin) is registered too, so that every input takes the same path.
//!
//! A front end returns the module in the parsed phase (or whatever phase an `.rvir` text has)
//! and, when it knows them, the numeric values of the model parameters it left symbolic
//! ([`Loaded::params`], canonical input names of SPEC §2 → number: what `-params-out` writes
//! and what `specialize<params=…>` and `-eval` read).

use std::collections::BTreeMap;
use std::path::Path;

use robovec_ir::Module;

use super::{parse_text_until, FrontError, Language};

/// What a front end may be asked beyond the text (command-line options that concern loading).
/// A front end reads only those it declares ([`FrontEnd::options`]); `robovec-opt` refuses the
/// others on the command line before any work, so "ignore it" below concerns library callers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrontOptions {
    /// `--fold-params`: fold the model's numeric parameters into the equations instead of
    /// keeping them as inputs (`dpt`, `l`, `m`, `In`). Front ends whose input has no numeric
    /// parameters (Robotran files, IR) ignore it.
    pub fold_params: bool,
    /// `--floating-base`: put the robot on Robotran's floating base (six joints `T1`–`T3`,
    /// `R1`–`R3` before the root link, `q[1..6]`; see `robovec_dynamics::robot::Robot::with_floating_base`).
    /// Front ends of fixed equations (Robotran files, IR) ignore it.
    pub floating_base: bool,
    /// `--free-flyer`: put the robot on Pinocchio's free-flyer base (`q[1..7]` position and
    /// quaternion, `qd[1..6]` the base's velocity in its frame; see
    /// `robovec_dynamics::robot::Robot::with_free_flyer`). Front ends of fixed equations ignore it.
    pub free_flyer: bool,
    /// `--continuous=cos-sin`: a URDF continuous joint's configuration as Pinocchio's
    /// `(cos θ, sin θ)` pair (`robovec_dynamics::robot::Robot::cos_sin`). Front ends of fixed
    /// equations ignore it.
    pub continuous_cos_sin: bool,
    /// `-gravity=x,y,z`: the gravity vector written into generated equations as numbers
    /// (m/s², world frame) instead of the inputs `g[1..3]`. Front ends of fixed equations ignore it.
    pub gravity: Option<[f64; 3]>,
    /// `--formulation=ops|depth`: the generator's formulation, the fewest ops (the default) or
    /// the shortest critical path (`robovec_dynamics::depth`). Front ends of fixed equations
    /// ignore it.
    pub formulation: robovec_dynamics::Formulation,
    /// `-function=NAME`: the functions the run will use; `None`: all. A front end that builds
    /// its functions (the URDF's generator) builds only these (issue 28: `-function=invdyna`
    /// does not build `dirdyna`); front ends that read their functions ignore it.
    pub functions: Option<Vec<String>>,
    /// `-time-limit`: the run's deadline, started before loading. Front ends check it in their
    /// long loops (statements read, bodies generated) and, once it is reached, fail with one
    /// error saying where they stopped (see [`FrontEnd::load`]).
    pub deadline: Option<robovec_ir::time_limit::Deadline>,
    /// Compute the input domain's defaults ([`Loaded::domain_defaults`], issue 48): asked when
    /// the run needs a domain (a pass reads it, or `-ranges` gives one); otherwise they stay
    /// empty and the load does not pay for them.
    pub domain: bool,
}

/// A command-line option that concerns one kind of input only: each front end declares the ones
/// it reads ([`FrontEnd::options`]), and the driver refuses any other given with its input as
/// bad usage before any work (issue 47: `--free-flyer` on a `.c` file was silently ignored).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrontOption {
    /// `--fold-params` ([`FrontOptions::fold_params`]).
    FoldParams,
    /// `--floating-base` ([`FrontOptions::floating_base`]).
    FloatingBase,
    /// `--free-flyer` ([`FrontOptions::free_flyer`]).
    FreeFlyer,
    /// `--continuous=angle|cos-sin` ([`FrontOptions::continuous_cos_sin`]).
    Continuous,
    /// `-gravity=X,Y,Z` ([`FrontOptions::gravity`]).
    Gravity,
    /// `--formulation=ops|depth` ([`FrontOptions::formulation`]).
    Formulation,
    /// `-params-out=FILE`: the values of the model parameters the input states
    /// ([`Loaded::params`]).
    ParamsOut,
}

impl FrontOption {
    /// Every option, in the order `--help` lists them.
    pub const ALL: [FrontOption; 7] = [
        FrontOption::FoldParams,
        FrontOption::FloatingBase,
        FrontOption::FreeFlyer,
        FrontOption::Continuous,
        FrontOption::Gravity,
        FrontOption::Formulation,
        FrontOption::ParamsOut,
    ];

    /// The option as the manual spells it (`--free-flyer`, `-gravity`).
    pub fn flag(self) -> &'static str {
        match self {
            FrontOption::FoldParams => "--fold-params",
            FrontOption::FloatingBase => "--floating-base",
            FrontOption::FreeFlyer => "--free-flyer",
            FrontOption::Continuous => "--continuous",
            FrontOption::Gravity => "-gravity",
            FrontOption::Formulation => "--formulation",
            FrontOption::ParamsOut => "-params-out",
        }
    }

    /// The names of the front ends that read this option (`URDF`), from [`FRONT_ENDS`].
    pub fn read_by(self) -> Vec<&'static str> {
        FRONT_ENDS.iter().filter(|f| f.options().contains(&self)).map(|f| f.name()).collect()
    }
}

/// A loaded input: the module, and the values of the model parameters it keeps as inputs.
#[derive(Clone, Debug, Default)]
pub struct Loaded {
    /// The functions read or generated.
    pub module: Module,
    /// Canonical parameter name (`m[2]`, `dpt[1][3]`) → value, when the input states them
    /// (a URDF does; a Robotran file does not: its parameters live in the user's `MbsData`).
    pub params: Option<BTreeMap<String, f64>>,
    /// Values the input's own conventions give its functions' inputs, for `-eval`'s inputs
    /// not given (issue 29): a URDF's model parameters and Pinocchio's gravity
    /// `g = (0, 0, −9.81)`; empty for a Robotran file, whose values live in the user's
    /// `MbsData`.
    pub input_defaults: BTreeMap<String, f64>,
    /// What [`Loaded::input_defaults`] are, for messages (`the URDF's parameters and
    /// Pinocchio's gravity (0, 0, -9.81)`); empty when there are none.
    pub defaults_source: &'static str,
    /// The ranges the input's own description gives its functions' inputs (issue 48), the
    /// defaults of the run's domain (`-ranges=FILE` overrides them): a URDF's `<limit>`s for
    /// `q`, `qd` and `Qq`, its documented defaults for continuous joints, accelerations and a
    /// free flyer, its parameters as point intervals (docs/accuracy.md, "Certified ranges");
    /// each range says where it came from. Empty for a Robotran file or IR.
    pub domain_defaults: BTreeMap<String, robovec_ir::domain::Range>,
    /// What the input holds that is read but suspect (a URDF's inertia tensor that is not
    /// positive semi-definite, used as written), located as errors are; the driver prints them
    /// as warnings. Empty for most inputs.
    pub warnings: Vec<FrontError>,
}

impl From<Module> for Loaded {
    fn from(module: Module) -> Loaded {
        Loaded {
            module,
            params: None,
            input_defaults: BTreeMap::new(),
            defaults_source: "",
            domain_defaults: BTreeMap::new(),
            warnings: Vec::new(),
        }
    }
}

/// One input language.
pub trait FrontEnd: Sync {
    /// Short name shown in messages (`Robotran C`, `URDF`).
    fn name(&self) -> &'static str;

    /// File extensions without the dot (`c`, `h`), matched exactly.
    fn extensions(&self) -> &'static [&'static str];

    /// Reads `text` (made by [`super::source_text`] from the bytes of `path`, every byte
    /// offset kept) into a module. `path` lets a front end read companion files (a C file's
    /// `.h`); it is `-` for stdin.
    ///
    /// # Errors
    /// Every problem found, with byte spans into `text` (the driver renders them as
    /// `file:line:col` diagnostics and exits 1). Once `opts.deadline` is reached: one error,
    /// `time limit of 5 s reached while reading (line N of M)` spanning the line reached, or
    /// `… while generating @dirdyna (body k of n)` at that body's joint; nothing is returned,
    /// since no pass can run on part of a module.
    fn load(&self, path: &Path, text: &str, opts: &FrontOptions) -> Result<Loaded, Vec<FrontError>>;

    /// The names of the functions this front end builds whatever its input (the URDF's
    /// `invdyna`, `dirdyna`, `fordyna`), so that a `-function` naming none of them is refused before any
    /// work; `None` (the default) for front ends whose functions are the input's.
    fn function_names(&self) -> Option<&'static [&'static str]> {
        None
    }

    /// The message when the input holds no function (`expected at least one function`).
    fn no_function_message(&self) -> &'static str {
        "expected at least one function"
    }

    /// The input-specific command-line options this front end reads ([`FrontOption`]); the
    /// driver refuses the others, given with an input of this front end, as bad usage before
    /// any work. None by default: the front ends of fixed equations (Robotran files, IR) read
    /// none.
    fn options(&self) -> &'static [FrontOption] {
        &[]
    }

    /// The files beside `path` (the input) that [`FrontEnd::load`] reads too (a Robotran C
    /// file's `.h`), so that no output of the run is written over one of them; none by
    /// default.
    fn reads_beside(&self, path: &Path) -> Vec<std::path::PathBuf> {
        let _ = path;
        Vec::new()
    }

    /// True when the input must be valid UTF-8 (XML: a URDF): the driver then refuses one
    /// that is not, at its first invalid byte, instead of reading each such byte as `?` as it
    /// does for Robotran files (issue 29: a URDF with invalid UTF-8 was accepted silently).
    fn requires_utf8(&self) -> bool {
        false
    }
}

/// A Robotran output file (C with its companion `.h`, Matlab or Python).
struct Robotran(Language);

impl FrontEnd for Robotran {
    fn name(&self) -> &'static str {
        match self.0 {
            Language::C => "Robotran C",
            Language::Matlab => "Robotran Matlab",
            Language::Python => "Robotran Python",
        }
    }

    fn extensions(&self) -> &'static [&'static str] {
        match self.0 {
            Language::C => &["c", "h"],
            Language::Matlab => &["m"],
            Language::Python => &["py"],
        }
    }

    fn reads_beside(&self, path: &Path) -> Vec<std::path::PathBuf> {
        match self.0 {
            Language::C if path.extension().is_some_and(|e| e == "c") => vec![path.with_extension("h")],
            _ => Vec::new(),
        }
    }

    fn load(&self, path: &Path, text: &str, opts: &FrontOptions) -> Result<Loaded, Vec<FrontError>> {
        let header = self.reads_beside(path).first().and_then(|h| std::fs::read(h).ok());
        parse_text_until(self.0, text, header.as_deref(), opts.deadline.as_ref()).map(Loaded::from)
    }
}

/// robovec's own textual IR (`.rvir`; `-` reads it from stdin).
struct Ir;

impl FrontEnd for Ir {
    fn name(&self) -> &'static str {
        "robovec IR"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["rvir"]
    }

    fn load(&self, _: &Path, text: &str, _: &FrontOptions) -> Result<Loaded, Vec<FrontError>> {
        robovec_ir::text::parse(text).map(Loaded::from)
    }

    fn no_function_message(&self) -> &'static str {
        "expected at least one `func`"
    }
}

/// Every front end, in the order `--help` lists them.
pub static FRONT_ENDS: &[&dyn FrontEnd] =
    &[&Robotran(Language::C), &Robotran(Language::Matlab), &Robotran(Language::Python), &super::urdf::Urdf, &Ir];

/// The front end for `input`: by extension, IR for `-` (stdin); `None` for an unknown extension.
pub fn front_end_for(input: &str) -> Option<&'static dyn FrontEnd> {
    if input == "-" {
        return Some(&Ir);
    }
    let ext = Path::new(input).extension()?.to_str()?;
    FRONT_ENDS.iter().copied().find(|f| f.extensions().contains(&ext))
}

/// Every registered extension as `.c, .h, .m, …` for messages.
pub fn extension_list() -> String {
    FRONT_ENDS.iter().flat_map(|f| f.extensions()).map(|e| format!(".{e}")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_pick_one_front_end_each() {
        assert_eq!(front_end_for("a/b.c").map(|f| f.name()), Some("Robotran C"));
        assert_eq!(front_end_for("b.h").map(|f| f.name()), Some("Robotran C"));
        assert_eq!(front_end_for("b.m").map(|f| f.name()), Some("Robotran Matlab"));
        assert_eq!(front_end_for("b.py").map(|f| f.name()), Some("Robotran Python"));
        assert_eq!(front_end_for("robot.urdf").map(|f| f.name()), Some("URDF"));
        assert_eq!(front_end_for("x.rvir").map(|f| f.name()), Some("robovec IR"));
        assert_eq!(front_end_for("-").map(|f| f.name()), Some("robovec IR"));
        assert!(front_end_for("x.txt").is_none());
        assert!(front_end_for("noext").is_none());
        // No extension is claimed twice.
        let all: Vec<&str> = FRONT_ENDS.iter().flat_map(|f| f.extensions().iter().copied()).collect();
        let mut dedup = all.clone();
        dedup.sort_unstable();
        dedup.dedup();
        assert_eq!(all.len(), dedup.len());
    }

    #[test]
    fn input_specific_options_are_declared_by_their_front_end() {
        // Robotran files and IR have fixed equations: no model option applies to them.
        for input in ["a.c", "a.h", "a.m", "a.py", "a.rvir", "-"] {
            assert_eq!(front_end_for(input).unwrap().options(), &[] as &[FrontOption], "{input}");
        }
        let urdf = front_end_for("r.urdf").unwrap();
        for o in FrontOption::ALL {
            assert!(urdf.options().contains(&o), "{}", o.flag());
            assert_eq!(o.read_by(), ["URDF"], "{}", o.flag());
        }
        // The C front end reads the header beside a `.c` file, nothing beside a `.h`.
        assert_eq!(front_end_for("d/a.c").unwrap().reads_beside(Path::new("d/a.c")), [Path::new("d/a.h")]);
        assert!(front_end_for("d/a.h").unwrap().reads_beside(Path::new("d/a.h")).is_empty());
    }
}
