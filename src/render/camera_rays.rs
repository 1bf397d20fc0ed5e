//! A camera sample traced as several rays spread over its pixel (`camera_rays`).
//!
//! Where strands far under a pixel wide show a bright sky between them, most of a pixel's
//! noise is which of the two a camera ray meets: stratifying the sample positions cannot
//! help when each pixel holds dozens of strands. A sample of k rays adds what the escaping
//! ones see exactly and goes on with one path from a ray that hit, picked at random and
//! weighted by how many hit (`World::camera_sample`): unbiased, since each ray is uniform
//! over the pixel and the picked path's expectation is the mean over the rays that hit.
//! The extra rays are occlusion queries from the eye, cheaper than the paths they stand
//! in for; where the strands cover the pixel, or the background is dim, they only cost.
//!
//! So `auto` (the default) chooses ([`Choice`]): the noise allocation's pilot takes its
//! first [`CHOOSING_SAMPLES`] with one ray, which tell, block by block, how much of a
//! sample's variance is which of background and hair its ray meets, and how wide the
//! strands it meets are; the rest of the render takes the count that a model of that
//! variance and of the rays' cost says makes the frame's noise cheapest, weighed against
//! the frame's mean variance and cost ([`FrameRates`]) (docs/measurements.md, "Camera
//! rays chosen per block").

use glam::Vec3;
use rayon::prelude::*;

use super::allocation::{BLOCK, blocks};
use super::film::{Film, PixelAccumulator, Window};

/// The most rays a camera sample may be traced as.
pub const MAX_CAMERA_RAYS: usize = 16;

/// The pilot's samples of a pixel traced with one ray, from which `auto` chooses for the
/// rest (and roulette learns its survival: `super::survival`): the same samples as a
/// render of one ray takes.
pub const CHOOSING_SAMPLES: u32 = 2;

/// The counts `auto` chooses among.
const COUNTS: [u32; 4] = [1, 2, 4, 8];

/// Strands at most this wide, in pixels, where their camera rays meet them: far under the
/// strata of the sampler's positions, which thus cannot tell strand from background
/// (wider strands' coverage the stratified positions already take: docs/measurements.md,
/// "Camera rays chosen per block").
const MAX_STRAND_WIDTH: f64 = 0.05;

/// The time of an extra camera ray (an occlusion query from the eye) over that of one of a
/// path's rays (docs/measurements.md, "Camera rays chosen per block").
const EXTRA_RAY_COST: f64 = 0.5;

/// Side of the cells of the lattices of pixels whose first samples measure a frame's
/// [`FrameRates`]: fixed on the full frame, so that a crop measures what the full frame
/// does.
const LATTICE: u32 = 8;

/// A frame's mean, over pixels, of a sample's variance (summed over channels) and of its
/// rays, from the first [`CHOOSING_SAMPLES`] (one ray each) of the pixels
/// (`LATTICE` i + colour, `LATTICE` j), all of that checkerboard colour: what a block's
/// gain in noise and extra rays are weighed against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct FrameRates {
    variance: f64,
    rays: f64,
}

