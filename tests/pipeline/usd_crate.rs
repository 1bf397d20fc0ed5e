//! Hostile crate files (.usdc) are refused with a message before openusd 0.6 reads them
//! (src/description/usd/crate_check): each kind of count the check bounds, set far beyond
//! the file in a crate file Pixar's library wrote (tests/fixtures/usd/make_crate_values.py),
//! must give an InvalidArg error naming it; a sweep sets every aligned 8 bytes of every
//! fixture to huge numbers and cuts the files short, and each must read or be refused. The
//! tests run in-process: an abort (a failed allocation, a stack overflow) fails the binary.

use std::io::{Cursor, Write};
use std::path::Path;

use hairtrace::Error;
use hairtrace::formats::usd::read_usd_file;
use openusd::usdc::CrateFile;

use super::usd::refused;

const HUGE: u64 = 1 << 40;

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/usd")
            .join(name),
    )
    .unwrap()
}

/// values.usdc with the offsets of its sections and fields, found by openusd's own reader.
struct Values {
    data: Vec<u8>,
    file: CrateFile<Cursor<Vec<u8>>>,
}

impl Values {
    fn new() -> Self {
        let data = fixture("values.usdc");
        let file = CrateFile::open(Cursor::new(data.clone())).unwrap();
        Self { data, file }
    }

    fn section(&self, name: &str) -> usize {
        self.file.find_section(name).unwrap().start as usize
    }

    /// The value representation of the first field named `name` of type `ty` (the type
    /// codes of openusd's `usdc::layout::Type`) that is not inlined.
    fn rep(&self, name: &str, ty: u8) -> u64 {
        let inlined = |rep: u64| (rep >> 62) & 1 == 1;
        let field = (self.file.fields.iter())
            .filter(|f| !inlined(f.value_rep.0))
            .find(|f| self.file.tokens[f.token_index] == name && (f.value_rep.0 >> 48) as u8 == ty)
            .unwrap_or_else(|| panic!("no field {name} of type {ty}"));
        field.value_rep.0
    }

    /// Where the data of that field starts.
    fn payload(&self, name: &str, ty: u8) -> usize {
        (self.rep(name, ty) & ((1 << 48) - 1)) as usize
    }

    fn read_u64(&self, at: usize) -> u64 {
        u64::from_le_bytes(self.data[at..at + 8].try_into().unwrap())
    }

    /// The file with the 8 bytes at `at` set to `value`, refused: the message.
    fn refused_with(&self, patches: &[(usize, &[u8])], name: &str) -> String {
        let mut data = self.data.clone();
        for (at, bytes) in patches {
            data[*at..*at + bytes.len()].copy_from_slice(bytes);
        }
        refused(&data, &format!("{name}.usdc"))
    }

    fn refused_at(&self, at: usize, value: u64, name: &str) -> String {
        self.refused_with(&[(at, &value.to_le_bytes())], name)
    }
}

fn assert_says(message: &str, what: &str) {
    assert!(message.contains(what), "expected «{what}» in: {message}");
}

#[test]
fn values_fixture_reads() {
    let v = Values::new();
    let path = std::env::temp_dir().join(format!("hairtrace-values-{}.usdc", std::process::id()));
    std::fs::write(&path, &v.data).unwrap();
    let grooms = read_usd_file(&path).unwrap();
    assert_eq!(grooms.curves.len(), 1);
    assert_eq!(grooms.curves[0].authored_counts, vec![4; 20]);
}

#[test]
fn a_tokens_block_of_2_to_the_40_bytes_is_refused() {
    let v = Values::new();
    let tokens = v.section("TOKENS");
    // TOKENS: token count, uncompressed size, compressed size, the block.
    let m = v.refused_at(tokens + 16, HUGE, "tokens_compressed");
    assert_says(&m, "TOKENS section claims 1099511627776 bytes at offset");
    assert_says(&m, "tokens_compressed.usdc");
    let m = v.refused_at(tokens + 8, HUGE, "tokens_uncompressed");
    assert_says(
        &m,
        "TOKENS section claims 1099511627776 bytes, more than the",
    );
    let m = v.refused_at(tokens, 5, "tokens_count");
    assert_says(&m, "TOKENS section claims 5 tokens, its block holds");
}

