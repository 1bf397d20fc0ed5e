//! The perspective camera: look-at placement, vertical field of view, optional thin lens.
//!
//! Image coordinates are normalised to [0, 1]^2 over the full frame, x to the right and
//! y down (row 0 at the top, as images are stored), so a crop or a tile never changes
//! which ray a pixel gets.

use glam::{Vec2, Vec3};

use crate::Result;
use crate::error::invalid_arg;
use crate::math::sampling::concentric_disk;
use crate::validate::{self, non_negative, positive};

/// A perspective camera. Built validated, it generates finite unit rays for any input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye: Vec3,
    /// Unit view, image-right and image-up directions.
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// Half width and half height of the image plane at distance 1, so that a ray needs
    /// no trigonometry.
    half_extent: Vec2,
    lens_radius: f32,
    focus_distance: f32,
}

impl Camera {
    /// Vertical field of view of a camera that does not give one: a portrait lens's.
    pub const DEFAULT_FOV_Y_DEG: f32 = 35.0;

    /// A pinhole camera at `eye` looking at `target`, with `up` giving the image's
    /// upward direction (it need not be perpendicular to the view, only not parallel),
    /// `fov_y_deg` the vertical field of view in degrees, in (0, 180), and `aspect` the
    /// image width over its height.
    pub fn new(eye: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32, aspect: f32) -> Result<Self> {
        validate::position("camera eye", eye)?;
        validate::position("camera target", target)?;
        if !up.is_finite() {
            return Err(invalid_arg!("camera up {up} is not finite"));
        }
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
            return Err(invalid_arg!(
                "camera vertical fov {fov_y_deg} degrees must be in (0, 180)"
            ));
        }
        positive("camera aspect", aspect)?;
        let view = target - eye;
        let forward = view.try_normalize().ok_or_else(|| {
            invalid_arg!("camera eye {eye} and target {target} must be distinct points")
        })?;
        let up_n = up
            .try_normalize()
            .ok_or_else(|| invalid_arg!("camera up {up} must be non-zero"))?;
        let right = forward.cross(up_n);
        // Under a hundredth of a degree from the view direction, "up" no longer picks a
        // roll angle reliably.
        if right.length() < 2e-4 {
            return Err(invalid_arg!(
                "camera up {up} is parallel to the view direction {forward}"
            ));
        }
        let right = right.normalize();
        let tan_half = (fov_y_deg.to_radians() / 2.0).tan();
        let half_width = tan_half * aspect;
        if !(tan_half.is_finite() && half_width.is_finite() && half_width > 0.0) {
            return Err(invalid_arg!(
                "camera fov {fov_y_deg} degrees and aspect {aspect} give an unusable image plane"
            ));
        }
        Ok(Self {
            eye,
            forward,
            right,
            up: right.cross(forward),
            half_extent: Vec2::new(half_width, tan_half),
            lens_radius: 0.0,
            focus_distance: view.length(),
        })
    }

    /// The same camera with a thin lens of `aperture_radius` (world units, >= 0; 0 is a
    /// pinhole) focused at `focus_distance` (> 0) along the view direction.
    pub fn with_thin_lens(self, aperture_radius: f32, focus_distance: f32) -> Result<Self> {
        non_negative("camera aperture radius", aperture_radius)?;
        positive("camera focus distance", focus_distance)?;
        validate::length("camera aperture radius", aperture_radius)?;
        validate::length("camera focus distance", focus_distance)?;
        Ok(Self {
            lens_radius: aperture_radius,
            focus_distance,
            ..self
        })
    }

    /// The same camera for an image of another `aspect` (width over height), keeping the
    /// vertical field of view: a scene's camera follows the size a command line asks for.
    pub fn with_aspect(self, aspect: f32) -> Result<Self> {
        let half_width = self.half_extent.y * aspect;
        if !(aspect.is_finite() && aspect > 0.0 && half_width.is_finite() && half_width > 0.0) {
            return Err(invalid_arg!(
                "camera aspect {aspect} must be finite and > 0"
            ));
        }
        Ok(Self {
            half_extent: Vec2::new(half_width, self.half_extent.y),
            ..self
        })
    }

    /// A camera that frames the box `[lo, hi]` for a quick look at a groom: it looks at
    /// the box centre from the front (+z), a little to the right and above (+y is up), at
    /// the distance where the bounding sphere fits both fields of view with a small margin.
    pub fn frame_bounds(lo: Vec3, hi: Vec3, aspect: f32, fov_y_deg: f32) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all()) {
            return Err(invalid_arg!(
                "cannot frame the box from {lo} to {hi}: corners must be finite and ordered"
            ));
        }
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0 && aspect.is_finite() && aspect > 0.0) {
            return Err(invalid_arg!(
                "cannot frame with fov {fov_y_deg} degrees and aspect {aspect}"
            ));
        }
        /// A three-quarter view: this far to the right of +z and above the horizon.
        const AZIMUTH_DEG: f32 = 20.0;
        const ELEVATION_DEG: f32 = 15.0;
        /// The sphere fills 90% of the narrower field of view.
        const MARGIN: f32 = 1.0 / 0.9;
        let centre = (lo + hi) / 2.0;
        // A point-sized box still gets a camera at a finite, representable distance.
        let floor = 1e-4 * centre.abs().max_element().max(1.0);
        let radius = ((hi - lo).length() / 2.0).max(floor);
        let half_y = fov_y_deg.to_radians() / 2.0;
        let half_x = (half_y.tan() * aspect).atan();
        let distance = MARGIN * radius / half_y.min(half_x).sin();
        let (sin_az, cos_az) = AZIMUTH_DEG.to_radians().sin_cos();
        let (sin_el, cos_el) = ELEVATION_DEG.to_radians().sin_cos();
        let view = Vec3::new(sin_az * cos_el, sin_el, cos_az * cos_el);
        Self::new(centre + view * distance, centre, Vec3::Y, fov_y_deg, aspect)
    }

    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// Unit view direction; a hit's distance times `dot(dir, forward)` is its z depth.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// The side of one pixel of an image `height` pixels tall, per unit of distance from the
    /// eye, at the image centre (off-centre pixels cover a little less).
    pub fn pixel_spread(&self, height: u32) -> f32 {
        2.0 * self.half_extent.y / height.max(1) as f32
    }

    /// Whether [`Self::ray`] uses its lens point (a thin lens) or ignores it (a pinhole).
    pub(crate) fn has_lens(&self) -> bool {
        self.lens_radius > 0.0
    }

    /// The ray through the image point `ndc` in [0, 1]^2 (x right, y down, over the full
    /// frame), from the lens point picked by `lens` in [0, 1)^2 (ignored by a pinhole):
    /// `(origin, unit direction)`.
    pub fn ray(&self, ndc: [f32; 2], lens: [f32; 2]) -> (Vec3, Vec3) {
        let screen = Vec2::new(2.0 * ndc[0] - 1.0, 1.0 - 2.0 * ndc[1]) * self.half_extent;
        let d = self.forward + self.right * screen.x + self.up * screen.y;
        if self.lens_radius == 0.0 {
            return (self.eye, d.normalize());
        }
        // Every ray through the lens meets the pinhole ray on the plane of focus.
        let focus = self.eye + d * self.focus_distance;
        let l = concentric_disk(lens) * self.lens_radius;
        let origin = self.eye + self.right * l.x + self.up * l.y;
        (origin, (focus - origin).normalize())
    }
}
