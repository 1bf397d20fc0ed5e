//! Materials through the C ABI: hair of either model from parameters (optionally varied
//! over the groom) and diffuse surfaces, each returning the id that geometries name; their
//! parameters can be changed later without a new build.

use super::bsdf::HtHairParams;
use super::huang::HtHuangParams;
use super::scene::{HtScene, add_with_id, scene_mut};
use super::{Failure, HtStatus, boundary, read_host, read_vec3};
use crate::bsdf::{HairParams, HuangParams};
use crate::description::MaterialDesc;
use crate::error::invalid_arg;
use crate::scene::{HairColor, HairMaterial, HairModel};

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
    /// 1: take the absorption from the curves where they give one (their per-point colours,
    /// or the melanin of a USD file's strands, taken as it is); 0: ignore it. Any other value is refused (`HT_ERR_INVALID_ARG`). An integer rather
    /// than a `bool`, so that no byte the host stores here is undefined behaviour.
    pub use_vertex_colors: u8,
    /// Seed of the per-strand random choices.
    pub seed: u64,
}

/// No variation: every strand has the material's parameters, and seed 0. Cannot fail;
/// any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_variation_default() -> HtHairVariation {
    let m = HairMaterial::default();
    HtHairVariation {
        absorption_variation: m.absorption_variation,
        roughness_variation: m.roughness_variation,
        tip_absorption: m.tip_absorption,
        use_vertex_colors: u8::from(m.use_vertex_colors),
        seed: m.seed,
    }
}

/// Adds a hair material with the same parameters on every strand (ranges as for
/// `ht_hair_prepare`); writes its id (0, 1, ... in the order materials are added) to
/// `material_id`.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `params` or `material_id` NULL);
/// `HT_ERR_INVALID_ARG` (a parameter NaN, infinite or out of range, `material_id`
/// misaligned). Nothing is added on failure.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `params` is NULL or
/// readable; `material_id` is NULL or points to a writable `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_hair_material(
    scene: *mut HtScene,
    params: *const HtHairParams,
    material_id: *mut u32,
) -> HtStatus {
    let none = ht_hair_variation_default();
    // SAFETY: the caller's promises, and `none` lives across the call.
    unsafe { ht_scene_add_hair_material_varied(scene, params, &none, material_id) }
}

/// Adds a hair material whose parameters vary over the groom as `variation` says (its
/// ranges on `HtHairVariation`).
///
/// Statuses: as `ht_scene_add_hair_material`, and `HT_ERR_NULL_ARG` for `variation` NULL,
/// `HT_ERR_INVALID_ARG` for a variation out of range (`use_vertex_colors` not 0 or 1).
///
/// One thread at a time per scene.
///
/// # Safety
/// As `ht_scene_add_hair_material`; `variation` is NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_hair_material_varied(
    scene: *mut HtScene,
    params: *const HtHairParams,
    variation: *const HtHairVariation,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        let material = hair_material(params, &read_host(variation, "variation")?)?;
        Ok(scene.add_material(&material)?)
    })
}

/// Adds a hair material of the Huang model (elliptical fibres: `HtHuangParams`, ranges as
/// for `ht_huang_prepare`), varied over the groom as `variation` says (NULL: no
/// variation; `roughness_variation` spreads `roughness`), and writes its id, counted with
/// the other materials, to `material_id`. It goes on curves as a Chiang hair material
/// does. The renderer orients each section by world up made perpendicular to the tangent
/// (world +x where the tangent is vertical), takes the far field on strands no wider than
/// their pixel and, where lights are sampled, at bounces too (at four offsets there), and
/// the near field elsewhere (docs/conventions.md, section 4b). A groom's colours
/// (`use_vertex_colors`) are inverted at `ht_hair_params_default`'s beta_n, as a scene
/// file's `model = "huang"` material inverts them.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `params` or `material_id` NULL);
/// `HT_ERR_INVALID_ARG` (a parameter or variation out of range, naming it; `material_id`
/// misaligned). Nothing is added on failure.
///
/// One thread at a time per scene.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `params` and
/// `variation` are NULL or readable; `material_id` is NULL or points to a writable
/// `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_huang_material(
    scene: *mut HtScene,
    params: *const HtHuangParams,
    variation: *const HtHairVariation,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        let material = huang_material(params, variation)?;
        Ok(scene.add_material(&material)?)
    })
}

/// Gives material `material_id` the Huang model with new parameters and variation (as
/// `ht_scene_add_huang_material` takes them), without a new build: the next render is the
/// one of a scene built with them. A hair material of either model may change model this
/// way, or back with `ht_scene_set_hair_material`.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `params` NULL); `HT_ERR_INVALID_ARG` (as
/// `ht_scene_set_hair_material`). On failure the material is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `params` and
/// `variation` are NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_huang_material(
    scene: *mut HtScene,
    material_id: u32,
    params: *const HtHuangParams,
    variation: *const HtHairVariation,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let material = huang_material(params, variation)?;
        Ok(scene.set_material(material_id, &material)?)
    })
}

