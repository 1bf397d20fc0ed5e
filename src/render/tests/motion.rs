//! Motion blur end to end: a groom, and a mesh, moving a known path, blurred over the
//! shutter, against the mean of static renders across it; a groom that stays put, blurred
//! and not; crops and thread counts with blur on; and the inputs refused.

use super::render::{
    assert_deterministic, assert_same_image_more_rays, camera, quadrant_means_over,
    quadrant_settings,
};
use crate::embree::{CurveBasis, CurveShape, Device, SceneOptions};
use crate::render::integrator::World;
use crate::render::renderer::render;
use crate::render::settings::{Allocation, CameraRays, PathSettings, RenderSettings};
use crate::render::{Aovs, NoProgress};
use crate::scene::curves::Curves;
use crate::scene::envmap::Environment;
use crate::scene::light::Light;
use crate::scene::material::{HairMaterial, Material};
use crate::scene::tracer::TracerBuilder;
use crate::scene::{Camera, FurBall, Mesh, Strands};
use glam::Vec3;
use std::sync::Arc;

/// How far the groom moves over the shutter: a third of the ball's width, many pixels.
const TRAVEL: Vec3 = Vec3::new(0.9, 0.3, 0.0);

pub(super) fn ball() -> Strands {
    FurBall {
        strands: 1500,
        segments: 8,
        ..FurBall::default()
    }
    .build()
    .unwrap()
}

/// `strands` moved `by`.
fn moved(strands: &Strands, by: Vec3) -> Strands {
    let points = (strands.points.iter())
        .map(|&p| (Vec3::from_array(p) + by).to_array())
        .collect();
    Strands {
        points,
        ..strands.clone()
    }
}

/// The ball under a sky and a sun, its curves at `steps` time steps (for each step, where
/// the groom is), `basis` and `shape`.
pub(super) fn world(steps: &[Strands], basis: CurveBasis, shape: CurveShape) -> World {
    let device = Arc::new(Device::new(Some(2)).unwrap());
    let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
    let curves = (steps.iter())
        .map(|s| Curves::from_strands(s, basis, shape))
        .collect::<crate::Result<Vec<_>>>()
        .and_then(Curves::in_motion)
        .unwrap();
    b.add_curves(curves).unwrap();
    let lights = vec![
        Light::Environment(Environment::uniform(Vec3::splat(0.3)).unwrap()),
        Light::distant(Vec3::new(1.0, 1.0, 1.0), Vec3::new(2.0, 1.8, 1.5), 10.0).unwrap(),
    ];
    let hair = HairMaterial::default().prepare().unwrap();
    World::new(
        b.build().unwrap(),
        vec![Material::Hair(Box::new(hair))],
        lights,
    )
    .unwrap()
}

pub(super) fn settings(spp: u32, seed: u64, blur: bool) -> RenderSettings {
    RenderSettings {
        width: 40,
        height: 30,
        spp,
        seed,
        allocation: Allocation::Uniform,
        shutter_open: if blur { -0.25 } else { 0.0 },
        shutter_close: if blur { 0.25 } else { 0.0 },
        ..RenderSettings::default()
    }
}

fn image(world: &World, settings: &RenderSettings) -> Vec<f64> {
    image_through(world, &camera(), settings)
}

pub(super) fn image_through(world: &World, camera: &Camera, settings: &RenderSettings) -> Vec<f64> {
    let out = render(world, camera, settings, Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|&v| f64::from(v)).collect()
}

pub(super) fn mean_square_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64
}

/// Static renders at this many stratified times across the shutter make the reference.
pub(super) const STATIC_TIMES: u32 = 16;

/// How far above the mean square difference that noise alone makes (measured from two
/// seeds a side) a render's difference from its reference may be and still count as noise.
pub(super) const NOISE_BOUND: f64 = 1.3;

/// The mean of [`STATIC_TIMES`] static renders of the ball moved to the middles of equal
/// slices of its path, each at `spp` / [`STATIC_TIMES`] samples.
fn static_mean(strands: &Strands, spp: u32, seed: u64, basis: CurveBasis) -> Vec<f64> {
    let mut sum: Vec<f64> = Vec::new();
    for i in 0..STATIC_TIMES {
        let t = (i as f32 + 0.5) / STATIC_TIMES as f32;
        let w = world(&[moved(strands, TRAVEL * t)], basis, CurveShape::Round);
        let seed = seed * 1000 + u64::from(i);
        let img = image(&w, &settings(spp / STATIC_TIMES, seed, false));
        sum.resize(img.len(), 0.0);
        sum.iter_mut().zip(&img).for_each(|(s, v)| *s += v);
    }
    sum.iter().map(|s| s / f64::from(STATIC_TIMES)).collect()
}

