//! Cem Yuksel's `.hair` format (<http://www.cemyuksel.com/research/hairmodels/>): a reader
//! that trusts nothing in the file and a writer whose output reads back bit for bit.
//!
//! Layout, all little-endian: a 128-byte header (`"HAIR"`, u32 strand count, u32 point
//! count, u32 array flags, u32 default segments, f32 default thickness, f32 default
//! transparency, f32x3 default colour, 88 bytes of text), then the arrays whose flag is set,
//! in this order: segments (u16 per strand, points - 1), points (f32x3), thickness (f32 per
//! point), transparency (f32 per point), colour (f32x3 per point).
//!
//! Choices this module makes, since the format leaves them open:
//! - Thickness is a **diameter** by default ([`Thickness::Diameter`]): the format's own
//!   tools and most exporters write it that way. [`Thickness::Radius`] reads it as is.
//! - Transparency is read past and ignored: the hair BSDF has no use for it.
//! - Without a colour array the strands have no colours (`colors: None`, so the material
//!   decides); the header's default colour is not spread over every point.
//! - Bytes after the last array are an error that says how many there are: they mean the
//!   header and the arrays disagree, and guessing which one is right would hide it.
//! - Flag bits the format does not define are an error: an unknown array may follow.
//! - The format says nothing of the curve its points draw, nor of units. A file that
//!   `hairtrace convert` writes says both in the header's text ([`HairTag`]); any other
//!   file's text is not read, and its reader must be given a basis.

use super::units::{StageUnits, UpAxis};
use super::usd::Layout;
use crate::error::{Error, Result, invalid_arg};
use crate::scene::strands::Strands;
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;

/// Size of the fixed header.
pub const HEADER_BYTES: usize = 128;
const MAGIC: &[u8; 4] = b"HAIR";
const HAS_SEGMENTS: u32 = 1 << 0;
const HAS_POINTS: u32 = 1 << 1;
const HAS_THICKNESS: u32 = 1 << 2;
const HAS_TRANSPARENCY: u32 = 1 << 3;
const HAS_COLORS: u32 = 1 << 4;
const KNOWN_FLAGS: u32 = HAS_SEGMENTS | HAS_POINTS | HAS_THICKNESS | HAS_TRANSPARENCY | HAS_COLORS;
/// The segments array holds u16, so a strand has at most this many points.
pub(crate) const MAX_POINTS_PER_STRAND: u32 = u16::MAX as u32 + 1;

/// How the file's thickness values are read and written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Thickness {
    /// Thickness is the fibre's diameter: radius = thickness / 2 (the default, as the
    /// format's own tools and most exporters use it).
    #[default]
    Diameter,
    /// Thickness is the fibre's radius.
    Radius,
}

impl Thickness {
    fn radius_of(self, t: f32) -> f32 {
        match self {
            Thickness::Diameter => t * 0.5,
            Thickness::Radius => t,
        }
    }

    /// The radius of a file's thickness `t`, if it is a usable one.
    fn checked_radius(self, t: f32) -> Option<f32> {
        let radius = self.radius_of(t);
        (t.is_finite() && radius > 0.0).then_some(radius)
    }

    fn error(self, t: f32, what: &str) -> Error {
        let halved = match self {
            Thickness::Diameter => " (a diameter: its half must be > 0 too)",
            Thickness::Radius => "",
        };
        invalid_arg!("{what} = {t:?}: must be finite and > 0{halved}")
    }

    fn thickness_of(self, r: f32) -> f32 {
        match self {
            Thickness::Diameter => r * 2.0,
            Thickness::Radius => r,
        }
    }
}

/// What the header's text of a `.hair` file that `hairtrace convert` wrote says of its
/// points: the USD layout of the curves they are the authored points of, and the units they
/// are in. With it a groom goes from USD to `.hair` and back as it was, and a renderer
/// reading the file needs no basis from its user.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HairTag {
    pub layout: Layout,
    pub units: StageUnits,
}

