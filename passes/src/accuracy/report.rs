//! What `accuracy` reports: SPEC §7's `accuracy` object (`samples`, `f32`, `f64`, `outputs`,
//! each output with its largest absolute errors `max_abs_f32`/`max_abs_f64`) plus where the
//! inputs were drawn (`drawn_in`), how the reference was obtained and the worst points; a text summary for stderr; the
//! `worst-K.json` files.

use std::collections::BTreeMap;

use serde::ser::{Serialize, SerializeMap, Serializer};

use super::acc::ReferenceCounts;
use super::measure::{BitsSummary, Subject};
use super::stats::Stream;
use super::stream::Run;
use super::Options;

/// Errors of one output over the points.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OutputAccuracy {
    /// binary32, bits.
    pub f32: BitsSummary,
    /// binary64, bits.
    pub f64: BitsSummary,
}

/// Errors of one output over the points: bits of error and the largest absolute errors.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OutputErrors {
    /// binary32, bits.
    pub f32: BitsSummary,
    /// binary64, bits.
    pub f64: BitsSummary,
    /// The largest absolute error in binary32 over the points measured (the samples and the
    /// hill-climbing results), in the output's units: max over the points of an upper bound of
    /// |computed − exact| (the distance to the reference's certified enclosure of the exact
    /// value, rounded upward). `+∞` (JSON `null`) when a computed value was not finite or a
    /// reference unbounded at some point.
    pub max_abs_f32: f64,
    /// The same in binary64.
    pub max_abs_f64: f64,
}

/// Outputs in the function's output order, serialised as a JSON object.
#[derive(Clone, Debug, Default)]
pub struct OutputsMap(pub Vec<(String, OutputErrors)>);

impl Serialize for OutputsMap {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// Which reference the errors were measured against, and how its values were obtained.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ReferenceInfo {
    /// What the exact values are those of: `input of the pipeline` (the function of the same
    /// name as it entered the pipeline: the parsed equations or the input `.rvir`; outputs and
    /// inputs matched by name) or `the measured IR itself` (no original available).
    pub against: String,
    /// How many (output, point) values each path produced.
    #[serde(flatten)]
    pub counts: ReferenceCounts,
}

/// One of the worst points found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct WorstPoint {
    /// Largest binary32 error over the outputs, bits.
    pub max_f32_bits: f64,
    /// Mean binary32 error over the outputs, bits.
    pub mean_f32_bits: f64,
    /// Largest binary64 error over the outputs, bits.
    pub max_f64_bits: f64,
    /// The output with the largest binary32 error.
    pub output: String,
    /// Every input's value (canonical name → value; `-eval`'s input format).
    pub inputs: BTreeMap<String, f64>,
}

