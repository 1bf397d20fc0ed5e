//! Arrays at several time steps from Python, for strands and meshes that move over the
//! shutter: one `(n, width)` array (one step), a `(K, n, width)` array, or a list of K
//! `(n, width)` arrays, each step as many rows as the first; and triangles as integers.

use numpy::{
    AllowTypeChange, PyArrayDescrMethods, PyArrayLikeDyn, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};

use crate::arrays::{Floats, show_shape};

/// The rows of `obj` at each of its time steps, `W` floats a row; `name` names it in
/// errors, with the step where one is wrong. How many steps Embree takes is the library's
/// check.
pub fn time_steps<const W: usize>(
    obj: &Bound<'_, PyAny>,
    name: &'static str,
) -> PyResult<Vec<Vec<[f32; W]>>>
where
    [f32; W]: bytemuck::Pod,
{
    let form = format!("({name} is (n, {W}), (K, n, {W}) or a list of K (n, {W}) arrays)");
    let steps = if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        (obj.try_iter()?.enumerate())
            .map(|(k, item)| {
                let f = real(&item?, &format!("{name}[{k}]"))?;
                match f.shape() {
                    [_, w] if *w == W => Ok(bytemuck::cast_slice(f.values()).to_vec()),
                    s => Err(PyValueError::new_err(format!(
                        "{name}[{k}]: shape {}: must be (n, {W}) {form}",
                        show_shape(s)
                    ))),
                }
            })
            .collect::<PyResult<Vec<Vec<[f32; W]>>>>()?
    } else {
        let f = real(obj, name)?;
        let rows: &[[f32; W]] = bytemuck::cast_slice(f.values());
        match *f.shape() {
            [_, w] if w == W => vec![rows.to_vec()],
            [_, n, w] if w == W && n > 0 => rows.chunks(n).map(<[_]>::to_vec).collect(),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "{name}: shape {}: must be (n, {W}) or (K, n, {W}) {form}",
                    show_shape(f.shape())
                )));
            }
        }
    };
    let Some(n) = steps.first().map(Vec::len) else {
        return Err(PyValueError::new_err(format!(
            "{name}: no time step: give at least one {form}"
        )));
    };
    if let Some(k) = steps.iter().position(|s| s.len() != n) {
        return Err(PyValueError::new_err(format!(
            "{name}[{k}] has {} rows and {name}[0] has {n}: every time step holds the same \
             points",
            steps[k].len()
        )));
    }
    Ok(steps)
}

/// `obj` as float32, refused unless its numbers are real (floats, integers): numpy would
/// drop a complex array's imaginary parts.
fn real<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Floats<'py>> {
    check_kind(obj, name, b"fiub", "real numbers")?;
    Floats::new(obj, name)
}

/// Refuses a numpy array whose dtype kind is not one of `kinds`.
fn check_kind(obj: &Bound<'_, PyAny>, name: &str, kinds: &[u8], what: &str) -> PyResult<()> {
    match obj.cast::<PyUntypedArray>() {
        Ok(a) if !kinds.contains(&a.dtype().kind()) => Err(PyTypeError::new_err(format!(
            "{name}: dtype {}: must be {what}",
            a.dtype()
        ))),
        _ => Ok(()),
    }
}

/// Triangles as a `(t, 3)` array of vertex indices: integers (not floats, which would be
/// truncated), each >= 0 and < 2^32.
pub fn triangles(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    check_kind(obj, "triangles", b"iu", "integers")?;
    let t: PyArrayLikeDyn<i64, AllowTypeChange> = obj
        .extract()
        .map_err(|e| PyTypeError::new_err(format!("triangles: must be integers: {e}")))?;
    if !matches!(t.shape(), [_, 3]) {
        return Err(PyValueError::new_err(format!(
            "triangles: shape {}: must be (t, 3)",
            show_shape(t.shape())
        )));
    }
    let index = |v: i64| {
        u32::try_from(v).map_err(|_| {
            PyValueError::new_err(format!("triangles: {v}: must be in [0, {}]", u32::MAX))
        })
    };
    let values: Vec<u32> = t
        .as_array()
        .iter()
        .map(|&v| index(v))
        .collect::<PyResult<_>>()?;
    Ok(bytemuck::cast_slice(&values).to_vec())
}
