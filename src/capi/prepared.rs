//! The prepared hair BSDF for hosts: a handle holding the per-material constants, and a
//! per-vertex point in storage the host owns, so that a path vertex costs no allocation
//! and no re-preparation (docs/c-abi.md).
//!
//! The point is an `OwnedPoint` (its own copy of the BSDF plus the (h, wo) work) written
//! into the host's `HtHairPoint` bytes behind a tag; it runs the Rust `HairPoint` code, so
//! it gives the same bits.

use super::bsdf::{
    Arg, check_args, check_dir, check_h, check_u, clean_args, read_params, read3, require,
    sample_parts, write_eval, write_sample, write1,
};
use super::{
    Failure, HtHairParams, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut,
};
use crate::bsdf::{HairBsdf, OwnedPoint};
use crate::error::invalid_arg;
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
    /// [`TAG`] once filled: catches points that were never filled.
    tag: u64,
    point: OwnedPoint,
}

/// "htpoint" and a layout version.
const TAG: u64 = 0x6874_706f_696e_7401;

// The host's storage must hold a `Stored` at its alignment: checked at compile time.
const _: () = assert!(
    size_of::<Stored>() <= HT_HAIR_POINT_SIZE
        && align_of::<Stored>() <= HT_HAIR_POINT_ALIGN
        && size_of::<HtHairPoint>() == HT_HAIR_POINT_SIZE
        && align_of::<HtHairPoint>() == HT_HAIR_POINT_ALIGN
);

/// The filled point behind the host's storage (NULL, misaligned or unfilled: an error).
fn read_point<'a>(point: *const HtHairPoint, name: &str) -> Result<&'a OwnedPoint, Failure> {
    host_slice(point, 1, name)?;
    if !filled(point) {
        return Err(invalid_arg!(
            "{name} was not filled by ht_hair_point_init (or was overwritten)"
        )
        .into());
    }
    // SAFETY: non-NULL, aligned and filled (checked); `HtHairPoint` holds a `Stored`.
    Ok(unsafe { &(*point.cast::<Stored>()).point })
}

/// The tag of a non-NULL, aligned point.
#[inline(always)]
fn filled(point: *const HtHairPoint) -> bool {
    // SAFETY: the caller checked `point`; `HtHairPoint` is at least as large and as aligned
    // as `Stored` (asserted above), and `Stored` is plain numbers, valid for any bytes.
    unsafe { (*point.cast::<Stored>()).tag == TAG }
}

/// The point of a per-point call, with the call's pointers checked: the common case (all
/// non-NULL and aligned, outputs clear of the inputs and the point, the point filled)
/// inline and cheaply, anything else through the full checks that name the problem.
#[inline(always)]
fn checked_point<'a>(
    point: *const HtHairPoint,
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<&'a OwnedPoint, Failure> {
    check_args((point, "point"), inputs, outputs)?;
    if filled(point) {
        // SAFETY: non-NULL, aligned (checked above) and filled.
        return Ok(unsafe { &(*point.cast::<Stored>()).point });
    }
    read_point(point, "point")
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
        let fast = !prepared.is_null()
            && !point.is_null()
            && point.is_aligned()
            && clean_args(&[(wo, "wo", 3)], &[], (0, 0))
            && (wo as usize + 3 * size_of::<f32>() <= point as usize
                || point as usize + HT_HAIR_POINT_SIZE <= wo as usize);
        if !fast {
            require(&[
                (prepared.cast(), "prepared"),
                (wo.cast(), "wo"),
                (point.cast_const().cast(), "point"),
            ])?;
            host_slice(wo, 3, "wo")?;
            host_slice(point.cast_const(), 1, "point")?;
            check_disjoint(&[Span::of("point", point, 1)], &[Span::of("wo", wo, 3)])?;
        }
        let h = check_h(h)?;
        let wo = check_dir(read3(wo), "wo")?;
        // SAFETY: non-NULL (checked), a live handle (the caller's promise).
        let bsdf = unsafe { &(*prepared).bsdf };
        let stored = Stored {
            tag: TAG,
            point: OwnedPoint::new(bsdf, h, wo),
        };
        // SAFETY: non-NULL and aligned (checked), `HT_HAIR_POINT_SIZE` writable bytes that
        // hold a `Stored` (asserted above).
        unsafe { point.cast::<Stored>().write(stored) };
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
        write_eval(p.eval(check_dir(read3(wi), "wi")?), f, pdf);
        Ok(())
    })
}

/// The pdf alone (per unit solid angle) toward `wi[3]` at a filled point: the `pdf` that
/// `ht_hair_point_eval` writes, for hosts that need only the density (MIS weights).
/// Arguments, statuses and thread safety as `ht_hair_point_eval`, without `f`.
///
/// # Safety
/// As `ht_hair_point_eval`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_point_pdf(
    point: *const HtHairPoint,
    wi: *const f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let p = checked_point(point, &[(wi, "wi", 3)], &[(pdf, "pdf", 1)])?;
        write1(pdf, p.eval(check_dir(read3(wi), "wi")?).pdf);
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
        let s = p.sample(check_u(read3(u).to_array(), "u")?);
        write_sample(s, wi, f, pdf);
        Ok(())
    })
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
/// `ht_hair_point_sample`. Checks and statuses as `ht_hair_points_eval` (every `u[i]` in
/// [0, 1)); `wi`, `f` and `pdf` must not overlap each other, `u` or `points`.
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
