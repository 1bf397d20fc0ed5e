//! Ray queries: closest hit and occlusion for single rays, with an optional per-query
//! exclusion filter.
//!
//! The exclusion data reaches the filter callback through the context pointer Embree passes
//! to it: the context is the first field of a `#[repr(C)]` struct that also holds the
//! [`Exclude`], so the callback can cast back (Embree's documented way to extend a ray).

use glam::Vec3;

use super::compat::{self, Filter, INVALID_ID, RawContext};
use super::geometry::Geometry;
use super::scene::Scene;
use super::sys;

/// A ray. Embree does not require a unit direction; `t` is in units of `dir`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub org: Vec3,
    pub dir: Vec3,
    pub tnear: f32,
    pub tfar: f32,
    /// Only geometries whose mask shares a bit with this one are hit.
    pub mask: u32,
    /// When in the shutter the ray is traced, as a fraction of it in [0, 1]: where curves in
    /// motion are (`math::time_steps`). Geometry that does not move ignores it.
    pub time: f32,
}

impl Ray {
    /// A ray from `org` along `dir` over [0, infinity), hitting every geometry.
    pub fn new(org: Vec3, dir: Vec3) -> Self {
        Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
            mask: u32::MAX,
            time: 0.0,
        }
    }

    pub(crate) fn point_at(&self, t: f32) -> Vec3 {
        self.org + t * self.dir
    }

    /// Whether Embree accepts the ray: origin and direction components within its
    /// `FLT_LARGE` (about 1.8e18) and no NaN bound. Embree asserts on anything else (an abort
    /// in a release build); the scene's inputs are bounded so that this never fails, and a
    /// ray that would is treated as a miss.
    fn is_valid(&self) -> bool {
        const EMBREE_LARGE: f32 = 1.844e18;
        let within = |v: Vec3| v.abs().cmple(Vec3::splat(EMBREE_LARGE)).all();
        within(self.org) && within(self.dir) && !self.tnear.is_nan() && !self.tfar.is_nan()
    }

    fn to_sys(self) -> sys::RTCRay {
        sys::RTCRay {
            org_x: self.org.x,
            org_y: self.org.y,
            org_z: self.org.z,
            tnear: self.tnear,
            dir_x: self.dir.x,
            dir_y: self.dir.y,
            dir_z: self.dir.z,
            time: self.time,
            tfar: self.tfar,
            mask: self.mask,
            id: 0,
            flags: 0,
        }
    }
}

/// What Embree reports about the closest hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    pub t: f32,
    pub geom_id: u32,
    pub prim_id: u32,
    /// Embree's hit coordinates: for curves u along the segment and v across a flat curve
    /// (-1..1); for triangles the barycentrics of vertices 1 and 2.
    pub u: f32,
    pub v: f32,
    /// Embree's unnormalised geometric normal (for flat curves: the curve tangent).
    pub ng: Vec3,
}

/// Hits a query must ignore: primitives `first_prim..=last_prim` of geometry `geom_id`
/// closer than `max_t`. It is how a ray leaving a fiber avoids hitting the same tube
/// again while still seeing the same strand further away.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exclude {
    pub geom_id: u32,
    pub first_prim: u32,
    pub last_prim: u32,
    pub max_t: f32,
}

/// Embree's context extended with the exclusion the filter reads.
#[repr(C)]
struct QueryContext<'a> {
    /// Must stay first: the filter receives a pointer to it and casts back to the whole.
    raw: RawContext,
    exclude: Exclude,
    /// The scene queried, which turns Embree's ids into its own ([`Scene::own_ids`]).
    scene: &'a Scene,
}

impl<'a> QueryContext<'a> {
    /// The equivalent of Embree's inline `rtcInitIntersectContext`/`rtcInitRayQueryContext`,
    /// which bindgen cannot translate.
    fn new(scene: &'a Scene, exclude: Option<&Exclude>) -> Self {
        let raw = compat::new_context(filter_for(exclude));
        QueryContext {
            raw,
            exclude: exclude.copied().unwrap_or(Exclude {
                geom_id: INVALID_ID,
                first_prim: 1,
                last_prim: 0,
                max_t: 0.0,
            }),
            scene,
        }
    }
}

