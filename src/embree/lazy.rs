//! Parts of a large curve geometry, built when a ray first reaches them.
//!
//! A part (`CurveGeometry::parts`) stands in the top-level scene as a user geometry of one
//! primitive whose bounds hold all its segments (`CurveGeometry::part_bounds`). The first
//! query whose ray enters those bounds builds the part's own scene, on the querying
//! thread with Embree's workers; a query on another thread that reaches the same part
//! waits for that build, and one that reaches another part builds that one meanwhile.
//! Every query then continues into the part's scene (`compat::forward_intersect1`), its
//! hits reported as inside the user geometry's id, as an instance's would be, so that
//! `Scene::own_ids` reads them alike.
//!
//! So the top-level build is all a render waits for: its first pixels wait only for the
//! parts their paths reach, and a part no ray reaches (behind the head, outside the
//! frame or the crop) is never built. A built part stays built for the scene's later
//! renders. A part's scene is a pure function of its segments, whenever and on whichever
//! thread it is built, so the pixels do not depend on the thread count.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use super::compat;
use super::geometry::RawGeometry;
use super::raw_scene::{RawScene, new_scene};
use super::{Device, sys};
use crate::Result;

/// A part in the top level: the user geometry that stands for it, and what builds it.
#[derive(Debug)]
pub(super) struct LazyPart {
    // Released in this order: the user geometry points at `build`.
    user: RawGeometry,
    build: Box<PartBuild>,
}

/// The part's curves, its bounds, and its scene once built.
#[derive(Debug)]
struct PartBuild {
    /// The part's handle on its geometry's buffers (`CurveGeometry::part_geometry`).
    geometry: RawGeometry,
    bounds: sys::RTCBounds,
    flags: sys::RTCSceneFlags,
    device: Arc<Device>,
    scene: OnceLock<Result<RawScene>>,
    /// Nanoseconds its build took.
    nanos: AtomicU64,
    /// Whether a build panicked (and left `scene` empty).
    panicked: AtomicBool,
}

impl PartBuild {
    /// The part's scene, built by the first call; `None` when that build failed (the
    /// error stays for [`LazyPart::error`]) or panicked.
    fn scene(&self) -> Option<sys::RTCScene> {
        let built = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.scene.get_or_init(|| {
                let start = Instant::now();
                let built = self.commit();
                self.nanos
                    .store(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
                built
            })
        }));
        match built {
            Ok(Ok(scene)) => Some(scene.raw()),
            Ok(Err(_)) => None,
            Err(_) => {
                self.panicked.store(true, Ordering::Relaxed);
                None
            }
        }
    }

    fn commit(&self) -> Result<RawScene> {
        #[cfg(test)]
        if tests::PANIC_IN_BUILD.get() {
            panic!("a part build's panic, provoked by a test");
        }
        let scene = new_scene(&self.device, self.flags)?;
        // SAFETY: live scene and committed geometry; the scene retains the geometry, whose
        // buffers outlive it (`LazyPart`'s contract).
        unsafe {
            sys::rtcAttachGeometryByID(scene.raw(), self.geometry.raw(), 0);
            sys::rtcCommitScene(scene.raw());
        }
        self.device.check()?;
        Ok(scene)
    }
}

impl LazyPart {
    /// A user geometry, committed with `mask`, standing for the part of curves `geometry`
    /// within `bounds` (lower, upper), whose scene is built with `flags` when a ray first
    /// enters them.
    ///
    /// # Safety
    /// `geometry`'s buffers outlive the returned value.
    pub(super) unsafe fn new(
        device: &Arc<Device>,
        geometry: RawGeometry,
        (lower, upper): ([f32; 3], [f32; 3]),
        flags: sys::RTCSceneFlags,
        mask: u32,
    ) -> Result<Self> {
        let build = Box::new(PartBuild {
            geometry,
            bounds: sys::RTCBounds {
                lower_x: lower[0],
                lower_y: lower[1],
                lower_z: lower[2],
                upper_x: upper[0],
                upper_y: upper[1],
                upper_z: upper[2],
                ..Default::default()
            },
            flags,
            device: Arc::clone(device),
            scene: OnceLock::new(),
            nanos: AtomicU64::new(0),
            panicked: AtomicBool::new(false),
        });
        let user = RawGeometry::new(device, sys::RTCGeometryType::RTC_GEOMETRY_TYPE_USER)?;
        let data = (&raw const *build).cast_mut().cast::<std::ffi::c_void>();
        // SAFETY: live user geometry; `data` points at the boxed `PartBuild`, which lives
        // at a fixed address until after `user` is released (field order), and the
        // callbacks only read it.
        unsafe {
            sys::rtcSetGeometryUserPrimitiveCount(user.raw(), 1);
            sys::rtcSetGeometryUserData(user.raw(), data);
            sys::rtcSetGeometryBoundsFunction(user.raw(), Some(bounds), data);
            sys::rtcSetGeometryIntersectFunction(user.raw(), Some(intersect));
            sys::rtcSetGeometryOccludedFunction(user.raw(), Some(occluded));
        }
        user.commit(device, mask)?;
        Ok(LazyPart { user, build })
    }

    /// The handle the top level attaches.
    pub(super) fn raw(&self) -> sys::RTCGeometry {
        self.user.raw()
    }

