//! Samples where the noise is: a pilot pass, whose samples decide how the later passes
//! share their samples among pixels and then enter each pixel with a fixed weight.
//!
//! Why it stays unbiased: a pixel's later samples come from a sequence of their own
//! (sample indices from [`ALLOCATED`]: independently scrambled), so their mean is
//! unbiased whatever number the pilot chose; the pilot's mean is unbiased; and the weight
//! that combines the two is the pilot's share of the average samples per pixel, fixed by
//! the pass count alone. A weight that followed the pixel's own count would correlate with
//! its pilot (a bright strand in the pilot means noise, so many samples, so a small pilot
//! weight) and bias it.
//!
//! Why crops stay exact: a pixel's share depends only on the pilot of its block
//! ([`BLOCK`] pixels square, aligned on the full frame), and a crop renders the pilot
//! over every block it touches.

use super::film::{Film, Window, relative_rmse};

/// Side of the square blocks, aligned on the full frame, among whose pixels each pass
/// shares the samples a uniform pass would give them.
pub const BLOCK: u32 = 16;

/// A pixel's share is at least this fraction of its block's mean share (plus its own), so
/// that a pixel whose pilot saw no noise (a strand its 8 samples missed) still converges.
const FLOOR: f64 = 0.1;

/// The first sample index of the passes after the pilot: a block of the sampler's own
/// scramble ([`super::sampler`]), independent of the pilot's samples.
pub const ALLOCATED: u32 = 1 << 31;

/// `crop` grown to whole blocks, inside the `width` x `height` frame: the pilot's window.
pub(super) fn pilot_window(crop: Window, width: u32, height: u32) -> Window {
    let down = |v: u32| v / BLOCK * BLOCK;
    let up = |v: u32, max: u32| v.div_ceil(BLOCK).saturating_mul(BLOCK).min(max);
    Window {
        x0: down(crop.x0),
        y0: down(crop.y0),
        x1: up(crop.x1, width),
        y1: up(crop.y1, height),
    }
}

/// Samples per pass of each pixel of a crop, as the pilot decided them.
#[derive(Debug)]
pub(super) struct Shares {
    crop: Window,
    counts: Vec<u32>,
}

impl Shares {
    /// Shares of `crop`'s pixels from `pilot` (rendered over [`pilot_window`]): each
    /// block's pixels share `per_pixel` x its pixel count in proportion to sigma / sqrt(cost)
    /// (which minimises the block's summed variance for its rays), where sigma is the
    /// standard deviation of a sample and the cost the rays per sample, both over the
    /// pixel's 3 x 3 neighbours inside its block, plus [`FLOOR`].
    pub(super) fn new(pilot: &Film, crop: Window, per_pixel: u32) -> Shares {
        let mut counts = vec![0; crop.pixel_count() as usize];
        let blocks = pilot.crop();
        for by in (blocks.y0..blocks.y1).step_by(BLOCK as usize) {
            for bx in (blocks.x0..blocks.x1).step_by(BLOCK as usize) {
                let block = Window {
                    x0: bx,
                    y0: by,
                    x1: (bx + BLOCK).min(blocks.x1),
                    y1: (by + BLOCK).min(blocks.y1),
                };
                for ((x, y), n) in block_shares(pilot, block, per_pixel) {
                    if (crop.x0..crop.x1).contains(&x) && (crop.y0..crop.y1).contains(&y) {
                        let i = (y - crop.y0) * crop.width() + (x - crop.x0);
                        counts[i as usize] = n;
                    }
                }
            }
        }
        Shares { crop, counts }
    }

    /// Samples per pass of `pixel` (full-frame, inside the crop).
    pub(super) fn of(&self, (x, y): (u32, u32)) -> u32 {
        self.counts[((y - self.crop.y0) * self.crop.width() + (x - self.crop.x0)) as usize]
    }
}

/// Each pixel of `block` and its samples per pass.
fn block_shares(pilot: &Film, block: Window, per_pixel: u32) -> Vec<((u32, u32), u32)> {
    let (variance, cost): (Vec<f64>, Vec<f64>) = block
        .pixels()
        .map(|p| {
            let acc = pilot.accumulator(p);
            let cost = acc.rays() as f64 / f64::from(acc.samples().max(1));
            (acc.sample_variance().iter().sum::<f64>(), cost.max(1.0))
        })
        .unzip();
    let (w, h) = (block.width() as i64, block.height() as i64);
    let smooth = |v: &[f64], x: i64, y: i64| {
        let (mut sum, mut n) = (0.0, 0.0);
        for ny in (y - 1).max(0)..=(y + 1).min(h - 1) {
            for nx in (x - 1).max(0)..=(x + 1).min(w - 1) {
                sum += v[(ny * w + nx) as usize];
                n += 1.0;
            }
        }
        sum / n
    };
    let scores: Vec<f64> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| (smooth(&variance, x, y) / smooth(&cost, x, y)).sqrt())
        .collect();
    let budget = f64::from(per_pixel) * scores.len() as f64;
    let mean = scores.iter().sum::<f64>() / scores.len() as f64;
    let weights: Vec<f64> = scores.iter().map(|s| s + FLOOR * mean).collect();
    let total: f64 = weights.iter().sum();
    block
        .pixels()
        .zip(weights)
        .map(|(p, weight)| {
            let n = if total > 0.0 {
                (budget * weight / total).round().max(1.0) as u32
            } else {
                per_pixel
            };
            (p, n)
        })
        .collect()
}

/// Writes into `film` each pixel's pilot mean x `pilot_weight` + its own mean x the rest.
pub(super) fn blend(film: &mut Film, pilot: &Film, pilot_weight: f64) {
    for p in film.crop().pixels() {
        film.store_blend(p, pilot.accumulator(p), pilot_weight);
    }
}

/// The estimated noise of [`blend`]'s image: the pilot's variance from its samples', the
/// rest's from its passes'. None before two passes after the pilot.
pub(super) fn blended_noise(film: &Film, pilot: &Film, pilot_weight: f64) -> Option<f32> {
    let (wp, wa) = (pilot_weight, 1.0 - pilot_weight);
    let mut pixels = Vec::with_capacity(film.crop().pixel_count() as usize);
    for p in film.crop().pixels() {
        let (own, first) = (film.accumulator(p), pilot.accumulator(p));
        let (ma, va) = (own.mean_rgb(), own.variance_of_mean()?);
        let (mp, vp) = (first.mean_rgb(), first.sample_variance());
        let n = f64::from(first.samples().max(1));
        pixels.push((
            std::array::from_fn(|c| wp * mp[c] + wa * ma[c]),
            std::array::from_fn(|c| wp * wp * vp[c] / n + wa * wa * va[c]),
        ));
    }
    relative_rmse(pixels)
}
