//! Scattering models. The hair BSDF is the heart of the crate; its pieces (longitudinal
//! and azimuthal lobes, absorption from colour) are public so that tests and hosts can
//! check them one by one.

pub(crate) mod absorption;
pub(crate) mod azimuthal;
pub(crate) mod diffuse;
mod fresnel;
pub(crate) mod hair;
pub(crate) mod huang;
pub mod inputs;
mod limits;
pub(crate) mod longitudinal;
pub(crate) mod params;
mod pick;

pub use absorption::{SIGMA_A_PRESETS, sigma_a_from_color, sigma_a_from_melanin, sigma_a_preset};
pub use diffuse::Diffuse;
pub use diffuse::DiffusePoint;
pub(crate) use hair::OwnedPoint;
pub use hair::{ACROSS, AcrossEval, HairBsdf, HairPoint, Lobes};
pub use huang::{HuangBsdf, HuangField, HuangParams, HuangPoint};
pub use longitudinal::{LongitudinalLobe, longitudinal_variance};
pub use params::{DEFAULT_EUMELANIN, HairParams};

use glam::Vec3;

/// The value of a BSDF for a pair of directions, in its local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfEval {
    /// RGB; includes 1/|wi.z|, so `f * |wi.z|` is the scattered fraction per unit solid
    /// angle.
    pub f: Vec3,
    /// Density of the BSDF's sampling at wi, per unit solid angle.
    pub pdf: f32,
}

/// A sampled incident direction with the BSDF's value and density there; `f * |wi.z| /
/// pdf` is the path weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub f: Vec3,
    pub pdf: f32,
}

/// A sampled incident direction with its path weight, for a path that needs no pdf.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightedSample {
    pub wi: Vec3,
    /// An unbiased estimate of `f * |wi.z| / pdf`: its expectation over the samples is
    /// the BSDF's albedo, as the exact ratio's is.
    pub weight: Vec3,
}

/// A BSDF at one shading point, its outgoing direction (and, for hair, h) fixed: what a
/// path vertex evaluates toward lights and samples to go on, in the local frame.
pub trait LocalBsdf {
    /// f and pdf toward the unit direction `wi`.
    fn eval(&self, wi: Vec3) -> BsdfEval;
    /// A direction drawn from `u` in [0, 1)^3 (`u[0]` picks among lobes where there are
    /// several); None where the density is zero.
    fn sample(&self, u: [f32; 3]) -> Option<BsdfSample>;
    /// The direction [`Self::sample`] draws from the same `u`, with a path weight that a
    /// BSDF of several lobes may take from the lobe that drew it alone, without evaluating
    /// the others there (cheaper; `eval` still gives the pdf where MIS needs it).
    fn sample_weight(&self, u: [f32; 3]) -> Option<WeightedSample> {
        let s = self.sample(u)?;
        Some(WeightedSample {
            wi: s.wi,
            weight: s.f * s.wi.z.abs() / s.pdf,
        })
    }
}

/// Below this |wi.z| the 1/|wi.z| factor is skipped, as pbrt does at exactly zero; the
/// threshold keeps f finite for every unit wi (docs/conventions.md, section 2, says why).
pub(crate) const MIN_COS_WI: f32 = 1e-20;
/// 1/|wi.z|, or 1 where |wi.z| is below [`MIN_COS_WI`].
#[inline(always)]
pub(crate) fn inv_cos(wi_z: f32) -> f32 {
    let cos_wi = wi_z.abs();
    if cos_wi > MIN_COS_WI {
        1.0 / cos_wi
    } else {
        1.0
    }
}
