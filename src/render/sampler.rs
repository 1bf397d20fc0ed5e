//! The numbers that drive every random decision of a camera path, from a padded,
//! Owen-scrambled Sobol sequence (Burley 2020, through `sobol_burley`).
//!
//! A sample's numbers depend only on (seed, full-frame pixel, sample index, the order in
//! which the path asks for them): never on the thread, the tile order or the crop, so
//! renders are reproducible bit for bit and crops assemble into the full frame.
//!
//! Each request (`next_2d`, `next_4d`) takes the first dimensions of its own
//! independently scrambled sequence, seeded from the pixel and the request's position
//! ("padding", as pbrt-v4's PaddedSobolSampler does): every 2D request (a lens point, a
//! light sample) is stratified across the pixel's samples, requests never correlate with
//! each other, and a path may ask for any number of them, as deep hair paths do.

use std::sync::LazyLock;

use sobol_burley::parts::{hash, owen_scramble_rev, sobol_rev, u32_to_f32_norm};

use crate::math::mix64;

/// `sobol_burley` holds 2^16 samples per sequence; past that, blocks of 2^16 get their own
/// scramble, which keeps values valid and independent (only the stratification across
/// blocks is lost).
const BLOCK_BITS: u32 = 16;

/// What [`PixelSampler::time`] mixes into the pixel's seed, in place of a request number:
/// far from any request count a path reaches.
const TIME_KEY: u64 = 0x7469_6d65_0000_0000;

/// A cursor over one pixel sample's dimensions. Cheap to create (a few hashes): make one
/// per camera sample.
#[derive(Debug, Clone)]
pub struct PixelSampler {
    /// Scramble seed of this pixel and sample block.
    seed: u64,
    /// Index inside the 2^16 block.
    index: u32,
    /// Number of requests made so far.
    request: u32,
}

impl PixelSampler {
    /// Sample `sample_index` of the full-frame `pixel` in a render seeded with `seed`.
    pub fn new(seed: u64, pixel: (u32, u32), sample_index: u32) -> Self {
        let pixel_key = (u64::from(pixel.0) << 32) | u64::from(pixel.1);
        let block = u64::from(sample_index >> BLOCK_BITS);
        Self {
            seed: mix64(mix64(mix64(seed) ^ pixel_key) ^ block),
            index: sample_index & ((1 << BLOCK_BITS) - 1),
            request: 0,
        }
    }

    /// The scramble of the next request's sequence.
    fn next_sequence(&mut self) -> u32 {
        let s = mix64(self.seed ^ u64::from(self.request));
        self.request = self.request.wrapping_add(1);
        (s >> 32) as u32
    }

    /// Two numbers in [0, 1), jointly stratified.
    pub fn next_2d(&mut self) -> [f32; 2] {
        let s = self.next_sequence();
        owen_sobol(self.index, s)
    }

    /// Four numbers in [0, 1): the first four dimensions of one sequence, so the first
    /// two are as stratified as [`next_2d`](Self::next_2d)'s and all four jointly well
    /// spread. One request instead of several is what a path vertex needs most: the
    /// scramble hashes are the sampler's cost.
    pub fn next_4d(&mut self) -> [f32; 4] {
        let s = self.next_sequence();
        owen_sobol(self.index, s)
    }

    /// The sample's time, in [0, 1): its fraction of the shutter. A dimension of its own,
    /// seeded apart from the requests, so that it is stratified across the pixel's samples
    /// as a request's first dimension is, and that a render with motion blur asks the other
    /// numbers exactly as one without it does. It takes no request: call it at any point.
    pub fn time(&self) -> f32 {
        let s = mix64(self.seed ^ TIME_KEY);
        owen_sobol::<1>(self.index, (s >> 32) as u32)[0]
    }

    /// Passes over one request that this path does not need (a lens sample for a
    /// pinhole, a light sample where no light is sampled): later requests keep the
    /// sequences they would have had, at no cost.
    pub fn skip(&mut self) {
        self.request = self.request.wrapping_add(1);
    }
}

