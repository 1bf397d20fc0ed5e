//! Hit records and the hair shading frame (docs/conventions.md).
//!
//! The frame and h are computed in f64 from the f32 inputs: h is a small offset (a fraction
//! of a fiber radius) taken from the difference of two points that may be far from the
//! origin and from the camera, and y must be exactly perpendicular to the ray, or the ray's
//! length leaks into h. In f64 both errors vanish and what remains is the f32 error of the
//! inputs themselves.

use glam::{Vec2, Vec3};

use super::curves::StrandSegment;
use super::material::HairColor;
use crate::embree::CurveShape;
use crate::math::Frame;
use crate::math::frame::hair_frame_offset;

/// The local frame of a hair hit and the ray's offset h across the fibre: x the tangent
/// (root to tip), y = normalize(cross(x, d)) for the ray direction d, z = cross(x, y),
/// facing back toward the viewer (z . d <= 0); h the offset of the ray from the axis point
/// `axis` along y in units of `radius`, clamped to [-1, 1].
///
/// Degenerate input never gives NaN: a zero tangent becomes a direction perpendicular
/// to the ray, and a ray along the tangent gets an arbitrary y perpendicular to x
/// (every y is then equally valid: the ray sees the fiber end-on).
pub(crate) fn hair_frame(
    tangent: Vec3,
    dir: Vec3,
    org: Vec3,
    axis: Vec3,
    radius: f32,
) -> (Frame, f32) {
    let (frame, offset) = hair_frame_offset(tangent, dir, org, axis, radius);
    let h = if radius > 0.0 && offset.is_finite() {
        offset.clamp(-1.0, 1.0) as f32
    } else {
        0.0
    };
    (frame, h)
}

/// A hit on a hair curve, with everything shading needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairHit {
    /// Distance along the ray, in units of its direction.
    pub t: f32,
    /// The hit point, `org + t dir`.
    pub p: Vec3,
    /// Unit geometric normal: the tube's outward normal for round curves, the ribbon's
    /// ray-facing normal (the frame's z) for flat ones.
    pub ng: Vec3,
    pub frame: Frame,
    /// Offset across the fiber in [-1, 1] (docs/conventions.md).
    pub h: f32,
    /// Axis point and fiber radius at the hit's curve parameter.
    pub axis: Vec3,
    pub radius: f32,
    pub shape: CurveShape,
    pub geom_id: u32,
    pub prim_id: u32,
    /// Parameter along the segment, in [0, 1], of the axis point the hit belongs to.
    pub u: f32,
    /// Embree's v: 0 on round curves, the offset across a flat ribbon in [-1, 1] (along -y;
    /// `h` is the more accurate measure, see `src/scene/tests/curves_geometry.rs`).
    pub v: f32,
    /// The strand and segment hit.
    pub strand: StrandSegment,
    /// Position along the strand: root 0, tip 1.
    pub s: f32,
    /// The groom's absorption here, when it gives one
    /// ([`super::curves::StrandIndex::absorption`]).
    pub absorption: Option<HairColor>,
    /// The groom's curve normal here, when it gives them ([`super::curves::StrandIndex::normal`]):
    /// the direction an elliptical fibre's major axis turns toward.
    pub normal: Option<Vec3>,
    /// The time of the ray that hit (`Ray::time`), at which the strand was met and is
    /// shaded, and which the rays leaving it keep.
    pub time: f32,
}

impl HairHit {
    /// The major axis of an elliptical fibre's section here, as a (y, z) direction of the
    /// hit's frame: the groom's curve normal made perpendicular to the tangent; where the
    /// groom has none, or it runs along the tangent, world up (+y) so made, or world +x
    /// where the tangent is too near vertical for that ([`MIN_MAJOR_AXIS_SQUARED`] of the
    /// unit vector). A property of the fibre, not of the ray, so that camera and shadow
    /// rays see one section (docs/conventions.md, section 4b).
    pub(crate) fn major_axis(&self) -> Vec2 {
        let x = self.frame.x;
        let off = |a: Vec3| {
            let a = a.normalize_or_zero();
            Some(a - x * x.dot(a)).filter(|m| m.length_squared() > MIN_MAJOR_AXIS_SQUARED)
        };
        let m = (self.normal.and_then(off))
            .or_else(|| off(Vec3::Y))
            .or_else(|| off(Vec3::X))
            .unwrap_or(Vec3::ZERO);
        Vec2::new(m.dot(self.frame.y), m.dot(self.frame.z))
    }
}

/// Below this squared length a unit direction is too near the tangent to orient the section.
const MIN_MAJOR_AXIS_SQUARED: f32 = 1e-6;

/// A hit on a triangle mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    pub t: f32,
    pub p: Vec3,
    /// Unit geometric normal, in the winding's orientation (counter-clockwise front).
    pub ng: Vec3,
    /// Unit shading normal: interpolated vertex normals when the mesh has them, else `ng`;
    /// always in the same hemisphere as `ng`.
    pub ns: Vec3,
    pub geom_id: u32,
    pub prim_id: u32,
    /// Barycentric coordinates of vertices 1 and 2.
    pub u: f32,
    pub v: f32,
    /// The time of the ray that hit (`Ray::time`), which the rays leaving it keep.
    pub time: f32,
}

