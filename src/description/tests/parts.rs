//! The `curve_parts` setting decides whether a build cuts a large groom into parts.

use std::path::Path;
use std::sync::Arc;

use crate::description::SceneDescription;
use crate::embree::Device;

/// A fur ball of 2^18 round linear segments (the least a geometry is cut at), built for a
/// `width` x `height` x 1 spp render with `curve_parts = parts`: the scenes its parts
/// were built as.
fn parts_built(width: u32, height: u32, parts: &str) -> usize {
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
strands = 16384
segments = 16

[[light]]
type = "environment"
radiance = [1, 1, 1]
"#
    );
    let scene = SceneDescription::from_toml(&text, Path::new("."), "parts test").unwrap();
    let built = scene.build(Arc::new(Device::new(None).unwrap())).unwrap();
    built.world.tracer.scene().part_count()
}

#[test]
fn a_large_groom_is_built_in_parts_as_the_setting_says() {
    // 2^18 segments: auto cuts them for 64 camera samples, not for 3 per segment.
    let parts = 1 << 4;
    assert_eq!(parts_built(8, 8, "auto"), parts);
    assert_eq!(parts_built(1024, 768, "auto"), 0);
    assert_eq!(parts_built(1024, 768, "on"), parts);
    assert_eq!(parts_built(8, 8, "off"), 0);
}
