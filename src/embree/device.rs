//! The Embree device: the root object that owns Embree's thread pool and its error state.

use std::ffi::{CStr, CString, c_char, c_void};
use std::ptr::NonNull;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use super::{Isa, abi_check, sys};
use crate::error::invalid_arg;
use crate::{Error, Result};

/// An Embree device, released when dropped.
///
/// Embree reports most errors through a callback rather than return values, so the device
/// records the last one it was told about; [`Device::check`] turns it into an
/// [`Error::Embree`] after a call that may have failed.
#[derive(Debug)]
pub struct Device {
    raw: NonNull<sys::RTCDeviceTy>,
    /// Boxed so that its address, handed to Embree as the callback's user pointer, stays
    /// fixed when the `Device` moves.
    last_error: Box<ErrorSlot>,
    /// BVH builds started on this device ([`Device::builds`]).
    builds: AtomicU64,
    /// The instruction set its kernels are pinned to ([`Device::isa`]).
    isa: Option<Isa>,
}

/// The last error Embree reported: code and message. A mutex because Embree calls the
/// callback from whichever thread hit the error, its own workers included.
#[derive(Debug, Default)]
struct ErrorSlot(Mutex<Option<(u32, String)>>);

impl ErrorSlot {
    fn take(&self) -> Option<(u32, String)> {
        // A poisoned lock only means another thread panicked while holding it; the
        // recorded error is still meaningful.
        self.0.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}

// SAFETY: Embree's device API is thread safe (devices are shared by the scenes that all
// render threads query), and the error slot is behind a mutex.
unsafe impl Send for Device {}
// SAFETY: as above; `&Device` only exposes thread-safe Embree calls and the mutex.
unsafe impl Sync for Device {}

impl Device {
    /// Creates a device that uses `threads` worker threads, or every hardware thread when
    /// `None`, with the kernels Embree picks for this CPU.
    pub fn new(threads: Option<usize>) -> Result<Device> {
        Self::pinned(threads, None)
    }

    /// As [`Device::new`], with Embree's kernels pinned to `isa` when given (see [`Isa`]:
    /// the same kernels, hence the same bits, on every CPU that can run them). An ISA this
    /// CPU cannot run is refused.
    pub fn pinned(threads: Option<usize>, isa: Option<Isa>) -> Result<Device> {
        Self::with_config(&Self::config(threads, isa)?)
    }

    /// The Embree configuration string of [`Device::pinned`]. Embree reads it left to
    /// right, so `max_isa=avx2,` in front makes a device behave as on a CPU without
    /// AVX-512 until the pin (what the farm test uses to stand in for mixed machines).
    pub fn config(threads: Option<usize>, isa: Option<Isa>) -> Result<String> {
        let mut config = Vec::new();
        match threads {
            // Embree reads "threads=0" as "all", which would silently ignore the request.
            Some(0) => {
                return Err(invalid_arg!(
                    "Embree thread count must be at least 1 (None uses every hardware thread)"
                ));
            }
            Some(n) => config.push(format!("threads={n}")),
            None => {}
        }
        if let Some(isa) = isa {
            isa.check_runs_here()?;
            config.push(format!("isa={isa}"));
        }
        Ok(config.join(","))
    }

