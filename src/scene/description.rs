//! Scene files: a TOML description of a render (settings, camera, materials, grooms,
//! meshes, lights), the built-in demos and the quick look at a bare groom. All of them are
//! a [`SceneDescription`], plain data that a caller may adjust (the CLI's `--spp`,
//! `--width`, ...) before [`SceneDescription::build`] turns it into a renderable world.
//!
//! # The file format
//!
//! ```toml
//! [render]                 # every key optional; defaults from RenderSettings::default()
//! width = 640
//! height = 480
//! spp = 16
//! seed = 0
//! threads = 2              # absent: all cores
//! max_depth = 256
//! rr_depth = 2            # Russian roulette after this many events
//! roulette = "sqrt"        # survival sqrt(throughput), or "throughput"
//! clamp_indirect = 10.0    # absent: no clamping
//! crop = [0, 0, 320, 240]  # [x0, y0, x1, y1) of the full frame
//! filter = "tent"          # or "box" (one pixel)
//! filter_radius = 1.0      # the tent's half-width in pixels
//!
//! [camera]                 # optional: without eye and target, an automatic camera frames
//! eye = [0, 1, 5]          # the grooms (or, with no groom, the meshes other than ground
//! target = [0, 0, 0]       # quads) at fov_deg
//! up = [0, 1, 0]
//! fov_deg = 35             # vertical field of view
//! aperture_radius = 0.0    # thin lens; 0 is a pinhole
//! focus_distance = 5.0     # default: the distance from eye to target
//!
//! [materials.brown]
//! type = "hair"            # exactly one of sigma_a = [r, g, b], melanin = [eu, pheo], color = [r, g, b]
//! melanin = [1.3, 0.2]     # then, optional: eta, beta_m, beta_n, alpha (degrees),
//! beta_m = 0.3             # absorption_variation, roughness_variation, tip_absorption,
//!                          # use_vertex_colors, seed (see HairMaterial)
//! [materials.skin]
//! type = "diffuse"
//! albedo = [0.6, 0.45, 0.4]
//!
//! [[groom]]
//! file = "curly.hair"      # relative to the scene file's folder
//! thickness = "diameter"   # how the file's thickness is read: "diameter" (default) or "radius"
//! basis = "bspline"        # "linear", "bezier", "bspline" (default) or "catmull_rom"
//! shape = "round"          # "round" (default) or "flat"
//! radius_scale = 1.0       # multiplies every fibre radius
//! translate = [0, 0, 0]    # the transform: points scaled, turned about +y, then moved;
//! scale = 1.0              # radii scaled too
//! rotate_y_deg = 0.0
//! material = "brown"
//!
//! [[groom]]
//! procedural = "fur_ball"  # or "scalp"; the [groom.params] keys are the fields of FurBall
//! material = "brown"       # or ScalpPatch (style = "straight" | "wavy" | "curly"), each
//! [groom.params]           # defaulting to that struct's Default
//! strands = 20000
//!
//! [[mesh]]
//! shape = "sphere"         # or file = "head.obj" (.obj or .ply)
//! centre = [0, 0, 0]       # default the origin
//! radius = 1.0
//! material = "skin"        # plus translate, scale, rotate_y_deg as for grooms
//!
//! [[mesh]]
//! shape = "ground"         # a square facing +y, from -half_size to half_size in x and z
//! y = -1.5                 # default 0
//! half_size = 10.0
//! material = "skin"
//!
//! [[light]]
//! type = "environment"     # radiance = [r, g, b] (uniform) or map = "sky.exr" (lat-long)
//! map = "sky.exr"
//! rotation_deg = 0.0       # about +y
//! scale = 1.0
//!
//! [[light]]
//! type = "distant"
//! direction = [-0.5, 1, 0.8]     # toward the light
//! irradiance = [3, 3, 3]         # at a surface facing it
//! angular_radius_deg = 1.0       # default 0: a delta light
//!
//! [[light]]
//! type = "rect"
//! corner = [-1, 3, -1]
//! edge_u = [2, 0, 0]
//! edge_v = [0, 0, 2]             # emits toward edge_u x edge_v
//! radiance = [5, 5, 5]
//! two_sided = false
//! ```
//!
//! Every table rejects keys it does not know, so a misspelt key is an error, not a silent
//! default. Errors found while reading the file name it, the line and the key
//! (`scene.toml:12:1: groom[1].params.strands: ...`); errors found while building name the
//! entry and key (`scene.toml: groom[1].material: no material named "blond" ...`).

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat3, Vec3};
use serde::Deserialize;
use toml::Spanned;

use super::camera::Camera;
use super::curves::Curves;
use super::envmap::Environment;
use super::groom::{FurBall, HairStyle, ScalpPatch};
use super::hair_file::{Thickness, read_hair_file};
use super::light::Light;
use super::material::{HairColor, HairMaterial};
use super::mesh::Mesh;
use super::shapes;
use super::strands::Strands;
use super::tracer::TracerBuilder;
use crate::bsdf::diffuse::Diffuse;
use crate::embree::{CurveBasis, CurveShape, Device, SceneOptions};
use crate::error::{Error, Result, invalid_arg};
use crate::render::PixelFilter;
use crate::render::integrator::{Material, PathSettings, Roulette, World};
use crate::render::settings::RenderSettings;

/// Vertical field of view of a camera that does not give one: a portrait lens's.
pub const DEFAULT_FOV_DEG: f32 = 35.0;
/// Subdivisions of a `shape = "sphere"` mesh: 5120 triangles, whose silhouette strays
/// from the true sphere by under 0.05% of its radius.
const SPHERE_SUBDIVISIONS: u32 = 4;
/// Names of the built-in scenes of [`demo`].
pub const DEMOS: [&str; 3] = ["furball", "furnace", "scalp"];

