//! `precision<budget=REL;target=c|mcu|fpga>`: a numeric format per value (issue 48 item 5) that
//! lowers the target's cost while the certified error bound of every output stays within the
//! budget over the input domain.
//!
//! Phase: atomised → atomised; it writes formats ([`robovec_ir::format`]) and nothing else (the
//! ops, their order and timing are kept; the exact real function too). The budget of output `o`
//! is `budget · max|o|`, `max|o|` the magnitude of its enclosure over the domain (relative to
//! each output's range, as the issue states); the bound is `error-bound<format=mixed>`'s
//! ([`crate::error_bound::bound()`]), so after the pass `error-bound` proves every output within
//! its budget and `codegen<c>` writes the formats bit for bit as `-eval` computes them.
//!
//! **How it chooses** ([`choose()`]): every value binary64 first (an output whose binary64 bound
//! already exceeds its budget keeps that bound as its budget and is named in `unreachable`:
//! the values it depends on stay binary64; one with no finite bound is named in `unbounded`
//! and not constrained); then the
//! first-order weight of each value's rounding in the outputs' bounds
//! ([`crate::error_bound::bound::sensitivities`], seeded with 1/budget per output) times the
//! rounding a cheaper format adds ranks the candidates, cheapest damage first; a binary search
//! finds the longest prefix of that ranking whose formats the certified bound accepts (each
//! step one O(ops) sweep, about log₂(values) of them). Targets:
//! - `c`: binary32 where the bound allows (twice the lanes of a vector of binary64);
//! - `mcu`: 32-bit fixed point first (`fix<32,f>`, or `fix<word,f>` with `word=`, the fewest integer bits that hold the
//!   value's range and binary64 error widened by 2⁻¹⁰; a value the bound finds may overflow
//!   gets one more: integer arithmetic on a microcontroller without a floating-point unit),
//!   then binary32 among the rest;
//! - `fpga`: fixed point in words as narrow as the budget allows (`fix<w,f>`, `w ≤ 53`, each
//!   value its own), then binary32 among the rest: fraction bits from the sensitivities and a
//!   cost per bit, one global shift and batches of bits removed, each step checked by the
//!   bound, and each width the smallest that holds the value's certified range ([`fpga`]).
//!
//! Cost (reported before and after): `c` counts ops as 1 per binary64 op and ½ per binary32 op
//! (lanes per vector) plus ½ per conversion (an operand read in another format than its
//! user's); `mcu` estimates cycles of a Cortex-M3-class core without an FPU: a fixed-point
//! integer op (`robovec_ir::format::integer_op`, what `codegen<c>` writes as `int32_t`/`int64_t`
//! code) 1 per add, 3 per product (`SMULL`), 1 more to shift; binary32 operation 50 and binary64
//! 100 (software floating point, order of magnitude), conversions 150 (`robovec_fix_from` is
//! five software floating-point routines) — a fixed-point value
//! whose op is not an integer op costs a binary64 op, its operands' conversions and its store; `fpga` the share of the device,
//! `100·(DSP/dsp + ALM/alm)`, of a datapath of one operator per op in its value's format, from
//! the target description (`-target`: its DSP modes, ALM per adder bit, binary32 PE and
//! binary64 unit costs, [`robovec_machine::target::Datapath`]; the table in [`fpga`]).
//!
//! [`ladder`]: the same search at budgets 10⁻² … 10⁻¹⁰, for `-report-dir`'s figure of cost
//! against the budget.

pub mod budget;
pub mod choose;
pub mod fpga;
pub mod ladder;

use robovec_ir::Module;
use serde::Serialize;

