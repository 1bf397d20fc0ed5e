//! One reference to an Embree scene: what the top level (`scene.rs`) and each part of a
//! large geometry (`lazy.rs`) hold.

use std::ptr::NonNull;

use super::{Device, sys};
use crate::{Error, Result};

/// One reference to an Embree scene, released when dropped.
#[derive(Debug)]
pub(super) struct RawScene(NonNull<sys::RTCSceneTy>);

impl RawScene {
    pub(super) fn raw(&self) -> sys::RTCScene {
        self.0.as_ptr()
    }
}

// SAFETY: Embree scenes may be used from any thread; mutation happens only through
// `SceneBuilder` (owned, not shared) or, for a part's scene, inside its `OnceLock` before
// any query reaches it (`lazy.rs`); queries only on committed scenes, which Embree allows
// from many threads at once.
unsafe impl Send for RawScene {}
// SAFETY: as above.
unsafe impl Sync for RawScene {}

impl Drop for RawScene {
    fn drop(&mut self) {
        // SAFETY: we own one reference.
        unsafe { sys::rtcReleaseScene(self.0.as_ptr()) };
    }
}

/// A new scene with `flags`.
pub(super) fn new_scene(device: &Device, flags: sys::RTCSceneFlags) -> Result<RawScene> {
    // SAFETY: live device.
    let raw = unsafe { sys::rtcNewScene(device.raw()) };
    let Some(raw) = NonNull::new(raw) else {
        return Err(device.check().err().unwrap_or_else(|| Error::Embree {
            code: sys::RTCError::RTC_ERROR_UNKNOWN.0,
            message: "rtcNewScene returned null".into(),
        }));
    };
    let raw = RawScene(raw);
    // SAFETY: live scene, valid flags.
    unsafe { sys::rtcSetSceneFlags(raw.raw(), flags) };
    device.check()?;
    Ok(raw)
}
