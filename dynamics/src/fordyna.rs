//! Forward dynamics `qdd = M(q)⁻¹ (Qq − c(q, qd, g))` of a tree (Pinocchio's `aba`): inputs
//! `q`, `qd`, the generalised forces `Qq` and `g`; outputs `qdd[1..nq]`.
//!
//! # Formulation: the fewer ops of two, per robot
//! 1. **CRBA + sparse `LᵀDL`** (this module): `M` by the composite-rigid-body algorithm
//!    ([`super::crba`], as `dirdyna`), `c` by one RNEA sweep with `qdd = 0`
//!    ([`super::rnea::sweep`]), the right-hand side `Qq − c`; `M = Lᵀ D L` by Featherstone's
//!    factorisation for branched trees (R. Featherstone, "Efficient factorization of the
//!    joint-space inertia matrix for branched kinematic trees", *Int. J. Robotics Research*
//!    24(6), 2005; *Rigid Body Dynamics Algorithms*, 2008, §6.5, "LTDL"): `L` is unit lower
//!    triangular and has an entry `L[k][i]` only where coordinate `i` is an ancestor of `k` (the
//!    parent array `λ` of [`crate::coordinate_parents`]), so there is no fill-in; `Σₖ dₖ(dₖ−1)/2`
//!    multiply–adds for coordinates at depth `dₖ`, one division per coordinate (`1/D[k]`, bound
//!    once); then `qdd = L⁻¹ D⁻¹ L⁻ᵀ (Qq − c)` by the two sparse substitutions.
//! 2. **The articulated-body algorithm** ([`crate::aba`]): linear in the bodies.
//!
//! [`Formulation::Fewest`] (what `-function=fordyna` writes) keeps whichever has fewer ops once
//! atomised and its repeated ops merged ([`crate::sym::Builder::ops_after_cse`]: the ABA
//! repeats many terms, which `cse` merges; compared before it, the ABA lost on TIAGo Pro and
//! Talos on the free flyer with `--fold-params`, where after `atomise,cse` it has 16 266 and
//! 12 152 ops against the factorisation's 19 313 and 12 834). The
//! factorisation grows as the cube of the tree's depth and the ABA linearly, but the ABA
//! carries a 6 × 6 articulated inertia across every joint where the CRBA carries one force per
//! column: measured (`-passes=atomise`, symbolic parameters, own frames: LTDL / ABA ops),
//! three_link_arm 689 / 1 543, UR5 952 / 3 167, Panda 2 615 / 5 915, Solo-12 (floating base)
//! 5 422 / 14 054, Talos (floating base) 21 141 / 41 774, TIAGo Pro 34 155 / 124 377, a 30-joint
//! serial chain 24 712 / 38 243 — the factorisation on every robot users bring; the ABA from
//! chains of about 40 joints: 60 joints 126 355 / 79 000, 120 joints 770 126 / 160 426, and a
//! 2,000-joint chain 2.28 million ops (4.9 s), where the factorisation would be billions. The
//! ABA is written first and the factorisation only when its updates alone (`Σₖ dₖ(dₖ − 1)`
//! ops) cost fewer ops than the ABA, so the generation stays linear in the ops it keeps.
//!
//! The matrix `M` is never an output here: its entries are temporaries the factorisation
//! overwrites in place, as `H` is in Featherstone's algorithm.

use rustc_hash::FxHashMap;

use super::crba;
use super::dirdyna::{Parted, Parts};
use super::rnea::{motions, sweep, Drive, Motion};
use super::sym::{mul, reciprocal, sub, Builder, Term, ZERO};
use super::{coordinate_parents, Layout, Model, Reached, Stopped};

/// The ancestors of coordinate `k` in `λ`, nearest first.
fn ancestors(lambda: &[usize], k: usize) -> impl Iterator<Item = usize> + '_ {
    let mut i = lambda[k];
    std::iter::from_fn(move || {
        let here = i;
        (here != 0).then(|| {
            i = lambda[here];
            here
        })
    })
}

/// How `fordyna` is formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Formulation {
    /// Whichever of the two below writes fewer ops for this robot (the first on a tie).
    Fewest,
    /// CRBA, sparse `LᵀDL`, substitutions (this module).
    Ltdl,
    /// The articulated-body algorithm ([`crate::aba`]).
    Aba,
}