#[test]
fn section_counts_beyond_the_file_are_refused() {
    let v = Values::new();
    for (section, skip, says) in [
        (
            "STRINGS",
            0,
            "STRINGS section claims 1099511627776 items of 4 bytes",
        ),
        ("FIELDS", 0, "FIELDS claims 1099511627776 items"),
        ("FIELDSETS", 0, "FIELDSETS claims 1099511627776 items"),
        ("PATHS", 0, "PATHS claims 1099511627776 items"),
        ("PATHS", 8, "PATHS entries claims 1099511627776 items"),
        ("SPECS", 0, "SPECS claims 1099511627776 items"),
        // The compressed size of FIELDS' first block.
        (
            "FIELDS",
            8,
            "FIELDS tokens claims 1099511627776 bytes at offset",
        ),
    ] {
        let m = v.refused_at(v.section(section) + skip, HUGE, section);
        assert_says(&m, says);
    }
    // The table of contents: a section reaching beyond the file.
    let toc = v.read_u64(16) as usize;
    let m = v.refused_at(toc + 8 + 16 + 8, HUGE, "toc");
    assert_says(
        &m,
        "TOKENS section claims 1099511627776 bytes at offset 2048, the file has",
    );
    let m = v.refused_at(toc, 64, "toc_count");
    assert_says(&m, "64 sections");
}

#[test]
fn array_counts_beyond_the_file_are_refused() {
    let v = Values::new();
    // (field, type, what the check says); every array here is from crate version 0.7 on:
    // a u64 count at the payload.
    for (name, ty, says) in [
        (
            "default",
            24,
            "an array claims 1099511627776 items of 12 bytes",
        ), // points
        (
            "default",
            15,
            "an array claims 1099511627776 items of 128 bytes",
        ), // matrices
        (
            "default",
            3,
            "a compressed array claims 1099511627776 items",
        ), // int, compressed
        (
            "default",
            5,
            "a compressed array claims 1099511627776 items",
        ), // int64, compressed
        (
            "default",
            8,
            "a compressed array claims 1099511627776 items",
        ), // float, compressed
        (
            "default",
            11,
            "a token array claims 1099511627776 items of 4 bytes",
        ),
        (
            "default",
            10,
            "a list claims 1099511627776 items of 4 bytes",
        ), // strings
        (
            "primChildren",
            41,
            "a list claims 1099511627776 items of 4 bytes",
        ),
    ] {
        let at = v.payload(name, ty);
        let m = v.refused_at(at, HUGE, &format!("array{ty}"));
        assert_says(&m, says);
    }
    // The LZ4 block of a compressed int array, after its count.
    let at = v.payload("default", 3) + 8;
    assert_says(
        &v.refused_at(at, HUGE, "int_block"),
        "a compressed array claims 1099511627776 bytes at offset",
    );
    // A float array compressed as a lookup table ('t', then a u32 table size).
    let widths = (v.file.fields.iter())
        .map(|f| (f.value_rep.0 & ((1 << 48) - 1)) as usize)
        .find(|&p| v.data.get(p + 8) == Some(&b't'))
        .expect("widths are compressed as a lookup table");
    let m = v.refused_with(&[(widths + 9, &u32::MAX.to_le_bytes())], "lut");
    assert_says(&m, "a lookup table claims 4294967295 items of 4 bytes");
    // A token index beyond the tokens.
    let at = v.payload("default", 11) + 8;
    let m = v.refused_with(&[(at, &u32::MAX.to_le_bytes())], "token_index");
    assert_says(&m, "an index names 4294967295 of");
}

#[test]
fn list_op_and_map_counts_beyond_the_file_are_refused() {
    let v = Values::new();
    // A list op: a header byte, then each list's u64 count.
    for (name, ty, says) in [
        (
            "apiSchemas",
            32,
            "a list claims 1099511627776 items of 4 bytes",
        ),
        (
            "variantSetNames",
            33,
            "a list claims 1099511627776 items of 4 bytes",
        ),
        (
            "targetPaths",
            34,
            "a list claims 1099511627776 items of 4 bytes",
        ),
        (
            "references",
            35,
            "a reference list claims 1099511627776 items of 32 bytes",
        ),
        (
            "payload",
            55,
            "a payload list claims 1099511627776 items of 24 bytes",
        ),
    ] {
        let m = v.refused_at(v.payload(name, ty) + 1, HUGE, name);
        assert_says(&m, says);
    }
    let m = v.refused_at(v.payload("variantSelection", 45), HUGE, "variants");
    assert_says(
        &m,
        "variant selections claims 1099511627776 items of 8 bytes",
    );
}

/// An int array whose representation is also flagged inlined: openusd reads it at its
/// payload all the same (a random mutation of converted_by_usd_core.usdc, whose compressed
/// block then claimed 20 GiB).
#[test]
fn an_inlined_int_array_is_read_as_openusd_reads_it() {
    let m = refused(fixture("mutated_inlined_ints.usdc"), "inlined_ints.usdc");
    assert_says(&m, "a compressed array claims 21474836482 bytes at offset");
}

