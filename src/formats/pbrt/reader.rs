//! The statements of a pbrt-v4 file, executed as they are read: the graphics state
//! (transform, material) and its stack, includes, the camera and film, lights, materials
//! and shapes. See the module doc of `pbrt` for what is supported and the warning rule.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::Read;
use std::path::{Path, PathBuf};

use glam::{DMat3, DMat4, DVec3};

use super::envmap::latlong_from_equal_area;
use super::lexer::{Lexer, Token};
use super::materials::{DEFAULT_REFLECTANCE, Material, material};
use super::params::{Color, Params, Warning, read_params};
use super::shapes::{Grooms, mesh};
use crate::description::{
    CameraDesc, EnvironmentSource, LightDesc, MaterialDesc, MeshDesc, SceneDescription,
};
use crate::error::{Error, Result, invalid_arg};
use crate::image::read_image;
use crate::render::settings::{PathSettings, RenderSettings};

/// Includes deeper than this are refused (a cycle is refused at once).
pub(super) const MAX_INCLUDE_DEPTH: usize = 32;
/// A gzipped file may not decompress to more than this (a small file could otherwise
/// claim all memory).
const MAX_DECOMPRESSED: u64 = 4 << 30;
/// Nested AttributeBegin / TransformBegin blocks beyond this are refused.
const MAX_NESTING: usize = 10_000;
/// The material of shapes before any Material statement, as in pbrt: diffuse, 0.5.
const DEFAULT_MATERIAL: &str = "(pbrt's default diffuse material)";

/// pbrt-v4's defaults for what a file does not say.
const DEFAULT_RESOLUTION: (u32, u32) = (1280, 720);
const DEFAULT_SPP: u32 = 16;
const DEFAULT_MAX_DEPTH: u32 = 5;
const DEFAULT_FOV_DEG: f64 = 90.0;

#[derive(Clone)]
struct State {
    ctm: DMat4,
    material: String,
}

/// What a Begin statement saved: the whole state (Attribute) or the transform only.
enum Saved {
    Attributes(State),
    Transform(DMat4),
}

struct CameraSetup {
    camera_from_world: DMat4,
    fov_deg: f64,
    lens_radius: f64,
    focus_distance: f64,
    loc: String,
}

/// Everything read so far.
pub(super) struct Reader {
    pub warnings: Vec<Warning>,
    grooms: Grooms,
    meshes: Vec<MeshDesc>,
    lights: Vec<LightDesc>,
    materials: BTreeMap<String, Material>,
    /// The names MakeNamedMaterial gave (the other keys of `materials` are anonymous).
    named: HashSet<String>,
    state: State,
    stack: Vec<Saved>,
    coordinate_systems: HashMap<String, DMat4>,
    camera: Option<CameraSetup>,
    /// World to the frame we render in: a mirror image when pbrt's camera is
    /// left-handed (see [`Reader::begin_world`]); None before WorldBegin.
    render_from_world: Option<DMat4>,
    resolution: (u32, u32),
    pub film_filename: Option<PathBuf>,
    spp: u32,
    max_depth: u32,
    /// pbrt's film gain is exposure time x ISO / 100 (`PixelSensor`): the Camera's
    /// shutter interval and the Film's `iso`.
    exposure_time: f64,
    iso: f64,
    /// Canonical paths of the files being read, outermost first.
    includes: Vec<PathBuf>,
}

impl Reader {
    pub fn new() -> Self {
        let mut materials = BTreeMap::new();
        let albedo = [DEFAULT_REFLECTANCE; 3];
        materials.insert(
            DEFAULT_MATERIAL.to_string(),
            Material::Supported(MaterialDesc::Diffuse { albedo }),
        );
        Reader {
            warnings: Vec::new(),
            grooms: Grooms::default(),
            meshes: Vec::new(),
            lights: Vec::new(),
            materials,
            named: HashSet::new(),
            state: State {
                ctm: DMat4::IDENTITY,
                material: DEFAULT_MATERIAL.to_string(),
            },
            stack: Vec::new(),
            coordinate_systems: HashMap::new(),
            camera: None,
            render_from_world: None,
            resolution: DEFAULT_RESOLUTION,
            film_filename: None,
            spp: DEFAULT_SPP,
            max_depth: DEFAULT_MAX_DEPTH,
            exposure_time: 1.0,
            iso: 100.0,
            includes: Vec::new(),
        }
    }