/// The measurement of one function (SPEC §7 `accuracy`, extra keys allowed).
#[derive(Clone, Debug, serde::Serialize)]
pub struct AccuracyReport {
    /// Function measured.
    pub function: String,
    /// `sampled` or `hard`.
    pub mode: &'static str,
    /// Points summarised, samples.
    pub samples: u64,
    /// Seed of the draws.
    pub seed: u64,
    /// Where the inputs were drawn: [`DRAWN_IN_DOMAIN`] (every drawn input in its range of
    /// the run's domain), [`DRAWN_IN_TABLE`] (the physical table of
    /// [`super::inputs`], no domain or none of the inputs in it) or [`DRAWN_IN_BOTH`] (some of
    /// each). Inputs fixed by `params` are not drawn.
    pub drawn_in: &'static str,
    /// Drawn inputs the domain covers, and drawn inputs (stderr only).
    #[serde(skip)]
    pub drawn_counts: (usize, usize),
    /// Points evaluated, including hill-climbing neighbours.
    pub evaluations: u64,
    /// Over every (output, point) pair, binary32, bits.
    pub f32: BitsSummary,
    /// Over every (output, point) pair, binary64, bits.
    pub f64: BitsSummary,
    /// Half-width of the 95% confidence interval of `f32.mean_bits`: 1.96·s/√n over the
    /// per-point means (every point has the same outputs), bits.
    pub f32_mean_ci95_bits: f64,
    /// Per output.
    pub outputs: OutputsMap,
    /// `f32` and `f64` over the outputs that are not [`AccuracyReport::structural_zeros`]
    /// (their ~30/62-bit errors against an exact 0 otherwise set every `max_bits`).
    pub excluding_structural_zeros: OutputAccuracy,
    /// The reference and its paths.
    pub reference: ReferenceInfo,
    /// User callbacks evaluated with the interpreter's stand-in (a linear form of the
    /// arguments; `robovec_ir::interp::callback_standin`), in the measured IR or the reference:
    /// their error figures are those of the stand-in, not of the real callback.
    pub callback_standins: Vec<String>,
    /// Inputs of the reference (the function as it entered the pipeline) that the measured IR
    /// no longer reads (e.g. folded by `specialize`) and that `params` does not fix: they are
    /// drawn like any input, so the reference may differ from what the pipeline assumed; give
    /// their values with `accuracy<params=FILE>`.
    pub drawn_reference_inputs: Vec<String>,
    /// Why fewer samples or hill-climbing rounds than asked were measured (the work budget
    /// `max-work` or the time limit), or `null` when the run is complete.
    pub stopped_early: Option<String>,
    /// Outputs whose reference stayed an uncertified interval around zero on the probe
    /// samples even at 256 bits: exact zeros reached through inexact steps (structural zeros
    /// such as `m·(cos²q + sin²q) − m`; in hard mode also outputs that vanish at the singular
    /// poses drawn). Their bits of error measure the computed value against zero: any nonzero
    /// result is many bits away (Herbie's metric has no absolute floor).
    pub structural_zeros: Vec<String>,
    /// The worst points, worst first.
    pub worst: Vec<WorstPoint>,
    /// `worst=DIR` of the pass, where the driver writes `worst-K.json`.
    #[serde(skip)]
    pub worst_dir: Option<String>,
}

/// [`AccuracyReport::drawn_in`]: every drawn input in its range of the run's domain.
pub const DRAWN_IN_DOMAIN: &str = "domain";
/// [`AccuracyReport::drawn_in`]: every drawn input from the physical table.
pub const DRAWN_IN_TABLE: &str = "physical table";
/// [`AccuracyReport::drawn_in`]: some drawn inputs in the domain, the others from the table.
pub const DRAWN_IN_BOTH: &str = "domain and physical table";

/// Where the inputs of `sub` not fixed by `o.known` are drawn (see [`AccuracyReport::drawn_in`]),
/// and how many of them the domain covers, of how many.
pub fn drawn_in(sub: &Subject, o: &Options) -> (&'static str, usize, usize) {
    let drawn: Vec<&String> = sub.names.iter().filter(|n| !o.known.contains_key(*n)).collect();
    let covered = drawn.iter().filter(|n| o.domain.as_ref().is_some_and(|d| d.get(n).is_some())).count();
    let word = match covered {
        0 => DRAWN_IN_TABLE,
        c if c == drawn.len() => DRAWN_IN_DOMAIN,
        _ => DRAWN_IN_BOTH,
    };
    (word, covered, drawn.len())
}

fn merged<'a>(xs: impl Iterator<Item = &'a Stream>) -> BitsSummary {
    let mut all = Stream::default();
    xs.for_each(|x| all.merge(x));
    all.summary()
}