/// The ball moving along [`TRAVEL`] over the shutter, blurred at 64 spp, against the mean
/// of 16 static renders at stratified times across it (64 spp in all), for a linear and a
/// cubic basis. The noise is measured, not assumed: two seeds of each side give the mean
/// square difference that noise alone makes (the blurred render's variance plus the
/// reference's), and the blurred render must stay within [`NOISE_BOUND`] of it from the
/// reference: over the frame's values that ratio's own noise is small, while a time ignored in the
/// shading or the intersection, or a shutter mapped onto the wrong steps, puts whole
/// strands elsewhere and the difference many times above it (the control: the groom at
/// the opening alone).
#[test]
fn a_moving_groom_blurs_to_the_mean_of_static_renders_across_the_shutter() {
    let strands = ball();
    for basis in [CurveBasis::Linear, CurveBasis::BSpline] {
        let blurred = world(
            &[strands.clone(), moved(&strands, TRAVEL)],
            basis,
            CurveShape::Round,
        );
        let a1 = image(&blurred, &settings(64, 1, true));
        let a2 = image(&blurred, &settings(64, 2, true));
        let b1 = static_mean(&strands, 64, 1, basis);
        let b2 = static_mean(&strands, 64, 2, basis);
        let noise = 0.5 * (mean_square_difference(&a1, &a2) + mean_square_difference(&b1, &b2));
        let against = mean_square_difference(&a1, &b1);
        let opening = world(std::slice::from_ref(&strands), basis, CurveShape::Round);
        let still = mean_square_difference(&a1, &image(&opening, &settings(64, 3, false)));
        println!(
            "{basis:?}: blurred against the static mean {:.3e}, noise {:.3e}, against the \
             opening {:.3e}",
            against, noise, still
        );
        assert!(
            against < NOISE_BOUND * noise,
            "{basis:?}: {against} against noise {noise}"
        );
        assert!(
            still > 5.0 * noise,
            "{basis:?}: the control is within noise: {still}"
        );
    }
}

/// A groom whose two time steps are the same, rendered with motion blur, is the groom
/// without time steps within noise, round and flat (noise measured as above, within
/// [`NOISE_BOUND`]). The
/// sample numbers are the same with and without blur (the time takes no request), so
/// the two differ only where Embree's motion-blur intersection rounds otherwise.
#[test]
fn a_groom_that_stays_put_renders_alike_with_and_without_blur() {
    let strands = ball();
    for shape in [CurveShape::Round, CurveShape::Flat] {
        let basis = CurveBasis::CatmullRom;
        let still = world(std::slice::from_ref(&strands), basis, shape);
        let steps = world(&[strands.clone(), strands.clone()], basis, shape);
        let off = image(&still, &settings(16, 1, false));
        let off2 = image(&still, &settings(16, 2, false));
        let on = image(&steps, &settings(16, 1, true));
        let noise = mean_square_difference(&off, &off2);
        let against = mean_square_difference(&off, &on);
        println!("{shape:?}: blur on against off {against:.3e}, noise {noise:.3e}");
        assert!(
            against < NOISE_BOUND * noise,
            "{shape:?}: {against} against noise {noise}"
        );
    }
}

/// With motion blur on, the same seed gives the same bits with one and two threads, and a
/// crop renders exactly the full frame's pixels, for every basis, round and flat.
#[test]
fn blurred_renders_are_deterministic_across_threads_and_crops() {
    let strands = ball();
    let bases = [
        CurveBasis::Linear,
        CurveBasis::Bezier,
        CurveBasis::BSpline,
        CurveBasis::CatmullRom,
    ];
    for basis in bases {
        for shape in [CurveShape::Round, CurveShape::Flat] {
            let w = world(&[strands.clone(), moved(&strands, TRAVEL)], basis, shape);
            let base = RenderSettings {
                allocation: Allocation::Noise,
                ..settings(4, 11, true)
            };
            assert_deterministic(&w, base, &format!("{basis:?} {shape:?}"));
        }
    }
}

