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
//!
//! **Fused multiply-adds** (`@fma`, `@fms`, `@fnma`, what `contract` writes; latency `f`, the
//! `call` latency the timing gives them): a program that has them is in a larger machine model,
//! where `a·b + c` takes `f` cycles instead of `m + a`. [`min_cycles_with`] bounds the programs
//! of `+ − ×` **and** fused ops: `#(A·B ± C) ≤ #A·#B + #C` and `deg ≤ max(deg A + deg B,
//! deg C)`, so `N(t)` also takes `N(t−f)² + N(t−f)` and `D(t)` also `2·D(t−f)`; a polynomial
//! with a sum at the root may also end in a fused op (`y + A·B`), ready at `t` when
//! `#f ≤ N(t−f)² + N(t−f)` and `deg f ≤ 2·D(t−f)`. That bound is at most the `+ − ×` one
//! (more programs), and a lower bound on the critical path of the contracted program.

/// The smallest cycle at which a polynomial of `terms` x-monomials and degree `degree` (with a
/// sum at the root when `sum_root`, see the module doc) can be ready, with add/sub latency
/// `add` and mul latency `mul` (cycles, ≥ 1).
///
/// # Panics
/// When a latency is 0 (the parameters' minimum is 1).
pub fn min_cycles(terms: u64, degree: u32, sum_root: bool, add: u32, mul: u32) -> u32 {
    min_cycles_with(terms, degree, sum_root, add, mul, None)
}

/// [`min_cycles`] over programs that may also use fused multiply-adds of latency `fma`
/// (cycles, ≥ 1) when `fma` is given (see the module doc); `None` is [`min_cycles`].
///
/// # Panics
/// When a latency is 0 (the parameters' minimum is 1).
pub fn min_cycles_with(terms: u64, degree: u32, sum_root: bool, add: u32, mul: u32, fma: Option<u32>) -> u32 {
    assert!(add >= 1 && mul >= 1 && fma != Some(0), "latencies are at least one cycle");
    let (add, mul) = (add as usize, mul as usize);
    let fma = fma.map(|f| f as usize);
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
        // A fused op A·B ± C over operands ready at t − f.
        let fused = |n: &[u64], d: &[u64]| {
            fma.filter(|&f| t >= f)
                .map(|f| (n[t - f].saturating_mul(n[t - f]).saturating_add(n[t - f]), d[t - f].saturating_mul(2)))
        };
        if let Some((fn_, fd)) = fused(&n, &d) {
            nt = nt.max(fn_);
            dt = dt.max(fd);
        }
        n.push(nt);
        d.push(dt);
        let ok = if sum_root {
            let by_sum = t >= add && n[t - add].saturating_mul(2) >= terms && d[t - add] >= degree;
            by_sum || fused(&n, &d).is_some_and(|(fn_, fd)| fn_ >= terms && fd >= degree)
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

    #[test]
    fn fused_ops_allow_what_their_latency_allows() {
        use super::min_cycles_with;
        // y = a·b + c: 2 monomials of degree 2, c alone. Over + − ×: a product (7) then a sum
        // (12). With an fma of latency 12: one op, ready at 12.
        assert_eq!(min_cycles(2, 2, true, 12, 7), 19);
        assert_eq!(min_cycles_with(2, 2, true, 12, 7, Some(12)), 12);
        // An fma slower than mul + add gains nothing.
        assert_eq!(min_cycles_with(2, 2, true, 12, 7, Some(30)), 19);
        // a·b·c·d: degree 4 needs two levels of products, whatever the latency of an fma used
        // as a product (f = 5: 10; f = 12: mul's 14).
        assert_eq!(min_cycles_with(1, 4, false, 12, 7, Some(5)), 10);
        assert_eq!(min_cycles_with(1, 4, false, 12, 7, Some(12)), 14);
        // Knee `dirdyna`'s c[2] (16 monomials, degree 4, a sum at the root) with fma latency
        // 12: N(19) = 4 (N(12) = 2, squared), so a fused op at t = 31 holds 4² + 4 = 20 ≥ 16
        // monomials of degree 2·D(19) = 8 ≥ 4; by a sum it still needs t = 38. No fused op
        // at t = 30: N(18) = 2 gives 6 < 16.
        assert_eq!(min_cycles_with(16, 4, true, 12, 7, Some(12)), 31);
        assert_eq!(min_cycles_with(16, 4, true, 12, 7, None), 38);
        // Never above the + − × bound (more programs), on a grid.
        for terms in [1, 2, 3, 5, 16, 100, 4096] {
            for degree in [0, 1, 2, 5] {
                for sum_root in [false, true] {
                    for f in [1, 7, 12, 19, 40] {
                        let plain = min_cycles(terms, degree, sum_root, 12, 7);
                        assert!(min_cycles_with(terms, degree, sum_root, 12, 7, Some(f)) <= plain);
                    }
                }
            }
        }
    }
}
