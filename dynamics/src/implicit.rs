//! The forward dynamics' derivatives through the inverse dynamics' (issue 50 item 2: "∂q̈ =
//! −M⁻¹ ∂(τ_ID)/∂(q, v) at q̈ reuses the factors instead of recomputing them").
//!
//! `fordyna` solves `M(q) q̈ = τ − c(q, v)`. Differentiating that identity at the solution gives
//! `∂q̈/∂q = −M⁻¹ · ∂τ_ID/∂q` and `∂q̈/∂v = −M⁻¹ · ∂τ_ID/∂v`, the partials of the inverse
//! dynamics `τ_ID(q, v, a)` taken at `a = q̈` (Carpentier & Mansard, RSS 2018, §IV; Pinocchio's
//! `computeABADerivatives` does the same), and `∂q̈/∂τ = M⁻¹`. [`aba_derivatives`] writes that
//! function: `fordyna` by the `LᵀDL` with `M⁻¹` from the same factors
//! ([`crate::fordyna::fordyna_and_inverse`]: `q̈` and `M⁻¹` share the CRBA and the
//! factorisation; or [`crate::fordyna::world_fordyna_and_inverse`], whose `M` and `c` are
//! written as the analytical partials write their kinematics and inertias, so that `cse` merges
//! them: the generator tries both), the partials of the inverse dynamics (the `rnea_derivatives` the generator
//! kept, rows along the tangent space) with their `qdd` inputs read from `q̈`, and the two
//! products `−M⁻¹ · ∂τ_ID` by the factors, `−Uᵀ·(D⁻¹·(U·x))` per column `x` (`U = L⁻ᵀ` has
//! entries only on ancestors: about `4·Σ(dₖ + 1) + nv` ops a column for coordinates at depth
//! `dₖ`, against `2nv²` for a dense `M⁻¹`; structural zeros skipped).
//!
//! Which of this and `diff` through the whole of `fordyna` has fewer ops depends on the robot:
//! the products grow as `nv·Σ dₖ`, `diff` through the factorisation roughly as ops × inputs. The
//! generator writes both and keeps the smaller (`crate::generate_with`); likewise for `minv`,
//! `diff` along `τ` or the inverted factors ([`crate::fordyna::minv`], through [`compact`]).

use std::collections::{BTreeMap, HashMap};

use robovec_ir::time_limit::Ticker;
use robovec_ir::transform::{atomise, cse};
use robovec_ir::{Def, Function, Operand, Span};

use crate::tangent::Ops;

/// Names of the values this module writes.
const PREFIX: &str = "implicit";

/// `f` atomised with its repeated ops merged (`atomise,cse`): how the generator's derivative
/// functions are handed on, so that their ops compare. `None` at the ticker's stop.
pub(crate) fn compact(f: &Function, ticker: &Ticker) -> Option<Function> {
    let mut f = atomise::atomise_until(f, ticker)?;
    cse::cse_within(&mut f, ticker);
    Some(f)
}

