//! Samples where the noise is: a pilot pass, whose samples decide how the later passes
//! share their samples among pixels, in the blocks where the pilot says that pays.
//!
//! Why it stays unbiased: every pixel takes its samples in the order of its own sequence,
//! the pilot's first, so its image is the mean of the first N samples of that sequence,
//! unbiased for any N chosen independently of them. Its N is: it is read from the pilot
//! of its neighbours alone (those of the other colour of a checkerboard), whose scrambles
//! are independent of its own. A count read from the pixel's own pilot would correlate
//! with it (a strand in the pilot means noise, so many samples, so a small pilot weight)
//! and bias it.
//!
//! Why crops stay exact: a pixel's share depends only on the pilot of its block
//! ([`BLOCK`] pixels square, aligned on the full frame), and a crop renders the pilot
//! over every block it touches.

use std::ops::Range;

use super::film::{Film, PixelAccumulator, Window, relative_rmse};

/// Side of the square blocks, aligned on the full frame, among whose pixels each pass
/// shares the samples a uniform pass would give them.
pub const BLOCK: u32 = 32;

/// A pixel's share is at least this fraction of its block's mean share (plus its own), so
/// that a pixel whose pilot saw no noise (a strand its 8 samples missed) still converges.
const FLOOR: f64 = 0.1;

/// The least [`gain`] for which a block's pixels of one colour share their samples by
/// noise; below it they take a uniform share. The pilot's noisy estimates overstate the
/// gain: on the bench scenes sharing everywhere lost 4% of MSE on the scalp, and from 1.3
/// no scene lost (docs/measurements.md).
const MIN_GAIN: f64 = 1.3;

/// The most spp a render takes with this allocation (`renderer::allocation_taken`): a pass
/// gives a pixel at most its colour's half of a block's samples (512 pixels x 8, 2^12),
/// so over 2^19 passes its sample indices stay below 2^31 plus the pilot's, within a u32.
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

/// The blocks of `window` (whole blocks aligned on the full frame, but at its right and
/// bottom edges), row by row.
pub(super) fn blocks(window: Window) -> impl Iterator<Item = Window> {
    (window.y0..window.y1)
        .step_by(BLOCK as usize)
        .flat_map(move |y0| {
            (window.x0..window.x1)
                .step_by(BLOCK as usize)
                .map(move |x0| Window {
                    x0,
                    y0,
                    x1: (x0 + BLOCK).min(window.x1),
                    y1: (y0 + BLOCK).min(window.y1),
                })
        })
}

/// Samples per pass of each pixel of a crop, as the pilot decided them.
#[derive(Debug)]
pub(super) struct Shares {
    crop: Window,
    /// The pilot's samples per pixel: where each pixel's later samples start.
    pilot: u32,
    counts: Vec<u32>,
}

impl Shares {
    /// Shares of `crop`'s pixels from `pilot` (rendered over [`pilot_window`]): each
    /// block's pixels share `per_pixel` x its pixel count in proportion to sigma / sqrt(cost)
    /// (which minimises the block's summed variance for its rays), where sigma is the
    /// standard deviation of a sample and the cost the rays per sample, both over the
    /// pixel's neighbours ([`block_shares`]), plus [`FLOOR`].
    pub(super) fn new(pilot: &Film, crop: Window, per_pixel: u32) -> Shares {
        let mut counts = vec![per_pixel; crop.pixel_count() as usize];
        for block in blocks(pilot.crop()) {
            for ((x, y), n) in block_shares(pilot, block, per_pixel) {
                if (crop.x0..crop.x1).contains(&x) && (crop.y0..crop.y1).contains(&y) {
                    let i = (y - crop.y0) * crop.width() + (x - crop.x0);
                    counts[i as usize] = n;
                }
            }
        }
        Shares {
            crop,
            pilot: per_pixel,
            counts,
        }
    }

