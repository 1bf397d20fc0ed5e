//! Reading scene files: serde reads the TOML into raw tables (every key optional where
//! the type of the entry decides), then each entry becomes its typed description, with
//! errors placed at the entry's line.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::hair::Thickness;
use super::usd::is_usd_path;
use crate::bsdf::sigma_a_preset;
use crate::description::{
    CameraDesc, EnvironmentSource, GroomDesc, GroomSource, LightDesc, MaterialDesc, MeshDesc,
    MeshSource, SceneDescription, Transform,
};
use crate::embree::CurveBasis;
use crate::error::{Error, Result, invalid_arg};
use crate::render::settings::RenderSettings;
use crate::scene::GroomShape;
use crate::scene::groom::{FurBall, HairStyle, ScalpPatch};
use crate::scene::material::{HairColor, HairMaterial, HairModel};

impl SceneDescription {
    /// Reads and checks a scene file; relative paths in it are relative to its folder.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
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
        let mut render = RenderSettings::default();
        for (key, value) in &raw.render {
            let at = source.position(key.span());
            let text = setting_text(value.get_ref()).ok_or_else(|| {
                invalid_arg!(
                    "{at}: render.{}: must be a number, a string or an array of them",
                    key.get_ref()
                )
            })?;
            render
                .set(key.get_ref(), &text)
                .map_err(|e| invalid_arg!("{at}: render.{}", e.detail()))?;
        }
        let animation = raw.animation.unwrap_or_default();
        if let Some([first, last]) = animation.frames
            && first > last
        {
            return Err(invalid_arg!(
                "{origin}: animation.frames = [{first}, {last}]: the first frame is after the last"
            ));
        }
        let mut camera = raw.camera;
        camera.usd = camera.usd.map(|p| base_dir.join(p));
        let mut desc = SceneDescription {
            notes: Vec::new(),
            render,
            camera,
            materials,
            grooms,
            meshes,
            lights,
            frames: animation.frames.map(|[first, last]| (first, last)),
            origin: origin.to_string(),
        };
        if let Some(frame) = animation.frame {
            desc.at_frame(frame)?;
        }
        Ok(desc)
    }
}

/// A `[render]` value as the text [`RenderSettings::set`] reads: `crop = [0, 0, 8, 8]` is
/// `0,0,8,8`.
fn setting_text(value: &toml::Value) -> Option<String> {
    match value {
        toml::Value::String(s) => Some(s.clone()),
        toml::Value::Integer(i) => Some(i.to_string()),
        toml::Value::Float(f) => Some(f.to_string()),
        toml::Value::Boolean(b) => Some(b.to_string()),
        toml::Value::Array(items) => items
            .iter()
            .map(|v| match v {
                toml::Value::Array(_) => None,
                v => setting_text(v),
            })
            .collect::<Option<Vec<_>>>()
            .map(|v| v.join(",")),
        _ => None,
    }
}

// Entries are not internally tagged serde enums because those lose the position of every
// error inside them.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    #[serde(default)]
    render: BTreeMap<Spanned<String>, Spanned<toml::Value>>,
    animation: Option<RawAnimation>,
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

/// The `[animation]` table.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawAnimation {
    frame: Option<f64>,
    frames: Option<[i64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    #[serde(rename = "type")]
    kind: MaterialKind,
    sigma_a: Option<[f32; 3]>,
    melanin: Option<[f32; 2]>,
    color: Option<[f32; 3]>,
    preset: Option<String>,
    eta: Option<f32>,
    beta_m: Option<f32>,
    beta_n: Option<f32>,
    alpha: Option<f32>,
    absorption_variation: Option<f32>,
    roughness_variation: Option<f32>,
    tip_absorption: Option<f32>,
    use_vertex_colors: Option<bool>,
    seed: Option<u64>,
    model: Option<ModelKey>,
    roughness: Option<f32>,
    aspect: Option<f32>,
    albedo: Option<[f32; 3]>,
}

