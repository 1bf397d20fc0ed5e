//! The renderer's fidelity knobs at one point ([`Lobes`]): lobe culling and the merged
//! lobe of deep bounces sample their own pdf (chi-square), return what they evaluate,
//! keep the energy they promise (quadrature furnaces against the f64 reference's lobe
//! attenuations), and culling at threshold 0 is the whole model bit for bit.

use crate::chi2::{Config, run_all};
use crate::common::sphere::uniform_sphere;
use crate::common::{
    Timer, brown, bsdf, d3, dir_deg, params, random_h, random_params, random_u, reference, rng, v3,
};
use crate::furnace::crate_integrals;
use glam::Vec3;
use hairtrace::{BsdfEval, BsdfSample, HairBsdf, Lobes};

/// Black hair (the preset): R dominates, the residual lobe is tiny.
const BLACK: [f32; 3] = [2.9, 5.1, 10.2];

/// Views (theta_o deg, phi_o deg, h) of the furnace and chi-square tests.
const VIEWS: [(f64, f64, f32); 3] = [(-60.0, 10.0, -0.6), (0.0, 100.0, 0.2), (40.0, -150.0, 0.9)];

/// A random h, wo and sample numbers.
fn random_vertex(g: &mut impl rand::Rng) -> (f32, Vec3, [f32; 3]) {
    (random_h(g), v3(uniform_sphere(g)), random_u(g))
}

fn bits(e: BsdfEval) -> ([u32; 3], u32) {
    (e.f.to_array().map(f32::to_bits), e.pdf.to_bits())
}

fn sample_bits(s: Option<BsdfSample>) -> Option<([u32; 3], [u32; 3], u32)> {
    s.map(|s| {
        (
            s.wi.to_array().map(f32::to_bits),
            s.f.to_array().map(f32::to_bits),
            s.pdf.to_bits(),
        )
    })
}

/// Culling at threshold 0 (and `Lobes::All`) gives exactly the bits of `HairBsdf::at`,
/// eval and sample, over random parameters with absorption extremes, h and directions.
#[test]
fn cull_threshold_zero_is_the_whole_model_bit_for_bit() {
    let mut g = rng(31);
    for _ in 0..200 {
        let b = bsdf(&random_params(&mut g, true));
        for _ in 0..500 {
            let (h, wo, wi, u) = (
                random_h(&mut g),
                v3(uniform_sphere(&mut g)),
                v3(uniform_sphere(&mut g)),
                random_u(&mut g),
            );
            let exact = b.at(h, wo);
            for lobes in [Lobes::All, Lobes::Culled(0.0)] {
                let p = b.at_lobes(h, wo, lobes);
                assert_eq!(bits(p.eval(wi)), bits(exact.eval(wi)), "{lobes:?}");
                assert_eq!(sample_bits(p.sample(u)), sample_bits(exact.sample(u)));
            }
        }
    }
}

/// What a culled or merged point samples, it evaluates: f and pdf of every sample are
/// `eval` at its direction bit for bit (what MIS relies on); samples are unit and finite.
#[test]
fn culled_and_merged_samples_are_their_eval() {
    let mut g = rng(32);
    let mut count = 0;
    for _ in 0..200 {
        let b = bsdf(&random_params(&mut g, true));
        for _ in 0..300 {
            let (h, wo, u) = random_vertex(&mut g);
            for lobes in [Lobes::Culled(0.05), Lobes::Culled(0.5), Lobes::Merged] {
                let p = b.at_lobes(h, wo, lobes);
                let Some(s) = p.sample(u) else { continue };
                count += 1;
                assert_eq!(
                    bits(BsdfEval { f: s.f, pdf: s.pdf }),
                    bits(p.eval(s.wi)),
                    "{lobes:?} at h={h} wo={wo} u={u:?}"
                );
                assert!(
                    s.pdf > 0.0 && s.f.is_finite() && (s.wi.length() - 1.0).abs() < 1e-5,
                    "{s:?}"
                );
            }
        }
    }
    assert!(count > 100_000, "only {count} samples");
}

/// The merged lobe's path weight f |wi.z| / pdf is the point's total attenuation, the
/// same for every sample: all of the BSDF's energy, none of its variance.
#[test]
fn merged_sample_weight_is_the_total_attenuation() {
    let mut g = rng(33);
    let mut worst = 0.0f64;
    for _ in 0..100 {
        let b = bsdf(&random_params(&mut g, true));
        for _ in 0..200 {
            let (h, wo, u) = random_vertex(&mut g);
            let total: Vec3 = b.lobe_energies(h, wo).iter().sum();
            let Some(s) = b.at_lobes(h, wo, Lobes::Merged).sample(u) else {
                continue;
            };
            let w = s.f * s.wi.z.abs() / s.pdf;
            for c in 0..3 {
                let rel =
                    (f64::from(w[c]) - f64::from(total[c])).abs() / f64::from(total[c]).max(1e-30);
                worst = worst.max(rel);
            }
        }
    }
    println!("merged weight against the total attenuation: worst relative {worst:.2e}");
    assert!(worst < 1e-5, "{worst}");
}

