//! The hair shading frame and h for hosts that trace their own rays: built exactly as the
//! renderer builds them (`math::frame::hair_frame_offset`), with degenerate input refused
//! by status instead of patched (docs/conventions.md, section 1).

use super::bsdf::{UNIT_TOLERANCE, is_unit, require, vec3};
use super::{Failure, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut};
use crate::error::invalid_arg;
use crate::math::Frame;
use crate::math::frame::hair_frame_offset;
use glam::Vec3;

/// How far past the radius (in radii) a ray may pass the axis and still count as a hit,
/// its h clamped to +-1: room for a host's intersection code (Embree's flat curves are
/// tessellated, and their hits reach 1.012 radii on a bent strand).
pub const HT_HAIR_FRAME_H_TOLERANCE: f32 = 5e-2;

/// The local frame of the hair BSDF at a hit, and the hit's offset h across the fibre.
///
/// THE CONVENTION (every BSDF call assumes it; nothing can detect a different one):
/// - `x` = normalize(tangent): along the fibre, root to tip.
/// - `y` = normalize(cross(x, d)), d the direction of the ray that hit: across the
///   fibre, perpendicular to the ray.
/// - `z` = cross(x, y): perpendicular to both, facing the viewer (dot(z, d) <= 0).
/// - `h` = dot(ray origin - axis point, y) / radius, in [-1, 1]: the signed offset of the
///   ray from the fibre's axis, *along +y*, in radii. `axis` is the point of the curve's
///   axis at the hit's curve parameter, `radius` the fibre radius there.
/// - `wo` and `wi` are unit vectors in this frame (|length - 1| <= 1e-3), both pointing
///   away from the fibre: `wo` toward the viewer (-d at a camera hit), `wi` toward the
///   light. At the hit that defines the frame, wo = -d/|d| has y = 0 and z >= 0.
/// - Ray along the tangent (cross(x, d) = 0): the fibre is seen end-on, every y
///   perpendicular to x is equally valid; `ht_hair_frame` picks one and measures h along
///   it.
///
/// DO NOT use pbrt's or Embree's ribbon coordinate (v, or h = -1 + 2 v) for h: it runs
/// along -y, and the call still returns HT_OK, with every azimuthal lobe mirrored. Example:
/// a fibre along +x, a ray d = (0, 0, -1) passing the axis at y = +0.5 radius gives
/// x = (1,0,0), y = (0,1,0), z = (0,0,1), h = +0.5, wo = (0,0,1); with alpha = 0 the R
/// lobe peaks at wi = (0, 0.866, 0.5) (light from the +y side). With h = -0.5 instead, the
/// highlight of a thick fibre lands half a radius on the wrong side. `ht_hair_frame`
/// computes all of this; use it, or check your frame against it once.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHairFrame {
    /// Unit tangent (world space).
    pub x: [f32; 3],
    /// Unit vector across the fibre, perpendicular to the ray (world space).
    pub y: [f32; 3],
    /// Unit vector toward the viewer, cross(x, y) (world space).
    pub z: [f32; 3],
    /// Offset of the ray from the axis along y, in radii, in [-1, 1].
    pub h: f32,
}

