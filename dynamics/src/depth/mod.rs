//! The depth-optimised formulation (`--formulation=depth`, issue 31 item 4): the same inverse
//! dynamics as the body-frame recursive Newton–Euler algorithm ([`crate::rnea`]), written so
//! that the dependence depth grows with the logarithm of the tree's depth instead of linearly.
//!
//! # Why
//! The body-frame RNEA is a chain of recurrences as long as the tree is deep (`R_k = R_{k−1}·A_k`,
//! `ω_k = A_kᵀ ω_{k−1} + qd_k e_k`, …, and the backward force sweep). The `recurrence` pass of
//! `default<depth>` restructures those chains after the fact; this formulation writes them as
//! parallel prefixes from the start (R. E. Ladner, M. J. Fischer, "Parallel prefix computation",
//! *J. ACM* 27(4), 1980; R. P. Brent, H. T. Kung, "A regular layout for parallel adders", *IEEE
//! Trans. Computers* C-31(3), 1982), along the heavy chains of the tree ([`scan`]).
//!
//! # Formulation (world frame, every quantity of body `b` with parent `p`)
//! - joint rotation child → parent `E_b = R_origin·R_axis(q_b)` (a constant for prismatic and
//!   fixed joints, the quaternion's for a free flyer) and the child origin in the parent frame
//!   `t_b = d_b (+ R_origin·axis·q_b` prismatic);
//! - orientations `R_b = E_{c₁}⋯E_{c_i}` along a chain `c₁ … c_m`: a Ladner–Fischer (`P₁`) prefix of the
//!   3 × 3 products, times the head's parent's `R_p` (one product, so the late `R_p` is one
//!   product deep); axes `z_b = R_b·axis`, origin steps `r_b = R_p·t_b`;
//! - `ω_b = ω_p + z_b qd_b`, `ω̇_b = ω̇_p + z_b qdd_b + ω_p × z_b qd_b`,
//!   `a_b = a_p + U_p r_b` (`U = [ω̇]× + [ω]×²`; prismatic: `+ z_b qdd_b + 2 ω_p × z_b qd_b`),
//!   `a_0 = −g`, and the origins `o_b = o_p + r_b`: each a sum over the ancestors, written as
//!   Sklansky prefix sums along the chain, the head's parent's value added after the network;
//! - per body: the force `F_b = m_b (a_b + U_b ρ_b)` at the centre of mass `c_b = o_b + ρ_b`,
//!   `ρ_b = R_b l_b`, and its moment about the world origin `Mo_b = R_b (In ω̇ᵇ + ωᵇ × In ωᵇ) +
//!   c_b × F_b` (`ωᵇ = R_bᵀ ω_b`, Euler's equation in the body frame, where `In` is given);
//! - the wrench of a subtree about the world origin, `Fq_k = Σ_{j ∈ subtree(k)} F_j`,
//!   `Mq_k = Σ Mo_j`: Sklansky suffix sums along each chain, the light children's totals added
//!   to their parent's term;
//! - the joint force is the wrench projected on the joint's Plücker axis `(z_k, o_k × z_k)`:
//!   `Q_k = z_k·Mq_k − (z_k × o_k)·Fq_k` (revolute), `z_k·Fq_k` (prismatic); a free flyer's is
//!   `(R_kᵀ Fq_k, R_kᵀ (Mq_k − o_k × Fq_k))`.
//!
//! In exact arithmetic (and with `cos² + sin² = 1`) this is the body-frame RNEA's `Qq`; the tests
//! compare both within the sum of their running error bounds (Wilkinson's running error
//! analysis, Higham, *Accuracy and Stability of Numerical Algorithms*, §3.3), evaluated at each
//! state.
//!
//! Every recursion is a prefix over at most `log₂ n` chains on any path from the root, so the
//! depth is `O(log² n)` on any tree and `O(log n)` on a chain or a tree of few branches.
//! `dirdyna` writes `c` by this sweep (`qdd = 0`) and `M` by the composite-rigid-body algorithm
//! in the world frame ([`composite`]: a subtree's inertia about the world origin is a suffix sum
//! of its bodies', each entry one projection on two Plücker axes), both on one set of
//! kinematics ([`kinematics`]). `fordyna` solves `M qdd = Qq − c` by the sparse `LᵀDL`, with this
//! `c` and the body-frame CRBA's `M`, whose leaf entries are ready early ([`fordyna`]).
//!
//! The frames of [`crate::frames`] and [`crate::origins`] are still chosen by the fewest ops.
//!
//! # Measured
//! See `docs/rewrites.md`, "A depth-optimised formulation (issue 31 item 4)".

