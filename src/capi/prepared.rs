//! The prepared hair BSDF for hosts: a handle holding the per-material constants, and a
//! per-vertex point in storage the host owns, so that a path vertex costs no allocation
//! and no re-preparation (docs/c-abi.md).
//!
//! The point is an `OwnedPoint` (its own copy of the BSDF plus the (h, wo) work) written
//! into the host's `HtHairPoint` bytes behind a tag; it runs the Rust `HairPoint` code, so
//! it gives the same bits. A point filled from a frame keeps the frame's axes too, so that
//! its world-space calls convert directions without the host's calls or a second check of
//! the frame: what init established is not checked again per direction.

use super::bsdf::{
    Arg, check_args, check_dir, check_h, check_u, read_params, read3, require, sample_parts,
    write_eval, write_sample, write1, write3,
};
use super::frame::{HtHairFrame, checked_axes};
use super::{
    Failure, HtHairParams, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut,
};
use crate::bsdf::{BsdfEval, BsdfSample, HairBsdf, OwnedPoint};
use crate::error::invalid_arg;
use crate::math::Frame;
use glam::Vec3;

/// Bytes of an `HtHairPoint`: 320 are used today, the rest leaves room for the model to
/// grow without changing the ABI.
pub const HT_HAIR_POINT_SIZE: usize = 384;
/// Alignment of an `HtHairPoint` in bytes.
pub const HT_HAIR_POINT_ALIGN: usize = 16;

/// The hair BSDF prepared for one parameter set (the constants that depend on the
/// parameters only). Create with `ht_hair_prepare`, release with `ht_hair_prepared_free`.
/// Immutable: any number of threads may use one handle at once.
pub struct HtHairPrepared {
    bsdf: HairBsdf,
}

/// Storage for the BSDF at one shading point (a prepared BSDF at a fixed h and wo), filled
/// by `ht_hair_point_init` and then evaluated and sampled any number of times.
///
/// - The host allocates it (stack, arrays, its own vertex structs): `HT_HAIR_POINT_SIZE`
///   bytes aligned to `HT_HAIR_POINT_ALIGN` (16); this type has both, so declaring an
///   `HtHairPoint` (or `malloc`, which aligns to 16 on 64-bit platforms) is enough. A
///   misaligned point is refused with `HT_ERR_INVALID_ARG`.
/// - The bytes are opaque. They hold plain numbers and no pointer: a filled point is
///   self-contained, may be copied with `memcpy` or assignment, stays valid after its
///   `HtHairPrepared` is freed, and needs no release.
/// - A point that `ht_hair_point_init` did not fill (zeroed, or overwritten) is refused
///   with `HT_ERR_INVALID_ARG` when its tag does not match; never pass uninitialised
///   storage.
/// - Reading it from several threads at once is safe; filling it while another thread
///   reads it is a data race (the host's to avoid).
#[repr(C, align(16))]
pub struct HtHairPoint {
    pub opaque: [u8; HT_HAIR_POINT_SIZE],
}

/// What the host's `HtHairPoint` bytes hold.
#[repr(C)]
struct Stored {
    /// [`TAG`] or [`TAG_FRAMED`] once filled: catches points that were never filled.
    tag: u64,
    point: OwnedPoint,
}

/// What a point filled by `ht_hair_point_init_world` ([`TAG_FRAMED`]) holds: the point and
/// the world axes of its frame, for the world-space calls.
#[repr(C)]
struct Framed {
    stored: Stored,
    frame: Frame,
}

/// "htpoint" and a layout version: a point filled in the local frame.
const TAG: u64 = 0x6874_706f_696e_7401;
/// The tag of a point filled from a frame, whose world-space calls may convert.
const TAG_FRAMED: u64 = 0x6874_706f_696e_7402;

// The host's storage must hold a `Framed` (and so a `Stored`) at its alignment: checked at
// compile time.
const _: () = assert!(
    size_of::<Framed>() <= HT_HAIR_POINT_SIZE
        && align_of::<Framed>() <= HT_HAIR_POINT_ALIGN
        && size_of::<HtHairPoint>() == HT_HAIR_POINT_SIZE
        && align_of::<HtHairPoint>() == HT_HAIR_POINT_ALIGN
);

/// The filled point behind the host's storage (NULL, misaligned or unfilled: an error).
fn read_point<'a>(point: *const HtHairPoint, name: &str) -> Result<&'a Stored, Failure> {
    host_slice(point, 1, name)?;
    if !filled(point) {
        return Err(invalid_arg!(
            "{name} was not filled by ht_hair_point_init (or was overwritten)"
        )
        .into());
    }
    // SAFETY: non-NULL, aligned and filled (checked); `HtHairPoint` holds a `Stored`.
    Ok(unsafe { &*point.cast::<Stored>() })
}

/// The tag of a non-NULL, aligned point.
#[inline(always)]
fn filled(point: *const HtHairPoint) -> bool {
    // SAFETY: the caller checked `point`; `HtHairPoint` is at least as large and as aligned
    // as `Stored` (asserted above), and `Stored` is plain numbers, valid for any bytes.
    let tag = unsafe { (*point.cast::<Stored>()).tag };
    tag == TAG || tag == TAG_FRAMED
}

/// The point of a per-point call, with the call's pointers checked: the common case (all
/// non-NULL and aligned, outputs clear of the inputs and the point, the point filled)
/// inline and cheaply, anything else through the full checks that name the problem.
#[inline(always)]
fn checked_point<'a>(
    point: *const HtHairPoint,
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<&'a Stored, Failure> {
    check_args((point, "point"), inputs, outputs)?;
    if filled(point) {
        // SAFETY: non-NULL, aligned (checked above) and filled.
        return Ok(unsafe { &*point.cast::<Stored>() });
    }
    read_point(point, "point")
}

/// [`checked_point`] for the world-space calls: the point must hold a frame.
#[inline(always)]
fn checked_framed<'a>(
    point: *const HtHairPoint,
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<&'a Framed, Failure> {
    if checked_point(point, inputs, outputs)?.tag != TAG_FRAMED {
        return Err(unframed());
    }
    // SAFETY: aligned (checked) and filled by `ht_hair_point_init_world`, which wrote a
    // `Framed` there (asserted to fit above).
    Ok(unsafe { &*point.cast::<Framed>() })
}

