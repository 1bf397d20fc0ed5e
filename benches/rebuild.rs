//! A C host's scene built and built again: a fur ball of copied xyzr points (10^6 strands
//! x 16 linear round segments unless `-- STRANDS` says otherwise), then a triangle added
//! before each of a few more builds (added geometry makes the next build start over).
//! Prints each `ht_scene_build_with`'s seconds and the rebuilds' median. The first build
//! orders the strands, cuts the groom into parts and bounds them; the scene keeps all of
//! it, so a rebuild is left with Embree's top-level scene (docs/large-grooms.md, "A C
//! scene builds again without sorting or cutting").
//!
//! `cargo bench -p hairtrace-benches --bench rebuild [-- STRANDS]`

use std::ptr::{null, null_mut};
use std::time::Instant;

use hairtrace::capi::HtStatus;
use hairtrace::capi::bsdf::ht_hair_params_default;
use hairtrace::capi::geometry::{
    HT_CURVE_LINEAR, HT_CURVE_ROUND, HtCurvesXyzr, ht_scene_add_curves_xyzr, ht_scene_add_mesh,
};
use hairtrace::capi::lights::ht_scene_add_environment;
use hairtrace::capi::materials::{ht_scene_add_diffuse_material, ht_scene_add_hair_material};
use hairtrace::capi::render::ht_scene_build_with;
use hairtrace::capi::scene::{ht_device_free, ht_device_new, ht_scene_free, ht_scene_new};
use hairtrace::capi::settings::{ht_settings_free, ht_settings_new, ht_settings_set};
use hairtrace::scene::FurBall;

const REBUILDS: usize = 5;

fn ok(status: HtStatus) {
    assert_eq!(status, HtStatus::HT_OK, "{}", unsafe {
        std::ffi::CStr::from_ptr(hairtrace::capi::ht_last_error()).to_string_lossy()
    });
}

fn main() {
    let strands: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let ball = FurBall {
        strands,
        segments: 16,
        ..FurBall::default()
    }
    .build()
    .expect("fur ball");
    let points: Vec<[f32; 4]> = (ball.points.iter().zip(&ball.radii))
        .map(|(&[x, y, z], &r)| [x, y, z, r])
        .collect();
    let desc = HtCurvesXyzr {
        strand_count: ball.counts.len(),
        point_counts: ball.counts.as_ptr(),
        point_count: points.len(),
        points: points.as_ptr().cast(),
        colors: null(),
        basis: HT_CURVE_LINEAR,
        shape: HT_CURVE_ROUND,
    };
    // SAFETY: live handles and locals; the scene copies the points it is given.
    unsafe {
        let (mut device, mut scene) = (null_mut(), null_mut());
        ok(ht_device_new(2, &mut device));
        ok(ht_scene_new(device, &mut scene));
        let mut settings = null_mut();
        ok(ht_settings_new(&mut settings));
        for (key, value) in [(c"width", c"64"), (c"height", c"64"), (c"threads", c"2")] {
            ok(ht_settings_set(settings, key.as_ptr(), value.as_ptr()));
        }
        let (mut hair, mut floor) = (0, 0);
        ok(ht_scene_add_hair_material(
            scene,
            &ht_hair_params_default(),
            &mut hair,
        ));
        ok(ht_scene_add_diffuse_material(
            scene,
            [0.5f32; 3].as_ptr(),
            &mut floor,
        ));
        ok(ht_scene_add_curves_xyzr(scene, &desc, hair, &mut 0));
        ok(ht_scene_add_environment(scene, [0.5f32; 3].as_ptr()));
        let build = || {
            let t0 = Instant::now();
            ok(ht_scene_build_with(scene, settings, None, null_mut()));
            t0.elapsed().as_secs_f64()
        };
        println!("{strands} strands x 16 linear round segments, copied, 2 threads");
        println!("first build: {:.2} s", build());
        let triangle = [-3.0f32, -3.0, -1.5, 3.0, -3.0, -1.5, 0.0, 3.0, -1.5];
        let mut rebuilds: Vec<f64> = (0..REBUILDS)
            .map(|_| {
                let at = triangle.as_ptr();
                ok(ht_scene_add_mesh(
                    scene,
                    3,
                    at,
                    null(),
                    1,
                    [0u32, 1, 2].as_ptr(),
                    floor,
                    &mut 0,
                ));
                build()
            })
            .collect();
        println!("rebuilds: {rebuilds:.2?} s");
        rebuilds.sort_by(f64::total_cmp);
        println!("median rebuild: {:.2} s", rebuilds[REBUILDS / 2]);
        ok(ht_settings_free(settings));
        ok(ht_scene_free(scene));
        ok(ht_device_free(device));
    }
}
