//! Any bytes given to the .hair reader either parse into valid strands or give an
//! InvalidArg error; no panic, no huge allocation, no other error kind.
#![no_main]

use hairtrace::Error;
use hairtrace::formats::hair::{Thickness, encode_hair, parse_hair};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    for thickness in [Thickness::Diameter, Thickness::Radius] {
        match parse_hair(data, thickness) {
            Ok(strands) => {
                strands.validate().expect("parsed strands are valid");
                // What was read can be written back, and reads back the same.
                let bytes = encode_hair(&strands, thickness).expect("parsed strands encode");
                assert_eq!(parse_hair(&bytes, thickness).as_ref(), Ok(&strands));
            }
            Err(Error::InvalidArg(message)) => assert!(!message.is_empty()),
            Err(other) => panic!("unexpected error kind: {other:?}"),
        }
    }
});
