//! The Lambertian BRDF of meshes (scalps, props, the furnace sphere), in the same
//! local-frame convention as the hair BSDF: z is the shading normal, and the path weight
//! of a sample is `f * |wi.z| / pdf`.
//!
//! It is two-sided: the hemisphere that reflects is the one `wo` is in, so that a mesh's
//! winding order never turns a surface black.

use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::{BsdfEval, BsdfSample, LocalBsdf};
use crate::Result;
use crate::error::invalid_arg;
use crate::math::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};

/// A Lambertian reflector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diffuse {
    albedo: Vec3,
}

impl Diffuse {
    /// `albedo` is the fraction of light reflected per channel, finite and in [0, 1]:
    /// above 1 the surface would create energy.
    pub fn new(albedo: Vec3) -> Result<Self> {
        if !(albedo.is_finite() && albedo.cmpge(Vec3::ZERO).all() && albedo.cmple(Vec3::ONE).all())
        {
            return Err(invalid_arg!(
                "diffuse albedo {albedo} must be finite and in [0, 1] per channel"
            ));
        }
        Ok(Self { albedo })
    }

    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }

    /// The BRDF seen from `wo` (local frame, z the shading normal).
    pub fn at(&self, wo: Vec3) -> DiffusePoint {
        DiffusePoint { bsdf: *self, wo }
    }
}

/// [`Diffuse`] at a fixed `wo`; see [`Diffuse::at`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffusePoint {
    bsdf: Diffuse,
    wo: Vec3,
}

impl LocalBsdf for DiffusePoint {
    /// Albedo / pi and the cosine-weighted pdf when `wo` and `wi` are on the same side of
    /// the surface, zero otherwise.
    fn eval(&self, wi: Vec3) -> BsdfEval {
        if self.wo.z * wi.z > 0.0 {
            BsdfEval {
                f: self.bsdf.albedo * FRAC_1_PI,
                pdf: cosine_hemisphere_pdf(wi.z.abs()),
            }
        } else {
            BsdfEval {
                f: Vec3::ZERO,
                pdf: 0.0,
            }
        }
    }

    /// A cosine-weighted direction on `wo`'s side from `u[1]` and `u[2]` (one lobe: `u[0]`
    /// is not needed), whose weight `f * |wi.z| / pdf` is exactly the albedo. `None` when
    /// `wo` lies in the surface plane or the sample grazes it (pdf 0).
    fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        if self.wo.z == 0.0 {
            return None;
        }
        let mut wi = cosine_hemisphere([u[1], u[2]]);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = cosine_hemisphere_pdf(wi.z);
        if self.wo.z < 0.0 {
            wi.z = -wi.z;
        }
        Some(BsdfSample {
            wi,
            f: self.bsdf.albedo * FRAC_1_PI,
            pdf,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::sampling::{UNIFORM_SPHERE_PDF, uniform_sphere};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    const ALBEDO: Vec3 = Vec3::new(0.8, 0.5, 0.1);

    fn directions(seed: u64, n: usize) -> impl Iterator<Item = Vec3> {
        let mut rng = Pcg64::seed_from_u64(seed);
        (0..n).map(move |_| uniform_sphere([rng.random(), rng.random()]))
    }

    #[test]
    fn white_furnace_by_uniform_directions_is_the_albedo() {
        let bsdf = Diffuse::new(ALBEDO).unwrap();
        let n = 400_000;
        for wo in [Vec3::Z, Vec3::new(0.6, 0.0, -0.8)] {
            let sum: Vec3 = directions(1, n)
                .map(|wi| bsdf.at(wo).eval(wi).f * wi.z.abs() / UNIFORM_SPHERE_PDF)
                .sum();
            let estimate = sum / n as f32;
            // Relative standard error of this estimator is about 1 / sqrt(n) = 0.0016.
            assert!(
                (estimate - ALBEDO).abs().max_element() < 0.01,
                "{estimate} for wo {wo}"
            );
        }
    }

    #[test]
    fn sample_weights_are_the_albedo_and_pdf_matches_eval() {
        let bsdf = Diffuse::new(ALBEDO).unwrap();
        let mut rng = Pcg64::seed_from_u64(2);
        for wo in directions(3, 2000) {
            let Some(BsdfSample { wi, f, pdf }) =
                bsdf.at(wo).sample([0.0, rng.random(), rng.random()])
            else {
                continue;
            };
            assert!((wi.length() - 1.0).abs() < 1e-5);
            assert!(wi.z * wo.z > 0.0, "wi {wi} on the other side of wo {wo}");
            let weight = f * wi.z.abs() / pdf;
            assert!((weight - ALBEDO).abs().max_element() < 1e-5, "{weight}");
            let e = bsdf.at(wo).eval(wi);
            assert_eq!(e.f, f);
            assert!((e.pdf - pdf).abs() <= 1e-6 * pdf);
        }
    }

    #[test]
    fn opposite_sides_and_grazing_are_zero_and_bad_albedo_is_an_error() {
        let bsdf = Diffuse::new(Vec3::ONE).unwrap();
        let zero = BsdfEval {
            f: Vec3::ZERO,
            pdf: 0.0,
        };
        assert_eq!(bsdf.at(Vec3::Z).eval(-Vec3::Z), zero);
        assert_eq!(bsdf.at(Vec3::X).eval(Vec3::Z), zero);
        assert!(bsdf.at(Vec3::X).sample([0.0, 0.3, 0.3]).is_none());
        for bad in [
            Vec3::new(1.1, 0.0, 0.0),
            Vec3::new(-0.1, 0.0, 0.0),
            Vec3::new(f32::NAN, 0.5, 0.5),
            Vec3::splat(f32::INFINITY),
        ] {
            assert!(Diffuse::new(bad).is_err(), "{bad}");
        }
    }
}
