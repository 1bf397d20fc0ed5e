//! Lights: light sampling agrees with BSDF-style direction sampling and with closed forms,
//! the pdfs the integrator's MIS needs are consistent, the lat-long orientation is the
//! documented one, and an EXR environment read through OIIO works.
//!
//! Statistical comparisons use fixed seeds and bounds of 4.5 combined standard errors.

use std::f32::consts::PI;
use std::path::PathBuf;

use crate::image::{WriteOptions, write_image};
use crate::math::sampling::{UNIFORM_SPHERE_PDF, cosine_hemisphere, uniform_sphere};
use crate::scene::{Environment, Light};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const N: usize = 200_000;
const SIGMAS: f64 = 4.5;

/// Mean and standard error per channel of a Monte Carlo estimator.
#[derive(Debug, Clone, Copy)]
struct Estimate {
    mean: [f64; 3],
    se: [f64; 3],
}

impl Estimate {
    fn of(values: impl Iterator<Item = Vec3>) -> Estimate {
        let (mut n, mut s, mut s2) = (0.0f64, [0.0f64; 3], [0.0f64; 3]);
        for v in values {
            n += 1.0;
            for c in 0..3 {
                let x = f64::from(v[c]);
                assert!(x.is_finite(), "non-finite estimator value {v}");
                s[c] += x;
                s2[c] += x * x;
            }
        }
        let mean = s.map(|x| x / n);
        let se = std::array::from_fn(|c| ((s2[c] / n - mean[c] * mean[c]).max(0.0) / n).sqrt());
        Estimate { mean, se }
    }

    fn assert_matches(&self, other: &Estimate, what: &str) {
        for c in 0..3 {
            let bound = SIGMAS * (self.se[c].powi(2) + other.se[c].powi(2)).sqrt() + 1e-6;
            assert!(
                (self.mean[c] - other.mean[c]).abs() <= bound,
                "{what}, channel {c}: {self:?} vs {other:?}"
            );
        }
    }

    fn assert_near(&self, exact: Vec3, what: &str) {
        let exact = Estimate {
            mean: exact.to_array().map(f64::from),
            se: [0.0; 3],
        };
        self.assert_matches(&exact, what);
    }
}

fn uniforms(seed: u64, n: usize) -> impl Iterator<Item = [f32; 2]> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n).map(move |_| [rng.random(), rng.random()])
}

/// Irradiance at `p` on a surface facing `n`, by the light's own sampling.
fn by_light_sampling(light: &Light, p: Vec3, n: Vec3) -> Estimate {
    Estimate::of(uniforms(1, N).map(|u| {
        light.sample_li(p, u).map_or(Vec3::ZERO, |s| {
            assert!(s.pdf > 0.0 && s.pdf.is_finite() && s.radiance.is_finite());
            s.radiance * s.wi.dot(n).max(0.0) / s.pdf
        })
    }))
}

/// The same irradiance by cosine-weighted directions around `n`, as a diffuse BSDF would
/// draw them: weight L cos / (cos / pi) = pi L.
fn by_cosine_sampling(light: &Light, p: Vec3, n: Vec3) -> Estimate {
    let (t, b) = n.any_orthonormal_pair();
    Estimate::of(uniforms(2, N).map(|u| {
        let l = cosine_hemisphere(u);
        let wi = t * l.x + b * l.y + n * l.z;
        light.eval_li(p, wi).map_or(Vec3::ZERO, |e| e.radiance * PI)
    }))
}

/// Lambert's closed form for the irradiance from a uniformly emitting polygon that lies
/// wholly above the surface's horizon.
fn polygon_irradiance(p: Vec3, n: Vec3, vertices: &[Vec3], radiance: Vec3) -> Vec3 {
    let mut sum = 0.0f32;
    for i in 0..vertices.len() {
        let a = (vertices[i] - p).normalize();
        let b = (vertices[(i + 1) % vertices.len()] - p).normalize();
        sum += a.angle_between(b) * a.cross(b).normalize().dot(n);
    }
    radiance * sum.abs() / 2.0
}