    /// Seconds its build took; `None` while it is not built.
    pub(super) fn built_seconds(&self) -> Option<f64> {
        let built = matches!(self.build.scene.get(), Some(Ok(_)));
        built.then(|| self.build.nanos.load(Ordering::Relaxed) as f64 * 1e-9)
    }

    /// Why its build failed, if it did: rays then pass through it.
    pub(super) fn error(&self) -> Option<crate::Error> {
        if self.build.panicked.load(Ordering::Relaxed) {
            return Some(crate::Error::Embree {
                code: sys::RTCError::RTC_ERROR_UNKNOWN.0,
                message: "a part's BVH build panicked".into(),
            });
        }
        self.build.scene.get()?.as_ref().err().cloned()
    }
}

/// The `PartBuild` an Embree callback was given as its user pointer.
///
/// # Safety
/// `user` is the pointer `LazyPart::new` set.
unsafe fn part<'a>(user: *mut std::ffi::c_void) -> &'a PartBuild {
    // SAFETY: the caller's contract: a live `PartBuild`.
    unsafe { &*user.cast::<PartBuild>() }
}

/// Embree's bounds callback: the part's bounds.
unsafe extern "C" fn bounds(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes live arguments, the user pointer `LazyPart::new` set, and
    // room for one `RTCBounds`.
    unsafe {
        let args = &*args;
        *args.bounds_o = part(args.geometryUserPtr).bounds;
    }
}

/// Embree's intersect callback: builds the part if needed and traces into it. Only single
/// rays are traced (`query.rs`), so `N` is 1.
unsafe extern "C" fn intersect(args: *const sys::RTCIntersectFunctionNArguments) {
    // SAFETY: Embree passes live arguments for one ray of an `rtcIntersect1` query.
    unsafe {
        let args = &*args;
        if args.N != 1 || *args.valid == 0 {
            return;
        }
        if let Some(scene) = part(args.geometryUserPtr).scene() {
            compat::forward_intersect1(args, scene);
        }
    }
}

/// Embree's occluded callback, as [`intersect`].
unsafe extern "C" fn occluded(args: *const sys::RTCOccludedFunctionNArguments) {
    // SAFETY: as in `intersect`, for an `rtcOccluded1` query.
    unsafe {
        let args = &*args;
        if args.N != 1 || *args.valid == 0 {
            return;
        }
        if let Some(scene) = part(args.geometryUserPtr).scene() {
            compat::forward_occluded1(args, scene);
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::embree::geometry::PARTS_FROM_SEGMENTS;
    use crate::embree::geometry::tests::round_in_parts;
    use crate::embree::{CurveBasis, Ray, Scene, SceneBuilder, SceneOptions};

    thread_local! {
        /// Makes the part builds this thread runs panic.
        pub(super) static PANIC_IN_BUILD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }

    /// Straight strands along y in a row along x, 4 linear segments each, in parts, and a
    /// ray at `x` into them; the last strand is at the returned x.
    fn row_in_parts(device: &Arc<Device>) -> (Scene, impl Fn(f32) -> Ray, f32) {
        let strands = PARTS_FROM_SEGMENTS / 4;
        let points: Vec<[f32; 4]> = (0..strands * 5)
            .map(|i| [(i / 5) as f32 * 0.1, (i % 5) as f32 * 0.25, 0.0, 0.02])
            .collect();
        let indices: Vec<u32> = (0..strands as u32)
            .flat_map(|s| (0..4).map(move |j| s * 5 + j))
            .collect();
        let geometry = round_in_parts(device, CurveBasis::Linear, points, indices);
        let mut scene = SceneBuilder::new(device.clone(), SceneOptions::default()).unwrap();
        scene.attach(geometry).unwrap();
        let scene = scene.commit(&|_| true).unwrap();
        let ray = |x: f32| Ray::new(Vec3::new(x, 0.5, -1.0), Vec3::Z);
        (scene, ray, (strands - 1) as f32 * 0.1)
    }

    /// A part whose build fails lets rays through, and the scene says why, so that the
    /// render that met it fails (`render::renderer`) rather than show a hole.
    #[test]
    fn a_part_whose_build_fails_is_reported() {
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let (scene, ray, far) = row_in_parts(&device);
        assert!(scene.intersect(&ray(0.0), None).is_some());
        assert!(scene.check_parts().is_ok());
        device.refuse_allocations(true);
        let through = scene.intersect(&ray(far), None);
        device.refuse_allocations(false);
        assert!(through.is_none());
        let err = scene.check_parts().unwrap_err();
        assert!(err.to_string().contains("RTC_ERROR_OUT_OF_MEMORY"), "{err}");
        // The part that was built still answers.
        assert!(scene.intersect(&ray(0.0), None).is_some());
    }

    /// A panic in a part's build stays inside the callback Embree called (it may not
    /// unwind through Embree's C++ frames): the ray passes through and the scene reports
    /// the panic, so the render fails, even once a later ray has built the part.
    #[test]
    fn a_part_whose_build_panics_is_reported() {
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let (scene, ray, far) = row_in_parts(&device);
        PANIC_IN_BUILD.set(true);
        let through = scene.intersect(&ray(far), None);
        PANIC_IN_BUILD.set(false);
        assert!(through.is_none());
        let err = scene.check_parts().unwrap_err();
        assert!(
            err.to_string().contains("a part's BVH build panicked"),
            "{err}"
        );
        assert!(scene.intersect(&ray(far), None).is_some());
        assert!(scene.check_parts().is_err());
    }
}
