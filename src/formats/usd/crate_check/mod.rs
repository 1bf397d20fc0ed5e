//! A structural check of USD crate files (.usdc) before openusd 0.6 reads them.
//!
//! openusd's crate reader (`usdc/reader.rs`, `usdc/coding.rs`, `usdc/mod.rs`) sizes its
//! buffers from counts it reads from the file before it knows whether the file holds that
//! much, so one corrupt number (a TOKENS block claiming 2^40 bytes) makes it ask for a
//! terabyte and the process aborts. This module walks the file the way openusd 0.6 will,
//! reading only the numbers that size something, and refuses the file with a message
//! naming the number and what bounds it. It decodes no more than bounds need: the LZ4
//! blocks of TOKENS, FIELDS (value representations) and PATHS are decompressed (with
//! `lz4_flex`, openusd's own LZ4) because later counts depend on them; values are not.
//!
//! **The bound.** Let B = 64 × the layer's size + 1 MiB (the layer: the crate file, or
//! the crate entry of a .usdz). Once a layer passes, no allocation openusd's crate reader
//! sizes from a number in that layer is larger than B, and the values of any one field
//! (nested dictionaries, time samples and list ops included) decode to at most B bytes in
//! all. Counts of plain data (arrays, index lists, offsets) are checked exactly against
//! the bytes after them; only compressed data may expand, and B caps that.
//!
//! Every allocation site of openusd 0.6's crate reader and the check that bounds it:
//!
//! | openusd site | allocation | check |
//! |---|---|---|
//! | `read_sections` | `read_vec::<Section>(count)` | count < 64 and the table inside the file ([`Crate::open`]) |
//! | `read_tokens` | `read_compressed(uncompressed)`: input `vec![0; compressed]`, output `vec![0; uncompressed]`; one `String` per token | compressed size within the section, uncompressed size <= B, tokens counted in the decompressed block |
//! | `read_strings` | `read_vec::<u32>(count)` | exact, within the section |
//! | `read_fields` | `read_encoded_ints(count)`, `read_compressed::<u64>(count)`, `Vec<Field>` | [`Crate::block`] for both blocks, count × 32 <= B |
//! | `read_fieldsets`, `read_specs` | `read_encoded_ints(count)` (× 3 for specs), `Vec<Spec>`, then `CrateData::open`'s `HashMap::with_capacity(specs)` | [`Crate::block`], count × 160 <= B |
//! | `read_paths` | `vec![Path; path_count]`, three `read_encoded_ints(count)`; `build_compressed_paths` makes one string per entry, each its parent's plus a token | counts × 32 <= B; the tree walked as openusd walks it ([`paths`]): each entry reached once (repeats would make the walk exponential), names summed <= B, each name one USD allows (a stray `}` sent openusd's composition into unbounded recursion) |
//! | `read_encoded_ints` (`coding::decode_ints`) | `vec![0u8; 4 + count/4 + 4 count]` before decompressing, `Vec::with_capacity(count)` | [`Crate::block`]: compressed size within the section, these sizes <= B |
//! | `read_ints`, `read_floats`, `read_gf_array`, `read_vec_array`, token arrays | `read_vec(count)` or, compressed, `read_encoded_ints(count)` / LUT `read_vec(lut)` + `vec![T; count]` | exact element sizes against the bytes after the count; compressed: the sizes above <= B ([`values`]) |
//! | `read_indexed_vec` (string, token, path and asset vectors and list ops) | `read_vec::<u32>(count)`, one clone of each named string | exact, and the named strings' lengths summed into the value's total; token vectors (children's names, which the stage's traversal appends to paths) hold names, each once |
//! | `read_pod_vec`, `LayerOffsetVector` | `read_vec(count)` | exact |
//! | reference and payload list ops, `Relocates`, `VariantSelectionMap` | `Vec/HashMap::with_capacity(count)` | count × the smallest entry on disk within the file, capacity × entry size in the value's total |
//! | `TimeSamples` | `read_vec::<ValueRep>(count)`, `Vec<Value>`, `Vec<(f64, Value)>` | count equal to the times' count and exact against the file; each sample's value walked |
//! | `read_custom_data` (dictionaries) | one entry per count; recursion through `value` | entries must move forward through the file (so count is bounded by it); nesting depth <= 32 and no value containing itself (it recurses without a limit) |
//!
//! Crate versions before 0.4.0 and chunked LZ4 blocks, which openusd 0.6 does not read (it
//! panics with `todo!`), are refused here.

