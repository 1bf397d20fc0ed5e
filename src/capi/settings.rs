//! Render settings by name through the C ABI: an opaque handle that hosts set with
//! `ht_settings_set(settings, "spp", "64")`, so that a new setting never changes the ABI's
//! layout (the names, types, ranges and defaults: docs/settings.md).

use super::{Failure, HtStatus, boundary, host_slice_mut, non_null, non_null_mut, read_str};
use crate::error::invalid_arg;
use crate::render::settings::RenderSettings;
use std::ffi::{CString, c_char};
use std::sync::OnceLock;

/// Render settings (every one has a default), read and written by name. Create with
/// `ht_settings_new`, release with `ht_settings_free`. A handle may be read by any number
/// of threads at once, but not while one of them sets it.
pub struct HtSettings {
    pub(crate) settings: RenderSettings,
}

/// Creates settings holding every default into `*out` (640 x 480, 16 samples per pixel,
/// seed 0, every core, the full frame, a tent filter of radius 1, the exact hair BSDF,
/// shadow-ray roulette below 0.03: docs/settings.md lists them all).
///
/// Statuses: `HT_ERR_NULL_ARG` (`out` NULL); `HT_ERR_INVALID_ARG` (`out` misaligned).
///
/// Any thread.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_settings_new(out: *mut *mut HtSettings) -> HtStatus {
    boundary(|| {
        let out = host_slice_mut(non_null_mut(out, "out")?, 1, "out")?;
        out[0] = Box::into_raw(Box::new(HtSettings {
            settings: RenderSettings::default(),
        }));
        Ok(())
    })
}

/// Releases settings (NULL: nothing to do; returns HT_OK).
///
/// Any thread, once no other thread uses the handle.
///
/// # Safety
/// `settings` is NULL or a live handle from `ht_settings_new`, not used after this call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_settings_free(settings: *mut HtSettings) -> HtStatus {
    boundary(|| {
        if !settings.is_null() {
            // SAFETY: a live handle from ht_settings_new (the caller's promise).
            drop(unsafe { Box::from_raw(settings) });
        }
        Ok(())
    })
}

/// Sets the setting `key` from the text `value`, as a scene file's `[render]` table and the
/// command line's `--set key=value` do: integers and numbers in decimal ("64", "0.03"),
/// choices by name ("box"), a crop as "x0,y0,x1,y1", and "none" for an optional setting
/// left unset. Checks that need other settings (a crop inside the frame) are made when the
/// settings are used.
///
/// Statuses: `HT_ERR_NULL_ARG` (any argument NULL); `HT_ERR_INVALID_ARG` (an unknown key,
/// or a value out of the setting's range: the message names the key and the range, and
/// the settings are left unchanged).
///
/// # Safety
/// `settings` is NULL or a live handle that no other thread uses during the call; `key`
/// and `value` are NULL or NUL-terminated strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_settings_set(
    settings: *mut HtSettings,
    key: *const c_char,
    value: *const c_char,
) -> HtStatus {
    boundary(|| {
        let (key, value) = (read_str(key, "key")?, read_str(value, "value")?);
        // SAFETY: non-NULL (checked); a live handle the caller does not share (its promise).
        let settings = unsafe { &mut *non_null_mut(settings, "settings")? };
        settings.settings.set(key, value)?;
        Ok(())
    })
}

/// Writes the value of `key` as text (the form `ht_settings_set` reads), NUL-terminated,
/// into `buf` of `buf_len` bytes, and its length without the NUL into `*len` (may be NULL).
/// With `buf` NULL (and `buf_len` 0) only `*len` is written: call once to size the buffer.
///
/// Statuses: `HT_ERR_NULL_ARG` (`settings` or `key` NULL, or both `buf` and `len`);
/// `HT_ERR_INVALID_ARG` (an unknown key, or `buf_len` too small: nothing is written to
/// `buf` then, and `*len` says what it needs).
///
/// Any thread; several may read one handle at once, but not while one sets it.
///
/// # Safety
/// `settings` is NULL or a live handle; `key` is NULL or NUL-terminated; `buf` is NULL or
/// `buf_len` writable bytes; `len` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_settings_get(
    settings: *const HtSettings,
    key: *const c_char,
    buf: *mut c_char,
    buf_len: usize,
    len: *mut usize,
) -> HtStatus {
    boundary(|| {
        let key = read_str(key, "key")?;
        // SAFETY: non-NULL (checked); a live handle (the caller's promise).
        let settings = unsafe { &*non_null(settings, "settings")? };
        let text = settings.settings.get(key)?;
        if buf.is_null() && len.is_null() {
            return Err(Failure(
                HtStatus::HT_ERR_NULL_ARG,
                "buf and len are both NULL: nowhere to write".into(),
            ));
        }
        if !len.is_null() {
            host_slice_mut(len, 1, "len")?[0] = text.len();
        }
        if !buf.is_null() {
            if buf_len <= text.len() {
                return Err(invalid_arg!(
                    "buf_len = {buf_len}: {key}'s value needs {} bytes with its NUL",
                    text.len() + 1
                )
                .into());
            }
            let out = host_slice_mut(buf.cast::<u8>(), buf_len, "buf")?;
            out[..text.len()].copy_from_slice(text.as_bytes());
            out[text.len()] = 0;
        }
        Ok(())
    })
}

/// The name of setting number `index` (0, 1, ... in the order of docs/settings.md), or NULL
/// past the last: how a host lists every setting. Static storage. Cannot fail; any thread.
#[unsafe(no_mangle)]
pub extern "C" fn ht_settings_key(index: usize) -> *const c_char {
    static KEYS: OnceLock<Vec<CString>> = OnceLock::new();
    let keys = KEYS.get_or_init(|| {
        RenderSettings::schema()
            .iter()
            .map(|s| CString::new(s.name).expect("setting names hold no NUL"))
            .collect()
    });
    keys.get(index).map_or(std::ptr::null(), |k| k.as_ptr())
}

/// The settings behind a handle, checked as a whole.
pub(crate) fn read_settings(settings: *const HtSettings) -> Result<RenderSettings, Failure> {
    // SAFETY: non-NULL (checked); a live handle (the caller's promise).
    let s = unsafe { &*non_null(settings, "settings")? }.settings;
    s.validate()?;
    Ok(s)
}
