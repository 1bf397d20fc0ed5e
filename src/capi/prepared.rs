//! The prepared hair BSDF for hosts: a handle holding the per-material constants, and a
//! per-vertex point in storage the host owns, so that a path vertex costs no allocation
//! and no re-preparation (docs/c-abi.md, section 12).
//!
//! The point is an `OwnedPoint` (its own copy of the BSDF plus the (h, wo) work) and the
//! world axes of its hit's frame, written into the host's `HtHairPoint` bytes behind a tag;
//! it runs the Rust `HairPoint` code, so it gives the same bits. Every call takes and gives
//! world directions: the frame is checked once, when the point is filled, and what init
//! established is not checked again per direction.
//!
//! The host's bytes, their checks and the world calls are generic over the model
//! (`HostPoint`): the Huang model's point (`huang.rs`) is filled and read by the same
//! code.

use super::bsdf::{Arg, check_args, check_dir, check_h, check_u, read3, require, write1, write3};
use super::frame::{HtHairFrame, checked_axes, hit_frame};
use super::{
    Failure, HtHairParams, HtStatus, Span, boundary, check_disjoint, free_handle, host_slice,
    host_slice_mut,
};
use crate::bsdf::{HairBsdf, LocalBsdf, OwnedPoint};
use crate::error::invalid_arg;
use crate::math::Frame;
use glam::Vec3;

/// Bytes of an `HtHairPoint`: the point and its frame fill most of them, the rest leaves
/// room for the model to grow without changing the ABI.
pub const HT_HAIR_POINT_SIZE: usize = 384;
/// Alignment of an `HtHairPoint` in bytes.
pub const HT_HAIR_POINT_ALIGN: usize = 16;

/// The hair BSDF prepared for one parameter set (the constants that depend on the
/// parameters only). Create with `ht_hair_prepare`, release with `ht_hair_prepared_free`.
/// Immutable: any number of threads may use one handle at once.
pub struct HtHairPrepared {
    bsdf: HairBsdf,
}

/// Storage for the BSDF at one shading point (a prepared BSDF at a hit's frame, h and wo),
/// filled by `ht_hair_point_at_hit` (or `ht_hair_point_init_world`) and then evaluated and
/// sampled any number of times.
///
/// - The host allocates it (stack, arrays, its own vertex structs): `HT_HAIR_POINT_SIZE`
///   bytes aligned to `HT_HAIR_POINT_ALIGN` (16); this type has both, so declaring an
///   `HtHairPoint` (or `malloc`, which aligns to 16 on 64-bit platforms) is enough. A
///   misaligned point is refused with `HT_ERR_INVALID_ARG`.
/// - The bytes are opaque. They hold plain numbers and no pointer: a filled point is
///   self-contained, may be copied with `memcpy` or assignment, stays valid after its
///   `HtHairPrepared` is freed, and needs no release.
/// - A point that no init filled (zeroed, or overwritten) is refused with
///   `HT_ERR_INVALID_ARG` when its tag does not match; never pass uninitialised storage.
/// - Reading it from several threads at once is safe; filling it while another thread
///   reads it is a data race (the host's to avoid).
#[repr(C, align(16))]
pub struct HtHairPoint {
    pub opaque: [u8; HT_HAIR_POINT_SIZE],
}

/// The host's opaque bytes for one model's point: what they hold once an init filled them.
pub(super) trait HostPoint: Sized {
    /// The model's point.
    type Point: LocalBsdf;
    /// Marks filled bytes: catches points that were never filled, or another model's.
    const TAG: u64;
    /// The calls that fill one, for the message on an unfilled point.
    const FILLED_BY: &'static str;
    /// Fails to compile unless the bytes hold a [`Stored`] point at its alignment; every
    /// generic function that reads or writes them evaluates it.
    const FITS: () = assert!(
        size_of::<Stored<Self::Point>>() <= size_of::<Self>()
            && align_of::<Stored<Self::Point>>() <= align_of::<Self>()
    );
}

/// What a host's point bytes hold: the point and the world axes of its frame.
#[repr(C)]
pub(super) struct Stored<P> {
    /// [`HostPoint::TAG`] once filled.
    tag: u64,
    point: P,
    frame: Frame,
}

impl HostPoint for HtHairPoint {
    type Point = OwnedPoint;
    /// "htpoint" and a layout version (3: every point holds its frame, ABI 7).
    const TAG: u64 = 0x6874_706f_696e_7403;
    const FILLED_BY: &'static str = "ht_hair_point_at_hit or ht_hair_point_init_world";
}

const _: () = {
    let () = <HtHairPoint as HostPoint>::FITS;
    assert!(
        size_of::<HtHairPoint>() == HT_HAIR_POINT_SIZE
            && align_of::<HtHairPoint>() == HT_HAIR_POINT_ALIGN
    );
};

/// The point of a per-point call, with the call's pointers checked: the common case (all
/// non-NULL and aligned, outputs clear of the inputs and the point, the point filled)
/// inline and cheaply, anything else through the full checks that name the problem.
#[inline(always)]
fn checked_point<'a, H: HostPoint>(
    point: *const H,
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<&'a Stored<H::Point>, Failure> {
    let () = H::FITS;
    check_args((point, "point"), inputs, outputs)?;
    // SAFETY: non-NULL and aligned (checked above); `H` is at least as large and as
    // aligned as its `Stored` (`H::FITS`), whose tag is a plain number valid for any
    // bytes, and a filled point holds a whole `Stored`.
    let stored = unsafe { &*point.cast::<Stored<H::Point>>() };
    if stored.tag == H::TAG {
        Ok(stored)
    } else {
        Err(unfilled(H::FILLED_BY))
    }
}

