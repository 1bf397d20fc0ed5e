//! Any text given to the USD reader as a .usda file either reads into grooms whose curves
//! Embree accepts, or gives an InvalidArg error naming the file; no panic, no huge
//! allocation, no other error kind. Text only: openusd 0.6's crate-file (.usdc) reader
//! allocates whatever counts a corrupt file claims, which is the crate's to fix (see
//! docs/formats.md).
#![no_main]

use std::sync::Once;

use hairtrace::Error;
use hairtrace::description::usd::read_usd_file;
use hairtrace::embree::CurveShape;

static HOOK: Once = Once::new();

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    // libfuzzer-sys aborts on every panic, even one caught: the reader catches openusd's
    // panics and turns them into errors, so the default hook goes back. A panic that
    // escapes the reader still aborts the run (libfuzzer-sys's own catch_unwind).
    HOOK.call_once(|| {
        let _ = std::panic::take_hook();
    });
    let path = std::env::temp_dir().join(format!("hairtrace-fuzz-{}.usda", std::process::id()));
    std::fs::write(&path, data).expect("write the input");
    match read_usd_file(&path) {
        Ok(grooms) => {
            for c in &grooms.curves {
                c.curves(CurveShape::Round, 1.0, |p| p, 0.3)
                    .expect("read curves are valid Embree curves");
            }
        }
        Err(Error::InvalidArg(message)) => assert!(message.contains("hairtrace-fuzz-")),
        Err(other) => panic!("unexpected error kind: {other:?}"),
    }
});
