//! Image files through OpenImageIO: the film goes out as EXR (linear) or as PNG, JPEG or
//! TIFF (sRGB-encoded), and environment maps or reference images come back in.
//!
//! OIIO is C++, so `oiio_shim.cpp` wraps the few calls needed in `extern "C"` functions
//! that catch every exception; that shim is a library of its own, opened at the first image
//! read or write (`shim.rs`). Colour handling stays here, in Rust, where it is tested:
//! OIIO only converts between float and the stored pixel type.

use std::ffi::{CStr, CString, c_char, c_int, c_void};

use shim::{Shim, shim};
use std::path::Path;

use crate::error::invalid_arg;
use crate::{Error, Result};

mod blocks;
mod compare;
mod shim;
pub use blocks::{BlockBias, block_bias};
pub use compare::{Comparison, compare};
pub use shim::preload_shim;

/// How samples are stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelType {
    /// 32-bit float (EXR), linear.
    F32,
    /// 16-bit half float (EXR), linear: about 3 significant digits, range up to 65504.
    F16,
    /// 8-bit unsigned integer (PNG, JPEG, TIFF), sRGB-encoded.
    U8,
    /// 16-bit unsigned integer (PNG, TIFF), sRGB-encoded.
    U16,
}

impl PixelType {
    /// The code `oiio_shim.cpp` expects (`ShimPixelType`).
    fn code(self) -> c_int {
        match self {
            PixelType::F32 => 0,
            PixelType::F16 => 1,
            PixelType::U8 => 2,
            PixelType::U16 => 3,
        }
    }

    fn is_integer(self) -> bool {
        matches!(self, PixelType::U8 | PixelType::U16)
    }
}

/// Options for [`write_image`]. The file format always comes from the path's extension.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// `None` picks the format's natural type: F32 for EXR, U8 for PNG, JPEG and TIFF.
    pub pixel_type: Option<PixelType>,
    /// Where the pixels lie in a larger frame (a crop), for EXR, which stores it; other
    /// formats store the pixels alone. `None`: they are the whole frame.
    pub placement: Option<Placement>,
    /// String attributes for the header, as (name, value): what rendered the image, for
    /// whoever reads it later (formats without such a header drop them).
    pub attributes: Vec<(String, String)>,
}

/// Where an image's pixels lie in a larger frame: a `width` x `height` window at (`x`, `y`)
/// of a `full_width` x `full_height` frame, which EXR stores as its data window inside its
/// display window (so OIIO, Nuke and others place a crop where it belongs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Placement {
    pub x: usize,
    pub y: usize,
    pub full_width: usize,
    pub full_height: usize,
}

/// An image read back as interleaved linear floats, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    /// `width * height * channels` values; channel `c` of pixel `(x, y)` is at
    /// `(y * width + x) * channels + c`.
    pub pixels: Vec<f32>,
    /// Where the pixels lie in the file's full frame (at (0, 0) of a frame their size,
    /// unless the file says otherwise).
    pub placement: Placement,
    /// The header's string attributes, as (name, value).
    pub attributes: Vec<(String, String)>,
}

impl Placement {
    /// A `width` x `height` image that is its whole frame.
    pub fn whole(width: usize, height: usize) -> Placement {
        Placement {
            x: 0,
            y: 0,
            full_width: width,
            full_height: height,
        }
    }
}

impl Image {
    /// Pixels that are a whole frame, with no attributes.
    pub fn new(width: usize, height: usize, channels: usize, pixels: Vec<f32>) -> Image {
        Image {
            width,
            height,
            channels,
            pixels,
            placement: Placement::whole(width, height),
            attributes: Vec::new(),
        }
    }

    /// The value of the header attribute `name`.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// The formats `write_image` knows, each with the pixel types it can store.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Exr,
    Png,
    Jpeg,
    Tiff,
}

const SUPPORTED_EXTENSIONS: &str = ".exr, .png, .jpg, .jpeg, .tif, .tiff";

impl Format {
    fn from_path(path: &Path) -> Result<Format> {
        let Some(ext) = path.extension() else {
            return Err(Error::Image(format!(
                "{} has no file extension to pick the image format from; supported: \
                 {SUPPORTED_EXTENSIONS}",
                path.display()
            )));
        };
        match ext.to_string_lossy().to_ascii_lowercase().as_str() {
            "exr" => Ok(Format::Exr),
            "png" => Ok(Format::Png),
            "jpg" | "jpeg" => Ok(Format::Jpeg),
            "tif" | "tiff" => Ok(Format::Tiff),
            _ => Err(Error::Image(format!(
                "unsupported image extension \".{}\" in {}; supported: {SUPPORTED_EXTENSIONS}",
                ext.to_string_lossy(),
                path.display()
            ))),
        }
    }