#[cold]
#[inline(never)]
fn unfilled(filled_by: &str) -> Failure {
    invalid_arg!("point was not filled by {filled_by} (or was overwritten)").into()
}

/// Prepares the BSDF for `*params` (see `HtHairParams` for the ranges) and writes the new
/// handle to `*out`.
///
/// - `params`, `out`: not NULL (`HT_ERR_NULL_ARG`), aligned for their types. A parameter
///   out of range: `HT_ERR_INVALID_ARG` naming it, and `*out` is left untouched.
/// - The handle is owned by the host: release it with `ht_hair_prepared_free`. Points
///   filled from it keep their own copy and outlive it.
///
/// Any thread.
///
/// # Safety
/// `params` is NULL or points to an `HtHairParams`; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_prepare(
    params: *const HtHairParams,
    out: *mut *mut HtHairPrepared,
) -> HtStatus {
    boundary(|| {
        prepare(params, out, |p| {
            Ok(HtHairPrepared {
                bsdf: HairBsdf::new(&p.into())?,
            })
        })
    })
}

/// The body of a `*_prepare` call: the handle `make` builds of the host's `*params`,
/// written to `*out` (every NULL checked first; `*out` untouched on error).
pub(super) fn prepare<P: Copy, T>(
    params: *const P,
    out: *mut *mut T,
    make: impl FnOnce(P) -> Result<T, Failure>,
) -> Result<(), Failure> {
    require(&[(params.cast(), "params"), (out.cast_const().cast(), "out")])?;
    let params = host_slice(params, 1, "params")?[0];
    let out = host_slice_mut(out, 1, "out")?;
    out[0] = Box::into_raw(Box::new(make(params)?));
    Ok(())
}

/// Releases a prepared BSDF (NULL: nothing to do; returns HT_OK). Points filled from it
/// stay valid. Freeing a handle twice, or while another thread uses it, is undefined
/// behaviour.
///
/// # Safety
/// `prepared` is NULL or a live handle from `ht_hair_prepare`, not used after this call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_prepared_free(prepared: *mut HtHairPrepared) -> HtStatus {
    boundary(|| {
        free_handle(prepared);
        Ok(())
    })
}

/// The pointers of a point init, checked inline in the common case, else in the documented
/// order with messages: every NULL first, then alignment, then an input inside the point.
/// `inputs` are the float arrays it reads; `frame` the frame it reads, if any.
#[inline(always)]
pub(super) fn check_init<P, H>(
    prepared: *const P,
    inputs: &[Arg],
    frame: Option<*const HtHairFrame>,
    point: *mut H,
) -> Result<(), Failure> {
    let start = point as usize;
    let apart = |p: usize, bytes: usize| p + bytes <= start || start + size_of::<H>() <= p;
    let fast = !prepared.is_null()
        && !point.is_null()
        && point.is_aligned()
        && inputs.iter().all(|&(p, _, n)| {
            !p.is_null() && p.is_aligned() && apart(p as usize, n * size_of::<f32>())
        })
        && frame.is_none_or(|f| {
            !f.is_null() && f.is_aligned() && apart(f as usize, size_of::<HtHairFrame>())
        });
    if fast {
        return Ok(());
    }
    let mut all = vec![(prepared.cast(), "prepared")];
    all.extend(frame.map(|f| (f.cast(), "frame")));
    all.extend(inputs.iter().map(|&(p, name, _)| (p.cast(), name)));
    all.push((point.cast_const().cast(), "point"));
    require(&all)?;
    host_slice(point.cast_const(), 1, "point")?;
    let mut spans = Vec::with_capacity(inputs.len() + 1);
    for &(p, name, n) in inputs {
        host_slice(p, n, name)?;
        spans.push(Span::of(name, p, n));
    }
    if let Some(f) = frame {
        host_slice(f, 1, "frame")?;
        spans.push(Span::of("frame", f, 1));
    }
    check_disjoint(&[Span::of("point", point, 1)], &spans)
}

/// Writes the tag, `frame` and, with `write`, the model's point into the host's storage in
/// place: built on the stack and copied, Chiang's point cost init a third more
/// (docs/c-abi.md, "Cost").
///
/// # Safety
/// `point` is non-NULL, aligned, writable and not read by anyone meanwhile; `write`
/// initialises the whole point it is given.
#[inline(always)]
pub(super) unsafe fn fill<H: HostPoint>(
    point: *mut H,
    frame: Frame,
    write: impl FnOnce(*mut H::Point),
) {
    let () = H::FITS;
    let stored = point.cast::<Stored<H::Point>>();
    // SAFETY: the caller's promise; `H` holds a `Stored` (`H::FITS`), whose fields are
    // plain numbers valid once written.
    unsafe {
        (&raw mut (*stored).tag).write(H::TAG);
        (&raw mut (*stored).frame).write(frame);
        write(&raw mut (*stored).point);
    }
}

/// The four arrays of a hit, as `check_init` takes them.
#[inline(always)]
pub(super) fn hit_args(
    tangent: *const f32,
    ray_org: *const f32,
    ray_dir: *const f32,
    axis: *const f32,
) -> [Arg; 4] {
    [
        (tangent, "tangent", 3),
        (ray_org, "ray_org", 3),
        (ray_dir, "ray_dir", 3),
        (axis, "axis", 3),
    ]
}

