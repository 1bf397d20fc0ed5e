//! `Scene`: the library's scene ([`hairtrace::Scene`]), edited by the scene file's keys
//! and rendered with settings by name. The library's scene decides when to build: an edit
//! of a material, the lights or the camera renders without a new build, and new geometry,
//! a setting that needs a build or a view its `auto` strands were not shaped for build
//! again.

use std::path::PathBuf;
use std::sync::Arc;

use hairtrace::description::{GroomSource, MeshDesc, MeshSource, demo};
use hairtrace::embree::SharedBuffer;
use hairtrace::incremental::ControlPoints;
use hairtrace::render::RenderStatus;
use hairtrace::scene::{Mesh, Strands};
use hairtrace::{Aovs, RenderOutput, RenderSettings, Scene, SceneDescription};
use numpy::ndarray::{Array, IxDyn};
use numpy::{
    AllowTypeChange, IntoPyArray, PyArrayDescrMethods, PyArrayDyn, PyArrayLike1, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList};

use crate::arrays::{Floats, same_rows};
use crate::errors::IntoPy;
use crate::keys::{self, nest};
use crate::steps::{self, time_steps};
use crate::watch::{self, Stop};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    let names: Vec<&str> = RenderSettings::schema().iter().map(|s| s.name).collect();
    m.add("SETTINGS", names)?;
    m.add("DEMOS", hairtrace::description::DEMOS.to_vec())?;
    Ok(())
}

/// The AOVs by the command line's names (`--aov albedo,depth,strand`).
const AOV_NAMES: [&str; 3] = ["albedo", "depth", "strand"];

/// A scene: from a file, a demo, or built up by keywords and numpy strands; rendered with
/// settings by name. See docs/python.md.
#[pyclass(name = "Scene", module = "hairtrace")]
pub struct PyScene {
    scene: Scene,
    /// What error messages call the scene: a file's path, "demo NAME" or "python".
    origin: String,
    notes: Vec<String>,
    /// Grooms and meshes added, for their names (`groom[i]`, `mesh[i]`).
    grooms: usize,
    meshes: usize,
}

/// What a render gives `hairtrace.Image`: rgb (h, w, 3), the AOVs asked for,
/// statistics, and whether it finished (False when the progress callback stopped it).
type Rendered<'py> = (
    Bound<'py, PyArrayDyn<f32>>,
    Bound<'py, PyDict>,
    Bound<'py, PyDict>,
    bool,
);

impl PyScene {
    /// The scene `desc` describes, on a device of its settings' threads and `isa`.
    fn with(desc: SceneDescription) -> PyResult<Self> {
        let device = Arc::new(desc.render.device().py()?);
        Ok(PyScene {
            scene: Scene::from_description(&desc, device).py()?,
            origin: desc.origin,
            notes: desc.notes,
            grooms: desc.grooms.len(),
            meshes: desc.meshes.len(),
        })
    }

    /// The one entry of `kind` ("groom", "mesh", "light") that `kwargs` describe.
    fn entry(
        kind: &str,
        kwargs: Option<&Bound<'_, PyDict>>,
        what: &str,
    ) -> PyResult<SceneDescription> {
        let table = kwargs.map(keys::table).transpose()?.unwrap_or_default();
        keys::read(nest(kind, toml::Value::Array(vec![table.into()])), what)
    }

    /// Settings with `kwargs` applied to the scene's, each by its name.
    fn settings_with(&self, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<RenderSettings> {
        let mut settings = self.scene.settings;
        for (k, v) in kwargs.into_iter().flat_map(|d| d.iter()) {
            let key: String = k.extract()?;
            settings.set(&key, &keys::setting_text(&key, &v)?).py()?;
        }
        Ok(settings)
    }

    /// Adds `groom` as the next `groom[i]`.
    fn add_groom_desc(&mut self, groom: &hairtrace::description::GroomDesc) -> PyResult<()> {
        let name = format!("groom[{}]", self.grooms);
        self.scene.add_groom(&name, groom).py()?;
        self.grooms += 1;
        Ok(())
    }
}

#[pymethods]
impl PyScene {
    /// An empty scene, to fill with `add_groom`, `add_strands`, `add_mesh`, `set_material`,
    /// `add_light` and `set_camera`.
    #[new]
    fn new() -> PyResult<Self> {
        Self::with(SceneDescription {
            origin: "python".into(),
            ..SceneDescription::default()
        })
    }

