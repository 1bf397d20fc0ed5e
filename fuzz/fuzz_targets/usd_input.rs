//! The body of the USD fuzz targets: the input written to a file of the target's
//! extension and read as a stage. It either reads into grooms whose curves Embree accepts,
//! or gives an InvalidArg error naming the file; no panic, no huge allocation (the runs
//! cap memory), no other error kind.

use std::sync::Once;

use hairtrace::Error;
use hairtrace::embree::CurveShape;
use hairtrace::formats::usd::read_usd_file;

static HOOK: Once = Once::new();

pub fn read_as(data: &[u8], extension: &str) {
    // libfuzzer-sys aborts on every panic, even one caught: the reader catches openusd's
    // panics and turns them into errors, so the default hook goes back. A panic that
    // escapes the reader still aborts the run (libfuzzer-sys's own catch_unwind).
    HOOK.call_once(|| {
        let _ = std::panic::take_hook();
    });
    let name = format!("hairtrace-fuzz-{}.{extension}", std::process::id());
    let path = std::env::temp_dir().join(name);
    std::fs::write(&path, data).expect("write the input");
    match read_usd_file(&path) {
        Ok(grooms) => {
            for c in &grooms.curves {
                c.curves(CurveShape::Round, 1.0, |p| p)
                    .expect("read curves are valid Embree curves");
            }
        }
        Err(Error::InvalidArg(message)) => assert!(message.contains("hairtrace-fuzz-")),
        Err(other) => panic!("unexpected error kind: {other:?}"),
    }
}
