//! A panic caught at the C boundary prints nothing: a hostile `.usdc` that makes the USD
//! library panic (a crate file whose table indexes run past their arrays) gives the host
//! `HT_ERR_INVALID_ARG` and the message through `ht_last_error()`, and its stderr stays
//! empty, with backtraces asked for.

use crate::c_examples::build;
use std::path::Path;
use std::process::Command;

#[test]
fn a_hostile_usd_file_leaves_the_hosts_stderr_empty() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = build(
        Path::new("tests/c_abi/c/hostile_usd.c"),
        "gcc",
        &["-std=c99", "-pedantic"],
        "quiet",
    );
    let out = Command::new(&exe)
        .arg(root.join("tests/fixtures/usd/panics_openusd.usdc"))
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("run the host");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}{stderr}");
    assert!(stdout.contains("status invalid argument"), "{stdout}");
    // The reader's own words for a panic inside the USD library: it did panic.
    assert!(stdout.contains("the USD library failed"), "{stdout}");
    assert_eq!(stderr, "", "the library wrote to the host's stderr");
}
