//! The view a view-dependent build chose its detail for (the `auto` shape's ribbons today,
//! any level of detail chosen from the camera), and the one rule that says whether
//! another view may reuse that build.
//!
//! Every such choice compares a strand's size with the side of a pixel where it lies
//! (the footprint: distance from the eye times [`Camera::pixel_spread`]), and each is
//! safe when the footprint grows: a strand found thinner than a pixel, or closer to its
//! polyline than a fraction of one, stays so; a strand kept at full detail stays at full
//! detail, which is never wrong, only slower. So a new view keeps the build when, at every
//! control point, its footprint is at least the built view's, within
//! [`FOOTPRINT_TOLERANCE`]. The rule compares with the view the build was made for, never
//! with a later view that reused it, so that small steps cannot add up.

use glam::Vec3;
use rayon::prelude::*;

use crate::embree::{Geometry, Scene};
use crate::error::{Result, invalid_arg};
use crate::scene::camera::Camera;

/// How much smaller, relatively, a pixel's footprint may become at a control point while
/// the build made for the larger one is kept: the choices have far coarser thresholds
/// (one pixel, a twentieth of one), and this also covers the points between control points,
/// whose footprint follows theirs to within about (segment / distance)^2 / 8.
pub const FOOTPRINT_TOLERANCE: f32 = 1e-3;

/// A camera and the height, in pixels, of the image it renders: what the side of a pixel
/// is at each point.
#[derive(Debug, Clone, PartialEq)]
pub struct DetailView {
    pub camera: Camera,
    pub height: u32,
    /// The level of detail's tolerance in pixels (`lod_pixels`): a build holds only for
    /// its own.
    pub lod_pixels: f32,
}

impl DetailView {
    pub fn new(camera: Camera, height: u32, lod_pixels: f32) -> Self {
        DetailView {
            camera,
            height,
            lod_pixels,
        }
    }

    /// Whether a build may choose detail for this view: not for a camera that moves, whose
    /// footprints change over the shutter; its curves keep their full detail, which is
    /// never wrong, only slower.
    pub fn chooses(&self) -> bool {
        !self.camera.moves()
    }

    /// Whether choices made for this view hold for `new` at every one of `points` (x, y,
    /// z, radius; the radius is not used): at each, `new`'s footprint is at least this
    /// view's times 1 - [`FOOTPRINT_TOLERANCE`]. A lens, the aspect and the target play
    /// no part, and the same eye with pixels no smaller needs no look at the points. No
    /// choice is made for a moving camera ([`DetailView::chooses`]), so none holds for one.
    pub fn holds_for(&self, new: &DetailView, points: &[[f32; 4]]) -> bool {
        if self.lod_pixels != new.lod_pixels || !new.chooses() {
            return false;
        }
        let (built, now) = (
            self.camera.pixel_spread(self.height),
            new.camera.pixel_spread(new.height),
        );
        let floor = built * (1.0 - FOOTPRINT_TOLERANCE);
        if self.camera.eye() == new.camera.eye() {
            return now >= floor;
        }
        let (eye, new_eye) = (self.camera.eye(), new.camera.eye());
        points.par_chunks(1 << 14).all(|chunk| {
            chunk.iter().all(|&[x, y, z, _]| {
                let p = Vec3::new(x, y, z);
                now * new_eye.distance(p) >= floor * eye.distance(p)
            })
        })
    }
}

/// The curve geometries of a scene whose detail was chosen for one view, and that view.
#[derive(Debug, Clone, Default)]
pub struct ViewDependent {
    view: Option<DetailView>,
    geometries: Vec<u32>,
}

impl ViewDependent {
    /// Refuses a second view: one scene's choices are made for one view.
    pub(crate) fn check(&self, view: &DetailView) -> Result<()> {
        match self.view {
            Some(ref v) if v != view => Err(invalid_arg!(
                "curves shaped for two different views cannot share one scene"
            )),
            _ => Ok(()),
        }
    }

