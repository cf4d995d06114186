//! `depth-bound<max-terms=4096;lat-*>`: a lower bound on the critical path (ASAPCycle, SPEC §4)
//! of **every** program of `+ − ×` ops that computes the same outputs from the same inputs —
//! how far any rewrite (`balance`, `recurrence`, `eqsat`, a hand derivation) could still go.
//!
//! Phase: atomised → atomised; an analysis: the function is unchanged. Each output is expanded
//! into a polynomial in its x-variables (the inputs no trig variable or call reads) with
//! coefficients that are functions of the others ([`expand`]); its number of x-monomials, its
//! degree and whether a sum must be its last op bound how early it can be ready
//! ([`count::min_cycles`]: monomial counting with the target's add and mul latencies). The
//! function's bound is the largest of its outputs'; outputs that do not expand within
//! `max-terms` monomials (large models: the expansion of products of sums is exponential), or
//! that divide by an x-variable, are left out, so the bound is then one of the expanded
//! outputs only — still a lower bound, usually far below the critical path.
//!
//! **Fused multiply-adds** (`contract`'s `@fma`, `@fms`, `@fnma`) are expanded into the
//! product and sum they fuse ([`expand`]): the polynomials, so the `+ − ×` bound, are those of
//! the function before `contract`. But a program with fused ops is in a larger machine model
//! (`a·b + c` in one op of the `call` latency), whose critical path may lie below the `+ − ×`
//! bound; for a function that has them the bound is over programs of `+ − ×` **and** fused ops
//! ([`count::min_cycles_with`], the fma latency `lat-call`, as the timing charges them) — a
//! lower bound on the critical path of the contracted program — and the `+ − ×` bound is given
//! beside it ([`FunctionBound::plus_minus_times_cycles`]; issue 47: after `contract` the
//! bound read 0 cycles).
//!
//! Printed after the run, one line per function (`depth-bound @dirdyna: critical path 69
//! cycles, lower bound 38 cycles (c[2]: 16 monomials of degree 4 in 16 x-variables, a sum at
//! the root); 10 of 10 outputs expanded`), and in the report as `depth_bound`. The bound holds
//! for programs whose leaves are the inputs, constants and any functions of the θ-inputs ready
//! at cycle 0 (so also for programs with trig, calls and divisions by such functions), and
//! assumes a coefficient nonzero at one of three random θ points is nonzero ([`expand`]'s
//! cancellation test). Issue 31 uses it to show where its 0.25× goal cannot be met. Cost:
//! O(ops · max-terms · 16) at worst; WALK-MAN's 37 579 ops take about a second.

pub mod count;
pub mod expand;
#[cfg(test)]
mod tests;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{Function, Module};
use serde::Serialize;

use crate::params::ParamKind;
use crate::{each_function, Before, LatencyOverride, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "depth-bound",
    doc: "lower bound on the critical path of any +−× program computing the same outputs (monomial counting)",
    params: &[
        ParamInfo {
            name: "max-terms",
            kind: ParamKind::U32 { default: 4096, min: 1, max: 1 << 24 },
            doc: "largest number of x-monomials of an expanded value; larger values (and the outputs they reach) are \
                  left out of the bound",
        },
        crate::params::LAT_ADD,
        crate::params::LAT_MUL,
        crate::params::LAT_DIV,
        crate::params::LAT_CALL,
    ],
    build: |p: &Params| {
        Ok(Box::new(DepthBound { max_terms: p.u32("max-terms")? as usize, lat: p.latency_override()? }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        preserves_timing: true,
        bit_exact: true,
        ..crate::Props::DEFAULT
    },
};

/// The `depth-bound` pass.
#[derive(Debug)]
pub struct DepthBound {
    /// Largest number of x-monomials of an expanded value.
    pub max_terms: usize,
    /// Latencies given on the pass (the others are the pipeline's), cycles.
    pub lat: LatencyOverride,
}

impl Pass for DepthBound {
    fn name(&self) -> &'static str {
        "depth-bound"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let lat = cx.latencies_for("depth-bound", &self.lat);
        let mut functions = each_function(
            m,
            cx,
            "depth-bound",
            Before::Ticked,
            |_, _| None,
            |f, _, ticker| {
                let b = bound_function(f, &lat, self.max_terms, || ticker.check());
                match ticker.stopped() {
                    true => Step::Stopped { what: format!("while expanding @{}", f.name), kept: Some(b) },
                    false => Step::Done(b),
                }
            },
        );
        // After a stop, the functions left expand nothing: their bounds are 0, with 0 outputs
        // expanded. The note names the function the stop came in.
        let rest = &m.functions[functions.len()..];
        functions.extend(rest.iter().map(|f| bound_function(f, &lat, self.max_terms, || true)));
        cx.emit(DepthBoundRun { functions });
        Ok(())
    }
}

/// One output's bound.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct OutputBound {
    /// The output's name.
    pub output: String,
    /// Its x-monomials (nonzero coefficients).
    pub monomials: u64,
    /// Its degree in the x-variables.
    pub degree: u32,
    /// The x-variables it reads.
    pub variables: u32,
    /// A sum must be its last op (an x-variable appears only alone; [`count`]).
    pub sum_root: bool,
    /// The bound, cycles.
    pub lower_bound_cycles: u32,
}

