//! The hair BSDFs on numpy arrays, Chiang's and Huang's: one call evaluates or samples n
//! inputs, every input checked first as the C ABI checks it (`hairtrace::bsdf::inputs`),
//! the GIL released while the batch runs. The absorption conversions take arrays too.

use hairtrace::bsdf::{self, inputs};
use hairtrace::glam::{Vec2, Vec3};
use hairtrace::{BsdfSample, HairBsdf, HairParams, HuangBsdf, HuangField, HuangParams, HuangPoint};
use numpy::ndarray::{Array, IxDyn};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays::{Floats, same_rows, show_shape};
use crate::errors::IntoPy;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyHairBsdf>()?;
    m.add_class::<PyHuangBsdf>()?;
    m.add_function(wrap_pyfunction!(sigma_a_from_melanin, m)?)?;
    m.add_function(wrap_pyfunction!(sigma_a_from_color, m)?)?;
    m.add_function(wrap_pyfunction!(sigma_a_preset, m)?)?;
    let presets: Vec<&str> = bsdf::SIGMA_A_PRESETS.iter().map(|(n, _)| *n).collect();
    m.add("SIGMA_A_PRESETS", presets)?;
    Ok(())
}

/// The Chiang 2016 hair BSDF for one parameter set (docs/conventions.md: the fibre's
/// frame, x along the fibre, h across it). Parameters left out take the default brown
/// hair's; each is checked against its range (ValueError), never clamped.
#[pyclass(name = "HairBsdf", module = "hairtrace", frozen)]
pub struct PyHairBsdf {
    bsdf: HairBsdf,
}

/// f and pdf, as `eval` returns them.
type Pair<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<f32>>);
/// wi, f and pdf, as `sample` returns them.
type Triple<'py> = (
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray1<f32>>,
);

#[pymethods]
impl PyHairBsdf {
    #[new]
    #[pyo3(signature = (sigma_a=None, eta=None, beta_m=None, beta_n=None, alpha=None))]
    fn new(
        sigma_a: Option<[f32; 3]>,
        eta: Option<f32>,
        beta_m: Option<f32>,
        beta_n: Option<f32>,
        alpha: Option<f32>,
    ) -> PyResult<Self> {
        let d = HairParams::default();
        let params = HairParams {
            sigma_a: sigma_a.unwrap_or(d.sigma_a),
            eta: eta.unwrap_or(d.eta),
            beta_m: beta_m.unwrap_or(d.beta_m),
            beta_n: beta_n.unwrap_or(d.beta_n),
            alpha: alpha.unwrap_or(d.alpha),
        };
        Ok(PyHairBsdf {
            bsdf: HairBsdf::new(&params).py()?,
        })
    }

    #[getter]
    fn sigma_a(&self) -> [f32; 3] {
        self.bsdf.params().sigma_a
    }
    #[getter]
    fn eta(&self) -> f32 {
        self.bsdf.params().eta
    }
    #[getter]
    fn beta_m(&self) -> f32 {
        self.bsdf.params().beta_m
    }
    #[getter]
    fn beta_n(&self) -> f32 {
        self.bsdf.params().beta_n
    }
    #[getter]
    fn alpha(&self) -> f32 {
        self.bsdf.params().alpha
    }

    fn __repr__(&self) -> String {
        let p = self.bsdf.params();
        format!(
            "HairBsdf(sigma_a={:?}, eta={}, beta_m={}, beta_n={}, alpha={})",
            p.sigma_a, p.eta, p.beta_m, p.beta_n, p.alpha
        )
    }

