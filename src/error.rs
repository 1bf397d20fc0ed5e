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

impl Error {
    /// The same error, of the same kind, with `context` (a file, a scene entry) in front
    /// of its message: `"{context}: {message}"`.
    pub fn context(self, context: impl std::fmt::Display) -> Error {
        let prefix = |m: String| format!("{context}: {m}");
        match self {
            Error::InvalidArg(m) => Error::InvalidArg(prefix(m)),
            Error::Io(m) => Error::Io(prefix(m)),
            Error::Image(m) => Error::Image(prefix(m)),
            Error::Embree { code, message } => Error::Embree {
                code,
                message: prefix(message),
            },
        }
    }

    /// The message without the kind in front, for hosts that get the kind apart (the C
    /// ABI's status): `Display` gives `"invalid argument: {detail}"`.
    pub fn detail(&self) -> String {
        match self {
            Error::InvalidArg(m) | Error::Io(m) | Error::Image(m) => m.clone(),
            Error::Embree { code, message } => format!("{message} (Embree error code {code})"),
        }
    }

    /// An i/o failure on `path`, naming it.
    pub fn io(path: &std::path::Path, e: std::io::Error) -> Error {
        Error::Io(format!("{}: {e}", path.display()))
    }

    /// An image `path` could not be encoded or drawn (`e` says why), naming it.
    pub fn image(path: &std::path::Path, e: impl std::fmt::Display) -> Error {
        Error::Image(format!("{}: {e}", path.display()))
    }
}

/// Shorthand used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Builds an [`Error::InvalidArg`] from a format string.
macro_rules! invalid_arg {
    ($($arg:tt)*) => { $crate::Error::InvalidArg(format!($($arg)*)) };
}
pub(crate) use invalid_arg;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn context_keeps_the_kind() {
        let e = Error::Embree {
            code: 3,
            message: "bad".into(),
        }
        .context("scene.toml: groom[0]");
        assert_eq!(
            e,
            Error::Embree {
                code: 3,
                message: "scene.toml: groom[0]: bad".into()
            }
        );
        let e = Error::io(
            std::path::Path::new("/x.hair"),
            std::io::Error::other("gone"),
        );
        assert_eq!(e.detail(), "/x.hair: gone");
        assert_eq!(e.context("a").to_string(), "i/o error: a: /x.hair: gone");
        let e = Error::image(std::path::Path::new("/x.png"), "too wide");
        assert_eq!(e.to_string(), "image error: /x.png: too wide");
    }
}
