//! The hair BSDF through the C ABI: the Rust model's eval and sample, with every input
//! checked (docs/c-abi.md).
//!
//! Hosts pass the parameters with every call. Building the per-parameter constants costs
//! about as much as an evaluation, so each thread keeps the last parameter set it saw and
//! its prepared BSDF, and reuses them while the parameters stay the same.

use super::{Failure, HtStatus, boundary, non_null, non_null_mut, read_vec3};
use crate::bsdf::{HairBsdf, HairParams, sigma_a_from_color, sigma_a_from_melanin};
use crate::error::invalid_arg;
use glam::Vec3;
use std::cell::RefCell;

/// Parameters of the hair BSDF: sigma_a per unit fibre radius (linear RGB, finite, >= 0),
/// eta in (1, 3], beta_m and beta_n in [0.01, 1], alpha (cuticle tilt) in degrees,
/// |alpha| <= 20. The frame: x along the fibre, y across it (h = offset along y over the
/// radius, in [-1, 1]), z toward the viewer; wo and wi unit vectors pointing away.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHairParams {
    /// Absorption per unit fiber radius, linear RGB.
    pub sigma_a: [f32; 3],
    /// Index of refraction of the fiber.
    pub eta: f32,
    /// Longitudinal roughness, [0.01, 1].
    pub beta_m: f32,
    /// Azimuthal roughness, [0.01, 1].
    pub beta_n: f32,
    /// Cuticle scale tilt, degrees.
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

/// Runs `f` with the BSDF for `params`, prepared once per parameter set and thread.
fn with_bsdf<R>(params: *const HtHairParams, f: impl FnOnce(&HairBsdf) -> R) -> Result<R, Failure> {
    let params: HairParams = unsafe { *non_null(params, "params")? }.into();
    PREPARED.with(|cell| {
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
}

fn bits(p: &HairParams) -> [u32; 7] {
    let s = p.sigma_a;
    [s[0], s[1], s[2], p.eta, p.beta_m, p.beta_n, p.alpha].map(f32::to_bits)
}

/// Reads a float[3] direction and checks that it is a finite unit vector.
fn read_dir(ptr: *const f32, name: &str) -> Result<Vec3, Failure> {
    let v = read_vec3(ptr, name)?;
    check_dir(v, name)?;
    Ok(v)
}

/// Directions must be unit length to 1e-3: the model reads angles from components.
fn check_dir(v: Vec3, name: &str) -> Result<(), Failure> {
    let len = v.length();
    if !(v.is_finite() && (len - 1.0).abs() <= 1e-3) {
        return Err(
            invalid_arg!("{name} = {v}: must be a finite unit vector (length {len})").into(),
        );
    }
    Ok(())
}

fn check_h(h: f32) -> Result<(), Failure> {
    if !(-1.0..=1.0).contains(&h) {
        return Err(invalid_arg!("h = {h}: must be in [-1, 1]").into());
    }
    Ok(())
}

fn write3(ptr: *mut f32, v: [f32; 3]) {
    unsafe { ptr.cast::<[f32; 3]>().write(v) }
}

/// Brown hair: sigma_a from eumelanin 1.3, eta 1.55, beta_m = beta_n = 0.3, alpha = 2.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_params_default() -> HtHairParams {
    HairParams::default().into()
}

/// sigma_a (per unit fiber radius) from melanin concentrations (finite, >= 0).
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_sigma_a_from_melanin(
    eumelanin: f32,
    pheomelanin: f32,
    sigma_a: *mut f32,
) -> HtStatus {
    boundary(|| {
        let out = non_null_mut(sigma_a, "sigma_a")?;
        write3(out, sigma_a_from_melanin(eumelanin, pheomelanin)?);
        Ok(())
    })
}

/// sigma_a that gives the reflectance `color` (each channel in (0, 1]) at roughness beta_n.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_sigma_a_from_color(
    color: *const f32,
    beta_n: f32,
    sigma_a: *mut f32,
) -> HtStatus {
    boundary(|| {
        let color = read_vec3(color, "color")?.to_array();
        let out = non_null_mut(sigma_a, "sigma_a")?;
        write3(out, sigma_a_from_color(color, beta_n)?);
        Ok(())
    })
}

