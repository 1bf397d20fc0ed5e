//! Chi-square goodness of fit of `HuangPoint::sample` against `HuangPoint::eval`'s pdf over
//! roughness x aspect x eta x tilt, near and far field: as `tests/bsdf/chi2.rs` does for
//! Chiang's model (32 x 64 equal-area cells, cells of fewer than 5 expected samples
//! pooled, Bonferroni over the configurations). Lost draws (total internal reflection at
//! an exit) are counted against the pdf's missing mass.

use super::{huang, point};
use crate::common::chi2::{Grid, dump_tables, pearson};
use crate::common::quad::gauss_legendre;
use crate::common::{Timer, d3, dir_deg, par_map, random_u, rng, v3};
use glam::Vec2;
use std::path::Path;

const GRID: Grid = Grid {
    n_theta: 32,
    n_phi: 64,
};
const SAMPLES: usize = 200_000;
const SIGNIFICANCE: f64 = 0.01;

#[derive(Clone, Copy, Debug)]
struct Config {
    roughness: f32,
    aspect: f32,
    eta: f32,
    alpha: f32,
    /// Offsets of the point (`point`).
    shifts: usize,
    theta_o: f64,
    phi_o: f64,
    h: f32,
    major_deg: f32,
}

fn configs() -> Vec<Config> {
    let views = [
        (0.0, 90.0, 0.3, 20.0),
        (-50.0, 60.0, -0.7, 100.0),
        (30.0, -120.0, 0.9, -45.0),
        (75.0, 135.0, -0.2, 0.0),
    ];
    let mut out = Vec::new();
    let mut i = 0;
    for roughness in [0.15, 0.5] {
        for aspect in [1.0, 0.6] {
            for eta in [1.55, 1.9] {
                for alpha in [0.0, 6.0] {
                    let (theta_o, phi_o, h, major_deg) = views[i % views.len()];
                    out.push(Config {
                        roughness,
                        aspect,
                        eta,
                        alpha,
                        shifts: [1, 2, 4][i % 3],
                        theta_o,
                        phi_o,
                        h,
                        major_deg,
                    });
                    i += 1;
                }
            }
        }
    }
    out
}

#[test]
fn huang_sampling_matches_pdf_chi_square() {
    let _t = Timer::start("huang chi-square");
    let configs = configs();
    let threshold = SIGNIFICANCE / configs.len() as f64;
    let gl = gauss_legendre(5);
    let results = par_map(&configs, |c| {
        let b = huang([0.0, 0.3, 1.0], c.eta, c.roughness, c.aspect, c.alpha);
        let (s, co) = c.major_deg.to_radians().sin_cos();
        let wo = v3(dir_deg(c.theta_o, c.phi_o));
        let p = point(
            &b,
            c.shifts,
            c.h,
            wo,
            Vec2::new(co, s),
            [c.major_deg / 360.0 + 0.5, 0.3],
        );
        let mut g = rng(46);
        let mut counts = vec![0.0; GRID.cells()];
        let mut lost = 0usize;
        for _ in 0..SAMPLES {
            match p.sample(random_u(&mut g)) {
                Some(s) => counts[GRID.cell(d3(s.wi))] += 1.0,
                None => lost += 1,
            }
        }
        let cells = GRID.integrate(|w| f64::from(p.eval(v3(w)).pdf), &[], &[], 0.04, &gl);
        let mass: f64 = cells.iter().sum();
        let expected: Vec<f64> = cells.iter().map(|c| c * SAMPLES as f64).collect();
        let r = pearson(&counts, &expected, 5.0);
        (r, mass, lost as f64 / SAMPLES as f64, counts, expected)
    });
    let mut failed = Vec::new();
    for (c, (r, mass, lost, counts, expected)) in configs.iter().zip(&results) {
        println!(
            "{c:?}: chi2 {:.1} dof {} p {:.3e}; pdf mass {mass:.5}, draws lost {lost:.5}",
            r.statistic, r.dof, r.p_value
        );
        // The pdf's mass is what the sampler returns: the lost draws are the rest.
        let mass_ok = (mass + lost - 1.0).abs() < 5e-3;
        if r.p_value < threshold || !mass_ok {
            let path = dump_tables(
                Path::new(env!("CARGO_TARGET_TMPDIR")),
                &format!("huang_chi2_{}", failed.len()),
                &format!("{c:?}"),
                &GRID,
                counts,
                expected,
            );
            failed.push(format!(
                "{c:?} (p {:.2e}, mass {mass}, lost {lost}) {}",
                r.p_value,
                path.display()
            ));
        }
    }
    assert!(failed.is_empty(), "failed:\n{}", failed.join("\n"));
}
