//! An independent f64 reference of the Chiang et al. 2016 hair BSDF (as in pbrt-v3/v4),
//! written from the formulas of the test brief, not from `src/bsdf`.
//!
//! Frame: x is the fiber tangent; for a direction w, sin(theta) = w.x,
//! cos(theta) = sqrt(1 - sin^2), phi = atan2(w.z, w.y). Both wo and wi point away from
//! the fiber. Every quantity is computed in f64 in a form without catastrophic
//! cancellation, so that the reference is accurate to ~1e-12 relative wherever the model
//! itself is well conditioned:
//!
//! - the longitudinal lobe uses `exp((cos(ti + to) - 1) / v) * [e^-x I0(x)] / (v (1 - e^-2/v))`
//!   with `1 - cos` written as `2 sin^2(./2)`,
//! - `e^-x I0(x)` is a power series below x = 25 and the asymptotic expansion above (both
//!   truncated at 1e-17 relative; the two agree to ~1e-15 where they overlap),
//! - the Fresnel transmittance `1 - F` is computed directly (no `1 - F` subtraction),
//! - `1 - T F` is written `(1 - T) + T (1 - F)` with `1 - T = -expm1(-tau)`.

#![allow(clippy::needless_range_loop)] // per-channel and per-lobe loops read as the formulas

use std::f64::consts::PI;

/// Switch from the power series to the asymptotic expansion of `e^-x I0(x)`.
const I0_SERIES_LIMIT: f64 = 25.0;

/// Variance v of the R lobe for longitudinal roughness `beta_m` (d'Eon / Chiang mapping).
pub fn longitudinal_variance(beta_m: f64) -> f64 {
    let b = beta_m;
    let r = 0.726 * b + 0.812 * b * b + 3.7 * b.powi(20);
    r * r
}

/// The four lobe variances [R, TT, TRT, residual] for `beta_m`.
pub fn lobe_variances(beta_m: f64) -> [f64; 4] {
    let v0 = longitudinal_variance(beta_m);
    [v0, v0 / 4.0, 4.0 * v0, 4.0 * v0]
}

/// Scale s of the azimuthal logistic for azimuthal roughness `beta_n`.
pub fn azimuthal_scale(beta_n: f64) -> f64 {
    let b = beta_n;
    (PI / 8.0).sqrt() * (0.265 * b + 1.194 * b * b + 5.372 * b.powi(22))
}

/// `e^-x I0(x)` by the power series `sum (x^2/4)^k / (k!)^2` (all terms positive, so the
/// sum has no cancellation); accurate for any x but slow and overflowing above ~700.
pub fn i0_scaled_series(x: f64) -> f64 {
    let x = x.abs();
    let q = 0.25 * x * x;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    loop {
        term *= q / (k * k);
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
        k += 1.0;
    }
    sum * (-x).exp()
}

/// `e^-x I0(x)` by the asymptotic expansion
/// `1/sqrt(2 pi x) * sum_k ((2k-1)!!)^2 / (k! (8x)^k)`, truncated at its smallest term
/// (which is ~e^-2x, i.e. < 1e-21 relative for x >= 25).
pub fn i0_scaled_asymptotic(x: f64) -> f64 {
    let x = x.abs();
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    loop {
        let next = term * (2.0 * k - 1.0) * (2.0 * k - 1.0) / (k * 8.0 * x);
        if next >= term || next < sum * 1e-17 {
            break;
        }
        term = next;
        sum += term;
        k += 1.0;
    }
    sum / (2.0 * PI * x).sqrt()
}

/// `e^-|x| I0(x)`, the reference for the crate's `i0_scaled`.
pub fn i0_scaled(x: f64) -> f64 {
    if x.abs() < I0_SERIES_LIMIT {
        i0_scaled_series(x)
    } else {
        i0_scaled_asymptotic(x)
    }
}

/// d'Eon's longitudinal lobe `exp(-si so / v) I0(ci co / v) / (2 v sinh(1/v))`, written
/// in terms of the angles (theta_i, theta_o in [-pi/2, pi/2]) so that it is stable for v
/// from 1e-6 to 1e3. Normalised: its integral against cos(theta_i) d theta_i is 1.
pub fn mp(theta_i: f64, theta_o: f64, v: f64) -> f64 {
    let x = theta_i.cos().max(0.0) * theta_o.cos().max(0.0) / v;
    let half = 0.5 * (theta_i + theta_o);
    let one_minus_cos = 2.0 * half.sin() * half.sin();
    (-one_minus_cos / v).exp() * i0_scaled(x) / (v * -(-2.0 / v).exp_m1())
}

