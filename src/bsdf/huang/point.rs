//! The Huang model at one point (h, wo): the light paths through the section, what each
//! gives toward wi, and the sampler whose density is their sum (module doc of `huang`).

use super::albedo::Side;
use super::section::Section;
use super::{Ggx, HuangBsdf};
use crate::bsdf::fresnel::{fresnel_dielectric, fresnel_inside};
use crate::bsdf::pick::{U_MIN, pick};
use crate::bsdf::{BsdfEval, BsdfSample, LocalBsdf, WeightedSample, inv_cos};
use crate::math::sampling::ONE_MINUS_EPSILON;
use crate::math::{cos_from_sin, hashed_pair};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, TAU};

/// Offsets a far-field point averages.
pub(super) const FAR_SHIFTS: usize = 2;
/// Offsets a far-field point averages where it weighs sampled lights: each light sample's
/// value is the point's estimate of the BSDF toward it, and one draw per interface makes
/// that estimate noisy under small lights (docs/measurements.md, "Offsets where lights
/// are sampled").
pub(super) const LIT_SHIFTS: usize = 4;
/// Below this (y, z) length an internal direction runs along the fibre and never meets
/// the far side: its path is dropped.
const MIN_CROSSING: f32 = 1e-6;
/// Visible normals whose Fresnel the residual averages for the interfaces past TRT.
const ESCAPE_NODES: usize = 3;
/// The least share of the residual's light an interface lets out: a fibre that reflects it
/// totally at every normal keeps its light until absorbed, and none at all would divide
/// zero by zero in the series of a clear fibre.
const MIN_ESCAPE: f32 = 1e-5;

/// Node `k` of the rank-1 lattice of `ESCAPE_NODES` points (generator 2) shifted by `u`,
/// modulo 1.
fn stratum(k: usize, u: [f32; 2]) -> [f32; 2] {
    let n = ESCAPE_NODES as f32;
    [
        modulo_one(u[0] + k as f32 / n),
        modulo_one(u[1] + (2 * k) as f32 / n),
    ]
}

/// x modulo 1, in [0, 1) even where the subtraction rounds up to 1.
fn modulo_one(x: f32) -> f32 {
    (x - x.floor()).min(ONE_MINUS_EPSILON)
}

/// The numbers offset `k` draws its three visible normals from: the entry's, the internal
/// reflection's and the third interface's. Offset 0's entry takes `jitter` (in [0, 1))
/// itself; every other pair is hashed from it, so that each interface draws independently
/// of the others: pairs tied to one another would average to another integral, a bias.
fn numbers(jitter: [f32; 2], k: usize) -> [[f32; 2]; 3] {
    std::array::from_fn(|i| match 3 * k + i {
        0 => jitter,
        n => hashed_pair(jitter, n as u64),
    })
}

/// Where a path meets its last interface from inside: the internal direction reversed
/// (`v`, away from the surface, into the fibre), the inner mesonormal there (`n`),
/// dot(v, n) (> 0 on a path that arrives; 0 marks none) and the path's RGB weight.
#[derive(Debug, Clone, Copy)]
struct Exit {
    v: Vec3,
    n: Vec3,
    cos_vn: f32,
    weight: Vec3,
}

/// The lobes, in the order of a point's sampling weights; TT and TRT also index an
/// offset's exits from 1.
const R: usize = 0;
const TT: usize = 1;
const TRT: usize = 2;
const RESIDUAL: usize = 3;

/// One offset's paths: one visible microfacet normal at each interface, drawn from the
/// point's numbers (module doc of `huang`).
#[derive(Debug, Clone, Copy)]
struct Paths {
    /// The entry's mesonormal.
    m: Vec3,
    /// dot(wo, m); the point sends nothing where it is <= 0.
    cos_om: f32,
    g1_o: f32,
    /// The entry's energy compensation (`albedo`): R's factor, and the first of TT's and
    /// TRT's.
    entry_scale: f32,
    /// TT's exit and TRT's; a path that ends early leaves `cos_vn` 0.
    exits: [Exit; 2],
    /// The residual lobe's RGB energy.
    residual: Vec3,
    /// Probability of sampling R, TT, TRT, the residual.
    lobe_pdf: [f32; 4],
}

