//! The Huang 2022 model of elliptical fibres for hosts: its parameters, a prepared handle
//! and a per-vertex point in storage the host owns, filled and read by the same code as
//! Chiang's (`prepared.rs`; docs/c-abi.md, section 12b). The point is the Rust
//! `HuangPoint`, near or far field as the host chooses, so it gives the same bits.

use super::bsdf::{check_u, read3};
use super::frame::HtHairFrame;
use super::prepared::{
    HostPoint, check_init, eval_world, fill, framed, framed_hit, hit_args, prepare, sample_world,
};
use super::{Failure, HtStatus, boundary, free_handle};
use crate::bsdf::inputs::check_major;
use crate::bsdf::{HuangBsdf, HuangField, HuangParams, HuangPoint};
use crate::error::invalid_arg;
use crate::math::Frame;
use glam::Vec3;

/// Parameters of the Huang et al. 2022 model of elliptical fibres (docs/conventions.md,
/// section 4b), all checked, never clamped:
/// - `sigma_a`: absorption per unit major semi-axis (the curve's radius), linear RGB, each
///   finite and >= 0 (`ht_hair_sigma_a_*` give it).
/// - `eta`: index of refraction, in (1, 3].
/// - `roughness`: GGX roughness of the cuticle, in [0.01, 1].
/// - `aspect`: minor over major axis of the section, in [0.05, 1] (1 is round); turn the
///   section with the major axis the point calls take, not with an aspect above 1.
/// - `alpha`: cuticle scale tilt in *degrees*, in [-20, 20] (pbrt's sign, as
///   `HtHairParams`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHuangParams {
    /// Absorption per unit major semi-axis, linear RGB, finite, >= 0.
    pub sigma_a: [f32; 3],
    /// Index of refraction of the fiber, (1, 3].
    pub eta: f32,
    /// GGX roughness of the cuticle, [0.01, 1].
    pub roughness: f32,
    /// Minor over major axis, [0.05, 1].
    pub aspect: f32,
    /// Cuticle scale tilt, degrees, [-20, 20].
    pub alpha: f32,
}

impl From<HtHuangParams> for HuangParams {
    fn from(p: HtHuangParams) -> Self {
        HuangParams {
            sigma_a: p.sigma_a,
            eta: p.eta,
            roughness: p.roughness,
            aspect: p.aspect,
            alpha: p.alpha,
        }
    }
}

impl From<HuangParams> for HtHuangParams {
    fn from(p: HuangParams) -> Self {
        HtHuangParams {
            sigma_a: p.sigma_a,
            eta: p.eta,
            roughness: p.roughness,
            aspect: p.aspect,
            alpha: p.alpha,
        }
    }
}

/// Brown hair as `ht_hair_params_default` gives it (absorption, eta, tilt), GGX roughness
/// 0.3, round (aspect 1). Cannot fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_huang_params_default() -> HtHuangParams {
    HuangParams::default().into()
}

/// Which part of the fibre a Huang point sees: `HT_HUANG_NEAR`, `HT_HUANG_FAR` or
/// `HT_HUANG_FAR_LIT`.
pub type HtHuangField = u32;
/// The near field: the fibre at the hit's h, for a fibre wider than the pixel that sees it.
pub const HT_HUANG_NEAR: HtHuangField = 0;
/// The far field: the fibre averaged across its width at two offsets stratified from the
/// hit's h, for a strand no wider than its pixel where no light is sampled (unbiased when
/// h is uniform over the width, as at bounces).
pub const HT_HUANG_FAR: HtHuangField = 1;
/// The far field at four offsets, for a thin strand's or a bounce's point that also weighs
/// sampled lights (next-event estimation): its values toward the lights are less noisy.
/// The renderer's own rule (docs/conventions.md, section 4b).
pub const HT_HUANG_FAR_LIT: HtHuangField = 2;

/// The Huang model prepared for one parameter set. Create with `ht_huang_prepare`, release
/// with `ht_huang_prepared_free`. Immutable: any number of threads may use one handle at
/// once.
pub struct HtHuangPrepared {
    pub(super) bsdf: HuangBsdf,
}

/// Bytes of an `HtHuangPoint`: a far-field point holds the paths of several offsets across
/// the fibre; the rest leaves room for the model to grow without changing the ABI.
pub const HT_HUANG_POINT_SIZE: usize = 4096;
/// Alignment of an `HtHuangPoint` in bytes.
pub const HT_HUANG_POINT_ALIGN: usize = 16;

/// Storage for the Huang model at one shading point, filled by `ht_huang_point_at_hit`,
/// `ht_huang_point_init_world` or `ht_huang_point_init_strand`, then evaluated and sampled
/// any number of times. The rules of `HtHairPoint` hold: the host allocates it
/// (`HT_HUANG_POINT_SIZE` bytes aligned to `HT_HUANG_POINT_ALIGN`, which this type has),
/// the bytes are opaque plain numbers that may be copied and outlive their
/// `HtHuangPrepared`, an unfilled point (or a Chiang one) is refused, and filling it while
/// another thread reads it is a data race.
#[repr(C, align(16))]
pub struct HtHuangPoint {
    pub opaque: [u8; HT_HUANG_POINT_SIZE],
}

impl HostPoint for HtHuangPoint {
    type Point = HuangPoint;
    /// "htgg" (GGX) and a layout version.
    const TAG: u64 = 0x6874_6767_0000_0002;
    const FILLED_BY: &'static str = "ht_huang_point_at_hit or ht_huang_point_init_world";
}

