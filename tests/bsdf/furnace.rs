//! Furnace tests: with sigma_a = 0 the fibre absorbs nothing, so the scattered fraction
//! integral of f |wi.z| over the sphere is exactly 1 for every (h, wo) and roughness;
//! with absorption it is sum_p A_p, strictly between 0 and 1.

use crate::common::quad::{SphereRule, gauss_legendre};
use crate::common::reference::RefHair;
use crate::common::sphere::uniform_sphere;
use crate::common::{Timer, bsdf, d3, dir_deg, par_map, params, reference, rng, v3};
use hairtrace::{HairBsdf, Lobes};
use rand::Rng;
use std::f64::consts::PI;

const BETAS: [f32; 5] = [0.1, 0.3, 0.5, 0.7, 0.9];
/// (theta_o, phi_o) in degrees: below, on and above the normal plane, near the tangent.
const WO_DEG: [(f64, f64); 4] = [(-60.0, 10.0), (0.0, 100.0), (30.0, -135.0), (80.0, 170.0)];
const HS: [f32; 5] = [-0.9, -0.3, 0.0, 0.5, 0.99];

/// Integral over the sphere of (f |wi.z| per channel, pdf) of the crate's BSDF (the
/// lobes `lobes` of it), by the
/// product Gauss–Legendre rule refined around the lobe centres. On the f64 reference the
/// same rule reproduces 1 within 2e-9 at every configuration used here (see
/// `reference_furnace_quadrature_is_exact`), so any deviation is the crate's.
pub(crate) fn crate_integrals(
    b: &HairBsdf,
    lobes: Lobes,
    r: &RefHair,
    h: f32,
    wo: [f64; 3],
) -> ([f64; 3], f64) {
    let point = b.at_lobes(h, v3(wo), lobes);
    let [r0, g0, b0, pdf] = rule_for(r, h, wo).integrate_n(|wi| {
        let wi32 = v3(wi);
        let e = point.eval(wi32);
        let c = (wi32.z as f64).abs();
        [
            e.f.x as f64 * c,
            e.f.y as f64 * c,
            e.f.z as f64 * c,
            e.pdf as f64,
        ]
    });
    ([r0, g0, b0], pdf)
}

fn rule_for(r: &RefHair, h: f32, wo: [f64; 3]) -> SphereRule {
    let (tc, pc) = r.lobe_centres(h as f64, d3(v3(wo)));
    SphereRule::new(&tc, &pc, &[], &[], 0.3, &gauss_legendre(6))
}

/// White furnace by quadrature: sigma_a = 0, all 25 (beta_m, beta_n) pairs, 4 wo, 5 h,
/// alpha = 2 degrees: the integral of f |wi.z| is 1 within 2e-3 per channel, and so is
/// the integral of the pdf. 2e-3 is the brief's bound; a correct f32 implementation
/// lands within ~1e-5 (f32 rounding summed over smooth lobes), a wrong attenuation,
/// normalisation or a dropped lobe misses by far more than 2e-3.
#[test]
fn white_furnace_quadrature() {
    let _t = Timer::start("white_furnace_quadrature");
    let mut configs = Vec::new();
    for bm in BETAS {
        for bn in BETAS {
            for wo in WO_DEG {
                for h in HS {
                    configs.push((bm, bn, wo, h));
                }
            }
        }
    }
    let results = par_map(&configs, |&(bm, bn, (to, po), h)| {
        let p = params([0.0; 3], 1.55, bm, bn, 2.0);
        let wo = dir_deg(to, po);
        let (f, pdf) = crate_integrals(&bsdf(&p), Lobes::All, &reference(&p), h, wo);
        let dev = f
            .iter()
            .map(|x| (x - 1.0).abs())
            .fold((pdf - 1.0).abs(), f64::max);
        (dev, f, pdf)
    });
    let mut worst = (0.0, 0);
    for (i, (dev, f, pdf)) in results.iter().enumerate() {
        assert!(
            *dev < 2e-3,
            "furnace off at {:?}: f integral {f:?}, pdf integral {pdf}",
            configs[i]
        );
        if *dev > worst.0 {
            worst = (*dev, i);
        }
    }
    println!(
        "white furnace ({} configs): worst |integral - 1| = {:.3e} at (beta_m, beta_n, wo deg, h) = {:?}",
        configs.len(),
        worst.0,
        configs[worst.1]
    );
}

/// The quadrature rule is exact enough: on the f64 reference (whose integral is exactly
/// 1 by construction) it gives 1 within 1e-8 at the hardest configurations (narrow lobes
/// beta = 0.1 and the widest azimuthal logistic, beta_n = 0.9, which wraps around).
#[test]
fn reference_furnace_quadrature_is_exact() {
    let mut worst = 0.0f64;
    for (bm, bn) in [(0.1, 0.1), (0.1, 0.9), (0.9, 0.1)] {
        for (to, po) in WO_DEG {
            for h in [-0.9, 0.99] {
                let p = params([0.0; 3], 1.55, bm, bn, 2.0);
                let r = reference(&p);
                let wo = d3(v3(dir_deg(to, po)));
                let g = r.geometry(h as f64, wo);
                let i = rule_for(&r, h, wo).integrate(|wi| r.eval_with(&g, wi).f[0] * wi[2].abs());
                worst = worst.max((i - 1.0).abs());
            }
        }
    }
    println!("reference furnace by the same quadrature: worst |integral - 1| = {worst:.3e}");
    assert!(worst < 1e-8, "{worst}");
}

