//! A Huang point for one strand of a groom whose material varies per strand, as the
//! renderer shades it: the Huang model's point (`huang.rs`) with the variation of a scene's
//! materials (`materials.rs`), apart from both so that neither names the other.

use super::frame::HtHairFrame;
use super::huang::{HtHuangField, HtHuangPoint, HtHuangPrepared, fill_huang};
use super::materials::{HtHairVariation, huang_varied_material};
use super::prepared::strand_init;
use super::{HtStatus, boundary};
use crate::bsdf::HuangBsdf;
use crate::error::invalid_arg;

/// `ht_huang_point_init_world` for one strand of a groom whose parameters vary as a scene's
/// Huang material varies them (`ht_scene_add_huang_material`): the parameters of
/// `prepared`, varied by `*variation` for strand number `strand` at position `s` along it
/// (root 0, tip 1), with the strand's own reflectance colour `color[3]` when
/// `variation->use_vertex_colors` is 1 (NULL: none), as `ht_hair_point_init_strand` varies
/// Chiang's: the absorption spread per strand and toward the tip (or the strand's colour,
/// inverted at `ht_hair_params_default`'s beta_n), and `roughness` spread per strand by
/// `roughness_variation`. No handle per parameter set and no allocation: the varied model
/// is built inside the point, and the point equals, bit for bit, the one the renderer
/// shades that strand's hit with at the same `major`, `jitter` and `field`.
///
/// - `strand`, `s`, `color`, the variation's ranges: as `ht_hair_point_init_strand` takes
///   and refuses them; `frame`, `wo`, `major`, `jitter`, `field` as
///   `ht_huang_point_init_world`. Else `HT_ERR_INVALID_ARG`.
/// - Pointers: `prepared`, `variation`, `frame`, `wo`, `major`, `jitter`, `point` not NULL
///   (`HT_ERR_NULL_ARG`, checked first); others as `ht_huang_point_init_world`. On error
///   `*point` is untouched.
/// - Cost: an init plus the preparation of the varied parameters.
///
/// Any thread; `prepared` and `variation` may be shared, `point` must not be read
/// meanwhile. Not in the BSDF-only library.
///
/// # Safety
/// As `ht_huang_point_init_world`; `variation` NULL or an `HtHairVariation`; `color` NULL
/// or 3 floats.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn ht_huang_point_init_strand(
    prepared: *const HtHuangPrepared,
    variation: *const HtHairVariation,
    strand: u32,
    s: f32,
    color: *const f32,
    frame: *const HtHairFrame,
    wo: *const f32,
    major: *const f32,
    jitter: *const f32,
    field: HtHuangField,
    point: *mut HtHuangPoint,
) -> HtStatus {
    boundary(|| {
        let inputs = [(wo, "wo", 3), (major, "major", 3), (jitter, "jitter", 2)];
        let (v, framed, groom) =
            strand_init(prepared, variation, &inputs, frame, point, (s, color))?;
        // SAFETY: non-NULL (checked), a live handle (the caller's promise).
        let given = *unsafe { &(*prepared).bsdf }.params();
        let material = huang_varied_material(given, &v)?;
        material.check_variation()?;
        let base = material.base_params()?;
        // `huang_varied_material` made a Huang material, which always varies into one.
        let params = material
            .huang_varied(base, strand, s, groom)?
            .ok_or_else(|| invalid_arg!("the prepared BSDF is not of the Huang model"))?;
        let bsdf = HuangBsdf::new(&params)?;
        // SAFETY: non-NULL, aligned and clear of the inputs (checked).
        unsafe { fill_huang(point, &bsdf, framed, (major, jitter, field)) }
    })
}
