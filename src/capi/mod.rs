//! The C ABI: `extern "C"` functions over the same Rust API (the contract: docs/c-abi.md).
//!
//! Every entry point goes through `boundary`: NULL pointers and bad values become an
//! [`HtStatus`] with a message for `ht_last_error`, and a panic is caught here instead of
//! unwinding into the host. The header `include/hairtrace.h` is generated from this
//! module by cbindgen.

pub mod bsdf;
pub mod frame;
pub mod prepared;
// After `prepared`, whose point code it shares, so that the header declares Chiang's
// point first.
pub mod huang;
#[cfg(feature = "render")]
pub mod scene;
// Scenes first: the header declares them before the calls that fill them.
#[cfg(all(test, feature = "render"))]
mod edit_tests;
#[cfg(feature = "render")]
pub mod geometry;
#[cfg(all(test, feature = "render"))]
mod huang_tests;
#[cfg(feature = "render")]
pub mod lights;
#[cfg(feature = "render")]
pub mod materials;
// After `huang` and `materials`, which it joins.
#[cfg(feature = "render")]
pub mod huang_strand;
#[cfg(all(test, feature = "render"))]
mod scene_tests;
#[cfg(feature = "render")]
pub mod settings;
#[cfg(all(test, feature = "render"))]
mod settings_tests;
// After `scene` and `settings`, so that the header declares them before the render that
// takes them.
#[cfg(all(test, feature = "render"))]
mod motion_tests;
#[cfg(feature = "render")]
pub mod render;
#[cfg(all(test, feature = "render"))]
mod render_tests;
#[cfg(all(test, feature = "render"))]
mod same_scene_tests;
#[cfg(feature = "render")]
pub mod shutdown;
#[cfg(all(test, feature = "render"))]
mod soundness_tests;

pub use bsdf::HtHairParams;

use crate::Error;
use crate::error::invalid_arg;
use crate::quiet_panic::Quiet;
use glam::Vec3;
use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

/// Version of the C ABI; bumped on any incompatible change of a signature or struct. The
/// shared library's soname carries it: `libhairtrace.so.<HT_ABI_VERSION>`.
pub const HT_ABI_VERSION: u32 = 7;

/// The major part of the library version, which `ht_version()` returns as a string. The
/// three parts are Cargo's version: a compile-time check keeps them equal.
pub const HT_VERSION_MAJOR: u32 = 0;
/// The minor part of the library version.
pub const HT_VERSION_MINOR: u32 = 1;
/// The patch part of the library version.
pub const HT_VERSION_PATCH: u32 = 0;

/// cbindgen:ignore
const _: () = {
    /// A decimal number at compile time (Cargo's version fields are plain digits).
    const fn parse(s: &str) -> u32 {
        let (bytes, mut i, mut n) = (s.as_bytes(), 0, 0);
        while i < bytes.len() {
            n = n * 10 + (bytes[i] - b'0') as u32;
            i += 1;
        }
        n
    }
    assert!(
        HT_VERSION_MAJOR == parse(env!("CARGO_PKG_VERSION_MAJOR"))
            && HT_VERSION_MINOR == parse(env!("CARGO_PKG_VERSION_MINOR"))
            && HT_VERSION_PATCH == parse(env!("CARGO_PKG_VERSION_PATCH")),
        "HT_VERSION_MAJOR/MINOR/PATCH in src/capi/mod.rs differ from Cargo.toml's version"
    );
};

/// Largest magnitude of a coordinate the scene API accepts (positions, camera, lights, in
/// world units): Embree cannot trace rays past about 1.8e18, and aborts on them.
pub const HT_MAX_COORDINATE: f32 = 1e15;

/// cbindgen:ignore
const _: () = assert!(HT_MAX_COORDINATE == crate::validate::MAX_COORDINATE);

