//! Build script: finds Embree, generates its FFI bindings from the installed header, and
//! compiles the C++ shim over OpenImageIO (all three only with the `render` feature; the
//! BSDF-only build needs neither library); gives the shared library its soname.
//!
//! Embree is looked up the way openssl-sys and libsqlite3-sys look up their libraries:
//! environment overrides first, then the usual system prefixes. The Embree version comes
//! from the installed `rtcore_config.h`, so the bindings and the `embree3`/`embree4` cfg
//! always describe the library that is actually linked, never a bundled copy.

#[cfg(feature = "render")]
use std::env;
use std::fs;
#[cfg(feature = "render")]
use std::path::{Path, PathBuf};

#[cfg(feature = "render")]
/// Where Embree's headers and library were found.
struct Embree {
    /// The directory that holds `rtcore.h`.
    include_dir: PathBuf,
    /// `None` when the library is on the linker's default search path.
    lib_dir: Option<PathBuf>,
    major: u32,
    version: String,
}

fn main() {
    set_soname();
    #[cfg(feature = "render")]
    {
        let embree = find_embree();
        generate_embree_bindings(&embree);
        link_embree(&embree);
        build_oiio_shim();
    }
}

/// `libhairtrace.so.N` with N = `HT_ABI_VERSION` (src/capi/mod.rs, which the header
/// publishes): the soname changes exactly when a host built against an older header could
/// no longer run, and a host records it instead of the unversioned name.
fn set_soname() {
    let source = "src/capi/mod.rs";
    println!("cargo:rerun-if-changed={source}");
    let text = fs::read_to_string(source).expect("hairtrace: cannot read src/capi/mod.rs");
    let abi: u32 = text
        .lines()
        .find_map(|l| l.strip_prefix("pub const HT_ABI_VERSION: u32 = "))
        .and_then(|rest| rest.trim_end_matches(';').parse().ok())
        .expect("hairtrace: no `pub const HT_ABI_VERSION: u32 = N;` in src/capi/mod.rs");
    println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libhairtrace.so.{abi}");
}

#[cfg(feature = "render")]
fn env_path(name: &str) -> Option<PathBuf> {
    println!("cargo:rerun-if-env-changed={name}");
    env::var_os(name)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
}

#[cfg(feature = "render")]
/// The header directory below an include root: Embree 4 wins when both are installed.
fn header_dir_under(include_root: &Path) -> Option<PathBuf> {
    ["embree4", "embree3"]
        .iter()
        .map(|sub| include_root.join(sub))
        .find(|dir| dir.join("rtcore.h").is_file())
}

#[cfg(feature = "render")]
fn find_embree() -> Embree {
    let embree_dir = env_path("EMBREE_DIR");
    let include_override = env_path("EMBREE_INCLUDE_DIR");
    let lib_override = env_path("EMBREE_LIB_DIR");

    let mut searched = Vec::new();
    // EMBREE_INCLUDE_DIR may name the header directory itself or its parent.
    let include_dir = if let Some(dir) = include_override {
        searched.push(dir.display().to_string());
        if dir.join("rtcore.h").is_file() {
            Some(dir)
        } else {
            header_dir_under(&dir)
        }
    } else if let Some(prefix) = &embree_dir {
        let root = prefix.join("include");
        searched.push(root.display().to_string());
        header_dir_under(&root)
    } else {
        ["/usr/include", "/usr/local/include"]
            .iter()
            .find_map(|root| {
                searched.push(root.to_string());
                header_dir_under(Path::new(root))
            })
    };

    let Some(include_dir) = include_dir else {
        panic!(
            "\n\nhairtrace: Embree (rtcore.h) not found; searched {}.\n\
             Install it with `scripts/setup` (on Debian/Ubuntu: `sudo apt-get install libembree-dev`),\n\
             or point EMBREE_DIR at an Embree 3 or 4 install prefix (or set EMBREE_INCLUDE_DIR and\n\
             EMBREE_LIB_DIR).\n\n",
            searched.join(", ")
        );
    };

    let lib_dir = lib_override.or_else(|| embree_dir.map(|prefix| prefix.join("lib")));
    let (major, version) = read_version(&include_dir.join("rtcore_config.h"));
    Embree {
        include_dir,
        lib_dir,
        major,
        version,
    }
}