mod paths;
mod values;

use std::collections::HashMap;

/// What a check of one layer found wrong.
pub(super) type Refusal = String;

/// A crate file starts with these 8 bytes.
pub(super) const MAGIC: &[u8; 8] = b"PXR-USDC";

/// Each allocation may be this many times the layer's size ...
const EXPANSION: u64 = 64;
/// ... plus this many bytes, so that small files may hold modestly compressed arrays.
const SLACK: u64 = 1 << 20;
/// Bytes per item of the widest per-item record openusd keeps for a section (an
/// `sdf::Path`, a token's `String`, a `Spec`: 24 bytes), rounded up.
const RECORD: u64 = 32;
/// Bytes per spec of `CrateData::open`'s `HashMap<sdf::Path, Spec>` with its spare slots.
const SPEC_ENTRY: u64 = 160;

/// Refuses `data` (a whole crate file) if openusd 0.6 could allocate beyond the bound in
/// the module doc reading it, recurse without limit, or loop for ever.
pub(super) fn check_crate(data: &[u8]) -> Result<(), Refusal> {
    let file = Crate::open(data)?;
    values::check_fields(&file)
}

/// A crate file's version: openusd reads each layout by it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Version(u8, u8, u8);

/// Reads little-endian numbers from `data` between a position and an end, refusing reads
/// past the end with the name of what was read.
struct At<'a> {
    data: &'a [u8],
    pos: usize,
    end: usize,
}

impl<'a> At<'a> {
    fn new(data: &'a [u8], pos: u64, end: usize, what: &str) -> Result<Self, Refusal> {
        match usize::try_from(pos) {
            Ok(pos) if pos <= end => Ok(Self { data, pos, end }),
            _ => Err(format!(
                "{what} starts at offset {pos}, past the end ({end})"
            )),
        }
    }

    fn left(&self) -> u64 {
        (self.end - self.pos) as u64
    }

    fn bytes(&mut self, n: u64, what: &str) -> Result<&'a [u8], Refusal> {
        if n > self.left() {
            return Err(format!(
                "{what} claims {n} bytes at offset {}, only {} bytes follow",
                self.pos,
                self.left()
            ));
        }
        let start = self.pos;
        self.pos += n as usize;
        Ok(&self.data[start..self.pos])
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], Refusal> {
        let pos = self.pos;
        let b = self
            .bytes(N as u64, what)
            .map_err(|_| format!("{what} at offset {pos}: the file ends"))?;
        Ok(b.try_into().expect("N bytes"))
    }

    fn u8(&mut self, what: &str) -> Result<u8, Refusal> {
        Ok(self.array::<1>(what)?[0])
    }

    fn u32(&mut self, what: &str) -> Result<u32, Refusal> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }

    fn u64(&mut self, what: &str) -> Result<u64, Refusal> {
        Ok(u64::from_le_bytes(self.array(what)?))
    }

    fn i64(&mut self, what: &str) -> Result<i64, Refusal> {
        Ok(i64::from_le_bytes(self.array(what)?))
    }

    /// Refuses `count` items of `size` bytes unless they fit in the bytes left.
    fn fits(&self, count: u64, size: u64, what: &str) -> Result<(), Refusal> {
        match count.checked_mul(size) {
            Some(n) if n <= self.left() => Ok(()),
            _ => Err(format!(
                "{what} claims {count} items of {size} bytes at offset {}, only {} bytes follow",
                self.pos,
                self.left()
            )),
        }
    }
}

