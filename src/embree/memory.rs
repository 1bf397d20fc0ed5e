//! Embree's own memory use, as its memory monitor callback reports it: the BVH, build
//! temporaries and any buffer Embree allocates (shared buffers are not Embree's and are
//! counted by the geometries' `heap_bytes`).

use std::ffi::c_void;
use std::sync::Arc;
use std::sync::atomic::{AtomicI64, Ordering};

use super::{Device, sys};

#[derive(Debug, Default)]
struct Counters {
    current: AtomicI64,
    peak: AtomicI64,
}

/// Tracks the bytes Embree allocates on one device while it lives; unregisters on drop.
/// A device has one monitor slot, so a second monitor on the same device replaces the first.
#[derive(Debug)]
pub struct MemoryMonitor {
    // Boxed: its address is the callback's user pointer and must not move.
    counters: Box<Counters>,
    device: Arc<Device>,
}

impl MemoryMonitor {
    pub fn attach(device: Arc<Device>) -> Self {
        let counters = Box::<Counters>::default();
        // SAFETY: live device; the counters outlive the registration, which `Drop` removes
        // before freeing them, and `device` (kept here) outlives both.
        unsafe {
            sys::rtcSetDeviceMemoryMonitorFunction(
                device.raw(),
                Some(record),
                std::ptr::from_ref::<Counters>(&counters) as *mut c_void,
            );
        }
        MemoryMonitor { counters, device }
    }

    /// Bytes Embree holds now.
    pub fn current(&self) -> i64 {
        self.counters.current.load(Ordering::Relaxed)
    }

    /// The most bytes Embree held at once since attaching.
    pub fn peak(&self) -> i64 {
        self.counters.peak.load(Ordering::Relaxed)
    }
}

impl Drop for MemoryMonitor {
    fn drop(&mut self) {
        // SAFETY: live device; removing the callback before the counters are freed.
        unsafe {
            sys::rtcSetDeviceMemoryMonitorFunction(self.device.raw(), None, std::ptr::null_mut())
        };
    }
}

/// Embree's memory callback: may run on any of its threads, so atomics only; never cancels.
unsafe extern "C" fn record(user: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user` is the `Counters` registered in `attach`, alive until `Drop`.
    let c = unsafe { &*(user as *const Counters) };
    let now = c.current.fetch_add(bytes as i64, Ordering::Relaxed) + bytes as i64;
    c.peak.fetch_max(now, Ordering::Relaxed);
    true
}