/// f (RGB, pbrt convention: includes 1/|wi.z|) and pdf (solid angle) for unit wo, wi in
/// the local hair frame at offset h in [-1, 1].
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_eval(
    params: *const HtHairParams,
    h: f32,
    wo: *const f32,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        check_h(h)?;
        let (wo, wi) = (read_dir(wo, "wo")?, read_dir(wi, "wi")?);
        let (f_out, pdf_out) = (non_null_mut(f, "f")?, non_null_mut(pdf, "pdf")?);
        let e = with_bsdf(params, |b| b.eval(h, wo, wi))?;
        write3(f_out, e.f.to_array());
        unsafe { pdf_out.write(e.pdf) };
        Ok(())
    })
}

/// Samples wi for wo at h from three uniform numbers u in [0, 1). On success pdf > 0;
/// pdf = 0 (with wi and f zero) means no direction could be sampled.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_sample(
    params: *const HtHairParams,
    h: f32,
    wo: *const f32,
    u: *const f32,
    wi: *mut f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        check_h(h)?;
        let wo = read_dir(wo, "wo")?;
        let u = read_vec3(u, "u")?.to_array();
        if let Some(bad) = u.iter().position(|x| !(0.0..1.0).contains(x)) {
            return Err(invalid_arg!("u[{bad}] = {}: must be in [0, 1)", u[bad]).into());
        }
        let (wi_out, f_out, pdf_out) = (
            non_null_mut(wi, "wi")?,
            non_null_mut(f, "f")?,
            non_null_mut(pdf, "pdf")?,
        );
        let s = with_bsdf(params, |b| b.sample(h, wo, u))?;
        let (d, v, p) = s.map_or(([0.0; 3], [0.0; 3], 0.0), |s| {
            (s.wi.to_array(), s.f.to_array(), s.pdf)
        });
        write3(wi_out, d);
        write3(f_out, v);
        unsafe { pdf_out.write(p) };
        Ok(())
    })
}

