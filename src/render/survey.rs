//! The survey: a few samples of a fixed lattice of pixels, traced before the image and
//! not kept in it, from which `auto` camera rays choose their counts
//! (`super::camera_rays::Choice`) and the roulette learns its survival where no light is
//! sampled (`super::survival`). Every sample the image keeps then takes what was chosen,
//! from its first (docs/measurements.md, "A survey before the image").
//!
//! The survey's samples are drawn with a seed of their own, so the image's samples are
//! independent of what was chosen from them (no pixel's count depends on its own samples:
//! unbiased).
//!
//! Two lattices, so that a crop chooses and learns what the full frame does while paying
//! for little more than its own pixels (a farm's tiles: docs/farm.md):
//! - the block lattice, every `LATTICE`-th pixel, traced only inside the window whose
//!   blocks choose their counts;
//! - the frame lattice, a sparser one over the whole frame whatever the crop, from which
//!   the frame's own rates and the survival are read. It is a subset of the block lattice,
//!   as sparse as keeps `FRAME_PIXELS`.

use rayon::prelude::*;

use super::film::{PixelAccumulator, Window};
use super::integrator::CameraSample;
use super::survival::{LatticePixel, Recorder};

/// Side of the block lattice's cells: every `LATTICE`-th pixel of every `LATTICE`-th row.
const LATTICE: u32 = 4;

/// The fewest pixels the frame lattice keeps, where the frame has them: its pixels measure
/// a frame's mean variance, whose samples are heavy-tailed under highlights, and the
/// survival's light per depth, so they stay many; a frame whose block lattice holds fewer
/// than four times this reads them from the whole block lattice (docs/conventions.md,
/// "The survey").
const FRAME_PIXELS: u64 = 1 << 14;

/// Samples of each lattice pixel, one camera ray each: two, the fewest a pixel's variance
/// is measured from.
const SAMPLES: u32 = 2;

/// What the survey's seed is the render's seed mixed with.
const SEED_SALT: u64 = 0x5f3c_a7e1_9b2d_4c81;

/// The seed of the survey of a render seeded `seed`.
pub(super) fn seed(seed: u64) -> u64 {
    seed ^ SEED_SALT
}

/// The frame lattice's step in a `width` x `height` frame: `LATTICE` times the integer
/// square root of the block lattice's pixels over `FRAME_PIXELS` (at least 1), so that
/// the frame lattice keeps at least `FRAME_PIXELS` where the block lattice has them.
fn frame_step(width: u32, height: u32) -> u32 {
    let cells = u64::from(width.div_ceil(LATTICE)) * u64::from(height.div_ceil(LATTICE));
    let k = (cells / FRAME_PIXELS).isqrt().max(1);
    LATTICE.saturating_mul(u32::try_from(k).unwrap_or(u32::MAX))
}

/// The lattice pixels of a `width` x `height` frame a survey traces, as (y, x), row by
/// row: the frame lattice's (every `step`-th), and the block lattice's inside `window`.
fn traced(width: u32, height: u32, step: u32, window: Option<Window>) -> Vec<(u32, u32)> {
    let mut keys = Vec::new();
    for y in (0..height).step_by(LATTICE as usize) {
        let row = keys.len();
        if y % step == 0 {
            keys.extend((0..width).step_by(step as usize).map(|x| (y, x)));
        }
        if let Some(w) = window.filter(|w| (w.y0..w.y1).contains(&y)) {
            let x0 = w.x0.div_ceil(LATTICE) * LATTICE;
            keys.extend((x0..w.x1).step_by(LATTICE as usize).map(|x| (y, x)));
        }
        keys[row..].sort_unstable();
    }
    keys.dedup();
    keys
}

/// One lattice pixel's samples: as a pixel accumulates them (radiance, rays, what each
/// camera ray met), and as the roulette learns from them.
#[derive(Debug, Clone, Default)]
pub(super) struct SurveyPixel {
    pub acc: PixelAccumulator,
    pub roulette: LatticePixel,
}

/// The lattice pixels a survey traced, and their samples.
#[derive(Debug)]
pub(super) struct Survey {
    /// The frame lattice's step.
    step: u32,
    /// Each traced pixel as (y, x), row by row.
    keys: Vec<(u32, u32)>,
    pixels: Vec<SurveyPixel>,
}

impl Survey {
    /// Traces the survey of a `width` x `height` frame, with the block lattice inside
    /// `window` (none: the frame lattice alone): sample `index` of `pixel` by `sample`,
    /// one ray each (with a recorder of the roulette's decisions), in parallel; the sums
    /// are kept in lattice order, so the survey is the same on any thread count, and a
    /// pixel's samples the same whatever the window.
    pub(super) fn trace(
        width: u32,
        height: u32,
        window: Option<Window>,
        sample: &(impl Fn((u32, u32), u32, &mut Recorder) -> CameraSample + Sync),
    ) -> Survey {
        let step = frame_step(width, height);
        let keys = traced(width, height, step, window);
        let pixels = keys
            .par_iter()
            .map(|&(y, x)| {
                let mut recorder = Recorder::default();
                let mut out = SurveyPixel::default();
                for i in 0..SAMPLES {
                    let s = sample((x, y), i, &mut recorder);
                    out.acc.add(s.radiance, None);
                    out.acc.add_seen(s.seen, s.radiance);
                    out.acc.add_rays(s.rays);
                    out.roulette.luminance[i as usize] = crate::math::luminance(s.radiance);
                    out.roulette.rays[i as usize] = s.rays;
                }
                out.roulette.depths = recorder.sums();
                out
            })
            .collect();
        Survey { step, keys, pixels }
    }

