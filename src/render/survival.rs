//! Russian roulette where no light is sampled, its survival scaled per depth by what the
//! survey measured: an efficiency-aware roulette (Rath et al. 2022, "EARS"), reduced to one
//! factor a depth for the whole frame, and never below the rule's survival.
//!
//! Ending a path with throughput w at a vertex with probability 1 - q adds w^2 M (1/q - 1)
//! to a sample's variance V and saves (1 - q) T' of its rays T, where M is the second
//! moment of the light the path would still gather per unit throughput and T' the rays it
//! would still trace. The q that makes V T least is, to first order, w sqrt(M T / (V T')).
//! How much of a pixel's light is deep in a groom is what the hair's colour sets (blonde
//! fur gathers most of its light many bounces deep, brown hair little), so M and T' are
//! measured per depth, on the survey's samples (`super::survey`), where the
//! throughput rule ran (docs/measurements.md, "Roulette from the pilot").

use glam::Vec3;

use crate::math::luminance;

/// Depths with a factor of their own; deeper decisions share the last one's.
const DEPTHS: usize = 16;

/// The fewest surviving decisions at a depth whose factor is its own: a second moment of
/// fewer is mostly its noise. A depth with fewer takes the factor of the depth before it.
const MIN_DECISIONS: f64 = 32.0;

/// The largest factor. The least is 1: below the rule's survival the first-order factor
/// measured worse than the rule (docs/measurements.md, "Roulette from the pilot").
const MAX_FACTOR: f32 = 16.0;

/// Per depth, the factor on the throughput rule's survival where no light is sampled.
#[derive(Debug, Clone, PartialEq)]
pub struct Survival {
    factors: [f32; DEPTHS],
}

impl Default for Survival {
    /// The throughput rule itself, for renders without a pilot to learn from.
    fn default() -> Self {
        Survival {
            factors: [1.0; DEPTHS],
        }
    }
}

impl Survival {
    /// The factor of a decision after `events` scattering events.
    pub fn factor(&self, events: u32) -> f32 {
        self.factors[(events as usize).min(DEPTHS - 1)]
    }

    /// The factors the first-order rule gives from `pixels`, each a pixel's two samples
    /// (in a fixed order, so the sums, and the image, are the same on any thread count):
    /// V from the pairs' differences, T their mean rays plus `build`, the frame's build in
    /// rays a sample (`super::camera_rays::FrameRates`), and per depth M and T' from the
    /// decisions the paths survived. Depths without enough decisions keep the one before
    /// theirs (1 for the first).
    pub fn learn<'a>(pixels: impl Iterator<Item = &'a LatticePixel>, build: f64) -> Survival {
        let mut sums = DepthSums::default();
        let (mut variance, mut rays, mut n) = (0.0, 0.0, 0.0);
        for p in pixels {
            variance += 0.5 * f64::from(p.luminance[0] - p.luminance[1]).powi(2);
            rays += 0.5 * f64::from(p.rays[0] + p.rays[1]);
            sums.add(&p.depths);
            n += 1.0;
        }
        let (variance, rays) = (variance / n, rays / n + build);
        let mut factors = [1.0; DEPTHS];
        let mut last = 1.0;
        for (d, factor) in factors.iter_mut().enumerate() {
            let decisions = sums.decisions[d];
            if decisions >= MIN_DECISIONS && variance > 0.0 {
                let moment = sums.second_moment[d] / decisions;
                let after = (sums.rays_after[d] / decisions).max(1.0);
                let f = (moment * rays / (variance * after)).sqrt() as f32;
                if f.is_finite() && f > 0.0 {
                    last = f.clamp(1.0, MAX_FACTOR);
                }
            }
            *factor = last;
        }
        Survival { factors }
    }
}

/// What the survival is learned from: one survey pixel's two samples, their
/// luminance and rays, and the decisions their paths survived.
#[derive(Debug, Clone, Default)]
pub struct LatticePixel {
    pub luminance: [f32; 2],
    pub rays: [u32; 2],
    pub depths: DepthSums,
}

/// Per depth, over the decisions paths survived: how many, the sum of the squared light
/// they then gathered per unit throughput (the roulette's own weight taken out), and the
/// sum of the rays they then traced.
#[derive(Debug, Clone, Default)]
pub struct DepthSums {
    decisions: [f64; DEPTHS],
    second_moment: [f64; DEPTHS],
    rays_after: [f64; DEPTHS],
}

impl DepthSums {
    fn add(&mut self, other: &DepthSums) {
        for d in 0..DEPTHS {
            self.decisions[d] += other.decisions[d];
            self.second_moment[d] += other.second_moment[d];
            self.rays_after[d] += other.rays_after[d];
        }
    }
}