/// n evaluations at once (SIMD inside); `h[n]`, `wo[3n]`, `wi[3n]`, `f[3n]`, `pdf[n]`, tightly
/// packed. Every input is checked before anything is written.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_eval_batch(
    params: *const HtHairParams,
    n: usize,
    h: *const f32,
    wo: *const f32,
    wi: *const f32,
    f: *mut f32,
    pdf: *mut f32,
) -> HtStatus {
    boundary(|| {
        if n == 0 {
            return Ok(());
        }
        let (h, wo, wi) = (non_null(h, "h")?, non_null(wo, "wo")?, non_null(wi, "wi")?);
        let (f, pdf) = (non_null_mut(f, "f")?, non_null_mut(pdf, "pdf")?);
        let (h, wo, wi, f, pdf) = unsafe {
            (
                std::slice::from_raw_parts(h, n),
                std::slice::from_raw_parts(wo.cast::<[f32; 3]>(), n),
                std::slice::from_raw_parts(wi.cast::<[f32; 3]>(), n),
                std::slice::from_raw_parts_mut(f.cast::<[f32; 3]>(), n),
                std::slice::from_raw_parts_mut(pdf, n),
            )
        };
        for i in 0..n {
            check_h(h[i])
                .and_then(|_| check_dir(Vec3::from_array(wo[i]), "wo"))
                .and_then(|_| check_dir(Vec3::from_array(wi[i]), "wi"))
                .map_err(|Failure(s, m)| Failure(s, format!("element {i}: {m}")))?;
        }
        with_bsdf(params, |b| b.eval_batch(h, wo, wi, f, pdf))??;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ptr::{null, null_mut};

    #[test]
    fn null_and_bad_arguments_are_reported() {
        let p = ht_hair_params_default();
        let wo = [0.0f32, 0.0, 1.0];
        let (mut f, mut pdf) = ([0.0f32; 3], 0.0f32);
        let eval = |p: *const HtHairParams, h: f32, wo: *const f32, f: *mut f32| {
            ht_hair_eval(p, h, wo, wo, f, &mut 0.0)
        };
        assert_eq!(
            eval(null(), 0.0, wo.as_ptr(), f.as_mut_ptr()),
            HtStatus::HT_ERR_NULL_ARG
        );
        assert_eq!(
            eval(&p, 0.0, null(), f.as_mut_ptr()),
            HtStatus::HT_ERR_NULL_ARG
        );
        assert_eq!(
            eval(&p, 0.0, wo.as_ptr(), null_mut()),
            HtStatus::HT_ERR_NULL_ARG
        );
        assert_eq!(
            eval(&p, 1.5, wo.as_ptr(), f.as_mut_ptr()),
            HtStatus::HT_ERR_INVALID_ARG
        );
        assert_eq!(
            eval(&p, f32::NAN, wo.as_ptr(), f.as_mut_ptr()),
            HtStatus::HT_ERR_INVALID_ARG
        );
        let long = [0.0f32, 0.0, 2.0];
        assert_eq!(
            eval(&p, 0.0, long.as_ptr(), f.as_mut_ptr()),
            HtStatus::HT_ERR_INVALID_ARG
        );
        let bad = HtHairParams { beta_m: 0.0, ..p };
        assert_eq!(
            eval(&bad, 0.0, wo.as_ptr(), f.as_mut_ptr()),
            HtStatus::HT_ERR_INVALID_ARG
        );
        let msg = unsafe { std::ffi::CStr::from_ptr(super::super::ht_last_error()) };
        assert!(msg.to_str().unwrap().contains("beta_m"), "{msg:?}");
        assert_eq!(
            ht_hair_eval(&p, 0.3, wo.as_ptr(), wo.as_ptr(), f.as_mut_ptr(), &mut pdf),
            HtStatus::HT_OK
        );
        assert!(pdf > 0.0 && f.iter().all(|v| v.is_finite() && *v > 0.0));
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
        let s = ht_hair_sample(
            &p,
            0.2,
            wo.as_ref().as_ptr(),
            u.as_ptr(),
            wi.as_mut_ptr(),
            f.as_mut_ptr(),
            &mut pdf,
        );
        assert_eq!(s, HtStatus::HT_OK);
        let want = bsdf.sample(0.2, wo, u).unwrap();
        assert_eq!(
            (Vec3::from_array(wi), Vec3::from_array(f), pdf),
            (want.wi, want.f, want.pdf)
        );
        let bad_u = [1.0f32, 0.5, 0.5];
        let s = ht_hair_sample(
            &p,
            0.2,
            wo.as_ref().as_ptr(),
            bad_u.as_ptr(),
            wi.as_mut_ptr(),
            f.as_mut_ptr(),
            &mut pdf,
        );
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);

        let hs = [0.2f32, -0.7];
        let wos = [wo.to_array(), [0.0, 1.0, 0.0]];
        let wis = [want.wi.to_array(), [0.0, 0.0, -1.0]];
        let (mut fb, mut pb) = ([[0.0f32; 3]; 2], [0.0f32; 2]);
        let s = ht_hair_eval_batch(
            &p,
            2,
            hs.as_ptr(),
            wos.as_ptr().cast(),
            wis.as_ptr().cast(),
            fb.as_mut_ptr().cast(),
            pb.as_mut_ptr(),
        );
        assert_eq!(s, HtStatus::HT_OK);
        for i in 0..2 {
            let e = bsdf.eval(hs[i], Vec3::from_array(wos[i]), Vec3::from_array(wis[i]));
            assert!((pb[i] - e.pdf).abs() <= 1e-5 * e.pdf);
        }
        let s = ht_hair_eval_batch(
            &p,
            2,
            hs.as_ptr(),
            null(),
            wis.as_ptr().cast(),
            fb.as_mut_ptr().cast(),
            pb.as_mut_ptr(),
        );
        assert_eq!(s, HtStatus::HT_ERR_NULL_ARG);
    }
}