#[cold]
#[inline(never)]
fn unframed() -> Failure {
    invalid_arg!(
        "point was filled by ht_hair_point_init, without a frame: the world-space calls need \
         a point from ht_hair_point_init_world"
    )
    .into()
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
        require(&[(params.cast(), "params"), (out.cast_const().cast(), "out")])?;
        let params = read_params(params)?;
        let out = host_slice_mut(out, 1, "out")?;
        let handle = Box::new(HtHairPrepared {
            bsdf: HairBsdf::new(&params)?,
        });
        out[0] = Box::into_raw(handle);
        Ok(())
    })
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
        if !prepared.is_null() {
            // SAFETY: a live handle from ht_hair_prepare (the caller's promise).
            drop(unsafe { Box::from_raw(prepared) });
        }
        Ok(())
    })
}

/// Fills `*point` with the BSDF of `prepared` at offset `h` and outgoing direction `wo`:
/// the work that depends on (h, wo) (Fresnel, absorption, refraction) is done here once,
/// and shared by every eval, pdf and sample at that point.
///
/// - `h` in [-1, 1], `wo[3]` a unit vector (|length - 1| <= 1e-3) in the local frame
///   pointing away from the fibre (see `HtHairFrame`); else `HT_ERR_INVALID_ARG`.
/// - `prepared`, `wo`, `point`: not NULL (`HT_ERR_NULL_ARG`, checked first); `wo` 4-byte
///   and `point` 16-byte aligned; `wo` must not lie inside `*point`. On error `*point` is
///   untouched.
///
/// Any thread; `prepared` may be shared, `point` must not be read meanwhile.
///
/// # Safety
/// `prepared` is NULL or a live handle; `wo` NULL or 3 floats; `point` NULL or writable
/// storage of `HT_HAIR_POINT_SIZE` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_init(
    prepared: *const HtHairPrepared,
    h: f32,
    wo: *const f32,
    point: *mut HtHairPoint,
) -> HtStatus {
    boundary(|| {
        check_init(prepared, wo, None, point)?;
        let h = check_h(h)?;
        let wo = check_dir(read3(wo), "wo")?;
        // SAFETY: non-NULL, aligned and clear of `wo` (checked); a live handle (the
        // caller's promise).
        unsafe { fill(point, &(*prepared).bsdf, h, wo, TAG) };
        Ok(())
    })
}

/// The pointers of a point init, checked inline in the common case, else in the documented
/// order with messages: every NULL first, then alignment, then `wo` or `frame` inside the
/// point.
#[inline(always)]
fn check_init(
    prepared: *const HtHairPrepared,
    wo: *const f32,
    frame: Option<*const HtHairFrame>,
    point: *mut HtHairPoint,
) -> Result<(), Failure> {
    let start = point as usize;
    let apart = |p: usize, bytes: usize| p + bytes <= start || start + HT_HAIR_POINT_SIZE <= p;
    let fast = !prepared.is_null()
        && !point.is_null()
        && point.is_aligned()
        && !wo.is_null()
        && wo.is_aligned()
        && apart(wo as usize, 3 * size_of::<f32>())
        && frame.is_none_or(|f| {
            !f.is_null() && f.is_aligned() && apart(f as usize, size_of::<HtHairFrame>())
        });
    if fast {
        return Ok(());
    }
    let mut all = vec![(prepared.cast(), "prepared")];
    all.extend(frame.map(|f| (f.cast(), "frame")));
    all.extend([(wo.cast(), "wo"), (point.cast_const().cast(), "point")]);
    require(&all)?;
    host_slice(wo, 3, "wo")?;
    host_slice(point.cast_const(), 1, "point")?;
    let mut inputs = vec![Span::of("wo", wo, 3)];
    if let Some(f) = frame {
        host_slice(f, 1, "frame")?;
        inputs.push(Span::of("frame", f, 1));
    }
    check_disjoint(&[Span::of("point", point, 1)], &inputs)
}

/// Writes the point of `bsdf` at (h, wo), tagged `tag`, into the host's storage in place:
/// built on the stack and copied, the same point cost init a third more (docs/c-abi.md,
/// "What a vertex costs").
///
/// # Safety
/// `point` is non-NULL, aligned, writable and not read by anyone meanwhile.
#[inline(always)]
unsafe fn fill(point: *mut HtHairPoint, bsdf: &HairBsdf, h: f32, wo: Vec3, tag: u64) {
    let stored = point.cast::<Stored>();
    // SAFETY: the caller's promise; `HtHairPoint` holds a `Stored` (asserted above), whose
    // fields are plain numbers valid once written.
    unsafe {
        (&raw mut (*stored).tag).write(tag);
        OwnedPoint::fill(&mut *(&raw mut (*stored).point).cast(), bsdf, h, wo);
    }
}

/// `ht_hair_point_init` from a hit's frame: h is `frame->h`, and `wo[3]` is in *world*
/// space (toward the viewer, -ray_dir normalised at a camera hit). The point keeps the
/// frame's axes, so that `ht_hair_point_eval_world` and `ht_hair_point_sample_world` take
/// and give world directions; the local calls work on it as well. Equal, bit for bit, to
/// `ht_hair_point_init(prepared, frame->h, wo_local, point)` with `wo_local` from
/// `ht_hair_frame_to_local(frame, wo, wo_local)`.
///
/// - `frame`: as `ht_hair_frame` writes it; axes not finite, unit and orthogonal to 1e-3,
///   or left-handed, or `h` outside [-1, 1]: `HT_ERR_INVALID_ARG`. Checked here once: the
///   world-space calls trust it.
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
        check_init(prepared, wo, Some(frame), point)?;
        // SAFETY: non-NULL and aligned (checked above), an `HtHairFrame` (the caller's
        // promise).
        let frame = unsafe { frame.read() };
        let (axes, h) = (checked_axes(&frame)?, frame.h);
        let h = check_h(h)?;
        let wo = check_dir(axes.to_local(read3(wo)), "wo")?;
        // SAFETY: as in `ht_hair_point_init`; the storage holds a `Framed` (asserted above).
        unsafe {
            fill(point, &(*prepared).bsdf, h, wo, TAG_FRAMED);
            (&raw mut (*point.cast::<Framed>()).frame).write(axes);
        }
        Ok(())
    })
}

