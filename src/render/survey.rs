//! The survey: a few samples of a fixed lattice of pixels, traced before the image and
//! not kept in it, from which `auto` camera rays choose their counts
//! (`super::camera_rays::Choice`) and the roulette learns its survival where no light is
//! sampled (`super::survival`). Every sample the image keeps then takes what was chosen,
//! from its first (docs/measurements.md, "A survey before the image").
//!
//! The survey's samples are drawn with a seed of their own, so the image's samples are
//! independent of what was chosen from them (no pixel's count depends on its own samples:
//! unbiased), and the lattice is the full frame's whatever the crop, so a crop chooses and
//! learns what the full frame does.

use rayon::prelude::*;

use super::film::PixelAccumulator;
use super::integrator::CameraSample;
use super::survival::{LatticePixel, Recorder};

/// Side of the lattice's cells: every `LATTICE`-th pixel of every `LATTICE`-th row.
const LATTICE: u32 = 4;

/// Samples of each lattice pixel, one camera ray each: two, the fewest a pixel's variance
/// is measured from.
const SAMPLES: u32 = 2;

/// What the survey's seed is the render's seed mixed with.
const SEED_SALT: u64 = 0x5f3c_a7e1_9b2d_4c81;

/// The seed of the survey of a render seeded `seed`.
pub(super) fn seed(seed: u64) -> u64 {
    seed ^ SEED_SALT
}

/// The lattice's pixels of a `width` x `height` frame, row by row.
fn lattice(width: u32, height: u32) -> Vec<(u32, u32)> {
    let step = LATTICE as usize;
    (0..height)
        .step_by(step)
        .flat_map(|y| (0..width).step_by(step).map(move |x| (x, y)))
        .collect()
}

/// One lattice pixel's samples: as a pixel accumulates them (radiance, rays, what each
/// camera ray met), and as the roulette learns from them.
#[derive(Debug, Clone, Default)]
pub(super) struct SurveyPixel {
    pub acc: PixelAccumulator,
    pub roulette: LatticePixel,
}

/// The lattice's pixels of a `width` x `height` frame, row by row.
#[derive(Debug)]
pub(super) struct Survey {
    columns: u32,
    pixels: Vec<SurveyPixel>,
}

impl Survey {
    /// Traces the survey: sample `index` of `pixel` by `sample`, one ray each (with a
    /// recorder of the roulette's decisions), in parallel; the sums are kept in lattice
    /// order, so the survey is the same on any thread count.
    pub(super) fn trace(
        width: u32,
        height: u32,
        sample: &(impl Fn((u32, u32), u32, &mut Recorder) -> CameraSample + Sync),
    ) -> Survey {
        let pixels = lattice(width, height)
            .par_iter()
            .map(|&p| {
                let mut recorder = Recorder::default();
                let mut out = SurveyPixel::default();
                for i in 0..SAMPLES {
                    let s = sample(p, i, &mut recorder);
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
        Survey {
            columns: width.div_ceil(LATTICE),
            pixels,
        }
    }

    /// Every lattice pixel's samples.
    pub(super) fn pixels(&self) -> &[SurveyPixel] {
        &self.pixels
    }

    /// The lattice pixels in `x0..x1` x `y0..y1`.
    pub(super) fn within(
        &self,
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
    ) -> impl Iterator<Item = &SurveyPixel> {
        let first = |v: u32| v.div_ceil(LATTICE);
        let rows = first(y0)..first(y1);
        let columns = first(x0)..first(x1);
        rows.flat_map(move |j| {
            columns
                .clone()
                .map(move |i| (j * self.columns + i) as usize)
        })
        .filter_map(|i| self.pixels.get(i))
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

    /// A survey of a 10 x 9 frame whose samples' radiance is the pixel's x + 100 y.
    fn survey() -> Survey {
        Survey::trace(10, 9, &|(x, y), _, _: &mut Recorder| CameraSample {
            radiance: Vec3::splat((x + 100 * y) as f32),
            first: None,
            rays: 3,
            seen: Seen::Nothing,
        })
    }

    /// The lattice covers the frame at every fourth pixel and row, including the last
    /// partial cells, and a rectangle finds exactly the lattice pixels inside it.
    #[test]
    fn the_lattice_and_its_rectangles() {
        let s = survey();
        assert_eq!(s.pixels().len(), 3 * 3);
        assert_eq!(s.rays(), 9 * 2 * 3);
        let found: Vec<f64> = s
            .within((4, 10), (1, 9))
            .map(|p| p.acc.mean_rgb()[0])
            .collect();
        assert_eq!(found, [404.0, 408.0, 804.0, 808.0]);
        assert_eq!(s.within((5, 8), (0, 9)).count(), 0);
        assert_eq!(s.within((0, 10), (0, 9)).count(), 9);
    }

    /// The survey's seed differs from the image's, the same for the same render.
    #[test]
    fn the_survey_has_a_seed_of_its_own() {
        assert_ne!(seed(7), 7);
        assert_eq!(seed(7), seed(7));
    }
}