    /// Reads a file (the top one or an include), relative paths in it relative to its
    /// folder.
    pub fn read_file(&mut self, path: &Path) -> Result<()> {
        let canonical = path.canonicalize().map_err(|e| Error::io(path, e))?;
        if self.includes.contains(&canonical) {
            return Err(invalid_arg!(
                "{}: included from itself (an include cycle)",
                path.display()
            ));
        }
        if self.includes.len() > MAX_INCLUDE_DEPTH {
            return Err(invalid_arg!(
                "{}: includes nested deeper than {MAX_INCLUDE_DEPTH}",
                path.display()
            ));
        }
        let text = read_text_file(path)?;
        self.includes.push(canonical);
        let dir = path.parent().unwrap_or(Path::new(""));
        let result = self.read_text(&text, dir, &path.display().to_string());
        self.includes.pop();
        result
    }

    /// Reads statements from `text`, which `origin` names in messages.
    pub fn read_text(&mut self, text: &str, dir: &Path, origin: &str) -> Result<()> {
        let mut lexer = Lexer::new(text, origin);
        while let Some((token, line)) = lexer.next_token()? {
            let Token::Word(word) = token else {
                return Err(
                    lexer.error(line, format_args!("expected a directive, found {token:?}"))
                );
            };
            self.statement(word, line, &mut lexer, dir)?;
        }
        if !self.stack.is_empty() && self.includes.len() <= 1 {
            return Err(lexer.error(lexer.line(), "AttributeBegin without AttributeEnd"));
        }
        Ok(())
    }

