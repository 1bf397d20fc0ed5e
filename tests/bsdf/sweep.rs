//! Sweep of the whole valid input range, with a structured grid of the hard cases
//! (h = +-1, directions at and within 1e-4 of the tangent, grazing, wi = +-wo, azimuths
//! half a turn apart, roughness and absorption at their extremes, eta near 1 and 3, the
//! largest tilts) plus random inputs: every output finite and non-negative, and the f32
//! evaluation accurate against the f64 reference wherever the inputs are well conditioned.

use crate::common::reference::RefHair;
use crate::common::sphere::{
    dir, f32_step, normalize, round_f32, tilt, ulp_jitter, uniform_sphere, widen,
};
use crate::common::{
    Timer, bsdf, par_map, params, random_beta, random_params, random_sigma, random_u, reference,
    rng, v3f,
};
use glam::Vec3;
use hairtrace::{Error, HairBsdf, HairParams};
use rand::Rng;
use rand_pcg::Pcg64;
use std::f64::consts::PI;

/// Relative accuracy required of the f32 path where the inputs are well conditioned.
const REL_TOL: f64 = 5e-4;
/// Values below this are "zero" for accuracy purposes (f32 denormals and underflow).
const ABS_TOL: f64 = 1e-30;
/// An ill-conditioned case may exceed REL_TOL only by less than this multiple of the
/// spread of the reference over f32-ulp perturbations of its inputs.
const SPREAD_FACTOR: f64 = 4.0;

/// One evaluation input.
#[derive(Clone, Copy, Debug)]
struct Input {
    h: f32,
    wo: [f32; 3],
    wi: [f32; 3],
}

/// The kinds of direction the hard-case grid draws.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Random,
    TangentPlus,
    TangentMinus,
    Grazing,
    SameAsWo,
    OppositeWo,
    HalfTurnFromWo,
}

const WO_KINDS: [Kind; 4] = [
    Kind::Random,
    Kind::TangentPlus,
    Kind::TangentMinus,
    Kind::Grazing,
];
const WI_KINDS: [Kind; 7] = [
    Kind::Random,
    Kind::TangentPlus,
    Kind::TangentMinus,
    Kind::Grazing,
    Kind::SameAsWo,
    Kind::OppositeWo,
    Kind::HalfTurnFromWo,
];

/// A direction of the given kind (wo is used by the kinds relative to it).
fn direction(kind: Kind, wo: [f64; 3], g: &mut Pcg64) -> [f64; 3] {
    let tangent_offset = |g: &mut Pcg64| match g.random_range(0..4) {
        0 => 0.0,
        1 => 1e-7,
        _ => g.random_range(0.0..1e-4),
    };
    match kind {
        Kind::Random => uniform_sphere(g),
        Kind::TangentPlus => {
            let a = tangent_offset(g);
            tilt([1.0, 0.0, 0.0], a, g)
        }
        Kind::TangentMinus => {
            let a = tangent_offset(g);
            tilt([-1.0, 0.0, 0.0], a, g)
        }
        Kind::Grazing => {
            let z = match g.random_range(0..3) {
                0 => 0.0,
                _ => g.random_range(-1e-4..1e-4),
            };
            let phi: f64 = g.random_range(-PI..PI);
            normalize([phi.sin(), phi.cos(), z])
        }
        Kind::SameAsWo => wo,
        Kind::OppositeWo => [-wo[0], -wo[1], -wo[2]],
        Kind::HalfTurnFromWo => {
            let phi_o = wo[2].atan2(wo[1]);
            let d = [0.0, 1e-7, -1e-7, 1e-4, -1e-4, 1e-2][g.random_range(0..6)];
            dir(g.random_range(-0.5 * PI..0.5 * PI), phi_o + PI + d)
        }
    }
}

