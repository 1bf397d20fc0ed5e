//! The one error type of the Rust API. The C ABI maps each variant to an `HtStatus`
//! and keeps the message for `ht_last_error`.

/// Everything that can go wrong in hairtrace. Messages name the offending parameter,
/// file or library call so that a user can fix the input without reading the source.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter is NaN, infinite or outside its documented range.
    #[error("invalid argument: {0}")]
    InvalidArg(String),
    /// Reading or writing a file failed.
    #[error("i/o error: {0}")]
    Io(String),
    /// OpenImageIO refused to read or write an image.
    #[error("image error: {0}")]
    Image(String),
    /// Embree reported an error (its code and message).
    #[error("embree error {code}: {message}")]
    Embree { code: u32, message: String },
}

/// Shorthand used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Builds an [`Error::InvalidArg`] from a format string.
macro_rules! invalid_arg {
    ($($arg:tt)*) => { $crate::Error::InvalidArg(format!($($arg)*)) };
}
pub(crate) use invalid_arg;