    /// Sample indices of `pixel` (full-frame, inside the crop) in `pass` (from 1, after
    /// the pilot): the next of its own sequence.
    pub(super) fn indices(&self, (x, y): (u32, u32), pass: u32) -> Range<u32> {
        let n = self.counts[((y - self.crop.y0) * self.crop.width() + (x - self.crop.x0)) as usize];
        self.pilot + (pass - 1) * n..self.pilot + pass * n
    }
}

/// Each pixel of `block` and its samples per pass. A pixel's share is read from the pilot
/// of the other colour of a checkerboard only (the pixels of the other colour within two
/// pixels, inside the block; each colour shares half the block's budget among its own),
/// so that it is independent of the pixel's own pilot: [`blend`] may then weight the
/// pilot by the pixel's count without bias. A colour whose [`gain`] is under [`MIN_GAIN`]
/// keeps `per_pixel` in every pixel.
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
    let estimates: Vec<(f64, f64)> = cells
        .iter()
        .map(|&(x, y)| (around(&variance, x, y), around(&cost, x, y).max(1.0)))
        .collect();
    let mut counts = vec![per_pixel; cells.len()];
    for colour in 0..2 {
        let mine: Vec<usize> = (0..cells.len())
            .filter(|&i| (cells[i].0 + cells[i].1) % 2 == colour)
            .collect();
        let estimated: Vec<(f64, f64)> = mine.iter().map(|&i| estimates[i]).collect();
        if gain(&estimated) < MIN_GAIN {
            continue;
        }
        let scores: Vec<f64> = estimated.iter().map(|(v, c)| (v / c).sqrt()).collect();
        let mean = scores.iter().sum::<f64>() / mine.len() as f64;
        let budget = f64::from(per_pixel) * mine.len() as f64;
        let total = (1.0 + FLOOR) * mean * mine.len() as f64;
        for (&i, score) in mine.iter().zip(scores) {
            let share = budget * (score + FLOOR * mean) / total;
            counts[i] = share.round().max(1.0) as u32;
        }
    }
    block.pixels().zip(counts).collect()
}

/// The efficiency (1 / (variance x rays)) that sharing samples in proportion to
/// sqrt(variance / cost) gains over a uniform share, for pixels of these (variance of a
/// sample, rays per sample): sum(v) sum(c) / sum(sqrt(v c))^2, at least 1 (Cauchy-Schwarz),
/// and 1 (nothing to gain) where no pixel shows noise.
fn gain(pixels: &[(f64, f64)]) -> f64 {
    let (v, c) = pixels
        .iter()
        .fold((0.0, 0.0), |(v, c), p| (v + p.0, c + p.1));
    let root: f64 = pixels.iter().map(|(v, c)| (v * c).sqrt()).sum();
    if root > 0.0 {
        v * c / (root * root)
    } else {
        1.0
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Even noise gains nothing and noise in one pixel of many gains most; a pixel whose
    /// rays cost more gains less from its samples, and a block with no noise shares
    /// uniformly.
    #[test]
    fn the_gain_is_the_efficiency_sharing_by_noise_buys() {
        assert!((gain(&[(2.0, 3.0); 50]) - 1.0).abs() < 1e-12);
        let mut one = vec![(0.0, 1.0); 63];
        one.push((1.0, 1.0));
        assert!((gain(&one) - 64.0).abs() < 1e-9);
        // Two pixels: v = 1, 4 at cost 1: (5 x 2) / (1 + 2)^2.
        assert!((gain(&[(1.0, 1.0), (4.0, 1.0)]) - 10.0 / 9.0).abs() < 1e-12);
        // The noisier pixel also costing 4x its rays: the gain falls to (5 x 5) / (1 + 4)^2.
        assert!((gain(&[(1.0, 1.0), (4.0, 4.0)]) - 1.0).abs() < 1e-12);
        assert_eq!(gain(&[(0.0, 2.0); 8]), 1.0);
        assert_eq!(gain(&[]), 1.0);
        assert!(gain(&[(1.0, 1.0), (4.0, 1.0)]) < MIN_GAIN && gain(&one) > MIN_GAIN);
    }
}
