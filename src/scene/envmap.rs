//! Light from infinitely far away in every direction: a uniform sky (the furnace test's
//! light) or a lat-long HDR map, importance-sampled by luminance.
//!
//! # Orientation of a lat-long map
//! +y is up. The map's rows run from +y (top row) to -y (bottom row), polar angle
//! `theta = pi * v`; its columns run around the vertical axis with
//! `direction(u, v) = (-sin(theta) sin(2 pi u), cos(theta), sin(theta) cos(2 pi u))`,
//! so u = 0 (left edge) is +z, u = 0.25 is -x, u = 0.5 (the centre) is -z and u = 0.75
//! is +x. A camera at the origin looking down -z with +y up therefore sees the middle of
//! the image the right way round, not mirrored, as in most DCC tools. The map's rotation
//! turns it about +y, counter-clockwise seen from above (right-hand rule): at +90 degrees
//! the map's centre moves from -z to -x.

use std::f32::consts::PI;
use std::fmt;
use std::path::Path;

use glam::{Mat3, Vec3};

use super::light_sample::{LightSample, check_radiance};
use crate::Result;
use crate::error::invalid_arg;
use crate::image::read_image;
use crate::math::luminance;
use crate::math::sampling::{Distribution2D, UNIFORM_SPHERE_PDF, uniform_sphere};
use crate::validate::non_negative;

/// An environment light. Cheap to query from many threads at once (`Send + Sync`, no
/// interior mutability).
#[derive(Debug, Clone)]
pub struct Environment {
    source: Source,
    /// Map directions to world directions, and back (its transpose).
    to_world: Mat3,
    to_map: Mat3,
    scale: f32,
}

#[derive(Debug, Clone)]
enum Source {
    Uniform(Vec3),
    Map(LatLong),
}

/// The texels and their sampling distribution. Lookups take the nearest texel (no
/// filtering), so radiance is constant on exactly the cells the pdf is constant on and
/// importance sampling has no texel whose radiance it cannot reach.
#[derive(Clone)]
struct LatLong {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
    distribution: Distribution2D,
    /// Integral of luminance over the sphere, divided by 4 pi (for `power`).
    mean_luminance: f32,
}

impl fmt::Debug for LatLong {
    // The texels would be megabytes of output.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LatLong")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("mean_luminance", &self.mean_luminance)
            .finish_non_exhaustive()
    }
}

impl Environment {
    /// The same radiance from every direction: finite and >= 0 per channel.
    pub fn uniform(radiance: Vec3) -> Result<Self> {
        check_radiance("uniform environment radiance", radiance)?;
        Ok(Self::with_source(Source::Uniform(radiance)))
    }

    /// A lat-long map from interleaved linear pixels, rows from the top: `channels` is
    /// 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA); alpha is ignored. Every value must
    /// be finite and >= 0: a negative texel is an error rather than a silent clamp.
    pub fn from_pixels(
        width: usize,
        height: usize,
        channels: usize,
        pixels: &[f32],
    ) -> Result<Self> {
        if width == 0 || height == 0 || !(1..=4).contains(&channels) {
            return Err(invalid_arg!(
                "environment map of {width} x {height} pixels with {channels} channels: \
                 needs a non-empty image with 1 to 4 channels"
            ));
        }
        if width
            .checked_mul(height)
            .and_then(|n| n.checked_mul(channels))
            != Some(pixels.len())
        {
            return Err(invalid_arg!(
                "environment map of {width} x {height} x {channels} needs that many values, \
                 got {}",
                pixels.len()
            ));
        }
        if let Some(i) = pixels.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            let pixel = i / channels;
            return Err(invalid_arg!(
                "environment map pixel ({}, {}) channel {} is {}; radiance must be finite \
                 and >= 0",
                pixel % width,
                pixel / width,
                i % channels,
                pixels[i]
            ));
        }
        let texels: Vec<Vec3> = pixels
            .chunks_exact(channels)
            .map(|p| match channels {
                1 | 2 => Vec3::splat(p[0]),
                _ => Vec3::new(p[0], p[1], p[2]),
            })
            .collect();