    /// f (n, 3), with its 1/|wi.z|, and pdf (n,) for h (n,) in [-1, 1] and unit
    /// directions wo, wi (n, 3) in the fibre's frame.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Pair<'py>> {
        let [h, wo, wi] = vertex_rows(h, wo, (wi, "wi"))?;
        let n = same_rows(&[&h, &wo, &wi])?;
        let (h, wo, wi) = (h.values(), wo.vec3s(), wi.vec3s());
        let (f, pdf) = py
            .detach(|| -> hairtrace::Result<_> {
                check_each(h, wo, |i| inputs::check_dir(Vec3::from_array(wi[i]), "wi"))?;
                let (mut f, mut pdf) = (vec![0.0f32; 3 * n], vec![0.0f32; n]);
                self.bsdf
                    .eval_batch(h, wo, wi, bytemuck::cast_slice_mut(&mut f), &mut pdf)?;
                Ok((f, pdf))
            })
            .py()?;
        Ok((rows3(py, f)?, pdf.into_pyarray(py)))
    }

    /// The density (n,) of `sample` at wi: `eval`'s pdf alone.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        Ok(self.eval(py, h, wo, wi)?.1)
    }

    /// Directions wi (n, 3) drawn for h (n,) and wo (n, 3) from uniform numbers u (n, 3)
    /// in [0, 1), with f (n, 3) and pdf (n,) there; pdf 0 (wi and f zero) where the
    /// density is zero. The path weight is f |wi.z| / pdf.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Triple<'py>> {
        let [h, wo, u] = vertex_rows(h, wo, (u, "u"))?;
        let n = same_rows(&[&h, &wo, &u])?;
        let (h, wo, u) = (h.values(), wo.vec3s(), u.vec3s());
        let (wi, f, pdf) = py
            .detach(|| -> hairtrace::Result<_> {
                check_each(h, wo, |i| inputs::check_u(u[i], "u"))?;
                samples(n, |i| {
                    Ok(self.bsdf.sample(h[i], Vec3::from_array(wo[i]), u[i]))
                })
            })
            .py()?;
        Ok((rows3(py, wi)?, rows3(py, f)?, pdf.into_pyarray(py)))
    }
}

/// The Huang 2022 model of elliptical fibres for one parameter set (docs/conventions.md,
/// section 4b), in the frame and units of `HairBsdf`. Parameters left out take the
/// defaults of `HuangParams` (brown, round); each is checked (ValueError), never clamped.
#[pyclass(name = "HuangBsdf", module = "hairtrace", frozen)]
pub struct PyHuangBsdf {
    bsdf: HuangBsdf,
}

#[pymethods]
impl PyHuangBsdf {
    #[new]
    #[pyo3(signature = (sigma_a=None, eta=None, roughness=None, aspect=None, alpha=None))]
    fn new(
        sigma_a: Option<[f32; 3]>,
        eta: Option<f32>,
        roughness: Option<f32>,
        aspect: Option<f32>,
        alpha: Option<f32>,
    ) -> PyResult<Self> {
        let d = HuangParams::default();
        let params = HuangParams {
            sigma_a: sigma_a.unwrap_or(d.sigma_a),
            eta: eta.unwrap_or(d.eta),
            roughness: roughness.unwrap_or(d.roughness),
            aspect: aspect.unwrap_or(d.aspect),
            alpha: alpha.unwrap_or(d.alpha),
        };
        Ok(PyHuangBsdf {
            bsdf: HuangBsdf::new(&params).py()?,
        })
    }

    #[getter]
    fn sigma_a(&self) -> [f32; 3] {
        self.bsdf.params().sigma_a
    }
    #[getter]
    fn eta(&self) -> f32 {
        self.bsdf.params().eta
    }
    #[getter]
    fn roughness(&self) -> f32 {
        self.bsdf.params().roughness
    }
    #[getter]
    fn aspect(&self) -> f32 {
        self.bsdf.params().aspect
    }
    #[getter]
    fn alpha(&self) -> f32 {
        self.bsdf.params().alpha
    }

    fn __repr__(&self) -> String {
        let p = self.bsdf.params();
        format!(
            "HuangBsdf(sigma_a={:?}, eta={}, roughness={}, aspect={}, alpha={})",
            p.sigma_a, p.eta, p.roughness, p.aspect, p.alpha
        )
    }

