//! The C examples use only `include/hairtrace.h`. Each is compiled as C99 and as C++
//! with warnings as errors, linked against the static library that this test run built,
//! run, and its output checked against the Rust API.

use glam::Vec3;
use hairtrace::image::read_image;
use hairtrace::{HairBsdf, HairParams};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The profile directory of this build (target/<profile>), where libhairtrace.a lives.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf()
}

/// Libraries the static library needs besides Embree, as `--print native-static-libs`
/// lists them; Embree's come from the build script ([`embree_link`]).
const NATIVE_LIBS: &[&str] = &[
    "-lOpenImageIO",
    "-lOpenImageIO_Util",
    "-lstdc++",
    "-lgcc_s",
    "-lutil",
    "-lrt",
    "-lpthread",
    "-lm",
    "-ldl",
];

/// The Embree link arguments of the Embree this build found (`-L<dir>` when it is not in
/// a system path, then `-lembree3` or `-lembree4`).
fn embree_link() -> Vec<&'static str> {
    env!("HT_EMBREE_LINK").split(' ').collect()
}

/// `libhairtrace.a`, checked to be newer than every source file and the build script:
/// `cargo test` builds only the rlib, so an archive left by an older build would test old
/// code under the new name.
fn fresh_archive() -> PathBuf {
    let lib = profile_dir().join("libhairtrace.a");
    let built = std::fs::metadata(&lib)
        .and_then(|m| m.modified())
        .unwrap_or_else(|_| {
            panic!(
                "{} not built: `cargo test` builds only the rlib; run `cargo build --release` \
                 first (the README's test command does)",
                lib.display()
            )
        });
    fn newest(path: &Path) -> std::time::SystemTime {
        let meta = std::fs::metadata(path).expect("source metadata");
        if meta.is_dir() {
            std::fs::read_dir(path)
                .expect("source folder")
                .map(|e| newest(&e.expect("source entry").path()))
                .max()
                .unwrap_or(std::time::UNIX_EPOCH)
        } else {
            meta.modified().expect("source mtime")
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sources = newest(&root.join("src")).max(newest(&root.join("build.rs")));
    assert!(
        built >= sources,
        "{} is older than the sources: run `cargo build --release` before the tests",
        lib.display()
    );
    lib
}

/// Compiles `c_examples/<name>` with `compiler` and `flags`, links and runs it with `args`;
/// returns stdout.
fn build_and_run(name: &str, compiler: &str, flags: &[&str], args: &[&OsStr]) -> String {
    build_and_run_file(&Path::new("c_examples").join(name), compiler, flags, args)
}

/// [`build_and_run`] for the C file at `source`, relative to the repository root.
pub(crate) fn build_and_run_file(
    source: &Path,
    compiler: &str,
    flags: &[&str],
    args: &[&OsStr],
) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = fresh_archive();
    let name = source.file_name().expect("a file").to_string_lossy();
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{compiler}"));
    let out = Command::new(compiler)
        .args(flags)
        .args(["-Wall", "-Wextra", "-Werror", "-O1", "-I"])
        .arg(root.join("include"))
        .arg(root.join(source))
        // Ends a `-x c++` so that the archive is not read as source.
        .args(["-x", "none"])
        .arg(&lib)
        .args(embree_link())
        .args(NATIVE_LIBS)
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {compiler}: {e}"));
    assert!(
        out.status.success(),
        "{compiler} {name} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = Command::new(&exe)
        .args(args)
        .output()
        .expect("run the example");
    assert!(
        run.status.success(),
        "{name} ({compiler}) exited with {}:\n{}",
        run.status,
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8(run.stdout).expect("utf-8 output")
}

/// The numbers after `key` on the line that starts with it.
fn numbers(out: &str, key: &str) -> Vec<f32> {
    let line = out
        .lines()
        .find(|l| l.starts_with(key))
        .unwrap_or_else(|| panic!("no `{key}` line in:\n{out}"));
    line.split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect()
}

fn check_bsdf_output(out: &str) {
    assert!(
        out.starts_with(&format!(
            "version {} abi {}",
            hairtrace::VERSION,
            hairtrace::capi::HT_ABI_VERSION
        )),
        "{out}"
    );
    let bsdf = HairBsdf::new(&HairParams::default()).unwrap();
    let e = bsdf.eval(0.5, Vec3::Z, Vec3::new(0.0, 0.866_025_4, 0.5));
    let want = [e.f.x, e.f.y, e.f.z, e.pdf];
    for key in ["eval", "batch", "point"] {
        let got = numbers(out, key);
        assert_eq!(got.len(), 4, "{key}: {got:?}");
        for (g, w) in got.iter().zip(want) {
            assert!(
                (g - w).abs() <= 1e-5 * w.abs(),
                "{key}: C printed {got:?}, Rust gives {want:?}"
            );
        }
    }
    // The frame helper gives the documented h of the worked example (docs/conventions.md).
    assert_eq!(numbers(out, "frame h"), [0.5], "{out}");
    let furnace = numbers(out, "furnace")[0];
    assert!(
        (furnace - 1.0).abs() < 1e-3,
        "white furnace through the C ABI: {furnace}"
    );
    assert!(out.contains("null a required pointer is NULL"), "{out}");
    assert!(
        out.contains("invalid invalid argument: invalid argument: beta_m = 2"),
        "{out}"
    );
    let sigma = numbers(out, "from_melanin");
    assert!((sigma[0] - 8.0 * 0.419).abs() < 1e-4, "{sigma:?}");
}

#[test]
fn bsdf_example_as_c99() {
    check_bsdf_output(&build_and_run(
        "bsdf.c",
        "gcc",
        &["-std=c99", "-pedantic"],
        &[],
    ));
}

#[test]
fn bsdf_example_as_cpp() {
    check_bsdf_output(&build_and_run(
        "bsdf.c",
        "g++",
        &["-x", "c++", "-std=c++17"],
        &[],
    ));
}

/// Builds and runs `render.c`, which writes its image to a file this test names, and checks
/// what it printed and wrote.
fn check_render_example(compiler: &str, flags: &[&str]) {
    let exr = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("render-{compiler}.exr"));
    let _ = std::fs::remove_file(&exr);
    let out = build_and_run("render.c", compiler, flags, &[exr.as_os_str()]);
    assert_eq!(numbers(&out, "geometry"), [0.0, 1.0], "{out}");
    assert!(
        out.contains("mismatch invalid argument: invalid argument: material_id = 1 is a diffuse"),
        "{out}"
    );
    assert_eq!(numbers(&out, "image"), [64.0, 48.0], "{out}");
    let mean = numbers(&out, "mean")[0];
    assert!(mean.is_finite() && mean > 0.0, "mean {mean}:\n{out}");
    // 64 x 48 pixels in 16 x 16 tiles: one call per tile.
    assert_eq!(numbers(&out, "progress"), [12.0], "{out}");
    // A 24 x 20 crop equals the full frame's pixels bit for bit, and its depth AOV sees the
    // fur and the sphere in the middle of the frame.
    let crop = numbers(&out, "crop");
    assert_eq!(crop[..3], [24.0, 20.0, 1.0], "{out}");
    assert!(crop[3] > 0.0, "{out}");
    let image = read_image(&exr).unwrap_or_else(|e| panic!("{}: {e}", exr.display()));
    assert_eq!((image.width, image.height, image.channels), (64, 48, 3));
    let file_mean =
        image.pixels.iter().map(|v| f64::from(*v)).sum::<f64>() / image.pixels.len() as f64;
    assert!(
        (file_mean - f64::from(mean)).abs() < 1e-5 * f64::from(mean),
        "the EXR's mean {file_mean} is not the printed {mean}"
    );
    // The fur and the sphere stand out from the sky: not a flat image.
    let (lo, hi) = image
        .pixels
        .iter()
        .fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    assert!(hi > 2.0 * lo, "pixels only span [{lo}, {hi}]");
}

#[test]
fn render_example_as_c99() {
    check_render_example("gcc", &["-std=c99", "-pedantic"]);
}

#[test]
fn render_example_as_cpp() {
    check_render_example("g++", &["-x", "c++", "-std=c++17"]);
}
