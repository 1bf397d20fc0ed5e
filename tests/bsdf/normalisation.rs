//! Normalisation of the longitudinal lobe and accuracy of the scaled Bessel function.
//!
//! The lobe variances the parameters can produce span v = longitudinal_variance(0.01)/4
//! (~1.3e-5, TT at the smoothest fibre) to 4 * longitudinal_variance(1) (~110, TRT and
//! residual at the roughest); the lobe must integrate to 1 over that whole span and at
//! outgoing angles up to grazing the tangent.

use crate::common::quad::{gauss_legendre, integrate_1d};
use crate::common::reference as r;
use hairtrace::bsdf::{LongitudinalLobe, longitudinal_variance};
use hairtrace::math::bessel::i0_scaled;
use std::f64::consts::FRAC_PI_2;

/// Outgoing angles (degrees) at which the lobes are integrated: both signs, the equator,
/// and 0.1 degree from the tangent, where the lobe is cut by the pole.
const THETA_O_DEG: [f64; 9] = [-89.9, -60.0, -45.0, -10.0, 0.0, 30.0, 45.0, 75.0, 89.9];

/// 80 log-spaced variances over the full reachable range (from the crate's own mapping).
fn variances() -> Vec<f64> {
    let lo = longitudinal_variance(0.01) as f64 / 4.0;
    let hi = 4.0 * longitudinal_variance(1.0) as f64;
    assert!(lo < 1.4e-5 && hi > 100.0, "variance range [{lo}, {hi}]");
    (0..80)
        .map(|k| lo * (hi / lo).powf(k as f64 / 79.0))
        .collect()
}

/// Integral over theta_i in [-pi/2, pi/2] of m(theta_i) cos(theta_i), with 10-point
/// Gauss–Legendre panels refined around the lobe peak at -theta_o (width sqrt(v)) down to
/// sqrt(v)/2: the same rule gives the f64 reference 1 within ~1e-14 (test below), so the
/// quadrature error is negligible against the 1e-4 tolerance.
fn lobe_integral(m: impl Fn(f64) -> f64, theta_o: f64, v: f64) -> f64 {
    let gl = gauss_legendre(10);
    integrate_1d(
        |t| m(t) * t.cos(),
        -FRAC_PI_2,
        FRAC_PI_2,
        &[(-theta_o, v.sqrt())],
        0.1,
        &gl,
    )
}

/// The crate's f32 LongitudinalLobe integrates to 1 within 1e-4 for every variance and
/// outgoing angle. The angles reach the lobe as f32 sines and cosines (as in the BSDF);
/// 1e-4 leaves room for f32 rounding of those inputs (which at v ~ 1e-5 shifts the lobe
/// by up to ~1e-7 / v relative) while catching any normalisation-constant mistake.
#[test]
fn crate_longitudinal_lobe_integrates_to_one() {
    let _t = crate::common::Timer::start("crate_longitudinal_lobe_integrates_to_one");
    let mut worst = (0.0f64, 0.0, 0.0);
    for v in variances() {
        let lobe = LongitudinalLobe::new(v as f32);
        for to_deg in THETA_O_DEG {
            let to = to_deg.to_radians();
            let (so, co) = (to.sin() as f32, to.cos() as f32);
            let i = lobe_integral(
                |t| lobe.eval(t.sin() as f32, t.cos() as f32, so, co) as f64,
                to,
                v,
            );
            assert!(i.is_finite(), "v = {v}, theta_o = {to_deg}: integral {i}");
            if (i - 1.0).abs() > worst.0 {
                worst = ((i - 1.0).abs(), v, to_deg);
            }
        }
    }
    println!(
        "crate lobe: worst |integral - 1| = {:.3e} at v = {:.4e}, theta_o = {} deg",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 < 1e-4, "worst {worst:?}");
}

/// The f64 reference lobe integrates to 1 within 1e-9 (it does to ~1e-14): the reference
/// and the quadrature rule are right, so the test above measures the crate alone.
#[test]
fn reference_longitudinal_lobe_integrates_to_one() {
    let mut worst = 0.0f64;
    for v in variances() {
        for to_deg in THETA_O_DEG {
            let to = to_deg.to_radians();
            let i = lobe_integral(|t| r::mp(t, to, v), to, v);
            worst = worst.max((i - 1.0).abs());
        }
    }
    println!("reference lobe: worst |integral - 1| = {worst:.3e}");
    assert!(worst < 1e-9, "worst {worst}");
}

/// The reference e^-x I0(x) is right: its series and asymptotic branches agree to 1e-13
/// over [15, 60] (where both converge), and it matches tabulated I0 values.
#[test]
fn reference_i0_scaled_is_consistent() {
    let mut worst = 0.0f64;
    for k in 0..4500 {
        let x = 15.0 + k as f64 * 0.01;
        let (a, b) = (r::i0_scaled_series(x), r::i0_scaled_asymptotic(x));
        worst = worst.max((a / b - 1.0).abs());
    }
    println!("reference I0: series vs asymptotic on [15, 60]: {worst:.3e}");
    assert!(worst < 1e-13);
    // I0 from Abramowitz & Stegun table 9.8 / high-precision values.
    for (x, i0) in [
        (0.0, 1.0),
        (1.0, 1.266_065_877_752_008_4),
        (10.0, 2_815.716_628_466_254),
        (50.0, 2.932_553_783_849_336e20),
    ] {
        let got = r::i0_scaled(x) * f64::exp(x);
        assert!((got / i0 - 1.0).abs() < 1e-13, "I0({x}) = {got}, want {i0}");
    }
}

/// The crate's f32 e^-x I0(x) against the f64 reference at exactly the same (f32) x:
/// dense on [0, 20] (the series / polynomial region), log-spaced on [1e-6, 1e5]. 1e-5
/// relative is ~100 f32 ulps, enough for a careful f32 implementation and far below
/// what would move the BSDF.
#[test]
fn crate_i0_scaled_matches_reference() {
    let mut xs: Vec<f32> = (0..=2000).map(|k| k as f32 * 0.01).collect();
    xs.extend((0..=2200).map(|k| (1e-6f64 * 1e11f64.powf(k as f64 / 2200.0)) as f32));
    xs.push(1e5);
    let mut worst = (0.0f64, 0.0f32);
    for x in xs {
        let got = i0_scaled(x) as f64;
        let want = r::i0_scaled(x as f64);
        let rel = (got / want - 1.0).abs();
        assert!(got.is_finite(), "i0_scaled({x}) = {got}");
        if rel > worst.0 || rel.is_nan() {
            worst = (rel, x);
        }
    }
    println!(
        "crate i0_scaled: max relative error {:.3e} at x = {}",
        worst.0, worst.1
    );
    assert!(
        worst.0 < 1e-5,
        "max relative error {} at x = {}",
        worst.0,
        worst.1
    );
}