/// The structured parameter grid: roughness at both ends and random, absorption from
/// none through huge to mixed, eta at both ends, tilt at both ends.
fn structured_params(g: &mut Pcg64) -> Vec<HairParams> {
    let mut out = Vec::new();
    let sigmas: [Option<[f32; 3]>; 6] = [
        Some([0.0; 3]),
        Some([1e3; 3]),
        Some([1e6; 3]),
        Some([1e30; 3]),
        Some([0.0, 5.0, 1e6]),
        None,
    ];
    for bm in [Some(0.01), Some(1.0), None] {
        for bn in [Some(0.01), Some(1.0), None] {
            for sa in sigmas {
                for eta in [Some(1.0001), Some(1.55), Some(3.0), None] {
                    for alpha in [Some(-20.0), Some(0.0), Some(20.0), None] {
                        out.push(params(
                            sa.unwrap_or_else(|| {
                                [random_sigma(g), random_sigma(g), random_sigma(g)]
                            }),
                            eta.unwrap_or_else(|| g.random_range(1.0001..=3.0)),
                            bm.unwrap_or_else(|| random_beta(g)),
                            bn.unwrap_or_else(|| random_beta(g)),
                            alpha.unwrap_or_else(|| g.random_range(-20.0..=20.0)),
                        ));
                    }
                }
            }
        }
    }
    out
}

const HARD_HS: [f32; 5] = [-1.0, -1.0 + 1e-6, 0.0, 1.0 - 1e-6, 1.0];

/// Inputs for one parameter set: either the full hard-case grid (6 h x 4 wo kinds x 7
/// wi kinds) or `n` random mixtures of the kinds.
fn inputs(g: &mut Pcg64, structured: bool, n: usize) -> Vec<Input> {
    let mut out = Vec::new();
    let mut push = |g: &mut Pcg64, h: f32, wk: Kind, ik: Kind| {
        let wo = direction(wk, [0.0; 3], g);
        let wo = widen(round_f32(wo));
        let wi = direction(ik, wo, g);
        out.push(Input {
            h,
            wo: round_f32(wo),
            wi: round_f32(wi),
        });
    };
    if structured {
        for h in HARD_HS.into_iter().chain([g.random_range(-1.0..=1.0)]) {
            for wk in WO_KINDS {
                for ik in WI_KINDS {
                    push(g, h, wk, ik);
                }
            }
        }
    } else {
        for _ in 0..n {
            let h = if g.random_range(0..4) == 0 {
                HARD_HS[g.random_range(0..5)]
            } else {
                g.random_range(-1.0..=1.0)
            };
            // Mostly plain random directions, a quarter of each drawn from the hard kinds.
            let wk = if g.random_range(0..4) == 0 {
                WO_KINDS[g.random_range(0..4)]
            } else {
                Kind::Random
            };
            let ik = if g.random_range(0..4) == 0 {
                WI_KINDS[g.random_range(0..7)]
            } else {
                Kind::Random
            };
            push(g, h, wk, ik);
        }
    }
    out
}

/// The four outputs compared: f per channel and pdf.
fn outputs_crate(b: &HairBsdf, x: &Input) -> [f64; 4] {
    let e = b.eval(x.h, v3f(x.wo), v3f(x.wi));
    [e.f.x as f64, e.f.y as f64, e.f.z as f64, e.pdf as f64]
}

fn outputs_ref(r: &RefHair, h: f32, wo: [f64; 3], wi: [f64; 3]) -> [f64; 4] {
    let e = r.eval(h as f64, wo, wi);
    [e.f[0], e.f[1], e.f[2], e.pdf]
}

/// Spread of the reference over perturbations of the inputs at the f32 rounding level:
/// the largest deviation from `base` per output.
#[derive(Clone, Copy, Debug)]
struct Spread {
    /// Over the evaluation inputs: h +- 1 ulp; 4 draws with every component of wo and wi
    /// moved by -1, 0 or +1 ulp (equally good f32 roundings of the same unit vectors);
    /// 4 draws with wo and wi rotated by 1e-7 rad about random axes; and, for a direction
    /// exactly along the tangent, every azimuth (see below).
    inputs: [f64; 4],
    /// Over the parameters: eta, beta_m, beta_n, alpha and sigma_a each +- 1 ulp.
    params: [f64; 4],
    /// wo or wi is exactly along the tangent (y = z = 0), where phi is undefined.
    no_azimuth: bool,
}

