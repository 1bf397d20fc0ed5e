//! The perspective camera: look-at placement, vertical field of view, optional thin lens,
//! and motion over the shutter.
//!
//! A moving camera holds its pose at K time steps spread evenly over the shutter, as a
//! geometry in motion does (`math::time_steps`), and a ray takes the pose at its time:
//! the eye, the lens and the image plane's size blend linearly between the two steps
//! around it, the orientation turns between them by spherical linear interpolation of
//! the two orientations' quaternions. Slerp rather than blending the axes and
//! orthonormalising again: it keeps the axes orthonormal by construction and turns at a
//! constant rate, as a camera panning between two keys does, where a blend of axes would
//! speed up in the middle of a large turn (and is undefined for a half turn).
//!
//! Image coordinates are normalised to [0, 1]^2 over the full frame, x to the right and
//! y down (row 0 at the top, as images are stored), so a crop or a tile never changes
//! which ray a pixel gets.

use std::sync::Arc;

use glam::{Mat3, Quat, Vec2, Vec3};

use crate::Result;
use crate::embree::MAX_TIME_STEPS;
use crate::error::invalid_arg;
use crate::math::sampling::concentric_disk;
use crate::math::time_steps::time_step;
use crate::validate::{self, non_negative, positive};

/// A perspective camera, still or moving over the shutter. Built validated, it generates
/// finite unit rays for any input.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// The pose of a still camera, and of a moving one where the shutter opens.
    pose: Pose,
    /// A moving camera's poses at its later time steps (the last where the shutter closes);
    /// empty for a still one.
    later: Arc<[Pose]>,
}

