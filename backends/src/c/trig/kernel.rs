//! The kernel polynomials of `trig=inline` (see the [parent module](super), step 3 and
//! *Constants*): weighted minimax fits of `(sin r − r)/r³` and `(cos r − 1 + r²/2)/r⁴` in
//! `z = r²` by a discrete Remez exchange in double-double arithmetic, each coefficient rounded
//! to the format in turn.

use std::sync::OnceLock;

use robovec_ir::numerics::DD;

use super::constants::pow2;

/// The number of coefficients `(sin, cos)` of the kernel polynomials, `[double, float]`: `sin`
/// through `r^13` and `cos` through `r^14` in `double`, `sin` through `r^9` and `cos` through
/// `r^8` in `float` — the fewest that keep the approximation error far below half an ulp (see
/// the unit test `kernel_polynomials_are_within_their_bound`; one fewer gives `2^−53.3` for the
/// `double` `cos`, `2^−27.9` for the `float` `sin`).
pub const KERNEL_TERMS: [(usize, usize); 2] = [(6, 6), (4, 3)];

/// The kernels' coefficients `(sin, cos)` of one format ([`kernel_poly`]), derived once.
pub(super) fn kernels(f32: bool) -> (Vec<f64>, Vec<f64>) {
    static CACHE: [OnceLock<(Vec<f64>, Vec<f64>)>; 2] = [OnceLock::new(), OnceLock::new()];
    let i = usize::from(f32);
    CACHE[i]
        .get_or_init(|| {
            let (ms, mc) = KERNEL_TERMS[i];
            (kernel_poly(3, ms, f32), kernel_poly(4, mc, f32))
        })
        .clone()
}

/// The kernels' domain: `|r| ≤ R_MAX` with `R_MAX = π/4 + 2^−30` in `double` (the rounding of
/// `k` lets `|r|` exceed π/4 by about `2^−32`) and `π/4 + 2^−10` in `float` (about `2^−13`
/// there); `z = r²` in `[0, R_MAX²]`.
pub fn kernel_r_max(f32: bool) -> f64 {
    std::f64::consts::FRAC_PI_4 + if f32 { pow2(-10) } else { pow2(-30) }
}

/// `(sin r − r)/r³` (`first = 3`) or `(cos r − 1 + r²/2)/r⁴` (`first = 4`) as a function of
/// `z = r²`: the Taylor series `∓Σ (−1)^n z^n / (2n + first)!` (`−1/3! + z/5! − …`,
/// `1/4! − z/6! + …`), summed in double-double until
/// the terms fall below `2^−110` of the sum (`0 ≤ z < 1`). Units: 1.
fn kernel_series(first: u32, z: DD) -> DD {
    let fact: f64 = (1..=first).map(f64::from).product();
    let sign = if first == 3 { -1.0 } else { 1.0 };
    let mut term = DD::from_f64(sign) / DD::from_f64(fact);
    let mut sum = term;
    let mut n = first;
    loop {
        term = -(term * z) / DD::from_f64(f64::from((n + 1) * (n + 2)));
        sum = sum + term;
        n += 2;
        if term.hi.abs() < sum.hi.abs() * pow2(-110) {
            return sum;
        }
    }
}

/// `(f(z), w(z))` of one kernel at `z`: the function the polynomial approximates (see
/// [`kernel_series`]) and the weight that turns its error into the relative error of the
/// result, `z/(sin r / r)` for `sin`, `z²/cos r` for `cos`.
fn kernel_target(first: u32, z: DD) -> (DD, DD) {
    let f = kernel_series(first, z);
    let one = DD::from_f64(1.0);
    let w = if first == 3 { z / (one + z * f) } else { (z * z) / (one - z.mul_f64(0.5) + z * z * f) };
    (f, w)
}

