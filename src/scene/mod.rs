//! What a hair scene is made of, independent of Embree: strands (from files, hosts or
//! procedural grooms).

pub mod camera;
pub mod curves;
pub mod description;
pub mod envmap;
pub mod groom;
pub mod hair_file;
pub mod hit;
pub mod light;
pub mod material;
pub mod mesh;
pub mod peer;
pub mod shapes;
pub mod strands;
pub mod tracer;

pub use camera::Camera;
pub use envmap::Environment;
pub use groom::{FurBall, HairStyle, ScalpPatch};
pub use hair_file::{
    Thickness, encode_hair, info_report, parse_hair, read_hair_file, write_hair_file,
};
pub use light::{Light, LightEval, LightSample};
pub use strands::Strands;