/// Builds the frame and h of a hit (the convention at `HtHairFrame`) from world-space
/// inputs and writes them to `*frame`; the frame is computed in double precision.
/// `ht_hair_point_at_hit` builds the same frame and the point there in one call; this one
/// is for a host that wants the frame itself (its axes, or h to check its own against).
///
/// - `tangent`: the curve's tangent at the hit (any non-zero length, root to tip);
///   `ray_org`, `ray_dir`: the ray that hit (any non-zero length); `axis`: the axis point
///   at the hit's curve parameter; `radius`: the fibre radius there, finite and > 0.
/// - Statuses: a NULL pointer, `HT_ERR_NULL_ARG` (checked first); misaligned pointers
///   (each 4-byte), `*frame` overlapping an input, a non-finite value, a zero tangent or
///   ray direction, a radius <= 0: `HT_ERR_INVALID_ARG`; a ray that passes the axis more
///   than `1 + HT_HAIR_FRAME_H_TOLERANCE` radii away (not a hit on this fibre: a diameter
///   passed as the radius, or the wrong axis point): `HT_ERR_INVALID_ARG`. Within the
///   tolerance h is clamped to +-1. `*frame` is untouched on error.
/// - A ray along the tangent is valid: HT_OK with an arbitrary y perpendicular to x.
///
/// Any thread; nothing is kept.
///
/// # Safety
/// Each float pointer is NULL or points to 3 floats; `frame` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_frame(
    tangent: *const f32,
    ray_org: *const f32,
    ray_dir: *const f32,
    axis: *const f32,
    radius: f32,
    frame: *mut HtHairFrame,
) -> HtStatus {
    boundary(|| {
        require(&[
            (tangent.cast(), "tangent"),
            (ray_org.cast(), "ray_org"),
            (ray_dir.cast(), "ray_dir"),
            (axis.cast(), "axis"),
            (frame.cast_const().cast(), "frame"),
        ])?;
        let inputs = [
            (tangent, "tangent"),
            (ray_org, "ray_org"),
            (ray_dir, "ray_dir"),
            (axis, "axis"),
        ];
        let mut v = [Vec3::ZERO; 4];
        for (v, &(p, name)) in v.iter_mut().zip(&inputs) {
            *v = vec3(host_slice(p, 3, name)?);
        }
        host_slice(frame.cast_const(), 1, "frame")?;
        let spans = inputs.map(|(p, name)| Span::of(name, p, 3));
        check_disjoint(&[Span::of("frame", frame, 1)], &spans)?;
        let [tangent, org, dir, axis] = v;
        let (axes, h) = hit_frame(tangent, org, dir, axis, radius)?;
        host_slice_mut(frame, 1, "frame")?[0] = HtHairFrame {
            x: axes.x.to_array(),
            y: axes.y.to_array(),
            z: axes.z.to_array(),
            h,
        };
        Ok(())
    })
}

/// The frame and h (clamped to +-1) of a hit, its values checked as `ht_hair_frame`
/// documents: finite, a non-zero tangent and ray direction, a radius finite and > 0, and a
/// ray within `1 + HT_HAIR_FRAME_H_TOLERANCE` radii of the axis.
#[inline(always)]
pub(super) fn hit_frame(
    tangent: Vec3,
    org: Vec3,
    dir: Vec3,
    axis: Vec3,
    radius: f32,
) -> Result<(Frame, f32), Failure> {
    let usable = tangent.is_finite()
        && org.is_finite()
        && dir.is_finite()
        && axis.is_finite()
        && tangent.length_squared() > 0.0
        && dir.length_squared() > 0.0
        && radius.is_finite()
        && radius > 0.0;
    if !usable {
        return Err(not_a_hit([tangent, org, dir, axis], radius));
    }
    let (axes, offset) = hair_frame_offset(tangent, dir, org, axis, radius);
    let limit = 1.0 + f64::from(HT_HAIR_FRAME_H_TOLERANCE);
    if offset.is_nan() || offset.abs() > limit {
        return Err(invalid_arg!(
            "the ray passes the axis {offset} radii away (radius = {radius}): not a hit \
             on this fibre (is the radius a diameter, or axis the wrong point?)"
        )
        .into());
    }
    Ok((axes, offset.clamp(-1.0, 1.0) as f32))
}

/// The message for the first of a hit's values that [`hit_frame`] refuses.
#[cold]
#[inline(never)]
fn not_a_hit(v: [Vec3; 4], radius: f32) -> Failure {
    let names = ["tangent", "ray_org", "ray_dir", "axis"];
    if let Some(k) = v.iter().position(|v| !v.is_finite()) {
        return invalid_arg!("{} = {}: must be finite", names[k], v[k]).into();
    }
    for (v, name) in [(v[0], "tangent"), (v[2], "ray_dir")] {
        if v.length_squared() == 0.0 {
            return invalid_arg!("{name} is zero: it must give a direction").into();
        }
    }
    invalid_arg!("radius = {radius}: must be finite and > 0").into()
}

