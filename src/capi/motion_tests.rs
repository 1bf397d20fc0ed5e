//! Strands in motion through the C ABI: the control points of each time step from host
//! arrays and the shutter by name render as the Rust `Scene` renders them; bad steps are
//! refused with the step named.

use super::HtStatus;
use super::geometry::*;
use super::lights::*;
use super::scene_tests::{Handles, fails, last_error};
use super::settings_tests::Named;
use crate::Scene;
use crate::bsdf::HairParams;
use crate::description::{EnvironmentSource, LightDesc, MaterialDesc};
use crate::embree::{CurveBasis, Device, SharedBuffer};
use crate::incremental::ControlPoints;
use crate::render::{Aovs, NoProgress};
use crate::scene::{GroomShape, HairColor, HairMaterial};
use std::ptr::null;
use std::sync::Arc;

const SIZE: (u32, u32) = (40, 30);
const SETTINGS: [(&str, &str); 5] = [
    ("spp", "4"),
    ("seed", "3"),
    ("threads", "2"),
    ("shutter_open", "-0.5"),
    ("shutter_close", "0.5"),
];
const SKY: [f32; 3] = [0.5, 0.5, 0.6];
const STRANDS: usize = 400;

/// Linear strands of 4 control points standing on a 20 x 20 grid, and the same strands
/// `dx` along x.
fn grid(dx: f32) -> Vec<[f32; 4]> {
    (0..STRANDS)
        .flat_map(|s| {
            let (x, z) = (
                (s % 20) as f32 * 0.1 - 1.0 + dx,
                (s / 20) as f32 * 0.1 - 1.0,
            );
            (0..4).map(move |k| [x + 0.05 * k as f32, k as f32 * 0.4 - 0.6, z, 0.01])
        })
        .collect()
}

fn c_render(pairs: &[(&str, &str)], steps: &[Vec<[f32; 4]>]) -> Vec<u32> {
    let h = Handles::new();
    let hair = h.hair_material();
    let counts = vec![4u32; STRANDS];
    let desc = HtCurvesXyzr {
        strand_count: STRANDS,
        point_counts: counts.as_ptr(),
        point_count: steps[0].len(),
        points: steps[0].as_ptr().cast(),
        colors: null(),
        basis: HT_CURVE_LINEAR,
        shape: HT_CURVE_ROUND,
    };
    let later: Vec<*const f32> = steps[1..].iter().map(|s| s.as_ptr().cast()).collect();
    unsafe {
        let s = ht_scene_add_curves_xyzr_motion(
            h.scene,
            &desc,
            later.as_ptr(),
            later.len(),
            hair,
            &mut 0,
        );
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        assert_eq!(
            ht_scene_add_environment(h.scene, SKY.as_ptr()),
            HtStatus::HT_OK
        );
    }
    let (w, h_) = (SIZE.0.to_string(), SIZE.1.to_string());
    let mut all = vec![("width", w.as_str()), ("height", h_.as_str())];
    all.extend(pairs);
    let (s, rgb) = Named::new(&all).render_rgb(h.scene, (SIZE.0 * SIZE.1) as usize);
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    rgb.iter().map(|v| v.to_bits()).collect()
}

fn rust_render(steps: &[Vec<[f32; 4]>]) -> Vec<u32> {
    let mut scene = Scene::new(Arc::new(Device::new(Some(2)).unwrap()));
    (scene.settings.width, scene.settings.height) = SIZE;
    for (k, v) in SETTINGS {
        scene.settings.set(k, v).unwrap();
    }
    let hair = HairMaterial {
        color: HairColor::SigmaA(HairParams::default().sigma_a),
        ..HairMaterial::default()
    };
    (scene.set_material("hair", &MaterialDesc::Hair(hair))).unwrap();
    let points = ControlPoints {
        points: SharedBuffer::from(steps[0].clone()),
        later_steps: steps[1..].iter().map(|s| s.clone().into()).collect(),
        counts: vec![4; STRANDS],
        colors: None,
        basis: CurveBasis::Linear,
    };
    (scene.add_control_points("grid", points, GroomShape::Round, "hair")).unwrap();
    let sky = LightDesc::Environment {
        source: EnvironmentSource::Uniform(SKY),
        rotation_deg: 0.0,
        scale: 1.0,
    };
    scene.add_light(&sky).unwrap();
    let out = scene.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// Three time steps from host arrays and the shutter set by name render bit for bit as the
/// Rust `Scene` renders the same control points; without the shutter, the same strands
/// render otherwise (at the opening).
#[test]
fn strands_in_motion_from_c_render_as_from_rust() {
    let steps = [grid(0.0), grid(0.05), grid(0.2)];
    let c = c_render(&SETTINGS, &steps);
    assert_eq!(c, rust_render(&steps));
    let still = c_render(&SETTINGS[..3], &steps);
    assert_ne!(c, still);
}

/// NULL later points, a NaN at a later step, and more steps than Embree takes are refused,
/// the message naming the array or the step.
#[test]
fn bad_time_steps_from_c_are_refused() {
    let h = Handles::new();
    let hair = h.hair_material();
    let counts = vec![4u32; STRANDS];
    let first = grid(0.0);
    let desc = HtCurvesXyzr {
        strand_count: STRANDS,
        point_counts: counts.as_ptr(),
        point_count: first.len(),
        points: first.as_ptr().cast(),
        colors: null(),
        basis: HT_CURVE_LINEAR,
        shape: HT_CURVE_ROUND,
    };
    let add = |later: *const *const f32, n: usize| unsafe {
        ht_scene_add_curves_xyzr_motion(h.scene, &desc, later, n, hair, &mut 0)
    };
    fails(add(null(), 1), HtStatus::HT_ERR_NULL_ARG, "later_points");
    let missing = [null::<f32>()];
    fails(
        add(missing.as_ptr(), 1),
        HtStatus::HT_ERR_NULL_ARG,
        "later_points[0]",
    );
    let mut nan = grid(0.1);
    nan[9][2] = f32::NAN;
    let second = grid(0.1);
    let later = [second.as_ptr().cast::<f32>(), nan.as_ptr().cast()];
    fails(
        add(later.as_ptr(), 2),
        HtStatus::HT_ERR_INVALID_ARG,
        "time step 2",
    );
    let many = vec![second.as_ptr().cast::<f32>(); HT_MAX_TIME_STEPS];
    fails(
        add(many.as_ptr(), HT_MAX_TIME_STEPS),
        HtStatus::HT_ERR_INVALID_ARG,
        "later_step_count",
    );
    // The good step alone is taken.
    assert_eq!(add(later.as_ptr(), 1), HtStatus::HT_OK, "{}", last_error());
}
