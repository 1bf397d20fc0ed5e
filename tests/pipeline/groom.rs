//! Procedural grooms: determinism, shape (roots on the sphere, tips where the model puts
//! them, tapering radii, no degenerate segments), parameter errors and the 10^6-strand size.

use hairtrace::Error;
use hairtrace::scene::{FurBall, HairStyle, ScalpPatch, Strands};
use std::time::Instant;

fn len(p: [f32; 3]) -> f64 {
    p.iter()
        .map(|&x| f64::from(x) * f64::from(x))
        .sum::<f64>()
        .sqrt()
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f64 {
    len([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

/// Each strand's points, from the flat arrays.
fn strands_of(s: &Strands) -> impl Iterator<Item = &[[f32; 3]]> {
    s.offsets()
        .zip(&s.counts)
        .map(|(o, &c)| &s.points[o..o + c as usize])
}

/// Checks everything a groom of uniform strands must satisfy; returns the shortest segment.
fn check_common(s: &Strands, strands: usize, segments: u32, root_r: f32, tip_r: f32) -> f64 {
    s.validate().unwrap();
    let pts = segments as usize + 1;
    assert_eq!(s.counts, vec![segments + 1; strands]);
    assert_eq!(
        (s.points.len(), s.radii.len()),
        (strands * pts, strands * pts)
    );
    assert!(s.points.iter().flatten().all(|v| v.is_finite()));
    for r in s.radii.chunks(pts) {
        assert_eq!((r[0], r[pts - 1]), (root_r, tip_r));
        assert!(
            r.windows(2).all(|w| w[1] <= w[0]),
            "radii do not taper: {r:?}"
        );
    }
    strands_of(s)
        .flat_map(|p| p.windows(2).map(|w| dist(w[0], w[1])))
        .fold(f64::INFINITY, f64::min)
}

fn small_ball() -> FurBall {
    FurBall {
        strands: 2000,
        ..Default::default()
    }
}

#[test]
fn fur_ball_is_deterministic() {
    let a = small_ball().build().unwrap();
    assert_eq!(a, small_ball().build().unwrap());
    let b = FurBall {
        seed: 1,
        ..small_ball()
    }
    .build()
    .unwrap();
    assert_eq!(a.counts, b.counts);
    assert_ne!(a.points, b.points);
}

#[test]
fn fur_ball_shape() {
    let f = small_ball();
    let s = f.build().unwrap();
    let shortest = check_common(&s, f.strands, f.segments, f.root_radius, f.tip_radius);
    // Each segment is length / segments long (f32 rounding aside).
    let step = f64::from(f.length) / f64::from(f.segments);
    assert!(
        shortest > step * 0.999,
        "shortest segment {shortest} vs {step}"
    );

    let (r, l) = (f64::from(f.radius), f64::from(f.length));
    // Directions stay within 70 degrees of the root normal, so every segment climbs by at
    // least cos(70) of its length: the tip lies in [r + l cos 70, r + l] (the upper bound is
    // the triangle inequality). f32 sums of 16 steps add ~1e-6 relative.
    let (lo, hi) = (r + l * 70f64.to_radians().cos(), r + l);
    let mut mean_tip = 0.0;
    for p in strands_of(&s) {
        let root = len(p[0]);
        assert!((root - r).abs() <= 1e-5 * r, "root at {root}");
        let tip = len(p[p.len() - 1]);
        assert!(
            tip >= lo * (1.0 - 1e-5) && tip <= hi * (1.0 + 1e-5),
            "tip at {tip}"
        );
        // Strands only ever move outward.
        assert!(p.windows(2).all(|w| len(w[1]) > len(w[0])));
        mean_tip += tip / f.strands as f64;
    }
    println!("fur ball tips: mean distance {mean_tip:.4}, bounds [{lo:.4}, {hi:.4}]");

    // Roots cover the sphere evenly: each octant holds an eighth of them, within 5%.
    let mut octants = [0usize; 8];
    for p in strands_of(&s) {
        let o = (p[0][0] > 0.0) as usize
            | ((p[0][1] > 0.0) as usize) << 1
            | ((p[0][2] > 0.0) as usize) << 2;
        octants[o] += 1;
    }
    for c in octants {
        assert!((c as f64 - 250.0).abs() < 12.5, "octant counts {octants:?}");
    }
}

#[test]
fn straight_fur_reaches_exactly_radius_plus_length() {
    let f = FurBall {
        strands: 500,
        segments: 7,
        radius: 2.5,
        length: 0.75,
        curl: 0.0,
        gravity: 0.0,
        noise: 0.0,
        clumping: 0.0,
        ..Default::default()
    };
    let s = f.build().unwrap();
    for p in strands_of(&s) {
        let tip = len(p[p.len() - 1]);
        assert!((tip - 3.25).abs() < 3.25 * 1e-5, "tip at {tip}");
    }
}

#[test]
fn clumping_gathers_tips() {
    // Mean distance from each tip to its nearest other tip shrinks as clumping grows.
    let spread = |clumping: f32| {
        let s = FurBall {
            strands: 1500,
            clumping,
            curl: 0.0,
            noise: 0.0,
            gravity: 0.0,
            ..Default::default()
        }
        .build()
        .unwrap();
        let tips: Vec<[f32; 3]> = strands_of(&s).map(|p| p[p.len() - 1]).collect();
        tips.iter()
            .map(|&a| {
                tips.iter()
                    .filter(|&&b| b != a)
                    .map(|&b| dist(a, b))
                    .fold(f64::INFINITY, f64::min)
            })
            .sum::<f64>()
            / tips.len() as f64
    };
    let (loose, tight) = (spread(0.0), spread(0.9));
    println!("nearest-tip distance: clumping 0: {loose:.5}, 0.9: {tight:.5}");
    assert!(tight < 0.5 * loose);
}

#[test]
fn fur_ball_parameters_are_checked() {
    let bad: Vec<(FurBall, &str)> = vec![
        (
            FurBall {
                strands: 0,
                ..Default::default()
            },
            "FurBall.strands",
        ),
        (
            FurBall {
                segments: 0,
                ..Default::default()
            },
            "FurBall.segments",
        ),
        (
            FurBall {
                segments: 70_000,
                ..Default::default()
            },
            "FurBall.segments",
        ),
        (
            FurBall {
                radius: 0.0,
                ..Default::default()
            },
            "FurBall.radius",
        ),
        (
            FurBall {
                radius: f32::NAN,
                ..Default::default()
            },
            "FurBall.radius",
        ),
        (
            FurBall {
                length: -1.0,
                ..Default::default()
            },
            "FurBall.length",
        ),
        (
            FurBall {
                length: f32::INFINITY,
                ..Default::default()
            },
            "FurBall.length",
        ),
        (
            FurBall {
                root_radius: 0.0,
                ..Default::default()
            },
            "FurBall.root_radius",
        ),
        (
            FurBall {
                tip_radius: f32::NAN,
                ..Default::default()
            },
            "FurBall.tip_radius",
        ),
        (
            FurBall {
                curl: -0.1,
                ..Default::default()
            },
            "FurBall.curl",
        ),
        (
            FurBall {
                gravity: f32::NAN,
                ..Default::default()
            },
            "FurBall.gravity",
        ),
        (
            FurBall {
                noise: f32::INFINITY,
                ..Default::default()
            },
            "FurBall.noise",
        ),
        (
            FurBall {
                clumping: 1.5,
                ..Default::default()
            },
            "FurBall.clumping",
        ),
        (
            FurBall {
                clumping: f32::NAN,
                ..Default::default()
            },
            "FurBall.clumping",
        ),
        (
            FurBall {
                strands: 100_000_000,
                ..Default::default()
            },
            "GiB",
        ),
        (
            FurBall {
                strands: usize::MAX,
                ..Default::default()
            },
            "GiB",
        ),
    ];
    for (f, needle) in bad {
        match f.build() {
            Err(Error::InvalidArg(m)) => assert!(m.contains(needle), "{m:?} lacks {needle:?}"),
            other => panic!(
                "{needle}: expected InvalidArg, got {:?}",
                other.map(|s| s.counts.len())
            ),
        }
    }
    let m = FurBall {
        strands: 100_000_000,
        ..Default::default()
    }
    .build()
    .unwrap_err()
    .to_string();
    println!("{m}");
    // Single strands and single segments are fine.
    let s = FurBall {
        strands: 1,
        segments: 1,
        ..Default::default()
    }
    .build()
    .unwrap();
    assert_eq!(s.points.len(), 2);
}

fn small_patch(style: HairStyle) -> ScalpPatch {
    ScalpPatch {
        style,
        strands: 1000,
        ..Default::default()
    }
}

/// Sum of segment lengths of each strand, averaged.
fn mean_arc_length(s: &Strands) -> f64 {
    strands_of(s)
        .map(|p| p.windows(2).map(|w| dist(w[0], w[1])).sum::<f64>())
        .sum::<f64>()
        / s.counts.len() as f64
}

#[test]
fn scalp_patch_is_deterministic() {
    for style in [HairStyle::Straight, HairStyle::Wavy, HairStyle::Curly] {
        let a = small_patch(style).build().unwrap();
        assert_eq!(a, small_patch(style).build().unwrap());
        let b = ScalpPatch {
            seed: 9,
            ..small_patch(style)
        }
        .build()
        .unwrap();
        assert_ne!(a.points, b.points);
    }
}

#[test]
fn scalp_patch_shape() {
    let mut arcs = Vec::new();
    for style in [HairStyle::Straight, HairStyle::Wavy, HairStyle::Curly] {
        let h = small_patch(style);
        let s = h.build().unwrap();
        let shortest = check_common(&s, h.strands, h.segments, h.root_radius, h.tip_radius);
        let step = f64::from(h.length) / f64::from(h.segments);
        // Sliding over the head shortens a centre-line step a little; it never collapses.
        assert!(
            shortest > 0.3 * step,
            "{style:?}: shortest segment {shortest} vs {step}"
        );
        let r = f64::from(h.radius);
        // The patch spans width / radius radians around latitude 30 degrees.
        let half = f64::from(h.width / h.radius) / 2.0;
        let lat0 = 30f64.to_radians();
        let mut mean_drop = 0.0;
        for p in strands_of(&s) {
            let root = len(p[0]);
            assert!((root - r).abs() <= 1e-5 * r, "root at {root}");
            let lat = (f64::from(p[0][1]) / root).asin();
            let lon = f64::from(p[0][0]).atan2(f64::from(p[0][2]));
            assert!((lat - lat0).abs() <= half + 1e-5 && lon.abs() <= half + 1e-5);
            // No point enters the head.
            assert!(p[1..].iter().all(|&q| len(q) >= r * (1.0 - 1e-6)));
            // Strands from the top of the patch rise before they fall, so the drop is
            // smallest there: still a quarter of the length with the default gravity.
            let drop = f64::from(p[0][1] - p[p.len() - 1][1]);
            assert!(drop > 0.25 * f64::from(h.length), "{style:?}: drop {drop}");
            mean_drop += drop / h.strands as f64;
        }
        assert!(
            mean_drop > 0.6 * f64::from(h.length),
            "{style:?}: mean drop {mean_drop}"
        );
        let arc = mean_arc_length(&s);
        println!(
            "{style:?}: mean fibre length {arc:.3} (centre line {}), mean drop {mean_drop:.3}",
            h.length
        );
        arcs.push(arc);
    }
    let length = f64::from(ScalpPatch::default().length);
    // A straight fibre is its centre line (only sliding over the head could shorten it).
    // Waves and curls wind the fibre: a helix of radius a and pitch p is
    // sqrt(1 + (2 pi a / p)^2) = 1.18 times longer than its axis for the defaults, a planar
    // sine wave about 1 + (pi a / p)^2 = 1.10; the ramp from the root takes some off.
    assert!(arcs[0] <= length * (1.0 + 1e-5) && arcs[0] > 0.95 * length);
    assert!(arcs[1] > 1.03 * length && arcs[2] > 1.12 * length && arcs[2] > arcs[1]);
}

#[test]
fn scalp_patch_parameters_are_checked() {
    let d = ScalpPatch::default;
    let bad: Vec<(ScalpPatch, &str)> = vec![
        (ScalpPatch { strands: 0, ..d() }, "ScalpPatch.strands"),
        (ScalpPatch { segments: 0, ..d() }, "ScalpPatch.segments"),
        (
            ScalpPatch {
                radius: -1.0,
                ..d()
            },
            "ScalpPatch.radius",
        ),
        (ScalpPatch { width: 0.0, ..d() }, "ScalpPatch.width"),
        (ScalpPatch { width: 1.6, ..d() }, "at most pi/2 * radius"),
        (
            ScalpPatch {
                length: f32::NAN,
                ..d()
            },
            "ScalpPatch.length",
        ),
        (
            ScalpPatch {
                root_radius: -0.0,
                ..d()
            },
            "ScalpPatch.root_radius",
        ),
        (
            ScalpPatch {
                tip_radius: f32::INFINITY,
                ..d()
            },
            "ScalpPatch.tip_radius",
        ),
        (
            ScalpPatch {
                amplitude: -0.1,
                ..d()
            },
            "ScalpPatch.amplitude",
        ),
        (ScalpPatch { period: 0.0, ..d() }, "ScalpPatch.period"),
        (
            ScalpPatch {
                gravity: f32::NAN,
                ..d()
            },
            "ScalpPatch.gravity",
        ),
        (
            ScalpPatch {
                strands: 1 << 40,
                ..d()
            },
            "GiB",
        ),
    ];
    for (h, needle) in bad {
        match h.build() {
            Err(Error::InvalidArg(m)) => assert!(m.contains(needle), "{m:?} lacks {needle:?}"),
            other => panic!(
                "{needle}: expected InvalidArg, got {:?}",
                other.map(|s| s.counts.len())
            ),
        }
    }
}

/// Peak resident memory of this process, from /proc (Linux), in MiB.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

#[test]
fn a_million_strands() {
    let f = FurBall {
        strands: 1_000_000,
        segments: 16,
        ..Default::default()
    };
    let start = Instant::now();
    let s = f.build().unwrap();
    let secs = start.elapsed().as_secs_f64();
    let bytes = s.points.capacity() * 12 + s.radii.capacity() * 4 + s.counts.capacity() * 4;
    println!(
        "fur ball 1e6 x 16: {secs:.2} s, {:.0} MiB of strands ({} bytes per segment), peak RSS {:.0} MiB",
        bytes as f64 / (1u64 << 20) as f64,
        bytes / s.segment_count(),
        peak_rss_mib().unwrap_or(f64::NAN)
    );
    assert_eq!(s.points.len(), 17_000_000);
    // Exactly sized: no growth slack in the flat arrays.
    assert_eq!(
        (s.points.capacity(), s.radii.capacity()),
        (17_000_000, 17_000_000)
    );
    assert!(s.points.iter().flatten().all(|v| v.is_finite()));
    drop(s);

    let h = ScalpPatch {
        strands: 1_000_000,
        segments: 16,
        style: HairStyle::Curly,
        ..Default::default()
    };
    let start = Instant::now();
    let s = h.build().unwrap();
    println!(
        "curly scalp 1e6 x 16: {:.2} s",
        start.elapsed().as_secs_f64()
    );
    assert_eq!(s.points.len(), 17_000_000);
}
