//! [`Scene`]: one scene that every host edits and renders, kept with its last build. Rust
//! hosts use it directly; the C ABI's `HtScene`, the command line and the Python package
//! are shells over it, so the rules of when to build are said once, here.
//!
//! A scene holds grooms, meshes, materials and lights, each by name, a camera and render
//! settings. Geometry is read and converted for Embree when it is added and kept, its
//! curves' points shared with every build: the first build puts the curves in spatial order
//! and gives them back, so a rebuild neither sorts nor copies them again. A render builds
//! only when the last build cannot serve it ([`Scene::build_for`]): an edit of a material,
//! a light or the camera reaches the build itself, and new geometry, a setting that [needs
//! a build](crate::render::settings::Needs) or a view the build's `auto` curves were not
//! shaped for builds again, never refused.

mod build;
mod description;

use std::collections::BTreeMap;
use std::sync::Arc;

use crate::description::assembly::Shape;
use crate::description::{
    CameraDesc, GroomDesc, LightDesc, MaterialDesc, MeshDesc, MeshSource, Shutter,
};
use crate::embree::{CurveBasis, Device, SharedBuffer};
use crate::error::{Error, Result, invalid_arg};
use crate::render::integrator::World;
use crate::render::settings::RenderSettings;
use crate::scene::curves::Curves;
use crate::scene::framing::Framing;
use crate::scene::light::Light;
use crate::scene::material::Material;
use crate::scene::ribbons::GroomShape;
use crate::scene::stages::{NoStages, Stage, StageRunner, StageTimes};

/// A scene kept with its last build: edit it by name, render it with any settings, and it
/// builds only where its build cannot serve the render.
///
/// ```no_run
/// use std::sync::Arc;
/// use hairtrace::description::{LightDesc, MaterialDesc};
/// use hairtrace::scene::{HairColor, HairMaterial};
/// use hairtrace::{Aovs, NoProgress, Scene, SceneDescription};
/// # fn main() -> hairtrace::Result<()> {
/// let desc = SceneDescription::load("scene.toml".as_ref())?;
/// let mut scene = Scene::from_description(&desc, Arc::new(desc.render.device()?))?;
/// let first = scene.render(Aovs::default(), &NoProgress)?; // builds
/// let blond = HairMaterial {
///     color: HairColor::Melanin { eumelanin: 0.3, pheomelanin: 0.1 },
///     ..HairMaterial::default()
/// };
/// scene.set_material("hair", &MaterialDesc::Hair(blond))?;
/// scene.add_light(&LightDesc::Distant {
///     direction: [0.0, 1.0, 1.0],
///     irradiance: [3.0; 3],
///     angular_radius_deg: 1.0,
/// })?;
/// let second = scene.render(Aovs::default(), &NoProgress)?; // no build
/// assert_eq!(scene.builds(), 1);
/// # let _ = (first, second);
/// # Ok(()) }
/// ```
pub struct Scene {
    device: Arc<Device>,
    /// What [`Scene::render`] renders with.
    pub settings: RenderSettings,
    /// Put in front of errors: a scene file's path, say; empty for none.
    origin: String,
    camera: CameraDesc,
    materials: BTreeMap<String, NamedMaterial>,
    geometries: Vec<Geometry>,
    lights: Vec<NamedLight>,
    built: Option<Built>,
    builds: u64,
    /// Seconds spent reading and converting geometry since the last build: the next build's
    /// stages count them.
    pending: StageTimes,
    stages: StageTimes,
}

struct NamedMaterial {
    desc: MaterialDesc,
    prepared: Material,
}

struct NamedLight {
    name: String,
    desc: LightDesc,
    light: Light,
}

/// A groom (one shape per curve set: a USD stage gives one per prim) or a mesh.
struct Geometry {
    name: String,
    shapes: Vec<Shape>,
    material: String,
    /// What it adds to the automatic camera's frame, kept apart so that a removal leaves
    /// the frame of the rest.
    framing: Framing,
    on_curves: bool,
}

/// The last build and what it was made for.
struct Built {
    world: World,
    /// The index in `geometries` of each Embree geometry.
    geometry_of: Vec<usize>,
    settings: RenderSettings,
    /// The lights changed since: the world takes them at the next render.
    lights_changed: bool,
}

