//! The lights hair scenes need: an environment (uniform or HDR map), a distant light with
//! an angular radius (the sun, a key light), and a rectangular area light (a softbox).
//!
//! Every query works in solid angle at the shading point, so that next-event estimation
//! and BSDF sampling can be combined with MIS: [`Light::sample_li`] draws a direction,
//! [`Light::eval_li`] (and its shorthand [`Light::pdf_li`]) answers for a direction the
//! BSDF drew. Occlusion is the integrator's business: `distance` says how far to look.

use std::f32::consts::PI;

use glam::Vec3;

use super::envmap::Environment;
use super::light_sample::check_radiance;
pub use super::light_sample::{LightEval, LightSample};
use crate::Result;
use crate::error::invalid_arg;
use crate::math::luminance;
use crate::math::sampling::{uniform_cone, uniform_cone_pdf};
use crate::validate;

/// A light source. Built through the validating constructors; `Send + Sync`.
#[derive(Debug, Clone)]
pub enum Light {
    Environment(Environment),
    Distant(Distant),
    Rect(Rect),
}

/// Light from a cone of directions around `direction`, uniform within it, or from one
/// direction when the angular radius is 0. See [`Light::distant`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distant {
    direction: Vec3,
    /// Two unit vectors completing `direction` to an orthonormal frame.
    tangent: Vec3,
    bitangent: Vec3,
    irradiance: Vec3,
    /// 1 - cos(angular radius), kept exact for tiny cones; 0 for a delta light.
    one_minus_cos: f32,
    /// Radiance within the cone (unused by a delta light).
    radiance: Vec3,
}

/// An emitting parallelogram. See [`Light::rect`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    /// Unit normal `edge_u x edge_v`: the emitting side of a one-sided light.
    normal: Vec3,
    /// Dual vectors: `dot(q - corner, dual_u)` is q's coordinate along `edge_u`.
    dual_u: Vec3,
    dual_v: Vec3,
    area: f32,
    radiance: Vec3,
    two_sided: bool,
}

impl Light {
    /// A light at infinity seen in `direction` (pointing toward the light, any non-zero
    /// length) as a disc of `angular_radius_deg` degrees, in [0, 90); 0 makes it a delta
    /// light (hard shadows, invisible to BSDF-sampled rays).
    ///
    /// It is specified by the `irradiance` it delivers to a surface facing it rather than
    /// by its radiance, which for a delta light does not exist: so widening the disc
    /// softens shadows without changing the exposure. The radiance within the disc is
    /// `irradiance / (pi sin^2(angular_radius))`.
    pub fn distant(direction: Vec3, irradiance: Vec3, angular_radius_deg: f32) -> Result<Light> {
        let dir = validate::direction("distant light direction", direction)?;
        check_radiance("distant light irradiance", irradiance)?;
        if !(0.0..90.0).contains(&angular_radius_deg) {
            return Err(invalid_arg!(
                "distant light angular radius {angular_radius_deg} degrees must be in [0, 90)"
            ));
        }
        let angular_radius = angular_radius_deg.to_radians();
        let one_minus_cos = 2.0 * (angular_radius / 2.0).sin().powi(2);
        let sin2 = one_minus_cos * (2.0 - one_minus_cos);
        let radiance = if sin2 > 0.0 {
            irradiance / (PI * sin2)
        } else {
            Vec3::ZERO
        };
        if !radiance.is_finite() {
            return Err(invalid_arg!(
                "distant light: irradiance {irradiance} over an angular radius of \
                 {angular_radius_deg} degrees gives an infinite radiance"
            ));
        }
        let (tangent, bitangent) = dir.any_orthonormal_pair();
        Ok(Light::Distant(Distant {
            direction: dir,
            tangent,
            bitangent,
            irradiance,
            one_minus_cos,
            radiance,
        }))
    }

    /// A parallelogram with corners `corner`, `corner + edge_u`, `corner + edge_v` and
    /// `corner + edge_u + edge_v` (a rectangle when the edges are perpendicular), emitting
    /// `radiance` from the side `edge_u x edge_v` points to, or from both sides.
    pub fn rect(
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
        radiance: Vec3,
        two_sided: bool,
    ) -> Result<Light> {
        validate::position("rect light corner", corner)?;
        validate::position("rect light edge_u", edge_u)?;
        validate::position("rect light edge_v", edge_v)?;
        check_radiance("rect light radiance", radiance)?;
        let cross = edge_u.cross(edge_v);
        let area = cross.length();
        // Edges within about 0.01 degree of parallel make no usable surface; edges so long
        // that the area overflows none either.
        if !(area.is_finite() && area > 2e-4 * edge_u.length() * edge_v.length()) {
            return Err(invalid_arg!(
                "rect light edges {edge_u} and {edge_v} are zero, parallel or too long"
            ));
        }
        let normal = cross / area;
        let dual_u = edge_v.cross(normal);
        let dual_v = normal.cross(edge_u);
        Ok(Light::Rect(Rect {
            corner,
            edge_u,
            edge_v,
            normal,
            dual_u: dual_u / edge_u.dot(dual_u),
            dual_v: dual_v / edge_v.dot(dual_v),
            area,
            radiance,
            two_sided,
        }))
    }

    /// Lights at infinity are met by rays that escape the scene; the rect by a hit.
    pub fn is_infinite(&self) -> bool {
        !matches!(self, Light::Rect(_))
    }

    /// Whether next-event estimation should sample this light. Not a uniform
    /// environment: its radiance is the same from every direction, so the BSDF-sampled
    /// ray a path traces anyway estimates it with the BSDF's own importance, and a shadow
    /// ray toward a uniformly drawn direction would double the rays for little gain
    /// (measured: docs/measurements.md, "Render efficiency").
    pub(crate) fn needs_light_sampling(&self) -> bool {
        !matches!(self, Light::Environment(env) if env.is_uniform())
    }

