//! The floating-point precisions robovec evaluates in (`f64`, `f32`): [`Float`], the arithmetic
//! the interpreter ([`crate::interp`]) and the intrinsics ([`crate::intrinsic::Intrinsic::eval`])
//! share. Also reachable as `interp::Float`.

/// A floating-point precision the interpreter evaluates in.
pub trait Float:
    Copy
    + std::fmt::Debug
    + PartialEq
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// Rounds an `f64` to this precision.
    fn from_f64(x: f64) -> Self;
    /// Widens to `f64` (exact).
    fn to_f64(self) -> f64;
    /// Square root, correctly rounded.
    fn sqrt(self) -> Self;
    /// Sine in this precision.
    fn sin(self) -> Self;
    /// Cosine in this precision.
    fn cos(self) -> Self;
    /// `self·b + c` rounded once (IEEE 754 `fusedMultiplyAdd`), for the fused intrinsics
    /// ([`crate::intrinsic::Intrinsic`]).
    fn mul_add(self, b: Self, c: Self) -> Self;
}

impl Float for f64 {
    fn from_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn mul_add(self, b: Self, c: Self) -> Self {
        f64::mul_add(self, b, c)
    }
}

impl Float for f32 {
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    fn sin(self) -> Self {
        f32::sin(self)
    }
    fn cos(self) -> Self {
        f32::cos(self)
    }
    fn mul_add(self, b: Self, c: Self) -> Self {
        f32::mul_add(self, b, c)
    }
}