/// Writes `fordyna` (outputs `qdd[1..nq]`) into `b`: [`Formulation::Fewest`].
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn fordyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    fordyna_with(model, layout, b, Formulation::Fewest)
}

/// Writes `fordyna` formed by `how` into `b`. [`Formulation::Fewest`] writes both into two
/// builders and keeps the one whose function has fewer ops (twice the generation time).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body of the recursions and per
/// coordinate of the factorisation and the substitutions).
pub fn fordyna_with(model: &Model, layout: &Layout, b: &mut Builder, how: Formulation) -> Result<(), Stopped> {
    match how {
        Formulation::Ltdl => ltdl_by(model, layout, b, &mut crba_rnea(model, layout)),
        Formulation::Aba => crate::aba::fordyna(model, layout, b),
        Formulation::Fewest => ltdl_or_aba(model, layout, b, &mut crba_rnea(model, layout), true),
    }
}

/// `M` by the CRBA and `c` by the RNEA in the body frames: [`ltdl_by`]'s parts for the fewest
/// ops.
fn crba_rnea<'a>(model: &'a Model, layout: &'a Layout) -> impl FnMut(&mut Builder, &[Motion], &Drive) -> Parted + 'a {
    move |b: &mut Builder, motions: &[Motion], drive: &Drive| {
        Ok((crba::mass_matrix(model, layout, b, motions)?, sweep(model, layout, b, motions, drive)?))
    }
}

/// The `LᵀDL` on the `M` and `c` that `parts` writes ([`ltdl_by`]), or the ABA when that has
/// fewer ops.
///
/// The ABA is written first: its cost is linear in the bodies. The factorisation alone costs
/// `Σₖ dₖ(dₖ − 1)` ops (a multiply and a subtraction per update) for coordinates at depth
/// `dₖ`: the `LᵀDL` is written only when that is below the ABA's ops (on a long chain it is
/// cubic, and writing it would cost more than the whole ABA). With `whole`, it is kept only when
/// the whole function also has no more ops than the ABA (the fewest ops); without, whenever its
/// updates cost fewer ops than the ABA (the depth formulation, whose `c` takes more ops for a
/// shorter path: [`crate::depth::fordyna`]).
///
/// The ABA's ops after `atomise,cse` are counted only when the factorisation might win: its
/// ops as written bound them from above (atomising writes exactly the ops counted, pruning and
/// merging only remove), so a factorisation whose updates alone cost as many never needs the
/// count (issue 47: on a 10,000-joint chain the count took 19 s of the 27 s per frame
/// candidate; the choice is the same).
///
/// # Errors
/// [`Stopped`] at the builder's deadline; the functions written are then abandoned
/// ([`crate::abandon`]).
pub(crate) fn ltdl_or_aba(
    model: &Model,
    layout: &Layout,
    b: &mut Builder,
    parts: &mut Parts<'_>,
    whole: bool,
) -> Result<(), Stopped> {
    let limited = b.deadline.is_some();
    let mut aba = b.fresh();
    if let Err(stop) = crate::aba::fordyna(model, layout, &mut aba) {
        crate::abandon(aba.f);
        return Err(stop);
    }
    let updates = factorisation_ops(&coordinate_parents(model, layout));
    let Some(written) = crate::sym::op_counts_until(&aba.f, &aba.ticker()) else {
        let stop = aba.stopped(Reached::Step("counting its ops"));
        crate::abandon(aba.f);
        return Err(stop);
    };
    if updates < written.total {
        let aba_ops = match aba.ops_after_cse_until() {
            Ok(n) => n,
            Err(stop) => {
                crate::abandon(aba.f);
                return Err(stop);
            }
        };
        if updates < aba_ops {
            let mut by_ltdl = b.fresh();
            let kept = ltdl_by(model, layout, &mut by_ltdl, parts)
                .and_then(|()| Ok(!whole || by_ltdl.ops_after_cse_until()? <= aba_ops));
            match kept {
                Ok(true) => {
                    crate::drop_later(std::mem::replace(b, by_ltdl).f, limited);
                    crate::drop_later(aba.f, limited);
                    return Ok(());
                }
                Ok(false) => crate::drop_later(by_ltdl.f, limited),
                Err(stop) => {
                    crate::abandon(by_ltdl.f);
                    crate::abandon(aba.f);
                    return Err(stop);
                }
            }
        }
    }
    crate::drop_later(std::mem::replace(b, aba).f, limited);
    Ok(())
}

