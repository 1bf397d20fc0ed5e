//! Curves from host data: the control points, index buffer and per-strand tables that turn
//! strands into one Embree curve geometry.
//!
//! Two ways in:
//! - [`Curves::from_strands`] treats each strand as a polyline through its points and
//!   converts it for the chosen basis, so that every basis draws a curve from the root
//!   point to the tip point, with one curve segment per polyline segment:
//!   - linear: the points themselves;
//!   - Catmull-Rom and B-spline: the points plus one phantom point at each end, the end
//!     point reflected through its neighbour (`2 p0 - p1`). Reflection rather than a tripled
//!     end point, because a tripled B-spline end has a zero derivative (a cusp) at the root
//!     and tip, and this way both bases share one layout. The Catmull-Rom curve passes
//!     through every point; the B-spline curve passes through the root and the tip and
//!     smooths the points between (it is the polyline read as B-spline control points);
//!   - Bezier: the Catmull-Rom curve above, each segment converted to its exact Bezier
//!     form (inner control points `p_i + (p_{i+1} - p_{i-1}) / 6` and
//!     `p_{i+1} - (p_{i+2} - p_i) / 6`), consecutive segments sharing end points.
//! - [`Curves::from_control_points`] takes float4 (x, y, z, radius) control points already
//!   laid out for the basis and hands them to Embree without copying them: a `Vec` given
//!   away, an `Arc<[[f32; 4]]>` shared (safe, for hosts that keep their points), or a host's
//!   array under the contract of [`SharedBuffer::from_raw_parts`] (the C ABI). Only the
//!   index buffer (4 bytes per segment, plus 16 of padding) and the strand table are built.
//!
//! Either way, attributes survive to the hit through [`StrandIndex`]: the strand of a
//! primitive (a prefix table of segment counts, 4 bytes per strand rather than 4 per
//! segment), the position s along the strand (root 0, tip 1, uniform in the segment
//! parameter) and the groom's optional absorption: a colour per polyline point,
//! interpolated linearly, or a melanin pair per strand ([`Curves::with_melanin`]), kept as
//! given so that the material converts it once, at the hit; and the groom's optional curve
//! normals ([`Curves::with_normals`]), a direction per polyline point, which orient an
//! elliptical fibre's section.
//!
//! `Curves::polylines` lays flat linear ribbons over points sampled on other curves (the
//! level of detail of `lod.rs`); [`TrueCurves`] keeps those curves, so that the ribbons'
//! hits take the true curve's tangent, position along the strand and colour.

use std::ops::Range;
use std::sync::Arc;

use glam::{Vec3, Vec4};

use super::ragged;
use crate::bsdf::sigma_a_from_melanin;
use crate::embree::{
    CurveBasis, CurveShape, DEFAULT_RIBBON_QUADS, MAX_TIME_STEPS, PartsCache, SharedBuffer,
    centroid, morton_order, padding_for,
};
use crate::error::{Result, invalid_arg};
use crate::scene::Strands;
use crate::scene::material::HairColor;
use crate::validate;

/// Curves ready for Embree: control points, index buffer and strand table.
#[derive(Debug, Clone, PartialEq)]
pub struct Curves {
    basis: CurveBasis,
    shape: CurveShape,
    vertices: SharedBuffer<[f32; 4]>,
    /// The control points at the time steps after the first (`vertices`), spread evenly
    /// over the shutter ([`Curves::in_motion`]), laid out alike; empty for curves that do
    /// not move.
    later_steps: Vec<SharedBuffer<[f32; 4]>>,
    indices: SharedBuffer<u32>,
    strands: StrandIndex,
    /// The curves these `Curves::polylines` stand for.
    truth: Option<Arc<TrueCurves>>,
    /// Already in spatial order: [`Curves::spatially_ordered`] keeps them as they are.
    ordered: bool,
    /// The parts Embree's geometry over these curves was cut into, for the next one.
    parts: PartsCache,
    /// Quads per segment Embree intersects these curves in, when flat and cubic.
    ribbon_quads: u32,
}

/// Where a primitive sits in its strand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StrandSegment {
    pub strand: u32,
    /// Index of the segment within its strand, from the root.
    pub segment: u32,
    /// Segments in the strand.
    pub segments: u32,
    /// Primitive id of the strand's first segment.
    pub first_prim: u32,
    /// The strand's number in the groom it came from, which per-strand material variation
    /// and the strand AOV use: `strand`, unless the groom's strands were shared out between
    /// a round and a flat geometry (see [`Curves::subset`]).
    pub id: u32,
}

impl StrandSegment {
    /// Position along the strand at parameter u of this segment: root 0, tip 1.
    pub fn s(&self, u: f32) -> f32 {
        ((self.segment as f32 + u.clamp(0.0, 1.0)) / self.segments as f32).clamp(0.0, 1.0)
    }

    /// Primitive ids of the strand's segments.
    pub(crate) fn prims(&self) -> Range<u32> {
        self.first_prim..self.first_prim + self.segments
    }
}

/// Per-strand data kept next to the Embree geometry: which strand a primitive belongs to,
/// and the groom's optional absorption.
#[derive(Debug, Clone, PartialEq)]
pub struct StrandIndex {
    /// First segment of each strand, plus the total at the end.
    segment_starts: Vec<u32>,
    absorption: Option<GroomAbsorption>,
    /// The groom's curve normals at each segment end (segments + 1 per strand), strand
    /// after strand, as given (not unit, not yet perpendicular to the curve).
    normals: Option<Vec<[f32; 3]>>,
    /// Each strand's number in the groom it came from, when it is not its index here.
    ids: Option<Vec<u32>>,
    /// The strand of every [`COARSE`]-th segment: a lookup narrows to the strands of one
    /// block (one or two, usually) before searching, instead of searching all of them,
    /// which cost a cache miss per step on large grooms (5% of a fur ball's render).
    coarse: Vec<u32>,
}

/// A groom's absorption as its source said it.
#[derive(Debug, Clone, PartialEq)]
enum GroomAbsorption {
    /// Linear RGB reflectance at each polyline point (segments + 1 per strand), strand
    /// after strand.
    Colors(Vec<[f32; 3]>),
    /// (eumelanin, pheomelanin) of each strand.
    Melanin(Vec<[f32; 2]>),
}

/// Segments per block of [`StrandIndex::coarse`]: 1/8 byte per segment.
const COARSE: usize = 32;

