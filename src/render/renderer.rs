//! One render: camera samples per pixel through the integrator, over tiles in parallel.

use std::sync::OnceLock;
use std::time::Instant;

use glam::Vec3;

use super::allocation;
use super::camera_rays::{self, FrameRates, MAX_CAMERA_RAYS};
use super::film::{Aovs, Film, Keep, Window, ndc};
use super::integrator::World;
use super::progress::Progress;
use super::rounds::{Rounds, Stops, Taken};
use super::sampler::PixelSampler;
use super::settings::{Allocation, CameraRays, RenderSettings, RouletteScale};
use super::survey::{self, Survey};
use super::survival::{Recorder, Survival};
use super::tiles::{RenderStatus, TileOptions, render_tiles};
use crate::embree::Ray;
use crate::error::{Result, invalid_arg};
use crate::scene::camera::Camera;
use crate::scene::detail_view::DetailView;
use crate::scene::footprint::{self, available_bytes};
use crate::threads;

/// A finished (or cancelled) render and what it cost.
#[derive(Debug)]
pub struct RenderOutput {
    pub film: Film,
    pub status: RenderStatus,
    pub stats: RenderStats,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderStats {
    pub seconds: f64,
    /// Camera samples taken.
    pub samples: u64,
    /// Samples per pixel taken: `spp`, or fewer where a noise target or a time budget
    /// stopped the render.
    pub spp: u32,
    /// The estimated noise at the end ([`Film::noise`]); None after a single pass, and for
    /// a render with neither a noise target nor a time budget, which estimates none.
    pub noise: Option<f32>,
    /// Rays traced: closest-hit and shadow.
    pub rays: u64,
    /// Seconds from the render's start to its first finished tile; `None` when it
    /// finished none (cancelled at once).
    pub first_tile_seconds: Option<f64>,
    /// Parts of large curve geometries built during this render, when a ray first reached
    /// them (`embree::lazy`), and the seconds their builds took, summed over threads.
    pub parts_built: usize,
    pub part_build_seconds: f64,
}

/// Samples per pixel of one pass. A render proceeds in passes, grouped in rounds
/// (`rounds.rs`), and decides whether to stop only between two rounds, so that its image is
/// that of a plain render of the samples it took.
/// A power of two, so that each pass is a block of the Sobol sequence stratified in itself
/// (the noise estimate's halves, [`PixelAccumulator::variance_of_mean`]).
///
/// [`PixelAccumulator::variance_of_mean`]: super::film::PixelAccumulator::variance_of_mean
pub const PASS_SAMPLES: u32 = 8;

/// Whether a render may stop before `spp`: it then renders in growing rounds of passes,
/// and estimates its noise (to stop on it, or to tell what a time budget reached).
fn stops_early(settings: &RenderSettings) -> bool {
    settings.noise_target.is_some() || settings.time_budget.is_some()
}

/// The allocation a render with `settings` takes: theirs where it has samples to share
/// after the pilot pass and sample indices to share them with (spp in (`PASS_SAMPLES`,
/// `allocation::MOST_SPP`]), uniform elsewhere. At `PASS_SAMPLES` or fewer the pilot is
/// the whole render, and the uniform render's samples.
pub(crate) fn allocation_taken(settings: &RenderSettings) -> Allocation {
    let shares = (PASS_SAMPLES + 1..=allocation::MOST_SPP).contains(&settings.spp);
    if shares {
        settings.allocation
    } else {
        Allocation::Uniform
    }
}

/// What the film of a render with `settings` keeps besides its image: the noise
/// estimate's halves for one that may stop early, the sums for one in passes (whose
/// progress sink [keeps passes](Progress::keeps_passes)) or whose pilot comes first, and
/// nothing for one that takes each pixel's samples at once.
pub fn film_keep(settings: &RenderSettings, keeps_passes: bool) -> Keep {
    match (
        stops_early(settings),
        keeps_passes,
        allocation_taken(settings),
    ) {
        (true, _, _) => Keep::Halves,
        (false, true, _) | (false, false, Allocation::Noise) => Keep::Sums,
        (false, false, Allocation::Uniform) => Keep::Image,
    }
}

/// The window of the frame `settings` crop to, if they crop.
fn crop(settings: &RenderSettings) -> Option<Window> {
    settings
        .crop
        .map(|[x0, y0, x1, y1]| Window { x0, y0, x1, y1 })
}

/// The bytes of the films a render with `settings` and `aovs` holds, its progress sink
/// keeping passes or not: its film's and the noise allocation's pilot's. Zero for settings
/// whose crop is not inside the frame.
pub fn film_bytes(settings: &RenderSettings, aovs: Aovs, keeps_passes: bool) -> u64 {
    let (width, height) = (settings.width, settings.height);
    let window = crop(settings).unwrap_or(Window::full(width, height));
    let film = window
        .pixel_count()
        .saturating_mul(film_keep(settings, keeps_passes).bytes_per_pixel(aovs));
    let pilot = match allocation_taken(settings) {
        Allocation::Uniform => 0,
        Allocation::Noise => allocation::pilot_window(window, width, height)
            .pixel_count()
            .saturating_mul(Keep::Spread.bytes_per_pixel(aovs)),
    };
    film.saturating_add(pilot)
}

/// [`film_bytes`] of the render, and of the same render sampled uniformly: what
/// [`footprint::check_film_fits`] suggests when the noise allocation's films do not fit.
pub fn film_bytes_and_uniform(
    settings: &RenderSettings,
    aovs: Aovs,
    keeps_passes: bool,
) -> (u64, u64) {
    let uniform = RenderSettings {
        allocation: Allocation::Uniform,
        ..*settings
    };
    (
        film_bytes(settings, aovs, keeps_passes),
        film_bytes(&uniform, aovs, keeps_passes),
    )
}

/// Whether `world`'s curves, shaped for the view they were built for, hold for `camera`
/// at `settings`' image height and level of detail ([`crate::scene::tracer::Tracer::serves`]).
pub(crate) fn serves(world: &World, camera: &Camera, settings: &RenderSettings) -> bool {
    (world.tracer).serves(&DetailView::new(
        camera.clone(),
        settings.height,
        settings.lod_pixels,
    ))
}

/// Renders `world` through `camera`. Each sample's numbers depend only on the seed, the
/// full-frame pixel and the sample index, so the image is the same for any thread count,
/// tile order or crop. A world whose curves were shaped for a view (the `auto` shape)
/// renders only the views for which those shapes hold ([`crate::scene::tracer::Tracer::serves`]);
/// any other is refused, to be built again for it.
///
/// The samples are taken in passes of [`PASS_SAMPLES`] per pixel (on average, under the
/// `noise` allocation, `src/render/allocation.rs`), in sample order, in rounds over the
/// tiles. Between rounds the render stops once the estimated noise of the window it renders
/// is at most `noise_target`; no round starts that (timed as the last one) would end past
/// `time_budget`, and none takes more passes than the noise estimate says the target needs
/// (`rounds.rs`). The image is then, bit for bit, that of a render with `spp` = the samples
/// taken ([`RenderStats::spp`]). A crop's noise is its own, so farm tiles fix `spp`. A
/// render with neither takes all its passes (after the pilot) in one round, the same
/// samples in the same order, so that its film need not keep them between passes
/// ([`film_keep`]), unless `progress` [keeps passes](Progress::keeps_passes): then in
/// growing rounds, so that a cancel leaves the whole frame at the rounds it finished.
pub fn render(
    world: &World,
    camera: &Camera,
    settings: &RenderSettings,
    aovs: Aovs,
    progress: &dyn Progress,
) -> Result<RenderOutput> {
    settings.validate()?;
    if !serves(world, camera, settings) {
        return Err(invalid_arg!(
            "the scene's curves were shaped for a view that saw them smaller (from farther, \
             or with fewer pixels): build the scene again for this camera and image height"
        ));
    }
    let (bytes, uniform) = film_bytes_and_uniform(settings, aovs, progress.keeps_passes());
    footprint::check_film_fits(bytes, uniform, available_bytes())?;
    let (width, height) = (settings.width, settings.height);
    let keep = film_keep(settings, progress.keeps_passes());
    let mut film = Film::keeping(width, height, crop(settings), aovs, keep)?;
    // The noise allocation's pilot, over whole blocks around the crop.
    let mut pilot = match allocation_taken(settings) {
        Allocation::Uniform => None,
        Allocation::Noise => {
            let window = allocation::pilot_window(film.crop(), width, height);
            Some(Film::keeping(
                width,
                height,
                Some(window),
                aovs,
                Keep::Spread,
            )?)
        }
    };
    let mut shares: Option<allocation::Shares> = None;
    let filter = settings.pixel_filter()?;
    let pixel_spread = camera.pixel_spread(height);
    // Each count's shifts (`validate` refuses counts outside [1, MAX_CAMERA_RAYS]).
    let shift_sets: Vec<_> = (0..=MAX_CAMERA_RAYS as u32)
        .map(camera_rays::shifts)
        .collect();
    // `auto` chooses from the survey where the render has a pilot (and so samples enough
    // to pay for the survey); it takes one ray elsewhere.
    let choosing = settings.camera_rays == CameraRays::Auto && pilot.is_some();
    // The roulette where no light is sampled learns its survival from the survey too.
    let learning = pilot.is_some()
        && settings.path.roulette_scale == RouletteScale::Auto
        && !world.samples_lights(&settings.path);
    let mut survival = Survival::default();
    let mut choice: Option<camera_rays::Choice> = None;
    // Rays the survey traced.
    let mut survey_rays = 0;
    let options = TileOptions {
        tile_size: 16,
        threads: settings.threads.unwrap_or(0),
    };
    let pixels = film.crop().pixel_count();
    let passes = settings.spp.div_ceil(PASS_SAMPLES);
    let stops = if stops_early(settings) || progress.keeps_passes() {
        Stops::Growing {
            noise_target: settings.noise_target,
            time_budget: settings.time_budget,
        }
    } else {
        Stops::Never
    };
    let mut rounds = Rounds::new(passes, pilot.is_some(), stops);
    let parts_before = world.tracer.scene().parts_built();
    let motion_blur = settings.motion_blur();
    let first_tile = OnceLock::new();
    // Sample `index` of `pixel` of the render seeded `seed`, traced as `count` rays, its
    // roulette's survival `survival`.
    let sample_at = |seed: u64,
                     (pixel, index): ((u32, u32), u32),
                     count: u32,
                     survival: &Survival,
                     record: Option<&mut Recorder>| {
        let shifts = &shift_sets[count as usize][..count as usize];
        let mut sampler = PixelSampler::new(seed, pixel, index);
        let [ux, uy, choice, _] = sampler.next_4d();
        let lens = if camera.has_lens() {
            sampler.next_2d()
        } else {
            sampler.skip();
            [0.5; 2]
        };
        let time = if motion_blur { sampler.time() } else { 0.0 };
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); MAX_CAMERA_RAYS];
        for (ray, shift) in rays.iter_mut().zip(shifts) {
            let u = [(ux + shift[0]).fract(), (uy + shift[1]).fract()];
            let image_point = ndc(width, height, pixel, filter.sample(u));
            let (org, dir) = camera.ray_at(image_point, lens, time);
            *ray = Ray {
                time,
                ..Ray::new(org, dir)
            };
        }
        world.camera_sample(
            &rays[..shifts.len()],
            choice,
            &settings.path,
            aovs.any(),
            pixel_spread,
            &mut sampler,
            (survival, record),
        )
    };
    let start = Instant::now();
    // One pool of workers for every round: `render_tiles` runs on it.
    let (spp, noise, status) = threads::scoped(options.threads, || -> Result<_> {
        if choosing || learning {
            let seed = survey::seed(settings.seed);
            let rule = Survival::default();
            // The block lattice only where blocks choose: the pilot's window.
            let window = pilot.as_ref().filter(|_| choosing).map(Film::crop);
            // The roulette's decisions are recorded only for a survival to learn.
            let survey = Survey::trace(width, height, window, &|p, i, recorder| {
                sample_at(seed, (p, i), 1, &rule, learning.then_some(recorder))
            });
            survey_rays = survey.rays();
            let frame_samples = u64::from(width) * u64::from(height) * u64::from(settings.spp);
            let segments = world.tracer.scene().curve_segments();
            let build = FrameRates::build_rays(segments, frame_samples);
            if learning {
                survival = Survival::learn(survey.frame().map(|p| &p.roulette), build);
            }
            if let Some(window) = window {
                let frame = FrameRates::of(&survey, build);
                let widest = camera_rays::widest_split(settings.spp, motion_blur);
                choice = Some(camera_rays::Choice::new(&survey, window, frame, widest));
            }
        }
        let (mut spp, mut noise, mut status) = (0, None, RenderStatus::Complete);
        let mut taken = None;
        while let Some(round) = rounds.next(taken) {
            let began = start.elapsed().as_secs_f64();
            // Saturating: a host may ask u32::MAX spp and cancel when it has enough.
            let end = round.end.saturating_mul(PASS_SAMPLES).min(settings.spp);
            // Sample indices of a pixel in a pass.
            let indices = |pixel, pass: u32| match &shares {
                None => {
                    pass * PASS_SAMPLES..(pass + 1).saturating_mul(PASS_SAMPLES).min(settings.spp)
                }
                Some(shares) => shares.indices(pixel, pass),
            };
            let target = match (&mut pilot, round.start) {
                (Some(pilot), 0) => pilot,
                _ => &mut film,
            };
            // Progress in pixels over every pass, the round's spread over its passes.
            let (offset, total) = (u64::from(round.start) * pixels, u64::from(passes) * pixels);
            let round_pixels = u128::from(round.len() as u64 * pixels);
            let in_pass = u128::from(target.crop().pixel_count());
            let pass_progress = |done: u64, _| {
                if done > 0 {
                    first_tile.get_or_init(|| start.elapsed().as_secs_f64());
                }
                let done = u128::from(done) * round_pixels / in_pass;
                progress.update(offset + done as u64, total)
            };
            let chosen = choice.as_ref();
            status = render_tiles(target, &options, &pass_progress, |pixel, acc, pulse| {
                let count = match (settings.camera_rays, chosen) {
                    (CameraRays::Fixed(n), _) => n,
                    (CameraRays::Auto, Some(c)) => c.rays(pixel),
                    (CameraRays::Auto, None) => 1,
                };
                for pass in round.clone() {
                    for index in indices(pixel, pass) {
                        if !pulse.keep_going() {
                            return;
                        }
                        let sample =
                            sample_at(settings.seed, (pixel, index), count, &survival, None);
                        acc.add(sample.radiance, sample.first.as_ref());
                        acc.add_rays(sample.rays);
                    }
                    acc.end_pass();
                }
            })?;
            if status == RenderStatus::Cancelled {
                break;
            }
            spp = end;
            noise = match &pilot {
                None => film.noise(),
                Some(pilot) if round.start == 0 => {
                    shares = Some(allocation::Shares::new(pilot, film.crop(), PASS_SAMPLES));
                    None
                }
                Some(pilot) => allocation::blended_noise(&film, pilot),
            };
            let elapsed = start.elapsed().as_secs_f64();
            taken = Some(Taken {
                noise,
                seconds: elapsed - began,
                elapsed,
            });
            progress.pass(spp, noise);
        }
        Ok((spp, noise, status))
    })??;
    // A part whose build failed let rays through: the image is wrong.
    world.tracer.scene().check_parts()?;
    if let Some(pilot) = &pilot {
        allocation::blend(&mut film, pilot);
    }
    let parts = world.tracer.scene().parts_built();
    let stats = RenderStats {
        seconds: start.elapsed().as_secs_f64(),
        samples: film.samples() + pilot.as_ref().map_or(0, Film::samples),
        spp,
        noise,
        rays: film.rays() + pilot.as_ref().map_or(0, Film::rays) + survey_rays,
        first_tile_seconds: first_tile.get().copied(),
        parts_built: parts.built - parts_before.built,
        part_build_seconds: parts.seconds - parts_before.seconds,
    };
    Ok(RenderOutput {
        film,
        status,
        stats,
    })
}