/// Result of every C entry point; `HT_OK` is 0.
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HtStatus {
    HT_OK = 0,
    /// A required pointer was NULL.
    HT_ERR_NULL_ARG = 1,
    /// A value was NaN, infinite or out of its range.
    HT_ERR_INVALID_ARG = 2,
    /// A Rust panic was caught at the boundary (a bug: please report it).
    HT_ERR_PANIC = 3,
    /// A file could not be read or written.
    HT_ERR_IO = 4,
    /// OpenImageIO failed.
    HT_ERR_IMAGE = 5,
    /// Embree failed.
    HT_ERR_EMBREE = 6,
    /// The progress callback returned false; the render stopped early.
    HT_ERR_CANCELLED = 7,
}

impl HtStatus {
    fn message(self) -> &'static CStr {
        match self {
            HtStatus::HT_OK => c"ok",
            HtStatus::HT_ERR_NULL_ARG => c"a required pointer is NULL",
            HtStatus::HT_ERR_INVALID_ARG => c"invalid argument",
            HtStatus::HT_ERR_PANIC => c"internal error (panic caught at the C boundary)",
            HtStatus::HT_ERR_IO => c"i/o error",
            HtStatus::HT_ERR_IMAGE => c"image error",
            HtStatus::HT_ERR_EMBREE => c"embree error",
            HtStatus::HT_ERR_CANCELLED => c"cancelled",
        }
    }

    const ALL: [HtStatus; 8] = [
        HtStatus::HT_OK,
        HtStatus::HT_ERR_NULL_ARG,
        HtStatus::HT_ERR_INVALID_ARG,
        HtStatus::HT_ERR_PANIC,
        HtStatus::HT_ERR_IO,
        HtStatus::HT_ERR_IMAGE,
        HtStatus::HT_ERR_EMBREE,
        HtStatus::HT_ERR_CANCELLED,
    ];
}

impl From<&Error> for HtStatus {
    fn from(e: &Error) -> Self {
        match e {
            Error::InvalidArg(_) => HtStatus::HT_ERR_INVALID_ARG,
            Error::Io(_) => HtStatus::HT_ERR_IO,
            Error::Image(_) => HtStatus::HT_ERR_IMAGE,
            #[cfg(feature = "render")]
            e if crate::embree::is_cancelled(e) => HtStatus::HT_ERR_CANCELLED,
            Error::Embree { .. } => HtStatus::HT_ERR_EMBREE,
        }
    }
}

/// A failure at the boundary: the status and its message.
pub(crate) struct Failure(HtStatus, String);

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        // The status names the kind: the message says what went wrong, once.
        Failure(HtStatus::from(&e), e.detail())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(msg: &str) {
    // Interior NULs would truncate the C string; replace them rather than lose the message.
    let c = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Runs the body of an entry point: its error becomes a status plus `ht_last_error`'s
/// message, and a panic becomes `HT_ERR_PANIC` instead of unwinding into C, printing
/// nothing to the host's stderr (`quiet_panic`).
pub(crate) fn boundary(body: impl FnOnce() -> Result<(), Failure>) -> HtStatus {
    let _quiet = Quiet::enter();
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => HtStatus::HT_OK,
        Ok(Err(Failure(status, msg))) => {
            set_last_error(&msg);
            status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_last_error(&format!("internal error: {what}"));
            HtStatus::HT_ERR_PANIC
        }
    }
}

/// A NULL check that names the argument in the message.
pub(crate) fn non_null<T>(ptr: *const T, name: &str) -> Result<*const T, Failure> {
    if ptr.is_null() {
        Err(Failure(
            HtStatus::HT_ERR_NULL_ARG,
            format!("{name} is NULL"),
        ))
    } else {
        Ok(ptr)
    }
}

/// A copy of the host's struct at `ptr`, which must not be NULL and must be aligned for
/// `T` (reading a misaligned one would be undefined behaviour).
pub(crate) fn read_host<T: Copy>(ptr: *const T, name: &str) -> Result<T, Failure> {
    let ptr = non_null(ptr, name)?;
    check_aligned(ptr, name)?;
    // SAFETY: non-NULL and aligned (checked); the host promises a readable, initialised
    // `T` there.
    Ok(unsafe { ptr.read() })
}