    /// A scene from any file the command line renders: a TOML scene, a pbrt-v4 scene, a
    /// `.hair` groom or a USD stage (a groom file as a quick look: default hair, lights and
    /// camera).
    /// `frame`: the frame of the shot every groom file is read at (the command line's
    /// `render --frame F`), over the shutter of the file's `[render]` settings.
    #[staticmethod]
    #[pyo3(signature = (path, frame=None))]
    fn load(path: PathBuf, frame: Option<f64>) -> PyResult<Self> {
        let mut desc = SceneDescription::load(&path).py()?;
        if let Some(f) = frame {
            desc.at_frame(f).py()?;
        }
        Self::with(desc)
    }

    /// A built-in demo: "furball", "furnace" or "scalp".
    #[staticmethod]
    #[pyo3(signature = (name="furball"))]
    fn demo(name: &str) -> PyResult<Self> {
        Self::with(demo(name).py()?)
    }

    /// Sets render settings by name (`spp=64, filter="box", crop=(0, 0, 32, 32)`,
    /// `noise_target=None`); the names, values and ranges are `hairtrace.SETTINGS`'s
    /// (docs/settings.md). Nothing is set unless every one is valid.
    #[pyo3(signature = (**settings))]
    fn set(&mut self, settings: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        self.scene.settings = self.settings_with(settings)?;
        Ok(())
    }

    /// Every render setting's value, as text.
    #[getter]
    fn settings(&self) -> PyResult<Vec<(&'static str, String)>> {
        (RenderSettings::schema().iter())
            .map(|s| Ok((s.name, self.scene.settings.get(s.name).py()?)))
            .collect()
    }

    /// The names of the materials.
    #[getter]
    fn materials(&self) -> Vec<String> {
        self.scene.material_names().map(String::from).collect()
    }

    /// Builds since the scene was made: renders that could use the last build add none.
    #[getter]
    fn builds(&self) -> u64 {
        self.scene.builds()
    }

    /// What the file's reader could not carry over (pbrt directives, say).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// Defines or replaces the material `name` by a scene file's `[materials.NAME]` keys:
    /// `type="hair"` with one of `melanin`, `sigma_a`, `color`, `preset`, then `eta`,
    /// `beta_m`, ...; or `type="diffuse", albedo=(r, g, b)`. Reaches the build: no new one.
    #[pyo3(signature = (name, **keys))]
    fn set_material(&mut self, name: &str, keys: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let table = keys.map(keys::table).transpose()?.unwrap_or_default();
        let inner = toml::Table::from_iter([(name.to_string(), table.into())]);
        let mut read = keys::read(nest("materials", inner.into()), "set_material")?;
        let material = read.materials.remove(name).expect("the one material read");
        (self.scene.set_material(name, &material))
            .map_err(|e| e.context(format!("materials.{name}")))
            .py()
    }

    /// Adds a light by a scene file's `[[light]]` keys: `type="environment"` (`radiance`
    /// or `map`), `"distant"` (`direction`, `irradiance`, `angular_radius_deg`) or `"rect"`.
    /// Reaches the build: no new one.
    #[pyo3(signature = (**keys))]
    fn add_light(&mut self, keys: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        for light in Self::entry("light", keys, "add_light")?.lights {
            self.scene.add_light(&light).py()?;
        }
        Ok(())
    }

    /// Replaces every light by those the dicts describe (each as `add_light`'s keywords).
    fn set_lights(&mut self, lights: &Bound<'_, PyList>) -> PyResult<()> {
        let mut all = Vec::new();
        for l in lights.iter() {
            let d = l.cast::<PyDict>().map_err(|_| {
                PyTypeError::new_err("set_lights: each light is a dict of a [[light]]'s keys")
            })?;
            all.extend(Self::entry("light", Some(d), "set_lights")?.lights);
        }
        self.scene.set_lights(&all).py()
    }

