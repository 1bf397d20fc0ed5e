//! Any text given to the pbrt-v4 reader either reads into a description whose grooms are
//! whole curves of their basis, or gives an InvalidArg error (Io for a missing include or
//! PLY file, Image for a missing environment map); no panic, no huge allocation, no other
//! error kind.
#![no_main]

use hairtrace::Error;
use hairtrace::description::GroomSource;
use hairtrace::formats::pbrt::PbrtScene;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // A folder that does not exist: includes and PLY files are i/o errors.
    let dir = std::path::Path::new("/nonexistent/hairtrace-fuzz");
    match PbrtScene::from_text(text, dir, "fuzz.pbrt") {
        Ok(scene) => {
            for g in &scene.description.grooms {
                let GroomSource::ControlPoints {
                    points,
                    counts,
                    basis,
                } = &g.source
                else {
                    panic!("pbrt grooms hold control points");
                };
                let total: usize = counts.iter().map(|&c| c as usize).sum();
                assert_eq!(total, points.len());
                assert!(
                    counts
                        .iter()
                        .all(|&c| basis.segments_for(c as usize).is_some())
                );
                assert!(points.iter().all(|p| p[3] >= 0.0));
            }
            assert!(scene.warnings.iter().all(|w| w.starts_with("fuzz.pbrt:")));
        }
        Err(Error::InvalidArg(message) | Error::Io(message) | Error::Image(message)) => {
            assert!(!message.is_empty())
        }
        Err(other) => panic!("unexpected error kind: {other:?}"),
    }
});