/// [`HuangBsdf`] at a point; see [`HuangBsdf::near`] and [`HuangBsdf::far`].
#[derive(Debug, Clone, Copy)]
pub struct HuangPoint {
    bsdf: HuangBsdf,
    wo: Vec3,
    sin_to: f32,
    cos_to: f32,
    /// wo's azimuth as a unit (y, z) direction; y along the tangent.
    azimuth: Vec2,
    /// The offsets' paths; the first `shifts` are used.
    paths: [Paths; LIT_SHIFTS],
    shifts: usize,
}

impl HuangPoint {
    /// The point at the offsets h + 2k / `shifts` (k < `shifts`, wrapped into [-1, 1]).
    pub(super) fn new(
        bsdf: &HuangBsdf,
        h: f32,
        wo: Vec3,
        major: Vec2,
        jitter: [f32; 2],
        shifts: usize,
    ) -> Self {
        let h = if h.is_nan() { 0.0 } else { h.clamp(-1.0, 1.0) };
        let jitter = jitter.map(|x| if x.is_finite() { modulo_one(x) } else { 0.0 });
        let major = major.try_normalize().unwrap_or(Vec2::X);
        let section = Section::new(bsdf.params.aspect, major);
        let azimuth = Vec2::new(wo.y, wo.z).try_normalize().unwrap_or(Vec2::X);
        let sin_to = wo.x.clamp(-1.0, 1.0);
        let mut paths = [Paths::NONE; LIT_SHIFTS];
        for (k, p) in paths.iter_mut().enumerate().take(shifts) {
            let x = h + 2.0 * k as f32 / shifts as f32;
            let x = if x > 1.0 { x - 2.0 } else { x };
            *p = Paths::new(bsdf, &section, x, wo, azimuth, numbers(jitter, k));
        }
        Self {
            bsdf: *bsdf,
            wo,
            sin_to,
            cos_to: cos_from_sin(sin_to),
            azimuth,
            paths,
            shifts,
        }
    }

    /// f and pdf toward the unit direction wi.
    pub fn eval(&self, wi: Vec3) -> BsdfEval {
        let mut f = Vec3::ZERO;
        let mut pdf = 0.0;
        let sin_ti = wi.x.clamp(-1.0, 1.0);
        let residual =
            self.bsdf
                .residual
                .eval(sin_ti, cos_from_sin(sin_ti), self.sin_to, self.cos_to)
                * (0.5 * FRAC_1_PI);
        for p in &self.paths[..self.shifts] {
            let (pf, ppdf) = p.eval(&self.bsdf, self.wo, wi, residual);
            f += pf;
            pdf += ppdf;
        }
        let scale = 1.0 / self.shifts as f32;
        BsdfEval {
            f: f * (scale * inv_cos(wi.z)),
            pdf: pdf * scale,
        }
    }