    /// Places the camera by a scene file's `[camera]` keys (`eye`, `target`, `up`,
    /// `fov_deg`, `aperture_radius`, `focus_distance`; neither eye nor target: framed
    /// automatically). Reaches the build; a render builds again only for a camera that
    /// sees `auto` strands larger than the build shaped them for.
    #[pyo3(signature = (**keys))]
    fn set_camera(&mut self, keys: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let table = keys.map(keys::table).transpose()?.unwrap_or_default();
        let camera = keys::read(nest("camera", table.into()), "set_camera")?.camera;
        self.scene.set_camera(&camera).py()
    }

    /// Adds a groom by a scene file's `[[groom]]` keys: `file=` (.hair or USD) or
    /// `procedural="fur_ball" | "scalp"` with `params={...}`, then `material`, `basis`,
    /// `shape`, `translate`, ... `frame`: the frame of its animation a file is read at (a
    /// USD stage's time samples, the file of a `groom.####.hair` sequence), moving over the
    /// scene's shutter (`set(shutter_open=..., shutter_close=...)` before) where it is open.
    /// The next render builds.
    #[pyo3(signature = (frame=None, **keys))]
    fn add_groom(&mut self, frame: Option<f64>, keys: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        for mut groom in Self::entry("groom", keys, "add_groom")?.grooms {
            if let Some(f) = frame {
                let GroomSource::File { frame, .. } = &mut groom.source else {
                    return Err(PyTypeError::new_err(
                        "add_groom: frame: only a groom file (file=...) is read at a frame",
                    ));
                };
                if !f.is_finite() {
                    return Err(PyValueError::new_err(format!(
                        "add_groom: frame = {f}: must be finite"
                    )));
                }
                *frame = Some(f);
            }
            self.add_groom_desc(&groom)?;
        }
        Ok(())
    }

    /// Adds strands of control points laid out for their basis, as float4 (x, y, z,
    /// radius): `points` (n, 4) for strands that stay put, or at K time steps spread evenly
    /// over the shutter (the settings `shutter_open` and `shutter_close`: the first step
    /// where it opens, the last where it closes), as (K, n, 4) or a list of K (n, 4)
    /// arrays; `counts` (strands,) control points per strand; `colors` (segment ends, 3)
    /// optional; `material`, `basis` (default "bspline") and `shape` (default "auto") as a
    /// `[[groom]]` names them. The next render builds.
    #[pyo3(signature = (points, counts, material, basis="bspline", shape="auto", colors=None))]
    fn add_curves(
        &mut self,
        points: &Bound<'_, PyAny>,
        counts: &Bound<'_, PyAny>,
        material: &str,
        basis: &str,
        shape: &str,
        colors: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut steps = time_steps::<4>(points, "points")?.into_iter();
        // Read as a procedural groom's entry, so that the scene reader checks the names.
        let table = toml::Table::from_iter([
            ("procedural".to_string(), "fur_ball".into()),
            ("material".to_string(), material.into()),
            ("basis".to_string(), basis.into()),
            ("shape".to_string(), shape.into()),
        ]);
        let entry = nest("groom", toml::Value::Array(vec![table.into()]));
        let groom = keys::read(entry, "add_curves")?.grooms.remove(0);
        let colors = colors.map(|c| Floats::rows(c, "colors", 3)).transpose()?;
        let points = ControlPoints {
            points: steps.next().expect("at least one time step").into(),
            later_steps: steps.map(SharedBuffer::from).collect(),
            counts: strand_counts(counts)?,
            colors: colors.map(|c| c.vec3s().to_vec()),
            basis: groom.basis.expect("given"),
        };
        let name = format!("groom[{}]", self.grooms);
        (self.scene)
            .add_control_points(&name, points, groom.shape, &groom.material)
            .py()?;
        self.grooms += 1;
        Ok(())
    }

    /// Adds a triangle mesh from arrays: `positions` (n, 3), or for a mesh that deforms
    /// over the shutter its vertices at K time steps spread evenly over it, (K, n, 3) or a
    /// list of K (n, 3) arrays; `triangles` (t, 3) vertex indices, counter-clockwise seen
    /// from the front, the same at every step; `normals` (n, 3) optional (none on a mesh
    /// that deforms: its geometric normal at each ray's time shades it); `material`, a
    /// diffuse one. The next render builds.
    #[pyo3(signature = (positions, triangles, material, normals=None))]
    fn add_triangles(
        &mut self,
        positions: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        material: &str,
        normals: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut steps = time_steps::<3>(positions, "positions")?.into_iter();
        let normals = normals.map(|n| Floats::rows(n, "normals", 3)).transpose()?;
        let mesh = Mesh {
            positions: steps.next().expect("at least one time step"),
            triangles: steps::triangles(triangles)?,
            normals: normals.map(|n| n.vec3s().to_vec()),
            later_positions: steps.collect(),
        };
        let desc = MeshDesc::new(MeshSource::Triangles(mesh), material);
        let name = format!("mesh[{}]", self.meshes);
        self.scene.add_mesh(&name, &desc).py()?;
        self.meshes += 1;
        Ok(())
    }