/// A whole scene as plain data. Adjust fields before [`SceneDescription::build`], not the
/// settings after it: the camera's aspect follows `render.width / render.height`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneDescription {
    pub render: RenderDesc,
    pub camera: CameraDesc,
    pub materials: BTreeMap<String, MaterialDesc>,
    pub grooms: Vec<GroomDesc>,
    pub meshes: Vec<MeshDesc>,
    pub lights: Vec<LightDesc>,
    /// What error messages call this description: the scene file's path, or "demo NAME".
    pub origin: String,
}

/// The `[render]` table: [`RenderSettings`] with its path settings flattened.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderDesc {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
    pub threads: Option<usize>,
    pub max_depth: u32,
    pub rr_depth: u32,
    /// "sqrt" (the default) or "throughput": see [`Roulette`].
    pub roulette: String,
    pub clamp_indirect: Option<f32>,
    pub crop: Option<[u32; 4]>,
    /// "tent" (the default) or "box".
    pub filter: String,
    /// The tent's half-width in pixels (default 1).
    pub filter_radius: Option<f32>,
}

impl Default for RenderDesc {
    fn default() -> Self {
        let s = RenderSettings::default();
        RenderDesc {
            width: s.width,
            height: s.height,
            spp: s.spp,
            seed: s.seed,
            threads: s.threads,
            max_depth: s.path.max_depth,
            rr_depth: s.path.rr_depth,
            roulette: s.path.roulette.name().to_string(),
            clamp_indirect: s.path.clamp_indirect,
            crop: s.crop,
            filter: s.filter.name().0.to_string(),
            filter_radius: None,
        }
    }
}

impl RenderDesc {
    /// The validated settings.
    pub fn settings(&self) -> Result<RenderSettings> {
        let settings = RenderSettings {
            width: self.width,
            height: self.height,
            spp: self.spp,
            seed: self.seed,
            threads: self.threads,
            crop: self.crop,
            filter: PixelFilter::named(&self.filter, self.filter_radius)?,
            path: PathSettings {
                max_depth: self.max_depth,
                rr_depth: self.rr_depth,
                roulette: Roulette::named(&self.roulette)?,
                clamp_indirect: self.clamp_indirect,
                ..PathSettings::default()
            },
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// The `[camera]` table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraDesc {
    /// Both, or neither for a camera that frames the grooms (see the module doc); `up` does
    /// not apply then (+y is up).
    pub eye: Option<[f32; 3]>,
    pub target: Option<[f32; 3]>,
    pub up: [f32; 3],
    pub fov_deg: f32,
    pub aperture_radius: f32,
    /// None: focus on the target (the framed box's centre for an automatic camera).
    pub focus_distance: Option<f32>,
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            eye: None,
            target: None,
            up: [0.0, 1.0, 0.0],
            fov_deg: DEFAULT_FOV_DEG,
            aperture_radius: 0.0,
            focus_distance: None,
        }
    }
}

/// A `[materials.NAME]` table.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialDesc {
    Hair(HairMaterial),
    Diffuse { albedo: [f32; 3] },
}

/// Scale (uniform, so fibres stay round), then a turn about +y, then a translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    pub translate: [f32; 3],
    pub scale: f32,
    pub rotate_y_deg: f32,
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translate: [0.0; 3],
            scale: 1.0,
            rotate_y_deg: 0.0,
        }
    }
}

/// A `[[groom]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct GroomDesc {
    pub source: GroomSource,
    pub basis: CurveBasis,
    pub shape: CurveShape,
    /// Multiplies every fibre radius, on top of the transform's scale: thins or thickens a
    /// groom without editing its file.
    pub radius_scale: f32,
    pub transform: Transform,
    pub material: String,
}

#[derive(Debug, Clone, PartialEq)]
pub enum GroomSource {
    File { path: PathBuf, thickness: Thickness },
    FurBall(FurBall),
    Scalp(ScalpPatch),
}

/// A `[[mesh]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshDesc {
    pub source: MeshSource,
    pub transform: Transform,
    pub material: String,
}

#[derive(Debug, Clone, PartialEq)]
pub enum MeshSource {
    /// An `.obj` or `.ply` file.
    File(PathBuf),
    Sphere {
        centre: [f32; 3],
        radius: f32,
    },
    Ground {
        y: f32,
        half_size: f32,
    },
}