fn reference_spread(p: &HairParams, x: &Input, base: &[f64; 4], g: &mut Pcg64) -> Spread {
    let mut sp = Spread {
        inputs: [0.0; 4],
        params: [0.0; 4],
        no_azimuth: (x.wo[1] == 0.0 && x.wo[2] == 0.0) || (x.wi[1] == 0.0 && x.wi[2] == 0.0),
    };
    let widen_max = |acc: &mut [f64; 4], v: [f64; 4]| {
        for c in 0..4 {
            acc[c] = acc[c].max((v[c] - base[c]).abs());
        }
    };
    let r = reference(p);
    let (wo, wi) = (widen(x.wo), widen(x.wi));
    for d in [-1, 1] {
        let h = f32_step(x.h, d).clamp(-1.0, 1.0);
        widen_max(&mut sp.inputs, outputs_ref(&r, h, wo, wi));
    }
    for k in 0..8 {
        let (wo2, wi2) = if k < 4 {
            (widen(ulp_jitter(x.wo, g)), widen(ulp_jitter(x.wi, g)))
        } else {
            (tilt(wo, 1e-7, g), tilt(wi, 1e-7, g))
        };
        widen_max(&mut sp.inputs, outputs_ref(&r, x.h, wo2, wi2));
    }
    // A direction exactly along the tangent has no azimuth at all: the model's value
    // there depends on an arbitrary convention (the reference takes atan2(0, 0) = 0 for
    // that direction's phi), so its spread is over every phi_i - phi_o. The lobes are
    // unimodal in phi, so the extremes are at their centres or anywhere between; a
    // 256-point grid plus the three centres covers them.
    if sp.no_azimuth {
        let geo = r.geometry(x.h as f64, wo);
        let phis = (0..256)
            .map(|k| -PI + 2.0 * PI * k as f64 / 256.0)
            .chain((0..3).map(|q| RefHair::phi_lobe(&geo, q)));
        for phi in phis {
            let e = r.eval_dphi(&geo, wi, phi);
            widen_max(&mut sp.inputs, [e.f[0], e.f[1], e.f[2], e.pdf]);
        }
    }
    for d in [-1, 1] {
        let st = |v: f32| f32_step(v, d);
        for q in [
            HairParams {
                eta: st(p.eta).max(f32_step(1.0, 1)),
                ..*p
            },
            HairParams {
                beta_m: st(p.beta_m).clamp(0.01, 1.0),
                ..*p
            },
            HairParams {
                beta_n: st(p.beta_n).clamp(0.01, 1.0),
                ..*p
            },
            HairParams {
                alpha: st(p.alpha).clamp(-20.0, 20.0),
                ..*p
            },
            HairParams {
                sigma_a: p.sigma_a.map(|v| if v > 0.0 { st(v) } else { v }),
                ..*p
            },
        ] {
            widen_max(&mut sp.params, outputs_ref(&reference(&q), x.h, wo, wi));
        }
    }
    sp
}

/// The factors that turn the outputs (f rgb, pdf) into what a renderer uses (f |wi.z|,
/// pdf), to which the absolute floor ABS_TOL applies: f alone is amplified by 1 / |wi.z|
/// (up to ~1e38 at grazing wi), so f32 underflow of a 1e-35 density may show as a lost
/// 1e-28 in f.
fn abs_scale(x: &Input) -> [f64; 4] {
    let c = if x.wi[2] == 0.0 {
        1.0
    } else {
        (x.wi[2] as f64).abs()
    };
    [c, c, c, 1.0]
}

