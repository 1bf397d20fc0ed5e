//! The BSDF-only library (`--no-default-features`, installed by `scripts/install
//! --bsdf-only`, and as `libhairtrace-bsdf.a` in the full install): a C program linked
//! against its archive needs neither Embree nor OpenImageIO, loads neither, and starts with
//! one thread and a few MiB; CMake (`COMPONENTS bsdf`, `hairtrace::bsdf`) and pkg-config
//! (`hairtrace-bsdf`) hosts build against it from either prefix with Embree's and
//! OpenImageIO's dev files out of sight.

use super::{
    Report, declared_functions, defined_functions, fresh_dir, install, needed, pkg_config, root,
    run,
};
use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn bsdf_only_host_loads_neither_embree_nor_openimageio() {
    let prefix = install(true);
    let lib = prefix.join("lib");
    // Its packages hide the render API from the header, so what it declares is exactly
    // what the library defines.
    let cflags = pkg_config(prefix, &["--cflags", "hairtrace"]);
    assert!(cflags.contains(&"-DHT_BSDF_ONLY".to_string()), "{cflags:?}");
    let declared = declared_functions(prefix, &["-DHT_BSDF_ONLY"]);
    assert!(declared.contains("ht_hair_point_at_hit"), "{declared:?}");
    assert!(!declared.contains("ht_device_new"), "{declared:?}");
    assert_eq!(declared, defined_functions(&lib.join("libhairtrace.a")));
    assert_eq!(declared, defined_functions(&lib.join("libhairtrace.so")));

    let exe = fresh_dir("hosts-bsdf-only").join("static");
    run(Command::new("gcc")
        .args(["-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"])
        .arg(root().join("tests/packaging/host.c"))
        .args(pkg_config(
            prefix,
            &["--static", "--cflags", "--libs", "hairtrace-static"],
        ))
        .arg("-o")
        .arg(&exe));
    let needs = needed(&exe);
    assert!(
        !needs.iter().any(|n| n.contains("embree")
            || n.contains("OpenImageIO")
            || n.contains("stdc++")
            || n.contains("tbb")),
        "{needs:?}"
    );
    let report = Report::parse(&run(&mut Command::new(&exe)));
    report.check_versions_and_eval();
    println!(
        "BSDF-only host at start-up: {} shared objects, {} thread(s), {} KiB resident",
        report.objects, report.threads, report.rss_kib
    );
    assert_eq!((report.embree, report.oiio), (0, 0), "{report:?}");
    assert!(!report.device, "{report:?}");
    // The full library's host: 262 objects, 5 threads, about 125 MiB (install.rs prints it).
    assert_eq!(report.threads, 1, "{report:?}");
    assert!(report.objects <= 8, "{report:?}");
    assert!(report.rss_kib < 16 * 1024, "{report:?}");
}

/// CMake that sees no package under the system prefixes (`CMAKE_IGNORE_PREFIX_PATH`; `/`
/// too, which reaches /usr/lib through the merged /lib) and a pkg-config that sees only
/// `prefix`'s files: the dev packages of Embree and OpenImageIO (CMake configs and `.pc`
/// files in /usr) are out of sight, as on a machine without them.
fn hidden_cmake(project: &Path, prefix: &Path) -> std::process::Output {
    Command::new("cmake")
        .arg("-S")
        .arg(project)
        .arg("-B")
        .arg(project.join("build"))
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()))
        .arg("-DCMAKE_IGNORE_PREFIX_PATH=/usr;/usr/local;/")
        .env("PKG_CONFIG_LIBDIR", prefix.join("lib/pkgconfig"))
        .env_remove("PKG_CONFIG_PATH")
        .output()
        .expect("run cmake")
}

/// A C project over `host.c` whose CMakeLists.txt is `cmake` (its `project` line first).
fn cmake_project(name: &str, cmake: &str) -> PathBuf {
    let project = fresh_dir(name);
    std::fs::copy(
        root().join("tests/packaging/host.c"),
        project.join("host.c"),
    )
    .unwrap();
    let text = format!("cmake_minimum_required(VERSION 3.16)\nproject(host C)\n{cmake}");
    std::fs::write(project.join("CMakeLists.txt"), text).unwrap();
    project
}