/// Summarises a streamed run of `sub` (function `function`, reference described by `against`).
pub fn build(function: &str, sub: &Subject, o: &Options, run: Run, against: &str) -> AccuracyReport {
    let Run { acc, skip, evaluations, stopped_early } = run;
    let outputs = sub
        .tape
        .outputs
        .iter()
        .enumerate()
        .map(|(k, (name, _))| {
            let e = OutputErrors {
                f32: acc.f32[k].summary(),
                f64: acc.f64[k].summary(),
                max_abs_f32: acc.max_abs_f32[k],
                max_abs_f64: acc.max_abs_f64[k],
            };
            (name.clone(), e)
        })
        .collect();
    let kept = |v: &[Stream]| -> BitsSummary { merged(v.iter().zip(&skip).filter(|(_, &z)| !z).map(|(s, _)| s)) };
    let worst = acc
        .worst
        .iter()
        .map(|w| {
            let e = &w.errs;
            let n_out = e.f32.len();
            let k = (0..n_out).max_by(|&a, &b| e.f32[a].total_cmp(&e.f32[b]).then(b.cmp(&a))).unwrap_or(0);
            WorstPoint {
                max_f32_bits: e.max_f32(),
                mean_f32_bits: e.mean_f32(),
                max_f64_bits: e.f64.iter().copied().fold(0.0, f64::max),
                output: sub.tape.outputs.get(k).map(|o| o.0.clone()).unwrap_or_default(),
                inputs: sub.names.iter().cloned().zip(w.point.iter().copied()).collect(),
            }
        })
        .collect();
    let drawn = drawn_in(sub, o);
    let mut standins = sub.tape.standin_callees();
    standins.extend(sub.reference.standin_callees());
    standins.sort();
    standins.dedup();
    AccuracyReport {
        function: function.to_string(),
        mode: o.mode.name(),
        samples: acc.samples(),
        seed: o.seed,
        drawn_in: drawn.0,
        drawn_counts: (drawn.1, drawn.2),
        evaluations,
        f32: merged(acc.f32.iter()),
        f64: merged(acc.f64.iter()),
        f32_mean_ci95_bits: acc.point_means.ci95(),
        excluding_structural_zeros: OutputAccuracy { f32: kept(&acc.f32), f64: kept(&acc.f64) },
        outputs: OutputsMap(outputs),
        reference: ReferenceInfo { against: against.to_string(), counts: acc.reference },
        callback_standins: standins,
        drawn_reference_inputs: sub
            .reference
            .inputs
            .iter()
            .filter(|n| !sub.tape.inputs.contains(n) && !o.known.contains_key(*n))
            .cloned()
            .collect(),
        stopped_early,
        structural_zeros: sub.tape.outputs.iter().zip(&skip).filter(|(_, &z)| z).map(|(o, _)| o.0.clone()).collect(),
        worst,
        worst_dir: o.worst_dir.clone(),
    }
}