impl StrandIndex {
    /// From segment counts per strand; `colors` must hold `segments + 1` entries per strand.
    fn new(segments: impl Iterator<Item = usize>, colors: Option<Vec<[f32; 3]>>) -> Result<Self> {
        let mut segment_starts = Vec::with_capacity(segments.size_hint().0 + 1);
        segment_starts.push(0u32);
        let mut total = 0u64;
        for n in segments {
            total += n as u64;
            let end = u32::try_from(total)
                .map_err(|_| invalid_arg!("more than {} curve segments", u32::MAX))?;
            segment_starts.push(end);
        }
        let mut coarse = Vec::with_capacity((total as usize).div_ceil(COARSE));
        let mut strand = 0;
        for first in (0..total as usize).step_by(COARSE) {
            while segment_starts[strand + 1] as usize <= first {
                strand += 1;
            }
            coarse.push(strand as u32);
        }
        if let Some(c) = &colors {
            let knots = total as usize + segment_starts.len() - 1;
            if c.len() != knots {
                return Err(invalid_arg!(
                    "{} colours for {knots} strand points (segments + 1 per strand)",
                    c.len()
                ));
            }
            validate::colors(c)?;
        }
        Ok(StrandIndex {
            segment_starts,
            absorption: colors.map(GroomAbsorption::Colors),
            normals: None,
            ids: None,
            coarse,
        })
    }

    pub fn strand_count(&self) -> usize {
        self.segment_starts.len() - 1
    }

    pub fn segment_count(&self) -> usize {
        *self.segment_starts.last().unwrap_or(&0) as usize
    }

    /// The strand and segment of primitive `prim` (a search among the strands of its block).
    pub fn locate(&self, prim: u32) -> Option<StrandSegment> {
        if prim as usize >= self.segment_count() {
            return None;
        }
        // The strand is between those of the block's first segment and the next block's.
        let block = prim as usize / COARSE;
        let lo = self.coarse[block] as usize;
        let hi = self
            .coarse
            .get(block + 1)
            .map_or(self.strand_count() - 1, |&s| s as usize);
        let strand = lo + self.segment_starts[lo + 1..=hi].partition_point(|&start| start <= prim);
        let first_prim = self.segment_starts[strand];
        self.segment(strand, prim - first_prim)
    }

    /// Segment `segment` of strand `strand` (the last one past it), without a search: a
    /// polyline hit, whose strand is known, reads one pair of starts instead of a block's
    /// and a search's cache lines (such chains of misses are a fifth of the white fur
    /// ball's render: docs/measurements.md).
    pub fn segment(&self, strand: usize, segment: u32) -> Option<StrandSegment> {
        let (&first_prim, &end) = (
            self.segment_starts.get(strand)?,
            self.segment_starts.get(strand + 1)?,
        );
        let segments = end.checked_sub(first_prim).filter(|&n| n > 0)?;
        Some(StrandSegment {
            strand: strand as u32,
            segment: segment.min(segments - 1),
            segments,
            first_prim,
            id: self.ids.as_ref().map_or(strand as u32, |ids| ids[strand]),
        })
    }

    /// The first segment of strand `strand`.
    pub fn first_segment(&self, strand: usize) -> Option<StrandSegment> {
        self.segment(strand, 0)
    }

    /// The groom's absorption at parameter u of segment `at`, if it gives one: the colour
    /// there (interpolated between the segment's ends) or the strand's melanin.
    pub fn absorption(&self, at: &StrandSegment, u: f32) -> Option<HairColor> {
        match self.absorption.as_ref()? {
            GroomAbsorption::Colors(colors) => Some(HairColor::Color(at_knots(colors, at, u)?)),
            GroomAbsorption::Melanin(m) => {
                let [eumelanin, pheomelanin] = *m.get(at.strand as usize)?;
                Some(HairColor::Melanin {
                    eumelanin,
                    pheomelanin,
                })
            }
        }
    }

    /// The groom's curve normal at parameter u of segment `at`, if it gives them:
    /// interpolated linearly between the segment's ends, as given (not unit).
    pub fn normal(&self, at: &StrandSegment, u: f32) -> Option<Vec3> {
        Some(Vec3::from_array(at_knots(self.normals.as_ref()?, at, u)?))
    }

    /// Heap bytes of the table.
    pub fn heap_bytes(&self) -> usize {
        self.segment_starts.capacity() * 4
            + self.normals.as_ref().map_or(0, |n| n.capacity() * 12)
            + match &self.absorption {
                Some(GroomAbsorption::Colors(c)) => c.capacity() * 12,
                Some(GroomAbsorption::Melanin(m)) => m.capacity() * 8,
                None => 0,
            }
            + self.ids.as_ref().map_or(0, |i| i.capacity() * 4)
            + self.coarse.capacity() * 4
    }
}

/// A per-segment-end value (segments + 1 per strand) at parameter u of segment `at`,
/// interpolated linearly between the segment's two ends.
fn at_knots(values: &[[f32; 3]], at: &StrandSegment, u: f32) -> Option<[f32; 3]> {
    // Each strand has one more end than segments: skip one per strand before.
    let k = (at.first_prim + at.strand + at.segment) as usize;
    let (a, b) = (values.get(k)?, values.get(k + 1)?);
    let u = u.clamp(0.0, 1.0);
    Some(std::array::from_fn(|c| a[c] + (b[c] - a[c]) * u))
}

/// Per-segment-end values (segments + 1 per strand) of the strands `order` names, in that
/// order, for curves whose strands start at segments `starts`.
fn gathered_knots(all: &[[f32; 3]], starts: &[u32], order: &[usize]) -> Result<Vec<[f32; 3]>> {
    let first = |s: usize| starts[s] as usize + s;
    let sizes = ragged::starts(order.iter().map(|&s| first(s + 1) - first(s)));
    ragged::filled(&sizes, 0, |i, out| {
        let s = order[i];
        out.copy_from_slice(&all[first(s)..first(s + 1)]);
    })
}

