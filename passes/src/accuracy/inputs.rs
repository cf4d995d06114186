//! Input points for the accuracy measurement: physical ranges per canonical input name
//! (SPEC §2) or the run's input domain, sampled and hard points, and the `params=FILE.json` of
//! known values.
//!
//! # Ranges (sampled mode), without a domain: the physical table
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
//!
//! # In a domain
//! When the run has an input domain ([`robovec_ir::domain::Domain`]: `-ranges=FILE`, a URDF's
//! defaults when a pass needs them, `accuracy<ranges=FILE>`), every input it covers is drawn
//! inside its range `[lo, hi]` ([`range_in`]); the inputs it does not cover keep the table
//! above. Values from `params` are used as given, inside the domain or not.
//!
//! | inputs in the domain | `mode=sampled` | `mode=hard` |
//! |---|---|---|
//! | `q[i]` | uniform in [lo, hi] | one of the poses 0, ±π/2, ±π that lie in [lo, hi] or an end `lo`, `hi` (uniformly among them), exactly (¼ of the time) or plus ±2⁻³⁰ … 2⁻⁸ (log-uniform), clamped into [lo, hi] |
//! | any other | uniform in [lo, hi] | `lo` or `hi` (2/8), 0 when inside, else uniform (1/8), an end moved inward by (hi − lo)·2⁻ᵏ, k uniform in [2, 24] (2/8), uniform (3/8) |
//!
//! A point range `[a, a]` gives `a`. Every value is then rounded to binary32 **inside** the
//! range ([`Range::settle`]): rounded to nearest, and when that steps outside `[lo, hi]`, the
//! next binary32 number inward; a range that holds no binary32 number (a point `[0.1, 0.1]`)
//! gives its binary64 value (clamped), which the binary32 evaluation then rounds as it rounds
//! `params` values. So every drawn coordinate lies in `[lo, hi]` exactly, hill climbing
//! included ([`super::hard`] settles every neighbour the same way).

use std::collections::BTreeMap;

use robovec_ir::domain::Domain;
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
    /// Lower end, in the input's units.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Log-uniform when true.
    pub log: bool,
    /// True when `[lo, hi]` is the input's range in the run's domain: every value drawn (hard
    /// and hill-climbing values included) then lies in `[lo, hi]` exactly (module doc, "In a
    /// domain"); false for the physical table, whose values may lie outside (hard mode, and
    /// binary32 rounding at the ends).
    pub within: bool,
}

impl Range {
    /// `x` as a drawn value: rounded to binary32; inside the domain (`within`), first clamped
    /// into `[lo, hi]`, then rounded to the binary32 number nearest it that lies in `[lo, hi]`
    /// (the next one inward when rounding to nearest steps outside), or kept in binary64 when
    /// `[lo, hi]` holds no binary32 number. Idempotent.
    pub fn settle(&self, x: f64) -> f64 {
        if !self.within {
            return x as f32 as f64;
        }
        let x = x.clamp(self.lo, self.hi);
        let y = x as f32;
        let y = if (y as f64) < self.lo {
            y.next_up()
        } else if (y as f64) > self.hi {
            y.next_down()
        } else {
            y
        } as f64;
        if self.lo <= y && y <= self.hi {
            y
        } else {
            x
        }
    }

    /// A uniform draw in `[lo, hi]` (the domain's; one `unit()` of `rng`).
    fn uniform(&self, rng: &mut SplitMix64) -> f64 {
        let t = rng.unit();
        let x = if (self.hi - self.lo).is_finite() {
            self.lo + t * (self.hi - self.lo)
        } else {
            self.lo * (1.0 - t) + self.hi * t
        };
        x.clamp(self.lo, self.hi)
    }
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
    let r = |family, lo, hi, log| Range { family, lo, hi, log, within: false };
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

/// The sampling range of input `name`: its range in `domain` when the domain covers it
/// (uniform, `within`; the family from the name), else the physical table's ([`range_of`]).
pub fn range_in(name: &str, domain: Option<&Domain>) -> Range {
    let table = range_of(name);
    match domain.and_then(|d| d.get(name)) {
        Some(r) => Range { lo: r.interval.lo, hi: r.interval.hi, log: false, within: true, ..table },
        None => table,
    }
}

/// A value drawn from `r`, rounded to binary32 (inside `[lo, hi]` when `r.within`:
/// [`Range::settle`]).
pub fn draw(rng: &mut SplitMix64, r: &Range) -> f64 {
    if r.within {
        let x = r.uniform(rng);
        return r.settle(x);
    }
    let x = if r.log {
        (r.lo.ln() + rng.unit() * (r.hi.ln() - r.lo.ln())).exp()
    } else {
        r.lo + rng.unit() * (r.hi - r.lo)
    };
    x as f32 as f64
}

/// A hard value for input `r` (see the module doc), rounded to binary32 (inside `[lo, hi]`
/// when `r.within`).
pub fn draw_hard(rng: &mut SplitMix64, r: &Range) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let sign = |rng: &mut SplitMix64| if rng.below(2) == 0 { 1.0 } else { -1.0 };
    if r.within {
        return r.settle(hard_within(rng, r));
    }
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

/// A hard value inside the domain's `[lo, hi]` (module doc, "In a domain"), before
/// [`Range::settle`].
fn hard_within(rng: &mut SplitMix64, r: &Range) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (lo, hi) = (r.lo, r.hi);
    if r.family == Family::Angle {
        // The poses inside, then the two ends, which always are (no allocation: this runs per
        // input and point).
        let mut bases = [0.0; 7];
        let mut n = 0;
        for p in [0.0, FRAC_PI_2, -FRAC_PI_2, PI, -PI, lo, hi] {
            if lo <= p && p <= hi {
                bases[n] = p;
                n += 1;
            }
        }
        let base = bases[rng.below(n as u64) as usize];
        if rng.below(4) == 0 {
            return base;
        }
        let k = 8.0 + rng.unit() * 22.0;
        let sign = if rng.below(2) == 0 { 1.0 } else { -1.0 };
        return base + sign * 2f64.powf(-k);
    }
    match rng.below(8) {
        0 => lo,
        1 => hi,
        2 if lo <= 0.0 && 0.0 <= hi => 0.0,
        3 | 4 => {
            let width = if (hi - lo).is_finite() { hi - lo } else { f64::MAX };
            let d = width * 2f64.powf(-(2.0 + 22.0 * rng.unit()));
            if rng.below(2) == 0 {
                lo + d
            } else {
                hi - d
            }
        }
        _ => r.uniform(rng),
    }
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