#[cfg(feature = "render")]
/// Parses `#define RTC_VERSION_{MAJOR,MINOR,PATCH} n` from Embree's config header.
fn read_version(config: &Path) -> (u32, String) {
    println!("cargo:rerun-if-changed={}", config.display());
    let text = fs::read_to_string(config).unwrap_or_else(|e| {
        panic!(
            "hairtrace: cannot read {} ({e}); the Embree install looks incomplete: reinstall \
             it with `scripts/setup` or fix EMBREE_DIR",
            config.display()
        )
    });
    let field = |name: &str| -> u32 {
        text.lines()
            .filter_map(|line| {
                let mut words = line.split_whitespace();
                match (words.next(), words.next(), words.next()) {
                    (Some("#define"), Some(n), Some(value)) if n == name => value.parse().ok(),
                    _ => None,
                }
            })
            .next()
            .unwrap_or_else(|| panic!("hairtrace: no `#define {name}` in {}", config.display()))
    };
    let (major, minor, patch) = (
        field("RTC_VERSION_MAJOR"),
        field("RTC_VERSION_MINOR"),
        field("RTC_VERSION_PATCH"),
    );
    if !(3..=4).contains(&major) {
        panic!(
            "hairtrace: found Embree {major}.{minor}.{patch} in {}, but only Embree 3 and 4 are \
             supported",
            config.display()
        );
    }
    (major, format!("{major}.{minor}.{patch}"))
}

#[cfg(feature = "render")]
fn generate_embree_bindings(embree: &Embree) {
    let header = embree.include_dir.join("rtcore.h");
    println!("cargo:rerun-if-changed={}", header.display());

    // Newtype enums: Embree may hand back values a Rust enum would not know (a newer
    // library than the header), which must not be undefined behaviour. The flag enums
    // are bitfields so that they can be or-ed together.
    let bindings = bindgen::Builder::default()
        .header(header.to_string_lossy())
        .clang_arg(format!("-I{}", embree.include_dir.display()))
        .allowlist_function("rtc.*")
        .allowlist_type("RTC.*")
        .allowlist_var("RTC.*")
        .default_enum_style(bindgen::EnumVariation::NewType {
            is_bitfield: false,
            is_global: false,
        })
        .bitfield_enum("RTC.*Flags")
        .derive_default(true)
        .derive_debug(true)
        .derive_copy(true)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()))
        .generate()
        .unwrap_or_else(|e| {
            panic!(
                "hairtrace: bindgen failed on {} ({e}); libclang is needed: run `scripts/setup`",
                header.display()
            )
        });

    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    bindings
        .write_to_file(out.join("embree_sys.rs"))
        .expect("hairtrace: cannot write embree_sys.rs into OUT_DIR");
}

#[cfg(feature = "render")]
fn link_embree(embree: &Embree) {
    println!("cargo:rustc-check-cfg=cfg(embree3)");
    println!("cargo:rustc-check-cfg=cfg(embree4)");
    println!("cargo:rustc-cfg=embree{}", embree.major);
    // For the packages that call Embree themselves (benches/groom.rs's direct baseline).
    println!("cargo::metadata=major={}", embree.major);
    println!("cargo:rustc-env=HT_EMBREE_VERSION={}", embree.version);
    // What a C program linking the static archive needs for Embree (tests/c_abi links
    // the examples with it): the library this build found, not a guess.
    let search = embree
        .lib_dir
        .as_ref()
        .map(|d| format!("-L{0} -Wl,-rpath,{0} ", d.display()))
        .unwrap_or_default();
    println!(
        "cargo:rustc-env=HT_EMBREE_LINK={search}-lembree{}",
        embree.major
    );
    if let Some(dir) = &embree.lib_dir {
        println!("cargo:rustc-link-search=native={}", dir.display());
        // A folder the loader does not search (scripts/embree4's): recorded as an rpath so
        // that the binaries, tests and shared library run without LD_LIBRARY_PATH.
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
        // The same for the packages that link this library (the command line, the benches).
        println!("cargo::metadata=rpath={}", dir.display());
    }
    println!("cargo:rustc-link-lib=dylib=embree{}", embree.major);
}

