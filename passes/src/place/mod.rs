//! `place<pe=N;priority=classical;select=preferential;…>`: list scheduling onto N ADD + N MULTI
//! pipelined PEs with per-PE memories, buffers and a crossbar (seed ch. 1, §2.3; SPEC §4–§5).
//!
//! Phase: atomised → atomised with a [`Placement`] attached (printed in the IR, re-read by the
//! parser, executed by `sim`). The machine model is documented in `robovec_ir::placement`.
//!
//! Algorithm ([`schedule`]): cycle by cycle, ready ops (every operand op arrived) sorted by
//! priority — **classical**: ALAPCycle, then ASAPCycle; **mobility**: ALAPCycle − ASAPCycle,
//! then ALAPCycle (seed §2.3.1, with latency-weighted attributes) — are assigned to a free PE of
//! their type (with `clusters=G`, of the PE cluster [`cluster`] binds the op to) where both
//! operands can be in its memory: **naive** selection takes the first such
//! PE, **preferential** the one with the best operand-location pair of seed Table 2.1 (PE/PE = 1
//! … Indirect/Indirect = 9). Then `improve` rounds of forward-backward improvement re-run the
//! list scheduler with the start times of a backward (right-justified) schedule as priorities,
//! keeping the best result (Tormos & Lova 2001; Valls et al. 2005): it recovers the idle cycles
//! that ALAP order leaves when both PE types are saturated. With `select=routes`, [`rebind`]
//! then moves ops between PEs of their type (and within their slack), never lengthening the
//! schedule, to fewer interconnect routes (`rebind=R` rounds, 64 by default). Then [`memory`]
//! assigns addresses and sizes.
//!
//! Contract: never changes the function; every placement it returns passes `sim`. Cost:
//! O(n log n + n·N) for n ops and N PEs per type.

pub mod bound;
pub mod cluster;
pub mod dag;
pub mod feed;
pub mod memory;
pub mod ready;
pub mod rebind;
pub mod report;
pub mod schedule;
pub mod search;

use robovec_ir::placement::{PeArray, Placement};
use robovec_ir::{Function, Module, OpKind};

pub use bound::{lower_bound, ops_per_side, tight_lower_bound};

use crate::params::ParamKind;
use crate::{try_each_function, AtTimeLimit, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step};

/// Priority of ready ops (seed §2.3.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Priority {
    /// ALAPCycle, then ASAPCycle.
    Classical,
    /// Mobility (ALAPCycle − ASAPCycle), then ALAPCycle.
    Mobility,
}

/// How a PE is chosen among the free ones (seed §2.3, Table 2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Select {
    /// First free PE of the right type that can receive the operands.
    Naive,
    /// Best operand-location preference (Table 2.1), then lowest index.
    Preferential,
    /// Best operand-location preference (Table 2.1), then the fewest new interconnect routes
    /// (sources — a PE's result or buffer read — not yet written into the chosen PE's memory):
    /// for `codegen<fpga;interconnect=specialised>`, whose multiplexers have an input per route
    /// (issue 49), then lowest index.
    Routes,
}

/// Options of one placement.
#[derive(Clone, Copy, Debug)]
pub struct PlaceOptions {
    /// The PE array to place on.
    pub arch: PeArray,
    /// Ready-list priority.
    pub priority: Priority,
    /// PE selection.
    pub select: Select,
    /// Rounds of forward-backward improvement after the seed's list schedule (0 = the seed's
    /// algorithm alone); the best schedule is kept.
    pub improve: u32,
    /// Restarts with other priorities (the other seed priority, then the seed keys with
    /// feeding bonuses of 8–1000 cycles — see [`feed::Feed`] — then ALAP keys with
    /// deterministic random jitter of 8–32 cycles, cycling through the bonuses), each improved
    /// as above, tried only while the best schedule is more than 2% above
    /// [`tight_lower_bound`] or 5% above [`lower_bound`] (when the tight bound allows it); at
    /// most about 10⁶ op schedulings in all. 0 = none. See [`search`].
    pub restarts: u32,
    /// PE clusters ([`cluster`]): each side's PEs split into this many clusters, the ops
    /// partitioned into as many parts with few values crossing (METIS), each op issued only on
    /// its part's cluster — for `codegen<fpga;interconnect=specialised>`, whose multiplexers
    /// then have inputs mostly from their own cluster. 1 = none (any op on any PE of its type).
    /// At most the smaller side's PE count.
    pub clusters: u32,
    /// With clusters: a ready op whose latest start is at most this many cycles away may issue
    /// on an idle PE of another cluster when that adds at most one interconnect route (work
    /// stealing for the ops the partition left waiting on a busy cluster; `None`: never).
    pub steal: Option<u32>,
    /// With clusters: the partition balances each cluster's share of the ops of each of this
    /// many time windows (per side, the ops split by latest start into windows of equal op
    /// count; [`cluster::partition`]). 1: one balance per side over the whole function.
    pub windows: u32,
    /// Rounds of interconnect-aware rebinding of the schedule kept ([`rebind`]; only with
    /// [`Select::Routes`]): ops move to other PEs of their type, in their cycle or within their
    /// slack, while the routes do not grow; the schedule's length stays. 0 = none.
    pub rebind: u32,
    /// Iterations of key-mutation search after the restarts, under the same condition (see
    /// [`search`]); at most about 1.2·10⁷ op schedulings in all. 0 = none.
    pub search: u32,
    /// `-time-limit`: rounds of improvement, restarts and search stop once it is reached
    /// (inside a schedule too: that schedule is dropped), keeping the best schedule so far
    /// (`None`: no limit; the work caps above still apply).
    pub deadline: Option<crate::Deadline>,
    /// `-time-limit` for the first list schedule, which the placement needs (the limit's grace
    /// in the `place` pass, [`crate::Deadline::grace`]): past it the placement fails with
    /// [`PlaceError::Stopped`] (`None`: never).
    pub grace: Option<crate::Deadline>,
    /// Tests: every ticker of the placement stops at this tick
    /// ([`crate::PassContext::tick_budget`]).
    pub tick_budget: Option<u64>,
}

