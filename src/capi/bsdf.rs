//! The hair BSDF's parameters and absorption through the C ABI, and the argument checks
//! every BSDF entry point shares (docs/c-abi.md). The prepared handle and per-vertex point
//! are in `prepared.rs`, the frame in `frame.rs`.
//!
//! Every entry point checks its pointers (NULL, then alignment, sizes and overlap) before
//! any value, so a NULL pointer is always `HT_ERR_NULL_ARG` whatever else is wrong.

use super::{
    Failure, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut, non_null,
    read_path,
};
use crate::bsdf::{HairParams, inputs, sigma_a_from_color, sigma_a_from_melanin, sigma_a_preset};
use glam::Vec3;
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
pub(super) fn check_u<const N: usize>(u: [f32; N], name: &str) -> Result<[f32; N], Failure> {
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
}