/// A shutter that closes before it opens, a NaN in a time step and time steps of other
/// point counts are refused, each in words that say which.
#[test]
fn bad_motion_is_refused_with_a_clear_message() {
    let mut s = RenderSettings::default();
    s.set("shutter_open", "0.25").unwrap();
    s.set("shutter_close", "-0.25").unwrap();
    let e = s.validate().unwrap_err().to_string();
    assert!(
        e.contains("shutter_close = -0.25") && e.contains("before it opens"),
        "{e}"
    );

    let strands = ball();
    let curves = |s: &Strands| Curves::from_strands(s, CurveBasis::BSpline, CurveShape::Round);
    let mut nan = strands.clone();
    nan.points[17][1] = f32::NAN;
    let e = curves(&nan).unwrap_err().to_string();
    assert!(e.contains("17") && e.contains("NaN"), "{e}");

    let mut fewer = strands.clone();
    fewer.counts[3] -= 1;
    fewer.points.remove(40);
    fewer.radii.remove(40);
    let e = Curves::in_motion(vec![curves(&strands).unwrap(), curves(&fewer).unwrap()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("time step 1: strand 3 has"), "{e}");
    let e = Curves::in_motion(Vec::new()).unwrap_err().to_string();
    assert!(e.contains("0 time steps"), "{e}");
}

/// A mesh that deforms (a quad turning about its vertical edge and sliding, in front of a
/// fur ball that stays put), blurred at 64 spp, against the mean of 16 static renders of
/// the quad at stratified times across the shutter: within [`NOISE_BOUND`] of the measured noise, as
/// for the moving groom, and the quad at the opening alone far outside it. Its hits are
/// shaded with the geometric normal at the ray's time.
#[test]
fn a_deforming_mesh_blurs_to_the_mean_of_static_renders_across_the_shutter() {
    let quad = |t: f32| -> Vec<[f32; 3]> {
        let (x, z) = (-0.6 + 0.8 * t, 1.2 + 0.5 * t);
        vec![
            [x, -0.5, 1.2],
            [x + 0.6, -0.5, z],
            [x + 0.6, 0.5, z],
            [x, 0.5, 1.2],
        ]
    };
    let scene = |steps: &[Vec<[f32; 3]>]| {
        let device = Arc::new(Device::new(Some(2)).unwrap());
        let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
        let ball = Curves::from_strands(&ball(), CurveBasis::Linear, CurveShape::Round).unwrap();
        b.add_curves(ball).unwrap();
        b.add_mesh(Mesh {
            positions: steps[0].clone(),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            normals: None,
            later_positions: steps[1..].to_vec(),
        })
        .unwrap();
        let lights = vec![
            Light::Environment(Environment::uniform(Vec3::splat(0.3)).unwrap()),
            Light::distant(Vec3::new(1.0, 1.0, 1.0), Vec3::new(2.0, 1.8, 1.5), 10.0).unwrap(),
        ];
        let hair = HairMaterial::default().prepare().unwrap();
        let materials = vec![
            Material::Hair(Box::new(hair)),
            Material::Diffuse(crate::bsdf::Diffuse::new(Vec3::new(0.8, 0.5, 0.3)).unwrap()),
        ];
        World::new(b.build().unwrap(), materials, lights).unwrap()
    };
    let blurred = scene(&[quad(0.0), quad(1.0)]);
    let mean = |seed: u64| {
        let mut sum = vec![0.0; 40 * 30 * 3];
        for i in 0..STATIC_TIMES {
            let t = (i as f32 + 0.5) / STATIC_TIMES as f32;
            let img = image(
                &scene(&[quad(t)]),
                &settings(64 / STATIC_TIMES, seed * 1000 + u64::from(i), false),
            );
            sum.iter_mut()
                .zip(&img)
                .for_each(|(s, v)| *s += v / f64::from(STATIC_TIMES));
        }
        sum
    };
    let (a1, a2) = (
        image(&blurred, &settings(64, 1, true)),
        image(&blurred, &settings(64, 2, true)),
    );
    let (b1, b2) = (mean(1), mean(2));
    let noise = 0.5 * (mean_square_difference(&a1, &a2) + mean_square_difference(&b1, &b2));
    let against = mean_square_difference(&a1, &b1);
    let still = mean_square_difference(&a1, &image(&scene(&[quad(0.0)]), &settings(64, 3, false)));
    println!(
        "mesh: blurred against the static mean {against:.3e}, noise {noise:.3e}, against the opening {still:.3e}"
    );
    assert!(
        against < NOISE_BOUND * noise,
        "{against} against noise {noise}"
    );
    assert!(still > 5.0 * noise, "the control is within noise: {still}");
}

/// `auto` camera rays under motion blur: the ball's strands are wider than the width that
/// keeps a still frame at one ray (the sampler's strata resolve them there), but moving,
/// each sample sees them where they are at its own time, so `auto` splits samples where
/// they show the sky, and the blurred image stays the one-ray image (quadrant means within
/// 4 standard errors over 32 seeds). The still ball takes one ray everywhere: its image is
/// the one-ray image.
#[test]
fn auto_camera_rays_split_moving_strands_and_keep_the_image() {
    // Wider at this framing than the width rule lets split at 16 spp
    // (`camera_rays::widest_split`): the still ball's one ray below shows it.
    let strands = FurBall {
        strands: 1500,
        segments: 8,
        root_radius: 0.036,
        tip_radius: 0.024,
        ..FurBall::default()
    }
    .build()
    .unwrap();
    let basis = CurveBasis::Linear;
    let blurred = world(
        &[strands.clone(), moved(&strands, TRAVEL)],
        basis,
        CurveShape::Round,
    );
    let still = world(std::slice::from_ref(&strands), basis, CurveShape::Round);
    let means = |world: &World, camera_rays, blur: bool| {
        let (open, close) = if blur { (-0.25, 0.25) } else { (0.0, 0.0) };
        let settings = RenderSettings {
            camera_rays,
            spp: 16,
            shutter_open: open,
            shutter_close: close,
            ..quadrant_settings(PathSettings::default())
        };
        quadrant_means_over(world, settings, 32)
    };
    let one = means(&blurred, CameraRays::Fixed(1), true);
    let auto = means(&blurred, CameraRays::Auto, true);
    let (still_one, still_auto) = (
        means(&still, CameraRays::Fixed(1), false),
        means(&still, CameraRays::Auto, false),
    );
    // The same samples, bit for bit (the survey's rays aside).
    assert_eq!(still_auto.0, still_one.0, "the still ball split");
    assert_same_image_more_rays("blurred, auto vs 1", &auto, &one, 0.2);
}
