//! Any bytes given to the USD reader as a .usdc crate file read or are refused (see
//! usd_input.rs): the crate check (src/description/usd/crate_check) must stop every count
//! that would make openusd 0.6 allocate beyond the file, recurse or loop without bound.
#![no_main]

mod usd_input;

libfuzzer_sys::fuzz_target!(|data: &[u8]| usd_input::read_as(data, "usdc"));
