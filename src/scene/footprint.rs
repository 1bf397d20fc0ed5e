//! How much memory a groom needs at the peak of its build, estimated from its size alone,
//! so that a groom that cannot fit is refused before the build with what it needs, rather
//! than killed by the kernel part way through a build of many minutes.
//!
//! The estimate adds, per geometry ([`CurvesSize`]), the buffers hairtrace hands Embree
//! (exact, from the layouts of `curves.rs`) and Embree's peak during the BVH build (a
//! per-segment figure measured on the bench scalp: its primitive references, nodes and
//! leaves; see docs/large-grooms.md), plus what the process needs besides. A groom made
//! here (procedural, or read from a `.hair` file) also briefly holds its polylines next to
//! its converted copy, and its curves next to their copy in spatial order;
//! [`conversion_bytes`] is the larger of those moments. Level of detail changes only
//! the sizes it passes in: fewer segments, a cheaper basis or shape per part. Curves in
//! motion hold their control points once per time step, and Embree's motion-blur BVH is
//! counted once per step too: an upper bound, not yet measured (docs/measurements.md).

use crate::embree::{CurveBasis, CurveShape, SceneOptions};
use crate::error::{Result, invalid_arg};
use crate::scene::curves::Curves;

/// Bytes a process holding a scene needs besides its grooms and its render's film (code,
/// Embree's thread pool, meshes), measured as the peak of a render of a 1-strand scalp.
pub const BASE_BYTES: u64 = 140 << 20;

/// The size of one curve geometry: what its memory depends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CurvesSize {
    pub strands: u64,
    /// Curve segments (Embree primitives), all strands together.
    pub segments: u64,
    /// Control points Embree reads, at one time step.
    pub control_points: u64,
    /// Time steps over the shutter (`Curves::in_motion`): 1 for curves that stay put.
    pub time_steps: u64,
    pub basis: CurveBasis,
    pub shape: CurveShape,
    /// Built in parts (`SceneOptions::builds_in_parts`): two more u32 per segment.
    pub in_parts: bool,
}

/// Whether a scene built with `options` cuts a geometry of `segments` segments into parts.
fn in_parts(options: &SceneOptions, segments: u64) -> bool {
    options.builds_in_parts(usize::try_from(segments).unwrap_or(usize::MAX))
}

impl CurvesSize {
    /// `strands` polylines of `segments` segments each, laid out for `basis` as
    /// [`Curves::from_strands`] lays them out, in a scene built with `options`.
    pub fn polylines(
        strands: u64,
        segments: u64,
        basis: CurveBasis,
        shape: CurveShape,
        options: &SceneOptions,
    ) -> Self {
        let per_strand = match basis {
            CurveBasis::Linear => segments + 1,
            CurveBasis::BSpline | CurveBasis::CatmullRom => segments + 3,
            CurveBasis::Bezier => 3 * segments + 1,
        };
        let segments = strands.saturating_mul(segments);
        CurvesSize {
            strands,
            segments,
            control_points: strands.saturating_mul(per_strand),
            time_steps: 1,
            basis,
            shape,
            in_parts: in_parts(options, segments),
        }
    }

    /// The size of curves already converted, in a scene built with `options`.
    pub fn of(curves: &Curves, options: &SceneOptions) -> Self {
        let segments = curves.indices().len() as u64;
        CurvesSize {
            strands: curves.strands().strand_count() as u64,
            segments,
            control_points: curves.vertices().len() as u64,
            time_steps: curves.time_steps() as u64,
            basis: curves.basis(),
            shape: curves.shape(),
            in_parts: in_parts(options, segments),
        }
    }

    /// Bytes of the buffers hairtrace keeps for these curves: float4 control points at
    /// each time step, one
    /// u32 index per segment (three in parts: the index buffer in the order of Embree's
    /// parts and each of its segments' own number), the strand table (two u32 per strand,
    /// its first segment and, in spatial order, its number; one per 32 segments).
    pub fn curve_bytes(&self) -> u64 {
        let points = (self.control_points.saturating_mul(16)).saturating_mul(self.time_steps);
        let indices = if self.in_parts { 12 } else { 4 };
        let segments = self.segments.saturating_mul(indices) + self.segments / 8;
        points
            .saturating_add(segments)
            .saturating_add(self.strands.saturating_mul(8))
    }

    /// Bytes Embree holds at the peak of the BVH build over these curves, `compact` or not:
    /// a static BVH's once per time step.
    pub fn bvh_bytes(&self, compact: bool) -> u64 {
        (self.segments)
            .saturating_mul(bvh_bytes_per_segment(self.basis, compact))
            .saturating_mul(self.time_steps)
    }

