//! Accuracy near the fiber tangent, where the azimuth is still defined: wo or wi at
//! sin(theta) = +-0.9998, 0.9999, 0.99999 and 0.999999 (0.02 to 0.0014 rad from the
//! tangent), h from -1 to 1 through +-0.99999, over a grid of hard parameters (narrow and
//! wide lobes, the beta_m 0.259 / beta_n 0.0161 / alpha 10, eta 1.55 and 3, no to
//! strong absorption). Every variant of the crate's evaluation (`HairBsdf::eval`, a
//! prepared `HairPoint`, `eval_batch`) is measured against the f64 reference, next to
//! pbrt-v3's float arithmetic on the same inputs (`common/pbrt_f32.rs`).

use crate::common::pbrt_f32::PbrtHair;
use crate::common::reference::RefHair;
use crate::common::sphere::{dir, f32_step, round_f32, ulp_jitter, widen};
use crate::common::{Timer, bsdf, par_map, params, reference, rng, v3f};
use hairtrace::{HairBsdf, HairParams};
use rand_pcg::Pcg64;

/// Values whose f |wi.z| (or pdf) is below this are "zero" for accuracy, as in the sweep:
/// f32 underflow, not accuracy, decides them.
const ABS_TOL: f64 = 1e-30;

/// pbrt-v3's float code is within 1.6e-4 to 5.4e-4 of the exact value on the issue's
/// near-tangent inputs: the crate must do at least as well everywhere on the grid.
const PBRT_BOUND: f64 = 5.4e-4;

/// Below this relative error, which of two f32 evaluations is closer is a matter of
/// rounding luck (about 300 ulps, spent in a dozen transcendental steps and the narrow
/// lobes' large exponents), so the value-by-value comparison with pbrt starts here.
const FLOOR: f64 = 2e-5;

/// Where the model is ill-conditioned in f32, the crate may also be off by up to this many
/// times the reference's spread over one-ulp changes of the inputs (the sweep allows 4).
const SPREAD_FACTOR: f64 = 2.0;

/// sin(theta) of the near-tangent directions (0.9998 is near where sqrt(1 - x^2) loses the
/// most in f32, 2.5e-5 relative).
const NEAR_TANGENT: [f32; 8] = [
    0.9998, 0.9999, 0.99999, 0.999999, -0.9998, -0.9999, -0.99999, -0.999999,
];

#[derive(Clone, Copy, Debug)]
struct Input {
    h: f32,
    wo: [f32; 3],
    wi: [f32; 3],
}

/// A unit f32 direction with the given x and azimuth phi = atan2(z, y).
fn near(x: f32, phi: f64) -> [f32; 3] {
    let xd = x as f64;
    let r = ((1.0 - xd) * (1.0 + xd)).sqrt();
    [x, (r * phi.cos()) as f32, (r * phi.sin()) as f32]
}

/// 360 parameter sets.
fn param_grid() -> Vec<HairParams> {
    let mut out = Vec::new();
    for bm in [0.01, 0.1, 0.259, 0.6, 1.0] {
        for bn in [0.01, 0.0161, 0.3, 1.0] {
            for alpha in [-10.0, 2.0, 10.0] {
                for eta in [1.55, 3.0] {
                    for sa in [[0.0; 3], [0.25, 0.5, 1.0], [2.0, 3.0, 5.0]] {
                        out.push(params(sa, eta, bm, bn, alpha));
                    }
                }
            }
        }
    }
    out
}

const HS: [f32; 7] = [-1.0, -0.99999, -0.5, 0.0, 0.9, 0.99999, 1.0];

