//! Renders that adapt: a noise target and a time budget, decided between passes, the noise
//! estimate they rest on, and the allocation of samples where the noise is.

use std::sync::Mutex;

use crate::render::integrator::World;
use crate::render::renderer::{PASS_SAMPLES, RenderOutput, allocation_taken, film_bytes, render};
use crate::render::settings::{Allocation, PathSettings, RenderSettings};
use crate::render::{Aovs, Keep, NoProgress, Progress};

use crate::scene::envmap::Environment;
use crate::scene::light::Light;
use crate::scene::material::HairMaterial;
use glam::Vec3;

use super::render::{
    CROP, assert_crop_of, assert_quadrants_agree, camera, fur_world, lit_world,
    quadrant_means_over, quadrant_settings,
};

fn run(world: &World, settings: RenderSettings, progress: &dyn Progress) -> RenderOutput {
    render(world, &camera(), &settings, Aovs::default(), progress).unwrap()
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A small uniform render: the rounds and the noise estimate without the allocation's pilot.
fn small(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: 24,
        height: 24,
        spp,
        seed,
        allocation: Allocation::Uniform,
        ..RenderSettings::default()
    }
}

/// A noise target no render here reaches: the render takes every spp, pass by pass, and
/// estimates its noise.
const UNREACHED: f32 = 1e-6;

fn estimating(base: RenderSettings) -> RenderSettings {
    RenderSettings {
        noise_target: Some(UNREACHED),
        ..base
    }
}

/// What a progress sink hears: the pixel counts and each pass's report.
#[derive(Default)]
struct Record {
    updates: Mutex<Vec<(u64, u64)>>,
    passes: Mutex<Vec<(u32, Option<f32>)>>,
}

impl Progress for Record {
    fn update(&self, done: u64, total: u64) -> bool {
        self.updates.lock().unwrap().push((done, total));
        true
    }
    fn pass(&self, samples_per_pixel: u32, noise: Option<f32>) {
        self.passes.lock().unwrap().push((samples_per_pixel, noise));
    }
}

/// A noise target stops the render after the first round whose estimate reaches it (the
/// round before did not), whatever the thread count, and the image is bit for bit the
/// plain render of the samples taken (which takes them at once, and estimates no noise).
/// Rounds grow (`rounds.rs`): the first is one pass, each later one at most as many as
/// were taken before it. The progress sink hears every round's estimate.
#[test]
fn a_noise_target_stops_at_the_first_round_that_reaches_it_with_the_plain_renders_bits() {
    let world = lit_world();
    let target = 0.03;
    let aimed = RenderSettings {
        noise_target: Some(target),
        threads: Some(2),
        ..small(512, 3)
    };
    let record = Record::default();
    let out = run(&world, aimed, &record);
    let (spp, noise) = (out.stats.spp, out.stats.noise.unwrap());
    println!("stopped at {spp} spp, noise {noise:.4} (target {target})");
    assert!(noise <= target && spp < 512 && spp % PASS_SAMPLES == 0 && spp > 2 * PASS_SAMPLES);
    let passes = record.passes.into_inner().unwrap();
    assert_eq!(
        passes[0],
        (PASS_SAMPLES, None),
        "one pass has no spread of passes"
    );
    assert!(
        passes
            .windows(2)
            .all(|w| w[0].0 < w[1].0 && w[1].0 <= 2 * w[0].0),
        "{passes:?}"
    );
    assert!((passes.len() as u32) < spp / PASS_SAMPLES, "{passes:?}");
    assert_eq!(passes.last(), Some(&(spp, Some(noise))));
    let before = passes[passes.len() - 2].1.unwrap();
    assert!(
        before > target,
        "the pass before was already good: {before}"
    );
    let updates = record.updates.into_inner().unwrap();
    // Pixels over passes: every pass's pixels are done, of all the passes spp allows.
    assert!(updates.windows(2).all(|w| w[0].0 <= w[1].0));
    let pass_pixels = |samples: u32| u64::from(samples / PASS_SAMPLES) * 24 * 24;
    assert_eq!(
        *updates.last().unwrap(),
        (pass_pixels(spp), pass_pixels(512))
    );

    let one_thread = run(
        &world,
        RenderSettings {
            threads: Some(1),
            ..aimed
        },
        &NoProgress,
    );
    assert_eq!(bits(one_thread.film.rgb()), bits(out.film.rgb()));
    let plain = run(&world, small(spp, 3), &NoProgress);
    assert_eq!(bits(plain.film.rgb()), bits(out.film.rgb()));
    assert_eq!((plain.stats.noise, plain.film.keep()), (None, Keep::Image));
}

