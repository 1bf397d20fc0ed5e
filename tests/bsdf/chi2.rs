//! Chi-square goodness of fit of `HairBsdf::sample` against `HairBsdf::pdf`.
//!
//! For each configuration, N = 10^6 sampled directions are binned on a 32 x 64 grid
//! (32 bands of equal sin(theta), 64 sectors of phi) and compared with N times the pdf
//! integrated over each cell (product Gauss–Legendre, panels at the cell edges and refined
//! around the lobe centres down to half a lobe width: the lobes at beta = 0.1 are ~0.02 rad
//! wide in phi, ~0.04 in theta). Cells expecting fewer than 5 samples are pooled, and a
//! configuration fails if Pearson's p-value is below 0.01 / (number of configurations)
//! (Bonferroni: the whole file then has a false-alarm rate below 1%). 10^6 samples make
//! a relative error of ~1% in a lobe holding 10% of the mass a ~30-sigma effect.

use crate::common::chi2::{Chi2Result, Grid, dump_tables, pearson};
use crate::common::quad::gauss_legendre;
use crate::common::reference::RefHair;
use crate::common::{Timer, bsdf, d3, dir_deg, par_map, params, random_u, reference, rng, v3};
use hairtrace::{HairBsdf, HairParams, Lobes};
use std::path::Path;

const GRID: Grid = Grid {
    n_theta: 32,
    n_phi: 64,
};
const SAMPLES: usize = 1_000_000;
const SIGNIFICANCE: f64 = 0.01;
const BETAS: [f32; 3] = [0.1, 0.3, 0.8];
const ALPHAS: [f32; 3] = [0.0, 2.0, 10.0];
/// (theta_o deg, phi_o deg, h): under, on and over the normal plane, near the tangent,
/// with h from the edge to the centre on both sides.
const VIEWS: [(f64, f64, f32); 4] = [
    (-70.0, 20.0, -0.6),
    (0.0, 90.0, 0.2),
    (40.0, -150.0, 0.9),
    (85.0, 135.0, -0.95),
];

#[derive(Clone, Copy, Debug)]
pub(crate) struct Config {
    pub p: HairParams,
    pub theta_o: f64,
    pub phi_o: f64,
    pub h: f32,
    /// The lobes the point samples and evaluates.
    pub lobes: Lobes,
}

impl Config {
    fn name(&self) -> String {
        let lobes = match self.lobes {
            Lobes::All => String::new(),
            Lobes::Culled(t) => format!("_cull{t}"),
            Lobes::Merged => "_merged".into(),
        };
        format!(
            "b{}_a{}_s{}_to{}_po{}_h{}{lobes}",
            self.p.beta_m,
            self.p.alpha,
            if self.p.sigma_a == [0.0; 3] {
                "0"
            } else {
                "brown"
            },
            self.theta_o,
            self.phi_o,
            self.h
        )
    }

    fn wo(&self) -> glam::Vec3 {
        v3(dir_deg(self.theta_o, self.phi_o))
    }
}

fn configs() -> Vec<Config> {
    let mut out = Vec::new();
    for beta in BETAS {
        for alpha in ALPHAS {
            for sigma_a in [crate::common::brown(), [0.0; 3]] {
                for (theta_o, phi_o, h) in VIEWS {
                    out.push(Config {
                        p: params(sigma_a, 1.55, beta, beta, alpha),
                        theta_o,
                        phi_o,
                        h,
                        lobes: Lobes::All,
                    });
                }
            }
        }
    }
    out
}

/// Histogram of `SAMPLES` sampled directions, each passed through `map` (the identity
/// except in the negative control). Returns the counts and the number of None samples.
fn histogram(
    b: &HairBsdf,
    c: &Config,
    seed: u64,
    map: impl Fn([f64; 3]) -> [f64; 3],
) -> (Vec<f64>, usize) {
    let mut g = rng(seed);
    let mut counts = vec![0.0; GRID.cells()];
    let mut none = 0;
    let point = b.at_lobes(c.h, c.wo(), c.lobes);
    for _ in 0..SAMPLES {
        match point.sample(random_u(&mut g)) {
            Some(s) => counts[GRID.cell(map(d3(s.wi)))] += 1.0,
            None => none += 1,
        }
    }
    (counts, none)
}