/// How a tag's text starts; text that does not is another tool's, and not read.
const TAG_PREFIX: &str = "hairtrace curves:";

impl HairTag {
    /// `hairtrace curves: TYPE BASIS WRAP UPAXIS METERSPERUNIT`, in USD's spelling.
    fn text(&self) -> String {
        let (kind, basis, wrap) = self.layout.tokens();
        let units = self.units;
        format!(
            "{TAG_PREFIX} {kind} {basis} {wrap} {} {}",
            units.up_axis.name(),
            units.meters_per_unit
        )
    }

    /// The tag in a header's text, if the text is one.
    fn parse(info: &[u8]) -> Result<Option<HairTag>> {
        let end = info.iter().position(|&b| b == 0).unwrap_or(info.len());
        let Some(rest) = std::str::from_utf8(&info[..end])
            .ok()
            .and_then(|t| t.strip_prefix(TAG_PREFIX))
        else {
            return Ok(None);
        };
        let bad = |why: String| invalid_arg!("the header's text {rest:?} is not a tag: {why}");
        let words: Vec<&str> = rest.split_whitespace().collect();
        let [kind, basis, wrap, up, mpu] = words[..] else {
            return Err(bad("type, basis, wrap, up axis and unit expected".into()));
        };
        let mpu: f64 = mpu.parse().map_err(|e| bad(format!("{mpu:?}: {e}")))?;
        let layout = Layout::named(kind, basis, wrap).map_err(|e| bad(e.to_string()))?;
        let units = UpAxis::named(up)
            .and_then(|up| StageUnits::new(up, mpu))
            .map_err(|e| bad(e.to_string()))?;
        Ok(Some(HairTag { layout, units }))
    }
}

/// Reads a `.hair` file; see [`parse_hair`] for what is checked. Errors name the path.
pub fn read_hair_file(path: &Path, thickness: Thickness) -> Result<Strands> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_hair(&bytes, thickness).map_err(|e| e.context(path.display()))
}

/// The tag in a `.hair` file's header ([`HairTag`]), reading the header alone; None for a
/// file another tool wrote, or one too short to hold a header ([`read_hair_file`] says
/// what is wrong with it).
pub fn read_hair_tag(path: &Path) -> Result<Option<HairTag>> {
    let mut header = Vec::with_capacity(HEADER_BYTES);
    std::fs::File::open(path)
        .and_then(|f| f.take(HEADER_BYTES as u64).read_to_end(&mut header))
        .map_err(|e| Error::io(path, e))?;
    parse_hair_tag(&header).map_err(|e| e.context(path.display()))
}

/// The tag in the header of `.hair` bytes, if they have a header and it holds one.
pub fn parse_hair_tag(bytes: &[u8]) -> Result<Option<HairTag>> {
    match bytes.get(..HEADER_BYTES) {
        Some(header) if header.starts_with(MAGIC) => HairTag::parse(&header[40..]),
        _ => Ok(None),
    }
}

/// Writes `strands` as a `.hair` file (see [`encode_hair`]). Errors name the path.
pub fn write_hair_file(path: &Path, strands: &Strands, thickness: Thickness) -> Result<()> {
    write_tagged_hair_file(path, strands, thickness, None)
}

/// Writes `strands` as a `.hair` file whose header says `tag`. Errors name the path.
pub fn write_tagged_hair_file(
    path: &Path,
    strands: &Strands,
    thickness: Thickness,
    tag: Option<&HairTag>,
) -> Result<()> {
    let bytes = encode_tagged_hair(strands, thickness, tag)?;
    std::fs::write(path, bytes).map_err(|e| Error::io(path, e))
}

