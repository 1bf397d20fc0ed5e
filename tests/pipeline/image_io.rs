//! Round trips through OpenImageIO for every supported format, and the errors that keep
//! bad input from becoming a file.

use std::path::PathBuf;

use hairtrace::Error;
use hairtrace::image::{Image, PixelType, Placement, WriteOptions, read_image, write_image};

/// A scratch path unique to the test, inside cargo's per-target temporary directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("image_io");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

/// A deterministic image with every value distinct, spread over [lo, hi].
fn ramp(width: usize, height: usize, channels: usize, lo: f32, hi: f32) -> Vec<f32> {
    let n = width * height * channels;
    (0..n)
        .map(|i| {
            // A stride coprime with n scatters neighbouring values across the range.
            let k = (i * 7919) % n;
            lo + (hi - lo) * k as f32 / (n - 1) as f32
        })
        .collect()
}

/// An independent sRGB encoder, the oracle for the integer formats' quantisation.
fn srgb(v: f32) -> f32 {
    let v = f64::from(v.clamp(0.0, 1.0));
    (if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }) as f32
}

fn opts(pixel_type: PixelType) -> WriteOptions {
    WriteOptions {
        pixel_type: Some(pixel_type),
        ..WriteOptions::default()
    }
}

fn write_read(name: &str, w: usize, h: usize, c: usize, px: &[f32], o: &WriteOptions) -> Image {
    let path = scratch(name);
    write_image(&path, w, h, c, px, o).unwrap();
    let image = read_image(&path).unwrap();
    assert_eq!((image.width, image.height, image.channels), (w, h, c));
    image
}

/// Checks an integer-format round trip: colour within half a step in sRGB-encoded space,
/// after un-premultiplying, and alpha (the last of 2 or 4 channels) within half a step.
fn assert_quantised(original: &[f32], read: &[f32], channels: usize, levels: f32) {
    let tolerance = 0.5 / levels + 1e-6;
    let alpha = matches!(channels, 2 | 4).then(|| channels - 1);
    let pixels = original
        .chunks_exact(channels)
        .zip(read.chunks_exact(channels));
    for (p, (orig, back)) in pixels.enumerate() {
        let (oa, ba) = alpha.map_or((1.0, 1.0), |i| (orig[i], back[i]));
        for c in 0..channels {
            let (expected, got) = if Some(c) == alpha {
                (oa.clamp(0.0, 1.0), ba)
            } else {
                (srgb(orig[c] / oa), srgb(back[c] / ba))
            };
            assert!(
                (expected - got).abs() <= tolerance,
                "pixel {p} channel {c}: wrote {orig:?}, read {back:?} ({expected} vs {got})"
            );
        }
    }
}

/// Premultiplied RGBA or grey + alpha with alpha in [0.1, 1] and straight colour in [0, 1].
fn premultiplied(width: usize, height: usize, channels: usize) -> Vec<f32> {
    let mut px = ramp(width, height, channels, 0.0, 1.0);
    for pixel in px.chunks_exact_mut(channels) {
        let a = 0.1 + 0.9 * pixel[channels - 1];
        pixel[channels - 1] = a;
        pixel[..channels - 1].iter_mut().for_each(|v| *v *= a);
    }
    px
}

#[test]
fn exr_float_round_trip_is_exact() {
    let (w, h, c) = (13, 7, 3);
    let px = ramp(w, h, c, -2.0, 1.0e4);
    let image = write_read("float.exr", w, h, c, &px, &WriteOptions::default());
    assert_eq!(image.pixels, px);
}

#[test]
fn exr_rgba_float_keeps_alpha_untouched() {
    let (w, h, c) = (4, 3, 4);
    let px = ramp(w, h, c, 0.0, 3.0);
    let image = write_read("rgba.exr", w, h, c, &px, &opts(PixelType::F32));
    assert_eq!(image.pixels, px);
}

#[test]
fn exr_half_is_within_half_precision() {
    let (w, h, c) = (11, 9, 3);
    let px = ramp(w, h, c, 1.0e-3, 6.0e4);
    let image = write_read("half.exr", w, h, c, &px, &opts(PixelType::F16));
    for (&a, &b) in px.iter().zip(&image.pixels) {
        // 10 stored mantissa bits: rounding moves a normal value by at most 2^-11 of it.
        assert!((a - b).abs() <= a.abs() * 2f32.powi(-11), "{a} vs {b}");
    }
}

#[test]
fn png_8_bit_round_trips_within_quantisation() {
    let (w, h, c) = (17, 5, 3);
    let px = ramp(w, h, c, 0.0, 1.0);
    let image = write_read("rgb8.png", w, h, c, &px, &WriteOptions::default());
    assert_quantised(&px, &image.pixels, c, 255.0);
}

#[test]
fn png_16_bit_rgba_round_trips_within_quantisation() {
    let (w, h, c) = (9, 8, 4);
    let px = premultiplied(w, h, c);
    let image = write_read("rgba16.png", w, h, c, &px, &opts(PixelType::U16));
    assert_quantised(&px, &image.pixels, c, 65535.0);
}