/// The Huang model's hair material of the host's parameters and variation (NULL: none).
fn huang_material(
    params: *const HtHuangParams,
    variation: *const HtHairVariation,
) -> std::result::Result<MaterialDesc, Failure> {
    let p = read_host(params, "params")?.into();
    let material = huang_varied_material(p, &variation_or_none(variation)?)?;
    Ok(MaterialDesc::Hair(material))
}

/// The Huang model's hair material of parameters `p` varied as `v` says, as a scene takes
/// it (`use_vertex_colors` checked; the other ranges by `HairMaterial::prepare` or
/// `check_variation`): the colour inversion's beta_n and the unused beta_m are the
/// defaults, as a scene file leaves them.
pub(super) fn huang_varied_material(
    p: HuangParams,
    v: &HtHairVariation,
) -> std::result::Result<HairMaterial, Failure> {
    let shared = HairParams {
        sigma_a: p.sigma_a,
        eta: p.eta,
        alpha: p.alpha,
        ..HairParams::default()
    };
    let model = HairModel::Huang {
        roughness: p.roughness,
        aspect: p.aspect,
    };
    Ok(HairMaterial {
        model,
        ..varied_material(shared, v)?
    })
}

/// Gives hair material `material_id` new parameters and variation (as
/// `ht_scene_add_hair_material_varied` takes them), without a new build: the next render
/// is the one of a scene built with them. `variation` may be NULL: no variation.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `params` NULL); `HT_ERR_INVALID_ARG` (a value
/// out of range as for `ht_scene_add_hair_material_varied`, no material `material_id`, a
/// diffuse material, or a `beta_n` other than the one a USD groom's melanin colours were
/// derived at, for a material with `use_vertex_colors`: add the groom again instead).
/// On failure the material is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `params` and
/// `variation` are NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_hair_material(
    scene: *mut HtScene,
    material_id: u32,
    params: *const HtHairParams,
    variation: *const HtHairVariation,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let material = hair_material(params, &variation_or_none(variation)?)?;
        Ok(scene.set_material(material_id, &material)?)
    })
}

/// The hair material of the host's parameters and variation (checked when the scene
/// takes it).
fn hair_material(
    params: *const HtHairParams,
    variation: &HtHairVariation,
) -> std::result::Result<MaterialDesc, Failure> {
    let p = read_host(params, "params")?;
    Ok(MaterialDesc::Hair(varied_material(p.into(), variation)?))
}

/// The host's variation; NULL is none.
fn variation_or_none(
    variation: *const HtHairVariation,
) -> std::result::Result<HtHairVariation, Failure> {
    if variation.is_null() {
        Ok(ht_hair_variation_default())
    } else {
        read_host(variation, "variation")
    }
}

/// The hair material of parameters `p` varied as `v` says (`use_vertex_colors` checked;
/// the other ranges by `HairMaterial::prepare` or `check_variation`).
pub(super) fn varied_material(
    p: HairParams,
    v: &HtHairVariation,
) -> std::result::Result<HairMaterial, Failure> {
    Ok(HairMaterial {
        color: HairColor::SigmaA(p.sigma_a),
        eta: p.eta,
        beta_m: p.beta_m,
        beta_n: p.beta_n,
        alpha: p.alpha,
        absorption_variation: v.absorption_variation,
        roughness_variation: v.roughness_variation,
        tip_absorption: v.tip_absorption,
        use_vertex_colors: match v.use_vertex_colors {
            0 => false,
            1 => true,
            other => {
                return Err(
                    invalid_arg!("variation->use_vertex_colors = {other}: must be 0 or 1").into(),
                );
            }
        },
        seed: v.seed,
        model: HairModel::Chiang,
    })
}

/// Adds a Lambertian material for meshes, with linear RGB `albedo` in [0, 1] per channel;
/// writes its id.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `albedo` or `material_id` NULL);
/// `HT_ERR_INVALID_ARG` (a channel NaN or outside [0, 1], a misaligned pointer).
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `albedo` is NULL or
/// points to 3 readable floats; `material_id` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_diffuse_material(
    scene: *mut HtScene,
    albedo: *const f32,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        let albedo = read_vec3(albedo, "albedo")?.to_array();
        Ok(scene.add_material(&MaterialDesc::Diffuse { albedo })?)
    })
}

/// Gives diffuse material `material_id` a new `albedo` (3 floats, linear RGB, each in
/// [0, 1]), without a new build: the next render is the one of a scene built with it.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `albedo` NULL); `HT_ERR_INVALID_ARG` (a channel
/// NaN or outside [0, 1], a misaligned pointer, no material `material_id`, a hair
/// material). On failure the material is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `albedo` is NULL or
/// points to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_diffuse_material(
    scene: *mut HtScene,
    material_id: u32,
    albedo: *const f32,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let albedo = read_vec3(albedo, "albedo")?.to_array();
        Ok(scene.set_material(material_id, &MaterialDesc::Diffuse { albedo })?)
    })
}