/// Why a placement has no result.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlaceError {
    /// Only with `buffer = false`: an operand can no longer reach any PE memory of its type.
    Stuck(String),
    /// [`PlaceOptions::grace`] (or the test budget) was reached in the first list schedule or
    /// while building the memories of the schedule kept.
    Stopped,
    /// The partitioner ([`cluster::partition`], METIS) failed.
    Partition(String),
}

impl std::fmt::Display for PlaceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlaceError::Stuck(m) => f.write_str(m),
            PlaceError::Stopped => f.write_str("stopped in the first list schedule or its memories: time limit"),
            PlaceError::Partition(m) => write!(f, "partitioning the ops into PE clusters: {m}"),
        }
    }
}

impl From<String> for PlaceError {
    fn from(m: String) -> PlaceError {
        PlaceError::Stuck(m)
    }
}

impl PlaceOptions {
    /// N ADD + N MULTI PEs, default latencies, 2 write ports, buffers on, classical,
    /// preferential.
    pub fn with_pes(n: u32) -> PlaceOptions {
        let mut o = options_from(&Params::defaults(&INFO)).expect("declared defaults are valid");
        o.arch.n_add = n;
        o.arch.n_mul = n;
        o
    }
}

/// The options of checked parameters `p` (defaults and ranges from [`INFO`]).
fn options_from(p: &Params) -> Result<PlaceOptions, PassError> {
    Ok(PlaceOptions {
        arch: PeArray {
            n_add: p.u32("add")?,
            n_mul: p.u32("mul")?,
            lat: p.latencies()?,
            writes: p.u32("writes")?,
            buffer: p.flag("buffer")?,
        },
        priority: if p.choice("priority")? == "mobility" { Priority::Mobility } else { Priority::Classical },
        select: match p.choice("select")? {
            "naive" => Select::Naive,
            "routes" => Select::Routes,
            _ => Select::Preferential,
        },
        improve: p.u32("improve")?,
        restarts: p.u32("restarts")?,
        search: p.u32("search")?,
        rebind: p.u32("rebind")?,
        clusters: p.u32("clusters")?,
        steal: p.u32_given("steal")?,
        windows: p.u32("windows")?,
        deadline: None,
        grace: None,
        tick_budget: None,
    })
}

/// Places `f` (atomised, verified).
///
/// # Errors
/// Only with `buffer = false`: an operand that can no longer reach any PE memory of its type
/// (and, with [`PlaceOptions::grace`] set, [`PlaceError::Stopped`]'s text).
pub fn try_place_function(f: &Function, opts: &PlaceOptions) -> Result<Placement, String> {
    try_place_function_within(f, opts).map(|(p, _)| p).map_err(|e| e.to_string())
}

/// [`try_place_function`] that also says whether rounds, restarts or search stopped at
/// `opts.deadline` (`true`: the placement is the best found by then).
///
/// # Errors
/// [`PlaceError::Stuck`] as [`try_place_function`]; [`PlaceError::Stopped`] when
/// `opts.grace` stopped the first list schedule or the memories.
pub fn try_place_function_within(f: &Function, opts: &PlaceOptions) -> Result<(Placement, bool), PlaceError> {
    try_place_function_progress(f, opts, &crate::progress::Progress::hidden())
}