/// A `[[light]]` entry; see [`Light`] for what each parameter means.
#[derive(Debug, Clone, PartialEq)]
pub enum LightDesc {
    Environment {
        source: EnvironmentSource,
        rotation_deg: f32,
        scale: f32,
    },
    Distant {
        /// Toward the light.
        direction: [f32; 3],
        irradiance: [f32; 3],
        angular_radius_deg: f32,
    },
    Rect {
        corner: [f32; 3],
        edge_u: [f32; 3],
        edge_v: [f32; 3],
        radiance: [f32; 3],
        two_sided: bool,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub enum EnvironmentSource {
    Uniform([f32; 3]),
    /// A lat-long image (see [`Environment`] for its orientation).
    Map(PathBuf),
}

/// What a render needs, built from a description.
pub struct BuiltScene {
    pub world: World,
    pub camera: Camera,
    pub settings: RenderSettings,
}

impl SceneDescription {
    /// Reads and checks a scene file; relative paths in it are relative to its folder.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
        let base_dir = path.parent().unwrap_or(Path::new(""));
        Self::from_toml(&text, base_dir, &path.display().to_string())
    }

    /// Parses and checks a description: every key known, every choice made once, every
    /// file path made relative to `base_dir`. Values are checked by [`Self::build`].
    /// `origin` names the text in error messages.
    pub fn from_toml(text: &str, base_dir: &Path, origin: &str) -> Result<Self> {
        let source = Source { origin, text };
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let message = one_line(e.message());
            match e.span() {
                Some(span) => invalid_arg!("{}: {message}", source.position(span)),
                None => invalid_arg!("{origin}: {message}"),
            }
        })?;
        let mut materials = BTreeMap::new();
        for (name, m) in raw.materials {
            let span = m.span();
            let desc = m
                .into_inner()
                .into_desc()
                .map_err(|p| source.problem(span, &format!("materials.{name}"), p))?;
            materials.insert(name, desc);
        }
        let grooms = convert(&source, "groom", raw.groom, |g| g.into_desc(base_dir))?;
        let meshes = convert(&source, "mesh", raw.mesh, |m| m.into_desc(base_dir))?;
        let lights = convert(&source, "light", raw.light, |l| l.into_desc(base_dir))?;
        Ok(SceneDescription {
            render: raw.render,
            camera: raw.camera,
            materials,
            grooms,
            meshes,
            lights,
            origin: origin.to_string(),
        })
    }

    /// Checks every value, reads the files, builds the grooms and meshes into one Embree
    /// scene on `device`, and places the camera. Cheap checks (settings, materials and their
    /// assignment, lights) come before any groom is read or built, so that a typo does not
    /// wait for a large groom.
    pub fn build(&self, device: Arc<Device>) -> Result<BuiltScene> {
        let settings = self
            .render
            .settings()
            .map_err(|e| self.error("render", e))?;
        let mut prepared = BTreeMap::new();
        for (name, m) in &self.materials {
            let material = m
                .prepare()
                .map_err(|e| self.error(&format!("materials.{name}"), e))?;
            prepared.insert(name.as_str(), material);
        }
        let assign = |kind: &str, i: usize, name: &str, hair: bool| {
            self.assigned(&prepared, name, hair)
                .cloned()
                .map_err(|e| self.error(&format!("{kind}[{i}].material"), e))
        };
        let mut materials = Vec::with_capacity(self.grooms.len() + self.meshes.len());
        for (i, g) in self.grooms.iter().enumerate() {
            materials.push(assign("groom", i, &g.material, true)?);
        }
        for (i, m) in self.meshes.iter().enumerate() {
            materials.push(assign("mesh", i, &m.material, false)?);
        }
        if self.lights.is_empty() {
            return Err(invalid_arg!(
                "{}: no lights: add a [[light]] (environment, distant or rect)",
                self.origin
            ));
        }
        let lights = self
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| l.build().map_err(|e| self.error(&format!("light[{i}]"), e)))
            .collect::<Result<Vec<_>>>()?;

        let mut tracer = TracerBuilder::new(device, SceneOptions::default())?;
        let mut hair_bounds = Bounds::EMPTY;
        for (i, g) in self.grooms.iter().enumerate() {
            let at = format!("groom[{i}]");
            let strands = g.strands().map_err(|e| self.error(&at, e))?;
            for (p, r) in strands.points.iter().zip(&strands.radii) {
                hair_bounds.add(Vec3::from_array(*p), *r);
            }
            Curves::from_strands(&strands, g.basis, g.shape)
                .and_then(|c| tracer.add_curves(c))
                .map_err(|e| self.error(&at, e))?;
        }
        let mut prop_bounds = Bounds::EMPTY;
        for (i, m) in self.meshes.iter().enumerate() {
            let at = format!("mesh[{i}]");
            let mesh = m.mesh().map_err(|e| self.error(&at, e))?;
            // A ground quad is the stage, not the subject: framing it would shrink the
            // subject to a speck.
            if !matches!(m.source, MeshSource::Ground { .. }) {
                for p in &mesh.positions {
                    prop_bounds.add(Vec3::from_array(*p), 0.0);
                }
            }
            tracer.add_mesh(mesh).map_err(|e| self.error(&at, e))?;
        }
        let framed = if hair_bounds.is_empty() {
            prop_bounds
        } else {
            hair_bounds
        };
        let aspect = settings.width as f32 / settings.height as f32;
        let camera = self
            .camera
            .build(framed, aspect)
            .map_err(|e| self.error("camera", e))?;
        let world = World::new(tracer.build()?, materials, lights)?;
        Ok(BuiltScene {
            world,
            camera,
            settings,
        })
    }

    /// The prepared material `name`, if it exists and suits the geometry.
    fn assigned<'a>(
        &self,
        prepared: &'a BTreeMap<&str, Material>,
        name: &str,
        hair: bool,
    ) -> Result<&'a Material> {
        let material = prepared.get(name).ok_or_else(|| {
            let defined: Vec<&str> = prepared.keys().copied().collect();
            invalid_arg!(
                "no material named {name:?} (defined: {})",
                if defined.is_empty() {
                    "none".to_string()
                } else {
                    defined.join(", ")
                }
            )
        })?;
        match (material, hair) {
            (Material::Hair(_), true) | (Material::Diffuse(_), false) => Ok(material),
            (Material::Diffuse(_), true) => Err(invalid_arg!(
                "{name:?} is a diffuse material; grooms need a hair material"
            )),
            (Material::Hair(_), false) => Err(invalid_arg!(
                "{name:?} is a hair material; meshes need a diffuse material"
            )),
        }
    }

    /// `e` with this description's origin and the entry or key `at` in front, same kind.
    fn error(&self, at: &str, e: Error) -> Error {
        let prefix = |m: String| format!("{}: {at}: {m}", self.origin);
        match e {
            Error::InvalidArg(m) => Error::InvalidArg(prefix(m)),
            Error::Io(m) => Error::Io(prefix(m)),
            Error::Image(m) => Error::Image(prefix(m)),
            Error::Embree { code, message } => Error::Embree {
                code,
                message: prefix(message),
            },
        }
    }
}

