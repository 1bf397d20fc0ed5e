//! Every C example under valgrind's memcheck and built with AddressSanitizer and
//! UndefinedBehaviorSanitizer: no invalid access, no uninitialised read, no undefined
//! behaviour, no leak. The examples are small scenes (the largest renders 64 x 48 at 4 spp)
//! so that the slow-down of valgrind (tens of times) keeps each run to seconds.

use crate::c_examples::{EXAMPLES, build_run_check};
use std::path::Path;

#[test]
fn every_example_is_clean_under_valgrind() {
    let supp = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c_abi/valgrind.supp");
    let supp = format!("--suppressions={}", supp.display());
    let valgrind = [
        "valgrind",
        "--error-exitcode=99",
        "--leak-check=full",
        "--show-leak-kinds=definite,indirect,possible",
        "--errors-for-leak-kinds=definite,indirect,possible",
        &supp,
        "-q",
    ];
    for example in &EXAMPLES {
        build_run_check(
            example,
            "gcc",
            &["-std=c99", "-D_DEFAULT_SOURCE", "-g"],
            "vg",
            &valgrind,
            &[],
        );
    }
}

#[test]
fn every_example_is_clean_under_asan_and_ubsan() {
    let flags = [
        "-std=c99",
        "-D_DEFAULT_SOURCE",
        "-g",
        "-fsanitize=address,undefined",
        "-fno-sanitize-recover=all",
        "-fno-omit-frame-pointer",
    ];
    let env = [
        (
            "ASAN_OPTIONS",
            "detect_leaks=1:halt_on_error=1:abort_on_error=0",
        ),
        ("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1"),
    ];
    for example in &EXAMPLES {
        build_run_check(example, "gcc", &flags, "asan", &[], &env);
    }
}
