//! An f64 reference of the Huang model, written from the model's description
//! (docs/conventions.md, section 4b) rather than from the crate's code: the section as a
//! parametric ellipse with its quadratics solved directly (the crate maps it to a unit
//! circle), Fresnel from Snell's cosines, and every vector in f64. It takes the same
//! numbers (the jitter and those the description hashes from it), so the two agree up to
//! rounding.
//! The BSDF tests (tests/bsdf/huang/reference.rs) and `hairtrace report`'s BSDF section
//! both judge the f32 model by it.

use glam::Vec3;
use std::f64::consts::PI;
use std::sync::OnceLock;

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn norm(a: V3) -> V3 {
    mul(a, 1.0 / dot(a, a).sqrt())
}

#[derive(Clone, Copy)]
struct Model {
    sigma: V3,
    eta: f64,
    a: f64,
    aspect: f64,
    tilt: f64,
    major: [f64; 2],
}

impl Model {
    fn d(&self, c: f64) -> f64 {
        if c <= 0.0 {
            return 0.0;
        }
        let a2 = self.a * self.a;
        let k = c * c * (a2 - 1.0) + 1.0;
        a2 / (PI * k * k)
    }
    fn lambda(&self, c: f64) -> f64 {
        let c2 = c * c;
        let tan2 = (1.0 - c2) / c2;
        ((1.0 + self.a * self.a * tan2).sqrt() - 1.0) / 2.0
    }
    fn g1(&self, c: f64) -> f64 {
        1.0 / (1.0 + self.lambda(c))
    }
    fn g2_g1(&self, cv: f64, cw: f64) -> f64 {
        let (lv, lw) = (self.lambda(cv), self.lambda(cw));
        (1.0 + lv) / (1.0 + lv + lw)
    }
    /// Fresnel for light in a medium of index n1 meeting one of n2.
    fn fresnel(cos_i: f64, n1: f64, n2: f64) -> f64 {
        let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).max(0.0).sqrt();
        if sin_t >= 1.0 {
            return 1.0;
        }
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
        let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
        0.5 * (rs * rs + rp * rp)
    }
    /// A visible normal by spherical caps, in an orthonormal frame around n built as glam
    /// builds it (the frame does not change the distribution, only which node is which).
    fn visible(&self, n: V3, v: V3, u: [f64; 2]) -> V3 {
        let (t, b) = {
            let nv = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
            let (x, y) = nv.any_orthonormal_pair();
            let f = |w: Vec3| [w.x as f64, w.y as f64, w.z as f64];
            (f(x), f(y))
        };
        let vl = [dot(v, t), dot(v, b), dot(v, n)];
        let vh = norm([self.a * vl[0], self.a * vl[1], vl[2]]);
        let phi = 2.0 * PI * u[0];
        let z = (1.0 - u[1]) * (1.0 + vh[2]) - vh[2];
        let s = (1.0 - z * z).max(0.0).sqrt();
        let h = add([s * phi.cos(), s * phi.sin(), z], vh);
        let m = norm([self.a * h[0], self.a * h[1], h[2].max(0.0)]);
        add(add(mul(t, m[0]), mul(b, m[1])), mul(n, m[2]))
    }
    fn visible_pdf(&self, n: V3, v: V3, m: V3) -> f64 {
        let (vn, vm) = (dot(v, n), dot(v, m));
        if vn <= 0.0 || vm <= 0.0 {
            return 0.0;
        }
        self.g1(vn) * vm * self.d(dot(m, n)) / vn
    }
    /// (x, y) along the major and minor axes of a (y, z) point.
    fn axes(&self, p: [f64; 2]) -> [f64; 2] {
        let [c, s] = self.major;
        [p[0] * c + p[1] * s, -p[0] * s + p[1] * c]
    }
    fn point_of(&self, q: [f64; 2]) -> [f64; 2] {
        let [c, s] = self.major;
        [q[0] * c - q[1] * s, q[0] * s + q[1] * c]
    }
    fn meso(&self, p: [f64; 2]) -> V3 {
        let q = self.axes(p);
        let g = self.point_of([q[0], q[1] / (self.aspect * self.aspect)]);
        let l = (g[0] * g[0] + g[1] * g[1]).sqrt();
        [
            self.tilt.sin(),
            self.tilt.cos() * g[0] / l,
            self.tilt.cos() * g[1] / l,
        ]
    }
    /// The second root of the ellipse along the unit direction d from p on it.
    fn chord(&self, p: [f64; 2], d: [f64; 2]) -> Option<([f64; 2], f64)> {
        let (q, e) = (self.axes(p), self.axes(d));
        let b2 = self.aspect * self.aspect;
        let t = -2.0 * (q[0] * e[0] + q[1] * e[1] / b2) / (e[0] * e[0] + e[1] * e[1] / b2);
        (t > 0.0).then(|| ([p[0] + t * d[0], p[1] + t * d[1]], t))
    }
    fn cross(&self, p: [f64; 2], d: V3) -> Option<([f64; 2], V3, V3)> {
        let l = (d[1] * d[1] + d[2] * d[2]).sqrt();
        if l < 1e-6 {
            return None;
        }
        let (p2, t) = self.chord(p, [d[1] / l, d[2] / l])?;
        let n = mul(self.meso(p2), -1.0);
        let len = t / l;
        (dot(d, n) < 0.0).then(|| (p2, n, self.sigma.map(|s| (-s * len).exp())))
    }
    fn refract_pdf(&self, v: V3, n: V3, wi: V3) -> (f64, f64) {
        let eta = self.eta;
        let mut wh = norm(mul(add(mul(v, eta), wi), -1.0));
        if dot(wh, n) < 0.0 {
            wh = mul(wh, -1.0);
        }
        let (cv, cw) = (dot(v, wh), dot(wi, wh));
        if cv <= 0.0 || cw >= 0.0 {
            return (0.0, 0.0);
        }
        let den = eta * cv + cw;
        let pdf = self.visible_pdf(n, v, wh) * -cw / (den * den);
        let cwn = dot(wi, n);
        let leaves = if cwn < 0.0 {
            (1.0 - Self::fresnel(cv, eta, 1.0)) * self.g2_g1(dot(v, n), cwn.abs())
        } else {
            0.0
        };
        (pdf, leaves)
    }

    /// f |wi.z| and pdf at the offset h: the model of section 4b, term by term.
    fn eval(&self, h: f64, wo: V3, wi: V3, u: [[f64; 2]; 3], residual_mp: f64) -> (V3, f64) {
        let vl = (wo[1] * wo[1] + wo[2] * wo[2]).sqrt();
        let view = if vl > 0.0 {
            [wo[1] / vl, wo[2] / vl]
        } else {
            [1.0, 0.0]
        };
        let across = [view[1], -view[0]];
        let e = self.axes(across);
        let b = self.aspect;
        let half = (e[0] * e[0] + b * b * e[1] * e[1]).sqrt();
        // (x0 + t vx)^2 + ((y0 + t vy) / b)^2 = 1 for the point s across + t view.
        let x0 = self.axes([across[0] * h * half, across[1] * h * half]);
        let vv = self.axes(view);
        let qa = vv[0] * vv[0] + vv[1] * vv[1] / (b * b);
        let qb = 2.0 * (x0[0] * vv[0] + x0[1] * vv[1] / (b * b));
        let qc = x0[0] * x0[0] + x0[1] * x0[1] / (b * b) - 1.0;
        let t = (-qb + (qb * qb - 4.0 * qa * qc).max(0.0).sqrt()) / (2.0 * qa);
        let p1 = self.point_of([x0[0] + t * vv[0], x0[1] + t * vv[1]]);
        let m = self.meso(p1);
        let com = dot(wo, m);
        if com <= 0.0 {
            return ([0.0; 3], 0.0);
        }
        let eta = self.eta;
        let mut exits: Vec<(V3, V3, V3, bool)> = Vec::new();
        let mut residual = [0.0; 3];
        // One visible normal per interface, each from its own numbers; a path that ends
        // leaves the later lobes dark.
        'path: {
            let wh = self.visible(m, wo, u[0]);
            let c = dot(wo, wh);
            if c <= 0.0 {
                break 'path;
            }
            let t1 = 1.0 - Self::fresnel(c, 1.0, eta);
            let cos_t = (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
            let wt = add(mul(wo, -1.0 / eta), mul(wh, c / eta - cos_t));
            let ctm = dot(wt, m);
            if ctm >= 0.0 {
                break 'path;
            }
            let w_in = t1 * self.g2_g1(com, ctm.abs());
            let Some((p2, n2, a1)) = self.cross(p1, wt) else {
                break 'path;
            };
            let v = mul(wt, -1.0);
            let w = mul(a1, w_in);
            // Compensation at the entry and the second interface (not the residual's).
            let s12 = self.scale(false, com) * self.scale(true, dot(v, n2));
            exits.push((v, n2, mul(w, s12), true));
            let wh2 = self.visible(n2, v, u[1]);
            let c2 = dot(v, wh2);
            if c2 <= 0.0 {
                break 'path;
            }
            let wr = add(mul(wh2, 2.0 * c2), mul(v, -1.0));
            let crn = dot(wr, n2);
            if crn <= 0.0 {
                break 'path;
            }
            let w_r = Self::fresnel(c2, eta, 1.0) * self.g2_g1(dot(v, n2), crn);
            let Some((_, n3, a2)) = self.cross(p2, wr) else {
                break 'path;
            };
            let v3 = mul(wr, -1.0);
            let arriving: V3 = std::array::from_fn(|c| w[c] * w_r * a2[c]);
            let s123 = s12 * self.scale(true, dot(v3, n3));
            exits.push((v3, n3, mul(arriving, s123), false));
            // The third interface reflects at u[2]'s normal; later ones let out 1 - F, F
            // averaged over three normals: u[2] and the two lattice points past it.
            let wrap = |x: f64| x - x.floor();
            let fresnel_at =
                |u: [f64; 2]| Self::fresnel(dot(v3, self.visible(n3, v3, u)).max(0.0), eta, 1.0);
            let f3 = fresnel_at(u[2]);
            let f_mean = (0..3)
                .map(|k| {
                    fresnel_at([
                        wrap(u[2][0] + k as f64 / 3.0),
                        wrap(u[2][1] + (2 * k) as f64 / 3.0),
                    ])
                })
                .sum::<f64>()
                / 3.0;
            let out = (1.0 - f_mean).max(1e-5);
            for c in 0..3 {
                let a = (a1[c] * a2[c]).sqrt();
                let s = a * out * f3 / (1.0 - a + a * out);
                if s.is_finite() {
                    residual[c] += arriving[c] * s;
                }
            }
        }
        let mean = |v: V3| (v[0] + v[1] + v[2]) / 3.0;
        let s1 = self.scale(false, com);
        let sums = [
            Self::fresnel(com, 1.0, eta) * s1,
            exits.iter().filter(|e| e.3).map(|e| mean(e.2)).sum::<f64>(),
            exits
                .iter()
                .filter(|e| !e.3)
                .map(|e| mean(e.2))
                .sum::<f64>(),
            mean(residual),
        ];
        let total: f64 = sums.iter().sum();
        let mut f = [0.0; 3];
        let mut pdf = 0.0;
        let hv = add(wo, wi);
        if dot(hv, hv) > 0.0 {
            let wh = norm(hv);
            let pdf_r = self.g1(com) * self.d(dot(wh, m)) / (4.0 * com);
            let cim = dot(wi, m);
            if cim > 0.0 {
                let fr = Self::fresnel(dot(wo, wh), 1.0, eta) * self.g2_g1(com, cim) * s1 * pdf_r;
                f = f.map(|x| x + fr);
            }
            pdf += sums[0] / total * pdf_r;
        }
        for (v, n, w, tt) in &exits {
            let (p, t) = self.refract_pdf(*v, *n, wi);
            for c in 0..3 {
                f[c] += w[c] * t * p;
            }
            let lobe = if *tt { sums[1] } else { sums[2] };
            pdf += mean(*w) / total * p * if lobe > 0.0 { 1.0 } else { 0.0 };
        }
        for c in 0..3 {
            f[c] += residual[c] * residual_mp;
        }
        pdf += sums[3] / total * residual_mp;
        (f, pdf)
    }
}

