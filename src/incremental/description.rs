//! A scene from its description: every value checked, files read, and, for
//! [`SceneDescription::build`], the first build.

use std::sync::Arc;

use super::Scene;
use crate::description::SceneDescription;
use crate::embree::Device;
use crate::error::{Result, invalid_arg};
use crate::scene::footprint::available_bytes;
use crate::scene::stages::{NoStages, Stage, StageProgress, StageRunner};

impl Scene {
    /// The scene `desc` describes, on `device`: its settings, camera, materials and lights,
    /// and its grooms and meshes read and converted (named `groom[0]`, ..., `mesh[0]`, ...,
    /// `light[0]`, ...). Cheap checks (settings, materials and their assignment, lights,
    /// the memory a procedural groom needs) come before any groom is read, so that a typo
    /// does not wait for a large groom. Nothing is built until the first render.
    pub fn from_description(desc: &SceneDescription, device: Arc<Device>) -> Result<Scene> {
        Scene::described(desc, device, &mut StageRunner::new(&NoStages))
    }

    /// [`Scene::from_description`], reading and converting as stages of `stages`.
    fn described(
        desc: &SceneDescription,
        device: Arc<Device>,
        stages: &mut StageRunner,
    ) -> Result<Scene> {
        let mut scene = Scene::new(device);
        scene.origin = desc.origin.clone();
        scene.settings = desc.render;
        (desc.render.validate()).map_err(|e| scene.error("render", e))?;
        for (name, m) in &desc.materials {
            (scene.set_material(name, m))
                .map_err(|e| scene.error(&format!("materials.{name}"), e))?;
        }
        let assigned = |kind: &str, i: usize, name: &str, hair: bool| {
            (scene.check_material(name, hair))
                .map_err(|e| scene.error(&format!("{kind}[{i}].material"), e))
        };
        for (i, g) in desc.grooms.iter().enumerate() {
            assigned("groom", i, &g.material, true)?;
        }
        for (i, m) in desc.meshes.iter().enumerate() {
            assigned("mesh", i, &m.material, false)?;
        }
        for (i, l) in desc.lights.iter().enumerate() {
            let name = format!("light[{i}]");
            scene.set_light(&name, l).map_err(|e| scene.error("", e))?;
        }
        scene.camera = desc.camera.clone();
        desc.check_memory(available_bytes())?;
        let (grooms, reads) = (desc.grooms.len(), desc.grooms.len() + desc.meshes.len());
        for (i, g) in desc.grooms.iter().enumerate() {
            scene.add_groom_in(&format!("groom[{i}]"), g, stages, (i, grooms, reads))?;
        }
        for (i, m) in desc.meshes.iter().enumerate() {
            scene.add_mesh_in(&format!("mesh[{i}]"), m, stages, (grooms + i, reads))?;
        }
        // A scene without grooms (or meshes) still goes through every stage.
        stages.report(Stage::Read, 1.0)?;
        stages.report(Stage::Curves, 1.0)?;
        Ok(scene)
    }
}

impl SceneDescription {
    /// The scene this describes ([`Scene::from_description`]), built for its settings on
    /// `device`.
    pub fn build(&self, device: Arc<Device>) -> Result<Scene> {
        self.build_with(device, &NoStages)
    }

    /// [`build`](Self::build), reporting each stage's progress to `progress` and timing
    /// it in [`Scene::stages`].
    pub fn build_with(&self, device: Arc<Device>, progress: &dyn StageProgress) -> Result<Scene> {
        if self.lights.is_empty() {
            return Err(invalid_arg!(
                "{}: no lights: add a [[light]] (environment, distant or rect)",
                self.origin
            ));
        }
        let mut stages = StageRunner::new(progress);
        let mut scene = Scene::described(self, device, &mut stages)?;
        let settings = scene.settings;
        scene.build_in(&settings, &mut stages)?;
        Ok(scene)
    }
}
