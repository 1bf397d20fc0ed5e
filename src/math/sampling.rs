//! Warping uniform numbers into directions and points, and tabulated distributions.
//!
//! Every warp takes numbers in [0, 1) and returns a point of its domain with a pdf that
//! is constant or cheap to recompute, so that light sampling, BSDF sampling and their MIS
//! weights all speak the same solid-angle measure. Directions are unit vectors around +z.

use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

use glam::{Vec2, Vec3};

use crate::Result;
use crate::error::invalid_arg;

/// The largest f32 below 1: where a warp must stay inside a half-open [0, 1).
pub(crate) const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Pdf of [`uniform_sphere`] per unit solid angle.
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// A direction uniformly distributed over the unit sphere.
pub fn uniform_sphere(u: [f32; 2]) -> Vec3 {
    let z = 1.0 - 2.0 * u[0];
    // (1 - z)(1 + z) rather than 1 - z^2: no cancellation near the poles.
    let r = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A point uniformly distributed over the unit disk, by Shirley and Chiu's concentric
/// map: it keeps strata of the square as compact strata of the disk, which a
/// low-discrepancy sampler needs to keep its advantage.
pub(crate) fn concentric_disk(u: [f32; 2]) -> Vec2 {
    let o = Vec2::new(2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// A direction on the hemisphere z >= 0 with density cos(theta) / pi (Malley's method:
/// project a uniform disk point up).
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// Pdf of [`cosine_hemisphere`] per unit solid angle for a direction with that cosine.
pub(crate) fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// A direction uniformly distributed in the cone around +z whose half-angle has
/// `1 - cos = one_minus_cos_max` (in [0, 2]).
///
/// Taking 1 - cos rather than cos keeps small cones exact: the sun's 0.27 degrees give
/// 1 - cos = 1.1e-5, which `1.0 - cos` in f32 would round to a tenth of that.
pub(crate) fn uniform_cone(u: [f32; 2], one_minus_cos_max: f32) -> Vec3 {
    let one_minus_cos = u[0] * one_minus_cos_max;
    let cos_theta = 1.0 - one_minus_cos;
    let sin_theta = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = 2.0 * PI * u[1];
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// Pdf of [`uniform_cone`] per unit solid angle: one over the cone's solid angle.
pub(crate) fn uniform_cone_pdf(one_minus_cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * one_minus_cos_max)
}

/// Veach's power heuristic (beta = 2): the MIS weight of a sample drawn `nf` times from
/// the strategy with pdf `f_pdf`, against `ng` samples of the strategy with pdf `g_pdf`.
/// Returns 0 when both pdfs vanish instead of NaN, and stays finite when a pdf is huge.
pub(crate) fn power_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    let f = nf * f_pdf;
    let g = ng * g_pdf;
    if f.is_infinite() {
        return 1.0;
    }
    let (ff, gg) = (f * f, g * g);
    if ff.is_infinite() || gg.is_infinite() {
        // Squares overflow before the pdfs do: compare the ratio instead.
        let r = g / f;
        return 1.0 / (1.0 + r * r);
    }
    let sum = ff + gg;
    if sum > 0.0 { ff / sum } else { 0.0 }
}

/// A piecewise-constant density on [0, 1) proportional to a table of non-negative
/// values, sampled by inverting its CDF.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Distribution1D {
    func: Vec<f32>,
    /// `func.len() + 1` entries from 0 to exactly 1.
    cdf: Vec<f32>,
    /// Mean of `func`: the integral of the step function over [0, 1).
    integral: f32,
}

impl Distribution1D {
    /// Builds the distribution of `func`, which must be non-empty, finite and >= 0.
    /// An all-zero table gives the uniform distribution (a black environment map still
    /// has to return valid samples), with [`integral`](Self::integral) 0.
    pub fn new(func: &[f32]) -> Result<Self> {
        if func.is_empty() {
            return Err(invalid_arg!("distribution: the table is empty"));
        }
        if let Some(i) = func.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(invalid_arg!(
                "distribution: entry {i} is {}; entries must be finite and >= 0",
                func[i]
            ));
        }
        let n = func.len();
        // Accumulate in f64 so that a long table's CDF does not drift from its sum.
        let mut cdf = Vec::with_capacity(n + 1);
        let mut sum = 0.0f64;
        cdf.push(0.0f64);
        for &v in func {
            sum += f64::from(v);
            cdf.push(sum);
        }
        let (cdf, integral) = if sum > 0.0 {
            (
                cdf.iter().map(|c| (c / sum) as f32).collect(),
                (sum / n as f64) as f32,
            )
        } else {
            ((0..=n).map(|i| i as f32 / n as f32).collect(), 0.0)
        };
        Ok(Self {
            func: func.to_vec(),
            cdf,
            integral,
        })
    }

    /// Mean of the table, i.e. the integral of the step function over [0, 1).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Maps `u` in [0, 1) to `(x, pdf, index)`: x in [0, 1) inside cell `index`, and the
    /// density at x. Never returns a cell whose value is 0 (unless all are).
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.func.len();
        let u = u.clamp(0.0, ONE_MINUS_EPSILON);
        // The last cell whose CDF start is <= u: empty cells have equal start and end,
        // so a strict `u < cdf[i + 1]` can never select them.
        let i = (self.cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        let mut x = ((i as f32 + du) / n as f32).min(ONE_MINUS_EPSILON);
        // Rounding can put x on a neighbouring cell's side of a boundary; step it back by
        // ulps so that `pdf(x)` is the pdf returned here.
        while self.cell(x) > i {
            x = f32::from_bits(x.to_bits() - 1);
        }
        while self.cell(x) < i {
            x = f32::from_bits(x.to_bits() + 1);
        }
        (x, self.cell_pdf(i), i)
    }

    /// Density at `x` in [0, 1) (values outside are clamped to the end cells).
    pub fn pdf(&self, x: f32) -> f32 {
        self.cell_pdf(self.cell(x))
    }

    /// Index of the cell holding `x`.
    pub fn cell(&self, x: f32) -> usize {
        let n = self.func.len();
        // `as usize` saturates, so NaN and negatives land in cell 0.
        ((x * n as f32) as usize).min(n - 1)
    }

    fn cell_pdf(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.func[i] / self.integral
        } else {
            1.0
        }
    }
}

