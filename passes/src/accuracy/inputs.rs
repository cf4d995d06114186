//! Input points for the accuracy measurement: physical ranges per canonical input name
//! (SPEC §2), sampled and hard points, and the `params=FILE.json` of known values.
//!
//! # Ranges (sampled mode)
//! | inputs | range | unit, why |
//! |---|---|---|
//! | `q[i]` | [−π, π] uniform | rad, joint coordinates (prismatic joints get the same numbers) |
//! | `qd[i]`, `qdd[i]` | [−10, 10] uniform | rad/s, rad/s² |
//! | `dpt[k][j]`, `l[k][b]` | [−1, 1] uniform | m, joint anchor and centre-of-mass vectors |
//! | `m[b]` | [0.1, 100] log-uniform | kg |
//! | `In[k][b]`, k ∈ {1, 5, 9} | [10⁻³, 10] log-uniform | kg·m², diagonal of the inertia tensor |
//! | `In[k][b]`, other k | [−10⁻², 10⁻²] uniform | kg·m², products of inertia |
//! | `g[k]` | [−10, 10] uniform | m/s² |
//! | `frc[k][b]`, `trq[k][b]` | [−100, 100] uniform | N, N·m |
//! | `lrod[i]` | [0.1, 2] uniform | m |
//! | `tsim` | [0, 10] uniform | s |
//! | anything else | [−1, 1] uniform | — |
//!
//! Every sampled value is rounded to binary32, so the binary32 and binary64 evaluations and the
//! reference all see the same input values and the measured error is the arithmetic's alone.
//! Values from a `params` file are used as given; the binary32 evaluation then rounds them, as
//! the FPGA would, and that input rounding is part of its error.
//!
//! # Hard points (`mode=hard`)
//! - `q[i]`: one of 0, ±π/2, ±π (singular poses of revolute chains), exactly (¼ of the time)
//!   or plus a perturbation of magnitude 2⁻³⁰ … 2⁻⁸ (log-uniform, random sign);
//! - `qd[i]`, `qdd[i]`: magnitude 10 … 1000 log-uniform, random sign;
//! - every parameter: a sampled value times 10^k, k uniform in {−3, …, 2} (six orders of
//!   magnitude);
//! - `tsim`: [0, 1000] s.

use std::collections::BTreeMap;

use robovec_ir::rng::SplitMix64;

/// Family of an input, from its canonical name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// `q[i]`
    Angle,
    /// `qd[i]`, `qdd[i]`
    Rate,
    /// A model parameter (lengths, masses, inertias, gravity, forces).
    Parameter,
    /// `tsim`
    Time,
}

/// How one input is sampled: `[lo, hi]`, uniformly or log-uniformly (then `0 < lo`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Family.
    pub family: Family,
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Log-uniform when true.
    pub log: bool,
}

/// The array name and first index of a canonical name: `In[5][17]` → (`In`, Some(5)).
fn split_name(name: &str) -> (&str, Option<u32>) {
    match name.find('[') {
        Some(i) => {
            let first = name[i + 1..].split(']').next().and_then(|x| x.parse().ok());
            (&name[..i], first)
        }
        None => (name, None),
    }
}

/// The sampling range of input `name` (table in the module doc).
pub fn range_of(name: &str) -> Range {
    use std::f64::consts::PI;
    let r = |family, lo, hi, log| Range { family, lo, hi, log };
    let (base, k) = split_name(name);
    match base {
        "q" => r(Family::Angle, -PI, PI, false),
        "qd" | "qdd" => r(Family::Rate, -10.0, 10.0, false),
        "dpt" | "l" => r(Family::Parameter, -1.0, 1.0, false),
        "m" => r(Family::Parameter, 0.1, 100.0, true),
        "In" if matches!(k, Some(1 | 5 | 9)) => r(Family::Parameter, 1e-3, 10.0, true),
        "In" => r(Family::Parameter, -1e-2, 1e-2, false),
        "g" => r(Family::Parameter, -10.0, 10.0, false),
        "frc" | "trq" => r(Family::Parameter, -100.0, 100.0, false),
        "lrod" => r(Family::Parameter, 0.1, 2.0, false),
        "tsim" => r(Family::Time, 0.0, 10.0, false),
        _ => r(Family::Parameter, -1.0, 1.0, false),
    }
}

/// A value drawn from `r`, rounded to binary32.
pub fn draw(rng: &mut SplitMix64, r: &Range) -> f64 {
    let x = if r.log {
        (r.lo.ln() + rng.unit() * (r.hi.ln() - r.lo.ln())).exp()
    } else {
        r.lo + rng.unit() * (r.hi - r.lo)
    };
    x as f32 as f64
}