/// A film keeps only what its render reads: a plain render its image alone (the sums too
/// for a progress sink that keeps passes), one that may stop early the sums and the noise
/// estimate's halves, the noise allocation the sums of its film and its pilot's squares,
/// rays and coverage. The bytes per pixel are the layout's.
#[test]
fn a_film_keeps_only_what_its_render_reads() {
    let world = lit_world();
    let all = Aovs {
        albedo: true,
        depth: true,
        strand_id: true,
    };
    // Image: rgb f32; sums: rgb f64 and a u32 count; halves: two f32 rgb and counts and a
    // pass count; spread: rgb squares f64 and a u64 ray count.
    let layout = [
        (Keep::Image, 12, 12 + 12 + 4 + 4),
        (Keep::Sums, 12 + 28, 32 + 28 + 24 + 4),
        (Keep::Halves, 12 + 28 + 36, 32 + 28 + 24 + 4 + 36),
        (Keep::Spread, 12 + 28 + 32, 32 + 28 + 24 + 4 + 32),
    ];
    for (keep, plain, with_aovs) in layout {
        assert_eq!(keep.bytes_per_pixel(Aovs::default()), plain, "{keep:?}");
        assert_eq!(keep.bytes_per_pixel(all), with_aovs, "{keep:?}");
    }
    let pixels = 24 * 24;
    for (settings, keep) in [
        (small(16, 1), Keep::Image),
        (estimating(small(16, 1)), Keep::Halves),
        (
            RenderSettings {
                time_budget: Some(1e3),
                ..small(16, 1)
            },
            Keep::Halves,
        ),
        (allocated(small(16, 1)), Keep::Sums),
        // The default allocation is the noise allocation, but for the few spp of its pilot.
        (
            RenderSettings {
                allocation: RenderSettings::default().allocation,
                ..small(16, 1)
            },
            Keep::Sums,
        ),
        (allocated(small(8, 1)), Keep::Image),
    ] {
        let out = render(&world, &camera(), &settings, all, &NoProgress).unwrap();
        assert_eq!(out.film.keep(), keep);
        assert_eq!(out.film.bytes(), pixels * keep.bytes_per_pixel(all));
        let pilot = match allocation_taken(&settings) {
            Allocation::Uniform => 0,
            Allocation::Noise => pixels * Keep::Spread.bytes_per_pixel(all),
        };
        assert_eq!(film_bytes(&settings, all, false), out.film.bytes() + pilot);
    }
    // A sink that keeps passes (the C ABI's callback) has a plain render keep the sums.
    struct KeepsPasses;
    impl Progress for KeepsPasses {
        fn update(&self, _: u64, _: u64) -> bool {
            true
        }
        fn keeps_passes(&self) -> bool {
            true
        }
    }
    let out = render(&world, &camera(), &small(16, 1), all, &KeepsPasses).unwrap();
    assert_eq!(out.film.keep(), Keep::Sums);
    assert_eq!(film_bytes(&small(16, 1), all, true), out.film.bytes());
}

/// A time budget far below one pass's time (a microsecond) still renders the first pass,
/// and no other: the budget is checked between passes, against the last pass's time.
#[test]
fn a_time_budget_stops_between_passes() {
    let world = lit_world();
    let out = run(
        &world,
        RenderSettings {
            time_budget: Some(1e-6),
            ..small(64, 1)
        },
        &NoProgress,
    );
    assert_eq!(out.stats.spp, PASS_SAMPLES);
    assert_eq!(out.stats.samples, u64::from(PASS_SAMPLES) * 24 * 24);
    assert_eq!(
        bits(out.film.rgb()),
        bits(run(&world, small(PASS_SAMPLES, 1), &NoProgress).film.rgb())
    );
}

/// The estimate against the truth: the relative RMSE measured over independent seeds
/// (each pixel's spread across them) against the mean of the renders' own estimates.
/// Within 20%, the bound.
#[test]
fn the_estimated_noise_is_within_a_fifth_of_the_measured_one() {
    const SEEDS: u64 = 24;
    let world = lit_world();
    let renders: Vec<RenderOutput> = (0..SEEDS)
        .map(|seed| run(&world, estimating(small(32, 100 + seed)), &NoProgress))
        .collect();
    let n = renders[0].film.rgb().len();
    let (mut variance, mut sum) = (0.0, 0.0);
    for i in 0..n {
        let v: Vec<f64> = renders.iter().map(|r| f64::from(r.film.rgb()[i])).collect();
        let m = v.iter().sum::<f64>() / SEEDS as f64;
        variance += v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (SEEDS - 1) as f64;
        sum += m;
    }
    let measured = (variance / n as f64).sqrt() / (sum / n as f64);
    let estimated = renders
        .iter()
        .map(|r| f64::from(r.stats.noise.unwrap()))
        .sum::<f64>()
        / SEEDS as f64;
    println!("noise: estimated {estimated:.4}, measured {measured:.4}");
    assert!(
        (estimated / measured - 1.0).abs() < 0.2,
        "estimated {estimated} against measured {measured}"
    );
}

