//! The hair BSDF through the C ABI: the Rust model's eval and sample, with every input
//! checked (docs/c-abi.md). The prepared handle and per-vertex point are in `prepared.rs`,
//! the frame helpers in `frame.rs`.
//!
//! Hosts pass the parameters with every call. Building the per-parameter constants costs
//! about as much as an evaluation, so each thread keeps the last parameter set it saw and
//! its prepared BSDF, and reuses them while the parameters stay the same.
//!
//! Every entry point checks its pointers (NULL, then alignment, sizes and overlap) before
//! any value, so a NULL pointer is always `HT_ERR_NULL_ARG` whatever else is wrong.

use super::{
    Failure, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut, non_null,
    read_path,
};
use crate::bsdf::{
    BsdfEval, BsdfSample, HairBsdf, HairParams, inputs, sigma_a_from_color, sigma_a_from_melanin,
    sigma_a_preset,
};
use glam::Vec3;
use std::cell::RefCell;
use std::ffi::c_char;

/// Parameters of the hair BSDF (Chiang et al. 2016), all checked, never clamped:
/// - `sigma_a`: absorption per unit fibre *radius* (so independent of the fibre's size),
///   linear RGB, each finite and >= 0; from `ht_hair_sigma_a_from_melanin` or
///   `ht_hair_sigma_a_from_color`.
/// - `eta`: index of refraction, in (1, 3] (1.55 for keratin).
/// - `beta_m`, `beta_n`: longitudinal and azimuthal roughness, each in [0.01, 1].
/// - `alpha`: cuticle scale tilt in *degrees*, in [-20, 20] (pbrt's sign; Blender's
///   "Offset" is -alpha in radians).
///
/// Directions and h live in the local hair frame described at `HtHairFrame`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHairParams {
    /// Absorption per unit fiber radius, linear RGB, finite, >= 0.
    pub sigma_a: [f32; 3],
    /// Index of refraction of the fiber, (1, 3].
    pub eta: f32,
    /// Longitudinal roughness, [0.01, 1].
    pub beta_m: f32,
    /// Azimuthal roughness, [0.01, 1].
    pub beta_n: f32,
    /// Cuticle scale tilt, degrees, [-20, 20].
    pub alpha: f32,
}

impl From<HtHairParams> for HairParams {
    fn from(p: HtHairParams) -> Self {
        HairParams {
            sigma_a: p.sigma_a,
            eta: p.eta,
            beta_m: p.beta_m,
            beta_n: p.beta_n,
            alpha: p.alpha,
        }
    }
}

impl From<HairParams> for HtHairParams {
    fn from(p: HairParams) -> Self {
        HtHairParams {
            sigma_a: p.sigma_a,
            eta: p.eta,
            beta_m: p.beta_m,
            beta_n: p.beta_n,
            alpha: p.alpha,
        }
    }
}

thread_local! {
    static PREPARED: RefCell<Option<HairBsdf>> = const { RefCell::new(None) };
}

/// Copies the host's parameters (NULL: `HT_ERR_NULL_ARG`; misaligned: invalid).
pub(super) fn read_params(ptr: *const HtHairParams) -> Result<HairParams, Failure> {
    Ok(host_slice(ptr, 1, "params")?[0].into())
}

/// Runs `f` with the BSDF for `params`, prepared once per parameter set and thread.
///
/// `try_with`, not `with`: `with` is not `#[inline]`, so its copy for this closure is a
/// single one that the partitioning into codegen units may place away from the entry point,
/// which then calls it out of line and reaches the thread-local through a function pointer.
/// `try_with` is `#[inline]`: a copy in the entry point's own unit, inlined. It fails where
/// `with` would panic, and so panics the same way.
fn with_bsdf<R>(params: HairParams, f: impl FnOnce(&HairBsdf) -> R) -> Result<R, Failure> {
    PREPARED
        .try_with(|cell| {
            let mut slot = cell.borrow_mut();
            // Compare bit patterns so that a NaN parameter is never taken as "unchanged".
            let same = slot
                .as_ref()
                .is_some_and(|b| bits(b.params()) == bits(&params));
            if !same {
                *slot = Some(HairBsdf::new(&params)?);
            }
            Ok(f(slot.as_ref().expect("prepared above")))
        })
        .expect("cannot access a Thread Local Storage value during or after destruction")
}

