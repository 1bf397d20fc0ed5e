//! Ribbons against tubes where a thin strand turns in the view, as a crown's strands do at
//! its silhouette: the `auto` shape's ribbons cover what the tubes cover, and are struck
//! where the tube's surface is.

use std::sync::Arc;

use crate::embree::{CurveBasis, CurveShape, Device, Ray, SceneOptions};
use crate::scene::Strands;
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;
use crate::scene::hit::Hit;
use crate::scene::lod::DEFAULT_LOD_PIXELS;
use crate::scene::ribbons::share_out;
use crate::scene::tracer::{Tracer, TracerBuilder};
use glam::Vec3;

/// Image height, in pixels, of the test camera (30 degrees tall): a pixel at distance 1 is
/// 2 tan(15 degrees) / HEIGHT wide.
const HEIGHT: u32 = 100;
const RADIUS: f32 = 0.001;
/// The hairpin's bend radius: about two pixels.
const BEND: f32 = 0.01;

fn camera() -> Camera {
    Camera::new(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 30.0, 1.0).unwrap()
}

/// A hairpin in the plane z = -1, facing the camera: straight legs joined by a half turn
/// of radius `BEND`, a Catmull-Rom point every quarter turn, so that each segment of the
/// turn bends by about 90 degrees.
fn hairpin() -> Curves {
    let mut s = Strands::default();
    let leg = [-0.03f32, -0.02, -0.01, 0.0];
    let mut push = |x: f32, y: f32| {
        s.points.push([x, y, -1.0]);
        s.radii.push(RADIUS);
    };
    for &y in &leg {
        push(-BEND, y);
    }
    push(0.0, BEND);
    for &y in leg.iter().rev() {
        push(BEND, y);
    }
    s.counts.push(s.points.len() as u32);
    Curves::from_strands(&s, CurveBasis::CatmullRom, CurveShape::Round).unwrap()
}

fn tracer(parts: Vec<Curves>) -> Tracer {
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
    for curves in parts {
        b.add_curves(curves).unwrap();
    }
    b.build().unwrap()
}

/// The share of a fine grid of rays from the eye over the turn that strike the strand.
fn coverage(t: &Tracer) -> f64 {
    let n = 600;
    let (x0, x1, y0, y1) = (-0.014f32, 0.014, -0.004, 0.014);
    let mut hits = 0u32;
    for i in 0..n {
        for j in 0..n {
            let x = x0 + (x1 - x0) * (i as f32 + 0.5) / n as f32;
            let y = y0 + (y1 - y0) * (j as f32 + 0.5) / n as f32;
            let ray = Ray::new(Vec3::ZERO, Vec3::new(x, y, -1.0));
            hits += u32::from(t.intersect(&ray).is_some());
        }
    }
    f64::from(hits) / f64::from(n * n)
}

#[test]
fn a_thin_strand_turning_in_the_view_covers_as_its_tube_does() {
    let tube = coverage(&tracer(vec![hairpin().with_shape(CurveShape::Round)]));
    // The case is one Embree's default quads cut short: chords of a quarter turn.
    let default_quads = coverage(&tracer(vec![hairpin().with_shape(CurveShape::Flat)]));
    assert!(
        default_quads < 0.985 * tube,
        "default quads cover {default_quads}, the tube {tube}"
    );
    for lod in [0.0, DEFAULT_LOD_PIXELS] {
        let parts = share_out(hairpin(), &camera(), HEIGHT, lod).unwrap();
        assert!(
            parts.iter().all(|p| p.shape() == CurveShape::Flat),
            "lod {lod}"
        );
        let auto = coverage(&tracer(parts));
        assert!(
            (auto / tube - 1.0).abs() < 0.005,
            "lod {lod}: auto covers {auto}, the tube {tube}"
        );
    }
}

#[test]
fn a_ribbon_is_struck_where_its_tube_is() {
    // A straight strand along x at z = 0, seen from z = 1, square on and at 45 degrees.
    let mut s = Strands::default();
    for k in 0..=4 {
        s.points.push([k as f32 * 0.25 - 0.5, 0.0, 0.0]);
        s.radii.push(0.01);
    }
    s.counts.push(5);
    for basis in [CurveBasis::Linear, CurveBasis::CatmullRom] {
        let flat = tracer(vec![
            Curves::from_strands(&s, basis, CurveShape::Flat).unwrap(),
        ]);
        let round = tracer(vec![
            Curves::from_strands(&s, basis, CurveShape::Round).unwrap(),
        ]);
        for dir in [Vec3::NEG_Z, Vec3::new(1.0, 0.0, -1.0)] {
            for h in [-0.9f32, -0.5, 0.0, 0.3, 0.8] {
                let org = Vec3::new(0.05, h * 0.01, 0.0) - dir;
                let ray = Ray::new(org, dir);
                let t = |tracer: &Tracer| match tracer.intersect(&ray) {
                    Some(Hit::Hair(hit)) => hit.t,
                    other => panic!("{basis:?} {dir} h {h}: {other:?}"),
                };
                let (flat, round) = (t(&flat), t(&round));
                assert!(
                    (flat - round).abs() * dir.length() < 0.01 * 0.01,
                    "{basis:?} {dir} h {h}: the ribbon at t {flat}, the tube at {round}"
                );
            }
        }
    }
}