    fn statement(&mut self, word: &str, line: u32, lexer: &mut Lexer, dir: &Path) -> Result<()> {
        let loc = format!("{}:{line}", lexer.origin());
        let world = self.render_from_world.is_some();
        let world_only = matches!(
            word,
            "Shape"
                | "LightSource"
                | "Material"
                | "MakeNamedMaterial"
                | "NamedMaterial"
                | "Texture"
                | "AreaLightSource"
        );
        let options_only = matches!(
            word,
            "Camera" | "Film" | "Sampler" | "Integrator" | "PixelFilter"
        );
        if world_only && !world {
            return Err(invalid_arg!("{loc}: {word} before WorldBegin"));
        }
        if options_only && world {
            return Err(invalid_arg!("{loc}: {word} after WorldBegin"));
        }
        match word {
            "Translate" => {
                let v = numbers::<3>(lexer, line)?;
                self.concat(DMat4::from_translation(DVec3::from_array(v)));
            }
            "Scale" => {
                let v = numbers::<3>(lexer, line)?;
                self.concat(DMat4::from_scale(DVec3::from_array(v)));
            }
            "Rotate" => {
                let [angle, x, y, z] = numbers::<4>(lexer, line)?;
                let axis = DVec3::new(x, y, z)
                    .try_normalize()
                    .ok_or_else(|| invalid_arg!("{loc}: Rotate about a zero axis"))?;
                self.concat(DMat4::from_axis_angle(axis, angle.to_radians()));
            }
            "LookAt" => {
                let v = numbers::<9>(lexer, line)?;
                let [eye, look, up] = [0, 3, 6].map(|i| DVec3::new(v[i], v[i + 1], v[i + 2]));
                let dir = (look - eye).normalize_or_zero();
                if dir == DVec3::ZERO || up.cross(dir).length() < 1e-9 {
                    return Err(invalid_arg!(
                        "{loc}: LookAt: the eye and the point looked at coincide, or the up \
                         vector is parallel to the view"
                    ));
                }
                // pbrt's camera space: x = up x view (left-handed), as glam's _lh view.
                self.concat(DMat4::look_at_lh(eye, look, up));
            }
            "Transform" | "ConcatTransform" => {
                let m = DMat4::from_cols_array(&numbers::<16>(lexer, line)?);
                if word == "Transform" {
                    self.state.ctm = m;
                } else {
                    self.concat(m);
                }
            }
            "Identity" => self.state.ctm = DMat4::IDENTITY,
            "CoordinateSystem" => {
                let name = string_arg(lexer, line, word)?;
                self.coordinate_systems.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = string_arg(lexer, line, word)?;
                self.state.ctm = *self.coordinate_systems.get(&name).ok_or_else(|| {
                    invalid_arg!("{loc}: CoordSysTransform: no coordinate system {name:?}")
                })?;
            }
            "AttributeBegin" | "TransformBegin" => {
                if self.stack.len() >= MAX_NESTING {
                    return Err(invalid_arg!(
                        "{loc}: {word} nested deeper than {MAX_NESTING}"
                    ));
                }
                self.stack.push(if word == "AttributeBegin" {
                    Saved::Attributes(self.state.clone())
                } else {
                    Saved::Transform(self.state.ctm)
                });
            }
            "AttributeEnd" | "TransformEnd" => match (self.stack.pop(), word) {
                (Some(Saved::Attributes(s)), "AttributeEnd") => self.state = s,
                (Some(Saved::Transform(m)), "TransformEnd") => self.state.ctm = m,
                _ => return Err(invalid_arg!("{loc}: {word} without its Begin")),
            },
            "Include" | "Import" => {
                let file = string_arg(lexer, line, word)?;
                self.read_file(&dir.join(file))
                    .map_err(|e| e.context(format_args!("{loc}: {word}")))?;
            }
            "WorldBegin" => self.begin_world(&loc)?,
            "WorldEnd" => self.warn(&loc, "WorldEnd (pbrt-v3) is not needed: ignored"),
            "ReverseOrientation" => self.warn(
                &loc,
                "ReverseOrientation: ignored (hairtrace's surfaces are two-sided)",
            ),
            "Camera" => self.camera(lexer, loc, line)?,
            "Film" => self.film(lexer, loc, line)?,
            "Sampler" | "Integrator" => self.sampler_or_integrator(word, lexer, loc, line)?,
            "PixelFilter" | "ColorSpace" | "Option" | "Accelerator" | "MakeNamedMedium"
            | "MediumInterface" | "TransformTimes" | "ActiveTransform" | "Texture" => {
                skip_arguments(lexer)?;
                let why = match word {
                    "PixelFilter" => "hairtrace filters with its own tent (see --filter)",
                    "Texture" => "textures are not supported; parameters naming it get defaults",
                    "MakeNamedMedium" | "MediumInterface" => {
                        "participating media are not supported (THE IMAGE WILL DIFFER)"
                    }
                    "TransformTimes" | "ActiveTransform" => "motion blur is not supported",
                    _ => "not supported",
                };
                self.warn(&loc, &format!("{word}: ignored: {why}"));
            }
            "Material" => {
                let kind = string_arg(lexer, line, word)?;
                let p = read_params(lexer, loc.clone(), format!("Material {kind:?}"))?;
                let m = material(&kind, &p, &mut self.warnings)?;
                let id = format!("{kind}@{loc}");
                self.materials.insert(id.clone(), m);
                self.state.material = id;
            }
            "MakeNamedMaterial" => {
                let name = string_arg(lexer, line, word)?;
                let p = read_params(lexer, loc.clone(), format!("MakeNamedMaterial {name:?}"))?;
                let kind = p
                    .string("type")?
                    .ok_or_else(|| p.fail("needs \"string type\""))?
                    .to_string();
                if name == DEFAULT_MATERIAL || self.materials.contains_key(&name) {
                    return Err(p.fail("a material of this name is already defined"));
                }
                let m = material(&kind, &p, &mut self.warnings)?;
                self.named.insert(name.clone());
                self.materials.insert(name, m);
            }
            "NamedMaterial" => {
                let name = string_arg(lexer, line, word)?;
                if !self.named.contains(&name) {
                    return Err(invalid_arg!(
                        "{loc}: NamedMaterial: no material named {name:?}"
                    ));
                }
                self.state.material = name;
            }
            "LightSource" => {
                let kind = string_arg(lexer, line, word)?;
                let p = read_params(lexer, loc, format!("LightSource {kind:?}"))?;
                let light = self.light(&kind, &p, dir)?;
                self.lights.push(light);
                self.warnings.extend(p.unused());
            }
            "AreaLightSource" | "ObjectBegin" | "ObjectEnd" | "ObjectInstance" | "Attribute" => {
                let why = match word {
                    "AreaLightSource" => "emitting shapes are not supported",
                    "Attribute" => "default parameters for later statements are not supported",
                    _ => "object instancing is not supported",
                };
                return Err(invalid_arg!("{loc}: {word}: {why}"));
            }
            "Shape" => {
                let kind = string_arg(lexer, line, word)?;
                let p = read_params(lexer, loc, format!("Shape {kind:?}"))?;
                self.shape(&kind, &p, dir)?;
                self.warnings.extend(p.unused());
            }
            _ => return Err(invalid_arg!("{loc}: unknown directive {word:?}")),
        }
        Ok(())
    }

