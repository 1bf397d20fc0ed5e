//! The formats' tests: which reader a file goes to, and grooms converted between formats.

mod convert;

use super::*;

/// A file of `bytes` named `name` in this process's scratch folder.
fn file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn the_format_comes_from_the_signature_then_the_extension_then_the_text() {
    let of = |name, bytes: &[u8]| SceneFormat::of(&file(name, bytes)).unwrap();
    assert_eq!(of("a.toml", b"[render]\nspp = 4\n"), SceneFormat::Toml);
    assert_eq!(of("a.pbrt", b"Film \"rgb\"\n"), SceneFormat::Pbrt);
    assert_eq!(of("a.usda", b"#usda 1.0\n"), SceneFormat::Usd);
    assert_eq!(of("a.usdz", b"PK\x03\x04"), SceneFormat::Usd);
    // A signature wins over a wrong name.
    assert_eq!(of("groom.toml", b"HAIR\x01\0\0\0"), SceneFormat::Hair);
    let e = SceneFormat::of(&file("stage.scene", b"PXR-USDC")).unwrap_err();
    assert!(e.to_string().contains("name it .usd"), "{e}");
    // Without a known extension, the text decides.
    assert_eq!(of("scene", b"# a scene\n\nspp = 4\n"), SceneFormat::Toml);
    assert_eq!(
        of("scene.txt", b"# pbrt\nLookAt 0 0 5  0 0 0  0 1 0\n"),
        SceneFormat::Pbrt
    );
    let e = SceneFormat::of(&file("notes.txt", b"hello there\n")).unwrap_err();
    assert!(e.to_string().contains("notes.txt: cannot tell"), "{e}");
    let e = SceneFormat::of(Path::new("/nonexistent/a.toml")).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/a.toml"), "{e}");
}