    fn within(name: &str, lo: f64, hi: f64) -> Range {
        let mut d = Domain::default();
        let r = robovec_ir::domain::Range { interval: robovec_ir::Interval::new(lo, hi), source: "test".into() };
        d.ranges.insert(name.to_string(), r);
        range_in(name, Some(&d))
    }

    #[test]
    fn domain_draws_lie_inside_exactly_and_are_binary32_when_they_can_be() {
        use std::f64::consts::PI;
        // Ends that are not binary32 numbers: rounding to nearest would step outside.
        let cases = [
            ("q[1]", -0.3, 1.7),             // an angle: 0 inside, ±π/2 and ±π not
            ("q[2]", -PI, PI),               // every pose inside; ±π as binary64 ends
            ("q[3]", 2.0, 2.0000001),        // no pose inside: the ends only
            ("qd[1]", 0.1, 0.3),             // 0 outside
            ("m[1]", 0.7, 0.7),              // a point that is not binary32
            ("dpt[1][2]", 0.1, 0.1 + 1e-12), // holds no binary32 number
            ("tsim", -1e-3, 1e-3),           // 0 inside
            ("g[3]", -9.81, -9.81),          // a point
        ];
        for (name, lo, hi) in cases {
            let r = within(name, lo, hi);
            assert!(r.within && !r.log && (r.lo, r.hi) == (lo, hi), "{name}");
            assert_eq!(r.family, range_of(name).family, "{name}: the family is the name's");
            // The smallest binary32 number ≥ lo: is it ≤ hi?
            let first = if (lo as f32 as f64) < lo { (lo as f32).next_up() } else { lo as f32 };
            let has_f32 = first as f64 <= hi;
            assert_eq!(has_f32, name != "dpt[1][2]" && name != "m[1]" && name != "g[3]", "{name}");
            let mut rng = rng_for(5, 0, 1);
            let mut at_ends = 0;
            for i in 0..2000 {
                let x = if i % 2 == 0 { draw(&mut rng, &r) } else { draw_hard(&mut rng, &r) };
                assert!(lo <= x && x <= hi, "{name}: {x:e} outside [{lo:e}, {hi:e}]");
                if has_f32 {
                    assert_eq!(x, x as f32 as f64, "{name}: {x:e} is not binary32");
                }
                // Idempotent: a drawn value settles to itself.
                assert_eq!(r.settle(x).to_bits(), x.to_bits());
                at_ends += (x == r.settle(lo) || x == r.settle(hi)) as u32;
            }
            assert!(at_ends > 0, "{name}: hard draws reach the ends");
        }
        // A point range gives its value (binary64 when it is not binary32).
        assert_eq!(draw(&mut rng_for(1, 0, 0), &within("m[1]", 0.7, 0.7)), 0.7);
        assert_eq!(draw(&mut rng_for(1, 0, 0), &within("m[1]", 1.5, 1.5)), 1.5);
        // Inward rounding: 0.3 rounds to 0.300000011920929 as binary32, above the range; the
        // next binary32 down is 0.29999998211860657.
        let r = within("qd[1]", 0.1, 0.3);
        assert_eq!(r.settle(0.3), 0.29999998211860657);
        assert_eq!(r.settle(5.0), 0.29999998211860657, "clamped first");
        assert_eq!(r.settle(0.1), 0.10000000149011612, "0.1 rounds up, inside");
        // Without a domain: the table, exactly as before.
        assert_eq!(range_in("q[1]", None), range_of("q[1]"));
        assert_eq!(range_in("qd[1]", Some(&Domain::default())), range_of("qd[1]"));
    }

    #[test]
    fn hard_angles_in_a_domain_sit_near_the_poses_it_holds_and_its_ends() {
        use std::f64::consts::FRAC_PI_2;
        let r = within("q[1]", -0.25, 2.0);
        let mut rng = rng_for(1, 1, 0);
        let mut seen = [0u32; 4];
        for _ in 0..2000 {
            let x = draw_hard(&mut rng, &r);
            assert!((-0.25..=2.0).contains(&x), "{x}");
            let near = [0.0, FRAC_PI_2, -0.25, 2.0].map(|p| (x - p).abs() <= 2f64.powi(-8) * 1.01);
            assert!(near.iter().any(|&n| n), "{x} is near no pose of the domain nor an end");
            for (k, n) in near.iter().enumerate() {
                seen[k] += *n as u32;
            }
        }
        assert!(seen.iter().all(|&n| n > 100), "every pose and end drawn: {seen:?}");
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