const _: () = {
    let () = <HtHuangPoint as HostPoint>::FITS;
    assert!(
        size_of::<HtHuangPoint>() == HT_HUANG_POINT_SIZE
            && align_of::<HtHuangPoint>() == HT_HUANG_POINT_ALIGN
    );
};

/// Prepares the Huang model for `*params` (see `HtHuangParams` for the ranges) and writes
/// the new handle to `*out`.
///
/// - `params`, `out`: not NULL (`HT_ERR_NULL_ARG`), aligned for their types. A parameter
///   out of range (an `aspect` of 0, above 1 or NaN included): `HT_ERR_INVALID_ARG` naming
///   it, and `*out` is left untouched.
/// - The handle is owned by the host: release it with `ht_huang_prepared_free`. Points
///   filled from it keep their own copy and outlive it.
///
/// Any thread.
///
/// # Safety
/// `params` is NULL or points to an `HtHuangParams`; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_huang_prepare(
    params: *const HtHuangParams,
    out: *mut *mut HtHuangPrepared,
) -> HtStatus {
    boundary(|| {
        prepare(params, out, |p| {
            Ok(HtHuangPrepared {
                bsdf: HuangBsdf::new(&p.into())?,
            })
        })
    })
}

/// Releases a prepared Huang model (NULL: nothing to do; returns HT_OK). Points filled
/// from it stay valid. Freeing a handle twice, or while another thread uses it, is
/// undefined behaviour.
///
/// # Safety
/// `prepared` is NULL or a live handle from `ht_huang_prepare`, not used after this call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_huang_prepared_free(prepared: *mut HtHuangPrepared) -> HtStatus {
    boundary(|| {
        free_handle(prepared);
        Ok(())
    })
}

/// A renderer's hair hit to a ready Huang point, in one call: the hit's frame and h as
/// `ht_hair_point_at_hit` builds them, and the point of `prepared` there, seen from
/// wo = -normalize(ray_dir). Equal, bit for bit, to `ht_hair_frame` followed by
/// `ht_huang_point_init_world` with the same `major`, `jitter` and `field`.
///
/// - `tangent`, `ray_org`, `ray_dir`, `axis`, `radius`: as `ht_hair_point_at_hit` takes
///   and refuses them.
/// - `major[3]`: the section's major axis in world space, any length: finite, and not
///   along the tangent (the sine of its angle to it at most 1e-3) nor zero, else
///   `HT_ERR_INVALID_ARG`. Its part along the tangent is ignored. A property of the
///   fibre: pass the same for camera and shadow rays. Any direction serves a round fibre
///   (aspect 1). The renderer's own choice is world up made perpendicular to the tangent,
///   or world +x where the tangent is vertical.
/// - `jitter[2]`: each in [0, 1) (`HT_ERR_INVALID_ARG`): the numbers the point draws its
///   microfacet normals from (docs/conventions.md, section 4b). Fresh uniform numbers at each hit make a render unbiased for
///   the model; a fixed pair gives a deterministic BSDF, whose eval, pdf and sample agree
///   exactly either way.
/// - `field`: `HT_HUANG_NEAR`, `HT_HUANG_FAR` or `HT_HUANG_FAR_LIT`; any other value:
///   `HT_ERR_INVALID_ARG`.
/// - Pointers: not NULL (`HT_ERR_NULL_ARG`, checked first); the floats 4-byte and `point`
///   16-byte aligned; no input may lie inside `*point` (`HT_ERR_INVALID_ARG`). On error
///   `*point` is untouched.
///
/// Any thread; `prepared` may be shared, `point` must not be read meanwhile.
///
/// # Safety
/// `prepared` is NULL or a live handle; each float pointer NULL or 3 floats (`jitter` 2);
/// `point` NULL or writable storage of `HT_HUANG_POINT_SIZE` bytes.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ht_huang_point_at_hit(
    prepared: *const HtHuangPrepared,
    tangent: *const f32,
    ray_org: *const f32,
    ray_dir: *const f32,
    axis: *const f32,
    radius: f32,
    major: *const f32,
    jitter: *const f32,
    field: HtHuangField,
    point: *mut HtHuangPoint,
) -> HtStatus {
    boundary(|| {
        let hit = hit_args(tangent, ray_org, ray_dir, axis);
        let [t, o, d, a] = hit;
        let inputs = [t, o, d, a, (major, "major", 3), (jitter, "jitter", 2)];
        check_init(prepared, &inputs, None, point)?;
        let (axes, h, wo) = framed_hit(&hit, radius)?;
        // SAFETY: non-NULL, aligned and clear of the inputs (checked); a live handle (the
        // caller's promise).
        let bsdf = unsafe { &(*prepared).bsdf };
        // SAFETY: as above.
        unsafe { fill_huang(point, bsdf, (axes, h, wo), (major, jitter, field)) }
    })
}