/// A sky for the tests: a gradient, a black ground, and a small, very bright sun (the
/// case importance sampling exists for).
fn sky_pixels(width: usize, height: usize) -> Vec<f32> {
    let mut px = Vec::with_capacity(width * height * 3);
    for row in 0..height {
        for col in 0..width {
            let v = (row as f32 + 0.5) / height as f32;
            let rgb = if v > 0.75 {
                [0.0; 3]
            } else if (40..42).contains(&col) && (10..12).contains(&row) {
                [2000.0, 1800.0, 1500.0]
            } else {
                [
                    0.2 + 0.3 * (1.0 - v),
                    0.3 + 0.4 * (1.0 - v),
                    0.6 + 0.4 * (1.0 - v),
                ]
            };
            px.extend_from_slice(&rgb);
        }
    }
    px
}

fn sky() -> Environment {
    Environment::from_pixels(64, 32, 3, &sky_pixels(64, 32)).unwrap()
}

/// Lat-long direction of map point (u, v), as the module doc of `envmap` defines it.
fn latlong_dir(u: f32, v: f32) -> Vec3 {
    let (theta, phi) = (PI * v, 2.0 * PI * u);
    Vec3::new(
        -theta.sin() * phi.sin(),
        theta.cos(),
        theta.sin() * phi.cos(),
    )
}

/// Integral of `le` over the sphere by a fine midpoint rule in (cos theta, phi),
/// independent of the light's sampling code.
fn integral_over_sphere(f: impl Fn(Vec3) -> Vec3) -> Vec3 {
    let (nz, np) = (2048, 4096);
    let mut sum = glam::DVec3::ZERO;
    for i in 0..nz {
        let z = -1.0 + 2.0 * (i as f32 + 0.5) / nz as f32;
        let r = (1.0 - z * z).sqrt();
        for j in 0..np {
            let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
            sum += f(Vec3::new(r * phi.cos(), z, r * phi.sin())).as_dvec3();
        }
    }
    (sum * (4.0 * std::f64::consts::PI / (nz * np) as f64)).as_vec3()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-lights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn lights_are_shareable_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Light>();
}

#[test]
fn uniform_environment_irradiance_is_pi_l() {
    let l = Vec3::new(1.0, 0.5, 0.25);
    let light = Light::Environment(Environment::uniform(l).unwrap());
    let (p, n) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.6, 0.8));
    let by_light = by_light_sampling(&light, p, n);
    by_light.assert_near(PI * l, "uniform environment, light sampling");
    by_cosine_sampling(&light, p, n).assert_near(PI * l, "uniform environment, cosine");
    assert_eq!(light.le(Vec3::X), l);
}

#[test]
fn distant_light_with_a_disc_matches_cosine_sampling_and_the_closed_form() {
    let irradiance = Vec3::new(3.0, 2.5, 2.0);
    let dir = Vec3::new(0.3, 1.0, 0.2);
    let light = Light::distant(dir, irradiance, 0.2f32.to_degrees()).unwrap();
    let (p, n) = (Vec3::ZERO, Vec3::Y);
    // The disc is wholly above the horizon, so E = irradiance * cos(angle to the normal).
    let exact = irradiance * dir.normalize().dot(n);
    let by_light = by_light_sampling(&light, p, n);
    let by_cosine = by_cosine_sampling(&light, p, n);
    by_light.assert_near(exact, "distant, light sampling");
    by_cosine.assert_near(exact, "distant, cosine sampling");
    by_light.assert_matches(&by_cosine, "distant, light vs cosine");
    eprintln!(
        "distant 0.2 rad: exact {exact}, light {:.4?} +- {:.1e}, cosine {:.4?} +- {:.1e}",
        by_light.mean, by_light.se[0], by_cosine.mean, by_cosine.se[0]
    );

    // A sun-sized disc (0.27 degrees) keeps its exposure and stays finite.
    let sun = Light::distant(dir, irradiance, 0.00465f32.to_degrees()).unwrap();
    by_light_sampling(&sun, p, n).assert_near(exact, "sun-sized distant light");
    let s = sun.sample_li(p, [0.3, 0.7]).unwrap();
    assert!(s.wi.angle_between(dir.normalize()) <= 0.00466);
    assert!((sun.pdf_li(p, s.wi) - s.pdf).abs() <= 1e-4 * s.pdf);
    assert!(sun.le(s.wi).is_finite() && sun.le(s.wi).x > 0.0 && sun.le(Vec3::Y) == Vec3::ZERO);
}

