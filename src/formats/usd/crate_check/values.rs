//! The fields' values, walked as openusd 0.6's `CrateFile::value` would read them, to
//! bound what each allocates: every count against the bytes after it, compressed arrays
//! against the budget, the strings that string, token and path lists clone, and the
//! recursion of dictionaries, time samples and references (depth and cycles). Values are
//! not decoded: only counts, indices and the offsets that lead to nested values are read.

use std::collections::{HashMap, HashSet};
use std::mem::size_of;

use openusd::{sdf, tf};

use super::paths::Name;
use super::{At, Crate, Refusal, Version, ints_capacity};

/// Deepest nesting of values (dictionaries in dictionaries, time samples of
/// dictionaries, ...): openusd recurses once per level, with no limit of its own, at
/// about 2 KiB of stack a level (a 1000-deep dictionary needed over 1 MiB), so 32 levels
/// fit any thread's stack; Pixar's files nest a few.
const MAX_DEPTH: u32 = 32;

/// Bytes of one dictionary or map entry in openusd's `HashMap`, spare slots included.
const MAP_ENTRY: u64 = 2 * (size_of::<String>() + size_of::<sdf::Value>()) as u64;

/// The type codes of a value representation that openusd reads a count for.
mod ty {
    pub(super) const BOOL: u8 = 1;
    pub(super) const UCHAR: u8 = 2;
    pub(super) const INT: u8 = 3;
    pub(super) const UINT: u8 = 4;
    pub(super) const INT64: u8 = 5;
    pub(super) const UINT64: u8 = 6;
    pub(super) const HALF: u8 = 7;
    pub(super) const FLOAT: u8 = 8;
    pub(super) const DOUBLE: u8 = 9;
    pub(super) const STRING: u8 = 10;
    pub(super) const TOKEN: u8 = 11;
    pub(super) const ASSET_PATH: u8 = 12;
    pub(super) const MATRIX2D: u8 = 13;
    pub(super) const MATRIX4D: u8 = 15;
    pub(super) const QUATD: u8 = 16;
    pub(super) const QUATH: u8 = 18;
    pub(super) const VEC2D: u8 = 19;
    pub(super) const VEC4I: u8 = 30;
    pub(super) const DICTIONARY: u8 = 31;
    pub(super) const TOKEN_LIST_OP: u8 = 32;
    pub(super) const STRING_LIST_OP: u8 = 33;
    pub(super) const PATH_LIST_OP: u8 = 34;
    pub(super) const REFERENCE_LIST_OP: u8 = 35;
    pub(super) const INT_LIST_OP: u8 = 36;
    pub(super) const INT64_LIST_OP: u8 = 37;
    pub(super) const UINT_LIST_OP: u8 = 38;
    pub(super) const UINT64_LIST_OP: u8 = 39;
    pub(super) const PATH_VECTOR: u8 = 40;
    pub(super) const TOKEN_VECTOR: u8 = 41;
    pub(super) const VARIANT_SELECTION_MAP: u8 = 45;
    pub(super) const TIME_SAMPLES: u8 = 46;
    pub(super) const DOUBLE_VECTOR: u8 = 48;
    pub(super) const LAYER_OFFSET_VECTOR: u8 = 49;
    pub(super) const STRING_VECTOR: u8 = 50;
    pub(super) const UNREGISTERED_VALUE_LIST_OP: u8 = 54;
    pub(super) const PAYLOAD_LIST_OP: u8 = 55;
    pub(super) const TIME_CODE: u8 = 56;
    pub(super) const PATH_EXPRESSION: u8 = 57;
    pub(super) const RELOCATES: u8 = 58;
}

/// Bytes of one element of a plain array of `code` as stored (vectors, matrices, quats).
fn element_size(code: u8) -> u64 {
    // Vec2d..Vec4i: d, f, h, i for 2, 3 and 4 components.
    const VECS: [u64; 12] = [16, 8, 4, 8, 24, 12, 6, 12, 32, 16, 8, 16];
    match code {
        ty::MATRIX2D => 32,
        14 => 72,
        ty::MATRIX4D => 128,
        ty::QUATD => 32,
        17 => 16,
        ty::QUATH => 8,
        _ => VECS[usize::from(code - ty::VEC2D)],
    }
}