/// The Huang point of `prepared` at a hit's frame: h is `frame->h`, `wo[3]` is in world
/// space, as `ht_hair_point_init_world` takes them (and refuses them); `major`, `jitter`
/// and `field` as `ht_huang_point_at_hit` takes them. With the axes (1,0,0), (0,1,0),
/// (0,0,1) every direction is its local form, and the major axis a (0, y, z) direction.
///
/// - Pointers: not NULL (`HT_ERR_NULL_ARG`, checked first); `frame` and the floats 4-byte
///   and `point` 16-byte aligned; no input may lie inside `*point` (`HT_ERR_INVALID_ARG`).
///   On error `*point` is untouched.
///
/// Any thread; `prepared` may be shared, `point` must not be read meanwhile.
///
/// # Safety
/// `prepared` is NULL or a live handle; `frame` NULL or an `HtHairFrame`; `wo`, `major`
/// NULL or 3 floats, `jitter` NULL or 2; `point` NULL or writable storage of
/// `HT_HUANG_POINT_SIZE` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_huang_point_init_world(
    prepared: *const HtHuangPrepared,
    frame: *const HtHairFrame,
    wo: *const f32,
    major: *const f32,
    jitter: *const f32,
    field: HtHuangField,
    point: *mut HtHuangPoint,
) -> HtStatus {
    boundary(|| {
        let inputs = [(wo, "wo", 3), (major, "major", 3), (jitter, "jitter", 2)];
        check_init(prepared, &inputs, Some(frame), point)?;
        let (axes, h, wo) = framed(frame, wo)?;
        // SAFETY: as in `ht_huang_point_at_hit`.
        let bsdf = unsafe { &(*prepared).bsdf };
        // SAFETY: as in `ht_huang_point_at_hit`.
        unsafe { fill_huang(point, bsdf, (axes, h, wo), (major, jitter, field)) }
    })
}

/// The Rust point a field names; None for an unknown field.
fn field_point(field: HtHuangField) -> Option<HuangField> {
    match field {
        HT_HUANG_NEAR => Some(HuangBsdf::near),
        HT_HUANG_FAR => Some(HuangBsdf::far),
        HT_HUANG_FAR_LIT => Some(HuangBsdf::far_lit),
        _ => None,
    }
}

/// Checks the section's orientation, the jitter and the field of a point init whose
/// pointers `check_init` passed, and writes the point of `bsdf` at (h, wo) and `frame`.
///
/// # Safety
/// `point` is non-NULL, aligned, writable and not read by anyone meanwhile; `major` and
/// `jitter` are non-NULL, aligned and hold 3 and 2 floats.
#[inline(always)]
pub(super) unsafe fn fill_huang(
    point: *mut HtHuangPoint,
    bsdf: &HuangBsdf,
    (frame, h, wo): (Frame, f32, Vec3),
    (major, jitter, field): (*const f32, *const f32, HtHuangField),
) -> Result<(), Failure> {
    let given = read3(major);
    let major = check_major(frame.to_local(given), given, "major")?;
    // SAFETY: non-NULL and aligned (checked by `check_init`), 2 floats (the caller's
    // promise).
    let jitter = check_u(unsafe { jitter.cast::<[f32; 2]>().read() }, "jitter")?;
    let at = field_point(field).ok_or_else(|| {
        invalid_arg!(
            "field = {field}: must be HT_HUANG_NEAR ({HT_HUANG_NEAR}), HT_HUANG_FAR \
             ({HT_HUANG_FAR}) or HT_HUANG_FAR_LIT ({HT_HUANG_FAR_LIT})"
        )
    })?;
    // SAFETY: the caller's promise; the closure writes a whole point.
    unsafe { fill(point, frame, |p| p.write(at(bsdf, h, wo, major, jitter))) };
    Ok(())
}

/// f |cos| and the pdf toward the world `wi[3]` at a filled Huang point, as
/// `ht_hair_point_eval_world` gives them at a Chiang point (the same checks, statuses and
/// outputs). The pdf is exact: the density of `ht_huang_point_sample_world` at wi.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HUANG_POINT_SIZE` readable bytes; `wi`, `f_cos` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_huang_point_eval_world(
    point: *const HtHuangPoint,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| eval_world(point, wi, f_cos, pdf))
}

/// A sampled direction at a filled Huang point: `wi[3]` (world), `f_cos[3]`, `weight[3]`
/// = f_cos / pdf and `*pdf`, as `ht_hair_point_sample_world` writes them (the same checks,
/// statuses and outputs). pdf = 0 (and zeros) means no direction: also where the draw met
/// total internal reflection on its way out, so the sampled density integrates to less
/// than 1 by that fraction.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HUANG_POINT_SIZE` readable bytes; `u`, `wi`, `f_cos`, `weight`
/// NULL or 3 floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_huang_point_sample_world(
    point: *const HtHuangPoint,
    u: *const f32,
    wi: *mut f32,
    f_cos: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| sample_world(point, u, [wi, f_cos, weight], pdf))
}

#[cfg(test)]
mod tests {
    use super::super::bsdf::last_error;
    use super::super::frame::{checked_axes, ht_hair_frame};
    #[cfg(feature = "render")]
    use super::super::huang_strand::ht_huang_point_init_strand;
    use super::super::prepared::{HT_HAIR_POINT_SIZE, HtHairPoint};
    use super::*;
    use glam::Vec2;
    use std::collections::BTreeSet;
    use std::ptr::{null, null_mut};

    fn point() -> HtHuangPoint {
        HtHuangPoint {
            opaque: [0; HT_HUANG_POINT_SIZE],
        }
    }

    fn prepare(p: &HtHuangParams) -> *mut HtHuangPrepared {
        let mut handle = null_mut();
        let s = unsafe { ht_huang_prepare(p, &mut handle) };
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        handle
    }

    /// The frame whose world directions are the local ones, at offset `h`.
    fn local(h: f32) -> HtHairFrame {
        HtHairFrame {
            x: [1.0, 0.0, 0.0],
            y: [0.0, 1.0, 0.0],
            z: [0.0, 0.0, 1.0],
            h,
        }
    }