/// Rejects the candidate hits an [`Exclude`] names. Embree calls it for every hit found on
/// the way (closest-hit and occlusion queries alike) and drops the lanes set to 0.
///
/// # Safety
/// Only installed by this module, on a context that is the first field of a `QueryContext`.
unsafe extern "C" fn exclude_filter(args: *const sys::RTCFilterFunctionNArguments) {
    // SAFETY: Embree passes valid arguments for the duration of the call.
    let args = unsafe { &*args };
    // SAFETY: the context is the first field of a live `QueryContext` (see `query`).
    let ctx = unsafe { &*(args.context as *const QueryContext<'_>) };
    let exclude = &ctx.exclude;
    let n = args.N as usize;
    // SAFETY: `valid` holds N ints; ray and hit are SOA packets of N lanes: tfar is the 9th
    // float array of RTCRayN, primID, geomID and instID[0] the 6th, 7th and 8th u32 arrays
    // of RTCHitN.
    unsafe {
        let ray = args.ray as *const f32;
        let hit = args.hit as *const u32;
        for i in 0..n {
            let valid = args.valid.add(i);
            if *valid == 0 {
                continue;
            }
            let t = *ray.add(8 * n + i);
            let prim = *hit.add(5 * n + i);
            let geom = *hit.add(6 * n + i);
            let instance = *hit.add(7 * n + i);
            let excluded = ctx
                .scene
                .own_ids(instance, geom, prim)
                .is_some_and(|(g, p)| {
                    g == exclude.geom_id && (exclude.first_prim..=exclude.last_prim).contains(&p)
                });
            if excluded && t < exclude.max_t {
                *valid = 0;
            }
        }
    }
}

impl Scene {
    /// The closest hit along `ray`, ignoring what `exclude` names.
    pub fn intersect(&self, ray: &Ray, exclude: Option<&Exclude>) -> Option<RayHit> {
        if !ray.is_valid() {
            return None;
        }
        let mut ctx = QueryContext::new(self, exclude);
        let mut rayhit = sys::RTCRayHit {
            ray: ray.to_sys(),
            hit: sys::RTCHit {
                geomID: INVALID_ID,
                primID: INVALID_ID,
                instID: [INVALID_ID; sys::RTC_MAX_INSTANCE_LEVEL_COUNT as usize],
                ..Default::default()
            },
        };
        // SAFETY: committed scene (a `Scene` is only made by commit); context and ray live
        // across the call; the filter reads the context as a `QueryContext`, which it is.
        unsafe { compat::intersect1(self.raw(), &mut ctx.raw, &mut rayhit, filter_for(exclude)) };
        let h = rayhit.hit;
        let (geom_id, prim_id) = self.own_ids(h.instID[0], h.geomID, h.primID)?;
        Some(RayHit {
            t: rayhit.ray.tfar,
            geom_id,
            prim_id,
            u: h.u,
            v: h.v,
            ng: Vec3::new(h.Ng_x, h.Ng_y, h.Ng_z),
        })
    }

    /// Whether anything (not named by `exclude`) lies along `ray` within [tnear, tfar].
    pub(crate) fn occluded(&self, ray: &Ray, exclude: Option<&Exclude>) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let mut ctx = QueryContext::new(self, exclude);
        let mut r = ray.to_sys();
        // SAFETY: as in `intersect`.
        unsafe { compat::occluded1(self.raw(), &mut ctx.raw, &mut r, filter_for(exclude)) };
        // Embree marks an occluded ray by setting tfar to -infinity.
        r.tfar < 0.0 && ray.tfar >= 0.0
    }
}

impl Scene {
    /// The geometry and primitive, in this scene's numbering, of Embree's hit on primitive
    /// `prim` of geometry `geom`, inside instance `instance` when that is not
    /// `INVALID_ID` (a part of a large geometry: `SceneBuilder::attach`). `None` for no
    /// hit, or ids Embree never returns.
    fn own_ids(&self, instance: u32, geom: u32, prim: u32) -> Option<(u32, u32)> {
        let top = if instance == INVALID_ID {
            geom
        } else {
            instance
        };
        let slot = self.slot(top)?;
        let Some(start) = slot.part_start else {
            return Some((slot.geometry, prim));
        };
        match self.geometry(slot.geometry)? {
            Geometry::Curves(c) => Some((slot.geometry, c.own_segment(start, prim)?)),
            Geometry::Triangles(_) => None,
        }
    }
}

/// The exclusion filter when there is something to exclude.
fn filter_for(exclude: Option<&Exclude>) -> Option<Filter> {
    exclude.map(|_| exclude_filter as Filter)
}