/// One function's bound.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct FunctionBound {
    /// Function name.
    pub function: String,
    /// Its critical path (largest ASAPCycle), cycles.
    pub critical_path_cycles: u32,
    /// The largest bound of its expanded outputs, cycles (0 when none expanded).
    pub lower_bound_cycles: u32,
    /// Outputs.
    pub outputs: usize,
    /// Outputs expanded within `max-terms` (the bound is theirs).
    pub outputs_expanded: usize,
    /// The output whose bound is the function's (the first of the largest).
    pub binding: Option<OutputBound>,
    /// Add/sub and mul latencies the bound is for, cycles.
    pub lat_add: u32,
    /// See `lat_add`.
    pub lat_mul: u32,
    /// When the function has fused multiply-adds (`contract`): their latency (`lat-call`,
    /// cycles), and the bound is over programs of `+ − ×` and fused ops; absent otherwise
    /// (the bound is over `+ − ×` programs).
    #[serde(rename = "lat_fma", skip_serializing_if = "Option::is_none")]
    pub fma_latency: Option<u32>,
    /// When the function has fused multiply-adds: the largest bound of its expanded outputs
    /// over programs of `+ − ×` ops alone (the function's bound before `contract`), cycles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plus_minus_times_cycles: Option<u32>,
}

/// The latency of a fused multiply-add in `f`'s timing (`lat.call`) when `f` has one
/// ([`expand::fused`]); `None` when it has none.
pub fn fma_latency(f: &Function, lat: &Latencies) -> Option<u32> {
    f.body.iter().any(|&v| expand::fused(&f.value(v).def).is_some()).then_some(lat.call)
}

/// The bound of every output of `f` (atomised) that expands within `max_terms` monomials, in
/// output order; `stop` is asked before each value is expanded. Over programs of `+ − ×` ops,
/// and of fused multiply-adds too when `f` has some ([`fma_latency`]).
pub fn output_bounds(f: &Function, lat: &Latencies, max_terms: usize, stop: impl FnMut() -> bool) -> Vec<OutputBound> {
    output_bounds_in(f, lat, fma_latency(f, lat), max_terms, stop)
}

/// [`output_bounds`] in the machine model `fma` says: programs of `+ − ×` ops (`None`), or of
/// `+ − ×` and fused multiply-adds of latency `fma` (cycles), whatever ops `f` has.
pub fn output_bounds_in(
    f: &Function,
    lat: &Latencies,
    fma: Option<u32>,
    max_terms: usize,
    stop: impl FnMut() -> bool,
) -> Vec<OutputBound> {
    let ex = expand::expand(f, max_terms, stop);
    f.outputs.iter().filter_map(|o| Some(output_bound_in(&o.name, &*ex.of(o.value)?, lat, fma))).collect()
}

