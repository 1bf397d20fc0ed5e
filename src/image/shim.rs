//! `oiio_shim.cpp`'s C interface, opened at the first image read or write rather than
//! linked: OpenImageIO's many shared objects cost every process that links them start-up
//! time (docs/measurements.md, "Start-up") and put their symbols beside a host's own.
//! build.rs builds the shim as a shared library of its own.
//!
//! Where it is looked for, first found wins:
//! 1. `HT_IMAGE_SHIM`, a path to the file (a static host whose install moved);
//! 2. beside the object that holds this code (the shared library in an install's `lib/`,
//!    the Python extension in its package, the command line in the build folder), and in
//!    `../lib` from there (the command line in an install's `bin/`);
//! 3. by its name alone, where the loader looks: the RUNPATH of a static host (the
//!    install's static pkg-config and CMake packages give it the prefix's `lib/`),
//!    LD_LIBRARY_PATH, the system's folders;
//! 4. where this build made it (the build tree's own binaries and tests).

use std::ffi::{CStr, c_char, c_int, c_void};
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use std::sync::{Once, OnceLock};

use libloading::Library;

use crate::{Error, Result};

/// The shim's file name (build.rs's `image_shim_name`).
const NAME: &str = env!("HT_IMAGE_SHIM_NAME");

/// The shim's entry points (documented in `oiio_shim.cpp`) and the library that holds them.
pub(super) struct Shim {
    pub write: unsafe extern "C" fn(
        path: *const c_char,
        write_path: *const c_char,
        width: c_int,
        height: c_int,
        channels: c_int,
        pixels: *const f32,
        pixel_type: c_int,
        display: c_int,
        x: c_int,
        y: c_int,
        full_width: c_int,
        full_height: c_int,
        attribute_names: *const *const c_char,
        attribute_values: *const *const c_char,
        attributes: usize,
        err: *mut c_char,
        err_len: usize,
    ) -> c_int,
    pub open: unsafe extern "C" fn(
        path: *const c_char,
        handle: *mut *mut c_void,
        width: *mut c_int,
        height: *mut c_int,
        channels: *mut c_int,
        origin_and_full: *mut c_int,
        integer_format: *mut c_int,
        alpha_channel: *mut c_int,
        unassociated_alpha: *mut c_int,
        err: *mut c_char,
        err_len: usize,
    ) -> c_int,
    pub read: unsafe extern "C" fn(
        handle: *mut c_void,
        pixels: *mut f32,
        len: usize,
        err: *mut c_char,
        err_len: usize,
    ) -> c_int,
    pub attributes: unsafe extern "C" fn(
        handle: *mut c_void,
        buf: *mut c_char,
        len: usize,
        needed: *mut usize,
        err: *mut c_char,
        err_len: usize,
    ) -> c_int,
    pub close: unsafe extern "C" fn(handle: *mut c_void),
    /// Kept open for the process's life: the entry points point into it.
    _library: Library,
}

/// The shim, opened once per process; every later call gets the same answer.
pub(super) fn shim() -> Result<&'static Shim> {
    static SHIM: OnceLock<std::result::Result<Shim, String>> = OnceLock::new();
    SHIM.get_or_init(|| open(places()))
        .as_ref()
        .map_err(|why| Error::Image(why.clone()))
}

/// Opens the shim on a thread of its own, for a process that will read or write an image
/// later: OpenImageIO then loads while the process does other work, instead of before it or
/// at the end. Loading holds the dynamic loader's lock, which a thread being started also
/// takes: call it once the work's threads run. Only the first call starts the thread; a
/// failure is reported at the first use.
pub fn preload_shim() {
    static STARTED: Once = Once::new();
    STARTED.call_once(|| {
        // A thread that cannot start leaves the opening to the first use.
        let _ = std::thread::Builder::new()
            .name("image shim".into())
            .spawn(|| shim().is_ok());
    });
}

/// Opens the first shim found at `places`.
fn open(places: Vec<Place>) -> std::result::Result<Shim, String> {
    let mut tried = Vec::new();
    for place in places {
        if let Place::File(path) = &place
            && !path.is_file()
        {
            tried.push(path.display().to_string());
            continue;
        }
        let name = match &place {
            Place::File(path) => path.as_path(),
            Place::Search => Path::new(NAME),
        };
        // SAFETY: opening runs the file's initialisers: a file of the shim's name (which
        // carries the crate's version) or the one HT_IMAGE_SHIM names, whose initialisers
        // only set up OpenImageIO.
        match unsafe { Library::new(name) } {
            Ok(library) => return entry_points(library, name),
            Err(e) => tried.push(format!("{} ({e})", name.display())),
        }
    }
    Err(format!(
        "images need {NAME}, OpenImageIO's shim, and it is in none of: {} (set HT_IMAGE_SHIM \
         to its path if the library was moved)",
        tried.join(", ")
    ))
}