    fn concat(&mut self, m: DMat4) {
        self.state.ctm *= m;
    }

    fn warn(&mut self, loc: &str, text: &str) {
        self.warnings.push((loc.to_string(), text.to_string()));
    }

    fn camera(&mut self, lexer: &mut Lexer, loc: String, line: u32) -> Result<()> {
        let kind = string_arg(lexer, line, "Camera")?;
        let p = read_params(lexer, loc.clone(), format!("Camera {kind:?}"))?;
        if kind != "perspective" {
            return Err(p.fail("only \"perspective\" cameras are supported"));
        }
        // pbrt names the camera's own frame "camera": world from camera.
        self.coordinate_systems
            .insert("camera".into(), self.state.ctm.inverse());
        self.camera = Some(CameraSetup {
            camera_from_world: self.state.ctm,
            fov_deg: p.float("fov")?.unwrap_or(DEFAULT_FOV_DEG),
            lens_radius: p.float("lensradius")?.unwrap_or(0.0),
            focus_distance: p.float("focaldistance")?.unwrap_or(1e6),
            loc,
        });
        self.exposure_time =
            p.float("shutterclose")?.unwrap_or(1.0) - p.float("shutteropen")?.unwrap_or(0.0);
        self.warnings.extend(p.unused());
        Ok(())
    }

    fn film(&mut self, lexer: &mut Lexer, loc: String, line: u32) -> Result<()> {
        let kind = string_arg(lexer, line, "Film")?;
        let p = read_params(lexer, loc, format!("Film {kind:?}"))?;
        let size = |name: &str, default: u32| -> Result<u32> {
            match p.int(name)? {
                None => Ok(default),
                Some(v) => u32::try_from(v)
                    .ok()
                    .filter(|&v| v > 0)
                    .ok_or_else(|| p.fail(format_args!("{name} = {v}: must be > 0"))),
            }
        };
        self.resolution = (
            size("xresolution", DEFAULT_RESOLUTION.0)?,
            size("yresolution", DEFAULT_RESOLUTION.1)?,
        );
        self.film_filename = p.string("filename")?.map(PathBuf::from);
        self.iso = p.float("iso")?.unwrap_or(100.0);
        self.warnings.extend(p.unused());
        Ok(())
    }

    /// Sampler's `pixelsamples` and Integrator's `maxdepth` are kept; the rest is ours.
    fn sampler_or_integrator(
        &mut self,
        word: &str,
        lexer: &mut Lexer,
        loc: String,
        line: u32,
    ) -> Result<()> {
        let kind = string_arg(lexer, line, word)?;
        let p = read_params(lexer, loc, format!("{word} {kind:?}"))?;
        let (name, target) = if word == "Sampler" {
            ("pixelsamples", &mut self.spp)
        } else {
            ("maxdepth", &mut self.max_depth)
        };
        if let Some(v) = p.int(name)? {
            *target =
                u32::try_from(v).map_err(|_| p.fail(format_args!("{name} = {v}: out of range")))?;
        }
        self.warnings.push(p.warning(format_args!(
            "hairtrace's own {} is used (only \"{name}\" is read)",
            if word == "Sampler" {
                "sampler"
            } else {
                "path tracer"
            }
        )));
        for q in &p.list {
            p.ignore(&q.name);
        }
        Ok(())
    }

