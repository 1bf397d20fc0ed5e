//! Scene descriptions: a TOML description of a render (settings, camera, materials, grooms,
//! meshes, lights), the built-in demos and the quick look at a bare groom. All of them are
//! a [`SceneDescription`], plain data that a caller may adjust (the CLI's `--spp`,
//! `--width`, ...) before [`crate::Scene::from_description`] (or
//! [`SceneDescription::build`]) makes a scene of it.
//!
//! # The file format
//!
//! ```toml
//! [render]                 # any render setting (RenderSettings::schema, docs/settings.md)
//! width = 640
//! spp = 16
//! threads = 2              # absent: all cores
//! crop = [0, 0, 320, 240]  # [x0, y0, x1, y1) of the full frame
//! filter = "tent"          # or "box" (one pixel)
//!
//! [camera]                 # optional: without eye and target, an automatic camera frames
//! eye = [0, 1, 5]          # the grooms (or, with no groom, the meshes other than ground
//! target = [0, 0, 0]       # quads) at fov_deg
//! up = [0, 1, 0]
//! fov_deg = 35             # vertical field of view
//! aperture_radius = 0.0    # thin lens; 0 is a pinhole
//! focus_distance = 5.0     # default: the distance from eye to target
//! [camera.shutter_close]   # optional: the pose where the shutter closes (any of eye,
//! eye = [0.5, 1, 5]        # target, up, fov_deg; absent ones keep the pose above, which
//!                          # is the opening's); moves the camera over an open shutter
//! # or, instead of all the above: usd = "shot.usda" (its UsdGeomCamera, read at the
//! # frame and over the shutter) and prim = "/cam" (default: the stage's only camera)
//!
//! [materials.brown]
//! type = "hair"            # exactly one of sigma_a = [r, g, b], melanin = [eu, pheo], color = [r, g, b],
//!                          # preset = "red_brown", "light_brown", "dark_brown", "black" or "white"
//! melanin = [1.3, 0.2]     # then, optional: eta, beta_m, beta_n, alpha (degrees),
//! beta_m = 0.3             # absorption_variation, roughness_variation, tip_absorption,
//!                          # use_vertex_colors, seed (see HairMaterial)
//! [materials.curly]
//! type = "hair"
//! color = [0.4, 0.25, 0.15]
//! model = "huang"          # elliptical fibres (docs/conventions.md 4b); default "chiang"
//! roughness = 0.3          # huang only: GGX roughness in [0.01, 1]; beta_m does not apply
//! aspect = 0.65            # huang only: minor over major axis, in [0.05, 1]
//! [materials.skin]
//! type = "diffuse"
//! albedo = [0.6, 0.45, 0.4]
//!
//! [animation]              # optional: the frame grooms read from animated files
//! frame = 12               # USD time samples at this frame, `groom.####.hair` -> groom.0012.hair
//! frames = [1, 48]         # the shot's frames: a frame outside them is refused
//!
//! [[groom]]
//! file = "curly.hair"      # relative to the scene file's folder; a run of # in the name
//!                          # is a sequence of per-frame files (needs a frame)
//! thickness = "diameter"   # how the file's thickness is read: "diameter" (default) or "radius"
//! basis = "bspline"        # "linear", "bezier", "bspline" or "catmull_rom": needed for a
//!                          # .hair file that does not say its own (only `convert` writes it);
//!                          # a procedural groom's default is "bspline"; USD prims say theirs
//! shape = "auto"           # "auto" (default: flat where thinner than a pixel), "round" or "flat"
//! radius_scale = 1.0       # multiplies every fibre radius
//! translate = [0, 0, 0]    # the transform: points scaled (radii too), turned about x, then
//! scale = 1.0              # y, then z (degrees, Blender's XYZ Euler), then moved; or
//! rotate = [0, 0, 0]       # matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
//!                          # (rows, acting on column vectors, translation in the last column),
//!                          # which must scale every axis alike: fibres stay round
//! material = "brown"
//!
//! [[groom]]
//! procedural = "fur_ball"  # or "scalp"; the [groom.params] keys are the fields of FurBall
//! material = "brown"       # or ScalpPatch (style = "straight" | "wavy" | "curly"), each
//! [groom.params]           # defaulting to that struct's Default
//! strands = 20000
//!
//! [[mesh]]
//! shape = "sphere"         # or file = "head.obj" (.obj, .ply, or a USD stage: every
//!                          # UsdGeomMesh, read at the frame and deforming over the shutter)
//! centre = [0, 0, 0]       # default the origin
//! radius = 1.0
//! material = "skin"        # plus translate, scale, rotate or matrix as for grooms
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