/// Brown hair absorbs: the furnace is strictly inside (0, 1) per channel and equals
/// sum_p A_p of the reference (each lobe is normalised), within the same 2e-3.
#[test]
fn absorbing_furnace_quadrature() {
    let mut worst = 0.0f64;
    for (bm, bn) in [(0.1, 0.3), (0.5, 0.5), (0.9, 0.9)] {
        for (to, po) in WO_DEG {
            for h in [-0.9, 0.0, 0.5] {
                let p = params(crate::common::brown(), 1.55, bm, bn, 2.0);
                let r = reference(&p);
                let wo = dir_deg(to, po);
                let (f, pdf) = crate_integrals(&bsdf(&p), Lobes::All, &r, h, wo);
                let g = r.geometry(h as f64, d3(v3(wo)));
                for (c, &got) in f.iter().enumerate() {
                    let want: f64 = (0..4).map(|q| g.a[q][c]).sum();
                    assert!(
                        got > 0.0 && got < 1.0 && (got - want).abs() < 2e-3,
                        "channel {c} at ({bm}, {bn}, {to}, {po}, {h}): {} want {want}",
                        got
                    );
                    worst = worst.max((got - want).abs());
                }
                assert!((pdf - 1.0).abs() < 2e-3, "pdf integral {pdf}");
            }
        }
    }
    println!("brown furnace: worst |integral - sum A_p| = {worst:.3e}");
}

/// One Monte Carlo furnace configuration: (beta_m, beta_n, sigma_a, theta_o, phi_o, h).
type McConfig = (f32, f32, [f32; 3], f64, f64, f32);

/// Monte Carlo furnaces: uniform sphere sampling (4 pi f |z|) and importance sampling
/// (f |z| / pdf, with samples the sampler refuses counted as 0) both estimate the same
/// integral as the quadrature. The bound is 4 standard errors + 1e-4 (a 4-sigma event
/// has probability ~6e-5 per estimate; the 1e-4 absorbs f32 rounding where the
/// estimator has no variance, as importance sampling with sigma_a = 0).
#[test]
fn monte_carlo_furnace() {
    let _t = Timer::start("monte_carlo_furnace");
    let configs: [McConfig; 6] = [
        (0.1, 0.1, [0.0; 3], 0.0, 100.0, 0.5),
        (0.3, 0.7, [0.0; 3], -60.0, 10.0, -0.9),
        (0.9, 0.3, [0.0; 3], 80.0, 170.0, 0.99),
        (0.1, 0.3, crate::common::brown(), 30.0, -135.0, -0.3),
        (0.5, 0.5, crate::common::brown(), 0.0, 100.0, 0.0),
        (0.3, 0.1, [0.2, 3.0, 0.0], -60.0, 10.0, 0.5),
    ];
    // Worst |mean - quadrature| as a fraction of the allowed 4 se + 1e-4.
    let mut worst_ratio = 0.0f64;
    for (k, &(bm, bn, sa, to, po, h)) in configs.iter().enumerate() {
        let p = params(sa, 1.55, bm, bn, 2.0);
        let b = bsdf(&p);
        let wo = dir_deg(to, po);
        let (want, _) = crate_integrals(&b, Lobes::All, &reference(&p), h, wo);
        let wo32 = v3(wo);
        let mut g = rng(1000 + k as u64);
        // Uniform sphere sampling.
        let n_uni = 400_000;
        let mut s1 = [0.0; 3];
        let mut s2 = [0.0; 3];
        for _ in 0..n_uni {
            let wi = v3(uniform_sphere(&mut g));
            let e = b.eval(h, wo32, wi);
            for c in 0..3 {
                let x = 4.0 * PI * e.f[c] as f64 * (wi.z as f64).abs();
                s1[c] += x;
                s2[c] += x * x;
            }
        }
        // Importance sampling.
        let n_is = 200_000;
        let mut t1 = [0.0; 3];
        let mut t2 = [0.0; 3];
        for _ in 0..n_is {
            let u = [g.random::<f32>(), g.random::<f32>(), g.random::<f32>()];
            if let Some(s) = b.sample(h, wo32, u) {
                for c in 0..3 {
                    let x = if s.pdf > 0.0 {
                        s.f[c] as f64 * (s.wi.z as f64).abs() / s.pdf as f64
                    } else {
                        0.0
                    };
                    t1[c] += x;
                    t2[c] += x * x;
                }
            }
        }
        for c in 0..3 {
            for (name, sum, sum2, n) in [
                ("uniform", s1[c], s2[c], n_uni as f64),
                ("importance", t1[c], t2[c], n_is as f64),
            ] {
                let mean = sum / n;
                let se = ((sum2 / n - mean * mean).max(0.0) / n).sqrt();
                println!(
                    "MC furnace config {k} channel {c} {name}: {mean:.6} +- {se:.1e} (quadrature {:.6})",
                    want[c]
                );
                assert!(
                    (mean - want[c]).abs() < 4.0 * se + 1e-4,
                    "{name} estimate {mean} +- {se} vs quadrature {} at config {:?}",
                    want[c],
                    configs[k]
                );
                worst_ratio = worst_ratio.max((mean - want[c]).abs() / (4.0 * se + 1e-4));
            }
        }
    }
    println!("MC furnace: worst |mean - quadrature| = {worst_ratio:.3} of the bound 4 se + 1e-4");
}
