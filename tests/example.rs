//! The shipped example `examples/double_pendulum/mbs_invdyna_double_pendulum.c` (hand-derived
//! RNEA in Robotran 6.6's C format) against an independent closed-form Lagrangian model of the
//! planar double pendulum: M(q) q̈ + C(q, q̇) q̇ + G(q) = Qq. Conventions (joint axes x, links
//! along body y, gravity vector (0, 0, g[3])) are in `examples/double_pendulum/README.md`.

use std::collections::HashMap;

use robovec_ir::rng::SplitMix64;
use robovec_ir::{interp, verifier, Function, Phase};
use robovec_passes::atomise::atomise_function;

fn example_path() -> String {
    format!("{}/examples/double_pendulum/mbs_invdyna_double_pendulum.c", env!("CARGO_MANIFEST_DIR"))
}

/// Uniform in [lo, hi).
fn range(rng: &mut SplitMix64, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * rng.unit()
}

/// One sampled state and parameter set, by canonical input name (SPEC §2).
fn sample(rng: &mut SplitMix64) -> HashMap<&'static str, f64> {
    let pi = std::f64::consts::PI;
    HashMap::from([
        ("q[1]", range(rng, -pi, pi)),
        ("q[2]", range(rng, -pi, pi)),
        ("qd[1]", range(rng, -3.0, 3.0)),
        ("qd[2]", range(rng, -3.0, 3.0)),
        ("qdd[1]", range(rng, -5.0, 5.0)),
        ("qdd[2]", range(rng, -5.0, 5.0)),
        ("m[1]", range(rng, 0.1, 5.0)),
        ("m[2]", range(rng, 0.1, 5.0)),
        ("l[2][1]", range(rng, 0.05, 1.5)),
        ("l[2][2]", range(rng, 0.05, 1.5)),
        ("dpt[2][2]", range(rng, 0.1, 2.0)),
        ("In[1][1]", range(rng, 0.01, 1.0)),
        ("In[1][2]", range(rng, 0.01, 1.0)),
        ("g[3]", range(rng, -12.0, 12.0)),
    ])
}

/// The Lagrangian model, written independently of the RNEA in the C file.
fn lagrange(x: &HashMap<&'static str, f64>) -> [f64; 2] {
    let (q1, q2) = (x["q[1]"], x["q[2]"]);
    let (qd1, qd2) = (x["qd[1]"], x["qd[2]"]);
    let (qdd1, qdd2) = (x["qdd[1]"], x["qdd[2]"]);
    let (m1, m2) = (x["m[1]"], x["m[2]"]);
    let (l1, l2, d) = (x["l[2][1]"], x["l[2][2]"], x["dpt[2][2]"]);
    let (i1, i2) = (x["In[1][1]"], x["In[1][2]"]);
    let g3 = x["g[3]"];
    // Centres of mass in the base y–z plane: p1 = l1 (c1, s1), p2 = d (c1, s1) + l2 (c12, s12).
    // T = ½ m1 l1² q̇1² + ½ I1 q̇1² + ½ m2 |ṗ2|² + ½ I2 (q̇1 + q̇2)²,  V = −g3 (m1 p1z + m2 p2z).
    let (c1, c2, s2, c12) = (q1.cos(), q2.cos(), q2.sin(), (q1 + q2).cos());
    let m11 = m1 * l1 * l1 + i1 + m2 * (d * d + l2 * l2 + 2.0 * d * l2 * c2) + i2;
    let m12 = m2 * (l2 * l2 + d * l2 * c2) + i2;
    let m22 = m2 * l2 * l2 + i2;
    let h = m2 * d * l2 * s2;
    let g1 = -g3 * (m1 * l1 * c1 + m2 * (d * c1 + l2 * c12));
    let g2 = -g3 * m2 * l2 * c12;
    [m11 * qdd1 + m12 * qdd2 - h * (2.0 * qd1 * qd2 + qd2 * qd2) + g1, m12 * qdd1 + m22 * qdd2 + h * qd1 * qd1 + g2]
}

fn outputs(f: &Function, x: &HashMap<&'static str, f64>) -> HashMap<String, f64> {
    interp::eval::<f64>(f, |name| *x.get(name).unwrap_or_else(|| panic!("unexpected input `{name}`")))
        .into_iter()
        .collect()
}

fn load_example() -> Function {
    let (module, _src) = match robovec::driver::load(&example_path()) {
        Ok(x) => x,
        Err(e) => panic!("the example does not load:\n{}", e.message()),
    };
    assert_eq!(module.functions.len(), 1, "one function expected");
    module.functions.into_iter().next().unwrap()
}

#[test]
fn example_loads_with_expected_inputs_and_ops() {
    let f = load_example();
    assert_eq!(f.phase, Phase::Parsed);
    let mut inputs: Vec<&str> = f.inputs.iter().map(|&v| f.name_of(v)).collect();
    inputs.sort_unstable();
    let mut want = vec![
        "In[1][1]",
        "In[1][2]",
        "dpt[2][2]",
        "g[3]",
        "l[2][1]",
        "l[2][2]",
        "m[1]",
        "m[2]",
        "q[1]",
        "q[2]",
        "qd[1]",
        "qd[2]",
        "qdd[1]",
        "qdd[2]",
    ];
    want.sort_unstable();
    assert_eq!(inputs, want);
    let outs: Vec<&str> = f.outputs.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(outs, ["Qq[1]", "Qq[2]"]);

    let a = atomise_function(&f);
    assert!(verifier::verify_function(&a).is_empty(), "atomised example does not verify");
    // Counted by hand with SPEC §3 (see docs/rewrites.md: 4 `0 - t`, one `-` in ALPHA32).
    let c = a.op_counts();
    assert_eq!((c.add, c.sub, c.mul, c.div, c.call, c.total), (16, 5, 27, 0, 0, 48));
}

#[test]
fn example_matches_lagrangian_model() {
    let f = load_example();
    let a = atomise_function(&f);
    assert!(verifier::verify_function(&a).is_empty(), "atomised example does not verify");
    let mut rng = SplitMix64::new(0x5eed_d0b1_e9e7_d01d);
    for k in 0..64 {
        let x = sample(&mut rng);
        let want = lagrange(&x);
        let parsed = outputs(&f, &x);
        let atomised = outputs(&a, &x);
        for (i, w) in want.iter().enumerate() {
            let name = format!("Qq[{}]", i + 1);
            let p = parsed[&name];
            let t = atomised[&name];
            // Parsed and atomised compute the same operations in the same order; only the sign
            // of a zero could differ (`-t` vs `0 - t`), so ±0 count as equal.
            assert!(
                p.to_bits() == t.to_bits() || (p == 0.0 && t == 0.0),
                "sample {k}, {name}: parsed {p:e} vs atomised {t:e}"
            );
            let tol = 1e-12 * w.abs().max(1.0);
            assert!((p - w).abs() <= tol, "sample {k}, {name}: IR {p:e} vs Lagrangian {w:e} (diff {:e})", p - w);
        }
    }
}
