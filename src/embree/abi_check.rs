//! Checks, once per process, that the Embree library loaded at run time is the one the
//! bindings were generated for.
//!
//! bindgen's generated layout assertions already pin every struct to the header at compile
//! time; what no compiler sees is a library from elsewhere (a different `LD_LIBRARY_PATH`,
//! or the Embree 4 leg, which pairs Debian's 4.3.3 headers with a 4.4.0 library). Two
//! checks cover it:
//! - **Version rule**: the library's major version equals the header's, and the library is
//!   at least as new as the header (Embree keeps the ABI within a major version and only
//!   adds to it, so 4.4.0 serves 4.3.3 headers; an older library may lack what the header
//!   declares).
//! - **Layout probe**: one ray against one triangle through `rtcIntersect1`, into an
//!   `RTCRayHit` followed by a guard band: every field lands where the header says, and
//!   the library writes nothing past the struct (which a library built with more instance
//!   levels than the header's `RTC_MAX_INSTANCE_LEVEL_COUNT` would).

use std::sync::OnceLock;

use super::compat::{self, INVALID_ID};
use super::sys;
use crate::{Error, Result};

/// Runs both checks the first time a device exists; later devices get the same answer.
pub(super) fn verify_once(device: sys::RTCDevice) -> Result<()> {
    static VERDICT: OnceLock<Result<()>> = OnceLock::new();
    VERDICT
        .get_or_init(|| {
            check_version(library_version(device))?;
            // SAFETY: a live device, the caller's.
            unsafe { probe_layout(device) }
        })
        .clone()
}

fn mismatch(message: String) -> Error {
    Error::Embree {
        code: sys::RTCError::RTC_ERROR_UNKNOWN.0,
        message,
    }
}

/// `RTC_DEVICE_PROPERTY_VERSION` of the loaded library: 10000 major + 100 minor + patch.
fn library_version(device: sys::RTCDevice) -> u32 {
    // SAFETY: live device; a read-only property.
    let v = unsafe {
        sys::rtcGetDeviceProperty(device, sys::RTCDeviceProperty::RTC_DEVICE_PROPERTY_VERSION)
    };
    u32::try_from(v).unwrap_or(0)
}

fn dotted(v: u32) -> String {
    format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100)
}

/// The version rule of the module doc, against the header the build used.
fn check_version(library: u32) -> Result<()> {
    check_version_against(library, sys::RTC_VERSION)
}

fn check_version_against(library: u32, header: u32) -> Result<()> {
    if library / 10000 == header / 10000 && library >= header {
        return Ok(());
    }
    Err(mismatch(format!(
        "the loaded Embree library is {} but hairtrace was built against the {} headers; \
         it needs the same major version, at least as new as the headers (rebuild against \
         the library's headers, or load the library the build found)",
        dotted(library),
        dotted(header)
    )))
}

/// An `RTCRayHit` followed by a guard band the library must leave alone.
#[repr(C)]
struct Guarded {
    rayhit: sys::RTCRayHit,
    guard: [u32; 16],
}

const GUARD: u32 = 0x5EED_F00D;

