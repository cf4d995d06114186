//! Feeding priority for list scheduling on two PE types (issue 3): an op whose issue completes
//! the operands of an op of the other type goes earlier, so that a saturated PE type keeps the
//! other one supplied with work.

use robovec_ir::Value;

use super::dag::{Key, OpDag};

/// Feeding priority: an op that is the last unissued op operand of an op of the *other* PE
/// type has its priority key lowered by `bonus` cycles, since issuing it makes work for the
/// other PE type after one latency. When both PE types are saturated (Jacobians such as
/// Mazda `cons_hJ`, with about one add per product), the seed's ALAP order issues the
/// products of long chains first and starves the ADD PEs for tens of cycles; feeding keeps
/// both types busy (issue 3's measurements, with restarts: 574 → 516 cycles at N=1, which is the
/// tight lower bound, hence optimal; 162 → 152 at N=4). The
/// backward schedule of forward-backward improvement feeds in reverse time the same way.
pub struct Feed {
    /// Cycles subtracted from the first key component (0 = off: the seed's static order).
    pub bonus: u32,
    /// True in a backward (reverse-time) schedule: "operand" and "user" swap roles.
    backward: bool,
    /// Current key per value index (lowered at most once per op that it completes).
    pub key: Vec<Key>,
    /// Distinct op predecessors (operands; users when backward) not yet issued, per value index.
    unissued: Vec<u32>,
}

impl Feed {
    /// Starts a schedule (`backward`: in reverse time) from the static `keys` (indexed by
    /// value index), with the bonus in cycles (0 = off): predecessors that alone stand
    /// between an op of the other type and its readiness are lowered at once.
    pub fn new(dag: &OpDag, keys: &[Key], bonus: u32, backward: bool) -> Feed {
        let unissued = if backward {
            (0..keys.len()).map(|i| dag.user_at[i + 1] - dag.user_at[i]).collect()
        } else {
            dag.n_distinct.clone()
        };
        let mut feed = Feed { bonus, backward, key: keys.to_vec(), unissued };
        if bonus > 0 {
            for &w in &dag.ops {
                if feed.unissued[w.index()] == 1 {
                    let u = feed.preds(dag, w)[0];
                    feed.lower(dag, u, w);
                }
            }
        }
        feed
    }

    /// Distinct op predecessors of `w` in the schedule's direction (operands forward, users
    /// backward).
    fn preds(&self, dag: &OpDag, w: Value) -> Vec<Value> {
        if self.backward {
            dag.users_of(w).to_vec()
        } else {
            dag.distinct_operands(w)
        }
    }

    /// Distinct op successors of `v` in the schedule's direction.
    fn succs(&self, dag: &OpDag, v: Value) -> Vec<Value> {
        if self.backward {
            dag.distinct_operands(v)
        } else {
            dag.users_of(v).to_vec()
        }
    }

    /// Lowers the key of `u` (an unissued predecessor of `w`) if the two are of different
    /// types; returns the new key when it changed.
    fn lower(&mut self, dag: &OpDag, u: Value, w: Value) -> Option<Key> {
        if dag.is_mul(u) == dag.is_mul(w) {
            return None;
        }
        let c = &mut self.key[u.index()];
        let lowered = (c.0.saturating_sub(self.bonus), c.1, c.2);
        (lowered < *c).then(|| {
            *c = lowered;
            lowered
        })
    }

    /// After `v` is issued (`done(u)`: whether `u` is issued): the ops whose last unissued
    /// predecessor is now known, with their new keys (pushed to `out`).
    pub fn issued(&mut self, dag: &OpDag, done: impl Fn(Value) -> bool, v: Value, out: &mut Vec<(Key, Value)>) {
        if self.bonus == 0 {
            return;
        }
        for w in self.succs(dag, v) {
            self.unissued[w.index()] -= 1;
            if self.unissued[w.index()] != 1 {
                continue;
            }
            let last = self.preds(dag, w).into_iter().find(|&u| !done(u));
            if let Some(u) = last {
                if let Some(k) = self.lower(dag, u, w) {
                    out.push((k, u));
                }
            }
        }
    }
}