    /// "1000000 strands x 16 segments, catmull_rom round".
    fn describe(&self) -> String {
        let per = self.segments.checked_div(self.strands).unwrap_or(0);
        let basis = match self.basis {
            CurveBasis::Linear => "linear",
            CurveBasis::Bezier => "bezier",
            CurveBasis::BSpline => "bspline",
            CurveBasis::CatmullRom => "catmull_rom",
        };
        let shape = match self.shape {
            CurveShape::Round => "round",
            CurveShape::Flat => "flat",
        };
        let steps = match self.time_steps {
            1 => String::new(),
            k => format!(" at {k} time steps"),
        };
        format!(
            "{} strands x {per} segments, {basis} {shape}{steps}",
            self.strands
        )
    }
}

/// Embree's peak bytes per curve segment during a BVH build: 32-byte primitive references,
/// then the BVH, both alive at the end of the build. A compact BVH's leaves index the
/// control points; the other's copy them. Cubic and linear leaves differ; round and flat
/// share them.
fn bvh_bytes_per_segment(basis: CurveBasis, compact: bool) -> u64 {
    match (basis, compact) {
        (CurveBasis::Linear, true) => 35,
        (CurveBasis::Linear, false) => 52,
        (_, true) => 40,
        (_, false) => 140,
    }
}

/// Bytes Embree holds at the peak of the BVH builds of a scene built with `options` whose
/// curves are `parts`: the curves attached whole share the top level's BVH, compact or not
/// by their total; parts are compact or not by their geometry's size.
pub fn bvh_bytes(parts: &[CurvesSize], options: &SceneOptions) -> u64 {
    let compacts =
        |segments: u64| options.compacts(usize::try_from(segments).unwrap_or(usize::MAX));
    let whole = compacts(
        parts
            .iter()
            .filter(|p| !p.in_parts)
            .map(|p| p.segments)
            .sum(),
    );
    parts
        .iter()
        .map(|p| {
            p.bvh_bytes(if p.in_parts {
                compacts(p.segments)
            } else {
                whole
            })
        })
        .fold(0, u64::saturating_add)
}

/// Peak bytes of a scene built with `options` whose curves are `parts`, at its BVH build.
pub fn build_bytes(parts: &[CurvesSize], options: &SceneOptions) -> u64 {
    parts
        .iter()
        .map(CurvesSize::curve_bytes)
        .fold(BASE_BYTES, u64::saturating_add)
        .saturating_add(bvh_bytes(parts, options))
}

/// Peak bytes while polylines of `points` points (xyz and radius, 16 bytes each) and
/// `strands` strands are converted into `part`, and then while `part` is copied (into
/// spatial order, or shared out between shapes): at each moment both are alive.
pub fn conversion_bytes(points: u64, strands: u64, part: &CurvesSize) -> u64 {
    let curves = part.curve_bytes();
    let conversion = points
        .saturating_mul(16)
        .saturating_add(strands.saturating_mul(4))
        .saturating_add(curves);
    BASE_BYTES.saturating_add(conversion.max(curves.saturating_mul(2)))
}

/// Bytes this process may still take before the system runs out: Linux's `MemAvailable`,
/// capped by the memory cgroup's limit when there is one. `None` when not known (then
/// nothing is refused).
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib = |text: &str, key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
    };
    let mut available = kib(&meminfo, "MemAvailable:")?.saturating_mul(1024);
    let read = |f: &str| std::fs::read_to_string(format!("/sys/fs/cgroup/{f}")).ok();
    if let (Some(max), Some(current)) = (read("memory.max"), read("memory.current"))
        && let (Ok(max), Ok(current)) = (max.trim().parse::<u64>(), current.trim().parse::<u64>())
    {
        available = available.min(max.saturating_sub(current));
    }
    Some(available)
}

/// Refuses `parts` when `needed` bytes (one of the estimates above), needed `when`, exceed
/// `available` (from [`available_bytes`]), naming their sizes, what they need and what
/// there is.
pub fn check_fits(
    parts: &[CurvesSize],
    needed: u64,
    when: &str,
    available: Option<u64>,
) -> Result<()> {
    let Some(available) = available.filter(|&a| needed > a) else {
        return Ok(());
    };
    let gib = |b: u64| b as f64 / f64::from(1u32 << 30);
    let sizes: Vec<String> = parts.iter().map(CurvesSize::describe).collect();
    Err(invalid_arg!(
        "{} need about {:.1} GiB of memory {when}, and {:.1} GiB are available: use fewer \
         strands or segments, or the linear basis",
        sizes.join(" + "),
        gib(needed),
        gib(available)
    ))
}