/// Traces one ray at one triangle and checks every field of the hit record.
///
/// # Safety
/// `device` is a live device.
unsafe fn probe_layout(device: sys::RTCDevice) -> Result<()> {
    // The triangle (0,0,2) (1,0,2) (0,1,2); the ray from (0.25, 0.5, 0) along +z hits it
    // at t = 2 with barycentrics u = 0.25, v = 0.5.
    let vertices: [f32; 9] = [0.0, 0.0, 2.0, 1.0, 0.0, 2.0, 0.0, 1.0, 2.0];
    // SAFETY: live device; each new object is checked before use and released at the end.
    let scene = unsafe { sys::rtcNewScene(device) };
    // SAFETY: as above.
    let geometry =
        unsafe { sys::rtcNewGeometry(device, sys::RTCGeometryType::RTC_GEOMETRY_TYPE_TRIANGLE) };
    if scene.is_null() || geometry.is_null() {
        // SAFETY: releasing what was created; Embree accepts no null here, so guard.
        unsafe { release(scene, geometry) };
        return Err(mismatch(
            "the Embree library could not create a probe scene".into(),
        ));
    }
    // SAFETY: live objects; Embree allocates the buffers (padded as it needs), which are
    // written within the sizes asked for.
    let guarded = unsafe {
        let v = sys::rtcSetNewGeometryBuffer(
            geometry,
            sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
            0,
            sys::RTCFormat::RTC_FORMAT_FLOAT3,
            12,
            3,
        ) as *mut f32;
        let i = sys::rtcSetNewGeometryBuffer(
            geometry,
            sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
            0,
            sys::RTCFormat::RTC_FORMAT_UINT3,
            12,
            1,
        ) as *mut u32;
        if v.is_null() || i.is_null() {
            release(scene, geometry);
            return Err(mismatch(
                "the Embree library could not allocate the probe's buffers".into(),
            ));
        }
        v.copy_from_nonoverlapping(vertices.as_ptr(), vertices.len());
        i.copy_from_nonoverlapping([0u32, 1, 2].as_ptr(), 3);
        sys::rtcCommitGeometry(geometry);
        sys::rtcAttachGeometryByID(scene, geometry, 0);
        sys::rtcCommitScene(scene);

        let mut guarded = Guarded {
            rayhit: sys::RTCRayHit::default(),
            guard: [GUARD; 16],
        };
        let ray = &mut guarded.rayhit.ray;
        (ray.org_x, ray.org_y, ray.org_z) = (0.25, 0.5, 0.0);
        (ray.dir_z, ray.tfar, ray.mask) = (1.0, f32::INFINITY, u32::MAX);
        guarded.rayhit.hit.geomID = INVALID_ID;
        let mut ctx = compat::new_context(None);
        compat::intersect1(scene, &mut ctx, &mut guarded.rayhit, None);
        release(scene, geometry);
        guarded
    };
    let (ray, hit) = (&guarded.rayhit.ray, &guarded.rayhit.hit);
    let near = |a: f32, b: f32| (a - b).abs() <= 1e-6;
    let guard_intact = guarded.guard.iter().all(|&g| g == GUARD);
    // The unnormalised geometric normal has length 1 here (unit edges), along z.
    let expected = near(ray.tfar, 2.0)
        && near(hit.u, 0.25)
        && near(hit.v, 0.5)
        && (hit.geomID, hit.primID) == (0, 0)
        && hit.instID[0] == INVALID_ID
        && near(hit.Ng_x, 0.0)
        && near(hit.Ng_y, 0.0)
        && near(hit.Ng_z.abs(), 1.0);
    if expected && guard_intact {
        return Ok(());
    }
    Err(mismatch(format!(
        "the loaded Embree library ({}) does not fill RTCRayHit as the {} headers lay it \
         out (size {} bytes): probe hit t = {}, u = {}, v = {}, geomID = {}, primID = {}, \
         guard band {}; rebuild against the library's own headers",
        dotted(library_version(device)),
        dotted(sys::RTC_VERSION),
        size_of::<sys::RTCRayHit>(),
        ray.tfar,
        hit.u,
        hit.v,
        hit.geomID,
        hit.primID,
        if guard_intact {
            "intact"
        } else {
            "overwritten"
        }
    )))
}

/// Releases the probe's scene and geometry, either of which may be null.
///
/// # Safety
/// Each is null or a live object the caller owns one reference to.
unsafe fn release(scene: sys::RTCScene, geometry: sys::RTCGeometry) {
    // SAFETY: the caller's contract.
    unsafe {
        if !geometry.is_null() {
            sys::rtcReleaseGeometry(geometry);
        }
        if !scene.is_null() {
            sys::rtcReleaseScene(scene);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_rule() {
        // Same major and at least as new: the Embree 4 leg's 4.4.0 library, 4.3.3 headers.
        assert_eq!(check_version_against(40400, 40303), Ok(()));
        assert_eq!(check_version_against(31305, 31305), Ok(()));
        for (library, header) in [(31305, 40303), (40303, 31305), (40302, 40303), (0, 31305)] {
            let e = check_version_against(library, header)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&dotted(library)) && e.contains(&dotted(header)),
                "{e}"
            );
        }
    }

    #[test]
    fn the_linked_library_passes_both_checks() {
        let device = super::super::Device::new(Some(1)).unwrap();
        assert_eq!(check_version(library_version(device.raw())), Ok(()));
        // SAFETY: live device.
        assert_eq!(unsafe { probe_layout(device.raw()) }, Ok(()));
    }
}