impl FrameRates {
    /// The rates of the lattice of `colour` of `pilot`'s frame, and the rays traced for
    /// them: the pilot's own first samples where the lattice is inside its window (as its
    /// first [`CHOOSING_SAMPLES`] left them), else `sample`'s radiance and rays of sample
    /// `index` of a pixel traced as one ray: the same samples.
    pub(super) fn measure(
        pilot: &Film,
        colour: u32,
        sample: impl Fn((u32, u32), u32) -> (Vec3, u32) + Sync,
    ) -> (FrameRates, u64) {
        let (width, height, window) = (pilot.width(), pilot.height(), pilot.crop());
        let pixels = lattice(width, height, LATTICE, colour);
        let inside = |(x, y): (u32, u32)| {
            (window.x0..window.x1).contains(&x) && (window.y0..window.y1).contains(&y)
        };
        let per_pixel: Vec<(f64, f64, u64)> = pixels
            .par_iter()
            .map(|&p| {
                let (acc, traced) = if inside(p) {
                    (pilot.accumulator(p), 0)
                } else {
                    let mut acc = PixelAccumulator::default();
                    for index in 0..CHOOSING_SAMPLES {
                        let (radiance, rays) = sample(p, index);
                        acc.add(radiance, None);
                        acc.add_rays(rays);
                    }
                    let traced = acc.rays();
                    (acc, traced)
                };
                let n = f64::from(acc.samples().max(1));
                (
                    acc.sample_variance().iter().sum(),
                    acc.rays() as f64 / n,
                    traced,
                )
            })
            .collect();
        let n = per_pixel.len().max(1) as f64;
        let (variance, rays, traced) = per_pixel
            .iter()
            .fold((0.0, 0.0, 0), |(v, r, t), p| (v + p.0, r + p.1, t + p.2));
        let rates = FrameRates {
            variance: variance / n,
            rays: rays / n,
        };
        (rates, traced)
    }
}

/// The pixels (`x0` + `step` i, `step` j) of a `width` x `height` frame, row by row: the
/// full frame's, whatever the crop, so that a crop measures what the full frame does.
pub(super) fn lattice(width: u32, height: u32, step: u32, x0: u32) -> Vec<(u32, u32)> {
    (0..height)
        .step_by(step as usize)
        .flat_map(|y| (x0..width).step_by(step as usize).map(move |x| (x, y)))
        .collect()
}

/// The rays per camera sample of each pixel after the pilot's first
/// [`CHOOSING_SAMPLES`], block by block.
#[derive(Debug)]
pub(super) struct Choice {
    /// The pilot's window, whole blocks aligned on the full frame.
    window: Window,
    /// Per block, row by row, the count of each checkerboard colour (`(x + y) % 2`).
    counts: Vec<[u32; 2]>,
}

impl Choice {
    /// The counts for the blocks of `pilot`'s window, from its first samples and the
    /// frame's rates of each colour (`frame[c]`, [`FrameRates::measure`]): each colour's
    /// from the other colour's pixels of the block and lattice alone ([`count_for`]), so
    /// that no pixel's count depends on its own samples, which the image keeps (the noise
    /// allocation's reason, `allocation.rs`); and from its block's and the frame's, so that
    /// a crop chooses as the full frame does. `blurred`: the shutter is open.
    pub(super) fn new(pilot: &Film, frame: [FrameRates; 2], blurred: bool) -> Choice {
        let window = pilot.crop();
        let counts = blocks(window)
            .map(|block| {
                let colour = |c: u32| {
                    let others = block.pixels().filter(move |(x, y)| (x + y) % 2 != c);
                    let frame = frame[1 - c as usize];
                    count_for(others.map(|p| pilot.accumulator(p)), frame, blurred)
                };
                [colour(0), colour(1)]
            })
            .collect();
        Choice { window, counts }
    }

    /// The rays per camera sample of `pixel` (full-frame, inside the window).
    pub(super) fn rays(&self, (x, y): (u32, u32)) -> u32 {
        let across = self.window.width().div_ceil(BLOCK);
        let block = (y - self.window.y0) / BLOCK * across + (x - self.window.x0) / BLOCK;
        self.counts[block as usize][((x + y) % 2) as usize]
    }
}