/// `ht_hair_point_init` for one strand of a groom whose parameters vary as a scene's hair
/// material varies them (`ht_scene_add_hair_material_varied`): the parameters of
/// `prepared`, varied by `*variation` for strand number `strand` at position `s` along it
/// (root 0, tip 1), with the strand's own reflectance colour `color[3]` when
/// `variation->use_vertex_colors` is 1 (NULL: none). No handle per parameter set and no
/// allocation: the varied BSDF is built inside the point, and the point equals, bit for
/// bit, the one the renderer shades that strand's hit with.
///
/// - `strand`: the strand's index as the scene numbers strands (0, 1, ... in the order the
///   host adds them); `s` in [0, 1]; `color` each channel in [0, 1] (0 is taken as 1e-4);
///   the variation's ranges as at `HtHairVariation`; `h`, `wo` as `ht_hair_point_init`.
///   Else `HT_ERR_INVALID_ARG`.
/// - Pointers: `prepared`, `variation`, `wo`, `point` not NULL (`HT_ERR_NULL_ARG`); others
///   as `ht_hair_point_init`. On error `*point` is untouched.
/// - Cost: an init plus the preparation of the varied parameters (about one evaluation).
///
/// Any thread; `prepared` and `variation` may be shared, `point` must not be read
/// meanwhile. Not in the BSDF-only library.
///
/// # Safety
/// As `ht_hair_point_init`; `variation` NULL or an `HtHairVariation`; `color` NULL or 3
/// floats.
#[cfg(feature = "render")]
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ht_hair_point_init_strand(
    prepared: *const HtHairPrepared,
    variation: *const super::materials::HtHairVariation,
    strand: u32,
    s: f32,
    color: *const f32,
    h: f32,
    wo: *const f32,
    point: *mut HtHairPoint,
) -> HtStatus {
    use crate::scene::material::HairColor;
    boundary(|| {
        require(&[(variation.cast(), "variation")])?;
        check_init(prepared, wo, None, point)?;
        let v = super::read_host(variation, "variation")?;
        let h = check_h(h)?;
        let wo = check_dir(read3(wo), "wo")?;
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
        // SAFETY: non-NULL (checked), a live handle (the caller's promise).
        let base = *unsafe { &(*prepared).bsdf }.params();
        let material = super::materials::varied_material(base, &v)?;
        material.check_variation()?;
        let bsdf = HairBsdf::new(&material.varied(base, strand, s, groom))?;
        // SAFETY: non-NULL, aligned and clear of `wo` (checked).
        unsafe { fill(point, &bsdf, h, wo, TAG) };
        Ok(())
    })
}

/// f (RGB, includes 1/|wi.z| as `ht_hair_eval`) and pdf (per unit solid angle) toward
/// `wi[3]` at a filled point: the same bits as `ht_hair_eval` with the point's parameters,
/// h and wo.
///
/// - `wi`: unit vector (|length - 1| <= 1e-3) in the point's local frame, pointing away;
///   else `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   filled by `ht_hair_point_init` and 16-byte aligned, the floats 4-byte aligned
///   (`HT_ERR_INVALID_ARG`); `f` and `pdf` must not overlap each other, `wi` or the point
///   (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi`, `f` NULL or 3 floats,
/// `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_eval(
    point: *const HtHairPoint,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let p = checked_point(point, &[(wi, "wi", 3)], &[(f, "f", 3), (pdf, "pdf", 1)])?;
        write_eval(p.point.eval(check_dir(read3(wi), "wi")?), f, pdf);
        Ok(())
    })
}

/// Offsets across the fibre that `ht_hair_point_eval_across` evaluates: one lane each.
pub const HT_ACROSS: usize = 8;
const _: () = assert!(HT_ACROSS == crate::bsdf::ACROSS);

/// f * |wi.z| and the pdf toward `wi[3]` (the point's local frame) at `HT_ACROSS` offsets
/// across the fibre: the point's h and its shifts by 2k / `HT_ACROSS`, wrapped into
/// [-1, 1]. Writes lane k's f |cos| to `f_cos[3k..3k+3]` and its pdf to `pdf[k]`; lane 0
/// is the point's own h.
///
/// What it is for: a strand under a pixel wide shows the camera its whole width, so the
/// image holds the BSDF averaged across the fibre. Next-event estimation that weighs a
/// light by the mean over the lanes of `f_cos[k]` times the lane's own MIS weight (from
/// `pdf[k]`), while BSDF sampling still draws from the point, renders the same image in
/// expectation with less noise: hairtrace's own renderer does so and measures 1.5x-2.5x
/// less variance under small lights (docs/c-abi.md). At a camera ray's hit on a strand
/// wider than its pixel, use `ht_hair_point_eval_cos`: the image resolves the fibre there.
///
/// - `wi`: unit vector (|length - 1| <= 1e-3) in the point's local frame; else
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   filled by an init and 16-byte aligned, the floats 4-byte aligned; `f_cos` and `pdf`
///   must not overlap each other, `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs
///   untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi` NULL or 3 floats; `f_cos`
/// NULL or `3 * HT_ACROSS` writable floats, `pdf` NULL or `HT_ACROSS` writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_eval_across(
    point: *const HtHairPoint,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        point_and_wi(point, wi, (f_cos, pdf, HT_ACROSS), false)
            .map(|(p, wi)| write_across(p, wi, f_cos, pdf))
    })
}

/// `ht_hair_point_eval_across` with `wi[3]` in *world* space, at a point filled by
/// `ht_hair_point_init_world`: wi is taken to the point's frame, as
/// `ht_hair_point_eval_world` takes it, and must be a unit vector there (|length - 1| <=
/// 1e-3). The same bits as `ht_hair_frame_to_local` followed by `ht_hair_point_eval_across`.
///
/// - `wi` not a unit vector in the point's frame: `HT_ERR_INVALID_ARG`.
/// - A point filled by `ht_hair_point_init` or `ht_hair_point_init_strand` (no frame):
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   16-byte and the floats 4-byte aligned; `f_cos` and `pdf` must not overlap each other,
///   `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
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
        point_and_wi(point, wi, (f_cos, pdf, HT_ACROSS), true)
            .map(|(p, wi)| write_across(p, wi, f_cos, pdf))
    })
}

