//! The farm recipe through the command line: `scripts/farm` and the `--isa` flag
//! (the library's side of ISA pinning is tested in tests/pipeline/farm.rs).

use std::path::Path;
use std::process::Command;

/// The documented recipe itself (`scripts/farm`): bands rendered by separate processes,
/// assembled with oiiotool, equal to the full render bit for bit (idiff, zero tolerance).
#[test]
fn the_farm_recipe_assembles_the_full_frame() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace");
    let out = Command::new(root.join("scripts/farm"))
        .env("HAIRTRACE", env!("CARGO_BIN_EXE_hairtrace"))
        .output()
        .expect("run scripts/farm (oiiotool and idiff come from scripts/setup)");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "scripts/farm failed: {err}");
    assert!(
        err.contains("assemble into the full frame bit for bit"),
        "{err}"
    );
}

#[test]
fn the_command_line_refuses_an_unknown_isa_in_one_line() {
    let out = Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args([
            "render", "--demo", "furball", "--isa", "sse4.2", "-o", "x.exr",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("isa = sse4.2: must be sse2 | avx | avx2 | avx512"),
        "{err}"
    );
}