/// The weighted minimax polynomial `Σ_{j<m} c_j z^j` for the values `g` with weights `w` on the
/// points `z` (discrete Remez exchange, double-double): minimises `max |w·(g − p)|`.
fn remez(z: &[DD], g: &[DD], w: &[DD], m: usize) -> Vec<DD> {
    let n = z.len();
    let one = DD::from_f64(1.0);
    let zero = DD::from_f64(0.0);
    // Start from the Chebyshev points of order m + 1 on the grid (Chebyshev-spaced itself).
    let mut refs: Vec<usize> = (0..=m).map(|i| ((i as f64 + 0.5) / (m as f64 + 1.0) * n as f64) as usize).collect();
    let mut coef = vec![zero; m];
    for _ in 0..40 {
        // Σ c_j z_i^j + (−1)^i E / w_i = g_i: m + 1 equations, Gaussian elimination.
        let mut a: Vec<Vec<DD>> = refs
            .iter()
            .enumerate()
            .map(|(i, &k)| {
                let mut row = Vec::with_capacity(m + 2);
                let mut p = one;
                for _ in 0..m {
                    row.push(p);
                    p = p * z[k];
                }
                let e = one / w[k];
                row.push(if i % 2 == 0 { e } else { -e });
                row.push(g[k]);
                row
            })
            .collect();
        for col in 0..=m {
            let piv = (col..=m).max_by(|&i, &j| a[i][col].hi.abs().total_cmp(&a[j][col].hi.abs())).unwrap();
            a.swap(col, piv);
            let pivot = a[col].clone();
            for (r, row) in a.iter_mut().enumerate() {
                if r != col {
                    let f = row[col] / pivot[col];
                    for (x, &v) in row.iter_mut().zip(&pivot).skip(col) {
                        *x = *x - f * v;
                    }
                }
            }
        }
        coef = (0..m).map(|j| a[j][m + 1] / a[j][j]).collect();
        // The weighted error on the grid; the extremum of each run of one sign.
        let err: Vec<f64> = (0..n).map(|k| (w[k] * (g[k] - horner_dd(&coef, z[k]))).hi).collect();
        let mut ext: Vec<usize> = Vec::new();
        for k in 0..n {
            match ext.last() {
                Some(&e) if (err[e] > 0.0) == (err[k] > 0.0) => {
                    if err[k].abs() > err[e].abs() {
                        *ext.last_mut().unwrap() = k;
                    }
                }
                _ => ext.push(k),
            }
        }
        while ext.len() > m + 1 {
            if err[ext[0]].abs() < err[ext[ext.len() - 1]].abs() {
                ext.remove(0);
            } else {
                ext.pop();
            }
        }
        if ext.len() < m + 1 || ext == refs {
            break;
        }
        refs = ext;
    }
    coef
}

/// `Σ c_j z^j` in double-double (Horner).
fn horner_dd(c: &[DD], z: DD) -> DD {
    c.iter().rev().fold(DD::from_f64(0.0), |acc, &x| acc * z + x)
}

/// The kernel polynomial of `sin` (`first = 3`: coefficients of `r³, r⁵, …`) or `cos`
/// (`first = 4`: `r⁴, r⁶, …`) with `m` coefficients, each rounded to the format: weighted
/// minimax ([`remez`]) on 4096 Chebyshev-spaced points of `z ∈ (0, R_MAX²]`; the coefficients
/// are rounded one at a time from the lowest power, the higher ones re-optimised after each
/// rounding so they absorb its error.
fn kernel_poly(first: u32, m: usize, f32: bool) -> Vec<f64> {
    let n = 4096;
    let zmax = DD::from_f64(kernel_r_max(f32)) * DD::from_f64(kernel_r_max(f32));
    let z: Vec<DD> = (0..n)
        .map(|k| zmax.mul_f64((1.0 - (std::f64::consts::PI * (k as f64 + 0.5) / n as f64).cos()) * 0.5))
        .collect();
    let (f, w): (Vec<DD>, Vec<DD>) = z.iter().map(|&z| kernel_target(first, z)).unzip();
    let mut rounded: Vec<f64> = Vec::with_capacity(m);
    for j in 0..m {
        // What is left to approximate, over z^j, with the weight times z^j.
        let done: Vec<DD> = rounded.iter().map(|&c| DD::from_f64(c)).collect();
        let (g, wj): (Vec<DD>, Vec<DD>) = (0..n)
            .map(|k| {
                let mut zj = DD::from_f64(1.0);
                for _ in 0..j {
                    zj = zj * z[k];
                }
                ((f[k] - horner_dd(&done, z[k])) / zj, w[k] * zj)
            })
            .collect();
        let c = remez(&z, &g, &wj, m - j)[0];
        rounded.push(if f32 { f64::from(c.round_f32()) } else { c.round_f64() });
    }
    rounded
}