/// Writes lane k's f |cos| toward the local `wi` to `f_cos[3k..3k+3]` and its pdf to
/// `pdf[k]`, for the `HT_ACROSS` offsets across the fibre (checked outputs).
fn write_across(p: &Stored, wi: Vec3, f_cos: *mut f32, pdf: *mut f32) {
    let a = p.point.eval_across(wi);
    let cos = wi.z.abs();
    for k in 0..HT_ACROSS {
        // SAFETY: `f_cos` holds 3 * HT_ACROSS floats and `pdf` HT_ACROSS (checked).
        unsafe {
            write3(f_cos.add(3 * k), (a.f[k] * cos).to_array());
            write1(pdf.add(k), a.pdf[k]);
        }
    }
}

/// The pdf alone (per unit solid angle) toward `wi[3]` at a filled point: the `pdf` that
/// `ht_hair_point_eval` writes, for hosts that need only the density (MIS weights).
///
/// - `wi`: unit vector (|length - 1| <= 1e-3) in the point's local frame; else
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point` filled by
///   an init and 16-byte aligned, the floats 4-byte aligned; `pdf` must not overlap `wi`
///   or the point (`HT_ERR_INVALID_ARG`). `*pdf` untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi` NULL or 3 floats; `pdf`
/// NULL or 1 writable float.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_pdf(
    point: *const HtHairPoint,
    wi: *const f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let p = checked_point(point, &[(wi, "wi", 3)], &[(pdf, "pdf", 1)])?;
        write1(pdf, p.point.eval(check_dir(read3(wi), "wi")?).pdf);
        Ok(())
    })
}

/// Samples an incident direction at a filled point from `u[3]` in [0, 1): writes `wi[3]`
/// (unit, local frame), `f[3]` and `*pdf`, the same bits as `ht_hair_sample` with the
/// point's parameters, h and wo. pdf = 0 (wi, f zero) means no direction; still HT_OK.
///
/// - `u[i]` outside [0, 1) or NaN: `HT_ERR_INVALID_ARG`.
/// - Pointers: not NULL (`HT_ERR_NULL_ARG`, checked first); `point` filled and 16-byte
///   aligned, floats 4-byte aligned; `wi`, `f`, `pdf` must not overlap each other, `u` or
///   the point (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `u`, `wi`, `f` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_sample(
    point: *const HtHairPoint,
    u: *const f32,
    wi: *mut f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let outputs = [
            (wi.cast_const(), "wi", 3),
            (f.cast_const(), "f", 3),
            (pdf.cast_const(), "pdf", 1),
        ];
        let p = checked_point(point, &[(u, "u", 3)], &outputs)?;
        let s = p.point.sample(check_u(read3(u).to_array(), "u")?);
        write_sample(s, wi, f, pdf);
        Ok(())
    })
}

/// f |cos| and pdf of an evaluation at the local `wi`: `f * |wi.z|`, the scattered fraction
/// per unit solid angle, as a host multiplies it.
#[inline(always)]
fn times_cos(e: BsdfEval, wi: Vec3) -> BsdfEval {
    BsdfEval {
        f: e.f * wi.z.abs(),
        pdf: e.pdf,
    }
}

/// A sample's wi, weight f |wi.z| / pdf and pdf, or zeros when there is none or the weight
/// is not finite (a pdf that underflowed).
#[inline(always)]
fn weighted(s: Option<BsdfSample>) -> Option<BsdfSample> {
    s.map(|s| BsdfSample {
        f: s.f * s.wi.z.abs() / s.pdf,
        ..s
    })
    .filter(|s| s.f.is_finite())
}

/// One call for what a path vertex wants of a light direction: writes `f_cos[3]` =
/// f * |wi.z| (the `f` of `ht_hair_point_eval` times the cosine, in that order: the
/// fraction scattered per unit solid angle) and `*pdf`, the same pdf as
/// `ht_hair_point_eval`.
///
/// - `wi`: unit vector (|length - 1| <= 1e-3) in the point's local frame; else
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   filled by an init and 16-byte aligned, the floats 4-byte aligned; `f_cos` and `pdf`
///   must not overlap each other, `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs
///   untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `wi`, `f_cos` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_eval_cos(
    point: *const HtHairPoint,
    wi: *const f32,
    f_cos: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        point_and_wi(point, wi, (f_cos, pdf, 1), false).map(|(p, wi)| write_cos(p, wi, f_cos, pdf))
    })
}

/// One call for what a path vertex wants of a sampled direction: writes `wi[3]` (as
/// `ht_hair_point_sample`), `weight[3]` = f * |wi.z| / pdf (the path throughput factor,
/// from that call's f and pdf in that order) and `*pdf`. pdf = 0 (wi, weight zero) means
/// no direction, also when the weight would not be finite; still HT_OK.
///
/// - `u[i]` outside [0, 1) or NaN: `HT_ERR_INVALID_ARG`.
/// - `point`, `u`, `wi`, `weight`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first);
///   `point` filled by an init and 16-byte aligned, the floats 4-byte aligned; `wi`,
///   `weight` and `pdf` must not overlap each other, `u` or the point
///   (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `u`, `wi`, `weight` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_sample_cos(
    point: *const HtHairPoint,
    u: *const f32,
    wi: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| sample_cos(point, u, wi, weight, pdf, false))
}

/// `ht_hair_point_eval_cos` with `wi[3]` in *world* space, at a point filled by
/// `ht_hair_point_init_world`: wi is taken to the point's frame (as
/// `ht_hair_frame_to_local` does, but with no check of the frame: init made it) and must be
/// a unit vector there (|length - 1| <= 1e-3). The same bits as `ht_hair_frame_to_local`
/// followed by `ht_hair_point_eval_cos`.
///
/// - `wi` not a unit vector in the point's frame: `HT_ERR_INVALID_ARG`.
/// - A point filled by `ht_hair_point_init` or `ht_hair_point_init_strand` (no frame):
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `wi`, `f_cos`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first); `point`
///   16-byte and the floats 4-byte aligned; `f_cos` and `pdf` must not overlap each other,
///   `wi` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on error.
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
    boundary(|| {
        point_and_wi(point, wi, (f_cos, pdf, 1), true).map(|(p, wi)| write_cos(p, wi, f_cos, pdf))
    })
}