/// The axes of a frame the host passed, checked: finite, unit and orthogonal to 1e-3,
/// right-handed.
#[inline(always)]
pub(super) fn checked_axes(f: &HtHairFrame) -> Result<Frame, Failure> {
    let [x, y, z] = [f.x, f.y, f.z].map(Vec3::from_array);
    let orthogonal = x.dot(y).abs().max(y.dot(z).abs()).max(z.dot(x).abs()) <= UNIT_TOLERANCE;
    if is_unit(x) && is_unit(y) && is_unit(z) && orthogonal && x.cross(y).dot(z) > 0.0 {
        Ok(Frame { x, y, z })
    } else {
        Err(not_a_frame(x, y, z))
    }
}

#[cold]
#[inline(never)]
fn not_a_frame(x: Vec3, y: Vec3, z: Vec3) -> Failure {
    invalid_arg!(
        "frame (x = {x}, y = {y}, z = {z}) is not a right-handed orthonormal frame (build it \
         with ht_hair_frame)"
    )
    .into()
}

// The tests compare the helper with the renderer's own frames and Embree's hits.
#[cfg(all(test, feature = "render"))]
mod tests {
    use super::super::bsdf::last_error;
    use super::*;
    use crate::scene::hit::hair_frame;

    fn frame(t: Vec3, org: Vec3, d: Vec3, axis: Vec3, r: f32) -> (HtStatus, HtHairFrame) {
        let mut out = HtHairFrame {
            x: [0.0; 3],
            y: [0.0; 3],
            z: [0.0; 3],
            h: 9.0,
        };
        let s = unsafe {
            ht_hair_frame(
                t.as_ref().as_ptr(),
                org.as_ref().as_ptr(),
                d.as_ref().as_ptr(),
                axis.as_ref().as_ptr(),
                r,
                &mut out,
            )
        };
        (s, out)
    }

