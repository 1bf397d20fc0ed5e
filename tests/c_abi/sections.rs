//! The header by topic: cbindgen writes every type before every function, so its output is
//! regrouped here into sections, one per part of the API, each with its types and then
//! the functions that use them, under one `HT_RENDER` guard where the whole section
//! belongs to the render build. Each function goes to the section of the `src/capi` file
//! that declares it; each type and constant to that of its file, or to the first section
//! whose functions use it, whichever comes first, so that C sees it declared before use.

use std::collections::BTreeMap;
use std::path::Path;

/// The sections in the order a reader meets them, with the `src/capi` files in each.
const SECTIONS: [(&str, &[&str]); 7] = [
    ("Versions, status and errors", &["mod"]),
    (
        "The hair BSDF alone: parameters, frames, eval and sample",
        &["bsdf", "frame"],
    ),
    ("The prepared BSDF and path vertices", &["prepared"]),
    (
        "The Huang model of elliptical fibres: parameters, prepared BSDF, path vertices",
        &["huang", "huang_strand"],
    ),
    (
        "Devices and scenes: geometry, materials, lights",
        &["scene", "geometry", "materials", "lights", "shutdown"],
    ),
    ("Render settings by name", &["settings"]),
    ("Rendering and images", &["render"]),
];

struct Item {
    text: String,
    render_only: bool,
    function: bool,
}

/// `generated` (cbindgen's header) regrouped by section.
pub fn sectioned(generated: &str, capi: &Path) -> String {
    let owner = owners(capi);
    let prologue_end = generated
        .find("#endif\n\n/**")
        .map(|i| i + "#endif\n".len())
        .expect("the prologue ends with the HT_ALIGNED block");
    let open = "#ifdef __cplusplus\nextern \"C\" {\n#endif // __cplusplus\n";
    let close = "#ifdef __cplusplus\n}  // extern \"C\"\n#endif  // __cplusplus\n";
    let (types, rest) = generated[prologue_end..]
        .split_once(open)
        .expect("cbindgen's extern \"C\" block");
    let (functions, epilogue) = rest.split_once(close).expect("the end of extern \"C\"");
    let mut items = Vec::new();
    for (chunk, function) in
        (types.split("\n\n").map(|c| (c, false))).chain(functions.split("\n\n").map(|c| (c, true)))
    {
        let chunk = chunk.trim_matches('\n');
        if chunk.is_empty() {
            continue;
        }
        let guarded = chunk
            .strip_prefix("#if defined(HT_RENDER)\n")
            .and_then(|c| c.strip_suffix("\n#endif"));
        let text = guarded.unwrap_or(chunk).to_owned();
        let name = item_name(&text);
        let file = owner
            .get(&name)
            .unwrap_or_else(|| panic!("no src/capi file declares {name:?}"));
        let section = SECTIONS
            .iter()
            .position(|(_, files)| files.contains(&file.as_str()))
            .unwrap_or_else(|| panic!("src/capi/{file}.rs is in no header section"));
        let item = Item {
            text,
            render_only: guarded.is_some(),
            function,
        };
        items.push((section, name, item));
    }
    let mut by_section: BTreeMap<usize, Vec<Item>> = BTreeMap::new();
    // A type or constant moves up to the first section that mentions it, until none moves
    // (a constant may be used by a type that itself moved).
    let mut sections: Vec<usize> = items.iter().map(|(section, _, _)| *section).collect();
    loop {
        let mut moved = false;
        for (i, (_, name, item)) in items.iter().enumerate() {
            if item.function {
                continue;
            }
            let first = (items.iter().enumerate())
                .filter(|(j, (_, _, other))| *j != i && mentions(&other.text, name))
                .map(|(j, _)| sections[j])
                .min();
            if let Some(first) = first.filter(|&f| f < sections[i]) {
                sections[i] = first;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    for ((_, _, item), section) in items.into_iter().zip(sections) {
        by_section.entry(section).or_default().push(item);
    }
    let mut out = generated[..prologue_end].to_owned();
    for (i, items) in by_section {
        out += &format!(
            "\n/* {0}\n * {1}. {2}\n * {0} */\n",
            "=".repeat(84),
            i + 1,
            SECTIONS[i].0
        );
        let whole = items.iter().all(|it| it.render_only);
        if whole {
            out += "\n#if defined(HT_RENDER)\n";
        }
        for function in [false, true] {
            let part: Vec<&Item> = items.iter().filter(|it| it.function == function).collect();
            if part.is_empty() {
                continue;
            }
            if function {
                out += &format!("\n{open}");
            }
            for render_only in [false, true] {
                let group: Vec<&&Item> = part
                    .iter()
                    .filter(|it| it.render_only == render_only)
                    .collect();
                if group.is_empty() {
                    continue;
                }
                let guard = render_only && !whole;
                if guard {
                    out += "\n#if defined(HT_RENDER)\n";
                }
                for it in group {
                    out += &format!("\n{}\n", it.text);
                }
                if guard {
                    out += "\n#endif\n";
                }
            }
            if function {
                out += &format!("\n{close}");
            }
        }
        if whole {
            out += "\n#endif  /* HT_RENDER */\n";
        }
    }
    out + "\n" + epilogue.trim_start_matches('\n')
}

/// Whether the declaration in `text` (its doc comment aside) names `name` as a whole word.
fn mentions(text: &str, name: &str) -> bool {
    let text = text.rsplit("*/").next().unwrap_or(text);
    let word = |c: char| c.is_alphanumeric() || c == '_';
    text.match_indices(name)
        .any(|(i, _)| !text[..i].ends_with(word) && !text[i + name.len()..].starts_with(word))
}

/// The C name an item declares.
fn item_name(text: &str) -> String {
    let code: String = text.split("*/").last().unwrap_or(text).trim().to_owned();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    if let Some(rest) = code.strip_prefix("#define ") {
        return ident(rest);
    }
    if let Some(i) = code.find("(*") {
        return ident(&code[i + 2..]);
    }
    for kind in ["typedef struct ", "typedef enum "] {
        if let Some(rest) = code.strip_prefix(kind) {
            let rest = rest.trim_start_matches("HT_ALIGNED(16) ");
            return ident(rest);
        }
    }
    if code.starts_with("typedef ") {
        let decl = code.split(';').next().unwrap_or("");
        return decl.rsplit(' ').next().map(ident).unwrap_or_default();
    }
    let before = code.split('(').next().unwrap_or("");
    before
        .rsplit([' ', '*'])
        .next()
        .map(ident)
        .unwrap_or_default()
}

/// Which `src/capi` file (stem) declares each exported name.
fn owners(capi: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(capi).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if stem.ends_with("_tests") || path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        for line in text.lines() {
            let line = line.trim_start();
            for lead in [
                "pub struct ",
                "pub enum ",
                "pub const ",
                "pub type ",
                "pub unsafe extern \"C\" fn ",
                "pub extern \"C\" fn ",
            ] {
                if let Some(rest) = line.strip_prefix(lead) {
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    out.entry(name).or_insert_with(|| stem.clone());
                }
            }
        }
    }
    out
}
