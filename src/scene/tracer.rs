//! A traceable scene: curves and meshes in one Embree scene, queries that return full hit
//! records (hair frame, h, strand attributes), and rays that leave a fiber without hitting
//! it again.

use std::sync::Arc;

use glam::{Vec3, Vec4};

use super::curves::{Curves, StrandIndex, StrandSegment, TrueCurves};
use super::detail_view::{DetailView, ViewDependent};
use super::hit::{HairHit, Hit, SurfaceHit, hair_frame};
use super::mesh::Mesh;
use super::stages::{Stage, StageRunner};
use crate::Result;
use crate::embree::{
    CurveBasis, CurveGeometry, CurvePoint, CurveShape, DEFAULT_RIBBON_QUADS, Device, Exclude,
    Geometry, Ray, RayHit, Scene, SceneBuilder, SceneOptions, SharedBuffer, TriangleGeometry,
};

/// Geometry mask bit of hair curves: a ray with `mask = SURFACE_MASK` ignores hair.
pub const HAIR_MASK: u32 = 1;
/// Geometry mask bit of triangle meshes.
pub const SURFACE_MASK: u32 = 2;

/// How a continued ray (reflection, transmission, shadow) leaves a fiber.
///
/// Measured re-hit rates (`src/scene/tests/rehit.rs`: ~2500 round-curve hits x 64 random
/// directions, every basis, straight and bent strands): `Offset` re-hits ~100% of transmitted and ~50%
/// of shadow rays; the three filtered strategies at most 0.005%. `ExitAndFilter` is the
/// default because it is the fastest of those on round cubic curves (`benches/groom.rs`:
/// Embree seldom meets the tube it left, so the filter seldom runs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Escape {
    /// Move the origin off the surface, to the side the ray goes: transmitted rays start
    /// inside the tube and hit its far wall. Kept as the baseline the others are measured
    /// against.
    #[cfg(any(test, feature = "bench-internals"))]
    Offset,
    /// The offset plus the exclusion filter.
    #[cfg(any(test, feature = "bench-internals"))]
    OffsetAndFilter,
    /// Start where the ray leaves the tube (past the far wall for a transmitted ray, just
    /// off the surface for a reflected one, from the local cylinder at the hit), plus the
    /// exclusion filter for what that cylinder misses (bends, taper). Embree then rarely
    /// meets the tube it left, which keeps the filter cheap.
    #[default]
    ExitAndFilter,
    /// Start exactly at the hit point and let the exclusion filter reject every hit on the
    /// same tube (same strand, neighbouring segments) before the ray can have left it.
    #[cfg(any(test, feature = "bench-internals"))]
    Filter,
}

/// Distance, in fiber radii over the sine of the angle to the tangent, within which a hit
/// on the same tube counts as the same tube: a ray crosses a cylinder of radius r in at most
/// 2 r / sin(angle); the rest is margin for bends and taper.
const EXIT_RADII: f32 = 3.0;
/// Floor of that sine, so a ray along the fiber still gets a finite exclusion distance.
const MIN_EXIT_SINE: f32 = 1e-3;
/// Offset of a continued ray's origin, in fiber radii, plus a few ulps of the larger of
/// the position and the distance the hit was found at: the hit point's error grows with
/// both (a point near the world origin, reached from afar, is no more accurate than the
/// ray that found it).
const OFFSET_RADII: f32 = 1e-3;
const OFFSET_ULPS: f32 = 64.0 * f32::EPSILON;

/// Embree ignores a flat curve's hits closer to the ray's origin than this many of the
/// curve's radii (its build option `EMBREE_CURVE_SELF_INTERSECTION_AVOIDANCE_FACTOR`, 2 by
/// default in Embree 3.13 and 4, Debian's and the Embree 4 leg's builds alike): a ray
/// leaving a strand would not see a ribbon touching it, and hair in clumps shaded too
/// bright. A spawned ray therefore starts this far, and [`RADIUS_OVERSHOOT`] more, behind
/// its origin, with `tnear` at the origin: the same ray, whose every hit is past Embree's
/// blind distance (docs/measurements.md, "Real grooms: the defaults against round curves").
const FLAT_BLIND_RADII: f32 = 2.0;
/// How far a cubic curve's interpolated radius may exceed its largest control radius: a
/// Catmull-Rom basis weighs its points by up to 1.25 in absolute sum (B-spline, Bezier and
/// linear weights are positive and sum to 1).
const RADIUS_OVERSHOOT: f32 = 1.25;

/// How far, in radii, a ribbon's hit may move back along its ray to the tube's surface
/// ([`tube_entry`]): a ray at angle a to the axis enters the tube up to 1 / sin(a) radii
/// before the midplane, so rays within 30 degrees of the axis are held at this.
const TUBE_ENTRY_RADII: f32 = 2.0;

/// A ray leaving a hit, with the exclusion that keeps it off the surface it left.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpawnedRay {
    pub ray: Ray,
    pub exclude: Option<Exclude>,
}

