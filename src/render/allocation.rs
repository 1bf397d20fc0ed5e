//! Samples where the noise is: a pilot pass, whose samples decide how the later passes
//! share their samples among pixels and then enter each pixel with a fixed weight.
//!
//! Why it stays unbiased: a pixel's later samples come from a sequence of their own
//! (sample indices from [`ALLOCATED`]: independently scrambled), so their mean is
//! unbiased whatever number the pilot chose; the pilot's mean is unbiased; and the weight
//! that combines the two, the pilot's share of the pixel's samples, is independent of the
//! pixel's own pilot, because its count is read from the pilot of its neighbours alone
//! (those of the other colour of a checkerboard). A count read from the pixel's own pilot
//! would correlate with it (a strand in the pilot means noise, so many samples, so a small
//! pilot weight) and bias it.
//!
//! Why crops stay exact: a pixel's share depends only on the pilot of its block
//! ([`BLOCK`] pixels square, aligned on the full frame), and a crop renders the pilot
//! over every block it touches.

use super::film::{Film, PixelAccumulator, Window, relative_rmse};

/// Side of the square blocks, aligned on the full frame, among whose pixels each pass
/// shares the samples a uniform pass would give them.
pub const BLOCK: u32 = 16;

/// A pixel's share is at least this fraction of its block's mean share (plus its own), so
/// that a pixel whose pilot saw no noise (a strand its 8 samples missed) still converges.
const FLOOR: f64 = 0.1;

/// The first sample index of the passes after the pilot: a block of the sampler's own
/// scramble ([`super::sampler`]), independent of the pilot's samples.
pub const ALLOCATED: u32 = 1 << 31;

/// The most spp a render with this allocation takes (`RenderSettings::validate`): its
/// passes' sample indices run from [`ALLOCATED`] up by at most a whole block's samples per
/// pass, 2^11, and must stay within a u32: 2^22 spp reach 2^31 + 2^30.
pub const MOST_SPP: u32 = 1 << 22;

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
    /// pixel's neighbours ([`block_shares`]), plus [`FLOOR`].
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

/// Each pixel of `block` and its samples per pass. A pixel's share is read from the pilot
/// of the other colour of a checkerboard only (the pixels of the other colour within two
/// pixels, inside the block; each colour shares half the block's budget among its own),
/// so that it is independent of the pixel's own pilot: [`blend`] may then weight the
/// pilot by the pixel's count without bias.
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
    // Means over the other colour's pixels within two pixels (never the pixel itself).
    let around = |v: &[f64], x: i64, y: i64| {
        let (mut sum, mut n) = (0.0, 0.0);
        for ny in (y - 2).max(0)..=(y + 2).min(h - 1) {
            for nx in (x - 2).max(0)..=(x + 2).min(w - 1) {
                if (nx + ny + x + y) % 2 == 1 {
                    sum += v[(ny * w + nx) as usize];
                    n += 1.0;
                }
            }
        }
        if n > 0.0 { sum / n } else { 0.0 }
    };
    let cells: Vec<(i64, i64)> = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).collect();
    let scores: Vec<f64> = cells
        .iter()
        .map(|&(x, y)| (around(&variance, x, y) / around(&cost, x, y).max(1.0)).sqrt())
        .collect();
    let mut counts = vec![per_pixel; cells.len()];
    for colour in 0..2 {
        let mine: Vec<usize> = (0..cells.len())
            .filter(|&i| (cells[i].0 + cells[i].1) % 2 == colour)
            .collect();
        let budget = f64::from(per_pixel) * mine.len() as f64;
        let mean = mine.iter().map(|&i| scores[i]).sum::<f64>() / mine.len().max(1) as f64;
        let total = (1.0 + FLOOR) * mean * mine.len() as f64;
        if total > 0.0 {
            for &i in &mine {
                let share = budget * (scores[i] + FLOOR * mean) / total;
                counts[i] = share.round().max(1.0) as u32;
            }
        }
    }
    block.pixels().zip(counts).collect()
}

/// The pilot's weight in a pixel: its share of the pixel's samples. Unbiased because the
/// pixel's count never depends on its own pilot ([`block_shares`]).
fn pilot_weight(pilot: &PixelAccumulator, own: &PixelAccumulator) -> f64 {
    let (p, o) = (f64::from(pilot.samples()), f64::from(own.samples()));
    if p + o > 0.0 { p / (p + o) } else { 1.0 }
}

/// Writes into `film` each pixel's blend of its pilot and its own samples.
pub(super) fn blend(film: &mut Film, pilot: &Film) {
    for p in film.crop().pixels() {
        let first = pilot.accumulator(p);
        let weight = pilot_weight(&first, &film.accumulator(p));
        film.store_blend(p, &first, weight);
    }
}

/// The estimated noise of [`blend`]'s image: the pilot's variance from its samples', the
/// rest's from its halves. None before two passes after the pilot.
pub(super) fn blended_noise(film: &Film, pilot: &Film) -> Option<f32> {
    let mut pixels = Vec::with_capacity(film.crop().pixel_count() as usize);
    for p in film.crop().pixels() {
        let (own, first) = (film.accumulator(p), pilot.accumulator(p));
        let wp = pilot_weight(&first, &own);
        let wa = 1.0 - wp;
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