/// A hair material's `model`.
#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
enum ModelKey {
    Chiang,
    Huang,
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
    rotate: Option<[f32; 3]>,
    matrix: Option<[[f32; 4]; 4]>,
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
    rotate: Option<[f32; 3]>,
    matrix: Option<[[f32; 4]; 4]>,
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
    Auto,
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

impl From<ShapeKey> for GroomShape {
    fn from(k: ShapeKey) -> Self {
        match k {
            ShapeKey::Round => GroomShape::Round,
            ShapeKey::Flat => GroomShape::Flat,
            ShapeKey::Auto => GroomShape::Auto,
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

/// The transform of a `[[groom]]` or `[[mesh]]` entry: `matrix`, or `translate`, `scale`
/// and `rotate`, not both.
fn transform(
    translate: Option<[f32; 3]>,
    scale: Option<f32>,
    rotate: Option<[f32; 3]>,
    matrix: Option<[[f32; 4]; 4]>,
) -> Checked<Transform> {
    let Some(matrix) = matrix else {
        return Ok(Transform::Trs {
            translate: translate.unwrap_or([0.0; 3]),
            rotate_deg: rotate.unwrap_or([0.0; 3]),
            scale: scale.unwrap_or(1.0),
        });
    };
    reject(
        "a `matrix` transform",
        &[
            ("translate", translate.is_some()),
            ("scale", scale.is_some()),
            ("rotate", rotate.is_some()),
        ],
    )?;
    Ok(Transform::Matrix(matrix))
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
                let color = match (self.sigma_a, self.melanin, self.color, &self.preset) {
                    (Some(s), None, None, None) => HairColor::SigmaA(s),
                    (None, Some([eumelanin, pheomelanin]), None, None) => HairColor::Melanin {
                        eumelanin,
                        pheomelanin,
                    },
                    (None, None, Some(c), None) => HairColor::Color(c),
                    (None, None, None, Some(name)) => {
                        HairColor::SigmaA(sigma_a_preset(name).map_err(|e| e.detail())?)
                    }
                    _ => {
                        return Err("a hair material needs exactly one of `sigma_a`, `melanin` \
                             (= [eumelanin, pheomelanin]), `color` or `preset`"
                            .to_string()
                            .into());
                    }
                };
                let d = HairMaterial::default();
                let model = match self.model.unwrap_or(ModelKey::Chiang) {
                    ModelKey::Chiang => {
                        reject(
                            "a hair material of model \"chiang\" (the default; `model = \"huang\"` \
                             takes them)",
                            &[
                                ("roughness", self.roughness.is_some()),
                                ("aspect", self.aspect.is_some()),
                            ],
                        )?;
                        HairModel::Chiang
                    }
                    ModelKey::Huang => {
                        reject(
                            "a hair material of model \"huang\" (its roughness is `roughness`)",
                            &[("beta_m", self.beta_m.is_some())],
                        )?;
                        let h = crate::bsdf::HuangParams::default();
                        HairModel::Huang {
                            roughness: self.roughness.unwrap_or(h.roughness),
                            aspect: self.aspect.unwrap_or(h.aspect),
                        }
                    }
                };
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
                    model,
                }))
            }
            MaterialKind::Diffuse => {
                // Spelt out without `..`: a key added to RawMaterial does not compile
                // until it is placed on one side or the other here.
                let RawMaterial {
                    kind: _,
                    albedo: _,
                    sigma_a,
                    melanin,
                    color,
                    preset,
                    eta,
                    beta_m,
                    beta_n,
                    alpha,
                    absorption_variation,
                    roughness_variation,
                    tip_absorption,
                    use_vertex_colors,
                    seed,
                    model,
                    roughness,
                    aspect,
                } = &self;
                reject(
                    "a diffuse material",
                    &[
                        ("sigma_a", sigma_a.is_some()),
                        ("melanin", melanin.is_some()),
                        ("color", color.is_some()),
                        ("preset", preset.is_some()),
                        ("eta", eta.is_some()),
                        ("beta_m", beta_m.is_some()),
                        ("beta_n", beta_n.is_some()),
                        ("alpha", alpha.is_some()),
                        ("absorption_variation", absorption_variation.is_some()),
                        ("roughness_variation", roughness_variation.is_some()),
                        ("tip_absorption", tip_absorption.is_some()),
                        ("use_vertex_colors", use_vertex_colors.is_some()),
                        ("seed", seed.is_some()),
                        ("model", model.is_some()),
                        ("roughness", roughness.is_some()),
                        ("aspect", aspect.is_some()),
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
                if is_usd_path(&file) {
                    reject(
                        "a USD groom: each BasisCurves prim gives its own type, basis and wrap, \
                         and its widths are diameters",
                        &[
                            ("basis", self.basis.is_some()),
                            ("thickness", self.thickness.is_some()),
                        ],
                    )?;
                }
                GroomSource::File {
                    path: base_dir.join(file),
                    thickness: self.thickness.map(Thickness::from).unwrap_or_default(),
                    frame: None,
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
        groom.basis = self.basis.map(CurveBasis::from);
        groom.shape = self.shape.map_or(groom.shape, GroomShape::from);
        groom.radius_scale = self.radius_scale.unwrap_or(groom.radius_scale);
        groom.transform = transform(self.translate, self.scale, self.rotate, self.matrix)?;
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
                match is_usd_path(&file) {
                    true => MeshSource::Usd {
                        path: base_dir.join(file),
                        frame: None,
                    },
                    false => MeshSource::File(base_dir.join(file)),
                }
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
            transform: transform(self.translate, self.scale, self.rotate, self.matrix)?,
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