    /// Allowed pixel types, the first being the default.
    fn pixel_types(self) -> &'static [PixelType] {
        match self {
            Format::Exr => &[PixelType::F32, PixelType::F16],
            Format::Png | Format::Tiff => &[PixelType::U8, PixelType::U16],
            Format::Jpeg => &[PixelType::U8],
        }
    }
}

/// Checks, before any work, that `write_image` can take `path`: a supported extension and
/// an existing folder to write into (permissions are only known when writing).
pub fn check_output_path(path: &Path) -> Result<()> {
    Format::from_path(path)?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        return Err(Error::Io(format!(
            "cannot write {}: folder {} does not exist",
            path.display(),
            folder.display()
        )));
    }
    Ok(())
}

/// Writes interleaved linear pixels (`channels` values per pixel, rows from the top) to
/// `path`, in the format its extension names.
///
/// The file is written under a temporary name of its own in the same folder (a hidden
/// `.NAME.XXXXXX.part`) and renamed to `path` only once complete: a process killed while
/// writing leaves no file at `path` that could pass for a good one, and two processes
/// writing the same `path` at once leave one whole image, never a mix.
///
/// Channels are grey, grey + alpha, RGB or RGBA. Alpha, when present, is premultiplied
/// (associated), as in EXR and in a renderer's film.
///
/// EXR stores the values as they are (float or half). PNG, JPEG and TIFF store 8- or
/// 16-bit sRGB with straight alpha, as those formats expect: colour is divided by alpha
/// (where alpha > 0), clamped to [0, 1] and sRGB-encoded here; alpha is clamped but stays
/// linear. JPEG has no alpha, so it takes 1 or 3 channels only. Any NaN or infinite value
/// is an error, so a broken render never becomes a plausible-looking file.
///
/// ```
/// use hairtrace::{read_image, write_image};
/// let path = std::env::temp_dir().join(format!("hairtrace-doc-{}.exr", std::process::id()));
/// let rgb = [0.5, 0.25, 1.0, 0.0, 2.0, 0.125]; // two pixels
/// write_image(&path, 2, 1, 3, &rgb, &Default::default())?;
/// assert_eq!(read_image(&path)?.pixels, rgb); // EXR keeps floats exactly
/// assert!(write_image(&path, 2, 1, 3, &[f32::NAN; 6], &Default::default()).is_err());
/// # std::fs::remove_file(&path).ok();
/// # Ok::<(), hairtrace::Error>(())
/// ```
pub fn write_image(
    path: &Path,
    width: usize,
    height: usize,
    channels: usize,
    pixels: &[f32],
    opts: &WriteOptions,
) -> Result<()> {
    let format = Format::from_path(path)?;
    let allowed = format.pixel_types();
    let pixel_type = opts.pixel_type.unwrap_or(allowed[0]);
    if !allowed.contains(&pixel_type) {
        return Err(Error::Image(format!(
            "{pixel_type:?} pixels cannot be stored in {}; {format:?} supports {allowed:?}",
            path.display()
        )));
    }
    check_size(width, height, channels, pixels.len())?;
    if format == Format::Jpeg && alpha_channel(channels).is_some() {
        return Err(Error::Image(format!(
            "JPEG has no alpha channel: {} needs 1 or 3 channels, got {channels}",
            path.display()
        )));
    }
    if let Some(i) = pixels.iter().position(|v| !v.is_finite()) {
        let (pixel, c) = (i / channels, i % channels);
        let what = if pixels[i].is_nan() {
            "NaN"
        } else {
            "infinite"
        };
        // A value the caller gave, like any other NaN argument: not an image failure.
        return Err(invalid_arg!(
            "pixel ({}, {}) channel {c} is {what}; refusing to write {}",
            pixel % width,
            pixel / width,
            path.display()
        ));
    }

    let encoded;
    let data = if pixel_type.is_integer() {
        encoded = encode_display(pixels, channels);
        &encoded[..]
    } else {
        pixels
    };

    let whole = Placement::whole(width, height);
    let placement = opts.placement.unwrap_or(whole);
    check_placement(&placement, width, height)?;
    let placement = if format == Format::Exr {
        placement
    } else {
        whole
    };
    let text = |t: &str| {
        CString::new(t).map_err(|_| invalid_arg!("image attribute {t:?} contains a NUL byte"))
    };
    let names = (opts.attributes.iter().map(|(n, _)| text(n))).collect::<Result<Vec<_>>>()?;
    let values = (opts.attributes.iter().map(|(_, v)| text(v))).collect::<Result<Vec<_>>>()?;
    let name_ptrs: Vec<*const c_char> = names.iter().map(|n| n.as_ptr()).collect();
    let value_ptrs: Vec<*const c_char> = values.iter().map(|v| v.as_ptr()).collect();

    let c_final = c_path(path)?;
    let cannot = |why: String| Error::Image(format!("cannot write {}: {why}", path.display()));
    let shim = shim()?;
    let temporary = temporary_beside(path).map_err(|e| cannot(e.to_string()))?;
    let c_temporary = c_path(temporary.path())?;
    let mut err = [0 as c_char; ERR_LEN];
    // SAFETY: `data` holds width*height*channels floats (checked above), the sizes and the
    // placement fit in c_int (checked in `check_size` and `check_placement`), the two
    // attribute arrays hold `names.len()` live C strings each, and `err` is a writable
    // buffer of ERR_LEN.
    let status = unsafe {
        (shim.write)(
            c_final.as_ptr(),
            c_temporary.as_ptr(),
            width as c_int,
            height as c_int,
            channels as c_int,
            data.as_ptr(),
            pixel_type.code(),
            c_int::from(pixel_type.is_integer()),
            placement.x as c_int,
            placement.y as c_int,
            placement.full_width as c_int,
            placement.full_height as c_int,
            name_ptrs.as_ptr(),
            value_ptrs.as_ptr(),
            name_ptrs.len(),
            err.as_mut_ptr(),
            ERR_LEN,
        )
    };
    if status != 0 {
        // Dropping `temporary` removes the incomplete file.
        return Err(cannot(message(&err)));
    }
    temporary
        .persist(path)
        .map_err(|e| cannot(e.error.to_string()))?;
    Ok(())
}