/// Findings of one parameter set.
#[derive(Default)]
struct Stats {
    cases: usize,
    /// Cases within REL_TOL / ABS_TOL on every output.
    good: usize,
    /// Cases that needed the allowance of the spread over the evaluation inputs ...
    allowance_inputs: usize,
    /// ... of which wo or wi was exactly along the tangent;
    allowance_no_azimuth: usize,
    /// ... and cases that needed the spread over the parameters as well.
    allowance_params: usize,
    /// Worst relative error among cases within tolerance (judged by the relative bound),
    /// directions exactly along the tangent left out.
    worst_good: (f64, String),
    /// The same, leaving out eta < 1.05, where the Fresnel factor ~ (eta - 1)^2 is
    /// ill-conditioned in f32 (one ulp of eta = 1.0001 moves it by 2.4e-3).
    worst_good_eta: (f64, String),
    /// Worst relative error overall, leaving out the inputs exactly along the tangent
    /// (whose error relative to the reference's arbitrary azimuth convention means nothing).
    worst_all: (f64, String),
    /// Worst error / spread among the cases that needed an allowance.
    worst_ratio: (f64, String),
    failures: Vec<String>,
    robustness: Vec<String>,
    /// Histogram of the relative error of every compared value (outside the absolute
    /// floor, directions exactly along the tangent left out) by decade: [< 1e-7, 1e-7..1e-6,
    /// ..., 1e-3..1e-2, >= 1e-2].
    decades: [usize; 7],
}

impl Stats {
    fn merge(&mut self, o: Stats) {
        self.cases += o.cases;
        self.good += o.good;
        self.allowance_inputs += o.allowance_inputs;
        self.allowance_no_azimuth += o.allowance_no_azimuth;
        self.allowance_params += o.allowance_params;
        for (mine, theirs) in [
            (&mut self.worst_good, o.worst_good),
            (&mut self.worst_good_eta, o.worst_good_eta),
            (&mut self.worst_all, o.worst_all),
            (&mut self.worst_ratio, o.worst_ratio),
        ] {
            if theirs.0 > mine.0 {
                *mine = theirs;
            }
        }
        self.failures.extend(o.failures);
        self.robustness.extend(o.robustness);
        for (a, b) in self.decades.iter_mut().zip(o.decades) {
            *a += b;
        }
    }
}

fn record(slot: &mut (f64, String), value: f64, what: impl FnOnce() -> String) {
    if value > slot.0 {
        *slot = (value, what());
    }
}

fn check_set(p: &HairParams, xs: &[Input], seed: u64) -> Stats {
    let b = bsdf(p);
    let r = reference(p);
    let mut g = rng(seed);
    let mut st = Stats::default();
    for x in xs {
        st.cases += 1;
        let (wo, wi) = (v3f(x.wo), v3f(x.wi));
        // Robustness: eval, pdf and sample outputs finite and non-negative.
        let e = b.eval(x.h, wo, wi);
        let pdf = b.pdf(x.h, wo, wi);
        let u = random_u(&mut g);
        let s = b.sample(x.h, wo, u);
        let sample_ok = s.is_none_or(|s| {
            s.wi.is_finite()
                && s.f.is_finite()
                && s.f.cmpge(Vec3::ZERO).all()
                && s.pdf.is_finite()
                && s.pdf > 0.0
        });
        let eval_ok = e.f.is_finite()
            && e.f.cmpge(Vec3::ZERO).all()
            && e.pdf.is_finite()
            && e.pdf >= 0.0
            && pdf.is_finite()
            && pdf >= 0.0;
        if !(eval_ok && sample_ok) {
            st.robustness.push(format!(
                "{p:?} {x:?} u={u:?}: eval {e:?}, pdf {pdf}, sample {s:?}"
            ));
            continue;
        }
        // Accuracy against the reference (absolute floor on f |wi.z| and pdf).
        let got = outputs_crate(&b, x);
        let want = outputs_ref(&r, x.h, widen(x.wo), widen(x.wi));
        let scale = abs_scale(x);
        let no_azimuth = (x.wo[1] == 0.0 && x.wo[2] == 0.0) || (x.wi[1] == 0.0 && x.wi[2] == 0.0);
        let mut spread: Option<Spread> = None;
        let mut needs = (false, false, false);
        for c in 0..4 {
            let err = (got[c] - want[c]).abs();
            if err * scale[c] <= ABS_TOL {
                continue;
            }
            let rel = err / want[c].abs().max(1e-300);
            if !no_azimuth {
                let d = (rel.log10().floor() + 7.0).clamp(-1.0, 5.0) as i64 + 1;
                st.decades[d as usize] += 1;
            }
            let describe = |spread: Option<Spread>| {
                format!(
                    "output {c} (0-2: f rgb, 3: pdf): crate {:e}, reference {:e}, rel err {rel:.3e}, reference spread {:?}; {p:?} h={:?} wo={:?} wi={:?}",
                    got[c],
                    want[c],
                    spread.map(|s| (s.inputs[c], s.params[c])),
                    x.h,
                    x.wo,
                    x.wi
                )
            };
            if err <= REL_TOL * want[c].abs() {
                if !no_azimuth {
                    record(&mut st.worst_good, rel, || describe(None));
                    if p.eta >= 1.05 {
                        record(&mut st.worst_good_eta, rel, || describe(None));
                    }
                }
                if !no_azimuth {
                    record(&mut st.worst_all, rel, || describe(None));
                }
                continue;
            }
            let sp = *spread.get_or_insert_with(|| reference_spread(p, x, &want, &mut g));
            if !sp.no_azimuth {
                record(&mut st.worst_all, rel, || describe(Some(sp)));
            }
            let allowed = SPREAD_FACTOR * sp.inputs[c].max(sp.params[c]);
            if err < SPREAD_FACTOR * sp.inputs[c] {
                needs.0 = true;
                needs.1 |= sp.no_azimuth;
            } else if err < allowed {
                needs.2 = true;
            } else {
                st.failures.push(describe(Some(sp)));
                continue;
            }
            record(&mut st.worst_ratio, err / allowed * SPREAD_FACTOR, || {
                describe(Some(sp))
            });
        }
        match needs {
            (_, _, true) => st.allowance_params += 1,
            (true, true, _) => {
                st.allowance_inputs += 1;
                st.allowance_no_azimuth += 1
            }
            (true, false, _) => st.allowance_inputs += 1,
            _ => st.good += 1,
        }
    }
    st
}

