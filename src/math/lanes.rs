//! One hair model, two widths. [`Lanes`] is the small set of operations the BSDF needs;
//! it is implemented for `f32` (the scalar hot path, branches stay branches) and for
//! `wide::f32x8` (eight evaluations at once for `eval_batch`, branches become selects).
//! Writing the model once against this trait keeps the scalar and the batched results
//! identical up to the last bits of the transcendental functions.

use std::ops::{Add, Div, Mul, Neg, Sub};
use wide::f32x8;

/// Arithmetic, comparisons and the transcendental functions the hair model uses.
pub trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The result of a comparison, one flag per lane.
    type Mask: Copy;

    fn splat(x: f32) -> Self;
    fn sqrt(self) -> Self;
    fn exp(self) -> Self;
    fn asin(self) -> Self;
    /// `atan2(self, x)`, like `f32::atan2`.
    fn atan2(self, x: Self) -> Self;
    fn abs(self) -> Self;
    /// Nearest integer for |x| < 2^22; ties may go either way (used for angle wrapping).
    fn round(self) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    fn lt(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    /// Per lane: `if mask { a } else { b }`.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// Per lane: `if mask { a() } else { b() }`. A scalar runs only the branch taken,
    /// a vector runs both and selects.
    fn branch(mask: Self::Mask, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self;
}

impl Lanes for f32 {
    type Mask = bool;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        super::fast::exp(self)
    }
    #[inline(always)]
    fn asin(self) -> Self {
        super::fast::asin(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        super::fast::atan2(self, x)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn round(self) -> Self {
        super::fast::round(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self > other
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn branch(mask: bool, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self {
        if mask { a() } else { b() }
    }
}

impl Lanes for f32x8 {
    type Mask = f32x8;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        f32x8::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32x8::sqrt(self)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f32x8::exp(self)
    }
    #[inline(always)]
    fn asin(self) -> Self {
        f32x8::asin(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        f32x8::atan2(self, x)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32x8::abs(self)
    }
    #[inline(always)]
    fn round(self) -> Self {
        f32x8::round(self)
    }
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        f32x8::min(self, other)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f32x8::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> Self {
        self.simd_lt(other)
    }
    #[inline(always)]
    fn gt(self, other: Self) -> Self {
        self.simd_gt(other)
    }
    #[inline(always)]
    fn select(mask: Self, a: Self, b: Self) -> Self {
        mask.select(a, b)
    }
    #[inline(always)]
    fn branch(mask: Self, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self {
        mask.select(a(), b())
    }
}
