//! `recurrence<rounds=64;max-terms=4;slack=0;max-slack=48;pe=0;fill=0.9;max-growth=1.5;lat-*>`: restructures the chains of
//! linear maps that tree-height reduction of single sums cannot see across (issue 31 item 1):
//! each body's velocity, acceleration and force in a Robotran file is its parent's (or
//! children's) rotated and added to, `x_k = A_k·x_{k−1} + b_k`, a chain as long as the tree is
//! deep, and the three sweeps (velocities, then the accelerations that read their squares, then
//! the backward force sweep) run one after the other.
//!
//! Phase: atomised → atomised. **Back-substitution into linear forms** (Kogge and Stone's
//! recursive doubling read on a DAG; Kuck's tree-height reduction with distribution; Brent,
//! Kuck and Maruyama, IEEE TC C-22, 1973): every critical value (slack ≤ `slack` cycles after
//! `balance`) is written as a `Form` (`forms.rs`) `Σ ± c_i·p_i` over *pivots* `p_i`, values that are
//! late, with coefficients `c_i` that are early: a sum adds its operands' forms (terms of the
//! same pivot collected, their coefficients added), a product scales the later operand's form
//! by the earlier operand, a coefficient that is not earlier than its pivot is multiplied out
//! (the product becomes a pivot), and a form of more than `max-terms` terms merges its two
//! earliest terms. Each value is then made from whichever is ready first: its own op on its
//! operands, or its form (one product per term, then the two-earliest-first sum). So a force
//! at the root waits for the latest acceleration only through one product and a few adds, and
//! the coefficients — products of the rotations along the path — are computed while the
//! accelerations are.
//!
//! Rounds: a round restructures the values with at most `slack` cycles of slack, balances, and
//! is kept when the critical path got shorter (with `pe=N`: when max(critical path, the
//! resource bound of N ADD + N MULTI PEs ÷ `fill`) got lower) within `max-growth` × the ops of the function as the pipeline first had it
//! atomised (`budget-of=atomised`: before `cse` and `zero-removal` removed any, so that
//! `default<depth>` keeps the goal of 1.5× `atomise`'s ops; the pass's input's when
//! larger, or with `budget-of=input`).
//! A round that gains nothing, or goes over the ops budget, is retried on the values ready in
//! the last half of the critical path, then the last quarter, … (4 times): the values at the
//! cut become the pivots and the coefficients after it start at 0 beside the part before it
//! (one level of recursive doubling: a chain restructured from its start has coefficients as
//! late as its values). Then a round that gains nothing widens the slack (to the smaller
//! latency, then doubling, up to `max-slack`); rounds stop at the budget after the last
//! halving, at `max-slack`, or after `rounds`. With `pe=N` the balanced input, the states of
//! the last six kept rounds and up to eight earlier ones are placed (list scheduling, `place`'s defaults without
//! improvement) and the fastest placed is returned: the bound is a model of the placement. The output is balanced (`balance` ran last); a
//! function no round shortened is left as it was.
//!
//! Measured on the public corpus's `dirdyna` and `invdyna` files after
//! `cse,zero-removal,balance,cse` (`scripts/depth_corpus.sh`, docs/rewrites.md): critical path
//! 0.22–0.51× `atomise`'s (coman `dirdyna` 744 → 461 cycles, WALK-MAN 831 → 499, Segway 350 →
//! 241) for 0.83–1.50× `atomise`'s ops.
//!
//! Exact in real arithmetic (distributivity, associativity, commutativity); in floating point
//! it changes rounding as reassociation and distribution do, and the magnitude bound of
//! `balance` applies to the result (`accuracy` and `-check` measure it). Cost per round:
//! O(values · max-terms²) plus two `balance` rewrites.

mod forms;
mod round;
#[cfg(test)]
mod tests;

use robovec_ir::analysis::{compute_timing, Latencies};
use robovec_ir::{Function, Module};

use crate::params::ParamKind;
use crate::tree_height::{rewrite_within, Shape};
use crate::{each_function, Before, ParamInfo, Params, Pass, PassContext, PassError, PassInfo, Step, Ticker};
use round::round;