/// The normalised logistic on [-pi, pi]: `L(x, s) / (C(pi) - C(-pi))`,
/// with `C(pi) - C(-pi) = tanh(pi / 2s)`.
pub fn trimmed_logistic(x: f64, s: f64) -> f64 {
    let e = (-x.abs() / s).exp();
    e / (s * (1.0 + e) * (1.0 + e)) / (PI / (2.0 * s)).tanh()
}

/// Wraps an angle into [-pi, pi].
pub fn wrap_pi(x: f64) -> f64 {
    x - 2.0 * PI * (x / (2.0 * PI)).round()
}

/// sin(theta), cos(theta), theta and phi of a direction (sin clamped to [-1, 1]).
pub fn angles(w: [f64; 3]) -> (f64, f64, f64, f64) {
    let s = w[0].clamp(-1.0, 1.0);
    let c = ((1.0 - s) * (1.0 + s)).sqrt();
    (s, c, s.atan2(c), w[2].atan2(w[1]))
}

/// Folds an angle in [-pi, pi] into [-pi/2, pi/2] keeping its sine; its cosine becomes
/// |cos|, which is what the tilted lobes use.
pub fn fold_theta(t: f64) -> f64 {
    if t > 0.5 * PI {
        PI - t
    } else if t < -0.5 * PI {
        -PI - t
    } else {
        t
    }
}

/// Unpolarised dielectric Fresnel reflectance from n = 1 into `eta` at incident cosine `c`,
/// returned with its complement `(F, 1 - F)`, the complement computed without cancellation.
pub fn fresnel(c: f64, eta: f64) -> (f64, f64) {
    let c = c.clamp(0.0, 1.0);
    let sin_t = ((1.0 - c) * (1.0 + c)).sqrt() / eta;
    let cos_t = ((1.0 - sin_t) * (1.0 + sin_t)).sqrt();
    let a = eta * c + cos_t;
    let b = c + eta * cos_t;
    let r_par = (eta * c - cos_t) / a;
    let r_perp = (c - eta * cos_t) / b;
    let f = 0.5 * (r_par * r_par + r_perp * r_perp);
    let t = 2.0 * eta * c * cos_t * (1.0 / (a * a) + 1.0 / (b * b));
    (f, t)
}

/// Lobe positions for quadrature: `(centre, width)` pairs.
pub type Centres = Vec<(f64, f64)>;

/// The f64 reference model for one set of parameters.
#[derive(Clone, Debug)]
pub struct RefHair {
    pub sigma_a: [f64; 3],
    pub eta: f64,
    /// Cuticle tilt in degrees.
    pub alpha_deg: f64,
    /// Lobe variances [R, TT, TRT, residual].
    pub v: [f64; 4],
    /// Azimuthal logistic scale.
    pub s: f64,
}

/// Everything about (h, wo) that does not depend on wi.
#[derive(Clone, Debug)]
pub struct Geometry {
    pub theta_o: f64,
    pub phi_o: f64,
    pub gamma_o: f64,
    pub gamma_t: f64,
    /// Attenuation A_p per channel, p = 0..=3.
    pub a: [[f64; 3]; 4],
    /// Lobe selection weights w_p (sum 1).
    pub w: [f64; 4],
}

/// Reference value of f (RGB, pbrt convention: divided by |wi.z|) and the solid-angle pdf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefEval {
    pub f: [f64; 3],
    pub pdf: f64,
}

impl RefHair {
    pub fn new(sigma_a: [f64; 3], eta: f64, beta_m: f64, beta_n: f64, alpha_deg: f64) -> Self {
        RefHair {
            sigma_a,
            eta,
            alpha_deg,
            v: lobe_variances(beta_m),
            s: azimuthal_scale(beta_n),
        }
    }

    /// The (folded) tilted outgoing angle used by lobe p (p = 3: untilted).
    pub fn theta_o_lobe(&self, theta_o: f64, p: usize) -> f64 {
        let a = self.alpha_deg.to_radians();
        let shift = match p {
            0 => -2.0 * a,
            1 => a,
            2 => 4.0 * a,
            _ => 0.0,
        };
        fold_theta(theta_o + shift)
    }

    /// Azimuthal centre Phi(p) = 2 p gamma_t - 2 gamma_o + p pi of lobe p (relative to phi_o).
    pub fn phi_lobe(g: &Geometry, p: usize) -> f64 {
        let p = p as f64;
        2.0 * p * g.gamma_t - 2.0 * g.gamma_o + p * PI
    }