/// `aba_derivatives` as `−M⁻¹ · ∂τ_ID` (module doc): `partials` the same robot's
/// `rnea_derivatives` (atomised; outputs `dtau_dq[i][j]`, `dtau_dv[i][j]` along the tangent
/// space, inputs `q`, `qd`, `qdd`), `solved` its `fordyna` with `M⁻¹`
/// ([`crate::fordyna::fordyna_and_inverse`]: outputs `qdd[i]`, `Minv[i][j]`). Outputs
/// `ddq_dq[i][j]`, `ddq_dv[i][j]` and `Minv[i][j]` (`i, j = 1..=nv`), row by row as `diff`
/// groups them. `None` at the ticker's stop.
pub(crate) fn aba_derivatives(partials: &Function, solved: &Function, ticker: &Ticker) -> Option<Function> {
    let mut f = compact(solved, ticker)?;
    // q̈ and M⁻¹.
    let outputs = std::mem::take(&mut f.outputs);
    let qdd: HashMap<String, Operand> =
        outputs.iter().filter(|o| o.name.starts_with("qdd[")).map(|o| (o.name.clone(), o.value)).collect();
    let minv = matrix(outputs.iter().map(|o| (o.name.as_str(), o.value)), "Minv");
    // The partials' body, appended: `qdd[i]` is q̈, every other input `fordyna`'s own.
    let mut map: Vec<Option<Operand>> = vec![None; partials.values.len()];
    for &v in &partials.inputs {
        let name = partials.name_of(v);
        map[v.index()] = Some(match qdd.get(name) {
            Some(&x) => x,
            None => Operand::Value(match f.lookup(name) {
                Some(x) => x,
                None => f.add_input(name.to_string(), Span::DUMMY).expect("a free name"),
            }),
        });
    }
    let at = |map: &[Option<Operand>], x: Operand| match x {
        Operand::Value(v) => map[v.index()].expect("defined before use"),
        c => c,
    };
    let mut count = 0;
    // The trig variables `f` has (`C1 = cos q[1]`): the partials' own are these, or are added
    // under their own names (`C4`, `S4`: what `trig=input` and the reports read them by).
    let mut trig: HashMap<(robovec_ir::TrigFn, robovec_ir::Value), robovec_ir::Value> = f
        .body
        .iter()
        .filter_map(|&v| match f.value(v).def {
            Def::Trig(t, x) => Some(((t, x), v)),
            _ => None,
        })
        .collect();
    for &v in &partials.body {
        if let Def::Trig(t, x) = partials.value(v).def {
            let Operand::Value(y) = at(&map, Operand::Value(x)) else { unreachable!("a trig variable of a constant") };
            let existing = trig.get(&(t, y)).copied();
            let value = existing.unwrap_or_else(|| {
                let name = partials.name_of(v);
                let def = Def::Trig(t, y);
                let made = if f.lookup(name).is_none() {
                    f.define(name.to_string(), def, Span::DUMMY).expect("a free name")
                } else {
                    f.define_counted(PREFIX, &mut count, def, Span::DUMMY)
                };
                trig.insert((t, y), made);
                made
            });
            map[v.index()] = Some(Operand::Value(value));
            continue;
        }
        let def = match &partials.value(v).def {
            Def::Binary(o, a, b) => Def::Binary(*o, at(&map, *a), at(&map, *b)),
            Def::Trig(..) => unreachable!("handled above"),
            Def::Call(callee, args) => Def::Call(callee.clone(), args.iter().map(|&a| at(&map, a)).collect()),
            Def::Input | Def::Expr(_) => unreachable!("an atomised body"),
        };
        map[v.index()] = Some(Operand::Value(f.define_counted(PREFIX, &mut count, def, Span::DUMMY)));
    }
    let renamed = partials.outputs.iter().map(|o| (o.name.as_str(), at(&map, o.value)));
    let renamed: Vec<(&str, Operand)> = renamed.collect();
    let dq = matrix(renamed.iter().copied(), "dtau_dq");
    let dv = matrix(renamed.iter().copied(), "dtau_dv");
    let nv = qdd.len();
    // M⁻¹·x as Uᵀ·(D⁻¹·(U·x)) by the factors: `U[i][a]` only for `i` an ancestor-or-self of `a`.
    let factors = matrix(outputs.iter().map(|o| (o.name.as_str(), o.value)), "U");
    let inv_d: Vec<Operand> = (1..=nv)
        .map(|i| outputs.iter().find(|o| o.name == format!("iD[{i}]")).map(|o| o.value).expect("iD written"))
        .collect();
    let mut below: Vec<Vec<(usize, Operand)>> = vec![Vec::new(); nv + 1];
    let mut above: Vec<Vec<(usize, Operand)>> = vec![Vec::new(); nv + 1];
    for a in 1..=nv {
        below[a].push((a, Operand::Const(1.0)));
        above[a].push((a, Operand::Const(1.0)));
    }
    for (&(i, a), &u) in &factors {
        below[i].push((a, u));
        above[a].push((i, u));
    }
    let mut w = Ops::new(&mut f, PREFIX);
    let neg_inv_d: Vec<Operand> = inv_d.iter().map(|&d| w.op(robovec_ir::BinOp::Sub, Operand::Const(0.0), d)).collect();
    let entry = |m: &BTreeMap<(usize, usize), Operand>, i, j| m.get(&(i, j)).copied().unwrap_or(Operand::Const(0.0));
    // Column j of −M⁻¹·X for X = ∂τ/∂q, ∂τ/∂v.
    let mut columns: BTreeMap<(&str, usize), Vec<Operand>> = BTreeMap::new();
    for (name, d) in [("ddq_dq", &dq), ("ddq_dv", &dv)] {
        for j in 1..=nv {
            let y: Vec<Operand> = (1..=nv)
                .map(|i| {
                    let terms: Vec<(Operand, Operand, bool)> =
                        below[i].iter().map(|&(a, u)| (u, entry(d, a, j), false)).collect();
                    let s = w.dot(&terms);
                    w.op(robovec_ir::BinOp::Mul, neg_inv_d[i - 1], s)
                })
                .collect();
            let out: Vec<Operand> = (1..=nv)
                .map(|a| {
                    let terms: Vec<(Operand, Operand, bool)> =
                        above[a].iter().map(|&(i, u)| (u, y[i - 1], false)).collect();
                    w.dot(&terms)
                })
                .collect();
            columns.insert((name, j), out);
        }
    }
    for i in 1..=nv {
        for name in ["ddq_dq", "ddq_dv"] {
            for j in 1..=nv {
                w.f.set_output(format!("{name}[{i}][{j}]"), columns[&(name, j)][i - 1], Span::DUMMY);
            }
        }
        for j in 1..=nv {
            w.f.set_output(format!("Minv[{i}][{j}]"), entry(&minv, i, j), Span::DUMMY);
        }
    }
    let live = f.live_values(&[]);
    f.retain(|_, v| live[v.index()]);
    cse::cse_within(&mut f, ticker);
    f.name = "aba_derivatives".to_string();
    Some(f)
}