/// The frame, h and wo = -normalize(ray_dir) of a hit whose arrays `check_init` passed,
/// refused as `ht_hair_frame` refuses them.
#[inline(always)]
pub(super) fn framed_hit(args: &[Arg; 4], radius: f32) -> Result<(Frame, f32, Vec3), Failure> {
    let [tangent, org, dir, axis] = args.map(|(p, _, _)| read3(p));
    let (axes, h) = hit_frame(tangent, org, dir, axis, radius)?;
    // The frame's z faces the viewer and y is across the ray: wo has y = 0 there.
    let wo = check_dir(axes.to_local(-dir.normalize()), "wo")?;
    Ok((axes, h, wo))
}

/// Writes the Chiang point of `bsdf` at (h, wo) and `frame` into the host's storage.
///
/// # Safety
/// As [`fill`].
#[inline(always)]
unsafe fn fill_chiang(point: *mut HtHairPoint, bsdf: &HairBsdf, frame: Frame, h: f32, wo: Vec3) {
    // SAFETY: the caller's promise; `OwnedPoint::fill` initialises the point.
    unsafe {
        fill(point, frame, |p| {
            OwnedPoint::fill(&mut *p.cast(), bsdf, h, wo)
        })
    }
}

/// A renderer's hair hit to a ready point, in one call: the hit's frame and h (exactly as
/// `ht_hair_frame` builds them, and kept in the point) and the point of `prepared` there,
/// seen from wo = -normalize(ray_dir). Equal, bit for bit, to `ht_hair_frame` followed by
/// `ht_hair_point_init_world(prepared, &frame, wo, point)`.
///
/// - `tangent`, `ray_org`, `ray_dir`, `axis`, `radius`: as `ht_hair_frame` takes them, and
///   refused as it refuses them (`HT_ERR_INVALID_ARG`: not finite, a zero tangent or ray
///   direction, a radius not finite and > 0, a ray that passes the axis more than
///   `1 + HT_HAIR_FRAME_H_TOLERANCE` radii away).
/// - Pointers: not NULL (`HT_ERR_NULL_ARG`, checked first); the floats 4-byte and `point`
///   16-byte aligned; no input may lie inside `*point` (`HT_ERR_INVALID_ARG`). On error
///   `*point` is untouched.
///
/// Any thread; `prepared` may be shared, `point` must not be read meanwhile.
///
/// # Safety
/// `prepared` is NULL or a live handle; each float pointer NULL or 3 floats; `point` NULL
/// or writable storage of `HT_HAIR_POINT_SIZE` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_at_hit(
    prepared: *const HtHairPrepared,
    tangent: *const f32,
    ray_org: *const f32,
    ray_dir: *const f32,
    axis: *const f32,
    radius: f32,
    point: *mut HtHairPoint,
) -> HtStatus {
    boundary(|| {
        let inputs = hit_args(tangent, ray_org, ray_dir, axis);
        check_init(prepared, &inputs, None, point)?;
        let (axes, h, wo) = framed_hit(&inputs, radius)?;
        // SAFETY: non-NULL, aligned and clear of the inputs (checked); a live handle (the
        // caller's promise).
        unsafe { fill_chiang(point, &(*prepared).bsdf, axes, h, wo) };
        Ok(())
    })
}

/// The point of `prepared` at a hit's frame: h is `frame->h`, and `wo[3]` is in world
/// space (toward the viewer, -ray_dir normalised at the hit that made the frame). The
/// point keeps the frame's axes, so that the other point calls take and give world
/// directions. For a host that builds its own frame (or its own h), or works in the local
/// frame: pass the axes (1,0,0), (0,1,0), (0,0,1) and every direction is its local form.
///
/// - `frame`: as `ht_hair_frame` writes it; axes not finite, unit and orthogonal to 1e-3,
///   or left-handed, or `h` outside [-1, 1]: `HT_ERR_INVALID_ARG`. Checked here once: the
///   other point calls trust it.
/// - `wo`: a world direction whose local form is a unit vector (|length - 1| <= 1e-3);
///   else `HT_ERR_INVALID_ARG`.
/// - Pointers: not NULL (`HT_ERR_NULL_ARG`, checked first); `frame` and `wo` 4-byte and
///   `point` 16-byte aligned; neither `frame` nor `wo` may lie inside `*point`
///   (`HT_ERR_INVALID_ARG`). On error `*point` is untouched.
///
/// Any thread; `prepared` may be shared, `point` must not be read meanwhile.
///
/// # Safety
/// `prepared` is NULL or a live handle; `frame` NULL or an `HtHairFrame`; `wo` NULL or 3
/// floats; `point` NULL or writable storage of `HT_HAIR_POINT_SIZE` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_init_world(
    prepared: *const HtHairPrepared,
    frame: *const HtHairFrame,
    wo: *const f32,
    point: *mut HtHairPoint,
) -> HtStatus {
    boundary(|| {
        check_init(prepared, &[(wo, "wo", 3)], Some(frame), point)?;
        let (axes, h, wo) = framed(frame, wo)?;
        // SAFETY: as in `ht_hair_point_at_hit`.
        unsafe { fill_chiang(point, &(*prepared).bsdf, axes, h, wo) };
        Ok(())
    })
}

/// The checked axes and h of a frame `check_init` has passed, and the world `wo` in them.
#[inline(always)]
pub(super) fn framed(
    frame: *const HtHairFrame,
    wo: *const f32,
) -> Result<(Frame, f32, Vec3), Failure> {
    // SAFETY: non-NULL and aligned (checked by `check_init`), an `HtHairFrame` (the
    // caller's promise).
    let frame = unsafe { frame.read() };
    let axes = checked_axes(&frame)?;
    let h = check_h(frame.h)?;
    Ok((axes, h, check_dir(axes.to_local(read3(wo)), "wo")?))
}

