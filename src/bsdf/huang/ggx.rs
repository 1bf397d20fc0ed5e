//! The GGX (Trowbridge-Reitz) microfacet distribution on a surface of any normal `n`:
//! its density D, Smith's shadowing Lambda and G1, and the distribution of normals visible
//! from a direction (Heitz 2018), which the hair model samples and whose density over the
//! reflected or refracted direction it evaluates exactly.

use crate::math::Frame;
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, TAU};

/// GGX of roughness `a` (the slope scale alpha; isotropic).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Ggx {
    a2: f32,
    a: f32,
}

impl Ggx {
    pub(super) fn new(a: f32) -> Self {
        Self { a2: a * a, a }
    }

    /// Density of microfacet normals with respect to solid angle, projected:
    /// D(m) with cos = dot(n, m); 0 where the normal faces away from n.
    pub(super) fn d(&self, cos: f32) -> f32 {
        if cos <= 0.0 {
            return 0.0;
        }
        let c2 = cos * cos;
        // (cos^2 (a^2 - 1) + 1) written as c2 a2 + (1 - c2): no cancellation near cos = 1.
        let k = c2 * self.a2 + (1.0 - c2);
        self.a2 * FRAC_1_PI / (k * k)
    }

    /// Smith's Lambda for a direction at cosine `cos` to n (its absolute value is used).
    pub(super) fn lambda(&self, cos: f32) -> f32 {
        let c2 = (cos * cos).min(1.0);
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        // (sqrt(1 + a^2 tan^2) - 1) / 2 = (a^2 tan^2) / (2 (sqrt(1 + a^2 tan^2) + 1)):
        // the second form keeps its digits where a^2 tan^2 is small.
        let t = self.a2 * (1.0 - c2) / c2;
        t / (2.0 * ((1.0 + t).sqrt() + 1.0))
    }

    /// Smith's masking G1 of a direction at cosine `cos` to n.
    pub(super) fn g1(&self, cos: f32) -> f32 {
        1.0 / (1.0 + self.lambda(cos))
    }

    /// The height-correlated masking-shadowing of two directions divided by the masking of
    /// the first: the fraction of the light that arrived from `cos_v` and left a visible
    /// facet toward `cos_w` without being blocked.
    pub(super) fn g2_over_g1(&self, cos_v: f32, cos_w: f32) -> f32 {
        let lv = self.lambda(cos_v);
        let lw = self.lambda(cos_w);
        if !lw.is_finite() || !lv.is_finite() {
            return 0.0;
        }
        (1.0 + lv) / (1.0 + lv + lw)
    }

    /// A microfacet normal visible from `v` (unit, dot(v, n) > 0), drawn with density
    /// G1(v) max(0, v.m) D(m) / (v.n) per solid angle of m (Heitz 2018); drawn as Dupuy and
    /// Benyoub 2023 do, from a spherical cap of the stretched view.
    pub(super) fn sample_visible(&self, n: Vec3, v: Vec3, u: [f32; 2]) -> Vec3 {
        self.visible_from(n, v).sample(u)
    }

    /// What every draw of [`Self::sample_visible`] from the same `n` and `v` shares.
    pub(super) fn visible_from(&self, n: Vec3, v: Vec3) -> VisibleNormals {
        let frame = Frame::from_z(n);
        let vl = frame.to_local(v);
        // The view in the frame where the distribution is a hemisphere of unit radius.
        let vh = Vec3::new(self.a * vl.x, self.a * vl.y, vl.z).normalize();
        VisibleNormals {
            frame,
            vh,
            a: self.a,
        }
    }

    /// Density of [`Self::sample_visible`] at m: G1(v) max(0, v.m) D(m) / (v.n).
    pub(super) fn visible_pdf(&self, n: Vec3, v: Vec3, m: Vec3) -> f32 {
        let vn = v.dot(n);
        let vm = v.dot(m);
        if vn <= 0.0 || vm <= 0.0 {
            return 0.0;
        }
        self.g1(vn) * vm * self.d(m.dot(n)) / vn
    }
}

/// The microfacet normals of a [`Ggx`] visible from one direction, ready to draw from.
#[derive(Debug, Clone, Copy)]
pub(super) struct VisibleNormals {
    frame: Frame,
    /// The view, stretched to where the distribution is a unit hemisphere.
    vh: Vec3,
    a: f32,
}

impl VisibleNormals {
    /// A normal from `u` in [0, 1)^2: uniform on the spherical cap the stretched view
    /// sees, stretched back.
    pub(super) fn sample(&self, u: [f32; 2]) -> Vec3 {
        let vh = self.vh;
        let phi = TAU * u[0];
        let z = (1.0 - u[1]) * (1.0 + vh.z) - vh.z;
        let sin_theta = (1.0 - z * z).max(0.0).sqrt();
        let c = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), z);
        let nh = c + vh;
        let m = Vec3::new(self.a * nh.x, self.a * nh.y, nh.z.max(0.0)).normalize_or(Vec3::Z);
        self.frame.to_world(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The visible normals integrate to one over the sphere of m, and their sampler
    /// lands where their density says (the mean of a test function both ways).
    #[test]
    fn visible_normals_are_normalised_and_sampled() {
        for a in [0.05f32, 0.3, 1.0] {
            let g = Ggx::new(a);
            let n = Vec3::new(0.2, -0.3, 0.9).normalize();
            let v = Vec3::new(0.7, 0.1, 0.4).normalize();
            // Quadrature over the hemisphere around n, in (cos, phi).
            let frame = Frame::from_z(n);
            let (nt, np) = (4000, 256);
            let mut total = 0.0f64;
            let mut mean_q = 0.0f64;
            for i in 0..nt {
                // cos from 1 - x^2 so that the narrow lobes near cos = 1 get nodes.
                let x0 = i as f64 / nt as f64;
                let x1 = (i + 1) as f64 / nt as f64;
                let xm = 0.5 * (x0 + x1);
                let cos = 1.0 - xm * xm;
                let dcos = 2.0 * xm * (x1 - x0);
                let sin = (1.0 - cos * cos).max(0.0).sqrt();
                for j in 0..np {
                    let phi = (j as f64 + 0.5) * std::f64::consts::TAU / np as f64;
                    let ml = Vec3::new(
                        (sin * phi.cos()) as f32,
                        (sin * phi.sin()) as f32,
                        cos as f32,
                    );
                    let m = frame.to_world(ml);
                    let p = f64::from(g.visible_pdf(n, v, m)) * dcos * std::f64::consts::TAU
                        / np as f64;
                    total += p;
                    mean_q += p * f64::from(m.dot(v));
                }
            }
            assert!((total - 1.0).abs() < 2e-3, "a = {a}: {total}");
            let k = 200;
            let mut sampled = 0.0f64;
            for i in 0..k {
                for j in 0..k {
                    let u = [(i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32];
                    let m = g.sample_visible(n, v, u);
                    assert!((m.length() - 1.0).abs() < 1e-4);
                    sampled += f64::from(m.dot(v));
                }
            }
            sampled /= (k * k) as f64;
            assert!(
                (sampled - mean_q).abs() < 3e-3,
                "a = {a}: {sampled} {mean_q}"
            );
        }
    }
}
