//! `hairtrace.hpp`'s wrappers of motion and animation (strands and a mesh at several time
//! steps, a USD stage and a `.hair` sequence read at a frame over the shutter of settings),
//! compiled as C++17 with warnings as errors and run: each renders the bits of the C calls
//! it wraps (which the library's C ABI tests hold to the Rust renders), and a bad time step
//! throws `hairtrace::Error` with the status and the step named.

use crate::c_examples::{CPP, build_and_run_file};
use hairtrace::formats::hair::{Thickness, write_hair_file};
use hairtrace::scene::Strands;
use std::path::Path;

/// Two linear strands, `dx` along x.
fn strands(dx: f32) -> Strands {
    Strands {
        points: vec![
            [dx, -0.5, 0.0],
            [dx, 0.5, 0.0],
            [dx + 0.3, -0.5, 0.0],
            [dx + 0.4, 0.5, 0.0],
        ],
        radii: vec![0.03; 4],
        counts: vec![2, 2],
        colors: None,
    }
}

#[test]
fn the_cpp_wrappers_of_motion_and_animation_give_the_c_calls_bits() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("motion-cpp");
    std::fs::create_dir_all(&dir).unwrap();
    for (frame, dx) in [(1, 0.0), (2, 0.25)] {
        let file = dir.join(format!("pair.{frame:04}.hair"));
        write_hair_file(&file, &strands(dx), Thickness::Radius).unwrap();
    }
    let usd = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/swaying.usda");
    let pattern = dir.join("pair.####.hair");
    let out = build_and_run_file(
        Path::new("tests/c_abi/c/motion.cpp"),
        "g++",
        CPP,
        &[usd.as_os_str(), pattern.as_os_str()],
    );
    for what in ["curves", "mesh", "usd", "hair"] {
        assert!(out.contains(&format!("same {what} 1\n")), "{what}:\n{out}");
    }
    assert!(out.contains("usd geometries 0 1\n"), "{out}");
    assert!(out.contains("usd blurred 1\n"), "{out}");
    assert!(
        out.contains("refused 2 invalid argument: ") && out.contains("time step 2"),
        "{out}"
    );
}