#[test]
fn png_8_bit_grey_alpha_round_trips_within_quantisation() {
    let (w, h, c) = (5, 6, 2);
    let px = premultiplied(w, h, c);
    let image = write_read("ya8.png", w, h, c, &px, &WriteOptions::default());
    assert_quantised(&px, &image.pixels, c, 255.0);
}

#[test]
fn png_grey_clamps_out_of_range_values() {
    let px = [-0.5, 0.0, 0.25, 1.0, 7.0, 0.5];
    let image = write_read("grey.png", 3, 2, 1, &px, &WriteOptions::default());
    assert_eq!(image.pixels[0], 0.0);
    assert_eq!(image.pixels[4], 1.0);
    assert_quantised(&px, &image.pixels, 1, 255.0);
}

#[test]
fn png_is_srgb_encoded_on_disk() {
    // Linear 0.5 is sRGB 0.7354, stored as 188 in 8 bits; read_image decodes it back, so
    // check that the decoded value sits at code 188, not at 128 (a linear file).
    let image = write_read("mid.png", 1, 1, 1, &[0.5], &WriteOptions::default());
    assert!(
        (srgb(image.pixels[0]) * 255.0 - 188.0).abs() < 1e-3,
        "{:?}",
        image.pixels
    );
}

#[test]
fn tiff_8_and_16_bit_round_trip() {
    let (w, h, c) = (6, 10, 3);
    let px = ramp(w, h, c, 0.0, 1.0);
    let image = write_read("rgb8.tif", w, h, c, &px, &WriteOptions::default());
    assert_quantised(&px, &image.pixels, c, 255.0);
    let image = write_read("rgb16.tiff", w, h, c, &px, &opts(PixelType::U16));
    assert_quantised(&px, &image.pixels, c, 65535.0);
    let px = premultiplied(w, h, 4);
    let image = write_read("rgba8.tif", w, h, 4, &px, &WriteOptions::default());
    assert_quantised(&px, &image.pixels, 4, 255.0);
}

#[test]
fn jpeg_reads_back_roughly() {
    // JPEG is lossy: a smooth image should survive with small errors.
    let (w, h, c) = (32, 24, 3);
    let px: Vec<f32> = (0..w * h * c)
        .map(|i| {
            let (x, y, ch) = ((i / c) % w, i / c / w, i % c);
            (x as f32 / w as f32 * 0.6 + y as f32 / h as f32 * 0.3 + ch as f32 * 0.05).min(1.0)
        })
        .collect();
    for name in ["smooth.jpg", "smooth.JPEG"] {
        let image = write_read(name, w, h, c, &px, &WriteOptions::default());
        let mean_err: f32 = px
            .iter()
            .zip(&image.pixels)
            .map(|(&a, &b)| (srgb(a) - srgb(b)).abs())
            .sum::<f32>()
            / px.len() as f32;
        assert!(mean_err < 0.01, "{name}: mean sRGB error {mean_err}");
    }
}

#[test]
fn jpeg_refuses_alpha() {
    // OIIO would silently write 3 channels instead.
    for channels in [2, 4] {
        let path = scratch("alpha.jpg");
        let px = vec![0.5; channels];
        let err = write_image(&path, 1, 1, channels, &px, &WriteOptions::default()).unwrap_err();
        assert!(
            matches!(&err, Error::Image(m) if m.contains("JPEG")),
            "{err:?}"
        );
        assert!(!path.exists());
    }
}

#[test]
fn missing_directory_is_an_error_naming_the_path() {
    let path = scratch("no-such-dir").join("out.png");
    let err = write_image(&path, 1, 1, 1, &[0.5], &WriteOptions::default()).unwrap_err();
    let text = err.to_string();
    assert!(text.contains(path.to_str().unwrap()), "{text}");
}

#[test]
fn reading_a_missing_file_is_an_error_naming_the_path() {
    let path = scratch("absent.exr");
    let err = read_image(&path).unwrap_err();
    assert!(err.to_string().contains(path.to_str().unwrap()), "{err}");
}

#[test]
fn unknown_or_missing_extension_is_refused() {
    for (name, needle) in [
        ("picture.bmp", "\".bmp\""),
        ("picture", "no file extension"),
    ] {
        let path = scratch(name);
        let err = write_image(&path, 1, 1, 1, &[0.5], &WriteOptions::default()).unwrap_err();
        match err {
            Error::Image(m) => {
                assert!(m.contains(needle), "{m}");
                assert!(m.contains(".exr") && m.contains(".png"), "{m}");
            }
            other => panic!("expected Error::Image, got {other:?}"),
        }
        assert!(!path.exists());
    }
}

#[test]
fn non_finite_pixels_are_refused() {
    for (bad, word) in [(f32::NAN, "NaN"), (f32::INFINITY, "infinite")] {
        for name in ["bad.exr", "bad.png"] {
            let path = scratch(name);
            let mut px = vec![0.25; 4 * 3 * 2];
            px[(4 + 2) * 2 + 1] = bad; // pixel (2, 1), channel 1
            let err = write_image(&path, 4, 3, 2, &px, &WriteOptions::default()).unwrap_err();
            let expected = format!("pixel (2, 1) channel 1 is {word}");
            assert!(
                matches!(&err, Error::InvalidArg(m) if m.contains(&expected)),
                "{err:?}"
            );
            assert!(!path.exists(), "{name} was written");
        }
    }
}

