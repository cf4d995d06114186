//! `robovec._robovec`: robovec from Python (issue 51). Bindings only: every operation is one
//! `robovec-opt` run through the command line's own code ([`robovec::cli`] parses the same
//! arguments, [`robovec::driver::run_with`] does the work), so a Python caller gets the command
//! line's behaviour and diagnostics; the compiled functions are `codegen<c;abi=pinocchio>`'s C
//! built by the system compiler and called over numpy arrays. The Python API and its choices
//! are in docs/python.md.
//!
//! - `load`: a Robotran file, a URDF or IR into a `Module` (`functions`, `ir`).
//! - `Module.run`: a pipeline → a new `Module` with its report (SPEC §7).
//! - `passes`: the registry, as `--print-passes`.
//! - `Module.compile`: a URDF's function → a `Compiled` callable over numpy arrays,
//!   through a cache of shared objects keyed by the model, pipeline and options.
//!
//! Errors are Python exceptions: `UsageError` (the command line's exit status 2), `InputError`
//! (exit status 1: a diagnostic with file, line and column), `TimeLimitError` (an `InputError`:
//! `time_limit=` reached), all `robovec.Error`; a shape or type that does not fit a compiled
//! function's signature is a `ValueError`.

#![allow(unsafe_code, reason = "FFI: the compiled C functions are loaded with libloading and called")]

use std::collections::HashMap;
use std::ffi::c_void;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use clap::Parser as _;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict, PyList, PyTuple};
use robovec_backends::c::pinocchio::{self, Dim, Signature};

create_exception!(_robovec, Error, PyException, "Every error robovec raises (its diagnostic in `diagnostic`).");
create_exception!(_robovec, UsageError, Error, "Bad usage: what the command line exits with status 2 for.");
create_exception!(
    _robovec,
    InputError,
    Error,
    "Bad input: the command line's diagnostic (exit status 1), with `file`, `line`, `column` when it names a place."
);
create_exception!(_robovec, TimeLimitError, InputError, "`time_limit=` seconds passed before the work was done.");

/// The exception of a failed run, carrying the diagnostic text and, when the diagnostic names
/// a place (codespan's `┌─ FILE:LINE:COLUMN`), `file`, `line` and `column` (1-based).
fn exception(py: Python<'_>, f: &robovec::options::Failure) -> PyErr {
    use robovec::options::Failure;
    let text = f.message().trim_end().to_string();
    let err = match f {
        Failure::Usage(_) => UsageError::new_err(text.clone()),
        Failure::Input(s) if s.contains("time limit") => TimeLimitError::new_err(text.clone()),
        Failure::Input(_) => InputError::new_err(text.clone()),
        Failure::Output(_) => Error::new_err(text.clone()),
    };
    let value = err.value(py);
    let (file, line, column) = place(&text).map_or((None, None, None), |(f, l, c)| (Some(f), Some(l), Some(c)));
    // Attributes of a fresh exception instance: setting them cannot fail.
    let _ = value.setattr("diagnostic", text);
    let _ = value.setattr("file", file);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    err
}

/// The first `┌─ FILE:LINE:COLUMN` of a codespan diagnostic.
fn place(text: &str) -> Option<(String, usize, usize)> {
    let at = text.find("┌─ ")?;
    let rest = text[at + "┌─ ".len()..].lines().next()?.trim();
    let (head, column) = rest.rsplit_once(':')?;
    let (file, line) = head.rsplit_once(':')?;
    Some((file.to_string(), line.parse().ok()?, column.parse().ok()?))
}

/// One `robovec-opt ARGS` run through the command line's code; its stdout and stderr.
fn opt(py: Python<'_>, args: &[String]) -> PyResult<(Vec<u8>, Vec<u8>)> {
    let argv = std::iter::once("robovec-opt".to_string()).chain(args.iter().cloned());
    let cli = robovec::cli::Cli::try_parse_from(robovec::cli::normalise_args(argv))
        .map_err(|e| UsageError::new_err(e.render().to_string().trim_end().to_string()))?;
    let opts = cli.options().map_err(UsageError::new_err)?;
    let (mut out, mut err) = (Vec::new(), Vec::new());
    robovec::driver::run_with(&opts, robovec::driver::Terminal::default(), &mut out, &mut err)
        .map_err(|f| exception(py, &f))?;
    Ok((out, err))
}