/// wo near the tangent (two azimuths), wi over a grid of theta and phi and the issue's
/// example wi: 7 h x 16 wo x 31 wi.
fn wo_near_inputs() -> Vec<Input> {
    let mut wis: Vec<[f32; 3]> = Vec::new();
    for t in [-80.0f64, -30.0, 0.0, 16.76, 60.0] {
        for k in 0..6 {
            wis.push(round_f32(dir(t.to_radians(), -3.0 + 1.1 * k as f64)));
        }
    }
    let y = (1.0f64 - 0.2883 * 0.2883 - 0.9309 * 0.9309).sqrt() as f32;
    wis.push([-0.2883, y, 0.9309]);
    let mut out = Vec::new();
    for h in HS {
        for x in NEAR_TANGENT {
            for phi_o in [0.0, 2.0] {
                let wo = near(x, phi_o);
                out.extend(wis.iter().map(|&wi| Input { h, wo, wi }));
            }
        }
    }
    out
}

/// wi near the tangent (six azimuths), wo over a grid: 7 h x 8 wo x 48 wi.
fn wi_near_inputs() -> Vec<Input> {
    let mut out = Vec::new();
    for h in HS {
        for t in [-60.0f64, 0.0, 30.0, 80.0] {
            for phi_o in [0.0, 2.0] {
                let wo = round_f32(dir(t.to_radians(), phi_o));
                for x in NEAR_TANGENT {
                    for k in 0..6 {
                        let wi = near(x, -3.0 + 1.1 * k as f64);
                        out.push(Input { h, wo, wi });
                    }
                }
            }
        }
    }
    out
}

/// Worst relative error of one evaluator, with the input that gave it.
#[derive(Clone, Default)]
struct Worst(f64, String);

impl Worst {
    fn record(&mut self, rel: f64, what: impl FnOnce() -> String) {
        if rel > self.0 {
            *self = Worst(rel, what());
        }
    }

    fn merge(&mut self, o: Worst) {
        if o.0 > self.0 {
            *self = o;
        }
    }
}

/// The evaluators compared: the crate's three entry points and the pbrt yardstick.
const NAMES: [&str; 4] = ["eval", "HairPoint::eval", "eval_batch", "pbrt-v3 float"];

#[derive(Default)]
struct Stats {
    values: usize,
    /// Worst relative error per evaluator (pbrt: among its finite values).
    worst: [Worst; 4],
    /// Relative errors by decade per evaluator: [< 1e-6, 1e-6.., 1e-5.., 1e-4.., 1e-3..,
    /// >= 1e-2 or not finite].
    decades: [[usize; 6]; 4],
    /// Values where pbrt's float code gives NaN or infinity (h = +-1 without absorption:
    /// 0 / 0 in its residual lobe).
    pbrt_not_finite: usize,
    /// Values where an entry point of the crate is off by more than max(pbrt's error,
    /// FLOOR, SPREAD_FACTOR x the spread of the reference over one-ulp input changes).
    worse_than_pbrt: Vec<String>,
    /// Values that needed the spread allowance.
    needed_spread: usize,
}

impl Stats {
    fn merge(&mut self, o: Stats) {
        self.values += o.values;
        for (mine, theirs) in self.worst.iter_mut().zip(o.worst) {
            mine.merge(theirs);
        }
        for (mine, theirs) in self.decades.iter_mut().zip(o.decades) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b;
            }
        }
        self.pbrt_not_finite += o.pbrt_not_finite;
        self.worse_than_pbrt.extend(o.worse_than_pbrt);
        self.needed_spread += o.needed_spread;
    }
}

fn outputs(f: [f32; 3], pdf: f32) -> [f64; 4] {
    [f[0] as f64, f[1] as f64, f[2] as f64, pdf as f64]
}

fn reference_outputs(r: &RefHair, h: f32, wo: [f32; 3], wi: [f32; 3]) -> [f64; 4] {
    let e = r.eval(h as f64, widen(wo), widen(wi));
    [e.f[0], e.f[1], e.f[2], e.pdf]
}

