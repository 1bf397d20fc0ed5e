//! The azimuthal distribution Np of one lobe: a logistic of scale s around the lobe's
//! deflection angle, trimmed to [-pi, pi] and renormalised there.

use crate::math::Lanes;
use crate::math::fast::{exp_neg, ln};
use std::f32::consts::PI;

/// Azimuthal logistic scale for roughness beta_n (Chiang et al. 2016, eq. 8).
pub fn azimuthal_scale(beta_n: f32) -> f32 {
    let b = f64::from(beta_n);
    let r = 0.265 * b + 1.194 * b * b + 5.372 * b.powi(22);
    ((std::f64::consts::PI / 8.0).sqrt() * r) as f32
}

/// A logistic of scale s trimmed to [-pi, pi], with its constants precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TrimmedLogistic {
    inv_s: f32,
    s: f32,
    /// 1 / (s (CDF(pi) - CDF(-pi))): the density's constant factor.
    scale: f32,
    /// CDF(-pi); CDF(pi) = 1 - CDF(-pi) by symmetry.
    cdf_lo: f32,
    /// CDF(pi) - CDF(-pi).
    mass: f32,
}

impl TrimmedLogistic {
    pub fn new(s: f32) -> Self {
        let sd = f64::from(s);
        let cdf_lo = 1.0 / (1.0 + (std::f64::consts::PI / sd).exp());
        let mass = 1.0 - 2.0 * cdf_lo;
        Self {
            inv_s: (1.0 / sd) as f32,
            s,
            scale: (1.0 / (sd * mass)) as f32,
            cdf_lo: cdf_lo as f32,
            mass: mass as f32,
        }
    }

    /// Density at x in [-pi, pi].
    #[inline(always)]
    pub fn eval<T: Lanes>(&self, x: T) -> T {
        let e = exp_neg(-(x.abs() * T::splat(self.inv_s)));
        let d = T::splat(1.0) + e;
        T::splat(self.scale) * e / (d * d)
    }

    /// Inverts the trimmed CDF. Both p and 1 - p are formed without cancellation, so the
    /// tails keep their precision at small s.
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        let p = self.cdf_lo + u * self.mass;
        let q = self.cdf_lo + (1.0 - u) * self.mass;
        (self.s * ln(p / q)).clamp(-PI, PI)
    }
}
