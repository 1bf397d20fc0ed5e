//! The checked-in C header must be exactly what cbindgen makes of the current sources, so
//! that hosts compiling against `include/hairtrace.h` see the ABI the library exports.

use std::path::Path;

#[test]
fn header_matches_the_sources() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("cannot read cbindgen.toml: {e}"));
    let bindings = cbindgen::Builder::new()
        .with_crate(root)
        .with_config(config)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed: {e}"));
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("cbindgen writes UTF-8");
    let generated = super::sections::sectioned(&generated, &root.join("src/capi"));

    let path = root.join("include").join("hairtrace.h");
    if std::env::var_os("HT_BLESS_HEADER").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &generated)
            .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    if checked_in != generated {
        let first_difference = checked_in
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(checked_in.lines().count().min(generated.lines().count()));
        panic!(
            "{} is out of date with the Rust sources (first difference at line {}).\n\
             Regenerate it with:\n    HT_BLESS_HEADER=1 cargo test --release --test c_abi header\n\
             and review the diff before committing.\n--- generated header ---\n{generated}",
            path.display(),
            first_difference + 1
        );
    }
}