/// Ops of the `LᵀDL` factorisation's updates for the coordinate parents `lambda`: a multiply
/// and a subtraction per pair (ancestor `i` of `k`, ancestor-or-self `j` of `i`), structural
/// zeros not counted (a lower bound of what [`ltdl`] writes).
fn factorisation_ops(lambda: &[usize]) -> u64 {
    let mut depth = vec![0u64; lambda.len()];
    let mut ops = 0;
    for k in 1..lambda.len() {
        depth[k] = depth[lambda[k]] + 1;
        ops += depth[k] * (depth[k] - 1);
    }
    ops
}

/// `fordyna`'s inputs (`q`, `qd`, `g`, then `Qq`), `M` and `c` written by `parts` (the CRBA and
/// the RNEA, or the depth formulation's, [`crate::depth`]), `M`'s `LᵀDL` factorisation, the
/// substitutions, and the outputs `qdd[1..nq]`.
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body and per row of the factorisation
/// and of the substitutions).
pub(crate) fn ltdl_by(model: &Model, layout: &Layout, b: &mut Builder, parts: &mut Parts<'_>) -> Result<(), Stopped> {
    ltdl_with(model, layout, b, parts, false)
}

/// [`ltdl_by`], then with `with_inverse` the outputs `Minv[a][c]` from the same factors
/// ([`inverse`]).
fn ltdl_with(
    model: &Model,
    layout: &Layout,
    b: &mut Builder,
    parts: &mut Parts<'_>,
    with_inverse: bool,
) -> Result<(), Stopped> {
    let nq = layout.nv;
    let drive = Drive::inputs(b, nq, false);
    let forces: Vec<Term> = (1..=nq).map(|i| b.input(&format!("Qq[{i}]"))).collect();
    let motions = motions(model, layout, b);
    let lambda = coordinate_parents(model, layout);
    let (entries, c) = parts(b, &motions, &drive)?;
    // `H[k][i]` for `i` an ancestor of `k` or `k` itself (1-based), from `M`'s upper triangle.
    let mut h: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    for ((i, j), t) in entries {
        h.insert((j, i), t);
    }
    let mut x = forces;
    for (qi, t) in c {
        let r = sub(std::mem::take(&mut x[qi - 1]), t);
        x[qi - 1] = b.bind(&format!("QC{qi}"), r);
    }
    let ancestors = |k: usize| ancestors(&lambda, k);
    let at = |k: usize| Reached::Row { row: k, rows: nq };
    let inv_d = factor(b, &mut h, &lambda)?;
    // x ← L⁻ᵀ x (leaves to root), x ← D⁻¹ x, x ← L⁻¹ x (root to leaves).
    for i in (1..=nq).rev() {
        b.check_at(at(i))?;
        for j in ancestors(i) {
            if let Some(l) = h.get(&(i, j)).cloned() {
                let t = sub(std::mem::take(&mut x[j - 1]), mul(l, x[i - 1].clone()));
                x[j - 1] = b.bind(&format!("Y{j}"), t);
            }
        }
    }
    for (i, xi) in x.iter_mut().enumerate() {
        let t = mul(std::mem::take(xi), inv_d[i + 1].clone());
        *xi = b.bind(&format!("Z{}", i + 1), t);
    }
    for i in 1..=nq {
        b.check_at(at(i))?;
        let mut t = std::mem::take(&mut x[i - 1]);
        for j in ancestors(i) {
            if let Some(l) = h.get(&(i, j)) {
                t = sub(t, mul(l.clone(), x[j - 1].clone()));
            }
        }
        x[i - 1] = b.bind(&format!("QDD{i}"), t);
    }
    for (i, t) in x.into_iter().enumerate() {
        b.output(&format!("qdd[{}]", i + 1), &format!("qdd{}", i + 1), t);
    }
    if with_inverse {
        inverse(b, &h, &inv_d, &lambda, true)?;
    }
    Ok(())
}