/// How far the reference moves when the inputs move by one f32 ulp (h and eta +- 1 ulp,
/// and 8 draws with every component of wo and wi moved by -1, 0 or +1 ulp): no f32 code
/// can know its inputs better. Near the tangent this matters for the azimuth: one ulp of
/// wi.y = 4e-3 turns wi by 1e-7 rad, one ulp of eta moves the TRT lobe's centre by up to
/// 1e-7 rad, and a logistic of scale 0.0017 turns each into 6e-5.
fn spread(p: &HairParams, x: &Input, base: &[f64; 4], g: &mut Pcg64) -> [f64; 4] {
    let r = reference(p);
    let mut sp = [0.0f64; 4];
    let mut widen_max = |v: [f64; 4]| {
        for c in 0..4 {
            sp[c] = sp[c].max((v[c] - base[c]).abs());
        }
    };
    for d in [-1, 1] {
        let h = f32_step(x.h, d).clamp(-1.0, 1.0);
        widen_max(reference_outputs(&r, h, x.wo, x.wi));
        let eta = HairParams {
            eta: f32_step(p.eta, d).max(f32_step(1.0, 1)),
            ..*p
        };
        widen_max(reference_outputs(&reference(&eta), x.h, x.wo, x.wi));
    }
    for _ in 0..8 {
        widen_max(reference_outputs(
            &r,
            x.h,
            ulp_jitter(x.wo, g),
            ulp_jitter(x.wi, g),
        ));
    }
    sp
}

fn check(p: &HairParams, xs: &[Input], seed: u64) -> Stats {
    let b: HairBsdf = bsdf(p);
    let r: RefHair = reference(p);
    let pb = PbrtHair::new(p);
    let mut g = rng(seed);
    let mut st = Stats::default();
    let h: Vec<f32> = xs.iter().map(|x| x.h).collect();
    let wo: Vec<[f32; 3]> = xs.iter().map(|x| x.wo).collect();
    let wi: Vec<[f32; 3]> = xs.iter().map(|x| x.wi).collect();
    let mut bf = vec![[0.0f32; 3]; xs.len()];
    let mut bp = vec![0.0f32; xs.len()];
    b.eval_batch(&h, &wo, &wi, &mut bf, &mut bp).unwrap();
    for (k, x) in xs.iter().enumerate() {
        let e = b.eval(x.h, v3f(x.wo), v3f(x.wi));
        let pe = b.at(x.h, v3f(x.wo)).eval(v3f(x.wi));
        let (pf, pp) = pb.eval(x.h, x.wo, x.wi);
        let got = [
            outputs(e.f.to_array(), e.pdf),
            outputs(pe.f.to_array(), pe.pdf),
            outputs(bf[k], bp[k]),
            outputs(pf, pp),
        ];
        let want = reference_outputs(&r, x.h, x.wo, x.wi);
        let cos_wi = (x.wi[2] as f64).abs();
        let mut sp: Option<[f64; 4]> = None;
        for c in 0..4 {
            // The absolute floor applies to what a renderer uses: f |wi.z| and pdf.
            let scale = if c < 3 && cos_wi > 0.0 { cos_wi } else { 1.0 };
            if want[c] * scale <= ABS_TOL {
                continue;
            }
            st.values += 1;
            // An error below the absolute floor counts as none; NaN stays NaN.
            let rel = got.map(|v| {
                let err = (v[c] - want[c]).abs();
                if err * scale <= ABS_TOL {
                    0.0
                } else {
                    err / want[c]
                }
            });
            let describe = |i: usize| {
                format!(
                    "output {c} (0-2 f rgb, 3 pdf): {} {:e} (rel err {:.2e}), pbrt {:e} ({:.2e}), reference {:e}; {p:?} {x:?}",
                    NAMES[i], got[i][c], rel[i], got[3][c], rel[3], want[c]
                )
            };
            for (i, &e) in rel.iter().enumerate() {
                let d = if e.is_finite() {
                    (e.log10().floor() + 7.0).clamp(0.0, 5.0) as usize
                } else {
                    5
                };
                st.decades[i][d] += 1;
                if e.is_finite() {
                    st.worst[i].record(e, || describe(i));
                }
            }
            let pbrt_err = if rel[3].is_finite() {
                rel[3]
            } else {
                st.pbrt_not_finite += 1;
                f64::INFINITY
            };
            let allowed = pbrt_err.max(FLOOR);
            if rel[..3].iter().all(|&e| e <= allowed) {
                continue;
            }
            let sp = *sp.get_or_insert_with(|| spread(p, x, &want, &mut g));
            let allowed = allowed.max(SPREAD_FACTOR * sp[c] / want[c]);
            st.needed_spread += 1;
            for (i, &e) in rel[..3].iter().enumerate() {
                if e.is_nan() || e > allowed {
                    st.worse_than_pbrt.push(format!(
                        "{}, reference spread {:.2e}",
                        describe(i),
                        sp[c] / want[c]
                    ));
                }
            }
        }
    }
    st
}

