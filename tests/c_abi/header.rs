//! The checked-in C header must be exactly what cbindgen makes of the current sources, so
//! that hosts compiling against `include/hairtrace.h` see the ABI the library exports; and
//! docs/c-abi.md lists every function it declares.

use std::collections::BTreeSet;
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

/// The `ht_*` names in `text` that are followed by `(`, outside comment lines.
fn called_names(text: &str) -> BTreeSet<String> {
    let code = text.lines().filter(|l| {
        let l = l.trim_start();
        !(l.starts_with('*') || l.starts_with("/*") || l.starts_with("//"))
    });
    let mut names = BTreeSet::new();
    for line in code {
        for (at, _) in line.match_indices("ht_") {
            let rest = &line[at..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            let joined = line[..at].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
            if !joined && rest[end..].starts_with('(') {
                names.insert(rest[..end].to_string());
            }
        }
    }
    names
}

/// docs/c-abi.md's table of functions (section 1) names every function the header declares,
/// and no other.
#[test]
fn the_function_table_lists_every_function() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = std::fs::read_to_string(root.join("include/hairtrace.h")).unwrap();
    let declared = called_names(&header);
    assert!(declared.len() > 40, "{declared:?}");
    let doc = std::fs::read_to_string(root.join("docs/c-abi.md")).unwrap();
    let start = doc.find("## 1. Shape of the interface").expect("section 1");
    let end = start + doc[start..].find("\n## 2.").expect("section 2");
    let mut listed = BTreeSet::new();
    for row in doc[start..end].lines().filter(|l| l.starts_with('|')) {
        for cell in row.split('`').skip(1).step_by(2) {
            if cell.starts_with("ht_") {
                listed.insert(cell.to_string());
            }
        }
    }
    assert_eq!(
        listed, declared,
        "docs/c-abi.md section 1 lists these, the header declares those"
    );
}