/// [`try_place_function_within`] reporting the restarts and search iterations, when they run,
/// as one task of `progress` (`place @f: search`).
///
/// # Errors
/// As [`try_place_function`].
pub fn try_place_function_progress(
    f: &Function,
    opts: &PlaceOptions,
    progress: &crate::progress::Progress,
) -> Result<(Placement, bool), PlaceError> {
    let a = &opts.arch;
    let required = crate::Ticker::new(opts.grace, opts.tick_budget);
    let seed = schedule::seed_keys(f, a, opts.priority);
    // Nodes in the seed's priority order: the schedules take ops mostly in that order, and
    // their per-op arrays are indexed by node (see `dag`).
    let mut dag = dag::OpDag::ordered(f, &seed);
    if opts.clusters > 1 {
        // the latest start of each node (the first or second component of the seed's key)
        let alap: Vec<u32> = dag
            .gather(&seed)
            .iter()
            .map(|k| match opts.priority {
                Priority::Classical => k.0,
                Priority::Mobility => k.1,
            })
            .collect();
        let shape = cluster::Shape { n_add: a.n_add, n_mul: a.n_mul, clusters: opts.clusters, windows: opts.windows };
        let part = cluster::partition(&dag, &alap, shape).map_err(PlaceError::Partition)?;
        dag.set_clusters(opts.clusters, part);
        dag.set_steal(opts.steal);
    }
    let seed = dag.gather(&seed);
    if required.check() {
        return Err(PlaceError::Stopped);
    }
    let (best, cut) = improved(&dag, opts, &seed, 0, &required)?;
    if required.check() {
        return Err(PlaceError::Stopped);
    }
    // The schedule kept, rebound to fewer routes (optional: up to the deadline), then its
    // memories: required, within the grace.
    let build = |mut best: schedule::Schedule| {
        if opts.select == Select::Routes && opts.rebind > 0 {
            let optional = crate::Ticker::new(opts.deadline, opts.tick_budget);
            rebind::rebind(&dag, a, &mut best, opts.rebind, &|| optional.tick());
        }
        memory::build(f, &dag, a, &best, &|| required.tick()).ok_or(PlaceError::Stopped)
    };
    if cut {
        return Ok((build(best)?, true));
    }
    let spec = lower_bound(f, a) as u64;
    // Within 2% of SPEC §4's bound (hence of the tight bound too): nothing to search for, and
    // the tight bound (O(n log n) but not free) is not computed.
    if (opts.restarts > 0 || opts.search > 0) && end(&best) as u64 * 100 > spec * 102 {
        let (best, stopped) = search::restarts_and_search(f, &dag, opts, seed, best, progress)?;
        return Ok((build(best)?, stopped));
    }
    Ok((build(best)?, false))
}

/// Cycles of a schedule: the largest arrival.
pub(crate) fn end(s: &schedule::Schedule) -> u32 {
    s.arrival.iter().copied().max().unwrap_or(0)
}

/// The list schedule for `keys` (indexed by node) with feeding bonus `feed` (cycles, see
/// [`feed::Feed`]; it ticks `first`, [`PlaceError::Stopped`] when that stops it), then up to
/// `opts.improve` rounds of forward-backward improvement (kept while they shorten it); a round
/// the `opts.deadline` reaches is dropped and none starts after (`true`: rounds were cut).
pub(crate) fn improved(
    dag: &dag::OpDag,
    opts: &PlaceOptions,
    keys: &[dag::Key],
    feed: u32,
    first: &crate::Ticker,
) -> Result<(schedule::Schedule, bool), PlaceError> {
    let a = &opts.arch;
    let mut best =
        schedule::schedule_until(dag, a, keys, opts.select, feed, &|| first.tick())?.ok_or(PlaceError::Stopped)?;
    let rounds = crate::Ticker::new(opts.deadline, opts.tick_budget);
    for _ in 0..opts.improve {
        if rounds.check() {
            return Ok((best, true));
        }
        // Backward pass: ops that arrived last go first in reverse time; then forward again in
        // order of the backward (justified) start times; ties by value index.
        let t = end(&best);
        let tie = |j: usize| dag.ops[j].index() as u32;
        let back: Vec<dag::Key> = (0..dag.len()).map(|j| (t - best.arrival[j], keys[j].0, tie(j))).collect();
        let r = schedule::backward_starts(dag, a.n_add, a.n_mul, &a.lat, &back, feed);
        let r_max = r.iter().copied().max().unwrap_or(0);
        let fwd: Vec<dag::Key> = (0..dag.len()).map(|j| (r_max - r[j], keys[j].0, tie(j))).collect();
        let Some(s) = schedule::schedule_until(dag, a, &fwd, opts.select, feed, &|| rounds.tick())? else {
            return Ok((best, true));
        };
        if end(&s) >= end(&best) {
            break;
        }
        best = s;
    }
    Ok((best, false))
}