    /// `ht_huang_point_eval_world`: status, f |cos|, pdf.
    fn eval(p: &HtHuangPoint, wi: Vec3) -> (HtStatus, [f32; 3], f32) {
        let (mut f_cos, mut pdf) = ([0.0f32; 3], 0.0f32);
        let wi = wi.to_array();
        let s = unsafe { ht_huang_point_eval_world(p, wi.as_ptr(), f_cos.as_mut_ptr(), &mut pdf) };
        (s, f_cos, pdf)
    }

    /// `ht_huang_point_sample_world`: status, then wi, f |cos|, weight, pdf.
    fn sample(p: &HtHuangPoint, u: [f32; 3]) -> (HtStatus, [[f32; 3]; 3], f32) {
        let (mut out, mut pdf) = ([[0.0f32; 3]; 3], 0.0f32);
        let [wi, f_cos, weight] = &mut out;
        let s = unsafe {
            ht_huang_point_sample_world(
                p,
                u.as_ptr(),
                wi.as_mut_ptr(),
                f_cos.as_mut_ptr(),
                weight.as_mut_ptr(),
                &mut pdf,
            )
        };
        (s, out, pdf)
    }

    /// What the C calls must give for the Rust point `rust` behind `axes`: f |cos| and
    /// pdf toward the world `wi`; a sample's world wi, f |cos|, weight and pdf (zeros for
    /// none).
    fn want(rust: &HuangPoint, axes: &Frame, wi: Vec3, u: [f32; 3]) -> ([f32; 4], [f32; 10]) {
        let l = axes.to_local(wi);
        let e = rust.eval(l);
        let fc = e.f * l.z.abs();
        let s = rust
            .sample(u)
            .map(|s| (s, s.f * s.wi.z.abs()))
            .filter(|(s, fc)| (*fc / s.pdf).is_finite())
            .map_or([0.0; 10], |(s, fc)| {
                let (d, w) = (axes.to_world(s.wi), fc / s.pdf);
                [d.x, d.y, d.z, fc.x, fc.y, fc.z, w.x, w.y, w.z, s.pdf]
            });
        ([fc.x, fc.y, fc.z, e.pdf], s)
    }

    /// What the C calls gave, as [`want`] lays it out.
    fn got(p: &HtHuangPoint, wi: Vec3, u: [f32; 3]) -> ([f32; 4], [f32; 10]) {
        let (s, fc, pdf) = eval(p, wi);
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let (s, [d, sfc, w], spdf) = sample(p, u);
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let mut sampled = [0.0; 10];
        for (k, v) in d.iter().chain(&sfc).chain(&w).chain([&spdf]).enumerate() {
            sampled[k] = *v;
        }
        ([fc[0], fc[1], fc[2], pdf], sampled)
    }

    fn bits<const N: usize>(v: [f32; N]) -> [u32; N] {
        v.map(f32::to_bits)
    }

    /// At the local frame, over random parameters, offsets, directions, orientations,
    /// jitters and both fields, every C call gives the bits of the Rust `HuangPoint`, and a
    /// byte copy of the point serves after its handle is freed.
    #[test]
    fn points_give_the_rust_bits_near_and_far() {
        let mut x = 0.377f32;
        let mut next = || {
            x = (x * 997.13 + 0.31).fract();
            x
        };
        for k in 0..300 {
            let params = HtHuangParams {
                sigma_a: [next() * 4.0, next() * 2.0, next()],
                eta: 1.1 + next(),
                roughness: 0.01 + 0.99 * next(),
                aspect: 0.05 + 0.95 * next(),
                alpha: 40.0 * next() - 20.0,
            };
            let bsdf = HuangBsdf::new(&params.into()).unwrap();
            let handle = prepare(&params);
            let h = 2.0 * next() - 1.0;
            let wo = Vec3::new(next() - 0.5, next() - 0.5, next() + 0.05).normalize();
            let major = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            let jitter = [next(), next()];
            let field = [HT_HUANG_NEAR, HT_HUANG_FAR, HT_HUANG_FAR_LIT][k % 3];
            let mut pt = point();
            let s = unsafe {
                let (wo, major) = (wo.to_array(), major.to_array());
                ht_huang_point_init_world(
                    handle,
                    &local(h),
                    wo.as_ptr(),
                    major.as_ptr(),
                    jitter.as_ptr(),
                    field,
                    &mut pt,
                )
            };
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            assert_eq!(unsafe { ht_huang_prepared_free(handle) }, HtStatus::HT_OK);
            let copy = HtHuangPoint { opaque: pt.opaque };
            let yz = Vec2::new(major.y, major.z);
            let rust = field_point(field).unwrap()(&bsdf, h, wo, yz, jitter);
            let wi = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let u = [next(), next(), next()];
            let axes = Frame {
                x: Vec3::X,
                y: Vec3::Y,
                z: Vec3::Z,
            };
            let (we, ws) = want(&rust, &axes, wi, u);
            let (ge, gs) = got(&copy, wi, u);
            assert_eq!((bits(ge), bits(gs)), (bits(we), bits(ws)), "case {k}");
        }
    }