impl MaterialDesc {
    fn prepare(&self) -> Result<Material> {
        Ok(match self {
            MaterialDesc::Hair(h) => Material::Hair(Box::new(h.prepare()?)),
            MaterialDesc::Diffuse { albedo } => {
                Material::Diffuse(Diffuse::new(Vec3::from_array(*albedo))?)
            }
        })
    }
}

impl Transform {
    /// The linear part (the turn times the scale), once every field is checked.
    fn linear(&self) -> Result<Mat3> {
        if !self.translate.iter().all(|v| v.is_finite()) {
            return Err(invalid_arg!(
                "translate = {:?}: must be finite",
                self.translate
            ));
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(invalid_arg!(
                "scale = {}: must be finite and > 0",
                self.scale
            ));
        }
        if !self.rotate_y_deg.is_finite() {
            return Err(invalid_arg!(
                "rotate_y_deg = {}: must be finite",
                self.rotate_y_deg
            ));
        }
        Ok(Mat3::from_rotation_y(self.rotate_y_deg.to_radians()) * self.scale)
    }

    fn point(&self, linear: Mat3, p: [f32; 3]) -> [f32; 3] {
        (linear * Vec3::from_array(p) + Vec3::from_array(self.translate)).to_array()
    }
}

impl GroomDesc {
    /// A groom with the defaults of a `[[groom]]` entry: B-spline round curves, no
    /// transform.
    pub fn new(source: GroomSource, material: &str) -> Self {
        GroomDesc {
            source,
            basis: CurveBasis::BSpline,
            shape: CurveShape::Round,
            radius_scale: 1.0,
            transform: Transform::default(),
            material: material.to_string(),
        }
    }

    /// The strands, transformed and with their radii scaled.
    pub(crate) fn strands(&self) -> Result<Strands> {
        let linear = self.transform.linear()?;
        if !(self.radius_scale.is_finite() && self.radius_scale > 0.0) {
            return Err(invalid_arg!(
                "radius_scale = {}: must be finite and > 0",
                self.radius_scale
            ));
        }
        let mut strands = match &self.source {
            GroomSource::File { path, thickness } => read_hair_file(path, *thickness)?,
            GroomSource::FurBall(f) => f.build()?,
            GroomSource::Scalp(s) => s.build()?,
        };
        if self.transform != Transform::default() {
            for p in &mut strands.points {
                *p = self.transform.point(linear, *p);
            }
        }
        let radius_factor = self.transform.scale * self.radius_scale;
        if radius_factor != 1.0 {
            for r in &mut strands.radii {
                *r *= radius_factor;
            }
        }
        Ok(strands)
    }
}

impl MeshDesc {
    pub fn new(source: MeshSource, material: &str) -> Self {
        MeshDesc {
            source,
            transform: Transform::default(),
            material: material.to_string(),
        }
    }

    /// The mesh, transformed.
    pub(crate) fn mesh(&self) -> Result<Mesh> {
        let linear = self.transform.linear()?;
        let mut mesh = match &self.source {
            MeshSource::File(path) => Mesh::load(path)?,
            MeshSource::Sphere { centre, radius } => {
                shapes::sphere(Vec3::from_array(*centre), *radius, SPHERE_SUBDIVISIONS)?
            }
            MeshSource::Ground { y, half_size } => shapes::ground(*y, *half_size)?,
        };
        if self.transform != Transform::default() {
            for p in &mut mesh.positions {
                *p = self.transform.point(linear, *p);
            }
            // The scale is uniform, so the linear part maps normals to normals.
            for n in mesh.normals.iter_mut().flatten() {
                *n = (linear * Vec3::from_array(*n))
                    .normalize_or_zero()
                    .to_array();
            }
        }
        Ok(mesh)
    }
}

impl LightDesc {
    pub fn build(&self) -> Result<Light> {
        let v = Vec3::from_array;
        match self {
            LightDesc::Environment {
                source,
                rotation_deg,
                scale,
            } => {
                let env = match source {
                    EnvironmentSource::Uniform(radiance) => Environment::uniform(v(*radiance))?,
                    EnvironmentSource::Map(path) => Environment::from_file(path)?,
                };
                Ok(Light::Environment(
                    env.with_rotation(*rotation_deg)?.with_scale(*scale)?,
                ))
            }
            LightDesc::Distant {
                direction,
                irradiance,
                angular_radius_deg,
            } => Light::distant(
                v(*direction),
                v(*irradiance),
                angular_radius_deg.to_radians(),
            ),
            LightDesc::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
                two_sided,
            } => Light::rect(v(*corner), v(*edge_u), v(*edge_v), v(*radiance), *two_sided),
        }
    }
}

impl CameraDesc {
    /// The camera for an image of `aspect`, framing `framed` when no eye and target are
    /// given.
    fn build(&self, framed: Bounds, aspect: f32) -> Result<Camera> {
        let (camera, target) = match (self.eye, self.target) {
            (Some(eye), Some(target)) => {
                let (eye, target) = (Vec3::from_array(eye), Vec3::from_array(target));
                let up = Vec3::from_array(self.up);
                (Camera::new(eye, target, up, self.fov_deg, aspect)?, target)
            }
            (None, None) if framed.is_empty() => {
                return Err(invalid_arg!(
                    "nothing to frame (no groom and no mesh but ground quads): give `eye` \
                     and `target`"
                ));
            }
            (None, None) => (
                Camera::frame_bounds(framed.lo, framed.hi, aspect, self.fov_deg)?,
                (framed.lo + framed.hi) / 2.0,
            ),
            _ => {
                return Err(invalid_arg!(
                    "give both `eye` and `target`, or neither for an automatic camera"
                ));
            }
        };
        let focus = self
            .focus_distance
            .unwrap_or_else(|| camera.eye().distance(target));
        camera.with_thin_lens(self.aperture_radius, focus)
    }
}

