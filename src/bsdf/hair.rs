//! The Chiang et al. 2016 near-field hair BSDF: lobes R, TT and TRT with their own
//! longitudinal (Mp), attenuation (Ap) and azimuthal (Np) terms, plus a residual lobe
//! that carries all higher orders of internal reflection.
//!
//! Frame and conventions are those of docs/conventions.md: x is the fiber tangent, h the signed
//! offset across the fiber, `f` includes the 1/|wi.z| of pbrt's convention.
//!
//! Work is split by what it depends on: [`HairBsdf::new`] computes everything that
//! depends on the parameters alone; `Outgoing` what depends on (h, wo) (Fresnel,
//! absorption, the lobes' azimuthal centres), shared by sampling and evaluation; the per-wi part is
//! the four lobes. Both stages are generic over [`Lanes`], so `eval_batch` runs the same
//! code eight inputs at a time.
//!
//! A point may also evaluate less than the whole model ([`Lobes`]): the renderer's two
//! fidelity knobs, lobe culling and the merged lobe of deep bounces (docs/measurements.md, "Speed
//! against error", has what each costs and buys).

use super::azimuthal::{TrimmedLogistic, azimuthal_scale};
use super::fresnel::fresnel_dielectric;
use super::longitudinal::{LongitudinalLobe, MpConstants, longitudinal_variance};
use super::params::HairParams;
use super::pick::{U_MIN, pick};
use super::{BsdfEval, BsdfSample, LocalBsdf, MIN_COS_WI, WeightedSample, inv_cos};
use crate::error::{Result, invalid_arg};
use crate::math::fast::atan2;
use crate::math::{Lanes, cos_from_sin};
use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, TAU};
use std::mem::MaybeUninit;
use wide::{f32x4, f32x8};

/// Number of explicit lobes (R, TT, TRT); the residual lobe comes after them.
const EXPLICIT_LOBES: usize = 3;

/// The hair BSDF for one parameter set, with every parameter-only constant precomputed.
/// Plain numbers only (`Copy`), so a copy can travel inside a self-contained point.
///
/// A path vertex in a host's integrator: the point once, then eval for the light and a
/// sample for the path. Directions are in the fiber's frame (x along the fiber, z toward
/// the viewer; docs/conventions.md).
///
/// ```
/// use hairtrace::glam::Vec3;
/// use hairtrace::{HairBsdf, HairParams};
/// let bsdf = HairBsdf::new(&HairParams { beta_m: 0.25, ..HairParams::default() })?;
/// let point = bsdf.at(0.5, Vec3::Z); // h = 0.5, seen straight on
/// let light = point.eval(Vec3::new(0.0, 0.6, 0.8)); // toward a light
/// assert!(light.pdf > 0.0 && light.f.min_element() >= 0.0);
/// let next = point.sample([0.3, 0.6, 0.9]).expect("a direction");
/// let weight = next.f * next.wi.z.abs() / next.pdf; // f |cos| / pdf, the path's throughput
/// assert!(weight.is_finite() && (next.wi.length() - 1.0).abs() < 1e-5);
/// # Ok::<(), hairtrace::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairBsdf {
    params: HairParams,
    /// Mp of R, TT, TRT and the residual lobe.
    mp: [LongitudinalLobe; 4],
    /// The same four lobes side by side, for the scalar evaluation.
    mp_packed: MpConstants<f32x4>,
    np: TrimmedLogistic,
    /// (sin, cos) of the cuticle shift of theta_o for R, TT, TRT: -2 alpha, alpha, 4 alpha.
    tilt: [(f32, f32); EXPLICIT_LOBES],
}

/// How much of the model a point evaluates, samples and integrates to.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Lobes {
    /// The whole model.
    #[default]
    All,
    /// The lobes whose attenuation (its largest channel) is below this fraction of the
    /// total's largest channel are dropped from f, pdf and sampling alike (the sampling
    /// renormalised over the lobes kept); the strongest lobe is always kept. 0 keeps
    /// every lobe. Lost energy: the dropped lobes'.
    Culled(f32),
    /// One azimuthally uniform lobe that carries the energy of all four, with the
    /// residual lobe's (widest) longitudinal spread: the same albedo at (h, wo), without
    /// the highlights' shapes. Costs one longitudinal lobe per eval instead of four lobes
    /// and three azimuths: the approximation for deep bounces.
    Merged,
}