/// The energy compensation's tables (section 4b): an interface's directional albedo E over
/// nodes of sqrt(roughness) in [0, 1], the cosine of the light to its normal in [0, 1] (the
/// first node 1e-3) and eta in [1, 3], each the mean over 32 x 32 cell centres of visible
/// normals of what leaves unmasked (reflected F, refracted 1 - F, each times G2 / G1), for
/// light from outside and from inside; linear between nodes.
const NODES: usize = 16;
struct Albedo {
    outside: Vec<f64>,
    inside: Vec<f64>,
}

fn albedo_tables() -> &'static Albedo {
    static TABLES: OnceLock<Albedo> = OnceLock::new();
    TABLES.get_or_init(|| {
        let node = |i: usize| i as f64 / (NODES - 1) as f64;
        let table = |inside: bool| {
            let mut t = Vec::with_capacity(NODES * NODES * NODES);
            for r in 0..NODES {
                for c in 0..NODES {
                    for e in 0..NODES {
                        t.push(node_albedo(
                            inside,
                            node(r),
                            node(c).max(1e-3),
                            1.0 + 2.0 * node(e),
                        ));
                    }
                }
            }
            t
        };
        Albedo {
            outside: table(false),
            inside: table(true),
        }
    })
}

fn node_albedo(inside: bool, sqrt_a: f64, cos: f64, eta: f64) -> f64 {
    let a = sqrt_a * sqrt_a;
    if a <= 0.0 {
        return 1.0;
    }
    let model = Model {
        sigma: [0.0; 3],
        eta,
        a,
        aspect: 1.0,
        tilt: 0.0,
        major: [1.0, 0.0],
    };
    let (n1, n2) = if inside { (eta, 1.0) } else { (1.0, eta) };
    let n = [0.0, 0.0, 1.0];
    let v = [(1.0 - cos * cos).sqrt(), 0.0, cos];
    let strata = 32;
    let mut sum = 0.0;
    for i in 0..strata {
        for j in 0..strata {
            let u = [
                (i as f64 + 0.5) / strata as f64,
                (j as f64 + 0.5) / strata as f64,
            ];
            // The crate's cell centres are f32: the same numbers, the same normals.
            let m = model.visible(n, v, [f64::from(u[0] as f32), f64::from(u[1] as f32)]);
            let c = dot(v, m);
            if c <= 0.0 {
                continue;
            }
            let f = Model::fresnel(c, n1, n2);
            let r = add(mul(m, 2.0 * c), mul(v, -1.0));
            if r[2] > 0.0 {
                sum += f * model.g2_g1(cos, r[2]);
            }
            let k = n1 / n2;
            let sin2_t = k * k * (1.0 - c * c);
            if sin2_t < 1.0 {
                let t = add(mul(v, -k), mul(m, k * c - (1.0 - sin2_t).sqrt()));
                if t[2] < 0.0 {
                    sum += (1.0 - f) * model.g2_g1(cos, t[2].abs());
                }
            }
        }
    }
    sum / (strata * strata) as f64
}