/// An axis-aligned box grown point by point.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
    };

    /// Grows the box to hold a ball of `radius` around `p`.
    fn add(&mut self, p: Vec3, radius: f32) {
        self.lo = self.lo.min(p - radius);
        self.hi = self.hi.max(p + radius);
    }

    fn is_empty(&self) -> bool {
        self.lo.cmpgt(self.hi).any()
    }
}

// ---------------------------------------------------------------------------------------
// Built-in scenes.

/// A built-in scene (see [`DEMOS`]): `"furball"` (the default demo: 20k strands of brown
/// fur on a ball over a floor, under the default lights), `"furnace"` (white fur, sigma_a = 0, around
/// a white diffuse sphere under a uniform environment of radiance 1: every pixel's
/// expected value is 1) or `"scalp"` (wavy auburn hair on a head).
pub fn demo(name: &str) -> Result<SceneDescription> {
    let scene = match name {
        "furball" => furball_demo(),
        "furnace" => furnace_demo(),
        "scalp" => scalp_demo(),
        _ => {
            return Err(invalid_arg!(
                "unknown demo {name:?} (choose one of: {})",
                DEMOS.join(", ")
            ));
        }
    };
    Ok(SceneDescription {
        origin: format!("demo {name}"),
        ..scene
    })
}

/// A quick look at a groom file: the default brown hair ([`HairMaterial::default`]),
/// B-spline round curves, [`default_lights`] and an automatic camera. Fails early, before
/// any scene is built, when the file cannot be read.
pub fn quick_look(hair_file: &Path) -> Result<SceneDescription> {
    std::fs::metadata(hair_file).map_err(|e| Error::Io(format!("{}: {e}", hair_file.display())))?;
    let file = GroomSource::File {
        path: hair_file.to_path_buf(),
        thickness: Thickness::default(),
    };
    Ok(SceneDescription {
        materials: BTreeMap::from([(
            "hair".to_string(),
            MaterialDesc::Hair(HairMaterial::default()),
        )]),
        grooms: vec![GroomDesc::new(file, "hair")],
        lights: default_lights(),
        origin: hair_file.display().to_string(),
        ..SceneDescription::default()
    })
}

/// The lights of the demos and quick looks: a soft bluish sky and a warm key light from
/// above, left of the automatic camera (which looks from the front right), small enough
/// to give the hair a crisp highlight and soft enough to avoid aliased shadow edges.
pub fn default_lights() -> Vec<LightDesc> {
    vec![
        LightDesc::Environment {
            source: EnvironmentSource::Uniform([0.25, 0.28, 0.32]),
            rotation_deg: 0.0,
            scale: 1.0,
        },
        LightDesc::Distant {
            direction: [-0.5, 1.0, 0.8],
            irradiance: [3.0, 2.85, 2.6],
            angular_radius_deg: 1.0,
        },
    ]
}

fn furball_demo() -> SceneDescription {
    let fur = FurBall {
        strands: 20_000,
        ..FurBall::default()
    };
    // Nothing hangs lower than a strand's length below the ball.
    let floor = -(fur.radius + fur.length);
    let hair = HairMaterial {
        absorption_variation: 0.2,
        roughness_variation: 0.1,
        seed: 1,
        ..HairMaterial::default()
    };
    SceneDescription {
        materials: BTreeMap::from([
            ("brown".to_string(), MaterialDesc::Hair(hair)),
            (
                "skin".to_string(),
                MaterialDesc::Diffuse {
                    albedo: [0.3, 0.2, 0.15],
                },
            ),
            (
                "floor".to_string(),
                MaterialDesc::Diffuse { albedo: [0.4; 3] },
            ),
        ]),
        meshes: vec![
            // The skin under the fur, so the floor does not show through the ball.
            MeshDesc::new(
                MeshSource::Sphere {
                    centre: [0.0; 3],
                    radius: fur.radius,
                },
                "skin",
            ),
            MeshDesc::new(
                MeshSource::Ground {
                    y: floor,
                    half_size: 10.0,
                },
                "floor",
            ),
        ],
        grooms: vec![GroomDesc::new(GroomSource::FurBall(fur), "brown")],
        lights: default_lights(),
        ..SceneDescription::default()
    }
}

fn furnace_demo() -> SceneDescription {
    let fur = FurBall::default();
    let white_hair = HairMaterial {
        color: HairColor::SigmaA([0.0; 3]),
        beta_m: 0.3,
        beta_n: 0.3,
        ..HairMaterial::default()
    };
    SceneDescription {
        render: RenderDesc {
            max_depth: 256,
            ..RenderDesc::default()
        },
        materials: BTreeMap::from([
            ("white_hair".to_string(), MaterialDesc::Hair(white_hair)),
            (
                "white".to_string(),
                MaterialDesc::Diffuse { albedo: [1.0; 3] },
            ),
        ]),
        meshes: vec![MeshDesc::new(
            MeshSource::Sphere {
                centre: [0.0; 3],
                radius: fur.radius,
            },
            "white",
        )],
        grooms: vec![GroomDesc::new(GroomSource::FurBall(fur), "white_hair")],
        lights: vec![LightDesc::Environment {
            source: EnvironmentSource::Uniform([1.0; 3]),
            rotation_deg: 0.0,
            scale: 1.0,
        }],
        ..SceneDescription::default()
    }
}