use crate::error_bound::TrigImpl;
use crate::params::ParamKind;
use crate::range::{domain_with_file, enclose_in_pass};
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};
pub use choose::{choose, choose_on, Choice, FpgaFigures, Target};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "precision",
    doc: "choose a numeric format per value (binary32, fixed point) that lowers the target's cost while the \
          certified error bound of every output stays within the budget over the input domain",
    params: &[
        ParamInfo {
            name: "budget",
            kind: ParamKind::F64OrPath { default: 1e-6, min: 1e-16, max: 1.0 },
            doc: "error budget of each output, relative to the largest magnitude of its range over the domain; or a \
                  JSON file of output name or glob -> {\"abs\": x} | {\"rel\": x} ({\"Qq[*]\": {\"abs\": 1e-4}})",
        },
        ParamInfo {
            name: "target",
            kind: ParamKind::Choice { choices: Target::WORDS, default: "c" },
            doc: "c: binary32 where the bound allows (vector lanes); mcu: 32-bit fixed point first, then binary32 \
                  (a microcontroller without FPU); fpga: fixed-point words as narrow as the budget allows, then \
                  binary32, costed in DSP blocks and ALM of the -target description",
        },
        ParamInfo {
            name: "word",
            kind: ParamKind::U32 {
                default: choose::MCU_WORD,
                min: *choose::MCU_WORDS.start(),
                max: *choose::MCU_WORDS.end(),
            },
            doc:
                "target=mcu's fixed-point word, bits (fix<word,f>; given without target, it selects target=mcu); 32 is \
                  a microcontroller's register, narrower words are for fixed-point PEs whose products fit one DSP \
                  multiplier (27 on the Cyclone V, 18 on the ECP5; docs/fpga.md)",
        },
        crate::range::RANGES,
        crate::error_bound::TRIG,
    ],
    build: |p: &Params| {
        let (mut target, trig): (Target, TrigImpl) = (p.word("target")?, p.word("trig")?);
        let word = p.u32("word")?;
        // `word` is target=mcu's: given alone it selects that target
        if p.get("word").is_some() && p.get("target").is_none() {
            target = Target::Mcu;
        }
        if word != choose::MCU_WORD && target != Target::Mcu {
            return Err(PassError::BadParameter {
                pass: "precision".into(),
                message: format!(
                    "word={word} is target=mcu's fixed-point word; target={} chooses its own formats",
                    target.as_str()
                ),
            });
        }
        if trig == TrigImpl::Inline && target != Target::C {
            return Err(PassError::BadParameter {
                pass: "precision".into(),
                message: format!(
                    "trig=inline is the C back end's own sin/cos (codegen<c;trig=inline>): it goes with target=c, \
                     not target={}",
                    target.as_str()
                ),
            });
        }
        Ok(Box::new(PrecisionPass { budget: p.f64_or_path("budget")?, target, ranges: p.path("ranges")?, trig, word }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: AtTimeLimit::Skip,
        preserves_timing: true,
        exact_in_reals: true,
        formats: true,
        needs_domain: true,
        ..crate::Props::DEFAULT
    },
};

/// The `precision` pass.
#[derive(Debug)]
pub struct PrecisionPass {
    /// Relative error budget of every output, or a budget file (`budget=FILE`, [`budget`]).
    pub budget: crate::params::NumberOrPath,
    /// What the formats are for.
    pub target: Target,
    /// A ranges file applied over the run's domain.
    pub ranges: Option<String>,
    /// The `sin`/`cos` the code will call (`trig=inline` with `target=c` only).
    pub trig: TrigImpl,
    /// `target=mcu`'s fixed-point word, bits (`word=`, [`choose::MCU_WORDS`]).
    pub word: u32,
}

impl Pass for PrecisionPass {
    fn name(&self) -> &'static str {
        "precision"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let dom = domain_with_file(cx.domain.as_ref(), self.ranges.as_deref(), m)?;
        let target = self.target;
        let device = &cx.target.clone();
        // One relative budget for every output, or the budget file's per output.
        let budgets_given = match &self.budget {
            crate::params::NumberOrPath::Number(r) => budget::Budgets::Every(budget::Budget::Rel(*r)),
            crate::params::NumberOrPath::Path(path) => {
                let failed = |message: String| PassError::Failed { pass: "precision".into(), message };
                let text = std::fs::read_to_string(path)
                    .map_err(|e| failed(format!("cannot read budget file `{path}`: {e}")))?;
                budget::Budgets::File(budget::parse(&text).map_err(|e| failed(format!("budget file `{path}`: {e}")))?)
            }
        };
        let functions = try_each_function(
            m,
            cx,
            "precision",
            AtTimeLimit::Skip,
            Before::Ticked,
            |f, k| Some(format!("before @{} ({k} functions given formats)", f.name)),
            |f, _, ticker| {
                let failed = |message: String| PassError::Failed { pass: "precision".into(), message };
                let x = match enclose_in_pass("precision", f, &dom, Some(crate::range::affine::DEFAULT_TERMS), ticker)?
                {
                    Ok(x) => x,
                    Err(stop) => return Ok(stop),
                };
                let budgets: Vec<budget::Budget> = match &budgets_given {
                    budget::Budgets::Every(b) => vec![*b; f.outputs.len()],
                    budget::Budgets::File(file) => {
                        let names: Vec<&str> = f.outputs.iter().map(|o| o.name.as_str()).collect();
                        file.resolve(&names).map_err(|e| failed(format!("@{}: budget file: {e}", f.name)))?
                    }
                };
                let c = choose_on(f, &x, &budgets, target, device, self.trig, self.word, || ticker.tick())
                    .map_err(failed)?;
                if c.stopped {
                    let note = format!(
                        "searching @{} early (the formats accepted so far kept, every budget met): {}",
                        f.name,
                        ticker.reason()
                    );
                    return Ok(Step::Cut { note, result: c });
                }
                Ok(Step::Done(c))
            },
        )?;
        let mut reports = Vec::new();
        for (k, c) in functions.into_iter().enumerate() {
            let f = &mut m.functions[k];
            for &(v, format) in &c.formats {
                f.set_format(v, format);
            }
            reports.push(c.report(&f.name));
        }
        cx.emit(PrecisionRun { functions: reports, target, domain: dom });
        Ok(())
    }
}