/// `ht_hair_point_sample_cos` giving `wi[3]` in *world* space, at a point filled by
/// `ht_hair_point_init_world`: the local sample taken to world space with the point's
/// frame, the same bits as `ht_hair_point_sample_cos` followed by `ht_hair_frame_to_world`
/// (weight and pdf are unchanged). pdf = 0 (wi, weight zero) means no direction.
///
/// - `u[i]` outside [0, 1) or NaN: `HT_ERR_INVALID_ARG`.
/// - A point filled by `ht_hair_point_init` or `ht_hair_point_init_strand` (no frame):
///   `HT_ERR_INVALID_ARG`.
/// - `point`, `u`, `wi`, `weight`, `pdf`: not NULL (`HT_ERR_NULL_ARG`, checked first);
///   `point` 16-byte and the floats 4-byte aligned; `wi`, `weight` and `pdf` must not
///   overlap each other, `u` or the point (`HT_ERR_INVALID_ARG`). Outputs untouched on
///   error.
///
/// Any thread, concurrently on the same point.
///
/// # Safety
/// `point` is NULL or `HT_HAIR_POINT_SIZE` readable bytes; `u`, `wi`, `weight` NULL or 3
/// floats, `pdf` NULL or 1 float; outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_sample_world(
    point: *const HtHairPoint,
    u: *const f32,
    wi: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| sample_cos(point, u, wi, weight, pdf, true))
}

/// Writes f |cos| and the pdf toward the local `wi` (checked outputs).
#[inline(always)]
fn write_cos(p: &Stored, wi: Vec3, f_cos: *mut f32, pdf: *mut f32) {
    write_eval(times_cos(p.point.eval(wi), wi), f_cos, pdf);
}

/// The checked point of an evaluation into `lanes` values of `f_cos` (3 floats each) and
/// `pdf`, and `wi[3]` in its local frame: read as given, or, with `world`, in world space
/// and taken to the frame of a point that holds one.
#[inline(always)]
fn point_and_wi<'a>(
    point: *const HtHairPoint,
    wi: *const f32,
    (f_cos, pdf, lanes): (*mut f32, *mut f32, usize),
    world: bool,
) -> Result<(&'a Stored, Vec3), Failure> {
    let inputs = [(wi, "wi", 3)];
    let outputs = [
        (f_cos.cast_const(), "f_cos", 3 * lanes),
        (pdf.cast_const(), "pdf", lanes),
    ];
    if world {
        let p = checked_framed(point, &inputs, &outputs)?;
        let local = p.frame.to_local(read3(wi));
        Ok((&p.stored, check_dir(local, "wi (in the point's frame)")?))
    } else {
        let p = checked_point(point, &inputs, &outputs)?;
        Ok((p, check_dir(read3(wi), "wi")?))
    }
}

/// The body of `ht_hair_point_sample_cos` and, with `world`, `ht_hair_point_sample_world`
/// (`wi` given in world space with the point's frame).
#[inline(always)]
fn sample_cos(
    point: *const HtHairPoint,
    u: *const f32,
    wi: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
    world: bool,
) -> Result<(), Failure> {
    let inputs = [(u, "u", 3)];
    let outputs = [
        (wi.cast_const(), "wi", 3),
        (weight.cast_const(), "weight", 3),
        (pdf.cast_const(), "pdf", 1),
    ];
    let (p, frame) = if world {
        let p = checked_framed(point, &inputs, &outputs)?;
        (&p.stored, Some(&p.frame))
    } else {
        (checked_point(point, &inputs, &outputs)?, None)
    };
    let s = weighted(p.point.sample(check_u(read3(u).to_array(), "u")?));
    let s = s.map(|s| BsdfSample {
        wi: frame.map_or(s.wi, |f| f.to_world(s.wi)),
        ..s
    });
    write_sample(s, wi, weight, pdf);
    Ok(())
}

/// The pointers of a batch over points, checked as one: `points[n]`, an input of `3n`
/// floats, and the outputs (`3n` floats each, then `pdf[n]`).
struct Batch<'a> {
    points: &'a [HtHairPoint],
    input: &'a [[f32; 3]],
    name: &'static str,
}

impl Batch<'_> {
    /// NULL checks of everything (when n > 0), then sizes, alignment and overlap.
    fn check(
        points: *const HtHairPoint,
        n: usize,
        input: (*const f32, &'static str),
        outputs: &[(*mut f32, &str)],
        pdf: *mut f32,
    ) -> Result<Self, Failure> {
        if n > 0 {
            let mut all = vec![(points.cast(), "points"), (input.0.cast(), input.1)];
            all.extend(
                outputs
                    .iter()
                    .map(|&(p, name)| (p.cast_const().cast(), name)),
            );
            all.push((pdf.cast_const().cast(), "pdf"));
            require(&all)?;
        }
        let points = host_slice(points, n, "points")?;
        let input_s = host_slice(input.0.cast::<[f32; 3]>(), n, input.1)?;
        let mut spans = Vec::with_capacity(outputs.len() + 1);
        for &(p, name) in outputs {
            host_slice(p.cast_const().cast::<[f32; 3]>(), n, name)?;
            spans.push(Span::of(name, p.cast_const().cast::<[f32; 3]>(), n));
        }
        host_slice(pdf.cast_const(), n, "pdf")?;
        spans.push(Span::of("pdf", pdf, n));
        check_disjoint(
            &spans,
            &[
                Span::of("points", points.as_ptr(), n),
                Span::of(input.1, input_s.as_ptr(), n),
            ],
        )?;
        Ok(Batch {
            points,
            input: input_s,
            name: input.1,
        })
    }

    /// Checks that every point is filled and every input valid (`check`) before anything
    /// is written; the message names the first bad element. Then runs `each` on every
    /// element: its point, its input and its index.
    fn run<T>(
        &self,
        check: impl Fn([f32; 3], &str) -> Result<T, Failure>,
        mut each: impl FnMut(usize, &OwnedPoint, T),
    ) -> Result<(), Failure> {
        let (points, input) = (self.points, self.input);
        for i in 0..points.len() {
            if !filled(&points[i]) {
                read_point(&points[i], "point")
                    .map_err(|Failure(s, m)| Failure(s, format!("element {i}: {m}")))?;
            }
            if let Err(Failure(s, m)) = check(input[i], self.name) {
                return Err(Failure(s, format!("element {i}: {m}")));
            }
        }
        for (i, (point, &x)) in points.iter().zip(input).enumerate() {
            // SAFETY: aligned (the slice's type) and filled (checked above).
            let p = unsafe { &(*std::ptr::from_ref(point).cast::<Stored>()).point };
            each(i, p, check(x, self.name)?);
        }
        Ok(())
    }
}