/// Little-endian cursor over a slice whose length was checked before reading.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    /// Splits off the next `n` bytes; callers checked the total size first, so a short
    /// slice here is a bug in that check and still reported as an error, not a panic.
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if n > self.bytes.len() {
            return Err(invalid_arg!(
                "file ends {} bytes early",
                n - self.bytes.len()
            ));
        }
        let (head, tail) = self.bytes.split_at(n);
        self.bytes = tail;
        Ok(head)
    }

    fn u32(&mut self) -> Result<u32> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn f32(&mut self) -> Result<f32> {
        Ok(f32::from_bits(self.u32()?))
    }
}

fn f32s(bytes: &[u8]) -> impl Iterator<Item = f32> + '_ {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

fn vec3s(bytes: &[u8]) -> impl Iterator<Item = [f32; 3]> + '_ {
    bytes.chunks_exact(12).map(|b| {
        let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        [f(0), f(4), f(8)]
    })
}

/// The strand and point index of point `i`, for error messages (only computed on error).
fn locate(counts: &[u32], i: usize) -> String {
    let mut start = 0usize;
    for (s, &c) in counts.iter().enumerate() {
        if i < start + c as usize {
            return format!("point {i} (strand {s}, point {} of it)", i - start);
        }
        start += c as usize;
    }
    format!("point {i}")
}

