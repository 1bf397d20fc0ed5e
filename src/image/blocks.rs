//! Whether two ways of rendering a frame converge to the same image: the means of small
//! pixel blocks against the noise that seeds alone put between them.
//!
//! An RMSE mixes noise and bias; a block mean averages the noise down while a bias that
//! covers the block stays, so block means against their own noise show a bias far below
//! the RMSE's reach. The noise comes from the renders themselves: each side is two or more
//! seeds. Per-pixel variances summed over a block assume independent pixels, which a tent
//! filter breaks; the blocks' own seed-to-seed scatter calibrates that sum once for the
//! whole image (`noise_calibration`), so z-scores keep unit variance under any filter.

use super::Image;
use super::compare::rgb_values;
use crate::Result;
use crate::error::invalid_arg;

/// Block means of one set of renders against another's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockBias {
    /// Side of a square block in pixels (edge blocks are cut to the frame).
    pub block: usize,
    /// Blocks with any noise; a block with none on either side (identical pixels in every
    /// seed, such as an empty background) counts only if its means differ.
    pub blocks: usize,
    /// Mean, root mean square and largest magnitude of the blocks' z-scores (difference of
    /// means over its noise): unbiased renders give about 0, 1 and a few.
    pub z_mean: f64,
    pub z_rms: f64,
    pub z_max: f64,
    /// The top-left pixel (x, y) of the block with the largest |z|: where to look first.
    pub worst: (usize, usize),
    /// Share of blocks with |z| > 2: 4.6% for normal noise.
    pub over_two: f64,
    /// Ratio of the blocks' seed-to-seed variance to the sum of their pixels' variances:
    /// 1 for independent pixels, above 1 where a filter spreads samples across pixels.
    pub noise_calibration: f64,
    /// The whole frame's mean difference (images minus references) relative to the
    /// references' mean, and its standard deviation from the noise.
    pub mean_difference: f64,
    pub mean_difference_sigma: f64,
}

impl BlockBias {
    /// Expected share of |z| > 2 for standard normal z-scores.
    pub const NORMAL_OVER_TWO: f64 = 0.0455;

    /// Whether the blocks' scatter is what noise alone gives: the share over 2 within
    /// three binomial deviations of the normal share, no block beyond
    /// [`Self::largest_z_of_noise`], and the frame's mean difference within three of its
    /// deviations. The largest |z| catches a bias confined to a few blocks (a silhouette),
    /// which the share and the mean average away.
    pub fn within_noise(&self) -> bool {
        let p = Self::NORMAL_OVER_TWO;
        let share_sigma = (p * (1.0 - p) / self.blocks.max(1) as f64).sqrt();
        self.over_two <= p + 3.0 * share_sigma
            && self.z_max <= Self::largest_z_of_noise(self.blocks)
            && self.mean_difference.abs() <= 3.0 * self.mean_difference_sigma
    }

