//! The camera's rays, automatic framing, and the film and tiles contract: crops equal the
//! full frame bit for bit, thread counts do not matter, cancellation is prompt, and bad
//! samples never poison a pixel.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::render::film::{FirstHit, PixelAccumulator};
use crate::render::sampler::PixelSampler;
use crate::render::tiles::{TileOptions, render_tiles, tiles};
use crate::render::{Aovs, Film, NoProgress, PixelFilter, RenderStatus, Window};
use crate::scene::Camera;
use glam::Vec3;

const EPS: f32 = 1e-5;

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < EPS
}

#[test]
fn render_pieces_are_shareable_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Camera>();
    send_sync::<Film>();
    send_sync::<PixelSampler>();
    send_sync::<PixelAccumulator>();
}

#[test]
fn pinhole_rays_follow_the_fov_and_image_axes() {
    let eye = Vec3::new(1.0, 2.0, 3.0);
    let cam = Camera::new(eye, eye + Vec3::new(0.0, 0.0, -5.0), Vec3::Y, 90.0, 2.0).unwrap();
    let ray = |x, y| cam.ray([x, y], [0.5, 0.5]);
    let (o, d) = ray(0.5, 0.5);
    assert_eq!(o, eye);
    assert!(close(d, -Vec3::Z));
    // 90 degrees vertically: the top edge centre is 45 degrees up; x grows to the right
    // (+x when looking down -z), y grows downward.
    assert!(close(
        ray(0.5, 0.0).1,
        Vec3::new(0.0, 1.0, -1.0).normalize()
    ));
    assert!(close(
        ray(0.5, 1.0).1,
        Vec3::new(0.0, -1.0, -1.0).normalize()
    ));
    // Aspect 2: the right edge is at tan = 2.
    assert!(close(
        ray(1.0, 0.5).1,
        Vec3::new(2.0, 0.0, -1.0).normalize()
    ));
    assert!(close(
        ray(0.0, 0.0).1,
        Vec3::new(-2.0, 1.0, -1.0).normalize()
    ));
    // A tilted up vector only needs to be non-parallel.
    let tilted = Camera::new(eye, eye - Vec3::Z, Vec3::new(0.0, 1.0, 0.7), 90.0, 1.0).unwrap();
    assert!(close(
        tilted.ray([0.5, 0.0], [0.0; 2]).1,
        Vec3::new(0.0, 1.0, -1.0).normalize()
    ));
    assert_eq!(cam.eye(), eye);
    assert!(close(cam.forward(), -Vec3::Z));
    // A new aspect keeps the vertical fov and the view.
    let square = cam.with_aspect(1.0).unwrap();
    assert!(close(
        square.ray([1.0, 0.0], [0.5; 2]).1,
        Vec3::new(1.0, 1.0, -1.0).normalize()
    ));
    assert!(cam.with_aspect(0.0).is_err() && cam.with_aspect(f32::NAN).is_err());
}

#[test]
fn thin_lens_rays_meet_on_the_plane_of_focus() {
    let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 40.0, 1.5)
        .unwrap()
        .with_thin_lens(0.1, 4.0)
        .unwrap();
    for ndc in [[0.5, 0.5], [0.1, 0.8], [0.95, 0.05]] {
        let meet = |lens| {
            let (o, d) = cam.ray(ndc, lens);
            assert!((d.length() - 1.0).abs() < 1e-6);
            assert!(o.z.abs() < 1e-7 && o.truncate().length() <= 0.1 + 1e-6);
            // Where the ray crosses the plane z = -4.
            o + d * ((-4.0 - o.z) / d.z)
        };
        let reference = meet([0.5, 0.5]);
        for lens in [[0.0, 0.0], [0.99, 0.2], [0.3, 0.97], [0.7, 0.6]] {
            assert!((meet(lens) - reference).length() < 1e-5, "{ndc:?} {lens:?}");
        }
    }
    let pinhole = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 40.0, 1.5).unwrap();
    assert_eq!(
        pinhole
            .with_thin_lens(0.0, 1.0)
            .unwrap()
            .ray([0.2, 0.3], [0.9, 0.9]),
        pinhole.ray([0.2, 0.3], [0.1, 0.1])
    );
}