/// A readable summary: one line per function, then (with `per_output`) one per output.
pub fn to_text(reports: &[AccuracyReport], per_output: bool) -> String {
    let b = |s: &BitsSummary| format!("{:.2}/{:.2}/{:.2}", s.mean_bits, s.p95_bits, s.max_bits);
    let mut s = String::new();
    for r in reports {
        let rc = &r.reference.counts;
        s += &format!(
            "@{}: accuracy ({} inputs, {} samples, seed {}, {} evaluations): bits of error mean/p95/max \
             f32 {} f64 {}; reference ({}): {} double-double, {} at 256 bits, {} at 1024 bits, {} uncertified\n",
            r.function,
            r.mode,
            r.samples,
            r.seed,
            r.evaluations,
            b(&r.f32),
            b(&r.f64),
            r.reference.against,
            rc.double_double,
            rc.bits_256,
            rc.bits_1024,
            rc.uncertified
        );
        for c in &r.callback_standins {
            s += &format!(
                "warning: @{} calls user callback `{c}`; evaluated with the stand-in (a linear form of its \
                 arguments, robovec_ir::interp::callback_standin): its figures are not the real callback's\n",
                r.function
            );
        }
        if !r.drawn_reference_inputs.is_empty() {
            s += &format!(
                "warning: @{}: {} input(s) of the function as it entered the pipeline are not read by the measured IR \
                 and are drawn for the reference (give their values with accuracy<params=FILE>): {}\n",
                r.function,
                r.drawn_reference_inputs.len(),
                r.drawn_reference_inputs.join(", ")
            );
        }
        if let Some(why) = &r.stopped_early {
            s += &format!("@{}: accuracy stopped early: {why}\n", r.function);
        }
        if !r.structural_zeros.is_empty() {
            let x = &r.excluding_structural_zeros;
            s += &format!(
                "@{}: {} structural zero output(s) (exact value 0 through inexact steps): {}; without them \
                 f32 {} f64 {}\n",
                r.function,
                r.structural_zeros.len(),
                r.structural_zeros.join(", "),
                b(&x.f32),
                b(&x.f64)
            );
        }
        if let Some(w) = r.worst.first() {
            s += &format!(
                "@{}: worst point: {:.2} bits (f32) on {}, {:.2} bits (f64)\n",
                r.function, w.max_f32_bits, w.output, w.max_f64_bits
            );
        }
        // The physical table's runs print as they always did; a domain's add where the inputs
        // were drawn and the absolute errors.
        let in_domain = r.drawn_in != DRAWN_IN_TABLE;
        if in_domain {
            let (covered, drawn) = r.drawn_counts;
            s += &format!(
                "@{}: inputs drawn in: {} ({covered} of {drawn} drawn inputs in the domain); max abs = the largest \
                 |computed - exact|, an upper bound\n",
                r.function, r.drawn_in
            );
        }
        if per_output && in_domain {
            s += &format!(
                "  {:<16} {:>20} {:>20} {:>12} {:>12}\n",
                "output", "f32 mean/p95/max", "f64 mean/p95/max", "max abs f32", "max abs f64"
            );
            for (name, o) in &r.outputs.0 {
                s += &format!(
                    "  {:<16} {:>20} {:>20} {:>12.3e} {:>12.3e}\n",
                    name,
                    b(&o.f32),
                    b(&o.f64),
                    o.max_abs_f32,
                    o.max_abs_f64
                );
            }
        } else if per_output {
            s += &format!("  {:<16} {:>20} {:>20}\n", "output", "f32 mean/p95/max", "f64 mean/p95/max");
            for (name, o) in &r.outputs.0 {
                s += &format!("  {:<16} {:>20} {:>20}\n", name, b(&o.f32), b(&o.f64));
            }
        }
    }
    s
}

/// The `worst-K.json` files of `r` (K from 1, worst first): file name and contents (a JSON
/// object of input name → value that `-eval` reads). With `prefix`, names are
/// `<function>-worst-K.json` (modules of several functions).
pub fn worst_files(r: &AccuracyReport, prefix: bool) -> Vec<(String, String)> {
    r.worst
        .iter()
        .enumerate()
        .map(|(k, w)| {
            let name =
                if prefix { format!("{}-worst-{}.json", r.function, k + 1) } else { format!("worst-{}.json", k + 1) };
            (name, serde_json::to_string_pretty(&w.inputs).expect("numbers serialise") + "\n")
        })
        .collect()
}

/// What one `accuracy` run measured, one report per function: its summary lines on stderr
/// (per-output lines under `-stats`), the report's `accuracy` (the last measurement of the
/// reported function) and the `worst-K.json` files of `accuracy<worst=DIR>`.
#[derive(Clone, Debug)]
pub struct AccuracyRun {
    /// One report per function, in module order.
    pub reports: Vec<AccuracyReport>,
}

impl crate::Artifact for AccuracyRun {
    fn pass(&self) -> &'static str {
        "accuracy"
    }

    fn log_text(&self, detail: bool) -> String {
        to_text(&self.reports, detail)
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let r = self.reports.iter().rev().find(|r| r.function == function)?;
        Some(crate::ReportEntry::new("accuracy", r, crate::Merge::Last))
    }

    fn files(&self, several_functions: bool) -> Vec<crate::ArtifactFile> {
        let mut out = Vec::new();
        for r in &self.reports {
            let Some(dir) = &r.worst_dir else { continue };
            for (name, json) in worst_files(r, several_functions) {
                out.push(crate::ArtifactFile {
                    path: std::path::Path::new(dir).join(name),
                    bytes: json.into_bytes(),
                    executable: false,
                });
            }
        }
        out
    }
}
