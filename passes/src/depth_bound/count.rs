//! How early a polynomial can be ready, from how many x-monomials it has and its degree.
//!
//! A program of `+ − ×` ops (add/sub latency `a`, mul latency `m`, cycles) whose leaves are
//! x-variables, constants and any functions of the θ-inputs, all ready at cycle 0, computes at
//! each value a polynomial in the x-variables over the ring of analytic functions of θ
//! ([`super::expand`]). Counting its x-monomials (monomial-counting lower bounds on formula and
//! circuit depth; see e.g. Shpilka and Yehudayoff, *Arithmetic circuits: a survey*, 2010, §3):
//! - a leaf has at most 1; `#(A ± B) ≤ #A + #B`; `#(A·B) ≤ #A · #B`; so a value ready at
//!   cycle `t` has at most `N(t)` monomials, `N(t) = max(1, N(t−1), 2·N(t−a), N(t−m)²)`;
//! - degrees: `deg(A ± B) ≤ max`, `deg(A·B) = deg A + deg B`: at most
//!   `D(t) = max(1, D(t−1), 2·D(t−m))`;
//! - **a sum at the root**: when an x-variable `y` appears only as the monomial `y` itself (a
//!   coefficient free of x, nonzero), the polynomial has no factorisation into two factors
//!   with x in both (the degree in `y` is 1, and the factor without `y` would divide `y`'s
//!   coefficient; the analytic functions of θ are an integral domain). Its last ops are then
//!   products by θ-functions only, and below them a sum: ready at `t` needs
//!   `#f ≤ 2·N(t−a)` and `deg f ≤ D(t−a)`.
//!
//! [`min_cycles`] is the smallest `t` these allow: a lower bound on the ASAPCycle of the value
//! in every program that computes the same function of the inputs with these ops (SPEC §4's
//! timing: inputs and trig variables ready at 0, calls and divisions by θ-functions free, so
//! the bound also holds for programs that have them).

/// The smallest cycle at which a polynomial of `terms` x-monomials and degree `degree` (with a
/// sum at the root when `sum_root`, see the module doc) can be ready, with add/sub latency
/// `add` and mul latency `mul` (cycles, ≥ 1).
///
/// # Panics
/// When a latency is 0 (the parameters' minimum is 1).
pub fn min_cycles(terms: u64, degree: u32, sum_root: bool, add: u32, mul: u32) -> u32 {
    assert!(add >= 1 && mul >= 1, "latencies are at least one cycle");
    let (add, mul) = (add as usize, mul as usize);
    let degree = degree as u64;
    let sum_root = sum_root && terms >= 2;
    // n[t], d[t]: the bounds N(t), D(t) of the module doc (saturating).
    let mut n: Vec<u64> = Vec::new();
    let mut d: Vec<u64> = Vec::new();
    for t in 0.. {
        let mut nt = 1u64;
        let mut dt = 1u64;
        if t >= 1 {
            nt = nt.max(n[t - 1]);
            dt = dt.max(d[t - 1]);
        }
        if t >= add {
            nt = nt.max(n[t - add].saturating_mul(2));
        }
        if t >= mul {
            nt = nt.max(n[t - mul].saturating_mul(n[t - mul]));
            dt = dt.max(d[t - mul].saturating_mul(2));
        }
        n.push(nt);
        d.push(dt);
        let ok = if sum_root {
            t >= add && n[t - add].saturating_mul(2) >= terms && d[t - add] >= degree
        } else {
            n[t] >= terms && d[t] >= degree
        };
        if ok {
            return t as u32;
        }
    }
    unreachable!("N and D grow without bound")
}

#[cfg(test)]
mod tests {
    use super::min_cycles;

    #[test]
    fn hand_derived_bounds_at_the_default_latencies() {
        // One input: ready at 0. Two terms summed: one add.
        assert_eq!(min_cycles(1, 1, true, 12, 7), 0);
        assert_eq!(min_cycles(2, 1, true, 12, 7), 12);
        // a+b+c+d: the root is a sum of two polynomials of ≤ 2 terms, ready at 12 → 24, and
        // N(19) = 4 cannot be used below a sum (2·N(7) = 2 < 4 at t = 19).
        assert_eq!(min_cycles(4, 1, true, 12, 7), 24);
        // ac+ad+bc+bd (no variable alone): (a+b)(c+d), N(19) = N(12)² = 4.
        assert_eq!(min_cycles(4, 2, false, 12, 7), 19);
        // x₁x₂x₃x₄: degree 4 needs two levels of products.
        assert_eq!(min_cycles(1, 4, false, 12, 7), 14);
        // Knee `dirdyna`'s c[2]: 16 terms, degree 4, a sum at the root: N(t−12) ≥ 8 first at
        // t − 12 = 26 (N(26) = N(19)² = 16, N(24) = 4).
        assert_eq!(min_cycles(16, 4, true, 12, 7), 38);
        // Unit latencies: 16 terms with a sum at the root need 2·N(t−1) ≥ 16, first at t = 4
        // (N(1) = 2, N(2) = 4, N(3) = N(2)² = 16).
        assert_eq!(min_cycles(16, 1, true, 1, 1), 4);
    }
}
