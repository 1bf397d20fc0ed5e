//! Everything between a groom and an image, end to end: grooms and .hair files, curves
//! in Embree against analytic tubes, leaving fibres, lights, camera and film, scene files,
//! image files, renders, and the layering of the sources (the command line is tested in
//! its own package, cli/tests). One test binary, so that the crate (with Embree and
//! OpenImageIO) is linked once.

mod animation;
mod architecture;
mod description;
mod farm;
mod groom;
mod hair_file;
mod image_io;
mod pbrt;
mod stages;
mod usd;
mod usd_crate;
mod usd_motion;
mod usd_normals;