/// Everything that depends on (h, wo) but not on wi.
#[derive(Clone, Copy)]
struct Outgoing<T> {
    sin_to: T,
    cos_to: T,
    /// (sin, |cos|) of theta_o shifted by each explicit lobe's cuticle tilt.
    tilted: [(T, T); EXPLICIT_LOBES],
    /// Where each explicit lobe is centred in azimuth, as a (y, z) direction: wo's
    /// azimuth turned by the deflection Phi(p) = 2 p gamma_t - 2 gamma_o + p pi. Kept as a
    /// direction rather than an angle, the offset of wi from it comes from one atan2 of
    /// small cross and dot products, accurate to a few ulps of the offset itself; going
    /// through angles near pi (phi_i - phi_o, 2 gamma_o, pi) costs ulps of pi (2.4e-7 rad),
    /// which a narrow logistic (s = 0.0017) turns into 1.4e-4 relative per ulp.
    centre: [(T, T); EXPLICIT_LOBES],
    /// wo's own azimuth as a (y, z) direction (see [`azimuth_o`]).
    azimuth: (T, T),
    /// Attenuation Ap per lobe and channel.
    ap: [[T; 3]; 4],
    /// Probability of sampling each lobe: its mean attenuation over the total.
    lobe_pdf: [T; 4],
}

impl HairBsdf {
    /// Validates the parameters and precomputes the per-parameter constants.
    pub fn new(params: &HairParams) -> Result<Self> {
        params.validate()?;
        let v = longitudinal_variance(params.beta_m);
        let alpha = f64::from(params.alpha).to_radians();
        let mp = [v, 0.25 * v, 4.0 * v, 4.0 * v].map(LongitudinalLobe::new);
        Ok(Self {
            params: *params,
            mp,
            mp_packed: LongitudinalLobe::pack(&mp),
            np: TrimmedLogistic::new(azimuthal_scale(params.beta_n)),
            tilt: [-2.0 * alpha, alpha, 4.0 * alpha].map(|a| (a.sin() as f32, a.cos() as f32)),
        })
    }

    pub fn params(&self) -> &HairParams {
        &self.params
    }