/// A ray that leaves no hit (a camera ray): nothing to exclude.
impl From<Ray> for SpawnedRay {
    fn from(ray: Ray) -> Self {
        SpawnedRay { ray, exclude: None }
    }
}

impl SpawnedRay {
    /// Where the ray really starts (Embree's origin lies `tnear` behind it,
    /// [`FLAT_BLIND_RADII`]), and `t` of Embree's (a hit's distance) from there: what a
    /// light's distance along the ray is measured against.
    pub fn start(&self, t: f32) -> (Vec3, f32) {
        let r = &self.ray;
        (r.org + r.dir * r.tnear, t - r.tnear)
    }
}

/// What a geometry id refers to, besides the Embree geometry.
#[derive(Debug)]
enum Table {
    Curves {
        strands: StrandIndex,
        /// The curves that level-of-detail polylines stand for ([`Curves::truth`]).
        truth: Option<Arc<TrueCurves>>,
    },
    Mesh {
        normals: Option<Vec<[f32; 3]>>,
    },
}

/// Collects curves and meshes, then builds the scene.
#[derive(Debug)]
pub struct TracerBuilder {
    scene: SceneBuilder,
    tables: Vec<Table>,
    view: ViewDependent,
    /// The largest control radius of the flat curves added (0 without any).
    flat_radius: f32,
}

impl TracerBuilder {
    pub fn new(device: Arc<Device>, options: SceneOptions) -> Result<Self> {
        Ok(TracerBuilder {
            scene: SceneBuilder::new(device, options)?,
            tables: Vec::new(),
            view: ViewDependent::default(),
            flat_radius: 0.0,
        })
    }

    /// Adds curves (mask [`HAIR_MASK`]) and returns their geometry id.
    pub fn add_curves(&mut self, curves: Curves) -> Result<u32> {
        let quads = curves.ribbon_quads();
        let (basis, shape, steps, indices, strands, truth, parts) = curves.into_parts();
        if shape == CurveShape::Flat {
            let largest =
                (steps.iter().flat_map(|s| s.as_slice())).fold(0.0f32, |m, v| m.max(v[3]));
            self.flat_radius = self.flat_radius.max(largest);
        }
        let in_parts = self.scene.options().builds_in_parts(indices.len());
        let geometry =
            CurveGeometry::in_motion(self.scene.device(), basis, shape, steps, indices, HAIR_MASK)?;
        let geometry = if quads != DEFAULT_RIBBON_QUADS {
            geometry.with_ribbon_quads(self.scene.device(), quads)?
        } else {
            geometry
        };
        let geometry = if in_parts {
            geometry.in_parts(&parts)?
        } else {
            geometry
        };
        let id = self.scene.attach(geometry)?;
        self.tables.push(Table::Curves { strands, truth });
        Ok(id)
    }

    /// Adds curves whose detail was chosen for `view`, one per scene ([`Tracer::serves`]).
    pub fn add_view_curves(&mut self, curves: Curves, view: DetailView) -> Result<u32> {
        self.view.check(&view)?;
        let id = self.add_curves(curves)?;
        self.view.push(id, view);
        Ok(id)
    }

    /// Adds a mesh (mask [`SURFACE_MASK`]) and returns its geometry id.
    pub fn add_mesh(&mut self, mesh: Mesh) -> Result<u32> {
        mesh.validate()?;
        let steps = std::iter::once(mesh.positions).chain(mesh.later_positions);
        let geometry = TriangleGeometry::in_motion(
            self.scene.device(),
            steps.map(SharedBuffer::new).collect(),
            SharedBuffer::new(mesh.triangles),
            SURFACE_MASK,
        )?;
        let id = self.scene.attach(geometry)?;
        self.tables.push(Table::Mesh {
            normals: mesh.normals,
        });
        Ok(id)
    }

    /// Builds the BVH.
    #[cfg(any(test, feature = "bench-internals"))]
    pub fn build(self) -> Result<Tracer> {
        self.build_with(&StageRunner::new(&super::stages::NoStages))
    }

    /// Builds the BVH, reporting its progress as [`Stage::Bvh`] to `stages`.
    pub fn build_with(self, stages: &StageRunner<'_>) -> Result<Tracer> {
        Ok(Tracer {
            scene: self
                .scene
                .commit(&|fraction| stages.forward(Stage::Bvh, fraction))?,
            tables: self.tables,
            view: self.view,
            flat_blind: FLAT_BLIND_RADII * RADIUS_OVERSHOOT * self.flat_radius,
        })
    }
}

/// A committed scene with the tables that turn Embree hits into hit records. `Sync`: share
/// it between render threads.
#[derive(Debug)]
pub struct Tracer {
    scene: Scene,
    tables: Vec<Table>,
    view: ViewDependent,
    /// The distance from a ray's origin within which Embree may ignore a flat curve's hit
    /// ([`FLAT_BLIND_RADII`]); 0 without flat curves.
    flat_blind: f32,
}