/// The first N (at most 4) dimensions of `sobol_burley::sample_4d(index, 0, seed)`, bit
/// for bit, at half its cost on baseline x86-64: the Sobol matrix product, a loop over the
/// index's bits there, is two lookups in [`SOBOL_BYTES`] here, and the scrambles run as
/// scalar integer code (the crate's four-lane multiplies need SSE4.1).
#[inline]
fn owen_sobol<const N: usize>(index: u32, seed: u32) -> [f32; N] {
    // Nested uniform shuffle of the index: which point of the sequence this sample takes.
    let shuffled = owen_scramble_rev(index.reverse_bits(), hash(seed ^ 0x79c6_8e4a));
    let table = &*SOBOL_BYTES;
    let (hi, lo) = (
        &table[0][(shuffled >> 24) as usize],
        &table[1][((shuffled >> 16) & 0xff) as usize],
    );
    // Per-dimension Owen scramble seeds, as the crate derives them for dimension set 0.
    const DIMENSION_KEYS: [u32; 4] = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8];
    let seed = seed.wrapping_mul(0x9c8f_2d3b);
    std::array::from_fn(|d| {
        let scrambled = owen_scramble_rev(hi[d] ^ lo[d], hash(seed ^ DIMENSION_KEYS[d]));
        u32_to_f32_norm(scrambled.reverse_bits())
    })
}

/// The Sobol points (bit-reversed, dimensions 0-3) of the bit-reversed indices whose
/// only set bits are in their top byte ([0]) or their second byte ([1]): a 16-bit
/// index's point is the XOR of one entry of each, the product being linear over GF(2).
static SOBOL_BYTES: LazyLock<Box<[[[u32; 4]; 256]; 2]>> = LazyLock::new(|| {
    let point = |rev_index: u32| std::array::from_fn(|d| sobol_rev(rev_index, d as u32));
    Box::new([
        std::array::from_fn(|b| point((b as u32) << 24)),
        std::array::from_fn(|b| point((b as u32) << 16)),
    ])
});

#[cfg(test)]
mod tests {
    use super::*;

    fn correlation(a: &[f32], b: &[f32]) -> f64 {
        let n = a.len() as f64;
        let mean = |x: &[f32]| x.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let (ma, mb) = (mean(a), mean(b));
        let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
        for (&x, &y) in a.iter().zip(b) {
            let (dx, dy) = (f64::from(x) - ma, f64::from(y) - mb);
            sab += dx * dy;
            saa += dx * dx;
            sbb += dy * dy;
        }
        sab / (saa * sbb).sqrt()
    }

    #[test]
    fn the_table_gives_the_crates_samples_bit_for_bit() {
        let mut seed = 1u64;
        for index in (0..1 << BLOCK_BITS).step_by(7).chain([0, 1, 65_535]) {
            seed = mix64(seed);
            let s = (seed >> 32) as u32;
            let expected = sobol_burley::sample_4d(index, 0, s);
            assert_eq!(
                owen_sobol::<4>(index, s),
                expected,
                "index {index} seed {s}"
            );
            assert_eq!(owen_sobol::<2>(index, s), [expected[0], expected[1]]);
        }
    }

    #[test]
    fn deterministic_and_in_range() {
        let draw = |seed, pixel, i| {
            let mut s = PixelSampler::new(seed, pixel, i);
            let [a, b, c, d] = s.next_4d();
            let [e, f] = s.next_2d();
            [a, b, c, d, e, f]
        };
        for i in [0, 1, 17, 65_535, 65_536, 1 << 20, u32::MAX] {
            let v = draw(42, (3, 9), i);
            assert_eq!(v, draw(42, (3, 9), i));
            assert!(v.iter().all(|x| (0.0..1.0).contains(x)), "{v:?}");
            assert_ne!(v, draw(43, (3, 9), i));
            assert_ne!(v, draw(42, (9, 3), i));
        }
    }