    /// The BSDF at one shading point: the work that depends on (h, wo) is done once here
    /// and shared by every `eval`, `pdf` and `sample` at that point (next-event
    /// estimation and BSDF sampling of a path vertex use the same point).
    pub fn at(&self, h: f32, wo: Vec3) -> HairPoint<'_> {
        self.at_lobes(h, wo, Lobes::All)
    }

    /// [`Self::at`] with only the lobes `lobes` asks for.
    pub fn at_lobes(&self, h: f32, wo: Vec3, lobes: Lobes) -> HairPoint<'_> {
        HairPoint {
            bsdf: self,
            at: self.vertex(h, wo, lobes),
            whole_h: (lobes == Lobes::All).then_some(h),
        }
    }

    /// The (h, wo) part of a point, without the reference back to the BSDF.
    fn vertex(&self, h: f32, wo: Vec3, lobes: Lobes) -> Vertex {
        let mut o = self.outgoing(h, wo.to_array());
        match lobes {
            Lobes::All => {}
            Lobes::Culled(threshold) => cull(&mut o, threshold),
            Lobes::Merged => merge(&mut o),
        }
        Vertex {
            o,
            merged: lobes == Lobes::Merged,
        }
    }

    /// f and pdf for outgoing wo and incident wi (unit vectors, local frame), h in [-1, 1].
    pub fn eval(&self, h: f32, wo: Vec3, wi: Vec3) -> BsdfEval {
        self.at(h, wo).eval(wi)
    }

    /// Density of [`Self::sample`] at wi (per unit solid angle).
    pub fn pdf(&self, h: f32, wo: Vec3, wi: Vec3) -> f32 {
        self.at(h, wo).eval(wi).pdf
    }

    /// Energy of each lobe (R, TT, TRT, residual) leaving wo at h: the lobes' Mp and Np
    /// integrate to one, so this is Ap.
    pub fn lobe_energies(&self, h: f32, wo: Vec3) -> [Vec3; 4] {
        self.vertex(h, wo, Lobes::All).o.ap.map(Vec3::from_array)
    }

    /// Samples wi: `u[0]` picks the lobe (proportionally to its mean attenuation) and is
    /// then reused, rescaled, for the azimuth; `u[1]` and `u[2]` sample the longitudinal lobe.
    /// Returns None only when the density at the sampled direction is zero.
    pub fn sample(&self, h: f32, wo: Vec3, u: [f32; 3]) -> Option<BsdfSample> {
        self.at(h, wo).sample(u)
    }

    /// Evaluates n inputs at once (eight per SIMD step); each result equals
    /// [`Self::eval`]'s bit for bit. All slices must have the same length.
    pub fn eval_batch(
        &self,
        h: &[f32],
        wo: &[[f32; 3]],
        wi: &[[f32; 3]],
        f: &mut [[f32; 3]],
        pdf: &mut [f32],
    ) -> Result<()> {
        let n = h.len();
        if [wo.len(), wi.len(), f.len(), pdf.len()]
            .iter()
            .any(|&m| m != n)
        {
            return Err(invalid_arg!(
                "eval_batch: slice lengths differ (h {n}, wo {}, wi {}, f {}, pdf {})",
                wo.len(),
                wi.len(),
                f.len(),
                pdf.len()
            ));
        }
        const W: usize = 8;
        for start in (0..n).step_by(W) {
            let len = W.min(n - start);
            // A short final chunk repeats its last input in the unused lanes.
            let lane = |k: usize| start + k.min(len - 1);
            let gather =
                |v: &[[f32; 3]], c: usize| f32x8::new(std::array::from_fn(|k| v[lane(k)][c]));
            let hv = f32x8::new(std::array::from_fn(|k| h[lane(k)]));
            let wov = [0, 1, 2].map(|c| gather(wo, c));
            let wiv = [0, 1, 2].map(|c| gather(wi, c));
            let o = self.outgoing_lanes(hv, wov);
            let (fv, pv) = self.eval_lobes(&o, wiv);
            let fa = fv.map(f32x8::to_array);
            let pa = pv.to_array();
            for k in 0..len {
                f[start + k] = [fa[0][k], fa[1][k], fa[2][k]];
                pdf[start + k] = pa[k];
            }
        }
        Ok(())
    }

    /// [`Self::outgoing`] in eight lanes, for [`Self::eval_batch`] and
    /// [`HairPoint::eval_across`]: one copy, out of line. Inlined into both, the stage's
    /// array maps and closures have two callers in one codegen unit, and LLVM leaves them
    /// out of line, each call with its own index checks and copies through memory; in a
    /// single copy each has one caller and is inlined. Same operations, same bits.
    #[inline(never)]
    fn outgoing_lanes(&self, h: f32x8, wo: [f32x8; 3]) -> Outgoing<f32x8> {
        self.outgoing(h, wo)
    }

    /// The (h, wo) stage: tilted outgoing angles, refraction inside the fiber, Fresnel
    /// and absorption, lobe attenuations and sampling weights.
    #[inline(always)]
    fn outgoing<T: Lanes>(&self, h: T, wo: [T; 3]) -> Outgoing<T> {
        let one = T::splat(1.0);
        let zero = T::splat(0.0);
        let h = h.max(-one).min(one);
        let sin_to = wo[0].max(-one).min(one);
        let cos_to = cos_from_sin(sin_to);
        let tilt = |p: usize| {
            let (s, c) = (T::splat(self.tilt[p].0), T::splat(self.tilt[p].1));
            (sin_to * c + cos_to * s, (cos_to * c - sin_to * s).abs())
        };
        let tilted = [tilt(0), tilt(1), tilt(2)];

        // Modified index eta' = sqrt(eta^2 - sin^2 to) / cos to enters only as h / eta';
        // written this way it never divides by cos to, which is 0 along the tangent.
        let eta = T::splat(self.params.eta);
        let sin_gt = h * cos_to / (eta * eta - sin_to * sin_to).sqrt();
        let cos_gt = cos_from_sin(sin_gt);
        let sin_tt = sin_to / eta;
        let cos_tt = cos_from_sin(sin_tt);
        let path = T::splat(2.0) * cos_gt / cos_tt;
        let sigma = self.params.sigma_a.map(T::splat);
        let transmit = T::exp_neg3([0, 1, 2].map(|c| -(sigma[c] * path)));

        // Near grazing incidence F is within a few ulps of 1, so 1 - F is taken from the
        // Fresnel formulas directly rather than by subtraction.
        let cos_go = cos_from_sin(h);
        let (fr, ft) = fresnel_dielectric(cos_to * cos_go, eta);
        let lobes = |t: T| {
            let tt = ft * ft * t;
            let trt = tt * t * fr;
            // Residual sum of p >= 3: trt * t f / (1 - t f), with 1 - t f = (1 - t) + t (1 - f)
            // free of the cancellation of 1 - f. When it is 0 (no absorption at grazing
            // Fresnel = 1) the numerator is 0 too and the limit is 0.
            let denom = (one - t) + t * ft;
            let residual = T::branch(denom.gt(zero), || trt * t * fr / denom, || zero);
            [fr, tt, trt, residual]
        };
        let [r, g, b] = transmit.map(lobes);
        let ap = [0, 1, 2, 3].map(|p| [r[p], g[p], b[p]]);
        let third = T::splat(1.0 / 3.0);
        let mean = |p: usize| (r[p] + g[p] + b[p]) * third;
        // The R lobe's Fresnel term is > 0 for eta > 1, so the total is never 0.
        let inv_total = one / (mean(0) + mean(1) + mean(2) + mean(3));

        // Turns as complex numbers, of length 1 up to rounding: by -2 gamma_o,
        // conj(cos gamma_o + i h)^2; by 2 gamma_t + pi, -(cos gamma_t + i sin gamma_t)^2.
        let turn_o = ((cos_go - h) * (cos_go + h), -(T::splat(2.0) * cos_go * h));
        let turn_t = (
            -((cos_gt - sin_gt) * (cos_gt + sin_gt)),
            -(T::splat(2.0) * cos_gt * sin_gt),
        );
        let mul = |a: (T, T), b: (T, T)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let azimuth = azimuth_o(wo);
        let r_centre = mul(azimuth, turn_o);
        let tt_centre = mul(r_centre, turn_t);
        Outgoing {
            sin_to,
            cos_to,
            tilted,
            centre: [r_centre, tt_centre, mul(tt_centre, turn_t)],
            azimuth,
            ap,
            lobe_pdf: [0, 1, 2, 3].map(|p| mean(p) * inv_total),
        }
    }

    /// The per-wi stage over inputs in lanes (the batch): sums the lobes into (f, pdf).
    #[inline(always)]
    fn eval_lobes<T: Lanes>(&self, o: &Outgoing<T>, wi: [T; 3]) -> ([T; 3], T) {
        let one = T::splat(1.0);
        let sin_ti = wi[0].max(-one).min(one);
        let cos_ti = cos_from_sin(sin_ti);
        let mp = std::array::from_fn(|p| {
            let (sin_to, cos_to) = if p < EXPLICIT_LOBES {
                o.tilted[p]
            } else {
                (o.sin_to, o.cos_to)
            };
            self.mp[p].eval(sin_ti, cos_ti, sin_to, cos_to)
        });
        self.sum_lobes(o, mp, wi)
    }

    /// The lobes' sum into (f, pdf) given each lobe's Mp toward wi: Np from the lobe
    /// centres, Ap, the sampling weights and 1/|wi.z|.
    #[inline(always)]
    fn sum_lobes<T: Lanes>(&self, o: &Outgoing<T>, mp: [T; 4], wi: [T; 3]) -> ([T; 3], T) {
        let one = T::splat(1.0);
        let (wy, wz) = azimuth_i(o.azimuth, wi);
        let mut f = [T::splat(0.0); 3];
        let mut pdf = T::splat(0.0);
        for (p, &m) in mp.iter().enumerate() {
            let weight = if p < EXPLICIT_LOBES {
                let (cy, cz) = o.centre[p];
                m * self.np.eval(offset(cy, cz, wy, wz))
            } else {
                m * T::splat(0.5 * FRAC_1_PI)
            };
            for (f, &a) in f.iter_mut().zip(&o.ap[p]) {
                *f = *f + weight * a;
            }
            pdf = pdf + weight * o.lobe_pdf[p];
        }
        let cos_wi = wi[2].abs();
        let inv_cos = T::select(cos_wi.gt(T::splat(MIN_COS_WI)), one / cos_wi, one);
        ([f[0] * inv_cos, f[1] * inv_cos, f[2] * inv_cos], pdf)
    }

    /// The per-wi stage of a merged point ([`Lobes::Merged`]): the residual lobe alone,
    /// which [`merge`] gave every lobe's energy and the whole sampling weight.
    #[inline(always)]
    fn eval_merged(&self, o: &Outgoing<f32>, wi: [f32; 3]) -> ([f32; 3], f32) {
        let sin_ti = wi[0].clamp(-1.0, 1.0);
        let cos_ti = cos_from_sin(sin_ti);
        let weight = self.mp[RESIDUAL].eval(sin_ti, cos_ti, o.sin_to, o.cos_to) * (0.5 * FRAC_1_PI);
        let inv_cos = inv_cos(wi[2]);
        let f = o.ap[RESIDUAL].map(|a| weight * a * inv_cos);
        (f, weight)
    }

    /// The per-wi stage of one evaluation, with the four lobes in the lanes of an f32x4.
    /// Every lane runs the operations [`Self::eval_lobes`] runs for that lobe, and the
    /// lobes are summed in the same order, so the two agree bit for bit.
    #[inline(always)]
    fn eval_lobes_packed(&self, o: &Outgoing<f32>, wi: [f32; 3]) -> ([f32; 3], f32) {
        let mp = self.mp_packed_at(o, wi);
        let (wy, wz) = azimuth_i(o.azimuth, wi);
        let [(y0, z0), (y1, z1), (y2, z2)] = o.centre;
        let np = self.np.eval(offset(
            f32x4::new([y0, y1, y2, 0.0]),
            f32x4::new([z0, z1, z2, 0.0]),
            f32x4::splat(wy),
            f32x4::splat(wz),
        ));
        let mut np = np.to_array();
        np[EXPLICIT_LOBES] = 0.5 * FRAC_1_PI;
        let weight = (mp * f32x4::new(np)).to_array();

        let mut f = [0.0f32; 3];
        let mut pdf = 0.0f32;
        for ((w, ap), lobe_pdf) in weight.iter().zip(&o.ap).zip(&o.lobe_pdf) {
            for (f, a) in f.iter_mut().zip(ap) {
                *f += w * a;
            }
            pdf += w * lobe_pdf;
        }
        let inv_cos = inv_cos(wi[2]);
        ([f[0] * inv_cos, f[1] * inv_cos, f[2] * inv_cos], pdf)
    }
}

