//! One hair model, two widths. [`Lanes`] is the small set of primitive operations the
//! BSDF needs; it is implemented for `f32` (the scalar hot path, where branches stay
//! branches) and for `wide::f32x8` (eight evaluations at once for `eval_batch`, where
//! branches become selects). The transcendental functions are written once on top of
//! these primitives (see [`super::fast`]), and every primitive is exact IEEE arithmetic,
//! so a batched result equals the scalar one bit for bit.

use std::ops::{Add, Div, Mul, Neg, Sub};
use wide::{f32x4, f32x8, i32x4, i32x8};

/// Exact arithmetic, comparisons and selection, per lane.
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
    fn abs(self) -> Self;
    fn min(self, other: Self) -> Self;
    fn max(self, other: Self) -> Self;
    /// |self| with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// 2^n for integral n in [-126, 127].
    fn pow2i(self) -> Self;
    fn lt(self, other: Self) -> Self::Mask;
    fn gt(self, other: Self) -> Self::Mask;
    /// Per lane: `if mask { a } else { b }`.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// Per lane: `if mask { a() } else { b() }`. A scalar runs only the branch taken,
    /// a vector runs both and selects.
    fn branch(mask: Self::Mask, a: impl FnOnce() -> Self, b: impl FnOnce() -> Self) -> Self;
    /// `exp_neg` of three values (an RGB absorption); a scalar packs them
    /// into one SIMD evaluation, with the same bits as three separate ones.
    #[inline(always)]
    fn exp_neg3(x: [Self; 3]) -> [Self; 3] {
        x.map(super::fast::exp_neg)
    }
}

/// Adding 2^23 + 127 to an integral n leaves n + 127 in the low mantissa bits; shifted by
/// 23 they become the exponent field of 2^n.
const POW2_BIAS: f32 = 8_388_608.0 + 127.0;

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
    fn abs(self) -> Self {
        f32::abs(self)
    }
    // Plain comparisons (one minss/maxss) with the SSE rule for NaN: the second operand.
    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if self < other { self } else { other }
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self > other { self } else { other }
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn pow2i(self) -> Self {
        f32::from_bits((self + POW2_BIAS).to_bits() << 23)
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
    #[inline(always)]
    fn exp_neg3(x: [Self; 3]) -> [Self; 3] {
        let e = super::fast::exp_neg(f32x4::new([x[0], x[1], x[2], 0.0])).to_array();
        [e[0], e[1], e[2]]
    }
}

/// The SIMD widths: f32x4 holds the four lobes of one scalar evaluation, f32x8 eight
/// inputs of a batch. Both use raw minps/maxps, which agree with the scalar min/max.
macro_rules! impl_lanes_for_simd {
    ($t:ty, $int:ty) => {
        impl Lanes for $t {
            type Mask = $t;

            #[inline(always)]
            fn splat(x: f32) -> Self {
                <$t>::splat(x)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$t>::fast_min(self, other)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$t>::fast_max(self, other)
            }
            #[inline(always)]
            fn copysign(self, sign: Self) -> Self {
                self.abs() | (sign & <$t>::splat(-0.0))
            }
            #[inline(always)]
            fn pow2i(self) -> Self {
                let bits: $int = bytemuck::cast(self + <$t>::splat(POW2_BIAS));
                bytemuck::cast(bits << 23)
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
    };
}

impl_lanes_for_simd!(f32x4, i32x4);
impl_lanes_for_simd!(f32x8, i32x8);