/// The entries `family[i][j]` among `outputs`, by `(i, j)`.
fn matrix<'a>(outputs: impl Iterator<Item = (&'a str, Operand)>, family: &str) -> BTreeMap<(usize, usize), Operand> {
    outputs
        .filter_map(|(name, value)| {
            let rest = name.strip_prefix(family)?.strip_prefix('[')?.strip_suffix(']')?;
            let (i, j) = rest.split_once("][")?;
            Some(((i.parse().ok()?, j.parse().ok()?), value))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use robovec_ir::time_limit::Ticker;

    use crate::depth::tests::worst_relative;
    use crate::robot::JointKind;
    use crate::sym::Builder;
    use crate::topology::{build, Topology};
    use crate::{Layout, Model, Writer};

    /// One function written by `write`, parameters as inputs.
    fn written(model: &Model, layout: &Layout, name: &str, write: Writer) -> robovec_ir::Function {
        let mut b = Builder::new(name, Default::default());
        write(model, layout, &mut b).expect("no deadline");
        b.finish()
    }

    /// `aba_derivatives` as `−M⁻¹·∂τ_ID` with either `fordyna` (the body frames' CRBA and RNEA,
    /// or `M` and `c` in the analytical partials' frame) equals `diff` through the whole of
    /// `fordyna` (an independent formulation, mapped to the tangent space) within 1e-9, on
    /// branches off a fixed base, a chain with prismatic joints and a free flyer over branches.
    #[test]
    fn aba_derivatives_agree_across_formulations() {
        let mut prismatic = build(Topology::Serial, 6, 7);
        for (k, j) in prismatic.joints.iter_mut().enumerate() {
            if k % 2 == 1 && j.kind == JointKind::Revolute {
                j.kind = JointKind::Prismatic;
                j.continuous = false;
            }
        }
        // A free base needs a mass of its own (a massless one turns with its first joint for
        // free: `M` singular).
        let mut floating = build(Topology::SemiSerial, 7, 3);
        let root = floating.root;
        floating.links[root].inertial = Some(crate::robot::Inertial {
            mass: 4.5,
            com: [0.05, -0.02, 0.1],
            inertia: [[0.3, 0.01, -0.02], [0.01, 0.25, 0.03], [-0.02, 0.03, 0.2]],
        });
        let cases = [
            ("semi-serial 8", build(Topology::SemiSerial, 8, 2)),
            ("serial 6, prismatic", prismatic),
            ("semi-serial 7, free flyer", floating.with_free_flyer().expect("free names")),
        ];
        let ticker = Ticker::new(None, None);
        for (label, robot) in cases {
            let model = Model { robot: robot.clone() };
            let layout = Layout::of(&robot);
            let partials = super::compact(
                &written(&model, &layout, "rnea_derivatives", crate::rnea_derivatives::rnea_derivatives),
                &ticker,
            )
            .expect("no deadline");
            let coords = crate::tangent::coordinates(&robot, &layout);
            let fordyna = written(&model, &layout, "fordyna", crate::fordyna::fordyna);
            let by_diff =
                crate::derive(&fordyna, &crate::DERIVED[1], &layout, coords.as_deref(), &ticker).expect("no deadline");
            for solve in [crate::fordyna::fordyna_and_inverse as Writer, crate::fordyna::world_fordyna_and_inverse] {
                let solved = written(&model, &layout, "aba_derivatives", solve);
                let f = super::aba_derivatives(&partials, &solved, &ticker).expect("no deadline");
                assert_eq!(f.outputs.len(), 3 * layout.nv * layout.nv, "{label}");
                let e = worst_relative(&robot, &f, &by_diff, true);
                assert!(e <= 1e-9, "{label}: {e:e}");
            }
        }
    }
}
