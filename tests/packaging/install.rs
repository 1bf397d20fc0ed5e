//! `scripts/install` of the full library, and C++ hosts built out of tree against the
//! installed prefix with pkg-config and with CMake, shared and static.

use super::{
    Report, declared_functions, defined_functions, fresh_dir, install, needed, pkg_config, root,
    run,
};
use std::path::Path;
use std::process::Command;

/// The soname: `libhairtrace.so.<HT_ABI_VERSION>`.
fn soname() -> String {
    format!("libhairtrace.so.{}", hairtrace::capi::HT_ABI_VERSION)
}

/// Runs `exe` with a path to write an image to: it must start without OpenImageIO and, once
/// it writes the image, map it through the shim installed in `prefix`.
fn check_image_shim(exe: &Path, prefix: &Path) -> Report {
    let image = fresh_dir("host-images").join("pixel.exr");
    let report = Report::parse(&run(Command::new(exe).arg(&image)));
    assert_eq!(report.oiio, 0, "OpenImageIO mapped at start-up: {report:?}");
    let shim = prefix.join("lib").join(format!(
        "libhairtrace-oiio.so.{}",
        env!("CARGO_PKG_VERSION")
    ));
    let (mapped, oiio) = report.image.clone().expect("the host wrote an image");
    assert_eq!(
        Path::new(&mapped),
        shim.canonicalize().unwrap(),
        "{report:?}"
    );
    assert!(oiio >= 1, "{report:?}");
    assert!(image.is_file());
    report
}

/// The installed command line reads an image (the one `check_image_shim` had a host
/// write) through the shim in the prefix's `lib/`, as the loader's log shows.
fn check_installed_command_line(prefix: &Path) {
    let image = Path::new(env!("CARGO_TARGET_TMPDIR")).join("host-images/pixel.exr");
    let out = Command::new(prefix.join("bin/hairtrace"))
        .arg("compare")
        .args([&image, &image])
        .env_remove("LD_LIBRARY_PATH")
        .env("LD_DEBUG", "files")
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{log}");
    let shim = format!(
        "file={}/bin/../lib/libhairtrace-oiio.so.{}",
        prefix.display(),
        env!("CARGO_PKG_VERSION")
    );
    assert!(log.contains(&shim), "no {shim} in the loader's log:\n{log}");
}

/// Runs a host linked against the shared library: it must record the soname (not the
/// unversioned name, not a path into the build folder), find the library through the
/// RUNPATH alone, and reach the render API.
fn check_shared_host(exe: &Path, prefix: &Path) {
    let needs = needed(exe);
    assert!(needs.contains(&soname()), "{exe:?} needs {needs:?}");
    assert!(
        !needs
            .iter()
            .any(|n| n == "libhairtrace.so" || n.contains('/')),
        "{needs:?}"
    );
    let dynamic = run(Command::new("readelf").arg("-d").arg(exe));
    assert!(
        dynamic.contains(&format!("[{}]", prefix.join("lib").display())),
        "no RUNPATH to the prefix:\n{dynamic}"
    );
    let report = check_image_shim(exe, prefix);
    report.check_versions_and_eval();
    assert!(report.device, "{report:?}");
}

/// Runs a host linked against the static archive: nothing of hairtrace is needed at run
/// time, Embree is loaded (the control for bsdf_only.rs, whose host must show none of
/// it), OpenImageIO only once an image is written, through the prefix's shim.
fn check_static_host(exe: &Path, prefix: &Path) {
    let needs = needed(exe);
    assert!(!needs.iter().any(|n| n.contains("hairtrace")), "{needs:?}");
    let report = check_image_shim(exe, prefix);
    report.check_versions_and_eval();
    assert!(report.device, "{report:?}");
    assert!(report.embree >= 1, "{report:?}");
    println!(
        "full static host at start-up: {} shared objects, {} threads, {} KiB resident",
        report.objects, report.threads, report.rss_kib
    );
}

