//! The renderer's building blocks: per-pixel sample numbers, the film and its AOVs, tiles
//! run in parallel, progress and cancellation. The integrator composes them with the
//! camera, the lights and the traceable scene.

pub mod film;
pub mod integrator;
pub mod progress;
pub mod renderer;
pub mod sampler;
pub mod settings;
pub mod tiles;

pub use film::{Aovs, Film, FirstHit, PixelAccumulator, PixelFilter, Window};
pub use progress::{NoProgress, Progress};
pub use sampler::PixelSampler;
pub use tiles::{RenderStatus, TileOptions, render_tiles, tiles};
