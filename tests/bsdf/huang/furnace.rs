//! The white furnace of the Huang model: a non-absorbing fibre, h uniform across it and wo
//! over the sphere. Its albedo is 1 less what the model loses: single-scattering
//! microfacets (masked light is dropped, not scattered again), paths that leave the
//! section's mesonormal side, and the residual's smooth-Fresnel series. The figure is
//! measured (docs/measurements.md, "The Huang model"); this checks that the sampler's
//! weights and the quadrature of `eval` agree on it, and that it stays in a stated band.

use super::{huang, point};
use crate::common::chi2::Grid;
use crate::common::quad::gauss_legendre;
use crate::common::{Timer, par_map, random_u, rng, v3};
use glam::{Vec2, Vec3};
use rand::Rng;

/// The lowest albedo a non-absorbing fibre may have, over the configurations below.
const MIN_ALBEDO: f64 = 0.40;

#[test]
fn huang_white_furnace() {
    let _t = Timer::start("huang furnace");
    let configs: Vec<(f32, f32, f32)> = [0.1f32, 0.3, 0.8]
        .into_iter()
        .flat_map(|r| [(r, 1.0, 2.0), (r, 0.6, 2.0), (r, 0.6, 0.0)])
        .collect();
    let results = par_map(&configs, |&(roughness, aspect, alpha)| {
        let b = huang([0.0; 3], 1.55, roughness, aspect, alpha);
        let mut g = rng(7);
        let (mut mc, mut n) = (0.0f64, 0usize);
        for _ in 0..200 {
            // wo uniform over the sphere, h uniform, the major axis at random.
            let z: f32 = g.random_range(-1.0..1.0);
            let phi: f32 = g.random_range(0.0..std::f32::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            let wo = Vec3::new(z, r * phi.cos(), r * phi.sin());
            let turn: f32 = g.random_range(0.0..std::f32::consts::TAU);
            let jitter = [g.random(), g.random()];
            let p = point(
                &b,
                1,
                g.random_range(-1.0..1.0),
                wo,
                Vec2::from_angle(turn),
                jitter,
            );
            for _ in 0..500 {
                if let Some(s) = p.sample(random_u(&mut g)) {
                    mc += f64::from((s.f * s.wi.z.abs() / s.pdf).element_sum() / 3.0);
                }
                n += 1;
            }
        }
        (roughness, aspect, alpha, mc / n as f64)
    });
    let mut low = Vec::new();
    for &(roughness, aspect, alpha, albedo) in &results {
        println!("roughness {roughness} aspect {aspect} alpha {alpha}: albedo {albedo:.4}");
        if !(MIN_ALBEDO..=1.0 + 1e-2).contains(&albedo) {
            low.push((roughness, aspect, alpha, albedo));
        }
    }
    assert!(low.is_empty(), "{low:?}");
}

/// At single points the sampler's mean weight equals the quadrature of f |wi.z| over the
/// sphere: eval and sample describe the same scattering (the sampler's support covers f).
#[test]
fn huang_sample_weights_integrate_eval() {
    let grid = Grid {
        n_theta: 64,
        n_phi: 128,
    };
    let gl = gauss_legendre(4);
    let cases = [
        (0.2f32, 1.0f32, 2.0f32, 1, 0.3f32, 10.0f32),
        (0.4, 0.6, -4.0, 2, -0.5, 70.0),
        (0.15, 0.75, 6.0, 1, 0.85, -30.0),
        (0.3, 0.65, 2.0, 4, 0.1, -60.0),
    ];
    let results = par_map(
        &cases,
        |&(roughness, aspect, alpha, shifts, h, theta_deg)| {
            let b = huang([0.2, 0.4, 0.8], 1.55, roughness, aspect, alpha);
            let (s, c) = theta_deg.to_radians().sin_cos();
            let p = point(
                &b,
                shifts,
                h,
                Vec3::new(s, 0.0, c),
                Vec2::from_angle(0.7),
                [0.2, 0.9],
            );
            let quad: f64 = grid
                .integrate(
                    |w| {
                        let e = p.eval(v3(w));
                        f64::from(e.f.element_sum() / 3.0) * w[2].abs()
                    },
                    &[],
                    &[],
                    0.03,
                    &gl,
                )
                .iter()
                .sum();
            let mut g = rng(3);
            let n = 400_000;
            let (mut mc, mut mc2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                if let Some(s) = p.sample(random_u(&mut g)) {
                    let w = f64::from((s.f * s.wi.z.abs() / s.pdf).element_sum() / 3.0);
                    mc += w;
                    mc2 += w * w;
                }
            }
            let mean = mc / n as f64;
            (
                quad,
                mean,
                ((mc2 / n as f64 - mean * mean) / n as f64).sqrt(),
            )
        },
    );
    for ((quad, mc, se), case) in results.iter().zip(&cases) {
        println!("{case:?}: quadrature {quad:.5}, sampled {mc:.5} +- {se:.5}");
        assert!(
            (quad - mc).abs() < 4.0 * se + 3e-3 * quad,
            "{case:?}: {quad} vs {mc}"
        );
    }
}