/// Registry entry.
pub const INFO: PassInfo = PassInfo {
    name: "recurrence",
    doc: "restructure chains of linear maps (velocity, acceleration, force recurrences) by back-substitution \
          into linear forms over late values, within an ops budget",
    params: &[
        ParamInfo {
            name: "rounds",
            kind: ParamKind::U32 { default: 64, min: 0, max: 1000 },
            doc: "rounds of (balance, restructure the critical values, balance)",
        },
        ParamInfo {
            name: "max-terms",
            kind: ParamKind::U32 { default: 4, min: 1, max: 64 },
            doc: "largest number of terms of a linear form",
        },
        ParamInfo {
            name: "slack",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "restructure values with at most this slack after balance, cycles (0: the critical paths)",
        },
        ParamInfo {
            name: "max-slack",
            kind: ParamKind::U32 { default: 48, min: 0, max: 1_000_000 },
            doc:
                "when a round gains nothing, widen the slack (to the smaller latency, then doubling) up to this, cycles",
        },
        ParamInfo {
            name: "pe",
            kind: ParamKind::U32 { default: 0, min: 0, max: 1_000_000 },
            doc: "N of the PE array to place on (N ADD + N MULTI): keep a round only if it lowers max(critical path, \
                  max(⌈add-side ops / N⌉, ⌈muls / N⌉) / fill), then return the fastest placed of the kept states; \
                  0: the critical path alone",
        },
        ParamInfo {
            name: "fill",
            kind: ParamKind::F64 { default: 0.9, min: 0.1, max: 1.0 },
            doc: "with pe=N: the share of the PEs' issue slots a placement fills; the resource bound is divided by it",
        },
        ParamInfo {
            name: "max-growth",
            kind: ParamKind::F64 { default: 1.5, min: 1.0, max: 100.0 },
            doc: "largest ops / the ops of `budget-of`",
        },
        ParamInfo {
            name: "budget-of",
            kind: ParamKind::Choice { choices: &["atomised", "input"], default: "atomised" },
            doc: "the ops max-growth multiplies: the function's when the pipeline first had it atomised (before cse \
                  and zero-removal removed any), or the pass's input's (the larger of the two is used)",
        },
        crate::params::LAT_ADD,
        crate::params::LAT_MUL,
        crate::params::LAT_DIV,
        crate::params::LAT_CALL,
    ],
    build: |p: &Params| Ok(Box::new(Recurrence::from_params(p)?)),
    props: crate::Props {
        requires: Some(robovec_ir::Phase::Atomised),
        at_time_limit: crate::AtTimeLimit::Skip,
        exact_in_reals: true,
        ..crate::Props::DEFAULT
    },
};

/// The `recurrence` pass.
#[derive(Clone, Debug)]
pub struct Recurrence {
    /// Rounds at most.
    pub rounds: u32,
    /// Largest number of terms of a form.
    pub max_terms: u32,
    /// Largest slack of a restructured value after `balance` in the first round, cycles.
    pub slack: u32,
    /// Largest slack the rounds widen to when one gains nothing, cycles.
    pub max_slack: u32,
    /// N of the PE array the result is placed on; 0: unbounded (the critical path alone).
    pub pe: u32,
    /// With `pe` = N > 0: the share of issue slots a placement fills (the resource bound is
    /// divided by it; 1: the bare bound).
    pub fill: f64,
    /// Largest ops / the ops of the budget's baseline ([`Recurrence::budget_of_atomised`]).
    pub max_growth: f64,
    /// The budget is `max_growth` × the ops of the function when the pipeline first had it
    /// atomised ([`crate::PassContext::atomised_ops`]), when larger than its input's; false:
    /// × the input's.
    pub budget_of_atomised: bool,
    /// Latencies, cycles (replaced at run time by the pipeline's with `given` applied).
    pub lat: Latencies,
    /// Latencies given on the pass.
    pub given: crate::LatencyOverride,
}

impl Recurrence {
    /// The pass with checked parameters `p`.
    ///
    /// # Errors
    /// A parameter of the wrong kind ([`PassError::BadParameter`]).
    pub fn from_params(p: &Params) -> Result<Recurrence, PassError> {
        Ok(Recurrence {
            rounds: p.u32("rounds")?,
            max_terms: p.u32("max-terms")?,
            slack: p.u32("slack")?,
            max_slack: p.u32("max-slack")?,
            pe: p.u32("pe")?,
            fill: p.f64("fill")?,
            max_growth: p.f64("max-growth")?,
            budget_of_atomised: p.choice("budget-of")? == "atomised",
            lat: p.latencies()?,
            given: p.latency_override()?,
        })
    }
}

impl Default for Recurrence {
    /// The defaults [`INFO`] declares (the ones `--print-passes` lists).
    fn default() -> Self {
        Recurrence::from_params(&Params::defaults(&INFO)).expect("the declared defaults are valid")
    }
}

