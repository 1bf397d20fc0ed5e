//! The modified Bessel function of the first kind, order zero, as the longitudinal lobe
//! needs it: scaled by e^-x so that it never overflows (the lobe's argument reaches
//! 1/v ≈ 7.4e4 at the narrowest roughness).
//!
//! Abramowitz & Stegun 9.8.1 and 9.8.2 give polynomial fits with absolute errors below
//! 1.6e-7 (|x| <= 3.75, where I0 >= 1) and 1.9e-7 (x >= 3.75, on sqrt(x) e^-x I0(x) >= 0.39):
//! relative errors under 5e-7 over the whole range, measured against an f64 reference in
//! the tests. A truncated Taylor series with a one-term asymptotic tail (as in pbrt) is
//! several percent off between x = 5 and 12; these fits are not, at the same cost.

// Coefficients are quoted as published, digits beyond f32 included.
#![allow(clippy::excessive_precision)]

use super::Lanes;
use super::fast::exp_neg;

/// Above this argument the asymptotic form is used.
pub(crate) const SPLIT: f32 = 3.75;

/// I0(x) for 0 <= x <= 3.75 (A&S 9.8.1), in powers of t^2, t = x / 3.75.
#[inline(always)]
pub(crate) fn i0_small<T: Lanes>(x: T) -> T {
    let t = x * T::splat(1.0 / SPLIT);
    let t2 = t * t;
    let c = |v: f32| T::splat(v);
    c(1.0)
        + t2 * (c(3.515_622_9)
            + t2 * (c(3.089_942_4)
                + t2 * (c(1.206_749_2)
                    + t2 * (c(0.265_973_2) + t2 * (c(0.036_076_8) + t2 * c(0.004_581_3))))))
}

/// e^-x I0(x) for x >= 3.75 (A&S 9.8.2): a polynomial in t = 3.75 / x over sqrt(x).
#[inline(always)]
pub(crate) fn i0_large_scaled<T: Lanes>(x: T) -> T {
    let t = T::splat(SPLIT) / x;
    let c = |v: f32| T::splat(v);
    let p = c(0.398_942_28)
        + t * (c(0.013_285_92)
            + t * (c(0.002_253_19)
                + t * (c(-0.001_575_65)
                    + t * (c(0.009_162_81)
                        + t * (c(-0.020_577_06)
                            + t * (c(0.026_355_37)
                                + t * (c(-0.016_476_33) + t * c(0.003_923_77))))))));
    p / x.sqrt()
}

/// e^-x I0(x) for x >= 0; finite for every finite x, about 1/sqrt(2 pi x) for large x.
pub fn i0_scaled(x: f32) -> f32 {
    if x < SPLIT {
        exp_neg(-x) * i0_small(x)
    } else {
        i0_large_scaled(x)
    }
}
