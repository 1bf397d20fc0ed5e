//! The one build every front end drives: geometries with their materials, the lights and
//! the view go in, a [`World`] comes out. Scene files (through [`SceneDescription::build`])
//! and the C ABI's scenes both end here, so that the same content gives the same world,
//! geometry ids and image, whichever way it came.
//!
//! [`SceneDescription::build`]: super::SceneDescription::build

use std::sync::Arc;

use crate::embree::{Device, PartsRule, SceneOptions};
use crate::error::{Error, Result};
use crate::render::Aovs;
use crate::render::integrator::World;
use crate::render::renderer::film_bytes;
use crate::render::settings::{CurveParts, RenderSettings};
use crate::scene::curves::Curves;
use crate::scene::detail_view::DetailView;
use crate::scene::footprint::{self, CurvesSize, available_bytes};
use crate::scene::light::Light;
use crate::scene::material::Material;
use crate::scene::mesh::Mesh;
use crate::scene::ribbons::{self, GroomShape};
use crate::scene::stages::{Stage, StageRunner};
use crate::scene::tracer::TracerBuilder;

/// One geometry as a front end hands it over.
#[derive(Clone)]
pub(crate) enum Shape {
    /// Curves traced as they are.
    Curves(Curves),
    /// Curves of the `auto` shape: each build shares them out between round, flat and
    /// level-of-detail ribbons for its view (`ribbons::share_out`).
    AutoCurves(Curves),
    Mesh(Mesh),
}

impl Shape {
    /// Curves given with `shape`: `auto` ones are shared out by each build for its view.
    pub fn curves(curves: Curves, shape: GroomShape) -> Shape {
        match shape {
            GroomShape::Auto => Shape::AutoCurves(curves),
            _ => Shape::Curves(curves),
        }
    }

    /// The same shape, whose clones share its curves' points ([`Curves::shared`]): what
    /// a caller that builds more than once (a C scene) keeps.
    pub fn shared(self) -> Shape {
        match self {
            Shape::Curves(c) => Shape::Curves(c.shared()),
            Shape::AutoCurves(c) => Shape::AutoCurves(c.shared()),
            mesh => mesh,
        }
    }

    /// Puts `kept` (these curves as a build gave them back, [`Assembled::curves`]) in the
    /// place of a curves shape's own; a mesh stays as it is.
    pub fn keep(&mut self, kept: Curves) {
        if let Shape::Curves(c) | Shape::AutoCurves(c) = self {
            *c = kept;
        }
    }
}

/// The curves a part is traced with: in spatial order (`Curves::spatially_ordered`) and,
/// for an `auto` part, shared out for `view` (as built, round, for a view that chooses no
/// detail); with `keep`, the ordered curves too, their
/// points shared with what is traced (`Curves::shared`).
fn traced_curves(
    curves: Curves,
    auto: bool,
    view: &DetailView,
    keep: bool,
) -> Result<(Vec<Curves>, Option<Curves>)> {
    let mut curves = curves.spatially_ordered()?;
    if keep {
        curves = curves.shared();
    }
    let kept = keep.then(|| curves.clone());
    let traced = if auto && view.chooses() {
        ribbons::share_out(curves, &view.camera, view.height, view.lod_pixels)?
    } else {
        vec![curves]
    };
    Ok((traced, kept))
}

/// How the build for a render of `settings` makes its scene: a large groom is cut into
/// parts as `curve_parts` says, for `auto` from the whole frame's camera samples (width x
/// height x spp, whatever the crop, so that every tile of a frame builds alike).
pub(crate) fn scene_options(settings: &RenderSettings) -> SceneOptions {
    let parts = match settings.curve_parts {
        CurveParts::Auto => PartsRule::ForSamples(
            u64::from(settings.width) * u64::from(settings.height) * u64::from(settings.spp),
        ),
        CurveParts::On => PartsRule::Always,
        CurveParts::Off => PartsRule::Never,
    };
    SceneOptions {
        parts,
        ..SceneOptions::default()
    }
}

/// What a build is made of, in geometry order.
#[derive(Default)]
pub(crate) struct Assembly {
    parts: Vec<Part>,
    /// Give the curves back ordered ([`Assembly::keeping_curves`]).
    keep_curves: bool,
}

