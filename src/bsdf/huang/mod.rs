//! The Huang, Hullin and Hanika 2022 hair model: a dielectric fibre of elliptical cross-
//! section whose surface is a GGX microfacet surface tilted by the cuticle scales. Light
//! reflects at the first interface (R), or refracts in, crosses the section, and leaves at
//! the second interface (TT) or reflects there and leaves at the third (TRT); the rest
//! (residual) leaves after more internal reflections, azimuthally uniform.
//!
//! Frame, h and `f` follow docs/conventions.md (x the tangent, z toward the viewer, `f`
//! with 1/|wi.z|). The section's major axis is a (y, z) direction in that frame, and h is
//! the offset across the section's width as seen from wo, so h in [-1, 1] covers the
//! fibre whatever its aspect and turn.
//!
//! How it is computed, staged by what it depends on (docs/conventions.md, section 4b):
//! - [`HuangBsdf::new`]: parameters alone.
//! - the point (h, wo): the entry on the section and its tilted normal (the mesonormal);
//!   one microfacet normal visible from wo for the refraction in, followed across the
//!   section to the second interface; there, one internal reflection followed to the
//!   third. Each is drawn from the distribution of visible normals at its own pair of
//!   numbers (the point's jitter, and pairs hashed from it). Every path ends at an *exit*:
//!   an internal direction, the inner normal there and the path's RGB weight (Fresnel,
//!   masking, absorption, and each interface's energy compensation: `albedo`).
//! - wi: R's microfacet reflection, and at each exit the exact density of a GGX
//!   refraction out toward wi. The last interface of TT and TRT is thus integrated
//!   exactly, and the earlier ones by the draws, which a renderer's fresh jitter at each
//!   hit averages.
//!
//! Sampling draws from the same terms: a lobe, then a visible microfacet normal at its
//! exit; its density over wi is the sum the evaluation already forms, so `pdf` is exact
//! and `sample` agrees with it (a draw that meets total internal reflection at the exit
//! is lost: the density integrates to less than 1 by that much).
//!
//! The far field averages the point over the fibre's width: the same point at
//! `FAR_SHIFTS` offsets h + 2k / `FAR_SHIFTS` (wrapped), an unbiased stratified estimate of
//! the average across the fibre when h is uniform over it, evaluated and sampled as one
//! mixture. A point that also weighs sampled lights takes `LIT_SHIFTS` offsets
//! ([`HuangBsdf::far_lit`]).

mod albedo;
mod ggx;
mod params;
mod point;
mod section;

pub use params::HuangParams;
pub use point::HuangPoint;
use point::{FAR_SHIFTS, LIT_SHIFTS};

use super::longitudinal::LongitudinalLobe;
use crate::error::Result;
use albedo::Albedos;
use ggx::Ggx;
use glam::{Vec2, Vec3};

/// The Huang model for one parameter set.
///
/// ```
/// use hairtrace::glam::{Vec2, Vec3};
/// use hairtrace::{HuangBsdf, HuangParams};
/// let bsdf = HuangBsdf::new(&HuangParams { aspect: 0.65, ..HuangParams::default() })?;
/// let point = bsdf.near(0.5, Vec3::Z, Vec2::X, [0.5; 2]); // h = 0.5, seen along z, major along y
/// let light = point.eval(Vec3::new(0.0, 0.6, 0.8));
/// assert!(light.pdf >= 0.0 && light.f.min_element() >= 0.0);
/// if let Some(next) = point.sample([0.3, 0.6, 0.9]) {
///     assert!((next.f * next.wi.z.abs() / next.pdf).is_finite());
/// }
/// # Ok::<(), hairtrace::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HuangBsdf {
    params: HuangParams,
    ggx: Ggx,
    /// What its interfaces keep, by the cosine of the light meeting them (`albedo`).
    albedos: Albedos,
    /// (sin, cos) of the cuticle tilt.
    tilt: (f32, f32),
    /// The residual lobe's longitudinal spread.
    residual: LongitudinalLobe,
}

impl HuangBsdf {
    /// Validates the parameters and precomputes what depends on them alone.
    pub fn new(params: &HuangParams) -> Result<Self> {
        params.validate()?;
        let alpha = f64::from(params.alpha).to_radians();
        Ok(Self {
            params: *params,
            ggx: Ggx::new(params.roughness),
            albedos: Albedos::new(params.roughness, params.eta),
            tilt: (alpha.sin() as f32, alpha.cos() as f32),
            residual: LongitudinalLobe::new(RESIDUAL_VARIANCE_PER_ROUGHNESS * params.roughness),
        })
    }

    pub fn params(&self) -> &HuangParams {
        &self.params
    }

    /// The near field: the fibre seen at the offset h (in [-1, 1], clamped; NaN is 0) from
    /// wo, its section's major axis along the (y, z) direction `major` (normalised here; a
    /// direction of zero or non-finite length is taken as y), its microfacet normals drawn
    /// from `jitter` (modulo 1; not finite is 0). A renderer passes fresh uniform numbers
    /// as `jitter` at each hit, so that the draws average to the model's integral over the
    /// first interfaces; any fixed jitter gives a deterministic model. The rules are those
    /// of docs/conventions.md, section 4b.
    pub fn near(&self, h: f32, wo: Vec3, major: Vec2, jitter: [f32; 2]) -> HuangPoint {
        HuangPoint::new(self, h, wo, major, jitter, 1)
    }

    /// The far field: the fibre averaged across its width, stratified from h (see the
    /// module doc); h uniform over [-1, 1] makes it unbiased. Arguments as [`Self::near`].
    pub fn far(&self, h: f32, wo: Vec3, major: Vec2, jitter: [f32; 2]) -> HuangPoint {
        HuangPoint::new(self, h, wo, major, jitter, FAR_SHIFTS)
    }

    /// The far field at `LIT_SHIFTS` offsets, for a point that also weighs sampled lights:
    /// their values are this point's estimate of the BSDF, whose noise more offsets cut
    /// by more than they cost. Arguments as [`Self::near`].
    pub fn far_lit(&self, h: f32, wo: Vec3, major: Vec2, jitter: [f32; 2]) -> HuangPoint {
        HuangPoint::new(self, h, wo, major, jitter, LIT_SHIFTS)
    }
}

/// One of [`HuangBsdf`]'s point constructors (`near`, `far`, `far_lit`): what a caller
/// that chooses the field once keeps.
pub type HuangField = fn(&HuangBsdf, f32, Vec3, Vec2, [f32; 2]) -> HuangPoint;

/// Below this squared sine of its angle to the fibre a direction is too near the fibre to
/// orient the section: a renderer's own choice of major axis falls back to another
/// direction there, and a host's is refused.
pub(crate) const MIN_ACROSS_SQUARED: f32 = 1e-6;

/// The residual lobe's longitudinal variance per unit of roughness (Cycles' choice).
const RESIDUAL_VARIANCE_PER_ROUGHNESS: f32 = 4.0;