    #[test]
    fn first_64_samples_are_stratified_in_every_request() {
        for pixel in [(0, 0), (1, 0), (640, 480)] {
            // Requests at several depths of a path: each is its own stratified sequence.
            for request in 0..5 {
                let mut grid = [0u8; 64];
                let mut strata_x = [0u8; 64];
                let mut strata_y = [0u8; 64];
                for i in 0..64 {
                    let mut s = PixelSampler::new(7, pixel, i);
                    for _ in 0..request {
                        s.next_2d();
                    }
                    let [x, y] = s.next_2d();
                    grid[(y * 8.0) as usize * 8 + (x * 8.0) as usize] += 1;
                    strata_x[(x * 64.0) as usize] += 1;
                    strata_y[(y * 64.0) as usize] += 1;
                }
                assert!(grid.iter().all(|&c| c == 1), "8x8 strata: {grid:?}");
                assert!(strata_x.iter().all(|&c| c == 1) && strata_y.iter().all(|&c| c == 1));
            }
        }
    }

    #[test]
    fn a_four_dimensional_request_is_stratified_in_each_dimension_and_its_first_pair() {
        for request in 0..3 {
            let mut strata = [[0u8; 64]; 4];
            let mut grid = [0u8; 64];
            for i in 0..64 {
                let mut s = PixelSampler::new(11, (5, 6), i);
                for _ in 0..request {
                    s.next_4d();
                }
                let v = s.next_4d();
                for (d, x) in v.iter().enumerate() {
                    strata[d][(x * 64.0) as usize] += 1;
                }
                grid[(v[1] * 8.0) as usize * 8 + (v[0] * 8.0) as usize] += 1;
            }
            assert!(strata.iter().flatten().all(|&c| c == 1), "{strata:?}");
            assert!(grid.iter().all(|&c| c == 1), "8x8 strata: {grid:?}");
        }
    }

    #[test]
    fn the_time_is_stratified_and_apart_from_the_requests() {
        for pixel in [(0, 0), (7, 3)] {
            let mut strata = [0u8; 64];
            for i in 0..64 {
                let s = PixelSampler::new(5, pixel, i);
                let t = s.time();
                assert!((0.0..1.0).contains(&t), "{t}");
                strata[(t * 64.0) as usize] += 1;
                // Asking it changes none of the requests.
                let mut asked = s.clone();
                let _ = asked.time();
                let mut plain = PixelSampler::new(5, pixel, i);
                assert_eq!(asked.next_4d(), plain.next_4d());
            }
            assert!(strata.iter().all(|&c| c == 1), "{strata:?}");
        }
        let n = 4096;
        let times: Vec<f32> = (0..n)
            .map(|i| PixelSampler::new(1, (10, 10), i).time())
            .collect();
        let bound = 4.0 / (n as f64).sqrt();
        for request in 0..3 {
            let other: Vec<f32> = (0..n)
                .map(|i| {
                    let mut s = PixelSampler::new(1, (10, 10), i);
                    for _ in 0..request {
                        s.next_4d();
                    }
                    s.next_2d()[0]
                })
                .collect();
            let r = correlation(&times, &other);
            assert!(r.abs() < bound, "request {request}: correlation {r}");
        }
    }

    #[test]
    fn pixels_and_requests_are_decorrelated() {
        let n = 4096;
        let series = |seed, pixel: (u32, u32), skip: usize| -> Vec<f32> {
            (0..n)
                .map(|i| {
                    let mut s = PixelSampler::new(seed, pixel, i);
                    for _ in 0..skip {
                        s.next_4d();
                    }
                    s.next_4d()[0]
                })
                .collect()
        };
        let base = series(1, (10, 10), 0);
        // 4 / sqrt(n) is four standard deviations of the correlation of independent series.
        let bound = 4.0 / (n as f64).sqrt();
        for other in [
            series(1, (11, 10), 0),
            series(1, (10, 11), 0),
            series(2, (10, 10), 0),
            series(1, (10, 10), 1),
            series(1, (10, 10), 40),
        ] {
            let r = correlation(&base, &other);
            assert!(r.abs() < bound, "correlation {r}");
        }
    }
}
