//! Deterministic quadrature: Gauss–Legendre rules and composite rules whose panels are
//! refined around known lobe centres (the hair lobes are as narrow as ~0.004 rad, so a
//! uniform rule would either miss them or cost millions of nodes).

use std::f64::consts::PI;

/// An n-point Gauss–Legendre rule on [-1, 1].
#[derive(Clone, Debug)]
pub struct GaussLegendre {
    pub x: Vec<f64>,
    pub w: Vec<f64>,
}

/// Nodes and weights of the n-point Gauss–Legendre rule, by Newton's method on P_n
/// (converged to machine precision; exact for polynomials of degree 2n - 1).
pub fn gauss_legendre(n: usize) -> GaussLegendre {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = nf * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        w[n - 1 - i] = w[i];
    }
    if n % 2 == 1 {
        x[n / 2] = 0.0;
    }
    GaussLegendre { x, w }
}

/// Offsets (in units of a lobe's width) at which panels break around a lobe centre.
const OFFSETS: [f64; 8] = [0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 16.0, 32.0];

/// Sorted breakpoints on [a, b]: the ends, `centre +- k * width` for k in a geometric-ish
/// sequence around every `(centre, width)`, any `extra` points (e.g. histogram cell edges),
/// then every panel longer than `max_panel` split evenly. With `periodic` the centres are
/// also repeated at +-(b - a), and the antipode of each centre (where a wrapped lobe has
/// a kink) is a breakpoint too.
pub fn breakpoints(
    a: f64,
    b: f64,
    centres: &[(f64, f64)],
    extra: &[f64],
    max_panel: f64,
    periodic: bool,
) -> Vec<f64> {
    let mut pts = vec![a, b];
    pts.extend(extra.iter().copied().filter(|&x| x > a && x < b));
    let period = b - a;
    for &(c0, width) in centres {
        let shifts: &[f64] = if periodic { &[-1.0, 0.0, 1.0] } else { &[0.0] };
        for &k in shifts {
            let c = c0 + k * period;
            pts.push(c);
            if periodic {
                // The wrapped lobe has a kink half a period away from its centre.
                pts.push(c + 0.5 * period);
            }
            for &o in &OFFSETS {
                pts.push(c - o * width);
                pts.push(c + o * width);
            }
        }
    }
    pts.retain(|&x| x >= a && x <= b && x.is_finite());
    pts.sort_by(f64::total_cmp);
    pts.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
    let mut out = vec![pts[0]];
    for win in pts.windows(2) {
        let (l, r) = (win[0], win[1]);
        let n = ((r - l) / max_panel).ceil().max(1.0) as usize;
        for k in 1..=n {
            out.push(if k == n {
                r
            } else {
                l + (r - l) * k as f64 / n as f64
            });
        }
    }
    out
}

/// The composite rule over the panels given by sorted `breaks`: `(node, weight)` pairs.
pub fn composite(breaks: &[f64], gl: &GaussLegendre) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(breaks.len() * gl.x.len());
    for win in breaks.windows(2) {
        let (l, r) = (win[0], win[1]);
        let half = 0.5 * (r - l);
        let mid = 0.5 * (r + l);
        for (x, w) in gl.x.iter().zip(&gl.w) {
            out.push((mid + half * x, half * w));
        }
    }
    out
}

/// Integral of f over [a, b] with panels refined around `centres` (see [`breakpoints`]).
pub fn integrate_1d(
    f: impl Fn(f64) -> f64,
    a: f64,
    b: f64,
    centres: &[(f64, f64)],
    max_panel: f64,
    gl: &GaussLegendre,
) -> f64 {
    let br = breakpoints(a, b, centres, &[], max_panel, false);
    composite(&br, gl).iter().map(|&(x, w)| w * f(x)).sum()
}

/// A product rule over the sphere in (theta, phi), theta in [-pi/2, pi/2] measured from the
/// y-z plane (so d omega = cos(theta) d theta d phi), phi in [-pi, pi]: nodes with their
/// full solid-angle weight (cos(theta) included).
#[derive(Clone, Debug)]
pub struct SphereRule {
    /// (theta, weight) with the cos(theta) factor folded in.
    pub theta: Vec<(f64, f64)>,
    /// (phi, weight).
    pub phi: Vec<(f64, f64)>,
}

impl SphereRule {
    /// Panels refined around the given theta and phi lobe centres (see [`breakpoints`]);
    /// `theta_extra` / `phi_extra` add breakpoints (cell edges).
    pub fn new(
        theta_centres: &[(f64, f64)],
        phi_centres: &[(f64, f64)],
        theta_extra: &[f64],
        phi_extra: &[f64],
        max_panel: f64,
        gl: &GaussLegendre,
    ) -> Self {
        let tb = breakpoints(
            -0.5 * PI,
            0.5 * PI,
            theta_centres,
            theta_extra,
            max_panel,
            false,
        );
        let pb = breakpoints(-PI, PI, phi_centres, phi_extra, max_panel, true);
        let theta = composite(&tb, gl)
            .into_iter()
            .map(|(t, w)| (t, w * t.cos()))
            .collect();
        SphereRule {
            theta,
            phi: composite(&pb, gl),
        }
    }

    /// Integral of f(direction) d omega over the sphere.
    pub fn integrate(&self, f: impl Fn([f64; 3]) -> f64) -> f64 {
        self.integrate_n(|w| [f(w)])[0]
    }

    /// Integrals of the N components of f(direction) d omega over the sphere, from one
    /// pass over the nodes.
    pub fn integrate_n<const N: usize>(&self, f: impl Fn([f64; 3]) -> [f64; N]) -> [f64; N] {
        let mut total = [0.0; N];
        for &(t, wt) in &self.theta {
            let (st, ct) = t.sin_cos();
            let mut row = [0.0; N];
            for &(p, wp) in &self.phi {
                let (sp, cp) = p.sin_cos();
                let v = f([st, ct * cp, ct * sp]);
                for k in 0..N {
                    row[k] += wp * v[k];
                }
            }
            for k in 0..N {
                total[k] += wt * row[k];
            }
        }
        total
    }
}