/// A temporary folder for one run's files.
fn scratch() -> PyResult<tempfile::TempDir> {
    tempfile::Builder::new()
        .prefix("robovec-")
        .tempdir()
        .map_err(|e| Error::new_err(format!("cannot make a temporary folder: {e}")))
}

fn read(path: &Path) -> PyResult<String> {
    std::fs::read_to_string(path).map_err(|e| Error::new_err(format!("cannot read {}: {e}", path.display())))
}

/// The names of the functions of an IR text (`func @NAME {`).
fn function_names(ir: &str) -> Vec<String> {
    ir.lines()
        .filter_map(|l| l.strip_prefix("func @"))
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

/// Where a module's IR comes from: the file it was loaded from (with the loading flags), or
/// the IR a run wrote (kept in a temporary file while the module lives).
#[derive(Clone)]
enum Source {
    File { path: String, flags: Vec<String> },
    Ir { file: Arc<tempfile::TempDir> },
}

impl Source {
    /// The input argument and flags of a run on this module.
    fn args(&self) -> Vec<String> {
        match self {
            Source::File { path, flags } => std::iter::once(path.clone()).chain(flags.iter().cloned()).collect(),
            Source::Ir { file } => vec![file.path().join("module.rvir").display().to_string()],
        }
    }
}

/// An IR module: the functions a front end built or a pipeline left. `ir` is its text
/// (docs/ir.md), `report` the report of the run that made it (SPEC §7; `None` for a loaded
/// module; with several functions a dict from function name to report).
#[pyclass(module = "robovec", frozen)]
struct Module {
    source: Source,
    /// The URDF it was loaded from and its flags, for `compile`.
    urdf: Option<(String, Vec<String>)>,
    #[pyo3(get)]
    ir: String,
    #[pyo3(get)]
    report: Option<Py<PyAny>>,
    time_limit: Option<f64>,
}

/// `-time-limit=S` when given.
fn limit_args(time_limit: Option<f64>) -> Vec<String> {
    time_limit.map(|s| format!("-time-limit={s}")).into_iter().collect()
}

/// Loads `path` (a Robotran `.c`/`.m`/`.py`, a `.urdf`, or robovec IR `.rvir`) as the command
/// line does; the URDF flags are those of `robovec-opt` (`--free-flyer`, `--floating-base`,
/// `--continuous=cos-sin`, `-gravity=x,y,z`, `--fold-params`). `time_limit` in seconds.
#[pyfunction]
#[pyo3(signature = (path, *, free_flyer=false, floating_base=false, continuous=None, gravity=None, fold_params=false, time_limit=None))]
#[allow(clippy::too_many_arguments, reason = "the command line's loading flags as keyword arguments")]
fn load(
    py: Python<'_>,
    path: PathBuf,
    free_flyer: bool,
    floating_base: bool,
    continuous: Option<String>,
    gravity: Option<(f64, f64, f64)>,
    fold_params: bool,
    time_limit: Option<f64>,
) -> PyResult<Module> {
    let mut flags = Vec::new();
    if free_flyer {
        flags.push("--free-flyer".to_string());
    }
    if floating_base {
        flags.push("--floating-base".to_string());
    }
    if let Some(c) = continuous {
        flags.push(format!("--continuous={c}"));
    }
    if let Some((x, y, z)) = gravity {
        flags.push(format!("-gravity={x},{y},{z}"));
    }
    if fold_params {
        flags.push("--fold-params".to_string());
    }
    let path = path.display().to_string();
    let dir = scratch()?;
    let out = dir.path().join("module.rvir");
    let mut args = vec![path.clone()];
    args.extend(flags.iter().cloned());
    args.extend(limit_args(time_limit));
    args.extend(["-o".to_string(), out.display().to_string()]);
    opt(py, &args)?;
    let ir = read(&out)?;
    let urdf = path.ends_with(".urdf").then(|| (path.clone(), flags.clone()));
    Ok(Module { source: Source::File { path, flags }, urdf, ir, report: None, time_limit })
}

#[pymethods]
impl Module {
    /// The names of the module's functions, in module order.
    #[getter]
    fn functions(&self) -> Vec<String> {
        function_names(&self.ir)
    }

    /// Runs `pipeline` (LLVM syntax, as `-passes=`) on the module: a new module, its report in
    /// `report`. `function` restricts the run to one function (a URDF builds only that one).
    #[pyo3(signature = (pipeline, *, function=None, time_limit=None))]
    fn run(
        &self,
        py: Python<'_>,
        pipeline: &str,
        function: Option<String>,
        time_limit: Option<f64>,
    ) -> PyResult<Module> {
        let time_limit = time_limit.or(self.time_limit);
        let dir = Arc::new(scratch()?);
        let out = dir.path().join("module.rvir");
        let base = |extra: &[String]| {
            let mut a = self.source.args();
            a.push(format!("-passes={pipeline}"));
            a.extend(limit_args(time_limit));
            a.extend(extra.iter().cloned());
            a
        };
        let functions: Vec<String> = match &function {
            Some(f) => vec![f.clone()],
            None => self.functions(),
        };
        let json = py.import("json")?;
        let report_of = |f: &str, out_ir: Option<&Path>| -> PyResult<Py<PyAny>> {
            let rep = dir.path().join(format!("report-{}.json", functions.iter().position(|x| x == f).unwrap_or(0)));
            let mut extra = vec![format!("-function={f}"), format!("-report={}", rep.display())];
            match out_ir {
                Some(p) => extra.extend(["-o".to_string(), p.display().to_string()]),
                None => extra.extend(["-o".to_string(), dir.path().join("discard.rvir").display().to_string()]),
            }
            opt(py, &base(&extra))?;
            Ok(json.call_method1("loads", (read(&rep)?,))?.unbind())
        };
        let report = if functions.len() == 1 {
            report_of(&functions[0], Some(&out))?
        } else {
            opt(py, &base(&["-o".to_string(), out.display().to_string()]))?;
            let d = PyDict::new(py);
            for f in &functions {
                d.set_item(f, report_of(f, None)?)?;
            }
            d.into_any().unbind()
        };
        let ir = read(&out)?;
        Ok(Module { source: Source::Ir { file: dir }, urdf: None, ir, report: Some(report), time_limit })
    }

    /// Compiles the URDF generator's function `name` (Pinocchio's names: `rnea`, `crba`,
    /// `nle`, `aba`, `rnea_derivatives`, `aba_derivatives`, `minv`) through `pipeline` and
    /// `codegen<c;abi=pinocchio;batch=…;trig=…>` with the system compiler (`cc`, or `$CC`), into
    /// the cache (docs/python.md); loaded once per process. The module must come from a URDF
    /// (its parameters are folded for the C).
    #[pyo3(signature = (name, *, pipeline="default<ops>", batch=1, trig="libm", cflags=None))]
    fn compile(
        &self,
        py: Python<'_>,
        name: &str,
        pipeline: &str,
        batch: usize,
        trig: &str,
        cflags: Option<Vec<String>>,
    ) -> PyResult<Compiled> {
        let Some((urdf, flags)) = &self.urdf else {
            return Err(UsageError::new_err(
                "compile: the module was not loaded from a URDF; abi=pinocchio writes the URDF generator's functions",
            ));
        };
        let sig = pinocchio::signature(name).ok_or_else(|| {
            UsageError::new_err(format!(
                "compile: no function `{name}`; expected one of {}",
                pinocchio::suffixes().join(", ")
            ))
        })?;
        // The widths `codegen<c;batch=…>` takes, from its parameter.
        let robovec_passes::ParamKind::U32Set { allowed, .. } = robovec_backends::c::BATCH.kind else {
            unreachable!("codegen<c>'s batch is a set of widths")
        };
        if !allowed.iter().any(|&w| w as usize == batch) {
            return Err(UsageError::new_err(format!(
                "compile: batch={batch}; expected one of {}",
                robovec_backends::c::BATCH.range_text()
            )));
        }
        let cflags = cflags.unwrap_or_else(default_cflags);
        let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
        let model = std::fs::read(urdf).map_err(|e| InputError::new_err(format!("cannot read {urdf}: {e}")))?;
        let mut h = std::collections::hash_map::DefaultHasher::new();
        let cpu = native_cpu(&cflags);
        (env!("CARGO_PKG_VERSION"), OBJECT_ABI, &model, flags, sig.suffix, pipeline, batch, trig, &cc, &cflags, cpu)
            .hash(&mut h);
        let key = format!("{}-{:016x}", sig.suffix, h.finish());
        let lib = shared_object(&key, || {
            build(py, urdf, flags, &sig, pipeline, batch, trig, &cc, &cflags, self.time_limit, &key)
        })?;
        Compiled::new(lib, sig, batch)
    }

    fn __repr__(&self) -> String {
        format!("<robovec.Module functions={:?}>", self.functions())
    }
}

/// What the cache's shared objects hold, in the key: 2 since `rvw_NAME` takes `layout=rows`
/// (1: lane-contiguous). An object of another value is never loaded.
const OBJECT_ABI: u32 = 2;

/// `compile`'s C flags when none are given: `-O2 -ffp-contract=off` (no contraction: the IR's
/// operations in its order, as `codegen<c>`'s header asks), and on x86-64 `-march=native`, the
/// vector width of this machine (UR5's `rnea` at `batch=4`: 39 ns a state with AVX2 against
/// 107 with x86-64's baseline SSE2, docs/python.md).
fn default_cflags() -> Vec<String> {
    let mut f = vec!["-O2".to_string(), "-ffp-contract=off".to_string()];
    if cfg!(target_arch = "x86_64") {
        f.push("-march=native".to_string());
    }
    f
}

/// For flags that tune the code to this machine (`-march=native`, `-mcpu=native`,
/// `-mtune=native`), its CPU as the kernel names it (the `model name` and `flags` lines of
/// `/proc/cpuinfo`), so that a cache folder shared between machines never loads an object built
/// for another CPU; empty otherwise, or where `/proc/cpuinfo` is not.
/// Read once per process: the CPU does not change under it, and `compile` of an object loaded
/// already takes about 0.1 ms, which reading `/proc/cpuinfo` each time would double.
fn native_cpu(cflags: &[String]) -> &'static str {
    static CPU: OnceLock<String> = OnceLock::new();
    if !cflags.iter().any(|f| f.ends_with("=native")) {
        return "";
    }
    CPU.get_or_init(|| {
        let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |name: &str| {
            info.lines().find(|l| l.split(':').next().is_some_and(|k| k.trim() == name)).unwrap_or_default().to_string()
        };
        field("model name") + "\n" + &field("flags")
    })
}

