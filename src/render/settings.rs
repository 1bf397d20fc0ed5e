//! What a render is asked to do: image size, samples, seed, threads, crop window, paths.

use super::film::PixelFilter;
use super::integrator::PathSettings;
use crate::error::{Result, invalid_arg};

/// Settings of one render. The image depends only on these and the scene: never on the
/// thread count or the order tiles finish in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    pub seed: u64,
    /// Worker threads; None = all cores.
    pub threads: Option<usize>,
    /// Pixels [x0, x1) x [y0, y1) of the full frame to render; None = all. A crop renders
    /// exactly the pixels the full frame has there, so pieces assemble bit for bit.
    pub crop: Option<[u32; 4]>,
    /// Where in and around its pixel each sample lands (validated when built).
    pub filter: PixelFilter,
    pub path: PathSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 640,
            height: 480,
            spp: 16,
            seed: 0,
            threads: None,
            crop: None,
            filter: PixelFilter::default(),
            path: PathSettings::default(),
        }
    }
}

/// Largest accepted image side, so that a typo cannot ask for terabytes.
pub(crate) const MAX_SIDE: u32 = 1 << 15;

impl RenderSettings {
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if v == 0 || v > MAX_SIDE {
                return Err(invalid_arg!("{name} = {v}: must be in [1, {MAX_SIDE}]"));
            }
        }
        if self.spp == 0 {
            return Err(invalid_arg!("spp = 0: must be at least 1"));
        }
        if self.threads == Some(0) {
            return Err(invalid_arg!(
                "threads = 0: must be at least 1 (or unset for all cores)"
            ));
        }
        if let Some([x0, y0, x1, y1]) = self.crop {
            if !(x0 < x1 && y0 < y1 && x1 <= self.width && y1 <= self.height) {
                return Err(invalid_arg!(
                    "crop = [{x0}, {y0}, {x1}, {y1}]: must satisfy x0 < x1 <= width ({}) and y0 < y1 <= height ({})",
                    self.width,
                    self.height
                ));
            }
        }
        self.path.validate()
    }

    /// The crop window, or the full frame.
    pub fn window(&self) -> [u32; 4] {
        self.crop.unwrap_or([0, 0, self.width, self.height])
    }
}
