//! The joint-space mass matrix `M(q)` by the composite-rigid-body algorithm (CRBA; Walker &
//! Orin 1982, method 3; Featherstone, *Rigid Body Dynamics Algorithms*, 2008, §6.2), in body
//! frames with Robotran's parameters and the same frames, numbering and joint motions as the
//! RNEA of [`super::rnea`].
//!
//! # The recursion
//! A composite body is `(m, h, J)`: mass, first moment `h = Σ mₖ rₖ` and rotational inertia
//! `J = −Σ mₖ [rₖ]×²` about the frame origin. Body `b` alone is `(m_b, m_b l_b,
//! In_b − m_b [l_b]×²)`. Leaves to root, each composite is moved into its parent's frame by
//! `x_parent = t + R x_child` and added there:
//! `m' = m`, `h' = R h + m t`, `J' = R J Rᵀ + m (|t|² I − t tᵀ) + 2 (t·u) I − u tᵀ − t uᵀ`
//! with `u = R h` (the parallel-axis theorem for a rotated, shifted body; symmetric, so only
//! the upper triangle is formed). The joint motion (`R = R_axis(q)`, or a shift `axis·q`) and
//! the constant joint origin (`dpt`, URDF `rpy`) are applied as two such moves.
//!
//! Column `j` of `M`: the spatial force that the composite below joint `j` needs for a unit
//! joint acceleration, `n = J a`, `f = a × h` (revolute axis `a`) or `n = h × a`, `f = m a`
//! (prismatic), gives `M[j][j] = a·n` (or `a·f`); carried up the path to the root (`f ← R f`,
//! `n ← R n + t × (R f)`), it gives `M[i][j]` for every ancestor joint `i`. Only the upper
//! triangle `i ≤ j` is written (joints are numbered depth first, so an ancestor has the smaller
//! index).
//!
//! # Turns about the joint axis
//! A revolute joint about `±x`, `±y` or `±z` turns the composite's `J` in one coordinate plane.
//! `Composite::moved` writes those three entries with `c² + s² = 1` (`turned`: `J'pp = Jpp − B`,
//! `J'qq = Jqq + B`, `J'pq = Jpq + s·c·d − 2Jpq·s²`, `d = Jpp − Jqq`, `B = d·s² + 2Jpq·s·c`)
//! instead of the rows-times-columns product `R J Rᵀ`; a constant rotation about one axis (a
//! URDF `rpy` about one axis, not a quarter turn) takes the same path with numbers for `c`,
//! `s`. Upper triangle of `M`, `--fold-params`, after `atomise,cse`: serial30 7 805 → 7 639
//! ops, UR5 175 → 153, Panda (9 coordinates) 547 → 515, Solo-12 984 → 906, Talos 4 235 →
//! 3 993, TIAGo Pro 8 466 → 8 271.
//!
//! # Constant rotations
//! A joint whose URDF `rpy` is neither a quarter turn nor about one axis has a dense constant
//! rotation `ro` (TIAGo Pro's and UR5's arms). Where it saves ops (`merged_rotation`), the
//! CRBA moves composites and column forces across such a joint by one rotation
//! `P = ro·R_axis(q)`, bound once per joint as `RP{r}{c}{body}`, instead of `R_axis(q)` then
//! `ro`: 15 ops per vector instead of up to 6 + 15. `M` of TIAGo Pro (floating base, 39
//! coordinates, `--fold-params`, after `atomise,cse`): 11 195 → 10 428 ops; UR5: 303 → 228
//! (measured when introduced, before the slid origins, `sym`'s gathered constants and the
//! turns above). The composite still crosses such a joint by `P` (turning it about the joint
//! axis, then by `ro`, cost more on UR5's `M`: 153 → 185 ops).
//!
//! # Robotran's floating base
//! The joints `T1 T2 T3 R1 R2 R3` have no offset and no constant rotation, so their axes meet
//! at the base's origin: a column force that reaches the base (or any body of that root
//! segment) gives all six entries by projection on the axes expressed in the base frame
//! (`WM`, formed once per body), `projection`, instead of being carried through five more
//! frames. `M` of TIAGo Pro: 10 032 → 9 908 ops; Talos 4 971 → 4 856; Solo-12 1 230 → 1 192
//! (measured when introduced).
//!
//! # Order of the statements
//! GCC keeps the statement order of a straight-line function, so the order the generator
//! writes decides what its register allocator spills; the ops are the same in any order.
//! - **Each column right after its body's composite**, leaves to root, so the composite's
//!   `J a`, `a × h` are read as soon as they are formed, and every entry of `M` bound where it
//!   is formed (not at the end, which kept the forces that a projection reads live). Forming
//!   every composite first and every column after kept all composites live until their
//!   column: serial30's `M` (after `atomise,cse,zero-removal,contract`) had 153 values live at
//!   once, this order 26; TIAGo Pro's 289 (after `schedule-cpu`'s greedy order), now 161.
//!   `batch=4` C, same-process A/B: serial30 4–5 % faster, TIAGo Pro 3–6 %.
//! - **Columns in pairs.** A column whose parent is the next body waits there (one step up)
//!   for the parent's column, and the two go up together, one step of each in turn: the
//!   joint's `C`, `S` of each step are loaded once for both (two 6-vectors and the two
//!   values fit the 16 vector registers of x86-64; three columns at once did not: 15 % slower
//!   than pairs on serial30). Only where the walk to the root segment is at least
//!   `PAIR_WALK` (8) steps and crosses no merged (dense) rotation: on short walks (Panda's arm,
//!   Solo-12's legs) and across the 9 entries of a dense rotation (TIAGo Pro's arms) the
//!   extra pressure cost 1–9 %. serial30's `M`, `batch=4` with `contract`: 10–11 % faster
//!   than single columns (`batch=8`: 9–11 %, one state: 0–1 %); Talos 0–2 %; the others'
//!   code is unchanged.
//!
//! # Why CRBA
//! The unit-acceleration RNEA (Walker & Orin's method 1) re-runs the forward and backward
//! recursion of joint `j`'s whole subtree for every column; CRBA forms each subtree's inertia
//! once and then only carries one force per column to the root. Counts in the
//! [`super::dirdyna`] module doc.