/// Places `f` (atomised, verified) on an architecture with buffers.
///
/// # Panics
/// If `opts.arch.buffer` is false and the placement gets stuck (use [`try_place_function`]).
pub fn place_function(f: &Function, opts: &PlaceOptions) -> Placement {
    try_place_function(f, opts).expect("with buffers a placement always exists")
}

/// Cycles of a placement (SPEC §4): the largest arrival, 0 without ops.
pub fn cycles(f: &Function, p: &Placement) -> u32 {
    f.body.iter().filter_map(|&v| Some(p.issue[v.index()]?.cycle + p.latency(f.op_kind(v)?))).max().unwrap_or(0)
}

/// Ops issued per cycle on each side: `(add_side, mul_side)`, one entry per cycle `0..cycles`.
pub fn issues_per_cycle(f: &Function, p: &Placement) -> (Vec<u32>, Vec<u32>) {
    let n = cycles(f, p) as usize;
    let (mut a, mut m) = (vec![0; n], vec![0; n]);
    for &v in &f.body {
        if let (Some(i), Some(k)) = (p.issue[v.index()], f.op_kind(v)) {
            let side = if k == OpKind::Mul { &mut m } else { &mut a };
            side[i.cycle as usize] += 1;
        }
    }
    (a, m)
}

/// Occupation rate of one PE type (SPEC §4, seed §3.6): issued ops / N per cycle, rolling mean
/// over a window of `window` cycles ending at each cycle.
pub fn occupation(issued: &[u32], n: u32, window: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(issued.len());
    let mut sum = 0u64;
    for i in 0..issued.len() {
        sum += issued[i] as u64;
        if i >= window {
            sum -= issued[i - window] as u64;
        }
        let w = (i + 1).min(window) as f64;
        out.push(sum as f64 / (w * n as f64));
    }
    out
}

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "place",
    doc: "list-schedule ops onto N ADD + N MULTI PEs with PE memories, buffers and a crossbar",
    params: &[
        ParamInfo {
            name: "pe",
            kind: ParamKind::U32 { default: 4, min: 1, max: 4096 },
            doc: "N: N ADD PEs and N MULTI PEs",
        },
        ParamInfo {
            name: "add",
            kind: ParamKind::U32Or { fallback: "pe", min: 1, max: 4096 },
            doc: "ADD PEs (overrides pe)",
        },
        ParamInfo {
            name: "mul",
            kind: ParamKind::U32Or { fallback: "pe", min: 1, max: 4096 },
            doc: "MULTI PEs (overrides pe)",
        },
        ParamInfo {
            name: "priority",
            kind: ParamKind::Choice { choices: &["classical", "mobility"], default: "classical" },
            doc: "classical (ALAP, ASAP) | mobility (mobility, ALAP)",
        },
        ParamInfo {
            name: "select",
            kind: ParamKind::Choice { choices: &["naive", "preferential", "routes"], default: "preferential" },
            doc: "naive (first free PE) | preferential (Table 2.1) | routes (Table 2.1, then the fewest new \
                  interconnect routes: smaller multiplexers for codegen<fpga;interconnect=specialised>)",
        },
        ParamInfo {
            name: "improve",
            kind: ParamKind::U32 { default: 2, min: 0, max: 16 },
            doc: "rounds of forward-backward improvement after the seed's list schedule (0 = seed only)",
        },
        ParamInfo {
            name: "restarts",
            kind: ParamKind::U32 { default: 64, min: 0, max: 10_000 },
            doc: "restarts with other priorities while >2% above the tight bound or >5% above SPEC's (0 = none)",
        },
        ParamInfo {
            name: "search",
            kind: ParamKind::U32 { default: 5000, min: 0, max: 1_000_000 },
            doc: "key-mutation search iterations after the restarts, same condition (0 = none)",
        },
        ParamInfo {
            name: "clusters",
            kind: ParamKind::U32 { default: 1, min: 1, max: 4096 },
            doc: "G: the PEs in G clusters, the ops partitioned (METIS) so that few values cross between \
                  clusters, each op issued on its cluster's PEs: fewer multiplexer inputs for \
                  codegen<fpga;interconnect=specialised> (1 = none; at most min(add, mul))",
        },
        ParamInfo {
            name: "steal",
            kind: ParamKind::U32Opt { min: 0, max: 4096 },
            doc: "S, with clusters: a ready op within S cycles of its latest start may issue on an idle PE of \
                  another cluster when that adds at most one interconnect route (none when not given)",
        },
        ParamInfo {
            name: "windows",
            kind: ParamKind::U32 { default: 1, min: 1, max: 16 },
            doc: "W, with clusters: the partition gives each cluster its share of each of W time windows' ops \
                  (latest-start quantiles): fewer cycles lost to a busy cluster, more interconnect routes",
        },
        ParamInfo {
            name: "rebind",
            kind: ParamKind::U32 { default: 64, min: 0, max: 4096 },
            doc: "with select=routes: rounds of rebinding ops to other PEs of their type (in their cycle, or in \
                  their slack) while the interconnect routes do not grow; the cycles stay (0 = none)",
        },
        crate::params::LAT_ADD,
        crate::params::LAT_MUL,
        crate::params::LAT_DIV,
        crate::params::LAT_CALL,
        ParamInfo {
            name: "writes",
            kind: ParamKind::U32Target { builtin: 2, min: 1, max: 64 },
            doc: "write ports per PE memory per cycle; when not given, the target's (-target)",
        },
        ParamInfo {
            name: "buffer",
            kind: ParamKind::Flag { default: true },
            doc: "on | off: results may wait in buffer memories",
        },
    ],
    build: |p: &Params| {
        Ok(Box::new(Place { opts: options_from(p)?, lat: p.latency_override()?, writes: p.u32_given("writes")? }))
    },
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        preserves_timing: true,
        bit_exact: true,
        formats: true,
        ..crate::Props::DEFAULT
    },
};