    /// Adds a mesh by a scene file's `[[mesh]]` keys (`shape="sphere" | "ground"` or
    /// `file=`, `material`, ...). The next render builds.
    #[pyo3(signature = (**keys))]
    fn add_mesh(&mut self, keys: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        for mesh in Self::entry("mesh", keys, "add_mesh")?.meshes {
            self.scene
                .add_mesh(&format!("mesh[{}]", self.meshes), &mesh)
                .py()?;
            self.meshes += 1;
        }
        Ok(())
    }

    /// Adds strands given as arrays: `points` (n, 3), `radii` (n,) one per point (> 0),
    /// `counts` (strands,) points per strand (>= 2), optional `colors` (n, 3); then a
    /// `[[groom]]`'s keys but its source (`material`, `basis` (default "bspline"),
    /// `shape`, `translate`, ...). The strands draw as a `.hair` file's. The next render
    /// builds.
    #[pyo3(signature = (points, radii, counts, colors=None, **keys))]
    fn add_strands(
        &mut self,
        points: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        counts: &Bound<'_, PyAny>,
        colors: Option<&Bound<'_, PyAny>>,
        keys: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let mut table = keys.map(keys::table).transpose()?.unwrap_or_default();
        for source in ["file", "procedural", "params", "thickness"] {
            if table.contains_key(source) {
                return Err(PyTypeError::new_err(format!(
                    "add_strands: `{source}` is a groom source's key: the strands are the source"
                )));
            }
        }
        // Read as a procedural groom's entry, whose source the strands then replace: every
        // other key is checked by the scene reader.
        table.insert("procedural".into(), "fur_ball".into());
        let entry = nest("groom", toml::Value::Array(vec![table.into()]));
        let mut groom = keys::read(entry, "add_strands")?.grooms.remove(0);
        let (p, r) = (
            Floats::rows(points, "points", 3)?,
            Floats::rows(radii, "radii", 0)?,
        );
        let colors = colors.map(|c| Floats::rows(c, "colors", 3)).transpose()?;
        let mut all = vec![&p, &r];
        all.extend(colors.as_ref());
        same_rows(&all)?;
        let strands = Strands {
            points: p.vec3s().to_vec(),
            radii: r.values().to_vec(),
            counts: strand_counts(counts)?,
            colors: colors.map(|c| c.vec3s().to_vec()),
        };
        strands.validate().py()?;
        groom.source = GroomSource::Strands(strands);
        self.add_groom_desc(&groom)
    }

    /// Renders with the scene's settings, changed for this render by `settings` (by name,
    /// as `set`), building first where the kept build does not serve them. `aovs`: any of
    /// "albedo", "depth", "strand". `progress(done, total)` is called on this thread as
    /// pixels finish; returning False stops the render (the image then holds what
    /// finished); `progress=True` shows a tqdm bar where tqdm is installed. Ctrl-C stops
    /// it and raises KeyboardInterrupt. The GIL is released. Returns a `hairtrace.Image`.
    #[pyo3(signature = (aovs=Vec::new(), progress=None, **settings))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        aovs: Vec<String>,
        progress: Option<&Bound<'py, PyAny>>,
        settings: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let settings = self.settings_with(settings)?;
        settings.validate().py()?;
        let aovs = aov_set(&aovs)?;
        // progress=True: a tqdm bar, where tqdm is installed (hairtrace/_progress.py).
        let bar = match progress {
            Some(p) if p.is_instance_of::<PyBool>() => match p.is_truthy()? {
                true => Some(py.import("hairtrace._progress")?.call_method0("bar")?),
                false => None,
            },
            p => p.cloned(),
        };
        let callback = bar.as_ref().filter(|b| !b.is_none());
        let scene = &mut self.scene;
        let (built, stop) = watch::run(py, None, |w| scene.build_for(&settings, w))?;
        if let Some(Stop::Raised(e)) = stop {
            return Err(e);
        }
        built.py()?;
        let (out, stop) = watch::run(py, callback, |w| scene.render_with(&settings, aovs, w))?;
        if let Some(Stop::Raised(e)) = stop {
            return Err(e);
        }
        let t = scene.stages();
        let (rgb, aovs, stats, complete) = rendered(py, &out.py()?, t.read + t.curves + t.bvh)?;
        let image = py.import("hairtrace._image")?.getattr("Image")?;
        image.call1((rgb, aovs, stats, complete))
    }

