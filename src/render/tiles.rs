//! Parallel rendering over square tiles with rayon.
//!
//! Each pixel is computed by one call of the per-pixel function, which sees only its
//! full-frame coordinates, and stored once: the result cannot depend on the number of
//! threads, the order tiles finish in, the tile size or the crop.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::film::{Film, PixelAccumulator, Window};
use super::progress::Progress;
use crate::Result;
use crate::error::invalid_arg;

/// How the work is split and run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileOptions {
    /// Tile edge in pixels: small enough that two threads share a small crop and that
    /// cancellation is prompt, large enough that per-tile costs vanish.
    pub tile_size: u32,
    /// Worker threads; 0 uses rayon's global pool (all cores unless `RAYON_NUM_THREADS`).
    pub threads: usize,
}

impl Default for TileOptions {
    fn default() -> Self {
        Self {
            tile_size: 16,
            threads: 0,
        }
    }
}

/// How a render ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RenderStatus {
    Complete,
    /// The progress sink asked to stop. Tiles finished before that hold their final
    /// values; the others stay black.
    Cancelled,
}

/// Splits `window` into tiles of at most `size` x `size` pixels, row by row from the top
/// left. Empty for an empty window or a zero size.
pub fn tiles(window: Window, size: u32) -> Vec<Window> {
    if size == 0 {
        return Vec::new();
    }
    let starts = |lo: u32, hi: u32| (lo..hi).step_by(size as usize);
    starts(window.y0, window.y1)
        .flat_map(|y0| {
            starts(window.x0, window.x1).map(move |x0| Window {
                x0,
                y0,
                x1: x0.saturating_add(size).min(window.x1),
                y1: y0.saturating_add(size).min(window.y1),
            })
        })
        .collect()
}

/// Renders every pixel of `film`'s crop window with `shade(pixel, accumulator)`, which
/// adds the pixel's samples to the fresh accumulator it is given; `pixel` is in
/// full-frame coordinates.
///
/// `progress` hears of each finished tile and may cancel: then no new pixel starts, the
/// tiles in flight are dropped, and the result is [`RenderStatus::Cancelled`].
pub fn render_tiles<F>(
    film: &mut Film,
    options: &TileOptions,
    progress: &dyn Progress,
    shade: F,
) -> Result<RenderStatus>
where
    F: Fn((u32, u32), &mut PixelAccumulator) + Sync,
{
    if options.tile_size == 0 {
        return Err(invalid_arg!("tile size must be at least 1 pixel"));
    }
    let crop = film.crop();
    let total = crop.pixel_count();
    let work = tiles(crop, options.tile_size);
    let cancelled = AtomicBool::new(false);
    // The film and the count of finished pixels, under one lock so that progress calls
    // are serialised and see `done` increase.
    let shared = Mutex::new((film, 0u64));

    let render_tile = |tile: &Window| {
        let mut pixels = Vec::with_capacity(tile.pixel_count() as usize);
        for pixel in tile.pixels() {
            if cancelled.load(Ordering::Relaxed) {
                return;
            }
            let mut acc = PixelAccumulator::default();
            shade(pixel, &mut acc);
            pixels.push((pixel, acc));
        }
        // A panic in another tile's `shade` poisons the lock but leaves the film valid.
        let mut guard = shared.lock().unwrap_or_else(|e| e.into_inner());
        let (film, done) = &mut *guard;
        for (pixel, acc) in &pixels {
            film.store(*pixel, acc);
        }
        *done += tile.pixel_count();
        if !progress.update(*done, total) {
            cancelled.store(true, Ordering::Relaxed);
        }
    };
    let run = || work.par_iter().for_each(render_tile);

    if options.threads == 0 {
        run();
    } else {
        rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads)
            .build()
            .map_err(|e| invalid_arg!("cannot start {} render threads: {e}", options.threads))?
            .install(run);
    }
    Ok(if cancelled.into_inner() {
        RenderStatus::Cancelled
    } else {
        RenderStatus::Complete
    })
}
