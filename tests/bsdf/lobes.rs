//! Geometry of the lobes: with low roughness the peaks of the R and TT lobes sit where
//! the model's geometry puts them (R: phi_i - phi_o = -2 asin(h), theta_i = -theta_o +
//! 2 alpha; TT: phi_i - phi_o = 2 gamma_t - 2 gamma_o + pi, theta_i = -theta_o - alpha),
//! and the worked example of docs/conventions.md holds.

use crate::common::reference::{RefHair, wrap_pi};
use crate::common::sphere::{dir, dot};
use crate::common::{Timer, bsdf, d3, dir_deg, par_map, params, v3};
use hairtrace::HairBsdf;
use std::f64::consts::PI;

/// Coarse search steps (theta, phi), then the fine step of the refinement around the
/// coarse maximum. The coarse steps are below the narrowest lobe's half-width at beta
/// = 0.02 (theta: sqrt(v/4) ~ 0.0074 rad; phi: logistic s ~ 0.0036 rad, whose value
/// half a coarse step away is still ~90% of the peak), so the coarse maximum is on the
/// right lobe; the fine step bounds the error of the located peak.
const COARSE: (f64, f64) = (0.01, 0.005);
const FINE: f64 = 2.5e-4;
const WINDOW: f64 = 0.015;

/// The direction maximising f |wi.z| (channel 0) over the sphere: (theta_i, phi_i).
fn peak(b: &HairBsdf, h: f32, wo: [f64; 3]) -> (f64, f64) {
    let wo32 = v3(wo);
    let value = |t: f64, p: f64| {
        let wi = v3(dir(t, p));
        b.eval(h, wo32, wi).f.x as f64 * (wi.z as f64).abs()
    };
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    let nt = (PI / COARSE.0).round() as usize;
    let np = (2.0 * PI / COARSE.1).round() as usize;
    for i in 0..=nt {
        let t = -0.5 * PI + PI * i as f64 / nt as f64;
        for j in 0..np {
            let p = -PI + 2.0 * PI * j as f64 / np as f64;
            let v = value(t, p);
            if v > best.0 {
                best = (v, t, p);
            }
        }
    }
    let (_, t0, p0) = best;
    let n = (WINDOW / FINE).round() as i64;
    for i in -n..=n {
        let t = (t0 + i as f64 * FINE).clamp(-0.5 * PI, 0.5 * PI);
        for j in -n..=n {
            let p = p0 + j as f64 * FINE;
            let v = value(t, p);
            if v > best.0 {
                best = (v, t, p);
            }
        }
    }
    (best.1, wrap_pi(best.2))
}

#[derive(Clone, Copy, Debug)]
struct Case {
    beta: f32,
    alpha: f32,
    theta_o_deg: f64,
    phi_o_deg: f64,
    h: f32,
    /// R alone (sigma_a huge removes every transmitted lobe) or TT (sigma_a = 0, where
    /// TT carries (1 - F)^2 ~ 90% of the energy and is the highest peak).
    tt: bool,
}

/// theta_o stays within 60 degrees: beyond, with alpha = 5 the TRT lobe's tilted angle
/// theta_o + 4 alpha reaches the pole, where its density per solid angle grows like 1/v
/// (instead of 1/sqrt(v)) and outshines TT, so TT would no longer be the global maximum.
fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    let mut k = 0;
    for tt in [false, true] {
        for alpha in [0.0, 2.0, 5.0] {
            for (theta_o_deg, phi_o_deg) in
                [(-50.0, 30.0), (0.0, 90.0), (30.0, -100.0), (60.0, 170.0)]
            {
                for h in [-0.8, -0.3, 0.5, 0.9] {
                    out.push(Case {
                        beta: [0.02, 0.03, 0.05][k % 3],
                        alpha,
                        theta_o_deg,
                        phi_o_deg,
                        h,
                        tt,
                    });
                    k += 1;
                }
            }
        }
    }
    out
}

