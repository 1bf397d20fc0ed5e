//! Any text given to the USD reader as a .usda file reads or is refused (see usd_input.rs).
#![no_main]

mod usd_input;

libfuzzer_sys::fuzz_target!(|data: &[u8]| usd_input::read_as(data, "usda"));