/// [`non_null`] for out-parameters, which must also be aligned for `T`: the library
/// writes through them.
pub(crate) fn non_null_mut<T>(ptr: *mut T, name: &str) -> Result<*mut T, Failure> {
    let ptr = non_null(ptr.cast_const(), name)?;
    check_aligned(ptr, name)?;
    Ok(ptr.cast_mut())
}

fn check_aligned<T>(ptr: *const T, name: &str) -> Result<(), Failure> {
    if ptr.is_aligned() {
        Ok(())
    } else {
        Err(invalid_arg!(
            "{name} = {ptr:?} is not aligned to {} bytes",
            align_of::<T>()
        )
        .into())
    }
}

/// Checks that a host array of `len` elements can be read as a slice: not NULL (unless
/// empty), aligned for `T`, no larger than Rust allows an allocation to be, and not running
/// past the end of the address space. Whether the host really holds `len` elements there
/// is its promise, as in any C API.
fn check_host_array<T>(ptr: *const T, len: usize, name: &str) -> Result<(), Failure> {
    if len == 0 {
        return Ok(());
    }
    non_null(ptr, name)?;
    check_aligned(ptr, name)?;
    let fits = len
        .checked_mul(size_of::<T>())
        .filter(|&b| b <= isize::MAX as usize)
        .is_some_and(|b| (ptr as usize).checked_add(b).is_some());
    if !fits {
        return Err(invalid_arg!(
            "{name}: {len} elements of {} bytes from {ptr:?} do not fit in memory",
            size_of::<T>()
        )
        .into());
    }
    Ok(())
}

/// The host array `ptr[0..len]` (see [`check_host_array`]); empty when `len` is 0.
pub(crate) fn host_slice<'a, T>(ptr: *const T, len: usize, name: &str) -> Result<&'a [T], Failure> {
    check_host_array(ptr, len, name)?;
    if len == 0 {
        return Ok(&[]);
    }
    // SAFETY: non-NULL, aligned and of a valid size (checked); the host promises `len`
    // initialised elements that stay put for the call.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// [`host_slice`] for an output array the host lends to the call.
pub(crate) fn host_slice_mut<'a, T>(
    ptr: *mut T,
    len: usize,
    name: &str,
) -> Result<&'a mut [T], Failure> {
    check_host_array(ptr.cast_const(), len, name)?;
    if len == 0 {
        return Ok(&mut []);
    }
    // SAFETY: non-NULL, aligned and of a valid size (checked); the host promises `len`
    // writable elements that nothing else touches during the call.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// The bytes a host buffer covers, for [`check_disjoint`].
pub(crate) struct Span<'a> {
    name: &'a str,
    start: usize,
    bytes: usize,
}

impl<'a> Span<'a> {
    /// `len` elements of `T` from `ptr` (an empty span when `len` is 0 or `ptr` NULL).
    pub(crate) fn of<T>(name: &'a str, ptr: *const T, len: usize) -> Self {
        let bytes = if ptr.is_null() {
            0
        } else {
            len.saturating_mul(size_of::<T>())
        };
        Span {
            name,
            start: ptr as usize,
            bytes,
        }
    }

    fn overlaps(&self, other: &Span) -> bool {
        self.bytes > 0
            && other.bytes > 0
            && self.start < other.start.saturating_add(other.bytes)
            && other.start < self.start.saturating_add(self.bytes)
    }
}

/// Refuses an output buffer that shares a byte with another output or with an input of the
/// same call: writing one while reading or writing the other is undefined behaviour.
pub(crate) fn check_disjoint(outputs: &[Span], inputs: &[Span]) -> Result<(), Failure> {
    for (i, out) in outputs.iter().enumerate() {
        let others = outputs[i + 1..].iter().chain(inputs);
        if let Some(other) = others.into_iter().find(|o| out.overlaps(o)) {
            return Err(invalid_arg!(
                "{} and {} overlap: an output buffer must not share memory with another buffer",
                out.name,
                other.name
            )
            .into());
        }
    }
    Ok(())
}