/// An empty file of a unique name in `path`'s folder (so that the rename is atomic),
/// hidden from `*` globs, readable as a file created with `File::create` would be. It is
/// removed when dropped unless persisted to `path`: what every file a long job writes
/// goes through, so that a reader never sees half of one.
pub fn temporary_beside(path: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{name}.");
    builder.prefix(&prefix).suffix(".part");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // tempfile's default is 0600; the umask applies to this as to any new file.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(folder)
}

fn check_placement(p: &Placement, width: usize, height: usize) -> Result<()> {
    let fits = |v: usize| c_int::try_from(v).is_ok();
    let inside = p.x.checked_add(width).is_some_and(|r| r <= p.full_width)
        && p.y.checked_add(height).is_some_and(|b| b <= p.full_height);
    if inside && fits(p.full_width) && fits(p.full_height) {
        Ok(())
    } else {
        Err(invalid_arg!(
            "a {width}x{height} image at ({}, {}) does not fit in its {}x{} frame",
            p.x,
            p.y,
            p.full_width,
            p.full_height
        ))
    }
}

/// Reads the first subimage of `path` as linear floats with premultiplied alpha, the
/// convention [`write_image`] takes, so `read_image(write_image(x)) ≈ x` up to
/// quantisation.
///
/// Files stored as integers (8- or 16-bit PNG, JPEG, TIFF) are taken to be sRGB-encoded,
/// as `write_image` writes them, and are decoded to linear here; their straight alpha is
/// then multiplied in. Float files (EXR, float TIFF) come back exactly as stored.
pub fn read_image(path: &Path) -> Result<Image> {
    let c_path = c_path(path)?;
    let fail =
        |err: &[c_char]| Error::Image(format!("cannot read {}: {}", path.display(), message(err)));
    let shim = shim()?;

    let mut err = [0 as c_char; ERR_LEN];
    let mut handle: *mut c_void = std::ptr::null_mut();
    let (mut width, mut height, mut channels) = (0, 0, 0);
    let mut origin_and_full: [c_int; 4] = [0; 4];
    let (mut integer, mut alpha, mut unassociated) = (0, 0, 0);
    // SAFETY: every out-pointer refers to a live local (`origin_and_full` to 4 ints);
    // `err` holds ERR_LEN chars.
    let status = unsafe {
        (shim.open)(
            c_path.as_ptr(),
            &mut handle,
            &mut width,
            &mut height,
            &mut channels,
            origin_and_full.as_mut_ptr(),
            &mut integer,
            &mut alpha,
            &mut unassociated,
            err.as_mut_ptr(),
            ERR_LEN,
        )
    };
    if status != 0 {
        return Err(fail(&err));
    }
    let input = Input { shim, handle };

    let dims = [width, height, channels].map(|d| usize::try_from(d).unwrap_or(0));
    let [width, height, channels] = dims;
    let len = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels))
        .filter(|&n| n > 0)
        .ok_or_else(|| {
            Error::Image(format!(
                "{} reports an unusable size {width}x{height} with {channels} channels",
                path.display()
            ))
        })?;
    let mut pixels = Vec::new();
    pixels.try_reserve_exact(len).map_err(|_| {
        Error::Image(format!(
            "{} ({width}x{height}, {channels} channels) does not fit in memory",
            path.display()
        ))
    })?;
    pixels.resize(len, 0.0);
    // SAFETY: `input.handle` is open and `pixels` holds exactly `len` floats.
    let status = unsafe {
        (shim.read)(
            input.handle,
            pixels.as_mut_ptr(),
            len,
            err.as_mut_ptr(),
            ERR_LEN,
        )
    };
    if status != 0 {
        return Err(fail(&err));
    }
    if integer != 0 {
        let alpha = usize::try_from(alpha).ok().filter(|&a| a < channels);
        decode_display(&mut pixels, channels, alpha, unassociated != 0);
    }
    // A window that does not lie inside its frame (a negative origin, a PNG's offset
    // without a frame size) is read as a whole frame, as files were before windows.
    let [x, y, full_width, full_height] = origin_and_full.map(|v| usize::try_from(v).ok());
    let placement = match (x, y, full_width, full_height) {
        (Some(x), Some(y), Some(full_width), Some(full_height))
            if x + width <= full_width && y + height <= full_height =>
        {
            Placement {
                x,
                y,
                full_width,
                full_height,
            }
        }
        _ => Placement::whole(width, height),
    };
    Ok(Image {
        width,
        height,
        channels,
        pixels,
        placement,
        attributes: read_attributes(&input).map_err(|e| fail(&e))?,
    })
}