/// `M = LᵀDL` in place, leaves to root (Featherstone 2005, Table 2): `h` holds `M`'s entries
/// `H[k][i]` (`i` an ancestor of `k` or `k` itself, 1-based) and ends holding `L[k][i]` for the
/// ancestors; returns `1/D[k]` (index 0 unused). `lambda` is the coordinate parent array.
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per row).
fn factor(b: &mut Builder, h: &mut FxHashMap<(usize, usize), Term>, lambda: &[usize]) -> Result<Vec<Term>, Stopped> {
    let nq = lambda.len() - 1;
    let ancestors = |k: usize| ancestors(lambda, k);
    let at = |k: usize| Reached::Row { row: k, rows: nq };
    let mut inv_d: Vec<Term> = vec![ZERO; nq + 1];
    for k in (1..=nq).rev() {
        b.check_at(at(k))?;
        let d = h.remove(&(k, k)).unwrap_or(ZERO);
        inv_d[k] = reciprocal(b, k, &format!("D{k}"), &format!("iD{k}"), d);
        let anc: Vec<usize> = ancestors(k).collect();
        for (n, &i) in anc.iter().enumerate() {
            let hki = h.remove(&(k, i)).unwrap_or(ZERO);
            if hki == ZERO {
                continue;
            }
            let a = b.bind(&format!("L{k}_{i}"), mul(hki.clone(), inv_d[k].clone()));
            // `H[i][j] −= a·H[k][j]` for `j = i` and its ancestors (whose `H[k][j]` are not yet
            // turned into `L[k][j]`: they come later in this walk up).
            for &j in std::iter::once(&i).chain(&anc[n + 1..]) {
                let hkj = if j == i { hki.clone() } else { h.get(&(k, j)).cloned().unwrap_or(ZERO) };
                if hkj == ZERO {
                    continue;
                }
                let old = h.remove(&(i, j)).unwrap_or(ZERO);
                let new = b.bind(&format!("H{i}_{j}"), sub(old, mul(a.clone(), hkj)));
                h.insert((i, j), new);
            }
            h.insert((k, i), a);
        }
    }
    Ok(inv_d)
}

/// The outputs `Minv[a][c]`, `a, c = 1..=nq` row by row, from the factors of [`factor`]:
/// `M⁻¹ = L⁻¹ D⁻¹ L⁻ᵀ = Uᵀ D⁻¹ U` with `U = L⁻ᵀ`, whose column `a` is nonzero only on `a` and
/// its ancestors (no fill-in on a tree), so `M⁻¹[a][c] = Σ U[i][a] U[i][c] / D[i]` over the
/// common ancestors-or-self `i` of `a` and `c`. Column `a` of `U` is `L⁻ᵀ e_a` by the
/// substitution of [`ltdl_by`] on a unit vector: `dₐ(dₐ − 1)/2` multiply–adds for `a` at
/// depth `dₐ` (no op where the unit's 1 multiplies); each entry of the upper triangle then
/// costs one multiply–add per common ancestor, and the lower one is a copy (0 ops).
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per column).
fn inverse(
    b: &mut Builder,
    h: &FxHashMap<(usize, usize), Term>,
    inv_d: &[Term],
    lambda: &[usize],
    factors: bool,
) -> Result<(), Stopped> {
    let nq = lambda.len() - 1;
    let at = |k: usize| Reached::Row { row: k, rows: nq };
    let one = Term::C(1.0);
    // `u[a]`: column `a` of `U` as (ancestor-or-self `i`, U[i][a]), `a` first; `w[a]` the
    // same entries times `1/D[i]`.
    let mut u: Vec<Vec<(usize, Term)>> = vec![Vec::new(); nq + 1];
    let mut w: Vec<Vec<(usize, Term)>> = vec![Vec::new(); nq + 1];
    for a in 1..=nq {
        b.check_at(at(a))?;
        let path: Vec<usize> = std::iter::once(a).chain(ancestors(lambda, a)).collect();
        let mut x: FxHashMap<usize, Term> = FxHashMap::default();
        x.insert(a, one.clone());
        for &i in &path {
            let xi = x.remove(&i).unwrap_or(ZERO);
            let xi = if i == a { xi } else { b.bind(&format!("U{i}_{a}"), xi) };
            for j in ancestors(lambda, i) {
                if let Some(l) = h.get(&(i, j)) {
                    let old = x.remove(&j).unwrap_or(ZERO);
                    x.insert(j, sub(old, mul(l.clone(), xi.clone())));
                }
            }
            u[a].push((i, xi));
        }
        for (i, t) in &u[a] {
            let scaled = mul(t.clone(), inv_d[*i].clone());
            w[a].push((*i, b.bind(&format!("W{i}_{a}"), scaled)));
        }
    }
    let mut mark: Vec<Option<Term>> = vec![None; nq + 1];
    let mut upper: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    for (a, wa) in w.iter().enumerate().skip(1) {
        b.check_at(at(a))?;
        for (i, t) in wa {
            mark[*i] = Some(t.clone());
        }
        for (c, uc) in u.iter().enumerate().skip(a) {
            let terms = uc.iter().filter_map(|(i, t)| mark[*i].clone().map(|x| mul(x, t.clone())));
            let t = crate::sym::sum(terms);
            upper.insert((a, c), b.bind(&format!("MI{a}_{c}"), t));
        }
        for (i, _) in wa {
            mark[*i] = None;
        }
    }
    for a in 1..=nq {
        for c in 1..=nq {
            let t = upper.get(&(a.min(c), a.max(c))).cloned().unwrap_or(ZERO);
            b.output_with(format!("Minv[{a}][{c}]"), || format!("Minv{a}_{c}"), t);
        }
    }
    if factors {
        // `U[i][a]` for the strict ancestors `i` of `a` (`U[a][a] = 1`), then `iD[i]` = 1/D[i].
        for (a, column) in u.iter().enumerate().skip(1) {
            for (i, t) in column.iter().filter(|(i, _)| *i != a) {
                b.output_with(format!("U[{i}][{a}]"), || format!("Uo{i}_{a}"), t.clone());
            }
        }
        for (i, t) in inv_d.iter().enumerate().skip(1) {
            b.output_with(format!("iD[{i}]"), || format!("iDo{i}"), t.clone());
        }
    }
    Ok(())
}