    /// A direction drawn from `u` in [0, 1)^3: `u[0]` picks the offset (far field), the
    /// lobe and the exit, rescaled after each choice, and then the residual's azimuth;
    /// `u[1]`, `u[2]` the microfacet normal or the residual's theta. None where the density
    /// there is zero or the draw met total internal reflection.
    pub fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        let wi = self.draw(u)?.1.wi;
        let e = self.eval(wi);
        (e.pdf > 0.0 && e.f.is_finite()).then_some(BsdfSample {
            wi,
            f: e.f,
            pdf: e.pdf,
        })
    }

    /// The direction of [`Self::sample`], weighted by the offset and lobe that drew it
    /// alone (`Paths::draw`): no offset or lobe is evaluated at wi. None also where that
    /// weight is zero (a direction the last interface masks).
    pub fn sample_weight(&self, u: [f32; 3]) -> Option<WeightedSample> {
        let (paths, d) = self.draw(u)?;
        let weight = paths.weight(&self.bsdf, &d);
        (weight.is_finite() && weight.max_element() > 0.0)
            .then_some(WeightedSample { wi: d.wi, weight })
    }

    /// The offset `u[0]` picks, and its draw from the rest of `u`.
    fn draw(&self, u: [f32; 3]) -> Option<(&Paths, Drawn)> {
        let n = self.shifts as f32;
        let k = ((u[0] * n) as usize).min(self.shifts - 1);
        let u0 = (u[0] * n - k as f32).clamp(0.0, 1.0);
        let paths = &self.paths[k];
        Some((paths, paths.draw(self, [u0, u[1].max(U_MIN), u[2]])?))
    }

    /// The RGB energy of R, TT, TRT and the residual leaving wo, averaged over the
    /// point's offsets, with the interfaces' energy compensation and without the masking of
    /// the last interface (for the lobes' balance).
    pub fn lobe_energies(&self) -> [Vec3; 4] {
        let mut out = [Vec3::ZERO; 4];
        for p in &self.paths[..self.shifts] {
            let e = p.energies(&self.bsdf);
            for (o, e) in out.iter_mut().zip(e) {
                *o += e / self.shifts as f32;
            }
        }
        out
    }
}

impl LocalBsdf for HuangPoint {
    fn eval(&self, wi: Vec3) -> BsdfEval {
        HuangPoint::eval(self, wi)
    }

    fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        HuangPoint::sample(self, u)
    }

    fn sample_weight(&self, u: [f32; 3]) -> Option<WeightedSample> {
        HuangPoint::sample_weight(self, u)
    }
}

/// The mesonormal over the outward (y, z) normal `n`: tilted toward +x by the cuticle.
fn mesonormal(bsdf: &HuangBsdf, n: Vec2) -> Vec3 {
    let (s, c) = bsdf.tilt;
    Vec3::new(s, c * n.x, c * n.y)
}

/// exp(-sigma_a len) per channel.
fn transmittance(bsdf: &HuangBsdf, len: f32) -> Vec3 {
    let s = bsdf.params.sigma_a;
    Vec3::new(
        (-s[0] * len).exp(),
        (-s[1] * len).exp(),
        (-s[2] * len).exp(),
    )
}

fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) * (1.0 / 3.0)
}

/// Follows the internal direction `d` (travel, unit) from `q` across the section: the
/// exit point, the inner mesonormal there and the transmittance; None when `d` does not
/// cross the section or meets the far side from outside its mesonormal.
fn cross(bsdf: &HuangBsdf, section: &Section, q: Vec2, d: Vec3) -> Option<(Vec2, Vec3, Vec3)> {
    let dyz = Vec2::new(d.y, d.z);
    let len_yz = dyz.length();
    if len_yz < MIN_CROSSING {
        return None;
    }
    let (q2, chord) = section.chord(q, dyz / len_yz)?;
    let n_in = -mesonormal(bsdf, section.normal(q2));
    // The path must reach the far surface from inside (travel against the inner normal).
    (d.dot(n_in) < 0.0).then(|| (q2, n_in, transmittance(bsdf, chord / len_yz)))
}

impl Paths {
    const NONE: Paths = Paths {
        m: Vec3::Z,
        cos_om: 0.0,
        g1_o: 0.0,
        entry_scale: 1.0,
        exits: [Exit {
            v: Vec3::Z,
            n: Vec3::Z,
            cos_vn: 0.0,
            weight: Vec3::ZERO,
        }; 2],
        residual: Vec3::ZERO,
        lobe_pdf: [0.0; 4],
    };

