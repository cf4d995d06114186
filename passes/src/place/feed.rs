//! Feeding priority for list scheduling on two PE types (issue 3): an op whose issue completes
//! the operands of an op of the other type goes earlier, so that a saturated PE type keeps the
//! other one supplied with work.

use super::dag::{Key, Node, OpDag};

/// Feeding priority: an op that is the last unissued op operand of an op of the *other* PE
/// type has its priority key lowered by `bonus` cycles, since issuing it makes work for the
/// other PE type after one latency. When both PE types are saturated (Jacobians such as
/// Mazda `cons_hJ`, with about one add per product), the seed's ALAP order issues the
/// products of long chains first and starves the ADD PEs for tens of cycles; feeding keeps
/// both types busy (issue 3's measurements, with restarts: 574 → 516 cycles at N=1, which is the
/// tight lower bound, hence optimal; 162 → 152 at N=4). The
/// backward schedule of forward-backward improvement feeds in reverse time the same way.
pub struct Feed<'k> {
    /// Cycles subtracted from the first key component (0 = off: the seed's static order).
    pub bonus: u32,
    /// True in a backward (reverse-time) schedule: "operand" and "user" swap roles.
    backward: bool,
    /// Current key per node (lowered at most once per op that it completes); borrowed until
    /// the first lowering.
    pub key: std::borrow::Cow<'k, [Key]>,
    /// Distinct op predecessors (operands; users when backward) not yet issued, per node
    /// (empty when the bonus is 0).
    unissued: Vec<u32>,
}

impl<'k> Feed<'k> {
    /// Starts a schedule (`backward`: in reverse time) from the static `keys` (indexed by
    /// node), with the bonus in cycles (0 = off): predecessors that alone stand
    /// between an op of the other type and its readiness are lowered at once.
    pub fn new(dag: &OpDag, keys: &'k [Key], bonus: u32, backward: bool) -> Feed<'k> {
        let unissued = match (bonus, backward) {
            (0, _) => Vec::new(),
            (_, true) => (0..dag.len() as Node).map(|j| dag.n_users(j)).collect(),
            (_, false) => dag.n_distinct.clone(),
        };
        let mut feed = Feed { bonus, backward, key: std::borrow::Cow::Borrowed(keys), unissued };
        if bonus > 0 {
            for w in 0..dag.len() as Node {
                if feed.unissued[w as usize] == 1 {
                    let u = feed.preds(dag, w)[0];
                    feed.lower(dag, u, w);
                }
            }
        }
        feed
    }

    /// Distinct op predecessors of `w` in the schedule's direction (operands forward, users
    /// backward).
    fn preds(&self, dag: &OpDag, w: Node) -> Vec<Node> {
        if self.backward {
            dag.users_of(w).to_vec()
        } else {
            dag.distinct_operands(w).collect()
        }
    }

    /// Distinct op successors of `v` in the schedule's direction.
    fn succs(&self, dag: &OpDag, v: Node) -> Vec<Node> {
        if self.backward {
            dag.distinct_operands(v).collect()
        } else {
            dag.users_of(v).to_vec()
        }
    }

    /// Lowers the key of `u` (an unissued predecessor of `w`) if the two are of different
    /// types; returns the new key when it changed.
    fn lower(&mut self, dag: &OpDag, u: Node, w: Node) -> Option<Key> {
        if dag.is_mul(u) == dag.is_mul(w) {
            return None;
        }
        let c = &mut self.key.to_mut()[u as usize];
        let lowered = (c.0.saturating_sub(self.bonus), c.1, c.2);
        (lowered < *c).then(|| {
            *c = lowered;
            lowered
        })
    }

    /// After `v` is issued (`done(u)`: whether `u` is issued): the ops whose last unissued
    /// predecessor is now known, with their new keys (pushed to `out`).
    pub fn issued(&mut self, dag: &OpDag, done: impl Fn(Node) -> bool, v: Node, out: &mut Vec<(Key, Node)>) {
        if self.bonus == 0 {
            return;
        }
        for w in self.succs(dag, v) {
            self.unissued[w as usize] -= 1;
            if self.unissued[w as usize] != 1 {
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