    /// f (n, 3), with its 1/|wi.z|, and pdf (n,) for h (n,) and unit wo, wi (n, 3), the
    /// section's major axis `major` (n, 3) in the fibre's frame (across the fibre; None:
    /// +y), `jitter` (n, 2) in [0, 1) (None: 0.5) and `field` "near", "far" or "far_lit".
    #[pyo3(signature = (h, wo, wi, major=None, jitter=None, field="near"))]
    #[allow(clippy::too_many_arguments)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        major: Option<&Bound<'py, PyAny>>,
        jitter: Option<&Bound<'py, PyAny>>,
        field: &str,
    ) -> PyResult<Pair<'py>> {
        let [h, wo, wi] = vertex_rows(h, wo, (wi, "wi"))?;
        let args = SectionArgs::read(major, jitter, field)?;
        let n = same_rows(&args.with(&[&h, &wo, &wi]))?;
        let (h, wo, wi, section) = (h.values(), wo.vec3s(), wi.vec3s(), args.section());
        let (f, pdf) = py
            .detach(|| -> hairtrace::Result<_> {
                check_each(h, wo, |i| {
                    inputs::check_dir(Vec3::from_array(wi[i]), "wi")?;
                    section.at(i)
                })?;
                let (mut f, mut pdf) = (vec![0.0f32; 3 * n], vec![0.0f32; n]);
                for i in 0..n {
                    let e = section.point(&self.bsdf, h[i], wo[i], i)?;
                    let e = e.eval(Vec3::from_array(wi[i]));
                    f[3 * i..3 * i + 3].copy_from_slice(&e.f.to_array());
                    pdf[i] = e.pdf;
                }
                Ok((f, pdf))
            })
            .py()?;
        Ok((rows3(py, f)?, pdf.into_pyarray(py)))
    }

    /// The density (n,) of `sample` at wi: `eval`'s pdf alone.
    #[pyo3(signature = (h, wo, wi, major=None, jitter=None, field="near"))]
    #[allow(clippy::too_many_arguments)]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        major: Option<&Bound<'py, PyAny>>,
        jitter: Option<&Bound<'py, PyAny>>,
        field: &str,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        Ok(self.eval(py, h, wo, wi, major, jitter, field)?.1)
    }

    /// Directions wi (n, 3) drawn from uniform numbers u (n, 3) in [0, 1), with f (n, 3)
    /// and pdf (n,) there, the other arguments as `eval`'s; pdf 0 (wi and f zero) where
    /// there is no direction (total internal reflection on the way out included).
    #[pyo3(signature = (h, wo, u, major=None, jitter=None, field="near"))]
    #[allow(clippy::too_many_arguments)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        h: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
        major: Option<&Bound<'py, PyAny>>,
        jitter: Option<&Bound<'py, PyAny>>,
        field: &str,
    ) -> PyResult<Triple<'py>> {
        let [h, wo, u] = vertex_rows(h, wo, (u, "u"))?;
        let args = SectionArgs::read(major, jitter, field)?;
        let n = same_rows(&args.with(&[&h, &wo, &u]))?;
        let (h, wo, u, section) = (h.values(), wo.vec3s(), u.vec3s(), args.section());
        let (wi, f, pdf) = py
            .detach(|| -> hairtrace::Result<_> {
                check_each(h, wo, |i| {
                    inputs::check_u(u[i], "u")?;
                    section.at(i)
                })?;
                samples(n, |i| {
                    Ok(section.point(&self.bsdf, h[i], wo[i], i)?.sample(u[i]))
                })
            })
            .py()?;
        Ok((rows3(py, wi)?, rows3(py, f)?, pdf.into_pyarray(py)))
    }
}

/// What a Huang point takes besides (h, wo), as given: the major axis (n, 3) and the
/// jitter (n, 2), each left to its default where None, and the field.
struct SectionArgs<'py> {
    major: Option<Floats<'py>>,
    jitter: Option<Floats<'py>>,
    field: HuangField,
}

impl<'py> SectionArgs<'py> {
    fn read(
        major: Option<&Bound<'py, PyAny>>,
        jitter: Option<&Bound<'py, PyAny>>,
        field: &str,
    ) -> PyResult<Self> {
        let field: HuangField = match field {
            "near" => HuangBsdf::near,
            "far" => HuangBsdf::far,
            "far_lit" => HuangBsdf::far_lit,
            other => {
                return Err(PyValueError::new_err(format!(
                    "field = {other:?}: must be \"near\", \"far\" or \"far_lit\""
                )));
            }
        };
        Ok(SectionArgs {
            major: major.map(|m| Floats::rows(m, "major", 3)).transpose()?,
            jitter: jitter.map(|j| Floats::rows(j, "jitter", 2)).transpose()?,
            field,
        })
    }