impl HairBsdf {
    /// Mp of the four lobes toward wi, in the lanes of an f32x4 (the bits of
    /// [`Self::eval_lobes`]' Mp): it depends on wo and wi, not on h.
    #[inline(always)]
    fn mp_packed_at(&self, o: &Outgoing<f32>, wi: [f32; 3]) -> f32x4 {
        let sin_ti = wi[0].clamp(-1.0, 1.0);
        let cos_ti = cos_from_sin(sin_ti);
        let [(s0, c0), (s1, c1), (s2, c2)] = o.tilted;
        let sin_to = f32x4::new([s0, s1, s2, o.sin_to]);
        let cos_to = f32x4::new([c0, c1, c2, o.cos_to]);
        self.mp_packed
            .eval(f32x4::splat(sin_ti), f32x4::splat(cos_ti), sin_to, cos_to)
    }

    /// [`HairPoint::eval_across`] at the vertex `at` of (h, wo): the (h, wo) stage in eight
    /// lanes, one offset each, then the lobes' sum with the vertex's Mp, which does not
    /// depend on h (Mp in the eight lanes cost 2% more of the scalp's render time). wo
    /// comes back from the vertex: its sin theta and its azimuth, which
    /// [`azimuth_o`] leaves as they are, are all the stage reads of it, so each lane has
    /// the bits of [`HairBsdf::eval`] at its offset.
    fn eval_across_at(&self, at: &Vertex, h: f32, wi: Vec3) -> AcrossEval {
        let step = 2.0 / ACROSS as f32;
        let offsets = f32x8::new(std::array::from_fn(|k| {
            let x = h + step * k as f32;
            if x > 1.0 { x - 2.0 } else { x }
        }));
        let wo = [at.o.sin_to, at.o.azimuth.0, at.o.azimuth.1];
        let o = self.outgoing_lanes(offsets, wo.map(f32x8::splat));
        let wi = wi.to_array();
        let mp = self.mp_packed_at(&at.o, wi).to_array().map(f32x8::splat);
        let (f, pdf) = self.sum_lobes(&o, mp, wi.map(f32x8::splat));
        let f = f.map(f32x8::to_array);
        AcrossEval {
            f: std::array::from_fn(|k| Vec3::new(f[0][k], f[1][k], f[2][k])),
            pdf: pdf.to_array(),
        }
    }
}