    /// Records geometry `id`, made for `view` (checked first with [`Self::check`]).
    pub(crate) fn push(&mut self, id: u32, view: DetailView) {
        self.view = Some(view);
        self.geometries.push(id);
    }

    /// Whether `new` may render `scene` as built: [`DetailView::holds_for`] at every
    /// control point of the view-dependent geometries, at each of their time steps; always,
    /// without any.
    pub fn holds_for(&self, scene: &Scene, new: &DetailView) -> bool {
        let Some(built) = &self.view else {
            return true;
        };
        self.geometries
            .iter()
            .all(|&id| match scene.geometries().get(id as usize) {
                Some(Geometry::Curves(c)) => c.steps().all(|step| built.holds_for(new, step)),
                _ => true,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(eye: Vec3, fov: f32, height: u32) -> DetailView {
        DetailView::new(
            Camera::new(eye, Vec3::ZERO, Vec3::Y, fov, 1.0).unwrap(),
            height,
            crate::scene::lod::DEFAULT_LOD_PIXELS,
        )
    }

    #[test]
    fn a_view_holds_while_every_footprint_stays_as_large() {
        let points = [[0.0, 0.0, 0.0, 0.01], [0.5, 0.0, 0.0, 0.01]];
        let built = view(Vec3::new(0.0, 0.0, 4.0), 40.0, 100);
        assert!(built.holds_for(&built, &points));
        // Another level of detail is another build.
        let finer = DetailView {
            lod_pixels: built.lod_pixels / 2.0,
            ..built.clone()
        };
        assert!(!built.holds_for(&finer, &points));
        // Farther, a wider field of view or fewer pixels: larger footprints.
        assert!(built.holds_for(&view(Vec3::new(0.0, 0.0, 5.0), 40.0, 100), &points));
        assert!(built.holds_for(&view(Vec3::new(0.0, 0.0, 4.0), 50.0, 100), &points));
        assert!(built.holds_for(&view(Vec3::new(0.0, 0.0, 4.0), 40.0, 80), &points));
        // A lens changes nothing.
        let lens = DetailView {
            camera: built.camera.with_thin_lens(0.1, 3.0).unwrap(),
            ..built.clone()
        };
        assert!(built.holds_for(&lens, &points));
        // A moving camera chooses nothing, so no choice holds for it, even one that
        // starts at the built view.
        let moving = Camera::in_motion(vec![built.camera.clone(), lens.camera.clone()]);
        let moving = DetailView {
            camera: moving.unwrap().at(0.0),
            ..built.clone()
        };
        assert!(moving.chooses() && built.holds_for(&moving, &points));
        let moving = DetailView {
            camera: Camera::in_motion(vec![
                built.camera.clone(),
                view(Vec3::new(0.0, 0.0, 5.0), 40.0, 100).camera,
            ])
            .unwrap(),
            ..built.clone()
        };
        assert!(!moving.chooses() && !built.holds_for(&moving, &points));
        // Nearer, narrower or more pixels: smaller footprints somewhere.
        assert!(!built.holds_for(&view(Vec3::new(0.0, 0.0, 3.9), 40.0, 100), &points));
        assert!(!built.holds_for(&view(Vec3::new(0.0, 0.0, 4.0), 39.0, 100), &points));
        assert!(!built.holds_for(&view(Vec3::new(0.0, 0.0, 4.0), 40.0, 101), &points));
        // Turned around the origin at the same distance: the far point came nearer.
        let turned = view(Vec3::new(4.0, 0.0, 0.0), 40.0, 100);
        assert!(!built.holds_for(&turned, &points));
        assert!(built.holds_for(&turned, &points[..1]));
        // Within the tolerance: a step of a ten-thousandth nearer still holds.
        assert!(built.holds_for(&view(Vec3::new(0.0, 0.0, 3.9996), 40.0, 100), &points[..1]));
    }
}