/// `ht_hair_point_eval` over `n` points at once: `points[n]` (each filled, possibly from
/// different prepared BSDFs), `wi[3n]` in, `f[3n]` and `pdf[n]` out, tightly packed; each
/// result bit-identical to `ht_hair_point_eval`.
///
/// - Arrays: NULL allowed only when `n` = 0 (else `HT_ERR_NULL_ARG`, checked first);
///   `points` 16-byte and the floats 4-byte aligned; sizes must fit in memory (a huge or
///   "negative" `n`: `HT_ERR_INVALID_ARG`); `f` and `pdf` must not overlap each other, `wi`
///   or `points` (`HT_ERR_INVALID_ARG`).
/// - Every point and every `wi` is checked before anything is written; the message names
///   the first bad element (`element 7: ...`).
///
/// Any thread, concurrently on the same points.
///
/// # Safety
/// Each array is NULL or holds the number of elements given above (outputs writable).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_points_eval(
    points: *const HtHairPoint,
    n: usize,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let batch = Batch::check(points, n, (wi, "wi"), &[(f, "f")], pdf)?;
        let f = host_slice_mut(f.cast::<[f32; 3]>(), n, "f")?;
        let pdf = host_slice_mut(pdf, n, "pdf")?;
        batch.run(
            |w, name| check_dir(Vec3::from_array(w), name),
            |i, p, wi| {
                let e = p.eval(wi);
                (f[i], pdf[i]) = (e.f.to_array(), e.pdf);
            },
        )
    })
}

/// `ht_hair_point_sample` over `n` points at once: `points[n]`, `u[3n]` in, `wi[3n]`,
/// `f[3n]` and `pdf[n]` out, tightly packed; each result bit-identical to
/// `ht_hair_point_sample`. `pdf[i]` = 0 (`wi`, `f` zero) means no direction for point i.
///
/// - Arrays: NULL allowed only when `n` = 0 (else `HT_ERR_NULL_ARG`, checked first);
///   `points` 16-byte and the floats 4-byte aligned; sizes must fit in memory (a huge or
///   "negative" `n`: `HT_ERR_INVALID_ARG`); `wi`, `f` and `pdf` must not overlap each
///   other, `u` or `points` (`HT_ERR_INVALID_ARG`).
/// - Every point must be filled and every `u` in [0, 1) (`HT_ERR_INVALID_ARG`), all
///   checked before anything is written; the message names the first bad element.
///
/// Any thread, concurrently on the same points.
///
/// # Safety
/// Each array is NULL or holds the number of elements given above (outputs writable).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_points_sample(
    points: *const HtHairPoint,
    n: usize,
    u: *const f32,
    wi: *mut f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let batch = Batch::check(points, n, (u, "u"), &[(wi, "wi"), (f, "f")], pdf)?;
        let wi = host_slice_mut(wi.cast::<[f32; 3]>(), n, "wi")?;
        let f = host_slice_mut(f.cast::<[f32; 3]>(), n, "f")?;
        let pdf = host_slice_mut(pdf, n, "pdf")?;
        batch.run(check_u, |i, p, u| {
            (wi[i], f[i], pdf[i]) = sample_parts(p.sample(u));
        })
    })
}

