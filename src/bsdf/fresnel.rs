//! Fresnel reflectance of a smooth dielectric interface, from either side.

use crate::math::Lanes;

/// Unpolarised Fresnel reflectance F from outside into a dielectric of index eta > 1 at
/// incidence cosine cos_i in [0, 1], and its complement 1 - F computed on its own: near
/// grazing incidence F is within a few ulps of 1 and 1 - F by subtraction would keep
/// none of its digits. F is 1 and 1 - F is 0 at grazing incidence; never divides by zero.
/// Written with e = eta^2 - 1 = (eta - 1)(eta + 1) factored out of both amplitudes, so that
/// an index just above 1 keeps its precision instead of cancelling in (eta c - cos t).
#[inline(always)]
pub(crate) fn fresnel_dielectric<T: Lanes>(cos_i: T, eta: T) -> (T, T) {
    let one = T::splat(1.0);
    let e = (eta - one) * (eta + one);
    let q = e.sqrt();
    let c2 = cos_i * cos_i;
    // w = eta cos_t = sqrt(eta^2 - sin_i^2) by Snell's law. At grazing incidence it is q
    // exactly, so both ratios below are exactly 1 and F is exactly 1 (no leak into 1 - F).
    let w = (e + c2).sqrt();
    let inv_perp = one / (cos_i + w);
    let inv_par = one / (eta * eta * cos_i + w);
    // Amplitudes with e factored out: r_perp = (c - w) / (c + w) = -e / (c + w)^2 and
    // r_par = (eta^2 c - w) / (eta^2 c + w) = e ((e + 2) c^2 - 1) / (eta^2 c + w)^2.
    let perp = q * inv_perp;
    let r_perp = perp * perp;
    let par = q * inv_par;
    let r_par = par * par * ((e + T::splat(2.0)) * c2 - one);
    // Rounding can lift the grazing value just above 1, which would leak into 1 - F.
    let f = (T::splat(0.5) * (r_par * r_par + r_perp * r_perp)).min(one);
    // 1 - r^2 = 4 c w / (c + w)^2 for perp and 4 eta^2 c w / (eta^2 c + w)^2 for par.
    let eta2 = eta * eta;
    let t = T::splat(2.0) * cos_i * w * (inv_perp * inv_perp + eta2 * inv_par * inv_par);
    (f, t.min(one))
}

/// F for light inside the dielectric meeting its surface at incidence cosine `cos_i`:
/// 1 under total internal reflection, else the outside value at the refracted angle (F is
/// the same both ways through an interface).
#[inline]
pub(crate) fn fresnel_inside(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    fresnel_dielectric((1.0 - sin2_t).sqrt(), eta).0
}
