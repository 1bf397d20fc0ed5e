//! The layering of docs/architecture.md, checked on the sources: every `crate::` and
//! `super::` path a file names (tests and `tests/` folders excluded) must point at a layer no higher than its
//! own, and no two files may name each other. A new import that breaks the layering
//! fails here with the two files it joins.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level modules from the bottom up; a module may use its own layer and those below.
const LAYERS: [&[&str]; 8] = [
    &["error", "quiet_panic", "threads", "validate"],
    &["math"],
    &["bsdf", "embree", "image"],
    &["scene"],
    &["render", "farm"],
    &["description", "formats"],
    &["incremental"],
    &["capi"],
];

fn layer(module: &str) -> usize {
    let top = module.split("::").next().unwrap_or("");
    LAYERS
        .iter()
        .position(|l| l.contains(&top))
        .unwrap_or_else(|| panic!("module {module:?} is in no layer: add it to LAYERS"))
}

/// Every library source file as (module path, source without its unit tests).
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, root: &Path, out: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                // A layer's `tests/` folder is test code, which may use any layer.
                if !path.ends_with("tests") {
                    walk(&path, root, out);
                }
            } else if path.extension().is_some_and(|e| e == "rs") {
                let rel = path.strip_prefix(root).unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
                    parts.pop();
                }
                let text = std::fs::read_to_string(&path).unwrap();
                let code = match text.find("#[cfg(test)]\nmod tests") {
                    Some(i) => text[..i].to_string(),
                    None => text,
                };
                out.insert(parts.join("::"), code);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = BTreeMap::new();
    walk(&root, &root, &mut out);
    out
}

/// The paths a source names after `crate::` or `super::`, with `use` groups expanded one
/// level (`super::{a, b::c}` gives `super::a` and `super::b::c`). Comments are skipped.
fn named_paths(code: &str) -> Vec<String> {
    let code: String = code
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut out = Vec::new();
    for start in ["crate::", "super::"] {
        for (at, _) in code.match_indices(start) {
            if at > 0 && code[..at].ends_with(ident) {
                continue;
            }
            // The path: identifiers joined by `::`, up to a group or the end.
            let rest = &code[at..];
            let end = rest
                .find(|c: char| !(ident(c) || c == ':'))
                .unwrap_or(rest.len());
            let path = rest[..end].trim_end_matches(':').to_string();
            if rest[end..].starts_with('{') {
                let group = &rest[end + 1..rest.find('}').unwrap_or(rest.len())];
                for item in group.split(',') {
                    let item = item.trim().split(' ').next().unwrap_or("");
                    if !item.is_empty() && item != "self" {
                        out.push(format!("{path}::{item}"));
                    }
                }
            }
            out.push(path);
        }
    }
    out
}

/// The file module a path names, from the file `from`, if it is one of ours.
fn resolve(from: &str, path: &str, known: &BTreeSet<String>) -> Option<String> {
    let mut base: Vec<&str> = if from.is_empty() {
        vec![]
    } else {
        from.split("::").collect()
    };
    let mut parts = path.split("::").peekable();
    match parts.next()? {
        "crate" => base.clear(),
        "super" => {
            base.pop();
            while parts.peek() == Some(&"super") {
                parts.next();
                base.pop();
            }
        }
        _ => return None,
    }
    let full: Vec<&str> = base.into_iter().chain(parts).collect();
    (1..=full.len())
        .rev()
        .map(|k| full[..k].join("::"))
        .find(|m| known.contains(m))
}

#[test]
fn layers_go_one_way_and_files_form_no_cycle() {
    let modules = modules();
    let known: BTreeSet<String> = modules.keys().cloned().collect();
    let mut uses: BTreeMap<&str, BTreeSet<String>> = BTreeMap::new();
    for (module, code) in &modules {
        for path in named_paths(code) {
            if let Some(target) = resolve(module, &path, &known) {
                // A file's own module and its parents (re-exports) are not dependencies.
                if !module.starts_with(&target) && !target.is_empty() {
                    uses.entry(module).or_default().insert(target);
                }
            }
        }
    }
    let mut problems = Vec::new();
    for (from, targets) in &uses {
        if from.is_empty() {
            continue;
        }
        for to in targets {
            if layer(to) > layer(from) {
                problems.push(format!("{from} uses {to}, a layer above it"));
            }
            if uses.get(to.as_str()).is_some_and(|t| t.contains(*from)) && *from < to.as_str() {
                problems.push(format!("{from} and {to} use each other"));
            }
        }
    }
    assert!(uses.len() > 30, "the scan found only {} files", uses.len());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_scan_sees_what_it_must() {
    let known: BTreeSet<String> = ["scene::light", "scene::envmap", "math"]
        .map(String::from)
        .into();
    let paths = named_paths(
        "use super::{envmap::Environment, light_sample};\nuse crate::math::luminance; // crate::render",
    );
    assert_eq!(
        paths,
        [
            "crate::math::luminance",
            "super::envmap::Environment",
            "super::light_sample",
            "super",
        ]
    );
    assert_eq!(
        resolve("scene::light", "super::envmap::Environment", &known).as_deref(),
        Some("scene::envmap")
    );
    assert_eq!(
        resolve("scene::light", "crate::math::luminance", &known).as_deref(),
        Some("math")
    );
    assert_eq!(layer("formats::usd"), 5);
}