#[test]
fn delta_distant_light_delivers_its_irradiance() {
    let irradiance = Vec3::new(1.0, 2.0, 3.0);
    let dir = Vec3::new(0.0, 1.0, 1.0);
    let light = Light::distant(dir, irradiance, 0.0).unwrap();
    let s = light.sample_li(Vec3::ZERO, [0.1, 0.9]).unwrap();
    assert!(s.is_delta && s.pdf == 1.0 && s.distance == f32::INFINITY);
    assert!((s.wi - dir.normalize()).length() < 1e-6 && s.radiance == irradiance);
    // BSDF-sampled rays never find it.
    assert!(light.eval_li(Vec3::ZERO, s.wi).is_none());
    assert_eq!(light.pdf_li(Vec3::ZERO, s.wi), 0.0);
    assert_eq!(light.le(s.wi), Vec3::ZERO);
    by_light_sampling(&light, Vec3::ZERO, Vec3::Y)
        .assert_near(irradiance * dir.normalize().y, "delta distant");
}

#[test]
fn rect_light_matches_cosine_sampling_and_lamberts_formula() {
    let radiance = Vec3::new(4.0, 3.0, 2.0);
    let (corner, eu, ev) = (
        Vec3::new(-0.5, 1.0, -0.3),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.3, 0.6),
    );
    let vertices = [corner, corner + eu, corner + eu + ev, corner + ev];
    let (p, n) = (Vec3::new(0.1, 0.0, 0.05), Vec3::Y);
    let exact = polygon_irradiance(p, n, &vertices, radiance);
    // eu x ev points toward p: one-sided and two-sided lights both reach p.
    for two_sided in [false, true] {
        let light = Light::rect(corner, eu, ev, radiance, two_sided).unwrap();
        let by_light = by_light_sampling(&light, p, n);
        let by_cosine = by_cosine_sampling(&light, p, n);
        by_light.assert_near(exact, "rect, light sampling");
        by_cosine.assert_near(exact, "rect, cosine sampling");
        by_light.assert_matches(&by_cosine, "rect, light vs cosine");
        eprintln!(
            "rect (two-sided {two_sided}): exact {exact}, light {:.4?} +- {:.1e}, cosine \
             {:.4?} +- {:.1e}",
            by_light.mean, by_light.se[0], by_cosine.mean, by_cosine.se[0]
        );
    }
    // Reversed edges turn the emitting side away from p.
    let back = Light::rect(corner, ev, eu, radiance, false).unwrap();
    assert!(uniforms(3, 1000).all(|u| back.sample_li(p, u).is_none()));
    by_cosine_sampling(&back, p, n).assert_near(Vec3::ZERO, "back of a one-sided rect");
    let both = Light::rect(corner, ev, eu, radiance, true).unwrap();
    by_light_sampling(&both, p, n).assert_near(exact, "reversed two-sided rect");
}