/// The function's bound: the largest of [`output_bounds`].
pub fn bound_function(f: &Function, lat: &Latencies, max_terms: usize, stop: impl FnMut() -> bool) -> FunctionBound {
    let fma = fma_latency(f, lat);
    let outputs = output_bounds_in(f, lat, fma, max_terms, stop);
    let binding = outputs.iter().fold(None::<&OutputBound>, |best, o| match best {
        Some(b) if b.lower_bound_cycles >= o.lower_bound_cycles => Some(b),
        _ => Some(o),
    });
    FunctionBound {
        function: f.name.clone(),
        critical_path_cycles: compute_timing(f, lat).1.asap_cycle,
        lower_bound_cycles: binding.map_or(0, |b| b.lower_bound_cycles),
        outputs: f.outputs.len(),
        outputs_expanded: outputs.len(),
        binding: binding.cloned(),
        lat_add: lat.add,
        lat_mul: lat.mul,
        fma_latency: fma,
        plus_minus_times_cycles: fma.map(|_| {
            let plain = |o: &OutputBound| count::min_cycles(o.monomials, o.degree, o.sum_root, lat.add, lat.mul);
            outputs.iter().map(plain).max().unwrap_or(0)
        }),
    }
}

/// The bound of one expanded output over programs of `+ − ×` ops.
pub fn output_bound(name: &str, p: &expand::Poly, lat: &Latencies) -> OutputBound {
    output_bound_in(name, p, lat, None)
}

/// [`output_bound`] over programs of `+ − ×` and fused multiply-adds of latency `fma`
/// (cycles) when it is given.
pub fn output_bound_in(name: &str, p: &expand::Poly, lat: &Latencies, fma: Option<u32>) -> OutputBound {
    let degree = p.iter().map(|(m, _)| m.len() as u32).max().unwrap_or(0);
    // Per x-variable: the monomials that hold it, and whether one of them is the variable alone
    // (one pass over the monomials; a monomial is sorted, so repeats are neighbours).
    let mut holding: std::collections::HashMap<u32, (u32, bool)> = std::collections::HashMap::new();
    for (m, _) in p {
        for (k, &y) in m.iter().enumerate() {
            if k == 0 || m[k - 1] != y {
                let e = holding.entry(y).or_default();
                e.0 += 1;
                e.1 |= m.len() == 1;
            }
        }
    }
    // An x-variable whose only monomial is itself.
    let sum_root = holding.values().any(|&(n, alone)| n == 1 && alone);
    let monomials = p.len() as u64;
    OutputBound {
        output: name.to_string(),
        monomials,
        degree,
        variables: holding.len() as u32,
        sum_root,
        lower_bound_cycles: count::min_cycles_with(monomials, degree, sum_root, lat.add, lat.mul, fma),
    }
}

/// What one `depth-bound` run found, one entry per function: printed after the run, and the
/// report's `depth_bound` (the reported function's entry).
#[derive(Clone, Debug)]
pub struct DepthBoundRun {
    /// Per function.
    pub functions: Vec<FunctionBound>,
}

impl std::fmt::Display for FunctionBound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "depth-bound @{}: critical path {} cycles, lower bound {} cycles",
            self.function, self.critical_path_cycles, self.lower_bound_cycles
        )?;
        if self.fma_latency.is_some() {
            write!(f, " over programs of + − × and fused multiply-add ops")?;
        }
        if let Some(b) = &self.binding {
            let root = if b.sum_root { ", a sum at the root" } else { "" };
            write!(
                f,
                " ({}: {} monomials of degree {} in {} x-variables{root})",
                b.output, b.monomials, b.degree, b.variables
            )?;
        }
        write!(
            f,
            "; {} of {} outputs expanded (latencies add {}, mul {}",
            self.outputs_expanded, self.outputs, self.lat_add, self.lat_mul
        )?;
        match (self.fma_latency, self.plus_minus_times_cycles) {
            (Some(fma), Some(plain)) => write!(f, ", fma {fma}); over + − × ops alone: {plain} cycles"),
            _ => write!(f, ")"),
        }
    }
}

impl crate::Artifact for DepthBoundRun {
    fn pass(&self) -> &'static str {
        "depth-bound"
    }

    fn log_text(&self, _detail: bool) -> String {
        self.functions.iter().map(|b| format!("{b}\n")).collect()
    }

    fn report(&self, function: &str) -> Option<crate::ReportEntry> {
        let b = self.functions.iter().find(|b| b.function == function)?;
        Some(crate::ReportEntry::new("depth_bound", b, crate::Merge::Last))
    }
}
