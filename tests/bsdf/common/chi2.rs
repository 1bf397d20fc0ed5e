//! Pearson chi-square goodness-of-fit harness for direction samplers, in the style of the
//! pbrt-v4 and Mitsuba 3 tests: a (theta, phi) grid of equal-area cells, a histogram of
//! the samples, the expected count per cell from the pdf integrated over the cell,
//! pooling of low-expectation cells, and a dump of both tables when a test fails.

use super::quad::{GaussLegendre, SphereRule};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Cells: `n_theta` bands of equal sin(theta) (equal area), times `n_phi` equal phi
/// sectors of [-pi, pi). Cell index = band * n_phi + sector.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    pub n_theta: usize,
    pub n_phi: usize,
}

impl Grid {
    pub fn cells(&self) -> usize {
        self.n_theta * self.n_phi
    }

    /// Band edges in theta: asin(-1 + 2k / n_theta).
    pub fn theta_edges(&self) -> Vec<f64> {
        (0..=self.n_theta)
            .map(|k| {
                (-1.0 + 2.0 * k as f64 / self.n_theta as f64)
                    .clamp(-1.0, 1.0)
                    .asin()
            })
            .collect()
    }

    /// Sector edges in phi.
    pub fn phi_edges(&self) -> Vec<f64> {
        (0..=self.n_phi)
            .map(|k| -PI + 2.0 * PI * k as f64 / self.n_phi as f64)
            .collect()
    }

    /// The cell of a direction (sin(theta) = w.x, phi = atan2(w.z, w.y)).
    pub fn cell(&self, w: [f64; 3]) -> usize {
        let band = ((w[0].clamp(-1.0, 1.0) + 1.0) * 0.5 * self.n_theta as f64).floor() as usize;
        let phi = w[2].atan2(w[1]);
        let sector = ((phi + PI) / (2.0 * PI) * self.n_phi as f64).floor() as usize;
        band.min(self.n_theta - 1) * self.n_phi + sector.min(self.n_phi - 1)
    }

    /// The integral of `pdf` over every cell. The product Gauss–Legendre rule has the cell
    /// edges as panel breaks and is further refined around the given lobe centres, so each
    /// node lies strictly inside one cell and narrow lobes get enough nodes.
    pub fn integrate(
        &self,
        pdf: impl Fn([f64; 3]) -> f64,
        theta_centres: &[(f64, f64)],
        phi_centres: &[(f64, f64)],
        max_panel: f64,
        gl: &GaussLegendre,
    ) -> Vec<f64> {
        let rule = SphereRule::new(
            theta_centres,
            phi_centres,
            &self.theta_edges(),
            &self.phi_edges(),
            max_panel,
            gl,
        );
        let mut out = vec![0.0; self.cells()];
        for &(t, wt) in &rule.theta {
            let (st, ct) = t.sin_cos();
            for &(p, wp) in &rule.phi {
                let (sp, cp) = p.sin_cos();
                let w = [st, ct * cp, ct * sp];
                out[self.cell(w)] += wt * wp * pdf(w);
            }
        }
        out
    }
}

/// Outcome of a Pearson test.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    pub statistic: f64,
    /// Degrees of freedom: (cells used after pooling) - 1.
    pub dof: usize,
    pub p_value: f64,
    /// Cells merged into the pool because their expected count was below the minimum.
    pub pooled_cells: usize,
}

/// Pearson's chi-square of `observed` against `expected` counts. Cells are taken in
/// increasing expected count; those below `min_expected` go into one pool, which keeps
/// absorbing cells until its own expectation reaches `min_expected` (as Mitsuba does).
/// Samples in cells of zero expectation make the p-value 0.
pub fn pearson(observed: &[f64], expected: &[f64], min_expected: f64) -> Chi2Result {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut stat, mut dof) = (0.0, 0usize);
    let (mut pool_obs, mut pool_exp, mut pooled) = (0.0, 0.0, 0usize);
    let mut impossible = 0.0;
    for i in order {
        let (o, e) = (observed[i], expected[i]);
        if e <= 0.0 {
            impossible += o;
        } else if e < min_expected || (pool_exp > 0.0 && pool_exp < min_expected) {
            pool_obs += o;
            pool_exp += e;
            pooled += 1;
        } else {
            stat += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pool_exp > 0.0 {
        stat += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        dof += 1;
    }
    let dof = dof.saturating_sub(1).max(1);
    let p_value = if impossible > 0.0 {
        0.0
    } else {
        ChiSquared::new(dof as f64).unwrap().sf(stat)
    };
    Chi2Result {
        statistic: stat,
        dof,
        p_value,
        pooled_cells: pooled,
    }
}

/// Writes the observed and expected tables (one row per theta band) and their
/// difference in standard deviations to `dir/name.txt`; returns the path.
pub fn dump_tables(
    dir: &Path,
    name: &str,
    header: &str,
    grid: &Grid,
    observed: &[f64],
    expected: &[f64],
) -> PathBuf {
    let mut s = String::new();
    writeln!(s, "# {header}").unwrap();
    writeln!(
        s,
        "# {} theta bands (equal sin theta, from -1 up) x {} phi sectors (from -pi)",
        grid.n_theta, grid.n_phi
    )
    .unwrap();
    for (title, table) in [("observed", observed), ("expected", expected)] {
        writeln!(s, "\n## {title}").unwrap();
        for row in table.chunks(grid.n_phi) {
            let line: Vec<String> = row.iter().map(|v| format!("{v:.1}")).collect();
            writeln!(s, "{}", line.join(" ")).unwrap();
        }
    }
    writeln!(s, "\n## (observed - expected) / sqrt(expected)").unwrap();
    for (ro, re) in observed.chunks(grid.n_phi).zip(expected.chunks(grid.n_phi)) {
        let line: Vec<String> = ro
            .iter()
            .zip(re)
            .map(|(o, e)| format!("{:.1}", (o - e) / e.max(1e-300).sqrt()))
            .collect();
        writeln!(s, "{}", line.join(" ")).unwrap();
    }
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(format!("{name}.txt"));
    std::fs::write(&path, s).unwrap();
    path
}