/// The closest hit of a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hit {
    Hair(HairHit),
    Surface(SurfaceHit),
}

impl Hit {
    pub fn t(&self) -> f32 {
        match self {
            Hit::Hair(h) => h.t,
            Hit::Surface(s) => s.t,
        }
    }

    pub fn p(&self) -> Vec3 {
        match self {
            Hit::Hair(h) => h.p,
            Hit::Surface(s) => s.p,
        }
    }

    pub fn geom_id(&self) -> u32 {
        match self {
            Hit::Hair(h) => h.geom_id,
            Hit::Surface(s) => s.geom_id,
        }
    }

    /// The time of the ray that hit.
    pub fn time(&self) -> f32 {
        match self {
            Hit::Hair(h) => h.time,
            Hit::Surface(s) => s.time,
        }
    }

    #[cfg(any(test, feature = "bench-internals"))]
    pub fn as_hair(&self) -> Option<&HairHit> {
        match self {
            Hit::Hair(h) => Some(h),
            Hit::Surface(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn design_worked_example() {
        // Fiber along +x, ray along -z passing at y = +0.5 radius.
        let (f, h) = hair_frame(
            Vec3::X,
            -Vec3::Z,
            Vec3::new(0.3, 0.5, 10.0),
            Vec3::new(0.3, 0.0, 0.0),
            1.0,
        );
        assert_eq!((f.x, f.y, f.z), (Vec3::X, Vec3::Y, Vec3::Z));
        assert_eq!(h, 0.5);
        let w = Vec3::new(0.2, -0.4, 0.7).normalize();
        assert!((f.to_world(f.to_local(w)) - w).length() < 1e-6);
    }

    #[test]
    fn degenerate_inputs_give_a_finite_orthonormal_frame() {
        for (t, d) in [
            (Vec3::ZERO, Vec3::Z),
            (Vec3::X, Vec3::X),
            (Vec3::X, -Vec3::X),
            (Vec3::ZERO, Vec3::ZERO),
            (Vec3::new(1e-30, 0.0, 0.0), Vec3::Y),
        ] {
            let (f, h) = hair_frame(t, d, Vec3::ONE, Vec3::ZERO, 0.0);
            for v in [f.x, f.y, f.z] {
                assert!((v.length() - 1.0).abs() < 1e-6, "{t} {d} {f:?}");
            }
            assert!(f.x.dot(f.y).abs() < 1e-6 && f.x.dot(f.z).abs() < 1e-6);
            assert!(f.z.dot(d) <= 1e-6);
            assert_eq!(h, 0.0);
        }
        let (_, h) = hair_frame(Vec3::X, -Vec3::Z, Vec3::Y * 5.0, Vec3::ZERO, 1.0);
        assert_eq!(h, 1.0);
    }

    /// A hit on a strand along `tangent`, seen along -z, with the groom's `normal`.
    fn hit(tangent: Vec3, normal: Option<Vec3>) -> HairHit {
        let (frame, h) = hair_frame(tangent, -Vec3::Z, Vec3::Z, Vec3::ZERO, 1.0);
        HairHit {
            t: 1.0,
            p: Vec3::ZERO,
            ng: frame.z,
            frame,
            h,
            axis: Vec3::ZERO,
            radius: 1.0,
            shape: CurveShape::Round,
            geom_id: 0,
            prim_id: 0,
            u: 0.0,
            v: 0.0,
            strand: StrandSegment {
                strand: 0,
                segment: 0,
                segments: 1,
                first_prim: 0,
                id: 0,
            },
            s: 0.0,
            absorption: None,
            normal,
            time: 0.0,
        }
    }

    /// The major axis in world space.
    fn axis(h: &HairHit) -> Vec3 {
        let m = h.major_axis();
        h.frame.y * m.x + h.frame.z * m.y
    }

    /// The groom's normal, made perpendicular to the strand, orients the section whatever
    /// its length; one along the strand, zero or none falls back to world up so made, and
    /// a vertical strand to world x.
    #[test]
    fn the_major_axis_follows_the_normal_else_the_stated_rule() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(close(
            axis(&hit(Vec3::X, Some(Vec3::new(0.0, 0.0, 5.0)))),
            Vec3::Z
        ));
        let n = axis(&hit(tilted, Some(Vec3::new(0.3, 2.0, 0.0))));
        assert!(n.dot(tilted).abs() < 1e-6 && n.y > 0.9, "{n}");
        for normal in [None, Some(Vec3::ZERO), Some(3.0 * Vec3::X)] {
            assert!(close(axis(&hit(Vec3::X, normal)), Vec3::Y), "{normal:?}");
        }
        assert!(close(axis(&hit(Vec3::Y, None)).abs(), Vec3::X));
    }
}