impl Model {
    /// 1 / E for light from outside or inside at cosine `cos` to an interface's normal.
    fn scale(&self, inside: bool, cos: f64) -> f64 {
        let t = albedo_tables();
        let t = if inside { &t.inside } else { &t.outside };
        let between = |x: f64| {
            let s = x.clamp(0.0, 1.0) * (NODES - 1) as f64;
            let i = (s as usize).min(NODES - 2);
            (i, s - i as f64)
        };
        let (r, wr) = between(self.a.sqrt());
        let (c, wc) = between(cos);
        let (e, we) = between((self.eta - 1.0) / 2.0);
        let mut sum = 0.0;
        for (dr, fr) in [(0, 1.0 - wr), (1, wr)] {
            for (dc, fc) in [(0, 1.0 - wc), (1, wc)] {
                for (de, fe) in [(0, 1.0 - we), (1, we)] {
                    sum += fr * fc * fe * t[((r + dr) * NODES + c + dc) * NODES + e + de];
                }
            }
        }
        1.0 / sum
    }
}

/// The Huang model for one parameter set, in f64, its tilt in degrees as `HuangParams`
/// takes it.
#[derive(Clone, Copy)]
pub struct RefHuang(Model);

impl RefHuang {
    pub fn new(sigma_a: V3, eta: f64, roughness: f64, aspect: f64, alpha_deg: f64) -> Self {
        Self(Model {
            sigma: sigma_a,
            eta,
            a: roughness,
            aspect,
            tilt: alpha_deg.to_radians(),
            major: [1.0, 0.0],
        })
    }