    /// `arrays` and the arrays given here, whose rows must agree.
    fn with<'a>(&'a self, arrays: &[&'a Floats<'py>]) -> Vec<&'a Floats<'py>> {
        let own = self.major.iter().chain(&self.jitter);
        arrays.iter().copied().chain(own).collect()
    }

    /// The values, for the batch that runs without the GIL.
    fn section(&self) -> Section<'_> {
        Section {
            major: self.major.as_ref().map(Floats::vec3s),
            jitter: self.jitter.as_ref().map(Floats::values),
            field: self.field,
        }
    }
}

/// [`SectionArgs`]' values.
struct Section<'a> {
    major: Option<&'a [[f32; 3]]>,
    jitter: Option<&'a [f32]>,
    field: HuangField,
}

/// The jitter of an element left without one: the middle of [0, 1).
const DEFAULT_JITTER: [f32; 2] = [0.5; 2];

impl Section<'_> {
    /// Element i's major axis as a (y, z) direction and its jitter, checked.
    fn at(&self, i: usize) -> hairtrace::Result<(Vec2, [f32; 2])> {
        let major = self.major.map_or(Vec3::Y, |m| Vec3::from_array(m[i]));
        let jitter = self
            .jitter
            .map_or(DEFAULT_JITTER, |j| [j[2 * i], j[2 * i + 1]]);
        Ok((
            inputs::check_major(major, major, "major")?,
            inputs::check_u(jitter, "jitter")?,
        ))
    }

    /// The point of element i, whose inputs `at` has passed.
    fn point(
        &self,
        bsdf: &HuangBsdf,
        h: f32,
        wo: [f32; 3],
        i: usize,
    ) -> hairtrace::Result<HuangPoint> {
        let (major, jitter) = self.at(i)?;
        let wo = Vec3::from_array(wo);
        Ok((self.field)(bsdf, h, wo, major, jitter))
    }
}

/// h (n,), wo (n, 3) and another (n, 3) array of a call, read and shape-checked.
fn vertex_rows<'py>(
    h: &Bound<'py, PyAny>,
    wo: &Bound<'py, PyAny>,
    (other, name): (&Bound<'py, PyAny>, &'static str),
) -> PyResult<[Floats<'py>; 3]> {
    Ok([
        Floats::rows(h, "h", 0)?,
        Floats::rows(wo, "wo", 3)?,
        Floats::rows(other, name, 3)?,
    ])
}

/// wi (3n), f (3n) and pdf (n) of n draws, zeros where `draw(i)` gives no direction.
fn samples(
    n: usize,
    draw: impl Fn(usize) -> hairtrace::Result<Option<BsdfSample>>,
) -> hairtrace::Result<(Vec<f32>, Vec<f32>, Vec<f32>)> {
    let (mut wi, mut f, mut pdf) = (vec![0.0f32; 3 * n], vec![0.0f32; 3 * n], vec![0.0f32; n]);
    for i in 0..n {
        if let Some(s) = draw(i)? {
            wi[3 * i..3 * i + 3].copy_from_slice(&s.wi.to_array());
            f[3 * i..3 * i + 3].copy_from_slice(&s.f.to_array());
            pdf[i] = s.pdf;
        }
    }
    Ok((wi, f, pdf))
}

/// Checks each element's h and wo, then the rest of it with `rest(i)`, as the C ABI
/// checks a call's arguments; an error names the element.
fn check_each<T>(
    h: &[f32],
    wo: &[[f32; 3]],
    rest: impl Fn(usize) -> hairtrace::Result<T>,
) -> hairtrace::Result<()> {
    for (i, (&h, &wo)) in h.iter().zip(wo).enumerate() {
        inputs::check_h(h)
            .and_then(|_| inputs::check_dir(Vec3::from_array(wo), "wo"))
            .and_then(|_| rest(i))
            .map_err(|e| e.context(format!("element {i}")))?;
    }
    Ok(())
}

