//! A camera moving over the shutter, end to end: blurred against the mean of static
//! renders across the shutter, a camera that stays put alike with and without blur, and
//! crops and thread counts with it.

use glam::Vec3;

use super::motion::{
    NOISE_BOUND, STATIC_TIMES, ball, image_through, mean_square_difference, settings, world,
};
use super::render::assert_deterministic_through;
use crate::embree::{CurveBasis, CurveShape};
use crate::render::settings::{Allocation, RenderSettings};
use crate::scene::Camera;

/// A camera that slides to the right and up, turns to keep a point beside the ball in
/// view, rolls a little and zooms in over the shutter: every part of its pose moves.
fn moving_camera() -> Camera {
    let open = Camera::new(Vec3::new(-0.6, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0).unwrap();
    let close = Camera::new(
        Vec3::new(0.9, 0.5, 3.6),
        Vec3::new(0.3, 0.0, 0.0),
        Vec3::new(0.25, 1.0, 0.0),
        32.0,
        1.0,
    )
    .unwrap();
    Camera::in_motion(vec![open, close]).unwrap()
}

/// The ball, still, seen by [`moving_camera`] blurred at 64 spp, against the mean of 16
/// static renders through the camera's pose at stratified times across the shutter (64
/// spp in all): within [`NOISE_BOUND`] of the noise measured from two seeds a side, as for
/// a moving groom; the camera at the opening alone is far outside it. A ray that took its
/// pose at another time than the one its geometry and shading see, or the shutter mapped
/// onto the wrong poses, moves the whole ball.
#[test]
fn a_moving_camera_blurs_to_the_mean_of_static_renders_across_the_shutter() {
    let scene = world(&[ball()], CurveBasis::Linear, CurveShape::Round);
    let camera = moving_camera();
    let mean = |seed: u64| {
        let mut sum = vec![0.0; 40 * 30 * 3];
        for i in 0..STATIC_TIMES {
            let t = (i as f32 + 0.5) / STATIC_TIMES as f32;
            let img = image_through(
                &scene,
                &camera.at(t),
                &settings(64 / STATIC_TIMES, seed * 1000 + u64::from(i), false),
            );
            (sum.iter_mut().zip(&img)).for_each(|(s, v)| *s += v / f64::from(STATIC_TIMES));
        }
        sum
    };
    let blurred = |seed| image_through(&scene, &camera, &settings(64, seed, true));
    let (a1, a2) = (blurred(1), blurred(2));
    let (b1, b2) = (mean(1), mean(2));
    let noise = 0.5 * (mean_square_difference(&a1, &a2) + mean_square_difference(&b1, &b2));
    let against = mean_square_difference(&a1, &b1);
    let opening = image_through(&scene, &camera.at(0.0), &settings(64, 3, false));
    let still = mean_square_difference(&a1, &opening);
    println!(
        "camera: blurred against the static mean {against:.3e}, noise {noise:.3e}, against \
         the opening {still:.3e}"
    );
    assert!(
        against < NOISE_BOUND * noise,
        "{against} against noise {noise}"
    );
    assert!(still > 5.0 * noise, "the control is within noise: {still}");
}

/// A camera given the same pose at every step is a still camera, and with the shutter
/// open renders the shutter-closed image bit for bit: the ray's time takes no sample
/// request and a still pose ignores it. A thin lens alike.
#[test]
fn a_camera_that_stays_put_renders_the_same_bits_with_the_shutter_open() {
    let scene = world(&[ball()], CurveBasis::Linear, CurveShape::Round);
    let pinhole = Camera::new(Vec3::new(0.2, 0.1, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0).unwrap();
    for camera in [pinhole.clone(), pinhole.with_thin_lens(0.1, 4.0).unwrap()] {
        let steps = Camera::in_motion(vec![camera.clone(); 3]).unwrap();
        assert!(!steps.moves());
        let closed = image_through(&scene, &camera, &settings(8, 5, false));
        let open = image_through(&scene, &steps, &settings(8, 5, true));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&closed), bits(&open));
    }
}

/// With a moving camera (a pinhole, and a thin lens whose focus moves with it), the same
/// seed gives the same bits with one and two threads, and a crop renders exactly the full
/// frame's pixels.
#[test]
fn renders_through_a_moving_camera_are_deterministic_across_threads_and_crops() {
    let scene = world(&[ball()], CurveBasis::BSpline, CurveShape::Flat);
    let lens = Camera::in_motion(vec![
        moving_camera().at(0.0).with_thin_lens(0.05, 4.0).unwrap(),
        moving_camera().at(1.0).with_thin_lens(0.1, 3.5).unwrap(),
    ])
    .unwrap();
    for (camera, what) in [(moving_camera(), "pinhole"), (lens, "thin lens")] {
        let base = RenderSettings {
            allocation: Allocation::Noise,
            ..settings(4, 11, true)
        };
        assert_deterministic_through(&scene, &camera, base, what);
    }
}