/// The count for pixels like these (their samples so far all of one ray), in a frame of
/// `frame`'s rates. Over the pixels: a sample's variance v (summed over channels), its
/// part from which of background and strands the ray meets (per pixel f (1 - f) |S - H|^2,
/// f the fraction of rays that met a strand, S and H the mean radiance of those that
/// escaped and of the others, unbiased for the pixel's samples, in pixels whose hits were
/// strands), the mean width of the strands met and the rays per sample c. k rays spread
/// over the pixel take that part down k-fold and cost (k - 1) extra rays; the frame's
/// noise times its cost then changes, to first order, by these pixels' change of v over
/// the frame's mean variance plus their change of c over the frame's mean rays: the count
/// of [`COUNTS`] that makes that least. One ray where none is met, or where the strands are
/// wider than [`MAX_STRAND_WIDTH`] and `blurred` is false: under motion blur each sample
/// sees the strands where they are at its own time, so the strata of positions across
/// samples do not resolve their edges, and the rays of one sample, at its time, do.
fn count_for(
    pixels: impl Iterator<Item = PixelAccumulator>,
    frame: FrameRates,
    blurred: bool,
) -> u32 {
    let (mut variance, mut part, mut rays, mut samples, mut count) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut width, mut strands) = (0.0, 0.0);
    for acc in pixels {
        let n = f64::from(acc.samples());
        if n < 2.0 {
            continue;
        }
        count += 1.0;
        variance += acc.sample_variance().iter().sum::<f64>();
        rays += acc.rays() as f64;
        samples += n;
        let c = acc.coverage();
        width += f64::from(c.strand_width);
        strands += f64::from(c.strands);
        let escaped = f64::from(c.escaped);
        let hit = n - escaped;
        if escaped > 0.0 && hit > 0.0 {
            let sum = acc.mean_rgb().map(|m| m * n);
            let gap: f64 = (0..3)
                .map(|ch| {
                    let s = f64::from(c.escaped_rgb[ch]) / escaped;
                    let h = (sum[ch] - f64::from(c.escaped_rgb[ch])) / hit;
                    (s - h) * (s - h)
                })
                .sum();
            let f = hit / n;
            // Only strands' share: a surface's silhouette is an edge, which the sampler's
            // stratified positions resolve.
            let on_strands = f64::from(c.strands) / hit;
            part += on_strands * f * (1.0 - f) * gap * n / (n - 1.0);
        }
    }
    let coarse = strands == 0.0 || (!blurred && width / strands > MAX_STRAND_WIDTH);
    if coarse || variance <= 0.0 || frame.variance <= 0.0 || frame.rays <= 0.0 {
        return 1;
    }
    let (v, c) = (variance / count, rays / samples);
    let at = |k: u32| {
        let k = f64::from(k);
        (
            v - part / count * (1.0 - 1.0 / k),
            c + (k - 1.0) * EXTRA_RAY_COST,
        )
    };
    let score = |k: u32| {
        let (v, c) = at(k);
        v / frame.variance + c / frame.rays
    };
    // A count must also make these pixels' own noise cheaper: the frame's weights alone
    // would buy a noisy block's small predicted gains, which its few samples overstate.
    let (v1, c1) = at(1);
    COUNTS
        .into_iter()
        .filter(|&k| {
            let (v, c) = at(k);
            v * c <= v1 * c1
        })
        .min_by(|&a, &b| score(a).total_cmp(&score(b)))
        .unwrap_or(1)
}

