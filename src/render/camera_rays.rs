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
//! So `auto` (the default) chooses ([`Choice`]), per block of pixels, from the survey
//! traced before the image (`super::survey`), one ray a sample: how much of a sample's
//! variance is which of background and hair its ray meets, and how wide the strands it
//! meets are; every sample of the image takes the count that a model of that variance and
//! of the rays' cost says makes the frame's noise cheapest, weighed against the frame's
//! mean variance and cost ([`FrameRates`]) (docs/measurements.md, "Camera rays chosen per
//! block", "A survey before the image").

use super::allocation::{BLOCK, blocks};
use super::film::{PixelAccumulator, Window};
use super::survey::{Survey, SurveyPixel};

/// The most rays a camera sample may be traced as.
pub const MAX_CAMERA_RAYS: usize = 16;

/// The counts `auto` chooses among.
const COUNTS: [u32; 4] = [1, 2, 4, 8];

/// The widest strands whose samples split, where their camera rays meet them, as a
/// fraction of the side of a stratum of the sampler's positions (1 / sqrt(spp) of a
/// pixel): strands far under a stratum the strata cannot tell from the background between
/// them, while wider strands' coverage the stratified positions already take
/// (docs/measurements.md, "Camera rays chosen per block", "The width rule relative to the
/// strata").
const WIDEST_IN_STRATA: f64 = 0.8;

/// The widest strands, in pixels, whose samples `auto` splits in a render of `spp` samples
/// per pixel ([`WIDEST_IN_STRATA`]); any where `blurred` (the shutter is open): each sample
/// then sees the strands where they are at its own time, so the strata of positions
/// across samples do not resolve their edges, and the rays of one sample, at its time, do.
pub(super) fn widest_split(spp: u32, blurred: bool) -> Option<f64> {
    (!blurred).then(|| WIDEST_IN_STRATA / f64::from(spp.max(1)).sqrt())
}

/// The time of an extra camera ray (an occlusion query from the eye) over that of one of a
/// path's rays (docs/measurements.md, "Camera rays chosen per block").
const EXTRA_RAY_COST: f64 = 0.5;

/// What reading and building a curve segment costs, in the path rays that take as long:
/// a frame's cost counts its share of its scene's segments, so that where they outweigh
/// its rays, as on a close-up of a large groom, more rays a sample cost the frame little
/// (measured on the real-groom close-ups, and chosen among nearby values by their
/// efficiency: docs/measurements.md, "A survey before the image").
const BUILD_RAYS_PER_SEGMENT: f64 = 1.0;

/// A frame's mean, over the survey's pixels, of a sample's variance (summed over channels)
/// and of its cost in rays: its own, and its share of the build (`build`): what a block's
/// gain in noise and extra rays are weighed against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct FrameRates {
    variance: f64,
    rays: f64,
    build: f64,
}

impl FrameRates {
    /// The rates of `survey`'s frame (its frame lattice), whose build costs `build` rays
    /// a sample.
    pub(super) fn of(survey: &Survey, build: f64) -> FrameRates {
        let (n, variance, rays) = survey.frame().fold((0.0, 0.0, 0.0), |(n, v, r), p| {
            let samples = f64::from(p.acc.samples().max(1));
            (
                n + 1.0,
                v + p.acc.sample_variance().iter().sum::<f64>(),
                r + p.acc.rays() as f64 / samples,
            )
        });
        let n = f64::max(n, 1.0);
        FrameRates {
            variance: variance / n,
            rays: rays / n + build,
            build,
        }
    }

    /// What a frame built in `segments` curve segments, rendered at `samples` camera
    /// samples (its full frame's), pays a sample for its build, in rays.
    pub(super) fn build_rays(segments: usize, samples: u64) -> f64 {
        BUILD_RAYS_PER_SEGMENT * segments as f64 / samples.max(1) as f64
    }
}

/// The rays per camera sample of each pixel, block by block.
#[derive(Debug)]
pub(super) struct Choice {
    /// The window chosen for, whole blocks aligned on the full frame.
    window: Window,
    /// Per block, row by row.
    counts: Vec<u32>,
}

impl Choice {
    /// The counts for the blocks of `window` (aligned on the full frame), each from the
    /// survey's pixels inside it and the frame's rates ([`count_for`]): the same for a
    /// crop as for the full frame. `widest`: [`widest_split`].
    pub(super) fn new(
        survey: &Survey,
        window: Window,
        frame: FrameRates,
        widest: Option<f64>,
    ) -> Choice {
        let counts = blocks(window)
            .map(|block| {
                let inside = survey.within((block.x0, block.x1), (block.y0, block.y1));
                count_for(inside.map(|p: &SurveyPixel| &p.acc), frame, widest)
            })
            .collect();
        Choice { window, counts }
    }

