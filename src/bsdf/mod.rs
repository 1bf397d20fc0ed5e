//! Scattering models. The hair BSDF is the heart of the crate; its pieces (longitudinal
//! and azimuthal lobes, absorption from colour) are public so that tests and hosts can
//! check them one by one.

pub mod absorption;
pub mod azimuthal;
pub mod diffuse;
pub mod hair;
mod limits;
pub mod longitudinal;
pub mod params;

pub use absorption::{sigma_a_from_color, sigma_a_from_melanin};
pub use diffuse::Diffuse;
pub use hair::{HairBsdf, HairEval, HairPoint, HairSample};
pub use longitudinal::{LongitudinalLobe, longitudinal_variance};
pub use params::HairParams;