pub mod composite;
pub mod forces;
pub mod kinematics;
pub mod scan;

#[cfg(test)]
pub(crate) mod tests;

use crate::dirdyna::dirdyna_by;
use crate::rnea::{motions, Drive, Motion};
use crate::sym::Builder;
use crate::{Layout, Model, Stopped};
use kinematics::Frames;

/// Writes `invdyna` (outputs `Qq[1..nv]`) by the world-frame parallel-prefix sweep
/// ([`forces::sweep`]).
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn invdyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let drive = Drive::inputs(b, layout.nv, true);
    let motions = motions(model, layout, b);
    for (qi, t) in forces::sweep(model, layout, b, &motions, &drive)? {
        b.output(&format!("Qq[{qi}]"), &format!("Qq{qi}"), t);
    }
    Ok(())
}

/// Writes `dirdyna` (outputs `M[i][j]`, then `c[i]`): `M` by world-frame composite inertias
/// ([`composite::mass_matrix`]), `c` by [`forces::sweep_in`] with `qdd = 0`, both on one set of
/// world-frame kinematics ([`kinematics::Frames`]).
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn dirdyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let mut parts = |b: &mut Builder, motions: &[Motion], drive: &Drive| {
        let frames = Frames::of(model, layout, b, motions)?;
        let entries = composite::mass_matrix(model, layout, b, &frames)?;
        Ok((entries, forces::sweep_in(model, layout, b, &frames, drive)?))
    };
    dirdyna_by(model, layout, b, &mut parts)
}

/// Writes `fordyna` (outputs `qdd[1..nq]`): `c` by [`forces::sweep_in`] with `qdd = 0` on the
/// world-frame kinematics, `M` by the body-frame CRBA ([`crate::crba`]), then Featherstone's
/// sparse `LᵀDL` and the two substitutions ([`crate::fordyna`]).
///
/// The factorisation runs from the leaves to the root, one division per coordinate, each row
/// waiting for its descendants': its depth grows with the tree's, and it starts as soon as the
/// leaves' entries of `M` are ready. The body-frame CRBA has those early (a leaf's composite
/// inertia is its own, no rotation to the world), so the factorisation overlaps it; the
/// world-frame `M` of [`dirdyna`] is ready all at once after the prefixes, and starts it late
/// (UR5 after `atomise,default<depth>`: 403 cycles with it, 279 with the CRBA's, 327 on
/// `--formulation=ops`). `c` is read by the substitutions only, after the factorisation, and
/// its parallel prefixes make it ready before them. Where the factorisation's updates alone
/// cost more ops than the whole articulated-body algorithm (chains of about 40 joints and more:
/// they are cubic in the depth), the ABA is written instead, as
/// [`crate::fordyna::Formulation::Fewest`] does.
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn fordyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let mut parts = |b: &mut Builder, motions: &[Motion], drive: &Drive| {
        let entries = crate::crba::mass_matrix(model, layout, b, motions)?;
        let frames = Frames::of(model, layout, b, motions)?;
        Ok((entries, forces::sweep_in(model, layout, b, &frames, drive)?))
    };
    crate::fordyna::ltdl_or_aba(model, layout, b, &mut parts, false)
}