#[test]
fn rect_intersection_and_sample_distance() {
    let light = Light::rect(
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::ONE,
        false,
    )
    .unwrap();
    let org = Vec3::new(1.0, 0.0, 0.5);
    assert_eq!(light.intersect(org, Vec3::Y), Some(2.0));
    assert_eq!(light.intersect(org, 2.0 * Vec3::Y), Some(1.0));
    assert_eq!(light.intersect(org, -Vec3::Y), None);
    assert_eq!(light.intersect(Vec3::new(2.5, 0.0, 0.5), Vec3::Y), None);
    assert_eq!(light.intersect(org, Vec3::X), None);
    for u in uniforms(4, 1000) {
        let s = light.sample_li(org, u).unwrap();
        let t = light.intersect(org, s.wi).unwrap();
        assert!(
            (t - s.distance).abs() <= 1e-5 * s.distance,
            "{t} {}",
            s.distance
        );
    }
    assert!(!light.is_infinite());
    assert!((light.power(1.0) - PI * 2.0).abs() < 1e-5);
}

#[test]
fn sample_li_pdf_equals_pdf_li_for_every_light() {
    let lights = [
        Light::Environment(Environment::uniform(Vec3::ONE).unwrap()),
        Light::Environment(sky().with_rotation(37.0).unwrap()),
        Light::distant(Vec3::new(1.0, 1.0, 0.0), Vec3::ONE, 0.3f32.to_degrees()).unwrap(),
        Light::rect(
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::X * 2.0,
            Vec3::Z * 2.0,
            Vec3::ONE,
            true,
        )
        .unwrap(),
    ];
    let p = Vec3::new(0.2, -0.5, 0.1);
    for (k, light) in lights.iter().enumerate() {
        let mut worst = 0.0f32;
        for u in uniforms(10 + k as u64, 20_000) {
            let Some(s) = light.sample_li(p, u) else {
                continue;
            };
            let e = light
                .eval_li(p, s.wi)
                .expect("a sampled direction reaches the light");
            worst = worst.max((e.pdf - s.pdf).abs() / s.pdf);
            assert_eq!(e.radiance, s.radiance, "light {k}");
            assert!(
                e.distance == s.distance || (e.distance - s.distance).abs() < 1e-5 * s.distance
            );
        }
        eprintln!("light {k}: worst relative pdf mismatch {worst:.2e}");
        assert!(worst < 1e-3, "light {k}: pdf mismatch {worst}");
    }
}

#[test]
fn environment_importance_sampling_matches_uniform_sampling() {
    let env = sky().with_rotation(-65.0).unwrap().with_scale(0.5).unwrap();
    let light = Light::Environment(env.clone());
    let exact = integral_over_sphere(|d| env.le(d));
    // Integral of Le over the sphere: importance sampling vs uniform directions.
    let by_is = Estimate::of(uniforms(5, N).map(|u| {
        let s = light.sample_li(Vec3::ZERO, u).unwrap();
        s.radiance / s.pdf
    }));
    let by_uniform =
        Estimate::of(uniforms(6, N).map(|u| env.le(uniform_sphere(u)) / UNIFORM_SPHERE_PDF));
    by_is.assert_matches(&by_uniform, "environment map: importance vs uniform");
    by_is.assert_near(exact, "environment map importance sampling vs quadrature");
    by_uniform.assert_near(exact, "environment map uniform sampling vs quadrature");
    // The point of importance sampling: far less noise on a map with a sun.
    let ratio = (by_uniform.se[0] / by_is.se[0]).powi(2);
    eprintln!(
        "env integral: quadrature {exact}, IS {:.3?} +- {:.2e}, uniform {:.3?} +- {:.2e}, \
         variance ratio {ratio:.0}",
        by_is.mean, by_is.se[0], by_uniform.mean, by_uniform.se[0]
    );
    assert!(ratio > 100.0, "variance ratio {ratio}");

    // Irradiance on a tilted surface, by light sampling and by cosine sampling.
    let n = Vec3::new(0.3, 0.9, -0.3).normalize();
    let by_light = by_light_sampling(&light, Vec3::ZERO, n);
    by_light.assert_matches(
        &by_cosine_sampling(&light, Vec3::ZERO, n),
        "environment map irradiance: light vs cosine",
    );
    // Power uses the same mean radiance.
    let mean_lum = (exact / (4.0 * PI)).dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let power = light.power(1.0) / (4.0 * PI * PI);
    assert!(
        (power - mean_lum).abs() < 1e-3 * mean_lum,
        "{power} {mean_lum}"
    );
}