    fn new(
        bsdf: &HuangBsdf,
        section: &Section,
        h: f32,
        wo: Vec3,
        view: Vec2,
        u: [[f32; 2]; 3],
    ) -> Self {
        let q1 = section.entry(view, h);
        let m = mesonormal(bsdf, section.normal(q1));
        let cos_om = wo.dot(m);
        let mut p = Paths::NONE;
        if cos_om.is_nan() || cos_om <= 0.0 {
            return p;
        }
        p.m = m;
        p.cos_om = cos_om;
        p.g1_o = bsdf.ggx.g1(cos_om);
        p.entry_scale = bsdf.albedos.scale(Side::Outside, cos_om);
        // A path that ends early leaves the later exits and the residual dark.
        let _ = p.follow(bsdf, section, q1, wo, u);
        let lobe_sums = [
            fresnel_dielectric(cos_om, bsdf.params.eta).0 * p.entry_scale,
            mean(p.exits[0].weight),
            mean(p.exits[1].weight),
            mean(p.residual),
        ];
        let total: f32 = lobe_sums.iter().sum();
        p.lobe_pdf = lobe_sums.map(|s| s / total);
        p
    }

    /// Follows the light refracted in at `q1` through the visible normal of `u[0]` across
    /// the section (TT's exit), reflected there through `u[1]` on to the third interface
    /// (TRT's), and what that interface reflects through `u[2]` (the residual).
    fn follow(
        &mut self,
        bsdf: &HuangBsdf,
        section: &Section,
        q1: Vec2,
        wo: Vec3,
        u: [[f32; 2]; 3],
    ) -> Option<()> {
        let ggx = &bsdf.ggx;
        let eta = bsdf.params.eta;
        let wh = ggx.sample_visible(self.m, wo, u[0]);
        let c = wo.dot(wh);
        if c <= 0.0 {
            return None;
        }
        // Refraction in: wt travels into the fibre.
        let (_, t) = fresnel_dielectric(c, eta);
        let cos_t = cos_from_sin((1.0 - c * c).max(0.0).sqrt() / eta);
        let wt = -wo / eta + wh * (c / eta - cos_t);
        let cos_tm = wt.dot(self.m);
        if cos_tm >= 0.0 {
            return None;
        }
        let (q2, n2, a1) = cross(bsdf, section, q1, wt)?;
        let v = -wt;
        let cos_vn = v.dot(n2);
        let weight = a1 * (t * ggx.g2_over_g1(self.cos_om, cos_tm));
        // Energy compensation at the entry and at the second interface, which TT leaves by
        // and TRT reflects at; the residual goes without, as in Cycles.
        let scale = self.entry_scale * bsdf.albedos.scale(Side::Inside, cos_vn);
        self.exits[0] = Exit {
            v,
            n: n2,
            cos_vn,
            weight: weight * scale,
        };
        let wh2 = ggx.sample_visible(n2, v, u[1]);
        let c2 = v.dot(wh2);
        if c2 <= 0.0 {
            return None;
        }
        let wr = wh2 * (2.0 * c2) - v;
        let cos_rn = wr.dot(n2);
        if cos_rn <= 0.0 {
            return None;
        }
        let (_, n3, a2) = cross(bsdf, section, q2, wr)?;
        let v3 = -wr;
        let arriving = weight * (fresnel_inside(c2, eta) * ggx.g2_over_g1(cos_vn, cos_rn)) * a2;
        let cos_v3n = v3.dot(n3);
        self.exits[1] = Exit {
            v: v3,
            n: n3,
            cos_vn: cos_v3n,
            weight: arriving * (scale * bsdf.albedos.scale(Side::Inside, cos_v3n)),
        };
        // Past TRT: the third interface reflects the light at one visible normal (its
        // Fresnel, total internal reflection included). That light crosses again and
        // again, each crossing absorbed as the mean of the two before, each interface
        // letting out 1 - F with F averaged over visible normals (a few, stratified from
        // the first): a geometric series. One normal's F would trap all of it wherever
        // that normal reflects totally, and later interfaces meet other normals.
        let seen = ggx.visible_from(n3, v3);
        let fresnel_at = |u: [f32; 2]| fresnel_inside(v3.dot(seen.sample(u)).max(0.0), eta);
        let f3 = fresnel_at(u[2]);
        let f_mean = (1..ESCAPE_NODES)
            .map(|k| fresnel_at(stratum(k, u[2])))
            .sum::<f32>()
            + f3;
        let out = (1.0 - f_mean / ESCAPE_NODES as f32).max(MIN_ESCAPE);
        let a = (a1 * a2).powf(0.5);
        // 1 - a (1 - out), written so that a clear fibre's (a = 1) keeps out's digits.
        let series = a * (out * f3) / (Vec3::ONE - a + a * out);
        if series.is_finite() {
            self.residual = arriving * series;
        }
        Some(())
    }