fn bits(p: &HairParams) -> [u32; 7] {
    let s = p.sigma_a;
    [s[0], s[1], s[2], p.eta, p.beta_m, p.beta_n, p.alpha].map(f32::to_bits)
}

pub(super) use crate::bsdf::inputs::{UNIT_TOLERANCE, is_unit};

/// [`inputs::check_dir`] with the C ABI's failure.
#[inline(always)]
pub(super) fn check_dir(v: Vec3, name: &str) -> Result<Vec3, Failure> {
    Ok(inputs::check_dir(v, name)?)
}

/// [`inputs::check_h`] with the C ABI's failure.
#[inline(always)]
pub(super) fn check_h(h: f32) -> Result<f32, Failure> {
    Ok(inputs::check_h(h)?)
}

/// [`inputs::check_u`] with the C ABI's failure.
#[inline(always)]
pub(super) fn check_u(u: [f32; 3], name: &str) -> Result<[f32; 3], Failure> {
    Ok(inputs::check_u(u, name)?)
}

/// NULL-checks every pointer of a call before anything else, so that a NULL pointer is
/// reported as such whatever else is wrong with the call.
pub(super) fn require(ptrs: &[(*const (), &str)]) -> Result<(), Failure> {
    for &(p, name) in ptrs {
        non_null(p, name)?;
    }
    Ok(())
}

