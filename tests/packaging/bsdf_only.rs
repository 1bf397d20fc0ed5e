//! The BSDF-only library (`--no-default-features`, installed by `scripts/install
//! --bsdf-only`): a C program linked against its archive needs neither Embree nor
//! OpenImageIO, loads neither, and starts with one thread and a few MiB; a CMake host
//! builds against its `hairtrace::bsdf` target with Embree's and OpenImageIO's dev files
//! out of sight.

use super::{
    Report, declared_functions, defined_functions, fresh_dir, install, needed, pkg_config, root,
    run,
};
use std::path::Path;
use std::process::Command;

#[test]
fn bsdf_only_host_loads_neither_embree_nor_openimageio() {
    let prefix = install("prefix-bsdf-only", true);
    let lib = prefix.join("lib");
    // Its packages hide the render API from the header, so what it declares is exactly
    // what the library defines.
    let cflags = pkg_config(&prefix, &["--cflags", "hairtrace"]);
    assert!(cflags.contains(&"-DHT_BSDF_ONLY".to_string()), "{cflags:?}");
    let declared = declared_functions(&prefix, &["-DHT_BSDF_ONLY"]);
    assert!(declared.contains("ht_hair_eval"), "{declared:?}");
    assert!(!declared.contains("ht_device_new"), "{declared:?}");
    assert_eq!(declared, defined_functions(&lib.join("libhairtrace.a")));
    assert_eq!(declared, defined_functions(&lib.join("libhairtrace.so")));

    let exe = fresh_dir("hosts-bsdf-only").join("static");
    run(Command::new("gcc")
        .args(["-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"])
        .arg(root().join("tests/packaging/host.c"))
        .args(pkg_config(
            &prefix,
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

#[test]
fn bsdf_only_cmake_host_builds_without_embree_or_openimageio_dev_files() {
    let prefix = install("prefix-bsdf-only-cmake", true);
    // The control: under the same hiding, Embree's own package is not found.
    let control = fresh_dir("cmake-embree-hidden");
    std::fs::write(
        control.join("CMakeLists.txt"),
        "cmake_minimum_required(VERSION 3.16)\nproject(control C)\n\
         find_package(embree 3 REQUIRED)\n",
    )
    .unwrap();
    let out = hidden_cmake(&control, &prefix);
    assert!(
        !out.status.success(),
        "Embree's CMake package is still visible: the test hides nothing"
    );

    let project = fresh_dir("hosts-bsdf-only-cmake");
    std::fs::copy(
        root().join("tests/packaging/host.c"),
        project.join("host.c"),
    )
    .unwrap();
    std::fs::write(
        project.join("CMakeLists.txt"),
        "cmake_minimum_required(VERSION 3.16)\nproject(host C)\n\
         find_package(hairtrace REQUIRED)\n\
         if(NOT hairtrace_BSDF_ONLY)\n  message(FATAL_ERROR \"not the BSDF-only package\")\nendif()\n\
         add_executable(host host.c)\n\
         target_link_libraries(host PRIVATE hairtrace::bsdf)\n",
    )
    .unwrap();
    let out = hidden_cmake(&project, &prefix);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    run(Command::new("cmake")
        .arg("--build")
        .arg(project.join("build")));
    let report = Report::parse(&run(&mut Command::new(project.join("build/host"))));
    report.check_versions_and_eval();
    assert_eq!((report.embree, report.oiio), (0, 0), "{report:?}");
}
