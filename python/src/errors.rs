//! The library's errors as Python exceptions, each carrying the library's message: a bad
//! argument is a `ValueError`, a file that cannot be read an `OSError`, the rest (images,
//! Embree) a `RuntimeError`.

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};

pub fn py_err(e: hairtrace::Error) -> PyErr {
    match e {
        hairtrace::Error::InvalidArg(m) => PyValueError::new_err(m),
        hairtrace::Error::Io(m) => PyOSError::new_err(m),
        e => PyRuntimeError::new_err(e.to_string()),
    }
}

/// `Result::map_err(py_err)` as a method.
pub trait IntoPy<T> {
    fn py(self) -> pyo3::PyResult<T>;
}

impl<T> IntoPy<T> for hairtrace::Result<T> {
    fn py(self) -> pyo3::PyResult<T> {
        self.map_err(py_err)
    }
}