/// The cache folder: `$ROBOVEC_CACHE_DIR`, else `$XDG_CACHE_HOME/robovec`, else
/// `~/.cache/robovec`.
fn cache_dir() -> PyResult<PathBuf> {
    let dir = std::env::var_os("ROBOVEC_CACHE_DIR")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("XDG_CACHE_HOME").map(|x| PathBuf::from(x).join("robovec")))
        .or_else(|| std::env::var_os("HOME").map(|x| PathBuf::from(x).join(".cache/robovec")))
        .ok_or_else(|| Error::new_err("no cache folder: set ROBOVEC_CACHE_DIR"))?;
    std::fs::create_dir_all(&dir).map_err(|e| Error::new_err(format!("cannot make {}: {e}", dir.display())))?;
    Ok(dir)
}

/// A loaded shared object and its sizes (`NAME_NQ`, `NAME_NV`).
struct Loaded {
    lib: libloading::Library,
    path: PathBuf,
    nq: usize,
    nv: usize,
}

/// The process's loaded shared objects, by cache key: each is loaded once.
fn loaded() -> &'static Mutex<HashMap<String, Arc<Loaded>>> {
    static LOADED: OnceLock<Mutex<HashMap<String, Arc<Loaded>>>> = OnceLock::new();
    LOADED.get_or_init(Default::default)
}

