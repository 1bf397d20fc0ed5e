//! Parallel rendering over square tiles with rayon.
//!
//! Each pixel is computed by one call of the per-pixel function per render, which sees only
//! its full-frame coordinates and the pixel's own samples so far, and stored once: the
//! result cannot depend on the number of threads, the order tiles finish in, the tile size
//! or the crop.

use std::cell::Cell;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::film::{Film, PixelAccumulator, Window};
use super::progress::Progress;
use crate::Result;
use crate::error::invalid_arg;
use crate::threads;

/// How the work is split and run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileOptions {
    /// Tile edge in pixels: small enough that two threads share a small crop and that
    /// cancellation is prompt, large enough that per-tile costs vanish.
    pub tile_size: u32,
    /// Worker threads; 0: one per hardware thread (or `RAYON_NUM_THREADS`). They are the
    /// render's own and are joined before [`render_tiles`] returns.
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
    /// The progress sink asked to stop. Tiles finished before that hold their new
    /// values; the others keep what they had (black in a fresh film).
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

/// How often, at most, the progress sink hears from a render in the middle of a tile, so
/// that it can cancel even a render whose pixels take seconds each.
pub const REPORT_INTERVAL: Duration = Duration::from_millis(20);

/// What the per-pixel function checks between samples: whether the render goes on.
pub struct Pulse<'a> {
    cancelled: &'a AtomicBool,
    /// Reports progress if [`REPORT_INTERVAL`] has passed since the last report.
    heartbeat: &'a (dyn Fn() + Sync),
    calls: Cell<u32>,
}

impl Pulse<'_> {
    /// Call before each sample (a few microseconds of work or more); false once the render
    /// is cancelled: return at once, the pixel is dropped. Every eighth call also gives
    /// the progress sink its periodic report.
    pub fn keep_going(&self) -> bool {
        let n = self.calls.get().wrapping_add(1);
        self.calls.set(n);
        if n % 8 == 0 {
            (self.heartbeat)();
        }
        !self.cancelled.load(Ordering::Relaxed)
    }
}

/// Renders every pixel of `film`'s crop window with `shade(pixel, accumulator, pulse)`,
/// which adds the pixel's samples to the accumulator it is given (the pixel's samples so
/// far: none in a fresh film, so that a render in passes calls this once a pass), asking
/// `pulse.keep_going()` before each; `pixel` is in full-frame coordinates.
///
/// `progress` hears of each finished tile, and between those at most every
/// [`REPORT_INTERVAL`] of work while shading calls `keep_going` (with the same `done`
/// while no tile finishes). It may cancel: then no new sample starts, the tiles in flight
/// are dropped, and the result is [`RenderStatus::Cancelled`].
pub fn render_tiles<F>(
    film: &mut Film,
    options: &TileOptions,
    progress: &dyn Progress,
    shade: F,
) -> Result<RenderStatus>
where
    F: Fn((u32, u32), &mut PixelAccumulator, &Pulse) + Sync,
{
    if options.tile_size == 0 {
        return Err(invalid_arg!("tile size must be at least 1 pixel"));
    }
    let crop = film.crop();
    let total = crop.pixel_count();
    let work = tiles(crop, options.tile_size);
    let cancelled = AtomicBool::new(false);
    // The film and the count of finished pixels, under one lock so that progress calls
    // are serialised and never see `done` decrease.
    let shared = Mutex::new((film, 0u64));
    let start = Instant::now();
    let next_report = AtomicU64::new(REPORT_INTERVAL.as_nanos() as u64);
    let heartbeat = || {
        let due = |now: u64| now >= next_report.load(Ordering::Relaxed);
        let now = start.elapsed().as_nanos() as u64;
        // A busy lock means a tile is being stored, and reported: skip this one.
        if let (true, Ok(guard)) = (due(now), shared.try_lock()) {
            if due(now) {
                next_report.store(now + REPORT_INTERVAL.as_nanos() as u64, Ordering::Relaxed);
                if !progress.update(guard.1, total) {
                    cancelled.store(true, Ordering::Relaxed);
                }
            }
        }
    };

    let render_tile = |tile: &Window| {
        let pulse = Pulse {
            cancelled: &cancelled,
            heartbeat: &heartbeat,
            calls: Cell::new(0),
        };
        let mut pixels: Vec<((u32, u32), PixelAccumulator)> = {
            let guard = shared.lock().unwrap_or_else(|e| e.into_inner());
            tile.pixels().map(|p| (p, guard.0.accumulator(p))).collect()
        };
        for (pixel, acc) in &mut pixels {
            if cancelled.load(Ordering::Relaxed) {
                return;
            }
            shade(*pixel, acc, &pulse);
        }
        // A pixel cut short by a cancellation is not stored.
        if cancelled.load(Ordering::Relaxed) {
            return;
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
    threads::scoped(options.threads, || work.par_iter().for_each(render_tile))?;
    Ok(if cancelled.into_inner() {
        RenderStatus::Cancelled
    } else {
        RenderStatus::Complete
    })
}