    /// A hit to a point in one call is `ht_hair_frame` then `ht_huang_point_init_world`, and
    /// the world calls are the Rust point's behind the frame's conversions, with the world
    /// major axis taken to the frame, bit for bit.
    #[test]
    fn a_hit_gives_the_framed_point_of_the_rust_calls() {
        let params = HtHuangParams {
            aspect: 0.6,
            roughness: 0.2,
            ..ht_huang_params_default()
        };
        let (handle, bsdf) = (prepare(&params), HuangBsdf::new(&params.into()).unwrap());
        let mut lit = 0;
        for k in 0..120 {
            let a = 0.37 * k as f32;
            let tangent = Vec3::new(a.cos(), a.sin(), 0.3 * (2.0 * a).sin()) * 2.0;
            let dir = Vec3::new((1.7 * a).sin(), -0.4, (0.9 * a).cos()) * 0.5;
            let across_ray = tangent.cross(dir).normalize();
            let (radius, axis) = (0.03, Vec3::new(1.0, -2.0, 0.5));
            let org = axis + across_ray * (0.61 * k as f32).sin() * 0.95 * radius - dir * 8.0;
            let major = Vec3::new(0.2, 1.0, (0.3 * a).sin()).to_array();
            let jitter = [(0.17 * k as f32).fract(), (0.29 * k as f32).fract()];
            let field = [HT_HUANG_FAR, HT_HUANG_NEAR, HT_HUANG_FAR_LIT, HT_HUANG_NEAR][k % 4];
            let hit = [tangent, org, dir, axis].map(|v| v.to_array());
            let [t, o, d, x] = hit.each_ref().map(|v| v.as_ptr());
            let (mut at_hit, mut framed) = (point(), point());
            let mut frame = local(0.0);
            unsafe {
                let (m, j) = (major.as_ptr(), jitter.as_ptr());
                let s = ht_huang_point_at_hit(handle, t, o, d, x, radius, m, j, field, &mut at_hit);
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
                let s = ht_hair_frame(t, o, d, x, radius, &mut frame);
                assert_eq!(s, HtStatus::HT_OK);
                let wo = (-dir.normalize()).to_array();
                let s = ht_huang_point_init_world(
                    handle,
                    &frame,
                    wo.as_ptr(),
                    m,
                    j,
                    field,
                    &mut framed,
                );
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            }
            let axes = checked_axes(&frame).ok().expect("a frame");
            let (wo, m) = (
                axes.to_local(-dir.normalize()),
                axes.to_local(Vec3::from_array(major)),
            );
            let m = Vec2::new(m.y, m.z);
            let rust = field_point(field).unwrap()(&bsdf, frame.h, wo, m, jitter);
            let wi = Vec3::new(0.3, (1.3 * a).cos(), (1.3 * a).sin()).normalize();
            let u = [(0.13 * k as f32).fract(), 0.42, (0.71 * k as f32).fract()];
            let (we, ws) = want(&rust, &axes, wi, u);
            let (ge, gs) = got(&at_hit, wi, u);
            assert_eq!((bits(ge), bits(gs)), (bits(we), bits(ws)), "at hit {k}");
            let (fe, fs) = got(&framed, wi, u);
            assert_eq!((bits(fe), bits(fs)), (bits(we), bits(ws)), "framed {k}");
            lit += usize::from(we[3] > 0.0);
        }
        assert!(lit > 60, "light reaches {lit} of 120 points");
        unsafe { ht_huang_prepared_free(handle) };
    }