/// The shared object of `key`: loaded already, or in the cache, or built by `make` (which
/// returns the path of the object it wrote into the cache).
fn shared_object(key: &str, make: impl FnOnce() -> PyResult<PathBuf>) -> PyResult<Arc<Loaded>> {
    if let Some(l) = loaded().lock().expect("not poisoned").get(key) {
        return Ok(l.clone());
    }
    let dir = cache_dir()?;
    let so = dir.join(format!("{key}.so"));
    let sizes = dir.join(format!("{key}.sizes"));
    if !(so.exists() && sizes.exists()) {
        make()?;
    }
    let text = read(&sizes)?;
    let mut it = text.split_whitespace().map(|x| x.parse::<usize>());
    let (Some(Ok(nq)), Some(Ok(nv))) = (it.next(), it.next()) else {
        return Err(Error::new_err(format!("{}: not `nq nv`", sizes.display())));
    };
    // SAFETY: the object is one this module compiled from robovec's generated C, which has no
    // initialisers that run on loading.
    let lib = unsafe { libloading::Library::new(&so) }
        .map_err(|e| Error::new_err(format!("cannot load {}: {e}", so.display())))?;
    let l = Arc::new(Loaded { lib, path: so, nq, nv });
    loaded().lock().expect("not poisoned").insert(key.to_string(), l.clone());
    Ok(l)
}

