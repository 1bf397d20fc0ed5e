//! USD grooms: every `BasisCurves` prim of a composed stage (.usda, .usdc or .usdz, read by
//! the pure-Rust `openusd` crate), each as its own curve geometry in world space, laid out
//! for Embree (see [`Layout`] for the basis and wrap conversions). See docs/formats.md for
//! what is read, the primvar names and what is refused.

mod crate_check;
mod layout;
mod prim;
mod resolver;
mod write;

use std::fmt::Write as _;
use std::path::Path;

use openusd::usd::{PrimPredicate, Stage};

use crate::embree::{CurveBasis, CurveShape};
use crate::error::{Error, Result, invalid_arg};
use crate::scene::curves::Curves;
use crate::scene::framing::Framing;

pub use layout::{Interpolation, Layout, Wrap};
pub use write::{CurvesToWrite, ROOT_PRIM, StageUnits, write_usd_file};

/// Bytes a USD file may have: the reader keeps the whole stage in memory.
const MAX_FILE_BYTES: u64 = 1 << 32;

/// A stage's grooms and what the reader made of the rest.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdGrooms {
    /// The stage's `upAxis` ("Y" when not authored). Reported, not applied: points are used
    /// as authored (see docs/formats.md).
    pub up_axis: String,
    /// The stage's `metersPerUnit` (0.01 when not authored). Reported, not applied.
    pub meters_per_unit: f64,
    pub curves: Vec<UsdCurves>,
    /// Paths and types of the prims that are not BasisCurves (nor plain Xforms or Scopes).
    pub ignored: Vec<String>,
}

/// One BasisCurves prim, in world space.
#[derive(Debug, Clone, PartialEq)]
pub struct UsdCurves {
    pub path: String,
    pub layout: Layout,
    /// `curveVertexCounts` as authored.
    pub authored_counts: Vec<u32>,
    /// Segments of all curves.
    pub segments: usize,
    /// Bounds of the authored points in world space.
    pub bounds: ([f32; 3], [f32; 3]),
    /// Smallest and largest world-space radius the widths give (widths / 2 times the
    /// transform's scale).
    pub radius_range: (f32, f32),
    /// Control points (x, y, z, radius) for Embree, curve after curve.
    pub control: Vec<[f32; 4]>,
    /// Control points of each curve in `control`.
    pub control_counts: Vec<u32>,
    /// `primvars:displayColor` at every segment end (segments + 1 per curve), if authored.
    pub colors: Option<Vec<[f32; 3]>>,
    /// `primvars:displayColor` at every authored point, if authored with `constant`,
    /// `uniform` or `vertex` interpolation (what a `.hair` file holds per point).
    pub point_colors: Option<Vec<[f32; 3]>>,
    /// `primvars:melanin`: the eumelanin concentration of each curve, if authored.
    pub melanin: Option<Vec<f32>>,
}

impl UsdCurves {
    /// The Embree curves of this prim, radii multiplied by `radius_scale` and every point
    /// mapped by `point` (a scene's placement of the groom). Colours and melanin go with
    /// the strands as authored: the material converts them at each hit.
    pub fn curves(
        &self,
        shape: CurveShape,
        radius_scale: f32,
        point: impl Fn([f32; 3]) -> [f32; 3],
    ) -> Result<Curves> {
        let curves = Curves::from_control_points(
            crate::description::placed(&self.control, point, radius_scale),
            &self.control_counts,
            self.colors.clone(),
            self.layout.basis,
            shape,
        );
        let curves = match &self.melanin {
            // The primvar is eumelanin alone.
            Some(m) => curves.and_then(|c| c.with_melanin(m.iter().map(|&e| [e, 0.0]).collect())),
            None => curves,
        };
        curves.map_err(|e| e.context(&self.path))
    }

    pub fn basis(&self) -> CurveBasis {
        self.layout.basis
    }

    /// Adds the prim to `framing` as a scene frames it: the corners of its authored bounds,
    /// mapped by `point`, each widened by its largest radius times `radius_scale`.
    pub fn frame(
        &self,
        framing: &mut Framing,
        radius_scale: f32,
        point: impl Fn([f32; 3]) -> [f32; 3],
    ) {
        let (lo, hi) = self.bounds;
        let r = self.radius_range.1 * radius_scale;
        for corner in 0..8 {
            let p = std::array::from_fn(|k| if corner >> k & 1 == 1 { hi[k] } else { lo[k] });
            framing.add_hair_point(point(p).into(), r);
        }
    }
}

