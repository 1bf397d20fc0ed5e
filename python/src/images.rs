//! Images through the library's OpenImageIO: EXR, PNG, JPEG, TIFF, as the command line
//! writes them (PNG, JPEG and TIFF sRGB-encoded and clamped; EXR float).

use std::path::PathBuf;

use numpy::ndarray::{Array, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays::{Floats, show_shape};
use crate::errors::IntoPy;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    Ok(())
}

/// Writes linear pixels (h, w) or (h, w, channels), the format by the extension. NaN or
/// infinite values are refused (ValueError).
#[pyfunction]
fn write_image(py: Python<'_>, path: PathBuf, pixels: &Bound<'_, PyAny>) -> PyResult<()> {
    let p = Floats::new(pixels, "pixels")?;
    let (h, w, c) = match *p.shape() {
        [h, w] => (h, w, 1),
        [h, w, c] => (h, w, c),
        _ => {
            return Err(PyValueError::new_err(format!(
                "pixels: shape {}: must be (h, w) or (h, w, channels)",
                show_shape(p.shape())
            )));
        }
    };
    let values = p.values();
    py.detach(|| hairtrace::write_image(&path, w, h, c, values, &Default::default()))
        .py()
}

/// The pixels (h, w, channels) of an image file, as linear float32.
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArrayDyn<f32>>> {
    let image = py.detach(|| hairtrace::read_image(&path)).py()?;
    let dims = [image.height, image.width, image.channels];
    let array = Array::from_shape_vec(IxDyn(&dims), image.pixels).expect("h x w x c values");
    Ok(array.into_pyarray(py))
}