/// The index of the residual lobe, after the explicit ones.
const RESIDUAL: usize = EXPLICIT_LOBES;

/// Drops the lobes of `o` whose largest channel of attenuation is below `threshold`
/// times the largest channel of the total (never the strongest lobe), and renormalises
/// the sampling weights over those kept. Keeps every bit of `o` when none is dropped.
fn cull(o: &mut Outgoing<f32>, threshold: f32) {
    let peak = o.ap.map(|a| a[0].max(a[1]).max(a[2]));
    let total = (0..3)
        .map(|c| o.ap.iter().map(|a| a[c]).sum::<f32>())
        .fold(0.0, f32::max);
    let strongest = (0..4).fold(0, |s, p| if peak[p] > peak[s] { p } else { s });
    let dropped = |p: usize| p != strongest && peak[p] < threshold * total;
    if !(0..4).any(dropped) {
        return;
    }
    for p in (0..4).filter(|&p| dropped(p)) {
        o.ap[p] = [0.0; 3];
        o.lobe_pdf[p] = 0.0;
    }
    let inv_kept = 1.0 / o.lobe_pdf.iter().sum::<f32>();
    o.lobe_pdf = o.lobe_pdf.map(|w| w * inv_kept);
}

/// Gives the residual lobe the energy of all four and the whole sampling weight
/// ([`Lobes::Merged`]).
fn merge(o: &mut Outgoing<f32>) {
    let ap = o.ap;
    o.ap[RESIDUAL] = std::array::from_fn(|c| ap.iter().map(|a| a[c]).sum());
    o.lobe_pdf = [0.0, 0.0, 0.0, 1.0];
}