#[test]
fn invalid_cameras_are_errors() {
    let (e, t, up) = (Vec3::ZERO, -Vec3::Z, Vec3::Y);
    assert!(Camera::new(e, e, up, 45.0, 1.0).is_err());
    assert!(Camera::new(e, t, -Vec3::Z, 45.0, 1.0).is_err());
    assert!(Camera::new(e, t, Vec3::ZERO, 45.0, 1.0).is_err());
    assert!(Camera::new(e, t, up, 0.0, 1.0).is_err());
    assert!(Camera::new(e, t, up, 180.0, 1.0).is_err());
    assert!(Camera::new(e, t, up, f32::NAN, 1.0).is_err());
    assert!(Camera::new(e, t, up, 45.0, 0.0).is_err());
    assert!(Camera::new(e, t, up, 45.0, f32::INFINITY).is_err());
    assert!(Camera::new(Vec3::splat(f32::NAN), t, up, 45.0, 1.0).is_err());
    let cam = Camera::new(e, t, up, 45.0, 1.0).unwrap();
    assert!(cam.with_thin_lens(-0.1, 1.0).is_err());
    assert!(cam.with_thin_lens(0.1, 0.0).is_err());
    assert!(cam.with_thin_lens(f32::NAN, 1.0).is_err());
    assert!(Camera::frame_bounds(Vec3::ONE, Vec3::ZERO, 1.0, 40.0).is_err());
    assert!(Camera::frame_bounds(Vec3::ZERO, Vec3::splat(f32::INFINITY), 1.0, 40.0).is_err());
    assert!(Camera::frame_bounds(Vec3::ZERO, Vec3::ONE, 1.0, 200.0).is_err());
}

/// Image-plane coordinates in [-1, 1]^2 (x right, y up) of a point seen by `cam`,
/// recovered from the camera's own edge rays.
fn project(cam: &Camera, q: Vec3) -> (f32, f32) {
    let f = cam.forward();
    let edge = |ndc| {
        let d = cam.ray(ndc, [0.5, 0.5]).1;
        d / d.dot(f) - f
    };
    let (right, up) = (edge([1.0, 0.5]), edge([0.5, 0.0]));
    let l = q - cam.eye();
    let z = l.dot(f);
    (
        l.dot(right) / right.length_squared() / z,
        l.dot(up) / up.length_squared() / z,
    )
}

#[test]
fn frame_bounds_fits_the_box_in_view() {
    for (lo, hi, aspect) in [
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 3.0, 1.0), 1.0),
        (
            Vec3::new(10.0, 10.0, 10.0),
            Vec3::new(10.5, 10.1, 10.2),
            16.0 / 9.0,
        ),
        (Vec3::new(-5.0, -1.0, -1.0), Vec3::new(5.0, 1.0, 1.0), 0.5),
        (Vec3::splat(3.0), Vec3::splat(3.0), 1.0),
    ] {
        let cam = Camera::frame_bounds(lo, hi, aspect, 40.0).unwrap();
        let centre = (lo + hi) / 2.0;
        assert!(
            (cam.ray([0.5, 0.5], [0.5; 2]).1 - (centre - cam.eye()).normalize()).length() < 1e-5
        );
        // Seen from above and the front: the eye is higher than the centre and at +z.
        assert!(cam.eye().y > centre.y && cam.eye().z > centre.z);
        let mut widest = 0.0f32;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let (x, y) = project(&cam, corner);
            assert!(
                x.abs() < 1.0 && y.abs() < 1.0,
                "corner {corner} at ({x}, {y})"
            );
            widest = widest.max(x.abs()).max(y.abs());
        }
        eprintln!("box {lo}..{hi} aspect {aspect}: widest corner at {widest:.3} of the frame");
    }
}

/// A stand-in for the integrator: pixel values from the sampler only, with some
/// structure so that misplaced pixels would show.
fn shade(seed: u64, spp: u32) -> impl Fn((u32, u32), &mut PixelAccumulator) + Sync {
    move |(x, y), acc| {
        for s in 0..spp {
            let mut sampler = PixelSampler::new(seed, (x, y), s);
            let [a, b] = sampler.next_2d();
            let [c, ..] = sampler.next_4d();
            let radiance = Vec3::new(a + x as f32 * 0.01, b * y as f32, c);
            let hit = (a > 0.3).then_some(FirstHit {
                albedo: Vec3::new(a, b, c),
                depth: 1.0 + b,
                strand: Some(x * 1000 + y + s),
            });
            acc.add(radiance, hit.as_ref());
        }
    }
}

const ALL_AOVS: Aovs = Aovs {
    albedo: true,
    depth: true,
    strand_id: true,
};