/// Drops a boxed handle; NULL is nothing to free.
pub(crate) fn free_handle<T>(handle: *mut T) {
    if !handle.is_null() {
        // SAFETY: a handle from the matching ht_*_new or ht_*_prepare, freed once (the
        // host's promise).
        drop(unsafe { Box::from_raw(handle) });
    }
}

/// Reads a `float[3]` that must be finite; the message names the argument.
pub(crate) fn read_vec3(ptr: *const f32, name: &str) -> Result<Vec3, Failure> {
    let v = Vec3::from_array(host_slice(ptr, 3, name)?.try_into().expect("3 elements"));
    if !v.is_finite() {
        return Err(invalid_arg!("{name} = {v}: must be finite").into());
    }
    Ok(v)
}

/// Reads a NUL-terminated UTF-8 string.
pub(crate) fn read_str<'a>(ptr: *const c_char, name: &str) -> Result<&'a str, Failure> {
    // SAFETY: non-NULL (checked); the host promises a NUL-terminated string that outlives
    // the call.
    let c = unsafe { CStr::from_ptr(non_null(ptr, name)?) };
    Ok(c.to_str()
        .map_err(|_| invalid_arg!("{name} {c:?} is not valid UTF-8"))?)
}

/// Reads a NUL-terminated UTF-8 path.
pub(crate) fn read_path(ptr: *const c_char, name: &str) -> Result<PathBuf, Failure> {
    let s = read_str(ptr, name)?;
    if s.is_empty() {
        return Err(invalid_arg!("{name} is empty").into());
    }
    Ok(PathBuf::from(s))
}

/// The ABI version this library was built with; compare with `HT_ABI_VERSION`. Cannot
/// fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_abi_version() -> u32 {
    HT_ABI_VERSION
}

/// The library version, e.g. "0.1.0": never NULL, static storage (never freed, never
/// changes). Cannot fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_version() -> *const c_char {
    static VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"unknown",
        };
    VERSION.as_ptr()
}

/// A short description of a status code (an `HtStatus` value); unknown codes give
/// "unknown status". Never NULL, static storage. Cannot fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_status_str(status: i32) -> *const c_char {
    HtStatus::ALL
        .iter()
        .find(|s| **s as i32 == status)
        .map_or(c"unknown status", |s| s.message())
        .as_ptr()
}

/// The message of the last failure on the calling thread ("" if none). Never NULL; valid
/// until the next failing call on this thread (copy it to keep it). Cannot fail; any
/// thread, each with its own message: one thread's failure is not seen on another.
#[unsafe(no_mangle)]
pub extern "C" fn ht_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        unsafe { CStr::from_ptr(ht_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn panics_and_errors_become_statuses() {
        assert_eq!(boundary(|| Ok(())), HtStatus::HT_OK);
        let s = boundary(|| Err(Error::InvalidArg("eta = 0".into()).into()));
        assert_eq!(s, HtStatus::HT_ERR_INVALID_ARG);
        assert!(last_error().contains("eta = 0"));
        let s = boundary(|| panic!("boom"));
        assert_eq!(s, HtStatus::HT_ERR_PANIC);
        assert!(last_error().contains("boom"));
    }

    #[test]
    fn status_strings_cover_every_code() {
        for s in HtStatus::ALL {
            let text = unsafe { CStr::from_ptr(ht_status_str(s as i32)) };
            assert!(!text.is_empty());
        }
        let unknown = unsafe { CStr::from_ptr(ht_status_str(999)) };
        assert_eq!(unknown.to_str().unwrap(), "unknown status");
        let v = unsafe { CStr::from_ptr(ht_version()) };
        assert_eq!(v.to_str().unwrap(), crate::VERSION);
    }
}