/// The surviving roulette decisions of a pixel's paths, into [`DepthSums`]; of the path
/// under way, at each decision: the depth, the survival, the throughput's largest channel
/// before it, and the luminance gathered and rays traced so far.
#[derive(Debug, Default)]
pub struct Recorder {
    decisions: Vec<(u32, f32, f32, f32, u32)>,
    sums: DepthSums,
}

impl Recorder {
    /// The path survived a decision after `events` events with probability `survival`,
    /// its throughput `beta` before it, having gathered `gathered` over `rays` rays.
    pub fn survived(&mut self, events: u32, survival: f32, beta: Vec3, gathered: Vec3, rays: u32) {
        let b = beta.max_element();
        self.decisions
            .push((events, survival, b, luminance(gathered), rays));
    }

    /// The path ended having gathered `gathered` over `rays` rays: adds its decisions to
    /// the sums and forgets them.
    pub fn finish(&mut self, gathered: Vec3, rays: u32) {
        let sums = &mut self.sums;
        let total = luminance(gathered);
        for (events, survival, beta, before, rays_before) in self.decisions.drain(..) {
            if beta > 0.0 {
                let d = (events as usize).min(DEPTHS - 1);
                let light = f64::from((total - before) * survival / beta);
                sums.decisions[d] += 1.0;
                sums.second_moment[d] += light * light;
                sums.rays_after[d] += f64::from(rays - rays_before);
            }
        }
    }

    /// The sums of every path finished.
    pub fn sums(self) -> DepthSums {
        self.sums
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(luminance: [f32; 2], decisions: f64, second: f64, after: f64) -> LatticePixel {
        let mut depths = DepthSums::default();
        depths.decisions[1] = decisions;
        depths.second_moment[1] = second;
        depths.rays_after[1] = after;
        LatticePixel {
            luminance,
            rays: [2, 2],
            depths,
        }
    }

    /// The factor is sqrt(M T / (V T')): light deep in the groom beside the pixel's noise
    /// raises it, little leaves the rule (never below 1); depths without enough decisions
    /// take the one before, and a lattice without any keeps the throughput rule.
    #[test]
    fn the_factor_weighs_the_light_still_to_come_against_the_pixels_noise() {
        // V = 0.5 (1 - 0)^2 = 0.5, T = 2; M = 2, T' = 4 at depth 1: sqrt(2 * 2 / (0.5 * 4)).
        let learned = Survival::learn(vec![pixel([1.0, 0.0], 8.0, 16.0, 32.0); 4].iter(), 0.0);
        assert!(
            (learned.factor(1) - 2f32.sqrt()).abs() < 1e-6,
            "{learned:?}"
        );
        assert_eq!(learned.factor(0), 1.0);
        assert_eq!(learned.factor(5), learned.factor(1));
        assert_eq!(learned.factor(1000), learned.factor(1));
        // A build of 6 rays a sample makes T 8: twice the factor.
        let built = Survival::learn(vec![pixel([1.0, 0.0], 8.0, 16.0, 32.0); 4].iter(), 6.0);
        assert!((built.factor(1) - 2.0 * learned.factor(1)).abs() < 1e-5);
        // sqrt(0.02) before the bound.
        let dim = Survival::learn(vec![pixel([1.0, 0.0], 8.0, 0.16, 32.0); 4].iter(), 0.0);
        assert_eq!(dim, Survival::default());
        let bright = Survival::learn(vec![pixel([1.0, 0.0], 8.0, 1e6, 32.0); 4].iter(), 0.0);
        assert_eq!(bright.factor(1), MAX_FACTOR);
        let few = Survival::learn([pixel([1.0, 0.0], 8.0, 16.0, 32.0)].iter(), 0.0);
        assert_eq!(few, Survival::default());
        let flat = Survival::learn(vec![pixel([1.0, 1.0], 8.0, 16.0, 32.0); 4].iter(), 0.0);
        assert_eq!(flat, Survival::default());
    }

    /// A recorded decision counts the light gathered after it, per unit throughput and
    /// without the roulette's weight, and the rays traced after it.
    #[test]
    fn a_recorder_counts_what_each_surviving_decision_led_to() {
        let mut r = Recorder::default();
        r.survived(2, 0.5, Vec3::splat(0.25), Vec3::splat(1.0), 3);
        r.finish(Vec3::splat(3.0), 7);
        r.finish(Vec3::ONE, 1);
        let sums = r.sums();
        assert_eq!(sums.decisions[2], 1.0, "finish forgets the decisions");
        // (3 - 1) * 0.5 / 0.25 = 4.
        assert!((sums.second_moment[2] - 16.0).abs() < 1e-4);
        assert_eq!(sums.rays_after[2], 4.0);
    }
}