#[test]
fn one_bright_pixel_is_sampled_toward_its_direction() {
    let (w, h) = (32, 16);
    let (col, row) = (24, 4);
    let mut px = vec![0.0f32; w * h];
    px[row * w + col] = 5.0;
    let env = Environment::from_pixels(w, h, 1, &px).unwrap();
    let at = |c: f32, r: f32| latlong_dir(c / w as f32, r / h as f32);
    let centre = at(col as f32 + 0.5, row as f32 + 0.5);
    // The pixel's farthest corner from its centre.
    let reach = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
        .map(|(dc, dr)| at(col as f32 + dc, row as f32 + dr).angle_between(centre))
        .into_iter()
        .fold(0.0f32, f32::max);
    for u in uniforms(7, 5000) {
        let s = env.sample(u).unwrap();
        assert!(
            s.wi.angle_between(centre) <= reach * 1.001,
            "{} from {centre}",
            s.wi
        );
        assert_eq!(s.radiance, Vec3::splat(5.0));
    }
    // Rotating the map by 90 degrees about +y moves the sampled direction with it.
    let turned = env.with_rotation(90.0).unwrap();
    let expected = glam::Mat3::from_rotation_y(PI / 2.0) * centre;
    let s = turned.sample([0.5, 0.5]).unwrap();
    assert!(s.wi.angle_between(expected) <= reach * 1.001);
}

#[test]
fn latlong_orientation_is_as_documented() {
    // A 4 x 2 map whose lower row is, left to right: +z, -x, -z, +x (u = 0, .25, .5, .75
    // at the cells' left edges: probe the cell centres instead, u = 0.125 + k/4).
    let (w, h) = (8, 4);
    let mut px = vec![0.0f32; w * h];
    for (k, v) in px.iter_mut().enumerate() {
        *v = k as f32;
    }
    let env = Environment::from_pixels(w, h, 1, &px).unwrap();
    let texel = |col: usize, row: usize| Vec3::splat((row * w + col) as f32);
    let horizon = |d: Vec3| (d + Vec3::new(0.0, -0.1, 0.0)).normalize();
    // Directions slightly below the horizon fall in row 2; u = 0.5 is -z, column 4.
    assert_eq!(
        env.le(horizon(-Vec3::Z) + Vec3::new(-0.01, 0.0, 0.0)),
        texel(3, 2)
    );
    assert_eq!(
        env.le(horizon(-Vec3::Z) + Vec3::new(0.01, 0.0, 0.0)),
        texel(4, 2)
    );
    assert_eq!(env.le(horizon(Vec3::X)), texel(6, 2));
    assert_eq!(env.le(horizon(-Vec3::X)), texel(2, 2));
    assert_eq!(env.le(horizon(Vec3::new(0.01, 0.0, 1.0))), texel(7, 2));
    assert_eq!(env.le(horizon(Vec3::new(-0.01, 0.0, 1.0))), texel(0, 2));
    // The top row is around +y, the bottom row around -y.
    assert_eq!(env.le(Vec3::new(0.0, 0.99, -0.1).normalize()), texel(4, 0));
    assert_eq!(env.le(Vec3::new(0.0, -0.99, -0.1).normalize()), texel(4, 3));
    // +90 degrees about +y carries the map's -z (its centre) to -x.
    let turned = env.clone().with_rotation(90.0).unwrap();
    assert_eq!(
        turned.le(horizon(-Vec3::X) + Vec3::new(0.0, 0.0, -0.01)),
        texel(4, 2)
    );
    // And the documented formula agrees with every cell centre.
    for row in 0..h {
        for col in 0..w {
            let d = latlong_dir((col as f32 + 0.5) / w as f32, (row as f32 + 0.5) / h as f32);
            assert_eq!(env.le(d), texel(col, row), "cell ({col}, {row})");
        }
    }
}