/// A prim name that is not an identifier (a random mutation made "bezier" "be}ier", and
/// openusd's composition recursed until the stack overflowed).
#[test]
fn paths_with_invalid_names_are_refused() {
    let v = Values::new();
    let tokens = v.section("TOKENS");
    let inst = (tokens..tokens + 500)
        .find(|&i| v.data[i..].starts_with(b"inst"))
        .expect("the prim name \"inst\" is a literal in the TOKENS block");
    let m = v.refused_with(&[(inst + 2, b"}")], "invalid_name");
    assert_says(&m, "PATHS: token");
    assert_says(&m, "is not a valid prim name");
}

/// A prim's children named twice (a random mutation listed an empty name, which made
/// openusd's traversal loop, growing its stack until the allocation failed).
#[test]
fn children_named_twice_are_refused() {
    let v = Values::new();
    // The root's primChildren: a u64 count, then u32 token indices.
    let at = v.payload("primChildren", 41) + 8;
    let first = v.data[at..at + 4].to_vec();
    let m = v.refused_with(&[(at + 4, &first)], "children_twice");
    assert_says(&m, "which is not a name or is repeated");
}

#[test]
fn dictionaries_that_loop_or_nest_too_deep_are_refused() {
    let v = Values::new();
    let dict = v.payload("customData", 31);
    // An entry: key (u32 string index), then an offset to its value representation.
    let offset_at = dict + 8 + 4;
    let m = v.refused_at(offset_at, (-20i64) as u64, "dict_backward");
    assert_says(&m, "the offset -20 at offset");
    assert_says(&m, "does not point forward");
    // The first entry's value made the dictionary itself.
    let rep_at = offset_at + v.read_u64(offset_at) as usize;
    let m = v.refused_at(rep_at, v.rep("customData", 31), "dict_cycle");
    assert_says(&m, &format!("the value at offset {dict} contains itself"));
    // Pixar's library nests dictionaries 40 deep; openusd would recurse as deep.
    let m = refused(fixture("deep_dict.usdc"), "deep_dict.usdc");
    assert_says(&m, "values nest deeper than 32");
}

#[test]
fn time_samples_beyond_the_file_are_refused() {
    let v = Values::new();
    let samples = v.payload("timeSamples", 46);
    let m = v.refused_at(samples, (-8i64) as u64, "samples_backward");
    assert_says(&m, "does not point forward");
    // The times: a double vector whose count is set beyond the file, with the sample
    // count after it to match.
    let times_at = samples + v.read_u64(samples) as usize;
    let times = (v.read_u64(times_at) & ((1 << 48) - 1)) as usize;
    let count_at = times_at + 8 + v.read_u64(times_at + 8) as usize;
    let m = v.refused_with(
        &[
            (times, &HUGE.to_le_bytes()),
            (count_at, &HUGE.to_le_bytes()),
        ],
        "samples_count",
    );
    assert_says(&m, "an array claims 1099511627776 items of 8 bytes");
}

