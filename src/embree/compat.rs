//! Every difference between Embree 3 (Debian's) and Embree 4 that hairtrace meets, behind
//! one set of functions, so that no other file needs `cfg(embree3)` / `cfg(embree4)`
//! (set by `build.rs` from the installed header):
//! - Embree 3 passes an `RTCIntersectContext` (flags, filter) as the second argument of
//!   `rtcIntersect1`/`rtcOccluded1`; Embree 4 takes the ray first and an optional
//!   `RTCIntersectArguments`/`RTCOccludedArguments` (flags, feature mask, context, filter).
//! - A per-query filter needs `RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION` on the scene in
//!   Embree 3, `RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS` plus the query flag
//!   `RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER` in Embree 4.
//! - Geometry masks default to all bits in Embree 3 and to 1 in Embree 4; the geometry layer
//!   always sets them and rays always carry one, so both behave the same.
//! - A user geometry's callback continues a ray into another scene by tracing it again
//!   with its id on the context's instance stack in Embree 3, and by
//!   `rtcForwardIntersect1`/`rtcForwardOccluded1` in Embree 4, which allows no nested query.

use super::sys;

/// Embree's "no geometry" / "no instance" id.
pub(super) const INVALID_ID: u32 = u32::MAX;

/// The scene flag that lets a query bring its own filter.
#[cfg(embree3)]
pub(super) const FILTER_SCENE_FLAG: sys::RTCSceneFlags =
    sys::RTCSceneFlags::RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
#[cfg(embree4)]
pub(super) const FILTER_SCENE_FLAG: sys::RTCSceneFlags =
    sys::RTCSceneFlags::RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS;

/// The per-query context Embree hands to filter callbacks.
#[cfg(embree3)]
pub(super) type RawContext = sys::RTCIntersectContext;
#[cfg(embree4)]
pub(super) type RawContext = sys::RTCRayQueryContext;

/// A filter callback as Embree calls it.
pub(super) type Filter = unsafe extern "C" fn(*const sys::RTCFilterFunctionNArguments);

/// A fresh context: the equivalent of Embree's inline `rtcInitIntersectContext` /
/// `rtcInitRayQueryContext`, which bindgen cannot translate. Embree 3 keeps the filter
/// here; Embree 4 takes it with each query (see [`intersect1`]).
pub(super) fn new_context(filter: Option<Filter>) -> RawContext {
    #[cfg(embree3)]
    let raw = sys::RTCIntersectContext {
        flags: sys::RTCIntersectContextFlags::RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
        filter,
        instID: [INVALID_ID; sys::RTC_MAX_INSTANCE_LEVEL_COUNT as usize],
    };
    #[cfg(embree4)]
    let raw = {
        let _ = filter;
        let mut raw = sys::RTCRayQueryContext::default();
        raw.instID = [INVALID_ID; sys::RTC_MAX_INSTANCE_LEVEL_COUNT as usize];
        raw
    };
    raw
}

/// `rtcIntersect1` with `ctx` (made by [`new_context`] with the same `filter`).
///
/// # Safety
/// `scene` is a committed scene; `ctx` is the first field of whatever the filter casts it
/// back to, and lives across the call.
pub(super) unsafe fn intersect1(
    scene: sys::RTCScene,
    ctx: &mut RawContext,
    rayhit: &mut sys::RTCRayHit,
    filter: Option<Filter>,
) {
    #[cfg(embree3)]
    // SAFETY: the caller's contract.
    unsafe {
        let _ = filter;
        sys::rtcIntersect1(scene, ctx, rayhit)
    };
    #[cfg(embree4)]
    // SAFETY: the caller's contract; the arguments live across the call.
    unsafe {
        let mut args = sys::RTCIntersectArguments {
            flags: query_flags(filter.is_some()),
            feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
            context: ctx,
            filter,
            ..Default::default()
        };
        sys::rtcIntersect1(scene, rayhit, &mut args)
    };
}

/// `rtcOccluded1`, as [`intersect1`].
///
/// # Safety
/// As for [`intersect1`].
pub(super) unsafe fn occluded1(
    scene: sys::RTCScene,
    ctx: &mut RawContext,
    ray: &mut sys::RTCRay,
    filter: Option<Filter>,
) {
    #[cfg(embree3)]
    // SAFETY: the caller's contract.
    unsafe {
        let _ = filter;
        sys::rtcOccluded1(scene, ctx, ray)
    };
    #[cfg(embree4)]
    // SAFETY: the caller's contract; the arguments live across the call.
    unsafe {
        let mut args = sys::RTCOccludedArguments {
            flags: query_flags(filter.is_some()),
            feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
            context: ctx,
            filter,
            ..Default::default()
        };
        sys::rtcOccluded1(scene, ray, &mut args)
    };
}

#[cfg(embree4)]
fn query_flags(filtered: bool) -> sys::RTCRayQueryFlags {
    if filtered {
        sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER
    } else {
        sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_INCOHERENT
    }
}

/// Continues the traversal of the single ray of a user geometry's intersect callback
/// (`args`) into `scene`, its hits reported as inside instance `args.geomID` (the
/// callback's own id in the top level): Embree 3 traces it again from the callback with
/// that id pushed on the context's instance stack, Embree 4 forwards it
/// (`rtcForwardIntersect1`). The callback must return right after.
///
/// # Safety
/// `args` are the live arguments of an intersect callback for one ray (`N == 1`) of an
/// `rtcIntersect1` query; `scene` is committed.
pub(super) unsafe fn forward_intersect1(
    args: &sys::RTCIntersectFunctionNArguments,
    scene: sys::RTCScene,
) {
    let rayhit = args.rayhit.cast::<sys::RTCRayHit>();
    #[cfg(embree3)]
    // SAFETY: the caller's contract: a live context and a single ray with its hit.
    unsafe {
        let ctx = args.context;
        let outer = (*ctx).instID[0];
        (*ctx).instID[0] = args.geomID;
        sys::rtcIntersect1(scene, ctx, rayhit);
        (*ctx).instID[0] = outer;
    }
    #[cfg(embree4)]
    // SAFETY: the caller's contract; Embree reads the copy's origin and direction only.
    unsafe {
        let mut ray = (*rayhit).ray;
        sys::rtcForwardIntersect1(args, scene, &mut ray, args.geomID)
    };
}

/// [`forward_intersect1`] for an occlusion callback.
///
/// # Safety
/// As for [`forward_intersect1`], for an `rtcOccluded1` query.
pub(super) unsafe fn forward_occluded1(
    args: &sys::RTCOccludedFunctionNArguments,
    scene: sys::RTCScene,
) {
    let ray = args.ray.cast::<sys::RTCRay>();
    #[cfg(embree3)]
    // SAFETY: as in `forward_intersect1`.
    unsafe {
        let ctx = args.context;
        let outer = (*ctx).instID[0];
        (*ctx).instID[0] = args.geomID;
        sys::rtcOccluded1(scene, ctx, ray);
        (*ctx).instID[0] = outer;
    }
    #[cfg(embree4)]
    // SAFETY: as in `forward_intersect1`.
    unsafe {
        let mut copy = *ray;
        sys::rtcForwardOccluded1(args, scene, &mut copy, args.geomID)
    };
}