/// The string attributes of an open file's header.
fn read_attributes(input: &Input) -> std::result::Result<Vec<(String, String)>, Vec<c_char>> {
    let mut buf: Vec<u8> = Vec::new();
    loop {
        let mut err = vec![0 as c_char; ERR_LEN];
        let mut needed = 0;
        // SAFETY: `input.handle` is open, `buf` holds `buf.len()` writable bytes and `err`
        // ERR_LEN chars.
        let status = unsafe {
            (input.shim.attributes)(
                input.handle,
                buf.as_mut_ptr().cast(),
                buf.len(),
                &mut needed,
                err.as_mut_ptr(),
                ERR_LEN,
            )
        };
        if status != 0 {
            return Err(err);
        }
        if needed <= buf.len() {
            buf.truncate(needed);
            break;
        }
        buf.resize(needed, 0);
    }
    let mut texts = buf
        .split(|&b| b == 0)
        .map(|t| String::from_utf8_lossy(t).into_owned());
    let mut out = Vec::new();
    while let (Some(name), Some(value)) = (texts.next(), texts.next()) {
        out.push((name, value));
    }
    Ok(out)
}

/// Room for OIIO's error text; longer messages are truncated by the shim.
const ERR_LEN: usize = 1024;

/// An open OIIO reader, closed on every exit path.
struct Input {
    shim: &'static Shim,
    handle: *mut c_void,
}

impl Drop for Input {
    fn drop(&mut self) {
        // SAFETY: the handle came from a successful open and is closed only here.
        unsafe { (self.shim.close)(self.handle) }
    }
}

fn check_size(width: usize, height: usize, channels: usize, len: usize) -> Result<()> {
    if width == 0 || height == 0 || !(1..=4).contains(&channels) {
        return Err(invalid_arg!(
            "image size {width}x{height} with {channels} channels: width and height must be \
             nonzero and channels in 1..=4"
        ));
    }
    let fits = |v: usize| c_int::try_from(v).is_ok();
    let expected = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels))
        .filter(|_| fits(width) && fits(height));
    match expected {
        Some(n) if n == len => Ok(()),
        Some(n) => Err(invalid_arg!(
            "{width}x{height} pixels with {channels} channels need {n} values, got {len}"
        )),
        None => Err(invalid_arg!(
            "image size {width}x{height} with {channels} channels is too large"
        )),
    }
}

