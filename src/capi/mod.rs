//! The C ABI: `extern "C"` functions over the same Rust API (DESIGN.md section 5).
//!
//! Every entry point goes through [`boundary`]: NULL pointers and bad values become an
//! [`HtStatus`] with a message for `ht_last_error`, and a panic is caught here instead of
//! unwinding into the host. The header `include/hairtrace.h` is generated from this
//! module by cbindgen.

pub mod bsdf;

pub use bsdf::HtHairParams;

use crate::Error;
use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Version of the C ABI; bumped on any incompatible change of a signature or struct.
pub const HT_ABI_VERSION: u32 = 1;

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
        }
    }

    const ALL: [HtStatus; 7] = [
        HtStatus::HT_OK,
        HtStatus::HT_ERR_NULL_ARG,
        HtStatus::HT_ERR_INVALID_ARG,
        HtStatus::HT_ERR_PANIC,
        HtStatus::HT_ERR_IO,
        HtStatus::HT_ERR_IMAGE,
        HtStatus::HT_ERR_EMBREE,
    ];
}

impl From<&Error> for HtStatus {
    fn from(e: &Error) -> Self {
        match e {
            Error::InvalidArg(_) => HtStatus::HT_ERR_INVALID_ARG,
            Error::Io(_) => HtStatus::HT_ERR_IO,
            Error::Image(_) => HtStatus::HT_ERR_IMAGE,
            Error::Embree { .. } => HtStatus::HT_ERR_EMBREE,
        }
    }
}

/// A failure at the boundary: the status and its message.
pub(crate) struct Failure(HtStatus, String);

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure(HtStatus::from(&e), e.to_string())
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
/// message, and a panic becomes `HT_ERR_PANIC` instead of unwinding into C.
pub(crate) fn boundary(body: impl FnOnce() -> Result<(), Failure>) -> HtStatus {
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

/// [`non_null`] for out-parameters.
pub(crate) fn non_null_mut<T>(ptr: *mut T, name: &str) -> Result<*mut T, Failure> {
    non_null(ptr.cast_const(), name).map(|p| p.cast_mut())
}

/// The ABI version this library was built with; compare with `HT_ABI_VERSION`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_abi_version() -> u32 {
    HT_ABI_VERSION
}

/// The library version, e.g. "0.1.0" (static storage).
#[unsafe(no_mangle)]
pub extern "C" fn ht_version() -> *const c_char {
    static VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => c"unknown",
        };
    VERSION.as_ptr()
}

/// A short static description of a status code (an `HtStatus` value); unknown codes
/// give "unknown status".
#[unsafe(no_mangle)]
pub extern "C" fn ht_status_str(status: i32) -> *const c_char {
    HtStatus::ALL
        .iter()
        .find(|s| **s as i32 == status)
        .map_or(c"unknown status", |s| s.message())
        .as_ptr()
}

/// The message of the last failure on the calling thread ("" if none). Never NULL; valid
/// until the next failing call on this thread.
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