impl LocalBsdf for HairPoint<'_> {
    fn eval(&self, wi: Vec3) -> BsdfEval {
        HairPoint::eval(self, wi)
    }

    fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        HairPoint::sample(self, u)
    }

    fn sample_weight(&self, u: [f32; 3]) -> Option<WeightedSample> {
        self.bsdf.sample_weight_at(&self.at, u)
    }
}

/// [`HairBsdf`] at a fixed (h, wo); see [`HairBsdf::at`].
pub struct HairPoint<'a> {
    bsdf: &'a HairBsdf,
    at: Vertex,
    /// h, kept where the point evaluates the whole model ([`Lobes::All`]), for
    /// [`Self::eval_across`].
    whole_h: Option<f32>,
}

/// How many offsets across the fibre [`HairPoint::eval_across`] evaluates: one SIMD step.
pub const ACROSS: usize = 8;

/// f and pdf toward one wi at [`ACROSS`] offsets across the fibre (see
/// [`HairPoint::eval_across`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcrossEval {
    pub f: [Vec3; ACROSS],
    pub pdf: [f32; ACROSS],
}

impl HairPoint<'_> {
    /// f and pdf for the incident direction wi.
    pub fn eval(&self, wi: Vec3) -> BsdfEval {
        self.bsdf.eval_at(&self.at, wi)
    }

    /// f and pdf toward wi at the point's offset h and at its shifts by 2k / [`ACROSS`],
    /// wrapped into [-1, 1]: a stratified sample of the fibre's width whose every member
    /// is uniform over it when h is. Their mean is an unbiased estimate of the BSDF
    /// averaged across the fibre, which is what a pixel sees of a strand narrower than
    /// itself: next-event estimation weighs a light by it and keeps the highlights' noise
    /// out of the image (docs/measurements.md, "Light across the fibre"). Costs one
    /// eight-lane pass of the (h, wo) stage and of the lobes. None for a point of fewer
    /// lobes ([`Lobes::Culled`], [`Lobes::Merged`]).
    pub fn eval_across(&self, wi: Vec3) -> Option<AcrossEval> {
        Some(self.bsdf.eval_across_at(&self.at, self.whole_h?, wi))
    }

    /// Samples wi; see [`HairBsdf::sample`].
    pub fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        self.bsdf.sample_at(&self.at, u)
    }
}

