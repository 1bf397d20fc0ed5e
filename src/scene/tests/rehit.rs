//! Leaving a fiber: rays that continue a path from a round-curve hit (reflected: on the
//! viewer's side; transmitted: through the fiber) and shadow rays must not hit the same tube
//! again. Measures the re-hit rate of each escape strategy over many random directions from
//! many hits, and asserts the default strategy stays below 0.1%.
//!
//! The strands stand far apart (closest approach > 0.9, continued rays reach at most 0.5
//! for shadow rays) and are straight or barely bent, so every hit on the strand a ray left
//! is a spurious re-hit. Run with `--nocapture` for the table.

use std::sync::Arc;

use crate::embree::{CurveBasis, CurveShape, Device, Ray, SceneOptions};
use crate::scene::Strands;
use crate::scene::curves::Curves;
use crate::scene::hit::Hit;
use crate::scene::tracer::{Escape, Tracer, TracerBuilder};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const RADIUS: f32 = 0.01;
const GRID: usize = 6;
const SPACING: f32 = 2.0;
const SEGMENTS: usize = 8;
const DIRECTIONS_PER_HIT: usize = 64;
const SHADOW_REACH: f32 = 0.5;

fn unit(rng: &mut Pcg64) -> Vec3 {
    let z: f32 = rng.random_range(-1.0..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// GRID^3 strands of length 1 with random orientations, straight or bent by `turn`
/// radians along their length.
fn strands(rng: &mut Pcg64, turn: f32) -> (Strands, Vec<(Vec3, Vec3)>) {
    let mut s = Strands::default();
    let mut frames = Vec::new();
    for i in 0..GRID * GRID * GRID {
        let centre = Vec3::new(
            (i % GRID) as f32,
            ((i / GRID) % GRID) as f32,
            (i / (GRID * GRID)) as f32,
        ) * SPACING;
        let axis = unit(rng);
        let bend = axis.any_orthonormal_vector();
        for k in 0..=SEGMENTS {
            let a = (k as f32 / SEGMENTS as f32 - 0.5) * turn;
            // An arc of length 1 and turning angle `turn` (a line when turn = 0).
            let (along, side) = if turn > 0.0 {
                (a.sin() / turn, (1.0 - a.cos()) / turn)
            } else {
                (k as f32 / SEGMENTS as f32 - 0.5, 0.0)
            };
            s.points
                .push((centre + axis * along + bend * side).to_array());
            s.radii.push(RADIUS);
        }
        s.counts.push(SEGMENTS as u32 + 1);
        frames.push((centre, axis));
    }
    (s, frames)
}

#[derive(Default, Clone, Copy)]
struct Count {
    rays: u64,
    rehits: u64,
}

impl Count {
    fn add(&mut self, rehit: bool) {
        self.rays += 1;
        self.rehits += u64::from(rehit);
    }

    fn rate(&self) -> f64 {
        self.rehits as f64 / self.rays.max(1) as f64
    }
}

/// Re-hit counts per strategy: (reflected, transmitted, shadow).
fn measure(basis: CurveBasis, turn: f32, seed: u64) -> Vec<(Escape, [Count; 3])> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let (s, frames) = strands(&mut rng, turn);
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
    let geom = b
        .add_curves(Curves::from_strands(&s, basis, CurveShape::Round).unwrap())
        .unwrap();
    let tracer: Tracer = b.build().unwrap();

    // Hits: rays from random directions at random offsets, aimed at random points of each
    // strand's middle 80%.
    let mut hits = Vec::new();
    for (strand, &(centre, axis)) in frames.iter().enumerate() {
        for _ in 0..12 {
            let target = centre + axis * rng.random_range(-0.4..0.4);
            let d = unit(&mut rng);
            let y = axis.cross(d).normalize_or_zero();
            let h: f32 = rng.random_range(-0.98..0.98);
            let ray = Ray::new(target + y * h * RADIUS * 0.9 - d * 0.8, d);
            if let Some(Hit::Hair(hit)) = tracer.intersect(&ray) {
                if hit.strand.strand as usize == strand {
                    hits.push(Hit::Hair(hit));
                }
            }
        }
    }
    assert!(hits.len() > 1500, "only {} hits", hits.len());

    let same_tube = |from: &Hit, to: Option<Hit>| {
        matches!((from, to), (Hit::Hair(a), Some(Hit::Hair(b)))
            if b.geom_id == geom && b.strand.strand == a.strand.strand)
    };
    [
        Escape::Offset,
        Escape::OffsetAndFilter,
        Escape::ExitAndFilter,
        Escape::Filter,
    ]
    .into_iter()
    .map(|escape| {
        let mut counts = [Count::default(); 3];
        let mut dirs = Pcg64::seed_from_u64(seed + 1);
        for from in &hits {
            let Hit::Hair(h) = from else { continue };
            for _ in 0..DIRECTIONS_PER_HIT {
                let dir = unit(&mut dirs);
                let reflected = dir.dot(h.ng) > 0.0;
                let ray = tracer.spawn_with(from, dir, f32::INFINITY, escape);
                let rehit = same_tube(from, tracer.intersect_spawned(&ray));
                counts[usize::from(!reflected)].add(rehit);
                let shadow = tracer.spawn_with(from, dir, SHADOW_REACH, escape);
                counts[2].add(tracer.occluded_spawned(&shadow));
            }
        }
        (escape, counts)
    })
    .collect()
}

#[test]
fn continued_and_shadow_rays_do_not_rehit_the_fiber() {
    let mut failures = Vec::new();
    println!(
        "{:<11} {:<9} {:<16} {:>10} {:>12} {:>10}",
        "basis", "strands", "escape", "reflected", "transmitted", "shadow"
    );
    for basis in CurveBasis::ALL {
        for (kind, turn) in [("straight", 0.0), ("bent", 0.1)] {
            for (escape, c) in measure(basis, turn, 7) {
                println!(
                    "{:<11} {kind:<9} {:<16} {:>9.3}% {:>11.3}% {:>9.3}%",
                    format!("{basis:?}"),
                    format!("{escape:?}"),
                    100.0 * c[0].rate(),
                    100.0 * c[1].rate(),
                    100.0 * c[2].rate()
                );
                if escape == Escape::default() && c.iter().any(|c| c.rate() >= 1e-3) {
                    failures.push(format!(
                        "{basis:?} {kind}: re-hit rates {:.4} {:.4} {:.4}",
                        c[0].rate(),
                        c[1].rate(),
                        c[2].rate()
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