impl Curves {
    /// Converts strands (radii, not diameters) for `basis`; see the module notes for what
    /// each basis makes of the points. Copies the points once, into the buffer Embree reads,
    /// strands in parallel.
    pub fn from_strands(strands: &Strands, basis: CurveBasis, shape: CurveShape) -> Result<Self> {
        strands.validate()?;
        let phantom = usize::from(basis != CurveBasis::Linear);
        let per_strand = |n: usize| match basis {
            CurveBasis::Linear => n,
            CurveBasis::BSpline | CurveBasis::CatmullRom => n + 2,
            CurveBasis::Bezier => 3 * (n - 1) + 1,
        };
        let laid_out = ragged::starts(strands.counts.iter().map(|&n| per_strand(n as usize)));
        check_vertex_count(laid_out.last().copied().unwrap_or(0))?;
        let first_point = ragged::starts(strands.counts.iter().map(|&n| n as usize));
        let vertices = ragged::filled(&laid_out, padding_for::<[f32; 4]>(), |s, out| {
            let (start, n) = (first_point[s], strands.counts[s] as usize);
            let point = |i: usize| {
                let [x, y, z] = strands.points[start + i];
                [x, y, z, strands.radii[start + i]]
            };
            let reflect = |end: usize, next: usize| {
                let (a, b) = (point(end), point(next));
                std::array::from_fn::<f32, 4, _>(|c| 2.0 * a[c] - b[c])
            };
            // Extended points: index 0 is the root's phantom, n + 1 the tip's.
            let ext = |k: usize| match k {
                0 => reflect(0, 1),
                k if k == n + 1 => reflect(n - 1, n - 2),
                k => point(k - 1),
            };
            match basis {
                CurveBasis::Linear | CurveBasis::BSpline | CurveBasis::CatmullRom => {
                    for (k, o) in out.iter_mut().enumerate() {
                        *o = ext(k + 1 - phantom);
                    }
                }
                CurveBasis::Bezier => {
                    out[0] = ext(1);
                    for (i, o) in (1..n).zip(out[1..].chunks_exact_mut(3)) {
                        let cr = [ext(i - 1), ext(i), ext(i + 1), ext(i + 2)].map(Vec4::from);
                        let [_, b1, b2, end] = CurveBasis::CatmullRom.bezier_form::<Vec4, f32>(cr);
                        // Bernstein weights are positive: radii >= 0 at the control points
                        // keep the interpolated radius >= 0, as Embree requires.
                        let [b1, b2] = [b1, b2].map(|b| b.with_w(b.w.max(0.0)).to_array());
                        o.copy_from_slice(&[b1, b2, end.to_array()]);
                    }
                }
            }
        })?;
        Self::assembled(
            vertices.into(),
            &laid_out,
            strands.colors.clone(),
            basis,
            shape,
        )
    }

    /// Control points already laid out for `basis`, `counts[i]` of them for strand i, read by
    /// Embree where they are: an `Arc<[[f32; 4]]>` or a [`SharedBuffer`] of the host's memory
    /// is shared, never copied (its clones share it too); a `Vec` is moved in, with no copy
    /// when it has `padding_for::<[f32; 4]>()` spare capacity (one reallocation otherwise).
    /// `colors`, if any, holds one linear RGB value per segment end: segments + 1 per strand.
    pub fn from_control_points(
        vertices: impl Into<SharedBuffer<[f32; 4]>>,
        counts: &[u32],
        colors: Option<Vec<[f32; 3]>>,
        basis: CurveBasis,
        shape: CurveShape,
    ) -> Result<Self> {
        let vertices = vertices.into();
        let points = vertices.as_slice();
        let starts = ragged::starts(counts.iter().map(|&n| n as usize));
        let total = starts.last().copied().unwrap_or(0);
        if total != points.len() {
            return Err(invalid_arg!(
                "strand counts add up to {total} control points but {} are given",
                points.len()
            ));
        }
        check_vertex_count(points.len())?;
        validate::positions("control point", points)?;
        if let Some(i) = points
            .iter()
            .position(|v| !(v[3].is_finite() && v[3] >= 0.0))
        {
            return Err(invalid_arg!(
                "control point {i} = {:?}: must be finite with a radius >= 0",
                points[i]
            ));
        }
        Self::assembled(vertices, &starts, colors, basis, shape)
    }

    /// Curves over control points already checked, strand s's at `starts[s]..starts[s + 1]`
    /// ([`ragged::starts`]): their index buffer (each strand's in parallel) and strand table.
    fn assembled(
        vertices: SharedBuffer<[f32; 4]>,
        starts: &[usize],
        colors: Option<Vec<[f32; 3]>>,
        basis: CurveBasis,
        shape: CurveShape,
    ) -> Result<Self> {
        let count = |s: usize| starts[s + 1] - starts[s];
        let strands = starts.len().saturating_sub(1);
        if let Some(s) = (0..strands).find(|&s| basis.segments_for(count(s)).is_none()) {
            return Err(invalid_arg!(
                "strand {s} has {} control points, which is not a whole number of {basis:?} \
                 segments",
                count(s)
            ));
        }
        let segments = |s: usize| basis.segments_for(count(s)).unwrap_or(0);
        let stride = basis.segment_stride() as u32;
        let firsts = ragged::starts((0..strands).map(segments));
        let indices = ragged::filled(&firsts, padding_for::<u32>(), |s, out| {
            for (i, o) in (0u32..).zip(out) {
                *o = starts[s] as u32 + stride * i;
            }
        })?;
        Ok(Curves {
            basis,
            shape,
            vertices,
            later_steps: Vec::new(),
            indices: SharedBuffer::new(indices),
            strands: StrandIndex::new((0..strands).map(segments), colors)?,
            truth: None,
            ordered: false,
            parts: PartsCache::default(),
            ribbon_quads: DEFAULT_RIBBON_QUADS,
        })
    }

    /// Curves that move over the shutter: `steps[k]` are the curves at time step k of 1 to
    /// `MAX_TIME_STEPS`, spread evenly over it (step 0 where it opens, the last where it
    /// closes; `math::time_steps`). Every step must have the basis, the strands and each
    /// strand's number of control points of step 0, whose shape, colours or melanin and
    /// ribbon quads the curves keep (the points of each were checked when it was made).
    pub fn in_motion(steps: Vec<Curves>) -> Result<Curves> {
        if !(1..=MAX_TIME_STEPS).contains(&steps.len()) {
            return Err(invalid_arg!(
                "{} time steps: curves in motion take 1 to {MAX_TIME_STEPS}",
                steps.len()
            ));
        }
        if let Some(k) =
            (steps.iter()).position(|c| !c.later_steps.is_empty() || c.truth.is_some() || c.ordered)
        {
            return Err(invalid_arg!(
                "time step {k}: curves as made from points, not curves in motion, a level of \
                 detail or curves reordered"
            ));
        }
        let mut steps = steps.into_iter();
        let Some(mut first) = steps.next() else {
            return Err(invalid_arg!("no time steps"));
        };
        for (k, step) in (1..).zip(steps) {
            if step.basis != first.basis {
                return Err(invalid_arg!(
                    "time step {k} holds {:?} curves, time step 0 {:?}",
                    step.basis,
                    first.basis
                ));
            }
            let strands = first.strands.strand_count();
            if step.strands.strand_count() != strands {
                return Err(invalid_arg!(
                    "time step {k} has {} strands, time step 0 {strands}",
                    step.strands.strand_count()
                ));
            }
            let points = |c: &Curves, s| c.strand_points(s).len();
            if let Some(s) = (0..strands).find(|&s| points(&step, s) != points(&first, s)) {
                return Err(invalid_arg!(
                    "time step {k}: strand {s} has {} control points, at time step 0 {} (a \
                     strand keeps its points over the shutter)",
                    points(&step, s),
                    points(&first, s)
                ));
            }
            first.later_steps.push(step.vertices);
        }
        Ok(first)
    }