impl Pass for Recurrence {
    fn name(&self) -> &'static str {
        "recurrence"
    }

    fn run(&self, m: &mut Module, cx: &mut PassContext) -> Result<(), PassError> {
        let opts = Recurrence { lat: cx.latencies_for("recurrence", &self.given), ..self.clone() };
        let atomised = cx.atomised_ops.clone();
        let parts = each_function(
            m,
            cx,
            "recurrence",
            Before::Ticked,
            |_, _| None,
            |f, _, ticker| {
                let base = match atomised.get(&f.name) {
                    Some(&a) if opts.budget_of_atomised => a.max(f.op_counts().total),
                    _ => f.op_counts().total,
                };
                let (g, s, stopped) = restructure_within(f, &opts, base, ticker);
                *f = g;
                let part = format!(
                    "@{}: {} rounds, ops {} -> {}, balanced critical path {} -> {} cycles",
                    f.name, s.rounds, s.ops.0, s.ops.1, s.cp.0, s.cp.1
                );
                match stopped {
                    true => Step::Stopped {
                        what: format!("in @{} after {} rounds (kept)", f.name, s.rounds),
                        kept: Some(part),
                    },
                    false => Step::Done(part),
                }
            },
        );
        cx.remark("recurrence", m, format!("recurrence: {}", parts.join("; ")));
        Ok(())
    }
}

/// What the restructuring did to one function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecurrenceStats {
    /// Rounds kept.
    pub rounds: u32,
    /// Ops before and after.
    pub ops: (u64, u64),
    /// Critical path after `balance` before, and of the result (cycles).
    pub cp: (u32, u32),
}

/// Restructures `f` (atomised, verified) as [`Recurrence`] says, within `max_growth` × its
/// own ops; the result is balanced.
pub fn restructure_function(f: &Function, opts: &Recurrence) -> (Function, RecurrenceStats) {
    let (g, s, _) = restructure_within(f, opts, f.op_counts().total, &Ticker::default());
    (g, s)
}

/// [`restructure_function`] with the ops budget `max_growth` × `base` (ops), that stops when
/// `ticker` says so (`-time-limit`): the rounds done are kept; the flag is true when it stopped.
pub fn restructure_within(
    f: &Function,
    opts: &Recurrence,
    base: u64,
    ticker: &Ticker,
) -> (Function, RecurrenceStats, bool) {
    let ops0 = f.op_counts().total;
    let budget = (base as f64 * opts.max_growth).floor() as u64;
    let Some((mut cur, _)) = rewrite_within(f, Shape::Balance, &opts.lat, ticker) else {
        return (f.clone(), RecurrenceStats { ops: (ops0, ops0), ..Default::default() }, true);
    };
    let (mut timing, sum) = compute_timing(&cur, &opts.lat);
    let mut cp = sum.asap_cycle;
    let mut stats = RecurrenceStats { rounds: 0, ops: (ops0, cur.op_counts().total), cp: (cp, cp) };
    let mut slack = opts.slack;
    let mut best = bound(&cur, cp, opts.pe, opts.fill);
    // After a round over the budget or without gain, a round restructures only the values ready
    // after cp·(1 − 2^−halving): the end of the critical paths, where the latest terms are.
    let mut halving = 0u32;
    // With pe = N: the balanced input and states after kept rounds (round count, function),
    // the last TAIL of them and at most 2·SNAPSHOTS before, placed at the end.
    let mut snapshots: Vec<(u32, Function)> = if opts.pe > 0 { vec![(0, cur.clone())] } else { Vec::new() };
    for _ in 0..opts.rounds {
        if ticker.check() {
            break;
        }
        let from = cp - (cp >> halving.min(31));
        let Some(g) = round(&cur, &timing, (slack, from), opts, ticker) else { break };
        let Some((g, _)) = rewrite_within(&g, Shape::Balance, &opts.lat, ticker) else { break };
        let (t, s) = compute_timing(&g, &opts.lat);
        let ops = g.op_counts().total;
        if ops > budget {
            if halving >= MAX_HALVING {
                break;
            }
            halving += 1;
            continue;
        }
        let b = bound(&g, s.asap_cycle, opts.pe, opts.fill);
        if b >= best {
            // Nothing shorter: restructure only the end of the critical paths (the values before
            // it become the pivots, the coefficients after it start early), then widen to the
            // near-critical values.
            if halving < MAX_HALVING {
                halving += 1;
                continue;
            }
            if slack >= opts.max_slack {
                break;
            }
            slack = opts.max_slack.min(if slack == 0 { opts.lat.mul.min(opts.lat.add).max(1) } else { 2 * slack });
            halving = 0;
            continue;
        }
        (cur, timing, cp, best) = (g, t, s.asap_cycle, b);
        stats.rounds += 1;
        stats.ops.1 = ops;
        if opts.pe > 0 {
            snapshots.push((stats.rounds, cur.clone()));
            thin(&mut snapshots);
        }
    }
    if opts.pe > 0 && stats.rounds > 0 && !ticker.check() {
        // The bound is a model: place the states kept along the way and return the fastest.
        if let Some((rounds, g)) = fastest_placed(snapshots, opts, ticker) {
            (cp, stats.rounds, stats.ops.1) = (compute_timing(&g, &opts.lat).1.asap_cycle, rounds, g.op_counts().total);
            cur = g;
        }
    }
    if stats.rounds == 0 {
        // Nothing kept: the function as it was, not its balanced form.
        return (f.clone(), RecurrenceStats { ops: (ops0, ops0), cp: (cp, cp), rounds: 0 }, ticker.stopped());
    }
    stats.cp.1 = cp;
    (cur, stats, ticker.stopped())
}

