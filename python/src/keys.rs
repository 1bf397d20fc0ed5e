//! Materials, lights, the camera and grooms by keyword: the keywords are the scene file's
//! own keys (`hairtrace::description`), so they are turned into a TOML table and read by
//! the library's scene reader, which checks them and names what is wrong exactly as it
//! does for a file. Render settings by keyword go through the settings schema as text
//! (`RenderSettings::set`), as the TOML `[render]` table and the command line's do.

use std::path::Path;

use hairtrace::SceneDescription;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

use crate::errors::IntoPy;

/// A Python value as TOML: bools, integers, floats (numpy's too), strings and paths,
/// dicts (a groom's `params`) and sequences or arrays of these.
fn value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    let py = v.py();
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(toml::Value::Table(table(d)?));
    }
    let os = py.import("os")?;
    if v.is_instance(&os.getattr("PathLike")?)? {
        return Ok(toml::Value::String(
            os.call_method1("fspath", (v,))?.extract()?,
        ));
    }
    // numpy scalars and arrays become Python numbers and lists.
    if v.hasattr("tolist")? {
        let plain = v.call_method0("tolist")?;
        if !plain.is(v) {
            return value(key, &plain);
        }
    }
    if let Ok(items) = v.try_iter() {
        let items = items
            .map(|item| value(key, &item?))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    Err(PyTypeError::new_err(format!(
        "{key}: a {} cannot be a scene key's value (numbers, strings, paths, bools, dicts \
         and sequences of them)",
        v.get_type().name()?
    )))
}

/// Keyword arguments as a TOML table.
pub fn table(kwargs: &Bound<'_, PyDict>) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in kwargs.iter() {
        let k: String = k.extract()?;
        let v = value(&k, &v)?;
        t.insert(k, v);
    }
    Ok(t)
}

/// The description of a scene file holding `document` alone, its relative paths taken
/// from the working folder; `what` names the call in errors.
pub fn read(document: toml::Table, what: &str) -> PyResult<SceneDescription> {
    let text =
        toml::to_string(&document).map_err(|e| PyTypeError::new_err(format!("{what}: {e}")))?;
    SceneDescription::from_toml(&text, Path::new(""), what).py()
}

/// `{outer: inner}` as a table.
pub fn nest(outer: &str, inner: toml::Value) -> toml::Table {
    toml::Table::from_iter([(outer.to_string(), inner)])
}

/// A render setting's value as the schema's text: numbers as written, names, `none` for
/// None, and a sequence (a crop) as comma-separated numbers.
pub fn setting_text(key: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    if v.is_none() {
        return Ok("none".into());
    }
    if v.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{key}: a bool is no render setting's value"
        )));
    }
    match value(key, v)? {
        toml::Value::String(s) => Ok(s),
        toml::Value::Integer(i) => Ok(i.to_string()),
        toml::Value::Float(f) => Ok(f.to_string()),
        toml::Value::Array(items) => items
            .iter()
            .map(|i| match i {
                toml::Value::Integer(i) => Ok(i.to_string()),
                toml::Value::Float(f) => Ok(f.to_string()),
                _ => Err(PyTypeError::new_err(format!(
                    "{key}: a sequence of numbers, or a number, a name or None"
                ))),
            })
            .collect::<PyResult<Vec<_>>>()
            .map(|v| v.join(",")),
        _ => Err(PyTypeError::new_err(format!(
            "{key}: must be a number, a name, a sequence of numbers or None"
        ))),
    }
}