/// Refuses a render whose films need `bytes` (`crate::render::renderer::film_bytes`) when
/// that exceeds `available` (from [`available_bytes`]), before any is allocated. `uniform`
/// is what the render would need sampled uniformly: the refusal suggests it where that fits.
pub fn check_film_fits(bytes: u64, uniform: u64, available: Option<u64>) -> Result<()> {
    let Some(available) = available.filter(|&a| bytes > a) else {
        return Ok(());
    };
    let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
    let uniform = if uniform < bytes && uniform <= available {
        format!(
            ", or sample uniformly (allocation = uniform: about {:.0} MiB)",
            mib(uniform)
        )
    } else {
        String::new()
    };
    Err(invalid_arg!(
        "the render's film needs about {:.0} MiB of memory, and {:.0} MiB are available: \
         render fewer pixels (a crop, or the frame in tiles){uniform}",
        mib(bytes),
        mib(available)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embree::{Device, PartsRule};
    use crate::scene::FurBall;
    use crate::scene::tracer::TracerBuilder;
    use std::sync::Arc;

    fn options(parts: PartsRule) -> SceneOptions {
        SceneOptions {
            parts,
            ..SceneOptions::default()
        }
    }

    /// The parts' two u32 per segment are counted where the scene's rule builds the
    /// geometry in parts, and only there: an `auto` groom under 2^20 segments, or rendered
    /// with many samples per segment, is built whole.
    #[test]
    fn the_parts_are_counted_only_where_the_rule_builds_in_parts() {
        let bytes = |strands: u64, parts| {
            let (basis, shape) = (CurveBasis::CatmullRom, CurveShape::Flat);
            CurvesSize::polylines(strands, 16, basis, shape, &options(parts)).curve_bytes()
        };
        let (few_samples, many_samples) =
            (PartsRule::ForSamples(1), PartsRule::ForSamples(1 << 40));
        // 2^19 segments: in parts only when asked.
        let whole = bytes(1 << 15, PartsRule::Never);
        assert_eq!(bytes(1 << 15, PartsRule::Always) - whole, 8 << 19);
        assert_eq!(bytes(1 << 15, few_samples), whole);
        // 2^21 segments: `auto` cuts them for few samples per segment.
        let whole = bytes(1 << 17, PartsRule::Never);
        assert_eq!(bytes(1 << 17, few_samples) - whole, 8 << 21);
        assert_eq!(bytes(1 << 17, many_samples), whole);
    }

    /// The estimate of the buffers is what a built scene holds, whole and in parts.
    #[test]
    fn the_curve_bytes_are_what_a_scene_of_the_curves_holds() {
        let device = Arc::new(Device::new(Some(2)).unwrap());
        let ball = FurBall {
            strands: 1 << 14,
            segments: 16,
            ..FurBall::default()
        };
        let strands = ball.build().unwrap();
        let curves = || Curves::from_strands(&strands, CurveBasis::CatmullRom, CurveShape::Flat);
        for (parts, steps) in [
            (PartsRule::Never, 1),
            (PartsRule::Always, 1),
            (PartsRule::Never, 3),
            (PartsRule::Always, 2),
        ] {
            // As a build holds them: in spatial order, with each strand's own number.
            let curves = (0..steps)
                .map(|_| curves())
                .collect::<Result<Vec<_>>>()
                .and_then(Curves::in_motion)
                .and_then(Curves::spatially_ordered)
                .unwrap();
            assert_eq!(curves.time_steps(), steps);
            let estimate = CurvesSize::of(&curves, &options(parts)).curve_bytes() as f64;
            let mut builder = TracerBuilder::new(device.clone(), options(parts)).unwrap();
            builder.add_curves(curves).unwrap();
            let held = builder.build().unwrap().heap_bytes() as f64;
            assert!(
                (held / estimate - 1.0).abs() < 2e-3,
                "{parts:?} x {steps} steps: {held} against {estimate}"
            );
        }
    }

    /// A BVH under the default threshold's segments is counted at the fast layout's bytes,
    /// one at or past it at the compact layout's: the whole curves by their total, parts
    /// by their geometry's size.
    #[test]
    fn the_bvh_is_counted_compact_from_its_threshold() {
        let threshold = SceneOptions::default().compact_from_segments as u64;
        let size = |strands: u64, basis| {
            CurvesSize::polylines(
                strands,
                16,
                basis,
                CurveShape::Round,
                &options(PartsRule::Never),
            )
        };
        let below = size((threshold - 16) / 16, CurveBasis::CatmullRom);
        let per_segment = |sizes: &[CurvesSize]| {
            let segments: u64 = sizes.iter().map(|s| s.segments).sum();
            bvh_bytes(sizes, &options(PartsRule::Never)) / segments
        };
        assert_eq!(per_segment(&[below]), 140);
        let linear = size((threshold - 16) / 16, CurveBasis::Linear);
        assert_eq!(per_segment(&[linear]), 52);
        // Two grooms under the threshold that together pass it share a compact BVH.
        assert_eq!(per_segment(&[below, below]), 40);
        // A geometry in parts is compact or not by its own size, whatever the scene's.
        let parts = CurvesSize {
            in_parts: true,
            ..below
        };
        assert_eq!(
            bvh_bytes(&[parts, below, below], &options(PartsRule::Always)),
            below.segments * (140 + 2 * 40)
        );
    }
}
