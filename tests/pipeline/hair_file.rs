//! The .hair reader and writer: exact round trips, a clear error for each malformed input,
//! and a deterministic mini-fuzz that must never panic.

use hairtrace::Error;
use hairtrace::formats::hair::{
    HEADER_BYTES, Thickness, encode_hair, info_report, parse_hair, read_hair_file, write_hair_file,
};
use hairtrace::scene::{FurBall, Strands};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Strands with varied counts, radii and (optionally) colours.
fn varied(strands: usize, colors: bool, seed: u64) -> Strands {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut s = Strands::default();
    for _ in 0..strands {
        let count = rng.random_range(2..40u32);
        s.counts.push(count);
        for _ in 0..count {
            s.points.push([
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
                rng.random_range(-10.0..10.0),
            ]);
            s.radii.push(rng.random_range(1e-6..0.1));
        }
    }
    if colors {
        s.colors = Some((0..s.points.len()).map(|_| rng.random()).collect());
    }
    s
}

fn bits(s: &Strands) -> (Vec<u32>, Vec<u32>, Vec<u32>, Option<Vec<u32>>) {
    let flat = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect();
    (
        flat(&s.points),
        s.radii.iter().map(|x| x.to_bits()).collect(),
        s.counts.clone(),
        s.colors.as_deref().map(flat),
    )
}

fn round_trip(s: &Strands, t: Thickness) -> Strands {
    parse_hair(&encode_hair(s, t).unwrap(), t).unwrap()
}

#[test]
fn round_trip_is_bit_exact() {
    for t in [Thickness::Diameter, Thickness::Radius] {
        for colors in [false, true] {
            let s = varied(3000, colors, 7);
            assert_eq!(bits(&round_trip(&s, t)), bits(&s), "{t:?} colours {colors}");
        }
    }
    // Uniform counts and radii take the header's defaults instead of arrays.
    let fur = FurBall {
        strands: 500,
        ..Default::default()
    }
    .build()
    .unwrap();
    let mut uniform = fur.clone();
    uniform.radii.fill(0.0123);
    for s in [&fur, &uniform, &Strands::default()] {
        let bytes = encode_hair(s, Thickness::Diameter).unwrap();
        assert_eq!(bits(&round_trip(s, Thickness::Diameter)), bits(s));
        assert!(bytes.len() <= HEADER_BYTES + 16 * s.points.len());
    }
    // Extreme radii survive the doubling and halving.
    let mut extreme = varied(2, false, 1);
    extreme.radii[0] = f32::MIN_POSITIVE;
    extreme.radii[1] = 1e-44; // subnormal
    extreme.radii[2] = f32::MAX / 2.0;
    assert_eq!(
        bits(&round_trip(&extreme, Thickness::Diameter)),
        bits(&extreme)
    );
}

/// A .hair file assembled by hand: header fields, then `arrays` as raw bytes.
fn file(strands: u32, points: u32, flags: u32, default_segments: u32, thickness: f32) -> Vec<u8> {
    let mut b = b"HAIR".to_vec();
    for v in [strands, points, flags, default_segments] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [thickness, 0.0, 0.5, 0.5, 0.5] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b.resize(HEADER_BYTES, 0);
    b
}

fn push_f32s(b: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        b.extend_from_slice(&x.to_le_bytes());
    }
}

fn push_u16s(b: &mut Vec<u8>, v: &[u16]) {
    for x in v {
        b.extend_from_slice(&x.to_le_bytes());
    }
}

const SEGMENTS: u32 = 1;
const POINTS: u32 = 2;
const THICKNESS: u32 = 4;
const TRANSPARENCY: u32 = 8;
const COLORS: u32 = 16;

/// Two strands (2 and 3 points) with every array, and the offsets of its arrays.
fn two_strands(point: [f32; 3], thickness: f32, color: f32) -> Vec<u8> {
    let mut b = file(
        2,
        5,
        SEGMENTS | POINTS | THICKNESS | TRANSPARENCY | COLORS,
        0,
        1.0,
    );
    push_u16s(&mut b, &[1, 2]);
    let mut pts = vec![0.0f32; 15];
    pts[..3].copy_from_slice(&[1.0, 2.0, 3.0]);
    pts[9..12].copy_from_slice(&point); // strand 1, its point 1
    push_f32s(&mut b, &pts);
    push_f32s(&mut b, &[0.2, 0.2, 0.2, 0.2, thickness]);
    push_f32s(&mut b, &[0.5; 5]);
    let mut colors = vec![0.3f32; 15];
    colors[7] = color;
    push_f32s(&mut b, &colors);
    b
}