#[test]
fn cpp_hosts_build_against_the_installed_prefix() {
    let prefix = install(false);
    let lib = prefix.join("lib");
    let version = env!("CARGO_PKG_VERSION");

    // The files and links of a shared library with a soname.
    let real = format!("{}.{version}", soname());
    let link = |name: &str| std::fs::read_link(lib.join(name)).unwrap();
    assert_eq!(link("libhairtrace.so"), Path::new(&soname()));
    assert_eq!(link(&soname()), Path::new(&real));
    let dynamic = run(Command::new("readelf").arg("-d").arg(lib.join(&real)));
    assert!(
        dynamic.contains(&format!("Library soname: [{}]", soname())),
        "{dynamic}"
    );
    assert!(lib.join("libhairtrace.a").is_file());
    // The header declares exactly what the library exports.
    assert_eq!(
        declared_functions(prefix, &[]),
        defined_functions(&lib.join(&real))
    );
    assert_eq!(
        pkg_config(prefix, &["--modversion", "hairtrace"]),
        [version]
    );
    assert_macros_prefixed(&prefix.join("include"));

    // pkg-config, as C++.
    let source = root().join("tests/packaging/host.c");
    let compile = |exe: &Path, flags: Vec<String>| {
        run(Command::new("g++")
            .args(["-x", "c++", "-std=c++17", "-Wall", "-Wextra", "-Werror"])
            .arg(&source)
            .args(["-x", "none"])
            .args(flags)
            .arg("-o")
            .arg(exe));
    };
    let out = fresh_dir("hosts-pkg-config");
    let shared = out.join("shared");
    let mut flags = pkg_config(prefix, &["--cflags", "--libs", "hairtrace"]);
    flags.push(format!("-Wl,-rpath,{}", lib.display()));
    compile(&shared, flags);
    check_shared_host(&shared, prefix);
    check_installed_command_line(prefix);
    let static_exe = out.join("static");
    compile(
        &static_exe,
        pkg_config(
            prefix,
            &["--static", "--cflags", "--libs", "hairtrace-static"],
        ),
    );
    check_static_host(&static_exe, prefix);

    // CMake: find_package with this version, refusing the next minor (0.x) or major.
    let project = fresh_dir("hosts-cmake");
    std::fs::copy(&source, project.join("host.cpp")).unwrap();
    std::fs::copy(
        root().join("c_examples/furnace.cpp"),
        project.join("furnace.cpp"),
    )
    .unwrap();
    let (major, minor) = (
        env!("CARGO_PKG_VERSION_MAJOR").parse::<u32>().unwrap(),
        env!("CARGO_PKG_VERSION_MINOR").parse::<u32>().unwrap(),
    );
    let too_new = if major == 0 {
        format!("0.{}", minor + 1)
    } else {
        format!("{}", major + 1)
    };
    std::fs::write(
        project.join("CMakeLists.txt"),
        format!(
            "cmake_minimum_required(VERSION 3.16)\n\
             project(host CXX)\n\
             find_package(hairtrace {too_new} QUIET)\n\
             if(hairtrace_FOUND)\n  message(FATAL_ERROR \"{too_new} accepted\")\nendif()\n\
             find_package(hairtrace {major}.{minor} REQUIRED)\n\
             add_executable(host_shared host.cpp)\n\
             target_link_libraries(host_shared PRIVATE hairtrace::hairtrace)\n\
             add_executable(host_static host.cpp)\n\
             target_link_libraries(host_static PRIVATE hairtrace::hairtrace_static)\n\
             add_executable(furnace furnace.cpp)\n\
             set_target_properties(furnace PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON \
             CXX_EXTENSIONS OFF)\n\
             target_compile_options(furnace PRIVATE -Wall -Wextra -Werror -pedantic)\n\
             target_link_libraries(furnace PRIVATE hairtrace::hairtrace)\n"
        ),
    )
    .unwrap();
    let build = project.join("build");
    run(Command::new("cmake")
        .arg("-S")
        .arg(&project)
        .arg("-B")
        .arg(&build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display())));
    run(Command::new("cmake").arg("--build").arg(&build));
    check_shared_host(&build.join("host_shared"), prefix);
    check_static_host(&build.join("host_static"), prefix);
    check_furnace(&run(&mut Command::new(build.join("furnace"))));
}

/// What `c_examples/furnace.cpp` printed: through hairtrace.hpp the white furnace gives 1
/// within 0.5%, every vertex made with the noexcept status forms has the bits of the same
/// vertex made with the value forms and with the C calls, an unfilled point gives a status
/// and the message, and a bad parameter is an exception with the library's message.
fn check_furnace(out: &str) {
    let value = |key: &str| -> Vec<f64> {
        let line = out.lines().find_map(|l| l.strip_prefix(key));
        let line = line.unwrap_or_else(|| panic!("no {key:?} line in:\n{out}"));
        line.split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect()
    };
    let furnace = value("furnace ")[0];
    assert!((furnace - 1.0).abs() < 5e-3, "furnace {furnace}:\n{out}");
    let mismatches = value("mismatches ");
    assert!(mismatches[0] == 0.0 && mismatches[1] > 19_000.0, "{out}");
    assert!(
        out.contains("unfilled invalid argument: point was not filled"),
        "{out}"
    );
    assert!(out.contains("error invalid argument: "), "{out}");
    assert!(out.contains("beta_m = 2"), "{out}");
}

/// Every macro the installed headers define is spelled `HT_...`, so that none can clash
/// with a host's own (`MAX_COORDINATE` once did). Both headers must be there.
fn assert_macros_prefixed(include: &Path) {
    let mut headers = 0;
    for entry in std::fs::read_dir(include).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        headers += 1;
        for line in text.lines() {
            // `#define NAME` and `#  define NAME`, as the preprocessor reads them.
            let Some(rest) = line.trim_start().strip_prefix('#') else {
                continue;
            };
            let Some(rest) = rest.trim_start().strip_prefix("define") else {
                continue;
            };
            let name: String = rest
                .trim_start()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            assert!(
                name.starts_with("HT_"),
                "{} defines {name:?}, not prefixed HT_",
                path.display()
            );
        }
    }
    assert_eq!(
        headers,
        2,
        "hairtrace.h and hairtrace.hpp in {}",
        include.display()
    );
}

/// `scripts/install --help` prints the help (its options, what a prefix gets, how a host
/// that only shades and one that renders link) and succeeds; without a prefix it is a usage
/// error that points to the help.
#[test]
fn install_prints_its_help() {
    let script = root().join("scripts/install");
    let out = Command::new(&script).arg("--help").output().unwrap();
    assert!(out.status.success(), "{out:?}");
    let help = String::from_utf8(out.stdout).unwrap();
    for words in [
        "--prefix DIR",
        "--bsdf-only",
        "--no-build",
        "COMPONENTS bsdf",
        "hairtrace::bsdf",
        "pkg-config --cflags --libs hairtrace-bsdf",
        "libhairtrace.so.ABI",
    ] {
        assert!(help.contains(words), "no {words:?} in:\n{help}");
    }
    let bare = Command::new(&script).output().unwrap();
    assert_eq!(bare.status.code(), Some(2), "{bare:?}");
    assert!(
        String::from_utf8_lossy(&bare.stderr).contains("--help"),
        "{bare:?}"
    );
}