    /// Fixes the frame we render in. pbrt's camera space is left-handed (image right is
    /// up x view) where ours is right-handed (view x up): when the camera transform keeps
    /// pbrt's handedness, the whole scene and the camera are mirrored through x = 0,
    /// which shows the image pbrt shows.
    fn begin_world(&mut self, loc: &str) -> Result<()> {
        if self.render_from_world.is_some() {
            return Err(invalid_arg!("{loc}: WorldBegin given twice"));
        }
        let camera_from_world = self
            .camera
            .as_ref()
            .map_or(DMat4::IDENTITY, |c| c.camera_from_world);
        let det = DMat3::from_mat4(camera_from_world).determinant();
        if !(det.is_finite() && det.abs() > 1e-12) {
            return Err(invalid_arg!(
                "{loc}: the camera transform cannot be inverted"
            ));
        }
        self.render_from_world = Some(if det > 0.0 {
            DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))
        } else {
            DMat4::IDENTITY
        });
        self.state.ctm = DMat4::IDENTITY;
        self.coordinate_systems
            .insert("world".into(), DMat4::IDENTITY);
        Ok(())
    }

    /// The current transform, into the frame we render in.
    fn to_render(&self) -> DMat4 {
        self.render_from_world.unwrap_or(DMat4::IDENTITY) * self.state.ctm
    }

    fn light(&mut self, kind: &str, p: &Params, dir: &Path) -> Result<LightDesc> {
        let given = match p.color("L")? {
            None => None,
            Some(Color::Rgb(c)) => Some(c),
            Some(Color::Texture(_)) => return Err(p.fail("\"L\" must be an rgb colour")),
        };
        let rgb = given.unwrap_or([1.0; 3]);
        // pbrt scales "L" so that its colour space's white is 1 nit: rgb values render as
        // they are given, times "scale" (and the "illuminance" target, if any).
        let scale = p.float("scale")?.unwrap_or(1.0);
        let illuminance = p.float("illuminance")?.filter(|&e| e > 0.0);
        let amount = |k: f64| rgb.map(|c| (c * scale * k) as f32);
        match kind {
            "infinite" => {
                if let Some(file) = p.string("filename")? {
                    if given.is_some() || illuminance.is_some() {
                        return Err(p.fail(
                            "give either \"L\" or \"filename\", and no \"illuminance\" with an \
                             image",
                        ));
                    }
                    let image = read_image(&dir.join(file)).map_err(|e| p.context(e))?;
                    let light_from_render = DMat3::from_mat4(self.to_render()).inverse();
                    let (width, height, rgb) = latlong_from_equal_area(&image, light_from_render)
                        .map_err(|e| p.context(e))?;
                    return Ok(LightDesc::Environment {
                        source: EnvironmentSource::LatLong { width, height, rgb },
                        rotation_deg: 0.0,
                        scale: scale as f32,
                    });
                }
                if p.nums("portal", &["point3", "point"])?.is_some() {
                    self.warnings
                        .push(p.warning("\"portal\" only guides pbrt's sampling: ignored"));
                }
                // Illuminance on an upward patch from a uniform sky is pi L.
                let radiance = amount(illuminance.map_or(1.0, |e| e / std::f64::consts::PI));
                Ok(LightDesc::Environment {
                    source: EnvironmentSource::Uniform(radiance),
                    rotation_deg: 0.0,
                    scale: 1.0,
                })
            }
            "distant" => {
                let from = p.point("from")?.unwrap_or([0.0; 3]);
                let to = p.point("to")?.unwrap_or([0.0, 0.0, 1.0]);
                let w = DVec3::from_array(from) - DVec3::from_array(to);
                let direction = self
                    .to_render()
                    .transform_vector3(w)
                    .try_normalize()
                    .ok_or_else(|| p.fail("\"from\" and \"to\" must differ"))?;
                Ok(LightDesc::Distant {
                    direction: direction.as_vec3().to_array(),
                    irradiance: amount(illuminance.unwrap_or(1.0)),
                    angular_radius_deg: 0.0,
                })
            }
            _ => Err(p.fail("only \"infinite\" and \"distant\" lights are supported")),
        }
    }

    fn shape(&mut self, kind: &str, p: &Params, dir: &Path) -> Result<()> {
        let id = self.state.material.clone();
        let on_curves = kind == "curve";
        match &self.materials[&id] {
            Material::Unsupported(why) => {
                return Err(p.fail(format_args!("its material cannot be rendered: {why}")));
            }
            Material::Supported(MaterialDesc::Hair(_)) if !on_curves => {
                return Err(p.fail("a hair material on a surface: only curves take hair"));
            }
            Material::Supported(MaterialDesc::Diffuse { .. }) if on_curves => {
                return Err(p.fail(format_args!(
                    "curves need a hair material; theirs is diffuse ({id})"
                )));
            }
            Material::Supported(_) => {}
        }
        let to_render = self.to_render();
        match kind {
            "curve" => self
                .grooms
                .add_curve(p, &to_render, &id, &mut self.warnings),
            "trianglemesh" | "plymesh" | "sphere" => {
                self.meshes.push(mesh(kind, p, &to_render, dir, &id)?);
                Ok(())
            }
            _ => Err(p.fail(
                "only \"curve\", \"trianglemesh\", \"plymesh\" and \"sphere\" shapes are \
                 supported",
            )),
        }
    }

    /// The description, once every file is read.
    pub fn finish(self, origin: &str) -> Result<SceneDescription> {
        if self.render_from_world.is_none() {
            return Err(invalid_arg!("{origin}: no WorldBegin"));
        }
        let (width, height) = self.resolution;
        let camera = self.camera_desc(width, height)?;
        // The image is linear in the light: pbrt's film gain scales every light.
        let gain = self.exposure_time * self.iso / 100.0;
        if !(gain.is_finite() && gain > 0.0) {
            return Err(invalid_arg!(
                "{origin}: the shutter interval ({}) times the Film's iso ({}) must be > 0",
                self.exposure_time,
                self.iso
            ));
        }
        let mut lights = self.lights;
        for light in &mut lights {
            match light {
                LightDesc::Environment { scale, .. } => *scale *= gain as f32,
                LightDesc::Distant { irradiance, .. }
                | LightDesc::Rect {
                    radiance: irradiance,
                    ..
                } => {
                    *irradiance = irradiance.map(|v| v * gain as f32);
                }
            }
        }
        let used: Vec<&str> = self
            .grooms
            .list
            .iter()
            .map(|g| g.material.as_str())
            .chain(self.meshes.iter().map(|m| m.material.as_str()))
            .collect();
        let materials = self
            .materials
            .into_iter()
            .filter(|(name, _)| used.contains(&name.as_str()))
            .filter_map(|(name, m)| match m {
                Material::Supported(d) => Some((name, d)),
                Material::Unsupported(_) => None,
            })
            .collect();
        Ok(SceneDescription {
            frames: None,
            render: RenderSettings {
                width,
                height,
                spp: self.spp,
                path: PathSettings {
                    max_depth: self.max_depth,
                    ..PathSettings::default()
                },
                ..RenderSettings::default()
            },
            camera,
            materials,
            grooms: self.grooms.list,
            meshes: self.meshes,
            lights,
            origin: origin.to_string(),
            notes: Vec::new(),
        })
    }

    fn camera_desc(&self, width: u32, height: u32) -> Result<CameraDesc> {
        let (camera_from_world, fov, lens, focus) = match &self.camera {
            Some(c) => {
                for (name, v, ok) in [
                    ("fov", c.fov_deg, c.fov_deg > 0.0 && c.fov_deg < 180.0),
                    ("lensradius", c.lens_radius, c.lens_radius >= 0.0),
                    ("focaldistance", c.focus_distance, c.focus_distance > 0.0),
                ] {
                    if !ok {
                        return Err(invalid_arg!(
                            "{}: Camera: {name} = {v} is out of range",
                            c.loc
                        ));
                    }
                }
                (
                    c.camera_from_world,
                    c.fov_deg,
                    c.lens_radius,
                    c.focus_distance,
                )
            }
            None => (DMat4::IDENTITY, DEFAULT_FOV_DEG, 0.0, 1e6),
        };
        let to_render =
            self.render_from_world.unwrap_or(DMat4::IDENTITY) * camera_from_world.inverse();
        let eye = to_render.transform_point3(DVec3::ZERO);
        let forward = to_render.transform_vector3(DVec3::Z).normalize();
        let up = to_render.transform_vector3(DVec3::Y).normalize();
        // pbrt's fov spans the shorter side of the image; ours is vertical.
        let half = (fov.to_radians() / 2.0).tan();
        let fov_y = if width < height {
            2.0 * (half * f64::from(height) / f64::from(width)).atan()
        } else {
            fov.to_radians()
        };
        Ok(CameraDesc {
            eye: Some(eye.as_vec3().to_array()),
            target: Some((eye + forward).as_vec3().to_array()),
            up: up.as_vec3().to_array(),
            fov_deg: fov_y.to_degrees() as f32,
            aperture_radius: lens as f32,
            focus_distance: (lens > 0.0).then_some(focus as f32),
            ..CameraDesc::default()
        })
    }
}