#[test]
fn bad_sizes_are_refused() {
    let path = scratch("size.exr");
    let cases: [(usize, usize, usize, usize); 5] = [
        (2, 2, 3, 11), // one value short
        (2, 2, 3, 13), // one too many
        (0, 2, 3, 0),  // empty
        (1, 1, 5, 5),  // too many channels
        (1, 1, 0, 0),  // no channels
    ];
    for (w, h, c, len) in cases {
        let px = vec![0.5; len];
        let err = write_image(&path, w, h, c, &px, &WriteOptions::default()).unwrap_err();
        assert!(
            matches!(err, Error::InvalidArg(_)),
            "{w}x{h}x{c}, {len}: {err:?}"
        );
    }
    assert!(!path.exists());
}

#[test]
fn pixel_type_the_format_cannot_store_is_refused() {
    let err = write_image(
        &scratch("float.jpg"),
        1,
        1,
        1,
        &[0.5],
        &opts(PixelType::U16),
    )
    .unwrap_err();
    assert!(matches!(err, Error::Image(m) if m.contains("U16")));
}

#[cfg(unix)]
#[test]
fn non_utf8_path_is_refused() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let path = scratch("x").with_file_name(OsStr::from_bytes(b"bad\xff.png"));
    let err = write_image(&path, 1, 1, 1, &[0.5], &WriteOptions::default()).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidArg(m) if m.contains("UTF-8")),
        "{err:?}"
    );
    assert!(matches!(read_image(&path), Err(Error::InvalidArg(_))));
}

/// Attributes and the data window go into an EXR's header and come back; formats without
/// a data window store the pixels alone, read back as a whole frame.
#[test]
fn exr_keeps_its_attributes_and_its_place_in_the_frame() {
    let (w, h) = (3, 2);
    let px = ramp(w, h, 3, 0.0, 1.0);
    let placement = Placement {
        x: 5,
        y: 1,
        full_width: 10,
        full_height: 4,
    };
    let o = WriteOptions {
        placement: Some(placement),
        attributes: vec![
            ("hairtrace:seed".into(), "7".into()),
            ("note".into(), "a b=c".into()),
        ],
        ..WriteOptions::default()
    };
    let exr = write_read("placed.exr", w, h, 3, &px, &o);
    assert_eq!(exr.placement, placement);
    assert_eq!(exr.attribute("hairtrace:seed"), Some("7"));
    assert_eq!(exr.attribute("note"), Some("a b=c"));
    assert_eq!(exr.pixels, px);
    let png = write_read("placed.png", w, h, 3, &px, &o);
    assert_eq!(png.placement, Placement::whole(w, h));
    let outside = WriteOptions {
        placement: Some(Placement { x: 8, ..placement }),
        ..WriteOptions::default()
    };
    let err = write_image(&scratch("outside.exr"), w, h, 3, &px, &outside).unwrap_err();
    assert!(
        err.to_string().contains("does not fit in its 10x4 frame"),
        "{err}"
    );
}

/// Writers racing on one path, each with its own image, while a reader reads it over and
/// over: every read finds a whole image of one writer (never a partial file, never a mix),
/// and the last one standing is whole. Writing in place, or through one shared temporary
/// name, fails this within a few of its hundreds of reads.
#[test]
fn concurrent_writers_never_leave_a_partial_or_mixed_image() {
    let path = scratch("raced.exr");
    let (w, h, writers, rounds) = (256, 128, 4, 12);
    let done = std::sync::atomic::AtomicUsize::new(0);
    let whole = |image: &Image| {
        let v = image.pixels[0];
        (1..=writers).any(|k| v == k as f32) && image.pixels.iter().all(|&p| p == v)
    };
    let reads = std::thread::scope(|s| {
        for k in 1..=writers {
            let (path, done) = (&path, &done);
            s.spawn(move || {
                // Counted even when a write fails, so that the reader stops.
                let _finished = Finished(done);
                let px = vec![k as f32; w * h * 3];
                for _ in 0..rounds {
                    write_image(path, w, h, 3, &px, &WriteOptions::default()).unwrap();
                }
            });
        }
        let mut reads = 0;
        while done.load(std::sync::atomic::Ordering::SeqCst) < writers {
            if path.exists() {
                let image = read_image(&path).expect("a complete image at the path");
                assert!(whole(&image), "a mixed image: {:?}", &image.pixels[..4]);
                reads += 1;
            }
        }
        reads
    });
    assert!(whole(&read_image(&path).unwrap()));
    let leftovers = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".raced.exr."))
        .count();
    assert_eq!(leftovers, 0, "temporary files left behind");
    eprintln!("{reads} reads during the race");
}

/// Counts a finished writer when dropped.
struct Finished<'a>(&'a std::sync::atomic::AtomicUsize);

impl Drop for Finished<'_> {
    fn drop(&mut self) {
        self.0.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    }
}
