//! Forward dynamics `qdd = M(q)⁻¹ (Qq − c(q, qd, g))` of a tree (Pinocchio's `aba`): inputs
//! `q`, `qd`, the generalised forces `Qq` and `g`; outputs `qdd[1..nq]`.
//!
//! # Formulation: CRBA, then the sparse LᵀDL factorisation of `M`
//! - `M` by the composite-rigid-body algorithm ([`super::crba`], as `dirdyna`), `c` by one RNEA
//!   sweep with `qdd = 0` ([`super::rnea::sweep`]), the right-hand side `Qq − c`;
//! - `M = Lᵀ D L` by Featherstone's factorisation for branched trees (R. Featherstone,
//!   "Efficient factorization of the joint-space inertia matrix for branched kinematic trees",
//!   *Int. J. Robotics Research* 24(6), 2005; *Rigid Body Dynamics Algorithms*, 2008, §6.5,
//!   algorithm "LTDL"): `L` is unit lower triangular and has an entry `L[k][i]` only where
//!   coordinate `i` is an ancestor of `k` in the tree (the parent array `λ` of
//!   [`crate::coordinate_parents`]), so the factorisation writes no fill-in and costs
//!   `Σₖ dₖ²/2` multiply–adds for a coordinate at depth `dₖ`; one division per coordinate
//!   (`1/D[k]`, bound once);
//! - `qdd = L⁻¹ D⁻¹ L⁻ᵀ (Qq − c)` by the two sparse substitutions of the same reference.
//!
//! # Why not the articulated-body algorithm (yet)
//! ABA is O(n) in the coordinates where this is O(Σ dₖ²): on a long chain (depth = n) ABA wins
//! and this formulation grows as n³/6 (a 2,000-joint chain would write billions of ops; the
//! generator's deadline stops it). On the robots users bring (arms, legs and humanoids: depth
//! at most about 8 below the base) the factorisation costs a few hundred ops on top of `M` and
//! `c`, which `dirdyna` already writes, and reuses the CRBA whose op count the generator has
//! been tuned on; ABA, which the issue allows by measurement, is the next formulation to
//! measure against it. Counts (symbolic parameters, `-passes=atomise,cse -stats`) are in
//! `docs/generator.md` ("Forward dynamics"): `fordyna` costs 5–40 % more ops than `dirdyna`.
//!
//! The matrix `M` is never an output here: its entries are temporaries the factorisation
//! overwrites in place, as `H` is in Featherstone's algorithm.

use rustc_hash::FxHashMap;

use robovec_ir::{BinOp, Def, Expr, Operand, Span};

use super::crba;
use super::rnea::{motions, sweep, Drive};
use super::sym::{mul, sub, to_expr, Builder, Term, ZERO};
use super::{coordinate_parents, Layout, Model, Reached, Stopped};

/// `1 / D[k]`: `D[k]` bound as `D{k}`, its reciprocal as `iD{k}` (a number stays a number).
fn reciprocal(b: &mut Builder, k: usize, d: Term) -> Term {
    let d = match d {
        Term::C(x) => return Term::C(1.0 / x),
        d => b.bind(&format!("D{k}"), d),
    };
    let e = Expr::Binary(BinOp::Div, Box::new(Expr::Operand(Operand::Const(1.0))), Box::new(to_expr(&d)));
    let n = b.f.fresh_name(&format!("iD{k}"));
    Term::V(b.f.define(n, Def::Expr(e), Span::DUMMY).expect("fresh"))
}

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