fn render(width: u32, height: u32, crop: Option<Window>, threads: usize, tile: u32) -> Film {
    let mut film = Film::new(width, height, crop, ALL_AOVS).unwrap();
    let options = TileOptions {
        tile_size: tile,
        threads,
    };
    let status = render_tiles(&mut film, &options, &NoProgress, |p, a, _| {
        shade(99, 8)(p, a)
    })
    .unwrap();
    assert_eq!(status, RenderStatus::Complete);
    film
}

/// The channels of every buffer of a film at full-frame pixel (x, y).
fn pixel(film: &Film, x: u32, y: u32) -> Vec<u32> {
    let crop = film.crop();
    let i = ((y - crop.y0) * crop.width() + (x - crop.x0)) as usize;
    let mut v: Vec<f32> = film.rgb()[3 * i..3 * i + 3].to_vec();
    v.extend_from_slice(&film.albedo().unwrap()[3 * i..3 * i + 3]);
    v.push(film.depth().unwrap()[i]);
    v.push(film.strand_id().unwrap()[i]);
    v.iter().map(|f| f.to_bits()).collect()
}

#[test]
fn crops_threads_and_tile_sizes_give_bit_identical_pixels() {
    let (w, h) = (53, 37);
    let full = render(w, h, None, 1, 16);
    let full2 = render(w, h, None, 2, 16);
    assert_eq!(full.rgb(), full2.rgb());
    assert_eq!(full.strand_id(), full2.strand_id());
    let odd_tiles = render(w, h, None, 2, 7);
    assert_eq!(full.rgb(), odd_tiles.rgb());
    assert_eq!(full.albedo(), odd_tiles.albedo());
    assert_eq!(full.depth(), odd_tiles.depth());

    for crop in [
        Window {
            x0: 5,
            y0: 3,
            x1: 30,
            y1: 20,
        },
        Window {
            x0: 0,
            y0: 0,
            x1: 1,
            y1: 1,
        },
        Window {
            x0: 40,
            y0: 30,
            x1: 53,
            y1: 37,
        },
    ] {
        for threads in [1, 2] {
            let part = render(w, h, Some(crop), threads, 16);
            assert_eq!(part.rgb().len(), 3 * crop.pixel_count() as usize);
            for (x, y) in crop.pixels() {
                assert_eq!(pixel(&part, x, y), pixel(&full, x, y), "pixel ({x}, {y})");
            }
        }
    }
    // The pieces of a frame split four ways assemble into the frame.
    let mut assembled = vec![0.0f32; full.rgb().len()];
    for crop in [
        Window {
            x0: 0,
            y0: 0,
            x1: 20,
            y1: 10,
        },
        Window {
            x0: 20,
            y0: 0,
            x1: 53,
            y1: 10,
        },
        Window {
            x0: 0,
            y0: 10,
            x1: 53,
            y1: 11,
        },
        Window {
            x0: 0,
            y0: 11,
            x1: 53,
            y1: 37,
        },
    ] {
        let part = render(w, h, Some(crop), 2, 16);
        for (k, (x, y)) in crop.pixels().enumerate() {
            let i = (y * w + x) as usize;
            assembled[3 * i..3 * i + 3].copy_from_slice(&part.rgb()[3 * k..3 * k + 3]);
        }
    }
    assert_eq!(assembled, full.rgb());
}

#[test]
fn aovs_average_albedo_and_keep_the_nearest_hit() {
    let mut acc = PixelAccumulator::default();
    acc.add(Vec3::ONE, None);
    let far = FirstHit {
        albedo: Vec3::new(0.2, 0.4, 0.6),
        depth: 3.0,
        strand: Some(7),
    };
    let near = FirstHit {
        albedo: Vec3::new(0.6, 0.2, 0.2),
        depth: 2.0,
        strand: None,
    };
    acc.add(Vec3::ONE, Some(&far));
    acc.add(Vec3::ONE, Some(&near));
    let mut film = Film::new(1, 1, None, ALL_AOVS).unwrap();
    let done = render_tiles(
        &mut film,
        &TileOptions::default(),
        &NoProgress,
        |_, a, _| *a = acc.clone(),
    )
    .unwrap();
    assert_eq!(done, RenderStatus::Complete);
    assert_eq!(film.rgb(), &[1.0, 1.0, 1.0]);
    let albedo = film.albedo().unwrap();
    assert!((albedo[0] - 0.8 / 3.0).abs() < 1e-6 && (albedo[1] - 0.2).abs() < 1e-6);
    assert_eq!(film.depth().unwrap(), &[2.0]);
    // The nearest hit is a mesh: no strand.
    assert_eq!(film.strand_id().unwrap(), &[-1.0]);

    let plain = Film::new(4, 4, None, Aovs::default()).unwrap();
    assert!(plain.albedo().is_none() && plain.depth().is_none() && plain.strand_id().is_none());
}