fn err(bytes: &[u8]) -> String {
    match parse_hair(bytes, Thickness::Diameter) {
        Err(Error::InvalidArg(m)) => m,
        other => panic!("expected InvalidArg, got {other:?}"),
    }
}

fn assert_err(bytes: &[u8], needles: &[&str]) {
    let m = err(bytes);
    for n in needles {
        assert!(m.contains(n), "{m:?} does not contain {n:?}");
    }
}

#[test]
fn a_hand_made_file_reads_as_written() {
    let s = parse_hair(&two_strands([4.0, 5.0, 6.0], 0.2, 0.3), Thickness::Diameter).unwrap();
    assert_eq!(s.counts, vec![2, 3]);
    assert_eq!(s.points[0], [1.0, 2.0, 3.0]);
    assert_eq!(s.points[3], [4.0, 5.0, 6.0]);
    // Diameter by default: radius is half the thickness; transparency is ignored.
    assert_eq!(Thickness::default(), Thickness::Diameter);
    assert_eq!(s.radii, vec![0.1; 5]);
    assert_eq!(s.colors.as_ref().unwrap()[2], [0.3; 3]);
    let r = parse_hair(&two_strands([4.0, 5.0, 6.0], 0.2, 0.3), Thickness::Radius).unwrap();
    assert_eq!(r.radii, vec![0.2; 5]);

    // No segments or thickness array: the header's defaults apply to every strand.
    let mut b = file(2, 6, POINTS, 2, 0.01);
    push_f32s(&mut b, &[0.0; 18]);
    let s = parse_hair(&b, Thickness::Diameter).unwrap();
    assert_eq!(
        (s.counts, s.radii, s.colors),
        (vec![3, 3], vec![0.005; 6], None)
    );
}

/// The fuzzer's seeds (fuzz/seeds) stay valid files, so fuzzing starts from real structure.
#[test]
fn fuzz_seeds_parse() {
    for seed in [
        &include_bytes!("../../fuzz/seeds/all_arrays.hair")[..],
        include_bytes!("../../fuzz/seeds/defaults.hair"),
        include_bytes!("../../fuzz/seeds/segments_thickness.hair"),
    ] {
        parse_hair(seed, Thickness::Diameter).unwrap();
    }
}

#[test]
fn short_files_and_wrong_magic() {
    let good = two_strands([4.0, 5.0, 6.0], 0.2, 0.3);
    for len in [0, 1, 4, 27, HEADER_BYTES - 1] {
        assert_err(
            &good[..len],
            &["shorter than the 128-byte", &format!("{len} bytes")],
        );
    }
    for len in [
        HEADER_BYTES,
        HEADER_BYTES + 1,
        HEADER_BYTES + 4,
        200,
        good.len() - 1,
    ] {
        assert_err(&good[..len], &["too short", "truncated"]);
    }
    let mut bad = good.clone();
    bad[..4].copy_from_slice(b"HAIX");
    assert_err(&bad, &["wrong magic", "HAIX"]);
    let mut bad = good.clone();
    bad[..4].copy_from_slice(b"RIAH"); // a big-endian writer
    assert_err(&bad, &["wrong magic"]);
}

#[test]
fn counts_that_do_not_fit_the_file() {
    // Every count that could ask for a huge allocation is checked against the file size.
    for (strands, points, flags) in [
        (u32::MAX, 5, SEGMENTS | POINTS),
        (2, u32::MAX, SEGMENTS | POINTS),
        (
            u32::MAX,
            u32::MAX,
            SEGMENTS | POINTS | THICKNESS | TRANSPARENCY | COLORS,
        ),
        (0x8000_0000, 0xFFFF_FFFE, POINTS),
    ] {
        let mut b = file(strands, points, flags, 1, 1.0);
        b.extend_from_slice(&[0u8; 100]);
        assert_err(
            &b,
            &[
                "too short",
                &format!("{strands} strands"),
                &format!("{points} points"),
            ],
        );
    }
    // The counts fit the file but not each other.
    let mut b = file(2, 6, SEGMENTS | POINTS, 0, 1.0);
    push_u16s(&mut b, &[1, 2]);
    push_f32s(&mut b, &[0.0; 18]);
    assert_err(
        &b,
        &["point count mismatch", "adds up to 5 points", "says 6"],
    );
    let mut b = file(2, 6, POINTS, 1, 1.0);
    push_f32s(&mut b, &[0.0; 18]);
    assert_err(
        &b,
        &["point count mismatch", "2 strands of 1 default segments"],
    );
    // 2^31 strands of 2^31 segments overflow u32 (and would wrap to 0 points) but not u64.
    let b = file(0x8000_0000, 0, POINTS, 0x7FFF_FFFF, 1.0);
    assert_err(&b, &["point count mismatch"]);
    let mut b = file(2, 2, POINTS, 0, 1.0);
    push_f32s(&mut b, &[0.0; 6]);
    assert_err(&b, &["default segment count is 0"]);
}

