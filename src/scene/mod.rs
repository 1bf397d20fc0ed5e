//! What a hair scene is made of, as data: strands (from files, hosts or procedural
//! grooms), curves, meshes, materials, lights and the camera; and the tracer, which puts
//! the geometry into Embree and turns its hits into hit records. Nothing here knows how a
//! picture is rendered (`render`) or described in a file (`description`).

pub(crate) mod camera;
#[cfg(feature = "bench-internals")]
pub mod curves;
#[cfg(not(feature = "bench-internals"))]
pub(crate) mod curves;
pub(crate) mod detail_view;
pub(crate) mod envmap;
pub(crate) mod footprint;
pub(crate) mod framing;
pub(crate) mod groom;
#[cfg(feature = "bench-internals")]
pub mod hit;
#[cfg(not(feature = "bench-internals"))]
pub(crate) mod hit;
pub(crate) mod light;
pub(crate) mod light_sample;
pub(crate) mod lod;
pub(crate) mod material;
pub(crate) mod mesh;
mod ragged;
pub(crate) mod ribbons;
pub(crate) mod shapes;
pub(crate) mod stages;
pub(crate) mod strands;
#[cfg(feature = "bench-internals")]
pub mod tracer;
#[cfg(not(feature = "bench-internals"))]
pub(crate) mod tracer;

pub use crate::math::{CurveBasis, CurveShape};
pub use camera::Camera;
pub use envmap::Environment;
pub use groom::{FurBall, HairStyle, ScalpPatch};
pub use light::{Light, LightEval, LightSample};
pub use material::{HairColor, HairMaterial, HairModel, Material};
pub use mesh::Mesh;
pub use ribbons::GroomShape;
pub use stages::{NoStages, Stage, StageProgress, StageTimes};
pub use strands::Strands;

#[cfg(test)]
mod tests;