/// Where a camera is and what it sees at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pose {
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
        Ok(Self::still(Pose {
            eye,
            forward,
            right,
            up: right.cross(forward),
            half_extent: Vec2::new(half_width, tan_half),
            lens_radius: 0.0,
            focus_distance: view.length(),
        }))
    }

    fn still(pose: Pose) -> Self {
        Camera {
            pose,
            later: Arc::new([]),
        }
    }

    /// A camera moving over the shutter through `steps`, still cameras at time steps
    /// spread evenly from its opening to its closing (see the module doc), 1 to Embree's
    /// most, as a geometry's. Steps that are all one pose make a still camera.
    pub fn in_motion(steps: Vec<Camera>) -> Result<Self> {
        if !(1..=MAX_TIME_STEPS).contains(&steps.len()) {
            return Err(invalid_arg!(
                "{} camera time steps: a camera in motion takes 1 to {MAX_TIME_STEPS}",
                steps.len()
            ));
        }
        if let Some(k) = steps.iter().position(Camera::moves) {
            return Err(invalid_arg!(
                "camera time step {k} moves itself: each step is one pose"
            ));
        }
        let pose = steps[0].pose;
        let later: Vec<Pose> = steps[1..].iter().map(|c| c.pose).collect();
        Ok(Camera {
            pose,
            later: match later.iter().all(|&p| p == pose) {
                true => Arc::new([]),
                false => later.into(),
            },
        })
    }

    /// Whether the camera moves over the shutter.
    pub fn moves(&self) -> bool {
        !self.later.is_empty()
    }

    /// The still camera of this one's pose at `time`, a fraction of the shutter (see
    /// `math::time_steps`).
    pub fn at(&self, time: f32) -> Camera {
        Camera::still(self.pose_at(time))
    }

    /// Every pose, as a function of what it changes, in time order.
    fn map_poses(&self, f: impl Fn(Pose) -> Result<Pose>) -> Result<Self> {
        Ok(Camera {
            pose: f(self.pose)?,
            later: (self.later.iter().map(|&p| f(p))).collect::<Result<_>>()?,
        })
    }

    fn pose_at(&self, time: f32) -> Pose {
        if self.later.is_empty() {
            return self.pose;
        }
        let (k, f) = time_step(time, self.later.len() + 1);
        let step = |i: usize| if i == 0 { self.pose } else { self.later[i - 1] };
        let (a, b) = (step(k), step(k + 1));
        // At a step the pose is that step's, bit for bit.
        if f == 0.0 || a == b {
            return a;
        }
        if f == 1.0 {
            return b;
        }
        let turn = Mat3::from_quat(a.orientation().slerp(b.orientation(), f));
        let blend = |x: f32, y: f32| x + (y - x) * f;
        Pose {
            eye: a.eye.lerp(b.eye, f),
            forward: -turn.z_axis,
            right: turn.x_axis,
            up: turn.y_axis,
            half_extent: a.half_extent.lerp(b.half_extent, f),
            lens_radius: blend(a.lens_radius, b.lens_radius),
            focus_distance: blend(a.focus_distance, b.focus_distance),
        }
    }

    /// The same camera with a thin lens of `aperture_radius` (world units, >= 0; 0 is a
    /// pinhole) focused at `focus_distance` (> 0) along the view direction.
    /// Every pose of a moving camera takes it.
    pub fn with_thin_lens(&self, aperture_radius: f32, focus_distance: f32) -> Result<Self> {
        non_negative("camera aperture radius", aperture_radius)?;
        positive("camera focus distance", focus_distance)?;
        validate::length("camera aperture radius", aperture_radius)?;
        validate::length("camera focus distance", focus_distance)?;
        self.map_poses(|p| {
            Ok(Pose {
                lens_radius: aperture_radius,
                focus_distance,
                ..p
            })
        })
    }

    /// The same camera for an image of another `aspect` (width over height), keeping the
    /// vertical field of view: a scene's camera follows the size a command line asks for.
    pub fn with_aspect(&self, aspect: f32) -> Result<Self> {
        self.map_poses(|p| {
            let half_width = p.half_extent.y * aspect;
            if !(aspect.is_finite() && aspect > 0.0 && half_width.is_finite() && half_width > 0.0) {
                return Err(invalid_arg!(
                    "camera aspect {aspect} must be finite and > 0"
                ));
            }
            Ok(Pose {
                half_extent: Vec2::new(half_width, p.half_extent.y),
                ..p
            })
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

    /// The eye where the shutter opens (a still camera's only one).
    pub fn eye(&self) -> Vec3 {
        self.pose.eye
    }

    /// Unit view direction where the shutter opens; a hit's distance times
    /// `dot(dir, forward)` is its z depth.
    pub fn forward(&self) -> Vec3 {
        self.pose.forward
    }

    /// The side of one pixel of an image `height` pixels tall, per unit of distance from the
    /// eye, at the image centre (off-centre pixels cover a little less); for a moving
    /// camera the smallest over its poses, so that what is thinner than a pixel is so
    /// throughout the shutter.
    pub fn pixel_spread(&self, height: u32) -> f32 {
        let half_height =
            (self.later.iter()).fold(self.pose.half_extent.y, |m, p| m.min(p.half_extent.y));
        2.0 * half_height / height.max(1) as f32
    }

    /// Whether [`Self::ray`] uses its lens point (a thin lens at some time) or ignores it
    /// (a pinhole throughout).
    pub(crate) fn has_lens(&self) -> bool {
        std::iter::once(&self.pose)
            .chain(self.later.iter())
            .any(|p| p.lens_radius > 0.0)
    }

    /// The ray through the image point `ndc` in [0, 1]^2 (x right, y down, over the full
    /// frame), from the lens point picked by `lens` in [0, 1)^2 (ignored by a pinhole), at
    /// the shutter's opening: `(origin, unit direction)`.
    pub fn ray(&self, ndc: [f32; 2], lens: [f32; 2]) -> (Vec3, Vec3) {
        self.pose.ray(ndc, lens)
    }

    /// [`Self::ray`] from the pose at `time`, a fraction of the shutter.
    pub fn ray_at(&self, ndc: [f32; 2], lens: [f32; 2], time: f32) -> (Vec3, Vec3) {
        self.pose_at(time).ray(ndc, lens)
    }
}

impl Pose {
    /// The turn from the camera's own frame (x right, y up, looking down -z, as USD's
    /// cameras) to the world.
    fn orientation(&self) -> Quat {
        Quat::from_mat3(&Mat3::from_cols(self.right, self.up, -self.forward))
    }

    fn ray(&self, ndc: [f32; 2], lens: [f32; 2]) -> (Vec3, Vec3) {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn looking(eye: Vec3, yaw_deg: f32, fov: f32) -> Camera {
        let (s, c) = yaw_deg.to_radians().sin_cos();
        Camera::new(eye, eye + Vec3::new(s, 0.0, -c), Vec3::Y, fov, 1.5).unwrap()
    }

    /// Between two poses the eye and the image plane blend linearly and the view turns at
    /// a constant rate (slerp): a quarter of the way through a 60 degree pan looks 15
    /// degrees round, its axes orthonormal; at the steps the poses are the steps' own.
    #[test]
    fn a_pose_between_steps_blends_the_eye_and_turns_at_a_constant_rate() {
        let (a, b) = (
            looking(Vec3::ZERO, 0.0, 40.0),
            looking(Vec3::new(2.0, 0.0, 0.0), 60.0, 30.0),
        );
        let moving = Camera::in_motion(vec![a.clone(), b.clone()]).unwrap();
        assert!(moving.moves());
        assert_eq!(moving.at(0.0), a);
        assert_eq!(moving.at(1.0), b);
        let q = moving.at(0.25);
        let want = looking(Vec3::new(0.5, 0.0, 0.0), 15.0, 40.0);
        assert!(q.eye().abs_diff_eq(want.eye(), 1e-6));
        assert!(
            q.forward().abs_diff_eq(want.forward(), 1e-5),
            "{}",
            q.forward()
        );
        let p = q.pose;
        for (u, v) in [(p.forward, p.right), (p.right, p.up), (p.up, p.forward)] {
            assert!(u.dot(v).abs() < 1e-5 && (u.length() - 1.0).abs() < 1e-5);
        }
        let tan = |deg: f32| (deg.to_radians() / 2.0).tan();
        let half = 0.75 * tan(40.0) + 0.25 * tan(30.0);
        assert!((p.half_extent.y - half).abs() < 1e-6);
        // The smaller field of view's pixels are the smaller.
        assert_eq!(moving.pixel_spread(100), b.pixel_spread(100));
    }

    /// Three steps: a time falls between the two steps around it.
    #[test]
    fn a_time_takes_the_steps_around_it() {
        let steps: Vec<Camera> = (0..3)
            .map(|k| looking(Vec3::new(k as f32, 0.0, 0.0), 0.0, 40.0))
            .collect();
        let moving = Camera::in_motion(steps.clone()).unwrap();
        assert_eq!(moving.at(0.5), steps[1]);
        assert!(
            moving
                .at(0.75)
                .eye()
                .abs_diff_eq(Vec3::new(1.5, 0.0, 0.0), 1e-6)
        );
    }

    #[test]
    fn no_steps_too_many_or_a_moving_step_are_refused() {
        let c = looking(Vec3::ZERO, 0.0, 40.0);
        let e = Camera::in_motion(Vec::new()).unwrap_err().to_string();
        assert!(e.contains("0 camera time steps"), "{e}");
        let e = (Camera::in_motion(vec![c.clone(); MAX_TIME_STEPS + 1]).unwrap_err()).to_string();
        assert!(e.contains("camera time steps"), "{e}");
        let moving = Camera::in_motion(vec![c.clone(), looking(Vec3::X, 0.0, 40.0)]).unwrap();
        let e = Camera::in_motion(vec![c, moving]).unwrap_err().to_string();
        assert!(e.contains("time step 1"), "{e}");
    }
}