mod column;
mod composite;
#[cfg(test)]
mod tests;
mod tree;

use super::rnea::{cross, numeric, Motion, M3, SUM_CHUNK, V3};
use super::robot::JointKind;
use super::sym::{mul, Builder, Term, ZERO};
use super::{Layout, Model, Stopped};
pub(crate) use column::bind_entry;
use column::merged_rotation;
use composite::Composite;
use rustc_hash::FxHashMap;
use tree::Tree;

/// Entries `((i, j), term)` of `M`'s upper triangle, `i ≤ j` (1-based coordinates).
pub type Entries = Vec<((usize, usize), Term)>;

/// The upper triangle of `M`: `(i, j) → term` for `i ≤ j` (1-based coordinates), entries that
/// fold to 0 left out. Writes the composites and column forces into `b` as temporaries `MC`,
/// `HC`, `JC` (per body) and `FM`, `CM` (per body and column), each column right after its
/// body's composite, and every entry as `M{i}_{j}` where it is formed
/// (`bind_entry`; module doc, "Order of the statements").
///
/// Cost: linear in the bodies and the ops written (each column step writes its entry's ops;
/// no table of body pairs).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body and per column step).
pub fn mass_matrix(model: &Model, layout: &Layout, b: &mut Builder, motions: &[Motion]) -> Result<Entries, Stopped> {
    let robot = &model.robot;
    let order = robot.dfs_joints();
    let nb = order.len();
    let parent = robot.body_parents(&order);
    let moves = layout.moving_bodies(&parent);
    let ro: Vec<M3> =
        std::iter::once(M3::default()).chain(order.iter().map(|&j| numeric(&robot.joints[j].origin.rot))).collect();
    let mut merged: Vec<Option<M3>> = vec![None; nb + 1];
    for body in 1..=nb {
        if moves[parent[body]] {
            merged[body] = merged_rotation(b, body, &ro[body], motions[body].rot.as_ref());
        }
    }
    let segment_of_link = robot.root_segment();
    let in_segment: Vec<bool> =
        std::iter::once(true).chain(order.iter().map(|&j| segment_of_link[robot.joints[j].child])).collect();
    let mut segment_moving = vec![0usize; nb + 1];
    for body in 1..=nb {
        segment_moving[body] = segment_moving[parent[body]] + usize::from(layout.v_index[body - 1].is_some());
    }
    let tree = Tree { robot, layout, motions, order, parent, moves, ro, merged, in_segment, segment_moving };
    let waits = tree.waits();
    let mut projections: FxHashMap<(usize, usize), V3> = FxHashMap::default();
    let mut upper = Vec::new();
    // Each body alone, then leaves to root: the composite of its subtree, then its column.
    let mut comp: Vec<Composite> = vec![Composite::zero(); nb + 1];
    // Children added to each composite (bound every `SUM_CHUNK`: `rnea::SUM_CHUNK`).
    let mut children = vec![0usize; nb + 1];
    let mut pending: Vec<column::Carry> = Vec::new();
    for body in (1..=nb).rev() {
        if !tree.moves[body] {
            continue;
        }
        b.check(body, nb)?;
        let m = layout.param(b, &format!("m[{body}]"));
        let l: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("l[{k}][{body}]")));
        let inn: M3 = [0, 1, 2].map(|r| [0, 1, 2].map(|c| layout.param(b, &Layout::inertia_name(r, c, body))));
        let c = Composite::body(m, l, inn).add(std::mem::take(&mut comp[body])).bind(b, body);
        let p = tree.parent[body];
        if tree.moves[p] {
            let d: V3 = [1, 2, 3].map(|k| layout.param(b, &format!("dpt[{k}][{body}]")));
            let in_parent = match &tree.merged[body] {
                Some(r) => c.moved(b, &body.to_string(), Some(r), Some(&d)),
                None => {
                    let mo = &motions[body];
                    let turned = c.moved(b, &body.to_string(), mo.rot.as_ref(), mo.shift.as_ref());
                    turned.moved(b, &format!("O{body}"), Some(&tree.ro[body]), Some(&d))
                }
            };
            // In place: a link's composite grows by one child at a time.
            comp[p] = std::mem::take(&mut comp[p]).add(in_parent);
            children[p] += 1;
            if children[p].is_multiple_of(SUM_CHUNK) {
                comp[p] = comp[p].bind(b, format_args!("{p}_{}", children[p] / SUM_CHUNK));
            }
        }
        let kind = robot.joints[tree.order[body - 1]].kind;
        if let (JointKind::FreeFlyer, Some(qj)) = (kind, layout.v_index[body - 1]) {
            // The base's six columns: the whole robot's composite about the base origin, in the
            // base frame (the world above does not move: nothing to carry). Columns waiting for
            // this body's go up first.
            tree.finish(b, &mut projections, &mut pending, &mut upper)?;
            upper.extend(free_flyer_block(b, qj, &c));
        } else if let Some(qj) = layout.v_index[body - 1] {
            // A column waiting for this body's (its child's, one step up already) goes up with it:
            // a body waits only for its parent, which is the next body this loop forms.
            debug_assert!(pending.iter().all(|o| o.at() == body), "a waiting column is at its parent");
            pending.push(tree.start(body, qj, &c));
            if pending.len() == 1 && waits[body] {
                tree.step(b, &mut projections, &mut pending[0], &mut upper)?;
            } else {
                tree.finish(b, &mut projections, &mut pending, &mut upper)?;
            }
        }
        comp[body] = c;
    }
    debug_assert!(pending.is_empty(), "the root waits for no column");
    Ok(upper)
}