/// Parses the bytes of a `.hair` file.
///
/// Everything is checked before it is used: the header's size and magic, that a points
/// array is present, that the arrays the counts promise fit the file exactly (u64 math, so
/// a count like 0xFFFFFFFF is an error and never an allocation), that segments add up to
/// the point count, that every strand has at least 2 points, and that points, thickness and
/// colours are finite (thickness > 0, colours >= 0). Nothing is allocated beyond a small
/// multiple of the file's size.
pub fn parse_hair(bytes: &[u8], thickness: Thickness) -> Result<Strands> {
    if bytes.len() < HEADER_BYTES {
        return Err(invalid_arg!(
            "file is {} bytes, shorter than the {HEADER_BYTES}-byte .hair header",
            bytes.len()
        ));
    }
    let mut r = Reader { bytes };
    let magic = r.take(4)?;
    if magic != MAGIC {
        return Err(invalid_arg!(
            "wrong magic {:?}: a .hair file starts with \"HAIR\"",
            String::from_utf8_lossy(magic)
        ));
    }
    let strand_count = r.u32()?;
    let point_count = r.u32()?;
    let flags = r.u32()?;
    let default_segments = r.u32()?;
    let default_thickness = r.f32()?;
    let _default_transparency = r.f32()?;
    // Default colour and information text: unused (see the module notes).
    r.take(HEADER_BYTES - 28)?;

    if flags & !KNOWN_FLAGS != 0 {
        return Err(invalid_arg!(
            "unknown array flags {:#x} (known: {KNOWN_FLAGS:#x})",
            flags & !KNOWN_FLAGS
        ));
    }
    if flags & HAS_POINTS == 0 {
        return Err(invalid_arg!(
            "points array missing (flag bit 1 unset): a .hair file without points holds no hair"
        ));
    }

    // Sizes in u64: they cannot overflow there (at most 2^32 * 12), and they are compared
    // with the file before anything is allocated.
    let (strands, points) = (u64::from(strand_count), u64::from(point_count));
    let has = |bit: u32| u64::from(flags & bit != 0);
    let segments_bytes = has(HAS_SEGMENTS) * strands * 2;
    let point_bytes = points * 12;
    let thickness_bytes = has(HAS_THICKNESS) * points * 4;
    let transparency_bytes = has(HAS_TRANSPARENCY) * points * 4;
    let color_bytes = has(HAS_COLORS) * points * 12;
    let needed = segments_bytes + point_bytes + thickness_bytes + transparency_bytes + color_bytes;
    let available = (bytes.len() - HEADER_BYTES) as u64;
    if needed > available {
        return Err(invalid_arg!(
            "file too short (truncated, or counts too large): the header's {strand_count} \
             strands and {point_count} points need {needed} bytes of arrays (segments \
             {segments_bytes}, points {point_bytes}, thickness {thickness_bytes}, transparency \
             {transparency_bytes}, colours {color_bytes}) but only {available} bytes follow \
             the header"
        ));
    }
    if needed < available {
        return Err(invalid_arg!(
            "{} bytes of trailing data after the last array (the header's {strand_count} \
             strands and {point_count} points need {needed} bytes of arrays)",
            available - needed
        ));
    }
    // Every size now fits in the file, hence in usize.
    let n_points = point_count as usize;

    let counts: Vec<u32> = if flags & HAS_SEGMENTS != 0 {
        let seg = r.take(segments_bytes as usize)?;
        let mut counts = Vec::with_capacity(strand_count as usize);
        let mut total = 0u64;
        for (s, b) in seg.chunks_exact(2).enumerate() {
            let segments = u16::from_le_bytes([b[0], b[1]]);
            if segments == 0 {
                return Err(invalid_arg!(
                    "strand {s} has 0 segments (1 point): a strand needs at least 2 points"
                ));
            }
            let c = u32::from(segments) + 1;
            total += u64::from(c);
            counts.push(c);
        }
        if total != points {
            return Err(invalid_arg!(
                "point count mismatch: the segments array adds up to {total} points but the \
                 header says {point_count}"
            ));
        }
        counts
    } else {
        if strand_count > 0 && default_segments == 0 {
            return Err(invalid_arg!(
                "default segment count is 0 and there is no segments array: every strand \
                 would have 1 point (at least 2 are needed)"
            ));
        }
        let per_strand = u64::from(default_segments) + 1;
        if strands.checked_mul(per_strand) != Some(points) {
            return Err(invalid_arg!(
                "point count mismatch: {strand_count} strands of {default_segments} default \
                 segments need {} points but the header says {point_count}",
                strands as u128 * per_strand as u128
            ));
        }
        // per_strand <= points <= u32::MAX here unless there are no strands.
        vec![per_strand as u32; strand_count as usize]
    };

    let point_data = r.take(point_bytes as usize)?;
    let mut pts = Vec::with_capacity(n_points);
    for p in vec3s(point_data) {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(invalid_arg!(
                "{} = {p:?} is not finite",
                locate(&counts, pts.len())
            ));
        }
        pts.push(p);
    }

    let radii = if flags & HAS_THICKNESS != 0 {
        let data = r.take(thickness_bytes as usize)?;
        let mut radii = Vec::with_capacity(n_points);
        for t in f32s(data) {
            let what = || format!("thickness of {}", locate(&counts, radii.len()));
            radii.push(
                thickness
                    .checked_radius(t)
                    .ok_or_else(|| thickness.error(t, &what()))?,
            );
        }
        radii
    } else {
        let t = default_thickness;
        let radius = thickness
            .checked_radius(t)
            .ok_or_else(|| thickness.error(t, "the header's default thickness"))?;
        vec![radius; n_points]
    };

    r.take(transparency_bytes as usize)?;

    let colors = if flags & HAS_COLORS != 0 {
        let data = r.take(color_bytes as usize)?;
        let mut colors = Vec::with_capacity(n_points);
        for c in vec3s(data) {
            if !c.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return Err(invalid_arg!(
                    "colour {c:?} of {} must be finite and >= 0",
                    locate(&counts, colors.len())
                ));
            }
            colors.push(c);
        }
        Some(colors)
    } else {
        None
    };

    let strands = Strands {
        points: pts,
        radii,
        counts,
        colors,
    };
    // Everything above already holds; this keeps the reader and the type's own rules in
    // step if either changes.
    strands.validate()?;
    Ok(strands)
}

/// Encodes strands as `.hair` bytes after validating them.
///
/// Writes the points array always, a segments array unless every strand has the same
/// number of points (then the header's default says it), a thickness array unless every
/// radius is the same (then the header's default thickness says it), and a colour array
/// when the strands have colours. A strand of more than 65536 points cannot be encoded
/// (segments are u16), nor can more than 2^32 - 1 strands or points, nor a radius whose
/// diameter overflows f32. The header's text names hairtrace.
pub fn encode_hair(strands: &Strands, thickness: Thickness) -> Result<Vec<u8>> {
    encode_tagged_hair(strands, thickness, None)
}