/// Writes `fordyna` (outputs `qdd[1..nq]`) into `b`.
///
/// # Errors
/// [`Stopped`] at the builder's deadline (checked per body of the recursions and per
/// coordinate of the factorisation and the substitutions).
pub fn fordyna(model: &Model, layout: &Layout, b: &mut Builder) -> Result<(), Stopped> {
    let nq = layout.q_index.iter().flatten().count();
    let drive = Drive::inputs(b, nq, false);
    let forces: Vec<Term> = (1..=nq).map(|i| b.input(&format!("Qq[{i}]"))).collect();
    let motions = motions(model, layout, b);
    let lambda = coordinate_parents(model, layout);
    // `H[k][i]` for `i` an ancestor of `k` or `k` itself (1-based), from `M`'s upper triangle.
    let mut h: FxHashMap<(usize, usize), Term> = FxHashMap::default();
    for ((i, j), t) in crba::mass_matrix(model, layout, b, &motions)? {
        h.insert((j, i), t);
    }
    let mut x = forces;
    for (qi, t) in sweep(model, layout, b, &motions, &drive)? {
        let r = sub(std::mem::take(&mut x[qi - 1]), t);
        x[qi - 1] = b.bind(&format!("QC{qi}"), r);
    }
    let ancestors = |k: usize| ancestors(&lambda, k);
    let at = |k: usize| Reached::Row { row: k, rows: nq };
    // LᵀDL, leaves to root (Featherstone 2005, Table 2): `H[k][i]` becomes `L[k][i]`, `H[k][k]`
    // stays `D[k]`.
    let mut inv_d: Vec<Term> = vec![ZERO; nq + 1];
    for k in (1..=nq).rev() {
        b.check_at(at(k))?;
        let d = h.remove(&(k, k)).unwrap_or(ZERO);
        inv_d[k] = reciprocal(b, k, d);
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
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use robovec_ir::interp;

    use crate::topology::{build, Topology};
    use crate::{coordinate_parents, generate_with, Model, Request};

    /// Worst `|M qdd + c − Qq|∞ / |Qq|∞` over a few states, `qdd` from `fordyna`, `M` and `c`
    /// from `dirdyna` (an independent use of the same CRBA and RNEA: the factorisation and the
    /// substitutions are what is checked), parameters at their values, all other inputs drawn.
    fn residual(robot: &crate::robot::Robot) -> f64 {
        let request = Request { functions: Some(vec!["dirdyna".into(), "fordyna".into()]), ..Request::default() };
        let g = generate_with(&Model { robot: robot.clone() }, &request).expect("no deadline");
        let params = g.params.expect("symbolic parameters");
        let (dir, fd) = (g.module.function("dirdyna").unwrap(), g.module.function("fordyna").unwrap());
        let nq = fd.outputs.len();
        let mut worst: f64 = 0.0;
        for seed in 1..=4u64 {
            let mut given: BTreeMap<String, f64> = params.clone();
            for i in 1..=nq {
                for v in ["q", "qd", "Qq"] {
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

    /// `M qdd + c = Qq` to 1e-10 on every topology family (chains, branches, stars), on
    /// Robotran's floating base (a dense 6 × 6 block above every branch) and with joints fixed
    /// between moving ones (coordinates whose parent is not the previous body).
    #[test]
    fn forward_dynamics_inverts_the_mass_matrix() {
        for t in Topology::ALL {
            let r = build(t, 9, 3);
            let e = residual(&r);
            assert!(e <= 1e-10, "{t}: residual {e:e}");
            // The base link gets a mass: a massless base turns with its first joint for free
            // (`M` singular), which no floating robot is.
            let mut massive = r.clone();
            let root = massive.root;
            massive.links[root].inertial = Some(crate::robot::Inertial {
                mass: 4.5,
                com: [0.05, -0.02, 0.1],
                inertia: [[0.3, 0.01, -0.02], [0.01, 0.25, 0.03], [-0.02, 0.03, 0.2]],
            });
            let floating = massive.with_floating_base().unwrap();
            let e = residual(&floating);
            assert!(e <= 1e-10, "{t} floating: residual {e:e}");
        }
        let mut with_fixed = build(Topology::SemiSerial, 8, 5);
        with_fixed.joints[2].kind = crate::robot::JointKind::Fixed;
        with_fixed.joints[5].kind = crate::robot::JointKind::Fixed;
        let e = residual(&with_fixed);
        assert!(e <= 1e-10, "fixed joints between moving ones: residual {e:e}");
    }

    /// `λ` by hand on a chain with a fixed joint and on Robotran's floating base: the base's
    /// six coordinates are a chain and its children hang from `R3` (coordinate 6).
    #[test]
    fn coordinate_parents_follow_the_tree() {
        let mut chain = build(Topology::Serial, 4, 1);
        chain.joints[1].kind = crate::robot::JointKind::Fixed;
        let layout = crate::Layout::of(&chain);
        // Joints 1, 3, 4 move: coordinates 1, 2, 3, each the child of the one before.
        assert_eq!(coordinate_parents(&Model { robot: chain.clone() }, &layout), [0, 0, 1, 2]);
        let floating = chain.with_floating_base().unwrap();
        let layout = crate::Layout::of(&floating);
        assert_eq!(coordinate_parents(&Model { robot: floating }, &layout), [0, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
    }
}