/// A [`HairPoint`] that holds its own copy of the BSDF instead of a reference: plain
/// numbers that may be copied byte for byte and outlive the [`HairBsdf`] they came from
/// (the C ABI keeps it in host memory). It runs the same code, so gives the same bits.
#[derive(Clone, Copy)]
pub(crate) struct OwnedPoint {
    bsdf: HairBsdf,
    at: Vertex,
    /// The point's h, for [`Self::eval_across`].
    h: f32,
}

impl OwnedPoint {
    /// Writes the point of `bsdf` at (h, wo) into `dst` field by field: the (h, wo) work
    /// lands where it stays, instead of in a whole point on the stack that is then copied.
    #[inline(never)]
    pub(crate) fn fill(dst: &mut MaybeUninit<Self>, bsdf: &HairBsdf, h: f32, wo: Vec3) {
        let dst = dst.as_mut_ptr();
        // SAFETY: `dst` is a valid, aligned `OwnedPoint` place (from a `&mut`); writing its
        // fields initialises it.
        unsafe {
            (&raw mut (*dst).bsdf).write(*bsdf);
            (&raw mut (*dst).at).write(bsdf.vertex(h, wo, Lobes::All));
            (&raw mut (*dst).h).write(h);
        }
    }

    /// [`HairPoint::eval_across`] at this point.
    pub(crate) fn eval_across(&self, wi: Vec3) -> AcrossEval {
        self.bsdf.eval_across_at(&self.at, self.h, wi)
    }

    #[inline]
    pub(crate) fn eval(&self, wi: Vec3) -> BsdfEval {
        self.bsdf.eval_at(&self.at, wi)
    }

    pub(crate) fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        self.bsdf.sample_at(&self.at, u)
    }
}

impl LocalBsdf for OwnedPoint {
    #[inline]
    fn eval(&self, wi: Vec3) -> BsdfEval {
        OwnedPoint::eval(self, wi)
    }

    fn sample(&self, u: [f32; 3]) -> Option<BsdfSample> {
        OwnedPoint::sample(self, u)
    }
}

/// What a point keeps of (h, wo).
#[derive(Clone, Copy)]
struct Vertex {
    o: Outgoing<f32>,
    /// Evaluated as [`Lobes::Merged`].
    merged: bool,
}

impl HairBsdf {
    /// f and pdf toward wi at a prepared vertex.
    #[inline(always)]
    fn eval_at(&self, at: &Vertex, wi: Vec3) -> BsdfEval {
        let (f, pdf) = if at.merged {
            self.eval_merged(&at.o, wi.to_array())
        } else {
            self.eval_lobes_packed(&at.o, wi.to_array())
        };
        BsdfEval {
            f: Vec3::from_array(f),
            pdf,
        }
    }

    /// Samples wi at a prepared vertex; see [`HairBsdf::sample`].
    #[inline]
    fn sample_at(&self, at: &Vertex, u: [f32; 3]) -> Option<BsdfSample> {
        let (wi, _) = self.draw(at, u);
        let e = self.eval_at(at, wi);
        (e.pdf > 0.0).then_some(BsdfSample {
            wi,
            f: e.f,
            pdf: e.pdf,
        })
    }

