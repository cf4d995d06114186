//! The placement's figures (SPEC §7 `placement`, seed §3.4–3.6): cycles against the lower
//! bounds, parallelisation rate, memories, writes and occupation.

use robovec_ir::Function;
use robovec_machine::target::{Resources, Target};
use serde::{Deserialize, Serialize};

use super::{cycles, issues_per_cycle, lower_bound, occupation, tight_lower_bound};

/// `placement` of SPEC §7: figures of the placement on the PE architecture (SPEC §4); read
/// back from the report for `-report-dir`'s figures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PlacementReport {
    /// ADD PEs.
    pub n_add: u32,
    /// MULTI PEs.
    pub n_mul: u32,
    /// add/sub latency, cycles.
    pub lat_add: u32,
    /// mul latency, cycles.
    pub lat_mul: u32,
    /// Cycles of the placement (largest arrival).
    pub cycles: u32,
    /// `cycles` in µs at the target's clock (`cycles / clock_mhz`); extra key.
    pub us: f64,
    /// The target's clock, MHz; extra key.
    pub clock_mhz: f64,
    /// States one evaluation computes (`Function::states`: K after `interleave<states=K>`,
    /// issue 49 item 3); extra key (1 when read from a report without it).
    #[serde(default = "one_state")]
    pub states: u32,
    /// Time per state, ns: `cycles / clock_mhz · 1000 / states`, the throughput figure beside
    /// the latency `us` (the two agree for one state); extra key.
    #[serde(default)]
    pub ns_per_state: f64,
    /// Lower bound LB (SPEC §4), cycles.
    pub lower_bound: u32,
    /// cycles / LB (1 is optimal).
    pub cycles_over_lower_bound: f64,
    /// A tighter lower bound (`place::tight_lower_bound`: per PE type, the exact one-type
    /// relaxation with heads and tails tightened through both types), cycles; extra key.
    pub tight_lower_bound: u32,
    /// ops / (cycles × (n_add + n_mul)) (seed §3.4).
    pub parallelisation_rate: f64,
    /// Words of each PE memory: ADD PEs, then MULTI PEs.
    pub pe_memory_words: Vec<u32>,
    /// Words of each buffer memory, same order.
    pub buffer_words: Vec<u32>,
    /// Results written directly into a PE memory at arrival.
    pub writes_direct: u64,
    /// Results written into a PE memory from a buffer.
    pub writes_indirect: u64,
    /// Occupation rate per cycle of each PE type: issued ops / N, rolling mean over 50 cycles
    /// (seed §3.6).
    pub occupation: Occupation,
    /// The first [`TIMELINE_CYCLES`] cycles of the placement, issue by issue: which PE issues
    /// which op when (the placement timeline figure of `-report-dir`); extra key.
    pub timeline: Timeline,
    /// The analytic resource estimate of this configuration on the target
    /// (`robovec_machine::target::Target::estimate`: unit costs of seed Table 1.4, memories in M10K
    /// blocks), with `fits` also requiring the placement's memories to fit the target's
    /// ([`fits_memories`]); extra key. The FPGA back end gives Yosys' figures instead.
    pub estimate: Resources,
}

/// The default of [`PlacementReport::states`].
fn one_state() -> u32 {
    1
}

/// Time per state of one evaluation of `cycles` at `clock_mhz` computing `states` states, ns:
/// `cycles / clock_mhz · 1000 / states` (issue 49 item 3; `states` 0 is taken as 1).
pub fn ns_per_state(cycles: u32, clock_mhz: f64, states: u32) -> f64 {
    f64::from(cycles) / clock_mhz * 1000.0 / f64::from(states.max(1))
}

/// True when the placement's memories fit the target's: every PE memory within `pe_words`,
/// every buffer within `buffer_words`, and `cycles + 1` instruction words within
/// `instr_words`.
pub fn fits_memories(p: &robovec_ir::placement::Placement, cycles: u32, target: &Target) -> bool {
    p.pe_words.iter().all(|&w| w <= target.pe_words)
        && p.buffer_words.iter().all(|&w| w <= target.buffer_words)
        && u64::from(cycles) < u64::from(target.instr_words)
}

/// `target` with the units of the PEs `f` runs on: the fixed-point PEs' for a function whose
/// values are all fixed point ([`robovec_machine::program::fixed::pe_kind`], issue 49).
pub fn units_of(f: &Function, target: &Target) -> Target {
    match robovec_machine::program::fixed::pe_kind(f) {
        Ok(robovec_machine::program::fixed::PeKind::Fixed) => target.with_fixed_units(),
        _ => target.clone(),
    }
}

/// The word bits of the design `f` runs on: the fixed-point PEs' word
/// ([`robovec_machine::program::fixed::word_bits`]) or binary32's 32.
pub fn word_bits_of(f: &Function) -> u32 {
    match robovec_machine::program::fixed::pe_kind(f) {
        Ok(robovec_machine::program::fixed::PeKind::Fixed) => robovec_machine::program::fixed::word_bits(f),
        _ => 32,
    }
}