/// `ht_hair_point_init_world` for one strand of a groom whose parameters vary as a scene's
/// hair material varies them (`ht_scene_add_hair_material_varied`): the parameters of
/// `prepared`, varied by `*variation` for strand number `strand` at position `s` along it
/// (root 0, tip 1), with the strand's own reflectance colour `color[3]` when
/// `variation->use_vertex_colors` is 1 (NULL: none). No handle per parameter set and no
/// allocation: the varied BSDF is built inside the point, and the point equals, bit for
/// bit, the one the renderer shades that strand's hit with.
///
/// - `strand`: the strand's index as the scene numbers strands (0, 1, ... in the order the
///   host adds them); `s` in [0, 1]; `color` each channel in [0, 1] (0 is taken as 1e-4);
///   the variation's ranges as at `HtHairVariation`; `frame`, `wo` as
///   `ht_hair_point_init_world`. Else `HT_ERR_INVALID_ARG`.
/// - Pointers: `prepared`, `variation`, `frame`, `wo`, `point` not NULL (`HT_ERR_NULL_ARG`);
///   others as `ht_hair_point_init_world`. On error `*point` is untouched.
/// - Cost: an init plus the preparation of the varied parameters (about one evaluation).
///
/// Any thread; `prepared` and `variation` may be shared, `point` must not be read
/// meanwhile. Not in the BSDF-only library.
///
/// # Safety
/// As `ht_hair_point_init_world`; `variation` NULL or an `HtHairVariation`; `color` NULL
/// or 3 floats.
#[cfg(feature = "render")]
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ht_hair_point_init_strand(
    prepared: *const HtHairPrepared,
    variation: *const super::materials::HtHairVariation,
    strand: u32,
    s: f32,
    color: *const f32,
    frame: *const HtHairFrame,
    wo: *const f32,
    point: *mut HtHairPoint,
) -> HtStatus {
    boundary(|| {
        let inputs = [(wo, "wo", 3)];
        let (v, (axes, h, wo), groom) =
            strand_init(prepared, variation, &inputs, frame, point, (s, color))?;
        // SAFETY: non-NULL (checked), a live handle (the caller's promise).
        let base = *unsafe { &(*prepared).bsdf }.params();
        let material = super::materials::varied_material(base, &v)?;
        material.check_variation()?;
        let bsdf = HairBsdf::new(&material.varied(base, strand, s, groom))?;
        // SAFETY: non-NULL, aligned and clear of the inputs (checked).
        unsafe { fill_chiang(point, &bsdf, axes, h, wo) };
        Ok(())
    })
}

/// The checks and reads a strand's point init of either model shares, in the documented
/// order (every NULL, then alignment and overlap, then the values): the host's variation,
/// the frame's axes and h with the world wo in them, and the strand's colour as the
/// renderer takes a groom's (NULL: none). `inputs` are the float arrays the init reads,
/// `wo` first.
#[cfg(feature = "render")]
pub(super) fn strand_init<P, H>(
    prepared: *const P,
    variation: *const super::materials::HtHairVariation,
    inputs: &[Arg],
    frame: *const HtHairFrame,
    point: *mut H,
    (s, color): (f32, *const f32),
) -> Result<StrandInputs, Failure> {
    use crate::scene::material::HairColor;
    require(&[(variation.cast(), "variation")])?;
    check_init(prepared, inputs, Some(frame), point)?;
    let v = super::read_host(variation, "variation")?;
    let framed = framed(frame, inputs[0].0)?;
    if !(0.0..=1.0).contains(&s) {
        return Err(invalid_arg!("s = {s}: must be in [0, 1]").into());
    }
    let groom = if color.is_null() {
        None
    } else {
        let c = super::read_vec3(color, "color")?.to_array();
        if let Some(bad) = c.iter().position(|x| !(0.0..=1.0).contains(x)) {
            return Err(invalid_arg!("color[{bad}] = {}: must be in [0, 1]", c[bad]).into());
        }
        Some(HairColor::Color(c))
    };
    Ok((v, framed, groom))
}

/// What [`strand_init`] gives: the variation, (frame, h, wo) and the strand's colour.
#[cfg(feature = "render")]
pub(super) type StrandInputs = (
    super::materials::HtHairVariation,
    (Frame, f32, Vec3),
    Option<crate::scene::material::HairColor>,
);

/// f |cos| and the pdf toward the world `wi[3]` at a filled point, for a light's
/// contribution and its MIS weight: writes `f_cos[3]` = f * |cos| (f the BSDF, RGB per
/// steradian, times the cosine to the fibre's normal plane: the fraction scattered per
/// unit solid angle) and `*pdf`, the density of `ht_hair_point_sample_world` at wi (per
/// unit solid angle). wi is taken to the point's frame (with no second check of the frame:
/// init made it) and must be a unit vector there (|length - 1| <= 1e-3).
///
/// - `wi` not a unit vector: `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   filled and 16-byte aligned, the floats 4-byte aligned; `f_cos` and `pdf` must not
///   overlap each other, `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on
///   error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi`, `f_cos` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_eval_world(
    point: *const HtHairPoint,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| eval_world(point, wi, f_cos, pdf))
}