#[test]
fn missing_points_unknown_flags_and_trailing_data() {
    let mut b = file(1, 2, SEGMENTS | THICKNESS, 0, 1.0);
    push_u16s(&mut b, &[1]);
    push_f32s(&mut b, &[1.0, 1.0]);
    assert_err(&b, &["points array missing"]);
    let mut b = file(1, 2, POINTS | 64, 1, 1.0);
    push_f32s(&mut b, &[0.0; 6]);
    assert_err(&b, &["unknown array flags 0x40"]);
    let mut b = two_strands([4.0, 5.0, 6.0], 0.2, 0.3);
    b.extend_from_slice(&[7; 5]);
    assert_err(&b, &["5 bytes of trailing data"]);
}

#[test]
fn bad_strands_and_values_are_named() {
    let mut b = file(3, 5, SEGMENTS | POINTS, 0, 1.0);
    push_u16s(&mut b, &[2, 0, 1]);
    push_f32s(&mut b, &[0.0; 15]);
    assert_err(&b, &["strand 1 has 0 segments"]);
    for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_err(
            &two_strands([4.0, v, 6.0], 0.2, 0.3),
            &["point 3 (strand 1, point 1 of it)", "not finite"],
        );
    }
    for t in [f32::NAN, f32::INFINITY, -0.2, 0.0, -0.0, 1e-45] {
        assert_err(
            &two_strands([4.0, 5.0, 6.0], t, 0.3),
            &["thickness of point 4 (strand 1, point 2 of it) = "],
        );
    }
    let mut b = file(1, 2, POINTS, 1, 0.0);
    push_f32s(&mut b, &[0.0; 6]);
    assert_err(&b, &["default thickness = 0.0"]);
    for c in [f32::NAN, f32::INFINITY, -1.0] {
        assert_err(
            &two_strands([4.0, 5.0, 6.0], 0.2, c),
            &["colour", "point 2 (strand 1"],
        );
    }
}

#[test]
fn the_writer_refuses_what_the_format_cannot_hold() {
    let mut s = Strands {
        points: vec![[0.0; 3]; 65537],
        radii: vec![0.01; 65537],
        counts: vec![65537],
        colors: None,
    };
    let m = encode_hair(&s, Thickness::Diameter)
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("strand 0 has 65537 points") && m.contains("65536"),
        "{m}"
    );
    s.points.pop();
    s.radii.pop();
    s.counts[0] = 65536;
    assert_eq!(round_trip(&s, Thickness::Diameter), s);
    s.radii[7] = f32::MAX;
    let m = encode_hair(&s, Thickness::Diameter)
        .unwrap_err()
        .to_string();
    assert!(m.contains("radius 7") && m.contains("too large"), "{m}");
    assert_eq!(round_trip(&s, Thickness::Radius), s);
    s.points[3][0] = f32::NAN;
    let m = encode_hair(&s, Thickness::Diameter)
        .unwrap_err()
        .to_string();
    assert!(m.contains("point 3"), "{m}");
}