/// A float array of a call: pointer, name, length in floats.
pub(super) type Arg = (*const f32, &'static str, usize);

/// The common case of a call's float arrays, checked inline and cheaply: every pointer
/// non-NULL and aligned, every output clear of the inputs, of `extra` (another byte range
/// the call reads, as (address, bytes)) and of the other outputs. When it is false the
/// call runs its full checks, which name the problem.
#[inline(always)]
pub(super) fn clean_args(inputs: &[Arg], outputs: &[Arg], extra: (usize, usize)) -> bool {
    let usable = |p: *const f32| !p.is_null() && p.is_aligned();
    let bytes = |(p, _, n): Arg| (p as usize, n * size_of::<f32>());
    let apart = |(a, m): (usize, usize), (b, n): (usize, usize)| a + m <= b || b + n <= a;
    inputs.iter().chain(outputs).all(|a| usable(a.0))
        && outputs.iter().enumerate().all(|(k, &o)| {
            apart(bytes(o), extra)
                && inputs
                    .iter()
                    .chain(&outputs[k + 1..])
                    .all(|&i| apart(bytes(o), bytes(i)))
        })
}

/// The pointers of a call: `head` (the struct it reads first: parameters or a point)
/// and its float arrays, checked inline by [`clean_args`] in the common case, else in the
/// documented order with messages: every NULL first, then alignment and sizes, then the
/// overlap of each output with the other outputs, the inputs and `head`.
#[inline(always)]
pub(super) fn check_args<H>(
    head: (*const H, &'static str),
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<(), Failure> {
    let ptr = head.0;
    let extra = (ptr as usize, size_of::<H>());
    if !ptr.is_null() && ptr.is_aligned() && clean_args(inputs, outputs, extra) {
        return Ok(());
    }
    full_checks(head, inputs, outputs)
}

#[cold]
#[inline(never)]
fn full_checks<H>(
    (ptr, name): (*const H, &'static str),
    inputs: &[Arg],
    outputs: &[Arg],
) -> Result<(), Failure> {
    let mut all = vec![(ptr.cast::<()>(), name)];
    all.extend(inputs.iter().chain(outputs).map(|a| (a.0.cast(), a.1)));
    require(&all)?;
    host_slice(ptr, 1, name)?;
    for &(p, arg, n) in inputs.iter().chain(outputs) {
        host_slice(p, n, arg)?;
    }
    let span = |&(p, arg, n): &Arg| Span::of(arg, p, n);
    let mut read: Vec<_> = inputs.iter().map(span).collect();
    read.push(Span::of(name, ptr, 1));
    check_disjoint(&outputs.iter().map(span).collect::<Vec<_>>(), &read)
}

/// Reads a `float[3]` that [`clean_args`] or the full checks have passed.
#[inline(always)]
pub(super) fn read3(ptr: *const f32) -> Vec3 {
    // SAFETY: non-NULL and aligned (checked), 3 floats (the caller's promise).
    Vec3::from_array(unsafe { ptr.cast::<[f32; 3]>().read() })
}

/// Writes a `float[3]` that [`clean_args`] or the full checks have passed.
#[inline(always)]
pub(super) fn write3(ptr: *mut f32, v: [f32; 3]) {
    // SAFETY: non-NULL, aligned and clear of every input (checked), 3 writable floats.
    unsafe { ptr.cast::<[f32; 3]>().write(v) }
}

/// Writes one float that [`clean_args`] or the full checks have passed.
#[inline(always)]
pub(super) fn write1(ptr: *mut f32, v: f32) {
    // SAFETY: as `write3`.
    unsafe { ptr.write(v) }
}

/// The host's `float[3]`, already checked for NULL and alignment by [`host_slice`].
pub(super) fn vec3(s: &[f32]) -> Vec3 {
    Vec3::new(s[0], s[1], s[2])
}

/// Brown hair: sigma_a from eumelanin 1.3, eta 1.55, beta_m = beta_n = 0.3, alpha = 2.
/// Cannot fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_params_default() -> HtHairParams {
    HairParams::default().into()
}

/// Writes `sigma_a[3]` (per unit fibre radius) for melanin concentrations: eumelanin about
/// 0.3 (blonde), 1.3 (brown), 8 (black); pheomelanin adds red.
///
/// - `eumelanin`, `pheomelanin`: finite, >= 0, and small enough that sigma_a stays finite
///   (up to about 1e37), else `HT_ERR_INVALID_ARG`.
/// - `sigma_a`: out, 3 floats, 4-byte aligned; NULL: `HT_ERR_NULL_ARG`. Untouched on error.
///
/// Any thread.
///
/// # Safety
/// `sigma_a` is NULL or points to 3 writable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_sigma_a_from_melanin(
    eumelanin: f32,
    pheomelanin: f32,
    sigma_a: *mut f32,
) -> HtStatus {
    boundary(|| {
        let out = host_slice_mut(sigma_a, 3, "sigma_a")?;
        out.copy_from_slice(&sigma_a_from_melanin(eumelanin, pheomelanin)?);
        Ok(())
    })
}

/// Writes `sigma_a[3]` (per unit fibre radius) of a named absorption preset: "red_brown"
/// (0.09, 1.3, 2.6), "light_brown" (0.6, 1.3, 2.0), "dark_brown" (0.9, 1.28, 2.66),
/// "black" (2.9, 5.1, 10.2) or "white" (0.08, 0.09, 0.18), the names of the scene format.
///
/// - `name`: a NUL-terminated UTF-8 string, NULL: `HT_ERR_NULL_ARG`; any other name:
///   `HT_ERR_INVALID_ARG`, whose message lists the valid ones.
/// - `sigma_a`: out, 3 floats, 4-byte aligned; NULL: `HT_ERR_NULL_ARG`. Untouched on error.
///
/// Any thread.
///
/// # Safety
/// `name` is NULL or a NUL-terminated string; `sigma_a` is NULL or points to 3 writable
/// floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_sigma_a_preset(
    name: *const c_char,
    sigma_a: *mut f32,
) -> HtStatus {
    boundary(|| {
        require(&[
            (name.cast(), "name"),
            (sigma_a.cast_const().cast(), "sigma_a"),
        ])?;
        let out = host_slice_mut(sigma_a, 3, "sigma_a")?;
        out.copy_from_slice(&sigma_a_preset(
            &read_path(name, "name")?.to_string_lossy(),
        )?);
        Ok(())
    })
}

/// Writes `sigma_a[3]` that makes a fibre look like the linear RGB reflectance `color` at
/// azimuthal roughness `beta_n` (Chiang's inversion: pass the beta_n you render with).
///
/// - `color`: 3 floats, each in (0, 1]; `beta_n` in [0.01, 1]; else `HT_ERR_INVALID_ARG`.
/// - `sigma_a`: out, 3 floats. Both pointers 4-byte aligned, not NULL (`HT_ERR_NULL_ARG`),
///   and not overlapping (`HT_ERR_INVALID_ARG`). Untouched on error.
///
/// Any thread.
///
/// # Safety
/// Each pointer is NULL or points to 3 floats (`sigma_a` writable).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_sigma_a_from_color(
    color: *const f32,
    beta_n: f32,
    sigma_a: *mut f32,
) -> HtStatus {
    boundary(|| {
        require(&[
            (color.cast(), "color"),
            (sigma_a.cast_const().cast(), "sigma_a"),
        ])?;
        let rgb = vec3(host_slice(color, 3, "color")?).to_array();
        host_slice(sigma_a.cast_const(), 3, "sigma_a")?;
        check_disjoint(
            &[Span::of("sigma_a", sigma_a, 3)],
            &[Span::of("color", color, 3)],
        )?;
        let rgb = sigma_a_from_color(rgb, beta_n)?;
        host_slice_mut(sigma_a, 3, "sigma_a")?.copy_from_slice(&rgb);
        Ok(())
    })
}