    /// f |wi.z| and pdf of the point of `shifts` offsets at h seen from wo: the near one
    /// (1) or a far one (the mean over the offsets h + 2k / shifts, wrapped, formed in f32
    /// as the crate forms them), the section's major axis along the unit (y, z) direction
    /// `major`.
    pub fn eval(
        &self,
        shifts: usize,
        h: f32,
        wo: V3,
        wi: V3,
        major: [f64; 2],
        jitter: [f32; 2],
    ) -> (V3, f64) {
        let model = Model { major, ..self.0 };
        let residual = mp(4.0 * model.a, wi[0], wo[0]) / (2.0 * PI);
        let (mut f, mut pdf) = ([0.0; 3], 0.0);
        for k in 0..shifts {
            let x = f64::from(h + 2.0 * k as f32 / shifts as f32);
            let x = if x > 1.0 { x - 2.0 } else { x };
            let (kf, kpdf) = model.eval(x, wo, wi, numbers(jitter, k), residual);
            for c in 0..3 {
                f[c] += kf[c] / shifts as f64;
            }
            pdf += kpdf / shifts as f64;
        }
        (f, pdf)
    }
}

/// The numbers of offset `k`'s three interfaces (section 4b): the jitter for offset 0's
/// entry, and for the others the two 24-bit halves of SplitMix64's finaliser of the
/// jitter's bits (first << 32 | second) xor (3k + interface) x 0x9e3779b97f4a7c15.
fn numbers(jitter: [f32; 2], k: usize) -> [[f64; 2]; 3] {
    let key = (u64::from(jitter[0].to_bits()) << 32) | u64::from(jitter[1].to_bits());
    std::array::from_fn(|i| {
        let n = (3 * k + i) as u64;
        if n == 0 {
            return jitter.map(f64::from);
        }
        let mut z = key ^ n.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        [
            (z >> 40) as f64 / 16777216.0,
            ((z << 24) >> 40) as f64 / 16777216.0,
        ]
    })
}