/// What `precision` chose for one function: printed after the run and the report's
/// `precision`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PrecisionReport {
    /// Function name.
    #[serde(skip)]
    pub function: String,
    /// `c`, `mcu` or `fpga`.
    pub target: &'static str,
    /// The relative budget of every output (`None` with a budget file).
    pub budget: Option<f64>,
    /// Values per format (`f64`, `f32`, `fix<w,f>`), inputs included.
    pub formats: std::collections::BTreeMap<String, usize>,
    /// The largest bound over the outputs, relative to each output's largest magnitude.
    pub max_rel_to_range: f64,
    /// The output that reaches it.
    pub worst_output: Option<String>,
    /// The target's cost with every value binary64 (module doc's model; `fpga`: percent of the
    /// device).
    pub cost_before: f64,
    /// Its cost with the chosen formats.
    pub cost_after: f64,
    /// Certified bound sweeps the search ran.
    pub sweeps: usize,
    /// Outputs whose binary64 bound already exceeds the budget (kept as binary64 computes them).
    pub unreachable: Vec<String>,
    /// Outputs with no finite bound (not constrained).
    pub unbounded: Vec<String>,
    /// `fpga`: fixed-point values per word width.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub widths: Option<std::collections::BTreeMap<u32, usize>>,
    /// `fpga`: DSP blocks of the datapath with the chosen formats ([`fpga::resources`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dsp: Option<f64>,
    /// `fpga`: its ALM.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alm: Option<f64>,
    /// `fpga`: the target description costed against (`-target`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
    /// `-report-dir`'s budget ladder, target `c`: the median ns per state of the C with these
    /// formats on the machine that ran it, at the faster of `batch=8` and `batch=16` (`None`
    /// elsewhere: not measured).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ns_per_state: Option<f64>,
    /// The `batch` of `ns_per_state`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ns_batch: Option<u32>,
    /// Per output with a budget: the certified bound reached, its budget, and the bound it would
    /// reach with one more bit in every binary32 and fixed-point value (the issue's "what bound
    /// each output would need one more bit for").
    pub outputs: std::collections::BTreeMap<String, OutputBound>,
}

/// One output's line of [`PrecisionReport::outputs`]: absolute, in the output's units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputBound {
    /// Its certified bound with the chosen formats (`null`: none finite).
    pub bound: Option<f64>,
    /// Its budget (absolute: a relative budget times the largest magnitude of its range; an
    /// unreachable output's binary64 bound).
    pub budget: f64,
    /// Its certified bound if every binary32 value had 25 significant bits and every `fix<w,f>`
    /// were `fix<w+1,f+1>`: what one more bit buys (`null`: none finite).
    pub one_more_bit: Option<f64>,
}

impl std::fmt::Display for PrecisionReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Fixed-point formats grouped by width on this line (the report has each), narrowest
        // first after the binary formats.
        let mut grouped: std::collections::BTreeMap<(u32, String), usize> = std::collections::BTreeMap::new();
        for (k, n) in &self.formats {
            let key = match k.split_once(',') {
                Some((w, _)) if k.starts_with("fix<") => {
                    (w.trim_start_matches("fix<").parse::<u32>().unwrap_or(u32::MAX), format!("{w},*>"))
                }
                _ => (0, k.clone()),
            };
            *grouped.entry(key).or_insert(0) += n;
        }
        let hist: Vec<String> = grouped.iter().map(|((_, k), n)| format!("{n} {k}")).collect();
        write!(
            f,
            "precision @{} ({}, budget {}): {}; bound {:.3e} of the range at most ({}); ",
            self.function,
            self.target,
            self.budget.map_or("per output".to_string(), |b| format!("{b:e}")),
            hist.join(", "),
            self.max_rel_to_range,
            self.worst_output.as_deref().unwrap_or("no output"),
        )?;
        match (self.dsp, self.alm, &self.device) {
            (Some(dsp), Some(alm), Some(device)) => write!(
                f,
                "cost {:.1} -> {:.1} % of {device} ({dsp:.1} DSP, {alm:.0} ALM)",
                self.cost_before, self.cost_after
            )?,
            _ => write!(f, "cost {:.0} -> {:.0}", self.cost_before, self.cost_after)?,
        }
        for (what, list) in [
            ("cannot meet the budget even in binary64 (kept so)", &self.unreachable),
            ("have no finite bound", &self.unbounded),
        ] {
            if let Some(first) = list.first() {
                let more = if list.len() > 1 { format!(" and {} more", list.len() - 1) } else { String::new() };
                write!(f, "; {first}{more} {what}")?;
            }
        }
        Ok(())
    }
}

/// One `precision` run, per function.
#[derive(Clone, Debug)]
pub struct PrecisionRun {
    /// Per function.
    pub functions: Vec<PrecisionReport>,
    /// The run's target.
    pub target: Target,
    /// The domain the run enclosed the functions over (the run's, with the pass's
    /// `ranges=FILE` applied): what [`ladder::study`] reads to run the chooser again.
    pub domain: robovec_ir::domain::Domain,
}

impl crate::Artifact for PrecisionRun {
    fn pass(&self) -> &'static str {
        "precision"
    }

    fn log_text(&self, _detail: bool) -> String {
        self.functions.iter().map(|r| format!("{r}\n")).collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let r = self.functions.iter().find(|r| r.function == function)?;
        Some(crate::ReportEntry::new("precision", r, crate::Merge::Last))
    }
}