/// The estimate of [`PlacementReport::estimate`]: the crossbar design of the placement
/// ([`Target::estimate_with`], each PE's buffer as placed) in `word_bits`-bit words.
pub fn estimate(p: &robovec_ir::placement::Placement, cycles: u32, target: &Target, word_bits: u32) -> Resources {
    let r = target.estimate_with(p.arch.n_add, p.arch.n_mul, cycles, word_bits, &p.buffer_words);
    Resources { fits: r.fits && fits_memories(p, cycles, target), ..r }
}

/// Cycles of the placement that [`PlacementReport::timeline`] covers, from cycle 0: a window
/// an FPGA engineer can read issue by issue (issue 13: "a few hundred cycles").
pub const TIMELINE_CYCLES: u32 = 256;

/// The issues of a window of cycles (see [`PlacementReport::timeline`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timeline {
    /// First cycle of the window.
    pub start: u32,
    /// One past the last cycle of the window (at most the placement's cycles).
    pub end: u32,
    /// Every op issued in the window, by cycle then PE.
    pub issues: Vec<TimelineIssue>,
}

/// One issue of [`Timeline`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TimelineIssue {
    /// `add` or `mul`: the PE type.
    pub pe_type: String,
    /// Index of the PE within its type (0-based).
    pub pe: u32,
    /// Issue cycle.
    pub cycle: u32,
    /// Cycles from issue to the result in the PE memory (the op's latency).
    pub latency: u32,
    /// The op (`add`, `sub`, `mul`, `div`, `call`).
    pub op: String,
    /// The value it defines (its IR name).
    pub value: String,
}

/// The [`Timeline`] of cycles `0..min(cycles, TIMELINE_CYCLES)` of `p`.
pub fn timeline(f: &Function, p: &robovec_ir::placement::Placement, cycles: u32) -> Timeline {
    use robovec_ir::placement::Pe;
    let end = cycles.min(TIMELINE_CYCLES);
    let mut issues: Vec<TimelineIssue> = f
        .body
        .iter()
        .filter_map(|&v| {
            let i = p.issue[v.index()]?;
            let k = f.op_kind(v)?;
            (i.cycle < end).then(|| {
                let (pe_type, pe) = match i.pe {
                    Pe::Add(x) => ("add", x),
                    Pe::Mul(x) => ("mul", x),
                };
                TimelineIssue {
                    pe_type: pe_type.to_string(),
                    pe,
                    cycle: i.cycle,
                    latency: p.latency(k),
                    op: format!("{k:?}").to_lowercase(),
                    value: f.name_of(v).to_string(),
                }
            })
        })
        .collect();
    issues.sort_by(|x, y| (x.cycle, &x.pe_type, x.pe).cmp(&(y.cycle, &y.pe_type, y.pe)));
    Timeline { start: 0, end, issues }
}

/// Per-cycle occupation rates (0 to 1), one entry per cycle.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Occupation {
    /// ADD PEs.
    pub add: Vec<f64>,
    /// MULTI PEs.
    pub mul: Vec<f64>,
}

/// The placement figures of `f`, if it is placed, on `target` (its clock for `us`, its
/// capacities for `estimate`; latencies are the placement's own).
pub fn placement_report(f: &Function, target: &Target) -> Option<PlacementReport> {
    let p = f.placement.as_ref()?;
    let a = &p.arch;
    let c = cycles(f, p);
    let lb = lower_bound(f, a);
    let (add, mul) = issues_per_cycle(f, p);
    let indirect = p.writes.iter().filter(|w| w.buffer_addr.is_some()).count() as u64;
    let ops = f.op_counts().total as f64;
    Some(PlacementReport {
        n_add: a.n_add,
        n_mul: a.n_mul,
        lat_add: a.lat.add,
        lat_mul: a.lat.mul,
        cycles: c,
        us: target.us(c),
        clock_mhz: target.clock_mhz,
        states: f.states,
        ns_per_state: ns_per_state(c, target.clock_mhz, f.states),
        lower_bound: lb,
        cycles_over_lower_bound: if lb == 0 { 1.0 } else { c as f64 / lb as f64 },
        tight_lower_bound: tight_lower_bound(f, a),
        parallelisation_rate: if c == 0 { 0.0 } else { ops / (c as f64 * (a.n_add + a.n_mul) as f64) },
        pe_memory_words: p.pe_words.clone(),
        buffer_words: p.buffer_words.clone(),
        writes_direct: p.writes.len() as u64 - indirect,
        writes_indirect: indirect,
        occupation: Occupation { add: occupation(&add, a.n_add, 50), mul: occupation(&mul, a.n_mul, 50) },
        timeline: timeline(f, p, c),
        estimate: estimate(p, c, &units_of(f, target), word_bits_of(f)),
    })
}