fn scalp_demo() -> SceneDescription {
    let scalp = ScalpPatch::default();
    // The patch faces +z: turned, the automatic camera sees the head beside the hair.
    let three_quarter = Transform {
        rotate_y_deg: 60.0,
        ..Transform::default()
    };
    let auburn = HairMaterial {
        color: HairColor::Melanin {
            eumelanin: 0.8,
            pheomelanin: 0.6,
        },
        absorption_variation: 0.15,
        roughness_variation: 0.1,
        seed: 2,
        ..HairMaterial::default()
    };
    SceneDescription {
        materials: BTreeMap::from([
            ("auburn".to_string(), MaterialDesc::Hair(auburn)),
            (
                "skin".to_string(),
                MaterialDesc::Diffuse {
                    albedo: [0.63, 0.45, 0.38],
                },
            ),
        ]),
        meshes: vec![MeshDesc {
            transform: three_quarter,
            ..MeshDesc::new(
                MeshSource::Sphere {
                    centre: [0.0; 3],
                    radius: scalp.radius,
                },
                "skin",
            )
        }],
        grooms: vec![GroomDesc {
            transform: three_quarter,
            ..GroomDesc::new(GroomSource::Scalp(scalp), "auburn")
        }],
        lights: default_lights(),
        ..SceneDescription::default()
    }
}