    /// The strands that `keep` marks (one flag per strand), copied into curves of their own
    /// with `shape`; each keeps its number here as its [`StrandSegment::id`], so that a
    /// groom shared out between shapes varies per strand as it would whole. None when no
    /// strand is kept.
    pub fn subset(&self, keep: &[bool], shape: CurveShape) -> Result<Option<Curves>> {
        if keep.len() != self.strands.strand_count() {
            return Err(invalid_arg!(
                "{} flags for {} strands",
                keep.len(),
                self.strands.strand_count()
            ));
        }
        let kept: Vec<usize> = (0..keep.len()).filter(|&s| keep[s]).collect();
        self.gathered(&kept, shape)
    }

    /// The same strands with those near one another in space near one another in memory
    /// too: ordered along a Morton curve through their control points' centroids. Each keeps
    /// its number here as its [`StrandSegment::id`]. Embree's build and traversal fetch the
    /// control points of neighbouring strands together, and a groom in another order (the
    /// bench scalp's roots follow a low-discrepancy sequence, so consecutive strands are far
    /// apart) misses the cache on each: on the bench scalp the build takes 0.76x the time
    /// at 2.5 x 10^5 strands and 0.6x-0.7x at 10^6 (docs/large-grooms.md). Control points
    /// the caller shares (a C host's memory, an `Arc` it made) are kept where they are, as
    /// are curves already in order (ordered here before, and kept: a C scene's rebuilds).
    pub fn spatially_ordered(mut self) -> Result<Curves> {
        let ours = self.vertices.is_ours() && self.later_steps.iter().all(SharedBuffer::is_ours);
        if self.ordered || !ours {
            return Ok(self);
        }
        let order = morton_order(self.strands.strand_count(), |s| {
            centroid(self.strand_points(s))
        })?;
        if !order.windows(2).all(|w| w[0] < w[1]) {
            let order: Vec<usize> = order.into_iter().map(|s| s as usize).collect();
            if let Some(ordered) = self.gathered(&order, self.shape)? {
                self = ordered;
            }
        }
        self.ordered = true;
        Ok(self)
    }

    /// The same curves, whose clones share the control points and the index buffer
    /// rather than copy them ([`SharedBuffer::into_shared`], no copy here): a C scene
    /// keeps its curves so, and hands each build a clone that costs no copy.
    pub fn shared(mut self) -> Curves {
        self.vertices = self.vertices.into_shared();
        self.later_steps = (self.later_steps.into_iter())
            .map(SharedBuffer::into_shared)
            .collect();
        self.indices = self.indices.into_shared();
        self
    }

    /// The strands `order` names, in that order, drawn with `shape`; each keeps its number
    /// here as its [`StrandSegment::id`]. None when `order` is empty. The points were checked
    /// when these curves were made: they are copied as they are, strands in parallel.
    fn gathered(&self, order: &[usize], shape: CurveShape) -> Result<Option<Curves>> {
        if order.is_empty() {
            return Ok(None);
        }
        let starts = &self.strands.segment_starts;
        let sizes = ragged::starts(order.iter().map(|&s| self.strand_points(s).len()));
        let vertices = ragged::filled(&sizes, padding_for::<[f32; 4]>(), |i, out| {
            out.copy_from_slice(self.strand_points(order[i]));
        })?;
        let later_steps = (1..self.time_steps())
            .map(|step| {
                ragged::filled(&sizes, padding_for::<[f32; 4]>(), |i, out| {
                    out.copy_from_slice(self.strand_points_at(order[i], step));
                })
                .map(SharedBuffer::from)
            })
            .collect::<Result<_>>()?;
        let colors = match &self.strands.absorption {
            Some(GroomAbsorption::Colors(all)) => Some(gathered_knots(all, starts, order)?),
            _ => None,
        };
        let mut part = Curves::assembled(vertices.into(), &sizes, colors, self.basis, shape)?;
        part.strands.normals = (self.strands.normals.as_ref())
            .map(|all| gathered_knots(all, starts, order))
            .transpose()?;
        if let Some(GroomAbsorption::Melanin(all)) = &self.strands.absorption {
            part = part.with_melanin(order.iter().map(|&s| all[s]).collect())?;
        }
        part.ribbon_quads = self.ribbon_quads;
        part.later_steps = later_steps;
        let ids = self.strands.ids.as_ref();
        part.strands.ids = Some(
            order
                .iter()
                .map(|&s| ids.map_or(s as u32, |i| i[s]))
                .collect(),
        );
        Ok(Some(part))
    }

    /// The control points strand `s` reads (`s` < the strand count), at the first time
    /// step.
    pub fn strand_points(&self, s: usize) -> &[[f32; 4]] {
        self.strand_points_at(s, 0)
    }

    /// The control points strand `s` reads at time step `step` (< [`Self::time_steps`]).
    pub fn strand_points_at(&self, s: usize, step: usize) -> &[[f32; 4]] {
        let starts = &self.strands.segment_starts;
        let first = self.indices();
        let start = first[starts[s] as usize] as usize;
        let end = first[starts[s + 1] as usize - 1] as usize + self.basis.points_per_segment();
        &self.step_vertices(step)[start..end]
    }

    /// The same curves with one (eumelanin, pheomelanin) pair per strand as the groom's
    /// absorption: a hair material with `use_vertex_colors` takes each strand's sigma_a
    /// from it as [`sigma_a_from_melanin`] gives it, with no colour in between. Each value
    /// must be finite and >= 0, and the curves must have no colours.
    pub fn with_melanin(mut self, melanin: Vec<[f32; 2]>) -> Result<Self> {
        if matches!(self.strands.absorption, Some(GroomAbsorption::Colors(_))) {
            return Err(invalid_arg!(
                "the curves have colours: give colours or melanin, not both"
            ));
        }
        let strands = self.strands.strand_count();
        if melanin.len() != strands {
            return Err(invalid_arg!(
                "{} melanin pairs for {strands} strands",
                melanin.len()
            ));
        }
        for (i, &[eumelanin, pheomelanin]) in melanin.iter().enumerate() {
            sigma_a_from_melanin(eumelanin, pheomelanin)
                .map_err(|e| e.context(format!("strand {i}")))?;
        }
        self.strands.absorption = Some(GroomAbsorption::Melanin(melanin));
        Ok(self)
    }

