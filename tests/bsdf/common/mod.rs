//! Shared helpers of the BSDF integration tests: independent f64 references of the hair
//! model ([`reference`]) and of the Huang model ([`huang_reference`]), quadrature
//! ([`quad`]), the chi-square harness ([`chi2`]) and direction helpers ([`sphere`]), plus
//! the glue between them and the crate's f32 API.

pub mod chi2;
pub mod huang_reference;
pub mod pbrt_f32;
pub mod quad;
pub mod reference;
pub mod sphere;

use glam::Vec3;
use hairtrace::{HairBsdf, HairParams};
use rand::SeedableRng;
use rand_pcg::Pcg64;
use reference::RefHair;

/// The deterministic generator of every test (PCG-XSL-RR 128/64).
pub fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

pub fn params(sigma_a: [f32; 3], eta: f32, beta_m: f32, beta_n: f32, alpha: f32) -> HairParams {
    HairParams {
        sigma_a,
        eta,
        beta_m,
        beta_n,
        alpha,
    }
}

/// The absorption of the default (brown) hair.
pub fn brown() -> [f32; 3] {
    HairParams::default().sigma_a
}

/// The crate's BSDF; panics with the parameters if they are rejected.
pub fn bsdf(p: &HairParams) -> HairBsdf {
    HairBsdf::new(p).unwrap_or_else(|e| panic!("HairBsdf::new({p:?}) failed: {e}"))
}

/// The f64 reference for exactly the same (f32) parameters.
pub fn reference(p: &HairParams) -> RefHair {
    RefHair::new(
        p.sigma_a.map(f64::from),
        p.eta as f64,
        p.beta_m as f64,
        p.beta_n as f64,
        p.alpha as f64,
    )
}

pub fn v3(w: [f64; 3]) -> Vec3 {
    Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32)
}

pub fn v3f(w: [f32; 3]) -> Vec3 {
    Vec3::from_array(w)
}

pub fn d3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Theta and phi (radians) of a degree pair, as a direction.
pub fn dir_deg(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
    sphere::dir(theta_deg.to_radians(), phi_deg.to_radians())
}

/// A short timer that prints how long a test took.
pub struct Timer(std::time::Instant, &'static str);

impl Timer {
    pub fn start(name: &'static str) -> Self {
        Timer(std::time::Instant::now(), name)
    }
}

impl Drop for Timer {
    fn drop(&mut self) {
        println!("[{}] {:.2} s", self.1, self.0.elapsed().as_secs_f64());
    }
}

/// A random valid absorption channel: zero, log-uniform over [1e-3, 1e3], uniform over
/// [0, 10], or huge (1e6, 1e30).
pub fn random_sigma(g: &mut impl rand::Rng) -> f32 {
    match g.random_range(0..10) {
        0 | 1 => 0.0,
        2 => [1e6, 1e30][g.random_range(0..2)],
        3 => g.random_range(0.0..10.0),
        _ => 10f32.powf(g.random_range(-3.0..3.0)),
    }
}

/// Random valid parameters: roughness log-uniform over [0.01, 1] (so the narrow lobes
/// are well represented), eta over (1, 3], alpha over [-20, 20]; `absorbing` picks
/// random absorption per channel, otherwise sigma_a = 0.
pub fn random_params(g: &mut impl rand::Rng, absorbing: bool) -> HairParams {
    let sigma_a = if absorbing {
        [random_sigma(g), random_sigma(g), random_sigma(g)]
    } else {
        [0.0; 3]
    };
    params(
        sigma_a,
        g.random_range(1.0001..=3.0),
        random_beta(g),
        random_beta(g),
        g.random_range(-20.0..=20.0),
    )
}

/// A roughness log-uniform over [0.01, 1].
pub fn random_beta(g: &mut impl rand::Rng) -> f32 {
    10f32.powf(g.random_range(-2.0..=0.0)).clamp(0.01, 1.0)
}

/// Three uniform numbers in [0, 1) for `sample`.
pub fn random_u(g: &mut impl rand::Rng) -> [f32; 3] {
    [g.random(), g.random(), g.random()]
}

/// A random h: uniform over [-1, 1], with the ends themselves 5% of the time.
pub fn random_h(g: &mut impl rand::Rng) -> f32 {
    match g.random_range(0..40) {
        0 => -1.0,
        1 => 1.0,
        _ => g.random_range(-1.0..=1.0),
    }
}

/// Test functions of a sampled direction, for paired comparisons of two sample weights:
/// 1, each hemisphere in x, y and z, and wi.x^2.
pub const WEIGHT_TESTS: [fn(Vec3) -> f64; 5] = [
    |_| 1.0,
    |w| f64::from(w.x > 0.0),
    |w| f64::from(w.y > 0.0),
    |w| f64::from(w.z > 0.0),
    |w| f64::from(w.x * w.x),
];

/// Maps `f` over `items` on all cores, keeping the order (deterministic as long as each
/// item is computed independently, e.g. with its own seed). Items are handed out one at
/// a time, so uneven costs still balance.
pub fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let next = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<R>>> = Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..threads.min(items.len()) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= items.len() {
                        break;
                    }
                    let r = f(&items[i]);
                    out.lock().unwrap()[i] = Some(r);
                }
            });
        }
    });
    out.into_inner()
        .unwrap()
        .into_iter()
        .map(Option::unwrap)
        .collect()
}