#[test]
fn non_finite_samples_are_counted_as_black_and_never_poison_a_pixel() {
    let mut film = Film::new(8, 8, None, ALL_AOVS).unwrap();
    let bad = [
        Vec3::new(f32::NAN, 1.0, 1.0),
        Vec3::splat(f32::INFINITY),
        Vec3::new(1.0, f32::NEG_INFINITY, 0.0),
    ];
    let status = render_tiles(
        &mut film,
        &TileOptions::default(),
        &NoProgress,
        |(x, y), acc, _| {
            for s in 0..4u32 {
                if x == 3 && y == 5 && s < 3 {
                    acc.add(bad[s as usize], None);
                } else if x == 1 && y == 1 && s == 0 {
                    let hit = FirstHit {
                        albedo: Vec3::ONE,
                        depth: f32::NAN,
                        strand: Some(1),
                    };
                    acc.add(Vec3::ONE, Some(&hit));
                } else {
                    acc.add(Vec3::splat(2.0), None);
                }
            }
        },
    )
    .unwrap();
    assert_eq!(status, RenderStatus::Complete);
    assert!(film.rgb().iter().all(|v| v.is_finite()));
    assert!(film.depth().unwrap().iter().all(|v| v.is_finite()));
    assert_eq!(film.rejected_samples(), 4);
    let at = |x: usize, y: usize| &film.rgb()[3 * (y * 8 + x)..3 * (y * 8 + x) + 3];
    // Three of four samples rejected: one good sample of 2 over four samples.
    assert_eq!(at(3, 5), &[0.5, 0.5, 0.5]);
    assert_eq!(at(1, 1), &[1.5, 1.5, 1.5]);
    assert_eq!(at(0, 0), &[2.0, 2.0, 2.0]);
}

#[test]
fn cancelling_stops_the_render_promptly() {
    let (w, h) = (128, 128);
    for threads in [1, 2] {
        let mut film = Film::new(w, h, None, Aovs::default()).unwrap();
        let shaded = AtomicU64::new(0);
        let calls = AtomicU64::new(0);
        let cancel_after_first_tile = |done: u64, total: u64| {
            assert!(done <= total && total == u64::from(w * h));
            calls.fetch_add(1, Ordering::Relaxed);
            false
        };
        let options = TileOptions {
            tile_size: 16,
            threads,
        };
        let status = render_tiles(
            &mut film,
            &options,
            &cancel_after_first_tile,
            |p, acc, _| {
                shaded.fetch_add(1, Ordering::Relaxed);
                shade(1, 4)(p, acc)
            },
        )
        .unwrap();
        assert_eq!(status, RenderStatus::Cancelled);
        let shaded = shaded.into_inner();
        // At most the tiles in flight when the first one finished, of 64 tiles.
        eprintln!(
            "{threads} thread(s): cancelled after {shaded} of {} pixels, {} progress calls",
            w * h,
            calls.into_inner()
        );
        assert!(shaded <= 2 * 256 * threads as u64, "{shaded} pixels shaded");
        // The first finished tile is kept; unfinished ones stay black.
        let lit = film.rgb().chunks(3).filter(|p| p[2] > 0.0).count();
        assert!(lit >= 256 && lit as u64 <= shaded, "{lit}");
    }
}

#[test]
fn progress_counts_up_to_the_total() {
    let seen = std::sync::Mutex::new(Vec::new());
    let record = |done: u64, total: u64| {
        seen.lock().unwrap().push((done, total));
        true
    };
    let mut film = Film::new(
        40,
        24,
        Some(Window {
            x0: 3,
            y0: 2,
            x1: 38,
            y1: 21,
        }),
        Aovs::default(),
    )
    .unwrap();
    let options = TileOptions {
        tile_size: 8,
        threads: 2,
    };
    assert_eq!(
        render_tiles(&mut film, &options, &record, |p, a, _| shade(3, 1)(p, a)).unwrap(),
        RenderStatus::Complete
    );
    let seen = seen.into_inner().unwrap();
    assert_eq!(seen.len(), tiles(film.crop(), 8).len());
    assert!(seen.windows(2).all(|p| p[0].0 < p[1].0));
    assert_eq!(*seen.last().unwrap(), (35 * 19, 35 * 19));
}

