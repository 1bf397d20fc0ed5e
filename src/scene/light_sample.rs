//! What a light answers for a direction, shared by every kind of light: a sample drawn
//! toward it, or its value and pdf along a direction the BSDF drew.

use glam::Vec3;

use crate::Result;
use crate::error::invalid_arg;

/// A direction toward a light, drawn by [`super::Light::sample_li`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Radiance arriving along `-wi`, unoccluded. For a delta light, the irradiance it
    /// delivers at normal incidence.
    pub radiance: Vec3,
    /// Solid-angle pdf of `wi`; 1 for a delta light (whose `radiance / pdf` is then the
    /// right weight), which MIS must not weigh against BSDF sampling.
    pub pdf: f32,
    /// Distance to the light along `wi`; `f32::INFINITY` for lights at infinity.
    pub distance: f32,
    pub is_delta: bool,
}

/// What a light contributes along a direction the BSDF drew: see [`super::Light::eval_li`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightEval {
    pub radiance: Vec3,
    /// Pdf with which [`super::Light::sample_li`] would have drawn this direction.
    pub pdf: f32,
    /// Distance to the light; `f32::INFINITY` for lights at infinity.
    pub distance: f32,
}

/// Radiance (or irradiance) given by a caller: finite and >= 0 in every channel.
pub(super) fn check_radiance(what: &str, radiance: Vec3) -> Result<()> {
    if radiance.is_finite() && radiance.cmpge(Vec3::ZERO).all() {
        Ok(())
    } else {
        Err(invalid_arg!(
            "{what} {radiance} must be finite and >= 0 per channel"
        ))
    }
}
