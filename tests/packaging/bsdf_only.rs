//! The BSDF-only library (`--no-default-features`, installed by `scripts/install
//! --bsdf-only`): a C program linked against its archive needs neither Embree nor
//! OpenImageIO, loads neither, and starts with one thread and a few MiB.

use super::{
    Report, declared_functions, defined_functions, fresh_dir, install, needed, pkg_config, root,
    run,
};
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