/// Where the `count` rays of a camera sample go in its pixel, as shifts of the sample's
/// own position (wrapped into the pixel): a Hammersley set, (j / count, the base-2
/// radical inverse of j), whose points spread over the pixel as evenly as `count` points
/// can. Each shifted position is as uniform over the pixel as the sample's own, so every
/// ray sees the pixel as a single camera ray would. The rays share the sample's time:
/// spreading them over the shutter too measured worse (docs/measurements.md, "Camera rays
/// under motion blur").
pub fn shifts(count: u32) -> [[f32; 2]; MAX_CAMERA_RAYS] {
    let n = count.max(1) as f32;
    std::array::from_fn(|j| {
        let inverse = (j as u32).reverse_bits() as f32 * (1.0 / 4_294_967_296.0);
        [j as f32 / n, inverse]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::film::{Aovs, Keep, Seen};

    /// A pixel of two one-ray samples: `(radiance, what the ray met)`, each of `rays` rays.
    fn pixel(samples: [(f32, Seen); 2], rays: u32) -> PixelAccumulator {
        let mut acc = PixelAccumulator::default();
        for (radiance, seen) in samples {
            let radiance = Vec3::splat(radiance);
            acc.add(radiance, None);
            acc.add_seen(seen, radiance);
            acc.add_rays(rays);
        }
        acc
    }

    /// Half its rays meet a strand of `width` pixels (radiance 0.1), half a sky of 1.
    fn mixed(width: f32) -> PixelAccumulator {
        pixel([(0.1, Seen::Strand(width)), (1.0, Seen::Nothing)], 1)
    }

    /// The rates of a frame of pixels like `acc`, its variance scaled by `scale`.
    fn frame_of(acc: &PixelAccumulator, scale: f64) -> FrameRates {
        FrameRates {
            variance: scale * acc.sample_variance().iter().sum::<f64>(),
            rays: acc.rays() as f64 / f64::from(acc.samples()),
        }
    }

    /// Strands far under a pixel against a bright sky split: more ways where the block is
    /// noisier than the frame; not where the strands are wide (the sampler's strata
    /// resolve them) unless the shutter is open, where no ray escapes (no background to
    /// tell from), nor where the block's noise is small beside the frame's (its extra rays
    /// buy the frame little).
    #[test]
    fn samples_split_where_thin_strands_against_the_sky_make_the_frames_noise() {
        let thin = mixed(0.02);
        let count = |acc: &PixelAccumulator, scale, blurred| {
            let pixels = std::iter::repeat_n(acc.clone(), 64);
            count_for(pixels, frame_of(&thin, scale), blurred)
        };
        let like = |acc: &PixelAccumulator, scale| count(acc, scale, false);
        assert_eq!(like(&thin, 2.0), 1);
        assert_eq!(like(&thin, 0.5), 2);
        assert_eq!(like(&thin, 0.125), 4);
        assert_eq!(like(&thin, 0.03125), 8);
        assert_eq!(like(&mixed(0.2), 0.0625), 1);
        assert_eq!(count(&mixed(0.2), 0.0625, true), 4);
        assert_eq!(count(&thin, 2.0, true), 1);
        let covered = pixel([(0.1, Seen::Strand(0.02)), (0.9, Seen::Strand(0.02))], 1);
        assert_eq!(like(&covered, 0.0625), 1);
        // A surface's silhouette against the sky is an edge: the strata resolve it.
        let edge = pixel([(0.1, Seen::Surface), (1.0, Seen::Nothing)], 1);
        assert_eq!(like(&edge, 0.0625), 1);
    }

    /// A colour's count is read from the other colour's pixels alone: with the even
    /// pixels of a block showing thin strands against the sky and the odd ones plain
    /// hair, the odd pixels split and the even ones do not; other blocks keep their own.
    #[test]
    fn each_colour_chooses_from_the_other_colours_pixels() {
        let (width, height) = (64, 32);
        let mut pilot = Film::keeping(width, height, None, Aovs::default(), Keep::Spread).unwrap();
        let plain = pixel([(0.1, Seen::Strand(0.02)), (0.3, Seen::Strand(0.02))], 1);
        for p in Window::full(width, height).pixels() {
            let even = (p.0 + p.1) % 2 == 0;
            let acc = if p.0 < BLOCK && even {
                mixed(0.02)
            } else {
                plain.clone()
            };
            pilot.store(p, &acc);
        }
        let frame = frame_of(&mixed(0.02), 0.0625);
        let choice = Choice::new(&pilot, [frame; 2], false);
        assert_eq!(choice.rays((0, 0)), 1, "an even pixel read its own colour");
        assert!(choice.rays((1, 0)) > 1, "an odd pixel missed the even ones");
        assert_eq!(
            choice.rays((BLOCK + 1, 0)),
            1,
            "the next block took this one's"
        );
    }
}
