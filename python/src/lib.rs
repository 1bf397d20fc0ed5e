//! The Python package's native module, `hairtrace._native`: a thin shell over the
//! library's public API (docs/python.md). The BSDF on numpy arrays (`bsdf.rs`), scenes
//! built and edited by the scene file's own keys (`scene.rs`, `keys.rs`), with strands
//! and meshes at several time steps (`steps.rs`), renders that release the GIL and answer
//! Ctrl-C (`watch.rs`), images (`images.rs`). The Python side (`hairtrace/__init__.py`)
//! adds the image type, tqdm and the stubs.

mod arrays;
mod bsdf;
mod errors;
mod images;
mod keys;
mod scene;
mod steps;
mod watch;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", hairtrace::VERSION)?;
    bsdf::register(m)?;
    scene::register(m)?;
    images::register(m)?;
    Ok(())
}
