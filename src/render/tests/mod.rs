//! The render layer's tests that need more than one module: the camera, film and tiles
//! contract, renders end to end, and renders that adapt.

mod adaptive;
mod camera_film;
mod huang;
pub(crate) mod render;