/// A field's value representation: type, flags and a 48-bit payload (the value itself
/// when inlined, else the offset of its data).
#[derive(Clone, Copy)]
struct Rep(u64);

impl Rep {
    fn ty(self) -> u8 {
        (self.0 >> 48) as u8
    }
    fn array(self) -> bool {
        self.0 >> 63 != 0
    }
    fn inlined(self) -> bool {
        (self.0 >> 62) & 1 != 0
    }
    fn compressed(self) -> bool {
        (self.0 >> 61) & 1 != 0
    }
    fn payload(self) -> u64 {
        self.0 & ((1 << 48) - 1)
    }
    /// The bits openusd reads (the others do not change what it does).
    fn key(self) -> u64 {
        self.0 & !(0x1f << 56)
    }
}

/// Bytes a value allocates and how deep its nested values go.
#[derive(Clone, Copy, Default)]
struct Cost {
    bytes: u64,
    depth: u32,
}

impl Cost {
    fn bytes(bytes: u64) -> Self {
        Self { bytes, depth: 0 }
    }
    fn add(&mut self, other: Cost) {
        self.bytes = self.bytes.saturating_add(other.bytes);
        self.depth = self.depth.max(other.depth);
    }
    fn nested(mut self, inner: Cost) -> Self {
        self.bytes = self.bytes.saturating_add(inner.bytes);
        self.depth = self.depth.max(inner.depth + 1);
        self
    }
}

/// What a list of indices names.
#[derive(Clone, Copy)]
enum Names {
    Tokens,
    Strings,
    Paths,
}

/// Walks every field's value, refusing one that allocates beyond the budget.
pub(super) fn check_fields(file: &Crate) -> Result<(), Refusal> {
    let mut walk = Walk {
        file,
        memo: HashMap::new(),
        work: 0,
    };
    for &rep in &file.reps {
        walk.value(Rep(rep), 0)?;
    }
    Ok(())
}

struct Walk<'f, 'a> {
    file: &'f Crate<'a>,
    /// Cost of each value already walked; `None` while it is being walked.
    memo: HashMap<u64, Option<Cost>>,
    /// Items read so far, bounded by the budget so that the walk stays linear.
    work: u64,
}