    /// The RGB energy of each lobe before the last interface's masking.
    fn energies(&self, bsdf: &HuangBsdf) -> [Vec3; 4] {
        if self.cos_om <= 0.0 {
            return [Vec3::ZERO; 4];
        }
        let leaving = |e: &Exit| e.weight * (1.0 - fresnel_inside(e.cos_vn, bsdf.params.eta));
        [
            Vec3::splat(fresnel_dielectric(self.cos_om, bsdf.params.eta).0 * self.entry_scale),
            leaving(&self.exits[0]),
            leaving(&self.exits[1]),
            self.residual,
        ]
    }

    /// f |wi.z| and pdf toward wi at this offset; `residual` the residual lobe's Mp Np.
    fn eval(&self, bsdf: &HuangBsdf, wo: Vec3, wi: Vec3, residual: f32) -> (Vec3, f32) {
        if self.cos_om <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let ggx = &bsdf.ggx;
        let mut f = Vec3::ZERO;
        let mut pdf = 0.0;
        // R: reflection from the visible normals of the mesonormal.
        if let Some(wh) = (wo + wi).try_normalize() {
            let pdf_r = self.g1_o * ggx.d(wh.dot(self.m)) / (4.0 * self.cos_om);
            let cos_im = wi.dot(self.m);
            if cos_im > 0.0 {
                let fr = fresnel_dielectric(wo.dot(wh).clamp(0.0, 1.0), bsdf.params.eta).0;
                let unmasked = ggx.g2_over_g1(self.cos_om, cos_im) * self.entry_scale;
                f += Vec3::splat(fr * unmasked * pdf_r);
            }
            pdf += self.lobe_pdf[R] * pdf_r;
        }
        for (e, lobe) in self.exits.iter().zip([TT, TRT]) {
            if e.cos_vn <= 0.0 {
                continue;
            }
            let (p, t) = refraction_out(ggx, bsdf.params.eta, e, wi);
            f += e.weight * (t * p);
            pdf += self.lobe_pdf[lobe] * p;
        }
        f += self.residual * residual;
        pdf += self.lobe_pdf[RESIDUAL] * residual;
        (f, pdf)
    }

    /// A direction from this offset's lobes: what [`Self::weight`] needs of it. None where
    /// a refraction out meets total internal reflection, or nothing leaves.
    fn draw(&self, point: &HuangPoint, u: [f32; 3]) -> Option<Drawn> {
        if self.cos_om <= 0.0 {
            return None;
        }
        let bsdf = &point.bsdf;
        let (ggx, eta) = (&bsdf.ggx, bsdf.params.eta);
        let (lobe, u0) = pick(&self.lobe_pdf, u[0]);
        let (wi, cos) = match lobe {
            R => {
                let wh = ggx.sample_visible(self.m, point.wo, [u[1], u[2]]);
                let c = point.wo.dot(wh);
                (wh * (2.0 * c) - point.wo, c)
            }
            RESIDUAL => {
                let (sin_ti, cos_ti) =
                    bsdf.residual
                        .sample(point.sin_to, point.cos_to, [u[1], u[2]]);
                let (s, c) = (TAU * u0).sin_cos();
                let a = point.azimuth;
                let wi = Vec3::new(
                    sin_ti,
                    cos_ti * (a.x * c - a.y * s),
                    cos_ti * (a.y * c + a.x * s),
                );
                (wi, 0.0)
            }
            _ => {
                let e = &self.exits[lobe - TT];
                if e.cos_vn <= 0.0 {
                    return None;
                }
                let wh = ggx.sample_visible(e.n, e.v, [u[1], u[2]]);
                (refract_out(eta, e.v, wh)?, e.v.dot(wh))
            }
        };
        Some(Drawn { wi, lobe, cos })
    }