/// Probability of every cell under `pdf`, with nodes refined around the lobe centres of
/// the reference model.
fn cell_probabilities(r: &RefHair, c: &Config, pdf: impl Fn([f64; 3]) -> f64) -> Vec<f64> {
    let (tc, pc) = r.lobe_centres(c.h as f64, d3(c.wo()));
    GRID.integrate(pdf, &tc, &pc, 0.3, &gauss_legendre(6))
}

struct Outcome {
    result: Chi2Result,
    total: f64,
    none: usize,
    observed: Vec<f64>,
    expected: Vec<f64>,
}

fn run(c: &Config, seed: u64) -> Outcome {
    let b = bsdf(&c.p);
    let r = reference(&c.p);
    let point = b.at_lobes(c.h, c.wo(), c.lobes);
    let prob = cell_probabilities(&r, c, |wi| point.eval(v3(wi)).pdf as f64);
    let total: f64 = prob.iter().sum();
    let expected: Vec<f64> = prob.iter().map(|p| p * SAMPLES as f64).collect();
    let (observed, none) = histogram(&b, c, seed, |w| w);
    Outcome {
        result: pearson(&observed, &expected, 5.0),
        total,
        none,
        observed,
        expected,
    }
}

fn dump_dir() -> &'static Path {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
}

pub(crate) fn run_all(configs: &[Config], first_seed: u64, threshold: f64) {
    let outcomes = par_map(
        &configs.iter().enumerate().collect::<Vec<_>>(),
        |&(i, c)| run(c, first_seed + i as u64),
    );
    let mut failures = Vec::new();
    let (mut p_min, mut p_max, mut worst_total) = (1.0f64, 0.0f64, 0.0f64);
    for (c, o) in configs.iter().zip(&outcomes) {
        println!(
            "{:<40} chi2 = {:9.1}  dof = {:4}  pooled = {:4}  p = {:.3e}  pdf integral - 1 = {:+.1e}",
            c.name(),
            o.result.statistic,
            o.result.dof,
            o.result.pooled_cells,
            o.result.p_value,
            o.total - 1.0
        );
        p_min = p_min.min(o.result.p_value);
        p_max = p_max.max(o.result.p_value);
        worst_total = worst_total.max((o.total - 1.0).abs());
        if o.result.p_value < threshold || (o.total - 1.0).abs() > 1e-3 || o.none > 0 {
            let path = dump_tables(
                &dump_dir().join("chi2"),
                &c.name(),
                &format!(
                    "{c:?}: {:?}, pdf integral {}, None samples {}",
                    o.result, o.total, o.none
                ),
                &GRID,
                &o.observed,
                &o.expected,
            );
            failures.push(format!(
                "{}: p = {:.3e} (threshold {threshold:.1e}), pdf integral {}, {} None samples; tables in {}",
                c.name(),
                o.result.p_value,
                o.total,
                o.none,
                path.display()
            ));
        }
    }
    println!(
        "{} configurations: p-values in [{p_min:.3e}, {p_max:.3e}], threshold {threshold:.1e}, worst |pdf integral - 1| = {worst_total:.2e}",
        configs.len()
    );
    assert!(
        failures.is_empty(),
        "chi-square failures:\n{}",
        failures.join("\n")
    );
}

/// The Bonferroni threshold shared by all configurations of this file.
fn threshold() -> f64 {
    SIGNIFICANCE / configs().len() as f64
}

/// sample() draws from pdf(): all 72 configurations (beta 0.1, 0.3, 0.8 x alpha 0, 2, 10
/// x brown and white x 4 views) pass at the Bonferroni-corrected 1% level, none returns
/// None, and the pdf integrates to 1 within 1e-3 over the sphere.
/// Split by beta into three tests so that the test runner can interleave them.
#[test]
fn chi2_beta_0_1() {
    let _t = Timer::start("chi2_beta_0_1");
    let all: Vec<Config> = configs()
        .into_iter()
        .filter(|c| c.p.beta_m == 0.1)
        .collect();
    run_all(&all, 100, threshold());
}