#[test]
fn exr_environment_read_through_oiio_matches_the_pixels() {
    let (w, h) = (64, 32);
    let px = sky_pixels(w, h);
    let path = scratch("sky.exr");
    write_image(&path, w, h, 3, &px, &WriteOptions::default()).unwrap();
    let from_file = Environment::from_file(&path).unwrap();
    let from_pixels = Environment::from_pixels(w, h, 3, &px).unwrap();
    for u in uniforms(8, 2000) {
        let d = uniform_sphere(u);
        assert_eq!(from_file.le(d), from_pixels.le(d));
        assert_eq!(from_file.eval(d), from_pixels.eval(d));
    }
    let a = from_file.sample([0.3, 0.6]).unwrap();
    assert_eq!(Some(a), from_pixels.sample([0.3, 0.6]));
    let missing = Environment::from_file(&scratch("missing.exr")).unwrap_err();
    assert!(missing.to_string().contains("missing.exr"), "{missing}");
}

#[test]
fn invalid_lights_are_errors() {
    let one = Vec3::ONE;
    assert!(Light::distant(Vec3::ZERO, one, 0.0).is_err());
    assert!(Light::distant(Vec3::new(f32::NAN, 1.0, 0.0), one, 0.0).is_err());
    assert!(Light::distant(Vec3::Y, -one, 0.0).is_err());
    assert!(Light::distant(Vec3::Y, Vec3::splat(f32::INFINITY), 0.0).is_err());
    assert!(Light::distant(Vec3::Y, one, 90.0).is_err());
    assert!(Light::distant(Vec3::Y, one, -0.1).is_err());
    assert!(Light::distant(Vec3::Y, one, f32::NAN).is_err());
    assert!(Light::rect(Vec3::ZERO, Vec3::X, Vec3::X * 2.0, one, false).is_err());
    assert!(Light::rect(Vec3::ZERO, Vec3::ZERO, Vec3::Y, one, false).is_err());
    assert!(
        Light::rect(
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(1.0, f32::NAN, 1.0),
            false
        )
        .is_err()
    );
    assert!(Light::rect(Vec3::splat(f32::INFINITY), Vec3::X, Vec3::Y, one, false).is_err());
    assert!(Environment::uniform(Vec3::new(0.0, -1.0, 0.0)).is_err());
    assert!(Environment::from_pixels(2, 1, 3, &[0.0; 5]).is_err());
    assert!(Environment::from_pixels(0, 1, 3, &[]).is_err());
    assert!(Environment::from_pixels(1, 1, 5, &[0.0; 5]).is_err());
    let bad = Environment::from_pixels(2, 1, 1, &[1.0, -0.5]).unwrap_err();
    assert!(bad.to_string().contains("(1, 0)"), "{bad}");
    assert!(Environment::from_pixels(1, 1, 1, &[f32::NAN]).is_err());
    let env = Environment::uniform(one).unwrap();
    assert!(env.clone().with_rotation(f32::INFINITY).is_err());
    assert!(env.clone().with_scale(-1.0).is_err());
    assert!(env.with_scale(f32::NAN).is_err());
}

#[test]
fn black_environment_map_still_samples_validly() {
    let env = Environment::from_pixels(8, 4, 3, &[0.0; 96]).unwrap();
    for u in uniforms(9, 100) {
        if let Some(s) = env.sample(u) {
            assert!(s.pdf > 0.0 && s.pdf.is_finite() && s.radiance == Vec3::ZERO);
        }
    }
    assert_eq!(Light::Environment(env).power(10.0), 0.0);
}