/// Attenuation per lobe (R, TT, TRT, residual) and channel of the f64 reference.
fn reference_energies(b: &HairBsdf, h: f32, wo: [f64; 3]) -> [[f64; 3]; 4] {
    let r = reference(b.params());
    r.geometry(f64::from(h), d3(v3(wo))).a
}

/// Largest error of a quadrature furnace here: the quadrature and f32 rounding give
/// about 1e-7 (furnace.rs), far below the energy a dropped lobe takes.
const TOLERANCE: f64 = 1e-5;

/// Quadrature furnaces: the merged lobe integrates to the whole model's energy (1 for
/// white hair; sum_p A_p of the reference for brown and black), its pdf to 1.
#[test]
fn merged_lobe_keeps_the_energy() {
    let _t = Timer::start("merged_lobe_keeps_the_energy");
    for sigma_a in [[0.0; 3], brown(), BLACK] {
        for beta in [0.1, 0.3, 0.9] {
            let b = bsdf(&params(sigma_a, 1.55, beta, beta, 2.0));
            for (to, po, h) in VIEWS {
                let wo = dir_deg(to, po);
                let (f, pdf) = crate_integrals(&b, Lobes::Merged, &reference(b.params()), h, wo);
                let a = reference_energies(&b, h, wo);
                for (c, got) in f.iter().enumerate() {
                    let want: f64 = a.iter().map(|lobe| lobe[c]).sum();
                    assert!(
                        (got - want).abs() < TOLERANCE,
                        "{sigma_a:?} beta {beta} view {to},{po},{h} channel {c}: {got} want {want}"
                    );
                }
                assert!((pdf - 1.0).abs() < TOLERANCE, "pdf integral {pdf}");
            }
        }
    }
}

/// Culling loses exactly the dropped lobes' energy: the integral of f |wi.z| is the sum
/// of the kept lobes' reference attenuations, where the kept lobes follow the rule
/// re-derived here (largest channel at least threshold x the total's largest channel, or
/// the strongest lobe), and the pdf still integrates to 1. Every configuration drops ten
/// times the tolerance, so the test cannot pass by culling nothing.
#[test]
fn culled_lobes_lose_exactly_their_energy() {
    let _t = Timer::start("culled_lobes_lose_exactly_their_energy");
    for (sigma_a, threshold) in [
        ([0.0; 3], 0.1),
        (brown(), 0.1),
        (brown(), 0.3),
        (BLACK, 0.2),
    ] {
        let b = bsdf(&params(sigma_a, 1.55, 0.3, 0.3, 2.0));
        for (to, po, h) in VIEWS {
            let wo = dir_deg(to, po);
            let a = reference_energies(&b, h, wo);
            let peak = a.map(|lobe| lobe.iter().copied().fold(0.0, f64::max));
            let total = (0..3)
                .map(|c| a.iter().map(|lobe| lobe[c]).sum::<f64>())
                .fold(0.0, f64::max);
            let strongest = (0..4).fold(0, |s, p| if peak[p] > peak[s] { p } else { s });
            let kept: Vec<usize> = (0..4)
                .filter(|&p| p == strongest || peak[p] >= f64::from(threshold) * total)
                .collect();
            let dropped = (0..3)
                .map(|c| {
                    (0..4)
                        .filter(|p| !kept.contains(p))
                        .map(|p| a[p][c])
                        .sum::<f64>()
                })
                .fold(0.0, f64::max);
            assert!(
                dropped > 10.0 * TOLERANCE,
                "{sigma_a:?} cull {threshold} view {to},{po},{h} drops {dropped}: too little \
                 to tell culling from none"
            );
            let lobes = Lobes::Culled(threshold);
            let (f, pdf) = crate_integrals(&b, lobes, &reference(b.params()), h, wo);
            for (c, got) in f.iter().enumerate() {
                let want: f64 = kept.iter().map(|&p| a[p][c]).sum();
                assert!(
                    (got - want).abs() < TOLERANCE,
                    "{sigma_a:?} cull {threshold} view {to},{po},{h} channel {c}: {got} want \
                     {want} (kept {kept:?})"
                );
            }
            assert!((pdf - 1.0).abs() < TOLERANCE, "pdf integral {pdf}");
        }
    }
}

/// Chi-square (the harness of chi2.rs): the merged lobe and culled points draw from
/// their own pdf, for white, brown and black hair over three views.
#[test]
fn chi2_culled_and_merged() {
    let _t = Timer::start("chi2_culled_and_merged");
    let mut configs = Vec::new();
    for (sigma_a, lobes) in [
        ([0.0; 3], Lobes::Merged),
        (brown(), Lobes::Merged),
        (brown(), Lobes::Culled(0.1)),
        (BLACK, Lobes::Culled(0.2)),
    ] {
        for (theta_o, phi_o, h) in VIEWS {
            configs.push(Config {
                p: params(sigma_a, 1.55, 0.3, 0.3, 2.0),
                theta_o,
                phi_o,
                h,
                lobes,
            });
        }
    }
    run_all(&configs, 400, 0.01 / configs.len() as f64);
}