impl Tracer {
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether `view` may render this scene as built ([`ViewDependent::holds_for`]).
    pub fn serves(&self, view: &DetailView) -> bool {
        self.view.holds_for(&self.scene, view)
    }

    /// The strand table of curves `geom_id`.
    pub fn strands(&self, geom_id: u32) -> Option<&StrandIndex> {
        match self.tables.get(geom_id as usize)? {
            Table::Curves { strands, .. } => Some(strands),
            Table::Mesh { .. } => None,
        }
    }

    /// Heap bytes hairtrace holds for the scene (buffers and tables; not Embree's BVH).
    #[cfg(any(test, feature = "bench-internals"))]
    pub fn heap_bytes(&self) -> usize {
        let tables: usize = self
            .tables
            .iter()
            .map(|t| match t {
                Table::Curves { strands, truth } => {
                    strands.heap_bytes() + truth.as_ref().map_or(0, |t| t.heap_bytes())
                }
                Table::Mesh { normals } => normals.as_ref().map_or(0, |n| n.capacity() * 12),
            })
            .sum();
        self.scene.heap_bytes() + tables
    }

    /// The closest hit along `ray` (one that leaves no hit: a camera ray), as a full hit
    /// record.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let hit = self.scene.intersect(ray, None)?;
        self.record(ray, &hit)
    }

    /// The ray that continues a path from `from` along `dir` up to `tfar`, leaving the fiber
    /// the default way ([`Escape::ExitAndFilter`]).
    pub fn spawn(&self, from: &Hit, dir: Vec3, tfar: f32) -> SpawnedRay {
        self.spawn_with(from, dir, tfar, Escape::default())
    }

    /// As [`Self::spawn`], with the given escape strategy for hair hits. Surface hits always
    /// offset the origin along the normal.
    pub fn spawn_with(&self, from: &Hit, dir: Vec3, tfar: f32, escape: Escape) -> SpawnedRay {
        let (p, ng) = match from {
            Hit::Hair(h) => (h.p, h.ng),
            Hit::Surface(s) => (s.p, s.ng),
        };
        let side = if dir.dot(ng) >= 0.0 { ng } else { -ng };
        let ulps = OFFSET_ULPS * p.abs().max_element().max(from.t());
        // The origin, and how far along the ray it was moved (the ray's end stays put).
        let (org, advance, exclude) = match (from, escape) {
            (Hit::Surface(_), _) => (p + side * ulps, 0.0, None),
            #[cfg(any(test, feature = "bench-internals"))]
            (Hit::Hair(h), Escape::Offset) => {
                (p + side * (OFFSET_RADII * h.radius + ulps), 0.0, None)
            }
            #[cfg(any(test, feature = "bench-internals"))]
            (Hit::Hair(h), Escape::OffsetAndFilter) => (
                p + side * (OFFSET_RADII * h.radius + ulps),
                0.0,
                self.exclusion(h, dir),
            ),
            (Hit::Hair(h), Escape::ExitAndFilter) => {
                let exclude = self.exclusion(h, dir);
                match (exit_distance(h, dir), exclude) {
                    (Some(t), Some(ex)) => (
                        p + dir * t,
                        t,
                        Some(Exclude {
                            max_t: ex.max_t - t,
                            ..ex
                        }),
                    ),
                    _ => (p + side * (OFFSET_RADII * h.radius + ulps), 0.0, exclude),
                }
            }
            #[cfg(any(test, feature = "bench-internals"))]
            (Hit::Hair(h), Escape::Filter) => (p, 0.0, self.exclusion(h, dir)),
        };
        // Started behind its origin by Embree's blind distance for flat curves, in units of
        // `dir`, so that every hit past the origin is one Embree reports.
        let back = self.flat_blind / dir.length();
        let back = if back.is_finite() { back } else { 0.0 };
        SpawnedRay {
            ray: Ray {
                org: org - dir * back,
                dir,
                tnear: back,
                // A target nearer than the fibre's far wall leaves nothing to test.
                tfar: (tfar - advance).max(0.0) + back,
                mask: u32::MAX,
                time: from.time(),
            },
            exclude: exclude.map(|ex| Exclude {
                max_t: ex.max_t + back,
                ..ex
            }),
        }
    }

    #[cfg(any(test, feature = "bench-internals"))]
    pub fn intersect_spawned(&self, s: &SpawnedRay) -> Option<Hit> {
        let hit = self.find_spawned(s)?;
        self.record_spawned(s, &hit)
    }

    /// The closest hit of `s` as Embree reports it: a path may end there, by roulette,
    /// without paying for the hit record.
    pub fn find_spawned(&self, s: &SpawnedRay) -> Option<RayHit> {
        self.scene.intersect(&s.ray, s.exclude.as_ref())
    }

    /// The full hit record of `hit`, which `find_spawned(s)` returned.
    pub fn record_spawned(&self, s: &SpawnedRay, hit: &RayHit) -> Option<Hit> {
        self.record(&s.ray, hit)
    }

    pub fn occluded_spawned(&self, s: &SpawnedRay) -> bool {
        self.scene.occluded(&s.ray, s.exclude.as_ref())
    }

    /// The segments of the hit's strand a ray along `dir` may cross before it is out of the
    /// tube, and how far along the ray that can take.
    fn exclusion(&self, h: &HairHit, dir: Vec3) -> Option<Exclude> {
        let Some(Geometry::Curves(geom)) = self.scene.geometry(h.geom_id) else {
            return None;
        };
        let len = dir.length();
        let sine = (dir.cross(h.frame.x).length() / len).max(MIN_EXIT_SINE);
        let reach = EXIT_RADII * h.radius / sine;
        // Segments that distance can span, from the length of this one (at least its
        // neighbours on each side, for the joints).
        let chord = segment_chord(geom, h.prim_id, h.time);
        let k = if chord > 0.0 {
            ((reach / chord).ceil() as u32).saturating_add(1)
        } else {
            h.strand.segments
        };
        let prims = h.strand.prims();
        Some(Exclude {
            geom_id: h.geom_id,
            first_prim: h.prim_id.saturating_sub(k).max(prims.start),
            last_prim: h.prim_id.saturating_add(k).min(prims.end - 1),
            max_t: reach / len,
        })
    }

    fn record(&self, ray: &Ray, hit: &RayHit) -> Option<Hit> {
        let p = ray.point_at(hit.t);
        match (
            self.scene.geometry(hit.geom_id)?,
            self.tables.get(hit.geom_id as usize)?,
        ) {
            (Geometry::Curves(geom), Table::Curves { strands, truth }) => {
                let at = strands.locate(hit.prim_id)?;
                let hair = hair_hit(ray, hit, p, geom, strands, at, truth.as_deref())?;
                Some(Hit::Hair(hair))
            }
            (Geometry::Triangles(geom), Table::Mesh { normals }) => Some(Hit::Surface(
                surface_hit(hit, p, ray.time, geom, normals.as_deref())?,
            )),
            _ => None,
        }
    }
}