/// What the check keeps of a crate file: its version, the lengths of its tokens, strings
/// and paths (strings that values clone) and its fields' value representations.
struct Crate<'a> {
    data: &'a [u8],
    version: Version,
    budget: u64,
    tokens: Vec<u64>,
    /// What each token may name in a path.
    names: Vec<paths::Name>,
    /// The token each string names.
    strings: Vec<u32>,
    /// Length of each path openusd builds, by path index (0: never built).
    paths: Vec<u64>,
    reps: Vec<u64>,
}

impl<'a> Crate<'a> {
    /// Checks the bootstrap, the table of contents and every section openusd reads when
    /// it opens the file.
    fn open(data: &'a [u8]) -> Result<Self, Refusal> {
        let mut at = At::new(data, 0, data.len(), "the bootstrap")?;
        if at.array::<8>("the bootstrap")? != *MAGIC {
            return Err("not a crate file (no PXR-USDC magic)".into());
        }
        let [major, minor, patch, ..] = at.array::<8>("the version")?;
        let version = Version(major, minor, patch);
        if version < Version(0, 4, 0) || major != 0 || minor > 12 {
            return Err(format!(
                "crate version {major}.{minor}.{patch}: openusd 0.6 reads 0.4.0 to 0.12.x"
            ));
        }
        let toc = at.u64("the table of contents' offset")?;
        let budget = (data.len() as u64).saturating_mul(EXPANSION) + SLACK;
        let mut file = Crate {
            data,
            version,
            budget,
            tokens: Vec::new(),
            names: Vec::new(),
            strings: Vec::new(),
            paths: Vec::new(),
            reps: Vec::new(),
        };
        let sections = file.sections(toc)?;
        let find = |name: &str| sections.get(name).copied();
        if let Some(s) = find("TOKENS") {
            file.read_tokens(s)?;
        }
        if let Some(s) = find("STRINGS") {
            file.read_strings(s)?;
        }
        if let Some(s) = find("FIELDS") {
            file.read_fields(s)?;
        }
        if let Some(s) = find("FIELDSETS") {
            file.coded_section(s, "FIELDSETS", RECORD, 1)?;
        }
        if let Some(s) = find("PATHS") {
            file.read_paths(s)?;
        }
        if let Some(s) = find("SPECS") {
            file.coded_section(s, "SPECS", SPEC_ENTRY, 3)?;
        }
        Ok(file)
    }

    /// The table of contents: each section's name, start and size, the first of each
    /// name (as openusd finds them), each inside the file.
    fn sections(&self, toc: u64) -> Result<HashMap<String, (u64, u64)>, Refusal> {
        let mut at = At::new(self.data, toc, self.data.len(), "the table of contents")?;
        let count = at.u64("the number of sections")?;
        if count == 0 || count >= 64 {
            return Err(format!("{count} sections: openusd reads 1 to 63"));
        }
        at.fits(count, 32, "the table of contents")?;
        let mut found = HashMap::new();
        for _ in 0..count {
            let name = at.array::<16>("a section name")?;
            let name = name.split(|&b| b == 0).next().unwrap_or_default();
            let name = String::from_utf8_lossy(name).into_owned();
            let start = at.u64("a section start")?;
            let size = at.u64("a section size")?;
            if start
                .checked_add(size)
                .is_none_or(|end| end > self.data.len() as u64)
            {
                return Err(format!(
                    "{name} section claims {size} bytes at offset {start}, the file has {}",
                    self.data.len()
                ));
            }
            found.entry(name).or_insert((start, size));
        }
        Ok(found)
    }