// ---------------------------------------------------------------------------------------
// Parsing: serde reads the file into raw tables (every key optional where the type of the
// entry decides), then each entry becomes its typed description, with errors placed at the
// entry's line. Entries are not internally tagged serde enums because those lose the
// position of every error inside them.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    #[serde(default)]
    render: RenderDesc,
    #[serde(default)]
    camera: CameraDesc,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<RawMaterial>>,
    #[serde(default)]
    groom: Vec<Spanned<RawGroom>>,
    #[serde(default)]
    mesh: Vec<Spanned<RawMesh>>,
    #[serde(default)]
    light: Vec<Spanned<RawLight>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    #[serde(rename = "type")]
    kind: MaterialKind,
    sigma_a: Option<[f32; 3]>,
    melanin: Option<[f32; 2]>,
    color: Option<[f32; 3]>,
    eta: Option<f32>,
    beta_m: Option<f32>,
    beta_n: Option<f32>,
    alpha: Option<f32>,
    absorption_variation: Option<f32>,
    roughness_variation: Option<f32>,
    tip_absorption: Option<f32>,
    use_vertex_colors: Option<bool>,
    seed: Option<u64>,
    albedo: Option<[f32; 3]>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum MaterialKind {
    Hair,
    Diffuse,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGroom {
    file: Option<PathBuf>,
    thickness: Option<ThicknessKey>,
    procedural: Option<Procedural>,
    params: Option<BTreeMap<String, Spanned<toml::Value>>>,
    basis: Option<BasisKey>,
    shape: Option<ShapeKey>,
    radius_scale: Option<f32>,
    translate: Option<[f32; 3]>,
    scale: Option<f32>,
    rotate_y_deg: Option<f32>,
    material: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    file: Option<PathBuf>,
    shape: Option<MeshShape>,
    centre: Option<[f32; 3]>,
    radius: Option<f32>,
    y: Option<f32>,
    half_size: Option<f32>,
    translate: Option<[f32; 3]>,
    scale: Option<f32>,
    rotate_y_deg: Option<f32>,
    material: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLight {
    #[serde(rename = "type")]
    kind: LightKind,
    radiance: Option<[f32; 3]>,
    map: Option<PathBuf>,
    rotation_deg: Option<f32>,
    scale: Option<f32>,
    direction: Option<[f32; 3]>,
    irradiance: Option<[f32; 3]>,
    angular_radius_deg: Option<f32>,
    corner: Option<[f32; 3]>,
    edge_u: Option<[f32; 3]>,
    edge_v: Option<[f32; 3]>,
    two_sided: Option<bool>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum LightKind {
    Environment,
    Distant,
    Rect,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum Procedural {
    FurBall,
    Scalp,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum MeshShape {
    Sphere,
    Ground,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum ThicknessKey {
    Diameter,
    Radius,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum BasisKey {
    Linear,
    Bezier,
    #[serde(rename = "bspline")]
    BSpline,
    CatmullRom,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum ShapeKey {
    Round,
    Flat,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum StyleKey {
    Straight,
    Wavy,
    Curly,
}

impl From<ThicknessKey> for Thickness {
    fn from(k: ThicknessKey) -> Self {
        match k {
            ThicknessKey::Diameter => Thickness::Diameter,
            ThicknessKey::Radius => Thickness::Radius,
        }
    }
}

impl From<BasisKey> for CurveBasis {
    fn from(k: BasisKey) -> Self {
        match k {
            BasisKey::Linear => CurveBasis::Linear,
            BasisKey::Bezier => CurveBasis::Bezier,
            BasisKey::BSpline => CurveBasis::BSpline,
            BasisKey::CatmullRom => CurveBasis::CatmullRom,
        }
    }
}

impl From<ShapeKey> for CurveShape {
    fn from(k: ShapeKey) -> Self {
        match k {
            ShapeKey::Round => CurveShape::Round,
            ShapeKey::Flat => CurveShape::Flat,
        }
    }
}

impl From<StyleKey> for HairStyle {
    fn from(k: StyleKey) -> Self {
        match k {
            StyleKey::Straight => HairStyle::Straight,
            StyleKey::Wavy => HairStyle::Wavy,
            StyleKey::Curly => HairStyle::Curly,
        }
    }
}

/// The text being parsed, to turn byte offsets into `origin:line:column`.
struct Source<'a> {
    origin: &'a str,
    text: &'a str,
}

impl Source<'_> {
    fn position(&self, span: Range<usize>) -> String {
        // toml spans sit on character boundaries; anything else counts as the end.
        let before = self.text.get(..span.start).unwrap_or(self.text);
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!("{}:{line}:{column}", self.origin)
    }

    /// A problem in the entry `entry` that starts at `span`.
    fn problem(&self, span: Range<usize>, entry: &str, p: Problem) -> Error {
        let at = self.position(p.span.unwrap_or(span));
        match p.key {
            Some(key) => invalid_arg!("{at}: {entry}.{key}: {}", p.message),
            None => invalid_arg!("{at}: {entry}: {}", p.message),
        }
    }
}

/// What is wrong with an entry: the key (relative to the entry) and, when known, where
/// that key's value is.
struct Problem {
    span: Option<Range<usize>>,
    key: Option<String>,
    message: String,
}

impl From<String> for Problem {
    fn from(message: String) -> Self {
        Problem {
            span: None,
            key: None,
            message,
        }
    }
}

type Checked<T> = std::result::Result<T, Problem>;

/// Converts the entries of an array of tables, `name[i]` in messages.
fn convert<R, T>(
    source: &Source,
    name: &str,
    entries: Vec<Spanned<R>>,
    into_desc: impl Fn(R) -> Checked<T>,
) -> Result<Vec<T>> {
    entries
        .into_iter()
        .enumerate()
        .map(|(i, e)| {
            let span = e.span();
            into_desc(e.into_inner()).map_err(|p| source.problem(span, &format!("{name}[{i}]"), p))
        })
        .collect()
}

/// Rejects the keys (name, present) that do not apply to `what`.
fn reject(what: &str, keys: &[(&str, bool)]) -> Checked<()> {
    match keys.iter().find(|(_, present)| *present) {
        Some((key, _)) => Err(Problem {
            span: None,
            key: Some(key.to_string()),
            message: format!("does not apply to {what}"),
        }),
        None => Ok(()),
    }
}

fn required<T>(value: Option<T>, key: &str, what: &str) -> Checked<T> {
    value.ok_or_else(|| format!("{what} needs `{key}`").into())
}

/// A toml message on one line (some end in a newline).
fn one_line(message: &str) -> String {
    message.trim().replace('\n', "; ")
}

fn transform(translate: Option<[f32; 3]>, scale: Option<f32>, rotate: Option<f32>) -> Transform {
    let d = Transform::default();
    Transform {
        translate: translate.unwrap_or(d.translate),
        scale: scale.unwrap_or(d.scale),
        rotate_y_deg: rotate.unwrap_or(d.rotate_y_deg),
    }
}

/// Sets fields of `$target` from a `[groom.params]` table whose keys are the field names,
/// each read as the given type and converted into the field's.
macro_rules! set_params {
    ($target:ident, $params:expr, $what:literal, { $($field:ident: $ty:ty),* $(,)? }) => {
        for (key, value) in $params {
            let span = value.span();
            let problem = |message: String| Problem {
                span: Some(span.clone()),
                key: Some(format!("params.{key}")),
                message,
            };
            match key.as_str() {
                $(stringify!($field) => {
                    $target.$field = value
                        .into_inner()
                        .try_into::<$ty>()
                        .map_err(|e| problem(one_line(e.message())))?
                        .into();
                })*
                _ => {
                    return Err(problem(format!(
                        "unknown parameter of {}; expected one of: {}",
                        $what,
                        [$(stringify!($field)),*].join(", ")
                    )));
                }
            }
        }
    };
}

impl RawMaterial {
    fn into_desc(self) -> Checked<MaterialDesc> {
        match self.kind {
            MaterialKind::Hair => {
                reject("a hair material", &[("albedo", self.albedo.is_some())])?;
                let color = match (self.sigma_a, self.melanin, self.color) {
                    (Some(s), None, None) => HairColor::SigmaA(s),
                    (None, Some([eumelanin, pheomelanin]), None) => HairColor::Melanin {
                        eumelanin,
                        pheomelanin,
                    },
                    (None, None, Some(c)) => HairColor::Color(c),
                    _ => {
                        return Err("a hair material needs exactly one of `sigma_a`, `melanin` \
                             (= [eumelanin, pheomelanin]) or `color`"
                            .to_string()
                            .into());
                    }
                };
                let d = HairMaterial::default();
                Ok(MaterialDesc::Hair(HairMaterial {
                    color,
                    eta: self.eta.unwrap_or(d.eta),
                    beta_m: self.beta_m.unwrap_or(d.beta_m),
                    beta_n: self.beta_n.unwrap_or(d.beta_n),
                    alpha: self.alpha.unwrap_or(d.alpha),
                    absorption_variation: self
                        .absorption_variation
                        .unwrap_or(d.absorption_variation),
                    roughness_variation: self.roughness_variation.unwrap_or(d.roughness_variation),
                    tip_absorption: self.tip_absorption.unwrap_or(d.tip_absorption),
                    use_vertex_colors: self.use_vertex_colors.unwrap_or(d.use_vertex_colors),
                    seed: self.seed.unwrap_or(d.seed),
                }))
            }
            MaterialKind::Diffuse => {
                reject(
                    "a diffuse material",
                    &[
                        ("sigma_a", self.sigma_a.is_some()),
                        ("melanin", self.melanin.is_some()),
                        ("color", self.color.is_some()),
                        ("eta", self.eta.is_some()),
                        ("beta_m", self.beta_m.is_some()),
                        ("beta_n", self.beta_n.is_some()),
                        ("alpha", self.alpha.is_some()),
                        ("absorption_variation", self.absorption_variation.is_some()),
                        ("roughness_variation", self.roughness_variation.is_some()),
                        ("tip_absorption", self.tip_absorption.is_some()),
                        ("use_vertex_colors", self.use_vertex_colors.is_some()),
                        ("seed", self.seed.is_some()),
                    ],
                )?;
                Ok(MaterialDesc::Diffuse {
                    albedo: required(self.albedo, "albedo", "a diffuse material")?,
                })
            }
        }
    }
}

impl RawGroom {
    fn into_desc(self, base_dir: &Path) -> Checked<GroomDesc> {
        let source = match (self.file, self.procedural) {
            (Some(file), None) => {
                reject("a groom file", &[("params", self.params.is_some())])?;
                GroomSource::File {
                    path: base_dir.join(file),
                    thickness: self.thickness.map(Thickness::from).unwrap_or_default(),
                }
            }
            (None, Some(kind)) => {
                reject(
                    "a procedural groom",
                    &[("thickness", self.thickness.is_some())],
                )?;
                let params = self.params.unwrap_or_default();
                match kind {
                    Procedural::FurBall => {
                        let mut f = FurBall::default();
                        set_params!(f, params, "fur_ball", {
                            strands: usize, segments: u32, radius: f32, length: f32,
                            root_radius: f32, tip_radius: f32, curl: f32, gravity: f32,
                            noise: f32, clumping: f32, seed: u64,
                        });
                        GroomSource::FurBall(f)
                    }
                    Procedural::Scalp => {
                        let mut s = ScalpPatch::default();
                        set_params!(s, params, "scalp", {
                            style: StyleKey, strands: usize, segments: u32, radius: f32,
                            width: f32, length: f32, root_radius: f32, tip_radius: f32,
                            amplitude: f32, period: f32, gravity: f32, seed: u64,
                        });
                        GroomSource::Scalp(s)
                    }
                }
            }
            _ => {
                return Err("give either `file` or `procedural` (not both)"
                    .to_string()
                    .into());
            }
        };
        let mut groom = GroomDesc::new(source, &self.material);
        groom.basis = self.basis.map_or(groom.basis, CurveBasis::from);
        groom.shape = self.shape.map_or(groom.shape, CurveShape::from);
        groom.radius_scale = self.radius_scale.unwrap_or(groom.radius_scale);
        groom.transform = transform(self.translate, self.scale, self.rotate_y_deg);
        Ok(groom)
    }
}

impl RawMesh {
    fn into_desc(self, base_dir: &Path) -> Checked<MeshDesc> {
        let sphere = [
            ("centre", self.centre.is_some()),
            ("radius", self.radius.is_some()),
        ];
        let ground = [
            ("y", self.y.is_some()),
            ("half_size", self.half_size.is_some()),
        ];
        let source = match (self.file, self.shape) {
            (Some(file), None) => {
                reject("a mesh file", &[sphere, ground].concat())?;
                MeshSource::File(base_dir.join(file))
            }
            (None, Some(MeshShape::Sphere)) => {
                reject("a sphere", &ground)?;
                MeshSource::Sphere {
                    centre: self.centre.unwrap_or([0.0; 3]),
                    radius: required(self.radius, "radius", "a sphere")?,
                }
            }
            (None, Some(MeshShape::Ground)) => {
                reject("a ground quad", &sphere)?;
                MeshSource::Ground {
                    y: self.y.unwrap_or(0.0),
                    half_size: required(self.half_size, "half_size", "a ground quad")?,
                }
            }
            _ => {
                return Err(
                    "give either `file` or `shape` (\"sphere\" or \"ground\"), not both"
                        .to_string()
                        .into(),
                );
            }
        };
        Ok(MeshDesc {
            source,
            transform: transform(self.translate, self.scale, self.rotate_y_deg),
            material: self.material,
        })
    }
}

impl RawLight {
    fn into_desc(self, base_dir: &Path) -> Checked<LightDesc> {
        let environment = [
            ("map", self.map.is_some()),
            ("rotation_deg", self.rotation_deg.is_some()),
            ("scale", self.scale.is_some()),
        ];
        let distant = [
            ("direction", self.direction.is_some()),
            ("irradiance", self.irradiance.is_some()),
            ("angular_radius_deg", self.angular_radius_deg.is_some()),
        ];
        let rect = [
            ("corner", self.corner.is_some()),
            ("edge_u", self.edge_u.is_some()),
            ("edge_v", self.edge_v.is_some()),
            ("two_sided", self.two_sided.is_some()),
        ];
        Ok(match self.kind {
            LightKind::Environment => {
                let what = "an environment light";
                reject(what, &[&distant[..], &rect[..]].concat())?;
                let source = match (self.radiance, self.map) {
                    (Some(r), None) => EnvironmentSource::Uniform(r),
                    (None, Some(map)) => EnvironmentSource::Map(base_dir.join(map)),
                    _ => {
                        return Err(
                            format!("{what} needs either `radiance` or `map`, not both").into()
                        );
                    }
                };
                LightDesc::Environment {
                    source,
                    rotation_deg: self.rotation_deg.unwrap_or(0.0),
                    scale: self.scale.unwrap_or(1.0),
                }
            }
            LightKind::Distant => {
                let what = "a distant light";
                reject(
                    what,
                    &[
                        &environment[..],
                        &rect[..],
                        &[("radiance", self.radiance.is_some())],
                    ]
                    .concat(),
                )?;
                LightDesc::Distant {
                    direction: required(self.direction, "direction", what)?,
                    irradiance: required(self.irradiance, "irradiance", what)?,
                    angular_radius_deg: self.angular_radius_deg.unwrap_or(0.0),
                }
            }
            LightKind::Rect => {
                let what = "a rect light";
                reject(what, &[&environment[..], &distant[..]].concat())?;
                LightDesc::Rect {
                    corner: required(self.corner, "corner", what)?,
                    edge_u: required(self.edge_u, "edge_u", what)?,
                    edge_v: required(self.edge_v, "edge_v", what)?,
                    radiance: required(self.radiance, "radiance", what)?,
                    two_sided: self.two_sided.unwrap_or(false),
                }
            }
        })
    }
}