/// Reads and composes the stage at `path` and converts each BasisCurves prim. Errors name
/// the file (and the prim when one is at fault).
pub fn read_usd_file(path: &Path) -> Result<UsdGrooms> {
    let at = |e: Error| e.context(path.display());
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.len() > MAX_FILE_BYTES {
        return Err(at(invalid_arg!(
            "{} bytes: larger than the {MAX_FILE_BYTES} this reader accepts",
            meta.len()
        )));
    }
    let name = path
        .to_str()
        .ok_or_else(|| at(invalid_arg!("the path is not valid UTF-8")))?;
    // Every layer passes the crate check on its way in (see `resolver`). openusd 0.6 still
    // indexes some tables of a corrupt .usdc without checking them, and panics: the panic
    // is caught here and becomes this file's error (the stage is dropped with it).
    let read = std::panic::catch_unwind(|| {
        let stage = Stage::builder()
            .resolver(resolver::CheckingResolver::default())
            .open(name)
            .map_err(|e| invalid_arg!("not a readable USD stage: {e:#}"))?;
        let grooms = read_stage(&stage, meta.len())?;
        // Composition is lazy: its errors (cycles, missing layers) are known once every
        // prim has been visited.
        match stage.composition_errors().first() {
            Some(e) => Err(invalid_arg!("composition failed: {e}")),
            None => Ok(grooms),
        }
    });
    match read {
        Ok(result) => result.map_err(at),
        Err(panic) => {
            let why = (panic.downcast_ref::<String>().map(String::as_str))
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("no message");
            Err(at(invalid_arg!(
                "not a readable USD stage (the USD library failed: {why})"
            )))
        }
    }
}

/// The grooms of a composed stage. `file_bytes` bounds what any count may ask for.
fn read_stage(stage: &Stage, file_bytes: u64) -> Result<UsdGrooms> {
    let meta = |key: &str| stage.stage_metadata(key).ok().flatten();
    let up_axis = meta("upAxis")
        .and_then(|v| v.try_as_token().map(|t| t.as_str().to_string()))
        .unwrap_or_else(|| "Y".to_string());
    let meters_per_unit = meta("metersPerUnit")
        .and_then(|v| v.try_as_double())
        .unwrap_or(0.01);
    let mut paths = Vec::new();
    stage
        .traverse(PrimPredicate::DEFAULT, |p| paths.push(p.clone()))
        .map_err(|e| invalid_arg!("traversal failed: {e:#}"))?;
    let mut curves = Vec::new();
    let mut ignored = Vec::new();
    for p in &paths {
        let prim = stage.prim(p.clone());
        let kind = prim
            .type_name()
            .map_err(|e| invalid_arg!("{}: {e:#}", p.as_str()))?
            .map(|t| t.as_str().to_string())
            .unwrap_or_default();
        match kind.as_str() {
            "BasisCurves" => curves.push(
                prim::read_basis_curves(stage, p, file_bytes).map_err(|e| e.context(p.as_str()))?,
            ),
            "" | "Xform" | "Scope" => {}
            other => ignored.push(format!("{} ({other})", p.as_str())),
        }
    }
    Ok(UsdGrooms {
        up_axis,
        meters_per_unit,
        curves,
        ignored,
    })
}

/// Whether `path` names a USD file by its extension (.usd, .usda, .usdc, .usdz).
pub fn is_usd_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["usd", "usda", "usdc", "usdz"].contains(&e.to_ascii_lowercase().as_str()))
}

/// `hairtrace info` for a USD stage: per prim, curve, point and segment counts, world bounds
/// and radius range; then the stage's units and the prims that were ignored.
pub fn info_report(grooms: &UsdGrooms) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "stage:    upAxis {}, metersPerUnit {} (reported, not applied)",
        grooms.up_axis, grooms.meters_per_unit
    );
    for c in &grooms.curves {
        let (lo, hi) = c.bounds;
        let _ = writeln!(
            s,
            "prim {} ({:?}, {:?})",
            c.path, c.layout.basis, c.layout.wrap
        );
        let _ = writeln!(s, "  strands:  {}", c.authored_counts.len());
        let points: u64 = c.authored_counts.iter().map(|&n| u64::from(n)).sum();
        let _ = writeln!(s, "  points:   {points}");
        let _ = writeln!(s, "  segments: {}", c.segments);
        let _ = writeln!(
            s,
            "  bounds:   min ({}, {}, {}), max ({}, {}, {})",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        );
        let _ = writeln!(
            s,
            "  radius:   min {}, max {}",
            c.radius_range.0, c.radius_range.1
        );
        let _ = writeln!(
            s,
            "  colours:  {}",
            if c.colors.is_some() { "yes" } else { "no" }
        );
    }
    if grooms.curves.is_empty() {
        let _ = writeln!(s, "no BasisCurves prims");
    }
    if !grooms.ignored.is_empty() {
        let _ = writeln!(s, "ignored:  {}", grooms.ignored.join(", "));
    }
    s
}
