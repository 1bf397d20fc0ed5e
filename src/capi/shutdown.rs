//! `ht_shutdown`: joins the worker threads the library started, so that a host can unload
//! it, or check for leaks, with no thread of ours left running.
//!
//! Render threads need nothing here: each render runs on a pool of its own that is joined
//! before `ht_render_with` returns (`render_tiles`). The threads that outlive every handle are
//! TBB's, which Embree uses to build scenes: TBB keeps its workers after the last Embree
//! device is released, until the process exits or someone finalizes it. TBB has no C
//! interface, so its two exported entry points for that (oneTBB's `task_scheduler_handle`
//! attach and finalize, stable ABI of `libtbb.so.12`) are looked up by name at run time:
//! the library needs no TBB link of its own, and a process without TBB has nothing to join.

use super::{Failure, HtStatus, boundary};
use crate::embree::Device;
use std::ffi::{CStr, c_char, c_void};
use std::sync::{Mutex, Weak};

/// Every Embree device the C ABI created, to tell whether any is still alive.
static DEVICES: Mutex<Vec<Weak<Device>>> = Mutex::new(Vec::new());

/// Remembers a device made by `ht_device_new`.
pub(super) fn track(device: &std::sync::Arc<Device>) {
    let mut devices = DEVICES.lock().unwrap_or_else(|e| e.into_inner());
    devices.retain(|d| d.strong_count() > 0);
    devices.push(std::sync::Arc::downgrade(device));
}

/// oneTBB's `d1::task_scheduler_handle`: one pointer.
#[repr(C)]
struct TbbHandle(*mut c_void);

unsafe extern "C" {
    fn dlsym(handle: *mut c_void, symbol: *const c_char) -> *mut c_void;
}

/// `tbb::detail::r1::get(task_scheduler_handle&)`: attaches the handle to the scheduler.
const TBB_ATTACH: &CStr = c"_ZN3tbb6detail2r13getERNS0_2d121task_scheduler_handleE";
/// `tbb::detail::r1::finalize(task_scheduler_handle&, intptr_t mode)`.
const TBB_FINALIZE: &CStr = c"_ZN3tbb6detail2r18finalizeERNS0_2d121task_scheduler_handleEl";
/// The `mode` that waits for the workers and reports failure instead of throwing.
const FINALIZE_NOTHROWING: isize = 1;

/// Joins TBB's workers if TBB is loaded; Err if it refused (another user still holds it).
fn join_tbb_workers() -> Result<(), Failure> {
    // SAFETY: dlsym with RTLD_DEFAULT (NULL) and NUL-terminated names.
    let (attach, finalize) = unsafe {
        (
            dlsym(std::ptr::null_mut(), TBB_ATTACH.as_ptr()),
            dlsym(std::ptr::null_mut(), TBB_FINALIZE.as_ptr()),
        )
    };
    if attach.is_null() || finalize.is_null() {
        return Ok(()); // no TBB in the process: no TBB thread to join
    }
    // SAFETY: the two functions have these signatures (oneTBB's global_control.h), and
    // plain C calling conventions on this platform.
    let (attach, finalize) = unsafe {
        (
            std::mem::transmute::<*mut c_void, unsafe extern "C" fn(*mut TbbHandle)>(attach),
            std::mem::transmute::<*mut c_void, unsafe extern "C" fn(*mut TbbHandle, isize) -> bool>(
                finalize,
            ),
        )
    };
    let mut handle = TbbHandle(std::ptr::null_mut());
    // SAFETY: a handle of the layout TBB expects; finalize releases it in every mode.
    let joined = unsafe {
        attach(&mut handle);
        handle.0.is_null() || finalize(&mut handle, FINALIZE_NOTHROWING)
    };
    if joined {
        Ok(())
    } else {
        Err(Failure(
            HtStatus::HT_ERR_EMBREE,
            "TBB's worker threads are still in use elsewhere in the process (another library \
             or the host uses TBB): they were not joined"
                .into(),
        ))
    }
}

/// Joins the worker threads the library started, once every device and scene has been
/// freed: TBB's workers, which Embree used to build scenes and which otherwise run until
/// the process exits. Render threads need no call: each `ht_render_with` joins its own before
/// it returns. After `HT_OK` no thread started by hairtrace is running, and the library
/// may still be used again (a new device starts new workers).
///
/// Call it from one thread, with no other hairtrace call running. Statuses:
/// `HT_ERR_INVALID_ARG` when a device or scene is still alive (nothing is joined: free them
/// first); `HT_ERR_EMBREE` when TBB refuses because something else in the process (the
/// host, another library) still uses it: its workers then keep running, as they would
/// without this call.
///
/// # Safety
/// No other thread is inside a hairtrace call, and none starts one until it returns.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_shutdown() -> HtStatus {
    boundary(|| {
        let alive = {
            let mut devices = DEVICES.lock().unwrap_or_else(|e| e.into_inner());
            devices.retain(|d| d.strong_count() > 0);
            devices.len()
        };
        if alive > 0 {
            return Err(crate::error::invalid_arg!(
                "{alive} Embree device(s) still in use by a device or scene handle: free every \
                 scene and device before ht_shutdown"
            )
            .into());
        }
        join_tbb_workers()
    })
}