    /// The frame lattice's pixels: what the frame's own rates and the survival read.
    pub(super) fn frame(&self) -> impl Iterator<Item = &SurveyPixel> {
        let step = self.step;
        self.keys
            .iter()
            .zip(&self.pixels)
            .filter(move |((y, x), _)| y % step == 0 && x % step == 0)
            .map(|(_, p)| p)
    }

    /// The block lattice's pixels in `x0..x1` x `y0..y1`, which must lie inside the window
    /// the survey was traced for (a pixel it did not trace is left out).
    pub(super) fn within(
        &self,
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
    ) -> impl Iterator<Item = &SurveyPixel> {
        let first = |v: u32| v.div_ceil(LATTICE) * LATTICE;
        let columns = (first(x0)..x1).step_by(LATTICE as usize);
        (first(y0)..y1)
            .step_by(LATTICE as usize)
            .flat_map(move |y| columns.clone().map(move |x| (y, x)))
            .filter_map(|key| self.keys.binary_search(&key).ok())
            .map(|i| &self.pixels[i])
    }

    /// Rays traced.
    pub(super) fn rays(&self) -> u64 {
        self.pixels.iter().map(|p| p.acc.rays()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::film::Seen;
    use glam::Vec3;

    /// A survey of a `width` x `height` frame with the block lattice inside `window`,
    /// whose samples' radiance is the pixel's x + 1000 y plus the sample's index / 2.
    fn survey(width: u32, height: u32, window: Option<Window>) -> Survey {
        Survey::trace(width, height, window, &|(x, y), i, _: &mut Recorder| {
            CameraSample {
                radiance: Vec3::splat((x + 1000 * y) as f32 + i as f32 / 2.0),
                first: None,
                rays: 3,
                seen: Seen::Nothing,
            }
        })
    }

    /// The red means of some survey pixels.
    fn means<'a>(pixels: impl Iterator<Item = &'a SurveyPixel>) -> Vec<f64> {
        pixels.map(|p| p.acc.mean_rgb()[0]).collect()
    }

    /// The block lattice covers a window at every fourth pixel and row, including the last
    /// partial cells, and a rectangle finds exactly the lattice pixels inside it; in a
    /// small frame the frame lattice is the whole block lattice.
    #[test]
    fn the_lattice_and_its_rectangles() {
        let s = survey(10, 9, Some(Window::full(10, 9)));
        assert_eq!(s.frame().count(), 3 * 3);
        assert_eq!(s.rays(), 9 * 2 * 3);
        assert_eq!(
            means(s.within((4, 10), (1, 9))),
            [4004.25, 4008.25, 8004.25, 8008.25]
        );
        assert_eq!(s.within((5, 8), (0, 9)).count(), 0);
        assert_eq!(s.within((0, 10), (0, 9)).count(), 9);
        assert_eq!(survey(10, 9, None).frame().count(), 9);
    }

    /// A large frame's frame lattice is sparser, as wide as keeps `FRAME_PIXELS`; a crop
    /// traces it and its own window's block lattice, and reads from both exactly what
    /// the full frame's survey does.
    #[test]
    fn a_crop_traces_the_frame_lattice_and_its_own_blocks() {
        let (width, height) = (1100, 1030);
        assert_eq!(frame_step(width, height), 8);
        let full = survey(width, height, Some(Window::full(width, height)));
        let frame = 1100_u64.div_ceil(8) * 1030_u64.div_ceil(8);
        assert!(frame >= FRAME_PIXELS);
        assert_eq!(full.frame().count() as u64, frame);
        assert_eq!(full.pixels.len(), 275 * 258);

        let window = Window {
            x0: 256,
            y0: 992,
            x1: 352,
            y1: 1030,
        };
        let crop = survey(width, height, Some(window));
        // The window's 24 x 10 block-lattice pixels, 12 x 5 of them on the frame lattice.
        assert_eq!(crop.pixels.len() as u64, frame + 24 * 10 - 12 * 5);
        assert_eq!(means(crop.frame()), means(full.frame()));
        let block = ((288, 320), (992, 1024));
        assert_eq!(crop.within(block.0, block.1).count(), 8 * 8);
        assert_eq!(
            means(crop.within(block.0, block.1)),
            means(full.within(block.0, block.1))
        );
        // Without a window, the frame lattice alone.
        assert_eq!(survey(width, height, None).pixels.len() as u64, frame);
    }

    /// The survey's seed differs from the image's, the same for the same render.
    #[test]
    fn the_survey_has_a_seed_of_its_own() {
        assert_ne!(seed(7), 7);
        assert_eq!(seed(7), seed(7));
    }
}