#[cfg(feature = "render")]
/// The shim over OpenImageIO as a shared library of its own, which `src/image/shim.rs` opens
/// at the first image read or write: OpenImageIO's many shared objects cost every process
/// that links them start-up time (docs/measurements.md, "Start-up"), and a host that never
/// touches an image should not map them at all. The library goes into
/// OUT_DIR, whose path the crate records (`HT_IMAGE_SHIM_BUILT`) for the build tree's own
/// binaries, and beside the build's binaries (target/<profile>/), where scripts/install and
/// scripts/python take it from.
fn build_oiio_shim() {
    let shim = "src/image/oiio_shim.cpp";
    println!("cargo:rerun-if-changed={shim}");
    let oiio = pkg_config::Config::new()
        .atleast_version("2.2")
        .cargo_metadata(false)
        .probe("OpenImageIO")
        .unwrap_or_else(|e| {
            panic!(
                "hairtrace: OpenImageIO not found through pkg-config ({e}).\n\
                 Install it with `scripts/setup` (on Debian/Ubuntu: `sudo apt-get install \
                 libopenimageio-dev pkg-config`)"
            )
        });
    let mut build = cc::Build::new();
    build
        .cpp(true)
        .std("c++17")
        .pic(true)
        // Not the sanitizer cc adds for a build whose Rust code has one (the fuzz build's
        // ASan): the shim would then need ASan's shared runtime, which a program with
        // ASan built in refuses to load.
        .flag("-fno-sanitize=all")
        .cargo_metadata(false)
        .file(shim)
        .includes(&oiio.include_paths);
    let objects = build.compile_intermediates();
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let name = image_shim_name();
    let library = out.join(&name);
    let mut link = build.get_compiler().to_command();
    link.arg("-shared")
        .arg(format!("-Wl,-soname,{name}"))
        // Every symbol resolved now, against OpenImageIO: not at a host's first image.
        .arg("-Wl,-z,defs")
        .arg("-o")
        .arg(&library)
        .args(&objects);
    for dir in &oiio.link_paths {
        link.arg(format!("-L{}", dir.display()));
    }
    for lib in &oiio.libs {
        link.arg(format!("-l{lib}"));
    }
    let status = link
        .status()
        .unwrap_or_else(|e| panic!("hairtrace: cannot run the linker for {name}: {e}"));
    assert!(
        status.success(),
        "hairtrace: linking {name} failed: {link:?}"
    );
    println!("cargo:rustc-env=HT_IMAGE_SHIM_NAME={name}");
    println!("cargo:rustc-env=HT_IMAGE_SHIM_BUILT={}", library.display());
    // target/<profile>/ is three levels above OUT_DIR (target/<profile>/build/<pkg>/out).
    // Copied under another name, then renamed over the old copy: a process running with the
    // old copy mapped keeps it, where writing into it in place would crash that process.
    if let Some(profile_dir) = out.ancestors().nth(3) {
        let part = profile_dir.join(format!(".{name}.{}.part", std::process::id()));
        fs::copy(&library, &part)
            .and_then(|_| fs::rename(&part, profile_dir.join(&name)))
            .unwrap_or_else(|e| panic!("hairtrace: cannot copy {name} beside the build: {e}"));
    }
}

#[cfg(feature = "render")]
/// The shim's file name, with the crate's version in it: a library opens only the shim of
/// its own version (the interface between them is internal and changes freely).
fn image_shim_name() -> String {
    format!(
        "libhairtrace-oiio.so.{}",
        env::var("CARGO_PKG_VERSION").expect("cargo sets CARGO_PKG_VERSION")
    )
}