/// Text read from a file; a `.gz` file is decompressed (pbrt's scenes include gzipped
/// geometry), up to [`MAX_DECOMPRESSED`] bytes.
fn read_text_file(path: &Path) -> Result<String> {
    let io = |e| Error::io(path, e);
    let file = std::fs::File::open(path).map_err(io)?;
    if !path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"))
    {
        return std::io::read_to_string(file).map_err(io);
    }
    let mut text = String::new();
    let decoder = flate2::read::GzDecoder::new(std::io::BufReader::new(file));
    decoder
        .take(MAX_DECOMPRESSED + 1)
        .read_to_string(&mut text)
        .map_err(io)?;
    if text.len() as u64 > MAX_DECOMPRESSED {
        return Err(invalid_arg!(
            "{}: decompresses to more than {} GiB",
            path.display(),
            MAX_DECOMPRESSED >> 30
        ));
    }
    Ok(text)
}

/// `N` numbers, bare or in brackets.
fn numbers<const N: usize>(lexer: &mut Lexer, line: u32) -> Result<[f64; N]> {
    let bracketed = matches!(lexer.peek()?, Some((Token::Open, _)));
    if bracketed {
        lexer.next_token()?;
    }
    let mut out = [0.0; N];
    for v in &mut out {
        match lexer.next_token()? {
            Some((Token::Num(x), _)) => *v = x,
            _ => return Err(lexer.error(line, format_args!("expected {N} numbers"))),
        }
    }
    if bracketed && !matches!(lexer.next_token()?, Some((Token::Close, _))) {
        return Err(lexer.error(line, format_args!("expected {N} numbers and `]`")));
    }
    Ok(out)
}

fn string_arg(lexer: &mut Lexer, line: u32, word: &str) -> Result<String> {
    match lexer.next_token()? {
        Some((Token::Str(s), _)) => Ok(s),
        _ => Err(lexer.error(line, format_args!("{word} needs a quoted name"))),
    }
}

/// Skips the arguments of an ignored statement, up to the next directive.
fn skip_arguments(lexer: &mut Lexer) -> Result<()> {
    while let Some((t, _)) = lexer.peek()? {
        if matches!(t, Token::Word(w) if *w != "true" && *w != "false") {
            break;
        }
        lexer.next_token()?;
    }
    Ok(())
}
