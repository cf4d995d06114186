//! Intrinsic functions: the callees of `call` whose meaning the IR knows. Every other callee
//! is an opaque user callback (Robotran's `user_ExtForces`, …), evaluated by the interpreter's
//! stand-in ([`crate::interp::callback_standin`]).
//!
//! | callee | operands | value | rounding |
//! |---|---|---|---|
//! | `@sqrt` | `x` | `√x` | once (IEEE 754 `squareRoot`) |
//! | `@fma` | `a, b, c` | `a·b + c` | once (IEEE 754 `fusedMultiplyAdd`, C99 `fma`) |
//! | `@fms` | `a, b, c` | `a·b − c` | once: `fma(a, b, −c)` |
//! | `@fnma` | `a, b, c` | `c − a·b` | once: `fma(−a, b, c)` |
//!
//! The fused forms are what the `contract` pass writes (LLVM's `llvm.fma` intrinsic and
//! `-ffp-contract`; the names are x86's `VFMADD`, `VFMSUB`, `VFNMADD`). Negating an operand is
//! exact, so `fms` and `fnma` are `fma` on negated operands bit for bit: the C back end writes
//! all three as C99 `fma`, which the interpreter's `mul_add` matches exactly. They count as
//! ops of kind `call` (SPEC §3 counts calls), one each.

use crate::float::Float;
use crate::syntax::Callee;

/// An intrinsic callee (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Intrinsic {
    /// `@sqrt(x)`.
    Sqrt,
    /// `@fma(a, b, c) = a·b + c`, one rounding.
    Fma,
    /// `@fms(a, b, c) = a·b − c`, one rounding.
    Fms,
    /// `@fnma(a, b, c) = c − a·b`, one rounding.
    Fnma,
}

impl Intrinsic {
    /// Every intrinsic.
    pub const ALL: [Intrinsic; 4] = [Intrinsic::Sqrt, Intrinsic::Fma, Intrinsic::Fms, Intrinsic::Fnma];

    /// The callee name without `@`.
    pub fn name(self) -> &'static str {
        match self {
            Intrinsic::Sqrt => "sqrt",
            Intrinsic::Fma => "fma",
            Intrinsic::Fms => "fms",
            Intrinsic::Fnma => "fnma",
        }
    }

    /// Number of operands.
    pub fn arity(self) -> usize {
        match self {
            Intrinsic::Sqrt => 1,
            _ => 3,
        }
    }

    /// The intrinsic named `name` (any arity), if there is one.
    pub fn named(name: &str) -> Option<Intrinsic> {
        Intrinsic::ALL.into_iter().find(|i| i.name() == name)
    }

    /// The intrinsic a call of `callee` with `n_args` operands is: a known name, no vector
    /// element, the right arity. `None`: a user callback (the verifier rejects a known name
    /// with another arity).
    pub fn of(callee: &Callee, n_args: usize) -> Option<Intrinsic> {
        let i = Intrinsic::named(&callee.name)?;
        (callee.elem.is_none() && n_args == i.arity()).then_some(i)
    }

    /// True for the fused multiply-add family.
    pub fn is_fused(self) -> bool {
        !matches!(self, Intrinsic::Sqrt)
    }

    /// The value in precision `T`, one rounding. `args` has [`Intrinsic::arity`] elements.
    pub fn eval<T: Float>(self, args: &[T]) -> T {
        match self {
            Intrinsic::Sqrt => args[0].sqrt(),
            Intrinsic::Fma => args[0].mul_add(args[1], args[2]),
            Intrinsic::Fms => args[0].mul_add(args[1], -args[2]),
            Intrinsic::Fnma => (-args[0]).mul_add(args[1], args[2]),
        }
    }

    /// A callee value for this intrinsic.
    pub fn callee(self) -> Callee {
        Callee { name: self.name().into(), elem: None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fused_forms_round_once() {
        // a·b = 1 − 2⁻⁶⁰ exactly: two roundings give 1 − 1 = 0, one gives −2⁻⁶⁰.
        let (a, b) = (1.0 + 2f64.powi(-30), 1.0 - 2f64.powi(-30));
        let exact_tail = -(2f64.powi(-60));
        assert_eq!(a * b - 1.0, 0.0, "the unfused form loses the tail");
        assert_eq!(Intrinsic::Fma.eval(&[a, b, -1.0]), exact_tail);
        assert_eq!(Intrinsic::Fms.eval(&[a, b, 1.0]), exact_tail);
        assert_eq!(Intrinsic::Fnma.eval(&[a, b, 1.0]), -exact_tail);
        assert_eq!(Intrinsic::Fma.eval(&[2.0f32, 3.0, 1.0]), 7.0);
        assert_eq!(Intrinsic::Sqrt.eval(&[9.0f64]), 3.0);
    }

    #[test]
    fn calls_are_intrinsics_only_with_their_arity_and_no_element() {
        let c = |n: &str, elem| Callee { name: n.into(), elem };
        assert_eq!(Intrinsic::of(&c("fma", None), 3), Some(Intrinsic::Fma));
        assert_eq!(Intrinsic::of(&c("fnma", None), 3), Some(Intrinsic::Fnma));
        assert_eq!(Intrinsic::of(&c("fma", None), 2), None);
        assert_eq!(Intrinsic::of(&c("sqrt", Some(1)), 1), None);
        assert_eq!(Intrinsic::of(&c("user_F.1", None), 3), None);
        for i in Intrinsic::ALL {
            assert_eq!(Intrinsic::named(i.name()), Some(i));
            assert_eq!(Intrinsic::of(&i.callee(), i.arity()), Some(i));
        }
    }
}