    /// Creates a device from an Embree configuration string (see `rtcNewDevice` in the
    /// Embree manual), for options [`Device::new`] does not cover, such as `verbose=1`.
    pub fn with_config(config: &str) -> Result<Device> {
        let c_config = CString::new(config)
            .map_err(|_| invalid_arg!("Embree config {config:?} contains a NUL byte"))?;
        // SAFETY: a valid NUL-terminated string that outlives the call.
        let raw = unsafe { sys::rtcNewDevice(c_config.as_ptr()) };
        let Some(raw) = NonNull::new(raw) else {
            // Without a device there is no callback: Embree 3 keeps only a code, per thread.
            // SAFETY: a null device asks for the error of the failed rtcNewDevice.
            let code = unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) }.0;
            return Err(Error::Embree {
                code,
                message: format!(
                    "{}: rtcNewDevice rejected the config {config:?}",
                    error_name(code)
                ),
            });
        };
        let last_error = Box::<ErrorSlot>::default();
        // SAFETY: `raw` is a live device; the slot outlives the registration because
        // `Drop` unregisters the callback before the box is freed.
        unsafe {
            sys::rtcSetDeviceErrorFunction(
                raw.as_ptr(),
                Some(record_error),
                std::ptr::from_ref::<ErrorSlot>(&last_error) as *mut c_void,
            );
        }
        // Embree reads the config left to right: the last `isa=` is the pin.
        let isa = (config.split(','))
            .filter_map(|key| key.trim().strip_prefix("isa="))
            .next_back()
            .and_then(|name| Isa::named(name).ok());
        let device = Device {
            raw,
            last_error,
            builds: AtomicU64::new(0),
            isa,
        };
        abi_check::verify_once(device.raw())?;
        Ok(device)
    }

    /// The instruction set its kernels are pinned to (`isa=` in its config); `None`: the
    /// widest this CPU runs.
    pub fn isa(&self) -> Option<Isa> {
        self.isa
    }

    /// The raw handle, for the scene and geometry layer. It is valid while `self` lives;
    /// code that keeps Embree objects beyond that must retain the device itself.
    pub(crate) fn raw(&self) -> sys::RTCDevice {
        self.raw.as_ptr()
    }

    /// How many scenes this device has started to build (commits, finished or not): what
    /// tells a host, and the tests, that an edit was applied without a BVH build. A large
    /// groom's part, built once when a ray first reaches it, is not counted: a render's
    /// `RenderStats::parts_built` says how many it built.
    pub fn builds(&self) -> u64 {
        self.builds.load(Ordering::Relaxed)
    }

    /// Counts one more build (by [`super::SceneBuilder::commit`]).
    pub(super) fn count_build(&self) {
        self.builds.fetch_add(1, Ordering::Relaxed);
    }

    /// Makes Embree fail every allocation from now on (`true`) with
    /// `RTC_ERROR_OUT_OF_MEMORY`, or stops (`false`): how tests meet a build that fails
    /// halfway. It takes the device's memory monitor slot ([`super::MemoryMonitor`]'s).
    #[cfg(test)]
    pub(crate) fn refuse_allocations(&self, refuse: bool) {
        unsafe extern "C" fn refuse_all(_: *mut c_void, bytes: isize, _: bool) -> bool {
            bytes <= 0
        }
        let monitor: sys::RTCMemoryMonitorFunction = if refuse { Some(refuse_all) } else { None };
        // SAFETY: live device; the callback reads no user data.
        unsafe {
            sys::rtcSetDeviceMemoryMonitorFunction(self.raw(), monitor, std::ptr::null_mut())
        };
    }

    /// Reports, and clears, the last error Embree recorded on this device (from any
    /// thread) or, failing that, the pending error code of the calling thread.
    pub fn check(&self) -> Result<()> {
        // SAFETY: live device. Also resets this thread's code, so the next check starts clean.
        let code = unsafe { sys::rtcGetDeviceError(self.raw.as_ptr()) }.0;
        match self.last_error.take() {
            Some((code, message)) => Err(Error::Embree { code, message }),
            None if code != sys::RTCError::RTC_ERROR_NONE.0 => Err(Error::Embree {
                code,
                message: error_name(code).to_owned(),
            }),
            None => Ok(()),
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: live device. Scenes may keep the device alive past this point (Embree
        // reference counts it), so the callback that points into `last_error` goes first.
        unsafe {
            sys::rtcSetDeviceErrorFunction(self.raw.as_ptr(), None, std::ptr::null_mut());
            sys::rtcReleaseDevice(self.raw.as_ptr());
        }
    }
}

/// Embree's error callback. It must not unwind into C, so it only formats and stores.
unsafe extern "C" fn record_error(user: *mut c_void, code: sys::RTCError, message: *const c_char) {
    let text = if message.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated string valid for the call.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    // SAFETY: `user` is the `ErrorSlot` registered in `with_config`, alive until `Drop`
    // unregisters this callback.
    let slot = unsafe { &*(user as *const ErrorSlot) };
    let mut last = slot.0.lock().unwrap_or_else(|e| e.into_inner());
    *last = Some((code.0, format!("{}: {text}", error_name(code.0))));
}

/// The `RTC_ERROR_*` name of an Embree error code, so messages are searchable in its docs.
fn error_name(code: u32) -> &'static str {
    match sys::RTCError(code) {
        sys::RTCError::RTC_ERROR_NONE => "RTC_ERROR_NONE",
        sys::RTCError::RTC_ERROR_UNKNOWN => "RTC_ERROR_UNKNOWN",
        sys::RTCError::RTC_ERROR_INVALID_ARGUMENT => "RTC_ERROR_INVALID_ARGUMENT",
        sys::RTCError::RTC_ERROR_INVALID_OPERATION => "RTC_ERROR_INVALID_OPERATION",
        sys::RTCError::RTC_ERROR_OUT_OF_MEMORY => "RTC_ERROR_OUT_OF_MEMORY",
        sys::RTCError::RTC_ERROR_UNSUPPORTED_CPU => "RTC_ERROR_UNSUPPORTED_CPU",
        sys::RTCError::RTC_ERROR_CANCELLED => "RTC_ERROR_CANCELLED",
        _ => "unrecognised Embree error code",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_with_one_two_and_all_threads() {
        for threads in [Some(1), Some(2), None] {
            let device = Device::new(threads).expect("device");
            assert!(!device.raw().is_null());
            assert_eq!(device.check(), Ok(()));
        }
    }

    #[test]
    fn zero_threads_is_invalid() {
        assert!(matches!(Device::new(Some(0)), Err(Error::InvalidArg(_))));
    }

    #[test]
    fn rejected_config_is_an_embree_error() {
        // Embree 3 ignores unknown keys but fails on a non-numeric thread count.
        match Device::with_config("threads=abc") {
            Err(Error::Embree { code, message }) => {
                assert_ne!(code, 0);
                assert!(message.contains("threads=abc"), "{message}");
            }
            other => panic!("expected an Embree error, got {other:?}"),
        }
    }

    #[test]
    fn nul_in_config_is_invalid() {
        assert!(matches!(
            Device::with_config("threads=1\0"),
            Err(Error::InvalidArg(_))
        ));
    }

    #[test]
    fn callback_errors_are_reported_once() {
        let device = Device::new(Some(1)).unwrap();
        // SAFETY: live device; an unknown property id is a reported error, not UB.
        unsafe { sys::rtcSetDeviceProperty(device.raw(), sys::RTCDeviceProperty(9999), 1) };
        match device.check() {
            Err(Error::Embree { code, message }) => {
                assert_eq!(code, sys::RTCError::RTC_ERROR_INVALID_ARGUMENT.0);
                assert!(
                    message.starts_with("RTC_ERROR_INVALID_ARGUMENT: "),
                    "{message}"
                );
            }
            other => panic!("expected an Embree error, got {other:?}"),
        }
        assert_eq!(device.check(), Ok(()));
    }

    #[test]
    fn device_is_send_and_sync() {
        fn assert_send_sync<T: Send + Sync>() {}
        assert_send_sync::<Device>();
    }

    #[test]
    fn version_matches_the_cfg() {
        let major = if cfg!(embree4) { "4." } else { "3." };
        assert!(super::super::version().starts_with(major));
    }
}