    /// Attenuations, lobe weights and angles for (h, wo).
    pub fn geometry(&self, h: f64, wo: [f64; 3]) -> Geometry {
        let h = h.clamp(-1.0, 1.0);
        let (sin_to, cos_to, theta_o, phi_o) = angles(wo);
        let eta = self.eta;
        let sin_gt = (h * cos_to / (eta * eta - sin_to * sin_to).sqrt()).clamp(-1.0, 1.0);
        let gamma_t = sin_gt.asin();
        let cos_gt = ((1.0 - sin_gt) * (1.0 + sin_gt)).sqrt();
        let gamma_o = h.asin();
        let sin_tt = sin_to / eta;
        let cos_tt = ((1.0 - sin_tt) * (1.0 + sin_tt)).sqrt();
        let len = 2.0 * cos_gt / cos_tt;
        let (f, tr) = fresnel(cos_to * ((1.0 - h) * (1.0 + h)).sqrt(), eta);
        let mut a = [[0.0; 3]; 4];
        for c in 0..3 {
            let tau = self.sigma_a[c] * len;
            let t = (-tau).exp();
            let one_minus_t = -(-tau).exp_m1();
            a[0][c] = f;
            a[1][c] = tr * tr * t;
            a[2][c] = a[1][c] * t * f;
            let denom = one_minus_t + t * tr;
            a[3][c] = if denom > 0.0 {
                a[2][c] * t * f / denom
            } else {
                0.0
            };
        }
        let mean: Vec<f64> = a.iter().map(|ap| (ap[0] + ap[1] + ap[2]) / 3.0).collect();
        let total: f64 = mean.iter().sum();
        let w = [
            mean[0] / total,
            mean[1] / total,
            mean[2] / total,
            mean[3] / total,
        ];
        Geometry {
            theta_o,
            phi_o,
            gamma_o,
            gamma_t,
            a,
            w,
        }
    }

    /// Per-lobe terms at wi: `(Mp * Np)` of lobes 0..=2 and `Mp / 2pi` of the residual,
    /// i.e. the lobe densities before the attenuation or weight is applied.
    pub fn lobe_densities(&self, g: &Geometry, wi: [f64; 3]) -> [f64; 4] {
        let phi = angles(wi).3 - g.phi_o;
        self.lobe_densities_dphi(g, wi, phi)
    }

    /// [`RefHair::lobe_densities`] with the azimuth difference phi_i - phi_o given
    /// explicitly (it is undefined for a direction exactly along the tangent).
    pub fn lobe_densities_dphi(&self, g: &Geometry, wi: [f64; 3], phi: f64) -> [f64; 4] {
        let theta_i = angles(wi).2;
        let mut d = [0.0; 4];
        for (p, dp) in d.iter_mut().enumerate().take(3) {
            let m = mp(theta_i, self.theta_o_lobe(g.theta_o, p), self.v[p]);
            let n = trimmed_logistic(wrap_pi(phi - Self::phi_lobe(g, p)), self.s);
            *dp = m * n;
        }
        d[3] = mp(theta_i, g.theta_o, self.v[3]) / (2.0 * PI);
        d
    }

    /// f (divided by |wi.z| unless wi.z == 0) and the solid-angle sampling pdf.
    pub fn eval(&self, h: f64, wo: [f64; 3], wi: [f64; 3]) -> RefEval {
        let g = self.geometry(h, wo);
        self.eval_with(&g, wi)
    }

    /// [`RefHair::eval`] with the wi-independent part precomputed.
    pub fn eval_with(&self, g: &Geometry, wi: [f64; 3]) -> RefEval {
        self.eval_dphi(g, wi, angles(wi).3 - g.phi_o)
    }

    /// [`RefHair::eval_with`] with the azimuth difference phi_i - phi_o given explicitly.
    pub fn eval_dphi(&self, g: &Geometry, wi: [f64; 3], phi: f64) -> RefEval {
        let d = self.lobe_densities_dphi(g, wi, phi);
        let mut f = [0.0; 3];
        let mut pdf = 0.0;
        for p in 0..4 {
            for c in 0..3 {
                f[c] += d[p] * g.a[p][c];
            }
            pdf += d[p] * g.w[p];
        }
        if wi[2] != 0.0 {
            for fc in &mut f {
                *fc /= wi[2].abs();
            }
        }
        RefEval { f, pdf }
    }

    /// Where the lobes sit, for placing quadrature nodes: `(theta centres, phi centres)`,
    /// each `(centre, width)`; theta in [-pi/2, pi/2], phi absolute (wrapped to [-pi, pi]).
    pub fn lobe_centres(&self, h: f64, wo: [f64; 3]) -> (Centres, Centres) {
        let g = self.geometry(h, wo);
        let thetas = (0..4)
            .map(|p| (-self.theta_o_lobe(g.theta_o, p), self.v[p].sqrt()))
            .collect();
        let phis = (0..3)
            .map(|p| (wrap_pi(g.phi_o + Self::phi_lobe(&g, p)), self.s))
            .collect();
        (thetas, phis)
    }
}
