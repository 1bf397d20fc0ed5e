//! The library as C and C++ hosts get it: `scripts/install` into a temporary prefix, then
//! `host.c` built out of tree against that prefix through pkg-config and CMake, shared and
//! static (`install.rs`), and the BSDF-only library, which must load neither Embree nor
//! OpenImageIO (`bsdf_only.rs`), nor does a host of the full prefix's BSDF component. Each
//! prefix is installed once per run. The full library's install reuses the release build
//! (the README's test command runs `cargo build --release` first); the BSDF-only library
//! builds in target/bsdf-only.

mod bsdf_only;
mod install;

use glam::Vec3;
use hairtrace::{HairBsdf, HairParams};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// An empty folder of this test run.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create a temporary folder");
    dir
}

/// Runs `cmd` without the library path `cargo test` sets (which names the build folder),
/// requires success and returns its stdout.
fn run(cmd: &mut Command) -> String {
    let out = cmd
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The prefix of `scripts/install --prefix <fresh folder> [--bsdf-only]`, installed once
/// per test run and shared by the tests that read it (they only read it).
fn install(bsdf_only: bool) -> &'static Path {
    static FULL: OnceLock<PathBuf> = OnceLock::new();
    static BSDF_ONLY: OnceLock<PathBuf> = OnceLock::new();
    let (once, name) = if bsdf_only {
        (&BSDF_ONLY, "prefix-bsdf-only")
    } else {
        (&FULL, "prefix-full")
    };
    once.get_or_init(|| {
        let prefix = fresh_dir(name);
        let mut cmd = Command::new(root().join("scripts/install"));
        cmd.arg("--prefix").arg(&prefix);
        if bsdf_only {
            cmd.arg("--bsdf-only");
        }
        run(cmd.env("CARGO", env!("CARGO")));
        prefix
    })
}

/// pkg-config's words for `args` with the prefix's pkg-config files.
fn pkg_config(prefix: &Path, args: &[&str]) -> Vec<String> {
    run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
        .args(args))
    .split_whitespace()
    .map(String::from)
    .collect()
}

/// The shared libraries an ELF file records as needed (`readelf -d`).
fn needed(elf: &Path) -> Vec<String> {
    run(Command::new("readelf").arg("-d").arg(elf))
        .lines()
        .filter(|l| l.contains("(NEEDED)"))
        .filter_map(|l| Some(l.split_once('[')?.1.trim_end_matches(']').to_string()))
        .collect()
}

/// Every `ht_*` function the installed header declares, with `defines` (`-DNAME`) set.
fn declared_functions(prefix: &Path, defines: &[&str]) -> BTreeSet<String> {
    let text = run(Command::new("gcc")
        .args(["-E", "-P", "-x", "c"])
        .args(defines)
        .arg(prefix.join("include/hairtrace.h")));
    let mut names = BTreeSet::new();
    for (at, _) in text.match_indices("ht_") {
        let rest = &text[at..];
        let end = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if at > 0 && text[..at].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_') {
            continue;
        }
        if rest[end..].trim_start().starts_with('(') {
            names.insert(rest[..end].to_string());
        }
    }
    names
}

/// The `ht_*` functions a library defines (`nm`, with `-D` for a shared library).
fn defined_functions(lib: &Path) -> BTreeSet<String> {
    let dynamic = lib.to_string_lossy().contains(".so");
    let mut cmd = Command::new("nm");
    cmd.args(["--defined-only", "-g"]);
    if dynamic {
        cmd.arg("-D");
    }
    run(cmd.arg(lib))
        .lines()
        .filter_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            [_, "T", name] if name.starts_with("ht_") => Some(name.to_string()),
            _ => None,
        })
        .collect()
}

/// What `host.c` printed.
#[derive(Debug)]
struct Report {
    /// HT_VERSION_* and HT_ABI_VERSION as the host was compiled.
    header: String,
    /// `ht_version()` and `ht_abi_version()` as the linked library answers.
    library: String,
    eval: Vec<f32>,
    threads: u32,
    rss_kib: u64,
    /// Distinct shared objects mapped, and how many are Embree's and OpenImageIO's.
    objects: u32,
    embree: u32,
    oiio: u32,
    /// The full library made and freed a render device.
    device: bool,
    /// After the host wrote an image (given a path): the image shim's path as mapped, and
    /// how many OpenImageIO objects are mapped then.
    image: Option<(String, u32)>,
}

impl Report {
    fn parse(out: &str) -> Report {
        let line = |key: &str| {
            out.lines()
                .find_map(|l| l.strip_prefix(key))
                .unwrap_or_else(|| panic!("no {key:?} line in:\n{out}"))
                .trim()
                .to_string()
        };
        let numbers = |key: &str| -> Vec<f64> {
            line(key)
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter_map(|w| w.parse().ok())
                .collect()
        };
        let maps = numbers("maps");
        Report {
            header: line("header"),
            library: line("library"),
            eval: numbers("eval").iter().map(|v| *v as f32).collect(),
            threads: numbers("Threads:")[0] as u32,
            rss_kib: numbers("VmRSS:")[0] as u64,
            objects: maps[0] as u32,
            embree: maps[1] as u32,
            oiio: maps[2] as u32,
            device: out.lines().any(|l| l == "device ok"),
            image: out
                .lines()
                .find_map(|l| l.strip_prefix("image shim "))
                .map(|shim| (shim.trim().to_string(), numbers("image maps")[2] as u32)),
        }
    }

    /// The host saw this crate's version and ABI in the header and in the library, and its
    /// evaluation (f |cos| and pdf) has the Rust API's bits (`%.9g` prints an f32 exactly).
    fn check_versions_and_eval(&self) {
        let abi = hairtrace::capi::HT_ABI_VERSION;
        let want = format!("{} abi {abi}", env!("CARGO_PKG_VERSION"));
        assert_eq!(self.header, want, "{self:?}");
        assert_eq!(self.library, want, "{self:?}");
        let wi = Vec3::new(0.0, 0.866_025_4, 0.5);
        let e = HairBsdf::new(&HairParams::default())
            .unwrap()
            .eval(0.5, Vec3::Z, wi);
        let f_cos = e.f * wi.z;
        assert_eq!(self.eval, [f_cos.x, f_cos.y, f_cos.z, e.pdf], "{self:?}");
    }
}