    /// Draws a direction toward the light from `p` with `u` in [0, 1)^2. `None` when the
    /// light sends nothing toward `p` (the back of a one-sided rect, a grazing angle).
    pub fn sample_li(&self, p: Vec3, u: [f32; 2]) -> Option<LightSample> {
        match self {
            Light::Environment(env) => env.sample(u),
            Light::Distant(d) if d.one_minus_cos == 0.0 => Some(LightSample {
                wi: d.direction,
                radiance: d.irradiance,
                pdf: 1.0,
                distance: f32::INFINITY,
                is_delta: true,
            }),
            Light::Distant(d) => {
                let l = uniform_cone(u, d.one_minus_cos);
                Some(LightSample {
                    wi: (d.tangent * l.x + d.bitangent * l.y + d.direction * l.z).normalize(),
                    radiance: d.radiance,
                    pdf: uniform_cone_pdf(d.one_minus_cos),
                    distance: f32::INFINITY,
                    is_delta: false,
                })
            }
            Light::Rect(r) => {
                // Uniform over the area: simple and exact; the pdf converts to solid angle.
                let to_light = r.corner + r.edge_u * u[0] + r.edge_v * u[1] - p;
                let distance = to_light.length();
                let wi = to_light / distance;
                let eval = r.eval(wi, distance)?;
                Some(LightSample {
                    wi,
                    radiance: eval.radiance,
                    pdf: eval.pdf,
                    distance,
                    is_delta: false,
                })
            }
        }
    }

    /// The light's contribution along the unit direction `wi` from `p`: radiance
    /// arriving (unoccluded), the pdf `sample_li` has for `wi`, and the distance to the
    /// light. `None` where the light does not reach: outside a distant light's disc,
    /// past the rect, toward a one-sided rect's back, and always for a delta light.
    pub fn eval_li(&self, p: Vec3, wi: Vec3) -> Option<LightEval> {
        match self {
            Light::Environment(env) => {
                let (radiance, pdf) = env.eval(wi);
                Some(LightEval {
                    radiance,
                    pdf,
                    distance: f32::INFINITY,
                })
            }
            Light::Distant(d) => d.in_disc(wi).then(|| LightEval {
                radiance: d.radiance,
                pdf: uniform_cone_pdf(d.one_minus_cos),
                distance: f32::INFINITY,
            }),
            Light::Rect(r) => r.eval(wi, r.intersect(p, wi)?),
        }
    }

    /// Solid-angle pdf of [`sample_li`](Self::sample_li) drawing `wi` from `p`: 0 where
    /// it never would.
    pub fn pdf_li(&self, p: Vec3, wi: Vec3) -> f32 {
        self.eval_li(p, wi).map_or(0.0, |e| e.pdf)
    }

    /// Radiance along the unit direction `dir` of a ray that escaped the scene, from a
    /// light at infinity (zero from a rect or a delta light).
    pub fn le(&self, dir: Vec3) -> Vec3 {
        match self {
            Light::Environment(env) => env.le(dir),
            Light::Distant(d) if d.in_disc(dir) => d.radiance,
            Light::Distant(_) | Light::Rect(_) => Vec3::ZERO,
        }
    }

    /// Distance `t > 0` along `dir` from `org` where the ray meets a rect light (in units
    /// of `|dir|`); `None` for a miss and for lights at infinity.
    pub fn intersect(&self, org: Vec3, dir: Vec3) -> Option<f32> {
        match self {
            Light::Rect(r) => r.intersect(org, dir),
            Light::Environment(_) | Light::Distant(_) => None,
        }
    }

    /// Luminance of the power the light sends into a scene of bounding radius
    /// `scene_radius`: the weight for choosing which light to sample. Lights at infinity
    /// count what crosses a disc of that radius.
    pub fn power(&self, scene_radius: f32) -> f32 {
        let disc = PI * scene_radius * scene_radius;
        match self {
            Light::Environment(env) => 4.0 * PI * disc * env.mean_luminance(),
            Light::Distant(d) => disc * luminance(d.irradiance),
            Light::Rect(r) => {
                let sides = if r.two_sided { 2.0 } else { 1.0 };
                sides * PI * r.area * luminance(r.radiance)
            }
        }
    }
}

impl Distant {
    fn in_disc(&self, wi: Vec3) -> bool {
        // |wi - d|^2 = 2 (1 - cos) keeps its precision for a sun-sized disc, where
        // 1 - dot(wi, d) would be mostly round-off.
        self.one_minus_cos > 0.0
            && (wi - self.direction).length_squared() <= 2.0 * self.one_minus_cos
    }
}

impl Rect {
    fn intersect(&self, org: Vec3, dir: Vec3) -> Option<f32> {
        let t = (self.corner - org).dot(self.normal) / dir.dot(self.normal);
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let q = org + dir * t - self.corner;
        let (a, b) = (q.dot(self.dual_u), q.dot(self.dual_v));
        ((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)).then_some(t)
    }

    /// Radiance and solid-angle pdf of the point at `distance` along the unit `wi`.
    fn eval(&self, wi: Vec3, distance: f32) -> Option<LightEval> {
        let cos_light = -wi.dot(self.normal);
        let cos = if self.two_sided {
            cos_light.abs()
        } else {
            cos_light
        };
        let pdf = distance * distance / (cos * self.area);
        (cos > 0.0 && pdf > 0.0 && pdf.is_finite()).then_some(LightEval {
            radiance: self.radiance,
            pdf,
            distance,
        })
    }
}
