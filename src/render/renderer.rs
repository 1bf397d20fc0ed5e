//! One render: camera samples per pixel through the integrator, over tiles in parallel.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use super::film::{Aovs, Film, Window, ndc};
use super::integrator::World;
use super::progress::Progress;
use super::sampler::PixelSampler;
use super::settings::RenderSettings;
use super::tiles::{RenderStatus, TileOptions, render_tiles};
use crate::error::{Result, invalid_arg};
use crate::scene::camera::Camera;
use crate::scene::detail_view::DetailView;

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
    /// Rays traced: closest-hit and shadow.
    pub rays: u64,
}

/// Renders `world` through `camera`. Each sample's numbers depend only on the seed, the
/// full-frame pixel and the sample index, so the image is the same for any thread count,
/// tile order or crop. A world whose curves were shaped for a view (the `auto` shape)
/// renders only the views for which those shapes hold ([`crate::scene::tracer::Tracer::serves`]);
/// any other is refused, to be built again for it.
pub fn render(
    world: &World,
    camera: &Camera,
    settings: &RenderSettings,
    aovs: Aovs,
    progress: &dyn Progress,
) -> Result<RenderOutput> {
    settings.validate()?;
    if !world.tracer.serves(&DetailView::new(
        *camera,
        settings.height,
        settings.lod_pixels,
    )) {
        return Err(invalid_arg!(
            "the scene's curves were shaped for a view that saw them smaller (from farther, \
             or with fewer pixels): build the scene again for this camera and image height"
        ));
    }
    let crop = settings
        .crop
        .map(|[x0, y0, x1, y1]| Window { x0, y0, x1, y1 });
    let mut film = Film::new(settings.width, settings.height, crop, aovs)?;
    let filter = settings.pixel_filter()?;
    let options = TileOptions {
        tile_size: 16,
        threads: settings.threads.unwrap_or(0),
    };
    let rays = AtomicU64::new(0);
    let start = Instant::now();
    let status = render_tiles(&mut film, &options, progress, |pixel, acc, pulse| {
        let mut pixel_rays = 0u64;
        for index in 0..settings.spp {
            if !pulse.keep_going() {
                break;
            }
            let mut sampler = PixelSampler::new(settings.seed, pixel, index);
            let offset = filter.sample(sampler.next_2d());
            let image_point = ndc(settings.width, settings.height, pixel, offset);
            let lens = if camera.has_lens() {
                sampler.next_2d()
            } else {
                sampler.skip();
                [0.5; 2]
            };
            let (org, dir) = camera.ray(image_point, lens);
            let (radiance, first, traced) =
                world.radiance(org, dir, &settings.path, aovs.any(), &mut sampler);
            pixel_rays += u64::from(traced);
            acc.add(radiance, first.as_ref());
        }
        rays.fetch_add(pixel_rays, Ordering::Relaxed);
    })?;
    let window = film.crop();
    let stats = RenderStats {
        seconds: start.elapsed().as_secs_f64(),
        samples: window.pixel_count() * u64::from(settings.spp),
        rays: rays.into_inner(),
    };
    Ok(RenderOutput {
        film,
        status,
        stats,
    })
}
