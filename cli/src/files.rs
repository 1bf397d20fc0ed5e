//! Files the command line writes, each whole or not at all: written under a temporary name
//! beside the path, then renamed, so that a reader never sees half a file and a job killed
//! part way leaves none where a finished one was.

use std::path::Path;

use hairtrace::{Error, Result};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;

/// Writes `contents` to `path`.
pub fn write_file(path: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    let io = |e: std::io::Error| Error::io(path, e);
    let mut file = hairtrace::image::temporary_beside(path).map_err(io)?;
    std::io::Write::write_all(&mut file, contents.as_ref()).map_err(io)?;
    file.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Writes 8-bit RGB pixels, `width` x `height`, row by row, to `path` as a PNG.
pub fn write_png(path: &Path, rgb: &[u8], (width, height): (u32, u32)) -> Result<()> {
    let mut png = Vec::new();
    PngEncoder::new(&mut png)
        .write_image(rgb, width, height, image::ColorType::Rgb8)
        .map_err(|e| Error::image(path, e))?;
    write_file(path, png)
}
