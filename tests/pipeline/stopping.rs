//! Renders that stop when they are good enough: a noise target and a time budget, decided
//! between passes, and the noise estimate they rest on.

use std::sync::Mutex;

use hairtrace::render::integrator::World;
use hairtrace::render::renderer::{PASS_SAMPLES, RenderOutput, render};
use hairtrace::render::settings::RenderSettings;
use hairtrace::render::{Aovs, NoProgress, Progress};

use super::render::{camera, lit_world};

fn run(world: &World, settings: RenderSettings, progress: &dyn Progress) -> RenderOutput {
    render(world, &camera(), &settings, Aovs::default(), progress).unwrap()
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn small(spp: u32, seed: u64) -> RenderSettings {
    RenderSettings {
        width: 24,
        height: 24,
        spp,
        seed,
        ..RenderSettings::default()
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

/// A noise target stops the render after the first pass whose estimate reaches it (the
/// pass before did not), whatever the thread count, and the image is bit for bit the
/// plain render of the samples taken. The progress sink hears every pass's estimate.
#[test]
fn a_noise_target_stops_at_the_first_pass_that_reaches_it_with_the_plain_renders_bits() {
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
    assert_eq!(passes.len() as u32, spp / PASS_SAMPLES);
    assert_eq!(passes.last(), Some(&(spp, Some(noise))));
    assert!(passes[0].1.is_none(), "one pass has no spread of passes");
    let before = passes[passes.len() - 2].1.unwrap();
    assert!(before > target, "the pass before was already good: {before}");
    let updates = record.updates.into_inner().unwrap();
    assert!(updates.windows(2).all(|w| w[0].0 <= w[1].0));
    assert_eq!(updates.last().unwrap().0, u64::from(spp) * 24 * 24);

    let one_thread = run(&world, RenderSettings { threads: Some(1), ..aimed }, &NoProgress);
    assert_eq!(bits(one_thread.film.rgb()), bits(out.film.rgb()));
    let plain = run(&world, small(spp, 3), &NoProgress);
    assert_eq!(bits(plain.film.rgb()), bits(out.film.rgb()));
    assert_eq!(plain.stats.noise, Some(noise));
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
    assert_eq!(bits(out.film.rgb()), bits(run(&world, small(PASS_SAMPLES, 1), &NoProgress).film.rgb()));
}

/// The estimate against the truth: the relative RMSE measured over independent seeds
/// (each pixel's spread across them) against the mean of the renders' own estimates.
/// Within 20%, the bound.
#[test]
fn the_estimated_noise_is_within_a_fifth_of_the_measured_one() {
    const SEEDS: u64 = 24;
    let world = lit_world();
    let renders: Vec<RenderOutput> = (0..SEEDS)
        .map(|seed| run(&world, small(32, 100 + seed), &NoProgress))
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