    /// A reader over one section's bytes.
    fn section(&self, (start, size): (u64, u64), name: &str) -> Result<At<'a>, Refusal> {
        At::new(self.data, start, (start + size) as usize, name)
    }

    /// Refuses `count` records of `size` bytes in memory beyond the budget.
    fn records(&self, count: u64, size: u64, what: &str) -> Result<u64, Refusal> {
        match count.checked_mul(size) {
            Some(n) if n <= self.budget => Ok(n),
            _ => {
                let claim = match size {
                    1 => format!("{count} bytes"),
                    _ => format!("{count} items ({size} bytes each in memory)"),
                };
                Err(format!(
                    "{what} claims {claim}, more than the {} bytes allowed for this {}-byte file",
                    self.budget,
                    self.data.len()
                ))
            }
        }
    }

    /// Checks one LZ4 block as openusd reads it (u64 compressed size, a chunk count byte,
    /// the block) into an output of `capacity` bytes, and returns the block.
    fn block(&self, at: &mut At<'a>, capacity: u64, what: &str) -> Result<&'a [u8], Refusal> {
        let size = at.u64(what)?;
        let block = at.bytes(size, what)?;
        self.records(capacity, 1, what)?;
        match block.first() {
            Some(0) | None => Ok(block.get(1..).unwrap_or_default()),
            Some(_) => Err(format!(
                "{what}: a chunked LZ4 block, which openusd 0.6 does not read"
            )),
        }
    }

    /// Decompresses a block checked by [`Crate::block`] into `capacity` bytes, as openusd
    /// will.
    fn decompress(&self, block: &[u8], capacity: u64, what: &str) -> Result<Vec<u8>, Refusal> {
        let mut out = vec![0; capacity as usize];
        let n = lz4_flex::block::decompress_into(block, &mut out)
            .map_err(|e| format!("{what}: the LZ4 block does not decompress: {e}"))?;
        out.truncate(n);
        Ok(out)
    }

    /// An integer-coded LZ4 block of `count` 32-bit integers, decoded.
    fn ints(&self, at: &mut At<'a>, count: u64, what: &str) -> Result<Vec<i32>, Refusal> {
        let capacity = ints_capacity(count);
        let block = self.block(at, capacity, what)?;
        let raw = self.decompress(block, capacity, what)?;
        decode_ints(&raw, count as usize).ok_or_else(|| {
            format!("{what}: the integer coding holds fewer than the {count} integers claimed")
        })
    }

    /// A section of a u64 count and `blocks` integer-coded blocks of that many integers,
    /// kept as records of `record` bytes each (FIELDSETS, SPECS).
    fn coded_section(
        &self,
        s: (u64, u64),
        name: &str,
        record: u64,
        blocks: usize,
    ) -> Result<(), Refusal> {
        let mut at = self.section(s, name)?;
        let count = at.u64(name)?;
        self.records(count, record, name)?;
        for _ in 0..blocks {
            self.block(&mut at, ints_capacity(count), name)?;
        }
        Ok(())
    }

    fn read_tokens(&mut self, s: (u64, u64)) -> Result<(), Refusal> {
        let mut at = self.section(s, "TOKENS")?;
        let count = at.u64("TOKENS count")?;
        let size = at.u64("TOKENS size")?;
        let block = self.block(&mut at, size, "TOKENS section")?;
        let raw = self.decompress(block, size, "TOKENS section")?;
        if let Some(text) = raw.strip_suffix(&[0]) {
            self.tokens = text.split(|&b| b == 0).map(|t| t.len() as u64).collect();
            self.names = text.split(|&b| b == 0).map(paths::Name::of).collect();
        }
        if self.tokens.len() as u64 != count {
            return Err(format!(
                "TOKENS section claims {count} tokens, its block holds {}",
                self.tokens.len()
            ));
        }
        self.records(count, RECORD, "TOKENS").map(drop)
    }

    fn read_strings(&mut self, s: (u64, u64)) -> Result<(), Refusal> {
        let mut at = self.section(s, "STRINGS")?;
        let count = at.u64("STRINGS count")?;
        at.fits(count, 4, "STRINGS section")?;
        for _ in 0..count {
            let token = at.u32("a string")?;
            if token as usize >= self.tokens.len() {
                return Err(format!(
                    "STRINGS: a string names token {token} of {}",
                    self.tokens.len()
                ));
            }
            self.strings.push(token);
        }
        Ok(())
    }

    fn read_fields(&mut self, s: (u64, u64)) -> Result<(), Refusal> {
        let mut at = self.section(s, "FIELDS")?;
        let count = at.u64("FIELDS count")?;
        self.records(count, RECORD, "FIELDS")?;
        self.block(&mut at, ints_capacity(count), "FIELDS tokens")?;
        let block = self.block(&mut at, count * 8, "FIELDS values")?;
        let raw = self.decompress(block, count * 8, "FIELDS values")?;
        self.reps = raw
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        Ok(())
    }

    fn read_paths(&mut self, s: (u64, u64)) -> Result<(), Refusal> {
        let mut at = self.section(s, "PATHS")?;
        let path_count = at.u64("PATHS count")?;
        self.records(path_count, RECORD, "PATHS")?;
        let count = at.u64("PATHS encoded count")?;
        self.records(count, RECORD, "PATHS entries")?;
        let parents = self.ints(&mut at, count, "PATHS path indices")?;
        let names = self.ints(&mut at, count, "PATHS name tokens")?;
        let jumps = self.ints(&mut at, count, "PATHS jumps")?;
        let tree = paths::Tree {
            path_indices: &parents,
            tokens: &names,
            jumps: &jumps,
        };
        self.paths = tree.lengths(path_count as usize, &self.tokens, &self.names, self.budget)?;
        Ok(())
    }
}

