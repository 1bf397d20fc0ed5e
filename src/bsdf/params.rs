//! The user-facing parameters of the hair BSDF and their validation.

use super::absorption::sigma_a_from_melanin;
use super::limits::{check_beta, check_shared};
use crate::error::Result;

/// Parameters of the Chiang 2016 hair model (units and ranges: docs/conventions.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairParams {
    /// Absorption per unit fiber radius, linear RGB; finite, >= 0.
    pub sigma_a: [f32; 3],
    /// Index of refraction of the fiber, in (1, 3].
    pub eta: f32,
    /// Longitudinal roughness, in [0.01, 1].
    pub beta_m: f32,
    /// Azimuthal roughness, in [0.01, 1].
    pub beta_n: f32,
    /// Cuticle scale tilt in degrees, |alpha| <= 20; pbrt's sign.
    pub alpha: f32,
}

/// Eumelanin concentration of the default (brown) hair.
pub const DEFAULT_EUMELANIN: f32 = 1.3;

impl Default for HairParams {
    /// Brown hair (eumelanin 1.3), eta 1.55, beta_m = beta_n = 0.3, alpha = 2 degrees.
    fn default() -> Self {
        Self {
            sigma_a: sigma_a_from_melanin(DEFAULT_EUMELANIN, 0.0)
                .expect("the default melanin concentration is valid"),
            eta: 1.55,
            beta_m: 0.3,
            beta_n: 0.3,
            alpha: 2.0,
        }
    }
}

impl HairParams {
    /// Checks every parameter against its range; the error names the first bad one.
    /// Out-of-range values are refused rather than clamped, so a mistake is seen.
    pub fn validate(&self) -> Result<()> {
        check_shared(&self.sigma_a, self.eta, self.alpha)?;
        check_beta("beta_m", self.beta_m)?;
        check_beta("beta_n", self.beta_n)?;
        Ok(())
    }
}