/// Layers a stage brings in (a sublayer, a reference) are checked as the root is.
#[test]
fn crate_layers_a_stage_brings_in_are_checked() {
    let v = Values::new();
    let dir = std::env::temp_dir().join(format!("hairtrace-layers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut hostile = v.data.clone();
    let tokens = v.section("TOKENS");
    hostile[tokens + 16..tokens + 24].copy_from_slice(&HUGE.to_le_bytes());
    std::fs::write(dir.join("hostile.usdc"), &hostile).unwrap();
    for (name, text) in [
        (
            "sublayer.usda",
            "#usda 1.0\n(\n    subLayers = [@./hostile.usdc@]\n)\n",
        ),
        (
            "reference.usda",
            "#usda 1.0\ndef Xform \"a\" (\n    references = @./hostile.usdc@</hair>\n)\n{\n}\n",
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        match read_usd_file(&path) {
            Err(Error::InvalidArg(m)) => {
                assert_says(&m, name);
                assert_says(
                    &m,
                    "hostile.usdc: TOKENS section claims 1099511627776 bytes",
                );
            }
            other => panic!("{name}: expected an invalid-argument error, got {other:?}"),
        }
    }
}

/// A .usdz package is checked whole: its crate layer with a hostile TOKENS block, and an
/// entry stored compressed, are refused.
#[test]
fn usdz_packages_are_checked() {
    let v = Values::new();
    let package = |layer: &[u8], method: zip::CompressionMethod| {
        let mut out = Cursor::new(Vec::new());
        let mut zip = zip::ZipWriter::new(&mut out);
        let options = zip::write::SimpleFileOptions::default().compression_method(method);
        zip.start_file("layer.usdc", options).unwrap();
        zip.write_all(layer).unwrap();
        zip.finish().unwrap();
        out.into_inner()
    };
    let path = std::env::temp_dir().join(format!("hairtrace-pkg-{}.usdz", std::process::id()));
    std::fs::write(&path, package(&v.data, zip::CompressionMethod::Stored)).unwrap();
    assert_eq!(read_usd_file(&path).unwrap().curves.len(), 1);

    let mut hostile = v.data.clone();
    let tokens = v.section("TOKENS");
    hostile[tokens + 16..tokens + 24].copy_from_slice(&HUGE.to_le_bytes());
    let m = refused(
        package(&hostile, zip::CompressionMethod::Stored),
        "hostile.usdz",
    );
    assert_says(
        &m,
        "package entry layer.usdc: TOKENS section claims 1099511627776 bytes",
    );
    let m = refused(
        package(&v.data, zip::CompressionMethod::Deflated),
        "deflated.usdz",
    );
    assert_says(&m, "package entry layer.usdc is compressed");

    // Packages nested 8 deep are checked through; 9 deep are refused before the stack
    // could run out on a deeper nest.
    let nest = |depth: usize| {
        (0..depth).fold(v.data.clone(), |inner, _| {
            package(&inner, zip::CompressionMethod::Stored)
        })
    };
    let path = std::env::temp_dir().join(format!("hairtrace-nest-{}.usdz", std::process::id()));
    std::fs::write(&path, nest(8)).unwrap();
    let error = read_usd_file(&path)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(!error.contains("nested"), "{error}");
    let m = refused(nest(9), "nested.usdz");
    assert_says(&m, "packages nested more than 8 deep");
}

/// Every 8-byte-aligned u64 of every crate fixture set to 2^40, 2^62 and u64::MAX, and
/// each fixture cut at every 8th length: each reads or gives InvalidArg.
#[test]
fn corrupted_and_truncated_fixtures_read_or_are_refused() {
    let dir = std::env::temp_dir().join(format!("hairtrace-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/usd");
    let mut names: Vec<_> = std::fs::read_dir(&fixtures)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "usdc"))
        .collect();
    names.sort();
    assert!(names.len() >= 12);
    let (mut read, mut refused) = (0, 0);
    let mut try_read = |bytes: &[u8], what: &dyn Fn() -> String| {
        // A new file each time: truncating one can take milliseconds.
        let path = dir.join(format!("{}.usdc", read + refused));
        std::fs::write(&path, bytes).unwrap();
        match read_usd_file(&path) {
            Ok(_) => read += 1,
            Err(Error::InvalidArg(_)) => refused += 1,
            Err(other) => panic!("{}: {other:?}", what()),
        }
    };
    for name in &names {
        let good = std::fs::read(name).unwrap();
        for at in (0..good.len() - 7).step_by(8) {
            for value in [1u64 << 40, 1 << 62, u64::MAX] {
                let mut bad = good.clone();
                bad[at..at + 8].copy_from_slice(&value.to_le_bytes());
                try_read(&bad, &|| format!("{} with {value} at {at}", name.display()));
            }
        }
        for cut in (0..good.len()).step_by(8) {
            try_read(&good[..cut], &|| format!("{} cut at {cut}", name.display()));
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(read > 0 && refused > 0, "{read} read, {refused} refused");
}

/// Random bytes changed (1 to 5 per file: set, a bit flipped, a u32 written, nudged) in
/// crate fixtures, 4000 times with a fixed seed: each reads or gives InvalidArg.
#[test]
fn randomly_mutated_fixtures_read_or_are_refused() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let dir = std::env::temp_dir().join(format!("hairtrace-mutated-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fixtures = [
        "values.usdc",
        "all_bases.usdc",
        "deep_dict.usdc",
        "converted_by_usd_core.usdc",
    ];
    let fixtures = fixtures.map(fixture);
    let (mut read, mut refused) = (0, 0);
    for i in 0..4000 {
        let mut data = fixtures[i % fixtures.len()].clone();
        for _ in 0..rng.random_range(1..6) {
            let at = rng.random_range(0..data.len());
            match rng.random_range(0..4) {
                0 => data[at] = rng.random(),
                1 => data[at] ^= 1 << rng.random_range(0..8),
                2 => {
                    let end = (at + 4).min(data.len());
                    let word: u32 = rng.random();
                    data[at..end].copy_from_slice(&word.to_le_bytes()[..end - at]);
                }
                _ => data[at] = data[at].wrapping_add(rng.random_range(1..4)),
            }
        }
        let path = dir.join(format!("{i}.usdc"));
        std::fs::write(&path, &data).unwrap();
        match read_usd_file(&path) {
            Ok(_) => read += 1,
            Err(Error::InvalidArg(_)) => refused += 1,
            Err(other) => panic!("mutation {i}: {other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(read > 0 && refused > 0, "{read} read, {refused} refused");
}
