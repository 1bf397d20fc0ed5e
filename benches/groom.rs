//! Fur balls of 10^4, 10^5 and 10^6 strands (16 segments), round and flat, linear and
//! B-spline: build time, bytes per segment, and single-thread ray throughput for primary
//! (coherent) and incoherent rays (one bounce inside the fur), through hairtrace and through
//! Embree called directly on the same scene and the same rays (incoherent rays: Embree alone
//! starts them past the fiber they leave, hairtrace uses its exclusion filter instead). Also the 8-wide packet call
//! on primary rays, to see whether packets pay. Prints a markdown table.
//!
//! `cargo bench -p hairtrace-benches --bench groom` (all sizes; the package turns on the
//! library's `bench-internals`, which opens the tracer and the raw Embree bindings for the
//! direct baseline) or add `-- 100000` (sizes up to the given strand count).

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use hairtrace::embree::{
    CurveBasis, CurveShape, Device, MemoryMonitor, Ray, Scene, SceneOptions, sys,
};
use hairtrace::scene::FurBall;
use hairtrace::scene::curves::Curves;
use hairtrace::scene::hit::Hit;
use hairtrace::scene::tracer::{Escape, SpawnedRay, Tracer, TracerBuilder};

/// Primary rays: a WIDTH x WIDTH pinhole camera looking at the fur ball.
const WIDTH: usize = 256;