#[test]
fn tiles_cover_the_window_once() {
    let window = Window {
        x0: 3,
        y0: 2,
        x1: 38,
        y1: 21,
    };
    for size in [1, 7, 16, 100] {
        let mut covered = vec![0u8; 40 * 24];
        for t in tiles(window, size) {
            assert!(t.width() <= size && t.height() <= size && t.pixel_count() > 0);
            for (x, y) in t.pixels() {
                covered[(y * 40 + x) as usize] += 1;
            }
        }
        for y in 0..24 {
            for x in 0..40 {
                let inside = (3..38).contains(&x) && (2..21).contains(&y);
                assert_eq!(
                    covered[(y * 40 + x) as usize],
                    u8::from(inside),
                    "({x}, {y})"
                );
            }
        }
    }
    assert!(tiles(window, 0).is_empty());
}

#[test]
fn invalid_films_and_options_are_errors() {
    assert!(Film::new(0, 10, None, Aovs::default()).is_err());
    let outside = Window {
        x0: 0,
        y0: 0,
        x1: 11,
        y1: 5,
    };
    assert!(Film::new(10, 10, Some(outside), Aovs::default()).is_err());
    let empty = Window {
        x0: 4,
        y0: 4,
        x1: 4,
        y1: 8,
    };
    assert!(Film::new(10, 10, Some(empty), Aovs::default()).is_err());
    // Far more memory than any machine has: an error, not an abort.
    assert!(Film::new(u32::MAX, u32::MAX, None, ALL_AOVS).is_err());
    let mut film = Film::new(4, 4, None, Aovs::default()).unwrap();
    let zero_tiles = TileOptions {
        tile_size: 0,
        threads: 1,
    };
    assert!(render_tiles(&mut film, &zero_tiles, &NoProgress, |_, _, _| {}).is_err());
    assert!(PixelFilter::tent(0.0).is_err() && PixelFilter::tent(f32::NAN).is_err());
}

#[test]
fn pixel_filters_place_samples_around_the_pixel_centre() {
    let film = Film::new(200, 100, None, Aovs::default()).unwrap();
    assert_eq!(film.ndc((0, 0), [0.0, 0.0]), [0.0025, 0.005]);
    assert_eq!(film.ndc((199, 99), [0.5, 0.5]), [1.0, 1.0]);
    assert_eq!(PixelFilter::BOX.sample([0.0, 0.5]), [-0.5, 0.0]);
    // A tent of radius 1: offsets in (-1, 1), symmetric, denser near the centre.
    let tent = PixelFilter::tent(1.0).unwrap();
    let n = 10_000;
    let offsets: Vec<f32> = (0..n)
        .map(|i| tent.sample([(i as f32 + 0.5) / n as f32, 0.5])[0])
        .collect();
    assert!(offsets.iter().all(|o| o.abs() < 1.0));
    let mean: f32 = offsets.iter().sum::<f32>() / n as f32;
    let inner = offsets.iter().filter(|o| o.abs() < 0.5).count() as f32 / n as f32;
    assert!(mean.abs() < 1e-4, "{mean}");
    // For the triangle on [-1, 1], P(|x| < 1/2) = 3/4.
    assert!((inner - 0.75).abs() < 1e-3, "{inner}");
}

/// A pixel that never ends (a stand-in for billions of samples) still hears the progress
/// sink, which cancels: the render returns. A watchdog fails the test instead of hanging
/// if it does not (the bound is no timing claim: a minute against a few tens of ms).
#[test]
fn cancelling_stops_a_pixel_that_never_ends() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut film = Film::new(4, 4, None, Aovs::default()).unwrap();
        let calls = AtomicU64::new(0);
        let cancel = |done: u64, _total: u64| {
            assert_eq!(done, 0, "no pixel can finish");
            calls.fetch_add(1, Ordering::Relaxed);
            false
        };
        let options = TileOptions {
            tile_size: 16,
            threads: 2,
        };
        let status = render_tiles(&mut film, &options, &cancel, |_, acc, pulse| {
            while pulse.keep_going() {
                acc.add(Vec3::ONE, None);
            }
        });
        tx.send((status, calls.into_inner(), film.rgb().to_vec()))
            .unwrap();
    });
    let (status, calls, rgb) = rx
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the render was not cancelled: it would never return");
    assert_eq!(status.unwrap(), RenderStatus::Cancelled);
    assert!(calls >= 1);
    // The unfinished pixels are dropped, not stored half done.
    assert!(rgb.iter().all(|&v| v == 0.0), "{rgb:?}");
}