/// Evaluates the BSDF for one (h, wo, wi): writes `f[3]` (linear RGB, per steradian,
/// pbrt's convention: includes the 1/|wi.z| factor, so `f * |wi.z|` is the scattered
/// fraction per unit solid angle) and `*pdf` (the density of `ht_hair_sample` at wi, per
/// unit solid angle).
///
/// - `params`: see `HtHairParams`; a value out of range: `HT_ERR_INVALID_ARG` naming it.
/// - `h`: offset across the fibre in [-1, 1] (NaN refused); `wo`, `wi`: 3 floats each,
///   unit vectors (|length - 1| <= 1e-3) in the local frame, both pointing away from the
///   fibre. `HtHairFrame` says how to build the frame and h: a wrong frame or a flipped
///   h is *not* detectable here and gives HT_OK with mirrored lobes.
/// - Pointers: none may be NULL (`HT_ERR_NULL_ARG`, checked before any value); all 4-byte
///   aligned; `f` and `pdf` must not overlap each other or an input (`HT_ERR_INVALID_ARG`).
///   Outputs are untouched on error. Nothing is kept after the call.
///
/// Any thread, concurrently. Each thread keeps the last parameter set it saw with its
/// prepared constants; calls alternating between materials prepare them every time:
/// use `ht_hair_prepare` and `HtHairPoint` for that.
///
/// # Safety
/// Each pointer is NULL or points to its type (3 floats for `wo`, `wi`, `f`), outputs
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_eval(
    params: *const HtHairParams,
    h: f32,
    wo: *const f32,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let (inputs, outputs) = (
            [(wo, "wo", 3), (wi, "wi", 3)],
            [(f.cast_const(), "f", 3), (pdf.cast_const(), "pdf", 1)],
        );
        check_args((params, "params"), &inputs, &outputs)?;
        // SAFETY: non-NULL and aligned (checked above).
        let params = HairParams::from(unsafe { params.read() });
        let h = check_h(h)?;
        let (wo, wi) = (check_dir(read3(wo), "wo")?, check_dir(read3(wi), "wi")?);
        write_eval(with_bsdf(params, |b| b.eval(h, wo, wi))?, f, pdf);
        Ok(())
    })
}