/// Over 10^6 inputs (the structured hard-case grid of 864 parameter sets x 168 (h, wo,
/// wi) cases, plus 900 random parameter sets x 1000 random inputs): eval, pdf and sample
/// give finite, non-negative values, and eval's f (per channel) and pdf match the f64
/// reference within 5e-4 relative (or 1e-30 absolute). A case may exceed that only when
/// the model itself is ill-conditioned there in f32: its error must then be below 4x the
/// spread of the reference over f32-ulp perturbations of its inputs (the crate cannot
/// know its inputs better than that). 5e-4 is ~4000 f32 ulps: room for the f32
/// transcendental functions and the exponent of lobes as narrow as v ~ 1e-5, while a
/// wrong formula anywhere is off by percents.
#[test]
fn sweep_finite_and_accurate() {
    let _t = Timer::start("sweep_finite_and_accurate");
    let mut g = rng(2024);
    let mut sets: Vec<(HairParams, Vec<Input>, u64)> = Vec::new();
    for (i, p) in structured_params(&mut g).into_iter().enumerate() {
        let xs = inputs(&mut g, true, 0);
        sets.push((p, xs, 10_000 + i as u64));
    }
    for i in 0..900 {
        let p = random_params(&mut g, true);
        let xs = inputs(&mut g, false, 1000);
        sets.push((p, xs, 20_000 + i as u64));
    }
    let mut total = Stats::default();
    for st in par_map(&sets, |(p, xs, seed)| check_set(p, xs, *seed)) {
        total.merge(st);
    }
    println!(
        "sweep: {} cases, {} within tolerance",
        total.cases, total.good
    );
    println!(
        "sweep: {} needed the conditioning allowance over the inputs ({} of them with wo or wi exactly along the tangent), {} also over the parameters",
        total.allowance_inputs, total.allowance_no_azimuth, total.allowance_params
    );
    println!(
        "sweep: relative errors by decade (<1e-7, 1e-7.., 1e-6.., 1e-5.., 1e-4.., 1e-3.., >=1e-2): {:?}",
        total.decades
    );
    println!(
        "sweep: worst relative error within tolerance {:.3e}: {}",
        total.worst_good.0, total.worst_good.1
    );
    println!(
        "sweep: worst relative error within tolerance, eta >= 1.05 {:.3e}: {}",
        total.worst_good_eta.0, total.worst_good_eta.1
    );
    println!(
        "sweep: worst relative error overall (directions exactly along the tangent left out) {:.3e}: {}",
        total.worst_all.0, total.worst_all.1
    );
    println!(
        "sweep: worst error / reference spread among allowed cases {:.3}: {}",
        total.worst_ratio.0, total.worst_ratio.1
    );
    println!(
        "sweep: {} robustness failures, {} accuracy failures",
        total.robustness.len(),
        total.failures.len()
    );
    for f in total.robustness.iter().take(10) {
        println!("  non-finite or negative: {f}");
    }
    for f in total.failures.iter().take(20) {
        println!("  inaccurate: {f}");
    }
    assert!(total.cases >= 1_000_000);
    assert!(
        total.robustness.is_empty() && total.failures.is_empty(),
        "{} robustness and {} accuracy failures (listed above with --nocapture); first: {:?} {:?}",
        total.robustness.len(),
        total.failures.len(),
        total.robustness.first(),
        total.failures.first()
    );
}