/// The shim's entry points in `library`, opened from `name`.
fn entry_points(library: Library, name: &Path) -> std::result::Result<Shim, String> {
    let cannot =
        |e: libloading::Error| format!("{} is not hairtrace's image shim: {e}", name.display());
    // SAFETY: each symbol is read as the type `oiio_shim.cpp` defines it with.
    unsafe {
        Ok(Shim {
            write: *library.get(b"hairtrace_oiio_write\0").map_err(cannot)?,
            open: *library.get(b"hairtrace_oiio_open\0").map_err(cannot)?,
            read: *library.get(b"hairtrace_oiio_read\0").map_err(cannot)?,
            attributes: *library
                .get(b"hairtrace_oiio_attributes\0")
                .map_err(cannot)?,
            close: *library.get(b"hairtrace_oiio_close\0").map_err(cannot)?,
            _library: library,
        })
    }
}

/// A place the shim may be.
enum Place {
    File(PathBuf),
    /// Its name alone, for the loader's search.
    Search,
}

/// Where the shim may be, in the order it is looked for (module docs).
fn places() -> Vec<Place> {
    let mut places = Vec::new();
    if let Some(path) = std::env::var_os("HT_IMAGE_SHIM") {
        places.push(Place::File(PathBuf::from(path)));
    }
    if let Some(dir) = this_object().as_deref().and_then(Path::parent) {
        places.push(Place::File(dir.join(NAME)));
        places.push(Place::File(dir.join("../lib").join(NAME)));
    }
    places.push(Place::Search);
    places.push(Place::File(PathBuf::from(env!("HT_IMAGE_SHIM_BUILT"))));
    places
}

/// The file of the shared object (or executable) that holds this code.
fn this_object() -> Option<PathBuf> {
    object_of(this_object as fn() -> Option<PathBuf> as *const c_void)
}

/// The file of the shared object (or executable) loaded at `address`.
fn object_of(address: *const c_void) -> Option<PathBuf> {
    let mut info = std::mem::MaybeUninit::<libc::Dl_info>::zeroed();
    // SAFETY: dladdr only reads the address and fills `info`.
    let found = unsafe { libc::dladdr(address, info.as_mut_ptr()) };
    // SAFETY: a nonzero return filled `info`; dli_fname is then null or a C string owned
    // by the loader while the object stays loaded (this code's, or the shim, never closed).
    let name = unsafe { (found != 0).then(|| info.assume_init().dli_fname) }?;
    if name.is_null() {
        return None;
    }
    // SAFETY: checked non-null above.
    let name = unsafe { CStr::from_ptr(name) };
    // The main program's name is how it was started (maybe relative, maybe a link).
    PathBuf::from(std::ffi::OsStr::from_bytes(name.to_bytes()))
        .canonicalize()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// This test binary finds the shim; the explicit variable comes first, the build's
    /// own copy last.
    #[test]
    fn the_shim_is_found_and_the_places_are_in_order() {
        let write = shim().expect("the build's shim").write;
        let path = object_of(write as *const c_void).expect("dladdr names the shim");
        assert!(path.ends_with(NAME), "{path:?}");
        let files: Vec<PathBuf> = places()
            .into_iter()
            .filter_map(|p| match p {
                Place::File(f) => Some(f),
                Place::Search => None,
            })
            .collect();
        assert_eq!(
            files.last(),
            Some(&PathBuf::from(env!("HT_IMAGE_SHIM_BUILT")))
        );
        let beside = this_object().expect("dladdr names this test binary");
        assert_eq!(files[files.len() - 3], beside.parent().unwrap().join(NAME));
    }

    /// Without the shim the error names every place tried; a library that is not the
    /// shim is refused by name.
    #[test]
    fn a_missing_or_foreign_shim_is_an_error_that_says_where_it_looked() {
        let missing = std::env::temp_dir().join("hairtrace-no-such-shim.so");
        let Err(e) = open(vec![Place::File(missing.clone())]) else {
            panic!("a missing file opened");
        };
        assert!(
            e.contains(&missing.display().to_string()) && e.contains("HT_IMAGE_SHIM"),
            "{e}"
        );
        let libc = object_of(libc::malloc as *const c_void).expect("libc is loaded");
        let Err(e) = open(vec![Place::File(libc)]) else {
            panic!("libc taken for the shim");
        };
        assert!(e.contains("is not hairtrace's image shim"), "{e}");
    }
}