fn primary_rays() -> Vec<Ray> {
    let eye = Vec3::new(0.0, 0.3, 3.2);
    let forward = (-eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    // Tiles of 4 x 2 pixels in a row, so that consecutive groups of 8 form coherent packets.
    let mut rays = Vec::with_capacity(WIDTH * WIDTH);
    for ty in (0..WIDTH).step_by(2) {
        for tx in (0..WIDTH).step_by(4) {
            for k in 0..8 {
                let (x, y) = (tx + k % 4, ty + k / 4);
                let sx = (x as f32 + 0.5) / WIDTH as f32 * 2.0 - 1.0;
                let sy = 1.0 - (y as f32 + 0.5) / WIDTH as f32 * 2.0;
                let d = (forward + 0.45 * (sx * right + sy * up)).normalize();
                rays.push(Ray::new(eye, d));
            }
        }
    }
    rays
}

/// Seconds per call of `f` over all inputs, best of three runs.
fn time<T>(inputs: &[T], mut f: impl FnMut(&T) -> usize) -> (f64, usize) {
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..3 {
        let t0 = Instant::now();
        hits = inputs.iter().map(&mut f).sum();
        best = best.min(t0.elapsed().as_secs_f64());
    }
    (inputs.len() as f64 / best / 1e6, hits)
}

fn rayhit(ray: &Ray) -> sys::RTCRayHit {
    sys::RTCRayHit {
        ray: sys::RTCRay {
            org_x: ray.org.x,
            org_y: ray.org.y,
            org_z: ray.org.z,
            tnear: ray.tnear,
            dir_x: ray.dir.x,
            dir_y: ray.dir.y,
            dir_z: ray.dir.z,
            time: 0.0,
            tfar: ray.tfar,
            mask: ray.mask,
            id: 0,
            flags: 0,
        },
        hit: sys::RTCHit {
            geomID: u32::MAX,
            primID: u32::MAX,
            instID: [u32::MAX; sys::RTC_MAX_INSTANCE_LEVEL_COUNT as usize],
            ..Default::default()
        },
    }
}

#[cfg(embree3)]
fn context(coherent: bool) -> sys::RTCIntersectContext {
    sys::RTCIntersectContext {
        flags: if coherent {
            sys::RTCIntersectContextFlags::RTC_INTERSECT_CONTEXT_FLAG_COHERENT
        } else {
            sys::RTCIntersectContextFlags::RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT
        },
        filter: None,
        instID: [u32::MAX; sys::RTC_MAX_INSTANCE_LEVEL_COUNT as usize],
    }
}

/// Embree called directly: one `rtcIntersect1`, nothing else.
fn direct(scene: &Scene, ray: &Ray) -> usize {
    let mut rh = rayhit(ray);
    // SAFETY: committed scene; ray and context live across the call.
    #[cfg(embree3)]
    unsafe {
        let mut ctx = context(false);
        sys::rtcIntersect1(scene.raw_handle(), &mut ctx, &mut rh);
    }
    #[cfg(embree4)]
    // SAFETY: committed scene; default arguments.
    unsafe {
        sys::rtcIntersect1(scene.raw_handle(), &mut rh, std::ptr::null_mut());
    }
    usize::from(rh.hit.geomID != u32::MAX)
}

/// Embree's 8-wide packet call on 8 consecutive rays.
#[cfg(embree3)]
fn direct8(scene: &Scene, rays: &[Ray]) -> usize {
    // Embree reads the valid mask with one aligned 32-byte load.
    #[repr(C, align(32))]
    struct Valid([i32; 8]);
    let valid = Valid([-1; 8]);
    let mut p = sys::RTCRayHit8::default();
    for (k, r) in rays.iter().enumerate() {
        p.ray.org_x[k] = r.org.x;
        p.ray.org_y[k] = r.org.y;
        p.ray.org_z[k] = r.org.z;
        p.ray.dir_x[k] = r.dir.x;
        p.ray.dir_y[k] = r.dir.y;
        p.ray.dir_z[k] = r.dir.z;
        p.ray.tnear[k] = r.tnear;
        p.ray.tfar[k] = r.tfar;
        p.ray.mask[k] = r.mask;
        p.hit.geomID[k] = u32::MAX;
    }
    let mut ctx = context(true);
    // SAFETY: committed scene; an RTCRayHit8 is 32-byte aligned by bindgen, and so is the
    // valid mask of 8 lanes.
    unsafe { sys::rtcIntersect8(valid.0.as_ptr(), scene.raw_handle(), &mut ctx, &mut p) };
    p.hit.geomID.iter().filter(|&&g| g != u32::MAX).count()
}

struct Row {
    strands: usize,
    basis: CurveBasis,
    shape: CurveShape,
    build_s: f64,
    ours_b: f64,
    embree_b: f64,
    primary: [f64; 3],
    packet8: f64,
    incoherent: [f64; 4],
    escapes: [f64; 3],
}

const ESCAPES: [Escape; 3] = [
    Escape::OffsetAndFilter,
    Escape::ExitAndFilter,
    Escape::Filter,
];

fn run(strands: usize, basis: CurveBasis, shape: CurveShape, camera: &[Ray]) -> Row {
    let groom = FurBall {
        strands,
        segments: 16,
        ..FurBall::default()
    }
    .build()
    .expect("fur ball");
    let curves = Curves::from_strands(&groom, basis, shape).expect("curves");
    drop(groom);
    let device = Arc::new(Device::new(None).expect("device"));
    let monitor = MemoryMonitor::attach(device.clone());
    let t0 = Instant::now();
    let mut builder = TracerBuilder::new(device, SceneOptions::default()).expect("scene");
    builder.add_curves(curves).expect("curves");
    let tracer: Tracer = builder.build().expect("build");
    let build_s = t0.elapsed().as_secs_f64();
    let segments = strands as f64 * 16.0;
    let scene = tracer.scene();

    let (direct_p, hits) = time(camera, |r| direct(scene, r));
    let (wrapped_p, hits2) = time(camera, |r| usize::from(scene.intersect(r, None).is_some()));
    let (record_p, _) = time(camera, |r| {
        usize::from(black_box(tracer.intersect(r)).is_some())
    });
    assert_eq!(hits, hits2, "the wrapper and Embree agree");
    #[cfg(embree3)]
    let packet8 = time(&camera.chunks_exact(8).collect::<Vec<_>>(), |c| {
        direct8(scene, c)
    })
    .0 * 8.0;
    #[cfg(embree4)]
    let packet8 = f64::NAN;

    // Incoherent rays: from each primary hit, a direction spread over the sphere.
    let hits_for_escapes: Vec<Hit> = camera.iter().filter_map(|r| tracer.intersect(r)).collect();
    let spawned: Vec<SpawnedRay> = hits_for_escapes
        .iter()
        .enumerate()
        .map(|(i, hit)| {
            let a = i as f32 * 2.399_963;
            let z = 1.0 - 2.0 * ((i * 7919) % 1000) as f32 / 1000.0;
            let s = (1.0 - z * z).max(0.0).sqrt();
            tracer.spawn(hit, Vec3::new(s * a.cos(), s * a.sin(), z), f32::INFINITY)
        })
        .collect();
    // The same rays for Embree alone, which has no exclusion filter: started past the fiber
    // they leave (tnear = the exclusion distance), so they do not stop on it at t ~ 0.
    let plain: Vec<Ray> = spawned
        .iter()
        .map(|s| Ray {
            tnear: s.exclude.map_or(0.0, |e| e.max_t),
            ..s.ray
        })
        .collect();
    let (direct_i, _) = time(&plain, |r| direct(scene, r));
    let (wrapped_i, _) = time(&plain, |r| usize::from(scene.intersect(r, None).is_some()));
    let (filtered_i, _) = time(&spawned, |s| {
        usize::from(scene.intersect(&s.ray, s.exclude.as_ref()).is_some())
    });
    let (record_i, _) = time(&spawned, |s| {
        usize::from(black_box(tracer.intersect_spawned(s)).is_some())
    });
    // The cost of each escape strategy on the same bounce directions (filtered queries).
    let escapes = ESCAPES.map(|escape| {
        let rays: Vec<SpawnedRay> = spawned
            .iter()
            .zip(&hits_for_escapes)
            .map(|(s, hit)| tracer.spawn_with(hit, s.ray.dir, f32::INFINITY, escape))
            .collect();
        time(&rays, |s| {
            usize::from(scene.intersect(&s.ray, s.exclude.as_ref()).is_some())
        })
        .0
    });
    Row {
        strands,
        basis,
        shape,
        build_s,
        ours_b: tracer.heap_bytes() as f64 / segments,
        embree_b: monitor.current() as f64 / segments,
        primary: [direct_p, wrapped_p, record_p],
        packet8,
        incoherent: [direct_i, wrapped_i, filtered_i, record_i],
        escapes,
    }
}

fn main() {
    // `cargo bench` passes `--bench`; a number caps the sizes.
    let cap = std::env::args()
        .filter_map(|a| a.parse::<usize>().ok())
        .next()
        .unwrap_or(usize::MAX);
    let camera = primary_rays();
    println!(
        "Mrays/s on one thread; wrapper = embree::Scene::intersect, record = Tracer (hit \
         record: frame, h, strand); ratios to Embree called directly on the same rays.\n"
    );
    println!(
        "| strands | basis | shape | build s | B/seg ours | B/seg Embree | primary direct | \
         wrapper | record | 8-wide packet | incoherent direct | wrapper | + filter | record |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for strands in [10_000, 100_000, 1_000_000]
        .into_iter()
        .filter(|&n| n <= cap)
    {
        for basis in [CurveBasis::Linear, CurveBasis::BSpline] {
            for shape in CurveShape::ALL {
                let r = run(strands, basis, shape, &camera);
                let [dp, wp, rp] = r.primary;
                let [di, wi, fi, ri] = r.incoherent;
                println!(
                    "| {} | {:?} | {:?} | {:.2} | {:.1} | {:.1} | {:.2} | {:.2} ({:.2}) | {:.2} \
                     ({:.2}) | {:.2} ({:.2}) | {:.2} | {:.2} ({:.2}) | {:.2} ({:.2}) | {:.2} ({:.2}) |",
                    r.strands,
                    r.basis,
                    r.shape,
                    r.build_s,
                    r.ours_b,
                    r.embree_b,
                    dp,
                    wp,
                    wp / dp,
                    rp,
                    rp / dp,
                    r.packet8,
                    r.packet8 / dp,
                    di,
                    wi,
                    wi / di,
                    fi,
                    fi / di,
                    ri,
                    ri / di
                );
                rows.push(r);
            }
        }
    }
    println!("\nIncoherent Mrays/s (filtered queries) per escape strategy, default marked *:\n");
    println!(
        "| strands | basis | shape | {} |",
        ESCAPES
            .map(|e| {
                let mark = if e == Escape::default() { "*" } else { "" };
                format!("{e:?}{mark}")
            })
            .join(" | ")
    );
    println!("|---|---|---|---|---|---|");
    for r in &rows {
        let [a, b, c] = r.escapes;
        println!(
            "| {} | {:?} | {:?} | {a:.2} | {b:.2} | {c:.2} |",
            r.strands, r.basis, r.shape
        );
    }
}
