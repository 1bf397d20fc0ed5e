//! The `auto` curve shape: ribbons for the strands thinner than a pixel give the image of
//! round tubes within noise, a groom seen both near and far is shared out between the two
//! shapes, and strands keep their numbers (material variation, the strand AOV) when split.

use std::path::Path;
use std::sync::Arc;

use crate::description::SceneDescription;
use crate::embree::{CurveBasis, CurveShape, Device, Geometry};
use crate::render::renderer::RenderOutput;
use crate::render::{Aovs, NoProgress};

/// A fur ball of `strands` brown strands with per-strand variation, in a uniform sky,
/// seen from `distance` at `size` x `size` pixels.
fn fur_ball(shape: &str, seed: u64, distance: f32, size: u32, spp: u32) -> SceneDescription {
    fur_ball_of("linear", shape, seed, distance, size, spp)
}

fn fur_ball_of(
    basis: &str,
    shape: &str,
    seed: u64,
    distance: f32,
    size: u32,
    spp: u32,
) -> SceneDescription {
    let text = format!(
        r#"
[render]
width = {size}
height = {size}
spp = {spp}
seed = {seed}
filter = "box"

[camera]
eye = [0, 0, {distance}]
target = [0, 0, 0]
fov_deg = 33

[materials.brown]
type = "hair"
sigma_a = [0.5447, 0.9061, 1.781]
absorption_variation = 0.5
roughness_variation = 0.5

[[groom]]
procedural = "fur_ball"
basis = "{basis}"
shape = "{shape}"
material = "brown"

[groom.params]
strands = 4000
segments = 8

[[light]]
type = "environment"
radiance = [1, 1, 1]
"#
    );
    SceneDescription::from_toml(&text, Path::new("."), "ribbons test").unwrap()
}

fn render(d: &SceneDescription, aovs: Aovs) -> RenderOutput {
    let mut built = d.build(Arc::new(Device::new(Some(2)).unwrap())).unwrap();
    built.render(aovs, &NoProgress).unwrap()
}

fn rmse(a: &[f32], b: &[f32]) -> f64 {
    let sum: f64 = a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum();
    (sum / a.len() as f64).sqrt()
}

fn curve_shapes(d: &SceneDescription) -> Vec<CurveShape> {
    curve_kinds(d).into_iter().map(|(_, shape)| shape).collect()
}

fn curve_kinds(d: &SceneDescription) -> Vec<(CurveBasis, CurveShape)> {
    let built = d.build(Arc::new(Device::new(Some(2)).unwrap())).unwrap();
    (built.world().unwrap().tracer.scene().geometries().iter())
        .filter_map(|g| match g {
            Geometry::Curves(c) => Some((c.basis(), c.shape())),
            _ => None,
        })
        .collect()
}

/// Renders `groom(shape, seed, spp)` round twice and auto once, and checks that auto differs
/// from a round render by no more than two round renders differ (their noise alone): a
/// systematic difference of the ribbons would add to it.
fn assert_auto_matches_round(groom: impl Fn(&str, u64, u32) -> SceneDescription) {
    let spp = 256;
    let reference = render(&groom("round", 1, spp), Aovs::default());
    let round = render(&groom("round", 2, spp), Aovs::default());
    let auto = render(&groom("auto", 3, spp), Aovs::default());
    let noise = rmse(round.film.rgb(), reference.film.rgb());
    let auto_error = rmse(auto.film.rgb(), reference.film.rgb());
    // 1.15x leaves room for noise, not for a bias of 0.5 noise.
    assert!(
        auto_error < 1.15 * noise,
        "auto differs from round by {auto_error}, round from round by {noise}"
    );
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let (m_auto, m_ref) = (mean(auto.film.rgb()), mean(reference.film.rgb()));
    assert!((m_auto - m_ref).abs() < 2e-3 * m_ref, "{m_auto} vs {m_ref}");
}

#[test]
fn auto_ribbons_give_the_image_of_round_tubes_within_noise() {
    // At 48 pixels across, every strand is under a pixel wide: `auto` is all ribbons.
    assert_eq!(
        curve_shapes(&fur_ball("auto", 0, 5.2, 48, 1)),
        [CurveShape::Flat]
    );
    assert_auto_matches_round(|shape, seed, spp| fur_ball(shape, seed, 5.2, 48, spp));
}

/// `auto` traces the thin strands of cubic grooms as linear ribbons through points on their
/// curves (the level of detail, `lod::DEFAULT_LOD_PIXELS`); the image is the round
/// tubes' within their noise.
#[test]
fn auto_level_of_detail_polylines_give_the_image_of_round_tubes_within_noise() {
    // B-spline at this 48-pixel view: 1.19x the noise at 0.05 px, 1.06x at the default
    // 0.02 (docs/large-grooms.md).
    let basis = "catmull_rom";
    let groom = |shape: &str, seed, spp| fur_ball_of(basis, shape, seed, 5.2, 48, spp);
    // Every strand is thin: polylines, and flat curves for the strands over the budget of
    // pieces per segment.
    let kinds = curve_kinds(&groom("auto", 0, 1));
    assert!(
        kinds.contains(&(CurveBasis::Linear, CurveShape::Flat)),
        "{basis}: {kinds:?}"
    );
    assert!(
        kinds.iter().all(|(_, shape)| *shape == CurveShape::Flat),
        "{kinds:?}"
    );
    assert_auto_matches_round(groom);
}

#[test]
fn a_groom_seen_near_and_far_is_shared_out_and_keeps_its_strand_numbers() {
    // At 256 pixels, a root 0.008 wide is a pixel wide 3.46 units from the eye: from 3.5
    // units, the roots facing the camera (2.5 units away) are wider and those on the far
    // side of the unit ball (4.5 units) narrower.
    let near = |shape| fur_ball(shape, 0, 3.5, 256, 1);
    assert_eq!(
        curve_shapes(&near("auto")),
        [CurveShape::Round, CurveShape::Flat]
    );
    assert_eq!(curve_shapes(&near("round")), [CurveShape::Round]);
    // The first hit's strand is the same strand whichever geometry holds it, except where
    // a ribbon's edge and a tube's differ (pixels straddling a strand's silhouette).
    let aovs = Aovs {
        strand_id: true,
        ..Aovs::default()
    };
    let ids = |shape| {
        render(&near(shape), aovs)
            .film
            .strand_id()
            .unwrap()
            .to_vec()
    };
    let (auto, round) = (ids("auto"), ids("round"));
    let same = auto.iter().zip(&round).filter(|(a, b)| a == b).count();
    assert!(
        same as f64 > 0.95 * auto.len() as f64,
        "{same} of {} pixels see the same strand",
        auto.len()
    );
}