/// The body of a point's `eval_world` call, for every model.
#[inline(always)]
pub(super) fn eval_world<H: HostPoint>(
    point: *const H,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> Result<(), Failure> {
    let (p, wi) = point_and_wi(point, wi, (f_cos, pdf, 1))?;
    let e = p.point.eval(wi);
    write3(f_cos, (e.f * wi.z.abs()).to_array());
    write1(pdf, e.pdf);
    Ok(())
}

/// Offsets across the fibre that `ht_hair_point_eval_across_world` evaluates: one lane each.
pub const HT_ACROSS: usize = 8;
const _: () = assert!(HT_ACROSS == crate::bsdf::ACROSS);

/// f |cos| and the pdf toward the world `wi[3]` at `HT_ACROSS` offsets across the fibre:
/// the point's h and its shifts by 2k / `HT_ACROSS`, wrapped into [-1, 1]. Writes lane k's
/// f |cos| to `f_cos[3k..3k+3]` and its pdf to `pdf[k]`; lane 0 is the point's own h, the
/// values of `ht_hair_point_eval_world`. wi is taken to the point's frame, as
/// `ht_hair_point_eval_world` takes it.
///
/// What it is for: a strand under a pixel wide shows the camera its whole width, so the
/// image holds the BSDF averaged across the fibre. Next-event estimation that weighs a
/// light by the mean over the lanes of `f_cos[k]` times the lane's own MIS weight (from
/// `pdf[k]`), while BSDF sampling still draws from the point, renders the same image in
/// expectation with less noise: hairtrace's own renderer does so and measures 1.5x-2.5x
/// less variance under small lights (docs/c-abi.md). At a camera ray's hit on a strand
/// wider than its pixel, use `ht_hair_point_eval_world`: the image resolves the fibre there.
///
/// - `wi` not a unit vector in the point's frame (|length - 1| <= 1e-3):
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   filled and 16-byte aligned, the floats 4-byte aligned; `f_cos` and `pdf` must not
///   overlap each other, `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on
///   error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi` NULL or 3 floats; `f_cos`
/// NULL or `3 * HT_ACROSS` writable floats, `pdf` NULL or `HT_ACROSS` writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_eval_across_world(
    point: *const HtHairPoint,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let (p, wi) = point_and_wi(point, wi, (f_cos, pdf, HT_ACROSS))?;
        let a = p.point.eval_across(wi);
        let cos = wi.z.abs();
        for k in 0..HT_ACROSS {
            // SAFETY: `f_cos` holds 3 * HT_ACROSS floats and `pdf` HT_ACROSS (checked).
            unsafe {
                write3(f_cos.add(3 * k), (a.f[k] * cos).to_array());
                write1(pdf.add(k), a.pdf[k]);
            }
        }
        Ok(())
    })
}

/// A sampled direction and what a path vertex wants of it, from `u[3]` in [0, 1): writes
/// `wi[3]` (unit, world space), `f_cos[3]` = f * |cos| (as `ht_hair_point_eval_world`
/// gives it toward wi: for a host that weighs strategies itself, with MIS or otherwise),
/// `weight[3]` = f_cos / pdf (the path throughput factor, from the same f_cos and pdf) and
/// `*pdf` (per unit solid angle). pdf = 0 (wi, f_cos, weight zero) means no direction, also
/// when the weight would not be finite; still HT_OK.
///
/// - `u[i]` outside [0, 1) or NaN: `HT_ERR_INVALID_ARG`.
/// - `point`, `u`, `wi`, `f_cos`, `weight`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked
///   first); `point` filled and 16-byte aligned, the floats 4-byte aligned; no output may
///   overlap another, `u` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `u`, `wi`, `f_cos`, `weight`
/// NULL or 3 floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_sample_world(
    point: *const HtHairPoint,
    u: *const f32,
    wi: *mut f32,
    f_cos: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| sample_world(point, u, [wi, f_cos, weight], pdf))
}

/// The body of a point's `sample_world` call, for every model: `out` is wi, f_cos and
/// weight.
#[inline(always)]
pub(super) fn sample_world<H: HostPoint>(
    point: *const H,
    u: *const f32,
    out: [*mut f32; 3],
    pdf: *mut f32,
) -> Result<(), Failure> {
    let [wi, f_cos, weight] = out;
    let outputs = [
        (wi.cast_const(), "wi", 3),
        (f_cos.cast_const(), "f_cos", 3),
        (weight.cast_const(), "weight", 3),
        (pdf.cast_const(), "pdf", 1),
    ];
    let p = checked_point(point, &[(u, "u", 3)], &outputs)?;
    let s = p.point.sample(check_u(read3(u).to_array(), "u")?);
    // The weight from f_cos in that order; none when it is not finite (a pdf that
    // underflowed).
    let s = s
        .map(|s| (s, s.f * s.wi.z.abs()))
        .filter(|(s, fc)| (*fc / s.pdf).is_finite());
    let zero = ([0.0; 3], [0.0; 3], [0.0; 3], 0.0);
    let (d, fc, w, density) = s.map_or(zero, |(s, fc)| {
        let d = p.frame.to_world(s.wi).to_array();
        (d, fc.to_array(), (fc / s.pdf).to_array(), s.pdf)
    });
    write3(wi, d);
    write3(f_cos, fc);
    write3(weight, w);
    write1(pdf, density);
    Ok(())
}

/// The checked point of an evaluation into `lanes` values of `f_cos` (3 floats each) and
/// `pdf`, and the world `wi[3]` in the point's frame.
#[inline(always)]
fn point_and_wi<'a, H: HostPoint>(
    point: *const H,
    wi: *const f32,
    (f_cos, pdf, lanes): (*mut f32, *mut f32, usize),
) -> Result<(&'a Stored<H::Point>, Vec3), Failure> {
    let outputs = [
        (f_cos.cast_const(), "f_cos", 3 * lanes),
        (pdf.cast_const(), "pdf", lanes),
    ];
    let p = checked_point(point, &[(wi, "wi", 3)], &outputs)?;
    let local = p.frame.to_local(read3(wi));
    Ok((p, check_dir(local, "wi (in the point's frame)")?))
}

