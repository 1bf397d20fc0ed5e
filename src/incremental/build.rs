//! When a scene builds, and its renders: the one place that decides whether a render can
//! use the last build.

use super::{Built, Scene};
use crate::description::Shutter;
use crate::description::assembly::Assembly;
use crate::error::{Result, invalid_arg};
use crate::render::renderer::{self, RenderOutput};
use crate::render::settings::RenderSettings;
use crate::render::{Aovs, Progress};
use crate::scene::camera::Camera;
use crate::scene::detail_view::DetailView;
use crate::scene::stages::{NoStages, StageProgress, StageRunner, StageTimes};

impl Scene {
    /// Renders with the scene's own settings ([`Scene::settings`]), building first where
    /// needed ([`Scene::build_for`]).
    pub fn render(&mut self, aovs: Aovs, progress: &dyn Progress) -> Result<RenderOutput> {
        let settings = self.settings;
        self.render_with(&settings, aovs, progress)
    }

    /// Renders with `settings`, building first where the last build cannot serve them
    /// ([`Scene::build_for`], its stages unreported).
    pub fn render_with(
        &mut self,
        settings: &RenderSettings,
        aovs: Aovs,
        progress: &dyn Progress,
    ) -> Result<RenderOutput> {
        self.build_for(settings, &NoStages)?;
        let camera = self.placed_camera(settings)?;
        let built = self.built.as_ref().expect("built above");
        renderer::render(&built.world, &camera, settings, aovs, progress)
    }

    /// Builds for the scene's own settings where needed; see [`Scene::build_for`].
    pub fn build(&mut self, progress: &dyn StageProgress) -> Result<bool> {
        let settings = self.settings;
        self.build_for(&settings, progress)
    }

    /// Builds now what a render with `settings` would build first, reporting the stages
    /// to `progress`; returns whether it built. The last build is kept unless geometry
    /// was added or removed since, a setting that [needs a build](crate::render::settings::Needs)
    /// changed, or the camera sees the `auto` curves larger than their shapes were chosen
    /// for (`renderer::serves`). A setting `isa` other than the device's is refused: the
    /// device's pin is what its scenes render with.
    pub fn build_for(
        &mut self,
        settings: &RenderSettings,
        progress: &dyn StageProgress,
    ) -> Result<bool> {
        self.build_in(settings, &mut StageRunner::new(progress))
    }

    /// [`Scene::build_for`], its stages run by `stages`.
    pub(super) fn build_in(
        &mut self,
        settings: &RenderSettings,
        stages: &mut StageRunner,
    ) -> Result<bool> {
        settings.validate().map_err(|e| self.error("render", e))?;
        if let Some(isa) = settings.isa.filter(|&isa| Some(isa) != self.device.isa()) {
            return Err(invalid_arg!(
                "isa = {isa}: this scene's device runs {}; make the scene on a device pinned \
                 to {isa} (Device::pinned, or ht_device_new_pinned(threads, \"{isa}\", ...))",
                self.device
                    .isa()
                    .map_or("the widest kernels this CPU runs".into(), |d| {
                        format!("{d} kernels")
                    })
            ));
        }
        if self.lights.is_empty() {
            let e = invalid_arg!("no lights: add a light (environment, distant or rect)");
            return Err(self.error("", e));
        }
        let camera = self.placed_camera(settings)?;
        let kept = self.built.as_ref().is_some_and(|b| {
            settings.build_change(&b.settings).is_none()
                && renderer::serves(&b.world, &camera, settings)
        });
        if kept {
            if self.built.as_ref().is_some_and(|b| b.lights_changed) {
                let lights = self.light_list();
                let built = self.built.as_mut().expect("kept");
                built.world.set_lights(lights)?;
                built.lights_changed = false;
            }
            return Ok(false);
        }
        self.built = None;
        let mut assembly = Assembly::keeping_curves();
        let mut part_of = Vec::new();
        for (i, g) in self.geometries.iter().enumerate() {
            let at = format!("{}.material", g.name);
            self.check_material(&g.material, g.on_curves)
                .map_err(|e| self.error(&at, e))?;
            let material = &self.materials[&g.material].prepared;
            for shape in &g.shapes {
                assembly.add(shape.clone(), material.clone(), self.at(&g.name));
                part_of.push(i);
            }
        }
        let view = DetailView::new(camera, settings.height, settings.lod_pixels);
        let assembled = assembly.build(
            self.device.clone(),
            self.light_list(),
            &view,
            settings,
            stages,
        )?;
        let mut kept = assembled.curves.into_iter();
        for shape in self.geometries.iter_mut().flat_map(|g| &mut g.shapes) {
            if let Some(curves) = kept.next().flatten() {
                shape.keep(curves);
            }
        }
        self.built = Some(Built {
            world: assembled.world,
            geometry_of: assembled.built_from.iter().map(|&p| part_of[p]).collect(),
            settings: *settings,
            lights_changed: false,
        });
        self.builds += 1;
        let (t, p) = (stages.times(), std::mem::take(&mut self.pending));
        self.stages = StageTimes {
            read: t.read + p.read,
            curves: t.curves + p.curves,
            bvh: t.bvh + p.bvh,
        };
        Ok(true)
    }

    /// The camera of a render with `settings`: the scene's, for their image's aspect, or
    /// one that frames the geometry.
    pub fn placed_camera(&self, settings: &RenderSettings) -> Result<Camera> {
        let aspect = settings.width as f32 / settings.height as f32;
        let shutter = Shutter::of(settings);
        (self.camera.build(&self.framing(), aspect, shutter)).map_err(|e| self.error("camera", e))
    }

    fn light_list(&self) -> Vec<crate::scene::light::Light> {
        self.lights.iter().map(|l| l.light.clone()).collect()
    }

    /// The last build's world, for tests of its insides.
    #[cfg(test)]
    pub(crate) fn world(&self) -> Option<&crate::render::integrator::World> {
        self.built.as_ref().map(|b| &b.world)
    }
}
