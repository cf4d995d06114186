//! The placement's figures (SPEC §7 `placement`, seed §3.4–3.6): cycles against the lower
//! bounds, parallelisation rate, memories, writes and occupation.

use robovec_ir::Function;
use serde::Serialize;

use super::{cycles, issues_per_cycle, lower_bound, occupation, tight_lower_bound};

/// `placement` of SPEC §7: figures of the placement on the PE architecture (SPEC §4).
#[derive(Clone, Debug, Serialize)]
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
}

/// Per-cycle occupation rates (0 to 1), one entry per cycle.
#[derive(Clone, Debug, Serialize)]
pub struct Occupation {
    /// ADD PEs.
    pub add: Vec<f64>,
    /// MULTI PEs.
    pub mul: Vec<f64>,
}

/// The placement figures of `f`, if it is placed.
pub fn placement_report(f: &Function) -> Option<PlacementReport> {
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
        lower_bound: lb,
        cycles_over_lower_bound: if lb == 0 { 1.0 } else { c as f64 / lb as f64 },
        tight_lower_bound: tight_lower_bound(f, a),
        parallelisation_rate: if c == 0 { 0.0 } else { ops / (c as f64 * (a.n_add + a.n_mul) as f64) },
        pe_memory_words: p.pe_words.clone(),
        buffer_words: p.buffer_words.clone(),
        writes_direct: p.writes.len() as u64 - indirect,
        writes_indirect: indirect,
        occupation: Occupation { add: occupation(&add, a.n_add, 50), mul: occupation(&mul, a.n_mul, 50) },
    })
}