    /// The same curves with the groom's curve normals, one per segment end (segments + 1
    /// per strand, as colours are given): at a hit, the normal there made perpendicular to
    /// the curve is the major axis of an elliptical fibre's section (`HairHit::major_axis`).
    /// Each must be finite; their length does not matter.
    pub fn with_normals(mut self, normals: Vec<[f32; 3]>) -> Result<Self> {
        let knots = self.strands.segment_count() + self.strands.strand_count();
        if normals.len() != knots {
            return Err(invalid_arg!(
                "{} normals for {knots} strand points (segments + 1 per strand)",
                normals.len()
            ));
        }
        validate::positions("normal", &normals)?;
        self.strands.normals = Some(normals);
        Ok(self)
    }

    /// The same curves drawn with `shape`.
    pub fn with_shape(mut self, shape: CurveShape) -> Self {
        self.shape = shape;
        self
    }

    /// The same curves, which Embree intersects as `quads` ray-facing quads per segment
    /// when they are flat and cubic (`CurveGeometry::with_ribbon_quads`).
    pub fn with_ribbon_quads(mut self, quads: u32) -> Self {
        self.ribbon_quads = quads;
        self
    }

    pub fn ribbon_quads(&self) -> u32 {
        self.ribbon_quads
    }

    /// Flat linear ribbons through `points`, `counts[i]` of them for strand i of `truth`,
    /// each on the curve of `truth` at the parameter `params` gives it (segment index plus
    /// u, from the root; one per point). Their hits take the strand numbers, tangent,
    /// position along the strand and colours of `truth` ([`Self::truth`]).
    pub(crate) fn polylines(
        truth: Curves,
        points: Vec<[f32; 4]>,
        counts: &[u32],
        params: Vec<f32>,
    ) -> Result<Curves> {
        if truth.time_steps() > 1 {
            return Err(invalid_arg!(
                "polylines of curves in motion: a level of detail is of curves that stay put"
            ));
        }
        if counts.len() != truth.strands.strand_count() || params.len() != points.len() {
            return Err(invalid_arg!(
                "{} polylines of {} points with {} parameters for {} strands",
                counts.len(),
                points.len(),
                params.len(),
                truth.strands.strand_count()
            ));
        }
        let mut lines = Curves::from_control_points(
            points,
            counts,
            None,
            CurveBasis::Linear,
            CurveShape::Flat,
        )?;
        lines.strands.ids = truth.strands.ids.clone();
        lines.truth = Some(Arc::new(TrueCurves {
            curves: truth,
            params,
        }));
        Ok(lines)
    }

    /// The curves these `Self::polylines` stand for, if they are polylines.
    pub fn truth(&self) -> Option<&Arc<TrueCurves>> {
        self.truth.as_ref()
    }

    /// The polynomial of segment `prim` at the first time step.
    pub(crate) fn segment_curve(&self, prim: u32) -> Option<SegmentCurve> {
        self.segment_curve_at(prim, 0)
    }

    /// The polynomial of segment `prim` at time step `step`; `None` past the steps.
    pub(crate) fn segment_curve_at(&self, prim: u32, step: usize) -> Option<SegmentCurve> {
        let first = *self.indices().get(prim as usize)? as usize;
        let points =
            (self.steps().nth(step)?).get(first..first + self.basis.points_per_segment())?;
        Some(SegmentCurve::new(self.basis, points))
    }

    pub fn basis(&self) -> CurveBasis {
        self.basis
    }

    pub fn shape(&self) -> CurveShape {
        self.shape
    }

    /// Control points (x, y, z, radius) as Embree will read them, at the first time step.
    pub fn vertices(&self) -> &[[f32; 4]] {
        self.vertices.as_slice()
    }

    /// Time steps over the shutter ([`Self::in_motion`]): 1 for curves that do not move.
    pub fn time_steps(&self) -> usize {
        1 + self.later_steps.len()
    }

    /// The control points at time step `step` (< [`Self::time_steps`]), laid out as
    /// [`Self::vertices`].
    pub fn step_vertices(&self, step: usize) -> &[[f32; 4]] {
        match step {
            0 => self.vertices(),
            k => self.later_steps[k - 1].as_slice(),
        }
    }

    /// The control points at each time step, from the first.
    pub fn steps(&self) -> impl Iterator<Item = &[[f32; 4]]> {
        std::iter::once(&self.vertices)
            .chain(&self.later_steps)
            .map(SharedBuffer::as_slice)
    }

    /// First control point of each segment.
    pub fn indices(&self) -> &[u32] {
        self.indices.as_slice()
    }

    pub fn strands(&self) -> &StrandIndex {
        &self.strands
    }

    /// Heap bytes of everything hairtrace keeps for these curves (shared control points are
    /// their owner's, not counted).
    pub fn heap_bytes(&self) -> usize {
        self.vertices.heap_bytes()
            + (self.later_steps.iter())
                .map(SharedBuffer::heap_bytes)
                .sum::<usize>()
            + self.indices.heap_bytes()
            + self.strands.heap_bytes()
            + self.truth.as_ref().map_or(0, |t| t.heap_bytes())
    }

    /// Splits into the Embree buffers and the table that stays with the scene.
    pub(crate) fn into_parts(self) -> CurveParts {
        (
            self.basis,
            self.shape,
            std::iter::once(self.vertices)
                .chain(self.later_steps)
                .collect(),
            self.indices,
            self.strands,
            self.truth,
            self.parts,
        )
    }
}

/// What [`Curves::into_parts`] gives: basis, shape, the control points of each time step,
/// index buffer, the strand table, the true curves of a polyline and the cache of Embree's
/// parts.
pub(crate) type CurveParts = (
    CurveBasis,
    CurveShape,
    Vec<SharedBuffer<[f32; 4]>>,
    SharedBuffer<u32>,
    StrandIndex,
    Option<Arc<TrueCurves>>,
    PartsCache,
);

/// The curves that `Curves::polylines` stand for, and where each polyline point lies on
/// them.
#[derive(Debug, Clone, PartialEq)]
pub struct TrueCurves {
    curves: Curves,
    /// The curve parameter (segment index plus u, from the root) of each polyline point.
    params: Vec<f32>,
}