    /// The rays per camera sample of `pixel` (full-frame, inside the window).
    pub(super) fn rays(&self, (x, y): (u32, u32)) -> u32 {
        let across = self.window.width().div_ceil(BLOCK);
        let block = (y - self.window.y0) / BLOCK * across + (x - self.window.x0) / BLOCK;
        self.counts[block as usize]
    }
}

/// The count for pixels like these (the survey's: samples of one ray each), in a frame of
/// `frame`'s rates. Over the pixels: a sample's variance v (summed over channels), its
/// part from which of background and strands the ray meets (per pixel f (1 - f) |S - H|^2,
/// f the fraction of rays that met a strand, S and H the mean radiance of those that
/// escaped and of the others, |S - H|^2 less what the hair's own noise adds to it
/// ([`hit_variance`]), unbiased for the pixel's samples, in pixels whose hits were
/// strands), the mean width of the strands met and the cost of a sample c in rays (its
/// own and its share of the build, [`FrameRates`]). k rays spread
/// over the pixel take that part down k-fold and cost (k - 1) extra rays; the frame's
/// noise times its cost then changes, to first order, by these pixels' change of v over
/// the frame's mean variance plus their change of c over the frame's mean cost: the count
/// of [`COUNTS`] that makes that least. One ray where none is met, or where the strands are
/// on average wider than `widest` ([`widest_split`]).
fn count_for<'a>(
    pixels: impl Iterator<Item = &'a PixelAccumulator>,
    frame: FrameRates,
    widest: Option<f64>,
) -> u32 {
    let pixels: Vec<&PixelAccumulator> = pixels.filter(|acc| acc.samples() >= 2).collect();
    let hit_variance = hit_variance(&pixels);
    let (mut variance, mut part, mut rays, mut samples) = (0.0, 0.0, 0.0, 0.0);
    let (mut width, mut strands) = (0.0, 0.0);
    for acc in &pixels {
        let n = f64::from(acc.samples());
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
            // The mean of `hit` hits strays from the hair's by their own variance over
            // `hit`: taken out, the gap is the background's from the hair's mean.
            let gap = (gap - hit_variance / hit).max(0.0);
            let f = hit / n;
            // Only strands' share: a surface's silhouette is an edge, which the sampler's
            // stratified positions resolve.
            let on_strands = f64::from(c.strands) / hit;
            part += on_strands * f * (1.0 - f) * gap * n / (n - 1.0);
        }
    }
    let count = pixels.len() as f64;
    let coarse = strands == 0.0 || widest.is_some_and(|w| width / strands > w);
    if coarse || variance <= 0.0 || frame.variance <= 0.0 || frame.rays <= 0.0 {
        return 1;
    }
    let (v, c) = (variance / count, rays / samples + frame.build);
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

