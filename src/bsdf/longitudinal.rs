//! The longitudinal lobe Mp of d'Eon et al. 2011: the marginal in theta of a von
//! Mises-Fisher lobe around the specular cone, normalised exactly for every variance.
//!
//! Mp(ti, to) = exp(-sin ti sin to / v) I0(cos ti cos to / v) / (2 v sinh(1/v)).
//! Written as norm * exp(-(1 - cos(ti + to)) / v) * e^-a I0(a) with a = cos ti cos to / v
//! and norm = 1 / (v (1 - e^(-2/v))), every factor stays in range from v = 1e-5 to 1e3,
//! the exponent is computed without cancellation, and one exp suffices.

use crate::math::bessel::{SPLIT, i0_large_scaled, i0_small};
use crate::math::fast::{exp_neg, ln};
use crate::math::{Lanes, cos_from_sin, safe_sqrt};

/// Variance v of the R lobe for longitudinal roughness beta_m (Chiang et al. 2016, eq. 7).
/// TT uses v/4, TRT and the residual 4v.
pub fn longitudinal_variance(beta_m: f32) -> f32 {
    let b = f64::from(beta_m);
    let r = 0.726 * b + 0.812 * b * b + 3.7 * b.powi(20);
    (r * r) as f32
}

/// One longitudinal lobe of variance v, with its per-variance constants precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LongitudinalLobe {
    v: f32,
    inv_v: f32,
    /// 1 / (v (1 - e^(-2/v))), computed in f64.
    norm: f32,
    /// e^(-2/v), the lower end of the sampled exponential (0 for small v).
    exp_m2v: f32,
}

impl LongitudinalLobe {
    pub fn new(v: f32) -> Self {
        let vd = f64::from(v);
        let exp_m2v = (-2.0 / vd).exp();
        Self {
            v,
            inv_v: (1.0 / vd) as f32,
            norm: (1.0 / (vd * -(-2.0 / vd).exp_m1())) as f32,
            exp_m2v: exp_m2v as f32,
        }
    }

    /// The constants of four lobes side by side, for [`MpConstants`] over f32x4.
    pub(crate) fn pack(lobes: &[LongitudinalLobe; 4]) -> MpConstants<wide::f32x4> {
        MpConstants {
            inv_v: wide::f32x4::new(lobes.map(|l| l.inv_v)),
            norm: wide::f32x4::new(lobes.map(|l| l.norm)),
        }
    }

    /// Density over theta_i with respect to cos(theta_i) d theta_i, for the outgoing
    /// direction (sin_to, cos_to >= 0) already tilted by the cuticle angle.
    #[inline(always)]
    pub fn eval<T: Lanes>(&self, sin_ti: T, cos_ti: T, sin_to: T, cos_to: T) -> T {
        let constants = MpConstants {
            inv_v: T::splat(self.inv_v),
            norm: T::splat(self.norm),
        };
        constants.eval(sin_ti, cos_ti, sin_to, cos_to)
    }

    /// Samples theta_i exactly from this lobe: a direction at angle psi from the lobe
    /// centre (theta = -theta_o), cos psi exponentially distributed, around it uniformly;
    /// its theta is distributed as Mp. Returns (sin theta_i, cos theta_i).
    #[inline]
    pub fn sample(&self, sin_to: f32, cos_to: f32, u: [f32; 2]) -> (f32, f32) {
        // x = 1 - cos psi directly, so that small variances keep their precision.
        let x = (-self.v * ln(u[0] + (1.0 - u[0]) * self.exp_m2v)).clamp(0.0, 2.0);
        let sin_psi = safe_sqrt(x * (2.0 - x));
        let cos_psi = 1.0 - x;
        let cos_phi = (std::f32::consts::TAU * u[1]).cos();
        let sin_ti = (-cos_psi * sin_to + sin_psi * cos_phi * cos_to).clamp(-1.0, 1.0);
        (sin_ti, cos_from_sin(sin_ti))
    }
}

/// Per-lane lobe constants: one lobe splatted, or the four lobes of a hair side by side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MpConstants<T> {
    pub inv_v: T,
    pub norm: T,
}

impl<T: Lanes> MpConstants<T> {
    #[inline(always)]
    pub fn eval(&self, sin_ti: T, cos_ti: T, sin_to: T, cos_to: T) -> T {
        let one = T::splat(1.0);
        let a = cos_ti * cos_to * self.inv_v;
        // 1 - cos(ti + to), through sin^2 / (1 + cos) where cos > 0 to avoid cancellation.
        let c = cos_ti * cos_to - sin_ti * sin_to;
        let s = sin_ti * cos_to + cos_ti * sin_to;
        let one_minus_c = T::branch(c.gt(T::splat(0.0)), || s * s / (one + c), || one - c);
        let exponent = -(one_minus_c * self.inv_v);
        // Small a: I0(a) itself, and e^-a moves into the exponent (both terms <= 0); one
        // exp serves both forms.
        let small = a.lt(T::splat(SPLIT));
        let scaled_i0 = T::branch(small, || i0_small(a), || i0_large_scaled(a));
        self.norm * exp_neg(T::select(small, exponent - a, exponent)) * scaled_i0
    }
}