    /// The |z| that noise alone exceeds in some block of `blocks` one time in a hundred
    /// (Bonferroni: a two-sided normal tail of 0.01 / blocks), from the tail's asymptotic
    /// series, within a few percent of the tail from |z| = 2.5 on.
    pub fn largest_z_of_noise(blocks: usize) -> f64 {
        let target = 0.01 / blocks.max(1) as f64;
        let two_tails = |z: f64| {
            let density = (-0.5 * z * z).exp() / std::f64::consts::TAU.sqrt();
            let z2 = z * z;
            2.0 * density / z * (1.0 - 1.0 / z2 + 3.0 / (z2 * z2))
        };
        let (mut lo, mut hi) = (2.0, 40.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if two_tails(mid) > target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

/// One side's pixels: the seeds' mean and that mean's variance, per pixel (the RGB
/// channels' mean), and its block means per seed.
struct Side {
    mean: Vec<f64>,
    variance: Vec<f64>,
    seed_blocks: Vec<Vec<f64>>,
}

/// Blocks of a `width` x `height` frame in rows, each as the pixel indices it covers
/// (its first is its top-left pixel).
fn blocks(width: usize, height: usize, block: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    for by in (0..height).step_by(block) {
        for bx in (0..width).step_by(block) {
            let rows = by..(by + block).min(height);
            let cols = bx..(bx + block).min(width);
            out.push(
                rows.flat_map(|y| cols.clone().map(move |x| y * width + x))
                    .collect(),
            );
        }
    }
    out
}

fn mean_of(values: &[f64], pixels: &[usize]) -> f64 {
    pixels.iter().map(|&p| values[p]).sum::<f64>() / pixels.len() as f64
}

fn side(seeds: &[Vec<f64>], blocks: &[Vec<usize>]) -> Side {
    let per_pixel: Vec<Vec<f64>> = seeds
        .iter()
        .map(|rgb| {
            rgb.chunks_exact(3)
                .map(|c| c.iter().sum::<f64>() / 3.0)
                .collect()
        })
        .collect();
    let n = per_pixel.len() as f64;
    let pixels = per_pixel[0].len();
    let mut mean = vec![0.0; pixels];
    let mut variance = vec![0.0; pixels];
    for p in 0..pixels {
        let m = per_pixel.iter().map(|s| s[p]).sum::<f64>() / n;
        let ss = per_pixel.iter().map(|s| (s[p] - m).powi(2)).sum::<f64>();
        mean[p] = m;
        variance[p] = ss / (n - 1.0) / n;
    }
    let seed_blocks = per_pixel
        .iter()
        .map(|s| blocks.iter().map(|b| mean_of(s, b)).collect())
        .collect();
    Side {
        mean,
        variance,
        seed_blocks,
    }
}

/// The variance of a block's seed mean from its seeds' scatter (1 degree of freedom per
/// extra seed: too rough per block, summed over blocks for the calibration).
fn scatter(side: &Side, block: usize) -> f64 {
    let n = side.seed_blocks.len() as f64;
    let m = side.seed_blocks.iter().map(|s| s[block]).sum::<f64>() / n;
    let ss = side
        .seed_blocks
        .iter()
        .map(|s| (s[block] - m).powi(2))
        .sum::<f64>();
    ss / (n - 1.0) / n
}

/// Block means of `images` (seeds of one way of rendering) against `references` (seeds of
/// another), each side at least two renders of the same frame.
pub fn block_bias(images: &[Image], references: &[Image], block: usize) -> Result<BlockBias> {
    if images.len() < 2 || references.len() < 2 {
        return Err(invalid_arg!(
            "two or more seeds on each side are needed to measure their noise: {} and {}",
            images.len(),
            references.len()
        ));
    }
    if block == 0 {
        return Err(invalid_arg!("a block is at least one pixel"));
    }
    let all: Vec<&Image> = images.iter().chain(references).collect();
    let mut values = rgb_values(&all)?;
    let refs = values.split_off(images.len());
    let (width, height) = (images[0].width, images[0].height);
    let cells = blocks(width, height, block);
    let (a, b) = (side(&values, &cells), side(&refs, &cells));

    // Each block's noise from its pixels, then one calibration from the blocks' scatter.
    let summed: Vec<f64> = cells
        .iter()
        .map(|c| {
            let v: f64 = c.iter().map(|&p| a.variance[p] + b.variance[p]).sum();
            v / (c.len() * c.len()) as f64
        })
        .collect();
    let scattered: f64 = (0..cells.len())
        .map(|i| scatter(&a, i) + scatter(&b, i))
        .sum();
    let total: f64 = summed.iter().sum();
    let noise_calibration = if total > 0.0 { scattered / total } else { 1.0 };

    let mut z = Vec::with_capacity(cells.len());
    let mut worst = (0, 0.0f64);
    for (c, v) in cells.iter().zip(&summed) {
        let (mean_a, mean_b) = (mean_of(&a.mean, c), mean_of(&b.mean, c));
        let d = mean_a - mean_b;
        // The images hold f32s: a block whose seeds agree to the last bit (a sky summed
        // in another order by one side) shows no noise, and a difference in that bit,
        // the same in all its pixels, is none.
        let rounding = f64::from(f32::EPSILON) * mean_a.abs().max(mean_b.abs());
        let sigma = (v * noise_calibration).sqrt().max(rounding);
        // No noise and no rounding: both sides' block is black.
        if sigma == 0.0 {
            continue;
        }
        let score = d / sigma;
        if score.abs() > worst.1 {
            worst = (c[0], score.abs());
        }
        z.push(score);
    }
    let n = z.len().max(1) as f64;
    let frame = |s: &Side| s.mean.iter().sum::<f64>() / s.mean.len() as f64;
    let pixels = (width * height) as f64;
    let frame_variance: f64 = a
        .variance
        .iter()
        .zip(&b.variance)
        .map(|(x, y)| x + y)
        .sum::<f64>()
        * noise_calibration
        / (pixels * pixels);
    let reference_mean = frame(&b);
    let relative = |x: f64| {
        if reference_mean != 0.0 {
            x / reference_mean.abs()
        } else {
            x
        }
    };
    Ok(BlockBias {
        block,
        blocks: z.len(),
        z_mean: z.iter().sum::<f64>() / n,
        z_rms: (z.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
        z_max: worst.1,
        worst: (worst.0 % width, worst.0 / width),
        over_two: z.iter().filter(|v| v.abs() > 2.0).count() as f64 / n,
        noise_calibration,
        mean_difference: relative(frame(&a) - reference_mean),
        mean_difference_sigma: relative(frame_variance.sqrt()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// A `size` x `size` render of `level` with Gaussian noise of deviation `sigma` per
    /// pixel, optionally blurred horizontally (as a wide filter correlates pixels).
    fn render(
        size: usize,
        level: &dyn Fn(usize, usize) -> f64,
        sigma: f64,
        blur: bool,
        rng: &mut Pcg64,
    ) -> Image {
        let noise: Vec<f64> = (0..size * size)
            .map(|_| {
                // Box-Muller.
                let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
                sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect();
        let mut pixels = Vec::with_capacity(size * size * 3);
        for y in 0..size {
            for x in 0..size {
                let n = if blur {
                    let l = noise[y * size + x.saturating_sub(1)];
                    let r = noise[y * size + (x + 1).min(size - 1)];
                    (l + 2.0 * noise[y * size + x] + r) / 6.0f64.sqrt()
                } else {
                    noise[y * size + x]
                };
                let v = (level(x, y) + n) as f32;
                pixels.extend([v, v, v]);
            }
        }
        Image::new(size, size, 3, pixels)
    }

    fn seeds(
        n: usize,
        level: &dyn Fn(usize, usize) -> f64,
        blur: bool,
        rng: &mut Pcg64,
    ) -> Vec<Image> {
        (0..n).map(|_| render(64, level, 0.2, blur, rng)).collect()
    }

    #[test]
    fn noise_alone_is_within_noise_under_any_filter() {
        let mut rng = Pcg64::seed_from_u64(7);
        let level = |x: usize, y: usize| 0.5 + 0.3 * ((x * y) as f64).sin();
        for blur in [false, true] {
            let (a, b) = (
                seeds(2, &level, blur, &mut rng),
                seeds(3, &level, blur, &mut rng),
            );
            let r = block_bias(&a, &b, 8).unwrap();
            assert!(r.within_noise(), "{r:?}");
            assert!((r.z_rms - 1.0).abs() < 0.25, "{r:?}");
            // The blur's weights (1, 2, 1) / sqrt 6 make a block row's sum 116/6 times one
            // pixel's variance where independent pixels give 8.
            let expected = if blur { 116.0 / 48.0 } else { 1.0 };
            assert!((r.noise_calibration / expected - 1.0).abs() < 0.3, "{r:?}");
        }
    }

    #[test]
    fn a_bias_far_below_the_pixel_noise_is_found() {
        let mut rng = Pcg64::seed_from_u64(8);
        let flat = |_: usize, _: usize| 0.5;
        // 8% brighter in one quadrant: a fifth of one pixel's noise.
        let patch = |x: usize, y: usize| if x < 32 && y < 32 { 0.54 } else { 0.5 };
        let (a, b) = (
            seeds(4, &patch, false, &mut rng),
            seeds(4, &flat, false, &mut rng),
        );
        let r = block_bias(&a, &b, 8).unwrap();
        assert!(!r.within_noise(), "{r:?}");
        assert!(r.over_two > 0.1, "{r:?}");
        assert!(
            r.worst.0 < 32 && r.worst.1 < 32,
            "in the brighter quadrant: {r:?}"
        );
        assert!(r.mean_difference > 0.0, "{r:?}");
    }

    /// A flat sky beside noisy hair, the sky rounded differently in the last bit by one
    /// side's seeds (eight rays' sum over eight, against one ray's): within noise.
    #[test]
    fn a_difference_in_the_last_bit_is_none() {
        let mut rng = Pcg64::seed_from_u64(9);
        let (sky, rounded) = (0.08f32, f32::from_bits(0.08f32.to_bits() - 1));
        let mut seed = |sky: f32| {
            let noisy = render(64, &|_, _| 0.3, 0.2, false, &mut rng);
            let pixels = noisy
                .pixels
                .chunks_exact(3 * 64)
                .enumerate()
                .flat_map(|(y, row)| {
                    let row = row.to_vec();
                    (0..64).flat_map(move |x| {
                        let v = if y < 32 { row[3 * x] } else { sky };
                        [v, v, v]
                    })
                })
                .collect();
            Image::new(64, 64, 3, pixels)
        };
        let a = [seed(sky), seed(rounded)];
        let b = [seed(sky), seed(sky)];
        let r = block_bias(&a, &b, 8).unwrap();
        assert!(r.within_noise(), "{r:?}");
    }

    #[test]
    fn the_largest_z_of_noise_grows_with_the_blocks() {
        // Two-sided normal quantiles: 1% (2.576), 1e-4 (3.891), 1e-6 (4.892).
        for (blocks, z) in [(1, 2.576), (100, 3.891), (10_000, 4.892)] {
            let got = BlockBias::largest_z_of_noise(blocks);
            assert!((got / z - 1.0).abs() < 0.01, "{blocks}: {got} against {z}");
        }
    }

    #[test]
    fn a_bias_in_one_block_is_found() {
        let mut rng = Pcg64::seed_from_u64(9);
        let flat = |_: usize, _: usize| 0.5;
        // One 8x8 block of 64 (a silhouette's worth) 20% brighter.
        let spot = |x: usize, y: usize| if x < 8 && y < 8 { 0.6 } else { 0.5 };
        let (a, b) = (
            seeds(4, &spot, false, &mut rng),
            seeds(4, &flat, false, &mut rng),
        );
        let r = block_bias(&a, &b, 8).unwrap();
        assert!(r.over_two < 0.1 && r.z_max > 5.0, "{r:?}");
        assert_eq!(r.worst, (0, 0));
        assert!(!r.within_noise(), "{r:?}");
    }

    #[test]
    fn a_difference_without_noise_is_far_beyond_it() {
        let a = vec![Image::new(1, 1, 3, vec![1.0; 3]); 2];
        let b = vec![Image::new(1, 1, 3, vec![0.5; 3]); 2];
        let r = block_bias(&a, &b, 8).unwrap();
        // Measured against the f32s' rounding alone.
        assert_eq!((r.blocks, r.worst), (1, (0, 0)));
        assert!(r.z_max > 1e6, "{r:?}");
        assert!(!r.within_noise());
        assert!(block_bias(&a, &a, 8).unwrap().within_noise());
    }

    #[test]
    fn too_few_seeds_or_mismatched_images_are_errors() {
        let one = vec![Image::new(2, 2, 3, vec![0.0; 12])];
        let two = vec![one[0].clone(), one[0].clone()];
        assert!(
            block_bias(&one, &two, 8)
                .unwrap_err()
                .to_string()
                .contains("seeds")
        );
        assert!(block_bias(&two, &two, 0).is_err());
        let wide = vec![Image::new(3, 2, 3, vec![0.0; 18]); 2];
        assert!(
            block_bias(&two, &wide, 8)
                .unwrap_err()
                .to_string()
                .contains("size")
        );
    }
}