pub(crate) mod assembly;
mod build;
mod demos;

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Deserialize;

use crate::embree::CurveBasis;
use crate::formats::hair::Thickness;
use crate::formats::units::StageUnits;
use crate::formats::usd::Layout;
use crate::render::settings::RenderSettings;
use crate::scene::GroomShape;
use crate::scene::camera::Camera;
use crate::scene::groom::{FurBall, ScalpPatch};
use crate::scene::material::HairMaterial;
use crate::scene::mesh::Mesh;
use crate::scene::strands::Strands;

pub use build::{Shutter, is_sequence};
pub use demos::{DEMOS, demo, quick_look};

/// A whole scene as plain data. Adjust fields before [`SceneDescription::build`], not the
/// settings after it: the camera's aspect follows `render.width / render.height`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneDescription {
    /// The `[render]` table.
    pub render: RenderSettings,
    pub camera: CameraDesc,
    pub materials: BTreeMap<String, MaterialDesc>,
    pub grooms: Vec<GroomDesc>,
    pub meshes: Vec<MeshDesc>,
    pub lights: Vec<LightDesc>,
    /// The `[animation]` table's `frames`: the first and last frame of the shot.
    pub frames: Option<(i64, i64)>,
    /// What error messages call this description: the scene file's path, or "demo NAME".
    pub origin: String,
    /// What the file's reader could not carry over (a pbrt file's unsupported directives,
    /// say), one sentence each, for the caller to show.
    pub notes: Vec<String>,
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
    /// The `[camera.shutter_close]` table: where the camera is when the shutter closes,
    /// the pose above being where it opens. With the shutter open the camera moves
    /// between the two; closed, it stays at the opening's.
    pub shutter_close: Option<PoseDesc>,
    /// A USD stage whose UsdGeomCamera is the camera, read at the frame (and over an open
    /// shutter); no other key but `prim` then.
    pub usd: Option<PathBuf>,
    /// The camera prim's path in `usd`; None: the stage's only camera.
    pub prim: Option<String>,
    /// The frame `usd` is read at ([`SceneDescription::at_frame`]); None: a still.
    #[serde(skip)]
    pub frame: Option<f64>,
}

/// The pose of a `[camera.shutter_close]` table: each key absent keeps the opening's.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PoseDesc {
    pub eye: Option<[f32; 3]>,
    pub target: Option<[f32; 3]>,
    pub up: Option<[f32; 3]>,
    pub fov_deg: Option<f32>,
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            eye: None,
            target: None,
            up: [0.0, 1.0, 0.0],
            fov_deg: Camera::DEFAULT_FOV_Y_DEG,
            aperture_radius: 0.0,
            focus_distance: None,
            shutter_close: None,
            usd: None,
            prim: None,
            frame: None,
        }
    }
}

/// A `[materials.NAME]` table.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialDesc {
    Hair(HairMaterial),
    Diffuse { albedo: [f32; 3] },
}

/// Where a groom or mesh goes in the world. Radii follow the scale, which must be the same
/// on every axis (fibres stay round); the build checks it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transform {
    /// A uniform scale, then turns about x, y and z in that order (Blender's default XYZ
    /// Euler), then a translation.
    Trs {
        translate: [f32; 3],
        /// Degrees about x, y and z.
        rotate_deg: [f32; 3],
        scale: f32,
    },
    /// An affine matrix acting on column vectors (`p' = M p`), given by rows: the
    /// translation is the last column and the last row is `0 0 0 1`, as Blender's
    /// `matrix_world` prints.
    Matrix([[f32; 4]; 4]),
}

impl Default for Transform {
    fn default() -> Self {
        Transform::Trs {
            translate: [0.0; 3],
            rotate_deg: [0.0; 3],
            scale: 1.0,
        }
    }
}

