//! The Rust vertex that bench/c_bsdf compares the C calls with: `HairBsdf::at` + `eval` +
//! `sample` on the inputs bench.c draws (its generator, its order of draws, its two
//! materials, alternating), timed with its protocol: 41 interleaved rounds over 4096 inputs,
//! medians of ns per vertex. Run by bench/c_bsdf/run (`cargo bench -p hairtrace-benches --bench c_vertex`).

use glam::Vec3;
use hairtrace::bsdf::sigma_a_from_melanin;
use hairtrace::{HairBsdf, HairParams};
use std::hint::black_box;
use std::time::Instant;

const N: usize = 4096;
const ROUNDS: usize = 41;

/// bench.c's xorshift64*: 24 bits in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / 16_777_216.0
    }

    fn unit(&mut self) -> [f32; 3] {
        let z = 2.0 * self.uniform() - 1.0;
        // bench.c's 6.2831853f is this f32.
        let phi = std::f32::consts::TAU * self.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        [z, r * phi.cos(), r * phi.sin()]
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut blond = HairParams {
        beta_m: 0.12,
        alpha: -3.0,
        ..HairParams::default()
    };
    blond.sigma_a = sigma_a_from_melanin(0.3, 0.2).expect("valid melanin");
    let bsdfs = [HairParams::default(), blond].map(|p| HairBsdf::new(&p).expect("valid"));
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let inputs: Vec<(f32, Vec3, Vec3, [f32; 3])> = (0..N)
        .map(|_| {
            let h = 2.0 * rng.uniform() - 1.0;
            let (wo, wi) = (rng.unit(), rng.unit());
            let u = [rng.uniform(), rng.uniform(), rng.uniform()];
            (h, wo.into(), wi.into(), u)
        })
        .collect();
    let vertex = || {
        for (i, &(h, wo, wi, u)) in inputs.iter().enumerate() {
            let point = bsdfs[i & 1].at(h, wo);
            black_box(point.eval(wi));
            black_box(point.sample(u));
        }
    };
    let points: Vec<_> = (inputs.iter().enumerate())
        .map(|(i, &(h, wo, _, _))| bsdfs[i & 1].at(h, wo))
        .collect();
    let at = || {
        for (i, &(h, wo, _, _)) in inputs.iter().enumerate() {
            black_box(bsdfs[i & 1].at(h, wo));
        }
    };
    let eval = || {
        for (p, &(_, _, wi, _)) in points.iter().zip(&inputs) {
            black_box(p.eval(wi));
        }
    };
    let sample = || {
        for (p, &(_, _, _, u)) in points.iter().zip(&inputs) {
            black_box(p.sample(u));
        }
    };
    let methods: [(&str, &dyn Fn()); 4] = [
        ("Rust vertex (at + eval + sample)", &vertex),
        ("Rust HairBsdf::at", &at),
        ("Rust HairPoint::eval", &eval),
        ("Rust HairPoint::sample", &sample),
    ];
    let mut ns = vec![Vec::with_capacity(ROUNDS); methods.len()];
    for _ in 0..ROUNDS {
        for (k, (_, run)) in methods.iter().enumerate() {
            let t0 = Instant::now();
            run();
            ns[k].push(t0.elapsed().as_secs_f64() * 1e9 / N as f64);
        }
    }
    for ((name, _), ns) in methods.iter().zip(ns) {
        println!("{name:<44} {:8.1}", median(ns));
    }
}