/// See [`chi2_beta_0_1`].
#[test]
fn chi2_beta_0_3() {
    let _t = Timer::start("chi2_beta_0_3");
    let all: Vec<Config> = configs()
        .into_iter()
        .filter(|c| c.p.beta_m == 0.3)
        .collect();
    run_all(&all, 200, threshold());
}

/// See [`chi2_beta_0_1`].
#[test]
fn chi2_beta_0_8() {
    let _t = Timer::start("chi2_beta_0_8");
    let all: Vec<Config> = configs()
        .into_iter()
        .filter(|c| c.p.beta_m == 0.8)
        .collect();
    run_all(&all, 300, threshold());
}

/// Negative control: the harness has teeth. Two deliberately wrong hypotheses about the
/// same sampler must be rejected at the same threshold as the real tests:
/// (a) the samples rotated by 0.01 rad in phi (a quarter of the azimuthal width at
///     beta = 0.3);
/// (b) the pdf with its R lobe's weight doubled (renormalised), using the reference's
///     R-lobe density: (pdf + w0 * D0) / (1 + w0).
#[test]
fn chi2_rejects_wrong_distributions() {
    let _t = Timer::start("chi2_rejects_wrong_distributions");
    let c = Config {
        p: params(crate::common::brown(), 1.55, 0.3, 0.3, 2.0),
        theta_o: 20.0,
        phi_o: 60.0,
        h: 0.3,
        lobes: Lobes::All,
    };
    let b = bsdf(&c.p);
    let r = reference(&c.p);
    let wo = c.wo();
    let thr = threshold();

    // The right hypothesis passes (so the rejections below are due to the error alone).
    let prob = cell_probabilities(&r, &c, |wi| b.pdf(c.h, wo, v3(wi)) as f64);
    let expected: Vec<f64> = prob.iter().map(|p| p * SAMPLES as f64).collect();
    let (observed, _) = histogram(&b, &c, 900, |w| w);
    let right = pearson(&observed, &expected, 5.0);
    println!("control, right hypothesis: {right:?}");
    assert!(right.p_value >= thr, "{right:?}");

    // (a) phi shifted by 0.01 rad.
    let (shifted, _) = histogram(&b, &c, 901, |w| {
        crate::common::sphere::rotate(w, [1.0, 0.0, 0.0], 0.01)
    });
    let a = pearson(&shifted, &expected, 5.0);
    // Exercise the failure dump on this expected rejection, so its format can be looked at.
    let path = dump_tables(
        &dump_dir().join("chi2"),
        "negative_control_phi_shift",
        &format!("{c:?} with samples rotated by 0.01 rad in phi: {a:?}"),
        &GRID,
        &shifted,
        &expected,
    );
    println!(
        "control (a), phi shifted by 0.01 rad: {a:?}; tables in {}",
        path.display()
    );
    assert!(a.p_value < thr, "phi-shifted samples not rejected: {a:?}");

    // (b) R lobe weight doubled.
    let g = r.geometry(c.h as f64, d3(wo));
    let wrong = cell_probabilities(&r, &c, |wi| {
        let d0 = r.lobe_densities(&g, d3(v3(wi)))[0];
        (b.pdf(c.h, wo, v3(wi)) as f64 + g.w[0] * d0) / (1.0 + g.w[0])
    });
    let wrong_total: f64 = wrong.iter().sum();
    let expected_b: Vec<f64> = wrong.iter().map(|p| p * SAMPLES as f64).collect();
    let bres = pearson(&observed, &expected_b, 5.0);
    println!(
        "control (b), R weight {:.4} doubled (integral {wrong_total:.6}): {bres:?}",
        g.w[0]
    );
    assert!((wrong_total - 1.0).abs() < 1e-3);
    assert!(bres.p_value < thr, "doubled R lobe not rejected: {bres:?}");
}
