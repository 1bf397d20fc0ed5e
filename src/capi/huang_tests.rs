//! Hair materials of the Huang model through the C ABI: a scene of them renders bit for bit
//! as the Rust `Scene` renders the same scene, a Chiang material turned into one without a
//! new build renders as a fresh scene, and bad parameters are refused, naming them.

use super::HtStatus;
use super::geometry::*;
use super::huang::{HtHuangParams, ht_huang_params_default};
use super::materials::*;
use super::same_scene_tests::{c_lights, c_pixels, rust_pixels, rust_scene};
use super::scene_tests::{Handles, fails, last_error, xyzr_desc};
use crate::description::MaterialDesc;
use crate::embree::{CurveBasis, SharedBuffer};
use crate::incremental::ControlPoints;
use crate::scene::{GroomShape, HairColor, HairMaterial, HairModel};
use std::ptr::null;

const STRANDS: usize = 144;

/// Linear strands of 4 control points on a 12 x 12 grid, bent along x: every other one
/// thick enough to be wider than its pixel (the near field at camera hits), the others
/// thinner (the far field).
fn grid() -> Vec<[f32; 4]> {
    (0..STRANDS)
        .flat_map(|s| {
            let (x, z) = ((s % 12) as f32 * 0.15 - 0.8, (s / 12) as f32 * 0.15 - 0.8);
            let r = if s % 2 == 0 { 0.05 } else { 0.006 };
            (0..4).map(move |k| {
                let k = k as f32;
                [x + 0.04 * k * k, k * 0.4 - 0.6, z, r]
            })
        })
        .collect()
}

/// A Huang material that varies over the groom.
fn params() -> (HtHuangParams, HtHairVariation) {
    let params = HtHuangParams {
        roughness: 0.25,
        aspect: 0.55,
        alpha: -3.0,
        ..ht_huang_params_default()
    };
    let variation = HtHairVariation {
        absorption_variation: 0.3,
        roughness_variation: 0.4,
        tip_absorption: 0.6,
        seed: 5,
        ..ht_hair_variation_default()
    };
    (params, variation)
}

/// The grid through the C ABI with the material `material` makes, in the lights and
/// camera of `same_scene_tests`, rendered, edited by `edit`, rendered again: the pixels'
/// bits and the scene's builds.
fn c_render(material: impl Fn(&Handles) -> u32, edit: impl Fn(&Handles, u32)) -> (Vec<u32>, u64) {
    let h = Handles::new();
    let id = material(&h);
    let (points, counts) = (grid(), vec![4u32; STRANDS]);
    let desc = xyzr_desc(&points, &counts);
    let s = unsafe { ht_scene_add_curves_xyzr(h.scene, &desc, id, &mut 0) };
    assert_eq!(s, HtStatus::HT_OK);
    c_lights(&h, true);
    c_pixels(&h);
    edit(&h, id);
    let rgb = c_pixels(&h);
    (rgb, h.scene().scene.builds())
}

/// The same scene through the Rust `Scene`, its material the scene file's `model = "huang"`.
fn rust_render() -> Vec<u32> {
    let mut scene = rust_scene(true);
    let (p, v) = params();
    let hair = HairMaterial {
        color: HairColor::SigmaA(p.sigma_a),
        eta: p.eta,
        alpha: p.alpha,
        absorption_variation: v.absorption_variation,
        roughness_variation: v.roughness_variation,
        tip_absorption: v.tip_absorption,
        seed: v.seed,
        model: HairModel::Huang {
            roughness: p.roughness,
            aspect: p.aspect,
        },
        ..HairMaterial::default()
    };
    (scene.set_material("hair", &MaterialDesc::Hair(hair))).unwrap();
    let points = ControlPoints {
        points: SharedBuffer::from(grid()),
        later_steps: Vec::new(),
        counts: vec![4; STRANDS],
        colors: None,
        basis: CurveBasis::Linear,
    };
    (scene.add_control_points("grid", points, GroomShape::Round, "hair")).unwrap();
    rust_pixels(&mut scene)
}

fn add_huang(h: &Handles) -> u32 {
    let (p, v) = params();
    let mut id = u32::MAX;
    let s = unsafe { ht_scene_add_huang_material(h.scene, &p, &v, &mut id) };
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    id
}

fn set_huang(h: &Handles, id: u32) {
    let (p, v) = params();
    let s = unsafe { ht_scene_set_huang_material(h.scene, id, &p, &v) };
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
}

/// A Huang material added through C renders the Rust scene's bits; a Chiang material
/// given the same Huang parameters on the built scene renders them too, without a build.
#[test]
fn huang_materials_from_c_render_as_from_rust() {
    let want = rust_render();
    assert!(want.iter().any(|&v| f32::from_bits(v) > 0.0));
    let (added, builds) = c_render(add_huang, |_, _| ());
    assert_eq!(added, want, "added through C");
    assert_eq!(builds, 1);
    let (edited, builds) = c_render(|h| h.hair_material(), set_huang);
    assert_eq!(edited, want, "set on a built Chiang material");
    assert_eq!(builds, 1, "a material edit needs no build");
}

/// Bad parameters and variations are refused naming the value, NULLs as NULL, and a
/// refused edit leaves the material as it was.
#[test]
fn bad_huang_materials_are_refused() {
    let h = Handles::new();
    let (p, v) = params();
    let mut id = u32::MAX;
    for (bad, words) in [
        (
            HtHuangParams { aspect: 1.5, ..p },
            "aspect = 1.5: must be in [0.05, 1]",
        ),
        (
            HtHuangParams {
                aspect: f32::NAN,
                ..p
            },
            "aspect = NaN",
        ),
        (
            HtHuangParams {
                roughness: 2.0,
                ..p
            },
            "roughness = 2",
        ),
    ] {
        let s = unsafe { ht_scene_add_huang_material(h.scene, &bad, null(), &mut id) };
        fails(s, HtStatus::HT_ERR_INVALID_ARG, words);
    }
    let uneven = HtHairVariation {
        roughness_variation: 1.5,
        ..v
    };
    let s = unsafe { ht_scene_add_huang_material(h.scene, &p, &uneven, &mut id) };
    fails(s, HtStatus::HT_ERR_INVALID_ARG, "roughness_variation = 1.5");
    let s = unsafe { ht_scene_add_huang_material(h.scene, null(), &v, &mut id) };
    fails(s, HtStatus::HT_ERR_NULL_ARG, "params is NULL");
    assert_eq!(id, u32::MAX, "nothing added");
    let id = add_huang(&h);
    let before = h.scene().scene.material("0").cloned();
    let bad = HtHuangParams { aspect: 0.0, ..p };
    let s = unsafe { ht_scene_set_huang_material(h.scene, id, &bad, null()) };
    fails(s, HtStatus::HT_ERR_INVALID_ARG, "aspect = 0");
    let s = unsafe { ht_scene_set_huang_material(h.scene, id + 1, &p, null()) };
    assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
    assert_eq!(h.scene().scene.material("0").cloned(), before);
}