/// A hard value for input `r` (see the module doc), rounded to binary32.
pub fn draw_hard(rng: &mut SplitMix64, r: &Range) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let sign = |rng: &mut SplitMix64| if rng.below(2) == 0 { 1.0 } else { -1.0 };
    let x = match r.family {
        Family::Angle => {
            let base = [0.0, FRAC_PI_2, -FRAC_PI_2, PI, -PI][rng.below(5) as usize];
            if rng.below(4) == 0 {
                base
            } else {
                let k = 8.0 + rng.unit() * 22.0;
                base + sign(rng) * 2f64.powf(-k)
            }
        }
        Family::Rate => sign(rng) * 10f64.powf(1.0 + 2.0 * rng.unit()),
        Family::Parameter => draw(rng, r) * 10f64.powi(rng.below(6) as i32 - 3),
        Family::Time => rng.unit() * 1000.0,
    };
    x as f32 as f64
}

/// A generator for point `index` of a run with `seed` (independent of evaluation order).
pub fn rng_for(seed: u64, stream: u64, index: u64) -> SplitMix64 {
    let mut r = SplitMix64::new(seed ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    for _ in 0..2 {
        r.next_u64();
    }
    SplitMix64::new(r.next_u64() ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03))
}

/// One point: a value per input of `names`, known values taken from `known`, the others drawn
/// (hard values when `hard`).
pub fn point(
    names: &[String],
    ranges: &[Range],
    known: &BTreeMap<String, f64>,
    rng: &mut SplitMix64,
    hard: bool,
) -> Vec<f64> {
    names
        .iter()
        .zip(ranges)
        .map(|(n, r)| match known.get(n) {
            Some(&x) => x,
            None if hard => draw_hard(rng, r),
            None => draw(rng, r),
        })
        .collect()
}

/// Reads a `params` file: a JSON object of canonical input name → number (the `-eval` format).
///
/// # Errors
/// A message naming the file and, for bad JSON, the line and column.
pub fn read_params(path: &str) -> Result<BTreeMap<String, f64>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read params file `{path}`: {e}"))?;
    serde_json::from_str::<BTreeMap<String, f64>>(&text).map_err(|e| {
        format!(
            "params file `{path}` line {}, column {}: {e}; expected a JSON object of input name → number, \
             e.g. {{\"m[2]\": 1.5}}",
            e.line(),
            e.column()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_follow_the_names() {
        assert_eq!(range_of("q[4]").family, Family::Angle);
        assert_eq!(range_of("qdd[1]").hi, 10.0);
        assert!(range_of("In[5][3]").log && range_of("In[5][3]").lo > 0.0);
        assert!(!range_of("In[2][3]").log && range_of("In[2][3]").lo < 0.0);
        assert!(range_of("m[7]").log);
        assert_eq!(range_of("tsim").family, Family::Time);
        assert_eq!(range_of("mystery").lo, -1.0);
    }

    #[test]
    fn draws_stay_in_range_are_binary32_and_deterministic() {
        for name in ["q[1]", "qd[2]", "dpt[1][3]", "m[4]", "In[1][2]", "In[4][2]", "frc[2][3]", "lrod[1]", "tsim"] {
            let r = range_of(name);
            let mut a = rng_for(7, 0, 3);
            let mut b = rng_for(7, 0, 3);
            for _ in 0..500 {
                let x = draw(&mut a, &r);
                assert_eq!(x.to_bits(), draw(&mut b, &r).to_bits());
                assert_eq!(x, x as f32 as f64, "{name}: {x} is not binary32");
                // Rounding to binary32 may step just outside an end point.
                let slack = 1e-6 * r.lo.abs().max(r.hi.abs());
                assert!(x >= r.lo - slack && x <= r.hi + slack, "{name}: {x} outside [{}, {}]", r.lo, r.hi);
            }
        }
        assert_ne!(draw(&mut rng_for(7, 0, 3), &range_of("q[1]")), draw(&mut rng_for(7, 0, 4), &range_of("q[1]")));
    }

    #[test]
    fn hard_angles_sit_near_singular_poses() {
        let r = range_of("q[1]");
        let mut rng = rng_for(1, 1, 0);
        let mut exact = 0;
        for _ in 0..400 {
            let x = draw_hard(&mut rng, &r);
            let d = [0.0, 1.0, -1.0, 2.0, -2.0]
                .iter()
                .map(|k| (x - k * std::f64::consts::FRAC_PI_2).abs())
                .fold(9.0, f64::min);
            assert!(d <= 2f64.powi(-8) * 1.01, "{x} is {d} from a singular pose");
            exact += (x == 0.0 || x == std::f64::consts::FRAC_PI_2 as f32 as f64) as u32;
        }
        assert!(exact > 20, "some angles sit exactly on a pose: {exact}");
    }
}