/// Control points laid out for their basis, as Embree reads them: a [`SharedBuffer`] of a
/// host's memory ([`SharedBuffer::from_raw_parts`]) is read in place through every build,
/// never copied.
pub struct ControlPoints {
    pub points: SharedBuffer<[f32; 4]>,
    /// For strands that move over the shutter, the same control points at each later time
    /// step, `points` being the first (`Curves::in_motion`); empty for strands that stay
    /// put.
    pub later_steps: Vec<SharedBuffer<[f32; 4]>>,
    /// Points per strand.
    pub counts: Vec<u32>,
    /// One linear RGB value per segment end (segments + 1 per strand), if any.
    pub colors: Option<Vec<[f32; 3]>>,
    pub basis: CurveBasis,
}

impl Scene {
    /// An empty scene on `device` (whose Embree threads build it and whose pinned `isa`
    /// its renders use), with default settings and an automatic camera.
    pub fn new(device: Arc<Device>) -> Scene {
        Scene {
            device,
            settings: RenderSettings::default(),
            origin: String::new(),
            camera: CameraDesc::default(),
            materials: BTreeMap::new(),
            geometries: Vec::new(),
            lights: Vec::new(),
            built: None,
            builds: 0,
            pending: StageTimes::default(),
            stages: StageTimes::default(),
        }
    }