/// Chiang's longitudinal lobe (d'Eon's Mp) of variance v, untilted, in f64.
fn mp(v: f64, sin_ti: f64, sin_to: f64) -> f64 {
    let (cos_ti, cos_to) = (
        (1.0 - sin_ti * sin_ti).sqrt(),
        (1.0 - sin_to * sin_to).sqrt(),
    );
    let a = cos_ti * cos_to / v;
    let i0_scaled = {
        // e^-a I0(a) by its series (a small) or asymptotics (a large).
        if a < 20.0 {
            let (mut term, mut sum) = (1.0f64, 1.0f64);
            for k in 1..200 {
                term *= (a / 2.0) * (a / 2.0) / (k as f64 * k as f64);
                sum += term;
            }
            sum * (-a).exp()
        } else {
            let mut s = 1.0;
            let mut term = 1.0;
            for k in 1..6 {
                let k2 = (2 * k - 1) as f64;
                term *= k2 * k2 / (8.0 * a * k as f64);
                s += term;
            }
            s / (2.0 * PI * a).sqrt()
        }
    };
    // exp(-sin ti sin to / v) I0(a) / (2 v sinh(1/v)), with the exponent gathered.
    let e = -sin_ti * sin_to / v - 1.0 / v + a;
    e.exp() * i0_scaled / (v * (1.0 - (-2.0 / v).exp()))
}