/// The variance of a sample's radiance (summed over channels) among samples whose rays met
/// strands, from the pixels all of whose rays did: the hair's own noise, which the gap
/// between background and hair in a pixel of few hits also holds. 0 where no pixel is
/// covered.
fn hit_variance(pixels: &[&PixelAccumulator]) -> f64 {
    let covered: Vec<f64> = pixels
        .iter()
        .filter(|acc| acc.coverage().strands == acc.samples())
        .map(|acc| acc.sample_variance().iter().sum())
        .collect();
    match covered.len() {
        0 => 0.0,
        n => covered.iter().sum::<f64>() / n as f64,
    }
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
    use crate::render::film::Seen;
    use crate::render::integrator::CameraSample;
    use glam::Vec3;

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

    /// The rates of a frame of pixels like `acc`, its variance scaled by `scale`, its build
    /// costing `build` rays a sample.
    fn frame_of(acc: &PixelAccumulator, scale: f64, build: f64) -> FrameRates {
        FrameRates {
            variance: scale * acc.sample_variance().iter().sum::<f64>(),
            rays: acc.rays() as f64 / f64::from(acc.samples()) + build,
            build,
        }
    }

    /// Strands far under a pixel against a bright sky split: more ways where the block is
    /// noisier than the frame, or where the build makes a frame's rays a small part of
    /// its cost; not where the strands are wide beside the sampler's strata (which resolve
    /// them), fewer samples making the strata wider, unless the shutter is open, where no ray escapes (no background to tell from), nor where
    /// the block's noise is small beside the frame's (its extra rays buy the frame little).
    #[test]
    fn samples_split_where_thin_strands_against_the_sky_make_the_frames_noise() {
        let thin = mixed(0.02);
        let (at_64, at_16, blurred) = (
            widest_split(64, false),
            widest_split(16, false),
            widest_split(64, true),
        );
        let count = |acc: &PixelAccumulator, scale, build, widest| {
            let pixels = std::iter::repeat_n(acc, 64);
            count_for(pixels, frame_of(&thin, scale, build), widest)
        };
        let like = |acc: &PixelAccumulator, scale| count(acc, scale, 0.0, at_64);
        assert_eq!(like(&thin, 2.0), 1);
        assert_eq!(like(&thin, 0.5), 2);
        assert_eq!(like(&thin, 0.125), 4);
        assert_eq!(like(&thin, 0.03125), 8);
        assert_eq!(count(&thin, 0.5, 4.0, at_64), 4);
        assert_eq!(count(&thin, 2.0, 4.0, at_64), 2);
        // Strands between the widest that split at 64 spp and at 16 spp (the strata are
        // wider at fewer samples).
        assert_eq!(like(&mixed(0.15), 0.0625), 1);
        assert_eq!(count(&mixed(0.15), 0.0625, 0.0, at_16), 4);
        assert_eq!(count(&mixed(0.15), 0.0625, 4.0, at_64), 1);
        assert_eq!(count(&mixed(0.2), 0.0625, 0.0, blurred), 4);
        assert_eq!(count(&thin, 2.0, 0.0, blurred), 1);
        let covered = pixel([(0.1, Seen::Strand(0.02)), (0.9, Seen::Strand(0.02))], 1);
        assert_eq!(like(&covered, 0.0625), 1);
        assert_eq!(count(&covered, 0.0625, 4.0, at_64), 1);
        // Strands whose own radiance varies about the sky's (a highlight or none, under a
        // key light) against a sky as bright as their mean: the gaps are their noise.
        let lit = pixel([(0.0, Seen::Strand(0.02)), (2.0, Seen::Strand(0.02))], 1);
        let glints = [(0.0, Seen::Strand(0.02)), (2.0, Seen::Strand(0.02))]
            .map(|hit| pixel([hit, (1.0, Seen::Nothing)], 1));
        let block = [&lit, &lit, &glints[0], &glints[1]];
        let frame = frame_of(&glints[0], 0.03125, 4.0);
        let glinting = block.into_iter().cycle().take(64);
        assert_eq!(count_for(glinting, frame, at_64), 1);
        let bare = [&glints[0], &glints[1]].into_iter().cycle().take(64);
        assert_eq!(count_for(bare, frame, at_64), 8);
        // A surface's silhouette against the sky is an edge: the strata resolve it.
        let edge = pixel([(0.1, Seen::Surface), (1.0, Seen::Nothing)], 1);
        assert_eq!(like(&edge, 0.0625), 1);
    }

    /// A block's count is read from the survey's pixels inside it: in a frame whose left
    /// block shows thin strands against the sky and whose other blocks show plain hair,
    /// the left block splits and the others do not, in the full frame and in a crop
    /// (whose survey traces its own blocks).
    #[test]
    fn each_block_chooses_from_the_survey_inside_it() {
        let (width, height) = (3 * BLOCK, BLOCK + 8);
        let choose = |window: Window| {
            let survey = Survey::trace(width, height, Some(window), &|(x, _), i, _| {
                let (radiance, seen) = match (x < BLOCK, i) {
                    (true, 0) => (0.1, Seen::Strand(0.02)),
                    (true, _) => (1.0, Seen::Nothing),
                    (false, 0) => (0.1, Seen::Strand(0.02)),
                    (false, _) => (0.3, Seen::Strand(0.02)),
                };
                CameraSample {
                    radiance: Vec3::splat(radiance),
                    first: None,
                    rays: 1,
                    seen,
                }
            });
            let frame = FrameRates::of(&survey, 0.0);
            Choice::new(&survey, window, frame, widest_split(16, false))
        };
        let full = choose(Window::full(width, height));
        assert!(full.rays((0, 0)) > 1, "the left block split");
        assert!(full.rays((BLOCK - 1, BLOCK + 7)) > 1);
        assert_eq!(
            full.rays((BLOCK, 0)),
            1,
            "the next block took the left one's"
        );
        assert_eq!(full.rays((2 * BLOCK + 5, BLOCK + 3)), 1);
        let window = Window {
            x0: BLOCK,
            y0: 0,
            x1: 3 * BLOCK,
            y1: BLOCK + 8,
        };
        let crop = choose(window);
        assert_eq!(crop.rays((BLOCK, 0)), 1);
        assert_eq!(crop.rays((2 * BLOCK + 5, BLOCK + 3)), 1);
        let left = Window {
            x0: 0,
            y0: BLOCK,
            x1: BLOCK,
            y1: BLOCK + 8,
        };
        let crop = choose(left);
        assert_eq!(crop.rays((3, BLOCK + 2)), full.rays((3, BLOCK + 2)));
    }

    /// A frame's build is its segments' share of its samples.
    #[test]
    fn a_frames_build_in_rays_a_sample() {
        let build = FrameRates::build_rays(1 << 20, 1 << 18);
        assert!((build - 4.0 * BUILD_RAYS_PER_SEGMENT).abs() < 1e-12);
        assert_eq!(FrameRates::build_rays(0, 100), 0.0);
        assert!(FrameRates::build_rays(10, 0).is_finite());
    }
}
