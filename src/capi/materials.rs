//! Materials through the C ABI: hair from parameters (optionally varied over the groom)
//! and diffuse surfaces, each returning the id that geometries name.

use super::bsdf::HtHairParams;
use super::scene::{HtScene, add_with_id};
use super::{Failure, HtStatus, non_null, read_vec3};
use crate::bsdf::diffuse::Diffuse;
use crate::error::invalid_arg;
use crate::scene::material::{HairColor, HairMaterial, Material};

/// How a hair material varies over the groom, deterministically from the seed, the
/// strand and the position along it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHairVariation {
    /// Per-strand spread of the absorption, in [0, 1]: sigma_a is scaled by a factor drawn
    /// from [1 - x, 1 + x].
    pub absorption_variation: f32,
    /// Per-strand spread of beta_m and beta_n, in [0, 1].
    pub roughness_variation: f32,
    /// Absorption at the tip relative to the root, > 0 (below 1: lighter tips).
    pub tip_absorption: f32,
    /// Take the absorption from the curves' per-point colours where they have them.
    pub use_vertex_colors: bool,
    /// Seed of the per-strand random choices.
    pub seed: u64,
}

/// No variation: every strand has the material's parameters, and seed 0.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_variation_default() -> HtHairVariation {
    let m = HairMaterial::default();
    HtHairVariation {
        absorption_variation: m.absorption_variation,
        roughness_variation: m.roughness_variation,
        tip_absorption: m.tip_absorption,
        use_vertex_colors: m.use_vertex_colors,
        seed: m.seed,
    }
}

/// Adds a hair material with the same parameters on every strand; writes its id (0, 1, ...
/// in the order materials are added) to `material_id`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_hair_material(
    scene: *mut HtScene,
    params: *const HtHairParams,
    material_id: *mut u32,
) -> HtStatus {
    let none = ht_hair_variation_default();
    ht_scene_add_hair_material_varied(scene, params, &none, material_id)
}

/// Adds a hair material whose parameters vary over the groom as `variation` says.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_hair_material_varied(
    scene: *mut HtScene,
    params: *const HtHairParams,
    variation: *const HtHairVariation,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        // SAFETY: non-NULL (checked); the host's structs.
        let p = unsafe { *non_null(params, "params")? };
        let v = unsafe { *non_null(variation, "variation")? };
        let material = HairMaterial {
            color: HairColor::SigmaA(p.sigma_a),
            eta: p.eta,
            beta_m: p.beta_m,
            beta_n: p.beta_n,
            alpha: p.alpha,
            absorption_variation: v.absorption_variation,
            roughness_variation: v.roughness_variation,
            tip_absorption: v.tip_absorption,
            use_vertex_colors: v.use_vertex_colors,
            seed: v.seed,
        };
        let prepared = material.prepare()?;
        push_material(scene, Material::Hair(Box::new(prepared)))
    })
}

/// Adds a Lambertian material for meshes, with linear RGB `albedo` in [0, 1].
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_diffuse_material(
    scene: *mut HtScene,
    albedo: *const f32,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        let diffuse = Diffuse::new(read_vec3(albedo, "albedo")?)?;
        push_material(scene, Material::Diffuse(diffuse))
    })
}

fn push_material(scene: &mut HtScene, material: Material) -> std::result::Result<u32, Failure> {
    let id =
        u32::try_from(scene.materials.len()).map_err(|_| invalid_arg!("too many materials"))?;
    scene.materials.push(material);
    Ok(id)
}