impl TrueCurves {
    pub fn curves(&self) -> &Curves {
        &self.curves
    }

    /// The curve parameter of each polyline point.
    pub fn params(&self) -> &[f32] {
        &self.params
    }

    /// The segment of the true curve, and its parameter, at parameter `u` of the polyline
    /// piece of strand `strand` that starts at polyline point `first`: the piece's
    /// parameter mapped linearly onto the curve's between its two points.
    pub fn locate(&self, strand: u32, first: u32, u: f32) -> Option<(StrandSegment, f32)> {
        let first = first as usize;
        let (a, b) = (*self.params.get(first)?, *self.params.get(first + 1)?);
        let t = a + u.clamp(0.0, 1.0) * (b - a);
        let at = self
            .curves
            .strands
            .segment(strand as usize, t.max(0.0) as u32)?;
        Some((at, (t - at.segment as f32).clamp(0.0, 1.0)))
    }

    /// The true curve's derivative at parameter `u` of segment `at`.
    pub fn derivative(&self, at: &StrandSegment, u: f32) -> Option<Vec3> {
        let curve = self.curves.segment_curve(at.first_prim + at.segment)?;
        Some(curve.derivative(u).truncate())
    }

    /// The true curve's colour at parameter `u` of segment `at`, if it has colours.
    pub fn absorption(&self, at: &StrandSegment, u: f32) -> Option<HairColor> {
        self.curves.strands.absorption(at, u)
    }

    /// The true curve's normal at parameter `u` of segment `at`, if it has normals.
    pub fn normal(&self, at: &StrandSegment, u: f32) -> Option<Vec3> {
        self.curves.strands.normal(at, u)
    }

    pub fn heap_bytes(&self) -> usize {
        self.curves.heap_bytes() + self.params.capacity() * 4
    }
}

/// One curve segment as the cubic c0 + c1 u + c2 u^2 + c3 u^3 in (x, y, z, radius), for
/// every basis from one table of coefficients ([`CurveBasis::power_matrix`]): what the
/// level of detail samples and its hits take their tangents from. (Embree evaluates the
/// same curves.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SegmentCurve([Vec4; 4]);

impl SegmentCurve {
    /// The segment of `basis` read from `points` (as many as one segment reads).
    pub(crate) fn new(basis: CurveBasis, points: &[[f32; 4]]) -> Self {
        let m = basis.power_matrix();
        SegmentCurve(std::array::from_fn(|k| {
            (points.iter().zip(m[k]))
                .map(|(p, w)| w as f32 * Vec4::from_array(*p))
                .sum()
        }))
    }

    /// Point (x, y, z) and radius (w) at `u`.
    pub(crate) fn at(&self, u: f32) -> Vec4 {
        let [c0, c1, c2, c3] = self.0;
        c0 + u * (c1 + u * (c2 + u * c3))
    }

    /// Derivative with respect to `u`.
    pub(crate) fn derivative(&self, u: f32) -> Vec4 {
        let [_, c1, c2, c3] = self.0;
        c1 + u * (2.0 * c2 + 3.0 * u * c3)
    }

    /// Second derivative with respect to `u`: linear in `u`, so its length over [0, 1] is
    /// largest at an end.
    pub(crate) fn second_derivative(&self, u: f32) -> Vec4 {
        let [_, _, c2, c3] = self.0;
        2.0 * c2 + 6.0 * u * c3
    }
}

/// Control points (x, y, z, radius) moved by `place`, radii multiplied by `radius_scale`:
/// a groom's control points where its scene entry puts them.
pub(crate) fn placed(
    points: &[[f32; 4]],
    place: impl Fn([f32; 3]) -> [f32; 3],
    radius_scale: f32,
) -> Vec<[f32; 4]> {
    points
        .iter()
        .map(|&[x, y, z, r]| {
            let [x, y, z] = place([x, y, z]);
            [x, y, z, r * radius_scale]
        })
        .collect()
}

