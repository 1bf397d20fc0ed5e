//! Progress reports and cancellation, for the CLI's progress bar and a host's callback.

/// Told how far a render has got. The renderer calls [`update`](Progress::update) once
/// per finished tile, from worker threads but never two calls at once, with `done`
/// increasing from call to call up to `total` (both in pixels, over every pass the render
/// may make: one that stops early ends below `total`).
pub trait Progress: Sync {
    /// Returns `false` to cancel the render: no new pixel starts after that, and the
    /// render returns [`RenderStatus::Cancelled`](super::RenderStatus::Cancelled).
    fn update(&self, done: u64, total: u64) -> bool;

    /// Told, after each round of passes of a render, the samples per pixel so far and the
    /// estimated noise then ([`Film::noise`](super::Film::noise)); by default, nothing.
    fn pass(&self, _samples_per_pixel: u32, _noise: Option<f32>) {}

    /// Whether a cancelled render should leave the whole frame at the rounds of passes its
    /// pixels finished (8 spp each; rounds of 1, 1, 2, 4... passes), rather than the
    /// finished tiles at every spp and black elsewhere: the render then goes in rounds even
    /// without a noise target or a time budget, its film keeping each pixel's sums between
    /// them (28 more bytes a pixel). By default, no.
    fn keeps_passes(&self) -> bool {
        false
    }
}

/// Reports nowhere and never cancels.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn update(&self, _done: u64, _total: u64) -> bool {
        true
    }
}

/// Any `Fn(done, total) -> keep_going` closure is a progress sink.
impl<F: Fn(u64, u64) -> bool + Sync> Progress for F {
    fn update(&self, done: u64, total: u64) -> bool {
        self(done, total)
    }
}
