//! The robot as the CRBA walks it ([`Tree`]): the tables of the leaves-to-root loop, and which
//! columns go up in pairs ([`Tree::waits`]; the module doc of [`super`], "Order of the
//! statements").

use crate::rnea::{Motion, M3};
use crate::robot::Robot;
use crate::Layout;

/// The robot as the CRBA walks it: bodies numbered `1..=nb` depth first (`0` is the fixed
/// root), each indexed by body.
pub(super) struct Tree<'a> {
    pub(super) robot: &'a Robot,
    pub(super) layout: &'a Layout,
    pub(super) motions: &'a [Motion],
    /// The joint of body `i` is `robot.joints[order[i - 1]]`.
    pub(super) order: Vec<usize>,
    pub(super) parent: Vec<usize>,
    /// Whether the body moves (a coordinate on its path to the root).
    pub(super) moves: Vec<bool>,
    /// The constant rotation of the body's joint origin.
    pub(super) ro: Vec<M3>,
    /// The joint's constant and joint rotations as one, where cheaper (`merged_rotation`).
    pub(super) merged: Vec<Option<M3>>,
    /// Whether the body is in the root segment (`Robot::root_segment`): its joints all act at
    /// one point, so a column force that reaches it gives every entry above by projection.
    pub(super) in_segment: Vec<bool>,
    /// Coordinates on the path from the root to the body.
    pub(super) segment_moving: Vec<usize>,
}

/// Steps a column must be carried (moving bodies between its body and the root segment) for
/// it to go up in a pair with its parent's (module doc, "Order of the statements").
const PAIR_WALK: usize = 8;

impl Tree<'_> {
    /// Per body: whether its column waits for its parent's to go up with it — the parent is
    /// the next body the leaves-to-root loop forms, has a coordinate, the walk to the root
    /// segment is at least [`PAIR_WALK`] steps and crosses no merged (dense) rotation.
    pub(super) fn waits(&self) -> Vec<bool> {
        let nb = self.order.len();
        let (mut walk, mut dense) = (vec![0usize; nb + 1], vec![false; nb + 1]);
        let mut waits = vec![false; nb + 1];
        for body in 1..=nb {
            let p = self.parent[body];
            walk[body] = walk[p] + usize::from(self.moves[body] && !self.in_segment[body]);
            dense[body] = dense[p] || self.merged[body].is_some();
            waits[body] = p > 0
                && p + 1 == body
                && self.moves[p]
                && self.layout.v_index[p - 1].is_some()
                && self.robot.joints[self.order[p - 1]].kind != crate::robot::JointKind::FreeFlyer
                && walk[body] >= PAIR_WALK
                && !dense[body];
        }
        waits
    }
}