/// Embree indexes control points with u32.
fn check_vertex_count(n: usize) -> Result<()> {
    if n > u32::MAX as usize {
        return Err(invalid_arg!(
            "{n} curve control points: at most {} fit Embree's 32-bit indices",
            u32::MAX
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn strands() -> Strands {
        Strands {
            points: vec![
                [0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 2.0, 1.0],
                [5.0, 0.0, 0.0],
                [5.0, 1.0, 0.0],
            ],
            radii: vec![0.1, 0.1, 0.05, 0.2, 0.1],
            counts: vec![3, 2],
            colors: Some(vec![
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
                [0.0, 0.0, 0.0],
            ]),
        }
    }

    #[test]
    fn layouts_per_basis() {
        let s = strands();
        for basis in CurveBasis::ALL {
            let c = Curves::from_strands(&s, basis, CurveShape::Round).unwrap();
            assert_eq!(c.indices().len(), 3, "{basis:?}");
            let expected_vertices = match basis {
                CurveBasis::Linear => 5,
                CurveBasis::BSpline | CurveBasis::CatmullRom => 9,
                CurveBasis::Bezier => 7 + 4,
            };
            assert_eq!(c.vertices().len(), expected_vertices, "{basis:?}");
            let span = basis.points_per_segment();
            assert!(
                c.indices()
                    .iter()
                    .all(|&i| i as usize + span <= c.vertices().len())
            );
        }
        let c = Curves::from_strands(&s, CurveBasis::BSpline, CurveShape::Flat).unwrap();
        // Root phantom of strand 0 is the root reflected through the second point.
        assert_eq!(c.vertices()[0], [0.0, -1.0, 0.0, 0.1]);
        assert_eq!(c.indices(), &[0, 1, 5]);
        let c = Curves::from_strands(&s, CurveBasis::Bezier, CurveShape::Flat).unwrap();
        assert_eq!(c.indices(), &[0, 3, 7]);
        assert_eq!(c.vertices()[3], [0.0, 1.0, 0.0, 0.1]);
    }

    #[test]
    fn a_subset_keeps_its_strands_numbers_points_colours_and_melanin() {
        let s = strands();
        let plain = Strands {
            colors: None,
            ..strands()
        };
        let melanin = |b| {
            Curves::from_strands(&plain, b, CurveShape::Round)
                .unwrap()
                .with_melanin(vec![[8.0, 0.0], [0.5, 1.5]])
                .unwrap()
        };
        for basis in CurveBasis::ALL {
            for whole in [
                Curves::from_strands(&s, basis, CurveShape::Round).unwrap(),
                melanin(basis),
            ] {
                subset_of(&whole);
            }
        }
    }

    #[test]
    fn spatial_order_keeps_each_strands_number_points_and_colours() {
        // Strands 0 and 2 lie together at x = 0, strand 1 far off at x = 9: the order is
        // 0, 2, 1 (or its reverse), and every strand keeps its number.
        let line = |x: f32| [[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 2.0, 0.5]];
        let points: Vec<[f32; 3]> = [0.0, 9.0, 0.1].into_iter().flat_map(line).collect();
        let s = Strands {
            radii: vec![0.01; points.len()],
            colors: Some((0..points.len()).map(|i| [i as f32 / 9.0; 3]).collect()),
            counts: vec![3, 3, 3],
            points,
        };
        for basis in CurveBasis::ALL {
            let whole = Curves::from_strands(&s, basis, CurveShape::Round).unwrap();
            let ordered = whole.clone().spatially_ordered().unwrap();
            let ids: Vec<u32> = (0..3)
                .map(|k| ordered.strands().first_segment(k).unwrap().id)
                .collect();
            assert!(ids == [0, 2, 1] || ids == [1, 2, 0], "{basis:?}: {ids:?}");
            carries(
                &whole,
                &ordered,
                &ids.iter().map(|&i| i as usize).collect::<Vec<_>>(),
            );
            // Already in order: nothing is copied.
            let again = ordered.clone().spatially_ordered().unwrap();
            assert_eq!(again, ordered);
        }
        // Points shared with the caller stay where they are, in its order.
        let shared: Arc<[[f32; 4]]> = s.points.iter().map(|p| [p[0], p[1], p[2], 0.01]).collect();
        let linear = |points| {
            Curves::from_control_points(
                points,
                &[3, 3, 3],
                None,
                CurveBasis::Linear,
                CurveShape::Round,
            )
            .unwrap()
            .spatially_ordered()
            .unwrap()
        };
        let kept = linear(SharedBuffer::from(shared.clone()));
        assert_eq!(kept.vertices().as_ptr(), shared.as_ptr());
        assert_eq!(kept.strands().first_segment(1).unwrap().id, 1);
        let owned = linear(SharedBuffer::from(shared.to_vec()));
        assert_ne!(owned.strands().first_segment(1).unwrap().id, 1);
    }

    #[test]
    fn many_strands_convert_and_reorder_as_each_strand_alone() {
        // More strands than one thread's share (`ragged`), of 2 to 5 points each, scattered
        // so that the spatial order moves them.
        let counts: Vec<u32> = (0..10_000).map(|s| 2 + s % 4).collect();
        let total: usize = counts.iter().map(|&n| n as usize).sum();
        let points: Vec<[f32; 3]> = (0..total)
            .map(|i| {
                let h = (i as u32).wrapping_mul(2_654_435_761);
                [(h % 1000) as f32, (h / 1000 % 1000) as f32, i as f32 * 1e-3]
            })
            .collect();
        let s = Strands {
            radii: (0..total).map(|i| 0.01 + (i % 7) as f32 * 1e-3).collect(),
            colors: Some((0..total).map(|i| [(i % 11) as f32 / 11.0; 3]).collect()),
            counts: counts.clone(),
            points,
        };
        let first: Vec<usize> = ragged::starts(counts.iter().map(|&n| n as usize));
        for basis in CurveBasis::ALL {
            let whole = Curves::from_strands(&s, basis, CurveShape::Round).unwrap();
            for k in [0, 1, 4095, 4096, 4097, 9999] {
                let (a, b) = (first[k], first[k + 1]);
                let alone = Strands {
                    points: s.points[a..b].to_vec(),
                    radii: s.radii[a..b].to_vec(),
                    counts: vec![counts[k]],
                    colors: None,
                };
                let alone = Curves::from_strands(&alone, basis, CurveShape::Round).unwrap();
                assert_eq!(
                    whole.strand_points(k),
                    alone.strand_points(0),
                    "{basis:?} {k}"
                );
            }
            let ordered = whole.clone().spatially_ordered().unwrap();
            let order: Vec<usize> = (0..counts.len())
                .map(|k| ordered.strands().first_segment(k).unwrap().id as usize)
                .collect();
            assert_ne!(order, (0..counts.len()).collect::<Vec<_>>());
            carries(&whole, &ordered, &order);
        }
    }

    /// `part`'s strand k is `whole`'s strand `order[k]`: its points, its number, its
    /// segments and its absorption.
    fn carries(whole: &Curves, part: &Curves, order: &[usize]) {
        let basis = whole.basis();
        assert_eq!(part.strands().strand_count(), order.len(), "{basis:?}");
        for (local, &s) in order.iter().enumerate() {
            assert_eq!(part.strand_points(local), whole.strand_points(s));
            let first = whole.strands().segment_starts[s];
            let local_first = part.strands().segment_starts[local];
            for seg in 0..whole.strands().locate(first).unwrap().segments {
                let (a, b) = (
                    whole.strands().locate(first + seg).unwrap(),
                    part.strands().locate(local_first + seg).unwrap(),
                );
                assert_eq!((b.id, b.segment, b.segments), (a.id, a.segment, a.segments));
                for u in [0.0, 0.3, 1.0] {
                    let at = |c: &Curves, s| c.strands().absorption(s, u);
                    assert!(at(whole, &a).is_some());
                    assert_eq!(at(whole, &a), at(part, &b));
                }
            }
        }
    }

    fn subset_of(whole: &Curves) {
        for keep in [[true, false], [false, true], [true, true]] {
            let part = whole.subset(&keep, CurveShape::Flat).unwrap().unwrap();
            assert_eq!(part.shape(), CurveShape::Flat);
            let kept: Vec<usize> = (0..2).filter(|&k| keep[k]).collect();
            carries(whole, &part, &kept);
            // A subset of a subset still names the strands of the whole.
            if kept.len() == 2 {
                let again = part
                    .subset(&[false, true], CurveShape::Round)
                    .unwrap()
                    .unwrap();
                assert_eq!(again.strands().locate(0).unwrap().id, 1);
            }
        }
        assert_eq!(
            whole.subset(&[false, false], CurveShape::Flat).unwrap(),
            None
        );
        let e = whole.subset(&[true], CurveShape::Flat).unwrap_err();
        assert!(e.to_string().contains("1 flags for 2 strands"), "{e}");
    }

    #[test]
    fn every_primitive_finds_its_strand() {
        // Strands of 1 to 100 segments, shorter and longer than a block.
        let lengths: Vec<usize> = (0..500).map(|i| 1 + (i * 37 + i * i) % 100).collect();
        let index = StrandIndex::new(lengths.iter().copied(), None).unwrap();
        let mut prim = 0u32;
        for (strand, &n) in lengths.iter().enumerate() {
            for segment in 0..n as u32 {
                let at = index.locate(prim).unwrap();
                assert_eq!(
                    (at.strand, at.segment, at.segments, at.first_prim, at.id),
                    (
                        strand as u32,
                        segment,
                        n as u32,
                        prim - segment,
                        strand as u32
                    )
                );
                // The strand's own lookup, without the search, gives the same segment.
                assert_eq!(index.segment(strand, segment), Some(at));
                prim += 1;
            }
            // Past the tip, the last segment: a parameter rounded up at the tip stays on it.
            let tip = index.segment(strand, n as u32 + 3).unwrap();
            assert_eq!(
                (tip.segment, tip.first_prim),
                (n as u32 - 1, prim - n as u32)
            );
        }
        assert_eq!(index.locate(prim), None);
        assert_eq!(index.segment(lengths.len(), 0), None);
    }

    #[test]
    fn strands_and_colours_survive() {
        let c = Curves::from_strands(&strands(), CurveBasis::Linear, CurveShape::Round).unwrap();
        let idx = c.strands();
        assert_eq!((idx.strand_count(), idx.segment_count()), (2, 3));
        let at = idx.locate(1).unwrap();
        assert_eq!(
            at,
            StrandSegment {
                strand: 0,
                segment: 1,
                segments: 2,
                first_prim: 0,
                id: 0,
            }
        );
        assert_eq!(at.s(0.5), 0.75);
        assert_eq!(
            idx.absorption(&at, 0.5),
            Some(HairColor::Color([0.0, 0.5, 0.5]))
        );
        let at = idx.locate(2).unwrap();
        assert_eq!(
            (at.strand, at.segment, at.s(0.0), at.s(1.0)),
            (1, 0, 0.0, 1.0)
        );
        assert_eq!(idx.absorption(&at, 0.25), Some(HairColor::Color([0.75; 3])));
        assert_eq!(idx.locate(3), None);
        assert_eq!(idx.locate(2).unwrap().prims(), 2..3);
    }

    /// Melanin stays one pair per strand, as given, and bad pairs are refused by strand.
    #[test]
    fn melanin_is_kept_per_strand() {
        let plain = Strands {
            colors: None,
            ..strands()
        };
        let c = Curves::from_strands(&plain, CurveBasis::BSpline, CurveShape::Round).unwrap();
        let m = c
            .clone()
            .with_melanin(vec![[8.0, 0.0], [0.5, 1.5]])
            .unwrap();
        let idx = m.strands();
        for (prim, want) in [(0, [8.0, 0.0]), (1, [8.0, 0.0]), (2, [0.5, 1.5])] {
            let at = idx.locate(prim).unwrap();
            for u in [0.0, 1.0] {
                assert_eq!(
                    idx.absorption(&at, u),
                    Some(HairColor::Melanin {
                        eumelanin: want[0],
                        pheomelanin: want[1]
                    })
                );
            }
        }
        for (melanin, want) in [
            (vec![[1.0, 0.0]], "1 melanin pairs for 2 strands"),
            (vec![[1.0, 0.0], [0.0, -1.0]], "strand 1: pheomelanin"),
            (vec![[f32::NAN, 0.0], [1.0, 0.0]], "strand 0: eumelanin"),
            (vec![[f32::MAX, 0.0], [1.0, 0.0]], "overflows"),
        ] {
            let e = c.clone().with_melanin(melanin).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
        let coloured = Curves::from_strands(&strands(), CurveBasis::Linear, CurveShape::Round);
        let e = coloured.unwrap().with_melanin(vec![[1.0, 0.0]; 2]);
        assert!(e.unwrap_err().to_string().contains("not both"));
    }

    #[test]
    fn host_xyzr_is_shared_not_copied() {
        let mut v = Vec::with_capacity(6 + padding_for::<[f32; 4]>());
        v.extend((0..6).map(|i| [i as f32, 0.0, 0.0, 0.1]));
        let ptr = v.as_ptr();
        let c =
            Curves::from_control_points(v, &[4, 2], None, CurveBasis::Linear, CurveShape::Round)
                .unwrap();
        assert_eq!(c.vertices().as_ptr(), ptr);
        assert_eq!(c.indices(), &[0, 1, 2, 4]);
        // An Arc is shared by the curves and their clones: only the index buffer and the
        // strand table are ours.
        let arc: Arc<[[f32; 4]]> = (0..6).map(|i| [i as f32, 0.0, 0.0, 0.1]).collect();
        let c = Curves::from_control_points(
            arc.clone(),
            &[4, 2],
            None,
            CurveBasis::Linear,
            CurveShape::Round,
        )
        .unwrap();
        assert_eq!(c.clone().vertices().as_ptr(), arc.as_ptr());
        let index_bytes = (4 + padding_for::<u32>()) * 4;
        assert_eq!(c.heap_bytes(), index_bytes + c.strands().heap_bytes());
        let bez = vec![[0.0, 0.0, 0.0, 0.1]; 7];
        let c = Curves::from_control_points(bez, &[7], None, CurveBasis::Bezier, CurveShape::Flat)
            .unwrap();
        assert_eq!(c.indices(), &[0, 3]);
    }

    #[test]
    fn bad_control_points_are_named() {
        let err = Curves::from_control_points(
            vec![[0.0; 4]; 5],
            &[5],
            None,
            CurveBasis::Bezier,
            CurveShape::Round,
        )
        .unwrap_err();
        assert!(err.to_string().contains("strand 0 has 5"), "{err}");
        let mut v = vec![[0.0, 0.0, 0.0, 0.1]; 4];
        v[2][1] = f32::NAN;
        let err =
            Curves::from_control_points(v, &[4], None, CurveBasis::BSpline, CurveShape::Round)
                .unwrap_err();
        assert!(err.to_string().contains("control point 2"), "{err}");
        let err = Curves::from_control_points(
            vec![[0.0, 0.0, 0.0, 0.1]; 4],
            &[4],
            Some(vec![[1.0; 3]; 3]),
            CurveBasis::Linear,
            CurveShape::Round,
        )
        .unwrap_err();
        assert!(err.to_string().contains("3 colours for 4"), "{err}");
        let mut s = strands();
        s.radii[0] = -1.0;
        assert!(Curves::from_strands(&s, CurveBasis::Linear, CurveShape::Round).is_err());
    }
}