impl<'a> Walk<'_, 'a> {
    fn at(&self, pos: u64, what: &str) -> Result<At<'a>, Refusal> {
        At::new(self.file.data, pos, self.file.data.len(), what)
    }

    fn count_work(&mut self, items: u64) -> Result<(), Refusal> {
        self.work = self.work.saturating_add(items);
        if self.work > self.file.budget {
            return Err(format!(
                "the values make more than {} reads of this {}-byte file",
                self.file.budget,
                self.file.data.len()
            ));
        }
        Ok(())
    }

    fn value(&mut self, rep: Rep, depth: u32) -> Result<Cost, Refusal> {
        let at = rep.payload();
        match self.memo.get(&rep.key()) {
            Some(None) => return Err(format!("the value at offset {at} contains itself")),
            Some(Some(cost)) if depth + cost.depth <= MAX_DEPTH => return Ok(*cost),
            Some(Some(_)) => {
                return Err(format!(
                    "values nest deeper than {MAX_DEPTH} (at offset {at})"
                ));
            }
            None if depth > MAX_DEPTH => {
                return Err(format!(
                    "values nest deeper than {MAX_DEPTH} (at offset {at})"
                ));
            }
            None => {}
        }
        self.memo.insert(rep.key(), None);
        let cost = self.walk(rep, depth)?;
        if cost.bytes > self.file.budget {
            return Err(format!(
                "the value at offset {at} (type {}) decodes to more than the {} bytes allowed \
                 for this {}-byte file",
                rep.ty(),
                self.file.budget,
                self.file.data.len()
            ));
        }
        self.memo.insert(rep.key(), Some(cost));
        Ok(cost)
    }

    /// The cost of one value, by its type and flags as openusd 0.6 dispatches them; a
    /// representation openusd refuses without reading, or reads at a fixed size, costs
    /// nothing here.
    fn walk(&mut self, rep: Rep, depth: u32) -> Result<Cost, Refusal> {
        let (code, array, inlined) = (rep.ty(), rep.array(), rep.inlined());
        let plain = !inlined && !array && !rep.compressed();
        let v5 = Some(Version(0, 5, 0));
        let v6 = Some(Version(0, 6, 0));
        let cost = match code {
            ty::BOOL | ty::UCHAR if array => self.plain_array(rep, 1, 2)?,
            ty::INT | ty::UINT if array => self.numbers(rep, 4, v5)?,
            ty::INT64 | ty::UINT64 if array => self.numbers(rep, 8, v5)?,
            ty::HALF if array => self.numbers(rep, 2, v6)?,
            ty::FLOAT if array => self.numbers(rep, 4, v6)?,
            ty::DOUBLE | ty::TIME_CODE if array => self.numbers(rep, 8, v6)?,
            ty::DOUBLE_VECTOR if !inlined => self.numbers(rep, 8, v6)?,
            ty::STRING | ty::ASSET_PATH | ty::PATH_EXPRESSION if array => {
                self.names_at(rep, Names::Strings)?
            }
            ty::STRING_VECTOR if !inlined => self.names_at(rep, Names::Strings)?,
            ty::TOKEN_VECTOR if !inlined => self.children(rep)?,
            ty::PATH_VECTOR if !inlined => self.names_at(rep, Names::Paths)?,
            ty::TOKEN if array => self.token_array(rep)?,
            ty::MATRIX2D..=ty::QUATH | ty::VEC2D..=ty::VEC4I if array => {
                self.plain_array(rep, element_size(code), 3)?
            }
            ty::TOKEN_LIST_OP if !inlined => {
                self.list_op(rep, |w, at| w.names(at, Names::Tokens))?
            }
            ty::STRING_LIST_OP | ty::UNREGISTERED_VALUE_LIST_OP if !inlined => {
                self.list_op(rep, |w, at| w.names(at, Names::Strings))?
            }
            ty::PATH_LIST_OP if !inlined => self.list_op(rep, |w, at| w.names(at, Names::Paths))?,
            ty::INT_LIST_OP | ty::UINT_LIST_OP if !inlined => {
                self.list_op(rep, |w, at| w.pods(at, 4))?
            }
            ty::INT64_LIST_OP | ty::UINT64_LIST_OP if !inlined => {
                self.list_op(rep, |w, at| w.pods(at, 8))?
            }
            ty::REFERENCE_LIST_OP if !inlined => {
                self.list_op(rep, |w, at| w.references(at, depth))?
            }
            ty::PAYLOAD_LIST_OP => self.list_op(rep, |w, at| w.payloads(at))?,
            ty::LAYER_OFFSET_VECTOR if plain => {
                let mut at = self.at(rep.payload(), "a layer offset vector")?;
                self.pods(&mut at, 16)?
            }
            ty::VARIANT_SELECTION_MAP if plain => {
                self.pairs(rep, Names::Strings, MAP_ENTRY, "variant selections")?
            }
            ty::TIME_SAMPLES if !inlined && !rep.compressed() => self.time_samples(rep, depth)?,
            ty::DICTIONARY if plain => {
                let mut at = self.at(rep.payload(), "a dictionary")?;
                self.dictionary(&mut at, depth)?
            }
            ty::RELOCATES if !inlined => {
                let entry = 2 * size_of::<sdf::Path>() as u64;
                self.pairs(rep, Names::Paths, entry, "relocates")?
            }
            _ => Cost::default(),
        };
        Ok(cost)
    }

    /// An array's element count and whether openusd reads it compressed (only from
    /// `compressed_from` on, with the flag set, and for 4 elements or more), with a reader
    /// after the count; `None` for an empty array (payload 0).
    fn array_head(
        &self,
        rep: Rep,
        compressed_from: Option<Version>,
    ) -> Result<Option<(u64, bool, At<'a>)>, Refusal> {
        if rep.payload() == 0 {
            return Ok(None);
        }
        let version = self.file.version;
        let mut at = self.at(rep.payload(), "an array")?;
        if version < Version(0, 5, 0) {
            at.u32("an array's shape")?;
        }
        let count = if version < Version(0, 7, 0) {
            u64::from(at.u32("an array's count")?)
        } else {
            at.u64("an array's count")?
        };
        let compressed =
            compressed_from.is_some_and(|from| version >= from) && rep.compressed() && count >= 4;
        Ok(Some((count, compressed, at)))
    }

    /// An array of `size`-byte elements read as they are and copied `copies` times.
    fn plain_array(&mut self, rep: Rep, size: u64, copies: u64) -> Result<Cost, Refusal> {
        let Some((count, _, at)) = self.array_head(rep, None)? else {
            return Ok(Cost::default());
        };
        at.fits(count, size, "an array")?;
        Ok(Cost::bytes(count * size * copies))
    }

    /// An int or float array of `size`-byte numbers, compressed from `compressed_from`
    /// on: integer-coded, or (floats) integer-coded or a lookup table and coded indices.
    fn numbers(
        &mut self,
        rep: Rep,
        size: u64,
        compressed_from: Option<Version>,
    ) -> Result<Cost, Refusal> {
        // openusd refuses an inlined float array, but reads an inlined int array's payload
        // as an offset all the same.
        let floats = compressed_from == Some(Version(0, 6, 0));
        if floats && rep.inlined() {
            return Ok(Cost::default());
        }
        let file = self.file;
        let Some((count, compressed, mut at)) = self.array_head(rep, compressed_from)? else {
            return Ok(Cost::default());
        };
        if !compressed {
            at.fits(count, size, "an array")?;
            return Ok(Cost::bytes(count * size));
        }
        let out = file.records(count, size, "a compressed array")?;
        let mut table = 0;
        if floats {
            match at.u8("a compressed array's code")? {
                b'i' => {}
                b't' => {
                    let entries = u64::from(at.u32("a lookup table's size")?);
                    at.fits(entries, size, "a lookup table")?;
                    at.bytes(entries * size, "a lookup table")?;
                    table = entries * size;
                }
                _ => return Ok(Cost::default()),
            }
        }
        let coded = ints_capacity(count);
        file.block(&mut at, coded, "a compressed array")?;
        let decoded = file.records(count, if floats { 4 } else { size }, "a compressed array")?;
        Ok(Cost::bytes(out + table + coded + decoded))
    }

    /// A token array: u32 token indices after an array head.
    fn token_array(&mut self, rep: Rep) -> Result<Cost, Refusal> {
        let file = self.file;
        let Some((count, _, mut at)) = self.array_head(rep, None)? else {
            return Ok(Cost::default());
        };
        at.fits(count, 4, "a token array")?;
        self.count_work(count)?;
        let mut bytes = count * (4 + size_of::<tf::Token>() as u64);
        for _ in 0..count {
            bytes += name_length(file, Names::Tokens, at.u32("a token index")?)?;
        }
        Ok(Cost::bytes(bytes))
    }

    fn names_at(&mut self, rep: Rep, names: Names) -> Result<Cost, Refusal> {
        let mut at = self.at(rep.payload(), "a list")?;
        self.names(&mut at, names)
    }

    /// A u64 count and as many u32 indices of tokens, strings or paths, each cloned.
    fn names(&mut self, at: &mut At, names: Names) -> Result<Cost, Refusal> {
        let count = at.u64("a list's count")?;
        at.fits(count, 4, "a list")?;
        self.count_work(count)?;
        let mut bytes = count * (4 + size_of::<String>() as u64);
        for _ in 0..count {
            bytes += name_length(self.file, names, at.u32("an index")?)?;
        }
        Ok(Cost::bytes(bytes))
    }

    /// A token vector, which Pixar's files use for names of children (`primChildren`,
    /// `properties`, variant sets and variants): openusd appends each to its parent's path,
    /// so each must be a name (an empty one or `.` made its traversal loop for ever) and
    /// appear once (repeats multiply the prims a traversal visits at each level).
    fn children(&mut self, rep: Rep) -> Result<Cost, Refusal> {
        let mut at = self.at(rep.payload(), "a list of names")?;
        let list = at.pos;
        let cost = self.names(&mut at, Names::Tokens)?;
        at.pos = list;
        let count = at.u64("a list of names")?;
        let mut seen = HashSet::new();
        for _ in 0..count {
            let token = at.u32("a name")?;
            let valid = !matches!(
                self.file.names[token as usize],
                Name::Variant | Name::Invalid
            );
            if !valid || !seen.insert(token) {
                return Err(format!(
                    "the list of names at offset {list} holds token {token}, which is not a name or is repeated"
                ));
            }
        }
        Ok(cost)
    }

    /// A u64 count and as many `size`-byte numbers.
    fn pods(&mut self, at: &mut At, size: u64) -> Result<Cost, Refusal> {
        let count = at.u64("a list's count")?;
        at.fits(count, size, "a list")?;
        at.bytes(count * size, "a list")?;
        Ok(Cost::bytes(count * size))
    }

    /// A list op: a header byte whose bits 1 to 6 say which of its six lists follow.
    fn list_op(
        &mut self,
        rep: Rep,
        mut list: impl FnMut(&mut Self, &mut At) -> Result<Cost, Refusal>,
    ) -> Result<Cost, Refusal> {
        let mut at = self.at(rep.payload(), "a list op")?;
        let header = at.u8("a list op's header")?;
        let mut cost = Cost::default();
        for _ in 0..(header >> 1 & 0x3f).count_ones() {
            cost.add(list(self, &mut at)?);
        }
        Ok(cost)
    }

    /// References: asset path (string index), prim path (path index), layer offset (two
    /// f64) and a dictionary of custom data, in place.
    fn references(&mut self, at: &mut At, depth: u32) -> Result<Cost, Refusal> {
        let count = at.u64("a reference list's count")?;
        at.fits(count, 4 + 4 + 16 + 8, "a reference list")?;
        self.count_work(count)?;
        let mut cost = Cost::bytes(count * size_of::<sdf::Reference>() as u64);
        for _ in 0..count {
            cost.add(self.asset_and_path(at)?);
            at.bytes(16, "a layer offset")?;
            cost.add(self.dictionary(at, depth)?);
        }
        Ok(cost)
    }

    /// Payloads: asset path, prim path and (from 0.8.0) a layer offset.
    fn payloads(&mut self, at: &mut At) -> Result<Cost, Refusal> {
        let offset = if self.file.version >= Version(0, 8, 0) {
            16
        } else {
            0
        };
        let count = at.u64("a payload list's count")?;
        at.fits(count, 8 + offset, "a payload list")?;
        self.count_work(count)?;
        let mut cost = Cost::bytes(count * size_of::<sdf::Payload>() as u64);
        for _ in 0..count {
            cost.add(self.asset_and_path(at)?);
            at.bytes(offset, "a layer offset")?;
        }
        Ok(cost)
    }

    fn asset_and_path(&self, at: &mut At) -> Result<Cost, Refusal> {
        let asset = name_length(self.file, Names::Strings, at.u32("an asset path")?)?;
        let path = name_length(self.file, Names::Paths, at.u32("a prim path")?)?;
        Ok(Cost::bytes(asset + path))
    }

    /// A u64 count and as many pairs of string or path indices, into a map or a list of
    /// `entry`-byte items (variant selections, relocates).
    fn pairs(&mut self, rep: Rep, names: Names, entry: u64, what: &str) -> Result<Cost, Refusal> {
        let file = self.file;
        let mut at = self.at(rep.payload(), what)?;
        let count = at.u64(what)?;
        at.fits(count, 8, what)?;
        self.count_work(count)?;
        let mut bytes = count * entry;
        for _ in 0..2 * count {
            bytes += name_length(file, names, at.u32(what)?)?;
        }
        Ok(Cost::bytes(bytes))
    }

    /// A dictionary: a u64 count, then per entry a key (string index), an offset to the
    /// entry's value representation and, after it, the next entry. Offsets must point
    /// forward (as Pixar's writer makes them), so the entries cannot loop.
    fn dictionary(&mut self, at: &mut At, depth: u32) -> Result<Cost, Refusal> {
        let count = at.u64("a dictionary's count")?;
        let mut cost = Cost::default();
        for _ in 0..count {
            self.count_work(1)?;
            let key = name_length(self.file, Names::Strings, at.u32("a dictionary key")?)?;
            jump(at)?;
            let rep = Rep(at.u64("a dictionary value")?);
            cost.add(Cost::bytes(key + MAP_ENTRY));
            cost = cost.nested(self.value(rep, depth + 1)?);
        }
        Ok(cost)
    }

    /// Time samples: an offset to the times (a double array), then an offset to a count
    /// equal to the times' and as many value representations.
    fn time_samples(&mut self, rep: Rep, depth: u32) -> Result<Cost, Refusal> {
        let mut at = self.at(rep.payload(), "time samples")?;
        jump(&mut at)?;
        let times = Rep(at.u64("the sample times")?);
        let double_array = times.ty() == ty::DOUBLE && times.array();
        if !(times.ty() == ty::DOUBLE_VECTOR || double_array) {
            return Ok(Cost::default());
        }
        let mut cost = self.value(times, depth + 1)?;
        let time_count = match self.array_head(times, None)? {
            Some((count, _, _)) => count,
            None => 0,
        };
        jump(&mut at)?;
        let count = at.u64("the sample count")?;
        if count != time_count {
            return Ok(cost);
        }
        at.fits(count, 8, "time samples")?;
        self.count_work(count)?;
        let per_sample = 8 + size_of::<sdf::Value>() + size_of::<(f64, sdf::Value)>();
        cost.add(Cost::bytes(count * per_sample as u64));
        for _ in 0..count {
            let sample = Rep(at.u64("a sample")?);
            cost = cost.nested(self.value(sample, depth + 1)?);
        }
        Ok(cost)
    }
}

/// Follows a recursive offset as openusd does (relative to the offset's own position),
/// refusing one that does not point forward past itself.
fn jump(at: &mut At) -> Result<(), Refusal> {
    let from = at.pos;
    let offset = at.i64("an offset")?;
    let to = u64::try_from(offset)
        .ok()
        .filter(|&o| o >= 8)
        .and_then(|o| o.checked_add(from as u64))
        .filter(|&to| to <= at.end as u64)
        .ok_or_else(|| {
            format!("the offset {offset} at offset {from} does not point forward into the file")
        })?;
    at.pos = to as usize;
    Ok(())
}

/// The length of the token, string or path an index names, refusing one out of range.
fn name_length(file: &Crate, names: Names, index: u32) -> Result<u64, Refusal> {
    let i = index as usize;
    let (found, of) = match names {
        Names::Tokens => (file.tokens.get(i).copied(), file.tokens.len()),
        Names::Strings => (
            file.strings
                .get(i)
                .and_then(|&t| file.tokens.get(t as usize).copied()),
            file.strings.len(),
        ),
        Names::Paths => (file.paths.get(i).copied(), file.paths.len()),
    };
    found.ok_or_else(|| format!("an index names {index} of {of} entries"))
}
