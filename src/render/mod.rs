//! The renderer's building blocks: per-pixel sample numbers, the film and its AOVs, tiles
//! run in parallel, progress and cancellation. The integrator composes them with the
//! camera, the lights and the traceable scene.

pub(crate) mod allocation;
pub(crate) mod film;
pub mod integrator;
pub(crate) mod progress;
pub mod renderer;
pub(crate) mod sampler;
pub mod settings;
pub(crate) mod tiles;

pub use film::{
    Aovs, Film, FirstHit, Keep, NO_HIT_DEPTH, NO_STRAND, PixelAccumulator, PixelFilter, Window, ndc,
};
pub use progress::{NoProgress, Progress};
pub use sampler::PixelSampler;
pub use tiles::{Pulse, REPORT_INTERVAL, RenderStatus, TileOptions, render_tiles, tiles};