/// Samples an incident direction for wo at h from three uniform numbers `u[3]` in [0, 1):
/// writes `wi[3]` (unit, local frame, pointing away), `f[3]` and `*pdf` exactly as
/// `ht_hair_eval` gives them at that wi. `f * |wi.z| / pdf` is the path weight. pdf = 0
/// (with wi and f zero) means no direction could be sampled; the status is still HT_OK.
///
/// Ranges of `params`, `h`, `wo` as in `ht_hair_eval`; `u[i]` outside [0, 1) or NaN:
/// `HT_ERR_INVALID_ARG`. Pointers: none NULL (`HT_ERR_NULL_ARG`, checked first), 4-byte
/// aligned; the outputs `wi`, `f`, `pdf` must not overlap each other or an input
/// (`HT_ERR_INVALID_ARG`). Outputs are untouched on error. Any thread, as `ht_hair_eval`.
///
/// # Safety
/// Each pointer is NULL or points to its type (3 floats for `wo`, `u`, `wi`, `f`),
/// outputs writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_sample(
    params: *const HtHairParams,
    h: f32,
    wo: *const f32,
    u: *const f32,
    wi: *mut f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        let inputs = [(wo, "wo", 3), (u, "u", 3)];
        let outputs = [
            (wi.cast_const(), "wi", 3),
            (f.cast_const(), "f", 3),
            (pdf.cast_const(), "pdf", 1),
        ];
        check_args((params, "params"), &inputs, &outputs)?;
        // SAFETY: non-NULL and aligned (checked above).
        let params = HairParams::from(unsafe { params.read() });
        let h = check_h(h)?;
        let wo = check_dir(read3(wo), "wo")?;
        let u = check_u(read3(u).to_array(), "u")?;
        write_sample(with_bsdf(params, |b| b.sample(h, wo, u))?, wi, f, pdf);
        Ok(())
    })
}

/// Writes an evaluation to outputs that [`check_args`] has passed.
#[inline(always)]
pub(super) fn write_eval(e: BsdfEval, f: *mut f32, pdf: *mut f32) {
    write3(f, e.f.to_array());
    write1(pdf, e.pdf);
}

/// Writes a sample (zeros when there is none) to outputs that [`check_args`] has passed.
#[inline(always)]
pub(super) fn write_sample(s: Option<BsdfSample>, wi: *mut f32, f: *mut f32, pdf: *mut f32) {
    let (d, v, p) = sample_parts(s);
    write3(wi, d);
    write3(f, v);
    write1(pdf, p);
}

/// A sample's wi, f and pdf, or zeros when there is none (the C ABI's "pdf = 0").
#[inline(always)]
pub(super) fn sample_parts(s: Option<BsdfSample>) -> ([f32; 3], [f32; 3], f32) {
    s.map_or(([0.0; 3], [0.0; 3], 0.0), |s| {
        (s.wi.to_array(), s.f.to_array(), s.pdf)
    })
}

/// `n` evaluations at once (eight per SIMD step), each bit-identical to `ht_hair_eval`:
/// reads `h[n]`, `wo[3n]`, `wi[3n]`, writes `f[3n]`, `pdf[n]`, tightly packed.
///
/// - `params` is checked (NULL, ranges) even when `n` = 0.
/// - Arrays: NULL allowed only when `n` = 0 (else `HT_ERR_NULL_ARG`, checked before any
///   value); 4-byte aligned; `3n` floats must fit in memory (a huge or "negative" `n`:
///   `HT_ERR_INVALID_ARG`); `f` and `pdf` must not overlap each other or an input
///   (`HT_ERR_INVALID_ARG`).
/// - Every element is checked (ranges as in `ht_hair_eval`) before anything is written;
///   the message names the first bad element (`element 7: ...`).
///
/// Any thread, as `ht_hair_eval`.
///
/// # Safety
/// Each array is NULL or holds the number of floats given above (outputs writable).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_hair_eval_batch(
    params: *const HtHairParams,
    n: usize,
    h: *const f32,
    wo: *const f32,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        non_null(params, "params")?;
        if n > 0 {
            require(&[
                (h.cast(), "h"),
                (wo.cast(), "wo"),
                (wi.cast(), "wi"),
                (f.cast_const().cast(), "f"),
                (pdf.cast_const().cast(), "pdf"),
            ])?;
        }
        let params = read_params(params)?;
        let h = host_slice(h, n, "h")?;
        let wo = host_slice(wo.cast::<[f32; 3]>(), n, "wo")?;
        let wi = host_slice(wi.cast::<[f32; 3]>(), n, "wi")?;
        let f = f.cast::<[f32; 3]>();
        host_slice(f.cast_const(), n, "f")?;
        host_slice(pdf.cast_const(), n, "pdf")?;
        check_disjoint(
            &[Span::of("f", f, n), Span::of("pdf", pdf, n)],
            &[
                Span::of("h", h.as_ptr(), h.len()),
                Span::of("wo", wo.as_ptr(), wo.len()),
                Span::of("wi", wi.as_ptr(), wi.len()),
            ],
        )?;
        with_bsdf(params, |b| -> Result<(), Failure> {
            for i in 0..n {
                check_h(h[i])
                    .and_then(|_| check_dir(Vec3::from_array(wo[i]), "wo"))
                    .and_then(|_| check_dir(Vec3::from_array(wi[i]), "wi"))
                    .map_err(|Failure(s, m)| Failure(s, format!("element {i}: {m}")))?;
            }
            let (f, pdf) = (host_slice_mut(f, n, "f")?, host_slice_mut(pdf, n, "pdf")?);
            Ok(b.eval_batch(h, wo, wi, f, pdf)?)
        })?
    })
}