/// OIIO takes UTF-8 paths (it converts them to wide strings on Windows), so anything
/// else is refused here rather than mangled.
fn c_path(path: &Path) -> Result<CString> {
    let text = path.to_str().ok_or_else(|| {
        invalid_arg!(
            "image path {} is not valid UTF-8, which OpenImageIO requires",
            path.display()
        )
    })?;
    CString::new(text).map_err(|_| invalid_arg!("image path {text:?} contains a NUL byte"))
}

fn message(err: &[c_char]) -> String {
    let bytes: Vec<u8> = err.iter().map(|&c| c as u8).collect();
    match CStr::from_bytes_until_nul(&bytes) {
        Ok(text) if !text.is_empty() => text.to_string_lossy().into_owned(),
        _ => "no reason given".to_owned(),
    }
}

/// The alpha channel of a `channels`-channel image: the last of grey + alpha or RGBA.
fn alpha_channel(channels: usize) -> Option<usize> {
    matches!(channels, 2 | 4).then(|| channels - 1)
}

/// The sRGB transfer function of a linear value in [0, 1], as the 8-bit writers apply it
/// (public for hosts that compose their own 8-bit pictures, such as the CLI's report).
pub fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        // f64 so that 1.0 encodes to exactly 1.0.
        (1.055 * f64::from(v).powf(1.0 / 2.4) - 0.055) as f32
    }
}

fn srgb_decode(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((f64::from(v) + 0.055) / 1.055).powf(2.4) as f32
    }
}

/// Premultiplied linear to what display formats store: straight, clamped, sRGB-encoded
/// colour, and clamped linear alpha. Colour under zero alpha is kept as it is (it cannot
/// be un-premultiplied; it is light without coverage, such as an emitter's glow).
fn encode_display(pixels: &[f32], channels: usize) -> Vec<f32> {
    let alpha = alpha_channel(channels);
    let mut out = Vec::with_capacity(pixels.len());
    for pixel in pixels.chunks_exact(channels) {
        let a = alpha.map_or(1.0, |i| pixel[i].clamp(0.0, 1.0));
        out.extend(pixel.iter().enumerate().map(|(c, &v)| {
            if Some(c) == alpha {
                a
            } else {
                let straight = if a > 0.0 { v / a } else { v };
                srgb_encode(straight.clamp(0.0, 1.0))
            }
        }));
    }
    out
}

/// The inverse of [`encode_display`] for a file whose alpha is channel `alpha`;
/// `straight_alpha` says whether it still has to be multiplied in.
fn decode_display(pixels: &mut [f32], channels: usize, alpha: Option<usize>, straight_alpha: bool) {
    for pixel in pixels.chunks_exact_mut(channels) {
        let a = match alpha {
            Some(i) if straight_alpha => pixel[i],
            _ => 1.0,
        };
        for (c, v) in pixel.iter_mut().enumerate() {
            if Some(c) != alpha {
                *v = srgb_decode(*v) * a;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_and_hits_the_ends() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert_eq!(srgb_encode(1.0), 1.0);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-6);
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-6, "{v}");
        }
    }

    #[test]
    fn display_encoding_unpremultiplies_and_clamps() {
        // RGBA, premultiplied: colour 0.25 under alpha 0.5 is straight 0.5.
        let encoded = encode_display(&[0.25, -1.0, 2.0, 0.5], 4);
        assert_eq!(encoded, [srgb_encode(0.5), 0.0, 1.0, 0.5]);
        // Grey + alpha: zero alpha keeps the colour, alpha is clamped.
        assert_eq!(encode_display(&[0.5, -0.5], 2), [srgb_encode(0.5), 0.0]);
        // No alpha in grey or RGB.
        assert_eq!(encode_display(&[0.5], 1), [srgb_encode(0.5)]);
    }

    #[test]
    fn display_decoding_premultiplies_straight_alpha_only() {
        let stored = [srgb_encode(0.5), 0.0, 1.0, 0.5];
        let mut straight = stored;
        decode_display(&mut straight, 4, Some(3), true);
        assert_eq!(straight, [0.25, 0.0, 0.5, 0.5]);
        let mut associated = stored;
        decode_display(&mut associated, 4, Some(3), false);
        assert_eq!(associated, [0.5, 0.0, 1.0, 0.5]);
    }

    #[test]
    fn pixel_type_must_suit_the_format() {
        let opts = WriteOptions {
            pixel_type: Some(PixelType::F16),
            ..WriteOptions::default()
        };
        let err = write_image(Path::new("x.png"), 1, 1, 1, &[0.5], &opts).unwrap_err();
        assert!(matches!(err, Error::Image(m) if m.contains("F16")));
    }
}