    /// The device the scene builds on.
    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }

    /// How many times the scene built its BVH: a render that could use the last build
    /// adds none.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Whether a build is kept (none before the first render and after geometry changed).
    pub fn is_built(&self) -> bool {
        self.built.is_some()
    }

    /// Seconds each stage of the last build took, with the reading and converting of the
    /// geometry added since the build before it.
    pub fn stages(&self) -> StageTimes {
        self.stages
    }

    pub fn camera(&self) -> &CameraDesc {
        &self.camera
    }

    /// Places the camera (no eye and target: framed automatically), checked now; the build
    /// is kept unless `auto` curves need other shapes for it.
    pub fn set_camera(&mut self, camera: &CameraDesc) -> Result<()> {
        camera.validate().map_err(|e| self.error("camera", e))?;
        self.camera = camera.clone();
        Ok(())
    }

    pub fn material(&self, name: &str) -> Option<&MaterialDesc> {
        self.materials.get(name).map(|m| &m.desc)
    }

    pub fn material_names(&self) -> impl Iterator<Item = &str> {
        self.materials.keys().map(String::as_str)
    }

    /// Defines or replaces the material `name`, without a new build: the next render is
    /// the one of a scene built with it. Refused (nothing changed) when it is out of range
    /// or does not suit the geometry that uses it (hair on curves, diffuse on meshes).
    pub fn set_material(&mut self, name: &str, material: &MaterialDesc) -> Result<()> {
        let prepared = material.prepare()?;
        let what = format!("material {name:?}");
        for g in self.geometries.iter().filter(|g| g.material == name) {
            prepared.check_suits(&what, g.on_curves)?;
        }
        if let Some(built) = &mut self.built {
            for (id, &g) in built.geometry_of.iter().enumerate() {
                if self.geometries[g].material == name {
                    if let Err(e) = built.world.set_material(id as u32, prepared.clone()) {
                        // Part of the world may have it: the next render builds afresh.
                        self.built = None;
                        return Err(e);
                    }
                }
            }
        }
        let desc = material.clone();
        self.materials
            .insert(name.into(), NamedMaterial { desc, prepared });
        Ok(())
    }

    /// Whether the material `name` exists and suits curves (`on_curves`: hair) or meshes
    /// (diffuse): what a host checks before adding geometry, as a build will.
    pub fn check_material(&self, name: &str, on_curves: bool) -> Result<()> {
        let material = self.materials.get(name).ok_or_else(|| {
            let defined: Vec<&str> = self.material_names().collect();
            invalid_arg!(
                "no material named {name:?} (defined: {})",
                if defined.is_empty() {
                    "none".to_string()
                } else {
                    defined.join(", ")
                }
            )
        })?;
        (material.prepared).check_suits(&format!("{name:?}"), on_curves)
    }

    pub fn light_names(&self) -> impl Iterator<Item = &str> {
        self.lights.iter().map(|l| l.name.as_str())
    }

    pub fn light(&self, name: &str) -> Option<&LightDesc> {
        self.lights.iter().find(|l| l.name == name).map(|l| &l.desc)
    }

    /// Adds a light (files read now) under a name of its own, which it returns; no new
    /// build.
    pub fn add_light(&mut self, light: &LightDesc) -> Result<String> {
        let name = (self.lights.len()..)
            .map(|i| format!("light[{i}]"))
            .find(|n| self.light(n).is_none())
            .expect("a free name");
        self.set_light(&name, light)?;
        Ok(name)
    }

    /// Defines or replaces the light `name` (files read now); no new build.
    pub fn set_light(&mut self, name: &str, light: &LightDesc) -> Result<()> {
        let built = light.build().map_err(|e| e.context(name))?;
        let named = NamedLight {
            name: name.into(),
            desc: light.clone(),
            light: built,
        };
        match self.lights.iter_mut().find(|l| l.name == name) {
            Some(l) => *l = named,
            None => self.lights.push(named),
        }
        self.lights_changed();
        Ok(())
    }

    /// Replaces every light by `lights`, named `light[0]`, `light[1]`...; no new build.
    /// Refused (nothing changed) for none or a bad one.
    pub fn set_lights(&mut self, lights: &[LightDesc]) -> Result<()> {
        if lights.is_empty() {
            return Err(invalid_arg!("no lights: give at least one"));
        }
        let named = (lights.iter().enumerate())
            .map(|(i, desc)| {
                let name = format!("light[{i}]");
                let light = desc.build().map_err(|e| e.context(&name))?;
                let desc = desc.clone();
                Ok(NamedLight { name, desc, light })
            })
            .collect::<Result<Vec<_>>>()?;
        self.lights = named;
        self.lights_changed();
        Ok(())
    }

    pub fn remove_light(&mut self, name: &str) -> Result<()> {
        let i = (self.lights.iter().position(|l| l.name == name))
            .ok_or_else(|| invalid_arg!("no light named {name:?}"))?;
        self.lights.remove(i);
        self.lights_changed();
        Ok(())
    }

    fn lights_changed(&mut self) {
        if let Some(built) = &mut self.built {
            built.lights_changed = true;
        }
    }

    pub fn geometry_names(&self) -> impl Iterator<Item = &str> {
        self.geometries.iter().map(|g| g.name.as_str())
    }

    /// Adds the groom `name` (its files read and its curves converted now; a USD groom at
    /// a frame over the shutter of the scene's settings now, `GroomDesc::curves`), shaded by
    /// the material named `groom.material`, which may be defined later; the next render
    /// builds again. Returns the number of curve geometries it made: one, or one per
    /// BasisCurves prim of a USD stage. A name in use is refused.
    pub fn add_groom(&mut self, name: &str, groom: &GroomDesc) -> Result<usize> {
        let mut stages = StageRunner::new(&NoStages);
        let n = self.add_groom_in(name, groom, &mut stages, (0, 1, 1))?;
        self.add_times(stages.times());
        Ok(n)
    }

    /// [`Scene::add_groom`], its stages run by `stages` as part `part` = (index, grooms,
    /// files to read) of a description's.
    fn add_groom_in(
        &mut self,
        name: &str,
        groom: &GroomDesc,
        stages: &mut StageRunner,
        part: (usize, usize, usize),
    ) -> Result<usize> {
        self.check_free(name)?;
        let mut framing = Framing::default();
        let shutter = Shutter::of(&self.settings);
        let curves =
            (groom.curves(stages, part, &mut framing, shutter)).map_err(|e| self.error(name, e))?;
        let n = curves.len();
        let shapes = curves
            .into_iter()
            .map(|c| Shape::curves(c, groom.shape))
            .collect();
        self.add(name, shapes, &groom.material, framing, true);
        Ok(n)
    }

    /// Adds strands of control points laid out for their basis (`points.points` and its
    /// later time steps shared, not copied), drawn with `shape` and shaded by the material
    /// named `material`. The automatic camera frames them at every time step.
    pub fn add_control_points(
        &mut self,
        name: &str,
        points: ControlPoints,
        shape: GroomShape,
        material: &str,
    ) -> Result<()> {
        self.check_free(name)?;
        let mut framing = Framing::default();
        let steps = std::iter::once(points.points).chain(points.later_steps);
        let curves = (steps.enumerate())
            .map(|(k, step)| {
                framing.add_control_points(step.as_slice());
                let curves = Curves::from_control_points(
                    step,
                    &points.counts,
                    points.colors.clone(),
                    points.basis,
                    shape.built(),
                );
                curves.map_err(|e| e.context(format!("time step {k}")))
            })
            .collect::<Result<Vec<_>>>()
            .and_then(Curves::in_motion)
            .map_err(|e| self.error(name, e))?;
        let shapes = vec![Shape::curves(curves, shape)];
        self.add(name, shapes, material, framing, true);
        Ok(())
    }

    /// Adds the mesh `name` (its file read now); the next render builds again. A ground
    /// quad is left out of the automatic camera's frame: it is the stage, not the subject.
    pub fn add_mesh(&mut self, name: &str, mesh: &MeshDesc) -> Result<()> {
        let mut stages = StageRunner::new(&NoStages);
        self.add_mesh_in(name, mesh, &mut stages, (0, 1))?;
        self.add_times(stages.times());
        Ok(())
    }

    fn add_mesh_in(
        &mut self,
        name: &str,
        mesh: &MeshDesc,
        stages: &mut StageRunner,
        part: (usize, usize),
    ) -> Result<()> {
        self.check_free(name)?;
        let shutter = Shutter::of(&self.settings);
        let made = (stages.run(Stage::Read, part, |_| mesh.mesh(shutter)))
            .map_err(|e| self.error(name, e))?;
        let mut framing = Framing::default();
        if !matches!(mesh.source, MeshSource::Ground { .. }) {
            for step in std::iter::once(&made.positions).chain(&made.later_positions) {
                framing.add_mesh(step);
            }
        }
        self.add(
            name,
            vec![Shape::Mesh(made)],
            &mesh.material,
            framing,
            false,
        );
        Ok(())
    }

    /// Removes the groom or mesh `name`; the next render builds again.
    pub fn remove_geometry(&mut self, name: &str) -> Result<()> {
        let i = (self.geometries.iter().position(|g| g.name == name))
            .ok_or_else(|| invalid_arg!("no groom or mesh named {name:?}"))?;
        self.geometries.remove(i);
        self.built = None;
        Ok(())
    }

    fn check_free(&self, name: &str) -> Result<()> {
        match self.geometries.iter().any(|g| g.name == name) {
            true => Err(invalid_arg!(
                "{name}: a groom or mesh of that name exists: remove it first"
            )),
            false => Ok(()),
        }
    }

    fn add(
        &mut self,
        name: &str,
        shapes: Vec<Shape>,
        material: &str,
        framing: Framing,
        on_curves: bool,
    ) {
        self.geometries.push(Geometry {
            name: name.into(),
            shapes: shapes.into_iter().map(Shape::shared).collect(),
            material: material.into(),
            framing,
            on_curves,
        });
        self.built = None;
    }

    fn add_times(&mut self, t: StageTimes) {
        self.pending.read += t.read;
        self.pending.curves += t.curves;
        self.pending.bvh += t.bvh;
    }

    /// What the automatic camera frames: every geometry's frame.
    fn framing(&self) -> Framing {
        (self.geometries.iter()).fold(Framing::default(), |mut f, g| {
            f.merge(&g.framing);
            f
        })
    }

    /// Heap bytes of the curves the scene keeps to build again, for tests of memory.
    #[cfg(test)]
    pub(crate) fn kept_curves_bytes(&self) -> usize {
        (self.geometries.iter().flat_map(|g| &g.shapes))
            .map(|s| match s {
                Shape::Curves(c) | Shape::AutoCurves(c) => c.heap_bytes(),
                Shape::Mesh(_) => 0,
            })
            .sum()
    }

    /// The curves geometry `i` keeps to build again (its first curve set).
    #[cfg(test)]
    pub(crate) fn kept_curves(&self, i: usize) -> Option<&Curves> {
        match self.geometries.get(i)?.shapes.first()? {
            Shape::Curves(c) | Shape::AutoCurves(c) => Some(c),
            Shape::Mesh(_) => None,
        }
    }

    /// `e` with the scene's origin and `at` (an entry, a key) in front.
    fn error(&self, at: &str, e: Error) -> Error {
        match self.at(at) {
            at if at.is_empty() => e,
            at => e.context(at),
        }
    }

    fn at(&self, at: &str) -> String {
        match (self.origin.is_empty(), at.is_empty()) {
            (true, _) => at.to_string(),
            (false, true) => self.origin.clone(),
            (false, false) => format!("{}: {at}", self.origin),
        }
    }
}

#[cfg(test)]
mod tests;