/// `cmake` configures `project` under [`hidden_cmake`]: its success and output.
fn configures_hidden(project: &Path, prefix: &Path) -> (bool, String) {
    let out = hidden_cmake(project, prefix);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

/// A host that only shades, built from `prefix` with Embree's and OpenImageIO's dev files
/// hidden, through CMake (`find_package(hairtrace COMPONENTS bsdf)`, `hairtrace::bsdf`)
/// and through pkg-config (`hairtrace-bsdf`): both build, run with the Rust API's bits,
/// and neither needs nor maps Embree or OpenImageIO.
fn check_bsdf_hosts(prefix: &Path, name: &str) {
    let project = cmake_project(
        &format!("hosts-{name}-cmake"),
        "find_package(hairtrace REQUIRED COMPONENTS bsdf)\n\
         add_executable(host host.c)\n\
         target_link_libraries(host PRIVATE hairtrace::bsdf)\n",
    );
    let (ok, out) = configures_hidden(&project, prefix);
    assert!(ok, "{out}");
    run(Command::new("cmake")
        .arg("--build")
        .arg(project.join("build")));

    let flags = run(Command::new("pkg-config")
        .env("PKG_CONFIG_LIBDIR", prefix.join("lib/pkgconfig"))
        .env_remove("PKG_CONFIG_PATH")
        .args(["--cflags", "--libs", "hairtrace-bsdf"]));
    let pc_host = project.join("pkg-config-host");
    run(Command::new("gcc")
        .args(["-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"])
        .arg(root().join("tests/packaging/host.c"))
        .args(flags.split_whitespace())
        .arg("-o")
        .arg(&pc_host));

    for exe in [project.join("build/host"), pc_host] {
        let needs = needed(&exe);
        assert!(
            !needs
                .iter()
                .any(|n| n.contains("embree") || n.contains("OpenImageIO")),
            "{exe:?} needs {needs:?}"
        );
        let report = Report::parse(&run(&mut Command::new(&exe)));
        report.check_versions_and_eval();
        assert_eq!((report.embree, report.oiio), (0, 0), "{exe:?}: {report:?}");
        assert!(!report.device, "{exe:?}: {report:?}");
    }
}

#[test]
fn bsdf_only_cmake_host_builds_without_embree_or_openimageio_dev_files() {
    let prefix = install(true);
    // The control: under the same hiding, Embree's own package is not found.
    let control = cmake_project("cmake-embree-hidden", "find_package(embree 3 REQUIRED)\n");
    assert!(
        !configures_hidden(&control, prefix).0,
        "Embree's CMake package is still visible: the test hides nothing"
    );
    let project = cmake_project(
        "hosts-bsdf-only-default",
        "find_package(hairtrace REQUIRED)\n\
         if(NOT hairtrace_BSDF_ONLY)\n  message(FATAL_ERROR \"not the BSDF-only package\")\nendif()\n\
         find_package(hairtrace QUIET COMPONENTS render)\n\
         if(hairtrace_FOUND)\n  message(FATAL_ERROR \"render found in the BSDF-only package\")\nendif()\n",
    );
    let (ok, out) = configures_hidden(&project, prefix);
    assert!(ok, "{out}");
    check_bsdf_hosts(prefix, "bsdf-only");
}

#[test]
fn the_full_prefix_serves_bsdf_hosts_without_embree_or_openimageio_dev_files() {
    let prefix = install(false);
    // Its BSDF archive is the BSDF-only library: what the header declares with
    // HT_BSDF_ONLY, nothing of the renderer.
    assert_eq!(
        declared_functions(prefix, &["-DHT_BSDF_ONLY"]),
        defined_functions(&prefix.join("lib/libhairtrace-bsdf.a"))
    );
    // The control: the full package itself needs Embree, so under the same hiding it is
    // not found; the component is what spares a host that only shades.
    let full = cmake_project("cmake-full-hidden", "find_package(hairtrace REQUIRED)\n");
    let (ok, out) = configures_hidden(&full, prefix);
    assert!(!ok && out.contains("embree"), "{out}");
    check_bsdf_hosts(prefix, "full-prefix");
}