/// A `[[groom]]` entry.
#[derive(Debug, Clone, PartialEq)]
pub struct GroomDesc {
    pub source: GroomSource,
    /// The curve drawn through the source's polylines. None: the source's own
    /// ([`GroomDesc::strand_curves`]); a `.hair` file that does not say its own is refused,
    /// never read with a basis assumed for it.
    pub basis: Option<CurveBasis>,
    pub shape: GroomShape,
    /// Multiplies every fibre radius, on top of the transform's scale: thins or thickens a
    /// groom without editing its file.
    pub radius_scale: f32,
    pub transform: Transform,
    pub material: String,
}

#[derive(Debug, Clone, PartialEq)]
pub enum GroomSource {
    File {
        path: PathBuf,
        thickness: Thickness,
        /// The frame of its animation the file is read at: a USD stage's time samples
        /// there, the file of that number in a sequence (a run of # in the path's file
        /// name); with the shutter open, either moves over it (`GroomDesc::curves`). None:
        /// a still (a stage's default values, else its first samples).
        frame: Option<f64>,
    },
    FurBall(FurBall),
    Scalp(ScalpPatch),
    /// A host's own polylines (points, radii, counts per strand), drawn as a `.hair`
    /// file's are: through the groom's basis, B-spline when it gives none.
    Strands(Strands),
    /// Control points (x, y, z, radius) already laid out for `basis`, `counts[i]` of them
    /// for strand i, as a pbrt file gives them: handed to Embree as they are, with no
    /// polyline conversion (and so no `.hair` export).
    ControlPoints {
        points: Vec<[f32; 4]>,
        counts: Vec<u32>,
        basis: CurveBasis,
    },
}

/// The curve a groom's strands draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StrandCurves {
    /// hairtrace's curve of this basis through polylines (`Curves::from_strands`): phantom
    /// end points `2 p0 - p1` for B-splines and Catmull-Rom, and Bezier as the Catmull-Rom
    /// curve in Bezier form.
    Polylines(CurveBasis),
    /// The points are the authored points of USD curves of this layout (a `.hair` file that
    /// `hairtrace convert` wrote from USD).
    Authored(Layout),
}

impl StrandCurves {
    /// The USD layout that draws the same curve.
    pub fn layout(self) -> Layout {
        match self {
            StrandCurves::Polylines(basis) => Layout::of_polylines(basis),
            StrandCurves::Authored(layout) => layout,
        }
    }

    /// The basis Embree traces.
    pub fn basis(self) -> CurveBasis {
        match self {
            StrandCurves::Polylines(basis) => basis,
            StrandCurves::Authored(layout) => layout.basis,
        }
    }
}

/// A set of a groom's strands with the curve they draw and the units they are in: as its
/// source authors them ([`GroomDesc::authored_strands`]), or in the world
/// ([`GroomDesc::placed_strands`], where the units are [`StageUnits::WORLD`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GroomStrands {
    /// The BasisCurves prim they come from, for a USD groom.
    pub prim: Option<String>,
    pub strands: Strands,
    pub curves: StrandCurves,
    pub units: StageUnits,
    /// The curves' normals at each segment end (segments + 1 per strand), where a USD
    /// groom authors them: in the same frame as the points, not unit.
    pub normals: Option<Vec<[f32; 3]>>,
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
    /// Every Mesh prim of a USD stage as one mesh, read at `frame` (None: a still).
    Usd {
        path: PathBuf,
        frame: Option<f64>,
    },
    Sphere {
        centre: [f32; 3],
        radius: f32,
    },
    Ground {
        y: f32,
        half_size: f32,
    },
    /// A mesh given inline (a pbrt `trianglemesh`, or a `plymesh` already placed).
    Triangles(Mesh),
}

/// A `[[light]]` entry; see [`crate::scene::light::Light`] for what each parameter means.
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
    /// A lat-long image (see [`crate::scene::envmap::Environment`] for its orientation).
    Map(PathBuf),
    /// A lat-long image given as linear RGB texels, rows from the top (a pbrt map,
    /// resampled).
    LatLong {
        width: usize,
        height: usize,
        rgb: Vec<f32>,
    },
}

/// Whether `path` ends in `.ext`, in any case.
pub fn has_extension(path: &std::path::Path, ext: &str) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

#[cfg(test)]
mod tests;