    /// Parameters out of range, a major axis along the fibre, zero or NaN, a jitter out of
    /// [0, 1), an unknown field, NULLs (first), and points that are not Huang points are
    /// refused with messages naming the argument; nothing is written.
    #[test]
    fn bad_input_is_refused_with_named_messages() {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let fails = |status: HtStatus, want: HtStatus, words: &str| {
            assert_eq!(status, want, "{words}: {}", last_error());
            assert!(last_error().contains(words), "{}", last_error());
        };
        let ok = ht_huang_params_default();
        let mut untouched = null_mut();
        for (p, words) in [
            (
                HtHuangParams { aspect: 0.0, ..ok },
                "aspect = 0: must be in [0.05, 1]",
            ),
            (HtHuangParams { aspect: 1.5, ..ok }, "aspect = 1.5"),
            (
                HtHuangParams {
                    aspect: f32::NAN,
                    ..ok
                },
                "aspect = NaN",
            ),
            (
                HtHuangParams {
                    roughness: 0.0,
                    ..ok
                },
                "roughness = 0",
            ),
            (HtHuangParams { eta: 1.0, ..ok }, "eta = 1"),
        ] {
            fails(
                unsafe { ht_huang_prepare(&p, &mut untouched) },
                INVALID,
                words,
            );
            assert!(untouched.is_null(), "a refused prepare wrote");
        }
        fails(
            unsafe { ht_huang_prepare(null(), null_mut()) },
            NULL,
            "params is NULL",
        );
        let handle = prepare(&ok);
        let (wo, frame) = ([0.0f32, 0.0, 1.0], local(0.3));
        let init = |major: [f32; 3], jitter: [f32; 2], field, pt: *mut HtHuangPoint| unsafe {
            let (m, j) = (major.as_ptr(), jitter.as_ptr());
            ht_huang_point_init_world(handle, &frame, wo.as_ptr(), m, j, field, pt)
        };
        let mut pt = point();
        let y = [0.0f32, 1.0, 0.0];
        fails(
            init([2.0, 0.0, 0.0], [0.5; 2], 0, &mut pt),
            INVALID,
            "major = [2, 0, 0]: lies along the fibre",
        );
        fails(
            init([0.0; 3], [0.5; 2], 0, &mut pt),
            INVALID,
            "major = [0, 0, 0]: lies along",
        );
        fails(
            init([1.0, 1e-4, 0.0], [0.5; 2], 0, &mut pt),
            INVALID,
            "lies along the fibre",
        );
        fails(
            init([0.0, f32::NAN, 1.0], [0.5; 2], 0, &mut pt),
            INVALID,
            "major = [0, NaN, 1]: must be finite",
        );
        fails(
            init(y, [0.5, 1.0], 0, &mut pt),
            INVALID,
            "jitter[1] = 1: must be in [0, 1)",
        );
        fails(
            init(y, [f32::NAN, 0.5], 0, &mut pt),
            INVALID,
            "jitter[0] = NaN",
        );
        fails(
            init(y, [0.5; 2], 3, &mut pt),
            INVALID,
            "field = 3: must be HT_HUANG_NEAR (0), HT_HUANG_FAR (1) or HT_HUANG_FAR_LIT (2)",
        );
        assert_eq!(pt.opaque, [0; HT_HUANG_POINT_SIZE], "a refused init wrote");
        // NULL before any value.
        let s = unsafe {
            ht_huang_point_init_world(
                handle,
                &frame,
                wo.as_ptr(),
                null(),
                [2.0f32; 2].as_ptr(),
                9,
                &mut pt,
            )
        };
        fails(s, NULL, "major is NULL");
        let (t, o, d, x) = (
            [1.0f32, 0.0, 0.0],
            [0.0f32, 0.5, 4.0],
            [0.0f32, 0.0, -1.0],
            [0.0f32; 3],
        );
        let s = unsafe {
            ht_huang_point_at_hit(
                handle,
                t.as_ptr(),
                o.as_ptr(),
                d.as_ptr(),
                x.as_ptr(),
                f32::NAN,
                y.as_ptr(),
                null(),
                0,
                &mut pt,
            )
        };
        fails(s, NULL, "jitter is NULL");
        let s = unsafe {
            ht_huang_point_at_hit(
                handle,
                t.as_ptr(),
                o.as_ptr(),
                d.as_ptr(),
                x.as_ptr(),
                1.0,
                t.as_ptr(),
                [0.5f32; 2].as_ptr(),
                0,
                &mut pt,
            )
        };
        fails(s, INVALID, "major = [1, 0, 0]: lies along the fibre");
        // The major axis may not lie inside the point it fills.
        let inside = pt.opaque.as_ptr().cast::<f32>();
        let s = unsafe {
            ht_huang_point_init_world(
                handle,
                &frame,
                wo.as_ptr(),
                inside,
                [0.5f32; 2].as_ptr(),
                0,
                &mut pt,
            )
        };
        fails(s, INVALID, "point and major overlap");
        // An unfilled point, and a Chiang point's bytes, are not Huang points.
        let wi = Vec3::new(0.0, 0.6, 0.8);
        fails(
            eval(&pt, wi).0,
            INVALID,
            "not filled by ht_huang_point_at_hit",
        );
        let mut chiang = point();
        let chiang_point = chiang.opaque.as_mut_ptr().cast::<HtHairPoint>();
        let hair = super::super::bsdf::ht_hair_params_default();
        unsafe {
            let mut prepared = null_mut();
            assert_eq!(
                super::super::prepared::ht_hair_prepare(&hair, &mut prepared),
                HtStatus::HT_OK
            );
            let s = super::super::prepared::ht_hair_point_init_world(
                prepared,
                &frame,
                wo.as_ptr(),
                chiang_point,
            );
            assert_eq!(s, HtStatus::HT_OK);
            super::super::prepared::ht_hair_prepared_free(prepared);
        }
        assert_ne!(chiang.opaque[..HT_HAIR_POINT_SIZE], [0; HT_HAIR_POINT_SIZE]);
        fails(
            sample(&chiang, [0.5; 3]).0,
            INVALID,
            "not filled by ht_huang_point_at_hit",
        );
        // Per direction: a unit wi, u in [0, 1).
        assert_eq!(init(y, [0.5; 2], HT_HUANG_FAR, &mut pt), HtStatus::HT_OK);
        fails(
            eval(&pt, Vec3::new(0.0, 0.0, 0.5)).0,
            INVALID,
            "wi (in the point's frame)",
        );
        fails(sample(&pt, [0.5, 1.0, 0.5]).0, INVALID, "u[1] = 1");
        unsafe { ht_huang_prepared_free(handle) };
    }

    /// A Huang material that varies over the groom, as the host gives it.
    #[cfg(feature = "render")]
    fn varied() -> (HtHuangParams, super::super::materials::HtHairVariation) {
        let params = HtHuangParams {
            roughness: 0.35,
            aspect: 0.6,
            alpha: 2.5,
            ..ht_huang_params_default()
        };
        let variation = super::super::materials::HtHairVariation {
            absorption_variation: 0.5,
            roughness_variation: 0.6,
            tip_absorption: 0.3,
            use_vertex_colors: 1,
            seed: 42,
        };
        (params, variation)
    }

