//! The render layer's tests that need more than one module: the camera, film and tiles
//! contract, renders end to end, renders that adapt, and motion blur (of the scene and of the
//! camera).

mod adaptive;
mod camera_film;
mod camera_motion;
mod huang;
mod motion;
pub(crate) mod render;
