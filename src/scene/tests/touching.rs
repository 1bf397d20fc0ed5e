//! Strands that touch: a ray leaving one strand sees its neighbour however close, whatever
//! the shape. Embree ignores a flat curve's hits within two of its radii of a ray's origin
//! (`tracer::FLAT_BLIND_RADII`); in a clump of ribbons that hid the neighbours from every
//! shadow and continued ray.

use std::sync::Arc;

use crate::embree::{CurveBasis, CurveShape, Device, Ray, SceneOptions};
use crate::scene::Strands;
use crate::scene::curves::Curves;
use crate::scene::hit::Hit;
use crate::scene::tracer::TracerBuilder;
use glam::Vec3;

const RADIUS: f32 = 0.01;

/// Two straight strands along x, at y = 0 and y = `gap` between their surfaces.
fn pair(gap: f32) -> Strands {
    let mut s = Strands::default();
    for y in [0.0, 2.0 * RADIUS + gap] {
        for k in 0..=4 {
            s.points.push([k as f32 * 0.25 - 0.5, y, 0.0]);
            s.radii.push(RADIUS);
        }
        s.counts.push(5);
    }
    s
}

#[test]
fn a_ray_leaving_a_strand_sees_its_touching_neighbour() {
    let device = Arc::new(Device::new(Some(1)).unwrap());
    for basis in [CurveBasis::Linear, CurveBasis::CatmullRom] {
        for shape in [CurveShape::Flat, CurveShape::Round] {
            for gap in [0.05 * RADIUS, 0.5 * RADIUS, 1.5 * RADIUS] {
                let mut b = TracerBuilder::new(device.clone(), SceneOptions::default()).unwrap();
                let curves = Curves::from_strands(&pair(gap), basis, shape).unwrap();
                b.add_curves(curves).unwrap();
                let tracer = b.build().unwrap();
                // Strand 0 struck from above, near its side that faces strand 1.
                let down = Ray::new(Vec3::new(0.1, 0.9 * RADIUS, 1.0), Vec3::NEG_Z);
                let Some(from @ Hit::Hair(h)) = tracer.intersect(&down) else {
                    panic!("{basis:?} {shape:?}: the first strand is missed");
                };
                assert_eq!(h.strand.strand, 0);
                // Toward strand 1, level: it lies across the way at about the gap.
                let toward = Vec3::Y;
                let next = tracer.intersect_spawned(&tracer.spawn(&from, toward, f32::INFINITY));
                let what = format!("{basis:?} {shape:?}, gap {:.2} radii", gap / RADIUS);
                match next {
                    Some(Hit::Hair(n)) => assert_eq!(n.strand.strand, 1, "{what}"),
                    other => panic!("{what}: the neighbour is not seen ({other:?})"),
                }
                let shadow = tracer.spawn(&from, toward, 1.0);
                assert!(tracer.occluded_spawned(&shadow), "{what}: no shadow");
            }
        }
    }
}