        let mut weights = Vec::with_capacity(texels.len());
        let mut mean_luminance = 0.0f64;
        for (row, texels) in texels.chunks_exact(width).enumerate() {
            let theta = |r: usize| PI * r as f32 / height as f32;
            let sin_centre = (PI * (row as f32 + 0.5) / height as f32).sin();
            let cell_solid_angle =
                2.0 * PI / width as f32 * (theta(row).cos() - theta(row + 1).cos());
            for &t in texels {
                let y = luminance(t);
                weights.push(y * sin_centre);
                mean_luminance += f64::from(y * cell_solid_angle);
            }
        }
        let distribution = Distribution2D::new(&weights, width, height)?;
        Ok(Self::with_source(Source::Map(LatLong {
            width,
            height,
            texels,
            distribution,
            mean_luminance: (mean_luminance / (4.0 * std::f64::consts::PI)) as f32,
        })))
    }

    /// A lat-long map read through OpenImageIO (EXR, HDR, TIFF, ...), linear.
    pub fn from_file(path: &Path) -> Result<Self> {
        // A missing or unreadable file is an i/o error, not an image one.
        std::fs::File::open(path).map_err(|e| crate::Error::io(path, e))?;
        let image = read_image(path)?;
        Self::from_pixels(image.width, image.height, image.channels, &image.pixels)
            .map_err(|e| e.context(path.display()))
    }

    /// The same environment turned by `degrees` about +y (see the module doc).
    pub fn with_rotation(self, degrees: f32) -> Result<Self> {
        if !degrees.is_finite() {
            return Err(invalid_arg!("environment rotation {degrees} is not finite"));
        }
        let to_world = Mat3::from_rotation_y(degrees.to_radians());
        Ok(Self {
            to_world,
            to_map: to_world.transpose(),
            ..self
        })
    }

    /// The same environment with its radiance multiplied by `scale` (finite, >= 0).
    pub fn with_scale(self, scale: f32) -> Result<Self> {
        non_negative("environment scale", scale)?;
        Ok(Self { scale, ..self })
    }

    fn with_source(source: Source) -> Self {
        Self {
            source,
            to_world: Mat3::IDENTITY,
            to_map: Mat3::IDENTITY,
            scale: 1.0,
        }
    }

    /// Radiance arriving from the unit world direction `dir` (toward the sky).
    pub fn le(&self, dir: Vec3) -> Vec3 {
        match &self.source {
            Source::Uniform(l) => *l * self.scale,
            Source::Map(map) => map.texel(dir_to_uv(self.to_map * dir)) * self.scale,
        }
    }

    /// A direction toward the sky, importance-sampled by luminance for a map.
    pub fn sample(&self, u: [f32; 2]) -> Option<LightSample> {
        let (wi, radiance, pdf) = match &self.source {
            Source::Uniform(l) => (uniform_sphere(u), *l, UNIFORM_SPHERE_PDF),
            Source::Map(map) => {
                let (uv, uv_pdf) = map.distribution.sample(u);
                let (dir, sin_theta) = uv_to_dir(uv);
                (
                    self.to_world * dir,
                    map.texel(uv),
                    uv_to_solid_angle(uv_pdf, sin_theta)?,
                )
            }
        };
        Some(LightSample {
            wi,
            radiance: radiance * self.scale,
            pdf,
            distance: f32::INFINITY,
            is_delta: false,
        })
    }

    /// Radiance from the unit direction `dir` and the solid-angle pdf with which
    /// [`sample`](Self::sample) returns it: what MIS needs for a BSDF-sampled direction.
    pub fn eval(&self, dir: Vec3) -> (Vec3, f32) {
        match &self.source {
            Source::Uniform(l) => (*l * self.scale, UNIFORM_SPHERE_PDF),
            Source::Map(map) => {
                let uv = dir_to_uv(self.to_map * dir);
                let (_, sin_theta) = uv_to_dir(uv);
                let pdf = uv_to_solid_angle(map.distribution.pdf(uv), sin_theta).unwrap_or(0.0);
                (map.texel(uv) * self.scale, pdf)
            }
        }
    }

    /// The same radiance from every direction.
    pub(crate) fn is_uniform(&self) -> bool {
        matches!(self.source, Source::Uniform(_))
    }

    /// Luminance of the radiance averaged over all directions.
    pub(crate) fn mean_luminance(&self) -> f32 {
        self.scale
            * match &self.source {
                Source::Uniform(l) => luminance(*l),
                Source::Map(map) => map.mean_luminance,
            }
    }
}

impl LatLong {
    /// The texel holding `uv`, by the same cell arithmetic as the distribution, so that
    /// a sample's radiance is the one its pdf was built from.
    fn texel(&self, uv: [f32; 2]) -> Vec3 {
        let col = ((uv[0] * self.width as f32) as usize).min(self.width - 1);
        let row = ((uv[1] * self.height as f32) as usize).min(self.height - 1);
        self.texels[row * self.width + col]
    }
}

/// Map-space direction of the lat-long point `uv`, and sin(theta).
fn uv_to_dir(uv: [f32; 2]) -> (Vec3, f32) {
    let (sin_theta, cos_theta) = (PI * uv[1]).sin_cos();
    let (sin_phi, cos_phi) = (2.0 * PI * uv[0]).sin_cos();
    (
        Vec3::new(-sin_theta * sin_phi, cos_theta, sin_theta * cos_phi),
        sin_theta,
    )
}

/// Lat-long point of a unit map-space direction, in [0, 1]^2.
fn dir_to_uv(dir: Vec3) -> [f32; 2] {
    let v = dir.y.clamp(-1.0, 1.0).acos() / PI;
    let u = (-dir.x).atan2(dir.z) / (2.0 * PI);
    [if u < 0.0 { u + 1.0 } else { u }, v]
}

/// Solid-angle pdf from a pdf over the unit square of the lat-long map, whose Jacobian is
/// 2 pi^2 sin(theta). `None` at the poles, where the map has no area.
fn uv_to_solid_angle(uv_pdf: f32, sin_theta: f32) -> Option<f32> {
    (sin_theta > 0.0).then(|| uv_pdf / (2.0 * PI * PI * sin_theta))
}