/// A piecewise-constant density on [0, 1)^2 over an `nu` x `nv` table, sampled as a
/// marginal over rows (v) and a conditional within the row (u).
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// `func` holds `nv` rows of `nu` values, row-major (`func[v * nu + u]`), finite
    /// and >= 0.
    pub fn new(func: &[f32], nu: usize, nv: usize) -> Result<Self> {
        if nu == 0 || nv == 0 || nu.checked_mul(nv) != Some(func.len()) {
            return Err(invalid_arg!(
                "distribution: a {nu} x {nv} table needs {nu} * {nv} values, got {}",
                func.len()
            ));
        }
        let rows = func
            .chunks_exact(nu)
            .map(Distribution1D::new)
            .collect::<Result<Vec<_>>>()?;
        let marginal = Distribution1D::new(&rows.iter().map(|r| r.integral()).collect::<Vec<_>>())?;
        Ok(Self { rows, marginal })
    }

    /// Maps `u` in [0, 1)^2 to a point `[u, v]` in [0, 1)^2 and its density.
    pub fn sample(&self, u: [f32; 2]) -> ([f32; 2], f32) {
        let (v, pdf_v, row) = self.marginal.sample(u[1]);
        let (x, pdf_u, _) = self.rows[row].sample(u[0]);
        ([x, v], pdf_v * pdf_u)
    }

    /// Density at `[u, v]`.
    pub fn pdf(&self, p: [f32; 2]) -> f32 {
        let row = self.marginal.cell(p[1]);
        self.marginal.cell_pdf(row) * self.rows[row].pdf(p[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    const N: usize = 200_000;

    fn uniforms(seed: u64) -> impl Iterator<Item = [f32; 2]> {
        let mut rng = Pcg64::seed_from_u64(seed);
        (0..N).map(move |_| [rng.random::<f32>(), rng.random::<f32>()])
    }

    /// Estimates the integral of `pdf` over the sphere by uniform sphere sampling, and
    /// checks it is 1 within 4 standard errors.
    fn assert_pdf_integrates_to_one(pdf: impl Fn(Vec3) -> f32) {
        let vals: Vec<f64> = uniforms(7)
            .map(|u| f64::from(pdf(uniform_sphere(u)) / UNIFORM_SPHERE_PDF))
            .collect();
        let mean = vals.iter().sum::<f64>() / N as f64;
        let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (N - 1) as f64;
        let se = (var / N as f64).sqrt();
        assert!((mean - 1.0).abs() < 4.0 * se + 1e-6, "{mean} +- {se}");
    }

    /// Checks a warp against its pdf: a histogram over (cos theta, phi) cells against the
    /// pdf integrated over each cell (by a fine midpoint rule), and every sample of
    /// unit length.
    fn assert_warp_matches(warp: impl Fn([f32; 2]) -> Vec3, pdf: impl Fn(Vec3) -> f32) {
        const NZ: usize = 16;
        const NP: usize = 16;
        let mut hist = vec![0usize; NZ * NP];
        let cell = |w: Vec3| {
            let z = (((w.z + 1.0) / 2.0 * NZ as f32) as usize).min(NZ - 1);
            let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
            let p = ((phi / (2.0 * PI) * NP as f32) as usize).min(NP - 1);
            z * NP + p
        };
        for u in uniforms(3) {
            let w = warp(u);
            assert!((w.length() - 1.0).abs() < 1e-5, "{w}");
            assert!(pdf(w) > 0.0, "sample {w} where pdf = 0");
            hist[cell(w)] += 1;
        }
        // Fine in z, where the cone's edge cuts through cells, coarse in phi.
        const SUB_Z: usize = 256;
        const SUB_P: usize = 4;
        for (c, &count) in hist.iter().enumerate() {
            let (iz, ip) = (c / NP, c % NP);
            let mut expected = 0.0f64;
            for sz in 0..SUB_Z {
                for sp in 0..SUB_P {
                    let z = -1.0 + 2.0 * ((iz * SUB_Z + sz) as f32 + 0.5) / (NZ * SUB_Z) as f32;
                    let phi = 2.0 * PI * ((ip * SUB_P + sp) as f32 + 0.5) / (NP * SUB_P) as f32;
                    let r = (1.0 - z * z).sqrt();
                    let w = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                    expected += f64::from(pdf(w));
                }
            }
            // Cell area in (z, phi) is its solid angle.
            expected *= (2.0 / NZ as f64) * (2.0 * std::f64::consts::PI / NP as f64)
                / (SUB_Z * SUB_P) as f64
                * N as f64;
            let sigma = expected.sqrt().max(1.0);
            assert!(
                (count as f64 - expected).abs() < 5.0 * sigma,
                "cell ({iz}, {ip}): {count} samples, expected {expected:.1}"
            );
        }
    }

    #[test]
    fn uniform_sphere_matches_its_pdf() {
        let sphere = |_: Vec3| UNIFORM_SPHERE_PDF;
        assert_pdf_integrates_to_one(sphere);
        assert_warp_matches(uniform_sphere, sphere);
    }

    #[test]
    fn cosine_hemisphere_matches_its_pdf() {
        let pdf = |w: Vec3| cosine_hemisphere_pdf(w.z);
        assert_pdf_integrates_to_one(pdf);
        assert_warp_matches(cosine_hemisphere, pdf);
    }

    #[test]
    fn cone_matches_its_pdf() {
        for half_angle in [0.3f32, 1.2, 2.5] {
            let omc = 2.0 * (half_angle / 2.0).sin().powi(2);
            let pdf = move |w: Vec3| {
                if 1.0 - w.z <= omc * (1.0 + 1e-5) {
                    uniform_cone_pdf(omc)
                } else {
                    0.0
                }
            };
            assert_pdf_integrates_to_one(pdf);
            assert_warp_matches(|u| uniform_cone(u, omc), pdf);
        }
        // A sun-sized cone stays inside its angle and of unit length.
        let omc = 2.0 * (0.00465f32 / 2.0).sin().powi(2);
        for u in uniforms(5).take(1000) {
            let w = uniform_cone(u, omc);
            assert!(w.z.acos() <= 0.00466 && (w.length() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn concentric_disk_is_uniform_inside_the_disk() {
        let mut quadrants = [0usize; 4];
        let mut inner = 0;
        for u in uniforms(11) {
            let d = concentric_disk(u);
            assert!(d.length() <= 1.0 + 1e-6);
            quadrants[usize::from(d.x < 0.0) * 2 + usize::from(d.y < 0.0)] += 1;
            inner += usize::from(d.length() < 0.5);
        }
        for q in quadrants {
            assert!((q as f64 / N as f64 - 0.25).abs() < 0.005, "{quadrants:?}");
        }
        // A disk of radius 0.5 holds a quarter of the area.
        assert!((inner as f64 / N as f64 - 0.25).abs() < 0.005, "{inner}");
        assert_eq!(concentric_disk([0.5, 0.5]), Vec2::ZERO);
    }

    #[test]
    fn power_heuristic_edge_cases() {
        assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
        assert_eq!(power_heuristic(1.0, 1.0, 1.0, 1.0), 0.5);
        assert!((power_heuristic(1.0, 3.0, 1.0, 1.0) - 0.9).abs() < 1e-6);
        assert_eq!(power_heuristic(1.0, f32::INFINITY, 1.0, 1.0), 1.0);
        let w = power_heuristic(1.0, 1e30, 1.0, 1e30);
        assert!((w - 0.5).abs() < 1e-6, "{w}");
        let (a, b) = (
            power_heuristic(1.0, 2e25, 1.0, 1e25),
            power_heuristic(1.0, 1e25, 1.0, 2e25),
        );
        assert!(
            (a + b - 1.0).abs() < 1e-6 && (a - 0.8).abs() < 1e-6,
            "{a} {b}"
        );
    }

    #[test]
    fn distribution_1d_histogram_matches() {
        let func = [0.0, 1.0, 3.0, 0.0, 0.5, 0.0, 2.0, 0.0];
        let d = Distribution1D::new(&func).unwrap();
        let total: f32 = func.iter().sum();
        assert!((d.integral() - total / 8.0).abs() < 1e-6);
        let mut hist = [0usize; 8];
        let mut rng = Pcg64::seed_from_u64(1);
        for _ in 0..N {
            let (x, pdf, i) = d.sample(rng.random());
            assert!((0.0..1.0).contains(&x));
            assert_eq!(d.cell(x), i);
            assert!(pdf > 0.0 && pdf == d.pdf(x));
            hist[i] += 1;
        }
        for (i, &count) in hist.iter().enumerate() {
            let p = f64::from(func[i] / total);
            let expected = p * N as f64;
            let sigma = (N as f64 * p * (1.0 - p)).sqrt();
            assert!((count as f64 - expected).abs() <= 5.0 * sigma, "{hist:?}");
        }
        // The ends of [0, 1) never select an empty cell.
        assert_eq!(d.sample(0.0).2, 1);
        assert_eq!(d.sample(ONE_MINUS_EPSILON).2, 6);
        assert!(d.sample(1.0).0 < 1.0);
    }

    #[test]
    fn distribution_1d_pdf_integrates_to_one_and_rejects_bad_tables() {
        let d = Distribution1D::new(&[1.0, 2.0, 7.0]).unwrap();
        let steps = 3000;
        let sum: f32 = (0..steps)
            .map(|i| d.pdf((i as f32 + 0.5) / steps as f32))
            .sum::<f32>()
            / steps as f32;
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
        let zero = Distribution1D::new(&[0.0; 4]).unwrap();
        assert_eq!(zero.integral(), 0.0);
        let (x, pdf, i) = zero.sample(0.6);
        assert!((x - 0.6).abs() < 1e-6 && pdf == 1.0 && i == 2);
        assert!(Distribution1D::new(&[]).is_err());
        assert!(Distribution1D::new(&[1.0, f32::NAN]).is_err());
        assert!(Distribution1D::new(&[1.0, -1.0]).is_err());
        assert!(Distribution1D::new(&[f32::INFINITY]).is_err());
    }

    #[test]
    fn distribution_2d_matches_its_table() {
        let (nu, nv) = (5, 3);
        let func: Vec<f32> = (0..nu * nv).map(|i| ((i * 7) % 4) as f32).collect();
        let d = Distribution2D::new(&func, nu, nv).unwrap();
        let total: f32 = func.iter().sum();
        let mut hist = vec![0usize; nu * nv];
        for u in uniforms(9) {
            let (p, pdf) = d.sample(u);
            assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]));
            let cell = ((p[1] * nv as f32) as usize) * nu + (p[0] * nu as f32) as usize;
            assert!(func[cell] > 0.0);
            let expected_pdf = func[cell] / total * (nu * nv) as f32;
            assert!(
                (pdf - expected_pdf).abs() < 1e-5 * expected_pdf,
                "{pdf} {expected_pdf}"
            );
            assert!((d.pdf(p) - pdf).abs() < 1e-5 * pdf);
            hist[cell] += 1;
        }
        for (c, &count) in hist.iter().enumerate() {
            let p = f64::from(func[c] / total);
            let sigma = (N as f64 * p * (1.0 - p)).sqrt();
            assert!(
                (count as f64 - p * N as f64).abs() <= 5.0 * sigma,
                "{hist:?}"
            );
        }
        assert!(Distribution2D::new(&func, 4, 3).is_err());
        assert!(Distribution2D::new(&[], 0, 0).is_err());
    }
}