    #[test]
    fn the_documented_example_and_the_renderer_agree() {
        // Fibre along +x, ray down -z passing the axis half a radius to +y.
        let (s, f) = frame(
            Vec3::X * 3.0,
            Vec3::new(0.0, 0.5, 5.0),
            -Vec3::Z * 2.0,
            Vec3::ZERO,
            1.0,
        );
        assert_eq!(s, HtStatus::HT_OK);
        assert_eq!(
            (f.x, f.y, f.z, f.h),
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 0.5)
        );
        let (t, org, d) = (
            Vec3::new(0.3, 1.0, -0.2),
            Vec3::new(0.1, 0.2, 4.0),
            Vec3::new(0.05, -0.1, -1.0),
        );
        let axis = Vec3::new(0.2, 0.25, 0.0);
        let (s, f) = frame(t, org, d, axis, 0.3);
        let (want, h) = hair_frame(t, d, org, axis, 0.3);
        assert_eq!(s, HtStatus::HT_OK);
        assert_eq!(
            (f.x, f.y, f.z, f.h),
            (want.x.to_array(), want.y.to_array(), want.z.to_array(), h)
        );
        // wo = -d has y = 0 and z > 0 in the frame.
        let axes = checked_axes(&f).ok().expect("a frame");
        let local = axes.to_local((-d).normalize());
        assert!(local.y.abs() < 1e-6 && local.z > 0.0, "{local:?}");
    }

    #[test]
    fn degenerate_inputs_get_a_status() {
        let (s, _) = frame(Vec3::ZERO, Vec3::Z, -Vec3::Z, Vec3::ZERO, 1.0);
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("tangent is zero"), "{}", last_error());
        let (s, _) = frame(Vec3::X, Vec3::new(0.0, 1.5, 1.0), -Vec3::Z, Vec3::ZERO, 1.0);
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("1.5 radii away"), "{}", last_error());
        let (s, f) = frame(
            Vec3::X,
            Vec3::new(0.0, 1.005, 1.0),
            -Vec3::Z,
            Vec3::ZERO,
            1.0,
        );
        assert_eq!((s, f.h), (HtStatus::HT_OK, 1.0));
        let (s, _) = frame(Vec3::X, Vec3::Z, -Vec3::Z, Vec3::ZERO, 0.0);
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("radius = 0"), "{}", last_error());
        // The ray runs along the fibre: any y across it, a valid frame.
        let (s, f) = frame(Vec3::X, Vec3::new(-5.0, 0.0, 0.0), Vec3::X, Vec3::ZERO, 1.0);
        assert_eq!(s, HtStatus::HT_OK);
        let [x, y, z] = [f.x, f.y, f.z].map(Vec3::from_array);
        assert!(x.dot(y).abs() < 1e-6 && (x.cross(y) - z).length() < 1e-6 && f.h == 0.0);
        // A mirrored (left-handed) frame is refused where a host's frame is read.
        let mirrored = HtHairFrame {
            z: (-z).to_array(),
            ..f
        };
        let Err(Failure(status, message)) = checked_axes(&mirrored) else {
            panic!("a mirrored frame was accepted")
        };
        assert_eq!(status, HtStatus::HT_ERR_INVALID_ARG);
        assert!(message.contains("right-handed"), "{message}");
        // A non-finite input is named.
        let (s, _) = frame(Vec3::X, Vec3::NAN, -Vec3::Z, Vec3::ZERO, 1.0);
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("ray_org = [NaN"), "{}", last_error());
    }

    /// Real hits from Embree, near the silhouette and on a bent tube, for every basis and
    /// both shapes: the helper accepts each (within its tolerance) and gives the renderer's
    /// frame and h.
    #[test]
    fn embree_hits_pass_through_the_helper_unchanged() {
        use crate::embree::{CurveBasis, CurveShape, Device, Ray, SceneOptions};
        use crate::scene::Strands;
        use crate::scene::curves::Curves;
        use crate::scene::tracer::TracerBuilder;
        use std::sync::Arc;
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let helix: Vec<[f32; 3]> = (0..9)
            .map(|k| {
                let t = 0.35 * k as f32;
                [1.5 * t.cos(), 1.5 * t.sin(), 0.4 * t]
            })
            .collect();
        let strands = Strands {
            radii: vec![0.05; helix.len()],
            counts: vec![helix.len() as u32],
            points: helix,
            colors: None,
        };
        let mut hits = 0;
        for basis in [
            CurveBasis::Linear,
            CurveBasis::Bezier,
            CurveBasis::BSpline,
            CurveBasis::CatmullRom,
        ] {
            for shape in [CurveShape::Round, CurveShape::Flat] {
                let curves = Curves::from_strands(&strands, basis, shape).unwrap();
                let mut b = TracerBuilder::new(device.clone(), SceneOptions::default()).unwrap();
                b.add_curves(curves).unwrap();
                let tracer = b.build().unwrap();
                // A grid of rays from two sides across the helix's bounds: hits at every h.
                for k in 0..2 * 120 * 120 {
                    let (side, i, j) = (k / 14400, (k / 120) % 120, k % 120);
                    let (x, z) = (-2.0 + 4.0 * i as f32 / 119.0, 2.8 * j as f32 / 119.0);
                    let org = if side == 0 {
                        Vec3::new(0.3, -6.0, 1.4)
                    } else {
                        Vec3::new(-6.0, 0.2, 0.5)
                    };
                    let target = if side == 0 {
                        Vec3::new(x, 0.0, z)
                    } else {
                        Vec3::new(0.0, x, z)
                    };
                    let ray = Ray::new(org, (target - org).normalize());
                    let Some(hit) = tracer.intersect(&ray).and_then(|h| h.as_hair().copied())
                    else {
                        continue;
                    };
                    hits += 1;
                    let (s, f) = frame(hit.frame.x, ray.org, ray.dir, hit.axis, hit.radius);
                    assert_eq!(s, HtStatus::HT_OK, "{basis:?} {shape:?}: {}", last_error());
                    // The same frame and h up to the rounding of the tangent, which the
                    // hit holds normalised in f32.
                    let close = |a: [f32; 3], b: Vec3| (Vec3::from_array(a) - b).length() < 1e-6;
                    let f0 = hit.frame;
                    assert!(
                        close(f.x, f0.x) && close(f.y, f0.y) && close(f.z, f0.z),
                        "{basis:?} {shape:?}: {f:?} against {f0:?}"
                    );
                    assert!(
                        (f.h - hit.h).abs() < 1e-5,
                        "{basis:?} {shape:?}: h {} against {}",
                        f.h,
                        hit.h
                    );
                }
            }
        }
        assert!(hits > 1000, "only {hits} hits");
    }
}
