//! pbrt-v3's hair evaluation redone in f32 with libm, as a yardstick of what plain float
//! arithmetic achieves: the accuracy tests require the crate to be at least this close to
//! the f64 reference. Written from the model's formulas in pbrt-v3's form, not copied:
//! the same steps in the same precision (cos theta as sqrt(1 - sin^2), phi from two atan2,
//! d'Eon's Mp as exp(log I0(a) - b - 1/v + ln(1/(2v)) + ln 2) for v <= 0.1 with pbrt's
//! truncated series and one-term asymptotic log I0, otherwise e^-b I0(a) / (2 v sinh(1/v)),
//! Fresnel by the textbook amplitudes, a logistic trimmed to [-pi, pi]). The pdf weights
//! the lobes by their mean attenuation, as the crate does (pbrt-v3 uses luminance), so that
//! its value is comparable.

use hairtrace::HairParams;
use std::f32::consts::PI;

/// pbrt-v3's per-material constants.
pub struct PbrtHair {
    sigma_a: [f32; 3],
    eta: f32,
    /// Lobe variances R, TT, TRT, residual.
    v: [f32; 4],
    s: f32,
    /// sin and cos of alpha, 2 alpha and 4 alpha, by the double-angle recurrence.
    sin_k: [f32; 3],
    cos_k: [f32; 3],
}

fn i0(x: f32) -> f32 {
    // sum over i < 10 of (x^2 / 4)^i / (i!)^2, in pbrt's integer bookkeeping.
    let mut sum = 0.0f32;
    let mut x_pow = 1.0f32;
    let mut fact: i64 = 1;
    let mut four: i64 = 1;
    for i in 0..10i64 {
        if i > 1 {
            fact *= i;
        }
        sum += x_pow / (four * fact * fact) as f32;
        x_pow *= x * x;
        four *= 4;
    }
    sum
}

fn log_i0(x: f32) -> f32 {
    if x > 12.0 {
        // The constant 0.5 is a double in pbrt, so this line is evaluated in double.
        let t = -(2.0 * PI).ln() + (1.0 / x).ln() + 1.0 / (8.0 * x);
        (x as f64 + 0.5 * t as f64) as f32
    } else {
        i0(x).ln()
    }
}

// pbrt writes ln 2 as 0.6931, 4.7e-5 relative off in every lobe with v <= 0.1: that is
// part of the float code measured here.
#[allow(clippy::approx_constant)]
fn mp(cos_ti: f32, cos_to: f32, sin_ti: f32, sin_to: f32, v: f32) -> f32 {
    let a = cos_ti * cos_to / v;
    let b = sin_ti * sin_to / v;
    if (v as f64) <= 0.1 {
        (log_i0(a) - b - 1.0 / v + 0.6931 + (1.0 / (2.0 * v)).ln()).exp()
    } else {
        ((-b).exp() * i0(a)) / ((1.0 / v).sinh() * 2.0 * v)
    }
}

fn fresnel(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(-1.0, 1.0);
    // Exactly grazing counts as leaving the medium, where total reflection gives 1.
    let (eta_i, eta_t, cos_i) = if cos_i > 0.0 {
        (1.0, eta, cos_i)
    } else {
        (eta, 1.0, cos_i.abs())
    };
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let sin_t = eta_i / eta_t * sin_i;
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
    let par = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    let perp = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    0.5 * (par * par + perp * perp)
}

fn logistic(x: f32, s: f32) -> f32 {
    let e = (-x.abs() / s).exp();
    e / (s * (1.0 + e) * (1.0 + e))
}