/// States kept for [`fastest_placed`] before the last [`TAIL`]: at most twice this many.
const SNAPSHOTS: usize = 4;

/// The last states kept, all of them: where the critical path nears what N PEs can issue, list
/// scheduling falls behind the path before the resource bound says so (Jeep `dirdyna` at N = 32:
/// the states of the last rounds, 320 / 315 / 313 / 308-cycle paths, place in 320 / 326 / 345 /
/// 347 cycles), so the fastest placed is among the last few.
const TAIL: usize = 6;

/// Keeps the last [`TAIL`] states, and drops every other state but the first before them once
/// there are more than 2·[`SNAPSHOTS`] there: the earlier states left are spread over the rounds.
fn thin(snapshots: &mut Vec<(u32, Function)>) {
    let head = snapshots.len().saturating_sub(TAIL);
    if head <= 2 * SNAPSHOTS {
        return;
    }
    let mut i = 0;
    snapshots.retain(|_| {
        let k = i;
        i += 1;
        k >= head || k % 2 == 0
    });
}

/// The state with the fewest placed cycles on N ADD + N MULTI PEs (list scheduling with
/// `place`'s defaults, no improvement rounds, restarts or search; ties to the later state,
/// which has the shorter critical path), with its round count; `None` when the ticker stops.
fn fastest_placed(snapshots: Vec<(u32, Function)>, opts: &Recurrence, ticker: &Ticker) -> Option<(u32, Function)> {
    let mut po = crate::place::PlaceOptions::with_pes(opts.pe);
    (po.arch.lat, po.improve, po.restarts, po.search) = (opts.lat, 0, 0, 0);
    let mut best: Option<(u32, u32, Function)> = None;
    for (rounds, g) in snapshots {
        if ticker.check() {
            return None;
        }
        let placed = crate::place::cycles(&g, &crate::place::place_function(&g, &po));
        if best.as_ref().is_none_or(|b| placed <= b.0) {
            best = Some((placed, rounds, g));
        }
    }
    best.map(|(_, r, g)| (r, g))
}

/// Rounds over the budget retry on the last half, quarter, … of the critical path, this many
/// times.
const MAX_HALVING: u32 = 4;

/// What a round must lower (cycles): the critical path, and with `pe` = N > 0 the resource
/// bound of N ADD + N MULTI pipelined PEs (one op issued per PE per cycle: ⌈add-side ops / N⌉,
/// ⌈muls / N⌉; seed §1.2), below which no placement goes, divided by `fill`: list scheduling
/// fills about that share of the issue slots where the dependences and the resources bind
/// together (WALK-MAN `dirdyna` at N = 32: a 616-cycle path at a 623-cycle bound placed in 662
/// cycles; stopped at 639 cycles with fewer ops, placed in 644).
fn bound(g: &Function, cp: u32, pe: u32, fill: f64) -> u64 {
    if pe == 0 {
        return cp as u64;
    }
    let c = g.op_counts();
    let add_side = c.add + c.sub + c.div + c.call;
    let slots = add_side.max(c.mul).div_ceil(pe as u64);
    (cp as u64).max((slots as f64 / fill).ceil() as u64)
}
