//! The renderer's building blocks: per-pixel sample numbers, the film and its AOVs, tiles
//! run in parallel, progress and cancellation. The integrator composes them with the
//! camera, the lights and the traceable scene.

pub(crate) mod allocation;
pub(crate) mod camera_rays;
pub(crate) mod film;
pub(crate) mod integrator;
pub(crate) mod progress;
pub(crate) mod renderer;
mod rounds;
pub(crate) mod sampler;
pub mod settings;
mod survey;
pub(crate) mod survival;
pub(crate) mod tiles;

pub use film::{Aovs, Film, Keep, NO_HIT_DEPTH, NO_STRAND, PixelFilter, Window};
pub use progress::{NoProgress, Progress};
pub use renderer::{RenderOutput, RenderStats};
pub use tiles::RenderStatus;

#[cfg(test)]
pub(crate) mod tests;