/// How far along `dir` (in its units) a ray from a hair hit travels inside the fiber,
/// plus the offset margin, from the cylinder tangent to the tube at the hit. `None` when
/// the ray leaves at once (reflected) or runs along the axis (no finite exit).
fn exit_distance(h: &HairHit, dir: Vec3) -> Option<f32> {
    let x = h.frame.x;
    let across = |v: Vec3| v - v.dot(x) * x;
    let (w, e) = (across(h.p - h.axis), across(dir));
    let (a, b) = (e.dot(e), 2.0 * w.dot(e));
    if b >= 0.0 || a <= 0.0 {
        return None;
    }
    let c = w.dot(w) - h.radius * h.radius;
    let far = (-b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
    let t = far + OFFSET_RADII * h.radius / a.sqrt();
    t.is_finite().then_some(t)
}

fn hair_hit(
    ray: &Ray,
    hit: &RayHit,
    p: Vec3,
    geom: &CurveGeometry,
    strands: &StrandIndex,
    at: StrandSegment,
    truth: Option<&TrueCurves>,
) -> Option<HairHit> {
    let flat_cubic = geom.shape() == CurveShape::Flat && geom.basis() != CurveBasis::Linear;
    // Curves in motion are shaded where the ray met them: at its time.
    let time = ray.time;
    let (u, c) = if flat_cubic {
        project_onto_axis(geom, hit.prim_id, hit.u, p, time)?
    } else {
        (hit.u, geom.interpolate(hit.prim_id, hit.u, time)?)
    };
    let axis = Vec3::from_array(c.p);
    // A polyline's hit takes the true curve's tangent, position, colour and normal there.
    let on_curve = truth.and_then(|t| {
        let first = *geom.indices().get(hit.prim_id as usize)?;
        let (seg, cu) = t.locate(at.strand, first, u)?;
        let (absorption, normal) = (t.absorption(&seg, cu), t.normal(&seg, cu));
        Some((t.derivative(&seg, cu)?, seg.s(cu), absorption, normal))
    });
    let (tangent, s, absorption, normal) = match on_curve {
        Some((d, s, absorption, normal)) => (
            Some(d)
                .filter(|d| usable(*d, c.radius))
                .unwrap_or_else(|| tangent(geom, hit.prim_id, Vec3::ZERO, c.radius, &at, time)),
            s,
            absorption,
            normal,
        ),
        None => (
            tangent(
                geom,
                hit.prim_id,
                Vec3::from_array(c.dp_du),
                c.radius,
                &at,
                time,
            ),
            at.s(u),
            strands.absorption(&at, u),
            strands.normal(&at, u),
        ),
    };
    let (frame, h) = hair_frame(tangent, ray.dir, ray.org, axis, c.radius);
    // Embree tessellates a cubic ribbon into a few flat quads per segment, which stray from
    // the true curve by up to about a radius where a thin fibre bends: the offset from the
    // true curve then piles hits up at |h| = 1, where Fresnel reflects everything, and the
    // hair shades too bright. The offset across the quad struck (-v) is spread over what
    // the ribbon covers as h is over a tube's width; the axis moves with it, to the quad's
    // centreline, so that a ray's way through the fibre agrees (docs/measurements.md,
    // "Curve shapes"). The frame still follows the true curve.
    let (h, axis) = match flat_cubic {
        true => {
            let h = (-hit.v).clamp(-1.0, 1.0);
            (h, p - frame.y * (h * c.radius))
        }
        false => (h, axis),
    };
    // A ribbon is struck on its midplane, up to a radius behind where the tube's surface
    // would be; rays leaving from there started inside clumps the tube keeps them out of,
    // and dense hair shaded too dark (docs/measurements.md, "Ribbons' quads at the
    // silhouette"). The hit moves to where the ray enters the tube around the axis.
    let (t, p) = match geom.shape() {
        CurveShape::Flat => tube_entry(ray, hit.t, p, axis, frame.x, c.radius),
        CurveShape::Round => (hit.t, p),
    };
    let ng = match geom.shape() {
        CurveShape::Round => hit.ng.try_normalize().unwrap_or(frame.z),
        // Embree reports the tangent as Ng of flat curves; the ribbon faces the ray.
        CurveShape::Flat => frame.z,
    };
    Some(HairHit {
        t,
        p,
        ng,
        frame,
        h,
        axis,
        radius: c.radius,
        shape: geom.shape(),
        geom_id: hit.geom_id,
        prim_id: hit.prim_id,
        u,
        v: hit.v,
        strand: at,
        s,
        absorption,
        normal,
        time,
    })
}

/// Where `ray`, which met a ribbon at `t` (point `p`), enters the cylinder of `radius`
/// around the line through `axis` along unit `x`: its distance and point. At most
/// [`TUBE_ENTRY_RADII`] radii before `p`, since a ray near the axis's direction runs long
/// inside a straight cylinder where the strand bends away; `p` itself when it is on or
/// outside the cylinder.
fn tube_entry(ray: &Ray, t: f32, p: Vec3, axis: Vec3, x: Vec3, radius: f32) -> (f32, Vec3) {
    let across = |v: Vec3| v - v.dot(x) * x;
    let (w, e) = (across(p - axis), across(ray.dir));
    let (a, b, c) = (e.dot(e), 2.0 * w.dot(e), w.dot(w) - radius * radius);
    if a <= 0.0 || c >= 0.0 {
        return (t, p);
    }
    let entry = (-b - (b * b - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a);
    let back = entry.max(-TUBE_ENTRY_RADII * radius / ray.dir.length());
    if back.is_finite() && back < 0.0 {
        (t + back, p + ray.dir * back)
    } else {
        (t, p)
    }
}

/// Newton steps on the closest point of the segment's axis to `p`, from Embree's u.
///
/// A flat cubic curve is intersected as a few ray-facing quads per segment, so Embree's u
/// is the parameter along a quad, up to ~1e-3 rad of tangent away from the point of the
/// curve the hit belongs to; two steps bring it to f32 precision.
fn project_onto_axis(
    geom: &CurveGeometry,
    prim: u32,
    u: f32,
    p: Vec3,
    time: f32,
) -> Option<(f32, CurvePoint)> {
    let mut u = u;
    let mut c = geom.interpolate(prim, u, time)?;
    for _ in 0..2 {
        let (q, d1, d2) = (
            Vec3::from_array(c.p) - p,
            Vec3::from_array(c.dp_du),
            Vec3::from_array(c.d2p_du2),
        );
        let slope = d1.dot(d1) + q.dot(d2);
        if slope.is_nan() || slope <= 0.0 {
            break;
        }
        u = (u - q.dot(d1) / slope).clamp(0.0, 1.0);
        c = geom.interpolate(prim, u, time)?;
    }
    Some((u, c))
}

/// A derivative shorter than this fraction of the radius is a cusp or a repeated point.
const DEGENERATE_DERIVATIVE: f32 = 1e-6;

/// Whether `t` can serve as a tangent at a point of radius `radius`.
fn usable(t: Vec3, radius: f32) -> bool {
    t.is_finite() && t.length() > DEGENERATE_DERIVATIVE * radius.max(0.0)
}

/// The curve tangent at the hit: the segment direction for linear curves, the derivative
/// for cubic ones; where that vanishes, the chord of the segment, then of its neighbours
/// (nearest first) in the same strand, all at `time`. Zero only when the whole strand is
/// one point.
fn tangent(
    geom: &CurveGeometry,
    prim: u32,
    derivative: Vec3,
    radius: f32,
    at: &StrandSegment,
    time: f32,
) -> Vec3 {
    let first = if geom.basis() == CurveBasis::Linear {
        chord(geom, prim, time)
    } else {
        derivative
    };
    if usable(first, radius) {
        return first;
    }
    let prims = at.prims();
    (0..at.segments)
        .flat_map(|k| [prim.checked_sub(k), prim.checked_add(k)])
        .flatten()
        .filter(|q| prims.contains(q))
        .map(|q| chord(geom, q, time))
        .find(|&t| t.is_finite() && t != Vec3::ZERO)
        .unwrap_or(Vec3::ZERO)
}

/// Start-to-end vector of segment `prim` at `time`: v1 - v0 for linear curves, from the
/// curve itself for cubic ones.
fn chord(geom: &CurveGeometry, prim: u32, time: f32) -> Vec3 {
    if geom.basis() == CurveBasis::Linear {
        let Some(&first) = geom.indices().get(prim as usize) else {
            return Vec3::ZERO;
        };
        let p = |i: u32| {
            geom.point_at(i as usize, time)
                .unwrap_or(Vec4::ZERO)
                .truncate()
        };
        return p(first + 1) - p(first);
    }
    let end = |u| {
        geom.interpolate(prim, u, time)
            .map_or(Vec3::ZERO, |c| Vec3::from_array(c.p))
    };
    end(1.0) - end(0.0)
}

/// Approximate segment length from its control points at `time`, for neighbour counts
/// only.
fn segment_chord(geom: &CurveGeometry, prim: u32, time: f32) -> f32 {
    let Some(&first) = geom.indices().get(prim as usize) else {
        return 0.0;
    };
    let (a, b) = match geom.basis() {
        CurveBasis::Linear => (first, first + 1),
        CurveBasis::BSpline | CurveBasis::CatmullRom => (first + 1, first + 2),
        CurveBasis::Bezier => (first, first + 3),
    };
    let p = |i: u32| {
        geom.point_at(i as usize, time)
            .unwrap_or(Vec4::ZERO)
            .truncate()
    };
    p(a).distance(p(b))
}

fn surface_hit(
    hit: &RayHit,
    p: Vec3,
    time: f32,
    geom: &TriangleGeometry,
    normals: Option<&[[f32; 3]]>,
) -> Option<SurfaceHit> {
    let tri = geom.triangles().get(hit.prim_id as usize)?;
    // A mesh that deforms is where the ray's time puts it.
    let pos = |i: usize| geom.vertex_at(tri[i] as usize, time).unwrap_or(Vec3::ZERO);
    let ng = (pos(1) - pos(0))
        .cross(pos(2) - pos(0))
        .try_normalize()
        .or_else(|| hit.ng.try_normalize())
        .unwrap_or(Vec3::Z);
    let ns = normals
        .and_then(|n| {
            let at = |i: usize| Vec3::from_array(n[tri[i] as usize]);
            (at(0) * (1.0 - hit.u - hit.v) + at(1) * hit.u + at(2) * hit.v).try_normalize()
        })
        .map_or(ng, |ns| if ns.dot(ng) < 0.0 { -ns } else { ns });
    Some(SurfaceHit {
        t: hit.t,
        p,
        ng,
        ns,
        geom_id: hit.geom_id,
        prim_id: hit.prim_id,
        u: hit.u,
        v: hit.v,
        time,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Strands;
    use crate::scene::material::HairColor;

    fn tracer(curves: Curves) -> Tracer {
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
        b.add_curves(curves).unwrap();
        b.build().unwrap()
    }

    fn geometry(t: &Tracer) -> &CurveGeometry {
        match t.scene().geometry(0) {
            Some(Geometry::Curves(g)) => g,
            _ => panic!("no curves"),
        }
    }

    #[test]
    fn zero_derivatives_fall_back_to_the_chord_then_the_neighbours() {
        // Tripled B-spline ends: the derivative at the root is exactly zero.
        let pts = [0.0f32, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0].map(|x| [x, 0.0, 0.0, 0.1]);
        let t = tracer(
            Curves::from_control_points(
                pts.to_vec(),
                &[7],
                None,
                CurveBasis::BSpline,
                CurveShape::Round,
            )
            .unwrap(),
        );
        let g = geometry(&t);
        let at = t.strands(0).unwrap().locate(0).unwrap();
        let root = g.interpolate(0, 0.0, 0.0).unwrap();
        assert_eq!(root.dp_du, [0.0; 3]);
        let x = tangent(g, 0, Vec3::from_array(root.dp_du), root.radius, &at, 0.0);
        assert!(x.normalize().dot(Vec3::X) > 1.0 - 1e-6, "{x}");

        // A zero-length first segment of a linear strand takes its neighbour's direction.
        let pts = [0.0f32, 0.0, 1.0, 2.0].map(|x| [x, 0.0, 0.0, 0.1]);
        let t = tracer(
            Curves::from_control_points(
                pts.to_vec(),
                &[4],
                None,
                CurveBasis::Linear,
                CurveShape::Round,
            )
            .unwrap(),
        );
        let at = t.strands(0).unwrap().locate(0).unwrap();
        let x = tangent(geometry(&t), 0, Vec3::ZERO, 0.1, &at, 0.0);
        assert_eq!(x.normalize(), Vec3::X);

        // A strand that is a single point has no tangent; the frame copes (see hit.rs).
        let t = tracer(
            Curves::from_control_points(
                vec![[1.0, 2.0, 3.0, 0.1]; 3],
                &[3],
                None,
                CurveBasis::Linear,
                CurveShape::Flat,
            )
            .unwrap(),
        );
        let at = t.strands(0).unwrap().locate(1).unwrap();
        assert_eq!(
            tangent(geometry(&t), 1, Vec3::ZERO, 0.1, &at, 0.0),
            Vec3::ZERO
        );
    }

    #[test]
    fn a_ray_moved_past_the_far_wall_still_ends_at_its_target() {
        // A thick fibre along x, hit from +z at its axis; a mesh 0.3 below the axis.
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
        let pts = [-1.0f32, 1.0].map(|x| [x, 0.0, 0.0, 0.1]);
        b.add_curves(
            Curves::from_control_points(
                pts.to_vec(),
                &[2],
                None,
                CurveBasis::Linear,
                CurveShape::Round,
            )
            .unwrap(),
        )
        .unwrap();
        let floor = Mesh::new(
            vec![[-2.0, -2.0, -0.3], [2.0, -2.0, -0.3], [0.0, 2.0, -0.3]],
            vec![[0, 1, 2]],
            None,
        )
        .unwrap();
        b.add_mesh(floor).unwrap();
        let t = b.build().unwrap();
        let hit = t
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z))
            .unwrap();
        assert!((hit.p().z - 0.1).abs() < 1e-4, "{}", hit.p());
        // A light point 0.25 below the hit, between the far wall (0.2) and the mesh (0.4).
        let target = hit.p() - 0.25 * Vec3::Z;
        let s = t.spawn(&hit, -Vec3::Z, 0.25);
        let end = s.ray.org + s.ray.dir * s.ray.tfar;
        assert!(
            end.distance(target) < 1e-5,
            "ray ends at {end}, not {target}"
        );
        assert!(s.ray.org.z < -0.099, "the exit point is past the far wall");
        assert!(!t.occluded_spawned(&s), "the mesh lies beyond the light");
        // Beyond the mesh, the same ray is blocked.
        assert!(t.occluded_spawned(&t.spawn(&hit, -Vec3::Z, 0.5)));
    }

    #[test]
    fn rays_leaving_a_surface_at_the_world_origin_do_not_hit_it_again() {
        // A floor through the origin, seen from 5 units away: the hit points are tiny
        // numbers with the error of the ray that found them, which an offset relative to
        // the position alone would not clear.
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
        let floor = Mesh::new(
            vec![[-3.0, 0.0, -3.0], [3.0, 0.0, -3.0], [0.0, 0.0, 3.0]],
            vec![[0, 2, 1]],
            None,
        )
        .unwrap();
        b.add_mesh(floor).unwrap();
        let t = b.build().unwrap();
        let eye = Vec3::new(0.3, 4.0, 3.0);
        let mut blocked = 0;
        for i in 0..4096 {
            // Targets within 1e-5 of the origin.
            let k = i as f32;
            let target = Vec3::new((k * 0.37).sin(), 0.0, (k * 0.91).cos()) * 1e-5;
            let hit = t
                .intersect(&Ray::new(eye, (target - eye).normalize()))
                .unwrap();
            let up = Vec3::new(0.2, 1.0, -0.4).normalize();
            blocked += usize::from(t.occluded_spawned(&t.spawn(&hit, up, f32::INFINITY)));
        }
        assert_eq!(blocked, 0, "{blocked} of 4096 rays hit the floor they left");
    }

    #[test]
    fn meshes_trace_with_shading_normals() {
        let device = Arc::new(Device::new(Some(1)).unwrap());
        let mut b = TracerBuilder::new(device, SceneOptions::default()).unwrap();
        let mesh = Mesh::new(
            vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
            Some(vec![[0.0, 0.0, -1.0]; 3]),
        )
        .unwrap();
        let id = b.add_mesh(mesh).unwrap();
        let t = b.build().unwrap();
        let hit = t
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z))
            .unwrap();
        let Hit::Surface(s) = hit else {
            panic!("expected a surface hit")
        };
        assert_eq!((s.geom_id, s.prim_id), (id, 0));
        assert!((s.t - 5.0).abs() < 1e-5);
        assert_eq!(s.ng, Vec3::Z);
        // The vertex normals point the other way: flipped into the geometric hemisphere.
        assert_eq!(s.ns, Vec3::Z);
        // Hair-only rays pass through.
        let hair_only = Ray {
            mask: HAIR_MASK,
            ..Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z)
        };
        assert!(t.intersect(&hair_only).is_none());
        assert!(t.occluded_spawned(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).into()));
        let spawned = t.spawn(&hit, Vec3::Z, f32::INFINITY);
        assert!(t.intersect_spawned(&spawned).is_none());
    }

    /// Two bent strands (0.05 rad per segment) with colours, as level-of-detail
    /// polylines of the second alone, against Embree's own flat ribbons of both, every
    /// basis: the same strand number, the true curve's tangent (within 1e-3 rad inside the
    /// pieces, a fifth of a segment's turn where a ray meets a joint, where the chords are
    /// up to half a piece's turn off), its position along the strand and its colour.
    #[test]
    fn polylines_shade_with_the_true_curves_tangent_position_and_colour() {
        use crate::scene::camera::Camera;
        use crate::scene::lod;
        const TURN: f32 = 0.05;
        const RADIUS: f32 = 1e-3;
        // Straight for four segments of 0.05, then bending TURN per segment.
        let mut arc = vec![[0.0f32; 3]];
        for i in 0..8 {
            let (a, [x, y, _]) = (TURN * (i as f32 - 3.0).max(0.0), arc[i]);
            arc.push([x + 0.05 * a.cos(), y + 0.05 * a.sin(), 0.0]);
        }
        let points: Vec<[f32; 3]> = (0..18).map(|i| arc[i % 9]).collect();
        let strands = Strands {
            radii: vec![RADIUS; points.len()],
            colors: Some((0..18).map(|i| [(i % 9) as f32 / 8.0, 0.2, 1.0]).collect()),
            counts: vec![9, 9],
            points,
        };
        // A pixel 4 radii wide at the strand: thin; a tolerance of a tenth of a pixel.
        let camera = Camera::new(Vec3::new(0.2, 0.1, 5.0), -Vec3::Z, Vec3::Y, 30.0, 1.0).unwrap();
        let height = (camera.pixel_spread(1) * 5.0 / (4.0 * RADIUS)) as u32;
        for basis in [
            CurveBasis::CatmullRom,
            CurveBasis::BSpline,
            CurveBasis::Bezier,
        ] {
            let curves = Curves::from_strands(&strands, basis, CurveShape::Flat).unwrap();
            let second = curves
                .subset(&[false, true], CurveShape::Flat)
                .unwrap()
                .unwrap();
            let lines = lod::polylines(second, &camera, height, 0.1)
                .unwrap()
                .0
                .unwrap();
            // The straight segments are one piece: s and the colours are not the pieces'.
            let pieces = lines.strands().segment_count();
            assert!(pieces < 8, "{basis:?}: {pieces} pieces");
            let (exact, fast) = (tracer(curves), tracer(lines));
            let (mut inside, mut joints, mut worst_chord) = (0.0f32, 0.0f32, 0.0f32);
            let (mut worst_s, mut worst_color) = (0.0f32, 0.0f32);
            for k in 0..40 {
                // Rays across the second strand's curve, from +z.
                let t = 0.05 + 0.0225 * k as f32 * 8.0;
                let prim = 8 + (t as u32).min(7);
                let on = geometry(&exact)
                    .interpolate(prim, t.fract(), 0.0)
                    .unwrap()
                    .p;
                let across = 0.5 * RADIUS * ((k % 7) as f32 / 3.0 - 1.0);
                let ray = Ray::new(Vec3::from_array(on) + Vec3::new(0.0, across, 5.0), -Vec3::Z);
                let (Some(Hit::Hair(e)), Some(Hit::Hair(f))) =
                    (exact.intersect(&ray), fast.intersect(&ray))
                else {
                    panic!("{basis:?}: ray {k} missed");
                };
                assert_eq!((e.strand.id, f.strand.id), (1, 1), "{basis:?}");
                let angle = f.frame.x.angle_between(e.frame.x);
                if f.u > 0.0 && f.u < 1.0 {
                    inside = inside.max(angle);
                } else {
                    joints = joints.max(angle);
                }
                let chord = chord(geometry(&fast), f.prim_id, 0.0).normalize();
                worst_chord = worst_chord.max(chord.angle_between(e.frame.x));
                worst_s = worst_s.max((f.s - e.s).abs());
                let colour = |h: &HairHit| match h.absorption {
                    Some(HairColor::Color(c)) => c,
                    other => panic!("a colour, not {other:?}"),
                };
                let (ce, cf) = (colour(&e), colour(&f));
                worst_color = worst_color.max((ce[0] - cf[0]).abs());
            }
            assert!(
                inside < 1e-3,
                "{basis:?}: tangent {inside} rad from Embree's"
            );
            assert!(
                joints < 0.2 * TURN,
                "{basis:?}: tangent {joints} rad from Embree's at a joint"
            );
            assert!(
                worst_chord > 10.0 * inside.max(1e-4),
                "{basis:?}: chords only {worst_chord} rad off"
            );
            // s and the colour run 1/8 per segment: 2.5e-3 is a fiftieth of a segment, about
            // where a ray half a radius off the axis meets the ribbon rather than the tube.
            assert!(worst_s < 2.5e-3, "{basis:?}: s {worst_s} off");
            assert!(worst_color < 2.5e-3, "{basis:?}: colour {worst_color} off");
        }
    }
}
