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
    let report = Report::parse(&run(&mut Command::new(exe)));
    report.check_versions_and_eval();
    assert!(report.device, "{report:?}");
}

/// Runs a host linked against the static archive: nothing of hairtrace is needed at run
/// time, and the full library's dependencies are loaded (the control for bsdf_only.rs,
/// whose host must show none of them).
fn check_static_host(exe: &Path) {
    let needs = needed(exe);
    assert!(!needs.iter().any(|n| n.contains("hairtrace")), "{needs:?}");
    let report = Report::parse(&run(&mut Command::new(exe)));
    report.check_versions_and_eval();
    assert!(report.device, "{report:?}");
    assert!(report.embree >= 1 && report.oiio >= 1, "{report:?}");
    println!(
        "full static host at start-up: {} shared objects, {} threads, {} KiB resident",
        report.objects, report.threads, report.rss_kib
    );
}

#[test]
fn cpp_hosts_build_against_the_installed_prefix() {
    let prefix = install("prefix-full", false);
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
        declared_functions(&prefix, &[]),
        defined_functions(&lib.join(&real))
    );
    assert_eq!(
        pkg_config(&prefix, &["--modversion", "hairtrace"]),
        [version]
    );

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
    let mut flags = pkg_config(&prefix, &["--cflags", "--libs", "hairtrace"]);
    flags.push(format!("-Wl,-rpath,{}", lib.display()));
    compile(&shared, flags);
    check_shared_host(&shared, &prefix);
    let static_exe = out.join("static");
    compile(
        &static_exe,
        pkg_config(
            &prefix,
            &["--static", "--cflags", "--libs", "hairtrace-static"],
        ),
    );
    check_static_host(&static_exe);

    // CMake: find_package with this version, refusing the next minor (0.x) or major.
    let project = fresh_dir("hosts-cmake");
    std::fs::copy(&source, project.join("host.cpp")).unwrap();
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
             target_link_libraries(host_static PRIVATE hairtrace::hairtrace_static)\n"
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
    check_shared_host(&build.join("host_shared"), &prefix);
    check_static_host(&build.join("host_static"));
}
