//! The `curve_parts` setting decides whether a build cuts a large groom into parts.

use std::path::Path;
use std::sync::Arc;

use crate::description::SceneDescription;
use crate::embree::Device;
use crate::{Aovs, NoProgress};

/// A fur ball of `strands` x 16 round linear segments, built for a `width` x `height` x 1
/// spp render with `curve_parts = parts`: the scenes its parts are built as (none built
/// yet, so this is cheap).
fn parts_built(width: u32, height: u32, parts: &str, strands: usize) -> usize {
    fur_ball_of(width, height, parts, strands)
        .build(Arc::new(Device::new(None).unwrap()))
        .unwrap()
        .world()
        .unwrap()
        .tracer
        .scene()
        .part_count()
}

/// The fur ball of [`parts_built`] at 2^18 segments, the least a geometry is cut at (in
/// parts of 2^10).
fn fur_ball(width: u32, height: u32, parts: &str) -> SceneDescription {
    fur_ball_of(width, height, parts, 1 << 14)
}

fn fur_ball_of(width: u32, height: u32, parts: &str, strands: usize) -> SceneDescription {
    let text = format!(
        r#"
[render]
width = {width}
height = {height}
spp = 1
curve_parts = "{parts}"

[materials.brown]
type = "hair"
sigma_a = [0.4, 0.6, 1.0]

[[groom]]
procedural = "fur_ball"
basis = "linear"
shape = "round"
material = "brown"

[groom.params]
strands = {strands}
segments = 16

[[light]]
type = "environment"
radiance = [1, 1, 1]
"#
    );
    SceneDescription::from_toml(&text, Path::new("."), "parts test").unwrap()
}

#[test]
fn a_large_groom_is_built_in_parts_as_the_setting_says() {
    // 2^20 segments: auto cuts them for 64 camera samples, not for 3 per segment.
    let (large, small) = (1 << 16, 1 << 14);
    assert_eq!(parts_built(8, 8, "auto", large), (1 << 20) / (1 << 10));
    assert_eq!(parts_built(2048, 2048, "auto", large), 0);
    // 2^18 segments: only `on` cuts them; auto keeps them whole whatever the samples.
    let parts = (1 << 18) / (1 << 10);
    assert_eq!(parts_built(8, 8, "auto", small), 0);
    assert_eq!(parts_built(1024, 768, "on", small), parts);
    assert_eq!(parts_built(8, 8, "off", small), 0);
}

/// Parts are built by the render whose rays first reach them, and a render that met a
/// part whose build failed fails with its error instead of showing the hole.
#[test]
fn a_render_builds_the_parts_it_reaches_and_fails_with_one_that_fails() {
    let device = Arc::new(Device::new(None).unwrap());
    let mut built = fur_ball(8, 8, "on").build(device.clone()).unwrap();
    let parts_built = |b: &crate::Scene| b.world().unwrap().tracer.scene().parts_built().built;
    assert_eq!(parts_built(&built), 0);
    let first = built.render(Aovs::default(), &NoProgress).unwrap().stats;
    assert!(
        first.parts_built > 0 && first.part_build_seconds > 0.0,
        "{first:?}"
    );
    assert_eq!(parts_built(&built), first.parts_built);
    assert!(first.first_tile_seconds.is_some_and(|t| t <= first.seconds));
    // A second render of the same view reaches no part the first did not.
    let again = built.render(Aovs::default(), &NoProgress).unwrap().stats;
    assert_eq!(again.parts_built, 0);

    let mut built = fur_ball(8, 8, "on").build(device.clone()).unwrap();
    device.refuse_allocations(true);
    let failed = built.render(Aovs::default(), &NoProgress);
    device.refuse_allocations(false);
    let err = failed.unwrap_err().to_string();
    assert!(err.contains("RTC_ERROR_OUT_OF_MEMORY"), "{err}");
}

/// Parts built in whatever order a render's threads reach them give the same pixels on
/// one thread or two, and a crop (which reaches fewer parts) the full frame's.
#[test]
fn parts_built_as_rays_reach_them_keep_threads_and_crops_exact() {
    use crate::render::tests::render::{CROP, assert_crop_of};
    let device = Arc::new(Device::new(None).unwrap());
    let desc = fur_ball(40, 30, "on");
    let run = |threads, crop| {
        let mut built = desc.build(device.clone()).unwrap();
        let settings = crate::RenderSettings {
            threads: Some(threads),
            crop,
            spp: 2,
            ..built.settings
        };
        let out = built
            .render_with(&settings, Aovs::default(), &NoProgress)
            .unwrap();
        (out.film.rgb().to_vec(), out.stats.parts_built)
    };
    let (one, all) = run(1, None);
    let (two, _) = run(2, None);
    assert!(
        one.iter()
            .zip(&two)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
    let (crop, some) = run(2, Some(CROP));
    assert_crop_of(&one, &crop);
    assert!(some <= all, "{some} of {all}");
}
