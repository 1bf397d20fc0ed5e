//! A camera sample traced as several rays spread over its pixel (`camera_rays`).
//!
//! Where strands far under a pixel wide show a bright sky between them, most of a pixel's
//! noise is which of the two a camera ray meets: stratifying the sample positions cannot
//! help when each pixel holds dozens of strands. A sample of k rays adds what the escaping
//! ones see exactly and goes on with one path from a ray that hit, picked at random and
//! weighted by how many hit (`World::camera_sample`): unbiased, since each ray is uniform
//! over the pixel and the picked path's expectation is the mean over the rays that hit.
//! The extra rays are occlusion queries from the eye, cheaper than the paths they stand
//! in for; where the strands cover the pixel, or the background is dim, they only cost.
//! So it is a setting, 1 by default (docs/measurements.md, "Camera rays").

/// The most rays a camera sample may be traced as.
pub const MAX_CAMERA_RAYS: usize = 16;

/// Where the `count` rays of a camera sample go in its pixel, as shifts of the sample's
/// own position (wrapped into the pixel): a Hammersley set, (j / count, the base-2
/// radical inverse of j), whose points spread over the pixel as evenly as `count` points
/// can. Each shifted position is as uniform over the pixel as the sample's own, so every
/// ray sees the pixel as a single camera ray would.
pub fn shifts(count: u32) -> [[f32; 2]; MAX_CAMERA_RAYS] {
    let n = count.max(1) as f32;
    std::array::from_fn(|j| {
        let inverse = (j as u32).reverse_bits() as f32 * (1.0 / 4_294_967_296.0);
        [j as f32 / n, inverse]
    })
}