/// The calling thread's last error message, for the tests of the BSDF entry points.
#[cfg(test)]
pub(super) fn last_error() -> String {
    // SAFETY: ht_last_error returns a valid NUL-terminated string.
    unsafe { std::ffi::CStr::from_ptr(super::ht_last_error()) }
        .to_string_lossy()
        .into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ptr::{null, null_mut};

    #[test]
    fn null_pointers_are_reported_before_bad_values() {
        let wo = [0.0f32, 0.0, 1.0];
        let (mut f, mut pdf) = ([0.0f32; 3], 0.0f32);
        let s = unsafe {
            ht_hair_eval(
                null(),
                f32::NAN,
                wo.as_ptr(),
                wo.as_ptr(),
                f.as_mut_ptr(),
                &mut pdf,
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
        assert_eq!(last_error(), "params is NULL");
        let p = ht_hair_params_default();
        let s = unsafe { ht_hair_eval(&p, 2.0, wo.as_ptr(), wo.as_ptr(), null_mut(), &mut pdf) };
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
        assert_eq!(last_error(), "f is NULL");
        let bad = HtHairParams { beta_m: 0.0, ..p };
        let s = unsafe {
            ht_hair_eval(
                &bad,
                0.0,
                wo.as_ptr(),
                wo.as_ptr(),
                f.as_mut_ptr(),
                &mut pdf,
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("beta_m = 0"), "{}", last_error());
    }

    #[test]
    fn batch_checks_sizes_params_and_overlap() {
        let p = ht_hair_params_default();
        let buf = [0.0f32; 64];
        let mut out = [0.0f32; 64];
        let n = usize::MAX / 2;
        let s = unsafe {
            ht_hair_eval_batch(
                &p,
                n,
                buf.as_ptr(),
                buf.as_ptr(),
                buf.as_ptr(),
                out.as_mut_ptr(),
                out.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("do not fit in memory"),
            "{}",
            last_error()
        );
        // n = 0 still checks the parameters.
        let bad = HtHairParams { eta: 0.5, ..p };
        let s =
            unsafe { ht_hair_eval_batch(&bad, 0, null(), null(), null(), null_mut(), null_mut()) };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("eta = 0.5"), "{}", last_error());
        let s = unsafe {
            ht_hair_eval_batch(null(), 0, null(), null(), null(), null_mut(), null_mut())
        };
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
        // pdf inside f: refused before anything is written.
        let (h, wo) = ([0.1f32; 2], [[0.0f32, 0.0, 1.0]; 2]);
        let mut f = [7.0f32; 8];
        let s = unsafe {
            ht_hair_eval_batch(
                &p,
                2,
                h.as_ptr(),
                wo.as_ptr().cast(),
                wo.as_ptr().cast(),
                f.as_mut_ptr(),
                f.as_mut_ptr().add(4),
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(
            last_error().contains("f and pdf overlap"),
            "{}",
            last_error()
        );
        assert_eq!(f, [7.0; 8]);
        // A misaligned output.
        let mut raw = [0u8; 64];
        let odd = unsafe { raw.as_mut_ptr().add(1) }.cast::<f32>();
        let s = unsafe {
            ht_hair_eval_batch(
                &p,
                2,
                h.as_ptr(),
                wo.as_ptr().cast(),
                wo.as_ptr().cast(),
                odd,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("not aligned"), "{}", last_error());
    }

    #[test]
    fn melanin_overflow_is_refused_at_the_source() {
        let mut sigma = [0.0f32; 3];
        let s = unsafe { ht_hair_sigma_a_from_melanin(f32::MAX, f32::MAX, sigma.as_mut_ptr()) };
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("overflows"), "{}", last_error());
        assert_eq!(sigma, [0.0; 3]);
    }

    #[test]
    fn presets_by_name() {
        for (name, want) in crate::bsdf::SIGMA_A_PRESETS {
            let c = std::ffi::CString::new(name).unwrap();
            let mut sigma = [0.0f32; 3];
            let s = unsafe { ht_hair_sigma_a_preset(c.as_ptr(), sigma.as_mut_ptr()) };
            assert_eq!((s, sigma), (HtStatus::HT_OK, want), "{name}");
        }
        let mut sigma = [0.0f32; 3];
        let s = unsafe { ht_hair_sigma_a_preset(c"auburn".as_ptr(), sigma.as_mut_ptr()) };
        assert_eq!((s, sigma), (HtStatus::HT_ERR_INVALID_ARG, [0.0; 3]));
        assert!(
            last_error().contains("\"auburn\"") && last_error().contains("dark_brown, black"),
            "{}",
            last_error()
        );
        // NULL first, whatever the name.
        let s = unsafe { ht_hair_sigma_a_preset(c"auburn".as_ptr(), std::ptr::null_mut()) };
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
        let s = unsafe { ht_hair_sigma_a_preset(std::ptr::null(), sigma.as_mut_ptr()) };
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
        assert!(last_error().contains("name"), "{}", last_error());
    }

    #[test]
    fn c_entry_points_match_the_rust_api() {
        let p = HtHairParams {
            alpha: 5.0,
            ..ht_hair_params_default()
        };
        let bsdf = HairBsdf::new(&p.into()).unwrap();
        let wo = Vec3::new(0.3, 0.5, (1.0f32 - 0.09 - 0.25).sqrt());
        let u = [0.3f32, 0.6, 0.8];
        let (mut wi, mut f, mut pdf) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
        let s = unsafe {
            ht_hair_sample(
                &p,
                0.2,
                wo.as_ref().as_ptr(),
                u.as_ptr(),
                wi.as_mut_ptr(),
                f.as_mut_ptr(),
                &mut pdf,
            )
        };
        assert_eq!(s, HtStatus::HT_OK);
        let want = bsdf.sample(0.2, wo, u).unwrap();
        assert_eq!(
            (Vec3::from_array(wi), Vec3::from_array(f), pdf),
            (want.wi, want.f, want.pdf)
        );
        let hs = [0.2f32, -0.7];
        let wos = [wo.to_array(), [0.0, 1.0, 0.0]];
        let wis = [want.wi.to_array(), [0.0, 0.0, -1.0]];
        let (mut fb, mut pb) = ([[0.0f32; 3]; 2], [0.0f32; 2]);
        let s = unsafe {
            ht_hair_eval_batch(
                &p,
                2,
                hs.as_ptr(),
                wos.as_ptr().cast(),
                wis.as_ptr().cast(),
                fb.as_mut_ptr().cast(),
                pb.as_mut_ptr(),
            )
        };
        assert_eq!(s, HtStatus::HT_OK);
        for i in 0..2 {
            let e = bsdf.eval(hs[i], Vec3::from_array(wos[i]), Vec3::from_array(wis[i]));
            assert_eq!((fb[i], pb[i]), (e.f.to_array(), e.pdf));
        }
    }
}
