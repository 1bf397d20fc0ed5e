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
const NATIVE_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl"];

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

/// Compiles the C file at `source` (relative to the repository root) with `compiler` and
/// `flags` into `<file name>-<tag>` and links it against the static archive; returns the
/// executable.
pub(crate) fn build(source: &Path, compiler: &str, flags: &[&str], tag: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = fresh_archive();
    let name = source.file_name().expect("a file").to_string_lossy();
    let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{tag}"));
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
    exe
}

/// Runs `exe` with `args`, under `wrapper` (a command and its options, e.g. valgrind) if
/// not empty, with `env` set; asserts success and returns stdout.
pub(crate) fn run(exe: &Path, wrapper: &[&str], env: &[(&str, &str)], args: &[&OsStr]) -> String {
    let mut command = match wrapper {
        [] => Command::new(exe),
        [tool, options @ ..] => {
            let mut c = Command::new(tool);
            c.args(options).arg(exe);
            c
        }
    };
    let run = command
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", exe.display()));
    assert!(
        run.status.success(),
        "{} {wrapper:?} exited with {}:\n{}\n{}",
        exe.display(),
        run.status,
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8(run.stdout).expect("utf-8 output")
}

/// Builds the C file at `source` (as [`build`]) and runs it directly with `args`; returns
/// stdout.
pub(crate) fn build_and_run_file(
    source: &Path,
    compiler: &str,
    flags: &[&str],
    args: &[&OsStr],
) -> String {
    run(&build(source, compiler, flags, compiler), &[], &[], args)
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
    // The worked example, at a hit and at the local frame: f |cos| and pdf.
    let bsdf = HairBsdf::new(&HairParams::default()).unwrap();
    let wi = Vec3::new(0.0, 0.866_025_4, 0.5);
    let e = bsdf.eval(0.5, Vec3::Z, wi);
    let f_cos = e.f * wi.z;
    let want = [f_cos.x, f_cos.y, f_cos.z, e.pdf];
    for key in ["point", "local"] {
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
        out.contains("invalid invalid argument: beta_m = 2"),
        "{out}"
    );
    let sigma = numbers(out, "from_melanin");
    assert!((sigma[0] - 8.0 * 0.419).abs() < 1e-4, "{sigma:?}");
}

/// What `render.c` printed and the image it wrote to `exr`.
fn check_render_output(out: &str, exr: &Path) {
    assert_eq!(numbers(out, "geometry"), [0.0, 1.0], "{out}");
    assert!(
        out.contains("mismatch invalid argument: material_id = 1 is a diffuse"),
        "{out}"
    );
    assert_eq!(numbers(out, "image"), [64.0, 48.0], "{out}");
    let mean = numbers(out, "mean")[0];
    assert!(mean.is_finite() && mean > 0.0, "mean {mean}:\n{out}");
    // 64 x 48 pixels in 16 x 16 tiles: a call per tile at least (more when a tile takes
    // longer than 20 ms), the last one at the total.
    let progress = numbers(out, "progress");
    assert!(progress[0] >= 12.0, "{out}");
    assert_eq!(progress[1..], [3072.0, 3072.0], "{out}");
    // A 24 x 20 crop equals the full frame's pixels bit for bit, and its depth AOV sees the
    // fur and the sphere in the middle of the frame.
    let crop = numbers(out, "crop");
    assert_eq!(crop[..3], [24.0, 20.0, 1.0], "{out}");
    assert!(crop[3] > 0.0, "{out}");
    // The hair material changed on the built scene darkens the crop.
    assert_eq!(numbers(out, "darker hair"), [1.0], "{out}");
    let image = read_image(exr).unwrap_or_else(|e| panic!("{}: {e}", exr.display()));
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

/// Every bad-input row of `abi_checks.c` gets its status and message (the program checks
/// them and prints the count), as C99 and as C++.
fn check_abi_checks(out: &str) {
    let counts = numbers(out, "checks");
    assert!(counts[0] >= 100.0 && counts[1] == 0.0, "{out}");
    assert!(!out.contains("FAIL"), "{out}");
}

/// `ht_shutdown` refuses while a scene lives, and afterwards leaves the threads the
/// process had before the first render (TBB's workers outlived the freed device until
/// then; OpenImageIO's pool, started when the library is loaded, is not ours to join); the
/// library works again after it.
fn check_shutdown(out: &str) {
    let start = numbers(out, "threads start")[0];
    assert!(numbers(out, "threads freed")[0] > start, "{out}");
    assert!(
        out.contains("refused invalid argument: 1 Embree device(s) still in use"),
        "{out}"
    );
    assert_eq!(numbers(out, "shutdown ok threads"), [start], "{out}");
    assert_eq!(numbers(out, "again ok threads"), [start], "{out}");
}

/// A C example and the check of what it printed (and wrote to the file it is given).
pub(crate) struct Example {
    pub name: &'static str,
    pub check: fn(&str, &Path),
}

/// Every program of `c_examples/`.
pub(crate) const EXAMPLES: [Example; 4] = [
    Example {
        name: "bsdf.c",
        check: |out, _| check_bsdf_output(out),
    },
    Example {
        name: "render.c",
        check: check_render_output,
    },
    Example {
        name: "abi_checks.c",
        check: |out, _| check_abi_checks(out),
    },
    Example {
        name: "shutdown.c",
        check: |out, _| check_shutdown(out),
    },
];

/// Builds `example` with `compiler` and `flags` (plus the warnings of [`build`]) as
/// variant `tag`, runs it under `wrapper` with `env` and the path of a file it may write,
/// and checks its output.
pub(crate) fn build_run_check(
    example: &Example,
    compiler: &str,
    flags: &[&str],
    tag: &str,
    wrapper: &[&str],
    env: &[(&str, &str)],
) {
    let exe = build(
        &Path::new("c_examples").join(example.name),
        compiler,
        flags,
        tag,
    );
    let file = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{}-{tag}.exr", example.name));
    let _ = std::fs::remove_file(&file);
    let out = run(&exe, wrapper, env, &[file.as_os_str()]);
    (example.check)(&out, &file);
}

const C99: &[&str] = &["-std=c99", "-pedantic", "-D_DEFAULT_SOURCE"];
pub(crate) const CPP: &[&str] = &["-x", "c++", "-std=c++17"];

#[test]
fn every_example_as_c99() {
    for example in &EXAMPLES {
        build_run_check(example, "gcc", C99, "c99", &[], &[]);
    }
}

#[test]
fn every_example_as_cpp() {
    for example in &EXAMPLES {
        build_run_check(example, "g++", CPP, "cpp", &[], &[]);
    }
}
