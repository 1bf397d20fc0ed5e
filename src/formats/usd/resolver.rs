//! The asset resolver stages are opened with: openusd's default resolver, except that
//! every layer it hands to openusd (root, sublayers, references, payloads, the layers of
//! a .usdz) is read into memory first, within the size the reader accepts, and a crate
//! file, or a package holding crate files, must pass [`check_crate`] before openusd
//! parses it. openusd opens a .usdz by reading the whole package through `open_asset` and
//! parsing its first layer from memory, so the package is checked whole: every entry
//! must be stored uncompressed (as the USDZ format requires; a compressed entry could
//! inflate without bound) and every crate entry must pass.
//!
//! A resolver made [`CheckingResolver::lifting`] also hands openusd each text layer with
//! its numeric arrays cut out (see `text_arrays`), keeping them for the reader to put back.

use std::collections::HashMap;
use std::io::{self, Read};
use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use openusd::ar::{self, Asset, AssetInfo, DefaultResolver, ResolvedPath, Resolver};

use super::crate_check::{MAGIC, Refusal, check_crate};
use super::text_arrays::{self, TextArrays};

/// The arrays cut out of each text layer, by resolved path.
pub(super) type Lifted = Arc<Mutex<HashMap<String, TextArrays>>>;

/// openusd's [`DefaultResolver`] with each asset checked before it is handed on.
#[derive(Default)]
pub(super) struct CheckingResolver {
    inner: DefaultResolver,
    lifted: Option<Lifted>,
}

impl CheckingResolver {
    /// A resolver that cuts the numeric arrays out of text layers into `lifted`.
    pub(super) fn lifting(lifted: Lifted) -> Self {
        Self {
            inner: DefaultResolver::default(),
            lifted: Some(lifted),
        }
    }

    /// The bytes of `resolved`, refused if they are more than the reader's
    /// `MAX_FILE_BYTES` or fail [`check_layer`].
    fn checked(&self, resolved: &ResolvedPath) -> io::Result<Vec<u8>> {
        let refused = |why: String| io::Error::new(io::ErrorKind::InvalidData, why);
        let name = resolved.to_string();
        let packaged = ar::split_package_relative_path_outer(&name);
        if let Some((package, _)) = &packaged {
            // The default resolver reads a packaged layer straight from the package on
            // disk: the package is checked whole first.
            self.checked(&ResolvedPath::new(package))?;
        }
        let asset = self.inner.open_asset(resolved)?;
        let limit = super::MAX_FILE_BYTES;
        // Sized once: a large text layer would otherwise be copied as the buffer grows.
        let size = asset.size().map_or(0, |n| n.min(limit));
        let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
        asset.take(limit + 1).read_to_end(&mut bytes)?;
        if bytes.len() as u64 > limit {
            return Err(refused(format!(
                "{name}: larger than the {limit} bytes this reader accepts"
            )));
        }
        check_layer(&bytes).map_err(|why| refused(format!("{name}: {why}")))?;
        match &self.lifted {
            Some(lifted) if packaged.is_none() && bytes.starts_with(b"#usda") => {
                match text_arrays::lift(bytes) {
                    Ok((text, arrays)) => {
                        lock(lifted).insert(name, arrays);
                        Ok(text)
                    }
                    Err(bytes) => Ok(bytes),
                }
            }
            _ => Ok(bytes),
        }
    }
}

impl Resolver for CheckingResolver {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ResolvedPath>) -> String {
        self.inner.create_identifier(asset_path, anchor)
    }

    fn resolve(&self, asset_path: &str) -> Option<ResolvedPath> {
        self.inner.resolve(asset_path)
    }

    fn resolve_for_new_asset(&self, asset_path: &str) -> Option<ResolvedPath> {
        self.inner.resolve_for_new_asset(asset_path)
    }

    fn open_asset(&self, resolved: &ResolvedPath) -> io::Result<Box<dyn Asset>> {
        Ok(Box::new(io::Cursor::new(self.checked(resolved)?)))
    }

    fn get_extension<'a>(&self, asset_path: &'a str) -> &'a str {
        self.inner.get_extension(asset_path)
    }

    fn get_asset_info(&self, asset_path: &str, resolved: &ResolvedPath) -> AssetInfo {
        self.inner.get_asset_info(asset_path, resolved)
    }

    fn get_modification_timestamp(
        &self,
        asset_path: &str,
        resolved: &ResolvedPath,
    ) -> Option<SystemTime> {
        self.inner.get_modification_timestamp(asset_path, resolved)
    }

    fn identity(&self) -> String {
        self.inner.identity()
    }
}

/// The lifted arrays, whether or not a thread panicked holding them (a panic abandons the
/// read that lifted them).
pub(super) fn lock(lifted: &Lifted) -> std::sync::MutexGuard<'_, HashMap<String, TextArrays>> {
    lifted
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Packages inside packages are checked to this depth: each level holds a copy of what it
/// contains, and a hostile file could otherwise nest until the stack runs out.
const MAX_PACKAGE_NESTING: usize = 8;

/// Checks one asset: a crate file, or each file of a zip package (a .usdz); anything else
/// (text layers) passes, the text parser checks it.
fn check_layer(bytes: &[u8]) -> Result<(), Refusal> {
    check_nested(bytes, 0)
}

/// [`check_layer`] of an asset inside `depth` packages.
fn check_nested(bytes: &[u8], depth: usize) -> Result<(), Refusal> {
    if bytes.starts_with(MAGIC) {
        check_crate(bytes)
    } else if bytes.starts_with(b"PK\x03\x04") {
        if depth == MAX_PACKAGE_NESTING {
            return Err(format!(
                "packages nested more than {MAX_PACKAGE_NESTING} deep"
            ));
        }
        check_package(bytes, depth)
    } else {
        Ok(())
    }
}

fn check_package(bytes: &[u8], depth: usize) -> Result<(), Refusal> {
    let unreadable = |e: zip::result::ZipError| format!("not a readable USDZ package: {e}");
    let mut package = zip::ZipArchive::new(io::Cursor::new(bytes)).map_err(unreadable)?;
    for i in 0..package.len() {
        let mut entry = package.by_index(i).map_err(unreadable)?;
        let name = entry.name().to_string();
        if entry.compression() != zip::CompressionMethod::Stored {
            return Err(format!(
                "package entry {name} is compressed: USDZ packages store their files uncompressed"
            ));
        }
        let mut data = Vec::new();
        (&mut entry)
            .take(bytes.len() as u64)
            .read_to_end(&mut data)
            .map_err(|e| format!("package entry {name}: {e}"))?;
        check_nested(&data, depth + 1).map_err(|why| format!("package entry {name}: {why}"))?;
    }
    Ok(())
}
