//! The scene layer's tests that need more than one module: curves in Embree against
//! analytic tubes, leaving a fibre, a large groom's memory, and the lights.

mod curves_geometry;
mod large_groom;
mod lights;
mod rehit;
mod silhouette;
mod touching;