/// Writes `minv` (outputs `Minv[a][c]`, `a, c = 1..=nq`, both triangles; Pinocchio's
/// `computeMinverse`) into `b`: `M` by the CRBA, its `LᵀDL` (`factor`) and the product of the
/// inverted factors over common ancestors (`inverse`). Inputs: `q` (and the parameters).
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn minv(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let motions = motions(model, layout, b);
    let lambda = coordinate_parents(model, layout);
    let mut h: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    for ((i, j), t) in crba::mass_matrix(model, layout, b, &motions)? {
        h.insert((j, i), t);
    }
    let inv_d = factor(b, &mut h, &lambda)?;
    inverse(b, &h, &inv_d, &lambda, false)
}

/// Writes `fordyna` by the CRBA and `LᵀDL` (`ltdl_by`) and, from the same factors, `M⁻¹`
/// (`inverse`): outputs `qdd[1..nq]`, `Minv[a][c]`, then the factors of `M⁻¹ = Uᵀ D⁻¹ U`:
/// `U[i][a]` for each strict ancestor `i` of `a` and `iD[i] = 1/D[i]`. What the forward
/// dynamics' derivatives through the inverse dynamics read (`implicit.rs`).
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn fordyna_and_inverse(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    ltdl_with(model, layout, b, &mut crba_rnea(model, layout), true)
}