fn allocated(base: RenderSettings) -> RenderSettings {
    RenderSettings {
        allocation: Allocation::Noise,
        ..base
    }
}

/// The noise allocation, the default, shares samples where there are samples to share
/// after its pilot and 32-bit sample indices to share them with; uniform sampling takes
/// every other spp, so that every spp is a valid render.
#[test]
fn the_noise_allocation_is_taken_between_its_pilot_and_its_indices_limit() {
    assert_eq!(RenderSettings::default().allocation, Allocation::Noise);
    let taken = |spp, allocation| {
        allocation_taken(&RenderSettings {
            spp,
            allocation,
            ..RenderSettings::default()
        })
    };
    for (spp, expected) in [
        (1, Allocation::Uniform),
        (PASS_SAMPLES, Allocation::Uniform),
        (PASS_SAMPLES + 1, Allocation::Noise),
        (1 << 22, Allocation::Noise),
        ((1 << 22) + 1, Allocation::Uniform),
        (u32::MAX, Allocation::Uniform),
    ] {
        assert_eq!(taken(spp, Allocation::Noise), expected, "{spp} spp");
        assert_eq!(
            taken(spp, Allocation::Uniform),
            Allocation::Uniform,
            "{spp} spp"
        );
    }
}

/// The noise allocation is unbiased: each image quadrant's mean agrees with the uniform
/// render's within 4 standard errors (over 64 seeds), at the same samples per pixel on
/// average. The pilot is weighted by its share of each pixel's samples, which is unbiased
/// only because the count is read from the neighbours' pilot: a count read from the
/// pixel's own pilot fails this (measured: 0.011 off in a quadrant, bound 0.0006), and one
/// read from its own with its neighbours' fails it too (0.00066 off, bound 0.00066).
#[test]
fn the_noise_allocation_keeps_the_quadrant_means_of_uniform_sampling() {
    // Few dark strands against a bright sky: a pixel whose pilot saw a strand is darker
    // and noisier, so a count read from that pilot would be larger and its weight smaller.
    let sky = Light::Environment(Environment::uniform(Vec3::ONE).unwrap());
    let world = fur_world(HairMaterial::default(), vec![sky], 300);
    let uniform = RenderSettings {
        spp: 16,
        ..quadrant_settings(PathSettings::default())
    };
    // Enough seeds to see those biases.
    let a = quadrant_means_over(&world, uniform, 1024);
    let b = quadrant_means_over(&world, allocated(uniform), 1024);
    assert_quadrants_agree("uniform vs noise allocation", &a, &b);
}

/// With the noise allocation, a crop across blocks renders the full frame's pixels bit for
/// bit, one thread or two, and pass by pass as at once; the samples are the uniform
/// render's count within the rounding of each pixel's share, and the estimated noise is no
/// higher.
#[test]
fn the_noise_allocation_is_crop_exact_and_thread_deterministic() {
    let world = lit_world();
    let base = estimating(allocated(RenderSettings {
        width: 40,
        height: 30,
        spp: 32,
        seed: 11,
        ..RenderSettings::default()
    }));
    let one = run(
        &world,
        RenderSettings {
            threads: Some(1),
            ..base
        },
        &NoProgress,
    );
    let two = run(
        &world,
        RenderSettings {
            threads: Some(2),
            ..base
        },
        &NoProgress,
    );
    assert_eq!(bits(one.film.rgb()), bits(two.film.rgb()));
    let at_once = RenderSettings {
        noise_target: None,
        ..base
    };
    let at_once = run(&world, at_once, &NoProgress);
    assert_eq!(bits(one.film.rgb()), bits(at_once.film.rgb()));
    let crop = run(
        &world,
        RenderSettings {
            crop: Some(CROP),
            threads: Some(2),
            ..base
        },
        &NoProgress,
    );
    assert_crop_of(one.film.rgb(), crop.film.rgb());
    let uniform = run(
        &world,
        RenderSettings {
            allocation: Allocation::Uniform,
            ..base
        },
        &NoProgress,
    );
    let ratio = one.stats.samples as f64 / uniform.stats.samples as f64;
    let (noise, uniform_noise) = (one.stats.noise.unwrap(), uniform.stats.noise.unwrap());
    println!("samples: {ratio:.3} of uniform; noise {noise:.4} against {uniform_noise:.4}");
    assert!((ratio - 1.0).abs() < 0.05, "{ratio}");
    assert!(noise < uniform_noise, "{noise} against {uniform_noise}");
}