/// `values` (3n floats) as an (n, 3) array, without a copy.
fn rows3(py: Python<'_>, values: Vec<f32>) -> PyResult<Bound<'_, PyArray2<f32>>> {
    let n = values.len() / 3;
    let array = Array::from_shape_vec((n, 3), values).expect("3n values");
    Ok(array.into_pyarray(py))
}

/// `shape` + (3,), filled by `each` from the i-th input: the conversions' arrays.
fn per_element<'py>(
    py: Python<'py>,
    shape: &[usize],
    count: usize,
    each: impl Fn(usize) -> hairtrace::Result<[f32; 3]>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let mut out = Vec::with_capacity(3 * count);
    for i in 0..count {
        let v = each(i).map_err(|e| {
            if count > 1 {
                e.context(format!("element {i}"))
            } else {
                e
            }
        });
        out.extend(v.py()?);
    }
    let dims: Vec<usize> = shape.iter().copied().chain([3]).collect();
    let array = Array::from_shape_vec(IxDyn(&dims), out).expect("3 values per element");
    Ok(array.into_pyarray(py))
}

/// sigma_a (..., 3) from eumelanin and pheomelanin concentrations (each >= 0; about 8 is
/// jet black, 1.3 brown, 0.3 blonde; pheomelanin adds red), numbers or arrays of one
/// shape (or one of them a number).
#[pyfunction]
#[pyo3(signature = (eumelanin, pheomelanin=None))]
fn sigma_a_from_melanin<'py>(
    py: Python<'py>,
    eumelanin: &Bound<'py, PyAny>,
    pheomelanin: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let eu = Floats::new(eumelanin, "eumelanin")?;
    let zero = [0.0f32];
    let pheo = pheomelanin
        .map(|p| Floats::new(p, "pheomelanin"))
        .transpose()?;
    let (e, p) = (eu.values(), pheo.as_ref().map_or(&zero[..], Floats::values));
    let shape = match (eu.shape(), pheo.as_ref().map(Floats::shape)) {
        (s, None) => s.to_vec(),
        (s, Some(t)) if s == t || p.len() == 1 => s.to_vec(),
        (_, Some(t)) if e.len() == 1 => t.to_vec(),
        (s, Some(t)) => {
            return Err(PyValueError::new_err(format!(
                "eumelanin {} and pheomelanin {}: must have one shape, or one be a number",
                show_shape(s),
                show_shape(t)
            )));
        }
    };
    let count = e.len().max(p.len());
    let pick = |v: &[f32], i: usize| if v.len() == 1 { v[0] } else { v[i] };
    per_element(py, &shape, count, |i| {
        bsdf::sigma_a_from_melanin(pick(e, i), pick(p, i))
    })
}

/// sigma_a (..., 3) that makes a fibre of azimuthal roughness beta_n look like the
/// reflectance `color` (..., 3), each channel in (0, 1] (Chiang et al. 2016's fit).
#[pyfunction]
#[pyo3(signature = (color, beta_n=None))]
fn sigma_a_from_color<'py>(
    py: Python<'py>,
    color: &Bound<'py, PyAny>,
    beta_n: Option<f32>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let color = Floats::new(color, "color")?;
    let shape = color.shape();
    if shape.last() != Some(&3) {
        return Err(PyValueError::new_err(format!(
            "color: shape {}: must be (..., 3)",
            show_shape(shape)
        )));
    }
    let beta_n = beta_n.unwrap_or(HairParams::default().beta_n);
    let rgb = color.vec3s();
    per_element(py, &shape[..shape.len() - 1], rgb.len(), |i| {
        bsdf::sigma_a_from_color(rgb[i], beta_n)
    })
}

/// The sigma_a (3,) of a named hair colour (`SIGMA_A_PRESETS`).
#[pyfunction]
fn sigma_a_preset<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyArray1<f32>>> {
    Ok(bsdf::sigma_a_preset(name).py()?.to_vec().into_pyarray(py))
}
