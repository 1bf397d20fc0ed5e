//! What a hair scene is made of, as data: strands (from files, hosts or procedural
//! grooms), curves, meshes, materials, lights and the camera; and the tracer, which puts
//! the geometry into Embree and turns its hits into hit records. Nothing here knows how a
//! picture is rendered (`render`) or described in a file (`description`).

pub mod camera;
pub mod curves;
pub mod detail_view;
pub mod envmap;
pub(crate) mod footprint;
pub mod framing;
pub(crate) mod groom;
pub mod hit;
pub mod light;
mod light_sample;
pub mod lod;
pub mod material;
pub(crate) mod mesh;
pub mod ribbons;
pub(crate) mod shapes;
pub mod stages;
pub(crate) mod strands;
pub mod tracer;

pub use camera::Camera;
pub use envmap::Environment;
pub use groom::{FurBall, HairStyle, ScalpPatch};
pub use light::{Light, LightEval, LightSample};
pub use mesh::Mesh;
pub use ribbons::GroomShape;
pub use stages::{NoStages, Stage, StageProgress, StageTimes};
pub use strands::Strands;