/// Writes the C of `sig` (one state, and `batch` states per call when `batch > 1`), compiles
/// them into one shared object in the cache under `key` and writes its sizes beside it.
#[allow(clippy::too_many_arguments, reason = "the compile options, passed through")]
fn build(
    py: Python<'_>,
    urdf: &str,
    flags: &[String],
    sig: &Signature,
    pipeline: &str,
    batch: usize,
    trig: &str,
    cc: &str,
    cflags: &[String],
    time_limit: Option<f64>,
    key: &str,
) -> PyResult<PathBuf> {
    let dir = scratch()?;
    let mut sources = Vec::new();
    let mut header = None;
    for (name, w) in [("rv1", 1), ("rvw", batch)] {
        if name == "rvw" && batch == 1 {
            continue;
        }
        let c = dir.path().join(format!("{name}.c"));
        let mut args = vec![urdf.to_string()];
        args.extend(flags.iter().filter(|f| *f != "--fold-params").cloned());
        args.push("--fold-params".to_string());
        args.push(format!("-function={}", sig.function));
        let sep = if pipeline.is_empty() { "" } else { "," };
        // The batched function reads and writes W rows of the (B, n) arrays in place.
        let layout = if w > 1 { ";layout=rows" } else { "" };
        args.push(format!("-passes={pipeline}{sep}codegen<c;abi=pinocchio;name={name};batch={w}{layout};trig={trig}>"));
        args.extend(limit_args(time_limit));
        args.extend(["-o".to_string(), c.display().to_string()]);
        opt(py, &args)?;
        if header.is_none() {
            header = Some(read(&dir.path().join(format!("{name}.h")))?);
        }
        sources.push(c);
    }
    let header = header.expect("the one-state file is written");
    let size = |what: &str| -> PyResult<usize> {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("#define rv1_{what} ")))
            .and_then(|x| x.trim().parse().ok())
            .ok_or_else(|| Error::new_err(format!("the generated header defines no rv1_{what}")))
    };
    let (nq, nv) = (size("NQ")?, size("NV")?);
    let cache = cache_dir()?;
    // Compiled beside the cache's entries, then renamed into place: a concurrent or interrupted
    // build never leaves a partial object under the key.
    let so_tmp = cache.join(format!("{key}.so.{}.tmp", std::process::id()));
    let out = std::process::Command::new(cc)
        .args(cflags)
        .args(["-shared", "-fPIC", "-o"])
        .arg(&so_tmp)
        .args(&sources)
        .arg("-lm")
        .output()
        .map_err(|e| Error::new_err(format!("cannot run the C compiler `{cc}`: {e}")))?;
    if !out.status.success() {
        let _ = std::fs::remove_file(&so_tmp);
        return Err(Error::new_err(format!(
            "`{cc}` failed on the generated C:\n{}",
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    let so = cache.join(format!("{key}.so"));
    let sizes = cache.join(format!("{key}.sizes"));
    let write = |path: &Path, text: String| -> PyResult<()> {
        let tmp = path.with_extension(format!("{}.tmp", std::process::id()));
        std::fs::write(&tmp, text)
            .and_then(|()| std::fs::rename(&tmp, path))
            .map_err(|e| Error::new_err(format!("cannot write {}: {e}", path.display())))
    };
    write(&sizes, format!("{nq} {nv}\n"))?;
    std::fs::rename(&so_tmp, &so).map_err(|e| Error::new_err(format!("cannot write {}: {e}", so.display())))?;
    Ok(so)
}

/// A compiled function: call it with numpy arrays (docs/python.md).
#[pyclass(module = "robovec", frozen)]
struct Compiled {
    lib: Arc<Loaded>,
    sig: Signature,
    batch: usize,
    one: usize,
    rows: Option<usize>,
}

impl Compiled {
    fn new(lib: Arc<Loaded>, sig: Signature, batch: usize) -> PyResult<Compiled> {
        let symbol = |name: &str| -> PyResult<usize> {
            let s = format!("{name}_{}\0", sig.suffix);
            // SAFETY: only the address is read; its type is fixed by `call`.
            let f: libloading::Symbol<'_, *const c_void> = unsafe { lib.lib.get(s.as_bytes()) }
                .map_err(|e| Error::new_err(format!("no symbol {}: {e}", s.trim_end_matches('\0'))))?;
            Ok(*f as usize)
        };
        let one = symbol("rv1")?;
        let rows = if batch > 1 { Some(symbol("rvw")?) } else { None };
        Ok(Compiled { lib, sig, batch, one, rows })
    }

    fn len(&self, d: Dim) -> usize {
        match d {
            Dim::Nq => self.lib.nq,
            Dim::Nv => self.lib.nv,
        }
    }
}

/// The most arrays of an `abi=pinocchio` function, inputs and outputs (`aba_derivatives`: 3 + 3).
const MAX_ARRAYS: usize = 6;

/// From this many states on, a call releases the GIL while the C runs, as numpy's loops do past
/// a size: below it, releasing and taking the GIL back costs more than the C (a fraction of a
/// µs against UR5's `rnea` at about 0.1 µs a state).
const DETACH_STATES: usize = 64;

/// A fresh array's data address, and the array.
fn fresh<'py, D: numpy::ndarray::Dimension>(a: Bound<'py, numpy::PyArray<f64, D>>) -> (usize, Bound<'py, PyAny>) {
    (a.data() as usize, a.into_any())
}

/// Runs `b` states on the arrays in place: full groups of `w` through the batched function
/// `rows` (`layout=rows`: `w` rows of each array), the rest one at a time through `one`.
///
/// # Safety
/// `one` (and `rows` when `w > 1`) are functions of `ptr.len()` `double *` parameters, the
/// inputs read, the outputs written; `ptr[i]` covers `b * len[i]` numbers, row-major
/// `(b, len[i])`, and the outputs overlap nothing.
unsafe fn run_states(one: usize, rows: Option<usize>, w: usize, b: usize, ptr: &[usize], len: &[usize]) {
    let mut args = [std::ptr::null_mut::<f64>(); MAX_ARRAYS];
    let args = &mut args[..ptr.len()];
    let mut s = 0;
    while s < b {
        let (f, step) = match rows {
            Some(f) if s + w <= b => (f, w),
            _ => (one, 1),
        };
        for (x, (&p, &n)) in args.iter_mut().zip(ptr.iter().zip(len)) {
            *x = (p as *mut f64).wrapping_add(s * n);
        }
        // SAFETY: the function of this signature on rows s .. s + step of every array.
        unsafe { call(f, args) };
        s += step;
    }
}

/// Calls the C function at `f` with `args` (its arrays in argument order).
///
/// # Safety
/// `f` is a function of `args.len()` `double *` parameters, and each pointer covers what it
/// reads or writes.
unsafe fn call(f: usize, args: &[*mut f64]) {
    type P = *mut f64;
    let f = f as *const c_void;
    unsafe {
        match args {
            [a, b] => std::mem::transmute::<*const c_void, extern "C" fn(P, P)>(f)(*a, *b),
            [a, b, c] => std::mem::transmute::<*const c_void, extern "C" fn(P, P, P)>(f)(*a, *b, *c),
            [a, b, c, d] => std::mem::transmute::<*const c_void, extern "C" fn(P, P, P, P)>(f)(*a, *b, *c, *d),
            [a, b, c, d, e] => {
                std::mem::transmute::<*const c_void, extern "C" fn(P, P, P, P, P)>(f)(*a, *b, *c, *d, *e)
            }
            [a, b, c, d, e, g] => {
                std::mem::transmute::<*const c_void, extern "C" fn(P, P, P, P, P, P)>(f)(*a, *b, *c, *d, *e, *g)
            }
            _ => unreachable!("abi=pinocchio's functions take 2 to 6 arrays"),
        }
    }
}

#[pymethods]
impl Compiled {
    /// `f(x1, x2, …)`: each input `(n,)` for one state or `(B, n)` for `B` states (float64,
    /// C-contiguous arrays are read in place; anything else is converted); returns the outputs
    /// (one array, or a tuple), `(rows,)`/`(rows, cols)` per state with a leading `B` axis for
    /// `(B, n)` inputs.
    #[pyo3(signature = (*args))]
    fn __call__<'py>(&self, py: Python<'py>, args: &Bound<'py, PyTuple>) -> PyResult<Py<PyAny>> {
        let sig = &self.sig;
        if args.len() != sig.inputs.len() {
            return Err(PyValueError::new_err(format!(
                "{}() takes {} arrays ({}); {} given",
                sig.suffix,
                sig.inputs.len(),
                sig.inputs.iter().map(|x| x.0).collect::<Vec<_>>().join(", "),
                args.len()
            )));
        }
        // The arrays' addresses and lengths per state, inputs then outputs. The inputs are
        // held (`held`) until the call returns; they are read through their pointers without
        // numpy's borrow tracking (a Python thread writing into an input meanwhile races, as
        // with numpy's own loops).
        let mut held: [Option<Bound<'py, PyArrayDyn<f64>>>; MAX_ARRAYS] = Default::default();
        let mut ptr = [0usize; MAX_ARRAYS];
        let mut len = [0usize; MAX_ARRAYS];
        let mut states: Option<Option<usize>> = None;
        for (i, (x, &(name, dim))) in args.iter().zip(&sig.inputs).enumerate() {
            // A float64 C-contiguous array is read in place; anything else converted.
            let a: Bound<'py, PyArrayDyn<f64>> = match x.cast::<PyArrayDyn<f64>>() {
                Ok(a) if a.is_c_contiguous() => a.clone(),
                _ => {
                    let kw = [("dtype", "float64")].into_py_dict(py)?;
                    py.import("numpy")?.call_method("ascontiguousarray", (x,), Some(&kw))?.extract()?
                }
            };
            let n = self.len(dim);
            let b = match a.shape() {
                [k] if *k == n => None,
                [b, k] if *k == n => Some(*b),
                shape => {
                    return Err(PyValueError::new_err(format!(
                        "{}: `{name}` has shape {shape:?}; expected ({n},) or (B, {n})",
                        sig.suffix
                    )))
                }
            };
            match states {
                None => states = Some(b),
                Some(s) if s != b => {
                    return Err(PyValueError::new_err(format!(
                        "{}: `{name}` has shape {:?}, the arrays before it {}",
                        sig.suffix,
                        a.shape(),
                        match s {
                            Some(b) => format!("(B = {b}, …)"),
                            None => "one state".to_string(),
                        }
                    )))
                }
                _ => {}
            }
            ptr[i] = a.data() as usize;
            len[i] = n;
            held[i] = Some(a);
        }
        let states = states.flatten();
        let b = states.unwrap_or(1);
        let inputs = sig.inputs.len();
        let mut outputs: [Option<Bound<'py, PyAny>>; MAX_ARRAYS] = Default::default();
        for (j, &(_, rows, cols)) in sig.outputs.iter().enumerate() {
            let (r, c) = (self.len(rows), cols.map(|c| self.len(c)));
            // SAFETY (each `new`): uninitialised, and every element is written below before
            // the array is returned: `abi=pinocchio` writes every entry of every output (both
            // triangles) for every state.
            let (p, a) = match (states, c) {
                (None, None) => fresh(unsafe { PyArray1::<f64>::new(py, [r], false) }),
                (None, Some(c)) => fresh(unsafe { PyArray2::<f64>::new(py, [r, c], false) }),
                (Some(b), None) => fresh(unsafe { PyArray2::<f64>::new(py, [b, r], false) }),
                (Some(b), Some(c)) => fresh(unsafe { PyArray3::<f64>::new(py, [b, r, c], false) }),
            };
            ptr[inputs + j] = p;
            len[inputs + j] = r * c.unwrap_or(1);
            outputs[j] = Some(a);
        }
        let arrays = inputs + sig.outputs.len();
        let (ptr, len) = (&ptr[..arrays], &len[..arrays]);
        // SAFETY: `ptr` are `b` states of `len` numbers each, inputs then outputs, in this
        // signature's order; the inputs are held, the outputs fresh.
        let run = || unsafe { run_states(self.one, self.rows, self.batch, b, ptr, len) };
        if b >= DETACH_STATES {
            py.detach(run);
        } else {
            run();
        }
        drop(held);
        let mut outputs = outputs.into_iter().take(sig.outputs.len()).map(|a| a.expect("made above"));
        if sig.outputs.len() == 1 {
            Ok(outputs.next().expect("one output").unbind())
        } else {
            Ok(PyTuple::new(py, outputs)?.into_any().unbind())
        }
    }

    /// `nq`, the configuration's size.
    #[getter]
    fn nq(&self) -> usize {
        self.lib.nq
    }

    /// `nv`, the velocity's size.
    #[getter]
    fn nv(&self) -> usize {
        self.lib.nv
    }

    /// The shared object in the cache: symbols `rv1_NAME` (one state) and, with `batch=W`,
    /// `rvw_NAME` (`W` states as `W` rows of each array, `layout=rows`), `abi=pinocchio`'s signatures.
    #[getter]
    fn library(&self) -> PathBuf {
        self.lib.path.clone()
    }

    /// `W`, the states of one call of the batched function (1: none).
    #[getter]
    fn batch(&self) -> usize {
        self.batch
    }

    fn __repr__(&self) -> String {
        format!("<robovec.Compiled {} nq={} nv={} batch={}>", self.sig.suffix, self.lib.nq, self.lib.nv, self.batch)
    }
}

/// The registered passes, as `--print-passes` lists them: a list of dicts `name`, `doc`,
/// `params` (each `name`, `default`, `range`, `doc`).
#[pyfunction]
fn passes(py: Python<'_>) -> PyResult<Py<PyList>> {
    let list = PyList::empty(py);
    for p in robovec_backends::REGISTRY.iter() {
        let d = PyDict::new(py);
        d.set_item("name", p.name)?;
        d.set_item("doc", p.doc)?;
        let params = PyList::empty(py);
        for q in p.params {
            let x = PyDict::new(py);
            x.set_item("name", q.name)?;
            x.set_item("default", q.default_text())?;
            x.set_item("range", q.range_text())?;
            x.set_item("doc", q.doc)?;
            params.append(x)?;
        }
        d.set_item("params", params)?;
        list.append(d)?;
    }
    Ok(list.unbind())
}

#[pymodule]
fn _robovec(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(passes, m)?)?;
    m.add_class::<Module>()?;
    m.add_class::<Compiled>()?;
    m.add("Error", py.get_type::<Error>())?;
    m.add("UsageError", py.get_type::<UsageError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("TimeLimitError", py.get_type::<TimeLimitError>())?;
    Ok(())
}