/// The upper triangle of a free flyer's 6 × 6 block of `M` (coordinates `qj..qj + 5`: linear,
/// then angular, in the base frame) from the composite `c = (m, h, J)` of everything it
/// carries: a unit linear acceleration `e_b` needs the force `m e_b` (and the moment
/// `h × e_b`), a unit angular one the force `e_b × h` and the moment `J e_b`; so
/// `M = [[m 1, −[h]×], [[h]×, J]]` (Featherstone 2008, §2.13), each entry bound as
/// [`bind_entry`].
fn free_flyer_block(b: &mut Builder, qj: usize, c: &Composite) -> Entries {
    let mut out = Vec::with_capacity(21);
    for col in 0..6 {
        let mut e: V3 = [ZERO, ZERO, ZERO];
        e[col % 3] = Term::C(1.0);
        // The force and moment of this column's unit acceleration.
        let (f, n): (V3, V3) = if col < 3 {
            (e.clone().map(|x| mul(c.m.clone(), x)), cross(&c.h, &e))
        } else {
            (cross(&e, &c.h), c.j[col - 3].clone())
        };
        for (row, t) in f.into_iter().chain(n).enumerate().take(col + 1) {
            let (i, j) = (qj + row, qj + col);
            out.push(((i, j), bind_entry(b, i, j, t)));
        }
    }
    out
}