/// The output buffer openusd allocates for `count` integer-coded integers: the coding's
/// largest size for 32-bit integers (`coding::encoded_buffer_size::<u32>`).
fn ints_capacity(count: u64) -> u64 {
    if count == 0 {
        0
    } else {
        count
            .saturating_mul(4)
            .saturating_add(count.div_ceil(4))
            .saturating_add(4)
    }
}

/// Decodes `count` 32-bit integers of USD's integer coding: a common delta, two bits per
/// integer saying whether its delta is the common one or an 8, 16 or 32-bit one that
/// follows, each integer the previous plus its delta. `None` if `raw` is too short.
fn decode_ints(raw: &[u8], count: usize) -> Option<Vec<i32>> {
    let common = i32::from_le_bytes(raw.get(..4)?.try_into().ok()?);
    let codes = raw.get(4..4 + count.div_ceil(4))?;
    let mut rest = &raw[4 + codes.len()..];
    let mut take = |n: usize| -> Option<i32> {
        let (b, r) = rest.split_at_checked(n)?;
        rest = r;
        Some(match n {
            1 => i32::from(b[0] as i8),
            2 => i32::from(i16::from_le_bytes([b[0], b[1]])),
            _ => i32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        })
    };
    let mut out = Vec::with_capacity(count);
    let mut value = 0i32;
    for i in 0..count {
        let delta = match (codes[i / 4] >> (2 * (i % 4))) & 3 {
            0 => common,
            1 => take(1)?,
            2 => take(2)?,
            _ => take(4)?,
        };
        value = value.wrapping_add(delta);
        out.push(value);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_coding_decodes_common_and_8_16_32_bit_deltas() {
        // 5, 6, 7, 300, 300, 70300: deltas 5 (8-bit), 1, 1 (common), 293 (16-bit), 0
        // (8-bit), 70000 (32-bit).
        let mut raw = 1i32.to_le_bytes().to_vec();
        raw.extend([0b10_00_00_01, 0b11_01]);
        raw.push(5);
        raw.extend(293i16.to_le_bytes());
        raw.push(0);
        raw.extend(70000i32.to_le_bytes());
        assert_eq!(decode_ints(&raw, 6), Some(vec![5, 6, 7, 300, 300, 70300]));
        assert_eq!(decode_ints(&raw[..raw.len() - 1], 6), None);
        assert_eq!(decode_ints(&raw[..5], 6), None);
    }

    #[test]
    fn the_integer_buffer_is_sized_as_openusd_sizes_it() {
        assert_eq!(ints_capacity(0), 0);
        assert_eq!(ints_capacity(5), 4 + 2 + 20);
        assert_eq!(ints_capacity(u64::MAX), u64::MAX);
    }
}