    fn __repr__(&self) -> String {
        let s = &self.scene;
        format!(
            "<hairtrace.Scene {}: {} grooms, {} meshes, {} materials, {} lights, {}>",
            self.origin,
            self.grooms,
            self.meshes,
            s.material_names().count(),
            s.light_names().count(),
            if s.is_built() { "built" } else { "not built" }
        )
    }
}

/// Strand counts: integers (not floats, which would be truncated), each >= 0 and < 2^32.
fn strand_counts(counts: &Bound<'_, PyAny>) -> PyResult<Vec<u32>> {
    if let Ok(a) = counts.cast::<PyUntypedArray>() {
        if !matches!(a.dtype().kind(), b'i' | b'u') {
            return Err(PyTypeError::new_err(format!(
                "counts: dtype {}: must be integers",
                a.dtype()
            )));
        }
    }
    let c: PyArrayLike1<i64, AllowTypeChange> = counts
        .extract()
        .map_err(|e| PyTypeError::new_err(format!("counts: must be integers: {e}")))?;
    (c.as_array().iter())
        .map(|&n| {
            u32::try_from(n).map_err(|_| {
                PyValueError::new_err(format!("counts: {n}: must be in [0, {}]", u32::MAX))
            })
        })
        .collect()
}

/// The AOVs named (`AOV_NAMES`).
fn aov_set(names: &[String]) -> PyResult<Aovs> {
    let mut aovs = Aovs::default();
    for n in names {
        match n.as_str() {
            "albedo" => aovs.albedo = true,
            "depth" => aovs.depth = true,
            "strand" => aovs.strand_id = true,
            other => {
                return Err(PyValueError::new_err(format!(
                    "aovs: {other:?}: not an AOV (the AOVs: {})",
                    AOV_NAMES.join(", ")
                )));
            }
        }
    }
    Ok(aovs)
}

/// A render's film as arrays (the crop's pixels), with its statistics.
fn rendered<'py>(
    py: Python<'py>,
    out: &RenderOutput,
    build_seconds: f64,
) -> PyResult<Rendered<'py>> {
    let window = out.film.crop();
    let (w, h) = (window.width() as usize, window.height() as usize);
    let image = |pixels: &[f32], channels: usize| {
        let dims: &[usize] = if channels == 1 {
            &[h, w]
        } else {
            &[h, w, channels]
        };
        Array::from_shape_vec(IxDyn(dims), pixels.to_vec())
            .expect("a film's pixels fill its window")
            .into_pyarray(py)
    };
    let aovs = PyDict::new(py);
    if let Some(a) = out.film.albedo() {
        aovs.set_item("albedo", image(a, 3))?;
    }
    if let Some(d) = out.film.depth() {
        aovs.set_item("depth", image(d, 1))?;
    }
    if let Some(s) = out.film.strand_id() {
        aovs.set_item("strand", image(s, 1))?;
    }
    let s = &out.stats;
    let stats = PyDict::new(py);
    stats.set_item("seconds", s.seconds)?;
    stats.set_item("build_seconds", build_seconds)?;
    stats.set_item("samples", s.samples)?;
    stats.set_item("spp", s.spp)?;
    stats.set_item("noise", s.noise)?;
    stats.set_item("rays", s.rays)?;
    stats.set_item("first_tile_seconds", s.first_tile_seconds)?;
    stats.set_item("crop", [window.x0, window.y0, window.x1, window.y1])?;
    let complete = out.status == RenderStatus::Complete;
    Ok((image(out.film.rgb(), 3), aovs, stats, complete))
}