fn logistic_cdf(x: f32, s: f32) -> f32 {
    1.0 / (1.0 + (-x / s).exp())
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

impl PbrtHair {
    pub fn new(p: &HairParams) -> Self {
        let bm = p.beta_m;
        let r = 0.726 * bm + 0.812 * bm * bm + 3.7 * bm.powi(20);
        let v0 = r * r;
        let bn = p.beta_n;
        let sqrt_pi_over_8 = 0.626_657_07f32;
        let s = sqrt_pi_over_8 * (0.265 * bn + 1.194 * bn * bn + 5.372 * bn.powi(22));
        let mut sin_k = [p.alpha.to_radians().sin(), 0.0, 0.0];
        let mut cos_k = [safe_sqrt(1.0 - sin_k[0] * sin_k[0]), 0.0, 0.0];
        for i in 1..3 {
            sin_k[i] = 2.0 * cos_k[i - 1] * sin_k[i - 1];
            cos_k[i] = cos_k[i - 1] * cos_k[i - 1] - sin_k[i - 1] * sin_k[i - 1];
        }
        Self {
            sigma_a: p.sigma_a,
            eta: p.eta,
            v: [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0],
            s,
            sin_k,
            cos_k,
        }
    }

    /// f (RGB, divided by |wi.z| when it is not 0) and pdf, as pbrt-v3's `f` computes them.
    pub fn eval(&self, h: f32, wo: [f32; 3], wi: [f32; 3]) -> ([f32; 3], f32) {
        let eta = self.eta;
        let sin_to = wo[0];
        let cos_to = safe_sqrt(1.0 - sin_to * sin_to);
        let phi_o = wo[2].atan2(wo[1]);
        let sin_ti = wi[0];
        let cos_ti = safe_sqrt(1.0 - sin_ti * sin_ti);
        let phi_i = wi[2].atan2(wi[1]);

        let sin_tt = sin_to / eta;
        let cos_tt = safe_sqrt(1.0 - sin_tt * sin_tt);
        let etap = (eta * eta - sin_to * sin_to).sqrt() / cos_to;
        let sin_gt = h / etap;
        let cos_gt = safe_sqrt(1.0 - sin_gt * sin_gt);
        let gamma_t = sin_gt.clamp(-1.0, 1.0).asin();
        let gamma_o = h.clamp(-1.0, 1.0).asin();
        let t = self
            .sigma_a
            .map(|sa| (-(sa * (2.0 * cos_gt / cos_tt))).exp());

        // Attenuations R, TT, TRT and the residual sum.
        let fr = fresnel(cos_to * safe_sqrt(1.0 - h * h), eta);
        let mut ap = [[0.0f32; 3]; 4];
        for c in 0..3 {
            ap[0][c] = fr;
            ap[1][c] = (1.0 - fr) * (1.0 - fr) * t[c];
            ap[2][c] = ap[1][c] * t[c] * fr;
            ap[3][c] = ap[2][c] * fr * t[c] / (1.0 - t[c] * fr);
        }

        let phi = phi_i - phi_o;
        let (sk, ck) = (self.sin_k, self.cos_k);
        let mut d = [0.0f32; 4];
        for (p, dp) in d.iter_mut().enumerate() {
            let (sin_po, cos_po) = match p {
                0 => (
                    sin_to * ck[1] - cos_to * sk[1],
                    cos_to * ck[1] + sin_to * sk[1],
                ),
                1 => (
                    sin_to * ck[0] + cos_to * sk[0],
                    cos_to * ck[0] - sin_to * sk[0],
                ),
                2 => (
                    sin_to * ck[2] + cos_to * sk[2],
                    cos_to * ck[2] - sin_to * sk[2],
                ),
                _ => (sin_to, cos_to),
            };
            let m = mp(cos_ti, cos_po.abs(), sin_ti, sin_po, self.v[p]);
            *dp = if p < 3 {
                let centre = 2.0 * p as f32 * gamma_t - 2.0 * gamma_o + p as f32 * PI;
                let mut dphi = phi - centre;
                while dphi > PI {
                    dphi -= 2.0 * PI;
                }
                while dphi < -PI {
                    dphi += 2.0 * PI;
                }
                let trim = logistic_cdf(PI, self.s) - logistic_cdf(-PI, self.s);
                m * logistic(dphi, self.s) / trim
            } else {
                m / (2.0 * PI)
            };
        }
        let mean: [f32; 4] = ap.map(|a| (a[0] + a[1] + a[2]) / 3.0);
        let total: f32 = mean.iter().sum();
        let mut f = [0.0f32; 3];
        let mut pdf = 0.0f32;
        for p in 0..4 {
            for c in 0..3 {
                f[c] += d[p] * ap[p][c];
            }
            pdf += d[p] * mean[p] / total;
        }
        let cos_wi = wi[2].abs();
        if cos_wi > 0.0 {
            f = f.map(|x| x / cos_wi);
        }
        (f, pdf)
    }
}