/// Out-of-range parameters are rejected by HairBsdf::new (and validate) with an
/// InvalidArg whose message names the parameter; the ends of the valid ranges are
/// accepted.
#[test]
fn invalid_parameters_are_rejected() {
    let base = HairParams::default();
    let with = |f: &dyn Fn(&mut HairParams)| {
        let mut p = base;
        f(&mut p);
        p
    };
    let bad: Vec<(&str, HairParams)> = vec![
        ("beta_m", with(&|p| p.beta_m = 0.009)),
        ("beta_m", with(&|p| p.beta_m = 1.01)),
        ("beta_m", with(&|p| p.beta_m = f32::NAN)),
        ("beta_m", with(&|p| p.beta_m = f32::INFINITY)),
        ("beta_m", with(&|p| p.beta_m = 0.0)),
        ("beta_n", with(&|p| p.beta_n = 0.009)),
        ("beta_n", with(&|p| p.beta_n = 1.01)),
        ("beta_n", with(&|p| p.beta_n = f32::NAN)),
        ("beta_n", with(&|p| p.beta_n = -0.5)),
        ("eta", with(&|p| p.eta = 1.0)),
        ("eta", with(&|p| p.eta = 0.5)),
        ("eta", with(&|p| p.eta = 3.01)),
        ("eta", with(&|p| p.eta = f32::NAN)),
        ("eta", with(&|p| p.eta = f32::INFINITY)),
        ("sigma_a", with(&|p| p.sigma_a = [-1.0, 0.0, 0.0])),
        ("sigma_a", with(&|p| p.sigma_a = [0.0, f32::NAN, 0.0])),
        ("sigma_a", with(&|p| p.sigma_a = [0.0, 0.0, f32::INFINITY])),
        ("sigma_a", with(&|p| p.sigma_a = [0.0, 0.0, -1e-30])),
        ("alpha", with(&|p| p.alpha = 20.5)),
        ("alpha", with(&|p| p.alpha = -20.5)),
        ("alpha", with(&|p| p.alpha = f32::NAN)),
        ("alpha", with(&|p| p.alpha = f32::NEG_INFINITY)),
    ];
    for (name, p) in &bad {
        for (what, r) in [
            ("HairBsdf::new", HairBsdf::new(p).map(|_| ())),
            ("validate", p.validate()),
        ] {
            match r {
                Err(Error::InvalidArg(msg)) => assert!(
                    msg.contains(name),
                    "{what}({p:?}): message {msg:?} does not name {name}"
                ),
                other => panic!("{what}({p:?}) gave {other:?}, want InvalidArg naming {name}"),
            }
        }
    }
    let good = [
        with(&|p| p.beta_m = 0.01),
        with(&|p| p.beta_m = 1.0),
        with(&|p| p.beta_n = 0.01),
        with(&|p| p.beta_n = 1.0),
        with(&|p| p.eta = 3.0),
        with(&|p| p.eta = 1.0001),
        with(&|p| p.alpha = 20.0),
        with(&|p| p.alpha = -20.0),
        with(&|p| p.sigma_a = [0.0; 3]),
        with(&|p| p.sigma_a = [f32::MAX, 0.0, 1e30]),
    ];
    for p in &good {
        assert!(HairBsdf::new(p).is_ok(), "{p:?} rejected");
    }
    println!(
        "{} invalid parameter sets rejected, {} boundary sets accepted",
        bad.len(),
        good.len()
    );
}