/// The `place` pass.
#[derive(Debug)]
pub struct Place {
    /// Options (`opts.arch.lat` and `opts.arch.writes` are replaced at run time: the
    /// pipeline's latencies with `lat` applied, [`PassContext::latencies_for`], and `writes`
    /// or the target's write ports).
    pub opts: PlaceOptions,
    /// Latencies given on the pass.
    pub lat: crate::LatencyOverride,
    /// `writes` when given on the pass (`None`: the target's).
    pub writes: Option<u32>,
}

impl Pass for Place {
    fn name(&self) -> &'static str {
        "place"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        // (checked here, not when the pipeline is built: each of `clusters`, `add` and `mul`
        // alone takes its whole range)
        let (g, n_add, n_mul) = (self.opts.clusters, self.opts.arch.n_add, self.opts.arch.n_mul);
        cluster::check(g, n_add, n_mul).map_err(|message| PassError::BadParameter { pass: "place".into(), message })?;
        let lat = cx.latencies_for("place", &self.lat);
        let arch = PeArray { lat, writes: self.writes.unwrap_or(cx.target.writes), ..self.opts.arch };
        // `-time-limit`: the first list schedule, which the placement needs, runs to the
        // limit's grace (`cx.ticker()`: place is required); the improvement, restarts and
        // search stop at the limit itself (a note for the function, the next one placed).
        let grace = cx.deadline.map(|d| d.grace());
        let opts = PlaceOptions { deadline: cx.deadline, grace, tick_budget: cx.tick_budget, arch, ..self.opts };
        let progress = cx.progress.clone();
        let limit = crate::Ticker::new(cx.deadline, cx.tick_budget);
        let target = cx.target.clone();
        try_each_function(
            m,
            cx,
            "place",
            AtTimeLimit::Required,
            Before::Ticked,
            |_, _| None,
            |f, _, _| {
                let lat = crate::function_latencies(&target, f, opts.arch.lat, &self.lat);
                let opts = PlaceOptions { arch: PeArray { lat, ..opts.arch }, ..opts };
                let (p, stopped) = match try_place_function_progress(f, &opts, &progress) {
                    Ok(placed) => placed,
                    Err(PlaceError::Stopped) => {
                        let what = format!("in @{} in its first list schedule or its memories", f.name);
                        return Ok(Step::Stopped { what, kept: None });
                    }
                    Err(e @ (PlaceError::Stuck(_) | PlaceError::Partition(_))) => {
                        return Err(PassError::Failed { pass: "place".into(), message: format!("@{}: {e}", f.name) })
                    }
                };
                let name = f.name.clone();
                f.placement = Some(p);
                Ok(match stopped {
                    true => Step::Cut {
                        note: format!("searching @{name} early (best schedule so far kept): {}", limit.reason()),
                        result: (),
                    },
                    false => Step::Done(()),
                })
            },
        )
        .map(drop)
    }
}
