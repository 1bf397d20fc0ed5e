//! The parameters of the Huang model and their validation.

use super::super::limits::{ASPECT_MIN, check_beta, check_shared};
use super::super::params::HairParams;
use crate::error::{Result, invalid_arg};

/// Parameters of the Huang 2022 hair model (units and ranges: docs/conventions.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HuangParams {
    /// Absorption per unit fibre radius (the major semi-axis), linear RGB; finite, >= 0.
    pub sigma_a: [f32; 3],
    /// Index of refraction, in (1, 3].
    pub eta: f32,
    /// GGX roughness (slope scale alpha) of the cuticle, in [0.01, 1].
    pub roughness: f32,
    /// Minor over major axis of the cross-section, in [0.05, 1]; 1 is round.
    pub aspect: f32,
    /// Cuticle tilt in degrees, |alpha| <= 20; pbrt's sign, as [`HairParams::alpha`].
    pub alpha: f32,
}

impl Default for HuangParams {
    /// The default Chiang hair's colour, index and tilt; roughness 0.3, round.
    fn default() -> Self {
        let c = HairParams::default();
        Self {
            sigma_a: c.sigma_a,
            eta: c.eta,
            roughness: 0.3,
            aspect: 1.0,
            alpha: c.alpha,
        }
    }
}

impl HuangParams {
    /// Checks every parameter against its range; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        check_shared(&self.sigma_a, self.eta, self.alpha)?;
        check_beta("roughness", self.roughness)?;
        if !(self.aspect >= ASPECT_MIN && self.aspect <= 1.0) {
            return Err(invalid_arg!(
                "aspect = {}: must be in [{ASPECT_MIN}, 1] (minor over major axis; give the \
                 major axis's direction to turn the section)",
                self.aspect
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_parameters_are_named() {
        let ok = HuangParams::default();
        assert!(ok.validate().is_ok());
        for (p, name) in [
            (HuangParams { aspect: 0.0, ..ok }, "aspect"),
            (HuangParams { aspect: 1.5, ..ok }, "aspect"),
            (
                HuangParams {
                    aspect: f32::NAN,
                    ..ok
                },
                "aspect",
            ),
            (
                HuangParams {
                    roughness: f32::NAN,
                    ..ok
                },
                "roughness",
            ),
            (
                HuangParams {
                    roughness: 0.0,
                    ..ok
                },
                "roughness",
            ),
            (HuangParams { eta: 1.0, ..ok }, "eta"),
            (
                HuangParams {
                    alpha: f32::NAN,
                    ..ok
                },
                "alpha",
            ),
            (
                HuangParams {
                    sigma_a: [0.0, f32::NAN, 0.0],
                    ..ok
                },
                "sigma_a[1]",
            ),
        ] {
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }
}
