//! The Rust side of python/bench/bsdf_batch.py: `HairBsdf::eval_batch` over 10^6 inputs
//! (h in [-1, 1], unit wo and wi), the median of `ROUNDS` calls printed in ns per
//! evaluation, for the Python package's batch to be compared with in the same run.

use hairtrace::{HairBsdf, HairParams};
use rand::{Rng, SeedableRng};
use std::time::Instant;

const N: usize = 1_000_000;
const ROUNDS: usize = 15;

fn main() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let mut unit = || loop {
        let v: [f32; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let l = v.iter().map(|x| x * x).sum::<f32>().sqrt();
        if (0.1..1.0).contains(&l) {
            break v.map(|x| x / l);
        }
    };
    let wo: Vec<[f32; 3]> = (0..N).map(|_| unit()).collect();
    let wi: Vec<[f32; 3]> = (0..N).map(|_| unit()).collect();
    let h: Vec<f32> = (0..N).map(|i| (i as f32 / N as f32) * 2.0 - 1.0).collect();
    let bsdf = HairBsdf::new(&HairParams::default()).expect("default parameters");
    let (mut f, mut pdf) = (vec![[0.0; 3]; N], vec![0.0; N]);
    let mut times: Vec<f64> = (0..ROUNDS)
        .map(|_| {
            let t = Instant::now();
            bsdf.eval_batch(&h, &wo, &wi, &mut f, &mut pdf)
                .expect("equal lengths");
            std::hint::black_box(&f);
            t.elapsed().as_secs_f64() * 1e9 / N as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!("{:.2}", times[ROUNDS / 2]);
}
