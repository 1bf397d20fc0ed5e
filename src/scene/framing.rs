//! What an automatic camera frames, gathered while geometry is added: the points a groom
//! was given as (a polyline's points, or control points laid out for a basis), each
//! widened by its radius, or, in a scene without hair, the meshes' vertices.
//!
//! Every front end (scene files, the C ABI) frames through this one type, from the same
//! inputs, so the same content gets the same camera, and no BVH is built to find it.

use glam::Vec3;

use crate::error::Result;
use crate::scene::camera::Camera;
use crate::scene::strands::Strands;

/// The boxes an automatic camera frames: the hair's, else the meshes'.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Framing {
    hair: Bounds,
    meshes: Bounds,
}

impl Default for Framing {
    fn default() -> Self {
        Framing {
            hair: Bounds::EMPTY,
            meshes: Bounds::EMPTY,
        }
    }
}

impl Framing {
    /// A hair point of `radius` at `p`.
    pub fn add_hair_point(&mut self, p: Vec3, radius: f32) {
        self.hair.add(p, radius);
    }

    /// Every point of `strands`, widened by its radius.
    pub fn add_strands(&mut self, strands: &Strands) {
        for (p, r) in strands.points.iter().zip(&strands.radii) {
            self.add_hair_point(Vec3::from_array(*p), *r);
        }
    }

    /// Every control point (x, y, z, radius), widened by its radius.
    pub fn add_control_points(&mut self, points: &[[f32; 4]]) {
        for &[x, y, z, r] in points {
            self.add_hair_point(Vec3::new(x, y, z), r);
        }
    }

    /// The vertices of a mesh, framed only when the scene has no hair. (A scene file
    /// leaves its ground quads out: framing the stage would shrink the subject.)
    /// Adds what `other` frames: the frame of two sets of geometry is the frame of both.
    pub fn merge(&mut self, other: &Framing) {
        for (mine, theirs) in [
            (&mut self.hair, other.hair),
            (&mut self.meshes, other.meshes),
        ] {
            mine.lo = mine.lo.min(theirs.lo);
            mine.hi = mine.hi.max(theirs.hi);
        }
    }

    pub fn add_mesh(&mut self, positions: &[[f32; 3]]) {
        for p in positions {
            self.meshes.add(Vec3::from_array(*p), 0.0);
        }
    }

    /// The box to frame, lower and upper corners: the hair's, else the meshes'; None when
    /// nothing was added.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        [self.hair, self.meshes]
            .into_iter()
            .find(|b| !b.is_empty())
            .map(|b| (b.lo, b.hi))
    }

    /// The automatic camera for an image of `aspect` (width over height) with a vertical
    /// field of view of `fov_y_deg` ([`Camera::frame_bounds`]); None when nothing was
    /// added (the front end says what to do instead).
    pub fn camera(&self, aspect: f32, fov_y_deg: f32) -> Option<Result<Camera>> {
        let (lo, hi) = self.bounds()?;
        Some(Camera::frame_bounds(lo, hi, aspect, fov_y_deg))
    }
}

/// An axis-aligned box grown point by point.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
    };

    /// Grows the box to hold a ball of `radius` around `p`.
    fn add(&mut self, p: Vec3, radius: f32) {
        self.lo = self.lo.min(p - radius);
        self.hi = self.hi.max(p + radius);
    }

    fn is_empty(&self) -> bool {
        self.lo.cmpgt(self.hi).any()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hair_is_framed_before_meshes_and_widened_by_its_radii() {
        let mut f = Framing::default();
        assert_eq!(f.bounds(), None);
        assert!(f.camera(1.0, 35.0).is_none());
        f.add_mesh(&[[-10.0, 0.0, 0.0], [10.0, 1.0, 0.0]]);
        assert_eq!(
            f.bounds(),
            Some((Vec3::new(-10.0, 0.0, 0.0), Vec3::new(10.0, 1.0, 0.0)))
        );
        f.add_control_points(&[[0.0, 0.0, 0.0, 0.5], [1.0, 2.0, 3.0, 0.25]]);
        let strands = Strands {
            points: vec![[0.0, -1.0, 0.0], [0.0, 0.0, 0.0]],
            radii: vec![0.1, 0.1],
            counts: vec![2],
            colors: None,
        };
        f.add_strands(&strands);
        assert_eq!(
            f.bounds(),
            Some((Vec3::new(-0.5, -1.1, -0.5), Vec3::new(1.25, 2.25, 3.25)))
        );
        let (lo, hi) = f.bounds().unwrap();
        let framed = Camera::frame_bounds(lo, hi, 1.5, 35.0).unwrap();
        assert_eq!(f.camera(1.5, 35.0).unwrap().unwrap(), framed);
    }
}