    /// One strand's point init at the local frame of offset `h`, seen from `wo`, with the
    /// major axis (0, 1, 0.3).
    #[cfg(feature = "render")]
    #[allow(clippy::too_many_arguments)]
    fn init_strand(
        handle: *const HtHuangPrepared,
        variation: *const super::super::materials::HtHairVariation,
        (strand, s, color): (u32, f32, *const f32),
        h: f32,
        wo: Vec3,
        jitter: [f32; 2],
        field: HtHuangField,
        pt: *mut HtHuangPoint,
    ) -> HtStatus {
        let (wo, major) = (wo.to_array(), [0.0f32, 1.0, 0.3]);
        unsafe {
            ht_huang_point_init_strand(
                handle,
                variation,
                strand,
                s,
                color,
                &local(h),
                wo.as_ptr(),
                major.as_ptr(),
                jitter.as_ptr(),
                field,
                pt,
            )
        }
    }

    /// A strand's point is the model the renderer shades that strand's hits with (the
    /// scene material's `huang_at`, of the material `ht_scene_add_huang_material` makes of
    /// the same parameters and variation), bit for bit, near and far, with and without the
    /// strand's colour; strands differ in absorption and roughness.
    #[cfg(feature = "render")]
    #[test]
    fn strand_points_are_the_scene_materials_model() {
        use super::super::materials::huang_varied_material;
        use crate::scene::material::HairColor;
        let (params, variation) = varied();
        let handle = prepare(&params);
        let Ok(material) = huang_varied_material(params.into(), &variation) else {
            panic!("a valid variation")
        };
        let scene = material.prepare().unwrap();
        let (mut absorptions, mut roughnesses) = (BTreeSet::new(), BTreeSet::new());
        let axes = Frame {
            x: Vec3::X,
            y: Vec3::Y,
            z: Vec3::Z,
        };
        let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
        for k in 0..120u32 {
            let (strand, s) = (k * 7 % 53, (k % 11) as f32 / 10.0);
            let color = [0.3 + 0.005 * k as f32, 0.2, 0.1];
            let groom = (k % 2 == 0).then_some(color);
            let color_ptr = groom.as_ref().map_or(null(), |c| c.as_ptr());
            let h = 0.9 * (0.3 * k as f32).sin();
            let jitter = [(0.17 * k as f32).fract(), (0.29 * k as f32).fract()];
            let field = [HT_HUANG_FAR, HT_HUANG_NEAR, HT_HUANG_FAR_LIT][k as usize % 3];
            let mut pt = point();
            let st = init_strand(
                handle,
                &variation,
                (strand, s, color_ptr),
                h,
                wo,
                jitter,
                field,
                &mut pt,
            );
            assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
            let Some(bsdf) = scene.huang_at(strand, s, groom.map(HairColor::Color)) else {
                panic!("a Huang material")
            };
            absorptions.insert(bsdf.params().sigma_a.map(f32::to_bits));
            roughnesses.insert(bsdf.params().roughness.to_bits());
            let major = Vec2::new(1.0, 0.3);
            let rust = field_point(field).unwrap()(&bsdf, h, wo, major, jitter);
            let wi = Vec3::new(-0.2, 0.7, 0.5).normalize();
            let u = [0.61, 0.27, 0.83];
            let (we, ws) = want(&rust, &axes, wi, u);
            let (ge, gs) = got(&pt, wi, u);
            assert_eq!(
                (bits(ge), bits(gs)),
                (bits(we), bits(ws)),
                "strand {strand} s {s}"
            );
        }
        assert!(
            absorptions.len() > 100,
            "absorptions: {}",
            absorptions.len()
        );
        assert!(roughnesses.len() > 40, "roughnesses: {}", roughnesses.len());
        unsafe { ht_huang_prepared_free(handle) };
    }

    /// Without variation (any seed, a groom's colours asked for but none given) a strand's
    /// point is `ht_huang_point_init_world`'s, bit for bit; with it, strands at the same
    /// position, offset and directions scatter differently.
    #[cfg(feature = "render")]
    #[test]
    fn strand_points_vary_only_with_a_variation() {
        use super::super::materials::ht_hair_variation_default;
        let (params, variation) = varied();
        let handle = prepare(&params);
        let none = [
            ht_hair_variation_default(),
            super::super::materials::HtHairVariation {
                seed: 77,
                use_vertex_colors: 1,
                ..ht_hair_variation_default()
            },
        ];
        let wo = Vec3::new(-0.4, 0.1, 0.8).normalize();
        let wi = Vec3::new(0.3, -0.6, 0.5).normalize();
        let u = [0.2, 0.55, 0.4];
        let mut distinct = BTreeSet::new();
        for k in 0..40u32 {
            let (s, h, jitter) = ((k % 5) as f32 / 4.0, 0.3, [0.25, 0.75]);
            let field = if k % 2 == 0 {
                HT_HUANG_NEAR
            } else {
                HT_HUANG_FAR
            };
            let mut world = point();
            let st = unsafe {
                let (wo, major) = (wo.to_array(), [0.0f32, 1.0, 0.3]);
                let j = jitter.as_ptr();
                ht_huang_point_init_world(
                    handle,
                    &local(h),
                    wo.as_ptr(),
                    major.as_ptr(),
                    j,
                    field,
                    &mut world,
                )
            };
            assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
            let plain = got(&world, wi, u);
            for v in &none {
                let mut pt = point();
                let st = init_strand(handle, v, (k, s, null()), h, wo, jitter, field, &mut pt);
                assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
                let (e, smp) = got(&pt, wi, u);
                assert_eq!(
                    (bits(e), bits(smp)),
                    (bits(plain.0), bits(plain.1)),
                    "strand {k}"
                );
            }
            let mut pt = point();
            let st = init_strand(
                handle,
                &variation,
                (k, 0.5, null()),
                h,
                wo,
                jitter,
                HT_HUANG_NEAR,
                &mut pt,
            );
            assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
            distinct.insert(bits(got(&pt, wi, u).0));
        }
        assert_eq!(distinct.len(), 40, "40 strands scatter alike");
        unsafe { ht_huang_prepared_free(handle) };
    }