    /// The direction of [`Self::sample_at`], weighted by the lobe that drew it alone:
    /// lobe p is picked with probability P(p) and its Mp and Np are sampled exactly, so
    /// f_p |cos| / (P(p) pdf_p) is Ap / P(p), with no lobe evaluated at wi. Its mean is
    /// the albedo, as the mixture's f |cos| / pdf; since P(p) is proportional to Ap's
    /// mean over the channels, that mean of the weight is the same constant either way.
    #[inline]
    fn sample_weight_at(&self, at: &Vertex, u: [f32; 3]) -> Option<WeightedSample> {
        let (wi, p) = self.draw(at, u);
        let weight = Vec3::from_array(at.o.ap[p]) / at.o.lobe_pdf[p];
        weight.is_finite().then_some(WeightedSample { wi, weight })
    }

    /// A direction from lobe p, picked by `u[0]`, and p.
    #[inline(always)]
    fn draw(&self, at: &Vertex, u: [f32; 3]) -> (Vec3, usize) {
        let o = &at.o;
        let (p, u_phi) = pick(&o.lobe_pdf, u[0]);
        // u = 0 stands for [0, 2^-24): its midpoint keeps the far tails, where the f32
        // density underflows, from being sampled with a whole 2^-24 of probability.
        let (u_phi, u_theta) = (u_phi.max(U_MIN), u[1].max(U_MIN));

        let (sin_to, cos_to) = if p < EXPLICIT_LOBES {
            o.tilted[p]
        } else {
            (o.sin_to, o.cos_to)
        };
        let (sin_ti, cos_ti) = self.mp[p].sample(sin_to, cos_to, [u_theta, u[2]]);
        // The azimuth: the lobe's centre turned by a logistic offset; the residual lobe's
        // is uniform.
        let (base, dphi) = if p < EXPLICIT_LOBES {
            (o.centre[p], self.np.sample(u_phi))
        } else {
            (o.azimuth, TAU * u_phi)
        };
        let (sin_d, cos_d) = dphi.sin_cos();
        let scale = cos_ti / (base.0 * base.0 + base.1 * base.1).sqrt();
        let wi = Vec3::new(
            sin_ti,
            scale * (base.0 * cos_d - base.1 * sin_d),
            scale * (base.1 * cos_d + base.0 * sin_d),
        );
        (wi, p)
    }
}

/// wo's azimuth as a (y, z) direction of length 1e-4 to sqrt(2); (1, 0) along the tangent,
/// which has none (evaluation and sampling then share that convention). Lengths do not
/// matter to the offsets (atan2 of products), but tiny components are scaled up so that
/// their products with wi's cannot underflow.
#[inline(always)]
fn azimuth_o<T: Lanes>(wo: [T; 3]) -> (T, T) {
    let (one, zero) = (T::splat(1.0), T::splat(0.0));
    let m = wo[1].abs().max(wo[2].abs());
    let defined = m.gt(zero);
    let scale = T::branch(
        m.lt(T::splat(MIN_AZIMUTH_O)),
        || one / T::select(defined, m, one),
        || one,
    );
    (
        T::select(defined, wo[1] * scale, one),
        T::select(defined, wo[2] * scale, zero),
    )
}

/// Below this largest yz component, wo's azimuth is rescaled (see [`azimuth_o`]).
const MIN_AZIMUTH_O: f32 = 1e-4;

/// Below this |wi.y| and |wi.z|, wi is taken to be along the tangent: its azimuth is
/// meaningless (and products with it could underflow), so it is given wo's.
const MIN_AZIMUTH: f32 = 1e-30;

/// wi's (y, z) for the azimuthal offsets: as it is, or wo's azimuth along the tangent
/// (phi_i - phi_o = 0 there: one azimuth for all the lobes, as the model has).
#[inline(always)]
fn azimuth_i<T: Lanes>(azimuth_o: (T, T), wi: [T; 3]) -> (T, T) {
    let defined = wi[1].abs().max(wi[2].abs()).gt(T::splat(MIN_AZIMUTH));
    (
        T::select(defined, wi[1], azimuth_o.0),
        T::select(defined, wi[2], azimuth_o.1),
    )
}

/// Signed azimuthal offset in [-pi, pi] of the direction (y, z) from a lobe centred at the
/// direction (cy, cz): one atan2 of their cross and dot products.
#[inline(always)]
fn offset<T: Lanes>(cy: T, cz: T, y: T, z: T) -> T {
    atan2(cy * z - cz * y, cy * y + cz * z)
}