/// eval_batch is the scalar eval applied elementwise: 10^4 inputs over 10 random
/// parameter sets (hard kinds included) agree bitwise or within 1e-6 relative (a
/// vectorised path may contract or reorder f32 operations differently; values whose
/// difference in f |wi.z| or pdf is below 1e-30 count as equal), and slices of mismatched lengths give an
/// error rather than a panic or a partial result. Inputs with wo or wi exactly along the
/// tangent are reported separately: their azimuth is a convention, but it must be the
/// same convention in both paths.
#[test]
fn eval_batch_matches_scalar_eval() {
    struct Tally {
        n: usize,
        exact: usize,
        tiny: usize,
        over: usize,
        worst: (f64, String),
    }
    let mut tallies = [(); 2].map(|_| Tally {
        n: 0,
        exact: 0,
        tiny: 0,
        over: 0,
        worst: (0.0, String::new()),
    });
    let mut g = rng(77);
    for _ in 0..10 {
        let p = random_params(&mut g, true);
        let b = bsdf(&p);
        let xs = inputs(&mut g, false, 1000);
        let h: Vec<f32> = xs.iter().map(|x| x.h).collect();
        let wo: Vec<[f32; 3]> = xs.iter().map(|x| x.wo).collect();
        let wi: Vec<[f32; 3]> = xs.iter().map(|x| x.wi).collect();
        let mut f = vec![[0.0f32; 3]; xs.len()];
        let mut pdf = vec![0.0f32; xs.len()];
        b.eval_batch(&h, &wo, &wi, &mut f, &mut pdf)
            .expect("eval_batch on matching slices");
        for (k, x) in xs.iter().enumerate() {
            let e = b.eval(x.h, v3f(x.wo), v3f(x.wi));
            let want = [e.f.x, e.f.y, e.f.z, e.pdf];
            let got = [f[k][0], f[k][1], f[k][2], pdf[k]];
            let tangent = (x.wo[1] == 0.0 && x.wo[2] == 0.0) || (x.wi[1] == 0.0 && x.wi[2] == 0.0);
            let t = &mut tallies[tangent as usize];
            let scale = abs_scale(x);
            for c in 0..4 {
                t.n += 1;
                if got[c].to_bits() == want[c].to_bits() {
                    t.exact += 1;
                    continue;
                }
                let err = (got[c] as f64 - want[c] as f64).abs();
                if err * scale[c] <= ABS_TOL {
                    t.tiny += 1;
                    continue;
                }
                let rel = err / (want[c] as f64).abs();
                t.over += (rel > 1e-6) as usize;
                if rel > t.worst.0 || rel.is_nan() {
                    t.worst = (
                        rel,
                        format!(
                            "batch {} vs eval {} (output {c}) at {p:?} {x:?}",
                            got[c], want[c]
                        ),
                    );
                }
            }
        }
        let short = &wi[..wi.len() - 1];
        assert!(
            b.eval_batch(&h, &wo, short, &mut f, &mut pdf).is_err(),
            "mismatched lengths accepted"
        );
    }
    for (t, what) in tallies
        .iter()
        .zip(["general inputs", "wo or wi exactly along the tangent"])
    {
        println!(
            "eval_batch, {what}: {} values, {} bitwise equal to eval, {} others within 1e-30, {} differ by more than 1e-6 relative; worst {:.3e}: {}",
            t.n, t.exact, t.tiny, t.over, t.worst.0, t.worst.1
        );
    }
    assert!(
        tallies.iter().all(|t| t.over == 0),
        "eval_batch differs from eval by more than 1e-6 relative (see the lines above): {} + {} values",
        tallies[0].over,
        tallies[1].over
    );
}