/// [`fordyna_and_inverse`] with `M` and `c` in the world frame of the analytical `∂τ`
/// ([`crate::rnea_derivatives::world_parts`]): what `aba_derivatives` shares its kinematics,
/// inertias and `r1 = Ic S` with the partials through (`implicit.rs`).
///
/// # Errors
/// [`Stopped`] at the builder's deadline.
pub fn world_fordyna_and_inverse(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    ltdl_with(model, layout, b, &mut crate::rnea_derivatives::world_parts(model, layout), true)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use robovec_ir::interp;

    use super::{fordyna_with, Formulation};
    use crate::topology::{build, Topology};
    use crate::{coordinate_parents, Model};

    /// Worst `|M qdd + c − Qq|∞ / |Qq|∞` over a few states, `qdd` from `fordyna`, `M` and `c`
    /// from `dirdyna` (an independent use of the same CRBA and RNEA: the factorisation and the
    /// substitutions are what is checked), parameters at their values, all other inputs drawn.
    fn residual(robot: &crate::robot::Robot, how: How) -> f64 {
        // Both in the robot's own frames, parameters at their values.
        let model = Model { robot: robot.clone() };
        let layout = crate::Layout::of(&model.robot);
        let params = layout.values.clone();
        let mut b = crate::sym::Builder::new("fordyna", Default::default());
        match how {
            How::Ops(how) => fordyna_with(&model, &layout, &mut b, how),
            How::Depth => crate::depth::fordyna(&model, &layout, &mut b),
            How::World => super::world_fordyna_and_inverse(&model, &layout, &mut b),
        }
        .expect("no deadline");
        let fd = &b.finish();
        let mut b = crate::sym::Builder::new("dirdyna", Default::default());
        crate::dirdyna::dirdyna(&model, &layout, &mut b).expect("no deadline");
        let dir = &b.finish();
        let nq = fd.outputs.iter().filter(|o| o.name.starts_with("qdd[")).count();
        assert_eq!(nq, layout.nv);
        let mut worst: f64 = 0.0;
        for seed in 1..=4u64 {
            let mut given: BTreeMap<String, f64> = params.clone();
            // (A free flyer's quaternion is drawn too, not of unit norm for the fewest-ops
            // formulation, where `M qdd + c = Qq` holds for any `R`; the depth formulation's
            // world-frame `M` and `c` assume a rotation, so there it is normalised.)
            for i in 1..=layout.nq {
                given.insert(format!("q[{i}]"), 3.0 * interp::pseudo_random_input(&format!("q[{i}]"), seed));
            }
            if matches!(how, How::Depth | How::World) && layout.nq > layout.nv {
                let n = (4..=7).map(|i| given[&format!("q[{i}]")].powi(2)).sum::<f64>().sqrt();
                (4..=7).for_each(|i| *given.get_mut(&format!("q[{i}]")).expect("drawn") /= n);
            }
            for i in 1..=nq {
                for v in ["qd", "Qq"] {
                    let name = format!("{v}[{i}]");
                    given.insert(name.clone(), 3.0 * interp::pseudo_random_input(&name, seed));
                }
            }
            for (k, x) in [0.3, -0.2, -9.81].iter().enumerate() {
                given.insert(format!("g[{}]", k + 1), *x);
            }
            let value = |name: &str| *given.get(name).unwrap_or_else(|| panic!("input {name} not given"));
            let qdd: BTreeMap<String, f64> = interp::eval::<f64>(fd, value).into_iter().collect();
            let mc: BTreeMap<String, f64> = interp::eval::<f64>(dir, value).into_iter().collect();
            let norm = (1..=nq).fold(0.0f64, |m, i| m.max(given[&format!("Qq[{i}]")].abs()));
            for i in 1..=nq {
                let lhs = (1..=nq).map(|j| mc[&format!("M[{i}][{j}]")] * qdd[&format!("qdd[{j}]")]).sum::<f64>()
                    + mc[&format!("c[{i}]")];
                worst = worst.max((lhs - given[&format!("Qq[{i}]")]).abs() / norm);
            }
        }
        worst
    }

    /// Which `fordyna` [`residual`] checks.
    #[derive(Clone, Copy, Debug)]
    enum How {
        /// The fewest-ops formulation's, formed so.
        Ops(Formulation),
        /// The depth formulation's ([`crate::depth::fordyna`]: its `M` and `c`, then `LᵀDL`).
        Depth,
        /// `M` and `c` in the analytical derivatives' world frame, with `M⁻¹`'s factors
        /// ([`super::world_fordyna_and_inverse`]).
        World,
    }

    /// `M qdd + c = Qq` to 1e-10 on every topology family (chains, branches, stars), on
    /// Robotran's floating base (a dense 6 × 6 block above every branch), on the free flyer (the
    /// same block, the ABA's 6 × 6 root solve) and with joints fixed
    /// between moving ones (coordinates whose parent is not the previous body); for the depth
    /// formulation's `fordyna` too, whose `M` and `c` are not the ones it is checked against
    /// (world-frame prefixes there, the body-frame CRBA and RNEA here), and for `M` and `c` in
    /// the analytical derivatives' world frame.
    #[test]
    fn forward_dynamics_inverts_the_mass_matrix() {
        for how in [How::Ops(Formulation::Ltdl), How::Ops(Formulation::Aba), How::Depth, How::World] {
            forward_dynamics_inverts_the_mass_matrix_by(how);
        }
    }

    fn forward_dynamics_inverts_the_mass_matrix_by(how: How) {
        for t in Topology::ALL {
            let r = build(t, 9, 3);
            let e = residual(&r, how);
            assert!(e <= 1e-10, "{how:?} {t}: residual {e:e}");
            // The base link gets a mass: a massless base turns with its first joint for free
            // (`M` singular), which no floating robot is.
            let mut massive = r.clone();
            let root = massive.root;
            massive.links[root].inertial = Some(crate::robot::Inertial {
                mass: 4.5,
                com: [0.05, -0.02, 0.1],
                inertia: [[0.3, 0.01, -0.02], [0.01, 0.25, 0.03], [-0.02, 0.03, 0.2]],
            });
            let floating = massive.clone().with_floating_base().unwrap();
            let e = residual(&floating, how);
            assert!(e <= 1e-10, "{how:?} {t} floating: residual {e:e}");
            let free = massive.with_free_flyer().unwrap();
            let e = residual(&free, how);
            assert!(e <= 1e-10, "{how:?} {t} free flyer: residual {e:e}");
        }
        let mut with_fixed = build(Topology::SemiSerial, 8, 5);
        with_fixed.joints[2].kind = crate::robot::JointKind::Fixed;
        with_fixed.joints[5].kind = crate::robot::JointKind::Fixed;
        let e = residual(&with_fixed, how);
        assert!(e <= 1e-10, "{how:?} fixed joints between moving ones: residual {e:e}");
    }

    /// `λ` by hand on a chain with a fixed joint, on Robotran's floating base and on the free
    /// flyer: the base's six coordinates are a chain and its children hang from coordinate 6.
    #[test]
    fn coordinate_parents_follow_the_tree() {
        let mut chain = build(Topology::Serial, 4, 1);
        chain.joints[1].kind = crate::robot::JointKind::Fixed;
        let layout = crate::Layout::of(&chain);
        // Joints 1, 3, 4 move: coordinates 1, 2, 3, each the child of the one before.
        assert_eq!(coordinate_parents(&Model { robot: chain.clone() }, &layout), [0, 0, 1, 2]);
        let floating = chain.clone().with_floating_base().unwrap();
        let layout = crate::Layout::of(&floating);
        assert_eq!(coordinate_parents(&Model { robot: floating }, &layout), [0, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
        // The free flyer: one joint, six coordinates in a chain; seven configuration ones.
        let free = chain.with_free_flyer().unwrap();
        let layout = crate::Layout::of(&free);
        assert_eq!((layout.nv, layout.nq), (9, 10));
        assert_eq!(layout.v_index, [Some(1), Some(7), None, Some(8), Some(9)]);
        assert_eq!(layout.q_index, [Some(1), Some(8), None, Some(9), Some(10)]);
        assert_eq!(coordinate_parents(&Model { robot: free }, &layout), [0, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
    }

    /// `Σ d(d − 1)` by hand: a chain of 4 (depths 1..4: 0 + 2 + 6 + 12) and a star of three
    /// branches off coordinate 1 (depths 1, 2, 2, 2: 0 + 2 + 2 + 2).
    #[test]
    fn factorisation_ops_count_the_updates() {
        assert_eq!(super::factorisation_ops(&[0, 0, 1, 2, 3]), 20);
        assert_eq!(super::factorisation_ops(&[0, 0, 1, 1, 1]), 6);
    }

    /// The fewer ops win (counted after `atomise,cse`): the factorisation on a short chain (9
    /// joints), the ABA on a long one (60 joints: the factorisation grows as the cube of the
    /// depth, the ABA linearly), and `Fewest` writes exactly the smaller of the two.
    #[test]
    fn the_formulation_with_fewer_ops_is_kept() {
        let ops = |robot: &crate::robot::Robot, how: Formulation| {
            let model = Model { robot: robot.clone() };
            let layout = crate::Layout::of(&model.robot);
            let mut b = crate::sym::Builder::new("fordyna", Default::default());
            fordyna_with(&model, &layout, &mut b, how).expect("no deadline");
            b.ops_after_cse()
        };
        for (dof, ltdl_wins) in [(9, true), (60, false)] {
            let r = build(Topology::Serial, dof, 1);
            let (l, a, f) = (ops(&r, Formulation::Ltdl), ops(&r, Formulation::Aba), ops(&r, Formulation::Fewest));
            assert_eq!(l < a, ltdl_wins, "serial {dof}: LTDL {l} ops, ABA {a}");
            assert_eq!(f, l.min(a), "serial {dof}");
        }
    }
}