    /// The weight of `d` from the lobe that drew it alone: f_l |cos| / (P(l) pdf_l), with
    /// f_l and pdf_l the lobe's terms of [`Self::eval`], which each lobe's draw follows
    /// exactly (the visible normals' density, the residual's longitudinal lobe), so the
    /// weight is the lobe's energy toward wi over P(l): R's Fresnel and unmasked share
    /// times the entry's compensation, an exit's weight (its compensations in it) and
    /// unmasked share out, the residual's energy. Its mean is the mixture's.
    fn weight(&self, bsdf: &HuangBsdf, d: &Drawn) -> Vec3 {
        let (ggx, eta) = (&bsdf.ggx, bsdf.params.eta);
        let energy = match d.lobe {
            R => {
                let cos_im = d.wi.dot(self.m);
                let unmasked = if cos_im > 0.0 {
                    ggx.g2_over_g1(self.cos_om, cos_im) * self.entry_scale
                } else {
                    0.0
                };
                Vec3::splat(fresnel_dielectric(d.cos.clamp(0.0, 1.0), eta).0 * unmasked)
            }
            RESIDUAL => self.residual,
            lobe => {
                let e = &self.exits[lobe - TT];
                e.weight * leaving(ggx, eta, e, d.cos, d.wi)
            }
        };
        energy / self.lobe_pdf[d.lobe]
    }
}

/// A direction [`Paths::draw`] drew, the lobe that drew it, and the cosine of the
/// microfacet it went through: with wo for R, with the inside direction for an exit (0 for
/// the residual, which has none).
#[derive(Debug, Clone, Copy)]
struct Drawn {
    wi: Vec3,
    lobe: usize,
    cos: f32,
}

/// The share of the light refracted out at the exit `e` through a microfacet at cosine
/// `cv` to its inside direction, toward wi, that leaves unmasked: 1 - F times G2 / G1; 0
/// where wi points back across the mesonormal's plane (drawn, but masked).
fn leaving(ggx: &Ggx, eta: f32, e: &Exit, cv: f32, wi: Vec3) -> f32 {
    let cos_wn = wi.dot(e.n);
    if cos_wn < 0.0 {
        (1.0 - fresnel_inside(cv, eta)) * ggx.g2_over_g1(e.cos_vn, cos_wn)
    } else {
        0.0
    }
}

/// The light of `v` (inside, away from the surface) refracted out through the microfacet
/// normal `wh` (on v's side); None under total internal reflection.
fn refract_out(eta: f32, v: Vec3, wh: Vec3) -> Option<Vec3> {
    let c = v.dot(wh);
    let sin2_t = eta * eta * (1.0 - c * c);
    if c <= 0.0 || sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-v * eta + wh * (eta * c - cos_t))
}

/// At the exit `e`, toward wi outside: the density of a refraction out through a
/// visible microfacet (`refract_out` of [`Ggx::sample_visible`]) and the fraction of the
/// light it carries that leaves unmasked, 1 - F times G2 / G1.
fn refraction_out(ggx: &Ggx, eta: f32, e: &Exit, wi: Vec3) -> (f32, f32) {
    // The generalised half vector of a refraction from index eta into 1, on v's side.
    let Some(mut wh) = (-(e.v * eta + wi)).try_normalize() else {
        return (0.0, 0.0);
    };
    if wh.dot(e.n) < 0.0 {
        wh = -wh;
    }
    let cv = e.v.dot(wh);
    let cw = wi.dot(wh);
    if cv <= 0.0 || cw >= 0.0 {
        return (0.0, 0.0);
    }
    let denom = eta * cv + cw;
    let pdf = ggx.visible_pdf(e.n, e.v, wh) * (-cw) / (denom * denom);
    let leaves = leaving(ggx, eta, e, cv, wi);
    // Not finite only where the half vector degenerates (denom = 0).
    if pdf.is_finite() {
        (pdf, leaves)
    } else {
        (0.0, 0.0)
    }
}
