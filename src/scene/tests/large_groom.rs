//! A 10^6-strand, 16-segment fur ball builds and traces within a stated memory budget.
//!
//! Budget: the process's peak resident memory (VmHWM, measured from the start of the test)
//! stays under the larger of the two moments that need the most memory, plus 64 MiB for the
//! allocator and the test harness:
//! - converting: the host's strands and hairtrace's converted copy, both alive;
//! - building: the converted copy (the strands are dropped by then) and 1.3 times Embree's
//!   own peak as its memory monitor reports it (the BVH and its build temporaries).
//!
//! VmHWM is the whole process's, and the other unit tests share this one, so the test runs
//! itself again, alone, in a process of its own. Run with `--nocapture` for the figures.

use std::sync::Arc;
use std::time::Instant;

use crate::embree::{CurveBasis, CurveShape, Device, MemoryMonitor, Ray, SceneOptions};
use crate::scene::FurBall;
use crate::scene::curves::Curves;
use crate::scene::hit::Hit;
use crate::scene::tracer::TracerBuilder;
use glam::Vec3;

const STRANDS: usize = 1_000_000;
const SEGMENTS: u32 = 16;
const RAYS: usize = 100_000;
const MIB: f64 = 1024.0 * 1024.0;

/// A `kB` line of /proc/self/status, in bytes.
fn status_bytes(key: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .unwrap_or_else(|| panic!("no {key} in /proc/self/status"))
}

/// Set in the process that takes the measurement.
const ALONE: &str = "HT_LARGE_GROOM_ALONE";

#[test]
fn million_strand_fur_ball_builds_and_traces_within_budget() {
    if std::env::var_os(ALONE).is_some() {
        return measure();
    }
    let name = "scene::tests::large_groom::million_strand_fur_ball_builds_and_traces_within_budget";
    let exe = std::env::current_exe().expect("the test binary");
    let out = std::process::Command::new(exe)
        .args([name, "--exact", "--nocapture", "--test-threads=1"])
        .env(ALONE, "1")
        .output()
        .expect("run the test alone");
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    assert!(
        out.status.success() && stdout.contains("1 passed"),
        "alone in its process, the test did not pass:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn measure() {
    let baseline = status_bytes("VmRSS:");
    let t0 = Instant::now();
    let ball = FurBall {
        strands: STRANDS,
        segments: SEGMENTS,
        ..FurBall::default()
    };
    let strands = ball.build().unwrap();
    let t_groom = t0.elapsed();
    let strands_bytes = strands.points.capacity() * 12
        + strands.radii.capacity() * 4
        + strands.counts.capacity() * 4;

    let t0 = Instant::now();
    let curves = Curves::from_strands(&strands, CurveBasis::Linear, CurveShape::Round).unwrap();
    let t_convert = t0.elapsed();
    let ours = curves.heap_bytes();
    let peak_converting = strands_bytes + ours;
    drop(strands);

    let device = Arc::new(Device::new(None).unwrap());
    let monitor = MemoryMonitor::attach(device.clone());
    let t0 = Instant::now();
    let mut builder = TracerBuilder::new(device, SceneOptions::default()).unwrap();
    builder.add_curves(curves).unwrap();
    let tracer = builder.build().unwrap();
    let t_build = t0.elapsed();
    let embree_peak = monitor.peak().max(0) as usize;
    let embree_now = monitor.current().max(0) as usize;

    // Primary rays from a ring of cameras at the fur ball, then one bounce each.
    let t0 = Instant::now();
    let mut primary_hits = Vec::new();
    for i in 0..RAYS {
        let a = i as f32 * 2.399_963; // golden angle: an even spread
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / RAYS as f32;
        let s = (1.0 - z * z).sqrt();
        let eye = Vec3::new(s * a.cos(), z, s * a.sin()) * 4.0;
        let jitter = Vec3::new((a * 7.0).sin(), (a * 11.0).cos(), (a * 13.0).sin()) * 0.5;
        if let Some(hit) = tracer.intersect(&Ray::new(eye, (jitter - eye).normalize())) {
            primary_hits.push(hit);
        }
    }
    let t_primary = t0.elapsed();
    let t0 = Instant::now();
    let mut secondary_hits = 0usize;
    for (i, hit) in primary_hits.iter().enumerate() {
        let Hit::Hair(h) = hit else { continue };
        let a = i as f32 * 2.399_963;
        let dir = h
            .frame
            .to_world(Vec3::new(a.sin(), a.cos(), (a * 3.0).sin()).normalize());
        secondary_hits += usize::from(
            tracer
                .intersect_spawned(&tracer.spawn(hit, dir, f32::INFINITY))
                .is_some(),
        );
    }
    let t_secondary = t0.elapsed();

    let hwm = status_bytes("VmHWM:") - baseline;
    let budget = peak_converting.max(ours + embree_peak * 13 / 10) + 64 * 1024 * 1024;
    let segments = STRANDS as f64 * f64::from(SEGMENTS);
    println!("groom: {STRANDS} strands x {SEGMENTS} segments, round linear");
    println!(
        "time: groom {:.2} s, convert {:.2} s, Embree build {:.2} s",
        t_groom.as_secs_f64(),
        t_convert.as_secs_f64(),
        t_build.as_secs_f64()
    );
    println!(
        "memory: strands {:.0} MiB, hairtrace buffers {:.0} MiB ({:.1} B/segment), Embree peak \
         {:.0} MiB, Embree after build {:.0} MiB ({:.1} B/segment), peak RSS {:.0} MiB, budget \
         {:.0} MiB",
        strands_bytes as f64 / MIB,
        ours as f64 / MIB,
        ours as f64 / segments,
        embree_peak as f64 / MIB,
        embree_now as f64 / MIB,
        embree_now as f64 / segments,
        hwm as f64 / MIB,
        budget as f64 / MIB
    );
    println!(
        "rays: {} primary, {} hits, {:.2} Mrays/s; {} secondary, {} hits, {:.2} Mrays/s (one thread)",
        RAYS,
        primary_hits.len(),
        RAYS as f64 / t_primary.as_secs_f64() / 1e6,
        primary_hits.len(),
        secondary_hits,
        primary_hits.len() as f64 / t_secondary.as_secs_f64() / 1e6
    );
    assert!(primary_hits.len() > RAYS / 2, "the fur ball is hit");
    assert!(embree_now > 0, "the memory monitor saw Embree's BVH");
    assert!(
        hwm as usize <= budget,
        "peak RSS {hwm} over the budget {budget}"
    );
}