fn run(name: &str, xs: &[Input], seed: u64) -> Stats {
    let sets = param_grid();
    let jobs: Vec<(usize, &HairParams)> = sets.iter().enumerate().collect();
    let mut total = Stats::default();
    for st in par_map(&jobs, |&(i, p)| check(p, xs, seed + i as u64)) {
        total.merge(st);
    }
    println!(
        "{name}: {} values ({} inputs x {} parameter sets)",
        total.values,
        xs.len(),
        sets.len()
    );
    for (n, (w, d)) in NAMES.iter().zip(total.worst.iter().zip(&total.decades)) {
        println!(
            "  {n}: relative errors by decade (<1e-6, 1e-6.., 1e-5.., 1e-4.., 1e-3.., >=1e-2 or not finite) {d:?}"
        );
        println!("  {n}: worst {:.3e}: {}", w.0, w.1);
    }
    println!(
        "  pbrt not finite on {} values; {} values needed the allowance of the reference's spread over one-ulp input changes",
        total.pbrt_not_finite, total.needed_spread
    );
    println!(
        "  {} values where the crate is less accurate than pbrt's float code",
        total.worse_than_pbrt.len()
    );
    for s in total.worse_than_pbrt.iter().take(10) {
        println!("    {s}");
    }
    total
}

/// Near the tangent (wo or wi within 0.02 rad of it, azimuth defined), over 5.7 million
/// compared values, every entry point of the crate (`eval`, `HairPoint::eval`,
/// `eval_batch`) is:
/// - within PBRT_BOUND (5.4e-4, pbrt-v3's float error on the inputs) of the f64
///   reference everywhere, and its worst error is no larger than pbrt's worst;
/// - value by value, no less accurate than pbrt-v3's float arithmetic on the same input,
///   unless both are within FLOOR (2e-5) or the crate is within twice the reference's
///   own spread over one-ulp changes of the inputs (1431 of the 5.7 million values need
///   that: narrow logistics, beta_n 0.01, where pbrt happens to round closer).
///
/// Before the fix, 1 - F near grazing Fresnel was taken by subtraction (7e-3 off in TT
/// and the residual lobe at h = 0.99999) and the azimuthal offsets went through angles
/// near pi (1.4e-4 per ulp of pi for the narrowest logistic): worst 7.1e-3 where pbrt is
/// within 4.9e-4.
#[test]
fn near_tangent_at_least_as_accurate_as_pbrt_float() {
    let _t = Timer::start("near_tangent_at_least_as_accurate_as_pbrt_float");
    for (name, xs, seed) in [
        ("wo near the tangent", wo_near_inputs(), 30_000),
        ("wi near the tangent", wi_near_inputs(), 40_000),
    ] {
        let st = run(name, &xs, seed);
        assert!(
            st.worse_than_pbrt.is_empty(),
            "{name}: {} values less accurate than pbrt's float code (listed above with --nocapture); first: {:?}",
            st.worse_than_pbrt.len(),
            st.worse_than_pbrt.first()
        );
        let pbrt_worst = st.worst[3].0;
        for (n, w) in NAMES.iter().zip(&st.worst).take(3) {
            assert!(
                w.0 <= PBRT_BOUND && w.0 <= pbrt_worst,
                "{name}: {n} worst error {:.3e} above {PBRT_BOUND:e} or pbrt's worst {pbrt_worst:.3e}: {}",
                w.0,
                w.1
            );
        }
    }
}