#[cfg(test)]
mod tests {
    use super::super::bsdf::last_error;
    use super::super::frame::ht_hair_frame;
    use super::*;
    use crate::bsdf::HairParams;
    use std::ptr::{null, null_mut};

    fn point() -> HtHairPoint {
        HtHairPoint {
            opaque: [0; HT_HAIR_POINT_SIZE],
        }
    }

    fn prepare(p: &HtHairParams) -> *mut HtHairPrepared {
        let mut handle = null_mut();
        assert_eq!(unsafe { ht_hair_prepare(p, &mut handle) }, HtStatus::HT_OK);
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

    /// `ht_hair_point_eval_world`: f |cos| and pdf.
    fn eval(p: &HtHairPoint, wi: [f32; 3]) -> (HtStatus, [f32; 3], f32) {
        let (mut f_cos, mut pdf) = ([0.0f32; 3], 0.0f32);
        let s = unsafe { ht_hair_point_eval_world(p, wi.as_ptr(), f_cos.as_mut_ptr(), &mut pdf) };
        (s, f_cos, pdf)
    }

    /// `ht_hair_point_sample_world`: status, wi, f |cos|, weight, pdf.
    fn sample(p: &HtHairPoint, u: [f32; 3]) -> (HtStatus, [[f32; 3]; 3], f32) {
        let (mut out, mut pdf) = ([[0.0f32; 3]; 3], 0.0f32);
        let [wi, f_cos, weight] = &mut out;
        let s = unsafe {
            ht_hair_point_sample_world(
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

    /// `ht_hair_point_eval_across_world`, as bits.
    fn across(p: &HtHairPoint, wi: [f32; 3]) -> ([u32; 3 * HT_ACROSS], [u32; HT_ACROSS]) {
        let (mut f, mut pdf) = ([0.0f32; 3 * HT_ACROSS], [0.0f32; HT_ACROSS]);
        let s = unsafe {
            ht_hair_point_eval_across_world(p, wi.as_ptr(), f.as_mut_ptr(), pdf.as_mut_ptr())
        };
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        (f.map(f32::to_bits), pdf.map(f32::to_bits))
    }

    /// In the local frame every call is the Rust point's, times |wi.z| where it says f |cos|.
    #[test]
    fn points_give_the_rust_bits_and_outlive_their_handle() {
        let params = HtHairParams {
            alpha: -3.0,
            ..HairParams::default().into()
        };
        let bsdf = HairBsdf::new(&params.into()).unwrap();
        let handle = prepare(&params);
        let (h, wo) = (0.4f32, Vec3::new(0.6, 0.0, 0.8));
        let mut pt = point();
        let s =
            unsafe { ht_hair_point_init_world(handle, &local(h), wo.as_ref().as_ptr(), &mut pt) };
        assert_eq!(s, HtStatus::HT_OK);
        assert_eq!(unsafe { ht_hair_prepared_free(handle) }, HtStatus::HT_OK);
        // A byte copy is as good as the original, after the handle is gone.
        let copy = HtHairPoint { opaque: pt.opaque };
        let rust = bsdf.at(h, wo);
        for k in 0..64 {
            let a = 0.1 * k as f32;
            let wi = Vec3::new(a.sin() * 0.5, a.cos() * 0.7, 0.5).normalize();
            let want = rust.eval(wi);
            let cos = wi.z.abs();
            assert_eq!(
                eval(&copy, wi.to_array()),
                (HtStatus::HT_OK, (want.f * cos).to_array(), want.pdf)
            );
            // Across the fibre: each lane's f |cos| and pdf, as the Rust point's lanes.
            let (f_cos, pdf) = across(&copy, wi.to_array());
            let lanes = rust.eval_across(wi).unwrap();
            for k in 0..HT_ACROSS {
                let want = (lanes.f[k] * cos).to_array().map(f32::to_bits);
                assert_eq!(f_cos[3 * k..3 * k + 3], want, "lane {k}");
                assert_eq!(pdf[k], lanes.pdf[k].to_bits(), "lane {k}");
            }
            let u = [k as f32 / 64.0, 0.37, 0.81];
            let want = rust.sample(u).unwrap();
            let f_cos = want.f * want.wi.z.abs();
            let (s, [wi_s, f_cos_s, weight], pdf) = sample(&pt, u);
            assert_eq!(s, HtStatus::HT_OK);
            assert_eq!(
                (wi_s, f_cos_s, weight, pdf),
                (
                    want.wi.to_array(),
                    f_cos.to_array(),
                    (f_cos / want.pdf).to_array(),
                    want.pdf
                )
            );
        }
    }

    /// A hit to a point in one call is `ht_hair_frame` then `ht_hair_point_init_world`, and
    /// the world calls are the Rust point's behind the frame's conversions, bit for bit.
    #[test]
    fn a_hit_gives_the_framed_point_of_the_rust_calls() {
        let params: HtHairParams = HairParams::default().into();
        let (handle, bsdf) = (prepare(&params), HairBsdf::new(&params.into()).unwrap());
        for k in 0..200 {
            let a = 0.37 * k as f32;
            let tangent = Vec3::new(a.cos(), a.sin(), 0.3 * (2.0 * a).sin()) * 2.0;
            let dir = Vec3::new((1.7 * a).sin(), -0.4, (0.9 * a).cos()) * 0.5;
            let across_ray = tangent.cross(dir).normalize();
            let (radius, axis) = (0.03, Vec3::new(1.0, -2.0, 0.5));
            let org = axis + across_ray * (0.61 * k as f32).sin() * 0.95 * radius - dir * 8.0;
            let hit = [tangent, org, dir, axis].map(|v| v.to_array());
            let [t, o, d, x] = hit.each_ref().map(|v| v.as_ptr());
            let (mut at_hit, mut framed) = (point(), point());
            let mut frame = local(0.0);
            unsafe {
                let s = ht_hair_point_at_hit(handle, t, o, d, x, radius, &mut at_hit);
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
                assert_eq!(
                    ht_hair_frame(t, o, d, x, radius, &mut frame),
                    HtStatus::HT_OK
                );
                let wo = (-dir.normalize()).to_array();
                let s = ht_hair_point_init_world(handle, &frame, wo.as_ptr(), &mut framed);
                assert_eq!(s, HtStatus::HT_OK);
            }
            let axes = checked_axes(&frame).ok().expect("a frame");
            let rust = bsdf.at(frame.h, axes.to_local(-dir.normalize()));
            // Light from a direction of the world, and a sample.
            let wi = Vec3::new(0.3, (1.3 * a).cos(), (1.3 * a).sin()).normalize();
            let u = [(0.13 * k as f32).fract(), 0.42, (0.71 * k as f32).fract()];
            let (status, f_cos, pdf) = eval(&at_hit, wi.to_array());
            assert_eq!(status, HtStatus::HT_OK);
            assert_eq!(
                eval(&framed, wi.to_array()),
                (status, f_cos, pdf),
                "eval at {k}"
            );
            let l = axes.to_local(wi);
            let want = rust.eval(l);
            assert_eq!((f_cos, pdf), ((want.f * l.z.abs()).to_array(), want.pdf));
            let (status, [d_s, fc_s, w_s], p_s) = sample(&at_hit, u);
            assert_eq!(status, HtStatus::HT_OK);
            assert_eq!(
                sample(&framed, u),
                (status, [d_s, fc_s, w_s], p_s),
                "sample at {k}"
            );
            let want = rust.sample(u).unwrap();
            let fc = want.f * want.wi.z.abs();
            assert_eq!(
                (d_s, fc_s, w_s, p_s),
                (
                    axes.to_world(want.wi).to_array(),
                    fc.to_array(),
                    (fc / want.pdf).to_array(),
                    want.pdf
                ),
                "sample at {k}"
            );
            // Across the fibre, lane 0 (the point's own h) being the plain evaluation.
            let (f_lanes, pdf_lanes) = across(&at_hit, wi.to_array());
            assert_eq!(f_lanes[..3], f_cos.map(f32::to_bits), "lane 0 at {k}");
            assert_eq!(pdf_lanes[0], pdf.to_bits(), "lane 0 at {k}");
            assert!(pdf > 0.0 && p_s > 0.0, "{k}: a lobe toward every light");
        }
        unsafe { ht_hair_prepared_free(handle) };
    }

    /// A strand's point is the BSDF the renderer shades that strand's hits with (the scene
    /// material's `bsdf_at`), bit for bit, with and without a groom colour.
    #[cfg(feature = "render")]
    #[test]
    fn strand_points_are_the_scene_materials_bsdf() {
        use crate::capi::materials::{HtHairVariation, varied_material};
        use crate::scene::material::HairColor;
        let params: HtHairParams = HairParams::default().into();
        let handle = prepare(&params);
        let variation = HtHairVariation {
            absorption_variation: 0.5,
            roughness_variation: 0.4,
            tip_absorption: 0.3,
            use_vertex_colors: 1,
            seed: 42,
        };
        let Ok(material) = varied_material(params.into(), &variation) else {
            panic!("a valid variation")
        };
        let scene = material.prepare().unwrap();
        let mut distinct = std::collections::BTreeSet::new();
        let wo = Vec3::new(0.3, 0.2, 0.9).normalize();
        for k in 0..120u32 {
            let (strand, s) = (k * 7 % 23, (k % 11) as f32 / 10.0);
            let color = [0.3 + 0.005 * k as f32, 0.2, 0.1];
            let groom = (k % 2 == 0).then_some(color);
            let h = 0.9 * (0.3 * k as f32).sin();
            let mut pt = point();
            let color_ptr = groom.as_ref().map_or(null(), |c| c.as_ptr());
            let st = unsafe {
                ht_hair_point_init_strand(
                    handle,
                    &variation,
                    strand,
                    s,
                    color_ptr,
                    &local(h),
                    wo.as_ref().as_ptr(),
                    &mut pt,
                )
            };
            assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
            let want = scene.bsdf_at(strand, s, groom.map(HairColor::Color));
            distinct.insert(want.params().sigma_a.map(f32::to_bits));
            let rust = want.at(h, wo);
            let wi = Vec3::new(-0.2, 0.7, 0.5).normalize();
            let e = rust.eval(wi);
            let want_eval = (HtStatus::HT_OK, (e.f * wi.z.abs()).to_array(), e.pdf);
            assert_eq!(eval(&pt, wi.to_array()), want_eval, "strand {strand} s {s}");
            let u = [0.61, 0.27, 0.83];
            let want = rust.sample(u).unwrap();
            let (_, [wi_s, f_cos, _], pdf) = sample(&pt, u);
            let fc = (want.f * want.wi.z.abs()).to_array();
            assert_eq!((wi_s, f_cos, pdf), (want.wi.to_array(), fc, want.pdf));
        }
        assert!(
            distinct.len() > 100,
            "the parameters vary: {}",
            distinct.len()
        );
        let init = |variation: &HtHairVariation, s: f32, pt: &mut HtHairPoint| unsafe {
            let wo = [0.0f32, 0.0, 1.0];
            ht_hair_point_init_strand(
                handle,
                variation,
                0,
                s,
                null(),
                &local(0.0),
                wo.as_ptr(),
                pt,
            )
        };
        let bad = HtHairVariation {
            roughness_variation: 2.0,
            ..variation
        };
        let mut pt = point();
        assert_eq!(init(&bad, 0.5, &mut pt), HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("roughness_variation = 2"),
            "{}",
            last_error()
        );
        let st = init(&variation, 1.5, &mut pt);
        assert!(st == HtStatus::HT_ERR_INVALID_ARG && last_error().contains("s = 1.5"));
        assert_eq!(pt.opaque, [0; HT_HAIR_POINT_SIZE], "a refused init wrote");
        unsafe { ht_hair_prepared_free(handle) };
    }

    #[test]
    fn unfilled_misaligned_and_overlapping_points_are_refused() {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let fails = |status: HtStatus, want: HtStatus, words: &str| {
            assert_eq!(status, want, "{}", last_error());
            assert!(last_error().contains(words), "{}", last_error());
        };
        let wi = [0.0f32, 0.0, 1.0];
        let zeroed = point();
        fails(
            eval(&zeroed, wi).0,
            INVALID,
            "not filled by ht_hair_point_at_hit",
        );
        fails(sample(&zeroed, [0.5; 3]).0, INVALID, "not filled");
        let handle = prepare(&HairParams::default().into());
        let mut two = [point(), point()];
        let odd = unsafe { two.as_mut_ptr().cast::<u8>().add(4) }.cast::<HtHairPoint>();
        let frame = local(0.0);
        let init = |frame: *const HtHairFrame, wo: *const f32, pt: *mut HtHairPoint| unsafe {
            ht_hair_point_init_world(handle, frame, wo, pt)
        };
        fails(init(&frame, wi.as_ptr(), odd), INVALID, "not aligned to 16");
        // wo inside the point it fills, or the frame.
        let inside = two[0].opaque.as_ptr();
        fails(
            init(&frame, inside.cast(), &mut two[0]),
            INVALID,
            "point and wo overlap",
        );
        fails(
            init(inside.cast(), wi.as_ptr(), &mut two[0]),
            INVALID,
            "point and frame overlap",
        );
        // NULL before any value; then the frame, then wo.
        let mut pt = point();
        fails(init(null(), wi.as_ptr(), &mut pt), NULL, "frame is NULL");
        let mirrored = HtHairFrame {
            z: [0.0, 0.0, -1.0],
            ..frame
        };
        fails(
            init(&mirrored, wi.as_ptr(), &mut pt),
            INVALID,
            "right-handed",
        );
        fails(init(&local(1.5), wi.as_ptr(), &mut pt), INVALID, "h = 1.5");
        fails(
            init(&frame, [0.0f32, 0.0, 2.0].as_ptr(), &mut pt),
            INVALID,
            "wo = ",
        );
        // A hit that is not one, and NULL first whatever else is wrong.
        let (t, o, d, x) = (
            [1.0f32, 0.0, 0.0],
            [0.0f32, 0.5, 4.0],
            [0.0f32, 0.0, -1.0],
            [0.0f32; 3],
        );
        let hit = |prepared, radius, pt| unsafe {
            ht_hair_point_at_hit(
                prepared,
                t.as_ptr(),
                o.as_ptr(),
                d.as_ptr(),
                x.as_ptr(),
                radius,
                pt,
            )
        };
        fails(hit(null(), f32::NAN, &raw mut pt), NULL, "prepared is NULL");
        fails(hit(handle, 0.0, &raw mut pt), INVALID, "radius = 0");
        fails(hit(handle, 0.1, &raw mut pt), INVALID, "5 radii away");
        let far = [0.0f32, 2e38, 4.0];
        let s = unsafe {
            ht_hair_point_at_hit(
                handle,
                t.as_ptr(),
                far.as_ptr(),
                d.as_ptr(),
                x.as_ptr(),
                1.0,
                &mut pt,
            )
        };
        fails(s, INVALID, "radii away");
        let s = unsafe {
            ht_hair_point_at_hit(
                handle,
                inside.cast(),
                o.as_ptr(),
                d.as_ptr(),
                x.as_ptr(),
                1.0,
                &mut two[0],
            )
        };
        fails(s, INVALID, "point and tangent overlap");
        assert_eq!(pt.opaque, [0; HT_HAIR_POINT_SIZE], "a refused init wrote");
        assert_eq!(hit(handle, 1.0, &raw mut pt), HtStatus::HT_OK);
        // Per direction: a unit wi, u in [0, 1), outputs apart.
        fails(
            eval(&pt, [0.0, 0.0, 0.5]).0,
            INVALID,
            "wi (in the point's frame)",
        );
        fails(sample(&pt, [0.5, 1.0, 0.5]).0, INVALID, "u[1] = 1");
        let mut out = [7.0f32; 8];
        let s = unsafe {
            let o = out.as_mut_ptr();
            ht_hair_point_sample_world(&pt, [0.5f32; 3].as_ptr(), o, o.add(2), o.add(5), o.add(7))
        };
        fails(s, INVALID, "wi and f_cos overlap");
        assert_eq!(out, [7.0; 8], "a refused call wrote");
        unsafe { ht_hair_prepared_free(handle) };
    }
}