    /// A strand's point refuses what `ht_hair_point_init_strand` and
    /// `ht_huang_point_init_world` refuse, with their statuses and messages, NULLs first,
    /// and writes nothing.
    #[cfg(feature = "render")]
    #[test]
    fn bad_strand_input_is_refused_with_named_messages() {
        use super::super::materials::HtHairVariation;
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let fails = |status: HtStatus, want: HtStatus, words: &str| {
            assert_eq!(status, want, "{words}: {}", last_error());
            assert!(last_error().contains(words), "{words}: {}", last_error());
        };
        let (params, v) = varied();
        let handle = prepare(&params);
        let wo = Vec3::Z;
        let mut pt = point();
        let init = |v: *const HtHairVariation, s: f32, color: *const f32, pt: *mut HtHuangPoint| {
            init_strand(
                handle,
                v,
                (3, s, color),
                0.2,
                wo,
                [0.5; 2],
                HT_HUANG_NEAR,
                pt,
            )
        };
        let grey = [0.5f32; 3];
        fails(
            init(null(), 0.5, null(), &mut pt),
            NULL,
            "variation is NULL",
        );
        fails(init(&v, 0.5, null(), null_mut()), NULL, "point is NULL");
        fails(
            init(null(), f32::NAN, null(), null_mut()),
            NULL,
            "variation is NULL",
        );
        let st = init_strand(null(), &v, (3, 0.5, null()), 0.2, wo, [0.5; 2], 0, &mut pt);
        fails(st, NULL, "prepared is NULL");
        let mut words = [0u64; 8];
        let odd = unsafe { words.as_mut_ptr().cast::<u8>().add(4) }.cast::<HtHairVariation>();
        fails(init(odd, 0.5, null(), &mut pt), INVALID, "variation = ");
        fails(
            init(&v, 1.5, null(), &mut pt),
            INVALID,
            "s = 1.5: must be in [0, 1]",
        );
        fails(
            init(&v, -0.25, null(), &mut pt),
            INVALID,
            "s = -0.25: must be in [0, 1]",
        );
        fails(
            init(&v, f32::NAN, null(), &mut pt),
            INVALID,
            "s = NaN: must be in [0, 1]",
        );
        let bright = [0.5f32, 2.0, 0.5];
        fails(
            init(&v, 0.5, bright.as_ptr(), &mut pt),
            INVALID,
            "color[1] = 2: must be in [0, 1]",
        );
        let nan = [0.5f32, 0.5, f32::NAN];
        fails(
            init(&v, 0.5, nan.as_ptr(), &mut pt),
            INVALID,
            "color = [0.5, 0.5, NaN]: must be finite",
        );
        for (bad, words) in [
            (
                HtHairVariation {
                    absorption_variation: 1.5,
                    ..v
                },
                "absorption_variation = 1.5: must be in [0, 1]",
            ),
            (
                HtHairVariation {
                    roughness_variation: -0.1,
                    ..v
                },
                "roughness_variation = -0.1: must be in [0, 1]",
            ),
            (
                HtHairVariation {
                    roughness_variation: f32::NAN,
                    ..v
                },
                "roughness_variation = NaN",
            ),
            (
                HtHairVariation {
                    tip_absorption: 0.0,
                    ..v
                },
                "tip_absorption = 0: must be finite and > 0",
            ),
            (
                HtHairVariation {
                    use_vertex_colors: 2,
                    ..v
                },
                "variation->use_vertex_colors = 2: must be 0 or 1",
            ),
        ] {
            fails(init(&bad, 0.5, grey.as_ptr(), &mut pt), INVALID, words);
        }
        // The frame's and the Huang point's own checks.
        let st = init_strand(handle, &v, (3, 0.5, null()), 1.5, wo, [0.5; 2], 0, &mut pt);
        fails(st, INVALID, "h = 1.5");
        let st = init_strand(
            handle,
            &v,
            (3, 0.5, null()),
            0.2,
            wo,
            [0.5, 1.0],
            0,
            &mut pt,
        );
        fails(st, INVALID, "jitter[1] = 1: must be in [0, 1)");
        let st = init_strand(handle, &v, (3, 0.5, null()), 0.2, wo, [0.5; 2], 3, &mut pt);
        fails(st, INVALID, "field = 3");
        let along = [1.0f32, 0.0, 0.0];
        let st = unsafe {
            let w = wo.to_array();
            let j = [0.5f32; 2];
            ht_huang_point_init_strand(
                handle,
                &v,
                3,
                0.5,
                null(),
                &local(0.0),
                w.as_ptr(),
                along.as_ptr(),
                j.as_ptr(),
                0,
                &mut pt,
            )
        };
        fails(st, INVALID, "major = [1, 0, 0]: lies along the fibre");
        assert_eq!(pt.opaque, [0; HT_HUANG_POINT_SIZE], "a refused init wrote");
        assert_eq!(
            init(&v, 1.0, grey.as_ptr(), &mut pt),
            HtStatus::HT_OK,
            "{}",
            last_error()
        );
        unsafe { ht_huang_prepared_free(handle) };
    }
}
