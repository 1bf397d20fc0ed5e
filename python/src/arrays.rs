//! Arrays from Python: anything numpy turns into float32 (lists, float64, ints,
//! non-contiguous views), shape-checked, and borrowed without a copy where it already is
//! contiguous float32. A value that numpy cannot convert is a `TypeError` naming the
//! argument.

use numpy::{AllowTypeChange, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// A float32 array read from an argument.
pub struct Floats<'py> {
    array: PyArrayLikeDyn<'py, f32, AllowTypeChange>,
    /// A C-ordered copy, where the array is not contiguous.
    copy: Option<Vec<f32>>,
    pub name: String,
}

impl<'py> Floats<'py> {
    /// `obj` as float32; `name` names it in errors.
    pub fn new(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Self> {
        let array: PyArrayLikeDyn<'py, f32, AllowTypeChange> = obj.extract().map_err(|e| {
            PyTypeError::new_err(format!("{name}: cannot be read as float32 numbers: {e}"))
        })?;
        // Fortran order is contiguous too, but not in the order the rows are read.
        let copy = match array.is_c_contiguous() {
            true => None,
            false => Some(array.as_array().iter().copied().collect()),
        };
        Ok(Floats {
            array,
            copy,
            name: name.into(),
        })
    }

    /// `obj` as an array of shape `(n,)` (`width` 0) or `(n, width)`.
    pub fn rows(obj: &Bound<'py, PyAny>, name: &str, width: usize) -> PyResult<Self> {
        let f = Self::new(obj, name)?;
        let shape = f.shape();
        let fits = match width {
            0 => shape.len() == 1,
            w => shape.len() == 2 && shape[1] == w,
        };
        if !fits {
            let want = if width == 0 {
                "(n,)".to_string()
            } else {
                format!("(n, {width})")
            };
            return Err(PyValueError::new_err(format!(
                "{name}: shape {}: must be {want}",
                show_shape(shape)
            )));
        }
        Ok(f)
    }

    pub fn shape(&self) -> &[usize] {
        self.array.shape()
    }

    /// Rows of an `(n, width)` or `(n,)` array: its first axis.
    pub fn len(&self) -> usize {
        self.shape().first().copied().unwrap_or(1)
    }

    /// The values in C order.
    pub fn values(&self) -> &[f32] {
        match &self.copy {
            Some(v) => v,
            None => self.array.as_slice().expect("C-contiguous, checked in new"),
        }
    }

    /// The rows of an `(n, 3)` array.
    pub fn vec3s(&self) -> &[[f32; 3]] {
        bytemuck::cast_slice(self.values())
    }
}

/// `(5, 3)`, as numpy writes a shape.
pub fn show_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        s => format!(
            "({})",
            s.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Checks that every array has `n` rows, naming the first that does not.
pub fn same_rows(arrays: &[&Floats]) -> PyResult<usize> {
    let n = arrays[0].len();
    match arrays.iter().find(|a| a.len() != n) {
        None => Ok(n),
        Some(a) => Err(PyValueError::new_err(format!(
            "{} has {} rows and {} has {n}: they must agree",
            a.name,
            a.len(),
            arrays[0].name
        ))),
    }
}