struct Part {
    shape: Shape,
    material: Material,
    /// Put in front of this part's errors (`groom[2]`); empty for none.
    label: String,
}

/// A built world, and for each of its Embree geometries the index of the part it was
/// made from (an `auto` part may make several).
pub(crate) struct Assembled {
    pub world: World,
    pub built_from: Vec<usize>,
    /// For each part, its curves in spatial order with their points shared with `world`,
    /// for a caller that builds again; None for a mesh, and for every part unless
    /// [`Assembly::keeping_curves`].
    pub curves: Vec<Option<Curves>>,
}

impl Assembly {
    /// An assembly whose build gives its curves back ([`Assembled::curves`]): a caller
    /// that keeps its geometry to build again (a C scene) keeps those instead, and its
    /// later builds neither sort the strands nor copy their points again. Without it the
    /// ordered curves live only in the world, as a one-off build wants (a scene file).
    pub fn keeping_curves() -> Self {
        Assembly {
            keep_curves: true,
            ..Assembly::default()
        }
    }

    /// Adds a geometry with its material; `label` names it in errors.
    pub fn add(&mut self, shape: Shape, material: Material, label: impl Into<String>) {
        self.parts.push(Part {
            shape,
            material,
            label: label.into(),
        });
    }

    /// Builds the world for `view` and a render of `settings`: `auto` curves shared out
    /// for the view, the memory the BVH build and then the render's film
    /// (`renderer::film_bytes`) will need checked against what is available, then the BVH
    /// built (timed as [`Stage::Bvh`] in `stages`), large grooms in parts as `curve_parts`
    /// says ([`scene_options`]).
    pub fn build(
        self,
        device: Arc<Device>,
        lights: Vec<Light>,
        view: &DetailView,
        settings: &RenderSettings,
        stages: &mut StageRunner,
    ) -> Result<Assembled> {
        let film = film_bytes(settings, Aovs::default(), true);
        let options = scene_options(settings);
        let mut tracer = TracerBuilder::new(device, options)?;
        let (mut materials, mut built_from, mut sizes) = (Vec::new(), Vec::new(), Vec::new());
        let mut kept_curves = Vec::new();
        let parts = self.parts.len();
        for (i, part) in self.parts.into_iter().enumerate() {
            let auto = matches!(part.shape, Shape::AutoCurves(_));
            let labelled = |e: Error| {
                if part.label.is_empty() {
                    e
                } else {
                    e.context(&part.label)
                }
            };
            let added = match part.shape {
                Shape::Mesh(m) => {
                    tracer.add_mesh(m).map_err(labelled)?;
                    kept_curves.push(None);
                    1
                }
                // The build's part of the curves stage, timed with the conversion: the
                // spatial order, an `auto` groom's parts and Embree's geometries (a large
                // one cut into parts of its own).
                Shape::Curves(c) | Shape::AutoCurves(c) => {
                    stages.run(Stage::Curves, (i, parts), |_| {
                        let (pieces, kept) =
                            traced_curves(c, auto, view, self.keep_curves).map_err(labelled)?;
                        kept_curves.push(kept);
                        let n = pieces.len();
                        for piece in pieces {
                            sizes.push(CurvesSize::of(&piece, &options));
                            let added = if auto && view.chooses() {
                                tracer.add_view_curves(piece, view.clone())
                            } else {
                                tracer.add_curves(piece)
                            };
                            added.map_err(labelled)?;
                        }
                        Ok(n)
                    })?
                }
            };
            materials.extend(std::iter::repeat_n(part.material, added));
            built_from.extend(std::iter::repeat_n(i, added));
        }
        stages.report(Stage::Curves, 1.0)?;
        // What is built so far is held already: only Embree's part and the film are still
        // to come.
        let bvh = footprint::bvh_bytes(&sizes, &options);
        footprint::check_fits(
            &sizes,
            bvh.saturating_add(film),
            "more for the BVH build and the film",
            available_bytes(),
        )?;
        let tracer = stages.run(Stage::Bvh, (0, 1), |stages| tracer.build_with(stages))?;
        Ok(Assembled {
            world: World::new(tracer, materials, lights)?,
            built_from,
            curves: kept_curves,
        })
    }
}