#[cfg(test)]
mod tests {
    use super::super::bsdf::last_error;
    use super::*;
    use crate::bsdf::HairParams;
    use std::ptr::null_mut;

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
        let s = unsafe { ht_hair_point_init(handle, h, wo.as_ref().as_ptr(), &mut pt) };
        assert_eq!(s, HtStatus::HT_OK);
        assert_eq!(unsafe { ht_hair_prepared_free(handle) }, HtStatus::HT_OK);
        // A byte copy is as good as the original, after the handle is gone.
        let copy = HtHairPoint { opaque: pt.opaque };
        let rust = bsdf.at(h, wo);
        for k in 0..64 {
            let a = 0.1 * k as f32;
            let wi = Vec3::new(a.sin() * 0.5, a.cos() * 0.7, 0.5).normalize();
            let (mut f, mut pdf, mut pdf_only) = ([0.0f32; 3], 0.0f32, 0.0f32);
            let s = unsafe {
                ht_hair_point_eval(&copy, wi.as_ref().as_ptr(), f.as_mut_ptr(), &mut pdf)
            };
            assert_eq!(s, HtStatus::HT_OK);
            let want = rust.eval(wi);
            assert_eq!((f, pdf), (want.f.to_array(), want.pdf));
            let s = unsafe { ht_hair_point_pdf(&copy, wi.as_ref().as_ptr(), &mut pdf_only) };
            assert_eq!(
                (s, pdf_only.to_bits()),
                (HtStatus::HT_OK, want.pdf.to_bits())
            );
            // Across the fibre: each lane's f |cos| and pdf, as the Rust point's lanes.
            let (mut f_cos, mut pdf_lanes) = ([0.0f32; 3 * HT_ACROSS], [0.0f32; HT_ACROSS]);
            let s = unsafe {
                ht_hair_point_eval_across(
                    &copy,
                    wi.as_ref().as_ptr(),
                    f_cos.as_mut_ptr(),
                    pdf_lanes.as_mut_ptr(),
                )
            };
            assert_eq!(s, HtStatus::HT_OK);
            let lanes = rust.eval_across(wi).unwrap();
            for k in 0..HT_ACROSS {
                let want = (lanes.f[k] * wi.z.abs()).to_array();
                assert_eq!(f_cos[3 * k..3 * k + 3], want, "lane {k}");
                assert_eq!(pdf_lanes[k].to_bits(), lanes.pdf[k].to_bits(), "lane {k}");
            }
            let u = [k as f32 / 64.0, 0.37, 0.81];
            let (mut wi_s, mut f_s, mut pdf_s) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
            let s = unsafe {
                ht_hair_point_sample(
                    &pt,
                    u.as_ptr(),
                    wi_s.as_mut_ptr(),
                    f_s.as_mut_ptr(),
                    &mut pdf_s,
                )
            };
            assert_eq!(s, HtStatus::HT_OK);
            let want = rust.sample(u).unwrap();
            assert_eq!(
                (wi_s, f_s, pdf_s),
                (want.wi.to_array(), want.f.to_array(), want.pdf)
            );
        }
    }

    /// The world-space calls are the host's conversions around the local calls, bit for bit.
    #[test]
    fn world_calls_equal_the_conversions_around_the_local_calls() {
        use super::super::frame::{ht_hair_frame, ht_hair_frame_to_local, ht_hair_frame_to_world};
        let handle = prepare(&HairParams::default().into());
        for k in 0..200 {
            let a = 0.37 * k as f32;
            let tangent = Vec3::new(a.cos(), a.sin(), 0.3 * (2.0 * a).sin()).normalize();
            let dir = Vec3::new((1.7 * a).sin(), -0.4, (0.9 * a).cos()).normalize();
            let across = tangent.cross(dir).normalize();
            let h = (0.61 * k as f32).sin() * 0.95;
            let org = across * h - dir * 4.0;
            let mut frame = HtHairFrame {
                x: [0.0; 3],
                y: [0.0; 3],
                z: [0.0; 3],
                h: 0.0,
            };
            let arr = |v: &Vec3| v.to_array();
            let s = unsafe {
                ht_hair_frame(
                    arr(&tangent).as_ptr(),
                    arr(&org).as_ptr(),
                    arr(&dir).as_ptr(),
                    [0.0f32; 3].as_ptr(),
                    1.0,
                    &mut frame,
                )
            };
            assert_eq!(s, HtStatus::HT_OK);
            let wo = arr(&-dir);
            let (mut world, mut local) = (point(), point());
            let mut wo_local = [0.0f32; 3];
            unsafe {
                assert_eq!(
                    ht_hair_point_init_world(handle, &frame, wo.as_ptr(), &mut world),
                    HtStatus::HT_OK
                );
                ht_hair_frame_to_local(&frame, wo.as_ptr(), wo_local.as_mut_ptr());
                ht_hair_point_init(handle, frame.h, wo_local.as_ptr(), &mut local);
            }
            // Light from a direction of the world, and a sample.
            let wi = arr(&Vec3::new(0.3, (1.3 * a).cos(), (1.3 * a).sin()).normalize());
            let u = [(0.13 * k as f32).fract(), 0.42, (0.71 * k as f32).fract()];
            let (mut f_w, mut pdf_w, mut f_l, mut pdf_l) =
                ([0.0f32; 3], 0.0f32, [0.0f32; 3], 0.0f32);
            let mut wi_local = [0.0f32; 3];
            let (mut d_w, mut wt_w, mut p_w) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
            let (mut d_l, mut wt_l, mut p_l, mut d_back) =
                ([0.0f32; 3], [0.0f32; 3], 0.0f32, [0.0f32; 3]);
            unsafe {
                assert_eq!(
                    ht_hair_point_eval_world(&world, wi.as_ptr(), f_w.as_mut_ptr(), &mut pdf_w),
                    HtStatus::HT_OK
                );
                ht_hair_frame_to_local(&frame, wi.as_ptr(), wi_local.as_mut_ptr());
                ht_hair_point_eval_cos(&local, wi_local.as_ptr(), f_l.as_mut_ptr(), &mut pdf_l);
                let s = ht_hair_point_sample_world(
                    &world,
                    u.as_ptr(),
                    d_w.as_mut_ptr(),
                    wt_w.as_mut_ptr(),
                    &mut p_w,
                );
                assert_eq!(s, HtStatus::HT_OK);
                ht_hair_point_sample_cos(
                    &local,
                    u.as_ptr(),
                    d_l.as_mut_ptr(),
                    wt_l.as_mut_ptr(),
                    &mut p_l,
                );
                ht_hair_frame_to_world(&frame, d_l.as_ptr(), d_back.as_mut_ptr());
            }
            assert_eq!((f_w, pdf_w), (f_l, pdf_l), "eval at {k}");
            assert_eq!((d_w, wt_w, p_w), (d_back, wt_l, p_l), "sample at {k}");
            // Across the fibre, lane 0 (the point's own h) being the plain evaluation.
            type Across = unsafe extern "C" fn(
                *const HtHairPoint,
                *const f32,
                *mut f32,
                *mut f32,
            ) -> HtStatus;
            let lanes = |call: Across, p: &HtHairPoint, wi: &[f32; 3]| {
                let (mut f, mut pdf) = ([0.0f32; 3 * HT_ACROSS], [0.0f32; HT_ACROSS]);
                let s = unsafe { call(p, wi.as_ptr(), f.as_mut_ptr(), pdf.as_mut_ptr()) };
                assert_eq!(s, HtStatus::HT_OK);
                (f.map(f32::to_bits), pdf.map(f32::to_bits))
            };
            let across_w = lanes(ht_hair_point_eval_across_world, &world, &wi);
            let across_l = lanes(ht_hair_point_eval_across, &local, &wi_local);
            assert_eq!(across_w, across_l, "across at {k}");
            assert_eq!(across_w.0[..3], f_w.map(f32::to_bits), "lane 0 at {k}");
            assert_eq!(across_w.1[0], pdf_w.to_bits(), "lane 0 at {k}");
            assert!(pdf_w > 0.0 && p_w > 0.0, "{k}: a lobe toward every light");
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
        for k in 0..120u32 {
            let (strand, s) = (k * 7 % 23, (k % 11) as f32 / 10.0);
            let color = [0.3 + 0.005 * k as f32, 0.2, 0.1];
            let groom = (k % 2 == 0).then_some(color);
            let (h, wo) = (
                0.9 * (0.3 * k as f32).sin(),
                Vec3::new(0.3, 0.2, 0.9).normalize(),
            );
            let mut pt = point();
            let color_ptr = groom.as_ref().map_or(std::ptr::null(), |c| c.as_ptr());
            let st = unsafe {
                ht_hair_point_init_strand(
                    handle,
                    &variation,
                    strand,
                    s,
                    color_ptr,
                    h,
                    wo.as_ref().as_ptr(),
                    &mut pt,
                )
            };
            assert_eq!(st, HtStatus::HT_OK, "{}", last_error());
            let want = scene.bsdf_at(strand, s, groom.map(HairColor::Color));
            distinct.insert(want.params().sigma_a.map(f32::to_bits));
            let rust = want.at(h, wo);
            let wi = Vec3::new(-0.2, 0.7, 0.5).normalize();
            let (mut f, mut pdf) = ([0.0f32; 3], 0.0f32);
            unsafe { ht_hair_point_eval(&pt, wi.as_ref().as_ptr(), f.as_mut_ptr(), &mut pdf) };
            let e = rust.eval(wi);
            assert_eq!((f, pdf), (e.f.to_array(), e.pdf), "strand {strand} s {s}");
            let u = [0.61, 0.27, 0.83];
            let (mut w, mut fs, mut ps) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
            unsafe {
                ht_hair_point_sample(&pt, u.as_ptr(), w.as_mut_ptr(), fs.as_mut_ptr(), &mut ps)
            };
            let want = rust.sample(u).unwrap();
            assert_eq!(
                (w, fs, ps),
                (want.wi.to_array(), want.f.to_array(), want.pdf)
            );
        }
        assert!(
            distinct.len() > 100,
            "the parameters vary: {}",
            distinct.len()
        );
        let bad = HtHairVariation {
            roughness_variation: 2.0,
            ..variation
        };
        let wo = [0.0f32, 0.0, 1.0];
        let mut pt = point();
        let st = unsafe {
            ht_hair_point_init_strand(
                handle,
                &bad,
                0,
                0.5,
                std::ptr::null(),
                0.0,
                wo.as_ptr(),
                &mut pt,
            )
        };
        assert_eq!(st, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("roughness_variation = 2"),
            "{}",
            last_error()
        );
        let st = unsafe {
            ht_hair_point_init_strand(
                handle,
                &variation,
                0,
                1.5,
                std::ptr::null(),
                0.0,
                wo.as_ptr(),
                &mut pt,
            )
        };
        assert!(st == HtStatus::HT_ERR_INVALID_ARG && last_error().contains("s = 1.5"));
        unsafe { ht_hair_prepared_free(handle) };
    }

    #[test]
    fn unfilled_misaligned_and_overlapping_points_are_refused() {
        let wi = [0.0f32, 0.0, 1.0];
        let (mut f, mut pdf) = ([0.0f32; 3], 0.0f32);
        let zeroed = point();
        let s = unsafe { ht_hair_point_eval(&zeroed, wi.as_ptr(), f.as_mut_ptr(), &mut pdf) };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("not filled by ht_hair_point_init"),
            "{}",
            last_error()
        );
        let handle = prepare(&HairParams::default().into());
        let mut two = [point(), point()];
        let odd = unsafe { two.as_mut_ptr().cast::<u8>().add(4) }.cast::<HtHairPoint>();
        let s = unsafe { ht_hair_point_init(handle, 0.0, wi.as_ptr(), odd) };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("not aligned to 16"),
            "{}",
            last_error()
        );
        // wo inside the point it fills.
        let inside = two[0].opaque.as_ptr().cast::<f32>();
        let s = unsafe { ht_hair_point_init(handle, 0.0, inside, &mut two[0]) };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("point and wo overlap"),
            "{}",
            last_error()
        );
        unsafe { ht_hair_prepared_free(handle) };
    }

    #[test]
    fn batches_match_single_calls_and_check_every_element() {
        let handle = prepare(&HairParams::default().into());
        let mut points = [point(), point(), point()];
        for (k, p) in points.iter_mut().enumerate() {
            let wo = Vec3::new(0.2 * k as f32, 0.0, 1.0).normalize();
            unsafe { ht_hair_point_init(handle, 0.3 * k as f32, wo.as_ref().as_ptr(), p) };
        }
        let wi = [[0.0f32, 0.6, 0.8], [0.0, -0.6, 0.8], [1.0, 0.0, 0.0]];
        let (mut f, mut pdf) = ([[0.0f32; 3]; 3], [0.0f32; 3]);
        let s = unsafe {
            ht_hair_points_eval(
                points.as_ptr(),
                3,
                wi.as_ptr().cast(),
                f.as_mut_ptr().cast(),
                pdf.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_OK);
        let u = [[0.1f32, 0.2, 0.3], [0.5, 0.5, 0.5], [0.9, 0.1, 0.7]];
        let (mut wis, mut fs, mut pdfs) = ([[0.0f32; 3]; 3], [[0.0f32; 3]; 3], [0.0f32; 3]);
        let s = unsafe {
            ht_hair_points_sample(
                points.as_ptr(),
                3,
                u.as_ptr().cast(),
                wis.as_mut_ptr().cast(),
                fs.as_mut_ptr().cast(),
                pdfs.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_OK);
        for k in 0..3 {
            let (mut f1, mut p1) = ([0.0f32; 3], 0.0f32);
            unsafe { ht_hair_point_eval(&points[k], wi[k].as_ptr(), f1.as_mut_ptr(), &mut p1) };
            assert_eq!((f[k], pdf[k]), (f1, p1));
            let (mut w1, mut f1, mut p1) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
            unsafe {
                ht_hair_point_sample(
                    &points[k],
                    u[k].as_ptr(),
                    w1.as_mut_ptr(),
                    f1.as_mut_ptr(),
                    &mut p1,
                )
            };
            assert_eq!((wis[k], fs[k], pdfs[k]), (w1, f1, p1));
        }
        let bad = [[0.0f32, 0.6, 0.8], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let s = unsafe {
            ht_hair_points_eval(
                points.as_ptr(),
                3,
                bad.as_ptr().cast(),
                f.as_mut_ptr().cast(),
                pdf.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().starts_with("element 1: "), "{}", last_error());
        let s = unsafe {
            ht_hair_points_eval(
                points.as_ptr(),
                usize::MAX / 2,
                bad.as_ptr().cast(),
                f.as_mut_ptr().cast(),
                pdf.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("do not fit in memory"),
            "{}",
            last_error()
        );
        unsafe { ht_hair_prepared_free(handle) };
    }
}