/// The located peak of every case is where the geometry says: azimuth within the fine
/// step (the logistic is symmetric, so its maximum is exactly at its centre), theta
/// within the fine step plus the lobe's own asymmetry (the mode of d'Eon's lobe sits at
/// sin(theta_i + theta_o') ~ v tan(theta_i) / 2 from the mirror angle: at most ~2e-3 rad
/// at beta = 0.05 and 75 degrees). gamma_t comes from the modified index
/// sin(gamma_t) = h cos(theta_o) / sqrt(eta^2 - sin^2(theta_o)).
#[test]
fn r_and_tt_peaks_are_where_the_geometry_puts_them() {
    let _t = Timer::start("r_and_tt_peaks_are_where_the_geometry_puts_them");
    let cs = cases();
    let found = par_map(&cs, |c| {
        let sigma = if c.tt { [0.0; 3] } else { [1e6; 3] };
        let p = params(sigma, 1.55, c.beta, c.beta, c.alpha);
        peak(&bsdf(&p), c.h, dir_deg(c.theta_o_deg, c.phi_o_deg))
    });
    let (mut worst_t, mut worst_p) = (0.0f64, 0.0f64);
    for (c, &(ti, pi)) in cs.iter().zip(&found) {
        let wo = d3(v3(dir_deg(c.theta_o_deg, c.phi_o_deg)));
        let (to, po) = (wo[0].asin(), wo[2].atan2(wo[1]));
        let a = (c.alpha as f64).to_radians();
        let h = c.h as f64;
        let (want_t, want_dphi) = if c.tt {
            let (sin_to, cos_to) = (to.sin(), to.cos());
            let gamma_t = (h * cos_to / (1.55f64 * 1.55 - sin_to * sin_to).sqrt()).asin();
            (-to - a, 2.0 * gamma_t - 2.0 * h.asin() + PI)
        } else {
            (-to + 2.0 * a, -2.0 * h.asin())
        };
        let v = crate::common::reference::longitudinal_variance(c.beta as f64)
            / if c.tt { 4.0 } else { 1.0 };
        let dt = (ti - want_t).abs();
        let dp = wrap_pi(pi - po - want_dphi).abs();
        let t_tol = 1.5 * FINE + 0.6 * v * want_t.tan().abs();
        println!(
            "{} {c:?}: peak theta_i {:.4} (want {:.4}, tol {:.1e}), dphi {:.4} (want {:.4})",
            if c.tt { "TT" } else { "R " },
            ti,
            want_t,
            t_tol,
            wrap_pi(pi - po),
            wrap_pi(want_dphi)
        );
        assert!(
            dt <= t_tol && dp <= 1.5 * FINE,
            "{c:?}: peak at (theta_i {ti}, phi_i - phi_o {}), want ({want_t}, {})",
            wrap_pi(pi - po),
            wrap_pi(want_dphi)
        );
        worst_t = worst_t.max(dt);
        worst_p = worst_p.max(dp);
    }
    println!(
        "{} lobe peaks: worst |theta_i error| {worst_t:.2e} rad, worst |phi error| {worst_p:.2e} rad",
        cs.len()
    );
}

/// The worked example of docs/conventions.md: fiber along +x, viewer looking along -z (so
/// wo = +z), ray passing at y = +0.5 (h = +0.5). The strongest R direction is the true
/// mirror direction of the tube surface, (0, 0.866, 0.5): light from above (+y). With
/// alpha = 2 degrees the peak lifts to theta_i = 4 degrees along the tangent. Within one
/// degree, as the brief asks (the search grid makes it ~0.02 degree).
#[test]
fn design_worked_example_r_peak_is_the_mirror_direction() {
    for alpha in [0.0f32, 2.0] {
        let p = params([1e6; 3], 1.55, 0.03, 0.03, alpha);
        let (t, ph) = peak(&bsdf(&p), 0.5, [0.0, 0.0, 1.0]);
        let got = dir(t, ph);
        let a = (2.0 * alpha as f64).to_radians();
        let want = [a.sin(), a.cos() * 0.75f64.sqrt(), a.cos() * 0.5];
        let angle = dot(got, want).clamp(-1.0, 1.0).acos().to_degrees();
        println!(
            "worked example, alpha = {alpha}: R peak wi = ({:.4}, {:.4}, {:.4}), want ({:.4}, {:.4}, {:.4}), {angle:.3} degrees apart",
            got[0], got[1], got[2], want[0], want[1], want[2]
        );
        assert!(
            angle < 1.0,
            "R peak {got:?} is {angle} degrees from {want:?}"
        );
        assert!(got[1] > 0.8, "light must come from above (+y): {got:?}");
    }
}

/// The same geometry from the f64 reference (its Np centre formula is the one the
/// tests above check the crate against), to keep the two in step: Phi(0) = -2 gamma_o.
#[test]
fn reference_r_centre_is_minus_two_gamma_o() {
    let r = RefHair::new([0.0; 3], 1.55, 0.3, 0.3, 2.0);
    for h in [-0.9, -0.2, 0.0, 0.5, 1.0] {
        let g = r.geometry(h, [0.0, 0.0, 1.0]);
        assert!((RefHair::phi_lobe(&g, 0) + 2.0 * f64::asin(h)).abs() < 1e-15);
    }
}