#[cfg(test)]
mod tests {
    use super::super::Constants;
    use super::*;

    /// The largest relative error of the kernel polynomials with the rounded coefficients,
    /// `r + r³·p(r²)` against `sin r` and `1 − r²/2 + r⁴·q(r²)` against `cos r`, on 20 000
    /// evenly spaced `r` in `(0, R_MAX]`, evaluated exactly enough (double-double) that only the
    /// approximation error shows; the reference is [`DD::sin`] / [`DD::cos`] (reduction in
    /// triple-double and Taylor series, absolute error below 2^−98), independent of the series
    /// the coefficients were fitted to.
    fn kernel_errors(c: &Constants, f32: bool) -> (f64, f64) {
        let to_dd = |cs: &[f64]| cs.iter().map(|&x| DD::from_f64(x)).collect::<Vec<_>>();
        let (ps, pc) = (to_dd(&c.sin), to_dd(&c.cos));
        let n = 20_000;
        let (mut es, mut ec) = (0.0f64, 0.0f64);
        for i in 1..=n {
            let r = DD::from_f64(kernel_r_max(f32) * i as f64 / n as f64);
            let z = r * r;
            let s = r + r * z * horner_dd(&ps, z);
            let c = DD::from_f64(1.0) - z.mul_f64(0.5) + z * z * horner_dd(&pc, z);
            let (ts, tc) = (r.sin(), r.cos());
            es = es.max(((s - ts) / ts).hi.abs());
            ec = ec.max(((c - tc) / tc).hi.abs());
        }
        (es, ec)
    }

    #[test]
    fn kernel_polynomials_are_within_their_bound() {
        // (f32, bounds on the relative error of sin and cos): far below half an ulp (2^−53,
        // resp. 2^−24 relative at most).
        for (f32, bound_sin, bound_cos) in [(false, -57.5f64, -63.0f64), (true, -32.0, -32.5)] {
            let c = Constants::new(f32);
            let (es, ec) = kernel_errors(&c, f32);
            eprintln!("f32={f32}: sin 2^{:.2}, cos 2^{:.2}", es.log2(), ec.log2());
            assert!(es < bound_sin.exp2() && ec < bound_cos.exp2(), "f32={f32}: sin {es:e}, cos {ec:e}");
        }
    }

    #[test]
    fn kernel_coefficients_are_near_the_taylor_ones() {
        // Minimax moves each coefficient a little from ±1/n!, more the higher the power; the
        // signs alternate like the series'.
        for f32 in [false, true] {
            let c = Constants::new(f32);
            for (first, cs) in [(3u32, &c.sin), (4, &c.cos)] {
                for (j, &x) in cs.iter().enumerate() {
                    let n = first + 2 * j as u32;
                    let fact: f64 = (1..=n).map(f64::from).product();
                    let sign = if j % 2 == 0 { -1.0 } else { 1.0 } * if first == 4 { -1.0 } else { 1.0 };
                    let rel = x * fact * sign - 1.0;
                    eprintln!("f32={f32} r^{n}: {x:e} (1/n! · (1 {rel:+e}))");
                    let tol = if j > 0 {
                        0.1
                    } else if f32 {
                        pow2(-18)
                    } else {
                        pow2(-40)
                    };
                    assert!(rel.abs() < tol, "f32={f32} r^{n}: {x:e}, relative to ±1/{n}! {rel:e}");
                }
            }
        }
    }
}