#[test]
fn files_on_disk() {
    let dir = std::env::temp_dir().join(format!("hairtrace-hair-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("groom.hair");
    let s = varied(50, true, 3);
    write_hair_file(&path, &s, Thickness::Diameter).unwrap();
    assert_eq!(read_hair_file(&path, Thickness::Diameter).unwrap(), s);

    std::fs::write(&path, b"HAIR").unwrap();
    let m = read_hair_file(&path, Thickness::Diameter)
        .unwrap_err()
        .to_string();
    assert!(m.contains("groom.hair") && m.contains("shorter"), "{m}");

    let missing = dir.join("no-such.hair");
    match read_hair_file(&missing, Thickness::Diameter) {
        Err(Error::Io(m)) => assert!(m.contains("no-such.hair"), "{m}"),
        other => panic!("expected Io, got {other:?}"),
    }
    let nowhere = dir.join("no-such-dir").join("out.hair");
    match write_hair_file(&nowhere, &s, Thickness::Diameter) {
        Err(Error::Io(m)) => assert!(m.contains("out.hair"), "{m}"),
        other => panic!("expected Io, got {other:?}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn info_report_summarises_a_groom() {
    let s = Strands {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0],
            [-1.0, 0.5, 0.0],
            [0.0, 0.0, 4.0],
            [0.0; 3],
        ],
        radii: vec![0.1, 0.2, 0.3, 0.4, 0.5],
        counts: vec![2, 3],
        colors: None,
    };
    let r = info_report(&s);
    println!("{r}");
    for needle in [
        "strands:  2",
        "points:   5",
        "segments: 3",
        "points per strand: min 2, max 3, mean 2.50",
        "bounds:   min (-1, 0, 0), max (1, 2, 4)",
        "radius:   min 0.1, max 0.5, mean 0.300000",
        "colours:  no",
    ] {
        assert!(r.contains(needle), "{r} lacks {needle}");
    }
    let coloured = Strands {
        colors: Some(vec![[1.0; 3]; 5]),
        ..s
    };
    assert!(info_report(&coloured).contains("colours:  yes"));
    let empty = info_report(&Strands::default());
    assert!(
        empty.contains("strands:  0") && empty.contains("bounds:   none"),
        "{empty}"
    );
}

/// 20k random mutations and truncations of valid files: every one parses or fails with an
/// error, none panics, and whatever parses is valid.
#[test]
fn mini_fuzz_never_panics() {
    let seeds = [
        encode_hair(&varied(4, true, 11), Thickness::Diameter).unwrap(),
        encode_hair(&varied(3, false, 12), Thickness::Diameter).unwrap(),
        encode_hair(
            &FurBall {
                strands: 3,
                segments: 4,
                ..Default::default()
            }
            .build()
            .unwrap(),
            Thickness::Diameter,
        )
        .unwrap(),
        two_strands([4.0, 5.0, 6.0], 0.2, 0.3),
    ];
    let mut rng = Pcg64::seed_from_u64(2024);
    let start = std::time::Instant::now();
    let (mut ok, mut failed) = (0, 0);
    for i in 0..20_000 {
        let mut b = seeds[i % seeds.len()].clone();
        for _ in 0..rng.random_range(1..4) {
            match rng.random_range(0..6) {
                // A random byte anywhere, biased towards the header.
                0 => {
                    let window = if rng.random() { 48 } else { b.len() };
                    let at = rng.random_range(0..window.clamp(1, b.len().max(1)));
                    if let Some(x) = b.get_mut(at) {
                        *x = rng.random();
                    }
                }
                // A random u32 over one of the header's counts.
                1 => {
                    let at = 4 * rng.random_range(1..5);
                    let v: u32 = match rng.random_range(0..3) {
                        0 => rng.random(),
                        1 => rng.random_range(0..64),
                        _ => u32::MAX - rng.random_range(0..4),
                    };
                    if b.len() >= at + 4 {
                        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
                    }
                }
                2 => b.truncate(rng.random_range(0..=b.len())),
                3 => b.extend((0..rng.random_range(1..32)).map(|_| rng.random::<u8>())),
                // Flip one bit.
                4 => {
                    let at = rng.random_range(0..b.len().max(1));
                    if let Some(x) = b.get_mut(at) {
                        *x ^= 1 << rng.random_range(0..8);
                    }
                }
                // A special float somewhere after the header.
                _ => {
                    let v = [f32::NAN, f32::INFINITY, -1.0, 0.0, 1e-45][rng.random_range(0..5)];
                    let at = rng.random_range(0..b.len().max(1)) & !3;
                    if b.len() >= at + 4 {
                        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
                    }
                }
            }
        }
        match parse_hair(&b, Thickness::Diameter) {
            Ok(s) => {
                s.validate().unwrap();
                ok += 1;
            }
            Err(Error::InvalidArg(m)) => {
                assert!(!m.is_empty());
                failed += 1;
            }
            Err(e) => panic!("unexpected error kind {e:?}"),
        }
    }
    println!(
        "mini-fuzz: {ok} parsed, {failed} rejected in {:.2} s",
        start.elapsed().as_secs_f64()
    );
    assert!(
        ok > 100 && failed > 10_000,
        "mutations too mild or too harsh: {ok} / {failed}"
    );
}