/// [`encode_hair`], with `tag` as the header's text when given.
pub fn encode_tagged_hair(
    strands: &Strands,
    thickness: Thickness,
    tag: Option<&HairTag>,
) -> Result<Vec<u8>> {
    strands.validate()?;
    if let Some(s) = strands
        .counts
        .iter()
        .position(|&c| c > MAX_POINTS_PER_STRAND)
    {
        return Err(invalid_arg!(
            "strand {s} has {} points: a .hair file holds at most {MAX_POINTS_PER_STRAND} \
             points per strand",
            strands.counts[s]
        ));
    }
    let strand_count = u32::try_from(strands.counts.len()).map_err(|_| {
        invalid_arg!(
            "{} strands: a .hair file holds at most {}",
            strands.counts.len(),
            u32::MAX
        )
    })?;
    let point_count = u32::try_from(strands.points.len()).map_err(|_| {
        invalid_arg!(
            "{} points: a .hair file holds at most {}",
            strands.points.len(),
            u32::MAX
        )
    })?;
    let thick: Vec<f32> = strands
        .radii
        .iter()
        .map(|&r| thickness.thickness_of(r))
        .collect();
    if let Some(i) = thick.iter().position(|t| !t.is_finite()) {
        return Err(invalid_arg!(
            "radius {i} = {} is too large: its diameter is not a finite f32",
            strands.radii[i]
        ));
    }

    let uniform_counts = strands.counts.windows(2).all(|w| w[0] == w[1]);
    let uniform_thickness = thick.windows(2).all(|w| w[0].to_bits() == w[1].to_bits());
    let mut flags = HAS_POINTS;
    if !uniform_counts {
        flags |= HAS_SEGMENTS;
    }
    if !uniform_thickness {
        flags |= HAS_THICKNESS;
    }
    if strands.colors.is_some() {
        flags |= HAS_COLORS;
    }
    let default_segments = strands.counts.first().map_or(1, |&c| c - 1);
    let default_thickness = thick.first().copied().unwrap_or(1.0);
    let default_color = strands
        .colors
        .as_ref()
        .and_then(|c| c.first().copied())
        .unwrap_or([1.0; 3]);

    let mut out = Vec::with_capacity(
        HEADER_BYTES + 2 * strands.counts.len() + (12 + 4 + 12) * strands.points.len(),
    );
    out.extend_from_slice(MAGIC);
    for v in [strand_count, point_count, flags, default_segments] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [default_thickness, 0.0].into_iter().chain(default_color) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let mut info = [0u8; HEADER_BYTES - 40];
    let text = match tag {
        Some(tag) => tag.text(),
        None => concat!("hairtrace ", env!("CARGO_PKG_VERSION")).to_string(),
    };
    // The longest tag (a unit of 1e-9 written out in full) fits with room to spare.
    info.get_mut(..text.len())
        .ok_or_else(|| invalid_arg!("the header's text {text:?} is longer than its 88 bytes"))?
        .copy_from_slice(text.as_bytes());
    out.extend_from_slice(&info);

    if flags & HAS_SEGMENTS != 0 {
        for &c in &strands.counts {
            // c - 1 <= u16::MAX was checked above.
            out.extend_from_slice(&((c - 1) as u16).to_le_bytes());
        }
    }
    for v in strands.points.iter().flatten() {
        out.extend_from_slice(&v.to_le_bytes());
    }
    if flags & HAS_THICKNESS != 0 {
        for t in &thick {
            out.extend_from_slice(&t.to_le_bytes());
        }
    }
    if let Some(colors) = &strands.colors {
        for v in colors.iter().flatten() {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(out)
}

/// A human-readable summary of a groom, as `hairtrace info` prints it: strand, point and
/// segment counts, points per strand, bounds, radius range and whether colours are present.
pub fn info_report(strands: &Strands) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "strands:  {}", strands.strand_count());
    let _ = writeln!(s, "points:   {}", strands.point_count());
    let _ = writeln!(s, "segments: {}", strands.segment_count());
    match (strands.counts.iter().min(), strands.counts.iter().max()) {
        (Some(lo), Some(hi)) => {
            let mean = strands.point_count() as f64 / strands.strand_count() as f64;
            let _ = writeln!(s, "points per strand: min {lo}, max {hi}, mean {mean:.2}");
        }
        _ => {
            let _ = writeln!(s, "points per strand: none");
        }
    }
    match strands.bounds() {
        Some((lo, hi)) => {
            let _ = writeln!(
                s,
                "bounds:   min ({}, {}, {}), max ({}, {}, {})",
                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
            );
        }
        None => {
            let _ = writeln!(s, "bounds:   none");
        }
    }
    if strands.radii.is_empty() {
        let _ = writeln!(s, "radius:   none");
    } else {
        let (lo, hi, sum) = strands.radii.iter().fold(
            (f32::INFINITY, f32::NEG_INFINITY, 0.0f64),
            |(lo, hi, sum), &r| (lo.min(r), hi.max(r), sum + f64::from(r)),
        );
        let mean = sum / strands.radii.len() as f64;
        let _ = writeln!(s, "radius:   min {lo}, max {hi}, mean {mean:.6}");
    }
    let _ = writeln!(
        s,
        "colours:  {}",
        if strands.colors.is_some() {
            "yes"
        } else {
            "no"
        }
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thickness_conversions_are_inverse() {
        for t in [Thickness::Diameter, Thickness::Radius] {
            for r in [1e-30f32, 0.004, 1.0, 3.3e37] {
                assert_eq!(t.radius_of(t.thickness_of(r)).to_bits(), r.to_bits());
            }
        }
    }

    /// Every layout and units a tag can say come back from its text, and text that is not a
    /// tag is not read as one.
    #[test]
    fn tags_read_back_and_other_text_is_ignored() {
        use crate::embree::CurveBasis;
        use crate::formats::usd::Wrap;
        for basis in CurveBasis::ALL {
            for wrap in [Wrap::Nonperiodic, Wrap::Pinned, Wrap::Periodic] {
                for (up, mpu) in [
                    (UpAxis::Y, 1.0),
                    (UpAxis::Z, 0.01),
                    (UpAxis::Z, 1.234_567_890_123_456_7e-9),
                ] {
                    let tag = HairTag {
                        layout: Layout { basis, wrap },
                        units: StageUnits::new(up, mpu).unwrap(),
                    };
                    let strands = Strands {
                        points: vec![[0.0; 3], [1.0; 3]],
                        radii: vec![0.5; 2],
                        counts: vec![2],
                        colors: None,
                    };
                    let bytes =
                        encode_tagged_hair(&strands, Thickness::Diameter, Some(&tag)).unwrap();
                    assert_eq!(parse_hair_tag(&bytes).unwrap(), Some(tag));
                    assert_eq!(parse_hair(&bytes, Thickness::Diameter).unwrap(), strands);
                }
            }
        }
        assert_eq!(HairTag::parse(b"hairtrace 0.1.0\0\0").unwrap(), None);
        assert_eq!(HairTag::parse(b"exported by a DCC").unwrap(), None);
        let e = HairTag::parse(b"hairtrace curves: cubic spiral pinned Y 1").unwrap_err();
        assert!(e.to_string().contains("spiral"), "{e}");
        let e = HairTag::parse(b"hairtrace curves: cubic bspline pinned Y -1").unwrap_err();
        assert!(e.to_string().contains("metersPerUnit"), "{e}");
    }

    #[test]
    fn locate_names_strand_and_point() {
        assert_eq!(locate(&[2, 3], 3), "point 3 (strand 1, point 1 of it)");
        assert_eq!(locate(&[2], 7), "point 7");
    }
}
